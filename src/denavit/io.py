"""Reading and writing robot files (YAML, TOML, JSON) and the built-in catalogue.

Robot files are untrusted: every value goes through :mod:`denavit._expr` (a restricted grammar), never
``eval``.  Errors are :class:`~denavit.errors.ParseError` naming the file, the row and the field.
Degrees are converted to radians here and nowhere else.
"""

from __future__ import annotations

import math
import re
import warnings
from importlib import resources
from pathlib import Path
from typing import Any, Mapping

import numpy as np

from . import _expr
from ._safeload import MAX_TEXT_BYTES, load_data
from ._write import dump_robot, expression_text, robot_to_dict, save_robot, value_text
from .errors import DenavitWarning, ModelError, ParseError
from .model import DH_FIELDS, INERTIA_TOLERANCE, MAX_ANGLE, MAX_MAGNITUDE, Convention, DHLink, DHRobot, JointType, LinkInertia

__all__ = [
    "load_robot",
    "robot_from_dict",
    "robot_to_dict",
    "dump_robot",
    "save_robot",
    "catalogue_names",
    "CATALOGUE_ALIASES",
    "with_parameters",
    "parse_values",
    "value_text",
    "expression_text",
    "resolve_pose",
]

#: Largest robot file read (bytes); a 32-joint arm with inertial data is about 10 kB.
MAX_FILE_BYTES = MAX_TEXT_BYTES
#: Most DH rows in a file, fixed rows included (joints are capped by :data:`denavit.model.MAX_JOINTS`).
MAX_ROWS = 64
#: Most named parameters in a file.
MAX_PARAMETERS = 256
#: Most values in one list given on the command line or to :func:`parse_values`, and its length in characters.
MAX_VALUES = 10_000
MAX_VALUES_TEXT = 200_000
_NAME = re.compile(r"^[A-Za-z_][A-Za-z_0-9]*$")
_QVAR = re.compile(r"^q(\d*)$")
_RESERVED = set(_expr.FUNCTIONS) | {"pi", "q"}
_ROW_KEYS = {"a", "alpha", "d", "theta", "limits", "inertia", "name"}
_TOP_KEYS = {
    "name", "description", "convention", "angle_unit", "parameters", "joints", "tool", "base", "gravity", "source",
    "poses",
}
_INERTIA_KEYS = {"mass", "com", "inertia", "motor_inertia", "viscous", "coulomb"}


# --------------------------------------------------------------------------------------------------
# catalogue


def _catalogue_dir():
    return resources.files("denavit") / "data" / "robots"


# old catalogue names (after the student report each arm came from) -> current names; still loadable
CATALOGUE_ALIASES = {
    "report000-6r": "coaxial-6r", "report000-planar3r": "planar3r-lagrange", "report001-6r": "offset-6r",
    "report003-6r": "elbow-6r-deg", "report004-1-planar2r": "planar2r-mdh", "report004-2-planar3r": "planar3r-mdh",
    "report004-3-articulated-rrr": "articulated-rrr", "report004-4-rrp": "spherical-rrp",
    "report004-5-rpp-cylindrical": "cylindrical-rpp", "report004-6-wrist3r": "spherical-wrist",
    "report004-7-scara-rrrp": "scara-rrrp", "report004-8-prrr": "lift-prrr",
}


def catalogue_names() -> list[str]:
    """Names of the built-in robots, sorted (old names in :data:`CATALOGUE_ALIASES` also load)."""
    return sorted(p.name[:-5] for p in _catalogue_dir().iterdir() if p.name.endswith(".yaml"))


def load_robot(source: str | Path, **parameters: float) -> DHRobot:
    """Load a robot from a file path or a built-in name (see :func:`catalogue_names`).

    Parameters
    ----------
    source : str or Path
        A ``.yaml``/``.yml``/``.toml``/``.json`` robot file, or a catalogue name such as ``"puma560"``.
    **parameters : float
        Override values of the robot's named parameters (``L1=0.7``).
    """
    path = Path(source)
    if path.suffix.lower() in (".yaml", ".yml", ".toml", ".json") or path.exists():
        if not path.is_file():
            raise ParseError(f"no such robot file: {str(path)!r}")
        size = path.stat().st_size
        if size > MAX_FILE_BYTES:
            raise ParseError(f"file too large ({size} bytes; at most {MAX_FILE_BYTES})", where=str(path))
        with path.open("rb") as fh:  # bounded read: the size on disk may lie (special files)
            raw = fh.read(MAX_FILE_BYTES + 1)
        if len(raw) > MAX_FILE_BYTES:
            raise ParseError(f"file too large (more than {MAX_FILE_BYTES} bytes)", where=str(path))
        data = _load_text(raw.decode("utf-8", errors="replace"), path.suffix.lower(), str(path))
        robot = robot_from_dict(_override(data, parameters, str(path)), where=str(path))
    else:
        name = CATALOGUE_ALIASES.get(str(source), str(source))
        if name not in catalogue_names():
            raise ParseError(
                f"unknown robot {name!r}: not a file and not a built-in name; built-in: {', '.join(catalogue_names())}"
            )
        res = _catalogue_dir() / f"{name}.yaml"
        data = _load_text(res.read_text(encoding="utf-8"), ".yaml", f"catalogue:{name}")
        robot = robot_from_dict(_override(data, parameters, name), where=name)
        robot = robot.replace(source=f"catalogue:{name}")
    return robot


