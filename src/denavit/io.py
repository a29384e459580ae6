"""Reading and writing robot files (YAML, TOML, JSON) and the built-in catalogue.

Robot files are untrusted: every value goes through :mod:`denavit._expr` (a restricted grammar), never
``eval``.  Errors are :class:`~denavit.errors.ParseError` naming the file, the row and the field.
Degrees are converted to radians here and nowhere else.
"""

from __future__ import annotations

import json
import math
import re
from importlib import resources
from pathlib import Path
from typing import Any, Mapping

import numpy as np

from . import _expr
from .errors import ModelError, ParseError
from .model import DH_FIELDS, Convention, DHLink, DHRobot, JointType, LinkInertia

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
    "resolve_pose",
]

MAX_FILE_BYTES = 1_000_000
MAX_ROWS = 64
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
        text = path.read_text(encoding="utf-8", errors="replace")
        data = _load_text(text, path.suffix.lower(), str(path))
        robot = robot_from_dict(data, where=str(path))
    else:
        name = CATALOGUE_ALIASES.get(str(source), str(source))
        if name not in catalogue_names():
            raise ParseError(
                f"unknown robot {name!r}: not a file and not a built-in name; built-in: {', '.join(catalogue_names())}"
            )
        res = _catalogue_dir() / f"{name}.yaml"
        robot = robot_from_dict(_load_text(res.read_text(encoding="utf-8"), ".yaml", f"catalogue:{name}"), where=name)
        robot = robot.replace(source=f"catalogue:{name}")
    return with_parameters(robot, **parameters) if parameters else robot


def _load_text(text: str, suffix: str, where: str) -> dict[str, Any]:
    if suffix == ".json":
        try:
            data = json.loads(text)
        except json.JSONDecodeError as exc:
            raise ParseError(f"malformed JSON at line {exc.lineno}, column {exc.colno}: {exc.msg}", where=where) from None
    elif suffix == ".toml":
        try:
            import tomllib
        except ModuleNotFoundError:  # Python 3.10
            import tomli as tomllib  # type: ignore[no-redef]
        try:
            data = tomllib.loads(text)
        except tomllib.TOMLDecodeError as exc:
            raise ParseError(f"malformed TOML: {exc}", where=where) from None
    else:
        import yaml

        try:
            data = yaml.safe_load(text)
        except yaml.YAMLError as exc:
            mark = getattr(exc, "problem_mark", None)
            at = f" at line {mark.line + 1}, column {mark.column + 1}" if mark is not None else ""
            problem = getattr(exc, "problem", None) or "syntax error"
            raise ParseError(f"malformed YAML{at}: {problem}", where=where) from None
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
            return _expr.evaluate(tree, self.params), _expr.to_text(tree)
        except ParseError as exc:
            raise self.fail(place, str(exc)) from None

    def angle_tree(self, tree: _expr.Node) -> _expr.Node:
        """In a degree file a bare angle is in degrees; one that says deg or uses pi is taken as written."""
        if self.deg and not _names_unit(tree):
            return ("call", "deg", (tree,))
        return tree


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


def _subst(tree: _expr.Node, name: str, value: _expr.Node) -> _expr.Node:
    kind = tree[0]
    if kind == "name":
        return value if tree[1] == name else tree
    if kind == "neg":
        return ("neg", _subst(tree[1], name, value))
    if kind == "bin":
        return ("bin", tree[1], _subst(tree[2], name, value), _subst(tree[3], name, value))
    if kind == "call":
        return ("call", tree[1], tuple(_subst(a, name, value) for a in tree[2]))
    return tree


