"""Derivation reports: built as data, rendered in every format, numbers equal to the library's."""

from __future__ import annotations

import functools
import json
import os
import re
import shutil
import subprocess
from html import unescape
from pathlib import Path

import numpy as np
import pytest
import sympy as sp

import denavit as dn
from denavit import _expr
from denavit import numeric as N
from denavit.report import Equation, Numbers, Table, Text, derive, render, write_report
from denavit.report import _capabilities

from conftest import CI, REDUCED
ALL = dn.catalogue_names()
FEW = ["report000-6r", "puma560", "report004-4-rrp", "planar2r"]


@functools.lru_cache(maxsize=None)
def _derived(name):
    """The full report of catalogue arm ``name`` at its rest pose, q̇ = 0.5 and one wrench: one derivation per arm
    and test process, rendered by every test that only needs some report of that arm (it is data; renderers do
    not change it)."""
    robot = dn.load_robot(name)
    if robot.name != name:  # an old alias: one cache entry per arm
        return _derived(robot.name)
    return derive(robot, qd=[0.5] * robot.dof, wrench=[1, 2, 3, 0.1, 0.2, 0.3])


def _case_inputs(robot, rng):
    lo, hi = robot.q_limits.T
    lo, hi = np.maximum(lo, -np.pi), np.minimum(hi, np.pi)
    q = rng.uniform(lo, hi)
    return q, rng.normal(size=robot.dof), rng.normal(size=6)


def _numbers(sec, lhs):
    return [s for s in sec.steps if isinstance(s, Numbers) and s.lhs == lhs]


def _equations(sec, lhs):
    return [s for s in sec.steps if isinstance(s, Equation) and s.lhs == lhs]


@pytest.mark.parametrize("name", ALL)
@pytest.mark.slow
def test_report_every_arm_renders_markdown(name):
    d = _derived(name)
    text, _ = render(d, "md")
    assert text.startswith(f"# Kinematics and dynamics of {name}")
    for sec in d.sections:
        assert sec.title in text
        assert sec.status in ("done", "skipped", "unavailable")
        if sec.status != "done":
            assert sec.reason and sec.reason in text
    assert "DISAGREE" not in text


@pytest.mark.parametrize("name", FEW[:2] if REDUCED else FEW)
@pytest.mark.parametrize("fmt", ["html", "tex"])
@pytest.mark.slow
def test_report_renders_html_and_latex(name, fmt, tmp_path):
    d = _derived(name)
    out = tmp_path / f"r.{fmt}"
    written = write_report(d, out)
    text = out.read_text()
    assert written[0] == out
    if fmt == "html":
        assert text.startswith("<!DOCTYPE html>") and "katex.render" in text and "data:font/woff2;base64" in text
        assert "http://" not in text.split("<script>")[0]  # no remote resources before the scripts
    else:
        assert text.startswith(r"\documentclass") and text.rstrip().endswith(r"\end{document}")
        assert text.count(r"\begin{center}") == text.count(r"\end{center}")


@pytest.mark.slow
def test_report_numbers_equal_the_library():
    rng = np.random.default_rng(7)
    for name in ["report000-6r", "report001-6r", "stanford", "report004-8-prrr"]:
        robot = dn.load_robot(name)
        q, qd, w = _case_inputs(robot, rng)
        d = derive(robot, q, qd, w)
        label = "T_{we}" if not (np.allclose(robot.base_matrix, np.eye(4)) and np.allclose(robot.tool_matrix, np.eye(4))) \
            else f"{{}}^{{0}}T_{{{robot.n_rows}}}"
        case = d.section("case")
        T = dn.forward_kinematics(robot, q)
        np.testing.assert_allclose(_numbers(case, label)[0].values, T, atol=1e-12)
        J = dn.geometric_jacobian(robot, q)
        np.testing.assert_allclose(_numbers(d.section("jacobian"), "J_0(q)")[0].values, J, atol=1e-12)
        np.testing.assert_allclose(_numbers(d.section("velocity"), "\\nu")[0].values, J @ qd, atol=1e-10)
        np.testing.assert_allclose(_numbers(d.section("statics"), "\\tau")[0].values, J.T @ w, atol=1e-10)
        # the decimals printed in the Markdown are the library's numbers, rounded
        text, _ = render(d, "md")
        for v in T[:3, 3]:
            assert dn_number(v) in text


