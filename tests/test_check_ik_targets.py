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
    closed-form solution of the pose it rounds, not called correct because analytic_ik refused the rounded matrix;
    the one solution within the limits of another pose, written to 3 decimals, is all of them (correct: its
    rounding and the target's are allowed for, each solution standing for the nearest one only)."""
    import numpy as np

    import denavit
    from denavit.check import check_claims

    robot = denavit.load_robot("puma560")
    for q, count in (([0.1, 1.0, -0.6, 0.3, 0.8, 0.2], 6), ([0.3, -0.4, 0.2, 0.5, 0.6, -0.7], 1)):
        exact = denavit.forward_kinematics(robot, np.array(q))
        target = [[float(x) for x in row] for row in np.round(exact, 3)]
        sols = np.asarray(denavit.analytic_ik(robot, exact).solutions).reshape(-1, 6)
        assert len(sols) == count and all(np.allclose(denavit.forward_kinematics(robot, s), exact) for s in sols)
        empty = check_claims(robot, [{"quantity": "ik_solutions", "T": target, "value": []}]).verdicts[0]
        assert empty.verdict == "incorrect" and "missing" in empty.message
        one = [[round(float(x), 3) for x in sols[0]]]
        partial = check_claims(robot, [{"quantity": "ik_solutions", "T": target, "value": one}]).verdicts[0]
        if count > 1:
            assert partial.verdict == "incorrect" and partial.message.count("missing") == count - 1, partial.message
        else:
            assert partial.verdict == "correct", partial.message


def test_a_right_solution_of_a_target_written_rounded_is_correct():
    """A target written with 3 decimals (a textbook's or a student's): the exact joint values of the pose it rounds
    reach it to its decimals (correct), a joint 0.0123 rad off does not (incorrect); the full solution list of the
    exact pose, each verified by FK here, is complete for the rounded target."""
    robot = dn.load_robot("puma560")
    q = np.array([0.1, 1.0, -0.6, 0.3, 0.8, 0.2])
    exact = dn.forward_kinematics(robot, q)
    target = np.round(exact, 3).tolist()
    one = {"quantity": "ik_solutions", "T": target, "complete": False}
    assert check_claims(robot, [{**one, "value": [q.tolist()]}]).verdicts[0].verdict == "correct"
    off = q + np.array([0.0123, 0, 0, 0, 0, 0])  # written with 4 decimals: reaches to about 1e-4 rad
    assert check_claims(robot, [{**one, "value": [off.tolist()]}]).verdicts[0].verdict == "incorrect"
    sols = np.asarray(dn.analytic_ik(robot, exact).solutions).reshape(-1, 6)
    assert len(sols) >= 2 and all(np.allclose(dn.forward_kinematics(robot, s), exact, atol=1e-9) for s in sols)
    full = {"quantity": "ik_solutions", "T": target, "value": [[round(float(x), 4) for x in s] for s in sols]}
    v = check_claims(robot, [full]).verdicts[0]
    assert v.verdict == "correct", v.message


def _polar_rp():
    """The polar RP arm (Spong's): a revolute joint about z0, α1 = 90°, a prismatic joint along z1; no fixed length."""
    return dn.robot_from_dict({"name": "polar-rp", "convention": "standard", "joints": [
        {"alpha": "pi/2", "theta": "q"}, {"d": "q"}]})


def test_ik_formulas_of_an_arm_without_a_closed_form_are_checked_numerically():
    """No closed form for the 2-joint RP arm: its solutions come from Gauss–Newton on the tip's position. The tip is
    (d2 sin θ1, −d2 cos θ1, 0) (its DH product, multiplied out by hand), so d2 = √(x² + y²) and θ1 = atan2(x, −y) are
    right (one branch each; d2 < 0, θ1 + π is the other), atan2(y, x) and x² + y² are not."""
    robot = _polar_rp()
    q = np.array([0.4, 0.7])
    assert np.allclose(dn.forward_kinematics(robot, q)[:3, 3], [0.7 * np.sin(0.4), -0.7 * np.cos(0.4), 0])
    claims = [{"quantity": "ik_formula", "value": v} for v in (
        "d_2 = \\sqrt{x^2 + y^2}", "\\theta_1 = \\operatorname{atan2}(x, -y)",
        "\\theta_1 = \\operatorname{atan2}(y, x)", "d_2 = x^2 + y^2")]
    got = check_claims(robot, claims).verdicts
    assert [v.verdict for v in got] == ["correct", "correct", "incorrect", "incorrect"], [v.message for v in got]
    assert "Gauss-Newton on the tip's position" in got[0].method and "one branch" in got[0].message


def test_ik_solutions_of_an_arm_without_a_closed_form_are_complete_against_a_numeric_search():
    """The polar RP arm at the tip (0.3, −0.4, 0): (θ1, d2) = (atan2(0.3, 0.4), 0.5) and (that − π, −0.5), from the
    tip formula above; one alone is correct when said to be one (the other named), both are complete."""
    robot = _polar_rp()
    t1 = float(np.arctan2(0.3, 0.4))
    T = dn.forward_kinematics(robot, np.array([t1, 0.5]))
    assert np.allclose(T[:3, 3], [0.3, -0.4, 0.0])
    one = {"quantity": "ik_solutions", "T": T.tolist(), "value": [[t1, 0.5]]}
    both = {**one, "value": [[t1, 0.5], [t1 - np.pi, -0.5]]}
    got = check_claims(robot, [{**one, "complete": False}, one, both]).verdicts
    assert [v.verdict for v in got] == ["correct", "incorrect", "correct"], [v.message for v in got]
    assert "-0.5" in got[0].message and "missing" in got[1].message
