"""Writing robot files: a robot as plain data and as YAML a person can read (re-exported by :mod:`denavit.io`).

Expressions are kept as written (``d1``, ``q + 5*pi/4``, ``-90deg``); a number is written as ``pi/2`` or ``170deg``
only when that text reads back to it bit for bit, else with ``repr``'s shortest exact digits; base and tool are
left out only when exactly the identity.  So every file written loads back to the same arm, bit for bit.  Free
text (name, description, pose names) is data: quoted and escaped (:mod:`denavit._text`), and one line in the
header comment.
"""

from __future__ import annotations

import functools
import json
import math
import re
from pathlib import Path
from typing import Any, Mapping

import numpy as np

from . import _expr, _text
from ._read_row import DEGREE_HINT
from .errors import ParseError
from .model import DH_FIELDS, DHRobot, JointType

__all__ = ["robot_to_dict", "dump_robot", "save_robot", "value_text", "expression_text"]


def _num_text(x: float, angle: bool = False) -> Any:
    """A value for a written file, read back to exactly ``x``: an int when whole, a multiple of π as text
    (``5*pi/4``) when that text evaluates to ``x`` bit for bit, with ``angle=True`` a whole number of degrees
    (``170deg``) under the same condition, else the float (written with ``repr``: shortest exact digits).

    An angle beyond a full turn that has no exact form is written ``rad(6.981317007977318)``: it says its unit,
    so reading the file does not warn "more than a full turn — degrees?" about a genuine multi-turn limit.
    """
    x = float(x)
    if x == int(x) and abs(x) < 1e15:
        return int(x)
    for k in (1, 2, 3, 4, 6, 8, 12):
        num = round(x * k / math.pi)
        if num:
            coef = {1: "", -1: "-"}.get(num, f"{num}*")
            text = f"{coef}pi" + (f"/{k}" if k != 1 else "")
            if _exact(text, x):
                return text
    if angle:
        d = round(math.degrees(x))
        if d and abs(d) <= 3600 and _exact(f"{d}deg", x):
            return f"{d}deg"
        if abs(x) > DEGREE_HINT:
            return f"rad({x!r})"
    return x


@functools.lru_cache(maxsize=4096)
def _value(text: str) -> float:
    return _expr.evaluate(_expr.parse(text))


def _exact(text: str, x: float) -> bool:
    """Whether ``text`` reads back (through the reader's own evaluator) to exactly ``x``."""
    return _value(text) == x


def _text_value(text: str) -> Any:
    """A stored expression text as it is best written: a plain number as a number, ``deg(90)`` as ``90deg``."""
    try:
        tree = _expr.parse(text)
    except ParseError:
        return text
    if _expr.is_literal(tree):
        value = _expr.evaluate(tree)
        return int(value) if value == int(value) and abs(value) < 1e15 else value
    short = _DEG_CALL.sub(r"\1deg", text)  # deg(90) -> 90deg; deg(-90) stays (-90deg reads as -(90deg))
    return short if short == text or _same_tree(short, tree) else text


def _same_tree(text: str, tree: _expr.Node) -> bool:
    try:
        return _expr.parse(text) == tree
    except ParseError:
        return False


_DEG_CALL = re.compile(r"\bdeg\((-?(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?)\)")


def value_text(x: float, angle: bool = False) -> str:
    """A value as it is written in robot files and tables: ``2``, ``0.4318``, ``5*pi/4``, ``-170deg`` (angles).

    >>> value_text(-2.356194490192345, angle=True), value_text(0.4318), value_text(-2.9670597283903604, angle=True)
    ('-3*pi/4', '0.4318', '-170deg')
    """
    return str(_num_text(x, angle))


def expression_text(text: str) -> str:
    """A stored field expression as it is best read: ``deg(90)`` → ``90deg``; others unchanged (``deg(-90)`` too:
    ``-90deg`` reads as ``-(90deg)``, another expression of the same value).

    >>> expression_text("deg(90)"), expression_text("deg(-90)"), expression_text("L1 + 0.1")
    ('90deg', 'deg(-90)', 'L1 + 0.1')
    """
    return str(_text_value(text))


