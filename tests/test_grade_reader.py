"""The report reader of ``denavit check REPORT``: what it understands, where it places verdicts, what it refuses.

The truths here are textbook results written by hand (the planar 2R arm of Spong, Sec. 3.2: x = L1 c1 + L2 c12 …)
and the library's own catalogue arms; the fixture corpus (tests/test_grade_corpus.py) covers whole reports.
"""

from __future__ import annotations

import json
import resource
import subprocess
import sys

import pytest

from denavit.cli import main
from denavit.grade import grade_text
from denavit.grade._lhs import read_symbol
from denavit.grade._names import read_name
from denavit.grade._split import split_block
from denavit.io import load_robot

TABLE = """| i | $a_i$ | $\\alpha_i$ | $d_i$ | $\\theta_i$ |
|---|---|---|---|---|
| 1 | $L_1$ | 0 | 0 | $\\theta_1$ |
| 2 | $L_2$ | 0 | 0 | $\\theta_2$ |
"""


def _report(*blocks: str) -> str:
    return "# Planar arm\n\n" + TABLE + "\n" + "\n\n".join(blocks) + "\n"


def _verdicts(text: str, **kw) -> list[tuple[int, str, str]]:
    r = grade_text(text, **kw)
    return [(c.line, c.quantity, c.verdict) for c in r.claims]


@pytest.mark.parametrize("lhs, spec", [
    ("{}^{0}T_{1}", {"quantity": "link_transform", "index": 1}),
    ("^{0}_{1}T", {"quantity": "link_transform", "index": 1}),
    ("T_0^1", {"quantity": "link_transform", "index": 1}),
    ("T_1^0", {"quantity": "link_transform", "index": 1}),
    ("A_2", {"quantity": "link_transform", "index": 2}),
    ("T01", {"quantity": "link_transform", "index": 1}),
    ("{}^{1}R_{3}", {"quantity": "transform", "from": 1, "to": 3}),
    ("T_{i-1}^{i}", {"quantity": "dh_matrix"}),
    ("p_x", {"quantity": "position", "entry": 1}),
    ("p_E", {"quantity": "position"}),
    ("\\dot{p}_{c3}", {"quantity": "com_velocity", "index": 3}),
    ("J", {"quantity": "jacobian"}),
    ("J_v", {"quantity": "jacobian", "rows": "linear"}),
    ("J_\\omega", {"quantity": "jacobian", "rows": "angular"}),
    ("J_{11}", {"quantity": "jacobian", "entry": [1, 1]}),
    ("J_{\\vartheta_2}", {"quantity": "jacobian", "column": 2}),
    ("{}^0J", {"quantity": "jacobian", "frame": 0}),
    ("{}^3J", {"quantity": "jacobian", "frame": 3}),
    ("J^T", {"quantity": "jacobian", "transpose": True}),
    ("\\tau", {"quantity": "torques"}),
    ("{}^2\\omega_2", {"quantity": "omega", "index": 2}),
    ("{}^1 v_1", {"quantity": "velocity", "index": 1}),
    ("{}^2\\mathbf{f}_2", {"quantity": "force", "index": 2}),
    ("{}^1n_1", {"quantity": "moment", "index": 1}),
    ("\\det J", {"quantity": "det_jacobian"}),
    ("M(q)", {"quantity": "mass_matrix"}),
    ("M_{12}", {"quantity": "mass_matrix", "entry": [1, 2]}),
    ("g(\\theta)", {"quantity": "gravity"}),
])
def test_left_hand_sides_are_read_as_textbooks_write_them(lhs, spec):
    robot = load_robot("articulated-rrr")
    sym = read_symbol(lhs)
    assert sym is not None, lhs
    reading = read_name(sym, robot)
    assert reading is not None, lhs
    assert {k: reading.spec.get(k) for k in spec} == spec


@pytest.mark.parametrize("lhs", ["\\delta d", "(\\delta q)^T \\tau", "e_{z_i}", "p_p", "J_{\\vartheta_{Li}}",
                                 "{}^4 w_0", "x^2 + y^2"])
def test_names_that_are_no_result_get_no_reading(lhs):
    robot = load_robot("articulated-rrr")
    sym = read_symbol(lhs)
    assert sym is None or read_name(sym, robot) is None


def test_aligned_rows_chains_and_quads_split_into_equations():
    eqs = split_block("\\begin{aligned} x &= L_1 c_1 \\\\ y &= L_1 s_1 \\\\ &\\quad + L_2 s_{12} \\end{aligned}", 5, 7)
    assert [e.parts[0] for e in eqs] == ["x", "y"]
    assert "L_2 s_{12}" in eqs[1].parts[-1]
    eqs = split_block("\\det J = 0 \\Rightarrow L_1 L_2 s_2 = 0 \\Rightarrow \\theta_2 = 0", 3, 3)
    assert len(eqs) == 3 and eqs[-1].parts == ("\\theta_2", "0")
    eqs = split_block("x = L_1 c_1 \\quad \\dot{x} = -L_1 s_1 \\dot\\theta_1", 1, 1)
    assert [e.parts[0] for e in eqs] == ["x", "\\dot{x}"]
    eqs = split_block("\\theta_2 = 0, \\pi", 1, 1)  # a comma inside a list of values splits nothing
    assert len(eqs) == 1


