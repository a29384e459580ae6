"""DH tables pasted from documents: tab-separated or Markdown tables with LaTeX cells, into a robot.

Documents write DH tables in many ways; this reader accepts the common ones:

- rows separated by tabs, ``|`` (Markdown, with or without ``|---|`` rules) or ``&`` (LaTeX ``tabular``,
  rows ending in ``\\\\``);
- a header row naming the columns in any order: ``a``, ``alpha``/``α``, ``d``, ``theta``/``θ``/``Q``/``q``, plus an
  optional index column (``i``, ``Link``, ``Joint``) and units in parentheses;
- the convention from the header: ``a_{i-1}`` or ``\\alpha_{i-1}`` mean modified (Craig), ``a_i``, ``\\alpha_i``
  standard; ``--convention`` decides when the header does not;
- degrees from the header (``deg``, ``°``) or from the values (a twist of ±90 or 180 is degrees);
- lengths in millimetres or centimetres when the header says so (``d (mm)``, ``a [cm]``): converted to metres,
  with a note; a header without a unit over lengths that all look like millimetres (every one above
  :data:`MM_HINT` in absolute value) gives a warning saying what to write;
- cells in LaTeX (``$\\theta_1$``, ``$\\frac{\\pi}{2}$``, ``$-d_3$``, ``$\\theta_2 - \\pi/2$``) or plain text; a cell
  ``$H_1 = 0.5$`` defines the parameter ``H1``; other names become parameters (value 1 unless defined,
  with a note);
- the joint variable: a θ cell naming θ_i/q_i/Q_i makes a revolute joint (its offset kept); a constant θ with a
  d cell naming d_i* / q_i (or d_i when no θ variable appears) makes a prismatic one; a row without a
  variable is fixed (e.g. a tool row).

Cells are read by the restricted reader of :mod:`denavit.check._latex` (never ``eval``).  Sizes are capped
(:data:`MAX_TABLE_CHARS`, :data:`MAX_TABLE_ROWS`, :data:`MAX_COLUMNS`, :data:`MAX_LINE_CHARS`,
:data:`MAX_CELL_CHARS`) and every pattern used runs in linear time, whatever the line.
"""

from __future__ import annotations

import re
import warnings
from dataclasses import dataclass
from typing import Any

from . import _expr
from . import errors as _errors
from .errors import ParseError
from .model import DHRobot

__all__ = ["TableImport", "import_table", "find_table", "table_file_text", "MAX_TABLE_CHARS", "MAX_TABLE_ROWS",
           "MAX_COLUMNS", "MAX_LINE_CHARS", "MAX_CELL_CHARS", "LENGTH_UNITS", "MM_HINT"]

#: Largest pasted text read (characters).
MAX_TABLE_CHARS = 200_000
#: Most data rows in one table (as many as a robot file's rows).
MAX_TABLE_ROWS = 64
#: Most columns in a table row.
MAX_COLUMNS = 16
#: Longest line that can be a table row; longer lines (prose) are skipped when looking for the header.
MAX_LINE_CHARS = 4_000
#: Longest cell.
MAX_CELL_CHARS = 500
#: Length units understood in a header (``a (mm)``, ``d [cm]``) and their factor to metres.
LENGTH_UNITS = {"mm": 0.001, "cm": 0.01, "m": 1.0}
#: Lengths all larger than this (in absolute value), under a header naming no unit, look like millimetres.
MM_HINT = 10.0
_COLS = ("a", "alpha", "d", "theta")
_RULE_CHARS = frozenset(" \t:|-")


@dataclass(frozen=True)
class TableImport:
    """The imported robot, the robot-file data it was built from and notes on what was assumed."""

    robot: DHRobot
    data: dict[str, Any]
    notes: tuple[str, ...]


def _cells(line: str) -> list[str]:
    s = line.strip()
    if "\t" in s:
        cells = s.split("\t")
    elif s.startswith("|") or s.count("|") >= 3:
        cells = s.strip("|").split("|")
    elif "&" in s:
        cells = _strip_row_end(s).split("&")
    else:
        return []
    return [c.strip() for c in cells]


def _strip_row_end(s: str) -> str:
    """A LaTeX row without its trailing ``\\\\`` (and ``\\hline``), by plain string tests (no backtracking)."""
    t = s.rstrip()
    if t.endswith("\\hline"):
        u = t[:-len("\\hline")].rstrip()
        if u.endswith("\\\\"):
            return u[:-2]
    if t.endswith("\\\\"):
        return t[:-2]
    return s


def _is_rule(line: str) -> bool:
    """A Markdown rule such as ``|---|:--:|``: only spaces, tabs, ``:``, ``|`` and ``-`` (with a ``-``)."""
    return "-" in line and set(line) <= _RULE_CHARS


