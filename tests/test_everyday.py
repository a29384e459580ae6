"""The rough edges a new user hits (issue 31): output that fits the terminal, messages that say what to do."""

from __future__ import annotations

import os
import re
import shutil

import pytest

from denavit.cli import main


def run(capsys, *argv):
    code = main(list(argv))
    out, err = capsys.readouterr()
    return code, out, err


# --- symbolic matrices fit the terminal -------------------------------------------------------------------------

def test_symbolic_t06_of_the_puma_fits_a_100_column_terminal_entry_by_entry(capsys, monkeypatch):
    monkeypatch.setenv("COLUMNS", "100")
    code, out, _ = run(capsys, "fk", "puma560", "--symbolic", "--shorthand")
    assert code == 0
    assert max(len(line) for line in out.splitlines()) <= 100
    t06 = out[out.index("T_0_6 ="):]
    entries = dict(re.findall(r"^\((\d, \d)\) = (.*)$", t06, re.M))
    assert len(entries) == 16
    assert [entries[f"4, {j}"] for j in range(1, 5)] == ["0", "0", "0", "1"]
    # Craig (3.14) / Paul's Puma: p_x = C1 (a2 C2 + a3 C23 - d4 S23) - d3 S1, expanded
    px = set(entries["1, 4"].replace(" ", "").replace("+", " +").replace("-", " -").split())
    assert px == {"C₁⋅C₂⋅a₂", "+C₁⋅C₂₃⋅a₃", "-C₁⋅S₂₃⋅d₄", "+S₁⋅d₃"} or px == {"C₁⋅C₂⋅a₂", "+C₁⋅C₂₃⋅a₃",
                                                                             "-C₁⋅S₂₃⋅d₄", "-S₁⋅d₃"}


def test_a_symbolic_matrix_that_fits_stays_a_matrix(capsys, monkeypatch):
    monkeypatch.setenv("COLUMNS", "400")
    code, out, _ = run(capsys, "fk", "puma560", "--symbolic", "--shorthand")
    assert code == 0 and "entry by entry" not in out and out.count("⎡") == 7  # A_1..A_6 and T_0_6


def test_symbolic_jacobian_fits_the_terminal(capsys, monkeypatch):
    monkeypatch.setenv("COLUMNS", "80")
    code, out, _ = run(capsys, "jacobian", "puma560", "--shorthand")
    assert code == 0 and "entry by entry" in out
    matrix = out[out.index("entry by entry"):].splitlines()[1:]
    assert len(matrix) >= 36 and max(len(line) for line in matrix) <= 80
    assert sum(line.startswith("(") for line in matrix) == 36


def test_a_long_entry_is_broken_at_its_plus_and_minus_and_reads_back_the_same():
    import sympy as sp

    from denavit.display import matrix_text

    x = sp.symbols("x1:40")
    M = sp.Matrix([[sum(x[i] * x[i + 1] for i in range(30)) - 7 * x[0] * sp.cos(x[2] + x[3]), 1]])
    text = matrix_text(M, width=40)
    lines = text.splitlines()[1:]
    assert max(len(line) for line in lines) <= 40
    assert lines[0] == "(1, 1) =" and lines[-1] == "(1, 2) = 1"
    body = [line.strip() for line in lines[1:-1]]
    assert all(b.startswith(("+", "-")) for b in body[1:])  # every break is before a sign
    one_line = sp.pretty(M[0, 0], use_unicode=True, wrap_line=False)
    assert "⋅" in one_line and " ".join(body) == one_line


# --- inverse kinematics says why ---------------------------------------------------------------------------------

def _beyond(text):
    m = re.search(r"out of reach: the target is ([\d.e+-]+) m beyond the arm's reach bound \(it is ([\d.e+-]+) m "
                  r"from the chain's base point; no configuration reaches farther than ([\d.e+-]+) m from it\)", text)
    assert m, text
    return tuple(float(g) for g in m.groups())


def test_out_of_reach_ik_says_how_far_beyond_the_reach_the_target_is(capsys):
    import denavit

    robot = denavit.load_robot("planar2r")
    reach = sum(link.a for link in robot.links)  # a 2R arm reaches a1 + a2 from its base, stretched out (q2 = 0)
    code, out, err = run(capsys, "ik", "planar2r", "--pose", "5,0,0,0,0,0")
    assert code == 1 and len(err.strip().splitlines()) == 1
    beyond, dist, bound = _beyond(out)
    assert (beyond, dist, bound) == pytest.approx((5 - reach, 5, reach))
    assert _beyond(err) == (beyond, dist, bound)


