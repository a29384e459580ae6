"""Matrices and lists as people write them: LaTeX matrix environments, ``[a, b; c, d]``, ``[[a, b], [c, d]]``.

Each cell is read by :func:`._latex.parse_math`; only the part after the last ``=`` counts.
"""

from __future__ import annotations

import re

from ..errors import ParseError
from ._latex import parse_math
from ._text import after_last_equals, strip_equation_number
from ._tokens import MAX_CHARS, Resolver, normalize

__all__ = ["RaggedMatrix", "split_matrix", "after_last_equals", "split_list", "encloses", "parse_matrix"]


class RaggedMatrix(ParseError):
    """A matrix whose rows have different lengths (for a claim: a value of the wrong shape, not unreadable)."""


_BEGIN = re.compile(r"\\begin\{([bBpvV]?matrix|array)\}(?:\{[^{}]*\})?")


def split_matrix(text: str) -> list[list[str]] | None:
    """The cells of the (first) LaTeX matrix environment in ``text``, or None if there is none.

    Linear time: the first ``\\begin{…matrix}`` is found by one regex search (no backtracking across the
    text) and its ``\\end`` by a plain substring search; a ``\\begin`` without its ``\\end`` is an error.
    """
    if len(text) > MAX_CHARS:
        raise ParseError(f"expression longer than {MAX_CHARS} characters")
    text = normalize(text)
    m = _BEGIN.search(text)
    if m is None:
        return None
    end = text.find("\\end{" + m.group(1) + "}", m.end())
    if end < 0:
        raise ParseError(f"\\begin{{{m.group(1)}}} without its \\end{{{m.group(1)}}}")
    body = text[m.end():end]
    rows = [r for r in re.split(r"\\\\(?:\[[^\]]*\])?", body) if r.strip() and not r.strip().startswith("\\hline")]
    return [[c.strip() for c in r.split("&")] for r in rows]


def split_list(text: str) -> list[list[str]] | None:
    """``[a, b, c]`` / ``(a, b, c)`` (a column) or ``[a, b; c, d]`` / ``[[a, b], [c, d]]`` (rows), else None."""
    t = text.strip()
    for a, b in (("\\left[", "\\right]"), ("\\left(", "\\right)")):
        if t.startswith(a) and t.endswith(b):
            t = t[len(a) - 1:len(t) - len(b)] + b[-1]
    if len(t) < 2 or (t[0], t[-1]) not in (("[", "]"), ("(", ")")) or not encloses(t):
        return None
    from ._text import split_top

    body = t[1:-1]
    rows = split_top(body, (";", "\\\\"))
    if len(rows) > 1:
        return [[c.strip() for c in split_top(r, (",", "&"))] for r in rows if r.strip()]
    items = [c.strip() for c in split_top(body, (",",))]
    if len(items) < 2:
        return None
    if all(len(i) >= 2 and i[0] == "[" and i[-1] == "]" and encloses(i) for i in items):
        return [[c.strip() for c in split_top(i[1:-1], (",",))] for i in items]
    return [[c] for c in items]


def encloses(t: str) -> bool:
    """The first bracket of ``t`` closes at its last character."""
    level = 0
    for k, ch in enumerate(t):
        level += ch in "([{"
        level -= ch in ")]}"
        if level == 0:
            return k == len(t) - 1
    return False


def parse_matrix(text: str, resolve: Resolver) -> list[list[tuple]]:
    """A LaTeX matrix (or a single expression, as a 1×1 matrix) → rows of trees; errors name the entry.

    Only the part after the last ``=`` counts (a definition pasted before it is skipped); a bracketed list
    ``[a, b, c]`` is a column and ``[a, b; c, d]`` a matrix.  Rows of different lengths raise
    :class:`RaggedMatrix`.
    """
    if len(text) > MAX_CHARS:
        raise ParseError(f"expression longer than {MAX_CHARS} characters")
    text = after_last_equals(strip_equation_number(text))
    cells = split_matrix(text)
    if cells is None:
        cells = split_list(normalize(text))
    if cells is None:
        return [[parse_math(text, resolve)]]
    if not cells:
        raise ParseError("empty matrix")
    width = max(len(r) for r in cells)
    if any(len(r) != width for r in cells):
        raise RaggedMatrix(f"rows of different lengths {[len(r) for r in cells]} in the matrix")
    out = []
    for i, row in enumerate(cells, start=1):
        out_row = []
        for j, cell in enumerate(row, start=1):
            try:
                out_row.append(parse_math(cell, resolve, rhs=False))
            except ParseError as exc:
                raise ParseError(f"entry ({i}, {j}) {cell[:40]!r}: {exc}") from None
        out.append(out_row)
    return out
