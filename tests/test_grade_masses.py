"""A report's own planar arm given the masses its dynamics section writes (grade._masses).

The truths are the textbook's, typed from the book: Spong, Hutchinson & Vidyasagar, *Robot Modeling and Control*,
Sec. 7.4 (the two-link planar arm, gravity along −y): d11 = m1 lc1² + m2 (l1² + lc2² + 2 l1 lc2 c2) + I1 + I2,
d12 = m2 (lc2² + l1 lc2 c2) + I2, d22 = m2 lc2² + I2, φ1 = (m1 lc1 + m2 l1) g c1 + m2 lc2 g c12,
φ2 = m2 lc2 g c12.  A second route: the same entries from sympy's Lagrange equations written here.
"""

from __future__ import annotations

import pytest

from denavit.grade import grade_text

STANDARD = """| i | $a_i$ | $\\alpha_i$ | $d_i$ | $\\theta_i$ |
|---|---|---|---|---|
| 1 | $\\ell_1$ | 0 | 0 | $q_1$ |
| 2 | $\\ell_2$ | 0 | 0 | $q_2$ |
"""
MODIFIED = """| i | $a_{i-1}$ | $\\alpha_{i-1}$ | $d_i$ | $\\theta_i$ |
|---|---|---|---|---|
| 1 | 0 | 0 | 0 | $q_1$ |
| 2 | $\\ell_1$ | 0 | 0 | $q_2$ |
"""
SPONG = {
    "M_{11}": "m_1 \\ell_{c1}^2 + m_2(\\ell_1^2 + \\ell_{c2}^2 + 2 \\ell_1 \\ell_{c2} \\cos q_2) + I_1 + I_2",
    "M_{12}": "m_2(\\ell_{c2}^2 + \\ell_1 \\ell_{c2} \\cos q_2) + I_2",
    "M_{22}": "m_2 \\ell_{c2}^2 + I_2",
    "g_1": "(m_1 \\ell_{c1} + m_2 \\ell_1) g \\cos q_1 + m_2 \\ell_{c2} g \\cos(q_1 + q_2)",
    "g_2": "m_2 \\ell_{c2} g \\cos(q_1 + q_2)",
}


def _judged(table: str, equations: list[str]) -> list[str]:
    text = "# Two-link arm\n\n" + table + "\n" + "\n\n".join(f"$${e}$$" for e in equations) + "\n"
    return [c.verdict for c in grade_text(text).claims]


@pytest.mark.parametrize("table", [STANDARD, MODIFIED])
def test_the_textbook_equations_of_the_two_link_arm_are_correct_and_a_slip_is_not(table):
    right = [f"{k} = {v}" for k, v in SPONG.items()]
    assert _judged(table, right) == ["correct"] * len(right)
    slips = [right[0].replace("2 \\ell_1", "\\ell_1"), right[2].replace("+ I_2", "+ 2 I_2"),
             right[4].replace("\\ell_{c2} g", "\\ell_{c1} g")]
    assert _judged(table, slips) == ["incorrect"] * 3


def test_the_entries_agree_with_lagrange_derived_here():
    """M and g from L = K − P of the lumped model (sympy, independent of denavit), written as the claims."""
    import sympy as sp

    q1, q2, l1, lc1, lc2, m1, m2, i1, i2, g = sp.symbols("q1 q2 ell1 ellc1 ellc2 m1 m2 I1 I2 g")
    qd = sp.symbols("qd1 qd2")
    p1 = sp.Matrix([lc1 * sp.cos(q1), lc1 * sp.sin(q1)])
    p2 = sp.Matrix([l1 * sp.cos(q1) + lc2 * sp.cos(q1 + q2), l1 * sp.sin(q1) + lc2 * sp.sin(q1 + q2)])
    v1, v2 = (p.jacobian([q1, q2]) * sp.Matrix(qd) for p in (p1, p2))
    K = (m1 * v1.dot(v1) + m2 * v2.dot(v2) + i1 * qd[0] ** 2 + i2 * (qd[0] + qd[1]) ** 2) / 2
    P = g * (m1 * p1[1] + m2 * p2[1])
    M = sp.hessian(K, qd)
    G = [sp.diff(P, q) for q in (q1, q2)]
    names = {"ellc1": "\\ell_{c1}", "ellc2": "\\ell_{c2}", "ell1": "\\ell_1", "m1": "m_1", "m2": "m_2",
             "I1": "I_1", "I2": "I_2", "q1": "q_1", "q2": "q_2"}

    def latex(e):
        return sp.latex(sp.expand(e), symbol_names={sp.Symbol(k): v for k, v in names.items()})
    claims = [f"M_{{11}} = {latex(M[0, 0])}", f"M_{{12}} = {latex(M[0, 1])}", f"M_{{22}} = {latex(M[1, 1])}",
              f"g_1 = {latex(G[0])}", f"g_2 = {latex(G[1])}"]
    assert _judged(STANDARD, claims) == ["correct"] * 5