def _override(data: dict[str, Any], values: Mapping[str, float], where: str) -> dict[str, Any]:
    """The file's data with some parameters given new values, so every field is evaluated with them.

    Fields, limits, inertia, gravity, base, tool and parameters defined from the overridden ones all
    follow, because the whole file is read again with the new values.
    """
    if not values:
        return data
    params = data.get("parameters")
    known = [str(k) for k in params] if isinstance(params, dict) else []
    for k in values:
        if k not in known:
            raise ParseError(f"no parameter {k!r}; parameters: {', '.join(known) or 'none'}", where=where)
    new = dict(params)  # type: ignore[arg-type]
    for k, v in values.items():
        new[k] = _param_value(k, v)
    return {**data, "parameters": new}


def _param_value(name: str, value: Any) -> float:
    try:
        v = float(value)
    except (TypeError, ValueError, OverflowError):
        raise ParseError(f"parameter {name}: expected a number, got {value!r:.40}") from None
    if not math.isfinite(v):
        raise ParseError(f"parameter {name}: value must be finite, got {v}")
    return v


def _load_text(text: str, suffix: str, where: str) -> dict[str, Any]:
    data = load_data(text, suffix, where)
    if not isinstance(data, dict):
        raise ParseError("a robot file must be a mapping with at least 'convention' and 'joints'", where=where)
    return data


# --------------------------------------------------------------------------------------------------
# dict -> robot


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
        if self.deg and not _names_unit(tree):
            return ("call", "deg", (tree,))
        return tree


#: A bare angle above this in a radian file draws the "did you mean degrees?" warning.
DEGREE_HINT = 2 * math.pi + 1e-9


def _names_unit(tree: _expr.Node) -> bool:
    if tree[0] == "name":
        return tree[1] == "pi"
    if tree[0] == "call":
        return tree[1] in ("deg", "rad") or any(_names_unit(a) for a in tree[2])
    if tree[0] == "neg":
        return _names_unit(tree[1])
    if tree[0] == "bin":
        return _names_unit(tree[2]) or _names_unit(tree[3])
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


def _transform_from_texts(texts: Mapping[str, str], place: str, params: Mapping[str, float]) -> np.ndarray | None:
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


def resolve_pose(robot: DHRobot, text: str) -> np.ndarray | None:
    """The joint values of the named pose ``text`` of ``robot`` (``"qr"``), or None when it names none.

    >>> resolve_pose(load_robot("puma560"), "qz")
    array([0., 0., 0., 0., 0., 0.])
    """
    poses = dict(robot.poses)
    key = text.strip() if isinstance(text, str) else None
    return np.array(poses[key], dtype=float) if key in poses else None


def _safe_names(value: Any) -> set[str]:
    try:
        return _expr.names_in(_expr.parse(value))
    except ParseError:
        return set()


# --------------------------------------------------------------------------------------------------
# parameters, values


def with_parameters(robot: DHRobot, **values: float) -> DHRobot:
    """The same robot with some named parameters given new values, every field that uses them re-evaluated.

    DH values, joint limits, inertial data, gravity, base and tool written with parameters all follow.
    Parameters defined in the file from other parameters keep their values here (``load_robot(path, L1=…)``
    re-reads the file, so they follow too).

    Raises
    ------
    ParseError
        An unknown parameter name (the message lists the robot's parameters), a value that is not a finite
        number, or a new value that puts a field out of range.
    """
    params = robot.parameter_values
    for k, v in values.items():
        if k not in params:
            raise ParseError(f"robot {robot.name!r} has no parameter {k!r}; parameters: {', '.join(params) or 'none'}")
        params[k] = _param_value(k, v)
    ev = lambda text: _expr.evaluate(_expr.parse(text), params)  # noqa: E731
    try:
        links = []
        for row, link in enumerate(robot.links, start=1):
            try:
                links.append(_link_with(link, ev))
            except ModelError as exc:
                raise ParseError(f"row {row}: {exc}") from None
        changes: dict[str, Any] = {"links": tuple(links), "parameters": tuple(params.items())}
        sym = dict(robot.symbols)
        if "gravity0" in sym:
            changes["gravity"] = tuple(ev(sym[f"gravity{i}"]) for i in range(3))
        for place in ("base", "tool"):
            T = _transform_from_texts(sym, place, params)
            if T is not None:
                changes[place] = T
        return robot.replace(**changes)
    except ModelError as exc:
        raise ParseError(str(exc)) from None


