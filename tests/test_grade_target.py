"""An IK target stated in words and the joint values a report gives for it (grade._target → ik_solutions).

The truth is the planar 3R arm's closed form written here (Spong et al. Sec. 3.3 / Craig Sec. 4.x: the wrist point
x_w = x − L3 cos φ, y_w = y − L3 sin φ, cos θ2 = (x_w² + y_w² − L1² − L2²)/(2 L1 L2), θ1 = atan2(y_w, x_w) −
atan2(L2 s2, L1 + L2 c2), θ3 = φ − θ1 − θ2), never denavit's solver.
"""

from __future__ import annotations

import math

import pytest

from denavit.check import check_claims
from denavit.grade import grade_text
from denavit.io import load_robot

L1, L2, L3 = 1.0, 0.8, 0.5
X, Y, PHI = 1.2, 0.9, 60.0
TABLE = f"""| i | $a_i$ | $\\alpha_i$ | $d_i$ | $\\theta_i$ |
|---|---|---|---|---|
| 1 | $L_1 = {L1}$ | 0 | 0 | $\\theta_1$ |
| 2 | $L_2 = {L2}$ | 0 | 0 | $\\theta_2$ |
| 3 | $L_3 = {L3}$ | 0 | 0 | $\\theta_3$ |
"""


def _solutions() -> list[tuple[float, float, float]]:
    phi = math.radians(PHI)
    xw, yw = X - L3 * math.cos(phi), Y - L3 * math.sin(phi)
    c2 = (xw ** 2 + yw ** 2 - L1 ** 2 - L2 ** 2) / (2 * L1 * L2)
    out = []
    for sign in (1, -1):
        t2 = math.atan2(sign * math.sqrt(1 - c2 * c2), c2)
        t1 = math.atan2(yw, xw) - math.atan2(L2 * math.sin(t2), L1 + L2 * math.cos(t2))
        out.append(tuple(math.degrees(v) for v in (t1, t2, phi - t1 - t2)))
    return out


def _report(values: str, words: str = "The tool must reach") -> str:
    return (f"# Inverse kinematics\n\n{TABLE}\n{words} $x = {X}$, $y = {Y}$ with orientation $\\phi = {PHI:g}^\\circ$.\n\n"
            f"Numerically: {values} (elbow down).\n")


def _values(q, fmt="{:.2f}") -> str:
    return ", ".join(f"$\\theta_{k} = {fmt.format(v)}^\\circ$" for k, v in enumerate(q, start=1))


@pytest.mark.parametrize("which, fmt", [(0, "{:.2f}"), (1, "{:.2f}"), (0, "{:.1f}"), (1, "{:.0f}")])
def test_joint_values_that_reach_the_target_are_correct_and_the_other_solution_is_named(which, fmt):
    sols = _solutions()
    claims = grade_text(_report(_values(sols[which], fmt))).claims
    (c,) = [c for c in claims if c.quantity == "ik_solutions"]
    assert c.verdict == "correct", c.message
    other = sols[1 - which]
    assert f"{other[1]:.6g}" in c.message  # the other branch's θ2, in degrees as the report wrote them
    assert not [c for c in claims if c.quantity == "position"]  # x = 1.2 … are the target, not claims


def test_joint_values_that_miss_are_incorrect_with_the_solutions():
    sols = _solutions()
    wrong = (sols[0][0] + 3.0, sols[0][1], sols[0][2])
    (c,) = [c for c in grade_text(_report(_values(wrong))).claims if c.quantity == "ik_solutions"]
    assert c.verdict == "incorrect" and "does not reach" in c.message
    assert all(f"{s[1]:.6g}" in c.message for s in sols)


def test_without_words_of_a_target_the_numbers_are_no_target():
    text = _report(_values(_solutions()[0]), words="We note").replace("# Inverse kinematics", "# Exercise 3")
    claims = grade_text(text).claims  # (under a heading about inverse kinematics the numbers would be its target)
    assert not [c for c in claims if c.quantity == "ik_solutions"]


