"""Trajectories: quintic and trapezoidal joint profiles, straight-line Cartesian paths.

Every check goes through an independent route: boundary values against what was asked, rates
against finite differences and numerical integration, quintic coefficients against a 6×6 linear
solve, and the Cartesian path against the geometry of the segment (distance to the line).
"""

from __future__ import annotations

import numpy as np
import pytest

import denavit
from denavit import ShapeError
from denavit.numeric import cartesian_path, quintic_trajectory, trapezoidal_trajectory

SEEDS = range(6)


def _poly_by_linear_solve(q0, q1, v0, v1, a0, a1, T, t):
    """Position of the quintic from the 6×6 boundary-condition system (a second route)."""
    M = np.array([
        [1, 0, 0, 0, 0, 0], [0, 1, 0, 0, 0, 0], [0, 0, 2, 0, 0, 0],
        [1, T, T**2, T**3, T**4, T**5], [0, 1, 2 * T, 3 * T**2, 4 * T**3, 5 * T**4],
        [0, 0, 2, 6 * T, 12 * T**2, 20 * T**3],
    ], dtype=float)
    c = np.linalg.solve(M, np.stack([q0, v0, a0, q1, v1, a1]))  # (6, n)
    return np.stack([t**j for j in range(6)], axis=1) @ c


@pytest.mark.parametrize("seed", SEEDS)
def test_quintic_meets_boundary_values_and_matches_linear_solve(seed):
    rng = np.random.default_rng(seed)
    n = int(rng.integers(1, 7))
    q0, q1, v0, v1, a0, a1 = rng.uniform(-2, 2, (6, n))
    T = float(rng.uniform(0.3, 4))
    tr = quintic_trajectory(q0, q1, 41, duration=T, qd0=v0, qd1=v1, qdd0=a0, qdd1=a1)
    assert tr.q.shape == tr.qd.shape == tr.qdd.shape == (41, n)
    np.testing.assert_allclose(tr.t[[0, -1]], [0, T])
    for got, want in ((tr.q[0], q0), (tr.q[-1], q1), (tr.qd[0], v0), (tr.qd[-1], v1),
                      (tr.qdd[0], a0), (tr.qdd[-1], a1)):
        np.testing.assert_allclose(got, want, atol=1e-9)
    t = rng.uniform(0, T, 15)
    np.testing.assert_allclose(quintic_trajectory(q0, q1, t, duration=T, qd0=v0, qd1=v1, qdd0=a0, qdd1=a1).q,
                               _poly_by_linear_solve(q0, q1, v0, v1, a0, a1, T, t), atol=1e-9)


@pytest.mark.parametrize("seed", SEEDS)
def test_quintic_rates_equal_finite_differences(seed):
    rng = np.random.default_rng(100 + seed)
    q0, q1 = rng.uniform(-3, 3, (2, 4))
    T, h = 2.0, 1e-5
    t = rng.uniform(0.1, 1.9, 9)
    f = lambda tt: quintic_trajectory(q0, q1, tt, duration=T, qd0=0.3, qdd1=-1.0)  # noqa: E731
    tr, plus, minus = f(t), f(t + h), f(t - h)
    np.testing.assert_allclose(tr.qd, (plus.q - minus.q) / (2 * h), atol=1e-6)
    np.testing.assert_allclose(tr.qdd, (plus.qd - minus.qd) / (2 * h), atol=1e-6)


def test_quintic_batch_equals_loop():
    rng = np.random.default_rng(7)
    q0, q1 = rng.uniform(-2, 2, (2, 3, 2, 5))
    batched = quintic_trajectory(q0, q1, 11, duration=1.5)
    assert batched.q.shape == (3, 2, 11, 5)
    for i in range(3):
        for j in range(2):
            one = quintic_trajectory(q0[i, j], q1[i, j], 11, duration=1.5)
            np.testing.assert_allclose(batched.q[i, j], one.q, atol=1e-12)
            np.testing.assert_allclose(batched.qdd[i, j], one.qdd, atol=1e-12)