def _plain(cell: str) -> str:
    s = cell.replace("$", " ").replace("\\", " ").replace("{", " ").replace("}", " ").lower()
    s = s.replace("θ", "theta").replace("α", "alpha").replace("ϑ", "theta")
    return re.sub(r"\s+", " ", s).strip()


def _column_kind(cell: str) -> str | None:
    """``a``/``alpha``/``d``/``theta``/``index`` from a header cell, or None."""
    s = re.sub(r"\([^()]*\)|\[[^\[\]]*\]", " ", _plain(cell)).strip()  # drop units and "(z_{i-1})" remarks
    head = re.match(r"[a-z]+", s)
    word = head.group(0) if head else ""
    if word in ("theta", "vartheta", "heta", "q", "joint_angle") or re.fullmatch(r"q(_?i|_?n)?", s.replace(" ", "")):
        return "theta"
    if word in ("alpha", "twist"):
        return "alpha"
    if word in ("d", "offset"):
        return "d"
    if word in ("a", "r", "length"):
        return "a"
    if word in ("i", "link", "joint", "n", "frame", "row", "no", "axis"):
        return "index"
    return None


def find_table(text: str) -> tuple[list[str], list[list[str]]]:
    """The header cells and data rows of the first DH table in ``text``."""
    if len(text) > MAX_TABLE_CHARS:
        raise ParseError(f"file too large for a table ({len(text)} characters; at most {MAX_TABLE_CHARS})")
    lines = text.splitlines()
    for k, line in enumerate(lines):
        if len(line) > MAX_LINE_CHARS:
            continue  # prose, not a header
        cells = _cells(line)
        if len(cells) > MAX_COLUMNS or any(len(c) > MAX_CELL_CHARS for c in cells):
            continue
        kinds = [_column_kind(c) for c in cells]
        if len(cells) >= 4 and all(c in kinds for c in _COLS):
            rows = []
            for n, nxt in enumerate(lines[k + 1:], start=k + 2):
                if _is_rule(nxt):
                    continue  # Markdown rule
                if len(nxt) > MAX_LINE_CHARS:
                    raise ParseError(f"line {n}: longer than {MAX_LINE_CHARS} characters")
                c = _cells(nxt)
                if len(c) != len(cells) or not any(x.strip() for x in c):
                    if rows:
                        break
                    continue
                long = [x for x in c if len(x) > MAX_CELL_CHARS]
                if long:
                    raise ParseError(f"line {n}: a cell longer than {MAX_CELL_CHARS} characters")
                rows.append(c)
                if len(rows) > MAX_TABLE_ROWS:
                    raise ParseError(f"line {n}: more than {MAX_TABLE_ROWS} rows in the table")
            if not rows:
                raise ParseError(f"line {k + 1}: a DH header but no rows under it")
            return cells, rows
    raise ParseError("no DH table found: expected a header row naming the columns a, alpha, d, theta "
                     "(tab, | or & separated)")


class _Reader:
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


def _is_degrees(header: list[str], kinds: list[str | None], rows: list[list[str]]) -> bool:
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


def import_table(text: str, name: str = "imported", convention: str | None = None,
                 degrees: bool | None = None, where: str = "<table>") -> TableImport:
    """Read the first DH table in ``text`` into a robot (see the module notes for what is accepted)."""
    try:
        return _import(text, name, convention, degrees, where)
    except ParseError as exc:
        if str(exc).startswith(where):
            raise
        raise ParseError(str(exc), where=where) from None


