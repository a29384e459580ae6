"""Reading a robot file's plain data into a :class:`~denavit.model.DHRobot` (used by :mod:`denavit.io`).

Every value goes through :mod:`denavit._expr` (a restricted grammar), never ``eval``; every error is a
:class:`~denavit.errors.ParseError` naming the file, the row and the field.  Degrees are converted to radians
here; bare angles above a full turn in a radian file draw one :class:`~denavit.errors.DenavitWarning`.
"""

from __future__ import annotations

import math
import re
import warnings
from pathlib import Path
from typing import Any, Mapping

import numpy as np

from . import _expr
from .errors import DenavitWarning, ModelError, ParseError
from .model import DH_FIELDS, INERTIA_TOLERANCE, MAX_ANGLE, MAX_MAGNITUDE, Convention, DHLink, DHRobot, JointType, LinkInertia

__all__ = ["robot_from_dict", "names_unit", "transform_from_texts", "MAX_ROWS", "MAX_PARAMETERS", "MAX_TEXT", "DEGREE_HINT"]

#: Most DH rows in a file, fixed rows included (joints are capped by :data:`denavit.model.MAX_JOINTS`).
MAX_ROWS = 64
#: Most named parameters in a file.
MAX_PARAMETERS = 256
_NAME = re.compile(r"^[A-Za-z_][A-Za-z_0-9]*$")
_QVAR = re.compile(r"^q(\d*)$")
_RESERVED = set(_expr.FUNCTIONS) | {"pi", "q"}
_ROW_KEYS = {"a", "alpha", "d", "theta", "limits", "inertia", "name"}
_TOP_KEYS = {
    "name", "description", "convention", "angle_unit", "parameters", "joints", "tool", "base", "gravity", "source",
    "poses",
}
_INERTIA_KEYS = {"mass", "com", "inertia", "motor_inertia", "viscous", "coulomb"}


class _Ctx:
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
            extra = " (the joint variable q may only appear in theta or d of a joint row)" if _QVAR.match(name) else ""
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
    if tree[0] == "name":
        return tree[1] == "pi"
    if tree[0] == "call":
        return tree[1] in ("deg", "rad") or any(names_unit(a) for a in tree[2])
    if tree[0] == "neg":
        return names_unit(tree[1])
    if tree[0] == "bin":
        return names_unit(tree[2]) or names_unit(tree[3])
    return False


def _parameters(raw: Any, where: str) -> dict[str, float]:
    if raw is None:
        return {}
    if not isinstance(raw, dict):
        raise ParseError("'parameters' must be a mapping name: value", where=f"{where}: parameters")
    if len(raw) > MAX_PARAMETERS:
        raise ParseError(f"too many parameters ({len(raw)}; at most {MAX_PARAMETERS})", where=f"{where}: parameters")
    params: dict[str, float] = {}
    for key, value in raw.items():
        key = str(key)
        place = f"parameters.{key}"
        if not _NAME.match(key) or key in _RESERVED or _QVAR.match(key):
            raise ParseError(f"{key!r} cannot be a parameter name (reserved or not an identifier)", where=f"{where}: {place}")
        ctx = _Ctx(where, dict(params), False)
        params[key] = ctx.number(value, place)[0]
    return params


def _joint_row(raw: Any, row: int, joint_no: int, ctx: _Ctx) -> DHLink:
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
        qnames = {n for n in _expr.names_in(tree) if _QVAR.match(n) and n not in ctx.params}
        if qnames:
            if variable is not None:
                raise ctx.fail(fplace, f"a row has one joint variable, but q appears in both '{variable}' and '{field}'")
            if field not in ("theta", "d"):
                raise ctx.fail(fplace, f"the joint variable may only appear in theta or d, not in '{field}'")
            if len(qnames) > 1:
                raise ctx.fail(fplace, f"two joint variables {sorted(qnames)} in one field")
            qname = qnames.pop()
            num = _QVAR.match(qname).group(1)  # type: ignore[union-attr]
            if num and int(num) != joint_no:
                raise ctx.fail(fplace, f"{qname} names joint {num}, but this row is joint {joint_no} (write q or q{joint_no})")
            variable = field
            tree = _check_linear(tree, qname, fplace, ctx)
        value, text = ctx.number(_expr.to_text(tree), fplace, angle=field in ("alpha", "theta"))
        values[field] = value
        bound, unit = (MAX_ANGLE, "rad") if field in ("alpha", "theta") else (MAX_MAGNITUDE, "m")
        if abs(value) > bound:
            raise ctx.fail(fplace, f"{value:.6g} {unit} is out of range (at most {bound:g} {unit} in magnitude)")
        if value != 0 or _has_names(text):
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


