"""The second newcomer pass of issue 31 (item 4): what a new user met reading the README and docs/*.md top to
bottom in a fresh clone and venv, each with the test that fails on the code before its fix."""

from __future__ import annotations

import pytest

from denavit.cli import main


def run(capsys, *argv):
    code = main(list(argv))
    out, err = capsys.readouterr()
    return code, out, err


# --- check REPORT: an --arm for a section the report does not have ---------------------------------------------------

def test_an_arm_given_for_a_section_the_report_lacks_is_refused_naming_its_sections(capsys, tmp_path):
    """``--arm 7=planar2r`` on a report of sections 1-4 was silently ignored (the report judged against its own
    table, as if --arm had not been given); a typo in SECTION must say so."""
    report = tmp_path / "hw.md"
    report.write_text("# Homework\n\n" + "".join(f"## {k}. Part {k}\n\nWords.\n\n" for k in range(1, 5)),
                      encoding="utf-8")
    code, out, err = run(capsys, "check", str(report), "--arm", "7=planar2r")
    assert code == 2 and out == "" and len(err.strip().splitlines()) == 1 and "Traceback" not in err
    assert "no section '7'" in err and "1, 2, 3, 4" in err
    code, out, _ = run(capsys, "check", str(report), "--arm", "1=planar2r")  # a section it has: used
    assert code == 0 and "--arm 1=planar2r" in out


def test_a_reports_arms_are_listed_in_the_order_of_its_sections():
    """Sections given one arm each are listed top to bottom (they came out by the length of their sections:
    report 004's eight arms as 6, 4, 2, 5, 1, 8, 3, 7 in the checked page)."""
    from denavit.grade import grade_text
    from denavit.io import load_robot

    names = ["planar2r-mdh", "planar3r-mdh", "spherical-wrist", "articulated-rrr"]
    body = [5, 1, 9, 3]  # lines of text per section: lengths that do not grow with the section number
    text = "".join(f"## {k}. Exercise\n\n" + "Some words.\n\n" * n for k, n in enumerate(body, start=1))
    report = grade_text(text, "md", arms={str(k): load_robot(name) for k, name in enumerate(names, start=1)})
    assert [a.name for a in report.arms] == names
    assert [a.line for a in report.arms] == sorted(a.line for a in report.arms)


def test_the_readme_names_every_extra_the_package_defines():
    """README's "Install options" named 4 of the 10 extras of pyproject.toml (no `fast`, `scale`, `xacro`, ...),
    while the docs and error messages send the reader to them."""
    from pathlib import Path

    tomllib = pytest.importorskip("tomllib")
    root = Path(__file__).parents[1]
    extras = tomllib.loads((root / "pyproject.toml").read_text(encoding="utf-8"))["project"]["optional-dependencies"]
    readme = (root / "README.md").read_text(encoding="utf-8")
    section = readme[readme.index("## Install options"):]
    assert len(extras) >= 5 and [e for e in extras if f"`{e}`" not in section] == []


# --- a mistyped command, option or choice -----------------------------------------------------------------------

def test_a_mistyped_command_gets_did_you_mean_and_no_list_cut_in_a_name(capsys):
    """`denavit jacobain` listed the 26 commands cut in the middle by the one-line limit ('jacobian' ... ,
    'dynamics': velocity, statics and singularities lost) and offered no nearest name."""
    code, out, err = run(capsys, "jacobain", "puma560")
    assert code == 2 and out == "" and len(err.strip().splitlines()) == 1
    assert "did you mean jacobian?" in err and " ... " not in err and "denavit --help" in err
    code, _, err = run(capsys, "ik", "puma560", "--method", "analitic", "--from-q", "0,0,0,0,0,0")
    assert code == 2 and "did you mean analytic?" in err and "choose from auto, analytic, numeric" in err


def test_a_mistyped_option_is_reported_by_its_command_with_the_nearest_option(capsys):
    """`denavit fk puma560 --frams` said `denavit: error: unrecognized arguments: --frams` (the top parser's
    name and help, no hint)."""
    code, out, err = run(capsys, "fk", "puma560", "--frams")
    assert code == 2 and out == "" and len(err.strip().splitlines()) == 1
    assert err.startswith("denavit fk: error: unrecognized arguments: --frams (did you mean --frames?)")
    assert "denavit fk --help" in err
    code, _, err = run(capsys, "fk", "puma560", "--zzzzzz")
    assert code == 2 and "did you mean" not in err and err.startswith("denavit fk: error: unrecognized")


# --- the report's friction in decimals, as M, c, g ---------------------------------------------------------------

_ARM4 = """name: arm4
convention: standard
joints:
  - {a: 0.5, alpha: 0, d: 0, theta: q, inertia: {mass: 1, com: [0, 0, 0], inertia: [0.005, 0.005, 0.01, 0, 0, 0],
     viscous: 5.801821768, coulomb: 25.9836065}}
""" + "".join(f"  - {{a: 0.{k}, alpha: 0, d: 0, theta: q, inertia: {{mass: 1, com: [0, 0, 0], "
              f"inertia: [0.005, 0.005, 0.01, 0, 0, 0]}}}}\n" for k in (4, 3, 2))


