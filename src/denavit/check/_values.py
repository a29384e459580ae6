"""A claim's written value: its entries read into trees, its shape against the quantity's, joint values.

Moved unchanged from ``_engine.py`` (the reading half of a verdict).
"""

from __future__ import annotations

import math
import re
from typing import Any

import numpy as np

from .. import _expr
from ..errors import ParseError
from ..model import DHRobot, JointType
from ._latex import parse_math
from ._matrices import RaggedMatrix, after_last_equals, encloses, parse_matrix
from ._text import split_top

__all__ = ["numbers", "claim_cells", "decimals", "no_names", "joint_values", "determinant", "shape_readings",
           "shape_to", "ShapeMismatch", "MAX_ENTRIES", "MAX_DET_SIZE", "MAX_DET_WORK"]

#: Most entries in one claimed value (a 64-joint mass matrix has 4096).
MAX_ENTRIES = 4096


def claim_cells(raw: Any, resolve) -> list[list[tuple]]:
    """A claim's value: a LaTeX/plain string (matrix or scalar) or a YAML list (of lists)."""
    if isinstance(raw, (int, float)) and not isinstance(raw, bool):
        return [[_expr.parse(raw)]]
    if isinstance(raw, str):
        try:
            return parse_matrix(raw, resolve)
        except RaggedMatrix as exc:
            raise ShapeMismatch(str(exc)) from None
    if isinstance(raw, list) and raw:
        if all(isinstance(r, list) for r in raw):
            rows = raw
        else:
            rows = [[v] for v in raw]
        if sum(len(r) for r in rows) > MAX_ENTRIES:
            raise ParseError(f"the value has more than {MAX_ENTRIES} entries")
        out = []
        for i, row in enumerate(rows, start=1):
            cells = []
            for j, v in enumerate(row, start=1):
                try:
                    cells.append(_expr.parse(v) if isinstance(v, (int, float)) else parse_math(str(v), resolve))
                except ParseError as exc:
                    raise ParseError(f"entry ({i}, {j}) {str(v)[:40]!r}: {exc}") from None
            out.append(cells)
        if len({len(r) for r in out}) != 1:
            raise ShapeMismatch(f"rows of different lengths {[len(r) for r in out]} in the value")
        return out
    raise ParseError("'value' must be a formula (string) or a list of entries / rows")


def decimals(node: tuple) -> int:
    """The most decimals of any number written in a tree (0 if none)."""
    kind = node[0]
    if kind == "num":
        s = node[1]
        return len(s.split(".")[1]) if "." in s and "e" not in s.lower() else 0
    if kind == "neg":
        return decimals(node[1])
    if kind == "bin":
        return max(decimals(node[2]), decimals(node[3]))
    if kind == "call":
        return max((decimals(a) for a in node[2]), default=0)
    return 0


class ShapeMismatch(ParseError):
    """The claimed value has another shape than the quantity: a wrong result (verdict "incorrect: shape …")."""


def _describe(shape: tuple[int, ...]) -> str:
    if len(shape) == 0:
        return "one entry"
    if len(shape) == 1:
        return f"a vector of {shape[0]} entries"
    return f"a {shape[0]}×{shape[1]} matrix"


def _fits(claimed: list[list[tuple]], shape: tuple[int, ...]) -> bool:
    r, c = len(claimed), len(claimed[0])
    if len(shape) == 0:
        return (r, c) == (1, 1)
    if len(shape) == 1:
        return (r, c) in ((shape[0], 1), (1, shape[0]))
    return (r, c) == shape


def shape_to(claimed: list[list[tuple]], shape: tuple[int, ...]) -> list[list[tuple]]:
    r, c = len(claimed), len(claimed[0])
    if not _fits(claimed, shape):
        raise ShapeMismatch(f"expected {_describe(shape)}, got a {r}×{c} value")
    if len(shape) == 1 and (r, c) == (1, shape[0]) and shape[0] != 1:
        return [[x] for x in claimed[0]]
    return claimed


_ROW_NAMES = ("vx", "vy", "vz", "ωx", "ωy", "ωz")