def test_out_of_reach_puma_target_names_the_bound_and_reachable_ones_do_not(capsys, rng):
    import numpy as np

    import denavit

    robot = denavit.load_robot("puma560")
    code, out, _ = run(capsys, "ik", "puma560", "--pose", "3,0,0,0,0,0")
    beyond, dist, bound = _beyond(out)
    assert code == 1 and beyond == pytest.approx(dist - bound, abs=1e-3) and beyond > 0
    # the bound is a bound: no configuration within the limits reaches past it (sampled), nor past 3 m
    lo, hi = robot.q_limits.T
    p = denavit.forward_kinematics(robot, rng.uniform(lo, hi, (20_000, 6)))[:, :3, 3]
    assert np.max(np.linalg.norm(p - p.mean(axis=0), axis=1)) < 2 * bound and np.max(np.linalg.norm(p, axis=1)) < 3
    code, out, err = run(capsys, "ik", "puma560", "--from-q", "0.1, 0.2, -0.3, 0.4, 0.5, 0.6")
    assert code == 0 and "out of reach" not in out + err
    code, out, err = run(capsys, "ik", "planar2r", "--pose", "0,0,0,0,0,0", "--method", "numeric")
    assert "out of reach" not in out + err  # inside the reach (a folded arm reaches its base): no such claim


def test_redundant_arm_analytic_refusal_names_lock(capsys):
    code, out, err = run(capsys, "ik", "panda", "--pose", "0.3,0,0.5,0,0,0", "--method", "analytic")
    assert code == 1 and out == "" and len(err.strip().splitlines()) == 1
    assert "--lock" in err and "--lock q7=0" in err and "redundant" in err
    # whole: the advice was cut in the middle ("use the numerical ... w mask)") by the one-line limit; and the
    # numeric solver needs no row mask on a 7-joint arm that controls the whole pose (rank 6)
    assert " ... " not in err and "--method numeric for one solution" in err and "mask" not in err
    code, out, _ = run(capsys, "ik", "panda", "--from-q", "0.1, 0.2, 0.3, -1.4, 0.5, 1.6, 0.7", "--method", "numeric")
    assert code == 0
    # and the advice works: with q7 held, the closed forms answer (the README's command)
    code, out, _ = run(capsys, "ik", "panda", "--from-q", "0.1, 0.2, 0.3, -1.4, 0.5, 1.6, 0.7", "--lock", "q7=0.7")
    assert code == 0 and "q7 locked" in out


# --- names: did you mean, any letter case; the symbols known -----------------------------------------------------

def test_unknown_robot_name_gets_did_you_mean_and_a_whole_short_line(capsys):
    code, out, err = run(capsys, "fk", "puma650", "-q", "0")
    assert code == 2 and out == "" and len(err.strip().splitlines()) == 1
    assert "did you mean puma560" in err and " ... " not in err  # no list cut in the middle of a name
    assert "denavit robots" in err
    code, _, err = run(capsys, "fk", "qwertyuiop", "-q", "0")
    assert code == 2 and "did you mean" not in err and " ... " not in err


@pytest.mark.parametrize(("typed", "name"), [("UR5", "ur5"), ("Puma560", "puma560"), ("PANDA", "panda"),
                                             ("Report000-6R", "coaxial-6r")])
def test_catalogue_lookup_ignores_letter_case(typed, name):
    import denavit

    assert denavit.load_robot(typed) == denavit.load_robot(name)


def test_unknown_symbol_in_joint_values_lists_only_what_is_known(capsys):
    code, _, err = run(capsys, "fk", "puma560", "-q", "0, 0, 0, 0, 0, O")
    assert code == 2 and "unknown symbol 'O' (known: pi)" in err and "none" not in err


# --- import-urdf: the end link users expect, no rounding noise -----------------------------------------------------

def _urdf(joints: list[tuple[str, str, str, str, str]]) -> str:
    """A URDF of (joint name, type, parent, child, origin xyz / rpy attributes) joints; links from the joints."""
    links = {j[2] for j in joints} | {j[3] for j in joints}
    body = "".join(f'<link name="{n}"/>' for n in sorted(links))
    for name, kind, parent, child, origin in joints:
        extra = '<axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/>' if kind != "fixed" else ""
        body += (f'<joint name="{name}" type="{kind}"><parent link="{parent}"/><child link="{child}"/>'
                 f'<origin {origin}/>{extra}</joint>')
    return f'<robot name="t">{body}</robot>'


