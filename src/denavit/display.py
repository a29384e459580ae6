"""Presenters for people: the DH table of a robot as text, Markdown, LaTeX or HTML, and the rich displays
Jupyter shows for robots and results (``_repr_html_``, ``_repr_latex_``, ``_repr_markdown_`` delegate here).

Results stay data; this module only turns them into text.  It needs numpy only, except where a result is
symbolic (sympy is then already loaded) and for the optional picture of the arm (matplotlib, when installed).
"""

from __future__ import annotations

import base64
import html
import io
import math
import re
from typing import Any

import numpy as np

from . import _expr
from .errors import ParseError
from .model import DHRobot, JointType

__all__ = [
    "TABLE_FORMATS",
    "MAX_HTML_ROWS",
    "dh_table",
    "robot_summary",
    "robot_html",
    "ik_html",
    "dynamics_latex",
    "derivation_markdown",
    "singularities_markdown",
]

TABLE_FORMATS = ("text", "markdown", "latex", "html")
#: Rows shown at most in the HTML table of a batch of IK results (the rest is counted, not shown).
MAX_HTML_ROWS = 50
#: Size [inch] and resolution [dpi] of the picture of the arm beside its table in Jupyter.
PICTURE_SIZE = 3.0
PICTURE_DPI = 72
_ZERO = 1e-12  # |x| below this prints as 0 (rounding noise of the radians ↔ degrees conversions)
_PI_DENOMINATORS = (1, 2, 3, 4, 6, 12)

# A cell is a pair (text, latex): text serves the plain, Markdown and HTML tables, latex the LaTeX one.
Cell = tuple[str, str]


# --------------------------------------------------------------------------------------------------
# numbers and expressions


def _g(x: float) -> str:
    """A number in 6 significant digits, rounding noise as 0."""
    if abs(x) < _ZERO:
        return "0"
    return f"{x:.6g}"


def _tex_number(s: str) -> str:
    m = re.fullmatch(r"(-?[\d.]+)e([+-]\d+)", s)
    return f"{m.group(1)} \\times 10^{{{int(m.group(2))}}}" if m else s


def _pi_fraction(x: float) -> tuple[int, int] | None:
    """(k, m) with x = k·π/m for a small denominator m, or None."""
    for m in _PI_DENOMINATORS:
        k = round(x * m / math.pi)
        if k and abs(x - k * math.pi / m) < 1e-12 and abs(k) <= 4 * m:
            return k, m
    return None


def _angle(x: float, deg: bool) -> Cell:
    """An angle [rad] as ``π/2`` (radians) or ``90°`` (``deg``)."""
    if abs(x) < _ZERO:
        return "0", "0"
    if deg:
        s = _g(math.degrees(x))
        return f"{s}°", f"{s}^\\circ"
    frac = _pi_fraction(x)
    if frac is None:
        s = _g(x)
        return s, _tex_number(s)
    k, m = frac
    sign = "-" if k < 0 else ""
    num = "" if abs(k) == 1 else str(abs(k))
    text = f"{sign}{num}π" + (f"/{m}" if m != 1 else "")
    tex = f"{sign}{num}\\pi" if m == 1 else f"{sign}\\frac{{{num}\\pi}}{{{m}}}"
    return text, tex


def _length(x: float) -> Cell:
    s = _g(x)
    return s, _tex_number(s)


_PREC = {"+": 1, "-": 1, "*": 2, "/": 2, "^": 4}
_TEX_FUNCS = {"sin", "cos", "tan", "exp", "log"}


def _tex_name(name: str) -> str:
    """``L1`` → ``L_{1}``, ``d_flange`` → ``d_{\\mathrm{flange}}``, ``Lc`` → ``\\mathit{Lc}``."""
    m = re.fullmatch(r"([A-Za-z]+?)_?(\d+)", name)
    if m:
        return f"{m.group(1)}_{{{m.group(2)}}}"
    head, _, tail = name.partition("_")
    head = head if len(head) == 1 else f"\\mathit{{{head}}}"
    return f"{head}_{{\\mathrm{{{tail.replace('_', '')}}}}}" if tail else head


