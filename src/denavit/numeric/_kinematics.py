"""Forward kinematics, batched over leading axes, by the chain's walker (:mod:`denavit.chain`).

A pose is walked as its three rotation columns and its origin, and every DH row is applied as the four
elementary motions it is made of: the same product as 4×4 matrices at about a third of the arithmetic.
One configuration is walked in plain floats (numpy's per-call overhead dominates for one pose), a batch
in the batch-contiguous layout (each column (3, B)).
"""

from __future__ import annotations

import numpy as np

from .._threads import split_call
from .._validate import as_joint_array
from ..chain import FLOATS, Batch, chain_of, pack, walk
from ..model import DHRobot, JointType

__all__ = ["forward_kinematics", "link_transforms", "joint_values_per_row"]


def joint_values_per_row(robot: DHRobot, q: np.ndarray) -> list[tuple[object, object]]:
    """(θ, d) of every row for joint values q (..., n): arrays where a joint acts, floats elsewhere.

    Written out here rather than taken from the chain: the routes that use it (Jacobian by differentiation
    and by propagation) are the independent checks of the chain's walk.
    """
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


def _walk_batch(robot: DHRobot, q: np.ndarray, frames: bool):
    """Walk a batch q (..., n): (poses, batch), poses the column tuples of :class:`denavit.chain.Batch`."""
    batch = q.shape[:-1]
    size = int(np.prod(batch, dtype=int))
    qT = np.ascontiguousarray(q.reshape(size, robot.dof).T)  # (n, B): each joint's values contiguous
    return walk(chain_of(robot), qT, Batch(size), frames=frames), batch


def joint_axes_batch(robot: DHRobot, q: np.ndarray):
    """Joint axes and end-effector pose for a batch, in the batch-contiguous layout.

    Returns ``(z, o, x_e, y_e, z_e, p_e, batch)``: z and o of shape (n, 3, B) (axis direction and a point
    on it, world axes), and the end-effector frame's columns, each (3, B), tool applied.  The frame that
    carries each axis is :attr:`denavit.chain.Chain.axis_frame`.
    """
    q = as_joint_array(q, robot.dof)
    chain = chain_of(robot)
    (axes, last), batch = _walk_batch(robot, q, frames=chain.axis_frame)
    zs = np.stack([pose[2] for pose in axes])  # (n, 3, B)
    os_ = np.stack([pose[3] for pose in axes])
    tool = chain.tool
    cols = last[:3]
    # a rotation column always has a non-zero entry, so each sum is an array
    xe, ye, ze = (sum(tool[k, j] * cols[k] for k in range(3) if tool[k, j] != 0.0) for j in range(3))
    pe = last[3] + sum(tool[k, 3] * cols[k] for k in range(3) if tool[k, 3] != 0.0)
    return zs, os_, xe, ye, ze, pe, batch


def link_transforms(robot: DHRobot, q, *, threads=None) -> np.ndarray:
    """World poses of every DH frame {0} … {N}, shape (..., N+1, 4, 4).

    Index 0 is the base frame {0} (= ``robot.base``), index i the frame of row i (fixed rows
    included); the tool transform is not applied.

    Parameters
    ----------
    robot : DHRobot
    q : array_like, shape (..., n)
        Joint values [rad for revolute, m for prismatic].
    threads : int, optional
        Threads a batch's rows are split over (default every core; small batches run inline; the result is
        the unsplit one bit for bit: :mod:`denavit._threads`).
    """
    qa = as_joint_array(q, robot.dof)
    split = None if qa.ndim == 1 and threads is None else split_call(  # one configuration: inline
        lambda x: link_transforms(robot, x, threads=1), (qa,), threads)
    if split is not None:
        return split
    if qa.ndim == 1:
        return pack(walk(chain_of(robot), qa.tolist(), FLOATS, frames=True), None)
    frames, batch = _walk_batch(robot, qa, frames=True)
    return pack(frames, batch)


def forward_kinematics(robot: DHRobot, q, *, threads=None) -> np.ndarray:
    """End-effector pose in the world frame, ``T_w_e = base @ A_1 ⋯ A_N @ tool``, shape (..., 4, 4).

    Parameters
    ----------
    robot : DHRobot
    q : array_like, shape (..., n)
        Joint values [rad for revolute, m for prismatic]; leading axes are batch axes.
    threads : int, optional
        Threads a batch's rows are split over (default every core; small batches run inline; the result is
        the unsplit one bit for bit: :mod:`denavit._threads`).

    Examples
    --------
    >>> import denavit
    >>> robot = denavit.load_robot("planar2r")
    >>> T = denavit.forward_kinematics(robot, [0.0, 0.0])
    >>> T.shape
    (4, 4)
    """
    qa = as_joint_array(q, robot.dof)
    split = None if qa.ndim == 1 and threads is None else split_call(  # one configuration: inline
        lambda x: forward_kinematics(robot, x, threads=1), (qa,), threads)
    if split is not None:
        return split
    chain = chain_of(robot)
    if qa.ndim == 1:
        T = pack([walk(chain, qa.tolist(), FLOATS)], None)[0]
    else:
        pose, batch = _walk_batch(robot, qa, frames=False)
        T = pack([pose], batch, contiguous=False)[..., 0, :, :]
    if not chain.tool_identity:
        T = T @ chain.tool
    return T
