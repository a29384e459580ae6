"""Robots built in Python, row by row, as naturally as in a DH table.

>>> import denavit
>>> arm = denavit.robot([denavit.revolute(a="L1"), denavit.revolute(a="L2")],
...                     name="two-link", parameters={"L1": 0.5, "L2": 0.4})
>>> arm
DHRobot('two-link', 2 joints, standard)

:func:`revolute`, :func:`prismatic` and :func:`fixed` describe rows; :func:`robot` assembles them.  Every value
is a number or an expression text (``"L1"``, ``"pi/2"``, ``"H1 + 0.05"``) read by the same restricted parser as a
robot file (never ``eval``), so a robot built here and one loaded from a file are the same value, and a bad value
is refused the same way: a :class:`~denavit.errors.ParseError` naming the row and the field.
"""

from __future__ import annotations

import numbers
from dataclasses import dataclass
from typing import Any, Iterable, Mapping

import numpy as np

from .errors import ModelError
from .model import DH_FIELDS, DHLink, DHRobot, JointType, LinkInertia

__all__ = ["Row", "revolute", "prismatic", "fixed", "robot"]

Value = Any  # a real number or an expression text


@dataclass(frozen=True)
class Row:
    """One DH row before it is placed in a robot (values may name the robot's parameters).

    ``a``, ``alpha``, ``d``, ``theta`` are the constant parts; the joint variable is added to ``theta``
    (revolute) or ``d`` (prismatic), so there they are the joint offset.  Make rows with :func:`revolute`,
    :func:`prismatic` and :func:`fixed`.
    """

    joint: JointType
    a: Value = 0.0
    alpha: Value = 0.0
    d: Value = 0.0
    theta: Value = 0.0
    limits: tuple[Value, Value] | None = None
    inertia: LinkInertia | Mapping[str, Any] | None = None


def _limits(limits: Any) -> tuple[Value, Value] | None:
    if limits is None:
        return None
    if isinstance(limits, (str, bytes)) or not hasattr(limits, "__len__") or len(limits) != 2:
        raise ModelError(f"limits must be a pair (low, high), got {limits!r:.60}")
    return (limits[0], limits[1])


def revolute(*, a: Value = 0.0, alpha: Value = 0.0, d: Value = 0.0, offset: Value = 0.0,
             limits: tuple[Value, Value] | None = None, inertia: LinkInertia | Mapping[str, Any] | None = None) -> Row:
    """A revolute row: θ = q + offset.

    Parameters
    ----------
    a, d : float or str
        Link length and offset [m] (in a modified-DH robot, ``a`` is a_{i-1}).
    alpha : float or str
        Link twist [rad] (α_{i-1} in a modified-DH robot).
    offset : float or str
        Constant part of θ [rad].
    limits : (low, high), optional
        Joint limits [rad].
    inertia : LinkInertia or mapping, optional
        Inertial data of the link, as :class:`~denavit.LinkInertia` or the mapping of a robot file
        (``{"mass": 2.0, "com": [x, y, z], "inertia": [Ixx, Iyy, Izz, Ixy, Ixz, Iyz]}``).
    """
    return Row(JointType.REVOLUTE, a, alpha, d, offset, _limits(limits), inertia)


def prismatic(*, a: Value = 0.0, alpha: Value = 0.0, theta: Value = 0.0, offset: Value = 0.0,
              limits: tuple[Value, Value] | None = None, inertia: LinkInertia | Mapping[str, Any] | None = None) -> Row:
    """A prismatic row: d = q + offset (``offset`` [m]); ``theta`` is the constant joint angle [rad].
    Other arguments as in :func:`revolute`; ``limits`` in metres."""
    return Row(JointType.PRISMATIC, a, alpha, offset, theta, _limits(limits), inertia)


def fixed(*, a: Value = 0.0, alpha: Value = 0.0, d: Value = 0.0, theta: Value = 0.0,
          inertia: LinkInertia | Mapping[str, Any] | None = None) -> Row:
    """A fixed row (no joint variable), e.g. a flange; as the ``tool`` of :func:`robot` it is the tool row."""
    return Row(JointType.FIXED, a, alpha, d, theta, None, inertia)


def _plain(value: Any) -> Any:
    """Numbers as floats (numpy scalars included), everything else as given for the parser to judge."""
    if isinstance(value, numbers.Real) and not isinstance(value, bool):
        return float(value)
    return value


def _inertia_data(inertia: Any) -> Any:
    if isinstance(inertia, LinkInertia):
        s = dict(inertia.symbols)
        out: dict[str, Any] = {
            "mass": s.get("mass", inertia.mass),
            "com": [s.get(f"com{i}", c) for i, c in enumerate(inertia.com)],
            "inertia": [s.get(f"inertia{i}", c) for i, c in enumerate(inertia.inertia)],
        }
        for key in ("motor_inertia", "viscous", "coulomb"):
            out[key] = s.get(key, getattr(inertia, key))
        return out
    if isinstance(inertia, Mapping):
        return {str(k): (list(map(_plain, v)) if isinstance(v, (list, tuple, np.ndarray)) else _plain(v))
                for k, v in inertia.items()}
    return inertia  # the parser refuses it, naming the row


