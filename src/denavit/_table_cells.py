"""Reading the cells of a DH table into robot-file values (see :mod:`denavit.tables`): LaTeX or plain cells through
the restricted reader of :mod:`denavit.check._latex`, parameters collected, joint variables spotted, degrees and
length units told from the header or the values."""

from __future__ import annotations

import re
import warnings
from typing import Any

from . import _expr
from . import errors as _errors
from ._table_find import COLUMNS, plain_cell
from .errors import ParseError

__all__ = ["CellReader", "is_degrees", "large_angle", "length_unit", "to_metres", "warn_if_millimetres", "row_values",
           "LENGTH_UNITS", "MM_HINT"]

#: Length units understood in a header (``a (mm)``, ``d [cm]``) and their factor to metres.
LENGTH_UNITS = {"mm": 0.001, "cm": 0.01, "m": 1.0}
#: Lengths all larger than this (in absolute value), under a header naming no unit, look like millimetres.
MM_HINT = 10.0


class CellReader:
    """Reads cells, collecting parameters and spotting joint variables."""

    def __init__(self) -> None:
        self.params: dict[str, float | None] = {}

    def resolve(self, ident) -> tuple:
        from .check._resolve import JOINT_BASES

        base = "theta" if ident.base == "heta" else ident.base
        if base in JOINT_BASES and ident.sub.isascii() and ident.sub.isdigit() and len(ident.sub) <= 6 \
                and ident.dots == 0:
            return ("name", f"q{int(ident.sub)}")
        name = ident.plain
        if ident.dots or not re.fullmatch(r"[A-Za-z][A-Za-z0-9]*", name):
            raise ParseError(f"cannot read the symbol {ident.base}_{ident.sub} in a DH table")
        if name in _expr.FUNCTIONS or name in ("pi", "q", "deg"):
            raise ParseError(f"{name!r} cannot be a parameter name")
        self.params.setdefault(name, None)
        return ("name", name)

    def cell(self, text: str, place: str) -> tuple:
        from .check._latex import parse_math

        s = text.strip().strip("$").strip().replace("^{*}", "").replace("^*", "").rstrip("*").strip()
        if not s:
            return ("num", "0")
        if "=" in s:  # $H_1 = 0.5$: a parameter with its value
            lhs, rhs = s.split("=", 1)
            try:
                name_node = parse_math(lhs, self.resolve, rhs=False)
                value = _expr.evaluate(parse_math(rhs, self._no_names, rhs=False))
            except ParseError as exc:
                raise ParseError(f"{place}: {text!r}: {exc}") from None
            if name_node[0] != "name":
                raise ParseError(f"{place}: {text!r}: the left side of '=' must be a parameter name")
            self.params[name_node[1]] = value
            return name_node
        try:
            return parse_math(s, self.resolve, rhs=False)
        except ParseError as exc:
            raise ParseError(f"{place}: {text!r}: {exc}") from None

    @staticmethod
    def _no_names(ident) -> tuple:
        raise ParseError(f"a parameter value must be a number, got {ident.plain!r}")


def _joint_names(node: tuple) -> set[str]:
    return {n for n in _expr.names_in(node) if re.fullmatch(r"q\d+", n)}


def is_degrees(header: list[str], kinds: list[str | None], rows: list[list[str]]) -> bool:
    for h, k in zip(header, kinds):
        if k in ("alpha", "theta") and re.search(r"deg|°", h.lower()):
            return True
        if k in ("alpha", "theta") and re.search(r"rad", h.lower()):
            return False
    col = kinds.index("alpha")
    for r in rows:
        try:
            v = abs(float(r[col].strip().strip("$").replace("−", "-")))
        except ValueError:
            continue
        if v in (30.0, 45.0, 60.0, 90.0, 120.0, 135.0, 180.0, 270.0):
            return True
    return False


def large_angle(angles: list[tuple[tuple, tuple]]) -> bool:
    """Some constant twist or joint offset (joint variables at 0, no other names) exceeds 2π in magnitude."""
    import math

    for cells in angles:
        for node in cells:
            names = _expr.names_in(node)
            if names - _joint_names(node):
                continue
            try:
                value = _expr.evaluate(node, {n: 0.0 for n in names})
            except ParseError:
                continue
            if abs(value) > 2 * math.pi + 1e-9:
                return True
    return False


def length_unit(cell: str) -> tuple[str | None, float]:
    """The length unit a header cell names (``d (mm)``, ``a [cm]``, ``a_i / m``) and its factor to metres."""
    words = set(re.findall(r"[a-z]+", plain_cell(cell)))
    for unit, spelled in (("mm", ("mm", "millimeter", "millimeters", "millimetre", "millimetres")),
                          ("cm", ("cm", "centimeter", "centimeters", "centimetre", "centimetres")),
                          ("m", ("m", "meter", "meters", "metre", "metres"))):
        if words & set(spelled):
            return unit, LENGTH_UNITS[unit]
    return None, 1.0


