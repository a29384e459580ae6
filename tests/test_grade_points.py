"""A report that names the wrist centre's coordinates P_x, P_y, P_z has its IK formulas in P read with the wrist
centre (seed report 003: ``T_4^0(1:3,4) = [⋯] = [P_x; P_y; P_z]``, then ``q_1 = atan2(P_y, P_x)``), and a sum of
squares that lost its '+' gets a hint saying where.

The arm is a 6R with a spherical wrist in standard DH (Spong's decoupling, Sec. 5.3); the formulas the tests call
right are verified here first with an independent DH product (numpy), never with denavit.
"""

from __future__ import annotations

import numpy as np
import pytest

from denavit.grade import grade_text
from denavit.grade._values import missing_plus

D1, A2, D4, D6 = 0.4, 0.5, 0.45, 0.1
ROWS = [(D1, 0.0, -np.pi / 2), (0.0, A2, 0.0), (0.0, 0.0, -np.pi / 2), (D4, 0.0, np.pi / 2), (0.0, 0.0, -np.pi / 2),
        (D6, 0.0, 0.0)]
TABLE = """| i | $\\theta_i$ | $d_i$ | $a_i$ | $\\alpha_i$ |
|---|---|---|---|---|
| 1 | $q_1$ | 0.4 | 0 | -90° |
| 2 | $q_2$ | 0 | 0.5 | 0 |
| 3 | $q_3$ | 0 | 0 | -90° |
| 4 | $q_4$ | 0.45 | 0 | 90° |
| 5 | $q_5$ | 0 | 0 | -90° |
| 6 | $q_6$ | 0.1 | 0 | 0 |
"""
Q1 = "q_1 = \\operatorname{atan2}(P_y, P_x)"
Q3 = "q_3 = \\arcsin\\left(\\frac{0.5^2 + 0.45^2 - P_x^2 - P_y^2 - (P_z - 0.4)^2}{2 \\cdot 0.5 \\cdot 0.45}\\right)"
Q3_SLIP = "q_3 = \\arcsin\\left(\\frac{0.5^2 + 0.45^2 - (P_x^2 + P_y^2 (P_z - 0.4)^2)}{2 \\cdot 0.5 \\cdot 0.45}\\right)"


def _frames(q):
    """World frames 0 … 6 by the standard DH product A_i = Rot_z(θ) Trans_z(d) Trans_x(a) Rot_x(α)."""
    out = [np.eye(4)]
    for th, (d, a, al) in zip(q, ROWS):
        ct, st, ca, sa = np.cos(th), np.sin(th), np.cos(al), np.sin(al)
        out.append(out[-1] @ np.array([[ct, -st * ca, st * sa, a * ct], [st, ct * ca, -ct * sa, a * st],
                                       [0, sa, ca, d], [0, 0, 0, 1]]))
    return out


def test_the_formulas_called_right_are_right():
    """Independent check of the truths below: frame 4's origin is the wrist centre, q1 = atan2(P_y, P_x) up to the
    other shoulder (q1 + π), sin q3 = (a2² + d4² − |P − d1 z|²) / (2 a2 d4)."""
    for q in np.random.default_rng(1).uniform(-np.pi, np.pi, (20, 6)):
        F = _frames(q)
        P = F[4][:3, 3]
        assert np.allclose(P, F[6][:3, 3] - D6 * F[6][:3, 2])
        dq1 = np.arctan2(P[1], P[0]) - q[0]
        assert min(abs(np.angle(np.exp(1j * dq1))), abs(np.angle(np.exp(1j * (dq1 - np.pi))))) < 1e-9
        assert np.isclose((A2 ** 2 + D4 ** 2 - P[0] ** 2 - P[1] ** 2 - (P[2] - D1) ** 2) / (2 * A2 * D4), np.sin(q[2]))


def _matrix(entries) -> str:
    return "\\begin{bmatrix} " + " \\\\ ".join(entries) + " \\end{bmatrix}"


def _report(named_frame: int | None, *formulas: str) -> str:
    head = "# IK of a 6R arm\n\n## 1. DH table\n\n" + TABLE + "\n## 2. Position problem\n\n"
    if named_frame is not None:  # the origin's value written as entries a student would (not judged here)
        head += (f"$$T_{named_frame}^0(1:3,4) = {_matrix(['x_c', 'y_c', 'z_c'])} = "
                 f"{_matrix(['P_x', 'P_y', 'P_z'])}$$\n\n")
    return head + "\n\n".join(f"$${f}$$" for f in formulas) + "\n"


def _ik(report) -> list[tuple[str, str]]:
    return [(c.verdict, c.message) for c in report.claims if c.quantity == "ik_formula"]


def test_p_named_as_the_wrist_centre_makes_ik_formulas_in_p_judged_with_it():
    before = _ik(grade_text(_report(None, Q1, Q3), "md"))
    assert [v for v, _ in before] == ["ambiguous", "ambiguous"], before  # P alone: the flange or the wrist centre?
    after = _ik(grade_text(_report(4, Q1, Q3), "md"))
    assert [v for v, _ in after] == ["correct", "correct"], after


def test_p_named_as_another_point_changes_nothing():
    """Frame 3's origin is the elbow, not the wrist centre: P stays a question."""
    got = _ik(grade_text(_report(3, Q1, Q3), "md"))
    assert [v for v, _ in got] == ["ambiguous", "ambiguous"], got


def test_a_sum_of_squares_that_lost_its_plus_is_incorrect_with_a_hint_where():
    got = _ik(grade_text(_report(4, Q3_SLIP), "md"))
    assert len(got) == 1 and got[0][0] == "incorrect", got
    assert "with a '+' between P_y^2 and (P_z - 0.4)^2 it is correct" in got[0][1]


@pytest.mark.parametrize("text, count", [
    ("a^2 b^2", 0),  # no bracket after the square
    ("k^2 (c_1 + c_2)", 0),  # a bracket that is not squared: a product, not a lost '+'
    ("x^2 (y)^2", 1), ("x^{2} \\left( y + z \\right)^{2}", 1), ("x^2 [y]^2 + u^2 (v)^2", 2),
])
def test_missing_plus_only_between_a_square_and_a_squared_bracket(text, count):
    out = missing_plus(text)
    assert len(out) == count
    for variant, where in out:
        assert variant.count("+") == text.count("+") + 1 and where.startswith("between ")