@pytest.mark.parametrize("seed", SEEDS)
def test_trapezoid_with_duration_rest_to_rest_and_cruise_speed(seed):
    rng = np.random.default_rng(200 + seed)
    n = int(rng.integers(1, 7))
    q0, q1 = rng.uniform(-3, 3, (2, n))
    T, ratio = float(rng.uniform(0.5, 3)), float(rng.uniform(1.05, 2.0))
    tr = trapezoidal_trajectory(q0, q1, 2001, duration=T, cruise_ratio=ratio)
    np.testing.assert_allclose(tr.q[0], q0, atol=1e-12)
    np.testing.assert_allclose(tr.q[-1], q1, atol=1e-9)
    np.testing.assert_allclose(tr.qd[[0, -1]], 0.0, atol=1e-9)
    # peak speed is the cruise speed ratio·|Δq|/T (Spong §5.5.2)
    np.testing.assert_allclose(np.abs(tr.qd).max(axis=0), ratio * np.abs(q1 - q0) / T, rtol=1e-9)
    # position is the integral of velocity, velocity the integral of acceleration (trapezoid rule)
    dt = np.diff(tr.t)[:, None]
    q_int = q0 + np.concatenate([np.zeros((1, n)), np.cumsum((tr.qd[1:] + tr.qd[:-1]) / 2 * dt, axis=0)])
    np.testing.assert_allclose(tr.q, q_int, atol=5e-6 * (1 + np.abs(q1 - q0).max()))
    qd_int = np.concatenate([np.zeros((1, n)), np.cumsum((tr.qdd[1:] + tr.qdd[:-1]) / 2 * dt, axis=0)])
    np.testing.assert_allclose(tr.qd, qd_int, atol=2e-2 * (1 + np.abs(tr.qd).max()))


@pytest.mark.parametrize("seed", SEEDS)
def test_trapezoid_from_limits_respects_them_and_is_time_optimal(seed):
    rng = np.random.default_rng(300 + seed)
    n = int(rng.integers(1, 7))
    q0, q1 = rng.uniform(-3, 3, (2, n))
    vmax, amax = rng.uniform(0.5, 2, n), rng.uniform(0.5, 4, n)
    tr = trapezoidal_trajectory(q0, q1, 3001, qd_max=vmax, qdd_max=amax)
    np.testing.assert_allclose(tr.q[-1], q1, atol=1e-9)
    np.testing.assert_allclose(tr.qd[[0, -1]], 0.0, atol=1e-9)
    assert np.all(np.abs(tr.qd) <= vmax * (1 + 1e-9))
    assert np.all(np.abs(tr.qdd) <= amax * (1 + 1e-9))
    # the slowest joint alone needs exactly this long: |h|/V + V/A (trapezoid) or 2√(|h|/A) (triangle)
    h = np.abs(q1 - q0)
    alone = np.where(h >= vmax**2 / amax, h / vmax + vmax / amax, 2 * np.sqrt(h / amax))
    assert tr.duration == pytest.approx(alone.max(), rel=1e-12)


def test_trapezoid_rejects_bad_inputs():
    with pytest.raises(ShapeError, match="duration"):
        trapezoidal_trajectory([0, 0], [1, 1])
    with pytest.raises(ShapeError, match="cruise_ratio"):
        trapezoidal_trajectory([0], [1], duration=1, cruise_ratio=3)
    with pytest.raises(ShapeError, match="expected shape"):
        trapezoidal_trajectory([0, 0], [1, 1, 1], duration=1)
    with pytest.raises(ShapeError, match="positive"):
        quintic_trajectory([0], [1], duration=-1)


def _distance_to_segment_line(p, a, b):
    u = (b - a) / np.linalg.norm(b - a)
    rel = p - a
    return np.linalg.norm(rel - (rel @ u)[:, None] * u, axis=-1), rel @ u / np.linalg.norm(b - a)