def test_verdicts_land_on_the_lines_of_their_equations():
    text = _report("$$T_0^2 = \\begin{bmatrix} c_{12} & -s_{12} & 0 & L_1 c_1 + L_2 c_{12} \\\\ s_{12} & c_{12} & 0 & "
                   "L_1 s_1 + L_2 s_{12} \\\\ 0 & 0 & 1 & 0 \\\\ 0 & 0 & 0 & 1 \\end{bmatrix}$$",
                   "$$x = L_1 c_1 - L_2 c_{12}$$")
    got = _verdicts(text)
    lines = text.splitlines()
    t_line = 1 + next(k for k, s in enumerate(lines) if s.startswith("$$T_0^2"))
    x_line = 1 + next(k for k, s in enumerate(lines) if s.startswith("$$x ="))
    assert got == [(t_line, "end_effector", "correct"), (x_line, "position", "incorrect")]


def test_a_misread_name_is_ambiguous_never_incorrect():
    """T_1^0 with the inverse of A_1 under it: right for one reading of the name, so a question, not a mistake."""
    inverse = ("$$T_1^0 = \\begin{bmatrix} c_1 & s_1 & 0 & -L_1 \\\\ -s_1 & c_1 & 0 & 0 \\\\ 0 & 0 & 1 & 0 \\\\ "
               "0 & 0 & 0 & 1 \\end{bmatrix}$$")
    (line, qty, verdict), = _verdicts(_report(inverse))
    assert (qty, verdict) == ("link_transform", "ambiguous")
    craig = inverse.replace("T_1^0", "{}^{1}T_{0}")  # Craig's left superscript is explicit: the inverse, correct
    assert _verdicts(_report(craig))[0][2] == "correct"


def test_case_numbers_are_judged_at_that_case_and_without_a_case_are_not_called_wrong():
    at_case = _report("Case 1: $q = (0, \\pi/2)$", "$$p_x = L_1$$")  # x = L1 c1 + L2 c12 = L1 at (0, π/2)
    assert [v for *_, v in _verdicts(at_case)] == ["not a claim", "correct"]
    wrong = _report("Case 1: $q = (0, \\pi/2)$", "$$p_x = L_2$$")
    assert [v for *_, v in _verdicts(wrong)][-1] == "incorrect"
    robot = load_robot("planar2r")
    no_case = "# arm\n\n$$p_x = 0.5$$\n"
    assert _verdicts(no_case, robot=robot)[0][2] == "ambiguous"


def test_inverse_trig_as_textbooks_write_it_is_the_inverse_function():
    text = _report("$$\\theta_2 = \\cos^{-1}\\left(\\frac{p_x^2 + p_y^2 - L_1^2 - L_2^2}{2 L_1 L_2}\\right)$$")
    assert _verdicts(text)[0][1:] == ("ik_formula", "correct")


def test_singular_configurations_in_words_are_one_claim():
    right = _report("The arm is singular when $\\theta_2 = 0$ or $\\theta_2 = \\pi$.")
    wrong = _report("The arm is singular when $\\theta_1 = 0$.")
    assert [v for _, q, v in _verdicts(right) if q == "singularities"] == ["correct"]
    assert [v for _, q, v in _verdicts(wrong) if q == "singularities"] == ["incorrect"]


def test_definitions_and_givens_are_not_claims_and_relations_are_judged():
    got = _verdicts(_report("$$T_0^2 = A_1 A_2$$", "$$F = \\begin{bmatrix} 1 \\\\ 2 \\\\ 0 \\end{bmatrix}$$",
                            "$$\\tau = J^T F$$", "$$\\tau = J F$$"))
    assert [(q, v) for _, q, v in got] == [("end_effector", "not a claim"), ("given: wrench", "not a claim"),
                                           ("relation", "correct"), ("relation", "incorrect")]


def test_each_table_governs_its_own_section():
    two = ("## 1. First arm\n\n" + TABLE + "\n$$x = L_1 c_1 + L_2 c_{12}$$\n\n## 2. Second arm\n\n"
           "| i | $a_{i-1}$ | $\\alpha_{i-1}$ | $d_i$ | $\\theta_i$ |\n|---|---|---|---|---|\n"
           "| 1 | 0 | 0 | 0 | $\\theta_1$ |\n| 2 | $L_1$ | 0 | 0 | $\\theta_2$ |\n\n$$x = L_1 c_1$$\n")
    r = grade_text(two)
    assert [a.convention for a in r.arms] == ["standard", "modified"]
    assert [c.verdict for c in r.claims] == ["correct", "correct"]  # the second arm's tip is joint 2's axis
    assert r.claims[0].arm != r.claims[1].arm