def _parameters(raw: Any, where: str) -> dict[str, float]:
    if raw is None:
        return {}
    if not isinstance(raw, dict):
        raise ParseError("'parameters' must be a mapping name: value", where=f"{where}: parameters")
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
        if text not in ("0", "0.0"):
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
        limits = tuple(ctx.number(v, lplace, angle=joint is JointType.REVOLUTE)[0] for v in lim)
        if limits[0] > limits[1]:
            raise ctx.fail(lplace, f"low limit {limits[0]:g} is above high limit {limits[1]:g}")
    inertia = _inertia(raw.get("inertia"), f"{place}, field 'inertia'", ctx) if "inertia" in raw else None
    try:
        return DHLink(joint=joint, q_limits=limits, inertia=inertia, symbols=tuple(texts), **values)
    except ModelError as exc:
        raise ctx.fail(place, str(exc)) from None


def _check_linear(tree: _expr.Node, qname: str, place: str, ctx: _Ctx) -> _expr.Node:
    """Check the field is q + offset (coefficient one) and return the offset tree."""
    env = dict(ctx.params)
    try:
        f = [_expr.evaluate(tree, {**env, qname: v}) for v in (0.0, 1.0, 2.5)]
    except ParseError as exc:
        raise ctx.fail(place, str(exc)) from None
    if abs((f[1] - f[0]) - 1.0) > 1e-12 or abs((f[2] - f[0]) - 2.5) > 1e-12:
        raise ctx.fail(place, f"the joint variable must enter as '{qname} + offset' (coefficient 1)")
    return _drop_zeros(_subst(tree, qname, ("num", "0")))


def _is_zero(node: _expr.Node) -> bool:
    return node[0] == "num" and float(node[1]) == 0.0


def _drop_zeros(tree: _expr.Node) -> _expr.Node:
    """Remove the ``0 +`` left where the joint variable was taken out of ``q + offset``."""
    if tree[0] == "bin" and tree[1] in "+-":
        left, right = _drop_zeros(tree[2]), _drop_zeros(tree[3])
        if _is_zero(right):
            return left
        if _is_zero(left):
            return right if tree[1] == "+" else ("neg", right)
        return ("bin", tree[1], left, right)
    return tree


def _inertia(raw: Any, place: str, ctx: _Ctx) -> LinkInertia:
    if not isinstance(raw, dict):
        raise ctx.fail(place, "inertia must be a mapping {mass, com, inertia, ...}")
    unknown = set(map(str, raw)) - _INERTIA_KEYS
    if unknown:
        raise ctx.fail(place, f"unknown key {sorted(unknown)[0]!r}; allowed: {', '.join(sorted(_INERTIA_KEYS))}")
    texts: list[tuple[str, str]] = []

    def val(key: str, value: Any, sym_key: str) -> float:
        number, text = ctx.number(value, f"{place}.{key}")
        if text not in ("0", "0.0"):
            texts.append((sym_key, text))
        return number

    def vec(key: str, n: int) -> tuple[float, ...]:
        value = raw.get(key, [0] * n)
        if key == "inertia" and isinstance(value, list) and len(value) == 3 and all(isinstance(r, list) for r in value):
            value = [value[0][0], value[1][1], value[2][2], value[0][1], value[0][2], value[1][2]]
        if not isinstance(value, (list, tuple)) or len(value) != n:
            raise ctx.fail(f"{place}.{key}", f"expected a list of {n} values")
        return tuple(val(f"{key}[{i}]", v, f"{key}{i}") for i, v in enumerate(value))

    mass = val("mass", raw.get("mass", 0), "mass")
    com = vec("com", 3)
    inertia = vec("inertia", 6)
    extra = {k: val(k, raw.get(k, 0), k) for k in ("motor_inertia", "viscous", "coulomb")}
    try:
        return LinkInertia(mass=mass, com=com, inertia=inertia, symbols=tuple(texts), **extra)  # type: ignore[arg-type]
    except ModelError as exc:
        raise ctx.fail(place, str(exc)) from None


