"""The one definition of where a joint is sampled or swept (denavit.model.sampling_ranges / DHRobot.sampling_ranges),
checked against ranges written by hand, and callers that relied on a fallback it changed."""

from __future__ import annotations

from dataclasses import replace

import numpy as np

import denavit
from denavit.calibration import excitation_trajectory
from denavit.model import sampling_ranges

INF = np.inf


def test_limits_kept_and_unlimited_joints_get_one_turn_or_the_travel():
    limits = [[-1.0, 2.0], [-INF, INF], [0.1, 0.4], [-INF, INF]]
    revolute = [True, True, False, False]
    got = sampling_ranges(limits, revolute, travel=0.7)
    np.testing.assert_array_equal(got, [[-1.0, 2.0], [-np.pi, np.pi], [0.1, 0.4], [-0.7, 0.7]])
    np.testing.assert_array_equal(got.mean(axis=1), [0.5, 0.0, 0.25, 0.0])  # the middle: 0 without limits


def test_one_sided_limits_stay_non_empty():
    limits = [[-INF, 1.0], [-INF, -4.0], [5.0, INF], [-INF, -2.0]]
    revolute = [True, True, True, False]
    got = sampling_ranges(limits, revolute, travel=0.5)
    expected = [[-np.pi, 1.0], [-4.0 - 2 * np.pi, -4.0], [5.0, 5.0 + 2 * np.pi], [-3.0, -2.0]]
    np.testing.assert_allclose(got, expected, rtol=0, atol=1e-15)


def test_robot_method_reads_its_own_limits_and_joint_types():
    panda = denavit.load_robot("panda")
    np.testing.assert_array_equal(panda.sampling_ranges(), panda.q_limits)  # every joint limited
    gen3 = denavit.load_robot("gen3")
    lim = gen3.q_limits
    free = ~np.isfinite(lim).all(axis=1)
    assert free.any()  # Kinova Gen3: q1, q3, q5, q7 turn without limits
    got = gen3.sampling_ranges()
    np.testing.assert_array_equal(got[free], np.tile([-np.pi, np.pi], (free.sum(), 1)))
    np.testing.assert_array_equal(got[~free], lim[~free])
    stanford = denavit.load_robot("stanford")
    k = [t is denavit.JointType.PRISMATIC for t in stanford.joint_types].index(True)
    row = stanford.joint_rows[k]
    links = list(stanford.links)
    links[row] = replace(links[row], q_limits=None)
    got = stanford.replace(links=tuple(links)).sampling_ranges(travel=0.3)
    assert tuple(got[k]) == (-0.3, 0.3)
    np.testing.assert_array_equal(np.delete(got, k, 0), np.delete(stanford.sampling_ranges(), k, 0))


def test_excitation_window_of_a_one_sided_limit_beyond_half_a_turn():
    """q_limits (−inf, −4] for a revolute joint: the window was clipped to [−π, −π] ("no room to move"); it is
    now one turn below −4."""
    robot = denavit.load_robot("planar2r")
    res = excitation_trajectory(robot, harmonics=1, starts=1, max_iterations=1, q_limits=[[-INF, -4.0], [-1.0, 1.0]])
    assert np.all(res.q[:, 0] <= -4.0) and np.all(res.q[:, 0] >= -4.0 - 2 * np.pi)