def _check_linear(tree: _expr.Node, qname: str, place: str, ctx: _Ctx) -> _expr.Node:
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


def _has_names(text: str) -> bool:
    """Whether an expression text uses a named parameter (so it must be kept to be re-evaluated)."""
    try:
        return bool(_expr.names_in(_expr.parse(text)))
    except ParseError:
        return False


def _inertia(raw: Any, row_place: str, ctx: _Ctx) -> LinkInertia:
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
        if number != 0 or _has_names(text):
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


def _transform(raw: Any, place: str, ctx: _Ctx) -> tuple[np.ndarray, list[tuple[str, str]]]:
    """A base or tool transform and, when it uses parameters, the expression texts of its entries."""
    from .numeric._transforms import transform_from_xyz_rpy

    if isinstance(raw, list):
        if len(raw) != 4 or not all(isinstance(r, list) and len(r) == 4 for r in raw):
            raise ctx.fail(place, "a transform given as a matrix must be 4×4")
        got = [ctx.number(v, f"{place}[{i}][{j}]") for i, r in enumerate(raw) for j, v in enumerate(r)]
        texts = [(f"{place}.m{k}", t) for k, (_, t) in enumerate(got)]
        return np.array([v for v, _ in got]).reshape(4, 4), texts if any(_has_names(t) for _, t in texts) else []
    if not isinstance(raw, dict) or set(map(str, raw)) - {"xyz", "rpy"}:
        raise ctx.fail(place, "expected {xyz: [x, y, z], rpy: [roll, pitch, yaw]}, a 4×4 list, or (tool) a DH row")
    xyz = raw.get("xyz", [0, 0, 0])
    rpy = raw.get("rpy", [0, 0, 0])
    for key, v in (("xyz", xyz), ("rpy", rpy)):
        if not isinstance(v, list) or len(v) != 3:
            raise ctx.fail(f"{place}.{key}", "expected a list of 3 values")
    p = [ctx.number(v, f"{place}.xyz[{i}]") for i, v in enumerate(xyz)]
    r = [ctx.number(v, f"{place}.rpy[{i}]", angle=True) for i, v in enumerate(rpy)]
    for key, got, bound, unit in (("xyz", p, MAX_MAGNITUDE, "m"), ("rpy", r, MAX_ANGLE, "rad")):
        for i, (v, _) in enumerate(got):
            if abs(v) > bound:
                raise ctx.fail(f"{place}.{key}[{i}]", f"{v:.6g} {unit} is out of range (at most {bound:g} {unit} in magnitude)")
    texts = [(f"{place}.xyz{i}", t) for i, (_, t) in enumerate(p)] + [(f"{place}.rpy{i}", t) for i, (_, t) in enumerate(r)]
    T = transform_from_xyz_rpy([v for v, _ in p], [v for v, _ in r])
    return T, texts if any(_has_names(t) for _, t in texts) else []


def transform_from_texts(texts: Mapping[str, str], place: str, params: Mapping[str, float]) -> np.ndarray | None:
    """Re-evaluate a transform stored by :func:`_transform` (None when it had no parameters)."""
    from .numeric._transforms import transform_from_xyz_rpy

    ev = lambda key: _expr.evaluate(_expr.parse(texts[key]), params)  # noqa: E731
    if f"{place}.m0" in texts:
        return np.array([ev(f"{place}.m{k}") for k in range(16)]).reshape(4, 4)
    if f"{place}.xyz0" in texts:
        return transform_from_xyz_rpy([ev(f"{place}.xyz{i}") for i in range(3)], [ev(f"{place}.rpy{i}") for i in range(3)])
    return None