def shape_readings(qty, spec: dict[str, Any], shape: tuple[int, ...], cells: list[list[tuple]]):
    """Ways to read a value of another shape as part of the quantity: [(label or None, function on one truth)].

    A 3×4 value of a pose is its top rows [R | p]; a 3-row (or 2-row) Jacobian or twist written without 'rows' is
    read as its linear rows, its angular rows, or the rows (vx, vy, ωz) of a planar arm.  None fits: ShapeMismatch.
    """
    if _fits(cells, shape):
        return [(None, lambda t: t)]
    r, c = len(cells), len(cells[0])
    out = []
    if qty.fk_like and shape == (4, 4) and (r, c) == (3, 4):
        out.append(("the top 3 rows [R | p] of the 4×4 transform", lambda t: t[:3]))
    if qty.name == "jacobian" and len(shape) == 2 and shape[0] != shape[1] and (r, c) == (shape[1], shape[0]):
        out.append(("the transpose Jᵀ (as in τ = Jᵀ F)", lambda t: t.T))
    if qty.fk_like and shape == (4, 4) and (r, c) == (3, 3):  # R_3_6 of a wrist derivation
        out.append(("the rotation block R of the 4×4 transform", lambda t: t[:3, :3]))
    six = (len(shape) >= 1 and shape[0] == 6 and qty.name in ("jacobian", "twist") and "rows" not in spec
           and "entry" not in spec)
    if six:
        tail = shape[1:]
        width_ok = (c == tail[0]) if tail else (c == 1 or r == 1)
        m = r if tail or c == 1 else c
        if width_ok and m in (2, 3):
            sets = [(0, 1, 2), (0, 1, 5), (3, 4, 5)] if m == 3 else [(0, 1)]
            for rows in sets:
                out.append((f"the rows ({', '.join(_ROW_NAMES[i] for i in rows)})", _take_rows(rows)))
    if not out:
        r, c = len(cells), len(cells[0])
        what = {"jacobian": " (rows v, ω; one column per joint)", "twist": " (v, ω)",
                "torques": " (one per joint)"}.get(qty.name, "")
        raise ShapeMismatch(f"expected {_describe(shape)}{what}, got a {r}×{c} value")
    return out


def _take_rows(rows: tuple[int, ...]):
    """The reading "these rows of the 6-row quantity"; ``.rows`` tells the correct formula which rows to show."""
    def take(t):
        return t[list(rows)]

    take.rows = rows  # type: ignore[attr-defined]
    return take


def no_names(ident) -> tuple:
    raise ParseError(f"unknown symbol {ident.plain!r} (joint values are numbers; pi is allowed)")


def numbers(raw: Any, n: int, what: str, *, marked: list[bool] | None = None) -> np.ndarray:
    """``"-pi/3, 0, \\frac{\\pi}{2}"`` or a YAML list → floats, read by the restricted LaTeX/plain reader.

    The list may be wrapped in ``[ ]`` or ``( )`` as pasted from a report; an entry written with a degree mark
    (``30^\\circ``, ``30^{\\circ}``, ``30°``) is converted to radians (``marked`` receives, per entry, whether
    it had one).
    """
    if isinstance(raw, str):
        text = raw.strip().strip("$").strip()
        assigned = _assignments(text, n)
        if assigned is not None:  # θ_1 = 0°, θ_2 = 90°, … (in any order)
            text = ", ".join(assigned)
        text = after_last_equals(text).strip()
        for a, b in (("\\left(", "\\right)"), ("\\left[", "\\right]")):
            if text.startswith(a) and text.endswith(b):
                text = text[len(a) - 1:len(text) - len(b)] + b[-1]
        if len(text) >= 2 and (text[0], text[-1]) in (("(", ")"), ("[", "]")) and encloses(text):
            text = text[1:-1]
        parts = split_top(text, (",", ";"))
        items: list[Any] = [p for p in parts if p.strip()]
    elif isinstance(raw, list):
        items = raw
    else:
        items = [raw]
    if len(items) != n:
        raise ParseError(f"{what}: expected {n} values, got {len(items)}")
    out = []
    for i, v in enumerate(items, start=1):
        try:
            node = _expr.parse(v) if isinstance(v, (int, float)) else parse_math(str(v), no_names, rhs=False)
            out.append(_expr.evaluate(node))
        except ParseError as exc:
            raise ParseError(f"{what}: value {i} ({str(v)[:40]!r}): {exc}") from None
        if marked is not None:
            marked.append(_has_degrees(node))
    return np.array(out, dtype=float)


