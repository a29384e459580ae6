"""Several numeric cases in one report (``denavit report ROBOT -q … -q …``): every numeric section shows each case
under its label, each case's numbers are those of its own q, and one -q keeps the single-case report."""

from __future__ import annotations

import json

import numpy as np
import pytest

import denavit as dn
from denavit.cli import main
from denavit.errors import ParseError
from denavit.report import MAX_CASES, Heading, derive, render

CASES = ["0, pi/4, pi/3", "(-pi/3, 0, pi/2)", "-pi/2, -pi/6, 3*pi/4"]
Q = [np.array([0, np.pi / 4, np.pi / 3]), np.array([-np.pi / 3, 0, np.pi / 2]),
     np.array([-np.pi / 2, -np.pi / 6, 3 * np.pi / 4])]
WRENCHES = ["1, 0, 0, 0, 0, 0", "0, 2, 0, 0, 0, 1", "0, 0, 0, 0, 0, 3"]
QD = np.array([1.0, -2.0, 0.5])


def _planar(q, L=(1.0, 1.0, 1.0)):
    """Tip position and the (vx, vy, ωz) Jacobian of a planar 3R arm, written from the textbook formulas."""
    th = np.cumsum(q)
    p = np.array([sum(L[i] * np.cos(th[i]) for i in range(3)), sum(L[i] * np.sin(th[i]) for i in range(3))])
    J = np.array([[-sum(L[i] * np.sin(th[i]) for i in range(k, 3)) for k in range(3)],
                  [sum(L[i] * np.cos(th[i]) for i in range(k, 3)) for k in range(3)],
                  [1.0, 1.0, 1.0]])
    return p, J


def _by_case(section):
    """The steps of a section (JSON) split at its case headings: [steps before, case 1, case 2, …]."""
    parts: list[list] = [[]]
    for st in section["steps"]:
        if st["type"] == "heading":
            parts.append([st])
        else:
            parts[-1].append(st)
    return parts


def _numbers(steps, lhs):
    return [np.array(s["values"], dtype=float) for s in steps if s["type"] == "numbers" and s["lhs"] == lhs]


