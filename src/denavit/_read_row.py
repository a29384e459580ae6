"""Reading one DH row of a robot file (its fields, joint variable, limits and inertia), for :mod:`denavit._read`.

Values go through :mod:`denavit._expr` (a restricted grammar), never ``eval``; errors are
:class:`~denavit.errors.ParseError` naming the file, the row and the field.  In a degree file bare angles are
converted here; bare angles above a full turn in a radian file are collected for one warning.
"""

from __future__ import annotations

import math
import re
import warnings
from typing import Any

import numpy as np

from . import _expr
from .errors import DenavitWarning, ModelError, ParseError
from .model import DH_FIELDS, INERTIA_TOLERANCE, MAX_ANGLE, MAX_MAGNITUDE, DHLink, JointType, LinkInertia

__all__ = ["Context", "joint_row", "names_unit", "has_names", "QVAR", "DEGREE_HINT"]

#: A joint variable's name: ``q`` or ``q<k>``.
QVAR = re.compile(r"^q(\d*)$")
_ROW_KEYS = {"a", "alpha", "d", "theta", "limits", "inertia", "name"}
_INERTIA_KEYS = {"mass", "com", "inertia", "motor_inertia", "viscous", "coulomb"}


class Context:
    """Where we are in a file, for error messages, plus the parameter environment."""

    def __init__(self, where: str, params: dict[str, float], deg: bool) -> None:
        self.where = where
        self.params = params
        self.deg = deg
        self.suspects: list[tuple[str, str]] = []  # (place, text) of bare angles > 2π in a radian file

    def fail(self, place: str, message: str) -> ParseError:
        return ParseError(message, where=f"{self.where}: {place}")

    def tree(self, value: Any, place: str) -> _expr.Node:
        try:
            return _expr.parse(value)
        except ParseError as exc:
            raise self.fail(place, str(exc)) from None

    def number(self, value: Any, place: str, angle: bool = False) -> tuple[float, str]:
        """Evaluate a constant value; returns (float, canonical text)."""
        tree = self.tree(value, place)
        bad = _expr.names_in(tree) - set(self.params)
        if bad:
            name = sorted(bad)[0]
            extra = " (the joint variable q may only appear in theta or d of a joint row)" if QVAR.match(name) else ""
            raise self.fail(place, f"unknown symbol {name!r}{extra}; parameters: {', '.join(self.params) or 'none'}")
        if angle:
            tree = self.angle_tree(tree)
        try:
            value = _expr.evaluate(tree, self.params)
        except ParseError as exc:
            raise self.fail(place, str(exc)) from None
        text = _expr.to_text(tree)
        if angle and not self.deg and _expr.is_literal(tree) and abs(value) > DEGREE_HINT:
            self.suspects.append((place, text))
        return value, text

    def warn_degrees(self) -> None:
        """One warning for bare angles above 2π in a radian file: probably degrees without ``angle_unit: deg``."""
        if not self.suspects:
            return
        place, text = self.suspects[0]
        more = f" (and {len(self.suspects) - 1} more such angles)" if len(self.suspects) > 1 else ""
        warnings.warn(DenavitWarning(
            f"{self.where}: {place}: {text} is read as {text} rad, more than a full turn{more}; if the file's "
            f"angles are in degrees, add 'angle_unit: deg' at the top of the file, or write {text}deg"
        ), stacklevel=3)

    def angle_tree(self, tree: _expr.Node) -> _expr.Node:
        """In a degree file a bare angle is in degrees; one that says deg or uses pi is taken as written."""
        if self.deg and not names_unit(tree):
            return ("call", "deg", (tree,))
        return tree


#: A bare angle above this in a radian file draws the "did you mean degrees?" warning.
DEGREE_HINT = 2 * math.pi + 1e-9


def names_unit(tree: _expr.Node) -> bool:
    """Whether an angle expression says its unit itself (``pi``, ``deg(…)``, ``rad(…)``), so a degree file leaves it as written."""
    if tree[0] == "name":
        return tree[1] == "pi"
    if tree[0] == "call":
        return tree[1] in ("deg", "rad") or any(names_unit(a) for a in tree[2])
    if tree[0] == "neg":
        return names_unit(tree[1])
    if tree[0] == "bin":
        return names_unit(tree[2]) or names_unit(tree[3])
    return False


