"""The verdict on one claim: read it, evaluate it and the truth at random points, compare, explain.

Equivalence is decided by evaluation, never by comparing text: the claimed formula and the library's
value are computed at several random configurations (and, when the claim keeps parameters as symbols,
at random parameter values too).  Different but equal forms (cos(q1 + q2) and c1 c2 − s1 s2, √3/2 and
0.866…) therefore agree.  A trigonometric polynomial that vanishes at six random points drawn from a
continuous distribution is zero with probability one; the tolerance is 1e-9 relative for exact claims and
one unit of the last decimal written for claims written with rounded decimals.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, field, replace
from functools import lru_cache
from typing import Any

import numpy as np

from .. import _expr
from ..errors import DenavitError, ParseError
from ..io import with_parameters
from ..model import DHRobot, JointType
from ._hints import hints_for
from ._latex import Ident, RaggedMatrix, after_last_equals, encloses, parse_math, parse_matrix, split_list
from ._text import split_top
from ._quantities import Point, quantity
from ._resolve import robot_resolver

__all__ = ["Verdict", "check_claim", "N_POINTS", "EXACT_RTOL", "MAX_ENTRIES"]

N_POINTS = 6
#: Most entries in one claimed value (a 64-joint mass matrix has 4096).
MAX_ENTRIES = 4096
N_PARAM_SETS = 2
EXACT_RTOL = 1e-9
#: Longest name a claim's 'where' may define.
MAX_NAME = 40


@dataclass(frozen=True)
class Verdict:
    """The verdict on one claim: ``verdict`` is ``correct``, ``incorrect`` or ``unreadable``."""

    id: str
    quantity: str
    verdict: str
    message: str
    entries: tuple[dict[str, Any], ...] = ()
    counterexample: dict[str, Any] | None = None
    hints: tuple[str, ...] = ()
    expected: Any = None
    method: str = ""
    extra: dict[str, Any] = field(default_factory=dict)

    def to_json(self) -> dict[str, Any]:
        out = {"id": self.id, "quantity": self.quantity, "verdict": self.verdict, "message": self.message,
               "entries": list(self.entries), "counterexample": self.counterexample, "hints": list(self.hints),
               "expected": self.expected, "method": self.method}
        out.update(self.extra)
        return out


def _values(raw: Any, resolve) -> list[list[tuple]]:
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


def _decimals(node: tuple) -> int:
    """The most decimals of any number written in a tree (0 if none)."""
    kind = node[0]
    if kind == "num":
        s = node[1]
        return len(s.split(".")[1]) if "." in s and "e" not in s.lower() else 0
    if kind == "neg":
        return _decimals(node[1])
    if kind == "bin":
        return max(_decimals(node[2]), _decimals(node[3]))
    if kind == "call":
        return max((_decimals(a) for a in node[2]), default=0)
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


def _shape_to(claimed: list[list[tuple]], shape: tuple[int, ...]) -> list[list[tuple]]:
    r, c = len(claimed), len(claimed[0])
    if not _fits(claimed, shape):
        raise ShapeMismatch(f"expected {_describe(shape)}, got a {r}×{c} value")
    if len(shape) == 1 and (r, c) == (1, shape[0]) and shape[0] != 1:
        return [[x] for x in claimed[0]]
    return claimed


_ROW_NAMES = ("vx", "vy", "vz", "ωx", "ωy", "ωz")


def _readings(qty, spec: dict[str, Any], shape: tuple[int, ...], cells: list[list[tuple]]):
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
                out.append((f"the rows ({', '.join(_ROW_NAMES[i] for i in rows)})",
                            lambda t, rows=rows: t[list(rows)]))
    if not out:
        r, c = len(cells), len(cells[0])
        what = {"jacobian": " (rows v, ω; one column per joint)", "twist": " (v, ω)",
                "torques": " (one per joint)"}.get(qty.name, "")
        raise ShapeMismatch(f"expected {_describe(shape)}{what}, got a {r}×{c} value")
    return out


def _no_names(ident) -> tuple:
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
            node = _expr.parse(v) if isinstance(v, (int, float)) else parse_math(str(v), _no_names, rhs=False)
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


def _joint_values(raw: Any, robot: DHRobot, what: str, deg: bool) -> np.ndarray:
    if isinstance(raw, str) and "=" in raw and _DEG_HEADER.search(raw[:raw.rindex("=")]):
        deg = True  # (θ_1, …, θ_6)[deg] = (0, 45, …): the unit is written before the values
    marked: list[bool] = []
    vals = numbers(raw, robot.dof, what, marked=marked)
    if deg:  # angle_unit: deg - except entries that carry their own degree mark (already in radians)
        rev = np.array([t is JointType.REVOLUTE for t in robot.joint_types]) & ~np.array(marked, dtype=bool)
        vals = np.where(rev, np.radians(vals), vals)
    return vals


def _sample_q(robot: DHRobot, rng: np.random.Generator) -> np.ndarray:
    lo, hi = robot.q_limits.T
    lo = np.where(np.isfinite(lo), lo, -np.pi)
    hi = np.where(np.isfinite(hi), hi, np.pi)
    return rng.uniform(np.maximum(lo, -np.pi), np.minimum(hi, np.pi))


def _gravity_name(robot: DHRobot) -> list[str]:
    """``g`` (the magnitude of the robot's gravity) is a known name unless the robot has a parameter g."""
    return [] if "g" in robot.parameter_values else ["g"]


#: Bases of the names a symbolic wrench may use, with subscript x, y, z or 1 … 6 (``f_x``, ``F_y``, ``n_z``, ``F_1``).
WRENCH_BASES = ("f", "F", "n", "N", "m", "M")


def _wrench_nodes(raw: Any, robot: DHRobot) -> list[tuple]:
    """A claim's 'wrench': 6 entries (f, n) or 3 (a pure force), numbers or symbols such as ``f_x``."""
    known = robot_resolver(robot)

    def resolve(ident):
        if ident.dots == 0 and ident.base in WRENCH_BASES and ident.sub in ("x", "y", "z", "1", "2", "3", "4", "5", "6"):
            return ("name", ident.base + ident.sub)
        return known(ident)

    if isinstance(raw, str):
        text = raw.strip().strip("$").strip()
        cells = split_list(text) if text[:1] in "([" else [[c] for c in split_top(text, (",", ";"))]
        items: list[Any] = [c for row in cells or [[text]] for c in row if str(c).strip()]
    elif isinstance(raw, list):
        items = raw
    else:
        items = [raw]
    if len(items) not in (3, 6):
        raise ParseError(f"wrench: expected 6 values (f, n) or 3 (a force), got {len(items)}")
    out = []
    for i, v in enumerate(items, start=1):
        try:
            out.append(_expr.parse(v) if isinstance(v, (int, float)) else parse_math(str(v), resolve, rhs=False))
        except ParseError as exc:
            raise ParseError(f"wrench: value {i} ({str(v)[:40]!r}): {exc}") from None
    zero = ("num", "0")
    return out + [zero] * (6 - len(out))


def _points(robot: DHRobot, spec: dict[str, Any], names: set[str], needs, rng, deg: bool, *,
            wrench: list[tuple] | None = None, symbols: list[str] = ()) -> list[Point]:
    """Evaluation points: the claim's q (or random ones), its q̇/wrench (or random), robot parameter sets."""
    params = [k for k, _ in robot.parameters]
    robots = [robot]
    varied = names & (set(params) | {"g"})
    if varied:
        for _ in range(N_PARAM_SETS):
            r = with_parameters(robot, **{k: v * rng.uniform(0.6, 1.4) if v else rng.uniform(0.1, 1.0)
                                          for k, v in robot.parameters if k in names})
            if "g" in names and "g" not in params:  # the symbol g: the same direction, another magnitude
                r = r.replace(gravity=tuple(float(x) * rng.uniform(0.6, 1.4) for x in r.gravity))
            robots.append(r)
    fixed_q = _joint_values(spec["q"], robot, "q", deg) if "q" in spec else None
    fixed_qd = _joint_values(spec["qd"], robot, "qd", deg) if "qd" in spec else None
    fixed_qdd = _joint_values(spec["qdd"], robot, "qdd", deg) if "qdd" in spec else None
    uses_qdd = any(n.startswith("qdd") and n[3:].isdigit() for n in names)
    if "wrench" in needs and wrench is None:
        raise ParseError("this claim needs 'wrench' (6 numbers or symbols f, n; or 3 for a force)")
    uses_q = any(n.startswith("q") and n[1:].isdigit() for n in names)
    uses_qd = any(n.startswith("qd") and n[2:].isdigit() for n in names)
    # a quantity of the rates claimed without 'qd' and without rates (ⁱvᵢ = 0, a constant): it must hold at any
    # rates, so it is checked at random ones
    const_qd = "qd" in needs and fixed_qd is None and not uses_qd
    const_qd = const_qd or ("qdd" in needs and fixed_qdd is None and not uses_qdd)
    n_q = N_POINTS if ((uses_q and fixed_q is None) or (uses_qd and fixed_qd is None) or symbols or const_qd
                       or (uses_qdd and fixed_qdd is None)) else 1
    pts = []
    for r in robots:
        for _ in range(n_q):
            q = fixed_q if fixed_q is not None else _sample_q(robot, rng)
            qd = fixed_qd if fixed_qd is not None else rng.normal(size=robot.dof)
            qdd = fixed_qdd if fixed_qdd is not None else rng.normal(size=robot.dof)
            sym = tuple((s, float(rng.normal())) for s in symbols)
            w = None
            if wrench is not None:
                env = {**r.parameter_values, **dict(sym)}
                w = np.array([_expr.evaluate(nd, env) for nd in wrench], dtype=float)
            pts.append(Point(r, q, qd, w, sym, qdd))
    return pts


def _env(p: Point) -> dict[str, float]:
    env = dict(p.robot.parameters)
    if "g" not in env:
        env["g"] = float(np.linalg.norm(p.robot.gravity))
    env.update(p.symbols)
    for k in range(p.robot.dof):
        env[f"q{k + 1}"] = float(p.q[k])
        if p.qd is not None:
            env[f"qd{k + 1}"] = float(p.qd[k])
        if p.qdd is not None:
            env[f"qdd{k + 1}"] = float(p.qdd[k])
    return env


#: Largest matrix whose determinant a det_jacobian claim may write out (``\\begin{vmatrix} … \\end{vmatrix}``).
MAX_DET_SIZE = 6
#: Bound on the work of expanding such a determinant (tree nodes of the entries × (n − 1)!).
MAX_DET_WORK = 200_000


def _determinant(cells: list[list[tuple]]) -> tuple:
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


def _where_nodes(raw: Any, robot: DHRobot, extra: list[str]) -> list[tuple[str, tuple]]:
    """A claim's 'where': names a derivation introduces (``k: a_2``, ``x_c: p_x - d_6 a_x``…), each a formula in
    the robot's names and the names defined before it, in order."""
    from ._ik_claims import MAX_WHERE

    if raw is None:
        return []
    if not isinstance(raw, dict):
        raise ParseError("'where' must be a mapping of names to formulas, in evaluation order")
    if len(raw) > MAX_WHERE:
        raise ParseError(f"'where' has {len(raw)} definitions; at most {MAX_WHERE}")
    out: list[tuple[str, tuple]] = []
    for key, text in raw.items():
        name = re.sub(r"[^A-Za-z0-9]", "", str(key)[:10 * MAX_NAME])
        if len(name) > MAX_NAME:
            raise ParseError(f"'where' name longer than {MAX_NAME} characters")
        if not name or name[0].isdigit():
            raise ParseError(f"'where' names must start with a letter, got {str(key)[:40]!r}")
        m = re.fullmatch(r"([A-Za-z]+?)(\d*)", name)
        try:  # a name that already means something (q1, L1, C12, pi, g) cannot be redefined
            meaning = robot_resolver(robot, extra=extra)(Ident(m.group(1), m.group(2))) if m else None
        except ParseError:
            meaning = None
        if meaning is not None or name in ("pi", "e"):
            raise ParseError(f"'where' cannot redefine {name!r}: it already means {_expr.to_text(meaning) if meaning else name}")
        try:
            node = (_expr.parse(text) if isinstance(text, (int, float)) and not isinstance(text, bool)
                    else parse_math(str(text), robot_resolver(robot, extra=extra + [n for n, _ in out]), rhs=False))
        except ParseError as exc:
            raise ParseError(f"where {name}: {exc}") from None
        out.append((name, node))
    return out


def _evaluate(cells: list[list[tuple]], p: Point, where: list[tuple[str, tuple]] = ()) -> np.ndarray:
    env = _env(p)
    for name, node in where:
        env[name] = _expr.evaluate(node, env)
    return np.array([[_expr.evaluate(c, env) for c in row] for row in cells], dtype=float)


def check_claim(robot: DHRobot, raw: dict[str, Any], label: str, rng: np.random.Generator,
                deg: bool = False, *, detail: bool = True) -> Verdict:
    """Read, evaluate and judge one claim (a mapping from the claims file).

    ``detail=False`` skips the costly part of an incorrect verdict (the search for hints and the correct
    formula); the verdict itself, the entries and the counterexample are the same.
    """
    cid = str(raw.get("id", label))[:80] if isinstance(raw, dict) else label
    qname = str(raw.get("quantity", "?"))[:80] if isinstance(raw, dict) else "?"
    try:
        if not isinstance(raw, dict):
            raise ParseError("a claim must be a mapping with at least 'quantity' and 'value'")
        if "value" not in raw:
            raise ParseError("the claim has no 'value'")
        special = _special(str(raw.get("quantity")))
        if special is not None:
            return special(robot, raw, cid, rng, bool(raw.get("deg", deg)))
        qty, extra = quantity(raw.get("quantity"))
        spec = {**extra, **{k: v for k, v in raw.items() if k not in ("id", "quantity", "value")}}
        deg = bool(spec.get("deg", deg))
        wrench = _wrench_nodes(spec["wrench"], robot) if "wrench" in spec else None
        symbols = sorted({n for nd in wrench or () for n in _expr.names_in(nd)} - {k for k, _ in robot.parameters})
        where = _where_nodes(spec.get("where"), robot, symbols + _gravity_name(robot))
        spec["_where"] = where
        cells = _values(raw["value"], robot_resolver(robot, extra=symbols + _gravity_name(robot)
                                                     + [n for n, _ in where]))
        if qty.name == "det_jacobian" and len(cells) * len(cells[0]) > 1 and 1 in (len(cells), len(cells[0])):
            factors = [c for row in cells for c in row]  # det J written as a list of its factors
            prod = factors[0]
            for f in factors[1:]:
                prod = ("bin", "*", prod, f)
            cells = [[prod]]
        elif qty.name == "det_jacobian" and 1 < len(cells) == len(cells[0]) <= MAX_DET_SIZE:
            cells = [[_determinant(cells)]]  # |a b; c d| (a vmatrix): the determinant of the matrix written
        names: set[str] = set()
        for row in cells:
            for c in row:
                names |= _expr.names_in(c)
        if where:  # the names the definitions use count as used (random q, parameter sets)
            used = {n for n, _ in where} & names
            for n, nd in reversed(where):
                if n in used:
                    used |= _expr.names_in(nd)
            names = (names | used) - {n for n, _ in where}
        points = _points(robot, spec, names, qty.needs, rng, deg, wrench=wrench, symbols=symbols)
        if "entry" in spec:  # one entry of the quantity: hints then compare that entry too
            qty = replace(qty, truth=_entry_of(qty.truth))
        truth = np.array([np.asarray(qty.truth(p, spec), dtype=float) for p in points])  # (P, *shape)
        try:
            readings = _readings(qty, spec, truth.shape[1:], cells)
        except ShapeMismatch as exc:
            return Verdict(cid, qty.name, "incorrect", f"incorrect: shape: {exc}", expected=truth[0].tolist(),
                           method="the shape of the value compared with the quantity's")
    except ShapeMismatch as exc:
        return Verdict(cid, qname, "incorrect", f"incorrect: shape: {exc}",
                       method="the shape of the value compared with the quantity's")
    except ParseError as exc:
        return Verdict(cid, qname, "unreadable", str(exc))
    if len(readings) == 1 and readings[0][0] is None:
        if qty.name == "jacobian" and len(truth.shape) == 3 and truth.shape[1] == truth.shape[2] and (
                spec.get("transpose") is True or (isinstance(raw["value"], str) and _says_transpose(raw["value"]))):
            readings = [("the transpose Jᵀ (as the claim writes it)", lambda t: t.T)]
        else:
            return _compare(robot, cid, qty, spec, cells, points, truth, rng, detail)
    verdicts = []
    for label, fn in readings:
        q2 = replace(qty, truth=lambda p, s, f=fn, t=qty.truth: f(np.asarray(t(p, s), dtype=float)))
        t2 = np.array([fn(t) for t in truth])
        v = _compare(robot, cid, q2, spec, _shape_to(cells, t2.shape[1:]), points, t2, rng, False)
        if v.verdict == "correct":
            return replace(v, message=f"{v.message}, read as {label}")
        verdicts.append((len(v.entries), label, q2, t2))
    _, label, q2, t2 = min(verdicts, key=lambda x: x[0])
    v = _compare(robot, cid, q2, spec, _shape_to(cells, t2.shape[1:]), points, t2, rng, detail)
    others = "; ".join(lb for _, lb, _, _ in verdicts if lb != label)
    return replace(v, message=f"{v.message}, read as {label}" + (f" (also wrong read as {others})" if others else ""))


_TRANSPOSED = re.compile(r"\^\s*(?:T|\{\s*T\s*\}|\\top|\{\s*\\top\s*\})(?![A-Za-z])")


def _says_transpose(text: str) -> bool:
    """``J^T = …`` / ``J_\\theta^{T} = …``: the left side names a transposed matrix."""
    head = text[:len(text) - len(after_last_equals(text))]
    return bool(_TRANSPOSED.search(head))


def _compare(robot, cid, qty, spec, cells, points, truth, rng, detail) -> Verdict:
    """The verdict on claimed cells (already of the truth's shape) against the truth at the points."""
    try:
        cells = _shape_to(cells, truth.shape[1:])
        claimed = np.array([_evaluate(cells, p, spec.get("_where", ())).reshape(truth.shape[1:]) for p in points])
    except ParseError as exc:
        return Verdict(cid, qty.name, "unreadable", str(exc))
    dec = np.array([[_decimals(c) for c in row] for row in cells]).reshape(truth.shape[1:])
    tol = np.where(dec >= 2, 10.0 ** (-dec.astype(float)), 0.0)  # one unit of the last decimal written
    scale = np.maximum(1.0, np.abs(truth))
    ok_tight = np.abs(claimed - truth) <= EXACT_RTOL * scale
    ok = np.abs(claimed - truth) <= EXACT_RTOL * scale + tol
    method = (f"evaluated at {len(points)} point(s)" + (" (random q)" if len(points) > 1 else "")
              + ", compared with the numeric engine")
    expected = truth[0].tolist()
    if ok.all():
        how = "exactly" if ok_tight.all() else "to the decimals written"
        return Verdict(cid, qty.name, "correct", f"correct ({how})", expected=expected, method=method)
    if qty.name in ("potential_energy", "lagrangian") and _constant_offset(claimed - truth, points, tol):
        return Verdict(cid, qty.name, "correct", "correct up to a constant (the zero of the potential energy is "
                       "chosen at another height; the equations of motion are the same)", expected=expected,
                       method=method)
    if qty.name == "coriolis_matrix" and "entry" not in spec and _factorizes_c(claimed, points, tol):
        return Verdict(cid, qty.name, "correct", "correct as a factorization c = C q̇, though not the Christoffel C "
                       "(so Ṁ − 2C need not be skew-symmetric)", expected=expected, method=method)
    return _incorrect(robot, cid, qty, spec, cells, points, claimed, truth, ok, tol, method, rng, detail)


def _constant_offset(diff: np.ndarray, points: list[Point], tol: np.ndarray) -> bool:
    """The difference is the same at every point of each robot (parameter set), at several joint values."""
    groups: dict[int, list[float]] = {}
    for d, p in zip(diff.reshape(len(points), -1)[:, 0], points):
        groups.setdefault(id(p.robot), []).append(float(d))
    if any(len(g) < 2 for g in groups.values()):
        return False  # one point (a fixed q): a constant cannot be told from a wrong value
    return all(np.ptp(g) <= 2 * EXACT_RTOL * max(1.0, np.max(np.abs(g))) + 2 * float(np.max(tol)) for g in groups.values())


def _factorizes_c(claimed: np.ndarray, points: list[Point], tol: np.ndarray) -> bool:
    """C q̇ equals the numeric engine's c(q, q̇) at every point (C is not unique; c is)."""
    from .. import numeric as N

    for C, p in zip(claimed, points):
        c = N.coriolis_vector(p.robot, p.q, p.qd)
        if not np.all(np.abs(C @ p.qd - c) <= EXACT_RTOL * np.maximum(1, np.abs(c)) + np.abs(tol) @ np.abs(p.qd)):
            return False
    return True


def _entry_of(truth):
    def one(p: Point, spec: dict[str, Any]) -> np.ndarray:
        v = np.asarray(truth(p, spec), dtype=float)
        return v[_entry_index(spec["entry"], v.shape)]

    return one


def _entry_index(raw: Any, shape: tuple[int, ...]) -> tuple[int, ...]:
    """``entry: [i, j]`` (1-based) or ``entry: k`` → a 0-based index into a value of ``shape``."""
    idx = [raw] if isinstance(raw, int) else list(raw) if isinstance(raw, list) else None
    if idx is None or len(idx) != len(shape) or not all(isinstance(i, int) and not isinstance(i, bool) for i in idx):
        raise ParseError(f"'entry' must give {len(shape)} index(es) (1-based) into a value of shape {shape}")
    if not all(1 <= i <= n for i, n in zip(idx, shape)):
        raise ParseError(f"'entry' {raw!r} is outside a value of shape {shape}")
    return tuple(i - 1 for i in idx)


def _special(name: str):
    """The checker of a claim kind judged by its own rules (sets and solution sets), or None."""
    if name in ("singularities", "singular_configurations", "singular"):
        from ._singular import check_singularities

        return check_singularities
    if name in ("relation", "rule"):
        from ._relations import check_relation

        return check_relation
    if name in ("dh_matrix", "general_dh", "dh"):
        from ._dh_claims import check_dh_matrix

        return check_dh_matrix
    if name in ("ik_formula", "ik_solutions"):
        from . import _ik_claims

        return _ik_claims.check_ik_formula if name == "ik_formula" else _ik_claims.check_ik_solutions
    return None


def _incorrect(robot, cid, qty, spec, cells, points, claimed, truth, ok, tol, method, rng, detail=True) -> Verdict:
    bad = ~ok.all(axis=0)  # entries wrong at some point
    idx = [tuple(int(i) + 1 for i in np.atleast_1d(ix)) for ix in zip(*np.nonzero(np.atleast_1d(bad)))]
    err = np.abs(claimed - truth) / (EXACT_RTOL * np.maximum(1, np.abs(truth)) + tol)
    err = err.reshape(len(points), -1).max(axis=1)
    own = np.array([p.robot is robot for p in points])
    k = int(np.argmax(np.where(own, err, -1.0))) if (own & (err > 1)).any() else int(np.argmax(err))
    p = points[k]
    if truth.ndim == 1:  # one entry per point ('entry' claims, scalar quantities)
        e = spec.get("entry", 1)
        e = e if isinstance(e, list) else [e]
        idx = [tuple(e)]
        entries = ({"entry": list(e), "claimed": float(claimed[k]), "expected": float(truth[k])},)
    else:
        entries = tuple({"entry": list(e), "claimed": float(claimed[k][tuple(i - 1 for i in e)]),
                         "expected": float(truth[k][tuple(i - 1 for i in e)])} for e in idx)
    cex: dict[str, Any] = {"q": p.q.tolist()}
    if p.qd is not None and "qd" in qty.needs:
        cex["qd"] = p.qd.tolist()
    if p.robot is not robot:
        cex["parameters"] = dict(p.robot.parameters)
    if p.symbols:  # a symbolic wrench's f_x, …: the values used at this point
        cex["symbols"] = dict(p.symbols)
    hints = hints_for(robot, qty, spec, cells, points, claimed, truth, ok, tol, rng) if detail else ()
    extra = {}
    if detail and len(points) > 1 and "q" not in spec:  # a formula: give the correct formula too
        formula = expected_formula(robot, qty.name, spec)
        if formula is not None:
            extra["expected_latex"] = formula
    only_params = all(ok[j].all() for j in range(len(points)) if points[j].robot is robot)
    if only_params:
        hints = ("it agrees at this robot's parameter values but not as a formula in the parameters "
                 "(check which parameter goes where)",) + hints
    where = ", ".join(str(tuple(e)) if len(e) > 1 else str(e[0]) for e in idx[:12])
    msg = f"incorrect: {len(idx)} entr{'y differs' if len(idx) == 1 else 'ies differ'} ({where})"
    return Verdict(cid, qty.name, "incorrect", msg, entries, cex, hints, truth[k].tolist(), method, extra)


def expected_formula(robot: DHRobot, name: str, spec: dict[str, Any]) -> str | None:
    """The correct formula in LaTeX (C_12/S_3 shorthand) from the symbolic engine, when it is cheap."""
    keys = tuple(spec.get(k) for k in ("index", "from", "to"))
    if not all(k is None or (isinstance(k, int) and not isinstance(k, bool)) for k in keys):
        return None
    if name in ("force", "moment"):
        return _expected_statics(robot, name, spec)
    return _expected_formula(robot, name, *keys)


#: Most joints for which an incorrect M or g(q) claim is given the correct formula (symbolic Lagrangian dynamics).
MAX_FORMULA_DOF_DYNAMICS = 4
#: Most joints for which an incorrect ⁱfᵢ / ⁱnᵢ claim is given the correct formula (symbolic force propagation of a
#: 6-joint arm takes seconds).
MAX_FORMULA_DOF_STATICS = 4


def _expected_statics(robot: DHRobot, name: str, spec: dict[str, Any]) -> str | None:
    """ⁱfᵢ / ⁱnᵢ from the symbolic force propagation, with the claim's wrench (tool axes) put in."""
    import sympy as sp

    from .. import symbolic as S

    if robot.dof > MAX_FORMULA_DOF_STATICS or str(spec.get("frame", "tool")) != "tool" or "wrench" not in spec:
        return None
    try:
        nodes = _wrench_nodes(spec["wrench"], robot)
        syms = {n: sp.Symbol(n[0] + "_" + n[1:]) for nd in nodes for n in _expr.names_in(nd)}
        params = {k: sp.Symbol(k) for k, _ in robot.parameters}
        values = [_expr.to_sympy(nd, {**params, **syms}) for nd in nodes]
        prop = _statics_sym(robot)
    except (ParseError, KeyError, ValueError, TypeError):
        return None
    steps = {st.label: st for st in prop.steps}
    step = steps.get(str(spec.get("index")))
    if step is None:
        return None
    M = (step.f if name == "force" else step.n).xreplace(dict(zip(S.wrench_symbols(), values)))
    M = sp.ImmutableMatrix(M.applyfunc(sp.expand))
    if len(str(M)) > 20_000:
        return None
    return sp.latex(S.shorthand_matrix(M, S.joint_symbols(robot.dof).q), mat_str="bmatrix", mat_delim="")


@lru_cache(maxsize=8)
def _statics_sym(robot: DHRobot):
    from .. import symbolic as S

    return S.force_propagation_sym(robot)


@lru_cache(maxsize=64)
def _expected_formula(robot: DHRobot, name: str, index: int | None, frm: int | None, to: int | None) -> str | None:
    import sympy as sp

    from .. import symbolic as S

    spec = {k: v for k, v in (("index", index), ("from", frm), ("to", to)) if v is not None}
    try:
        if name == "link_transform":
            M = S.simplify_matrix(S.link_matrices_sym(robot)[int(spec["index"]) - 1])
        elif name == "transform":
            F = S.link_transforms_sym(robot)
            i, j = int(spec.get("from", 0)), int(spec.get("to", robot.n_rows))
            M = S.simplify_matrix(_inverse(F[i]) * F[j])
        elif name in ("end_effector", "position", "rotation"):
            T = S.forward_kinematics_sym(robot)
            M = T if name == "end_effector" else T[:3, 3] if name == "position" else T[:3, :3]
        elif name in ("gravity", "mass_matrix"):
            if robot.dof > MAX_FORMULA_DOF_DYNAMICS or not robot.has_dynamics:
                return None
            terms = S.lagrangian_dynamics(robot, coriolis=False)
            if name == "mass_matrix":
                M = terms.M
            elif terms.g_unit is not None and "g" not in robot.parameter_values:
                M = sp.Symbol("g") * terms.g_unit  # the symbol g, not 981/100
            else:
                M = terms.g
        elif name in ("omega", "velocity"):
            steps = {st.label: st for st in S.velocity_propagation_sym(robot).steps}
            step = steps[str(spec["index"])]
            M = step.omega if name == "omega" else step.v
        else:
            return None
    except (KeyError, ValueError, IndexError, TypeError, DenavitError):
        return None
    if len(str(M)) > 20_000:
        return None
    M = S.shorthand_matrix(sp.ImmutableMatrix(M), S.joint_symbols(robot.dof).q)
    return sp.latex(M, mat_str="bmatrix", mat_delim="")


def _inverse(T):
    import sympy as sp

    R, p = T[:3, :3], T[:3, 3]
    return sp.ImmutableMatrix(sp.BlockMatrix([[R.T, -R.T * p], [sp.zeros(1, 3), sp.ones(1, 1)]]).as_explicit())
