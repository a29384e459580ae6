"""The workbench's inverse kinematics answer: every analytic solution of a target (``denavit ik``'s analytic
route, :func:`denavit.analytic_ik`), with joints held for a redundant arm, or the numeric solution from the
sliders' q (:func:`denavit.solve_ik`, ``denavit ik --method numeric``).  Request data in, JSON data out, as in
:mod:`denavit.web._handlers`."""

from __future__ import annotations

import re
from typing import Any

import numpy as np

from .. import DenavitError, analytic_ik, forward_kinematics, solve_ik
from ..ik import TOL
from ._handlers import (
    RequestError,
    field_of,
    json_matrix,
    one_line,
    q_of,
    robot_of,
    values_of,
)

__all__ = ["MAX_SHIFT", "MAX_SOLUTIONS", "inverse_kinematics"]

#: Most IK solutions listed (an analytic 6R arm has at most 16).
MAX_SOLUTIONS = 64


def inverse_kinematics(body: Any) -> dict[str, Any]:
    """IK of a target: ``pose`` "x, y, z, roll, pitch, yaw" (m, rad) or the pose at ``q``, moved by ``shift``
    (dx, dy, dz in world axes [m]: the page's drag pad).  ``method`` analytic (default): every analytic solution,
    ``lock`` holding joints of a redundant arm (``"q7"`` at its value in ``q``, or ``"q7 = 0.3"``); numeric: the
    Levenberg–Marquardt solution of :func:`denavit.solve_ik` from ``seed`` (default ``q``; any arm, 7 joints too).
    ``pose`` of the answer is the target as x, y, z, roll, pitch, yaw (the page's target field)."""
    from ..numeric import rpy_from_rotation

    robot = robot_of(body)
    T = _target(body, robot)
    method = field_of(body, "method", "analytic")
    if method not in ("analytic", "numeric"):
        raise RequestError("'method' must be analytic or numeric")
    if method == "numeric":
        out = _numeric(robot, T, q_of(body, robot, "seed" if field_of(body, "seed") is not None else "q"))
    else:
        out = _analytic(body, robot, T)
    return {"target": json_matrix(T), "pose": json_matrix(np.concatenate([T[:3, 3], rpy_from_rotation(T[:3, :3])])),
            **out}


#: Largest drag of the target in one request [m].
MAX_SHIFT = 1e3


def _target(body: Any, robot: Any) -> np.ndarray:
    """The target pose (4, 4) in the world frame: the typed pose or the pose at ``q``, then moved by ``shift``."""
    from ..numeric import transform_from_xyz_rpy

    if field_of(body, "pose") is not None:
        if not isinstance(body["pose"], str):
            raise RequestError("'pose' must be a text \"x, y, z, roll, pitch, yaw\" (m, rad; deg suffix allowed)")
        p = values_of(body, "pose", 6)
        T = transform_from_xyz_rpy(p[:3], p[3:])
    else:
        T = forward_kinematics(robot, q_of(body, robot))
    if field_of(body, "shift") is not None:
        d = values_of(body, "shift", 3)
        if np.abs(d).max() > MAX_SHIFT:
            raise RequestError(f"shift: at most {MAX_SHIFT:g} m along each axis")
        T = T.copy()
        T[:3, 3] += d
    return T


def _analytic(body: Any, robot: Any, T: np.ndarray) -> dict[str, Any]:
    try:
        res = analytic_ik(robot, T, _locked(body, robot) or None)
    except DenavitError as exc:
        raise RequestError(str(exc), 422) from None
    k = min(len(res.solutions), MAX_SOLUTIONS)
    return {"method": res.method, "controlled": res.controlled,
            "solutions": [{"q": json_matrix(res.solutions[i]), "branch": res.branches[i], "valid": bool(res.valid[i]),
                           "position_error": float(res.position_error[i]),
                           "orientation_error": float(res.orientation_error[i])} for i in range(k)],
            "outside_limits": len(res.outside_limits)}


def _numeric(robot: Any, T: np.ndarray, q0: np.ndarray) -> dict[str, Any]:
    """One solution by :func:`denavit.solve_ik` from ``q0`` (seeded restarts: the same answer each time); an arm
    with fewer than six joints matches the position only (its orientations are a subset)."""
    mask = "pose" if robot.dof >= 6 else "position"
    res = solve_ik(robot, T, q0, mask=mask, rng=np.random.default_rng(0))
    sol = {"q": json_matrix(res.q), "branch": f"numeric from q ({res.iterations} iterations)", "valid": bool(res.success),
           "position_error": float(res.position_error), "orientation_error": float(res.orientation_error)}
    return {"method": "numeric (Levenberg–Marquardt" + (", position only)" if mask == "position" else ")"),
            "controlled": None, "solutions": [sol] if res.success else [], "outside_limits": 0,
            "reason": res.reason, "tolerance": TOL}


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
