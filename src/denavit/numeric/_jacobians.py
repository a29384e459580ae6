"""Geometric Jacobians from the frames, batched: shape (..., 6, n), rows (v, ω)."""

from __future__ import annotations

import numpy as np

from ..model import Convention, DHRobot, Frame, JointType
from ._kinematics import link_transforms

__all__ = ["geometric_jacobian", "joint_axes"]


def joint_axes(robot: DHRobot, frames: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Axis direction z and a point o on it for every joint, in world axes, each (..., n, 3).

    Standard DH: joint i moves about/along z_{i-1} through o_{i-1}; modified DH: z_i through o_i.
    """
    shift = 0 if robot.convention is Convention.STANDARD else 1
    idx = [r + shift for r in robot.joint_rows]
    sel = np.take(frames, idx, axis=-3)  # (..., n, 4, 4)
    return sel[..., :3, 2], sel[..., :3, 3]


def geometric_jacobian(robot: DHRobot, q, frame: Frame | str = Frame.BASE) -> np.ndarray:
    """Geometric Jacobian of the end-effector origin, shape (..., 6, n), rows (v, ω).

    Column i is [z_i × (p_e − o_i); z_i] for a revolute joint and [z_i; 0] for a prismatic one
    (Siciliano et al. 2009, eq. 3.30), with z_i, o_i the joint axis and a point on it.

    Parameters
    ----------
    robot : DHRobot
    q : array_like, shape (..., n)
    frame : Frame or {"base", "tool"}
        ``base``: J0, velocities in world/base axes; ``tool``: Je, in end-effector axes.
    """
    frame = Frame(frame)
    frames = link_transforms(robot, q)  # (..., N+1, 4, 4)
    T_e = frames[..., -1, :, :] @ robot.tool_matrix  # (..., 4, 4)
    z, o = joint_axes(robot, frames)  # (..., n, 3)
    p_e = T_e[..., None, :3, 3]  # (..., 1, 3)
    revolute = np.array([t is JointType.REVOLUTE for t in robot.joint_types])
    v = np.where(revolute[:, None], np.cross(z, p_e - o), z)  # (..., n, 3)
    w = np.where(revolute[:, None], z, 0.0)
    J = np.concatenate([np.swapaxes(v, -1, -2), np.swapaxes(w, -1, -2)], axis=-2)  # (..., 6, n)
    if frame is Frame.TOOL:
        Rt = np.swapaxes(T_e[..., :3, :3], -1, -2)
        J = np.concatenate([Rt @ J[..., :3, :], Rt @ J[..., 3:, :]], axis=-2)
    return J