def dn_number(v):
    from denavit.report import number_text

    return number_text(float(v))


def test_report_exact_case_is_exact_and_agrees_with_numeric():
    """q given as text is substituted exactly: cos(π/3) appears as 1/2, √3/2, and the exact T equals the
    numeric engine's (an independent route: sympy arithmetic vs the numpy chain)."""
    robot = dn.load_robot("report000-6r")
    q = ["0", "pi/4", "pi/3", "-pi/2", "-pi/3", "pi/6"]
    d = derive(robot, q, topics=["case"])
    case = d.section("case")
    A3 = _equations(case, "A_{3}")[0].expr
    assert A3[0, 0] == sp.Rational(1, 2) and A3[2, 0] == sp.sqrt(3) / 2
    T_exact = _equations(case, "{}^{0}T_{7}")[0].expr
    assert all(e.is_number and not e.has(sp.Float) for e in T_exact)
    qf = np.array([0, np.pi / 4, np.pi / 3, -np.pi / 2, -np.pi / 3, np.pi / 6])
    np.testing.assert_allclose(np.array(T_exact.evalf(30), dtype=float), dn.forward_kinematics(robot, qf), atol=1e-14)


@pytest.mark.slow
def test_report_symbolic_jacobian_matches_numeric_at_random_points():
    """The report's symbolic J0 (z_i × (p_e − p_i) from symbolic frames), evaluated at random q, equals
    central finite differences of the numeric FK position (an independent route)."""
    from denavit.report._context import Context
    from denavit.report._motion import jacobian_sym
    from denavit.symbolic import joint_symbols, parameter_symbols

    rng = np.random.default_rng(3)
    for name in ["report001-6r", "report004-4-rrp", "scara"]:
        robot = dn.load_robot(name)
        ctx = Context.build(robot, None, None, None)
        J = jacobian_sym(ctx)
        qs = joint_symbols(robot.dof).q
        params = {parameter_symbols(robot)[k]: v for k, v in robot.parameters}
        for _ in range(3):
            q = rng.uniform(-np.pi, np.pi, robot.dof) * 0.5
            Jq = np.array(J.xreplace(params).xreplace(dict(zip(qs, q))).evalf(), dtype=float)
            h = 1e-6
            fd = np.stack([(dn.forward_kinematics(robot, q + h * e)[:3, 3] - dn.forward_kinematics(robot, q - h * e)[:3, 3])
                           / (2 * h) for e in np.eye(robot.dof)], axis=1)
            np.testing.assert_allclose(Jq[:3], fd, atol=1e-7)


def test_report_sections_say_honestly_when_a_capability_is_missing(monkeypatch):
    monkeypatch.setattr(_capabilities, "capability", lambda module, *names: None)
    robot = dn.load_robot("puma560")
    d = derive(robot, topics=["singularities", "ik", "dynamics", "figures"])
    for key in ("ik", "dynamics", "figures"):
        assert d.section(key).status == "unavailable"
        assert "not available" in d.section(key).reason
    text, _ = render(d, "md")
    assert text.count("> Not available:") == 4


def test_report_skips_sections_without_their_inputs():
    d = derive(dn.load_robot("planar3r"), topics=["velocity", "statics"])
    assert [s.status for s in d.sections] == ["skipped", "skipped"]
    assert "--qd" in d.section("velocity").reason and "--wrench" in d.section("statics").reason


