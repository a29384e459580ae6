"""The data handed to the plotting layer: where every joint, link segment and frame of an arm is.

A pure function of ``(robot, q)`` built on :func:`denavit.link_transforms`; the drawing code
(matplotlib, the HTML viewer) only turns these arrays into pixels, so tests check the arrays.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .._validate import as_joint_array
from ..chain import chain_of
from ..model import Convention, DHRobot, JointType
from ..numeric import link_transforms

__all__ = ["ArmGeometry", "arm_geometry", "robot_scale", "default_configuration"]


@dataclass(frozen=True)
class ArmGeometry:
    """Positions of an arm's parts in the world frame, batched over leading axes.

    Attributes
    ----------
    frames : ndarray, shape (..., N+1, 4, 4)
        World poses of the DH frames {0} … {N} (fixed rows included).
    end_effector : ndarray, shape (..., 4, 4)
        T_w_e = base · A_1 ⋯ A_N · tool.
    skeleton : ndarray, shape (..., 2N+2, 3)
        The link centre line as one polyline: o_0, k_1, o_1, …, k_N, o_N, o_e, where k_i is the
        knee of row i: standard DH goes from o_{i-1} along z_{i-1} by d_i to k_i, then along x_i by
        a_i to o_i; modified DH goes from o_{i-1} along x_{i-1} by a_{i-1} to k_i, then along z_i
        by d_i to o_i.
    joint_frames : ndarray, shape (..., n, 4, 4)
        For each joint the DH frame whose z axis is its axis ({i-1} standard, {i} modified).
    joint_types : tuple of JointType
    triad_origins : ndarray, shape (..., F, 3)
    triad_axes : ndarray, shape (..., F, 3, 3)
        Unit x, y, z axes (rows) of every frame drawn as a triad, in world coordinates.
    triad_labels : tuple of str
        ``"w"`` (world, only when the base is not the identity), ``"0"`` … ``"N"``, and ``"e"``
        (end effector, only when the tool is not the identity).
    scale : float
        A characteristic length of the arm [m] (q-independent) for sizing glyphs.
    """

    frames: np.ndarray
    end_effector: np.ndarray
    skeleton: np.ndarray
    joint_frames: np.ndarray
    joint_types: tuple[JointType, ...]
    triad_origins: np.ndarray
    triad_axes: np.ndarray
    triad_labels: tuple[str, ...]
    scale: float

    @property
    def joint_positions(self) -> np.ndarray:
        """A point on each joint axis (the origin of its joint frame), shape (..., n, 3)."""
        return self.joint_frames[..., :3, 3]

    @property
    def joint_axes(self) -> np.ndarray:
        """Unit direction of each joint axis, shape (..., n, 3)."""
        return self.joint_frames[..., :3, 2]


def robot_scale(robot: DHRobot) -> float:
    """A characteristic length of the arm [m]: Σ|a| + Σ|d| + prismatic strokes + tool offset.

    Independent of q, so glyph sizes stay fixed during an animation; 1.0 for a degenerate table.
    """
    total = sum(abs(link.a) + abs(link.d) for link in robot.links)
    for link in robot.joints:
        if link.joint is JointType.PRISMATIC and link.q_limits is not None:
            total += max(abs(v) for v in link.q_limits)
    total += float(np.linalg.norm(robot.tool_matrix[:3, 3]))
    return total if total > 1e-9 else 1.0


def default_configuration(robot: DHRobot) -> np.ndarray:
    """The home pose used when no q is given: zero, moved into the joint limits where needed."""
    lim = robot.q_limits
    return np.clip(np.zeros(robot.dof), lim[:, 0], lim[:, 1])


def _knees(robot: DHRobot, frames: np.ndarray) -> np.ndarray:
    """Knee point of every row (see ArmGeometry.skeleton), shape (..., N, 3)."""
    o = frames[..., :3, 3]  # (..., N+1, 3)
    if robot.convention is Convention.STANDARD:
        # o_i = k_i + a_i x_i
        a = np.array([link.a for link in robot.links])[:, None]
        return o[..., 1:, :] - a * frames[..., 1:, :3, 0]
    # modified: k_i = o_{i-1} + a_{i-1} x_{i-1}
    a = np.array([link.a for link in robot.links])[:, None]
    return o[..., :-1, :] + a * frames[..., :-1, :3, 0]


def arm_geometry(robot: DHRobot, q) -> ArmGeometry:
    """Everything needed to draw the arm at joint values q.

    Parameters
    ----------
    robot : DHRobot
    q : array_like, shape (..., n)
        Joint values [rad for revolute, m for prismatic].

    Returns
    -------
    ArmGeometry
    """
    q = as_joint_array(q, robot.dof)
    frames = link_transforms(robot, q)  # (..., N+1, 4, 4)
    tool = robot.tool_matrix
    T_e = frames[..., -1, :, :] @ tool  # (..., 4, 4)
    o = frames[..., :3, 3]  # (..., N+1, 3)
    knees = _knees(robot, frames)  # (..., N, 3)
    batch = q.shape[:-1]
    n_rows = robot.n_rows
    skel = np.empty(batch + (2 * n_rows + 2, 3))
    skel[..., 0, :] = o[..., 0, :]
    skel[..., 1:-1:2, :] = knees
    skel[..., 2:-1:2, :] = o[..., 1:, :]
    skel[..., -1, :] = T_e[..., :3, 3]
    joint_frames = np.take(frames, chain_of(robot).axis_frame, axis=-3)  # (..., n, 4, 4)
    triads = [frames]
    labels = [str(i) for i in range(n_rows + 1)]
    if not np.allclose(robot.base_matrix, np.eye(4)):
        triads.insert(0, np.broadcast_to(np.eye(4), batch + (1, 4, 4)))
        labels.insert(0, "w")
    if not np.allclose(tool, np.eye(4)):
        triads.append(T_e[..., None, :, :])
        labels.append("e")
    T_tr = np.concatenate(triads, axis=-3)  # (..., F, 4, 4)
    return ArmGeometry(
        frames=frames,
        end_effector=T_e,
        skeleton=skel,
        joint_frames=joint_frames,
        joint_types=robot.joint_types,
        triad_origins=T_tr[..., :3, 3],
        triad_axes=np.swapaxes(T_tr[..., :3, :3], -1, -2),  # rows = axes
        triad_labels=tuple(labels),
        scale=robot_scale(robot),
    )
