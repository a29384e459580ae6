"""The workbench's inverse kinematics answer: every analytic solution of a target (``denavit ik``'s analytic
route, :func:`denavit.analytic_ik`), with joints held for a redundant arm.  Request data in, JSON data out, as in
:mod:`denavit.web._handlers`."""

from __future__ import annotations

import re
from typing import Any

from .. import DenavitError, analytic_ik, forward_kinematics
from ._handlers import (
    RequestError,
    field_of,
    json_matrix,
    one_line,
    q_of,
    robot_of,
    values_of,
)

__all__ = ["MAX_SOLUTIONS", "inverse_kinematics"]

#: Most IK solutions listed (an analytic 6R arm has at most 16).
MAX_SOLUTIONS = 64


def inverse_kinematics(body: Any) -> dict[str, Any]:
    """Every analytic IK solution of the target: ``pose`` "x, y, z, roll, pitch, yaw" (m, rad) or the pose at ``q``;
    ``lock`` holds joints of a redundant arm (``"q7"`` at its value in ``q``, or ``"q7 = 0.3"``)."""
    from ..numeric import transform_from_xyz_rpy

    robot = robot_of(body)
    if field_of(body, "pose") is not None:
        if not isinstance(body["pose"], str):
            raise RequestError("'pose' must be a text \"x, y, z, roll, pitch, yaw\" (m, rad; deg suffix allowed)")
        p = values_of(body, "pose", 6)
        T = transform_from_xyz_rpy(p[:3], p[3:])
    else:
        T = forward_kinematics(robot, q_of(body, robot))
    try:
        res = analytic_ik(robot, T, _locked(body, robot) or None)
    except DenavitError as exc:
        raise RequestError(str(exc), 422) from None
    k = min(len(res.solutions), MAX_SOLUTIONS)
    return {"target": json_matrix(T), "method": res.method, "controlled": res.controlled,
            "solutions": [{"q": json_matrix(res.solutions[i]), "branch": res.branches[i], "valid": bool(res.valid[i]),
                           "position_error": float(res.position_error[i]),
                           "orientation_error": float(res.orientation_error[i])} for i in range(k)],
            "outside_limits": len(res.outside_limits)}


_LOCK = re.compile(r"^\s*q(\d{1,3})\s*(?:=\s*(.+?))?\s*$")


def _locked(body: Any, robot: Any) -> dict[str, float]:
    """The held joints of a redundant arm's IK: ``"q7"`` (at its value in ``q``) or ``"q7 = 0.3"``, comma-separated."""
    text = field_of(body, "lock")
    if text in (None, ""):
        return {}
    if not isinstance(text, str) or len(text) > 400:
        raise RequestError("'lock' must be a text such as \"q7\" or \"q7 = 0.3\"")
    held: dict[str, float] = {}
    for part in text.split(","):
        m = _LOCK.match(part)
        if not m or not 1 <= int(m.group(1)) <= robot.dof:
            raise RequestError(f"lock: {one_line(part, 40)!r} is not q1 … q{robot.dof}, alone or '= value'")
        k = int(m.group(1))
        if m.group(2) is None:
            held[f"q{k}"] = float(q_of(body, robot)[k - 1])
        else:
            held[f"q{k}"] = float(values_of({"v": [m.group(2)]}, "v", 1)[0])
    return held