def test_a_partial_list_of_solutions_is_correct_only_when_said_so():
    """The checker's own claim: one of the two solutions, with complete: false (correct) and without (missing)."""
    robot = load_robot("planar3r")
    q = (0.3, 1.1, -0.4)
    one = [{"quantity": "ik_solutions", "q": ", ".join(map(str, q)), "value": [list(q)], "complete": False},
           {"quantity": "ik_solutions", "q": ", ".join(map(str, q)), "value": [list(q)]}]
    first, second = check_claims(robot, one).verdicts
    assert first.verdict == "correct" and "the others" in first.message
    assert second.verdict == "incorrect" and "missing" in second.message


def test_the_heading_formula_of_a_planar_arm_is_judged_and_phi_elsewhere_is_not():
    """θ3 = φ − θ1 − θ2 (the planar arm's heading, the closed form above) is an IK formula; on a spatial arm φ
    names no target entry the reader may assume (an Euler angle?), so the equation stays no claim."""
    text = f"# IK\n\n{TABLE}\n$$\\theta_3 = \\phi - \\theta_1 - \\theta_2$$\n\n$$\\theta_3 = \\phi + \\theta_1 - \\theta_2$$\n"
    assert [c.verdict for c in grade_text(text).claims] == ["correct", "incorrect"]
    rrp = TABLE.replace("| 0 | 0 | $\\theta_2$ |", "| $90^\\circ$ | 0 | $\\theta_2$ |")
    text = f"# IK\n\n{rrp}\n$$\\theta_3 = \\phi - \\theta_1 - \\theta_2$$\n"
    assert [c.verdict for c in grade_text(text).claims] == ["not a claim"]


def test_manipulability_written_out_is_judged_with_the_rows_its_j_names():
    """w = √det(J_v J_vᵀ) of the elbow RRR arm = |det J_v| = a2 a3 |s3| |a2 c2 + a3 c23| (Spong et al. Sec. 4.10,
    det J_v = a2 a3 s3 (a2 c2 + a3 c23) up to sign); without the second bars the sign changes with q: wrong, hinted."""
    table = """| i | $a_i$ | $\\alpha_i$ | $d_i$ | $\\theta_i$ |
|---|---|---|---|---|
| 1 | 0 | $90^\\circ$ | $d_1$ | $\\theta_1$ |
| 2 | $a_2$ | 0 | 0 | $\\theta_2$ |
| 3 | $a_3$ | 0 | 0 | $\\theta_3$ |
"""
    good = "$$w = \\sqrt{\\det(J_v J_v^T)} = a_2 a_3 |s_3| |a_2 c_2 + a_3 c_{23}|$$"
    bad = "$$w = \\sqrt{\\det(J_v J_v^T)} = a_2 a_3 |s_3| (a_2 c_2 + a_3 c_{23})$$"
    ok, wrong = grade_text(f"# Elbow\n\n{table}\n{good}\n\n{bad}\n").claims
    assert (ok.verdict, wrong.verdict) == ("correct", "incorrect") and ok.quantity == "manipulability"
    assert "absolute value" in str(wrong.details.get("hints"))


def test_the_checkers_manipulability_of_the_planar_two_link_arm():
    """w = L1 L2 |sin θ2| for the (x, y) rows of the planar 2R arm (Yoshikawa's textbook example)."""
    robot = load_robot("planar2r")
    claims = [{"quantity": "manipulability", "rows": "vx,vy", "value": "L_1 L_2 |\\sin\\theta_2|"},
              {"quantity": "manipulability", "rows": "vx,vy", "value": "L_1 L_2 \\sin\\theta_2"}]
    assert [v.verdict for v in check_claims(robot, claims).verdicts] == ["correct", "incorrect"]


def test_a_case_or_a_heading_after_the_target_ends_it():
    """Joint values of a later case (forward kinematics at a configuration) are no IK answer."""
    sols = _solutions()
    after = [f"Case 2: {_values(sols[0])}.", f"## Forward kinematics\n\n{_values(sols[0])}"]
    for tail in after:
        text = _report(_values(sols[0])) + "\n" + tail + "\n"
        judged = [c for c in grade_text(text).claims if c.quantity == "ik_solutions"]
        assert len(judged) == 1 and judged[0].verdict == "correct"


# A 6R arm with a spherical wrist (standard DH), its target a 4×4 written with 4 decimals: the pose is an independent
# DH product here (numpy), never denavit's forward kinematics.
WRIST_ROWS = [(0.4, 0.0, -90.0), (0.0, 0.5, 0.0), (0.0, 0.0, -90.0), (0.45, 0.0, 90.0), (0.0, 0.0, -90.0),
              (0.1, 0.0, 0.0)]