def _with_q(offset: Any) -> str:
    """``q``, ``q + offset`` or ``q - offset`` for a joint field."""
    if offset in (0, "0"):
        return "q"
    text = str(offset)
    return f"q - {text[1:]}" if text.startswith("-") else f"q + {text}"


def _transform_dict(robot: DHRobot, place: str) -> Any:
    sym = dict(robot.symbols)
    if f"{place}.m0" in sym:
        return [[_text_value(sym[f"{place}.m{4 * i + j}"]) for j in range(4)] for i in range(4)]
    if f"{place}.xyz0" in sym:
        return {"xyz": [_text_value(sym[f"{place}.xyz{i}"]) for i in range(3)],
                "rpy": [_text_value(sym[f"{place}.rpy{i}"]) for i in range(3)]}
    return [[_num_text(x) for x in r] for r in getattr(robot, f"{place}_matrix")]


def robot_to_dict(robot: DHRobot) -> dict[str, Any]:
    """Plain data for a robot file (radians; expressions kept as written, exact multiples of π as such)."""
    rows: list[dict[str, Any]] = []
    for link in robot.links:
        sym = dict(link.symbols)
        row: dict[str, Any] = {}
        for field in DH_FIELDS:
            angle = field in ("alpha", "theta")
            v: Any = _text_value(sym[field]) if field in sym else _num_text(getattr(link, field), angle)
            if (link.joint is JointType.REVOLUTE and field == "theta") or (link.joint is JointType.PRISMATIC and field == "d"):
                v = _with_q(v)
            row[field] = v
        if link.q_limits is not None:
            angle = link.joint is JointType.REVOLUTE
            row["limits"] = ([_text_value(sym["limits0"]), _text_value(sym["limits1"])] if "limits0" in sym
                             else [_num_text(link.q_limits[0], angle), _num_text(link.q_limits[1], angle)])
        if link.inertia is not None:
            li = link.inertia
            s = dict(li.symbols)
            get = lambda key, x: _text_value(s[key]) if key in s else _num_text(x)  # noqa: E731
            inertia: dict[str, Any] = {
                "mass": get("mass", li.mass),
                "com": [get(f"com{i}", c) for i, c in enumerate(li.com)],
                "inertia": [get(f"inertia{i}", c) for i, c in enumerate(li.inertia)],
            }
            for k in ("motor_inertia", "viscous", "coulomb"):
                if getattr(li, k) or k in s:
                    inertia[k] = get(k, getattr(li, k))
            row["inertia"] = inertia
        rows.append(row)
    out: dict[str, Any] = {"name": robot.name}
    if robot.description:
        out["description"] = robot.description
    out["convention"] = robot.convention.value
    out["angle_unit"] = "rad"
    if robot.parameters:
        out["parameters"] = {k: _num_text(v) if v == int(v) else v for k, v in robot.parameters}
    out["joints"] = rows
    for place in ("tool", "base"):  # left out only when exactly the identity: 1e-12 off it is still written
        if any(k.startswith(f"{place}.") for k, _ in robot.symbols) or not np.array_equal(
                getattr(robot, f"{place}_matrix"), np.eye(4)):
            out[place] = _transform_dict(robot, place)
    gsym = dict(robot.symbols)
    out["gravity"] = ([_text_value(gsym[f"gravity{i}"]) for i in range(3)] if "gravity0" in gsym
                      else [_num_text(g) for g in robot.gravity])
    if robot.poses:
        revolute = [t is JointType.REVOLUTE for t in robot.joint_types]
        out["poses"] = {k: [_num_text(v, r) for v, r in zip(q, revolute)] for k, q in robot.poses}
    return out


_PLAIN = re.compile(r"[A-Za-z0-9_.+\-*/^() ]*[A-Za-z0-9_.)]")