@pytest.mark.slow  # a symbolic 4-joint derivation: about 3 s
def test_report_friction_is_written_in_decimals_like_the_rest_of_the_dynamics(tmp_path):
    """The README's puma560 report wrote tau_f as 725227721 qd1 / 125000000 + 51967213 sign(qd1) / 2000000 (the
    exact decimals the symbolic engine keeps) beside M, c, g in decimals; the file says 5.801821768, 25.9836065."""
    import denavit
    from denavit.report import derive

    path = tmp_path / "arm4.yaml"
    path.write_text(_ARM4, encoding="utf-8")
    d = derive(denavit.load_robot(str(path)), topics=["dynamics"])
    (tau_f,) = [st for st in d.section("dynamics").steps if getattr(st, "lhs", "") == "\\tau_f(\\dot q)"]
    text = str(tau_f.expr)
    assert "5.80182 \\dot{q}_{1}" in text and "25.9836 \\operatorname{sign}" in text, text
    assert "\\frac" not in text and "125000000" not in text


def test_a_name_in_q_of_an_arm_without_poses_gets_the_values_error(capsys, tmp_path):
    """`-q "O"` on a one-joint arm without named poses said `'O' is neither 1 joint values nor a named pose of p
    (its poses: none)`: a pose cannot be meant there, and the value's own error names the unknown symbol."""
    arm = tmp_path / "p.yaml"
    arm.write_text("name: p\nconvention: standard\njoints:\n  - {a: 0.5, alpha: 0, d: 0, theta: q}\n", encoding="utf-8")
    code, out, err = run(capsys, "fk", str(arm), "-q", "O")
    assert code == 2 and out == "" and "unknown symbol 'O' (known: pi)" in err and "pose" not in err
    code, _, err = run(capsys, "fk", "puma560", "-q", "qx")  # an arm with poses: the pose names are offered
    assert code == 2 and "neither 6 joint values nor a named pose" in err and "qz, qr, qs, qn" in err


def test_the_correction_of_a_jacobian_read_as_three_rows_shows_those_rows(capsys, tmp_path):
    """The homework's 3-row J (rows vx, vy, ωz) with a slip was corrected by the whole 6-row J0, three rows of
    zeros the student never wrote among them; the correction is now in the rows the claim was read as."""
    claims = tmp_path / "j.yaml"
    claims.write_text("claims:\n  - quantity: jacobian\n    value: |\n"
                      "      \\begin{bmatrix} -L_1 s_1 - L_2 s_{12} & -L_2 s_{12} \\\\ L_1 c_1 + L_2 c_{12} & L_1 c_{12}"
                      " \\\\ 1 & 1 \\end{bmatrix}\n", encoding="utf-8")
    code, out, _ = run(capsys, "check", "planar2r", str(claims))
    assert code == 0 and "INCORRECT" in out and "read as the rows (vx, vy, ωz)" in out
    (fix,) = [line.split("(LaTeX): ", 1)[1] for line in out.splitlines() if "correct formula (LaTeX)" in line]
    rows = fix.removeprefix("\\begin{bmatrix}").removesuffix("\\end{bmatrix}").split("\\\\")
    # Spong's planar 2R, rows (vx, vy, ωz): [-L1 S1 - L2 S12, -L2 S12; L1 C1 + L2 C12, L2 C12; 1, 1]
    assert len(rows) == 3 and rows[2].replace(" ", "") == "1&1", fix
    assert rows[1].replace(" ", "").endswith("&C_{12}L_{2}"), fix


def test_symbolic_equations_of_motion_fit_the_terminal_and_read_back_the_same(capsys, monkeypatch):
    """`dynamics planar3r --symbolic` wrote c[1] on one 228-column line; now every line fits 80 columns, broken
    before a top-level + or − and aligned under the expression, and re-joined it is the unwrapped text (the JSON's
    symbolic_text, which stays whole)."""
    import json
    import re

    from denavit.cli import main

    monkeypatch.setenv("COLUMNS", "80")
    assert main(["dynamics", "planar3r", "--symbolic"]) == 0
    out = capsys.readouterr().out
    assert max(len(line) for line in out.splitlines()) <= 80
    assert main(["dynamics", "planar3r", "--symbolic", "--json"]) == 0
    whole = json.loads(capsys.readouterr().out)["symbolic_text"]
    assert max(len(line) for line in whole.splitlines()) > 80  # the case this is about
    joined = re.sub(r"\n {4,}(?=[+-] )", " ", out)
    assert whole in joined


def test_singularities_prose_fits_the_terminal_and_reads_back_the_same(capsys, monkeypatch):
    """`singularities puma560` wrote its notes on lines up to 154 columns; its prose now fits 80 columns (the
    determinant, a formula, is sympy's picture and is not broken), and re-joined it says what the JSON says."""
    import json
    import re

    from denavit.cli import main

    monkeypatch.setenv("COLUMNS", "80")
    assert main(["singularities", "puma560"]) == 0
    out = capsys.readouterr().out
    prose = [line for line in out.splitlines() if "⋅" not in line and "⎡" not in line and "⎢" not in line
             and "⎣" not in line]
    assert max(len(line) for line in prose) <= 80
    assert main(["singularities", "puma560", "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    joined = re.sub(r"\n +", " ", out)
    assert len(f"matrix: {data['matrix_note']}") > 80 and f"matrix: {data['matrix_note']}" in joined
    for cond in data["conditions"]:
        assert f"kind: {cond['kind']} — {cond['explanation']}" in joined