WRIST_TABLE = "| i | $\\theta_i$ | $d_i$ | $a_i$ | $\\alpha_i$ |\n|---|---|---|---|---|\n" + "".join(
    f"| {k} | $q_{k}$ | {d:g} | {a:g} | {al:g}° |\n" for k, (d, a, al) in enumerate(WRIST_ROWS, start=1))
Q_TRUE = (0.3, -0.5, 0.4, 0.7, -0.6, 1.1)


def _pose(q):
    import numpy as np

    T = np.eye(4)
    for th, (d, a, al) in zip(q, WRIST_ROWS):
        ct, st, ca, sa = np.cos(th), np.sin(th), np.cos(np.radians(al)), np.sin(np.radians(al))
        T = T @ np.array([[ct, -st * ca, st * sa, a * ct], [st, ct * ca, -ct * sa, a * st], [0, sa, ca, d],
                          [0, 0, 0, 1]])
    return T


def _pose_report(words: str, q) -> str:
    rows = " \\\\ ".join(" & ".join(f"{v:.4f}" for v in r) for r in _pose(Q_TRUE)[:3]) + " \\\\ 0 & 0 & 0 & 1"
    return (f"# IK\n\n{WRIST_TABLE}\n{words}\n\n$$T_6^0 = \\begin{{bmatrix}} {rows} \\end{{bmatrix}}$$\n\n"
            f"One solution is\n\n$$q = ({', '.join(f'{v:.4f}' for v in q)})$$\n")


def test_a_target_pose_written_as_a_matrix_and_the_joint_values_that_reach_it():
    """"The desired pose is T_6^0 = [4×4 of numbers]": the target; the q given after it is judged by FK against the
    target to both their decimals (the other solutions named, none required)."""
    report = grade_text(_pose_report("Find the joints for the desired pose of the tool:", Q_TRUE))
    (c,) = [c for c in report.claims if c.quantity == "ik_solutions"]
    assert c.verdict == "correct", c.message
    assert [c.verdict for c in report.claims if c.quantity == "given: target"] == ["not a claim"]
    wrong = list(Q_TRUE)
    wrong[1] += 0.05
    (c,) = [c for c in grade_text(_pose_report("The desired pose:", wrong)).claims if c.quantity == "ik_solutions"]
    assert c.verdict == "incorrect" and "does not reach" in c.message


def test_a_numeric_pose_without_words_of_a_target_is_no_target():
    """Without words of a target the matrix is a numeric end-effector result (no case given: ambiguous) and the q
    after it a case, not an answer."""
    report = grade_text(_pose_report("The pose of the tool is", Q_TRUE))
    assert not [c for c in report.claims if c.quantity == "ik_solutions"]
    assert [c.verdict for c in report.claims if c.quantity == "end_effector"] == ["ambiguous"]


def test_coordinates_stated_under_an_inverse_kinematics_heading_are_the_target():
    """"With x = 0.3 m and y = −0.4 m, d_2 = 0.5 m and θ_1 = 36.87°" under "Inverse kinematics", for the polar RP arm
    (tip (d2 sin θ1, −d2 cos θ1), so atan2(0.3, 0.4) = 36.87°): the coordinates are the target, the joint values a
    solution (judged against the tip's position; this arm has no closed form); elsewhere they are no target."""
    table = ("| Link | $a_i$ | $\\alpha_i$ | $d_i$ | $\\theta_i$ |\n|---|---|---|---|---|\n"
             "| 1 | 0 | $90^\\circ$ | 0 | $\\theta_1$ |\n| 2 | 0 | 0 | $d_2$ | 0 |\n")
    assert abs(math.degrees(math.atan2(0.3, 0.4)) - 36.87) < 0.005

    def report(heading: str, angle: str) -> str:
        return (f"# RP arm\n\n## 1. DH table\n\n{table}\n## 2. {heading}\n\nWith $x = 0.3$ m and $y = -0.4$ m, "
                f"$d_2 = 0.5$ m and $\\theta_1 = {angle}^\\circ$.\n")
    verdicts = [[c.verdict for c in grade_text(report(h, a)).claims if c.quantity == "ik_solutions"]
                for h, a in (("Inverse kinematics", "36.87"), ("Inverse kinematics", "30"), ("A case", "36.87"))]
    assert verdicts == [["correct"], ["incorrect"], []]


