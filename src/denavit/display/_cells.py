"""Cells of the presenters: numbers, angles (π fractions or degrees) and parameter expressions as
(text, LaTeX) pairs."""

from __future__ import annotations

import math
import re
from typing import Any

from .. import _expr
from ..errors import ParseError
from ..model import DHRobot, JointType

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
        arg = node[2][0]
        if arg[0] == "neg" and arg[1][0] in ("num", "name"):  # deg(-170) → -170°, not (-170)°
            t, x = _node(arg[1], 3)
            return f"-{t}°", f"-{x}^\\circ"
        t, x = _node(arg, 3)
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


def _limits(link: Any, deg: bool, as_written: bool = False) -> Cell:
    """``[lo, hi]``; ``as_written``: as the file wrote them when it did (``-160deg`` in a radian file → -160°)."""
    if link.q_limits is None:
        return "", ""
    texts = dict(link.symbols)
    if as_written and "limits0" in texts and "limits1" in texts:
        try:
            lo, hi = _expression(texts["limits0"]), _expression(texts["limits1"])
        except ParseError:
            lo, hi = (_joint_value(v, link.joint, deg) for v in link.q_limits)
    else:
        lo, hi = (_joint_value(v, link.joint, deg) for v in link.q_limits)
    unit = " m" if link.joint is JointType.PRISMATIC else ""
    return f"[{lo[0]}, {hi[0]}]{unit}", f"[{lo[1]}, {hi[1]}]" + ("\\,\\mathrm{m}" if unit else "")


def _use_degrees(robot: DHRobot, deg: bool | None) -> bool:
    if deg is not None:
        return bool(deg)
    return getattr(robot, "angle_unit", "rad") == "deg"
