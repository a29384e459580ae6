"""Presenters: the DH table (text, Markdown, LaTeX, HTML) and the Jupyter displays of robots and results.

The tables are checked by reading them back: every cell is parsed by the restricted expression reader of
the robot files (``parse_values``, independent of the presenter) and compared with the model's numbers.
"""

from __future__ import annotations

import base64
import re
import sys
from html.parser import HTMLParser

import numpy as np
import pytest

import denavit
from denavit import JointType
from denavit.io import catalogue_names, parse_values

from _random_robots import random_q, random_robot

CATALOGUE = catalogue_names()


class _Tables(HTMLParser):
    """Every <table> of an HTML text as a list of rows of (tag, cell text); also <img> sources."""

    def __init__(self) -> None:
        super().__init__()
        self.tables: list[list[list[tuple[str, str]]]] = []
        self.images: list[str] = []
        self.stack: list[str] = []
        self._cell: list[str] | None = None

    def handle_starttag(self, tag, attrs):
        if tag in ("br", "img"):
            if tag == "img":
                self.images.append(dict(attrs)["src"])
            return
        self.stack.append(tag)
        if tag == "table":
            self.tables.append([])
        elif tag == "tr":
            self.tables[-1].append([])
        elif tag in ("td", "th"):
            self._cell = []

    def handle_endtag(self, tag):
        assert self.stack and self.stack[-1] == tag, f"</{tag}> closes <{self.stack[-1] if self.stack else None}>"
        self.stack.pop()
        if tag in ("td", "th"):
            self.tables[-1][-1].append((tag, "".join(self._cell)))
            self._cell = None

    def handle_data(self, data):
        if self._cell is not None:
            self._cell.append(data)


def parse_html(text: str) -> _Tables:
    p = _Tables()
    p.feed(text)
    p.close()
    assert p.stack == [], f"unclosed tags {p.stack}"
    return p


def _value(cell: str, robot, deg: bool) -> float:
    """A cell read back by the robot-file reader, with the robot's parameters."""
    text = re.sub(r"(\d)π", r"\1*π", cell.replace("°", "deg"))  # 5π/4 is 5*pi/4
    (v,) = parse_values([text], env=robot.parameter_values, deg=False)
    return float(v)


def _offset(cell: str, var: str) -> str:
    assert cell.startswith(var), (cell, var)
    rest = cell[len(var):].strip()
    if not rest:
        return "0"
    assert rest[0] in "+-", cell
    return rest if rest[0] == "-" else rest[1:]


def _check_rows(robot, rows: list[list[str]], deg: bool) -> None:
    """Rows of cells j, joint, a, alpha, d, theta, limits against the model."""
    assert len(rows) == robot.n_rows
    assert sum(r[1] != "fixed" for r in rows) == robot.dof
    k = 0
    for link, r in zip(robot.links, rows):
        j, kind, a, alpha, d, theta, limits = r
        assert kind == link.joint.value
        if link.is_joint:
            k += 1
            assert j == str(k)
            if link.joint is JointType.REVOLUTE:
                theta = _offset(theta, f"q{k}")
            else:
                d = _offset(d, f"q{k}")
        for cell, field in ((a, "a"), (alpha, "alpha"), (d, "d"), (theta, "theta")):
            want = getattr(link, field)
            if deg and field in ("alpha", "theta") and cell != "0":
                assert cell.endswith("°") or any(n in cell for n in robot.parameter_values), cell
            np.testing.assert_allclose(_value(cell, robot, deg), want, rtol=1e-5, atol=1e-9, err_msg=f"{field}: {cell}")
        if link.q_limits is None:
            assert limits == ""
        else:
            lo, hi = limits.removesuffix(" m").strip("[]").split(", ")
            np.testing.assert_allclose([_value(lo, robot, deg), _value(hi, robot, deg)], link.q_limits,
                                       rtol=1e-5, atol=1e-9)