def _yaml_value(v: Any) -> str:
    """One value in YAML flow style: numbers unquoted, expressions plain when safe, else double-quoted."""
    if isinstance(v, bool) or v is None:
        return json.dumps(v)
    if isinstance(v, int):
        return str(v)
    if isinstance(v, float):
        text = repr(v)  # the shortest digits that read back to exactly v
        return text.replace("e", ".0e") if "e" in text and "." not in text else text  # YAML 1.1 floats need a dot
    if isinstance(v, dict):
        return "{" + ", ".join(f"{_yaml_value(str(k))}: {_yaml_value(x)}" for k, x in v.items()) + "}"
    if isinstance(v, (list, tuple)):
        return "[" + ", ".join(_yaml_value(x) for x in v) + "]"
    text = str(v)
    if _PLAIN.fullmatch(text) and not text.startswith(("- ", " ")) and _plain_is_text(text):
        return text
    return _text.yaml_string(text)


@functools.lru_cache(maxsize=4096)
def _plain_is_text(text: str) -> bool:
    import yaml

    try:
        return isinstance(yaml.safe_load(text), str)
    except yaml.YAMLError:
        return False


def _yaml_row(row: Mapping[str, Any]) -> str:
    """A joint row: the DH values (and limits) on one line, the inertial data on their own lines."""
    head = ", ".join(f"{k}: {_yaml_value(v)}" for k, v in row.items() if k != "inertia")
    if "inertia" not in row:
        return "  - {" + head + "}\n"
    inertia = row["inertia"]
    groups = [("mass", "com"), ("inertia",), tuple(k for k in inertia if k not in ("mass", "com", "inertia"))]
    parts = [", ".join(f"{k}: {_yaml_value(inertia[k])}" for k in g if k in inertia) for g in groups]
    return "  - {" + head + ",\n     inertia: {" + ",\n               ".join(p for p in parts if p) + "}}\n"


def dump_robot(robot: DHRobot, fmt: str = "yaml") -> str:
    """The robot as file text (``yaml`` or ``json``).

    The YAML is written for people: one line per DH row, inertial data on their own lines, numbers
    unquoted, expressions and exact multiples of π kept as text; it loads back to exactly ``robot``.
    """
    data = robot_to_dict(robot)
    if fmt == "json":
        return json.dumps(data, indent=2)
    out = [f"# {_text.visible(robot.name)}: written by denavit"]  # a comment: one line, whatever the name holds
    for key, value in data.items():
        if key == "joints":
            out.append("joints:\n" + "".join(_yaml_row(row) for row in value).rstrip("\n"))
        elif key in ("base", "tool") and isinstance(value, list):
            out.append(f"{key}:\n" + "\n".join(f"  - {_yaml_value(r)}" for r in value))
        elif isinstance(value, dict) and len(_yaml_value(value)) > 100:  # many parameters or poses: one per line
            out.append(f"{key}:\n" + "\n".join(f"  {_yaml_value(str(k))}: {_yaml_value(v)}" for k, v in value.items()))
        else:
            out.append(f"{key}: {_yaml_value(value)}")
    return "\n".join(out) + "\n"


def save_robot(robot: DHRobot, path: str | Path, *, overwrite: bool = False) -> None:
    """Write a robot file (``.yaml``, ``.yml`` or ``.json``); refuses to overwrite an existing file unless
    ``overwrite=True``, and refuses other suffixes (``x.png`` would receive YAML)."""
    path = Path(path)
    if path.suffix.lower() not in (".yaml", ".yml", ".json"):
        raise ParseError(f"{str(path)!r}: unsupported file type {path.suffix or '(none)'!r}; expected .yaml, .yml or .json")
    if path.exists() and not overwrite:
        raise ParseError(f"{str(path)!r} exists; not overwriting it (choose another name or pass overwrite=True)")
    fmt = "json" if path.suffix.lower() == ".json" else "yaml"
    path.write_text(dump_robot(robot, fmt), encoding="utf-8")