def joint_row(raw: Any, row: int, joint_no: int, ctx: Context) -> DHLink:
    """DH row ``row`` (1-based; joint ``joint_no`` if it has a variable) of a file, read in ``ctx``."""
    place = f"row {row}"
    if not isinstance(raw, dict):
        raise ctx.fail(place, "each joint row must be a mapping like {a: 0, alpha: 0, d: 0, theta: q}")
    unknown = set(map(str, raw)) - _ROW_KEYS
    if unknown:
        raise ctx.fail(place, f"unknown field {sorted(unknown)[0]!r}; allowed: {', '.join(sorted(_ROW_KEYS))}")
    values: dict[str, float] = {}
    texts: list[tuple[str, str]] = []
    variable: str | None = None
    for field in DH_FIELDS:
        fplace = f"{place}, field '{field}'"
        tree = ctx.tree(raw.get(field, 0), fplace)
        qnames = {n for n in _expr.names_in(tree) if QVAR.match(n) and n not in ctx.params}
        if qnames:
            if variable is not None:
                raise ctx.fail(fplace, f"a row has one joint variable, but q appears in both '{variable}' and '{field}'")
            if field not in ("theta", "d"):
                raise ctx.fail(fplace, f"the joint variable may only appear in theta or d, not in '{field}'")
            if len(qnames) > 1:
                raise ctx.fail(fplace, f"two joint variables {sorted(qnames)} in one field")
            qname = qnames.pop()
            num = QVAR.match(qname).group(1)  # type: ignore[union-attr]
            if num and int(num) != joint_no:
                raise ctx.fail(fplace, f"{qname} names joint {num}, but this row is joint {joint_no} (write q or q{joint_no})")
            variable = field
            tree = _check_linear(tree, qname, fplace, ctx)
        value, text = ctx.number(_expr.to_text(tree), fplace, angle=field in ("alpha", "theta"))
        values[field] = value
        bound, unit = (MAX_ANGLE, "rad") if field in ("alpha", "theta") else (MAX_MAGNITUDE, "m")
        if abs(value) > bound:
            raise ctx.fail(fplace, f"{value:.6g} {unit} is out of range (at most {bound:g} {unit} in magnitude)")
        if value != 0 or has_names(text):
            texts.append((field, text))
    joint = {None: JointType.FIXED, "theta": JointType.REVOLUTE, "d": JointType.PRISMATIC}[variable]
    limits = None
    if "limits" in raw:
        lplace = f"{place}, field 'limits'"
        lim = raw["limits"]
        if not isinstance(lim, (list, tuple)) or len(lim) != 2:
            raise ctx.fail(lplace, "limits must be a list [low, high]")
        if joint is JointType.FIXED:
            raise ctx.fail(lplace, "a fixed row (no q) cannot have limits")
        got = [ctx.number(v, lplace, angle=joint is JointType.REVOLUTE) for v in lim]
        limits = (got[0][0], got[1][0])
        bound, unit = (MAX_ANGLE, "rad") if joint is JointType.REVOLUTE else (MAX_MAGNITUDE, "m")
        if max(map(abs, limits)) > bound:
            raise ctx.fail(lplace, f"limits [{limits[0]:.6g}, {limits[1]:.6g}] {unit} are out of range (at most {bound:g} "
                                   f"{unit} in magnitude)")
        if not all(_expr.is_literal(_expr.parse(t)) for _, t in got):  # kept as written: 5*pi/4, deg(170), L1
            texts += [("limits0", got[0][1]), ("limits1", got[1][1])]
        if limits[0] > limits[1]:
            raise ctx.fail(lplace, f"low limit {limits[0]:g} is above high limit {limits[1]:g}")
    inertia = _inertia(raw.get("inertia"), place, ctx) if "inertia" in raw else None
    try:
        return DHLink(joint=joint, q_limits=limits, inertia=inertia, symbols=tuple(texts), **values)
    except ModelError as exc:
        raise ctx.fail(place, str(exc)) from None


def _check_linear(tree: _expr.Node, qname: str, place: str, ctx: Context) -> _expr.Node:
    """Check the field is exactly ``q + offset`` (q once, coefficient +1, offset free of q); return the offset tree.

    The test is on the expression's structure (a sum of terms, one of which is q itself), not on sample
    values, so ``abs(q)``, ``sqrt(q^2)``, ``q + sin(2*pi*q)``, ``2*q`` or ``q*q`` are all refused.
    """
    terms = _sum_terms(tree)
    with_q = [(sign, t) for sign, t in terms if qname in _expr.names_in(t)]
    hint = f"the joint variable must enter as '{qname} + offset' (coefficient 1, offset without {qname})"
    if len(with_q) != 1:
        raise ctx.fail(place, f"{hint}; {qname} appears in {len(with_q)} terms")
    sign, term = with_q[0]
    if term != ("name", qname):
        raise ctx.fail(place, f"{hint}; found {_expr.to_text(term)!r}")
    if sign < 0:
        raise ctx.fail(place, f"{hint}; found -{qname}")
    offset: _expr.Node | None = None
    for sign, t in terms:
        if t[0] == "name" and t[1] == qname:
            continue
        if offset is None:
            offset = t if sign > 0 else ("neg", t)
        else:
            offset = ("bin", "+" if sign > 0 else "-", offset, t)
    return offset if offset is not None else ("num", "0")