def test_report_bad_inputs_raise_parse_errors():
    robot = dn.load_robot("planar2r")
    with pytest.raises(dn.ParseError, match="q: expected 2 values, got 3"):
        derive(robot, ["0", "1", "2"])
    with pytest.raises(dn.ParseError, match="q: value 2"):
        derive(robot, ["0", "import os"])
    with pytest.raises(dn.ParseError, match="unknown report topic"):
        derive(robot, topics=["nonsense"])


@pytest.mark.skipif(shutil.which("node") is None, reason="node not installed")
@pytest.mark.slow
def test_report_every_formula_is_valid_katex(tmp_path):
    """Every formula of the HTML report is parsed by the bundled KaTeX with throwOnError."""
    js = Path(dn.__file__).parent / "report" / "assets" / "katex" / "katex.min.js"
    script = tmp_path / "check.js"
    script.write_text(
        "const k=require(process.argv[2]);const items=JSON.parse(require('fs').readFileSync(0,'utf8'));"
        "const bad=[];for(const [s,d] of items){try{k.renderToString(s,{displayMode:d,throwOnError:true,"
        "strict:false,maxSize:20});}catch(e){bad.push([s.slice(0,120),String(e).slice(0,160)]);}}"
        "console.log(JSON.stringify(bad));")
    for name in ["report000-6r", "report004-4-rrp", "puma560", "report000-planar3r"]:
        text, _ = render(_derived(name), "html")
        items = [(unescape(m.group(2)), m.group(1) == "display")
                 for m in re.finditer(r'<(?:div|span) class="math-(display|inline)">(.*?)</(?:div|span)>', text, re.S)]
        assert len(items) > 20
        out = subprocess.run(["node", str(script), str(js)], input=json.dumps(items), capture_output=True,
                             text=True, timeout=120, check=True)
        assert json.loads(out.stdout) == [], name


# --- inverse kinematics and dynamics sections ---------------------------------------------------------


def _tables(sec):
    return [s for s in sec.steps if isinstance(s, Table)]


def _qs(cell):
    """A joint vector printed in an IK table cell, ``(0, 0.7854, −1.0472)``, read back."""
    return np.array([float(x) for x in cell.strip("()").replace("−", "-").split(",")])


def _wrapped(robot, a, b):
    rev = np.array([t.value == "revolute" for t in robot.joint_types])
    d = np.asarray(a) - np.asarray(b)
    return np.max(np.where(rev, np.abs((d + np.pi) % (2 * np.pi) - np.pi), np.abs(d)), axis=-1)


@pytest.mark.parametrize("name", ["puma560", "stanford", "planar2r", "report000-planar3r"])
@pytest.mark.slow
def test_report_ik_derivation_branches_reproduce_every_analytic_solution(name):
    """The derivation's formulas, evaluated at the target for every sign, each land on a solution of the
    analytic solver (a different algorithm) or outside the limits, with an FK residual ~1e-16; every analytic
    solution is reproduced by some branch; the printed solutions are analytic_ik's, each satisfying FK = T."""
    robot = dn.load_robot(name)
    q, _, _ = _case_inputs(robot, np.random.default_rng(5))
    sec = derive(robot, q, topics=["ik"]).section("ik")
    texts = " ".join(s.text for s in sec.steps if isinstance(s, Text))
    assert "Closed-form derivation" in texts and "Step 3," in texts
    assert any(isinstance(s, Equation) and s.lhs == "q_{1}" for s in sec.steps)
    derived, solutions = _tables(sec)[-2:]
    assert "sigma" in derived.header[0] and solutions.header[1] == "branch"
    assert not derived.math and not solutions.math  # plain text: residuals like 4.9e-16 are not typeset as math
    T = dn.forward_kinematics(robot, q)
    res = dn.analytic_ik(robot, T)
    assert len(solutions.rows) == res.solutions.shape[0] >= 1
    for (k, _, qcell, err), truth in zip(solutions.rows, res.solutions):
        assert _wrapped(robot, _qs(qcell), truth) < 6e-5 and float(err) < 1e-9
    matched = set()
    for _, qcell, err, which in derived.rows:
        if "no real value" in qcell:
            continue
        assert float(err) < 1e-9 and which != "none", (qcell, which)
        matched |= {int(x) for x in which.split(", ")} if which[0].isdigit() else set()
    assert matched == set(range(1, len(solutions.rows) + 1))