def test_a_section_about_another_arm_without_a_table_is_not_judged_against_the_first():
    text = _report("$$x = L_1 c_1 + L_2 c_{12}$$") + "\n# 2. Dynamics of a 3DOF arm\n\n$$x = L_1 c_1$$\n"
    got = grade_text(text).claims
    assert [c.verdict for c in got] == ["correct", "unreadable"]
    assert "--arm" in got[1].message


def test_pathological_equations_are_their_own_unreadable_and_the_run_is_bounded():
    evil = ["$$x = " + "(" * 5000 + "$$", "$$J = \\begin{bmatrix}" + " 1 &" * 20000 + "\\end{bmatrix}$$",
            "$$p_x = " + " + ".join(["L_1"] * 3000) + "$$", "$$" + "{" * 3000 + "$$", "$$x = L_1 c_1 + L_2 c_{12}$$"]
    start = resource.getrusage(resource.RUSAGE_SELF).ru_utime
    r = grade_text(_report(*evil))
    spent = resource.getrusage(resource.RUSAGE_SELF).ru_utime - start
    assert r.claims[-1].verdict == "correct"  # the good one after the bad ones is still judged
    assert all(c.verdict in ("unreadable", "not a claim", "incorrect") for c in r.claims[:-1])
    assert spent < 60


