"""Right-hand sides students write that the checker's value reader does not take as they are.

``τ = \\begin{bmatrix} … \\end{bmatrix} \\begin{bmatrix} f_x \\\\ … \\\\ n_z \\end{bmatrix}`` (a matrix times the
wrench) is written out entry by entry, ``(a)(f_x) + (b)(f_y) + …``, so the one checker judges it as τ(F); a value
is "numeric" when it holds numbers only (a value at a case, not a formula); the wrench's symbols are the ones the
section names.  String work only, bounded by the checker's own limits (matrices of at most 8×8 here).
"""

from __future__ import annotations

import re

from ._context import is_numeric, vector_entries
from ._split import top_level_split

__all__ = ["matrices", "scale_matrix", "expand_product", "numeric_value", "wrench_symbols", "WRENCH_NAMES",
           "missing_plus", "cells"]

_MAT = re.compile(r"\\begin\{([bBpv]?matrix)\}")
#: The wrench's symbols, in the order (f, n), as the checker names them.
WRENCH_NAMES = ("f_x", "f_y", "f_z", "n_x", "n_y", "n_z")
_SYMBOL = re.compile(r"(?<![A-Za-z\\])([fFnN])_\{?([xyz])\}?")


def matrices(text: str) -> list[str] | None:
    """``text`` as a sequence of whole matrix environments (and nothing else but spaces), or None."""
    out, k = [], 0
    t = text.strip()
    while k < len(t):
        while k < len(t) and t[k].isspace():
            k += 1
        if k >= len(t):
            break
        m = _MAT.match(t, k)
        if not m:
            return None
        end = t.find("\\end{" + m.group(1) + "}", m.end())
        if end < 0:
            return None
        stop = end + len("\\end{" + m.group(1) + "}")
        out.append(t[k:stop])
        k = stop
    return out


def cells(matrix: str) -> list[list[str]]:
    """The entries of one matrix environment, row by row, as written."""
    m = _MAT.match(matrix)
    body = matrix[m.end():matrix.rfind("\\end{")]
    rows = [r for r in top_level_split(body, ("\\\\",)) if r.strip()]
    return [[c.strip() for c in top_level_split(r, ("&",))] for r in rows]


def expand_product(value: str) -> str | None:
    """``[M] [v]`` (a matrix times a column vector) written out as one column vector, or None if not that form."""
    mats = matrices(value)
    if mats is None or len(mats) != 2:
        return None
    a = cells(mats[0])
    v = vector_entries(mats[1])
    if not a or v is None or len(a) > 8 or any(len(r) != len(v) for r in a) or len(v) > 8:
        return None
    rows = []
    for r in a:
        terms = [f"({x})({y})" for x, y in zip(r, v) if x.strip() not in ("0", "") and y.strip() not in ("0", "")]
        rows.append(" + ".join(terms) if terms else "0")
    return "\\begin{bmatrix} " + " \\\\ ".join(rows) + " \\end{bmatrix}"


def numeric_value(value: str) -> bool:
    """A value with numbers only (entries of a matrix included): a result at a case, not a formula."""
    t = re.sub(r"\\(?:begin|end)\{[bBpvV]?matrix\}|\\\\|&", " ", value)
    return is_numeric(t)


def wrench_symbols(*texts: str) -> list[str]:
    """The wrench symbols written in ``texts`` (``f_x``, ``F_y``, ``n_z`` …), in the checker's (f, n) order."""
    seen = {f"{m.group(1).lower()}_{m.group(2)}" for t in texts for m in _SYMBOL.finditer(t)}
    return [n for n in WRENCH_NAMES if n in seen]


_SCALED = re.compile(r"^([^\\=]{0,0}(?:[^=]{1,200}?))\s*(\\begin\{([bBpv]?matrix)\}.*\\end\{\3\})\s*$", re.S)


def scale_matrix(value: str) -> str | None:
    """``g \\begin{bmatrix} a \\\\ b \\end{bmatrix}`` (a factor before one matrix) with the factor in every entry."""
    m = _SCALED.match(value.strip())
    if m is None or "\\begin" in m.group(1) or not m.group(1).strip():
        return None
    factor = m.group(1)
    if re.search(r"[-+=]|\{\}|\\(?:times|cdot|left|right)|(?<![a-z\\])[A-Z](?![a-z])|\b[wvfn]_", factor):
        return None  # "{}^1R^0 w_0 + [..]": a sum with other results, not a factor
    mats = matrices(m.group(2))
    if mats is None or len(mats) != 1:
        return None
    factor = factor.strip()
    rows = [" & ".join(f"({factor})({c})" for c in r) for r in cells(mats[0])]
    return "\\begin{bmatrix} " + " \\\\ ".join(rows) + " \\end{bmatrix}"


#: A square written right before a bracket: ``P_y^2 (P_z - d_1)^2``, where a sum of squares lost its '+'.
_SQUARE_THEN_BRACKET = re.compile(r"\^\s*\{?\s*2\s*\}?(?=\s*(?:\\left\s*)?[(\[])")


def missing_plus(text: str, most: int = 4) -> list[tuple[str, str]]:
    """``text`` with a '+' put between a square and a bracketed square after it, one place at a time (at most
    ``most``), each with where it was put: the slip of a sum of squares, ``P_x^2 + P_y^2 (P_z - d_1)^2``
    for ``P_x^2 + P_y^2 + (P_z - d_1)^2``.  Only where the bracket is itself squared."""
    out = []
    for m in _SQUARE_THEN_BRACKET.finditer(text):
        rest = re.sub(r"^\s*(?:\\left\s*)?", "", text[m.end():])
        depth, k = 0, 0
        for k, ch in enumerate(rest):
            depth += ch in "([{"
            depth -= ch in ")]}"
            if depth == 0:
                break
        if depth != 0 or not re.match(r"\s*(?:\\right\s*[)\]]\s*)?\^\s*\{?\s*2", rest[k + 1:]):
            continue
        head = text[:m.end()].rstrip()
        left = re.search(r"[A-Za-z0-9_{}\\]{0,24}\^\s*\{?\s*2\s*\}?$", head)
        tail = text[m.end():].lstrip()
        right = tail[:len(tail) - len(rest) + k + 1]
        out.append((head + " + " + tail, f"between {left.group(0) if left else head[-12:]} and {right}^2"))
        if len(out) >= most:
            break
    return out