@pytest.mark.parametrize("name", CATALOGUE)
@pytest.mark.parametrize("deg", [False, True])
def test_dh_table_html_of_every_catalogue_arm_reads_back_to_the_model(name, deg):
    robot = denavit.load_robot(name)
    page = parse_html(denavit.dh_table(robot, deg=deg, fmt="html"))
    (table,) = page.tables
    head, *rows = table
    assert all(tag == "th" for tag, _ in head) and len(head) == 7
    assert all(len(r) == 7 and all(tag == "td" for tag, _ in r) for r in rows)
    _check_rows(robot, [[c for _, c in r] for r in rows], deg)


@pytest.mark.parametrize("name", CATALOGUE)
def test_dh_table_text_and_markdown_carry_the_same_rows(name):
    robot = denavit.load_robot(name)
    md = denavit.dh_table(robot, fmt="markdown").splitlines()
    start = next(i for i, line in enumerate(md) if line.startswith("| j |"))
    assert set(md[start + 1]) <= set("|-")
    rows = [[c.strip() for c in line.strip("|").split(" | ")] for line in md[start + 2:start + 2 + robot.n_rows]]
    _check_rows(robot, rows, deg=False)
    text = str(robot)
    assert text == denavit.dh_table(robot)
    assert robot.name in text.splitlines()[0] and robot.convention.value in text.splitlines()[1]
    lines = text.splitlines()
    head = next(i for i, line in enumerate(lines) if line.startswith("j  "))
    for link, line in zip(robot.links, lines[head + 1:head + 1 + robot.n_rows]):
        assert link.joint.value in line.split()
    for key, value in robot.parameters:
        assert f"{key} = {value:.6g}" in text
    assert "gravity: (" in text
    for pose, q in dict(robot.poses).items():  # named poses read back, each value in its joint's unit
        line = next(x for x in lines if x.startswith(f"pose {pose}: "))
        cells = line.split(": ", 1)[1].strip("()").split(", ")
        np.testing.assert_allclose([_value(c, robot, False) for c in cells], q, rtol=1e-5, atol=1e-9)


@pytest.mark.parametrize("seed", range(25))
def test_dh_table_of_random_robots_reads_back(seed):
    rng = np.random.default_rng(seed)
    robot = random_robot(rng)
    for deg in (False, True):
        (table,) = parse_html(denavit.dh_table(robot, deg=deg, fmt="html")).tables
        _check_rows(robot, [[c for _, c in r] for r in table[1:]], deg)
    text = str(robot)
    identity = np.allclose(robot.base_matrix, np.eye(4))
    assert ("base: xyz = (" in text) == (not identity)
    assert ("tool: xyz = (" in text) == (not np.allclose(robot.tool_matrix, np.eye(4)))


def test_dh_table_base_and_tool_lines_give_the_transform_back():
    rng = np.random.default_rng(7)
    robot = random_robot(rng, base_tool=False)
    base = denavit.numeric.transform_from_xyz_rpy([0.1, -0.2, 0.3], [0.4, -0.5, 0.6])
    tool = denavit.numeric.transform_from_xyz_rpy([0.0, 0.0, 0.125], [np.pi / 2, 0, 0])
    robot = robot.replace(base=base, tool=tool)
    text = str(robot)
    for label, T in (("base", base), ("tool", tool)):
        line = next(x for x in text.splitlines() if x.startswith(f"{label}: "))
        m = re.fullmatch(rf"{label}: xyz = \((.*)\) m, rpy = \((.*)\)", line)
        xyz = parse_values(m.group(1))
        rpy = parse_values(m.group(2).replace("π", "pi"))
        np.testing.assert_allclose(denavit.numeric.transform_from_xyz_rpy(xyz, rpy), T, atol=1e-5)


