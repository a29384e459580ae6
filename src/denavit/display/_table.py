"""The DH table of a robot as text, Markdown, LaTeX or HTML, and the robot's display in Jupyter."""

from __future__ import annotations

import base64
import html
import io
from typing import Any

import numpy as np

from ..model import DHRobot, JointType
from ._terminal import one_line_text
from ._cells import Cell, _angle, _expression, _field, _joint_value, _length, _limits, _plus, _use_degrees

TABLE_FORMATS = ("text", "markdown", "latex", "html")
#: Size [inch] and resolution [dpi] of the picture of the arm beside its table in Jupyter.
PICTURE_SIZE = 3.0
PICTURE_DPI = 72


# --------------------------------------------------------------------------------------------------
# the DH table


def _rows(robot: DHRobot, deg: bool, as_written: bool = False) -> list[list[Cell]]:
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
        rows.append([j, (link.joint.value, link.joint.value), a, alpha, d, theta, _limits(link, deg, as_written)])
    return rows


def _header(robot: DHRobot) -> list[Cell]:
    sub = "i-1" if robot.convention.value == "modified" else "i"
    return [("j", "j"), ("joint", "joint"), (f"a({sub})" if sub != "i" else "a", f"a_{{{sub}}}"),
            (f"α({sub})" if sub != "i" else "α", f"\\alpha_{{{sub}}}"), ("d", "d_{i}"), ("θ", "\\theta_{i}"),
            ("limits", "\\text{limits}")]


def _transform_line(T: np.ndarray, deg: bool) -> tuple[str, str]:
    """``xyz = (x, y, z) m, rpy = (r, p, y)`` as (text, latex)."""
    from ..numeric import rpy_from_rotation

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
    first = one_line_text(robot.name) + (f": {one_line_text(robot.description)}" if robot.description else "")
    formula = ("A_i = Rz(θ_i) Tz(d_i) Tx(a_i) Rx(α_i)" if robot.convention.value == "standard"
               else "A_i = Rx(α_{i-1}) Tx(a_{i-1}) Rz(θ_i) Tz(d_i)")
    second = (f"{robot.convention.value} DH ({formula}), {robot.dof} joint{'s' * (robot.dof != 1)} ({kinds}), "
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
    rows = _rows(robot, use_deg, as_written=deg is None)  # no unit asked for: limits as the file wrote them
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

    # the title as one comment line, whatever the name holds
    lines = ["% " + " ".join(title[0].split()), "\\begin{tabular}{cl" + "l" * (len(head) - 2) + "}", "\\hline"]
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
    from ..viz import plot_robot

    fig = plot_robot(robot, q, frames=True, labels=False, figsize=(PICTURE_SIZE, PICTURE_SIZE), dpi=PICTURE_DPI)
    buf = io.BytesIO()
    fig.savefig(buf, format="png")
    return buf.getvalue()


def _home(robot: DHRobot) -> np.ndarray:
    """The pose drawn beside the table: ``qz`` when the robot names it, else the default configuration."""
    poses = _poses(robot)
    if "qz" in poses:
        return np.asarray(poses["qz"], dtype=float)
    from ..viz import default_configuration

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
    from ..errors import MissingDependencyError

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
