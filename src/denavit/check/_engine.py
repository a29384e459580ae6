"""The verdict on one claim: read it, evaluate it and the truth at random points, compare, explain.

Equivalence is decided by evaluation, never by comparing text: the claimed formula and the library's
value are computed at several random configurations (and, when the claim keeps parameters as symbols,
at random parameter values too).  Different but equal forms (cos(q1 + q2) and c1 c2 − s1 s2, √3/2 and
0.866…) therefore agree.  A trigonometric polynomial that vanishes at six random points drawn from a
continuous distribution is zero with probability one; the tolerance is 1e-9 relative for exact claims and
one unit of the last decimal written for claims written with rounded decimals.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np

from .. import _expr
from ..errors import ParseError
from ..model import DHRobot
from ._formulas import expected_formula
from ._hints import hints_for
from ._matrices import after_last_equals
from ._points import evaluate_cells, gravity_names, sample_points, where_nodes, wrench_nodes
from ._quantities import Point, quantity
from ._resolve import robot_resolver
from ._values import MAX_DET_SIZE, ShapeMismatch, claim_cells, decimals, determinant, shape_readings, shape_to

__all__ = ["Verdict", "check_claim", "EXACT_RTOL"]

EXACT_RTOL = 1e-9


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
        wrench = wrench_nodes(spec["wrench"], robot) if "wrench" in spec else None
        symbols = sorted({n for nd in wrench or () for n in _expr.names_in(nd)} - {k for k, _ in robot.parameters})
        where = where_nodes(spec.get("where"), robot, symbols + gravity_names(robot))
        spec["_where"] = where
        cells = claim_cells(raw["value"], robot_resolver(robot, extra=symbols + gravity_names(robot)
                                                     + [n for n, _ in where]))
        if qty.name == "det_jacobian" and len(cells) * len(cells[0]) > 1 and 1 in (len(cells), len(cells[0])):
            factors = [c for row in cells for c in row]  # det J written as a list of its factors
            prod = factors[0]
            for f in factors[1:]:
                prod = ("bin", "*", prod, f)
            cells = [[prod]]
        elif qty.name == "det_jacobian" and 1 < len(cells) == len(cells[0]) <= MAX_DET_SIZE:
            cells = [[determinant(cells)]]  # |a b; c d| (a vmatrix): the determinant of the matrix written
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
        points = sample_points(robot, spec, names, qty.needs, rng, deg, wrench=wrench, symbols=symbols)
        if "entry" in spec:  # one entry of the quantity: hints then compare that entry too
            qty = replace(qty, truth=_entry_of(qty.truth))
        truth = np.array([np.asarray(qty.truth(p, spec), dtype=float) for p in points])  # (P, *shape)
        try:
            readings = shape_readings(qty, spec, truth.shape[1:], cells)
        except ShapeMismatch as exc:
            return Verdict(cid, qty.name, "incorrect", f"incorrect: shape: {exc}{_left_out(cells, points, spec, truth)}",
                           expected=truth[0].tolist(), method="the shape of the value compared with the quantity's")
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
        v = _compare(robot, cid, q2, spec, shape_to(cells, t2.shape[1:]), points, t2, rng, False)
        if v.verdict == "correct":
            return replace(v, message=f"{v.message}, read as {label}")
        verdicts.append((len(v.entries), label, q2, t2, getattr(fn, "rows", None)))
    _, label, q2, t2, rows = min(verdicts, key=lambda x: x[0])
    spec_read = {**spec, "_rows": rows} if rows else spec  # the correct formula shown in the rows read
    v = _compare(robot, cid, q2, spec_read, shape_to(cells, t2.shape[1:]), points, t2, rng, detail)
    others = "; ".join(lb for _, lb, *_ in verdicts if lb != label)
    return replace(v, message=f"{v.message}, read as {label}" + (f" (also wrong read as {others})" if others else ""))


_TRANSPOSED = re.compile(r"\^\s*(?:T|\{\s*T\s*\}|\\top|\{\s*\\top\s*\})(?![A-Za-z])")


def _says_transpose(text: str) -> bool:
    """``J^T = …`` / ``J_\\theta^{T} = …``: the left side names a transposed matrix."""
    head = text[:len(text) - len(after_last_equals(text))]
    return bool(_TRANSPOSED.search(head))


def _left_out(cells, points, spec, truth) -> str:
    """For a vector written with one entry fewer than the quantity has: which entry, left out, makes the rest right
    (a column of J with ω's zero lost); "" when none does or the shapes differ otherwise."""
    flat = [c for row in cells for c in row]
    n = truth.shape[1] if truth.ndim == 2 else 0
    if n < 2 or len(flat) != n - 1 or min(len(cells), len(cells[0])) != 1:
        return ""
    try:
        claimed = np.array([evaluate_cells([[c] for c in flat], p, spec.get("_where", ())).ravel() for p in points])
    except ParseError:
        return ""
    tol = np.array([10.0 ** -decimals(c) if decimals(c) >= 2 else 0.0 for c in flat])
    gaps = []
    for k in range(n):
        rest = np.delete(truth, k, axis=1)
        if (np.abs(claimed - rest) <= EXACT_RTOL * np.maximum(1.0, np.abs(rest)) + tol).all():
            gaps.append(str(k + 1))
    if not gaps:
        return ""
    which = f"entry {gaps[0]}" if len(gaps) == 1 else f"one of the equal entries {', '.join(gaps)}"
    return f"; it is the right vector with {which} left out (its other {n - 1} entries are correct)"


def _compare(robot, cid, qty, spec, cells, points, truth, rng, detail) -> Verdict:
    """The verdict on claimed cells (already of the truth's shape) against the truth at the points."""
    try:
        cells = shape_to(cells, truth.shape[1:])
        claimed = np.array([evaluate_cells(cells, p, spec.get("_where", ())).reshape(truth.shape[1:]) for p in points])
    except ParseError as exc:
        return Verdict(cid, qty.name, "unreadable", str(exc))
    dec = np.array([[decimals(c) for c in row] for row in cells]).reshape(truth.shape[1:])
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
    if name == "ik_formula":
        from ._ik_claims import check_ik_formula

        return check_ik_formula
    if name == "ik_solutions":
        from ._ik_solutions import check_ik_solutions

        return check_ik_solutions
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