def test_dh_table_latex_rows_and_math_are_balanced():
    for name in ("puma560", "stanford", "panda", "planar2r"):
        robot = denavit.load_robot(name)
        tex = denavit.dh_table(robot, fmt="latex")
        body = tex[tex.index("\\hline", tex.index("\\\\")) + len("\\hline"):tex.index("\\end{tabular}")]
        rows = [r for r in body.split("\\\\") if r.strip() and r.strip() != "\\hline"]
        assert len(rows) == robot.n_rows
        assert all(r.count(" & ") == 6 for r in rows)
        assert tex.count("{") == tex.count("}") and tex.count("$") % 2 == 0
        if any(abs(abs(link.alpha) - np.pi / 2) < 1e-12 for link in robot.links):  # a 90° twist, written exactly
            assert "\\frac{\\pi}{2}" in tex


def test_dh_table_refuses_an_unknown_format():
    with pytest.raises(ValueError, match="choose one of text, markdown, latex, html"):
        denavit.dh_table(denavit.load_robot("planar2r"), fmt="rst")


def test_robot_repr_is_short():
    for name in ("puma560", "panda", "planar2r"):
        robot = denavit.load_robot(name)
        assert repr(robot) == f"DHRobot({name!r}, {robot.dof} joints, {robot.convention.value})"
        assert "inertia" not in repr(robot) and len(repr(robot)) < 60


@pytest.mark.parametrize("name", CATALOGUE)
def test_robot_repr_html_of_every_catalogue_arm(name):
    robot = denavit.load_robot(name)
    page = parse_html(robot._repr_html_())
    assert len(page.tables) == 1 and len(page.tables[0]) == robot.n_rows + 1
    assert len(page.images) == (1 if "matplotlib" in sys.modules or _has_matplotlib() else 0)
    assert robot._repr_markdown_() == denavit.dh_table(robot, fmt="markdown")


def _has_matplotlib() -> bool:
    import importlib.util

    return importlib.util.find_spec("matplotlib") is not None


def test_robot_repr_html_embeds_a_png_of_the_arm():
    pytest.importorskip("matplotlib")
    robot = denavit.load_robot("puma560")
    page = parse_html(robot._repr_html_())
    (src,) = page.images
    assert src.startswith("data:image/png;base64,")
    png = base64.b64decode(src.split(",", 1)[1])
    assert png[:8] == b"\x89PNG\r\n\x1a\n" and len(png) > 1000
    assert len(page.tables[0]) == robot.n_rows + 1


def test_robot_repr_html_without_matplotlib_is_the_table_alone(monkeypatch):
    for mod in [m for m in sys.modules if m == "matplotlib" or m.startswith("matplotlib.")]:
        monkeypatch.setitem(sys.modules, mod, None)
    robot = denavit.load_robot("planar2r")
    page = parse_html(robot._repr_html_())
    assert page.images == [] and len(page.tables) == 1


# --------------------------------------------------------------------------------------------------
# results


def _ik_rows(result) -> tuple[list[str], list[list[str]]]:
    page = parse_html(result._repr_html_())
    (table,) = page.tables
    return [c for _, c in table[0]], [[c for _, c in r] for r in table[1:]]


@pytest.mark.parametrize("name", ["puma560", "ur5", "stanford", "planar3r"])
def test_analytic_ik_html_lists_every_solution_with_branch_and_residuals(name):
    robot = denavit.load_robot(name)
    rng = np.random.default_rng(3)
    q = np.clip(random_q(rng, robot), robot.q_limits[:, 0], robot.q_limits[:, 1])
    result = denavit.analytic_ik(robot, denavit.forward_kinematics(robot, q))
    head, rows = _ik_rows(result)
    assert len(rows) == result.count > 0
    n = robot.dof
    qcols = [head.index(f"q{k + 1}") for k in range(n)]
    for r, sol, branch, pe, oe in zip(rows, result.solutions, result.branches, result.position_error,
                                      result.orientation_error):
        assert r[head.index("branch")] == branch
        np.testing.assert_allclose([float(r[c]) for c in qcols], sol, rtol=1e-5, atol=1e-6)
        assert float(r[head.index("position error [m]")]) == pytest.approx(pe, rel=0.06, abs=1e-300)
        assert float(r[head.index("orientation error [rad]")]) == pytest.approx(oe, rel=0.06, abs=1e-300)
        np.testing.assert_allclose(denavit.forward_kinematics(robot, [float(r[c]) for c in qcols]),
                                   denavit.forward_kinematics(robot, q), atol=1e-4)


