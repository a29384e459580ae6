"""Finding the DH table in pasted text: the header row (columns a, alpha, d, theta in any order, tab, ``|`` or ``&``
separated) and the data rows under it, within the size limits below (see :mod:`denavit.tables`)."""

from __future__ import annotations

import re

from .errors import ParseError

__all__ = ["find_table", "find_tables", "column_kind", "plain_cell", "COLUMNS", "MAX_TABLE_CHARS", "MAX_TABLE_ROWS", "MAX_COLUMNS",
           "MAX_LINE_CHARS", "MAX_CELL_CHARS"]

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
COLUMNS = ("a", "alpha", "d", "theta")
_RULE_CHARS = frozenset(" \t:|-")


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


def _spaced(line: str) -> list[str]:
    """The cells of a row of a space-separated table (its header named a column with every word)."""
    return line.split()


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


def plain_cell(cell: str) -> str:
    s = cell.replace("$", " ").replace("\\", " ").replace("{", " ").replace("}", " ").lower()
    s = s.replace("θ", "theta").replace("α", "alpha").replace("ϑ", "theta")
    return re.sub(r"\s+", " ", s).strip()


def column_kind(cell: str) -> str | None:
    """``a``/``alpha``/``d``/``theta``/``index`` from a header cell, or None."""
    s = re.sub(r"\([^()]*\)|\[[^\[\]]*\]", " ", plain_cell(cell)).strip()  # drop units and "(z_{i-1})" remarks
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


def _header_at(line: str):
    """(cells, splitter) when ``line`` is a DH header row (names a, alpha, d and theta), else None."""
    if len(line) > MAX_LINE_CHARS:
        return None  # prose, not a header
    cells, split = _cells(line), _cells
    if not cells and 4 <= len(line.split()) <= MAX_COLUMNS and all(map(column_kind, line.split())):
        cells, split = line.split(), _spaced  # "i a alpha d theta": every word names a column
    if len(cells) > MAX_COLUMNS or any(len(c) > MAX_CELL_CHARS for c in cells):
        return None
    kinds = [column_kind(c) for c in cells]
    if len(cells) >= 4 and all(c in kinds for c in COLUMNS):
        return cells, split
    return None


def _rows_under(lines: list[str], k: int, cells: list[str], split) -> tuple[list[list[str]], int]:
    """The data rows under the header on line ``k`` (0-based) and the index of the last line read."""
    rows: list[list[str]] = []
    last = k
    for n, nxt in enumerate(lines[k + 1:], start=k + 2):
        if _is_rule(nxt):
            continue  # Markdown rule
        if len(nxt) > MAX_LINE_CHARS:
            raise ParseError(f"line {n}: longer than {MAX_LINE_CHARS} characters")
        c = split(nxt)
        if split is _spaced and len(c) > len(cells):
            raise ParseError(f"line {n}: {len(c)} cells under a header of {len(cells)} separated by spaces: "
                             "a cell of such a table cannot hold a space (write pi/2, not pi / 2; or "
                             "separate the columns with tabs or |)")
        if len(c) != len(cells) or not any(x.strip() for x in c):
            if rows:
                break
            continue
        long = [x for x in c if len(x) > MAX_CELL_CHARS]
        if long:
            raise ParseError(f"line {n}: a cell longer than {MAX_CELL_CHARS} characters")
        rows.append(c)
        last = n - 1
        if len(rows) > MAX_TABLE_ROWS:
            raise ParseError(f"line {n}: more than {MAX_TABLE_ROWS} rows in the table")
    if not rows:
        raise ParseError(f"line {k + 1}: a DH header but no rows under it")
    return rows, last


def find_table(text: str) -> tuple[list[str], list[list[str]]]:
    """The header cells and data rows of the first DH table in ``text``."""
    if len(text) > MAX_TABLE_CHARS:
        raise ParseError(f"file too large for a table ({len(text)} characters; at most {MAX_TABLE_CHARS})")
    lines = text.splitlines()
    for k, line in enumerate(lines):
        head = _header_at(line)
        if head is not None:
            rows, _ = _rows_under(lines, k, *head)
            return head[0], rows
    raise ParseError("no DH table found: expected a header row naming the columns a, alpha, d, theta "
                     "(tab, |, & or space separated)")


def find_tables(lines: list[str]) -> list[tuple[int, int, str | None]]:
    """Every DH table among ``lines``: (first line, last line, None) 1-based, or (line, line, why) for a header
    whose rows cannot be read.  Tables follow one another; a header inside a table's rows starts no new one."""
    found: list[tuple[int, int, str | None]] = []
    k = 0
    while k < len(lines):
        head = _header_at(lines[k])
        if head is None:
            k += 1
            continue
        try:
            _, last = _rows_under(lines, k, *head)
        except ParseError as exc:
            found.append((k + 1, k + 1, str(exc)))
            k += 1
            continue
        found.append((k + 1, last + 1, None))
        k = last + 1
    return found