ARM = [("j1", "revolute", "base", "l1", 'xyz="0 0 0.3"'), ("j2", "revolute", "l1", "l2", 'xyz="0.4 0 0" rpy="1.57079632679 0 0"'),
       ("j3", "revolute", "l2", "l3", 'xyz="0.3 0 0"')]


def test_fixed_frames_of_the_last_link_do_not_compete_and_tool0_is_chosen(tmp_path):
    from denavit.interop import import_urdf

    res = import_urdf(_urdf(ARM + [("f1", "fixed", "l3", "ee_link", 'xyz="0.1 0 0"'),
                                   ("f2", "fixed", "l3", "tool0", 'xyz="0 0 0.1"')]))
    assert res.tip_link == "tool0" and res.robot.dof == 3
    assert any(n.startswith("end link tool0 (chosen:") and "ee_link" in n and "--tip" in n for n in res.notes)


def test_gripper_fingers_do_not_win_over_the_hand(tmp_path):
    from denavit.interop import import_urdf

    hand = [("h", "fixed", "l3", "hand", 'xyz="0 0 0.1"'), ("fl", "prismatic", "hand", "finger_l", 'xyz="0 0.02 0"'),
            ("fr", "prismatic", "hand", "finger_r", 'xyz="0 -0.02 0"')]
    res = import_urdf(_urdf(ARM + hand))
    assert res.tip_link == "hand" and res.robot.dof == 3
    assert any("branches there into finger_l, finger_r" in n for n in res.notes)


def test_two_arms_on_a_torso_still_need_tip(tmp_path):
    from denavit import ParseError
    from denavit.interop import import_urdf

    arms = [("t", "revolute", "base", "torso", 'xyz="0 0 0.5"')]
    for side in "lr":
        arms += [(f"{side}1", "revolute", "torso", f"{side}a", 'xyz="0 0.2 0"'),
                 (f"{side}2", "revolute", f"{side}a", f"{side}b", 'xyz="0.3 0 0"')]
    with pytest.raises(ParseError, match=r"choose the end link with --tip \(leaves: lb, rb\)"):
        import_urdf(_urdf(arms))


def _example_robot(rel):
    from test_urdf_examples import _robots_dir

    return str(_robots_dir() / rel)


def test_example_robot_data_ur5_and_panda_import_without_tip(capsys, tmp_path):
    path = _example_robot("ur_description/urdf/ur5_robot.urdf")
    code, out, err = run(capsys, "import-urdf", path, "-o", str(tmp_path / "ur5.yaml"))
    assert code == 0, err
    assert "world -> tool0" in out and "note: end link tool0 (chosen:" in out
    code, out, err = run(capsys, "import-urdf", _example_robot("panda_description/urdf/panda.urdf"))
    assert code == 0, err
    assert "panda_link0 -> panda_hand " in out and "note: end link panda_hand (chosen:" in out


def test_urdf_rounded_right_angles_are_right_angles_in_the_table_and_the_file(capsys, tmp_path):
    import numpy as np

    import denavit

    path = _example_robot("ur_description/urdf/ur5_robot.urdf")
    assert "1.57079632679" in open(path).read()  # the file's pi/2, 4.9e-12 short
    code, out, _ = run(capsys, "import-urdf", path, "-o", str(tmp_path / "ur5.yaml"))
    written = (tmp_path / "ur5.yaml").read_text()
    table = [line for line in out.splitlines() if " revolute " in line or line.startswith("tool:")]
    assert code == 0 and len(table) == 6 and not any("e-1" in line for line in table), table  # no tool line either
    assert [line.split()[5] for line in table] == ["q1", "q2", "q3", "q4", "q5", "q6"]
    assert re.findall(r"theta: ([^,]*)", written) == ["q", "q", "q", "q", "q", "q + pi"] and "tool" not in written
    robot = denavit.load_robot(str(tmp_path / "ur5.yaml"))
    offsets = np.array([link.theta for link in robot.links] + [link.alpha for link in robot.links])
    assert np.all(np.remainder(offsets, np.pi / 2) == 0)  # exactly multiples of pi/2
    assert np.array_equal(robot.tool_matrix, np.eye(4))