def to_metres(value: Any, factor: float, place: str) -> Any:
    """A length cell (robot-file text or number, joint variable ``q``) times ``factor``, the variable kept."""
    node = _expr.parse(value)

    def scale(nd: tuple) -> tuple:
        names = _expr.names_in(nd)
        if not names:
            v = _expr.evaluate(nd) * factor
            num = ("num", f"{abs(v):.15g}")
            return ("neg", num) if v < 0 else num
        if nd == ("name", "q"):
            return nd
        if nd[0] == "bin" and nd[1] in "+-":
            return ("bin", nd[1], scale(nd[2]), scale(nd[3]))
        if nd[0] == "neg":
            return ("neg", scale(nd[1]))
        if "q" in names:
            raise ParseError(f"{place}: cannot convert {_expr.to_text(nd)!r} to metres (the joint variable must "
                             "appear as q + offset); write this column in metres")
        return ("bin", "*", ("num", f"{factor:g}"), nd)

    return _number_or_text(_expr.to_text(scale(node)))


def warn_if_millimetres(joints: list[dict[str, Any]], headers: list[str], where: str) -> None:
    """Warn when every length written as a number is larger than :data:`MM_HINT` (millimetres, probably)."""
    lengths = [abs(float(j[k])) for j in joints for k in ("a", "d")
               if isinstance(j[k], (int, float)) and not isinstance(j[k], bool) and j[k] != 0]
    if lengths and min(lengths) > MM_HINT:
        warning = getattr(_errors, "DenavitWarning", UserWarning)
        warnings.warn(f"{where}: the lengths ({min(lengths):g} to {max(lengths):g}) look like millimetres but the "
                      f"header names no unit, so they are read as metres; if they are millimetres write the unit in "
                      f"the header, e.g. '{headers[0]} (mm)' and '{headers[1]} (mm)'", warning, stacklevel=3)


def row_values(cells: dict[str, tuple], raw: list[str], col: dict[str, int], r: int, where: str) -> dict[str, Any]:
    theta_q = _joint_names(cells["theta"])
    d_q = _joint_names(cells["d"])
    for k in ("a", "alpha"):
        if _joint_names(cells[k]):
            raise ParseError(f"{where}: row {r}: a joint variable in column {k!r}")
    out: dict[str, Any] = {k: _expr.to_text(cells[k]) for k in COLUMNS}
    if theta_q:
        out["theta"] = _expr.to_text(_replace_joint(cells["theta"]))
    elif d_q or "*" in raw[col["d"]] or (not _expr.names_in(cells["theta"])
                                         and cells["d"][0] == "name" and cells["d"][1] != "pi"):
        node = cells["d"]
        if not d_q:  # d_3^* style (or a lone d_3 under a constant θ): that symbol is the variable
            names = sorted(_expr.names_in(node))
            if len(names) != 1:
                raise ParseError(f"{where}: row {r}: cannot tell the joint variable in {raw[col['d']]!r}")
            node = _subst_name(node, names[0])
        out["d"] = _expr.to_text(_replace_joint(node))
    return {k: _number_or_text(v) for k, v in out.items()}


def _number_or_text(text: str) -> Any:
    """``"0"`` → 0, ``"-90"`` → -90, ``"0.5"`` → 0.5; expressions stay text."""
    if re.fullmatch(r"-?\d+", text):
        return int(text)
    if re.fullmatch(r"-?(?:\d+(?:\.\d*)?|\.\d+)(?:[eE][-+]?\d+)?", text) and len(text) < 40:
        value = float(text)
        return value if value not in (float("inf"), float("-inf")) else text
    return text


def _subst_name(node: tuple, name: str) -> tuple:
    if node == ("name", name):
        return ("name", "q")
    if node[0] == "neg":
        return ("neg", _subst_name(node[1], name))
    if node[0] == "bin":
        return ("bin", node[1], _subst_name(node[2], name), _subst_name(node[3], name))
    if node[0] == "call":
        return ("call", node[1], tuple(_subst_name(a, name) for a in node[2]))
    return node


def _replace_joint(node: tuple) -> tuple:
    """q3 → q (the robot file numbers joints itself)."""
    if node[0] == "name" and re.fullmatch(r"q\d+", node[1]):
        return ("name", "q")
    if node[0] == "neg":
        return ("neg", _replace_joint(node[1]))
    if node[0] == "bin":
        return ("bin", node[1], _replace_joint(node[2]), _replace_joint(node[3]))
    if node[0] == "call":
        return ("call", node[1], tuple(_replace_joint(a) for a in node[2]))
    return node