_ASSIGNED = re.compile(r"\s*(?:\\(?:var)?theta|θ|q|Q|d)\s*_?\s*\{?\s*(\d{1,3})\s*\}?\s*=(.*)", re.S)


def _assignments(text: str, n: int) -> list[str] | None:
    """``θ_1 = 0, θ_2 = \\pi/2`` (each joint once, any order) → the values in joint order; None otherwise."""
    parts = [p for p in split_top(text, (",", ";")) if p.strip()]
    if len(parts) != n:
        return None
    found: dict[int, str] = {}
    for p in parts:
        m = _ASSIGNED.fullmatch(p)
        if m is None or "=" in m.group(2):
            return None
        found[int(m.group(1))] = m.group(2)
    if sorted(found) != list(range(1, n + 1)):
        return None
    return [found[k] for k in range(1, n + 1)]


def _has_degrees(node: tuple) -> bool:
    if node[0] == "call":
        return node[1] == "deg" or any(_has_degrees(a) for a in node[2])
    if node[0] == "neg":
        return _has_degrees(node[1])
    if node[0] == "bin":
        return _has_degrees(node[2]) or _has_degrees(node[3])
    return False


_DEG_HEADER = re.compile(r"\[\s*deg\s*\]|\(\s*deg\s*\)|\[\s*°\s*\]|\\text\{\s*deg\s*\}")


def joint_values(raw: Any, robot: DHRobot, what: str, deg: bool) -> np.ndarray:
    if isinstance(raw, str) and "=" in raw and _DEG_HEADER.search(raw[:raw.rindex("=")]):
        deg = True  # (θ_1, …, θ_6)[deg] = (0, 45, …): the unit is written before the values
    marked: list[bool] = []
    vals = numbers(raw, robot.dof, what, marked=marked)
    if deg:  # angle_unit: deg - except entries that carry their own degree mark (already in radians)
        rev = np.array([t is JointType.REVOLUTE for t in robot.joint_types]) & ~np.array(marked, dtype=bool)
        vals = np.where(rev, np.radians(vals), vals)
    return vals


#: Largest matrix whose determinant a det_jacobian claim may write out (``\\begin{vmatrix} … \\end{vmatrix}``).
MAX_DET_SIZE = 6
#: Bound on the work of expanding such a determinant (tree nodes of the entries × (n − 1)!).
MAX_DET_WORK = 200_000


def determinant(cells: list[list[tuple]]) -> tuple:
    """det of a square matrix of trees, by Laplace expansion (sums balanced, so the tree stays shallow)."""
    import itertools

    n = len(cells)
    work = sum(_tree_size(c) for row in cells for c in row) * math.factorial(n - 1)
    if work > MAX_DET_WORK:
        raise ParseError(f"the determinant written out is too large to expand ({n}×{n} with long entries); "
                         "give its value instead")
    terms = []
    for perm in itertools.permutations(range(n)):
        inversions = sum(perm[a] > perm[b] for a in range(n) for b in range(a + 1, n))
        term = _balanced("*", [cells[i][perm[i]] for i in range(n)])
        terms.append(("neg", term) if inversions % 2 else term)
    return _balanced("+", terms)


def _tree_size(node: tuple) -> int:
    size, stack = 0, [node]
    while stack:
        nd = stack.pop()
        size += 1
        if nd[0] == "neg":
            stack.append(nd[1])
        elif nd[0] == "bin":
            stack += [nd[2], nd[3]]
        elif nd[0] == "call":
            stack += list(nd[2])
    return size


def _balanced(op: str, nodes: list[tuple]) -> tuple:
    while len(nodes) > 1:
        nodes = [("bin", op, nodes[k], nodes[k + 1]) if k + 1 < len(nodes) else nodes[k] for k in range(0, len(nodes), 2)]
    return nodes[0]
