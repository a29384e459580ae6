"""Names a derivation defines for itself (grade._shorthand): an IK intermediate ``c_2 = (x² + y² − a₁² − a₂²)/(2a₁a₂)``,
a signed shorthand ``c_{124} = \\cos(\\theta_1 + \\theta_2 - \\theta_4)`` (defined after the matrix that uses it),
``c_{12-4}`` written directly, and a prismatic joint's IK formula ``d_3 = d_1 - d_4 - z``.

The arm is Spong's SCARA (Example 3.3.3, standard DH: a₁, a₂, d₁ fixed, α₂ = π, d₃ sliding, d₄ fixed); every formula
called right here is first verified with an independent DH product (numpy), never with denavit.
"""

from __future__ import annotations

import numpy as np
import pytest

from denavit.grade import grade_text
from denavit.grade._shorthand import renamed

A1, A2, D1, D4 = 0.35, 0.3, 0.4, 0.05
TABLE = """\\begin{tabular}{|c|c|c|c|c|}
Link & $a_i$ & $\\alpha_i$ & $d_i$ & $\\theta_i$ \\\\
1 & $a_1$ & 0 & $d_1$ & $\\theta_1$ \\\\
2 & $a_2$ & $180^\\circ$ & 0 & $\\theta_2$ \\\\
3 & 0 & 0 & $d_3$ & 0 \\\\
4 & 0 & 0 & $d_4$ & $\\theta_4$ \\\\
\\end{tabular}
"""
R_SIGNED = "\\begin{bmatrix} c_{12-4} & s_{12-4} & 0 \\\\ s_{12-4} & -c_{12-4} & 0 \\\\ 0 & 0 & -1 \\end{bmatrix}"
C2 = "c_2 = \\frac{x^2 + y^2 - a_1^2 - a_2^2}{2 a_1 a_2}"
Q2 = "\\theta_2 = \\operatorname{atan2}(\\pm\\sqrt{1 - c_2^2}, c_2)"
Q1 = "\\theta_1 = \\operatorname{atan2}(y, x) - \\operatorname{atan2}(a_2 s_2, a_1 + a_2 c_2)"
D3 = "d_3 = d_1 - d_4 - z"


def _fk(q):
    """T_0^4 of the SCARA by the standard DH product."""
    rows = [(q[0], D1, A1, 0.0), (q[1], 0.0, A2, np.pi), (0.0, q[2], 0.0, 0.0), (q[3], D4, 0.0, 0.0)]
    T = np.eye(4)
    for th, d, a, al in rows:
        ct, st, ca, sa = np.cos(th), np.sin(th), np.cos(al), np.sin(al)
        T = T @ np.array([[ct, -st * ca, st * sa, a * ct], [st, ct * ca, -ct * sa, a * st], [0, sa, ca, d],
                          [0, 0, 0, 1]])
    return T


def test_the_formulas_called_right_are_right():
    for q in np.random.default_rng(2).uniform([-2, -2, 0, -3], [2, 2, 0.3, 3], (25, 4)):
        T = _fk(q)
        t = q[0] + q[1] - q[3]
        assert np.allclose(T[:3, :3], [[np.cos(t), np.sin(t), 0], [np.sin(t), -np.cos(t), 0], [0, 0, -1]])
        x, y, z = T[:3, 3]
        c2 = (x * x + y * y - A1 ** 2 - A2 ** 2) / (2 * A1 * A2)
        t2 = [np.arctan2(s * np.sqrt(max(1 - c2 * c2, 0)), c2) for s in (1, -1)]
        assert min(abs(np.angle(np.exp(1j * (v - q[1])))) for v in t2) < 1e-6
        t1 = np.arctan2(y, x) - np.arctan2(A2 * np.sin(q[1]), A1 + A2 * np.cos(q[1]))
        assert abs(np.angle(np.exp(1j * (t1 - q[0])))) < 1e-9
        assert np.isclose(D1 - D4 - z, q[2])


def _report(*equations: str, where: str = "") -> str:
    body = "\n".join(f"\\begin{{equation}}\n{e}\n\\end{{equation}}" for e in equations)
    return ("\\section{The SCARA}\n" + TABLE + "\n" + body + "\n" + where + "\n")


def _verdicts(text: str) -> list[tuple[str, str]]:
    return [(c.quantity, c.verdict) for c in grade_text(text, "tex").claims if c.verdict != "not a claim"]


def test_an_ik_intermediate_named_like_a_cosine_is_the_formula_it_is_given():
    """``c_2 = (x² + y² − …)/…`` then ``θ_2 = atan2(±√(1 − c_2²), c_2)`` (Spong's two-link IK): correct, not "uses q2
    itself"; the slide d_3 = d_1 − d_4 − z is an IK formula too."""
    assert _verdicts(_report(C2, Q2, Q1, D3)) == [("ik_formula", "correct")] * 3
    assert _verdicts(_report(C2, Q2.replace("1 - c_2^2", "1 + c_2^2"), "d_3 = d_1 + d_4 - z")) == [
        ("ik_formula", "incorrect")] * 2


@pytest.mark.parametrize("written, where, verdict", [
    (R_SIGNED, "", "correct"),
    (R_SIGNED.replace("12-4", "124"), "where $c_{124} = \\cos(\\theta_1 + \\theta_2 - \\theta_4)$ and "
     "$s_{124} = \\sin(\\theta_1 + \\theta_2 - \\theta_4)$.", "correct"),
    (R_SIGNED.replace("12-4", "124"), "", "incorrect"),  # c_124 without a definition: cos(θ1 + θ2 + θ4), wrong
    (R_SIGNED.replace("-c_{12-4}", "c_{12-4}"), "", "incorrect"),
])
def test_a_signed_shorthand_written_or_defined_after_the_matrix(written, where, verdict):
    got = _verdicts(_report(f"R_4^0 = {written}", where=where))
    assert got == [("end_effector", verdict)], got


def test_renamed_touches_only_the_shorthand_named():
    assert renamed("c_{124} + s_124 + c_{1245} + C_{124}", {"124": "12-4"}) == \
        "c_{12-4} + s_{12-4} + c_{1245} + C_{12-4}"


def test_the_heading_of_a_scara_is_judged_with_its_tool_z_down():
    """φ = θ1 + θ2 − θ4 is the SCARA's heading (R = [c s 0; s −c 0; 0 0 −1] with c = cos(θ1 + θ2 − θ4), checked
    above); θ1 + θ2 + θ4 is not."""
    got = [_verdicts(_report(f"\\phi = {v}")) for v in ("\\theta_1 + \\theta_2 - \\theta_4",
                                                         "\\theta_1 + \\theta_2 + \\theta_4")]
    assert got == [[("heading", "correct")], [("heading", "incorrect")]], got