def _node(node: _expr.Node, parent: int = 0) -> Cell:
    """(text, latex) of an expression tree: ``pi`` as π, ``deg(30)`` as 30°, ``L1`` as L_{1}."""
    kind = node[0]
    if kind == "num":
        return node[1], _tex_number(node[1])
    if kind == "name":
        if node[1] == "pi":
            return "π", "\\pi"
        return node[1], _tex_name(node[1])
    if kind == "neg":
        t, x = _node(node[1], 3)
        return (f"(-{t})", f"\\left(-{x}\\right)") if parent >= 3 else (f"-{t}", f"-{x}")
    if kind == "bin":
        op = node[1]
        prec = _PREC[op]
        right = prec + 1 if op in "-/" else prec
        (lt, lx), (rt, rx) = _node(node[2], 5 if op == "^" else prec), _node(node[3], 4 if op == "^" else right)
        if op == "^":
            t, x = f"{lt}^{rt}", f"{{{lx}}}^{{{_node(node[3])[1]}}}"
        elif op == "/":
            t, x = f"{lt}/{rt}", f"\\frac{{{_node(node[2])[1]}}}{{{_node(node[3])[1]}}}"
        else:
            t = f"{lt}{op}{rt}" if op == "*" else f"{lt} {op} {rt}"
            x = f"{lx} {rx}" if op == "*" else f"{lx} {op} {rx}"
        if prec < parent:
            return f"({t})", (x if op == "/" else f"\\left({x}\\right)")
        return t, x
    name, args = node[1], [_node(a) for a in node[2]]
    if name == "deg":
        t, x = _node(node[2][0], 3)
        return f"{t}°", f"{x}^\\circ"
    t = f"{name}({', '.join(a[0] for a in args)})"
    inner = ", ".join(a[1] for a in args)
    if name == "sqrt":
        return t, f"\\sqrt{{{inner}}}"
    fn = f"\\{name}" if name in _TEX_FUNCS else f"\\operatorname{{{name}}}"
    return t, f"{fn}\\left({inner}\\right)"


def _expression(text: str) -> Cell:
    """An expression of named parameters as written (``deg(30)`` shown as ``30°``)."""
    return _node(_expr.parse(text))


def _has_parameter(text: str, robot: DHRobot) -> bool:
    try:
        return bool(_expr.names_in(_expr.parse(text)) & set(robot.parameter_values))
    except ParseError:  # a text the parser refuses is shown as its value
        return False


def _field(robot: DHRobot, link: Any, name: str, deg: bool) -> Cell:
    """One DH field: the parameter expression when the file used one, else its value."""
    text = dict(link.symbols).get(name)
    if text is not None and _has_parameter(text, robot):
        return _expression(text)
    value = getattr(link, name)
    return _angle(value, deg) if name in ("alpha", "theta") else _length(value)


def _plus(var: Cell, offset: Cell) -> Cell:
    """``q1 + π/2`` / ``q1 - π/2`` / ``q1``."""
    if offset[0] == "0":
        return var
    if offset[0].startswith("-"):
        return f"{var[0]} - {offset[0][1:]}", f"{var[1]} - {offset[1][1:]}"
    return f"{var[0]} + {offset[0]}", f"{var[1]} + {offset[1]}"


def _joint_value(x: float, kind: JointType, deg: bool) -> Cell:
    return _angle(x, deg) if kind is JointType.REVOLUTE else _length(x)


def _limits(link: Any, deg: bool) -> Cell:
    if link.q_limits is None:
        return "", ""
    lo, hi = (_joint_value(v, link.joint, deg) for v in link.q_limits)
    unit = " m" if link.joint is JointType.PRISMATIC else ""
    return f"[{lo[0]}, {hi[0]}]{unit}", f"[{lo[1]}, {hi[1]}]" + ("\\,\\mathrm{m}" if unit else "")


def _use_degrees(robot: DHRobot, deg: bool | None) -> bool:
    if deg is not None:
        return bool(deg)
    return getattr(robot, "angle_unit", "rad") == "deg"


# --------------------------------------------------------------------------------------------------
# the DH table


def _rows(robot: DHRobot, deg: bool) -> list[list[Cell]]:
    rows = []
    k = 0
    for link in robot.links:
        a, alpha, d, theta = (_field(robot, link, f, deg) for f in ("a", "alpha", "d", "theta"))
        if link.is_joint:
            k += 1
            var = (f"q{k}", f"q_{{{k}}}")
            if link.joint is JointType.REVOLUTE:
                theta = _plus(var, theta)
            else:
                d = _plus(var, d)
            j: Cell = (str(k), str(k))
        else:
            j = ("-", "-")
        rows.append([j, (link.joint.value, link.joint.value), a, alpha, d, theta, _limits(link, deg)])
    return rows


