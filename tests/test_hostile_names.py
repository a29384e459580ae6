"""A name is data, never syntax (issue 29, item 3): a hostile-name corpus through every writer.

Each name of :data:`CORPUS` (newline, CR, NEL U+0085, U+2028/2029, the bidi override U+202E, ESC, ``---``, quotes,
``#``, ``*/``, ``\"\"\"``, ...) is given to every writer of denavit: ``save_robot`` (YAML and JSON),
``import-urdf`` (the name from ``<robot name=...>``), ``import-table --name``, ``convert``, ``export-urdf``,
``export-mjcf``, ``export --lang c|python`` and ``report`` (md, tex, html), and printed by ``show``.  What is
reloaded equals what was written (the truth is the original object); a format that cannot carry a character
(XML 1.0 has no ESC, not even as ``&#27;``) refuses it with one line; nothing is printed raw to the terminal.
"""

from __future__ import annotations

import ast
import re
import shutil
import subprocess
from pathlib import Path
from xml.sax.saxutils import quoteattr

import numpy as np
import pytest

import denavit
from denavit.interop import import_urdf, to_mjcf, to_urdf
from denavit.io import dump_robot, load_robot, save_robot

from _hostile import assert_refused, run_cli
from test_lossless_files import plain_model

CORPUS = {
    "newline-base": "arm\nbase: [[1,0,0,5],[0,1,0,0],[0,0,1,0],[0,0,0,1]] #",
    "cr": "arm\rtool: [[1,0,0,0],[0,1,0,0],[0,0,1,9],[0,0,0,1]]",
    "nel": "arm\x85gravity: [0, 0, 99]",
    "line-separator": "arm\u2028joints: []",
    "paragraph-separator": "arm\u2029x",
    "bidi-override": "arm\u202eevil\u202c",
    "escape": "arm\x1b[2J\x1b]0;owned\x07",
    "document-marker": "a---b\n---\n...",
    "quotes": "a\"b'c`d",
    "hash": "a # b #",
    "c-comment-end": "a*/b/*c",
    "docstring-end": 'a"""b\\N{x}',
    "xml": "<!-- a --> &amp; </robot>",
    "dash-end": "a-",
    "latex": "x$\\input{/etc/passwd}$}{",
}
#: Characters XML 1.0 cannot carry at all (no character reference either): URDF/MJCF writers refuse these names.
NOT_XML = re.compile("[\x00-\x08\x0b\x0c\x0e-\x1f\ufffe\uffff]")
#: What must never reach a file or the terminal raw (denavit._text.UNSAFE, written out again here).
RAW = re.compile("[\x00-\x08\x0b-\x1f\x7f-\x9f\u061c\u200e\u200f\u2028\u2029\u202a-\u202e\u2066-\u2069]")

names = pytest.mark.parametrize("name", list(CORPUS.values()), ids=list(CORPUS))


def _named(name: str, base: str = "puma560") -> denavit.DHRobot:
    robot = load_robot(base)
    return robot.replace(name=name, description=f"about {name}")


def _same(a: denavit.DHRobot, b: denavit.DHRobot) -> bool:
    """Equal models, up to the file path and the expression texts a reader records (``d: 0.2`` read from a file
    keeps the text "0.2"; the same arm built in memory has none)."""
    return plain_model(a.replace(source="")) == plain_model(b.replace(source=""))


@names
@pytest.mark.parametrize("suffix", [".yaml", ".json"])
def test_save_robot_round_trips_the_name(name, suffix, tmp_path):
    robot = _named(name)
    path = tmp_path / f"arm{suffix}"
    save_robot(robot, path)
    text = path.read_text(encoding="utf-8")
    assert not RAW.search(text)
    back = load_robot(path)
    assert _same(back, robot)
    assert back.name == name and back.base == robot.base and back.tool == robot.tool and back.gravity == robot.gravity


@names
def test_yaml_header_comment_is_one_line(name):
    first, second = dump_robot(_named(name)).splitlines()[:2]
    assert first.startswith("# ") and first.endswith(": written by denavit")
    assert second.startswith("name: ")


def _urdf(name: str) -> str:
    return (f"<robot name={quoteattr(name)}><link name=\"a\"/><link name=\"b\"/>"
            "<joint name=\"j\" type=\"revolute\"><parent link=\"a\"/><child link=\"b\"/><axis xyz=\"0 0 1\"/>"
            "<origin xyz=\"0.1 0 0.2\" rpy=\"0 0 0\"/><limit lower=\"-1\" upper=\"1\" effort=\"1\" velocity=\"1\"/></joint>"
            "</robot>")