def test_snapping_leaves_real_offsets_alone():
    import math

    from denavit.interop._urdf_snap import snap_angle

    assert snap_angle(1.57079632679) == math.pi / 2 and snap_angle(-3.14159265358) == -math.pi
    assert snap_angle(4.9e-12) == 0.0 and snap_angle(1e-8) == 1e-8 and snap_angle(0.3) == 0.3


# --- workspace pictures: the axes end where the image does ------------------------------------------------------

@pytest.mark.parametrize("name", ["puma560", "planar3r", "stanford"])
def test_occupancy_panels_do_not_run_past_their_image(name):
    pytest.importorskip("matplotlib")
    import matplotlib

    matplotlib.use("Agg")
    import denavit
    from denavit.scale import occupancy
    from denavit.viz import plot_occupancy

    fig = plot_occupancy(occupancy(denavit.load_robot(name), 20_000, seed=0), name)
    fig.canvas.draw()
    panels = [ax for ax in fig.axes if ax.images]
    assert len(panels) == (1 if name == "planar3r" else 3)
    for ax in panels:
        x0, x1, y0, y1 = ax.images[0].get_extent()
        (a, b), (c, d) = ax.get_xlim(), ax.get_ylim()
        tol = 1e-9 * (x1 - x0)
        assert x0 - tol <= a < b <= x1 + tol and y0 - tol <= c < d <= y1 + tol, (ax.get_title(), (a, b, c, d),
                                                                                  (x0, x1, y0, y1))
    import matplotlib.pyplot as plt

    plt.close(fig)


# --- long formulas broken over lines -------------------------------------------------------------------------------

def _report_argv(out):
    from test_report import _readme_first_command

    argv = _readme_first_command()  # the README's `denavit report puma560 ... -o report.html`
    assert argv[:3] == ["denavit", "report", "puma560"]
    return [a if a != "report.html" else str(out) for a in argv[1:]]


@pytest.mark.browser
def test_no_formula_of_the_readme_report_is_wider_than_its_column_in_chromium(tmp_path, capsys):
    """Chromium at 1,280 px: every display formula fits the report's 960-px column (before: 29 of 153 wider,
    up to 29,134 px), and KaTeX typesets all of them (the broken ones are `aligned` blocks)."""
    from test_report import CHROMIUM, CI

    try:
        from playwright.sync_api import sync_playwright
    except ImportError:
        pytest.skip("playwright is not installed")
    if not shutil.which(CHROMIUM) and not os.path.exists(CHROMIUM):
        if CI:
            pytest.fail(f"no chromium at {CHROMIUM} under CI")
        pytest.skip(f"no chromium at {CHROMIUM}")
    out = tmp_path / "r.html"
    assert main(_report_argv(out)) == 0
    capsys.readouterr()
    with sync_playwright() as pw:
        b = pw.chromium.launch(executable_path=CHROMIUM, headless=True,
                               args=["--headless", "--no-sandbox", "--disable-gpu", "--no-first-run"])
        page = b.new_page(viewport={"width": 1280, "height": 900})
        page.goto(out.as_uri())
        page.wait_for_function("document.querySelectorAll('.katex').length > 0")
        sizes = page.evaluate("""() => Array.from(document.querySelectorAll('.math-display')).map(el => {
            const k = el.querySelector('.katex-display .katex-html');
            return [el.scrollWidth, el.clientWidth, k ? k.scrollWidth : -1,
                    (el.querySelector('annotation') || {}).textContent || ''];})""")
        errors = page.evaluate("document.querySelectorAll('.katex-error').length")
        b.close()
    assert errors == 0 and len(sizes) > 100
    assert {s[1] for s in sizes} == {960}  # the column (60rem) at this viewport
    wide = [(s[0], s[3][:120]) for s in sizes if s[0] > s[1] or s[2] > s[1]]
    assert wide == [], wide
    assert sum("\\begin{aligned}" in s[3] for s in sizes) >= 20  # the long ones were broken, not dropped