def _row_of_link(link: DHLink) -> Row:
    sym = dict(link.symbols)
    v = {f: sym.get(f, getattr(link, f)) for f in DH_FIELDS}
    return Row(link.joint, v["a"], v["alpha"], v["d"], v["theta"], link.q_limits, link.inertia)


def _with_q(offset: Any) -> Any:
    offset = _plain(offset)
    if isinstance(offset, float):
        return f"q + {offset!r}" if offset >= 0 else f"q - {-offset!r}"
    if isinstance(offset, str):
        return f"q + ({offset})"
    return offset  # the parser refuses it, naming the row and field


def _row_data(row: Any, k: int) -> dict[str, Any]:
    if isinstance(row, DHLink):
        row = _row_of_link(row)
    if not isinstance(row, Row):
        raise ModelError(f"row {k}: expected a row made by denavit.revolute, prismatic or fixed (or a DHLink), "
                         f"got {type(row).__name__}")
    out = {f: _plain(getattr(row, f)) for f in DH_FIELDS}
    if row.joint is JointType.REVOLUTE:
        out["theta"] = _with_q(row.theta)
    elif row.joint is JointType.PRISMATIC:
        out["d"] = _with_q(row.d)
    if row.limits is not None:
        out["limits"] = [_plain(v) for v in row.limits]
    if row.inertia is not None:
        out["inertia"] = _inertia_data(row.inertia)
    return out


def _transform_data(value: Any, what: str) -> Any:
    if value is None or isinstance(value, Mapping):
        return value
    arr = np.asarray(value, dtype=object)
    if arr.shape != (4, 4):
        raise ModelError(f"{what} must be a 4×4 homogeneous transform or {{'xyz': [...], 'rpy': [...]}}, "
                         f"got shape {arr.shape}")
    return [[_plain(x) for x in r] for r in arr]


def robot(rows: Iterable[Row | DHLink], name: str = "robot", convention: str = "standard", *,
          parameters: Mapping[str, Value] | None = None, tool: Any = None, base: Any = None,
          gravity: Iterable[Value] = (0.0, 0.0, -9.81), angle_unit: str = "rad", description: str = "",
          poses: Mapping[str, Iterable[Value]] | None = None) -> DHRobot:
    """Assemble DH rows into a :class:`~denavit.DHRobot`.

    Parameters
    ----------
    rows : sequence of Row (or DHLink)
        The rows base to tip, from :func:`revolute`, :func:`prismatic`, :func:`fixed`.
    name : str
    convention : {"standard", "modified"}
    parameters : mapping of str to float or str, optional
        Named constants the rows may use (``{"L1": 0.5}``); the symbolic engine keeps them as symbols.
    tool : Row, 4×4 array or {"xyz": [...], "rpy": [...]}, optional
        Pose of the end effector in the last DH frame: a fixed row (appended as the tool row, as a robot
        file's ``tool:`` row is) or a transform.
    base : 4×4 array or {"xyz": [...], "rpy": [...]}, optional
        Pose of frame {0} in the world frame.
    gravity : 3 values
        Gravity acceleration in the world frame [m/s²].
    angle_unit : {"rad", "deg"}
        Unit of bare angle values (α, θ offsets, revolute limits, rpy); ``"pi/2"`` or ``"90deg"`` say their
        unit themselves.
    description : str
    poses : mapping of str to joint values, optional
        Named configurations (``{"qz": [0, 0], "qr": [0, "pi/2"]}``) [rad or ``angle_unit``, m].

    Returns
    -------
    DHRobot
        The same value :func:`denavit.robot_from_dict` gives for the equivalent robot file.

    Raises
    ------
    ParseError
        A value the restricted parser refuses, an unknown parameter, limits low > high, … naming the row.
    ModelError
        Something that is not a row, a transform of the wrong shape.
    """
    from .io import robot_from_dict

    if isinstance(rows, (Row, DHLink)):
        raise ModelError("rows must be a list of rows, e.g. [denavit.revolute(a=0.5), denavit.revolute(a=0.4)]")
    joints = [_row_data(r, k) for k, r in enumerate(rows, start=1)]
    data: dict[str, Any] = {"name": str(name), "convention": convention, "angle_unit": angle_unit,
                            "joints": joints, "gravity": [_plain(g) for g in gravity]}
    if description:
        data["description"] = str(description)
    if parameters:
        data["parameters"] = {str(k): _plain(v) for k, v in parameters.items()}
    if isinstance(tool, (Row, DHLink)):
        tool_row = tool if isinstance(tool, Row) else _row_of_link(tool)
        if tool_row.joint is not JointType.FIXED:
            raise ModelError("the tool row cannot have a joint variable; make it with denavit.fixed(...)")
        data["tool"] = _row_data(tool_row, len(joints) + 1)
    elif tool is not None:
        data["tool"] = _transform_data(tool, "tool")
    if base is not None:
        data["base"] = _transform_data(base, "base")
    if poses:
        data["poses"] = {str(k): [_plain(v) for v in np.asarray(q, dtype=object).reshape(-1)]
                         for k, q in poses.items()}
    return robot_from_dict(data, where=f"robot {str(name)!r}")