def test_report_ik_without_derivation_shows_analytic_or_numeric_solutions():
    robot = dn.load_robot("report000-6r")
    q = np.array([0.0, np.pi / 4, np.pi / 3, -np.pi / 2, -np.pi / 3, np.pi / 6])
    sec = derive(robot, q, topics=["ik"]).section("ik")
    texts = " ".join(s.text for s in sec.steps if isinstance(s, Text))
    assert "derivation is not printed for this arm" in texts
    # the text does not contradict the table: solutions in closed form, so no "no closed form" anywhere
    assert "no closed form" not in texts.lower() and "from analytic_ik (closed form" in texts
    (table,) = _tables(sec)
    assert len({row[1] for row in table.rows}) == len(table.rows)  # every solution named once
    for row in table.rows:
        assert "continuum" in row[1] and float(row[3]) < 1e-9  # joints 1 and 2 are coaxial
        T = dn.forward_kinematics(robot, _qs(row[2]))
        np.testing.assert_allclose(T, dn.forward_kinematics(robot, q), atol=1e-4)
    panda = dn.load_robot("panda")
    sec = derive(panda, topics=["ik"]).section("ik")
    q_sol = _numbers(sec, "q_{sol}")[0].values
    target = _numbers(sec, "T_{\\text{target}}")[0].values
    np.testing.assert_allclose(dn.forward_kinematics(panda, q_sol), target, atol=1e-9)


@pytest.mark.parametrize("name", ["planar2r", "report000-planar3r"])
@pytest.mark.slow
def test_report_dynamics_printed_formulas_equal_the_numeric_library(name):
    """The M, c, g printed in the report (LaTeX, C_12 shorthand, dotted rates), read back by the claims reader
    and evaluated at random q, q̇, equal the numeric engine's CRBA mass matrix, Christoffel c and gravity
    torques; the numbers at the case are the library's; the report's own checks agree."""
    from denavit import symbolic
    from denavit.check import parse_matrix, robot_resolver

    if not hasattr(symbolic, "lagrange_steps"):
        pytest.skip("denavit.symbolic.lagrange_steps is not in this checkout yet")
    robot = dn.load_robot(name)
    rng = np.random.default_rng(21)
    q, qd, _ = _case_inputs(robot, rng)
    sec = derive(robot, q, qd, topics=["dynamics"]).section("dynamics")
    assert sec.status == "done"
    printed = {e.lhs: parse_matrix(e.expr, robot_resolver(robot)) for e in sec.steps
               if isinstance(e, Equation) and e.lhs in ("M(q)", "c(q, \\dot q)", "g(q)")}
    assert len(printed) == 3
    for _ in range(3):
        qx, qdx, _ = _case_inputs(robot, rng)
        env = {**robot.parameter_values, **{f"q{k + 1}": v for k, v in enumerate(qx)},
               **{f"qd{k + 1}": v for k, v in enumerate(qdx)}}
        val = {k: np.array([[_expr.evaluate(c, env) for c in row] for row in cells]) for k, cells in printed.items()}
        np.testing.assert_allclose(val["M(q)"], N.mass_matrix(robot, qx), atol=1e-10)
        np.testing.assert_allclose(val["c(q, \\dot q)"][:, 0], N.coriolis_vector(robot, qx, qdx), atol=1e-10)
        np.testing.assert_allclose(val["g(q)"][:, 0], N.gravity_torques(robot, qx), atol=1e-10)
    np.testing.assert_allclose(_numbers(sec, "M(q)")[0].values, N.mass_matrix(robot, q), atol=1e-12)
    np.testing.assert_allclose(_numbers(sec, "c(q, \\dot q)")[0].values, N.coriolis_vector(robot, q, qd), atol=1e-12)
    np.testing.assert_allclose(_numbers(sec, "g(q)")[0].values, N.gravity_torques(robot, q), atol=1e-12)
    texts = " ".join(s.text for s in sec.steps if isinstance(s, Text))
    assert texts.count("agree") == 4 and "DISAGREE" not in texts
    assert any(isinstance(s, Equation) and s.lhs.startswith("\\frac{d}{dt}") for s in sec.steps)