def _sum_terms(tree: _expr.Node) -> list[tuple[int, _expr.Node]]:
    """``a - (b + c)`` as [(+1, a), (-1, b), (-1, c)], left to right (no recursion)."""
    out: list[tuple[int, _expr.Node]] = []
    stack: list[tuple[int, _expr.Node]] = [(1, tree)]
    while stack:
        sign, node = stack.pop()
        if node[0] == "bin" and node[1] in "+-":
            stack.append((sign if node[1] == "+" else -sign, node[3]))
            stack.append((sign, node[2]))
        elif node[0] == "neg":
            stack.append((-sign, node[1]))
        else:
            out.append((sign, node))
    return out


def has_names(text: str) -> bool:
    """Whether an expression text uses a named parameter (so it must be kept to be re-evaluated)."""
    try:
        return bool(_expr.names_in(_expr.parse(text)))
    except ParseError:
        return False


def _inertia(raw: Any, row_place: str, ctx: Context) -> LinkInertia:
    """A row's inertial data; errors name e.g. ``row 3, field 'inertia.com[1]'``."""

    def at(key: str = "") -> str:
        return f"{row_place}, field 'inertia{'.' + key if key else ''}'"

    if not isinstance(raw, dict):
        raise ctx.fail(at(), "inertia must be a mapping {mass, com, inertia, ...}")
    unknown = set(map(str, raw)) - _INERTIA_KEYS
    if unknown:
        raise ctx.fail(at(), f"unknown key {sorted(unknown)[0]!r}; allowed: {', '.join(sorted(_INERTIA_KEYS))}")
    texts: list[tuple[str, str]] = []

    def val(key: str, value: Any, sym_key: str) -> float:
        number, text = ctx.number(value, at(key))
        if number != 0 or has_names(text):
            texts.append((sym_key, text))
        return number

    def vec(key: str, n: int) -> tuple[float, ...]:
        value = raw.get(key, [0] * n)
        if key == "inertia" and isinstance(value, list) and any(isinstance(r, list) for r in value):
            return matrix(value)
        if not isinstance(value, (list, tuple)) or len(value) != n:
            raise ctx.fail(at(key), f"expected a list of {n} values" + (
                " (Ixx, Iyy, Izz, Ixy, Ixz, Iyz) or a 3×3 list" if key == "inertia" else ""))
        return tuple(val(f"{key}[{i}]", v, f"{key}{i}") for i, v in enumerate(value))

    def matrix(rows: list[Any]) -> tuple[float, ...]:
        """A 3×3 tensor: symmetric, read as its 6 distinct entries."""
        if len(rows) != 3 or not all(isinstance(r, list) and len(r) == 3 for r in rows):
            raise ctx.fail(at("inertia"), "a 3×3 inertia matrix needs 3 rows of 3 values")
        M = np.array([[ctx.number(v, at(f"inertia[{i}][{j}]"))[0] for j, v in enumerate(r)] for i, r in enumerate(rows)])
        if np.abs(M - M.T).max() > INERTIA_TOLERANCE * max(np.abs(M).max(), 1e-300):
            i, j = np.unravel_index(np.argmax(np.abs(M - M.T)), M.shape)
            raise ctx.fail(at("inertia"), f"the 3×3 inertia matrix is not symmetric ([{i}][{j}] = {M[i, j]:g} but "
                                          f"[{j}][{i}] = {M[j, i]:g})")
        pick = ((0, 0), (1, 1), (2, 2), (0, 1), (0, 2), (1, 2))
        return tuple(val(f"inertia[{i}][{j}]", rows[i][j], f"inertia{k}") for k, (i, j) in enumerate(pick))

    mass = val("mass", raw.get("mass", 0), "mass")
    com = vec("com", 3)
    inertia = vec("inertia", 6)
    extra = {k: val(k, raw.get(k, 0), k) for k in ("motor_inertia", "viscous", "coulomb")}
    try:
        return LinkInertia(mass=mass, com=com, inertia=inertia, symbols=tuple(texts), **extra)  # type: ignore[arg-type]
    except ModelError as exc:
        raise ctx.fail(at(), str(exc)) from None