def _transform(raw: Any, place: str, ctx: _Ctx) -> np.ndarray:
    from .numeric._transforms import transform_from_xyz_rpy

    if isinstance(raw, list):
        if len(raw) != 4 or not all(isinstance(r, list) and len(r) == 4 for r in raw):
            raise ctx.fail(place, "a transform given as a matrix must be 4×4")
        return np.array([[ctx.number(v, place)[0] for v in r] for r in raw])
    if not isinstance(raw, dict) or set(map(str, raw)) - {"xyz", "rpy"}:
        raise ctx.fail(place, "expected {xyz: [x, y, z], rpy: [roll, pitch, yaw]}, a 4×4 list, or (tool) a DH row")
    xyz = raw.get("xyz", [0, 0, 0])
    rpy = raw.get("rpy", [0, 0, 0])
    for key, v in (("xyz", xyz), ("rpy", rpy)):
        if not isinstance(v, list) or len(v) != 3:
            raise ctx.fail(f"{place}.{key}", "expected a list of 3 values")
    return transform_from_xyz_rpy(
        [ctx.number(v, f"{place}.xyz") [0] for v in xyz], [ctx.number(v, f"{place}.rpy", angle=True)[0] for v in rpy]
    )


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
    if "tool" in data and data["tool"] is not None:
        raw_tool = data["tool"]
        if isinstance(raw_tool, dict) and set(map(str, raw_tool)) & set(DH_FIELDS):
            link = _joint_row(raw_tool, len(rows) + 1, joint_no + 1, ctx)
            if link.is_joint:
                raise ParseError("the tool row cannot have a joint variable", where=f"{where}: tool")
            links.append(link)
        else:
            tool = _transform(raw_tool, "tool", ctx)
    base = _transform(data["base"], "base", ctx) if data.get("base") is not None else np.eye(4)
    gravity = data.get("gravity", [0, 0, -9.81])
    if not isinstance(gravity, list) or len(gravity) != 3:
        raise ParseError("gravity must be a list of 3 values [m/s²]", where=f"{where}: gravity")
    g = tuple(ctx.number(v, "gravity")[0] for v in gravity)
    poses = _poses(data.get("poses"), [link.joint for link in links if link.is_joint], ctx)
    try:
        return DHRobot(
            name=str(data.get("name", Path(where).stem)),
            links=tuple(links),
            convention=Convention(conv),
            base=base,  # type: ignore[arg-type]
            tool=tool,  # type: ignore[arg-type]
            gravity=g,  # type: ignore[arg-type]
            parameters=tuple(params.items()),
            description=str(data.get("description", "")),
            source=str(data.get("source", where)),
            poses=poses,
        )
    except ModelError as exc:
        raise ParseError(str(exc), where=where) from None


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
    """The same robot with some named parameters given new values (all fields re-evaluated)."""
    params = robot.parameter_values
    for k, v in values.items():
        if k not in params:
            raise ParseError(f"robot {robot.name!r} has no parameter {k!r}; parameters: {', '.join(params) or 'none'}")
        params[k] = float(v)
    ev = lambda text: _expr.evaluate(_expr.parse(text), params)  # noqa: E731
    links = []
    for link in robot.links:
        new = {k: ev(t) for k, t in link.symbols}
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
        links.append(DHLink(**{**_link_kwargs(link), **new, "inertia": inertia}))
    return robot.replace(links=tuple(links), parameters=tuple(params.items()))


def _link_kwargs(link: DHLink) -> dict[str, Any]:
    return {
        "a": link.a, "alpha": link.alpha, "d": link.d, "theta": link.theta, "joint": link.joint,
        "q_limits": link.q_limits, "inertia": link.inertia, "symbols": link.symbols,
    }


def parse_values(text: str | list[Any], n: int | None = None, *, what: str = "q", deg: bool = False,
                 env: Mapping[str, float] | None = None) -> np.ndarray:
    """Parse ``"0, pi/4, 90deg"`` (comma or space separated expressions) into floats.

    ``deg=True`` reads plain numbers as degrees (``pi`` or ``deg`` in a value still say their unit).
    Raises ParseError naming the value when something is wrong.
    """
    if isinstance(text, str):
        parts = [p for p in re.split(r"[,\s;]+(?![^()]*\))", text.strip().strip("[]()")) if p]
    else:
        parts = list(text)
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