def test_broken_formulas_keep_every_term_and_break_only_before_a_sign():
    import sympy as sp

    from denavit.report import Equation, math_of

    x = sp.symbols("x1:60")
    expr = sum(x[i] * x[i + 1] * sp.cos(x[i + 2]) for i in range(50)) - 3 * x[0]
    text = math_of(Equation("c_{1}", expr))
    assert text.startswith("\\begin{aligned}c_{1} &= ") and text.endswith("\\end{aligned}")
    rows = text[len("\\begin{aligned}"):-len("\\end{aligned}")].split(" \\\\ ")
    assert len(rows) > 3 and all(r.startswith("&\\quad + ") or r.startswith("&\\quad - ") for r in rows[1:])
    joined = " ".join([rows[0].split("&= ", 1)[1]] + [r[len("&\\quad "):] for r in rows[1:]])
    assert joined == sp.latex(expr).replace("\\left(", "\\bigl(").replace("\\right)", "\\bigr)")
    assert math_of(Equation("y", x[0] + x[1])) == "y = x_{1} + x_{2}"  # short ones unchanged


def test_a_wide_matrix_is_written_entry_by_entry_under_the_names_of_its_left_side():
    import sympy as sp

    from denavit.report import Equation, math_of

    x = sp.symbols("x1:40")
    M = sp.Matrix(2, 2, [sum(x[k + i] * x[k + i + 1] for i in range(12)) for k in range(4)])
    text = math_of(Equation("\\begin{bmatrix}m_{11} & m_{12}\\\\m_{21} & m_{22}\\end{bmatrix}", M))
    labels = re.findall(r"(?:^|\\\\ )(m_{\d\d}) &= ", text.replace("\\begin{aligned}", ""))
    assert labels == ["m_{11}", "m_{12}", "m_{21}", "m_{22}"]
    text = math_of(Equation("J", M))
    assert "\\left[J\\right]_{12} &= " in text


#: LaTeX engines the PDF check can run offline (tectonic fetches its packages on first use).
_TEX = next((e for e in ("pdflatex", "lualatex", "xelatex") if shutil.which(e)), None)
#: LaTeX's own report of a line wider than the text: "Overfull \\hbox (12.3pt too wide) in paragraph at lines
#: 5--9", "... in alignment at lines ...", or "... detected at line 40" (display mathematics).
_OVERFULL = re.compile(r"Overfull \\hbox \(([\d.]+)pt too wide\) (in paragraph|in alignment|detected) at lines? ([\d-]+)")


@pytest.mark.slow
@pytest.mark.skipif(_TEX is None, reason="no LaTeX engine (pdflatex, lualatex, xelatex)")
def test_pdf_report_has_no_formula_wider_than_the_text(tmp_path, capsys):
    """The README's puma560 report as LaTeX, compiled with every formula at its natural size: the report wraps
    displays in ``adjustbox{max width=\\linewidth}``, which would shrink a formula too wide for the page (to
    unreadable type) rather than let it overflow, so the check takes that wrapper out and reads LaTeX's log:
    no line, formula or alignment row wider than the text (before the breaking at + and -, commit 4b3ea7b: 30
    boxes, up to 14,879 pt too wide, c_1 — shrunk some 30-fold in the PDF; after it: none, pdflatex)."""
    import subprocess

    out = tmp_path / "r.tex"
    assert main([a if not a.endswith(".html") else str(out) for a in _report_argv(tmp_path / "r.html")]) == 0
    capsys.readouterr()
    tex = out.read_text(encoding="utf-8")
    shrink = "\\begin{adjustbox}{max width=\\linewidth}"
    assert tex.count(shrink) > 50 and "\\begin{align*}" in tex
    (tmp_path / "natural.tex").write_text(tex.replace(shrink, "\\begin{adjustbox}{}"), encoding="utf-8")
    run = subprocess.run([_TEX, "-interaction=nonstopmode", "-halt-on-error", "natural.tex"], cwd=tmp_path, check=False,
                         capture_output=True, text=True, timeout=600)
    log = (tmp_path / "natural.log").read_text(errors="replace")
    assert run.returncode == 0 and "Output written on natural.pdf" in log, run.stdout[-2000:]
    over = [(float(w), kind, lines) for w, kind, lines in _OVERFULL.findall(log)]
    assert log.count("Overfull \\hbox") == len(over)  # every one was read
    assert [o for o in over if o[0] > 1.0] == [], over


def test_the_overfull_reader_reads_every_form_latex_writes():
    log = ("Overfull \\hbox (12.5pt too wide) in paragraph at lines 5--9\n"
           "Overfull \\hbox (3.0pt too wide) detected at line 40\n"
           "Overfull \\hbox (0.7pt too wide) in alignment at lines 61--70\n")
    assert [(float(w), k) for w, k, _ in _OVERFULL.findall(log)] == [(12.5, "in paragraph"), (3.0, "detected"),
                                                                       (0.7, "in alignment")]