def test_report_dynamics_of_a_long_arm_is_in_recursive_form():
    """Panda (7 joints, more than HAND_FORM_MAX_DOF): M, c, g as recursions in named link quantities
    (denavit.symbolic.recursive_dynamics), which the report evaluates at the case against the numeric engine."""
    robot = dn.load_robot("panda")
    q = np.array([0, -0.3, 0, -2.2, 0, 2, 0.8])
    sec = derive(robot, q=list(q), qd=[1] * 7, topics=["dynamics"]).section("dynamics")
    lhs = [s.lhs for s in sec.steps if isinstance(s, Equation)]
    assert "M_{11}" in lhs and "M_{77}" in lhs and "c_{7}" in lhs and "g_{7}" in lhs and "J^{c}_{2zz}" in lhs
    np.testing.assert_allclose(_numbers(sec, "M(q)")[0].values, N.mass_matrix(robot, q), atol=1e-12)
    texts = " ".join(s.text for s in sec.steps if isinstance(s, Text))
    assert "these formulas at the case vs the numeric engine: M agree" in texts and "DISAGREE" not in texts


def test_report_dynamics_of_a_six_joint_arm_is_in_closed_form_entry_by_entry():
    """Puma 560: M_jk (j <= k), c_k, g_k as equations (hand form, C_{23}), checked at the case against the
    numeric engine in the report's own text, without the step-by-step Lagrange derivation."""
    robot = dn.load_robot("puma560")
    sec = derive(robot, qd=[1] * 6, topics=["dynamics"]).section("dynamics")
    lhs = [s.lhs for s in sec.steps if isinstance(s, Equation)]
    assert lhs[:2] == ["M_{11}", "M_{12}"] and "M_{66}" in lhs and "c_{6}" in lhs and "g_{2}" in lhs
    assert not any(x.startswith("\\frac{d}{dt}") for x in lhs)
    assert any("C_{23}" in str(s.expr) for s in sec.steps if isinstance(s, Equation))
    texts = " ".join(s.text for s in sec.steps if isinstance(s, Text))
    assert texts.count("agree") >= 4 and "DISAGREE" not in texts
    q = np.array([float(sp.pi / 6)] * 6)
    np.testing.assert_allclose(_numbers(sec, "M(q)")[0].values, N.mass_matrix(robot, q), atol=1e-12)


CHROMIUM = os.environ.get("DENAVIT_CHROMIUM", "/usr/bin/chromium")


@pytest.mark.browser
def test_report_html_typesets_offline_in_a_browser(tmp_path):
    """The HTML report opened in headless Chromium: every formula typeset by the bundled KaTeX, no KaTeX
    error, no request leaves the file (fonts and scripts are embedded)."""
    try:
        from playwright.sync_api import sync_playwright
    except ImportError:
        pytest.skip("playwright is not installed")
    if not Path(CHROMIUM).exists():
        if CI:
            pytest.fail(f"no chromium at {CHROMIUM} under CI")
        pytest.skip(f"no chromium at {CHROMIUM}")
    robot = dn.load_robot("report000-6r")
    out = tmp_path / "r.html"
    write_report(derive(robot, ["0", "pi/4", "pi/3", "-pi/2", "-pi/3", "pi/6"], [1] * 6, [1, 0, 0, 0, 0, 1]), out)
    n_math = out.read_text().count('class="math-')
    with sync_playwright() as pw:
        b = pw.chromium.launch(executable_path=CHROMIUM, headless=True,
                               args=["--headless", "--no-sandbox", "--disable-gpu", "--no-first-run"])
        page = b.new_page()
        requests: list[str] = []
        errors: list[str] = []
        page.on("request", lambda r: requests.append(r.url))
        page.on("pageerror", lambda e: errors.append(str(e)))
        page.goto(out.as_uri())
        page.wait_for_function("document.querySelectorAll('.katex').length > 0")
        typeset = page.evaluate("document.querySelectorAll('.katex').length")
        bad = page.evaluate("document.querySelectorAll('.katex-error').length")
        fonts_ok = page.evaluate("document.fonts.check('16px KaTeX_Main')")
        b.close()
    assert errors == [] and bad == 0
    assert typeset == n_math
    assert fonts_ok
    assert all(u.startswith(("file:", "data:")) for u in requests), requests


