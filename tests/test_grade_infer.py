"""Arms recognised from a section's own results: a report whose tables were pictures, or a section about another
arm than the report's table (seed report 000's "Equation of Motion for 3DOF Manipulator" after a 6-joint table).

The section's results are derived here independently (SymPy: centre-of-mass positions written by hand, the
Lagrangian's Hessian for M, ∂P/∂q for g), never by denavit; the slips are made on purpose.
"""

from __future__ import annotations

import pytest
import sympy as sp

from denavit.grade import grade_text

pytestmark = pytest.mark.slow  # each report judges its section against every 3-joint catalogue arm

th = sp.symbols("theta_1:4")
L1, L2 = sp.symbols("L_1 L_2")
Lc = sp.symbols("Lc_1:4")
m = sp.symbols("m_1:4")
Iz = sp.symbols("I_1:4")
g0 = sp.Symbol("g")


def _truth():
    """p_ci, M(θ) and g(θ) of a planar 3R arm with lumped links (centre of link i at Lc_i along it, inertia I_i
    about it), gravity g along −y: Spong, Sec. 7.4, derived here from K and P."""
    qd = sp.symbols("qd1:4")
    ang = [th[0], th[0] + th[1], th[0] + th[1] + th[2]]
    lengths = [L1, L2]
    pc = []
    for i in range(3):
        x = sum(lengths[k] * sp.cos(ang[k]) for k in range(i)) + Lc[i] * sp.cos(ang[i])
        y = sum(lengths[k] * sp.sin(ang[k]) for k in range(i)) + Lc[i] * sp.sin(ang[i])
        pc.append(sp.Matrix([x, y, 0]))
    K = 0
    for i in range(3):
        v = pc[i].jacobian(th) * sp.Matrix(qd)
        w = sum(qd[: i + 1])
        K += m[i] * (v.T * v)[0] / 2 + Iz[i] * w ** 2 / 2
    P = sum(m[i] * g0 * pc[i][1] for i in range(3))
    M = sp.hessian(K, qd).applyfunc(sp.simplify)
    G = sp.Matrix([sp.diff(P, q) for q in th]).applyfunc(sp.simplify)
    return pc, M, G


def _section(title: str, slip: bool = True) -> str:
    pc, M, G = _truth()
    if slip:
        G = G.copy()
        G[1] = -G[1]  # a sign slip in the second gravity torque
    tex = sp.latex
    parts = [f"## {title}", "", "The centre of mass of each link:", ""]
    parts += [f"$$p_{{c{i + 1}}} = {tex(pc[i])}$$\n" for i in range(3)]
    parts += ["From the kinetic energy, the inertia matrix", "", f"$$M(\\theta) = {tex(M)}$$", "",
              "and from the potential energy (gravity g along -y) the gravity torques", "",
              f"$$g(\\theta) = {tex(G)}$$", ""]
    return "\n".join(parts)


TABLE = """# Homework 5

## 1. Two-link arm

| Link | $a_i$ | $\\alpha_i$ | $d_i$ | $\\theta_i$ |
|------|-------|------------|-------|------------|
| 1    | $L_1$ | 0          | 0     | $\\theta_1$ |
| 2    | $L_2$ | 0          | 0     | $\\theta_2$ |

$$T_2^0 = \\begin{bmatrix} c_{12} & -s_{12} & 0 & L_1 c_1 + L_2 c_{12} \\\\ s_{12} & c_{12} & 0 & L_1 s_1 + L_2 s_{12} \\\\ 0 & 0 & 1 & 0 \\\\ 0 & 0 & 0 & 1 \\end{bmatrix}$$

"""


def _verdicts(report, first_line: int) -> dict[str, list[str]]:
    out: dict[str, list[str]] = {}
    for c in report.claims:
        if c.line >= first_line and c.verdict != "not a claim":
            out.setdefault(c.quantity, []).append(c.verdict)
    return out


def _line_of(text: str, needle: str) -> int:
    return next(k for k, s in enumerate(text.splitlines(), 1) if needle in s)


def test_a_section_about_another_arm_is_judged_against_the_arm_its_results_fit():
    text = TABLE + _section("2. Equations of motion of a 3-DOF planar manipulator")
    report = grade_text(text, "md")
    start = _line_of(text, "## 2.")
    arm = [a for a in report.arms if a.line == start]
    assert arm and arm[0].name == "planar3r-lagrange", report.arms
    assert "results fit" in arm[0].source
    assert any("fit the catalogue arm planar3r-lagrange" in n for n in report.notes)
    got = _verdicts(report, start)
    assert got.get("com_position") == ["correct"] * 3, got
    assert got.get("mass_matrix") == ["correct"], got
    assert got.get("gravity") == ["incorrect"], got  # the sign slip is caught, not explained away
    first = [c for c in report.claims if c.line < start and c.verdict != "not a claim"]
    assert first and all(c.arm.startswith("table-line") for c in first)  # the table still governs section 1


def test_a_section_no_arm_fits_keeps_no_arm_and_its_advice():
    """Results no catalogue arm explains (x and y swapped in every centre of mass): nothing is recognised, the
    section is not judged, and the advice to give an arm stays."""
    pc, _, _ = _truth()
    body = "\n".join(f"$$p_{{c{i + 1}}} = {sp.latex(sp.Matrix([p[1], p[0], 0]))}$$\n" for i, p in enumerate(pc))
    text = TABLE + "## 2. Dynamics of a 3-DOF planar manipulator\n\n" + body
    report = grade_text(text, "md")
    start = _line_of(text, "## 2.")
    assert not any(a.line == start for a in report.arms), report.arms
    assert any("3-joint arm and has no DH table" in n for n in report.notes), report.notes
    assert set(_verdicts(report, start).get("com_position", [])) <= {"unreadable"}


def test_an_arm_given_for_the_section_wins_over_recognition():
    text = TABLE + _section("2. Equations of motion of a 3-DOF planar manipulator")
    from denavit.io import load_robot

    report = grade_text(text, "md", arms={"2": load_robot("planar3r")})
    start = _line_of(text, "## 2.")
    arm = [a for a in report.arms if a.line == start]
    assert arm and arm[0].name == "planar3r" and arm[0].source == "--arm 2=planar3r"
    assert not any("fit the catalogue arm" in n for n in report.notes)


def test_a_report_without_tables_has_its_sections_recognised():
    text = "# Homework 6\n\n" + _section("1. Planar 3R arm: dynamics", slip=False)
    report = grade_text(text, "md")
    assert [a.name for a in report.arms] == ["planar3r-lagrange"], report.arms
    got = _verdicts(report, 1)
    assert got.get("com_position") == ["correct"] * 3 and got.get("gravity") == ["correct"], got