def _header(robot: DHRobot) -> list[Cell]:
    sub = "i-1" if robot.convention.value == "modified" else "i"
    return [("j", "j"), ("joint", "joint"), (f"a({sub})" if sub != "i" else "a", f"a_{{{sub}}}"),
            (f"α({sub})" if sub != "i" else "α", f"\\alpha_{{{sub}}}"), ("d", "d_{i}"), ("θ", "\\theta_{i}"),
            ("limits", "\\text{limits}")]


def _transform_line(T: np.ndarray, deg: bool) -> tuple[str, str]:
    """``xyz = (x, y, z) m, rpy = (r, p, y)`` as (text, latex)."""
    from .numeric import rpy_from_rotation

    xyz = [_length(float(v)) for v in T[:3, 3]]
    rpy = [_angle(float(v), deg) for v in rpy_from_rotation(T[:3, :3])]
    text = f"xyz = ({', '.join(c[0] for c in xyz)}) m, rpy = ({', '.join(c[0] for c in rpy)})"
    tex = (f"xyz = ({', '.join(c[1] for c in xyz)})\\,\\mathrm{{m}},\\ "
           f"rpy = ({', '.join(c[1] for c in rpy)})")
    return text, tex


def _poses(robot: DHRobot) -> dict[str, Any]:
    poses = getattr(robot, "poses", None)
    if not poses:
        return {}
    try:
        return dict(poses)
    except (TypeError, ValueError):
        return {}


def _notes(robot: DHRobot, deg: bool) -> list[tuple[str, Cell]]:
    """The lines under the table: (label, (text, latex))."""
    out: list[tuple[str, Cell]] = []
    if robot.parameters:
        pairs = [(_expression(k), _length(v)) for k, v in robot.parameters]
        out.append(("parameters", (", ".join(f"{k[0]} = {v[0]}" for k, v in pairs),
                                   ",\\ ".join(f"{k[1]} = {v[1]}" for k, v in pairs))))
    for label, M in (("base", robot.base_matrix), ("tool", robot.tool_matrix)):
        if not np.allclose(M, np.eye(4), atol=1e-12):
            out.append((label, _transform_line(M, deg)))
    g = [_length(v) for v in robot.gravity]
    out.append(("gravity", (f"({', '.join(c[0] for c in g)}) m/s²",
                            f"({', '.join(c[1] for c in g)})\\,\\mathrm{{m/s^2}}")))
    for name, q in _poses(robot).items():
        vals = [_joint_value(float(v), t, deg) for v, t in zip(np.asarray(q, dtype=float), robot.joint_types)]
        out.append((f"pose {name}", (f"({', '.join(c[0] for c in vals)})", f"({', '.join(c[1] for c in vals)})")))
    return out


def _title(robot: DHRobot, deg: bool) -> tuple[str, str]:
    kinds = "".join("R" if t is JointType.REVOLUTE else "P" for t in robot.joint_types)
    first = f"{robot.name}" + (f": {robot.description}" if robot.description else "")
    formula = ("A_i = Rz(θ_i) Tz(d_i) Tx(a_i) Rx(α_i)" if robot.convention.value == "standard"
               else "A_i = Rx(α_{i-1}) Tx(a_{i-1}) Rz(θ_i) Tz(d_i)")
    second = (f"{robot.convention.value} DH ({formula}), {robot.dof} joints ({kinds}), "
              f"angles in {'degrees' if deg else 'radians'}")
    return first, second