@pytest.mark.parametrize("name", ["puma560", "ur5", "stanford", "offset-6r"])
def test_ik_branch_labels_are_unique_per_solution_set(name):
    """Distinct solutions of one pose never share a branch label (random poses; the library's labels), and the
    two elbow solutions of one shoulder are told apart by the elbow word alone."""
    robot = dn.load_robot(name)
    rng = np.random.default_rng(16)
    lo, hi = np.maximum(robot.q_limits.T[0], -np.pi), np.minimum(robot.q_limits.T[1], np.pi)
    q = rng.uniform(lo, hi, (150 if not REDUCED else 60, robot.dof))
    res = dn.analytic_ik(robot, dn.forward_kinematics(robot, q))
    for labels, valid, sols in zip(res.branches, res.valid, res.solutions):
        names = [b for b, v in zip(labels, valid) if v]
        assert len(set(names)) == len(names), names
        for b in names:
            assert b.startswith("shoulder ") and "wrist " in b
        # same shoulder and wrist words, different solutions: the elbow word differs (for elbow arms)
        if name != "stanford":
            rest = [b.replace("elbow up", "").replace("elbow down", "") for b in names]
            for r in set(rest):
                elbows = [b for b, x in zip(names, rest) if x == r]
                assert len(elbows) <= 2 and len(set(elbows)) == len(elbows)


def test_report_ik_labels_unique_even_where_the_solver_repeats_one():
    from denavit.report._ik import unique_labels

    rng = np.random.default_rng(3)
    words = ["elbow up", "elbow down", "-", "shoulder left, wrist flip"]
    for _ in range(200):
        labels = list(rng.choice(words, size=rng.integers(1, 9)))
        out = unique_labels(labels)
        named = [o for o, b in zip(out, labels) if b != "-"]
        assert len(set(named)) == len(named)
        assert all(o.startswith(b) for o, b in zip(out, labels))
        assert [o for o, b in zip(out, labels) if labels.count(b) == 1] == [b for b in labels if labels.count(b) == 1]
    # coaxial-6r: the solver gives its two continuum solutions one label; the report names them apart
    robot = dn.load_robot("coaxial-6r")
    q = np.array([0.3, 0.0, -0.6, 0.4, -2.0, 1.0])
    sec = derive(robot, q, topics=["ik"]).section("ik")
    (table,) = _tables(sec)
    assert len({row[1] for row in table.rows}) == len(table.rows) >= 2



def _readme_first_command():
    """The `denavit report ...` part of the README's first command, as argv."""
    import shlex

    text = (Path(__file__).parents[1] / "README.md").read_text(encoding="utf-8")
    first = text.split("```bash", 1)[1].split("```", 1)[0].strip().splitlines()[0]
    return shlex.split(first.split("&&", 1)[1])