def test_gravity_another_way_is_a_question_and_links_not_named_get_names():
    """Only link 2 named (m_2, ℓ_c2): link 1's symbols are made; g₂ with sin is right for gravity along −x."""
    assert _judged(STANDARD, ["g_2 = -m_2 \\ell_{c2} g \\sin(q_1 + q_2)"]) == ["ambiguous"]
    assert _judged(STANDARD, ["M_{22} = m_2 \\ell_{c2}^2 + I_2", "g_2 = m_2 \\ell_{c2} g \\sin(q_1 + q_2) + 1"]) \
        == ["correct", "incorrect"]


def test_lengths_stated_equal_carry_into_the_masses():
    eqs = ["\\ell_1 = \\ell_2 = \\ell", "M_{12} = m_2(\\ell_{c2}^2 + \\ell \\ell_{c2} \\cos q_2) + I_2"]
    assert _judged(STANDARD, eqs)[-1] == "correct"


def test_no_masses_for_a_spatial_arm_or_without_a_centre_of_mass():
    rrp = """| i | $a_i$ | $\\alpha_i$ | $d_i$ | $\\theta_i$ |
|---|---|---|---|---|
| 1 | 0 | $-90^\\circ$ | $d_1$ | $\\theta_1$ |
| 2 | 0 | $90^\\circ$ | $d_2$ | $\\theta_2$ |
| 3 | 0 | 0 | $d_3$ | 0 |
"""
    assert _judged(rrp, ["M_{33} = m_3"]) == ["unreadable"]
    assert _judged(STANDARD, ["M_{22} = m_2 \\ell_2^2"]) == ["unreadable"]  # no ℓ_c: where the mass sits is unsaid


def test_spongs_own_names_d_ij_and_phi_k():
    eqs = [f"d_{{11}} = {SPONG['M_{11}']}", f"d_{{12}} = {SPONG['M_{12}']}", f"\\phi_2 = {SPONG['g_2']}",
           f"\\phi_1 = {SPONG['g_2']}"]
    assert _judged(STANDARD, eqs) == ["correct", "correct", "correct", "incorrect"]


def test_the_equations_of_motion_in_the_reports_own_names():
    """Spong (7.4): τ₁ = d11 q̈1 + d12 q̈2 + 2h q̇1 q̇2 + h q̇2² + φ1, τ₂ = d21 q̈1 + d22 q̈2 − h q̇1² + φ2 with
    h = −m2 ℓ1 ℓc2 sin q2; d21 is d12 (M symmetric).  A wrong d12 carries into τ₁ and τ₂."""
    defs = [f"d_{{11}} = {SPONG['M_{11}']}", f"d_{{12}} = {SPONG['M_{12}']}", f"d_{{22}} = {SPONG['M_{22}']}",
            "h = -m_2 \\ell_1 \\ell_{c2} \\sin q_2", f"\\phi_1 = {SPONG['g_1']}", f"\\phi_2 = {SPONG['g_2']}"]
    eom = ["\\tau_1 = d_{11} \\ddot q_1 + d_{12} \\ddot q_2 + 2 h \\dot q_1 \\dot q_2 + h \\dot q_2^2 + \\phi_1",
           "\\tau_2 = d_{21} \\ddot q_1 + d_{22} \\ddot q_2 - h \\dot q_1^2 + \\phi_2"]
    assert _judged(STANDARD, defs + eom) == ["correct"] * 3 + ["not a claim"] + ["correct"] * 4  # h: a definition
    wrong = [defs[0], defs[1].replace("+ I_2", "+ I_1")] + defs[2:] + eom
    judged = _judged(STANDARD, wrong)
    assert judged[-2:] == ["incorrect", "incorrect"] and judged.count("incorrect") == 3


def test_the_correct_value_writes_the_centre_of_mass_distance_as_the_report_does():
    text = "# Two-link arm\n\n" + STANDARD + "\n$$M_{22} = m_2 \\ell_{c2}^2 + 2 I_2$$\n"
    (c,) = grade_text(text).claims
    assert c.verdict == "incorrect" and "\\ell_{c2}" in c.fix and "ellc" not in c.fix