def robot_from_dict(data: Mapping[str, Any], where: str = "<robot>") -> DHRobot:
    """Build a :class:`DHRobot` from the plain data of a robot file (see ``docs/robot-file.md``)."""
    unknown = set(map(str, data)) - _TOP_KEYS
    if unknown:
        raise ParseError(f"unknown key {sorted(unknown)[0]!r}; allowed: {', '.join(sorted(_TOP_KEYS))}", where=where)
    conv = str(data.get("convention", "")).strip().lower()
    if conv not in ("standard", "modified"):
        raise ParseError(
            f"'convention' must be standard or modified, got {data.get('convention')!r}", where=f"{where}: convention"
        )
    unit = str(data.get("angle_unit", "rad")).strip().lower()
    if unit not in ("rad", "deg"):
        raise ParseError(f"'angle_unit' must be rad or deg, got {unit!r}", where=f"{where}: angle_unit")
    params = _parameters(data.get("parameters"), where)
    ctx = _Ctx(where, params, unit == "deg")
    rows = data.get("joints")
    if not isinstance(rows, list) or not rows:
        raise ParseError("'joints' must be a non-empty list of DH rows", where=f"{where}: joints")
    if len(rows) > MAX_ROWS:
        raise ParseError(f"too many rows ({len(rows)}; at most {MAX_ROWS})", where=f"{where}: joints")
    links: list[DHLink] = []
    joint_no = 0
    for i, raw in enumerate(rows, start=1):
        is_joint = isinstance(raw, dict) and any(
            _QVAR.match(n) and n not in params
            for f in ("theta", "d", "a", "alpha")
            if f in raw
            for n in _safe_names(raw[f])
        )
        link = _joint_row(raw, i, joint_no + 1 if is_joint else joint_no, ctx)
        joint_no += link.is_joint
        links.append(link)
    tool = np.eye(4)
    symbols: list[tuple[str, str]] = []
    if "tool" in data and data["tool"] is not None:
        raw_tool = data["tool"]
        if isinstance(raw_tool, dict) and set(map(str, raw_tool)) & set(DH_FIELDS):
            link = _joint_row(raw_tool, len(rows) + 1, joint_no + 1, ctx)
            if link.is_joint:
                raise ParseError("the tool row cannot have a joint variable", where=f"{where}: tool")
            links.append(link)
        else:
            tool, found = _transform(raw_tool, "tool", ctx)
            symbols += found
    if data.get("base") is not None:
        base, found = _transform(data["base"], "base", ctx)
        symbols += found
    else:
        base = np.eye(4)
    gravity = data.get("gravity", [0, 0, -9.81])
    if not isinstance(gravity, list) or len(gravity) != 3:
        raise ParseError("gravity must be a list of 3 values [m/s²]", where=f"{where}: gravity")
    got = [ctx.number(v, f"gravity[{i}]") for i, v in enumerate(gravity)]
    g = tuple(v for v, _ in got)
    if any(_has_names(t) for _, t in got):
        symbols += [(f"gravity{i}", t) for i, (_, t) in enumerate(got)]
    poses = _poses(data.get("poses"), [link.joint for link in links if link.is_joint], ctx)
    try:
        robot = DHRobot(
            name=_text_field(data, "name", Path(where).stem, where),
            links=tuple(links),
            convention=Convention(conv),
            base=base,  # type: ignore[arg-type]
            tool=tool,  # type: ignore[arg-type]
            gravity=g,  # type: ignore[arg-type]
            parameters=tuple(params.items()),
            description=_text_field(data, "description", "", where),
            source=_text_field(data, "source", where, where),
            poses=poses,
            symbols=tuple(symbols),
            angle_unit="deg" if ctx.deg else "rad",
        )
    except ModelError as exc:
        raise ParseError(str(exc), where=where) from None
    ctx.warn_degrees()
    return robot


#: Longest name, description or source text in a robot file.
MAX_TEXT = 2_000


def _text_field(data: Mapping[str, Any], key: str, default: str, where: str) -> str:
    value = data.get(key, default)
    if value is None:  # "description:" left empty
        value = default
    if isinstance(value, bool) or not isinstance(value, (str, int, float)):
        raise ParseError(f"'{key}' must be text, got {type(value).__name__}", where=f"{where}: {key}")
    text = str(value)
    try:
        text.encode("utf-8")
    except UnicodeEncodeError:
        raise ParseError(f"'{key}' is not valid Unicode (a lone surrogate?)", where=f"{where}: {key}") from None
    if len(text) > MAX_TEXT:
        raise ParseError(f"'{key}' is longer than {MAX_TEXT} characters", where=f"{where}: {key}")
    return text


def _poses(raw: Any, joints: list[JointType], ctx: _Ctx) -> tuple[tuple[str, tuple[float, ...]], ...]:
    """``poses: {qr: [...], ...}``: each value read like a DH field (angles in the file's angle_unit)."""
    if raw is None:
        return ()
    if not isinstance(raw, dict):
        raise ctx.fail("poses", "'poses' must be a mapping of name: [one value per joint]")
    out = []
    for name, values in raw.items():
        place = f"poses.{str(name)[:40]}"
        if not isinstance(values, list) or len(values) != len(joints):
            raise ctx.fail(place, f"expected a list of {len(joints)} values (one per joint)")
        out.append((str(name), tuple(ctx.number(v, place, angle=j is JointType.REVOLUTE)[0]
                                     for v, j in zip(values, joints))))
    return tuple(out)


def _safe_names(value: Any) -> set[str]:
    try:
        return _expr.names_in(_expr.parse(value))
    except ParseError:
        return set()