# --------------------------------------------------------------------------------------------------
# robot -> dict / file


def _num_text(x: float) -> Any:
    if x == int(x) and abs(x) < 1e15:
        return int(x)
    for k in (1, 2, 3, 4, 6, 12):
        for s in (1, -1):
            if abs(x - s * math.pi / k) < 1e-14:
                return ("-" if s < 0 else "") + ("pi" if k == 1 else f"pi/{k}")
    return float(x)


def robot_to_dict(robot: DHRobot) -> dict[str, Any]:
    """Plain data for a robot file (radians, expressions kept as written)."""
    rows: list[dict[str, Any]] = []
    for link in robot.links:
        sym = dict(link.symbols)
        row: dict[str, Any] = {}
        for field in DH_FIELDS:
            v: Any = sym.get(field, _num_text(getattr(link, field)))
            if link.joint is JointType.REVOLUTE and field == "theta":
                v = "q" if v in (0, "0") else f"q + {v}"
            if link.joint is JointType.PRISMATIC and field == "d":
                v = "q" if v in (0, "0") else f"q + {v}"
            row[field] = v
        if link.q_limits is not None:
            row["limits"] = [_num_text(link.q_limits[0]), _num_text(link.q_limits[1])]
        if link.inertia is not None:
            li = link.inertia
            s = dict(li.symbols)
            inertia: dict[str, Any] = {
                "mass": s.get("mass", li.mass),
                "com": [s.get(f"com{i}", c) for i, c in enumerate(li.com)],
                "inertia": [s.get(f"inertia{i}", c) for i, c in enumerate(li.inertia)],
            }
            for k in ("motor_inertia", "viscous", "coulomb"):
                if getattr(li, k) or k in s:
                    inertia[k] = s.get(k, getattr(li, k))
            row["inertia"] = inertia
        rows.append(row)
    out: dict[str, Any] = {"name": robot.name}
    if robot.description:
        out["description"] = robot.description
    out["convention"] = robot.convention.value
    out["angle_unit"] = "rad"
    if robot.parameters:
        out["parameters"] = {k: v for k, v in robot.parameters}
    out["joints"] = rows
    if not np.allclose(robot.tool_matrix, np.eye(4)):
        out["tool"] = [[float(x) for x in r] for r in robot.tool]
    if not np.allclose(robot.base_matrix, np.eye(4)):
        out["base"] = [[float(x) for x in r] for r in robot.base]
    out["gravity"] = list(robot.gravity)
    if robot.poses:
        out["poses"] = {k: [_num_text(v) for v in q] for k, q in robot.poses}
    return out


def dump_robot(robot: DHRobot, fmt: str = "yaml") -> str:
    """The robot as file text (``yaml`` or ``json``)."""
    data = robot_to_dict(robot)
    if fmt == "json":
        return json.dumps(data, indent=2)
    import yaml

    lines = [f"# {robot.name}: written by denavit"]
    body = {k: v for k, v in data.items() if k != "joints"}
    text = yaml.safe_dump(body, sort_keys=False, default_flow_style=None)
    joints = "joints:\n" + "".join(
        "  - " + yaml.safe_dump(row, default_flow_style=True, sort_keys=False, width=10_000).strip() + "\n"
        for row in data["joints"]
    )
    return "\n".join(lines) + "\n" + text + joints


def save_robot(robot: DHRobot, path: str | Path, *, overwrite: bool = False) -> None:
    """Write a robot file; refuses to overwrite an existing file unless ``overwrite=True``."""
    path = Path(path)
    if path.exists() and not overwrite:
        raise ParseError(f"{str(path)!r} exists; not overwriting it (choose another name or pass --force)")
    fmt = "json" if path.suffix.lower() == ".json" else "yaml"
    path.write_text(dump_robot(robot, fmt), encoding="utf-8")
