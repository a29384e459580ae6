"""The inner loop of the IK solvers: pose residual and geometric Jacobian in one pass over the chain.

The chain is the joint-screw form ``C0 J1(q1) C1 ⋯ Jn(qn) Cn`` of :mod:`denavit.chain`, walked by its
:func:`~denavit.chain.screw_walk`.  A batch of poses is kept as rotation columns x, y, z and origin p, each of shape (3, B) with the batch
contiguous, so a joint rotation is two axpy's (``x ← c x + s y``, ``y ← c y − s x``) and a constant ``C_k`` is
a handful of them (most DH constants are signed permutations: α = ±90°).  The Jacobian needs only the joint axes z_k and
their origins o_k, which this same pass visits, and the end-effector origin p_e at the end:

    revolute k:  J_k = (z_k × (p_e − o_k), z_k),      prismatic k:  J_k = (z_k, 0)

(Spong, Hutchinson & Vidyasagar 2006, eq. 4.52-4.53), so no second forward-kinematics pass is needed.
The final success test of the solvers still uses :func:`forward_kinematics`, an independent computation.
"""

from __future__ import annotations

import numpy as np

from ..chain import chain_of, screw_walk, screws_of
from ..model import DHRobot
from ._residual import rotation_log

__all__ = ["Kernel", "kernel_of", "targets_soa"]


class Kernel:
    """Pose residual and Jacobian of one arm, batched; build with :func:`kernel_of` (cached per robot)."""

    def __init__(self, robot: DHRobot) -> None:
        self.screws = screws_of(robot)
        self.n = self.screws.n
        self.prismatic = self.screws.prismatic

    def residual(self, q: np.ndarray, Rt: np.ndarray, pt: np.ndarray, w: np.ndarray, jacobian: bool = True):
        """Weighted residual ``e = W (p_t − p, log(R_t Rᵀ))`` (B, 6) and weighted J0 (B, 6, n).

        q (B, n); Rt (3, 3, B) and pt (3, B) the targets in the layout of :func:`targets_soa`.
        """
        walked = screw_walk(self.screws, q, axes=jacobian)  # columns (3, B), and the axes for J
        x, y, z, p = walked[:4]
        e = np.empty((q.shape[0], 6))
        e[:, :3] = (pt - p).T
        Re = np.stack([x, y, z], axis=1)  # (3, 3, B): Re[i, j] = R[i, j]
        e[:, 3:] = _log_soa(np.einsum("ijb,kjb->ikb", Rt, Re))
        e *= w
        if not jacobian:
            return e, None
        zs, os = walked[4:]
        J = np.zeros((q.shape[0], 6, self.n))
        for k in range(self.n):
            if self.prismatic[k]:
                J[:, :3, k] = zs[k].T
            else:
                zk, r = zs[k], p - os[k]
                J[:, 0, k] = zk[1] * r[2] - zk[2] * r[1]
                J[:, 1, k] = zk[2] * r[0] - zk[0] * r[2]
                J[:, 2, k] = zk[0] * r[1] - zk[1] * r[0]
                J[:, 3:, k] = zk.T
        J *= w[:, None]
        return e, J


def _log_soa(M: np.ndarray) -> np.ndarray:
    """Rotation vectors (B, 3) of rotations M (3, 3, B); see ``rotation_log`` (the near-π case is delegated)."""
    cos = np.clip((M[0, 0] + M[1, 1] + M[2, 2] - 1.0) / 2.0, -1.0, 1.0)
    theta = np.arccos(cos)
    v = np.stack([M[2, 1] - M[1, 2], M[0, 2] - M[2, 0], M[1, 0] - M[0, 1]], axis=-1)  # (B, 3)
    sin = np.sin(theta)
    with np.errstate(invalid="ignore", divide="ignore"):
        factor = np.where(theta < 1e-6, 0.5 + theta**2 / 12.0, theta / (2.0 * np.where(sin == 0, 1, sin)))
    out = v * factor[:, None]
    near_pi = cos < -0.9
    if near_pi.any():
        out[near_pi] = rotation_log(np.moveaxis(M[:, :, near_pi], -1, 0))
    return out


def targets_soa(T: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Targets (B, 4, 4) → rotations (3, 3, B) and positions (3, B), batch contiguous."""
    return np.ascontiguousarray(np.moveaxis(T[:, :3, :3], 0, -1)), np.ascontiguousarray(T[:, :3, 3].T)


def kernel_of(robot: DHRobot) -> Kernel:
    """The kernel of a robot (a pure function of the robot, kept with its chain: found without hashing it)."""
    memo = chain_of(robot).memo
    kern = memo.get("ik_kernel")
    if kern is None:
        kern = memo["ik_kernel"] = Kernel(robot)
    return kern