def test_three_cases_from_the_command_line(capsys):
    assert main(["report", "planar3r", "-q", CASES[0], "-q", CASES[1], "-q", CASES[2], "--qd", "1, -2, 0.5",
                 "--wrench", WRENCHES[0], "--wrench", WRENCHES[1], "--wrench", WRENCHES[2],
                 "--topics", "fk,case,jacobian,velocity,statics", "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert len(data["cases"]) == 3
    for k, c in enumerate(data["cases"]):
        np.testing.assert_allclose(c["q"], Q[k], atol=1e-15)
    sections = {s["key"]: s for s in data["sections"]}
    assert not any(st["type"] == "heading" for st in sections["fk"]["steps"])  # fk does not depend on q
    for key in ("case", "jacobian", "velocity", "statics"):
        parts = _by_case(sections[key])
        assert len(parts) == 4, key  # the common opening, then one part per case
        for k in range(3):
            assert parts[k + 1][0]["text"].startswith(f"Case {k + 1}: "), parts[k + 1][0]
            text = json.dumps(parts[k + 1])
            assert "DISAGREE" not in text and "agree" in text, (key, k)
    wrench = [np.array([float(x) for x in w.split(",")]) for w in WRENCHES]
    for k in range(3):
        p, Jp = _planar(Q[k])
        (T,) = _numbers(_by_case(sections["case"])[k + 1], "{}^{0}T_{3}")
        np.testing.assert_allclose(T[:2, 3], p, atol=1e-12)
        (J,) = _numbers(_by_case(sections["jacobian"])[k + 1], "J_0(q)")
        np.testing.assert_allclose(J[[0, 1, 5]], Jp, atol=1e-12)
        nu = _numbers(_by_case(sections["velocity"])[k + 1], "\\nu")[0]
        np.testing.assert_allclose(nu[[0, 1, 5]], Jp @ QD, atol=1e-12)
        tau = _numbers(_by_case(sections["statics"])[k + 1], "\\tau")[0]
        np.testing.assert_allclose(tau, Jp.T @ wrench[k][[0, 1, 5]], atol=1e-12)
    # the propagation formulas (in q, q̇) are written once, in case 1; every case keeps their check at its q
    vel = _by_case(sections["velocity"])
    formulas = [[s for s in part if s["type"] == "equation" and s["lhs"].startswith("{}^{3}\\omega")]
                for part in vel[1:]]
    assert [len(f) for f in formulas] == [1, 0, 0], formulas
    for part in vel[2:]:
        texts = " ".join(s.get("text", "") for s in part)
        assert "formulas are those written for case 1" in texts and "Check, the formulas at the numeric case" in texts
    # the velocity labels do not repeat the shared rates; the statics labels name each case's wrench
    assert "\\dot q" not in _by_case(sections["velocity"])[1][0]["text"]
    assert "F = (0, 2, 0, 0, 0, 1)" in _by_case(sections["statics"])[2][0]["text"]


def test_one_case_keeps_the_single_case_report(capsys):
    assert main(["report", "planar3r", "-q", CASES[0], "--topics", "case,jacobian"]) == 0
    out = capsys.readouterr().out
    assert "### Case" not in out and "numeric cases" not in out and "q = (0, pi/4, pi/3)" in out
    d = derive(dn.load_robot("planar3r"), ["0", "pi/4", "pi/3"], topics=["case", "jacobian"])
    assert "cases" not in d.inputs and not any(isinstance(s, Heading) for sec in d.sections for s in sec.steps)


def test_cases_render_as_headings_in_every_format():
    robot = dn.load_robot("planar2r")
    d = derive(robot, cases=[{"q": ["0", "pi/2"]}, {"q": ["pi/3", "-pi/4"], "qd": [1, 2]}], topics=["case", "velocity"])
    md, _ = render(d, "md")
    assert md.count("### Case 1: $q = (0, \\frac{\\pi}{2})$") == 2 and md.count("### Case 2: ") == 2
    assert "2 numeric cases" in md
    html, _ = render(d, "html")
    assert html.count("<h3>Case 2: <span class=\"math-inline\">") == 2
    tex, _ = render(d, "tex")
    assert tex.count("\\subsection*{Case 1: $q = (0, \\frac{\\pi}{2})$}") == 2
    vel = d.section("velocity")  # case 1 has no rates (skipped), case 2 has them: each says so
    assert vel.status == "done"
    text = " ".join(getattr(s, "text", "") for s in vel.steps)
    assert "Skipped for this case: no joint rates given" in text


@pytest.mark.parametrize("argv, words", [
    (["-q", "0, 0", "-q", "0, 1", "--qd", "1, 2", "--qd", "1, 2", "--qd", "0, 0"], ["--qd given 3 times", "2 case"]),
    (["-q", "0, 0", "-q", "0, 1, 2"], ["case 2: q: expected 2 values"]),
    (["-q", "0, 0", "-q", "0, 9"], ["case 2:", "outside its limits"]),
    (["-q", "0, 0", "-q", "0, 0", "--wrench", "1, 2", "--wrench", "0,0,0,0,0,0"], ["case 1: wrench"]),
    (["--qd", "1, 2", "--qd", "1, 2"], ["--qd given 2 times for 1 case"]),
    (sum((["-q", "0, 0"] for _ in range(MAX_CASES + 1)), []), [f"at most {MAX_CASES} numeric cases"]),
])
def test_bad_cases_are_one_line(tmp_path, capsys, argv, words):
    out = tmp_path / "r.md"
    assert main(["report", "planar2r", *argv, "-o", str(out)]) == 2
    cap = capsys.readouterr()
    assert cap.out == "" and cap.err.count("\n") == 1 and "Traceback" not in cap.err, cap.err
    for w in words:
        assert w in cap.err, cap.err
    assert not out.exists()


def test_derive_refuses_bad_case_lists():
    robot = dn.load_robot("planar2r")
    with pytest.raises(ParseError, match="not both"):
        derive(robot, [0, 0], cases=[{"q": [0, 0]}])
    with pytest.raises(ParseError, match="unknown key 'qdd'"):
        derive(robot, cases=[{"q": [0, 0]}, {"q": [0, 0], "qdd": [0, 0]}])
    with pytest.raises(ParseError, match="1 to"):
        derive(robot, cases=[])
    with pytest.raises(ParseError, match="case 2"):
        derive(robot, cases=[{"q": [0, 0]}, "0, 0"])


def test_the_ik_derivation_is_written_once_and_evaluated_per_case():
    robot = dn.load_robot("planar2r")
    d = derive(robot, cases=[{"q": ["pi/6", "pi/3"]}, {"q": ["-pi/4", "pi/2"]}], topics=["ik"])
    steps = d.section("ik").steps
    heads = [k for k, s in enumerate(steps) if isinstance(s, Heading)]
    assert len(heads) == 2
    one, two = steps[heads[0]:heads[1]], steps[heads[1]:]
    eq = [s for s in one if type(s).__name__ == "Equation"]
    assert eq and not [s for s in two if type(s).__name__ == "Equation"]  # the derivation: once
    tables = [[s for s in part if type(s).__name__ == "Table"] for part in (one, two)]
    assert all(tables) and tables[0] != tables[1]  # evaluated at each case's own target
    for q, part in zip(([np.pi / 6, np.pi / 3], [-np.pi / 4, np.pi / 2]), (one, two)):
        (T,) = [s.values for s in part if type(s).__name__ == "Numbers" and s.lhs == "T_{\\text{target}}"]
        c1, c12 = np.cos(q[0]), np.cos(q[0] + q[1])
        s1, s12 = np.sin(q[0]), np.sin(q[0] + q[1])
        L1, L2 = dict(robot.parameters)["L1"], dict(robot.parameters)["L2"]
        np.testing.assert_allclose(T[:2, 3], [L1 * c1 + L2 * c12, L1 * s1 + L2 * s12], atol=1e-12)
