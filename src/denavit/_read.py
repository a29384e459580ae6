"""Reading a robot file's plain data into a :class:`~denavit.model.DHRobot` (used by :mod:`denavit.io`).

Every value goes through :mod:`denavit._expr` (a restricted grammar), never ``eval``; every error is a
:class:`~denavit.errors.ParseError` naming the file, the row and the field.  Degrees are converted to radians
here; bare angles above a full turn in a radian file draw one :class:`~denavit.errors.DenavitWarning`.  The rows
themselves are read by :mod:`denavit._read_row`.
"""

from __future__ import annotations

import re
from pathlib import Path
from typing import Any, Mapping

import numpy as np

from . import _expr
from ._read_row import DEGREE_HINT, QVAR, Context, has_names, joint_row, names_unit
from .errors import ModelError, ParseError
from .model import DH_FIELDS, MAX_ANGLE, MAX_MAGNITUDE, Convention, DHLink, DHRobot, JointType

__all__ = ["robot_from_dict", "names_unit", "transform_from_texts", "MAX_ROWS", "MAX_PARAMETERS", "MAX_TEXT", "DEGREE_HINT"]

#: Most DH rows in a file, fixed rows included (joints are capped by :data:`denavit.model.MAX_JOINTS`).
MAX_ROWS = 64
#: Most named parameters in a file.
MAX_PARAMETERS = 256
_NAME = re.compile(r"^[A-Za-z_][A-Za-z_0-9]*$")
_RESERVED = set(_expr.FUNCTIONS) | {"pi", "q"}
_TOP_KEYS = {
    "name", "description", "convention", "angle_unit", "parameters", "joints", "tool", "base", "gravity", "source",
    "poses",
}


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
        if not _NAME.match(key) or key in _RESERVED or QVAR.match(key):
            raise ParseError(f"{key!r} cannot be a parameter name (reserved or not an identifier)", where=f"{where}: {place}")
        ctx = Context(where, dict(params), False)
        params[key] = ctx.number(value, place)[0]
    return params


def _transform(raw: Any, place: str, ctx: Context) -> tuple[np.ndarray, list[tuple[str, str]]]:
    """A base or tool transform and, when it uses parameters, the expression texts of its entries."""
    from .numeric._transforms import transform_from_xyz_rpy

    if isinstance(raw, list):
        if len(raw) != 4 or not all(isinstance(r, list) and len(r) == 4 for r in raw):
            raise ctx.fail(place, "a transform given as a matrix must be 4×4")
        got = [ctx.number(v, f"{place}[{i}][{j}]") for i, r in enumerate(raw) for j, v in enumerate(r)]
        texts = [(f"{place}.m{k}", t) for k, (_, t) in enumerate(got)]
        return np.array([v for v, _ in got]).reshape(4, 4), texts if any(has_names(t) for _, t in texts) else []
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
    return T, texts if any(has_names(t) for _, t in texts) else []


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
    if data.get("convention") is None:
        raise ParseError("'convention' is missing: add 'convention: standard' (Spong, distal) or 'convention: "
                         "modified' (Craig, proximal)", where=f"{where}: convention")
    conv = str(data.get("convention", "")).strip().lower()
    if conv not in ("standard", "modified"):
        raise ParseError(
            f"'convention' must be standard or modified, got {data.get('convention')!r}", where=f"{where}: convention"
        )
    unit = str(data.get("angle_unit", "rad")).strip().lower()
    if unit not in ("rad", "deg"):
        raise ParseError(f"'angle_unit' must be rad or deg, got {unit!r}", where=f"{where}: angle_unit")
    params = _parameters(data.get("parameters"), where)
    ctx = Context(where, params, unit == "deg")
    rows = data.get("joints")
    if not isinstance(rows, list) or not rows:
        raise ParseError("'joints' must be a non-empty list of DH rows", where=f"{where}: joints")
    if len(rows) > MAX_ROWS:
        raise ParseError(f"too many rows ({len(rows)}; at most {MAX_ROWS})", where=f"{where}: joints")
    links: list[DHLink] = []
    joint_no = 0
    for i, raw in enumerate(rows, start=1):
        is_joint = isinstance(raw, dict) and any(
            QVAR.match(n) and n not in params
            for f in ("theta", "d", "a", "alpha")
            if f in raw
            for n in _safe_names(raw[f])
        )
        link = joint_row(raw, i, joint_no + 1 if is_joint else joint_no, ctx)
        joint_no += link.is_joint
        links.append(link)
    tool = np.eye(4)
    symbols: list[tuple[str, str]] = []
    if "tool" in data and data["tool"] is not None:
        raw_tool = data["tool"]
        if isinstance(raw_tool, dict) and set(map(str, raw_tool)) & set(DH_FIELDS):
            link = joint_row(raw_tool, len(rows) + 1, joint_no + 1, ctx)
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
    if any(has_names(t) for _, t in got):
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


def _poses(raw: Any, joints: list[JointType], ctx: Context) -> tuple[tuple[str, tuple[float, ...]], ...]:
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
