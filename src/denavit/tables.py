"""DH tables pasted from documents: tab-separated or Markdown tables with LaTeX cells, into a robot.

Documents write DH tables in many ways; this reader accepts the common ones:

- rows separated by tabs, ``|`` (Markdown, with or without ``|---|`` rules) or ``&`` (LaTeX ``tabular``,
  rows ending in ``\\\\``);
- a header row naming the columns in any order: ``a``, ``alpha``/``α``, ``d``, ``theta``/``θ``/``Q``/``q``, plus an
  optional index column (``i``, ``Link``, ``Joint``) and units in parentheses;
- the convention from the header: ``a_{i-1}`` or ``\\alpha_{i-1}`` mean modified (Craig), ``a_i``, ``\\alpha_i``
  standard; ``--convention`` decides when the header does not;
- degrees from the header (``deg``, ``°``) or from the values (a twist of ±90 or 180 is degrees);
- cells in LaTeX (``$\\theta_1$``, ``$\\frac{\\pi}{2}$``, ``$-d_3$``, ``$\\theta_2 - \\pi/2$``) or plain text; a cell
  ``$H_1 = 0.5$`` defines the parameter ``H1``; other names become parameters (value 1 unless defined,
  with a note);
- the joint variable: a θ cell naming θ_i/q_i/Q_i makes a revolute joint (its offset kept); a constant θ with a
  d cell naming d_i* / q_i (or d_i when no θ variable appears) makes a prismatic one; a row without a
  variable is fixed (e.g. a tool row).

Cells are read by the restricted reader of :mod:`denavit.check._latex` (never ``eval``).
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from typing import Any

from . import _expr
from .errors import ParseError
from .model import DHRobot

__all__ = ["TableImport", "import_table", "find_table", "table_file_text", "MAX_TABLE_CHARS"]

MAX_TABLE_CHARS = 200_000
_COLS = ("a", "alpha", "d", "theta")


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
        cells = re.sub(r"\\\\\s*(\\hline)?\s*$", "", s).split("&")
    else:
        return []
    return [c.strip() for c in cells]


def _plain(cell: str) -> str:
    s = cell.replace("$", " ").replace("\\", " ").replace("{", " ").replace("}", " ").lower()
    s = s.replace("θ", "theta").replace("α", "alpha").replace("ϑ", "theta")
    return re.sub(r"\s+", " ", s).strip()


def _column_kind(cell: str) -> str | None:
    """``a``/``alpha``/``d``/``theta``/``index`` from a header cell, or None."""
    s = re.sub(r"\(.*?\)|\[.*?\]", " ", _plain(cell)).strip()  # drop units and "(z_{i-1})" remarks
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
        cells = _cells(line)
        kinds = [_column_kind(c) for c in cells]
        if len(cells) >= 4 and all(c in kinds for c in _COLS):
            rows = []
            for nxt in lines[k + 1:]:
                if re.fullmatch(r"\s*\|?[\s:|-]+\|?\s*", nxt) and "-" in nxt:
                    continue  # Markdown rule
                c = _cells(nxt)
                if len(c) != len(cells) or not any(x.strip() for x in c):
                    if rows:
                        break
                    continue
                rows.append(c)
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
        if base in JOINT_BASES and ident.sub.isdigit() and ident.dots == 0 and not (base == "Q" and False):
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
    reader = _Reader()
    joints = []
    for r, raw in enumerate(rows, start=1):
        cells = {k: reader.cell(raw[col[k]], f"{where}: row {r}, column {header[col[k]]!r}") for k in _COLS}
        joints.append(_row(cells, raw, col, r, where))
    used: set[str] = set()
    for j in joints:
        for text_ in j.values():
            used |= _expr.names_in(_expr.parse(text_ if isinstance(text_, str) else str(text_)))
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
    if re.fullmatch(r"-?\d*\.\d+(e-?\d+)?", text):
        return float(text)
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