def test_analytic_ik_html_of_a_batch_counts_every_pose():
    robot = denavit.load_robot("puma560")
    rng = np.random.default_rng(4)
    qs = np.clip(random_q(rng, robot, (3,)), robot.q_limits[:, 0], robot.q_limits[:, 1])
    result = denavit.analytic_ik(robot, denavit.forward_kinematics(robot, qs))
    head, rows = _ik_rows(result)
    assert len(rows) == int(np.sum(result.count))
    assert [r[head.index("pose")] for r in rows] == sorted(r[head.index("pose")] for r in rows)


def test_numeric_ik_html_single_and_batch():
    robot = denavit.load_robot("ur5")
    rng = np.random.default_rng(5)
    qs = random_q(rng, robot, (2, 2))
    result = denavit.solve_ik(robot, denavit.forward_kinematics(robot, qs), rng=np.random.default_rng(0))
    head, rows = _ik_rows(result)
    assert len(rows) == 4
    flat = result.q.reshape(-1, robot.dof)
    for i, r in enumerate(rows):
        np.testing.assert_allclose([float(r[head.index(f"q{k + 1}")]) for k in range(robot.dof)], flat[i],
                                   rtol=1e-5, atol=1e-6)
        assert r[head.index("success")] == ("yes" if result.success.reshape(-1)[i] else "no")
    one = denavit.solve_ik(robot, denavit.forward_kinematics(robot, qs[0, 0]), rng=np.random.default_rng(0))
    head, rows = _ik_rows(one)
    assert len(rows) == 1 and "target" not in head


def test_numeric_ik_html_caps_the_rows_of_a_large_batch():
    robot = denavit.load_robot("planar2r")
    n = denavit.display.MAX_HTML_ROWS + 7
    qs = random_q(np.random.default_rng(6), robot, (n,))
    result = denavit.solve_ik(robot, denavit.forward_kinematics(robot, qs), mask="position",
                              rng=np.random.default_rng(0))
    page = result._repr_html_()
    _, rows = _ik_rows(result)
    assert len(rows) == denavit.display.MAX_HTML_ROWS and "and 7 more rows" in page


def test_dynamics_terms_latex_is_sympy_latex_of_each_entry():
    sp = pytest.importorskip("sympy")
    from denavit import symbolic as S

    robot = denavit.load_robot("planar2r")
    terms = S.lagrangian_dynamics(robot)
    tex = terms._repr_latex_()
    assert tex.startswith("$$\\begin{aligned}") and tex.endswith("\\end{aligned}$$")
    n = robot.dof
    for i in range(n):
        for j in range(i, n):  # M by its upper triangle, and the line saying it is symmetric
            assert f"M_{{{i + 1}{j + 1}}} &= {sp.latex(S.shorthand(terms.M[i, j], terms.q))}" in tex
    assert "M_{kj} &= M_{jk}" in tex
    for i in range(n):
        # format_dynamics prints fractions with denominators above 12 (981/100) as 6-digit decimals
        g = terms.g[i].xreplace({r: sp.Float(r, 6) for r in terms.g[i].atoms(sp.Rational) if r.q > 12})
        assert f"g_{{{i + 1}}} &= {sp.latex(S.shorthand(g, terms.q))}" in tex
        assert f"\\tau_{{f,{i + 1}}} &= " in tex
    assert "}_{" not in tex.replace("\\tau_{f,", "")  # no double subscripts