def dh_table(robot: DHRobot, deg: bool | None = None, fmt: str = "text") -> str:
    """The DH table of a robot, for people: convention, one line per row, parameters, base/tool, gravity.

    Parameters
    ----------
    robot : DHRobot
    deg : bool, optional
        Angles (twists, offsets, revolute limits) in degrees instead of radians.  Default: the unit the
        robot's file used when the model records it, radians otherwise (multiples of π shown as ``π/2``).
    fmt : {"text", "markdown", "latex", "html"}
        Plain text (what ``print(robot)`` shows), a Markdown table, a LaTeX ``tabular`` or an HTML table.

    Returns
    -------
    str
        A revolute row shows its variable in θ (``q1 + π/2`` with an offset), a prismatic one in d
        (``q3``); a fixed row has no joint number.  Fields written with named parameters show the
        expression (``d1``) and the parameters line gives the values.

    Examples
    --------
    >>> import denavit
    >>> print(denavit.dh_table(denavit.load_robot("planar2r"), fmt="markdown").splitlines()[6])
    | 1 | revolute | L1 | 0 | 0 | q1 | [-π, π] |
    """
    if fmt not in TABLE_FORMATS:
        raise ValueError(f"unknown table format {fmt!r}; choose one of {', '.join(TABLE_FORMATS)}")
    use_deg = _use_degrees(robot, deg)
    rows = _rows(robot, use_deg)
    head = _header(robot)
    notes = _notes(robot, use_deg)
    title = _title(robot, use_deg)
    return {"text": _text_table, "markdown": _markdown_table, "latex": _latex_table, "html": _html_table}[fmt](
        title, head, rows, notes)


def _text_table(title, head, rows, notes) -> str:
    cells = [[c[0] for c in r] for r in [head] + rows]
    widths = [max(len(r[i]) for r in cells) for i in range(len(head))]
    lines = list(title) + [""]
    lines += ["  ".join(c.ljust(w) for c, w in zip(r, widths)).rstrip() for r in cells]
    lines.append("")
    lines += [f"{label}: {cell[0]}" for label, cell in notes]
    return "\n".join(lines)


def _md_escape(s: str) -> str:
    return s.replace("|", "\\|")


def _markdown_table(title, head, rows, notes) -> str:
    lines = [f"**{_md_escape(title[0])}**", "", _md_escape(title[1]), ""]
    lines.append("| " + " | ".join(_md_escape(c[0]) for c in head) + " |")
    lines.append("|" + "---|" * len(head))
    lines += ["| " + " | ".join(_md_escape(c[0]) for c in r) + " |" for r in rows]
    lines.append("")
    lines += [f"- {label}: {_md_escape(cell[0])}" for label, cell in notes]
    return "\n".join(lines)


_TEX_TEXT = {"&": r"\&", "%": r"\%", "#": r"\#", "_": r"\_", "{": r"\{", "}": r"\}", "~": r"\textasciitilde{}",
             "^": r"\textasciicircum{}", "\\": r"\textbackslash{}", "$": r"\$"}


def _tex_text(s: str) -> str:
    return "".join(_TEX_TEXT.get(ch, ch) for ch in s)


def _latex_table(title, head, rows, notes) -> str:
    def cell(c: Cell, k: int) -> str:
        if k < 2 or not c[1]:
            return _tex_text(c[0])
        return f"${c[1]}$"

    lines = [f"% {title[0]}", "\\begin{tabular}{cl" + "l" * (len(head) - 2) + "}", "\\hline"]
    lines.append(" & ".join(_tex_text(c[0]) if k < 2 else f"${c[1]}$" for k, c in enumerate(head)) + " \\\\")
    lines.append("\\hline")
    lines += [" & ".join(cell(c, k) for k, c in enumerate(r)) + " \\\\" for r in rows]
    lines += ["\\hline", "\\end{tabular}"]
    if notes:
        lines += ["", "\\\\ ".join(f"{_tex_text(label)}: ${cell[1]}$" for label, cell in notes)]
    return "\n".join(lines)


def _html_table(title, head, rows, notes) -> str:
    e = html.escape
    out = [f'<table class="denavit-dh"><caption><b>{e(title[0])}</b><br>{e(title[1])}</caption>',
           "<thead><tr>" + "".join(f"<th>{e(c[0])}</th>" for c in head) + "</tr></thead>", "<tbody>"]
    out += ["<tr>" + "".join(f"<td>{e(c[0])}</td>" for c in r) + "</tr>" for r in rows]
    out.append("</tbody></table>")
    if notes:
        out.append('<ul class="denavit-notes">' + "".join(f"<li>{e(label)}: {e(cell[0])}</li>" for label, cell in notes)
                   + "</ul>")
    return "\n".join(out)


# --------------------------------------------------------------------------------------------------
# robots in Jupyter


def robot_summary(robot: DHRobot) -> str:
    """The short ``repr``: ``DHRobot('puma560', 6 joints, standard)``."""
    return f"DHRobot({robot.name!r}, {robot.dof} joint{'s' if robot.dof != 1 else ''}, {robot.convention.value})"


