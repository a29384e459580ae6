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
from dataclasses import dataclass
from typing import Any

from . import _expr, _text
from ._table_cells import (LENGTH_UNITS, MM_HINT, CellReader, is_degrees, large_angle, length_unit, row_values,
                           to_metres, warn_if_millimetres)
from ._table_find import (COLUMNS, MAX_CELL_CHARS, MAX_COLUMNS, MAX_LINE_CHARS, MAX_TABLE_CHARS, MAX_TABLE_ROWS,
                          column_kind, find_table, find_tables, plain_cell)
from .errors import ParseError
from .model import DHRobot

__all__ = ["TableImport", "import_table", "find_table", "find_tables", "table_file_text", "MAX_TABLE_CHARS", "MAX_TABLE_ROWS",
           "MAX_COLUMNS", "MAX_LINE_CHARS", "MAX_CELL_CHARS", "LENGTH_UNITS", "MM_HINT"]


@dataclass(frozen=True)
class TableImport:
    """The imported robot, the robot-file data it was built from and notes on what was assumed."""

    robot: DHRobot
    data: dict[str, Any]
    notes: tuple[str, ...]


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
    kinds = [column_kind(h) for h in header]
    notes: list[str] = []
    col = {k: kinds.index(k) for k in COLUMNS}
    mod_hint = any(re.search(r"i\s*-\s*1", plain_cell(header[col[k]])) for k in ("a", "alpha"))
    conv = convention or ("modified" if mod_hint else "standard")
    if convention is None:
        notes.append(f"convention {conv} (read from the header: "
                     + ("a_{i-1}/alpha_{i-1})" if mod_hint else "a_i/alpha_i, no i-1 subscripts)"))
    deg = is_degrees(header, kinds, rows) if degrees is None else degrees
    if deg and degrees is None:
        notes.append("angles read as degrees (from the header or twist values such as 90)")
    factors = {k: length_unit(header[col[k]]) for k in ("a", "d")}
    for k, (unit, _) in factors.items():
        if unit not in (None, "m"):
            notes.append(f"column {header[col[k]]!r}: lengths converted from {unit} to metres")
    reader = CellReader()
    joints, angles = [], []
    for r, raw in enumerate(rows, start=1):
        cells = {k: reader.cell(raw[col[k]], f"{where}: row {r}, column {header[col[k]]!r}") for k in COLUMNS}
        row = row_values(cells, raw, col, r, where)
        for k, (unit, factor) in factors.items():
            if factor != 1.0:
                row[k] = to_metres(row[k], factor, f"{where}: row {r}, column {header[col[k]]!r}")
        joints.append(row)
        angles.append((cells["alpha"], cells["theta"]))
    says_rad = any(k in ("alpha", "theta") and re.search(r"rad", h.lower()) for h, k in zip(header, kinds))
    if degrees is None and not deg and not says_rad and large_angle(angles):
        deg = True
        notes.append("angles read as degrees (a twist or joint offset larger than 2π in magnitude, such as "
                     "θ - 90; write (rad) in the header if they really are radians)")
    if all(unit is None for unit, _ in factors.values()):
        warn_if_millimetres(joints, [header[col[k]] for k in ("a", "d")], where)
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


def table_file_text(result: TableImport, fmt: str = "yaml", source: str = "") -> str:
    """The robot file of an import, as the table wrote it (its units and expressions kept)."""
    import json

    if fmt == "json":
        return json.dumps(result.data, indent=2) + "\n"
    import yaml

    head = [f"# {_text.visible(result.data['name'])}: imported by denavit import-table"
            + (f" from {_text.visible(source)}" if source else "")]  # comments: one line each, whatever they quote
    head += [f"# note: {_text.visible(n)}" for n in result.notes]
    body = {k: v for k, v in result.data.items() if k != "joints"}
    text = yaml.safe_dump(body, sort_keys=False, default_flow_style=None)
    rows = "".join("  - " + yaml.safe_dump(r, default_flow_style=True, sort_keys=False, width=10_000).strip() + "\n"
                   for r in result.data["joints"])
    return "\n".join(head) + "\n" + text + "joints:\n" + rows
