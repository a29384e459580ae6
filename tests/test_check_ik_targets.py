"""An ``ik_solutions`` claim's target ``T`` must be a pose (issue 29): a matrix that is no rigid transform makes the
claim unreadable, with the reason, instead of being judged (it was "incorrect: missing ..." or even "correct")."""

from __future__ import annotations

import numpy as np
import pytest

import denavit as dn
from denavit.check import check_claims

ROBOT = "planar2r"


def _verdict(T, value):
    (v,) = check_claims(dn.load_robot(ROBOT), [{"quantity": "ik_solutions", "T": T, "value": value}]).verdicts
    return v


def _pose(q):
    return dn.forward_kinematics(dn.load_robot(ROBOT), np.asarray(q, dtype=float))


@pytest.mark.parametrize("value", [[], [[0.3, 0.2]]])
@pytest.mark.parametrize("change, reason", [
    (lambda T: np.vstack([T[:3], [5, 5, 5, 5]]), "bottom row is [5, 5, 5, 5]"),
    (lambda T: np.diag([2.0, 1.0, 1.0, 1.0]) @ T, "not orthonormal"),
    (lambda T: np.diag([1.0, 1.0, -1.0, 1.0]) @ T, "reflection"),
    (lambda T: np.where(np.eye(4, dtype=bool), np.inf, T), "finite"),  # (the claim reader refuses inf first)
])
def test_a_target_that_is_no_pose_makes_the_claim_unreadable(change, reason, value):
    T = change(_pose([0.3, 0.2]))
    v = _verdict(T.tolist(), value)
    assert v.verdict == "unreadable" and reason in v.message, v.message


def test_the_bottom_row_read_from_text_is_checked_too():
    v = _verdict("[[1,0,0,1],[0,1,0,0],[0,0,1,0],[5,5,5,5]]", [])
    assert v.verdict == "unreadable" and "rigid transform" in v.message, v.message


def test_a_genuine_target_is_still_judged():
    q = [0.3, 0.2]
    T = _pose(q)
    sols = dn.analytic_ik(dn.load_robot(ROBOT), T).solutions
    assert _verdict(T.tolist(), [list(map(float, s)) for s in sols]).verdict == "correct"
    assert _verdict(T.tolist(), [[0.3, 0.9]]).verdict == "incorrect"
    # a pose written with four decimals is still a pose (its rotation is 1e-4 off orthonormal)
    assert _verdict(np.round(T, 4).tolist(), [q]).verdict != "unreadable"


def test_a_target_written_with_few_decimals_is_checked_for_completeness(tmp_path):
    """A pose rounded to 3 decimals is still a pose: an empty (or partial) solution list is judged against every
    closed-form solution of the pose it rounds, not called correct because analytic_ik refused the rounded matrix."""
    import numpy as np

    import denavit
    from denavit.check import check_claims

    robot = denavit.load_robot("puma560")
    T = np.round(denavit.forward_kinematics(robot, np.array([0.3, -0.4, 0.2, 0.5, 0.6, -0.7])), 3)
    target = [[float(x) for x in row] for row in T]
    empty = check_claims(robot, [{"quantity": "ik_solutions", "T": target, "value": []}]).verdicts[0]
    assert empty.verdict == "incorrect" and "missing" in empty.message
    sols = denavit.analytic_ik(robot, denavit.forward_kinematics(robot, np.array([0.3, -0.4, 0.2, 0.5, 0.6, -0.7])))
    one = [[round(float(x), 3) for x in sols.solutions[0]]]
    partial = check_claims(robot, [{"quantity": "ik_solutions", "T": target, "value": one}]).verdicts[0]
    assert partial.verdict == "incorrect" and "missing" in partial.message