def _picture_png(robot: DHRobot, q: np.ndarray) -> bytes:
    from .viz import plot_robot

    fig = plot_robot(robot, q, frames=True, labels=False, figsize=(PICTURE_SIZE, PICTURE_SIZE), dpi=PICTURE_DPI)
    buf = io.BytesIO()
    fig.savefig(buf, format="png")
    return buf.getvalue()


def _home(robot: DHRobot) -> np.ndarray:
    """The pose drawn beside the table: ``qz`` when the robot names it, else the default configuration."""
    poses = _poses(robot)
    if "qz" in poses:
        return np.asarray(poses["qz"], dtype=float)
    from .viz import default_configuration

    return default_configuration(robot)


def robot_html(robot: DHRobot, deg: bool | None = None, picture: bool = True) -> str:
    """The DH table as HTML, with a small picture of the arm at ``qz`` beside it when matplotlib is installed.

    Parameters
    ----------
    robot : DHRobot
    deg : bool, optional
        As in :func:`dh_table`.
    picture : bool
        Draw the arm (a PNG of :data:`PICTURE_SIZE` inches at :data:`PICTURE_DPI` dpi, embedded as a data URI).
    """
    from .errors import MissingDependencyError

    table = dh_table(robot, deg, fmt="html")
    if not picture:
        return f'<div class="denavit-robot">{table}</div>'
    try:
        png = _picture_png(robot, _home(robot))
    except MissingDependencyError:  # no matplotlib: the table alone
        return f'<div class="denavit-robot">{table}</div>'
    img = (f'<img alt="{html.escape(robot.name)} at its home pose" style="flex:none" '
           f'src="data:image/png;base64,{base64.b64encode(png).decode("ascii")}">')
    return f'<div class="denavit-robot" style="display:flex;gap:1em;align-items:flex-start">{table}{img}</div>'


# --------------------------------------------------------------------------------------------------
# results


def _ik_header(n: int) -> list[str]:
    return [f"q{k + 1}" for k in range(n)]


def _table_html(caption: str, header: list[str], rows: list[list[str]], more: int = 0) -> str:
    e = html.escape
    out = [f'<table class="denavit-ik"><caption>{e(caption)}</caption>',
           "<thead><tr>" + "".join(f"<th>{e(h)}</th>" for h in header) + "</tr></thead><tbody>"]
    out += ["<tr>" + "".join(f"<td>{e(c)}</td>" for c in r) + "</tr>" for r in rows]
    out.append("</tbody></table>")
    if more:
        out.append(f"<p>… and {more} more rows (at most {MAX_HTML_ROWS} are shown)</p>")
    return "\n".join(out)


def _res(x: Any) -> str:
    return f"{float(x):.1e}"


def _analytic_html(r: Any) -> str:
    sol = np.asarray(r.solutions, dtype=float)
    n = sol.shape[-1]
    has_free = bool(np.any(r.continuum))
    header = ["#"] + (["pose"] if sol.ndim > 2 else []) + ["branch"] + (["free"] if has_free else []) \
        + _ik_header(n) + ["position error [m]", "orientation error [rad]"]
    rows: list[list[str]] = []
    total = 0
    if sol.ndim == 2:
        picks = [((), k) for k in range(sol.shape[0])]
    else:
        valid = np.asarray(r.valid)
        picks = [(idx[:-1], idx[-1]) for idx in zip(*np.nonzero(valid))]
    branches = np.asarray(r.branches, dtype=object)
    free = np.asarray(r.free, dtype=object)
    for pose, k in picks:
        total += 1
        if len(rows) >= MAX_HTML_ROWS:
            continue
        at = (*pose, k)
        row = [str(total)] + ([str(tuple(int(i) for i in pose))] if sol.ndim > 2 else [])
        row.append(str(branches[at]))
        if has_free:
            row.append(str(free[at]))
        row += [_g(float(v)) for v in sol[at]]
        row += [_res(np.asarray(r.position_error)[at]), _res(np.asarray(r.orientation_error)[at])]
        rows.append(row)
    out_lim = r.outside_limits
    outside = int(np.sum(out_lim)) if sol.ndim > 2 else int(np.asarray(out_lim).reshape(-1, n).shape[0])
    caption = (f"{total} closed-form solution{'s' if total != 1 else ''} ({r.method}; controls {r.controlled}); "
               f"{outside} more outside the joint limits; q in rad (revolute) and m (prismatic)")
    return _table_html(caption, header, rows, max(0, total - MAX_HTML_ROWS))


