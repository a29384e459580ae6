"""The report / check command lines: files written, JSON, exit codes and one-line errors."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import numpy as np
import pytest

import denavit as dn
from denavit.cli import main

EXAMPLES = Path(__file__).resolve().parents[1] / "examples" / "claims"


def _one_line_error(capsys, *words):
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "Traceback" not in err, err
    for w in words:
        assert w in err, err


@pytest.mark.parametrize("suffix", ["md", "html", "tex"])
@pytest.mark.slow
def test_cli_report_writes_each_format(tmp_path, capsys, suffix):
    out = tmp_path / f"r.{suffix}"
    code = main(["report", "planar3r", "-q", "0, pi/4, -pi/2", "--qd", "1, 0, 0", "--wrench", "1,0,0,0,0,0",
                 "-o", str(out)])
    assert code == 0, capsys.readouterr().err
    assert out.exists() and out.stat().st_size > 1000
    assert f"wrote {out}" in capsys.readouterr().out


def test_cli_report_json_numbers_equal_fk(capsys):
    assert main(["report", "report000-6r", "-q", "0, 45, 60, -90, -60, 30", "--deg", "--topics", "case", "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    q = np.radians([0, 45, 60, -90, -60, 30])
    np.testing.assert_allclose(data["q"], q, atol=1e-15)
    (case,) = data["sections"]
    T = [s for s in case["steps"] if s["type"] == "numbers" and s["lhs"] == "{}^{0}T_{7}"][0]["values"]
    np.testing.assert_allclose(T, dn.forward_kinematics(dn.load_robot("report000-6r"), q), atol=1e-12)
    assert any("\\sqrt{3}" in s.get("latex", "") for s in case["steps"])


def test_cli_report_default_robot_to_stdout(capsys):
    assert main(["report", "planar2r", "--topics", "model,fk"]) == 0
    out = capsys.readouterr().out
    assert out.startswith("# Kinematics and dynamics of planar2r") and "p_x" in out


def test_cli_report_bad_inputs(tmp_path, capsys):
    assert main(["report", "planar2r", "-q", "1, 2, 3", "-o", str(tmp_path / "r.md")]) == 2
    _one_line_error(capsys, "q: expected 2 values")
    assert main(["report", "planar2r", "-q", "0, 9", "-o", str(tmp_path / "r.md")]) == 2
    _one_line_error(capsys, "outside its limits")
    assert main(["report", "planar2r", "-o", str(tmp_path / "r.docx")]) == 2
    _one_line_error(capsys, ".md, .tex, .html or .pdf")
    assert main(["report", "planar2r", "--wrench", "1,2", "-o", str(tmp_path / "r.md")]) == 2
    _one_line_error(capsys, "wrench")
    assert main(["report", "planar2r", "--topics", "fk,bogus"]) == 2
    _one_line_error(capsys, "unknown report topic 'bogus'")
    assert main(["report", "no-such-robot"]) == 2
    _one_line_error(capsys, "unknown robot")


def test_cli_report_pdf_needs_an_engine(tmp_path, capsys, monkeypatch):
    out = tmp_path / "r.pdf"
    if shutil.which("pdflatex") or shutil.which("tectonic") or shutil.which("xelatex") or shutil.which("lualatex"):
        assert main(["report", "planar2r", "--topics", "model,links,fk", "-o", str(out)]) == 0
        assert out.read_bytes().startswith(b"%PDF")
    monkeypatch.setenv("PATH", str(tmp_path))  # no engine on PATH
    capsys.readouterr()
    out2 = tmp_path / "r2.pdf"  # a new name, so that "not written" can be seen
    assert main(["report", "planar2r", "--topics", "model", "-o", str(out2)]) == 1
    _one_line_error(capsys, "LaTeX engine")
    assert not out2.exists()


@pytest.mark.parametrize("example", sorted(p.name for p in EXAMPLES.glob("*.yaml")))
@pytest.mark.slow
def test_cli_check_examples_run_and_judge_every_claim(example, capsys):
    import yaml

    path = EXAMPLES / example
    robot = yaml.safe_load(path.read_text())["robot"]
    assert main(["check", robot, str(path), "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["summary"]["unreadable"] == 0
    assert sum(data["summary"].values()) == len(data["claims"]) > 0
    for c in data["claims"]:
        if c["verdict"] == "incorrect":  # which entries differ, or which solutions/configurations are missing
            assert (c["entries"] and c["counterexample"]["q"]) or c.get("missing")


# --- output paths (issues 14, 29): checked before any work; replaced (with the pictures) only after it -------------

def _hostile():
    import sys

    sys.path.insert(0, str(Path(__file__).resolve().parent))
    import _hostile

    return _hostile


@pytest.mark.parametrize("suffix", ["md", "tex"])
def test_cli_report_no_clobber_refuses_its_picture(tmp_path, suffix):
    """``report -o r.md --no-clobber`` writes r-planar2r-arm.png beside it: an existing one is refused (before the
    derivation)."""
    h = _hostile()
    o = h.run_cli(["report", "planar2r", "-o", f"r.{suffix}", "--no-clobber"], tmp_path,
                  {"r-planar2r-arm.png": b"my picture"})
    h.assert_refused(o, mentions=["r-planar2r-arm.png", "exists", "--no-clobber"])
    assert (tmp_path / "r-planar2r-arm.png").read_bytes() == b"my picture"
    assert o.seconds < 3, o.describe()  # refused before any work


def test_cli_report_writes_the_picture_it_names(tmp_path):
    h = _hostile()
    o = h.run_cli(["report", "planar2r", "--topics", "model,figures", "-o", "r.md"], tmp_path, {})
    assert o.code == 0, o.describe()
    names = sorted(p.name for p in tmp_path.iterdir())
    assert names == ["r-planar2r-arm.png", "r.md"], names  # the name checked beforehand is the one written
    assert "(r-planar2r-arm.png)" in (tmp_path / "r.md").read_text()
    png = (tmp_path / "r-planar2r-arm.png").read_bytes()
    (tmp_path / "r-planar2r-arm.png").write_bytes(b"old picture")
    o = h.run_cli(["report", "planar2r", "--topics", "model,figures", "-o", "r.md"], tmp_path, {})
    assert o.code == 0 and sorted(p.name for p in tmp_path.iterdir()) == names, o.describe()
    assert (tmp_path / "r-planar2r-arm.png").read_bytes() == png  # the picture replaced with the report


@pytest.mark.parametrize("out, files, words", [
    ("r.docx", {}, ["r.docx", ".md"]),
    ("missing/r.md", {}, ["missing"]),
    ("r.md", {"r.md": "my notes"}, ["r.md", "exists", "--no-clobber"]),
    ("d.md", {"d.md/keep": "x"}, ["not a regular file"]),
])
def test_cli_report_bad_output_refused_before_the_work(tmp_path, out, files, words):
    h = _hostile()
    o = h.run_cli(["report", "report000-6r", "-o", out, "--no-clobber"], tmp_path, files)
    h.assert_refused(o, mentions=words)
    assert o.seconds < 3, o.describe()


def test_cli_report_topics_without_figures_ignore_an_existing_picture(tmp_path):
    h = _hostile()
    o = h.run_cli(["report", "planar2r", "--topics", "model", "-o", "r.md"], tmp_path, {"r-planar2r-arm.png": b"x"})
    assert o.code == 0, o.describe()
    assert (tmp_path / "r-planar2r-arm.png").read_bytes() == b"x"


@pytest.mark.parametrize("q_text", ["0 , pi / 4", "0, (pi/2)", "[0; pi/4]", "(0 0.5)"])
def test_cli_report_reads_q_as_every_other_command_does(tmp_path, capsys, q_text):
    """The report's numeric case is the q that ``fk`` reads from the same text (the report used its own splitter,
    which cut ``pi / 4`` at the spaces and dropped the closing bracket of ``(pi/2)``)."""
    from denavit.io import parse_values

    out = tmp_path / "r.md"
    assert main(["report", "planar2r", "-q", q_text, "--topics", "fk", "-o", str(out)]) == 0
    capsys.readouterr()
    shown = out.read_text().split("q = (", 1)[1].split(")", 1)[0]
    np.testing.assert_allclose(parse_values(shown, 2), parse_values(q_text, 2), atol=1e-12)