def _import(text: str, name: str, convention: str | None, degrees: bool | None, where: str) -> TableImport:
    from .io import robot_from_dict

    header, rows = find_table(text)
    kinds = [_column_kind(h) for h in header]
    notes: list[str] = []
    col = {k: kinds.index(k) for k in _COLS}
    mod_hint = any(re.search(r"i\s*-\s*1", _plain(header[col[k]])) for k in ("a", "alpha"))
    conv = convention or ("modified" if mod_hint else "standard")
    if convention is None:
        notes.append(f"convention {conv} (read from the header: "
                     + ("a_{i-1}/alpha_{i-1})" if mod_hint else "a_i/alpha_i, no i-1 subscripts)"))
    deg = _is_degrees(header, kinds, rows) if degrees is None else degrees
    if deg and degrees is None:
        notes.append("angles read as degrees (from the header or twist values such as 90)")
    factors = {k: _length_unit(header[col[k]]) for k in ("a", "d")}
    for k, (unit, _) in factors.items():
        if unit not in (None, "m"):
            notes.append(f"column {header[col[k]]!r}: lengths converted from {unit} to metres")
    reader = _Reader()
    joints, angles = [], []
    for r, raw in enumerate(rows, start=1):
        cells = {k: reader.cell(raw[col[k]], f"{where}: row {r}, column {header[col[k]]!r}") for k in _COLS}
        row = _row(cells, raw, col, r, where)
        for k, (unit, factor) in factors.items():
            if factor != 1.0:
                row[k] = _to_metres(row[k], factor, f"{where}: row {r}, column {header[col[k]]!r}")
        joints.append(row)
        angles.append((cells["alpha"], cells["theta"]))
    says_rad = any(k in ("alpha", "theta") and re.search(r"rad", h.lower()) for h, k in zip(header, kinds))
    if degrees is None and not deg and not says_rad and _large_angle(angles):
        deg = True
        notes.append("angles read as degrees (a twist or joint offset larger than 2π in magnitude, such as "
                     "θ - 90; write (rad) in the header if they really are radians)")
    if all(unit is None for unit, _ in factors.values()):
        _warn_if_millimetres(joints, [header[col[k]] for k in ("a", "d")], where)
    used: set[str] = set()
    for r, j in enumerate(joints, start=1):
        for text_ in j.values():
            try:
                used |= _expr.names_in(_expr.parse(text_ if isinstance(text_, str) else str(text_)))
            except ParseError as exc:
                raise ParseError(f"row {r}: {exc}", where=where) from None
    params = {}
    for k, v in reader.params.items():
        if k not in used:
            continue
        if v is None:
            notes.append(f"parameter {k} has no value in the table; set to 1 (edit the robot file)")
            v = 1.0
        params[k] = v
    data = {"name": name, "convention": conv, "angle_unit": "deg" if deg else "rad",
            "parameters": params, "joints": joints}
    return TableImport(robot_from_dict(data, where=where), data, tuple(notes))


def _large_angle(angles: list[tuple[tuple, tuple]]) -> bool:
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


def _length_unit(cell: str) -> tuple[str | None, float]:
    """The length unit a header cell names (``d (mm)``, ``a [cm]``, ``a_i / m``) and its factor to metres."""
    words = set(re.findall(r"[a-z]+", _plain(cell)))
    for unit, spelled in (("mm", ("mm", "millimeter", "millimeters", "millimetre", "millimetres")),
                          ("cm", ("cm", "centimeter", "centimeters", "centimetre", "centimetres")),
                          ("m", ("m", "meter", "meters", "metre", "metres"))):
        if words & set(spelled):
            return unit, LENGTH_UNITS[unit]
    return None, 1.0


def _to_metres(value: Any, factor: float, place: str) -> Any:
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


def _warn_if_millimetres(joints: list[dict[str, Any]], headers: list[str], where: str) -> None:
    """Warn when every length written as a number is larger than :data:`MM_HINT` (millimetres, probably)."""
    lengths = [abs(float(j[k])) for j in joints for k in ("a", "d")
               if isinstance(j[k], (int, float)) and not isinstance(j[k], bool) and j[k] != 0]
    if lengths and min(lengths) > MM_HINT:
        warning = getattr(_errors, "DenavitWarning", UserWarning)
        warnings.warn(f"{where}: the lengths ({min(lengths):g} to {max(lengths):g}) look like millimetres but the "
                      f"header names no unit, so they are read as metres; if they are millimetres write the unit in "
                      f"the header, e.g. '{headers[0]} (mm)' and '{headers[1]} (mm)'", warning, stacklevel=3)


def _row(cells: dict[str, tuple], raw: list[str], col: dict[str, int], r: int, where: str) -> dict[str, Any]:
    theta_q = _joint_names(cells["theta"])
    d_q = _joint_names(cells["d"])
    for k in ("a", "alpha"):
        if _joint_names(cells[k]):
            raise ParseError(f"{where}: row {r}: a joint variable in column {k!r}")
    out: dict[str, Any] = {k: _expr.to_text(cells[k]) for k in _COLS}
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


def table_file_text(result: TableImport, fmt: str = "yaml", source: str = "") -> str:
    """The robot file of an import, as the table wrote it (its units and expressions kept)."""
    import json

    if fmt == "json":
        return json.dumps(result.data, indent=2) + "\n"
    import yaml

    head = [f"# {result.data['name']}: imported by denavit import-table" + (f" from {source}" if source else "")]
    head += [f"# note: {n}" for n in result.notes]
    body = {k: v for k, v in result.data.items() if k != "joints"}
    text = yaml.safe_dump(body, sort_keys=False, default_flow_style=None)
    rows = "".join("  - " + yaml.safe_dump(r, default_flow_style=True, sort_keys=False, width=10_000).strip() + "\n"
                   for r in result.data["joints"])
    return "\n".join(head) + "\n" + text + "joints:\n" + rows