def test_cli_report_json_has_lines_verdicts_and_arms(tmp_path, capsys):
    rep = tmp_path / "hw.md"
    text = _report("$$x = L_1 c_1 + L_2 c_{12}$$", "$$y = L_1 s_1$$")
    rep.write_text(text, encoding="utf-8")
    assert main(["check", str(rep), "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    claims = [{k: c[k] for k in ("line", "end_line", "quantity", "verdict")} for c in data["claims"]]
    x, y = (1 + text.splitlines().index(s) for s in ("$$x = L_1 c_1 + L_2 c_{12}$$", "$$y = L_1 s_1$$"))
    assert claims == [{"line": x, "end_line": x, "quantity": "position", "verdict": "correct"},
                      {"line": y, "end_line": y, "quantity": "position", "verdict": "incorrect"}]
    assert all({"arm", "message"} <= set(c) for c in data["claims"]) and data["arms"][0]["dof"] == 2


def test_cli_annotated_markdown_keeps_every_line_and_refuses_to_overwrite_the_report(tmp_path, capsys):
    rep = tmp_path / "hw.md"
    text = _report("$$x = L_1 c_1 + L_2 c_{12}$$")
    rep.write_text(text, encoding="utf-8")
    out = tmp_path / "checked.md"
    assert main(["check", str(rep), "-o", str(out)]) == 0
    marked = out.read_text(encoding="utf-8").splitlines()
    it = iter(marked)
    assert all(any(line == m for m in it) for line in text.splitlines())  # the original, in order
    assert any("correct" in m and m.startswith(">") for m in marked)
    assert main(["check", str(rep), "-o", str(rep)]) == 2
    assert rep.read_text(encoding="utf-8") == text
    capsys.readouterr()


@pytest.mark.parametrize("content, expect", [
    (b"\xff\xfe\x00garbage", "not UTF-8"),
    (b"", "no DH table"),
])
def test_cli_bad_reports_one_line(tmp_path, content, expect):
    rep = tmp_path / "bad.md"
    rep.write_bytes(content)
    res = subprocess.run([sys.executable, "-m", "denavit", "check", str(rep)], capture_output=True, text=True,
                         timeout=600)
    out = res.stdout + res.stderr
    assert expect in out and "Traceback" not in out
    assert res.returncode in (0, 2)
    if expect == "not UTF-8":
        assert res.returncode == 2 and len(res.stderr.strip().splitlines()) == 1


def test_cli_report_without_a_table_or_arm_says_what_to_give(tmp_path, capsys):
    rep = tmp_path / "hw.md"
    rep.write_text("# hw\n\n$$x = L_1 c_1$$\n", encoding="utf-8")
    assert main(["check", str(rep)]) == 0
    out = capsys.readouterr().out
    assert "no DH table" in out and "unreadable" in out
    assert main(["check", "planar2r", str(rep)]) == 0
    assert "INCORRECT" in capsys.readouterr().out  # planar2r's x is L1 c1 + L2 c12


def test_a_chain_ending_in_another_name_claims_its_value_for_both_and_recursions_are_definitions():
    """Craig's force propagation as students write it (the seed reports do): ``¹f₁ = ¹R₂ ²f₂ = [⋯] = ⁰f₀`` claims
    the vector for ¹f₁ *and* for ⁰f₀ — right for the first, wrong for the second (⁰f₀ = ⁰R₁ ¹f₁), each judged by the
    numeric engine; the recursion ``¹n₁ = ¹R₂ n₂ + ¹P₂ × ¹f₁`` is a definition, not an unreadable value; a symbol
    where the operator belongs (``¹P₂ α ¹f₁``) is named in the one line."""
    vector = "\\begin{bmatrix} c_2 f_x - s_2 f_y \\\\ s_2 f_x + c_2 f_y \\\\ f_z \\end{bmatrix}"
    text = _report(f"$${{}}^1 f_1 = {{}}^1 R_2 {{}}^2 f_2 = {vector} = {{}}^0 f_0$$",
                   f"$${{}}^1 f_1 = {vector} = {{}}^1 \\mathbf{{f}}_1$$",
                   "$${}^1 n_1 = {}^1 R_2 n_2 + {}^1 P_2 \\times {}^1 f_1$$",
                   "$${}^1 n_1 = {}^1 R_2 n_2 + {}^1 P_2 \\alpha {}^1 f_1$$",
                   "$$x = L_1 c_1 + L_2 c_{12}$$")
    r = grade_text(text)
    got = [(c.quantity, c.verdict) for c in r.claims]
    assert got == [("force", "correct"), ("force", "incorrect"), ("force", "correct"), ("force", "correct"),
                   ("moment", "not a claim"), ("moment", "unreadable"), ("position", "correct")]
    assert [c.line for c in r.claims[:2]] == [r.claims[0].line] * 2  # both claims on the chain's line
    assert "frame 0" in r.claims[1].understood and "frame 1" in r.claims[0].understood
    assert "'\\alpha' where an operator" in r.claims[5].message and "\n" not in r.claims[5].message
    # the wrong vector under the trailing name: both names judged, both wrong
    wrong = _report(f"$${{}}^1 f_1 = {vector.replace('- s_2 f_y', '+ s_2 f_y')} = {{}}^0 f_0$$")
    assert [(c.quantity, c.verdict) for c in grade_text(wrong).claims] == [("force", "incorrect")] * 2


def test_a_section_without_a_table_is_offered_the_catalogue_arms_whose_parameters_it_writes():
    """The advice names a catalogue arm with the section's joint count and its symbols; followed, the section's
    textbook centre-of-mass position (p_c2 = (L1 c1 + Lc2 c12, L1 s1 + Lc2 s12, 0)) is judged correct."""
    pc2 = ("$$p_{c2} = \\begin{bmatrix} L_1 \\cos\\theta_1 + Lc_2 \\cos(\\theta_1 + \\theta_2) \\\\ "
           "L_1 \\sin\\theta_1 + L c_2 \\sin(\\theta_1 + \\theta_2) \\\\ 0 \\end{bmatrix}$$")
    text = (_report("$$x = L_1 c_1 + L_2 c_{12}$$") + "\n# 2. Dynamics of a 3DOF arm\n\n"
            "$$K = \\frac{1}{2} m_1 Lc_1^2 \\dot\\theta_1^2 + \\frac{1}{2} I_1 \\dot\\theta_1^2$$\n\n" + pc2 + "\n")
    notes = grade_text(text).notes
    advice = [n for n in notes if "--arm 2=p" in n]
    assert len(advice) == 1 and advice[0].index("--arm 2=planar3r-lagrange") < advice[0].find("--arm 2=planar3r ")
    judged = grade_text(text, arms={"2": load_robot("planar3r-lagrange")}).claims
    assert [c.verdict for c in judged if c.quantity == "com_position"] == ["correct"]
    other = _report("$$x = L_1 c_1$$") + "\n# 2. A 3DOF arm\n\n$$x = h_1 + w_2 + u_3$$\n"
    assert not [n for n in grade_text(other).notes if "--arm 2=p" in n]  # no catalogue arm writes h1, w2, u3


def test_a_wrong_planar_pair_is_judged_entry_by_entry_not_by_shape():
    """(x, y) of the planar 2R tip (Spong 3.2: y = L1 s1 + L2 s12) with y wrong: the entry is named, not the shape."""
    good = "$$p_E = \\begin{bmatrix} L_1 c_1 + L_2 c_{12} \\\\ L_1 s_1 + L_2 s_{12} \\end{bmatrix}$$"
    bad = "$$p_E = \\begin{bmatrix} L_1 c_1 + L_2 c_{12} \\\\ L_1 c_1 + L_2 s_{12} \\end{bmatrix}$$"
    ok, wrong = grade_text(_report(good, bad)).claims
    assert ok.verdict == "correct" and "(x, y)" in ok.message
    assert wrong.verdict == "incorrect" and "(x, y)" in wrong.message and "shape" not in wrong.message
    assert "1 entry differs (2)" in wrong.message


@pytest.mark.parametrize("tail", ["S v_s", "{}^0v_s", "\\vec{u}"])
def test_names_after_a_matrix_name_it_and_the_matrix_is_judged(tail):
    """``⁴v₄ = [⋯] = S v_s`` (report 004): the matrix is the claim, right (Spong 3.2's tip) or wrong."""
    good = f"$$p_E = \\begin{{bmatrix}} L_1 c_1 + L_2 c_{{12}} \\\\ L_1 s_1 + L_2 s_{{12}} \\end{{bmatrix}} = {tail}$$"
    bad = good.replace("L_1 s_1", "L_1 c_1")
    ok, wrong = grade_text(_report(good, bad)).claims
    assert (ok.verdict, wrong.verdict) == ("correct", "incorrect"), (ok.message, wrong.message)
    assert "the matrix before" in ok.understood


def test_lengths_the_report_states_equal_are_equal_from_there_on():
    """``L_1 = L_2 = L`` (the table leaves both without a value): x = L (c₁ + c₁₂) is the textbook tip of the
    planar 2R arm with equal links, judged correct after the statement; before it, and for an arm whose table gives
    the two lengths different values, the same formula is wrong."""
    early = grade_text(_report("$$x = L_1 (c_1 + c_{12})$$", "$$L_1 = L_2 = L$$", "$$x = L (c_1 + c_{12})$$",
                               "$$y = L_1 s_1 + L_2 s_{12}$$", "$$y = L_1 s_1 + L_1 s_{12}$$"))
    judged = [c.verdict for c in early.claims if c.quantity == "position"]
    assert judged == ["incorrect", "correct", "correct", "correct"]
    assert any("L1 = L2" in n for n in early.notes)
    valued = _report("$$L_1 = L_2 = L$$", "$$x = L (c_1 + c_{12})$$").replace("| $L_1$ |", "| $L_1 = 0.5$ |") \
        .replace("| $L_2$ |", "| $L_2 = 0.3$ |")
    assert [c.verdict for c in grade_text(valued).claims if c.quantity == "position"] == ["incorrect"]


@pytest.mark.parametrize("arrow", ["", "\\{x_1, y_1, z_1\\} \\rightarrow ", "\\{x_1, y_1, z_1\\} \\Rightarrow "])
def test_a_matlab_position_column_and_the_subject_carried_over_an_arrow(arrow):
    """``T_1^0(1:3,4)``: frame 1's origin, (L1 c1, L1 s1, 0) for the planar 2R arm (Spong 3.2); after an arrow the
    matrix is the value of the name before it, and a vector of bare names after it only names it."""
    tail = " = \\begin{bmatrix} P_x \\\\ P_y \\\\ P_z \\end{bmatrix}"
    good = f"$$T_1^0(1:3,4) = {arrow}\\begin{{bmatrix}} L_1 c_1 \\\\ L_1 s_1 \\\\ 0 \\end{{bmatrix}}{tail}$$"
    bad = good.replace("L_1 s_1", "L_1 c_1")
    judged = [c for c in grade_text(_report(good, bad)).claims if c.quantity == "origin" and c.verdict != "not a claim"]
    assert [c.verdict for c in judged] == ["correct", "incorrect"], [c.message for c in judged]
    assert all("column 4 of T_0_1" in c.understood for c in judged)


def test_a_determinant_after_an_arrow_keeps_its_own_reading():
    """``\\det J = 0 ⇒ |J| = 0 ⇒ θ₂ = 0``: the bars are a determinant, not the value of the name before the arrow
    (planar 2R, Spong 3.2: det J = L1 L2 s2)."""
    j = ("\\begin{vmatrix} -L_1 s_1 - L_2 s_{12} & -L_2 s_{12} \\\\ L_1 c_1 + L_2 c_{12} & L_2 c_{12} \\end{vmatrix}")
    for bars in (j, j.replace("-L_2 s_{12}", "a")):  # a stray 'a' (report 004) leaves the det J claim judged
        claims = grade_text(_report(f"$$\\det(J) = 0 \\Rightarrow {bars} = 0 \\Rightarrow \\theta_2 = 0$$")).claims
        assert "unreadable" not in [c.verdict for c in claims if c.quantity == "det_jacobian"]
        assert "correct" in [c.verdict for c in claims]


def test_unbalanced_brackets_are_named_in_the_unreadable_line():
    (c,) = grade_text(_report("$$x = (L_1 c_1 + L_2 c_{12}))$$")).claims
    assert c.verdict == "unreadable" and "1 more ')' than '('" in c.message


@pytest.mark.parametrize("value", ["\\frac{L_1 (c_1 + L_2 c_{12}}{2}", "(L_1 c_1 + L_2 c_{12}",
                                   "\\frac{\\left( L_1 \\left( c_1 \\right)^2}{2}"])
def test_a_bracket_left_open_is_named_in_the_unreadable_line(value):
    """Seed 000's K: ``\\frac{m_3 \\left( \\left( … \\right)^2}{2}`` (one '(' never closed)."""
    (c,) = grade_text(_report(f"$$x = {value}$$")).claims
    assert c.verdict == "unreadable" and "is not closed (the brackets do not balance)" in c.message, c.message


RRP = """| i | $a_i$ | $\\alpha_i$ | $d_i$ | $\\theta_i$ |
|---|---|---|---|---|
| 1 | 0 | $-90^\\circ$ | $d_1$ | $\\theta_1$ |
| 2 | 0 | $90^\\circ$ | $d_2$ | $\\theta_2$ |
| 3 | 0 | 0 | $d_3$ | 0 |
"""


def test_the_determinant_of_a_spatial_three_joint_arm_is_of_its_position_rows():
    """A spherical RRP arm: det J_v = −d₃² sin θ₂ (derived here with sympy from the DH product, not by denavit);
    the sign slipped is named, and 'singular when θ₂ = 0 or d₃ = 0' is judged with the position rows (θ₂ = π
    missing), not with the 6-row J whose angular rows keep θ₂ = 0 regular."""
    import sympy as sp
    t1, t2, d1, d2, d3 = sp.symbols("t1 t2 d1 d2 d3")

    def dh(th, d, al):
        return sp.Matrix([[sp.cos(th), -sp.sin(th) * sp.cos(al), sp.sin(th) * sp.sin(al), 0],
                          [sp.sin(th), sp.cos(th) * sp.cos(al), -sp.cos(th) * sp.sin(al), 0],
                          [0, sp.sin(al), sp.cos(al), d], [0, 0, 0, 1]])
    p = (dh(t1, d1, -sp.pi / 2) * dh(t2, d2, sp.pi / 2) * dh(0, d3, 0))[:3, 3]
    assert sp.simplify(p.jacobian([t1, t2, d3]).det() + d3 ** 2 * sp.sin(t2)) == 0
    text = ("# RRP arm\n\n" + RRP + "\n$$\\det J_v = -d_3^2 s_2$$\n\n$$\\det J_v = d_3^2 s_2$$\n\n"
            "The arm is singular when $\\theta_2 = 0$ or $d_3 = 0$.\n")
    dets = [c for c in grade_text(text).claims if c.quantity == "det_jacobian"]
    assert [c.verdict for c in dets] == ["correct", "incorrect"]
    assert "opposite sign" in str(dets[1].details.get("hints"))
    (sing,) = [c for c in grade_text(text).claims if c.quantity == "singularities"]
    assert sing.verdict == "incorrect" and "vx,vy,vz" in sing.message and "3.14159" in sing.message


@pytest.mark.parametrize("given", ["At $\\theta_1 = 30^\\circ$, $\\theta_2 = 60^\\circ$ and a tip force $F = (0, -10)$ N.",
                                   "Case: $\\theta_1 = 30^\\circ$, $\\theta_2 = 60^\\circ$.\n\n"
                                   "$$F = \\begin{bmatrix} 0 \\\\ -10 \\end{bmatrix}$$"])
def test_a_force_of_two_entries_is_a_force_in_the_plane(given):
    """τ = Jᵀ F for the planar 2R arm (a1 = 1, a2 = 0.5) at (30°, 60°) with F = (0, −10): J's first row
    (−y, −a2 s12) = (−1, −0.5), its second (x, a2 c12) = (√3/2, 0), so τ = (−5√3, 0) (by hand)."""
    table = TABLE.replace("| $L_1$ |", "| $a_1 = 1$ |").replace("| $L_2$ |", "| $a_2 = 0.5$ |")
    good = "$$\\tau = J^T F = \\begin{bmatrix} -8.66 \\\\ 0 \\end{bmatrix}$$"
    text = "# Planar arm\n\n" + table + "\n" + given + "\n\n" + good + "\n\n" + good.replace("-8.66", "8.66") + "\n"
    judged = [c.verdict for c in grade_text(text).claims if c.quantity == "torques"]
    assert judged == ["correct", "incorrect"]


def test_torque_numbers_without_a_stated_wrench_are_a_question_not_wrong():
    """Numbers for τ with no F given before them cannot be judged (τ = Jᵀ F is linear in F): ambiguous."""
    text = ("# Planar arm\n\n" + TABLE + "\nCase: $\\theta_1 = 30^\\circ$, $\\theta_2 = 60^\\circ$.\n\n"
            "$$\\tau = J^T F = \\begin{bmatrix} -8.66 \\\\ 0 \\end{bmatrix}$$\n")
    (c,) = [c for c in grade_text(text).claims if c.quantity == "torques"]
    assert c.verdict == "ambiguous" and "no wrench" in c.message


def _planar2r_tip_sympy():
    """T_2^0 of the planar 2R arm as SymPy writes it (``\\left[\\begin{matrix} … \\end{matrix}\\right]``): the
    product of Spong's A_i, Rot_z(θ_i) Trans_x(L_i), multiplied out here."""
    import sympy as sp

    t1, t2, l1, l2 = sp.symbols("theta_1 theta_2 L_1 L_2")

    def a(t, length):
        return sp.Matrix([[sp.cos(t), -sp.sin(t), 0, length * sp.cos(t)], [sp.sin(t), sp.cos(t), 0, length * sp.sin(t)],
                          [0, 0, 1, 0], [0, 0, 0, 1]])
    return sp.Matrix(sp.simplify(a(t1, l1) * a(t2, l2))), sp


@pytest.mark.parametrize("form", ["matrix", "array"])
def test_sympy_and_array_matrices_are_read_as_bmatrix(form):
    """Jupyter/SymPy reports write ``\\left[\\begin{matrix} … \\end{matrix}\\right]``, hand-written LaTeX
    ``\\left[\\begin{array}{cccc} … \\end{array}\\right]``: both are the matrix, judged (a slip still caught)."""
    T, sp = _planar2r_tip_sympy()
    slipped = sp.Matrix(T)
    slipped[0, 3] = -slipped[0, 3]
    texts = []
    for M in (T, slipped):
        tex = sp.latex(M)
        if form == "array":
            tex = tex.replace("\\begin{matrix}", "\\begin{array}{cccc}").replace("\\end{matrix}", "\\end{array}")
        assert tex.startswith("\\left[\\begin{")
        texts.append(f"$$T_2^0 = {tex}$$")
    got = [v for _, q, v in _verdicts(_report(*texts), fmt="md") if q == "end_effector"]
    assert got == ["correct", "incorrect"]


def test_a_wrench_named_with_capitals_is_the_wrench():
    """``F = [F_x, F_y]^T`` then ``τ = J^T F = [⋯ F_x ⋯]``: the capital names are the wrench's (were "in terms of
    other results"). τ = J_vᵀ F of the planar 2R arm by hand: (−L1 s1 − L2 s12) F_x + (L1 c1 + L2 c12) F_y,
    −L2 s12 F_x + L2 c12 F_y."""
    tau = ("\\begin{bmatrix} (-L_1 s_1 - L_2 s_{12}) F_x + (L_1 c_1 + L_2 c_{12}) F_y \\\\ "
           "-L_2 s_{12} F_x + L_2 c_{12} F_y \\end{bmatrix}")
    right = _report("For a force $F = [F_x, F_y]^T$ at the tip:", f"$$\\tau = J^T F = {tau}$$")
    wrong = right.replace("-L_2 s_{12} F_x", "L_2 s_{12} F_x")
    assert [v for _, q, v in _verdicts(right) if q == "torques"] == ["correct"]
    assert [v for _, q, v in _verdicts(wrong) if q == "torques"] == ["incorrect"]


@pytest.mark.parametrize("lhs", ["\\det J", "\\det \\begin{bmatrix} -L_1 s_1 - L_2 s_{12} & -L_2 s_{12} \\\\ "
                                 "L_1 c_1 + L_2 c_{12} & L_2 c_{12} \\end{bmatrix}"])
def test_det_of_the_planar_two_link_arm_and_of_its_rows_written_out(lhs):
    """det of the (x, y) rows of the planar 2R Jacobian = L1 L2 sin θ2 (Spong Sec. 4.10, by hand: the 2×2 above);
    a slip is incorrect (the default rows of a 2-joint planar arm are (vx, vy), a square block)."""
    right, wrong = (_report(f"$${lhs} = {v}$$") for v in ("L_1 L_2 s_2", "L_1 L_2 c_2"))
    assert [v for _, q, v in _verdicts(right) if q == "det_jacobian"] == ["correct"]
    assert [v for _, q, v in _verdicts(wrong) if q == "det_jacobian"] == ["incorrect"]


def test_a_notebook_export_names_its_outputs_by_the_cell_before_them():
    """nbconvert's Markdown: a code cell ending in a bare name (``T02``, ``display(Jv)``) and its output as
    ``$\\displaystyle \\left[\\begin{matrix} … \\end{matrix}\\right]$`` with no left-hand side: judged as ``T02 = …``,
    ``J_v = …`` (the planar 2R's T and J_v multiplied out by SymPy here); a cell ending in another call names nothing."""
    import sympy as sp

    t1, t2, l1, l2 = sp.symbols("theta_1 theta_2 L_1 L_2")

    def a(t, length):
        return sp.Matrix([[sp.cos(t), -sp.sin(t), 0, length * sp.cos(t)], [sp.sin(t), sp.cos(t), 0, length * sp.sin(t)],
                          [0, 0, 1, 0], [0, 0, 0, 1]])
    T = sp.simplify(a(t1, l1) * a(t2, l2))
    Jv = T[:3, 3].jacobian([t1, t2])
    slipped = sp.Matrix(Jv)
    slipped[0, 1] = -slipped[0, 1]

    def cell(code: str, out) -> str:
        return f"```python\n{code}\n```\n\n\n\n$\\displaystyle {sp.latex(out)}$\n"
    text = _report(cell("T02 = sp.simplify(A1 * A2)\nT02", T), cell("Jv = p.jacobian([t1, t2])\ndisplay(Jv)", Jv),
                   cell("Jw", slipped).replace("Jw", "Jv"), cell("sp.simplify(Jv[:2, :].det())", l1 * l2 * sp.sin(t2)))
    got = [(q, v) for _, q, v in _verdicts(text) if v != "not a claim"]
    assert got == [("end_effector", "correct"), ("jacobian", "correct"), ("jacobian", "incorrect")], got


@pytest.mark.parametrize("given", ["$L_1 = L_2 = 1$ m", "$L_1 = 1$ m and $L_2 = 1$ m", "$L_1 = L_2 = 1\\,\\text{m}$"])
def test_lengths_given_a_value_are_used_for_the_numbers_after_them(given):
    """The table leaves L1, L2 as symbols; "L_1 = L_2 = 1 m" then T at θ = (30°, 45°): the tip (c30 + c75,
    s30 + s75) = (1.125, 1.466) by hand is right (was judged with generic lengths: incorrect), (1.2, 1.466) is not."""
    import math

    assert abs(math.cos(math.radians(30)) + math.cos(math.radians(75)) - 1.125) < 5e-4
    assert abs(math.sin(math.radians(30)) + math.sin(math.radians(75)) - 1.466) < 5e-4

    def t(x):
        return (f"$$T_2^0 = \\begin{{bmatrix}} 0.259 & -0.966 & 0 & {x} \\\\ 0.966 & 0.259 & 0 & 1.466 \\\\ "
                "0 & 0 & 1 & 0 \\\\ 0 & 0 & 0 & 1 \\end{bmatrix}$$")
    for x, verdict in (("1.125", "correct"), ("1.2", "incorrect")):
        text = _report(f"For $\\theta = (30^\\circ, 45^\\circ)$ and {given}:", t(x))
        assert [v for _, q, v in _verdicts(text) if q == "end_effector"] == [verdict]


def test_joint_rates_given_one_by_one_are_the_rates_of_the_velocities_after_them():
    """θ1 = 30°, θ2 = 60° (L1 = 1, L2 = 0.5), θ̇1 = 0.1, θ̇2 = 0.2: ẋ = −(L1 s1 + L2 s12) θ̇1 − L2 s12 θ̇2 = −0.2 and
    ẏ = (L1 c1 + L2 c12) θ̇1 + L2 c12 θ̇2 = 0.0866 by hand (s12 = 1, c12 = 0); −0.3 is wrong; without the rates
    the numbers are a question, not wrong."""
    import math

    assert abs(-(math.sin(math.radians(30)) + 0.5) * 0.1 - 0.5 * 0.2 - (-0.2)) < 1e-12
    assert abs(math.cos(math.radians(30)) * 0.1 - 0.0866) < 5e-5
    head = "The links are $L_1 = 1$ and $L_2 = 0.5$. Take $\\theta_1 = 30^\\circ$ and $\\theta_2 = 60^\\circ$."
    rates = "With $\\dot\\theta_1 = 0.1$ and $\\dot\\theta_2 = 0.2$ the tip moves at"
    for given, x, verdict in ((rates, "-0.2", "correct"), (rates, "-0.3", "incorrect"), ("The tip moves at", "-0.2",
                                                                                         "ambiguous")):
        text = _report(head, given, f"$$\\dot x = {x}, \\quad \\dot y = 0.0866$$")
        assert [v for _, q, v in _verdicts(text) if q == "twist"][:1] == [verdict], (given, x)


@pytest.mark.parametrize("name", ["z_1", "\\hat{z}_1", "e_{z_1}", "{}^{0}z_{1}"])
def test_joint_axes_written_as_z_i_are_judged(name):
    """Spong's articulated RRR (standard DH, α1 = 90°): z_1 (frame 1's z, the axis of joint 2) = (s1, −c1, 0) — the
    third column of A_1 = Rot_z(θ1) Rot_x(90°), multiplied out here; (c1, s1, 0) is not; z_0 = (0, 0, 1)."""
    import numpy as np

    t = 0.7
    A1 = np.array([[np.cos(t), 0, np.sin(t)], [np.sin(t), 0, -np.cos(t)], [0, 1, 0]])
    assert np.allclose(A1[:, 2], [np.sin(t), -np.cos(t), 0])
    table = ("| i | $a_i$ | $\\alpha_i$ | $d_i$ | $\\theta_i$ |\n|---|---|---|---|---|\n"
             "| 1 | 0 | $90^\\circ$ | $d_1$ | $\\theta_1$ |\n| 2 | $a_2$ | 0 | 0 | $\\theta_2$ |\n"
             "| 3 | $a_3$ | 0 | 0 | $\\theta_3$ |\n")
    eqs = ["z_0 = \\begin{bmatrix} 0 \\\\ 0 \\\\ 1 \\end{bmatrix}",
           f"{name} = \\begin{{bmatrix}} s_1 \\\\ -c_1 \\\\ 0 \\end{{bmatrix}}",
           f"{name} = \\begin{{bmatrix}} c_1 \\\\ s_1 \\\\ 0 \\end{{bmatrix}}"]
    text = "# RRR\n\n" + table + "\n" + "\n\n".join(f"$${e}$$" for e in eqs) + "\n"
    got = [(c.quantity, c.verdict) for c in grade_text(text).claims]
    assert got == [("joint_axis", "correct"), ("joint_axis", "correct"), ("joint_axis", "incorrect")], got