def _link_with(link: DHLink, ev: Any) -> DHLink:
    """A DH row with the fields written with parameters evaluated again by ``ev``."""
    sym = dict(link.symbols)
    new: dict[str, Any] = {k: ev(t) for k, t in sym.items() if k in DH_FIELDS}
    if "limits0" in sym:
        new["q_limits"] = (ev(sym["limits0"]), ev(sym["limits1"]))
    inertia = link.inertia
    if inertia is not None and inertia.symbols:
        s = dict(inertia.symbols)
        inertia = LinkInertia(
            mass=ev(s["mass"]) if "mass" in s else inertia.mass,
            com=tuple(ev(s[f"com{i}"]) if f"com{i}" in s else inertia.com[i] for i in range(3)),  # type: ignore[arg-type]
            inertia=tuple(ev(s[f"inertia{i}"]) if f"inertia{i}" in s else inertia.inertia[i] for i in range(6)),  # type: ignore[arg-type]
            **{k: ev(s[k]) if k in s else getattr(inertia, k) for k in ("motor_inertia", "viscous", "coulomb")},
            symbols=inertia.symbols,
        )
    return DHLink(**{**_link_kwargs(link), **new, "inertia": inertia})


def _link_kwargs(link: DHLink) -> dict[str, Any]:
    return {
        "a": link.a, "alpha": link.alpha, "d": link.d, "theta": link.theta, "joint": link.joint,
        "q_limits": link.q_limits, "inertia": link.inertia, "symbols": link.symbols,
    }


def parse_values(text: str | list[Any], n: int | None = None, *, what: str = "q", deg: bool = False,
                 env: Mapping[str, float] | None = None) -> np.ndarray:
    """Parse ``"0, pi/4, 90deg"`` (comma or space separated expressions) into floats.

    Values are separated by commas (or semicolons) when there are any outside brackets, else by spaces;
    the whole list may be wrapped in ``[...]`` or ``(...)``; ``\\pi`` is read as ``pi``.  An empty value
    (``"1,,2"``, ``"1 2,"``), unbalanced brackets (``"[1,2"``), more than :data:`MAX_VALUES` values or
    more than :data:`MAX_VALUES_TEXT` characters are refused.  The text is read in one linear pass.
    ``deg=True`` reads plain numbers as degrees (``pi`` or ``deg`` in a value still say their unit).
    Raises ParseError naming the value when something is wrong.

    >>> parse_values("[0 0.5]").tolist(), parse_values("(-\\pi/2, 90deg)").round(4).tolist()
    ([0.0, 0.5], [-1.5708, 1.5708])
    """
    if isinstance(text, str):
        parts = _split_values(text, what)
    else:
        parts = list(text)
        if len(parts) > MAX_VALUES:
            raise ParseError(f"{what}: more than {MAX_VALUES} values")
    if n is not None and len(parts) != n:
        raise ParseError(f"{what}: expected {n} values, got {len(parts)}")
    out = []
    for i, p in enumerate(parts, start=1):
        try:
            tree = _expr.parse(p)
            if deg and not _names_unit(tree):
                tree = ("call", "deg", (tree,))
            out.append(_expr.evaluate(tree, env or {}))
        except ParseError as exc:
            raise ParseError(f"{what}: value {i} ({str(p)[:40]!r}): {exc}") from None
    return np.array(out, dtype=float)


_CLOSE = {"(": ")", "[": "]"}


def _split_values(text: str, what: str) -> list[str]:
    """The values of a list text (see :func:`parse_values`), checked for balanced brackets and empty values."""
    if len(text) > MAX_VALUES_TEXT:
        raise ParseError(f"{what}: longer than {MAX_VALUES_TEXT} characters")
    t = text.strip().replace("\\pi", "pi")
    opened: list[int] = []
    outer_close = -1
    for i, ch in enumerate(t):
        if ch in "([":
            opened.append(i)
        elif ch in ")]":
            if not opened or _CLOSE[t[opened[-1]]] != ch:
                raise ParseError(f"{what}: unbalanced brackets: {ch!r} at position {i + 1} closes nothing")
            if opened.pop() == 0:
                outer_close = i
    if opened:
        raise ParseError(f"{what}: unbalanced brackets: {t[opened[-1]]!r} at position {opened[-1] + 1} is never closed")
    if t and outer_close == len(t) - 1:
        t = t[1:-1].strip()
    depth = 0
    commas = False
    for ch in t:
        depth += (ch in "([") - (ch in ")]")
        if depth == 0 and ch in ",;":
            commas = True
            break
    parts: list[str] = []
    start = depth = 0
    for i, ch in enumerate(t):
        depth += (ch in "([") - (ch in ")]")
        if depth == 0 and (ch in ",;" if commas else ch.isspace()):
            parts.append(t[start:i].strip())
            start = i + 1
            if len(parts) > MAX_VALUES:
                raise ParseError(f"{what}: more than {MAX_VALUES} values")
    parts.append(t[start:].strip())
    if not commas:
        return [p for p in parts if p]
    for k, p in enumerate(parts, start=1):
        if not p:
            raise ParseError(f"{what}: value {k} is empty (two separators in a row, or one at an end): {text[:60]!r}")
    return parts