def _numeric_html(r: Any) -> str:
    q = np.asarray(r.q, dtype=float)
    n = q.shape[-1]
    flat_q = q.reshape(-1, n)
    fields = [np.asarray(getattr(r, f)).reshape(-1) for f in
              ("success", "position_error", "orientation_error", "iterations", "restarts", "reason")]
    batch = q.ndim > 1
    header = (["target"] if batch else []) + _ik_header(n) + [
        "success", "position error [m]", "orientation error [rad]", "iterations", "restarts", "reason"]
    rows = []
    for i in range(min(flat_q.shape[0], MAX_HTML_ROWS)):
        idx = [str(tuple(int(j) for j in np.unravel_index(i, q.shape[:-1])))] if batch else []
        ok, pe, oe, it, rs, why = (f[i] for f in fields)
        rows.append(idx + [_g(float(v)) for v in flat_q[i]]
                    + ["yes" if ok else "no", _res(pe), _res(oe), str(int(it)), str(int(rs)), str(why)])
    good = int(np.sum(fields[0]))
    caption = (f"numeric IK: {good} of {flat_q.shape[0]} target{'s' if flat_q.shape[0] != 1 else ''} solved; "
               "q in rad (revolute) and m (prismatic)")
    return _table_html(caption, header, rows, max(0, flat_q.shape[0] - MAX_HTML_ROWS))


def ik_html(result: Any) -> str:
    """An IK result (:class:`~denavit.AnalyticIKResult` or :class:`~denavit.IKResult`) as an HTML table:
    one row per solution (per target for a batch) with its branch label and residuals."""
    if hasattr(result, "branches"):
        return _analytic_html(result)
    return _numeric_html(result)


def dynamics_latex(terms: Any) -> str:
    """Equations of motion (:class:`~denavit.symbolic.DynamicsTerms`) as display LaTeX for Jupyter: the
    entries of M, c, g and τ_f as :func:`denavit.symbolic.format_dynamics` writes them."""
    from .symbolic import format_dynamics

    return "$$" + format_dynamics(terms, style="latex") + "$$"


def derivation_markdown(derivation: Any) -> str:
    """A report (:class:`~denavit.report.Derivation`) as Markdown for Jupyter: the report's own Markdown
    renderer, with its pictures embedded as data URIs instead of files beside it."""
    from .report import render_markdown

    text, files = render_markdown(derivation)
    for name, data in files.items():
        uri = "data:image/png;base64," + base64.b64encode(data).decode("ascii")
        text = text.replace(f"]({name})", f"]({uri})")
    return text


def singularities_markdown(analysis: Any) -> str:
    """A singularity analysis (:class:`~denavit.symbolic.SingularityAnalysis`) as Markdown with typeset
    formulas: the measure, its factored form, and each condition with its kind, explanation and solutions."""
    import sympy as sp

    a = analysis
    out = [f"**Singularities of {a.robot}**: {a.matrix_note}; measure: {a.measure}", "",
           f"$$ {sp.latex(a.determinant)} $$", ""]
    if a.constant_factors:
        out += ["Constant factors (assumed non-zero): "
                + ", ".join(f"${sp.latex(c)}$" for c in a.constant_factors), ""]
    if a.everywhere:
        out.append(f"**Singular everywhere**: rank {a.generic_rank} of {a.full_rank} for every q ({a.reason}).")
    elif a.conditions:
        out.append("Singular when:")
        for c in a.conditions:
            sols = "; ".join(
                (f"${sp.latex(sp.Symbol(s.variable))} = {sp.latex(s.expression)}$" if s.expression is not None
                 else f"{s.variable} numerically")
                + (" at " + ", ".join(_g(v) for v in s.values) if s.values else "")
                for s in c.solutions)
            out.append(f"- ${sp.latex(c.factor)} = 0$ ({c.kind}): {c.explanation.rstrip('.')}."
                       + (f" Solutions: {sols}." if sols else ""))
    elif "minors" in a.measure:
        out.append("The minors share no factor: singular configurations, if any, lie where all the minors vanish "
                   "together, which is not solved symbolically here.")
    else:
        out.append("No singular configuration: the determinant never vanishes.")
    return "\n".join(out)
