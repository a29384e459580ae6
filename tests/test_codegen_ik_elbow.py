"""Compiled analytic IK of the elbow class (6R, axes 2 ∥ 3, spherical wrist: the Puma's) against the plain solver,
on random arms of the class: the elbow kernel computes every branch of a chunk of poses in stages (candidates,
verifying FK, residuals, labels) and walks each pose's branches afterwards, so its answers, labels and hand-overs
are checked pose by pose and in batches that end inside a chunk.

The peer is :func:`denavit.analytic_ik` (numpy, batched), compared as in test_codegen_ik.py (same solution sets to
1e-10 widened by the conditioning, same labels, continuum texts and outside-limits sets, FK(IK(T)) = T by the plain
forward kinematics); singular poses are found from the joint axes alone (no formula of the solver).
"""

from __future__ import annotations

import numpy as np
import pytest
from conftest import REDUCED
from hypothesis import assume, example, given, settings
from hypothesis import strategies as st

import denavit
from denavit import Convention, DHRobot

pytest.importorskip("numba")

from test_codegen_ik import (N_POSES, _axes, _check_arm, _meet, _same_batch, _shoulder,  # noqa: E402
                             _wrist_coplanar, random_base_tool, random_revolute, random_wrist_draws)
from test_codegen_ik import _kernel_cache  # noqa: E402, F401  (the module's kernel folder, a fixture)

from denavit.ik import ik_plan  # noqa: E402


def _random_elbow_class(seed: int) -> DHRobot:
    """A random 6R arm with axes 2 ∥ 3 and a spherical wrist (either convention): random lengths, offsets along the
    axes, twists of the other axes (half of the wrists with equal outer twists, so that axes 4 and 6 can align),
    joint offsets, limits, base and tool."""
    rng, conv, twist, length, t4, t5 = random_wrist_draws(seed)
    if conv is Convention.STANDARD:  # (a, alpha, d) of z_{i-1} -> z_i; axes 2, 3 = z1, z2; wrist z3, z4, z5 at o4
        rows = [(length(), twist(), length()), (rng.uniform(0.2, 0.8), 0.0, length()), (length(), twist(), length()),
                (0.0, t4, length()), (0.0, t5, 0.0), (length(), twist(), length())]
    else:  # (a_{i-1}, alpha_{i-1}, d_i); axes 2, 3 = z2, z3; wrist z4, z5, z6 at o4 = o5
        rows = [(length(), twist(), length()), (length(), twist(), length()), (rng.uniform(0.2, 0.8), 0.0, length()),
                (length(), twist(), length()), (0.0, t4, 0.0), (0.0, t5, length())]
    links = [random_revolute(rng, a, alpha, d) for a, alpha, d in rows]
    base, tool = random_base_tool(rng)
    return DHRobot(name="random-elbow", links=tuple(links), convention=conv, base=base, tool=tool)


def _elbow_line(robot, q):
    """det(o3 − o2, W − o2, z2) (o2, o3 points of axes 2, 3, W the wrist centre): zero where W lies in the plane of
    the parallel axes 2 and 3, the elbow stretched or folded (its two roots meet)."""
    z, o = _axes(robot, q)
    return np.cross(o[2] - o[1], _meet(z, o, 4, 5) - o[1]) @ z[1]


ELBOW_SINGULAR = ((_shoulder, 1), (_elbow_line, 2), (_wrist_coplanar, 4))


@pytest.mark.slow
@settings(max_examples=2 if REDUCED else 5)
@given(seed=st.integers(0, 2**32 - 1))
@example(seed=54)  # a pose next to the wrist's axes coplanar (not aligned: its twists differ), the two q5 meeting
def test_random_elbow_class_arms_compiled_equals_plain(seed, _kernel_cache):  # noqa: F811
    """Random elbow-class arms (both conventions, offsets, limits, base and tool) x random and singular poses, one
    at a time and in a batch of 37 (two chunks of the stages and part of a third)."""
    robot = _random_elbow_class(seed)
    plan = ik_plan(robot)
    assume(plan.route == "closed form (elbow)")  # not where the elbow leaves the reach unchanged (a3 = d4 = 0 …)
    fast = denavit.compile(robot, kernels=["fk", "fk_jacobian0"])
    assert fast._analytic_solver()[1][1] == "pieper"  # the elbow kernel answers (not the plain solver alone)
    rng = np.random.default_rng(seed)
    _check_arm(robot, fast, rng, N_POSES // 2, 6 if REDUCED else 12, ELBOW_SINGULAR, wrist=True, handed_over=0.6)
    lim = np.clip(robot.q_limits, -2 * np.pi, 2 * np.pi)
    batch = denavit.forward_kinematics(robot, rng.uniform(lim[:, 0], lim[:, 1], (37, 6)))
    _same_batch(robot, fast.analytic_ik(batch), denavit.analytic_ik(robot, batch))