def _christoffel_truth():
    """Spong's c_ijk = ½(∂d_kj/∂q_i + ∂d_ki/∂q_j − ∂d_ij/∂q_k) of the textbook M above, differentiated by sympy here
    (Sec. 7.4: c121 = c211 = c221 = h, c112 = −h, the rest 0, h = −m2 l1 lc2 sin q2)."""
    import sympy as sp

    q1, q2, l1, lc1, lc2, m1, m2, i1, i2 = sp.symbols("q_1 q_2 ell_1 ell_c1 ell_c2 m_1 m_2 I_1 I_2")
    M = sp.Matrix([[m1 * lc1 ** 2 + m2 * (l1 ** 2 + lc2 ** 2 + 2 * l1 * lc2 * sp.cos(q2)) + i1 + i2,
                    m2 * (lc2 ** 2 + l1 * lc2 * sp.cos(q2)) + i2],
                   [m2 * (lc2 ** 2 + l1 * lc2 * sp.cos(q2)) + i2, m2 * lc2 ** 2 + i2]])
    q = (q1, q2)
    out = {}
    for i in range(2):
        for j in range(2):
            for k in range(2):
                c = sp.simplify((sp.diff(M[k, j], q[i]) + sp.diff(M[k, i], q[j]) - sp.diff(M[i, j], q[k])) / 2)
                out[(i + 1, j + 1, k + 1)] = sp.latex(c)
    return out


def test_spongs_christoffel_symbols_are_judged_and_a_slip_is_caught():
    truth = _christoffel_truth()
    assert truth[(1, 2, 1)] != "0" and truth[(1, 1, 1)] == "0"  # the derivation is not trivially empty
    right = [f"c_{{{i}{j}{k}}} = {v}" for (i, j, k), v in truth.items()]
    right.append(f"\\Gamma^1_{{22}} = {truth[(2, 2, 1)]}")
    intro = "M_{22} = m_2 \\ell_{c2}^2 + I_2"  # names the masses, so the arm is read with them
    assert _judged(STANDARD, [intro] + right) == ["correct"] * (len(right) + 1)
    slips = [f"c_{{221}} = -({truth[(2, 2, 1)]})", "c_{222} = m_2 \\ell_1 \\ell_{c2} \\sin q_2"]
    assert _judged(STANDARD, [intro] + slips) == ["correct", "incorrect", "incorrect"]


def test_the_other_index_order_is_a_question_and_a_cosine_shorthand_is_no_christoffel_symbol():
    """``c_{112}`` written with the row index first (Murray–Li–Sastry's Γ_ijk: the value of Spong's c_121) is
    ambiguous, not incorrect; ``c_{122} = \\cos(q_1 + 2 q_2)`` and ``c_{122} = c_{12} c_2 - s_{12} s_2`` are cosines."""
    truth = _christoffel_truth()
    intro = "M_{22} = m_2 \\ell_{c2}^2 + I_2"
    got = _judged(STANDARD, [intro, f"c_{{112}} = {truth[(1, 2, 1)]}", "c_{122} = \\cos(q_1 + 2 q_2)",
                             "c_{122} = c_{12} c_2 - s_{12} s_2"])
    assert got[:2] == ["correct", "ambiguous"] and "incorrect" not in got[2:], got


def test_numbers_given_to_the_masses_are_used_at_a_case():
    """ℓ1 = ℓ2 = 1, ℓc1 = ℓc2 = 0.5, m1 = m2 = 2, I1 = I2 = 0.2 at q = (0, 90°): by the textbook entries above,
    d11 = 2·0.25 + 2·(1 + 0.25 + 0) + 0.4 = 3.4, d12 = 2·0.25 + 0.2 = 0.7, d22 = 0.7; a wrong d12 = 0.9 is
    caught in exactly its two entries (with stand-in values every entry differed)."""
    def report(d12: str) -> str:
        return ("# Two-link arm\n\n" + STANDARD + "\n$$M_{22} = m_2 \\ell_{c2}^2 + I_2$$\n\n"
                "Numbers: $\\ell_1 = \\ell_2 = 1$, $\\ell_{c1} = \\ell_{c2} = 0.5$, $m_1 = m_2 = 2$, $I_1 = I_2 = 0.2$. "
                "At $q = (0, 90^\\circ)$:\n\n"
                f"$$M = \\begin{{bmatrix}} 3.4 & {d12} \\\\ {d12} & 0.7 \\end{{bmatrix}}$$\n")
    right = [c for c in grade_text(report("0.7")).claims if c.quantity == "mass_matrix"]
    wrong = [c for c in grade_text(report("0.9")).claims if c.quantity == "mass_matrix"]
    assert [c.verdict for c in right] == ["correct", "correct"]
    assert [c.verdict for c in wrong] == ["correct", "incorrect"] and "(1, 2), (2, 1)" in wrong[1].message