CARTESIAN_CASES = [("puma560", 11), ("panda", 12), ("stanford", 13), ("planar2r", 14), ("scara", 15),
                   ("ur5", 16), ("report004-8-prrr", 17)]


@pytest.mark.parametrize("name,seed", CARTESIAN_CASES)
def test_cartesian_path_stays_on_the_line(name, seed):
    robot = denavit.load_robot(name)
    rng = np.random.default_rng(seed)
    lim = robot.q_limits
    mid = (lim[:, 0] + lim[:, 1]) / 2
    q0 = mid + rng.uniform(-0.25, 0.25, robot.dof) * (lim[:, 1] - lim[:, 0]) / 2
    q1 = q0 + rng.uniform(-0.3, 0.3, robot.dof) * np.minimum(1.0, (lim[:, 1] - lim[:, 0]) / 2)
    path = cartesian_path(robot, q0, q1, 40, duration=2.0)
    assert path.success, (path.position_error.max(), path.orientation_error.max())
    T = denavit.forward_kinematics(robot, path.q)  # recomputed here, not taken from the result
    T0, T1 = denavit.forward_kinematics(robot, q0), denavit.forward_kinematics(robot, q1)
    dist, s = _distance_to_segment_line(T[:, :3, 3], T0[:3, 3], T1[:3, 3])
    assert dist.max() < 1e-6
    assert np.all(np.diff(s) >= -1e-9), "progress along the line must be monotone"
    assert s[0] == pytest.approx(0, abs=1e-9) and s[-1] == pytest.approx(1, abs=1e-6)
    np.testing.assert_allclose(path.q[0], q0, atol=1e-9)
    if path.orientation_tracked:
        np.testing.assert_allclose(T[-1, :3, :3], T1[:3, :3], atol=1e-6)
        # geodesic: every relative rotation R0ᵀR(t) turns about the axis of R0ᵀR1
        R01 = T0[:3, :3].T @ T1[:3, :3]
        axis = np.array([R01[2, 1] - R01[1, 2], R01[0, 2] - R01[2, 0], R01[1, 0] - R01[0, 1]])
        for R in T[1:-1, :3, :3]:
            Rr = T0[:3, :3].T @ R
            w = np.array([Rr[2, 1] - Rr[1, 2], Rr[0, 2] - Rr[2, 0], Rr[1, 0] - Rr[0, 1]])
            assert np.linalg.norm(np.cross(w, axis)) < 1e-6 * (1 + np.linalg.norm(axis))
    assert np.abs(np.diff(path.q, axis=0)).max() < 0.5, "joint path must be continuous"


def test_cartesian_path_to_a_pose_goal_and_timing():
    robot = denavit.load_robot("puma560")
    q0 = np.array([0.1, 0.6, -1.2, 0.2, 0.7, -0.3])
    goal = denavit.forward_kinematics(robot, q0 + 0.2)
    path = cartesian_path(robot, q0, goal, np.linspace(0, 1.5, 25), duration=1.5)
    assert path.success and path.q.shape == (25, 6)
    np.testing.assert_allclose(denavit.forward_kinematics(robot, path.q[-1]), goal, atol=1e-7)
    # quintic timing: the speed along the line is zero at both ends
    p = denavit.forward_kinematics(robot, path.q)[:, :3, 3]
    steps = np.linalg.norm(np.diff(p, axis=0), axis=-1)
    assert steps[0] < 0.05 * steps.max() and steps[-1] < 0.05 * steps.max()


def test_cartesian_path_reports_failure_for_an_unreachable_goal():
    robot = denavit.load_robot("planar2r")
    far = np.eye(4)
    far[:3, 3] = [5.0, 0.0, 0.0]  # reach is 2 m
    path = cartesian_path(robot, [0.3, 0.5], far, 10)
    assert not path.success
    assert path.position_error.max() > 1.0
