"""Forward kinematics, batched over leading axes.

The chain is composed column by column: a pose is kept as its three rotation columns and its origin,
each of shape (..., 3), and every DH row is applied as the four elementary motions it is made of
(rotation/translation about z and about x).  That is the same product as multiplying 4×4 matrices but
needs about a third of the arithmetic and no small-matrix matmul, which is what makes large batches fast.
"""

from __future__ import annotations

import numpy as np

from .._validate import as_joint_array
from ..model import Convention, DHRobot, JointType

__all__ = ["forward_kinematics", "link_transforms", "joint_values_per_row"]


def joint_values_per_row(robot: DHRobot, q: np.ndarray) -> list[tuple[object, object]]:
    """(θ, d) of every row for joint values q (..., n): arrays where a joint acts, floats elsewhere."""
    out: list[tuple[object, object]] = []
    k = 0
    for link in robot.links:
        if link.joint is JointType.REVOLUTE:
            out.append((q[..., k] + link.theta, link.d))
            k += 1
        elif link.joint is JointType.PRISMATIC:
            out.append((link.theta, q[..., k] + link.d))
            k += 1
        else:
            out.append((link.theta, link.d))
    return out


def _row_values(robot: DHRobot, cols) -> list[tuple[object, object]]:
    """(θ, d) per row from per-joint values ``cols[k]`` (floats, or contiguous (B,) arrays)."""
    out: list[tuple[object, object]] = []
    k = 0
    for link in robot.links:
        if link.joint is JointType.REVOLUTE:
            out.append((cols[k] + link.theta, link.d))
            k += 1
        elif link.joint is JointType.PRISMATIC:
            out.append((link.theta, cols[k] + link.d))
            k += 1
        else:
            out.append((link.theta, link.d))
    return out


class _Pose:
    """A batch of poses as rotation columns x, y, z and origin p, each (3, B) with B contiguous.

    Composition is on the right (T ← T · motion); c, s, d, a are floats or (B,) arrays.
    """

    __slots__ = ("x", "y", "z", "p")

    def __init__(self, T: np.ndarray, size: int) -> None:
        self.x, self.y, self.z, self.p = (np.repeat(T[:3, j : j + 1], size, axis=1) for j in range(4))

    # In-place updates where possible: at large batches the cost is memory traffic, not arithmetic.
    def rot_z(self, c, s) -> None:
        x, y = self.x, self.y
        nx = c * x
        nx += s * y
        ny = c * y
        ny -= s * x
        self.x, self.y = nx, ny

    def rot_x(self, c, s) -> None:
        y, z = self.y, self.z
        ny = c * y
        ny += s * z
        nz = c * z
        nz -= s * y
        self.y, self.z = ny, nz

    def move_z(self, d) -> None:
        if isinstance(d, np.ndarray) or d != 0.0:
            self.p += d * self.z

    def move_x(self, a) -> None:
        if a != 0.0:
            self.p += a * self.x

    def matrix(self, batch: tuple[int, ...]) -> np.ndarray:
        T = np.zeros((4, 4) + self.p.shape[1:])
        T[:3, 0], T[:3, 1], T[:3, 2], T[:3, 3] = self.x, self.y, self.z, self.p
        T[3, 3] = 1.0
        return np.moveaxis(T, (0, 1), (-2, -1)).reshape(batch + (4, 4))


def _apply_row(pose: _Pose, convention: Convention, theta, d, a: float, alpha: float) -> None:
    ct, st = np.cos(theta), np.sin(theta)
    if convention is Convention.STANDARD:  # Rz(θ) Tz(d) Tx(a) Rx(α)
        pose.rot_z(ct, st)
        pose.move_z(d)
        pose.move_x(a)
        if alpha != 0.0:
            pose.rot_x(np.cos(alpha), np.sin(alpha))
    else:  # Rx(α) Tx(a) Rz(θ) Tz(d)
        if alpha != 0.0:
            pose.rot_x(np.cos(alpha), np.sin(alpha))
        pose.move_x(a)
        pose.rot_z(ct, st)
        pose.move_z(d)


def _run_chain(robot: DHRobot, q, keep_frames: bool):
    q = as_joint_array(q, robot.dof)
    batch = q.shape[:-1]
    size = int(np.prod(batch, dtype=int))
    qT = np.ascontiguousarray(q.reshape(size, robot.dof).T)  # (n, B): each joint's values contiguous
    pose = _Pose(robot.base_matrix, size)
    frames = [pose.matrix(batch)] if keep_frames else []
    for link, (theta, d) in zip(robot.links, _row_values(robot, qT)):
        _apply_row(pose, robot.convention, theta, d, link.a, link.alpha)
        if keep_frames:
            frames.append(pose.matrix(batch))
    return pose, frames, batch