@names
def test_import_urdf_writes_the_name_as_data(name, tmp_path):
    """The issue's attack: <robot name="arm&#10;base: [[1,0,0,5],...] #"> must not give the written file a base."""
    if NOT_XML.search(name):
        o = run_cli(["import-urdf", "arm.urdf", "-o", "arm.yaml"], tmp_path,
                    {"arm.urdf": _urdf(name).replace("\x1b", "&#27;").replace("\x07", "&#7;")})
        assert_refused(o, mentions=["arm.urdf"])
        return
    o = run_cli(["import-urdf", "arm.urdf", "-o", "arm.yaml"], tmp_path, {"arm.urdf": _urdf(name)})
    assert o.code == 0, o.describe()
    assert not RAW.search(o.out)
    expected = import_urdf(str(tmp_path / "arm.urdf")).robot
    back = load_robot(tmp_path / "arm.yaml")
    assert back.name == name and _same(back, expected)
    assert np.array_equal(back.base_matrix, expected.base_matrix)


@names
@pytest.mark.parametrize("suffix", [".yaml", ".json"])
def test_import_table_name_round_trips(name, suffix, tmp_path):
    table = "| a | alpha | d | theta |\n|---|---|---|---|\n| 0 | 90 | 0.3 | q1 |\n| 0.4 | 0 | 0 | q2 |\n"
    o = run_cli(["import-table", "t.md", "--name", name, "-o", f"arm{suffix}"], tmp_path, {"t.md": table})
    assert o.code == 0, o.describe()
    text = (tmp_path / f"arm{suffix}").read_text(encoding="utf-8")
    assert not RAW.search(text) and not RAW.search(o.out)
    back = load_robot(tmp_path / f"arm{suffix}")
    expected = denavit.tables.import_table(table, name=name).robot
    assert back.name == name and _same(back, expected)


@names
def test_convert_keeps_the_name_as_data(name, tmp_path):
    from denavit._convert import convert_convention

    robot = _named(name)
    save_robot(robot, tmp_path / "in.yaml")
    o = run_cli(["convert", "in.yaml", "--to", "modified", "-o", "out.yaml"], tmp_path)
    assert o.code == 0, o.describe()
    back = load_robot(tmp_path / "out.yaml")
    expected = convert_convention(load_robot(tmp_path / "in.yaml"), "modified")
    assert back.name == name and _same(back, expected)


@names
def test_export_urdf_and_mjcf_carry_the_name_or_refuse_it(name, tmp_path):
    from xml.etree import ElementTree

    robot = _named(name)
    if NOT_XML.search(name):
        for cmd in ("export-urdf", "export-mjcf"):
            save_robot(robot, tmp_path / "arm.yaml", overwrite=True)
            o = run_cli([cmd, "arm.yaml", "-o", "arm.xml" if cmd == "export-mjcf" else "arm.urdf"], tmp_path)
            assert_refused(o, mentions=["U+001B"])
        return
    urdf = to_urdf(robot)
    back = import_urdf(urdf).robot
    assert back.name == name
    q = np.random.default_rng(1).uniform(-1, 1, (5, robot.dof))
    np.testing.assert_allclose(denavit.forward_kinematics(back, q), denavit.forward_kinematics(robot, q), atol=1e-12)
    comment = re.search(r"<!--(.*?)-->", urdf, re.S).group(1)
    assert "--" not in comment and "\n" not in comment
    mjcf = ElementTree.fromstring(to_mjcf(robot).encode("utf-8"))  # well-formed: expat refuses '--' in a comment
    assert mjcf.attrib["model"] == name


@names
def test_exported_code_is_valid_whatever_the_name(name, tmp_path):
    from denavit.codegen import export_sources

    robot = _named(name, "planar2r")
    py = export_sources(robot, "python")
    (text,) = py.values()
    ast.parse(text)  # a docstring or comment broken open would be a SyntaxError
    assert not RAW.search(text)
    c = export_sources(robot, "c")
    for file, source in c.items():
        assert not RAW.search(source)
        (tmp_path / file).write_text(source)
    cc = shutil.which("cc") or shutil.which("gcc")
    if cc:
        src = next(f for f in c if f.endswith(".c"))
        done = subprocess.run([cc, "-std=c99", "-fsyntax-only", src], cwd=tmp_path, capture_output=True, text=True)
        assert done.returncode == 0, done.stderr