def test_report_markdown_embeds_its_figures():
    pytest.importorskip("matplotlib")
    from denavit.report import Figure, derive, render_markdown

    robot = denavit.load_robot("planar2r")
    d = derive(robot, topics=("model", "fk", "figures"))
    md = d._repr_markdown_()
    text, files = render_markdown(d)
    figures = [s for sec in d.sections for s in sec.steps if isinstance(s, Figure)]
    assert files and len(figures) == len(files)
    for fig in figures:
        uri = "data:image/png;base64," + base64.b64encode(fig.png).decode("ascii")
        assert f"]({uri})" in md
    assert not any(f"]({name})" in md for name in files)
    stripped = re.sub(r"\]\(data:image/png;base64,[A-Za-z0-9+/=]+\)", "](X)", md)
    assert stripped == re.sub(r"\]\((" + "|".join(map(re.escape, files)) + r")\)", "](X)", text)


def test_ik_derivation_markdown_is_its_own_markdown():
    pytest.importorskip("sympy")
    from denavit import symbolic as S

    d = S.ik_derivation(denavit.load_robot("planar2r"))
    md = d._repr_markdown_()
    assert md == d.to_markdown() and md.count("$$") % 2 == 0


def test_singularity_analysis_markdown_lists_every_condition():
    sp = pytest.importorskip("sympy")
    from denavit import symbolic as S

    a = S.singularity_analysis(denavit.load_robot("puma560"))
    md = a._repr_markdown_()
    assert f"$$ {sp.latex(a.determinant)} $$" in md
    items = [line for line in md.splitlines() if line.startswith("- $")]
    assert len(items) == len(a.conditions) == 3
    for line, c in zip(items, a.conditions):
        assert line.startswith(f"- ${sp.latex(c.factor)} = 0$ ({c.kind}): ")
        assert line.count("$") % 2 == 0
        for s in c.solutions:
            assert sp.latex(s.expression) in line


def test_robot_text_from_the_file_is_escaped_in_html_and_markdown():
    robot = denavit.load_robot("planar2r").replace(name="<script>alert(1)</script> | x", description="a & b <i>")
    page = robot._repr_html_()
    assert "<script" not in page and "<i>" not in page and "&lt;script&gt;" in page
    parse_html(page)
    md = denavit.dh_table(robot, fmt="markdown")
    assert "\\| x" in md
    tex = denavit.dh_table(robot.replace(name="arm\n\\input{/etc/passwd}"), fmt="latex")
    assert tex.splitlines()[0].startswith("% arm") and not any(x.startswith("\\input") for x in tex.splitlines())


def test_print_uses_the_angle_unit_the_file_was_written_in(tmp_path):
    """The same arm written in degrees and in radians: the same kinematics, each printed in its file's unit."""
    rows = [{"a": 0.3, "alpha": 90, "d": 0.1, "theta": "q"}, {"a": 0.2, "alpha": 0, "d": 0, "theta": "q - 30"}]
    deg = denavit.robot_from_dict({"name": "two", "convention": "standard", "angle_unit": "deg", "joints": rows})
    rad = denavit.robot_from_dict({"name": "two", "convention": "standard", "joints": [
        {"a": 0.3, "alpha": "pi/2", "d": 0.1, "theta": "q"}, {"a": 0.2, "alpha": 0, "d": 0, "theta": "q - pi/6"}]})
    q = np.array([0.4, -0.7])
    np.testing.assert_allclose(denavit.forward_kinematics(deg, q), denavit.forward_kinematics(rad, q), atol=1e-15)
    other = deg.replace(angle_unit="rad")  # the unit is presentation: not part of equality or the hash
    assert other == deg and hash(other) == hash(deg) and "π/2" in str(other)
    assert (deg.angle_unit, rad.angle_unit) == ("deg", "rad")
    assert "90°" in str(deg) and "q2 - 30°" in str(deg) and "degrees" in str(deg)
    assert "π/2" in str(rad) and "q2 - π/6" in str(rad) and "90°" not in str(rad)
    assert "π/2" in denavit.dh_table(deg, deg=False)  # an explicit choice wins