def joint_axes_batch(robot: DHRobot, q: np.ndarray):
    """Joint axes and end-effector pose for a batch, in the batch-contiguous layout.

    Returns ``(z, o, x_e, y_e, z_e, p_e, batch)``: z and o of shape (n, 3, B) (axis direction and a point
    on it, world axes), and the end-effector frame's columns, each (3, B), tool applied.
    Standard DH: joint i acts about z_{i-1}; modified: about z_i.
    """
    q = as_joint_array(q, robot.dof)
    batch = q.shape[:-1]
    size = int(np.prod(batch, dtype=int))
    qT = np.ascontiguousarray(q.reshape(size, robot.dof).T)  # (n, B)
    pose = _Pose(robot.base_matrix, size)
    std = robot.convention is Convention.STANDARD
    zs, os_ = [], []
    for link, (theta, d) in zip(robot.links, _row_values(robot, qT)):
        if std and link.is_joint:
            zs.append(pose.z)
            os_.append(pose.p.copy())
        _apply_row(pose, robot.convention, theta, d, link.a, link.alpha)
        if not std and link.is_joint:
            zs.append(pose.z)
            os_.append(pose.p.copy())
    tool = robot.tool_matrix
    cols = [pose.x, pose.y, pose.z]
    # a rotation column always has a non-zero entry, so each sum is an array
    xe, ye, ze = (sum(tool[k, j] * cols[k] for k in range(3) if tool[k, j] != 0.0) for j in range(3))
    pe = pose.p + sum(tool[k, 3] * cols[k] for k in range(3) if tool[k, 3] != 0.0)
    return np.stack(zs), np.stack(os_), xe, ye, ze, pe, batch


def _single_frames(robot: DHRobot, q: list[float], keep_frames: bool) -> np.ndarray:
    """Unbatched fast path in plain floats (numpy's per-call overhead dominates for one pose).

    Returns the world poses of {0} … {N}, shape (N+1, 4, 4), or only {N}, shape (4, 4).
    """
    from math import cos, sin

    B = robot.base
    x, y, z, p = ([B[0][j], B[1][j], B[2][j]] for j in range(4))
    std = robot.convention is Convention.STANDARD
    rows = [(x, y, z, p)] if keep_frames else []
    for link, (theta, d) in zip(robot.links, _row_values(robot, q)):
        c, s = cos(theta), sin(theta)
        if not std and link.alpha != 0.0:
            ca, sa = cos(link.alpha), sin(link.alpha)
            y, z = [ca * y[i] + sa * z[i] for i in range(3)], [ca * z[i] - sa * y[i] for i in range(3)]
        if not std and link.a != 0.0:
            p = [p[i] + link.a * x[i] for i in range(3)]
        x, y = [c * x[i] + s * y[i] for i in range(3)], [c * y[i] - s * x[i] for i in range(3)]
        if d != 0.0:
            p = [p[i] + d * z[i] for i in range(3)]
        if std:
            if link.a != 0.0:
                p = [p[i] + link.a * x[i] for i in range(3)]
            if link.alpha != 0.0:
                ca, sa = cos(link.alpha), sin(link.alpha)
                y, z = [ca * y[i] + sa * z[i] for i in range(3)], [ca * z[i] - sa * y[i] for i in range(3)]
        if keep_frames:
            rows.append((x, y, z, p))
    if not keep_frames:
        rows = [(x, y, z, p)]
    out = np.zeros((len(rows), 4, 4))
    out[:, :3, :] = np.array(rows).transpose(0, 2, 1)  # (frames, 4 columns, 3) → rows × columns
    out[:, 3, 3] = 1.0
    return out if keep_frames else out[0]


def link_transforms(robot: DHRobot, q) -> np.ndarray:
    """World poses of every DH frame {0} … {N}, shape (..., N+1, 4, 4).

    Index 0 is the base frame {0} (= ``robot.base``), index i the frame of row i (fixed rows
    included); the tool transform is not applied.

    Parameters
    ----------
    robot : DHRobot
    q : array_like, shape (..., n)
        Joint values [rad for revolute, m for prismatic].
    """
    qa = as_joint_array(q, robot.dof)
    if qa.ndim == 1:
        return _single_frames(robot, qa.tolist(), keep_frames=True)
    _, frames, _ = _run_chain(robot, qa, keep_frames=True)
    return np.stack(frames, axis=-3)


def forward_kinematics(robot: DHRobot, q) -> np.ndarray:
    """End-effector pose in the world frame, ``T_w_e = base @ A_1 ⋯ A_N @ tool``, shape (..., 4, 4).

    Parameters
    ----------
    robot : DHRobot
    q : array_like, shape (..., n)
        Joint values [rad for revolute, m for prismatic]; leading axes are batch axes.

    Examples
    --------
    >>> import denavit
    >>> robot = denavit.load_robot("planar2r")
    >>> T = denavit.forward_kinematics(robot, [0.0, 0.0])
    >>> T.shape
    (4, 4)
    """
    qa = as_joint_array(q, robot.dof)
    if qa.ndim == 1:
        T = _single_frames(robot, qa.tolist(), keep_frames=False)
    else:
        pose, _, batch = _run_chain(robot, qa, keep_frames=False)
        T = pose.matrix(batch)
    tool = robot.tool_matrix
    if not np.array_equal(tool, np.eye(4)):
        T = T @ tool
    return T