def test_the_heading_stated_as_a_result_stays_the_targets_in_ik_and_a_cosine_step_is_its_value():
    """``\\phi = \\theta_1 + \\theta_2 + \\theta_3`` (forward kinematics) must not make φ a name for the joints in
    the IK after it (θ₃ = φ − θ₁ − θ₂ was "uses q3 itself"); ``\\cos\\theta_2 = …`` is an IK step and the
    ``\\theta_2 = atan2(±√(1 − \\cos^2\\theta_2), \\cos\\theta_2)`` after it uses that value (the closed form above)."""
    steps = ["\\phi = \\theta_1 + \\theta_2 + \\theta_3", "x_w = x - L_3 \\cos\\phi", "y_w = y - L_3 \\sin\\phi",
             "\\cos\\theta_2 = \\frac{x_w^2 + y_w^2 - L_1^2 - L_2^2}{2 L_1 L_2}",
             "\\theta_2 = \\operatorname{atan2}(\\pm\\sqrt{1 - \\cos^2\\theta_2}, \\cos\\theta_2)",
             "\\theta_3 = \\phi - \\theta_1 - \\theta_2"]
    text = f"# IK\n\n{TABLE}\n" + "\n\n".join(f"$${s}$$" for s in steps) + "\n"
    got = [c.verdict for c in grade_text(text).claims if c.quantity == "ik_formula"]
    assert got == ["correct"] * 3, got


def test_a_squared_name_defined_is_its_root_in_the_ik_after_it():
    """Spong's elbow arm (Sec. 5.3): ``r^2 = x^2 + y^2``, ``s = z - d_1``, D = (r² + s² − a2² − a3²)/(2 a2 a3),
    θ3 = atan2(±√(1 − D²), D), θ2 = atan2(s, r) − atan2(a3 s3, a2 + a3 c3) — r is √(x² + y²) (was "unknown
    symbol r"); the formulas checked first with the arm's FK written by hand at random configurations."""
    import numpy as np

    a2, a3, d1 = 0.6, 0.45, 0.3
    for q in np.random.default_rng(5).uniform([-3, 0.1, 0.2], [3, 0.8, 1.2], (20, 3)):  # a2 c2 + a3 c23 > 0
        w = a2 * np.cos(q[1]) + a3 * np.cos(q[1] + q[2])
        x, y, z = np.cos(q[0]) * w, np.sin(q[0]) * w, d1 + a2 * np.sin(q[1]) + a3 * np.sin(q[1] + q[2])
        r, s = np.hypot(x, y), z - d1
        D = (r * r + s * s - a2 ** 2 - a3 ** 2) / (2 * a2 * a3)
        assert np.isclose(np.arctan2(np.sqrt(1 - D * D), D), q[2])
        assert np.isclose(np.arctan2(s, r) - np.arctan2(a3 * np.sin(q[2]), a2 + a3 * np.cos(q[2])), q[1])
    table = ("| Link | $a_i$ | $\\alpha_i$ | $d_i$ | $\\theta_i$ |\n|---|---|---|---|---|\n"
             "| 1 | 0 | $90^\\circ$ | $d_1$ | $\\theta_1$ |\n| 2 | $a_2$ | 0 | 0 | $\\theta_2$ |\n"
             "| 3 | $a_3$ | 0 | 0 | $\\theta_3$ |\n")
    steps = ["r^2 = x^2 + y^2", "s = z - d_1", "D = \\frac{r^2 + s^2 - a_2^2 - a_3^2}{2 a_2 a_3}",
             "\\theta_3 = \\operatorname{atan2}\\left(\\pm\\sqrt{1 - D^2}, D\\right)",
             "\\theta_2 = \\operatorname{atan2}(s, r) - \\operatorname{atan2}(a_3 s_3, a_2 + a_3 c_3)",
             "\\theta_2 = \\operatorname{atan2}(s, r) + \\operatorname{atan2}(a_3 s_3, a_2 + a_3 c_3)"]
    text = "# Elbow\n\n" + table + "\n" + "\n\n".join(f"$${e}$$" for e in steps) + "\n"
    got = [c.verdict for c in grade_text(text).claims if c.quantity == "ik_formula"]
    assert got == ["correct", "correct", "incorrect"], got