@names
def test_report_titles_are_text_in_every_format(name):
    from denavit.report import derive, render

    d = derive(_named(name, "planar2r"), topics=["model"])
    md, _ = render(d, "md")
    tex, _ = render(d, "tex")
    page, _ = render(d, "html")
    for text in (md, tex, page):
        assert not RAW.search(text)
    title = md.splitlines()[0]
    assert title.startswith("# Kinematics and dynamics of ") and md.splitlines()[1] == ""
    assert not re.search(r"(?<!\\)[$#*`<\[]", title[2:])  # every markup character escaped
    tex_title = next(line for line in tex.splitlines() if line.startswith("\\title{"))
    assert tex_title.endswith("}") and not re.search(r"(?<!\\)\$", tex_title)
    body = tex_title[len("\\title{"):-1]
    assert not re.search(r"(?<!\\)[{}]", body.replace("\\textbackslash{}", "").replace("\\textasciicircum{}", "")
                         .replace("\\textasciitilde{}", ""))
    h1 = re.search(r"<h1>(.*?)</h1>", page, re.S).group(1)
    assert "<" not in h1 and "\n" not in h1
    for text in (md, tex):  # the description's sentence: its $ never opens mathematics (raw LaTeX in a .tex)
        about = next(line for line in text.splitlines() if line.startswith("about "))
        assert not re.search(r"(?<!\\)\$", about)


@names
def test_show_prints_names_escaped(name, tmp_path):
    save_robot(_named(name), tmp_path / "arm.yaml")
    o = run_cli(["show", "arm.yaml"], tmp_path)
    assert o.code == 0, o.describe()
    assert not RAW.search(o.out)
    first = o.out.splitlines()[0]
    assert first.startswith(denavit.display.one_line_text(name))


def test_error_lines_escape_control_characters(tmp_path):
    """A file name holding ESC and U+202E, named in an error line, reaches stderr escaped."""
    o = run_cli(["show", "arm\x1b[2J\u202e.yaml"], tmp_path)
    assert_refused(o)
    assert "\x1b" not in o.err and "\u202e" not in o.err and "\\x1b" in o.err


def test_import_table_of_a_device_says_not_a_regular_file(tmp_path):
    o = run_cli(["import-table", "/dev/zero"], tmp_path)
    assert_refused(o, mentions=["not a regular file"])
    o = run_cli(["import-table", "missing.md"], tmp_path)
    assert_refused(o, mentions=["no such file"])


def test_report_picture_file_name_is_made_of_safe_characters(tmp_path):
    """The arm picture beside a .tex report is named from the robot: its name's }, \\, newline never reach
    \\includegraphics{...} (nor a path)."""
    pytest.importorskip("matplotlib")
    save_robot(_named("x}\\write18{ls} (a)\n#/..", "planar2r"), tmp_path / "arm.yaml")
    o = run_cli(["report", "arm.yaml", "-o", "r.tex", "--topics", "figures"], tmp_path, time_limit=60)
    assert o.code == 0, o.describe()
    pictures = [p.name for p in tmp_path.glob("*.png")]
    assert len(pictures) == 1 and re.fullmatch(r"r-[A-Za-z0-9_.-]+-arm\.png", pictures[0])
    assert f"\\includegraphics[width=0.7\\linewidth]{{{pictures[0]}}}" in (tmp_path / "r.tex").read_text()


@pytest.mark.parametrize("cmd", [["fk", "-q", "0.1, 0.2"], ["jacobian", "-q", "0.1, 0.2"], ["show"],
                                 ["dynamics", "-q", "0.1, 0.2", "--qd", "0, 0", "--qdd", "0, 0"]])
def test_a_name_with_line_breaks_never_breaks_a_commands_output_lines(cmd, tmp_path, capsys):
    """A robot named "evil\\nname: injected" prints on one line (as evil\\nname …), whatever the command."""
    import denavit
    from denavit.cli import main

    path = tmp_path / "evil.yaml"
    denavit.save_robot(denavit.load_robot("planar2r").replace(name="evil\nbase: injected\u2028x\r"), path)
    assert main([cmd[0], str(path), *cmd[1:]]) == 0
    out = capsys.readouterr().out
    assert not any(line.startswith(("base: injected", "x")) for line in out.splitlines())
    assert "\u2028" not in out and "\r" not in out
    assert "evil\\nbase: injected\\u2028x\\r" in out