@pytest.mark.slow
def test_readme_first_command_shows_a_well_known_arm_with_every_section_filled(tmp_path, capsys):
    """The README's main command: a catalogue arm with dynamics, at a regular configuration, every section
    done (none skipped), its dynamics numbers the numeric library's at the same q, and quick."""
    import time

    from denavit.cli import main

    argv = _readme_first_command()
    assert argv[:2] == ["denavit", "report"]
    robot = dn.load_robot(argv[2])
    assert robot.has_dynamics and robot.dof == 6 and not robot.source.startswith("catalogue:report")
    out = tmp_path / "report.html"
    argv = [a if a != "report.html" else str(out) for a in argv[1:]]
    t0 = time.process_time()
    assert main(argv) == 0
    assert time.process_time() - t0 < 60  # CPU seconds in this process (10-13 when measured), not a benchmark
    html = unescape(out.read_text(encoding="utf-8"))
    for k, title in enumerate(["Model: DH table and convention", "Link transforms", "Forward kinematics",
                               "Numeric case", "Jacobian", "Velocity", "Statics", "Singularities",
                               "Inverse kinematics", "Dynamics", "Figures"], start=1):
        assert f"<h2>{k}. {title}</h2>" in html, title
    assert 'class="status"' not in html  # nothing skipped or unavailable
    # the same derivation as data: the numbers printed are the numeric engine's at q (independent of the
    # report's code path: recomputed here from the parsed q)
    q = dn.io.parse_values(argv[argv.index("-q") + 1], robot.dof)
    qd = dn.io.parse_values(argv[argv.index("--qd") + 1], robot.dof)
    d = derive(robot, q, qd, dn.io.parse_values(argv[argv.index("--wrench") + 1], 6))
    assert all(s.status == "done" for s in d.sections)
    sec = d.section("dynamics")
    np.testing.assert_allclose(_numbers(sec, "M(q)")[0].values, N.mass_matrix(robot, q), rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(_numbers(sec, "g(q)")[0].values, N.gravity_torques(robot, q), atol=1e-12)
    np.testing.assert_allclose(_numbers(sec, "c(q, \\dot q)")[0].values + _numbers(sec, "g(q)")[0].values
                               + N.friction_torques(robot, qd), N.rnea(robot, q, qd, np.zeros(6)), atol=1e-9)
    # a regular configuration: full-rank Jacobian, several IK solutions all checked
    assert np.linalg.matrix_rank(dn.geometric_jacobian(robot, q)) == 6
    ik = d.section("ik")
    (solutions,) = [s for s in ik.steps if isinstance(s, Table) and s.header[1] == "branch"]
    assert len(solutions.rows) >= 2 and len({r[1] for r in solutions.rows}) == len(solutions.rows)
    texts = " ".join(s.text for s in ik.steps if isinstance(s, Text))
    assert "no closed form" not in texts.lower()


def test_report_takes_a_named_pose():
    """derive(robot, "qn") is the report at robot's named pose qn: the same numbers as the pose's values."""
    robot = dn.load_robot("puma560")
    for name, q in robot.poses:
        d = derive(robot, name, topics=["case"])
        T = _numbers(d.section("case"), "{}^{0}T_{6}")
        np.testing.assert_allclose(T[-1].values, dn.forward_kinematics(robot, np.array(q)), atol=1e-12)
        assert [float(sp.sympify(v)) for v in d.inputs["q_exact"]] == pytest.approx(q, abs=1e-12)


@pytest.mark.parametrize("name, q", [("planar3r", "0.3, 0.5, -0.2"), ("report004-1-planar2r", "0.4, -0.7")])
def test_report_writes_the_propagation_routes_as_formulas_checked_at_the_case(name, q):
    """Velocity and force propagation step by step as formulas (issue 13), each evaluated at the numeric case
    by the report and compared with the numeric route: the text must say they agree."""
    from denavit.report import derive, render_markdown

    robot = dn.load_robot(name)
    n = robot.dof
    d = derive(robot, [float(x) for x in q.split(",")], [0.1 * (k + 1) for k in range(n)],
               [1.0, 2.0, 0.0, 0.0, 0.0, 0.5], topics=["velocity", "statics"])
    text = render_markdown(d)[0]
    assert "The same propagation as formulas" in text
    assert text.count("vs the table above: agree") == 1
    assert "(the wrench turned into tool axes) vs route 1: agree" in text
    assert "DISAGREE" not in text
