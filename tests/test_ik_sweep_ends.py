"""free_joint_sweep's branch ends, regression cases from the issue-30 runs at 1,000 random poses
(scripts/ik_free_check.py), each checked against a route the sweep does not use: the branch followed by
Levenberg–Marquardt continuation of the held arm built from the DH rows, and a dense numeric search past the end.
"""

from __future__ import annotations

import numpy as np
import pytest

from denavit import forward_kinematics, free_joint_sweep, load_robot, solve_ik
from denavit.ik._sweep import _Held, _refine

from test_ik_sweep import _check_solutions, _dense, _held_arm, _sweep_checks


def _follow(robot, T, k, q, values):
    """The solution q (joint k at values[0]) carried along ``values`` by LM seeded at the previous one, on the held
    arm built here; each step must converge and move every joint by less than 0.1 rad (one continuous branch)."""
    path = [np.asarray(q, float)]
    for v in values[1:]:
        held = _held_arm(robot, k, v)
        res = solve_ik(held, T, np.delete(path[-1], k), restarts=0)
        assert res.success
        nxt = np.insert(res.q, k, v)
        assert np.abs(nxt - path[-1]).max() < 0.1
        path.append(nxt)
    return np.array(path)


# Panda pose 830 of the 1,000 (seed 0): the held arm near a fold (σ_min 1.4e-4 at q7 = −1.0056154, 3.7e-4 from the
# fold), joints 1 and 3 turning at up to ~500 rad per rad of q7 there. Its sweep at 64 samples bisected the end
# between −1.0117556 (inside) and −1.0002583: the first midpoint's solution lay 0.54 rad away (LINK_RADIUS 0.5), the
# end was placed at −1.0060076, 4e-4 short of the generating value.
PANDA_830 = [-1.9747035308943577, 0.0967450410284676, -0.13809211146951572, -1.3289998234645408,
             -1.579880563632576, 1.2564716402649514, -1.0056154421703896]


@pytest.mark.slow  # about 2 CPU-s
def test_end_bisection_follows_a_branch_whose_joints_turn_fast_next_to_a_fold():
    robot = load_robot("panda")
    q = np.array(PANDA_830)
    T = forward_kinematics(robot, q)
    inside, outside = -1.0117556, -1.0002583
    # the branch from q back to the inside value, in steps growing as the square (joints move as √ of the distance)
    track = _follow(robot, T, 6, q, q[6] + (inside - q[6]) * np.linspace(0, 1, 81) ** 2)
    held = _Held(robot, T, 6)
    sols, labels = held.solve([inside])
    ok = ~np.isnan(sols[0]).any(axis=-1)
    near = np.abs(sols[0][ok] - track[-1]).max(axis=-1)
    assert near.min() < 1e-6  # the sweep's solver has the followed solution at the inside value
    j = int(np.argmin(near))
    (end, q_end), = _refine(robot, held, [(inside, outside, sols[0][ok][j], labels[0][ok][j])], 1e-6)
    _check_solutions(robot, T, q_end[None])
    assert q_end[6] == end >= q[6]  # the branch runs at least to the generating configuration
    # and ends within 1e-4 past the refined end: the dense search finds no solution near it there
    found = _dense(robot, T, 6, end + 1e-4, np.random.default_rng(3))
    assert len(found) == 0 or np.abs(found - q_end).max(axis=-1).min() > 0.05


# Panda poses with q2 near 0 (joints 1 and 3 nearly aligned; drawn with q2 uniform in ±0.15, the rest uniform in the
# limits): a fold where joints 1 and 3 turn fast, inside a sample step cut into 8. The end bisections of the two
# branches meeting there each stopped short of it, leaving a false gap of 2.9e-3 rad between two intervals in which
# analytic_ik(free=) and the dense search find solutions.
FOLD_GAPS = [
    [0.4924686057458021, -0.005807380452338695, 1.1165590808157142, -1.5074198424815484, 0.12714597478660306,
     2.762011441858418, -2.4487343943586866],
    [-2.411991671633271, 0.010868016131655056, 0.9664955194229257, -1.6013716167987295, 0.8941297093820024,
     0.9677987190620504, -1.1367870341481616],
]


@pytest.mark.slow  # about 2 CPU-s each
@pytest.mark.parametrize("q", FOLD_GAPS)
def test_no_false_gap_where_two_branches_meet_at_a_fast_fold(q):
    robot = load_robot("panda")
    q = np.array(q)
    T = forward_kinematics(robot, q)
    sweep = free_joint_sweep(robot, T, "q7", samples=64)
    _sweep_checks(robot, T, q, sweep, np.random.default_rng(4))  # gaps: the dense search finds nothing at their middle
