"""Targets of IK claims: the names a person uses for the target pose, the pose error, a reach test from a start,
and joint-wise distances (angles modulo 2π) — shared by the ik_formula and ik_solutions checks.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from .. import numeric as N
from ..errors import ParseError
from ..model import DHRobot, JointType

__all__ = ["MATCH_TOL", "POSE_COLUMNS", "RIGID_TOL", "revolute_mask", "joint_distance", "target_env",
           "controlled_rows", "pose_error", "reaches", "free_joints", "rigid_target", "NumericSolutions",
           "numeric_solutions", "NUMERIC_STARTS"]

MATCH_TOL = 1e-6
POSE_COLUMNS = {"n": 0, "o": 1, "a": 2}
#: A claimed target's rotation R may be off orthonormal by this much (max |RᵀR − I|): entries written with a few
#: decimals (0.707 for √2/2 is 3e-4 off); a matrix further off is no pose, and the claim is unreadable.
RIGID_TOL = 1e-2


def rigid_target(T: np.ndarray) -> np.ndarray:
    """``T`` when it is a rigid transform (finite, bottom row 0 0 0 1, R orthonormal within :data:`RIGID_TOL` and
    det R > 0: a rotation, no reflection); ParseError naming what is wrong otherwise (the claim is unreadable)."""
    if not np.all(np.isfinite(T)):
        raise ParseError("'T' has entries that are not finite; it is not a pose")
    if not np.allclose(T[3], [0.0, 0.0, 0.0, 1.0], rtol=0.0, atol=1e-12):
        raise ParseError("'T' is not a rigid transform: its bottom row is [" + ", ".join(f"{x:.6g}" for x in T[3])
                         + "], expected [0, 0, 0, 1]")
    R = T[:3, :3]
    err = float(np.abs(R.T @ R - np.eye(3)).max())
    if err > RIGID_TOL:
        raise ParseError(f"'T' is not a rigid transform: its rotation part is not orthonormal (max |RᵀR − I| = "
                         f"{err:.3g} > {RIGID_TOL:g})")
    if np.linalg.det(R) < 0:
        raise ParseError("'T' is not a rigid transform: its rotation part is a reflection (det R < 0)")
    return T


def revolute_mask(robot: DHRobot) -> np.ndarray:
    return np.array([t is JointType.REVOLUTE for t in robot.joint_types])


def joint_distance(robot: DHRobot, a, b) -> np.ndarray:
    """Joint-wise distance, angles modulo 2π."""
    d = np.asarray(a, dtype=float) - np.asarray(b, dtype=float)
    return np.abs(np.where(revolute_mask(robot), (d + np.pi) % (2 * np.pi) - np.pi, d))


def target_env(robot: DHRobot, T_world: np.ndarray, pose: str) -> dict[str, float]:
    """The names a person uses for the target pose, with their values."""
    T = T_world if pose == "world" else np.linalg.solve(robot.base_matrix, T_world) @ np.linalg.inv(robot.tool_matrix)
    env = {f"r{i + 1}{j + 1}": T[i, j] for i in range(3) for j in range(3)}
    env.update(px=T[0, 3], py=T[1, 3], pz=T[2, 3], Px=T[0, 3], Py=T[1, 3], Pz=T[2, 3])
    for c, j in POSE_COLUMNS.items():
        env.update({f"{c}{ax}": T[i, j] for i, ax in enumerate("xyz")})
    env["phi"] = float(np.arctan2(T[1, 0], T[0, 0]))
    params = {k for k, _ in robot.parameters}
    env.update({k: T[i, 3] for i, k in enumerate("xyz") if k not in params})
    return {k: v for k, v in env.items() if k not in params}


def controlled_rows(res: Any) -> list[int]:
    kind = getattr(res, "controlled", "pose")
    return {"position": [0, 1, 2], "orientation": [3, 4, 5], "position+heading": [0, 1, 2, 5]}.get(kind, list(range(6)))


def pose_error(robot: DHRobot, q: np.ndarray, T: np.ndarray) -> np.ndarray:
    """(p_t − p, rotation vector of R_t Rᵀ) in world axes, (6,)."""
    F = N.forward_kinematics(robot, q)
    E = T[:3, :3] @ F[:3, :3].T
    w = np.array([E[2, 1] - E[1, 2], E[0, 2] - E[2, 0], E[1, 0] - E[0, 1]]) / 2
    s, c = np.linalg.norm(w), (np.trace(E) - 1) / 2
    ang = np.arctan2(s, c)
    rot = w * (ang / s) if s > 1e-300 else w
    return np.concatenate([T[:3, 3] - F[:3, 3], rot])


def reaches(robot: DHRobot, q0: np.ndarray, T: np.ndarray, fixed: list[int], rows: list[int]) -> np.ndarray | None:
    """Gauss–Newton from q0 on the free joints (``fixed`` held); the solution if it reaches T, else None."""
    q = q0.astype(float).copy()
    free = [k for k in range(robot.dof) if k not in fixed]
    if not free:
        return q if np.max(np.abs(pose_error(robot, q, T)[rows])) < 1e-9 else None
    for _ in range(40):
        e = pose_error(robot, q, T)[rows]
        if np.max(np.abs(e)) < 1e-11:
            return q
        J = N.geometric_jacobian(robot, q)[rows][:, free]
        q[free] += np.linalg.lstsq(J, e, rcond=1e-10)[0]
    return q if np.max(np.abs(pose_error(robot, q, T)[rows])) < 1e-9 else None


def free_joints(text: str) -> set[int]:
    import re

    return {int(m) - 1 for m in re.findall(r"q(\d+)", text or "")}


#: Starts of the Gauss–Newton search for the solutions of an arm without a closed form.
NUMERIC_STARTS = 48


@dataclass(frozen=True)
class NumericSolutions:
    """The IK solutions of a target for an arm of at most 3 joints without a closed form (the 2-joint polar RP arm),
    found by Gauss–Newton on its tip's position from many starts: complete as far as the starts reach.  The fields
    an analytic_ik result has that the IK checks read."""

    solutions: np.ndarray
    outside_limits: np.ndarray
    free: tuple[str, ...]
    branches: tuple[str, ...]
    controlled: str = "position"


def numeric_solutions(robot: DHRobot, T: np.ndarray, known: np.ndarray, starts: np.ndarray) -> NumericSolutions:
    """The distinct configurations (revolute angles in (−π, π]) that put the tip at T's position, from ``known``
    (one that does) and each of ``starts``."""
    rev = revolute_mask(robot)
    found: list[np.ndarray] = []
    for q0 in [np.asarray(known, dtype=float), *starts]:
        q = reaches(robot, q0, T, [], [0, 1, 2])
        if q is None:
            continue
        q = np.where(rev, (q + np.pi) % (2 * np.pi) - np.pi, q)
        if not any(np.all(joint_distance(robot, q, f) < 1e-7) for f in found):
            found.append(q)
    sols = np.array(found).reshape(-1, robot.dof)
    return NumericSolutions(sols, np.zeros((0, robot.dof)), ("",) * len(sols),
                            tuple(f"solution {k} (numeric)" for k in range(1, len(sols) + 1)))
