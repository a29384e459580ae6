"""What every IK solver shares, below all of them: the result type, the pose residual and rotation log, row masks,
joint limits and the arm's length scale.  Nothing here imports another IK module, so the solvers never import
in circles.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Sequence

import numpy as np

from ..chain import chain_of
from ..errors import ShapeError
from ..model import DHRobot, JointType, sampling_ranges
from ..numeric import rotation_log

__all__ = ["IKResult", "AnalyticIKResult", "row_mask", "rotation_log", "pose_error", "JointLimits", "characteristic_length", "limits_of",
           "LAMBDA0", "LAMBDA_MAX"]

LAMBDA0 = 1e-3  # initial damping, relative to the squared characteristic length
LAMBDA_MAX = 1e3  # damping (relative to L²) beyond which an attempt counts as stuck


@dataclass(frozen=True)
class IKResult:
    """Result of :func:`solve_ik` (arrays with the batch shape of the targets; scalars for one target).

    Attributes
    ----------
    q : ndarray, shape (..., n)
        Joint values [rad, m]: the solution, or the best point found when ``success`` is False.
    success : bool or ndarray of bool, shape (...)
        True when ``forward_kinematics(robot, q)`` matches the target within ``tol`` on the selected rows
        and q is within the joint limits (decided by re-running FK, not by the iteration).
    position_error, orientation_error : float or ndarray, shape (...)
        Norm of the selected rows of the residual: position [m] and rotation vector log(R_t Rᵀ) [rad],
        both in world axes.
    iterations : int or ndarray, shape (...)
        LM iterations spent, all restarts included.
    restarts : int or ndarray, shape (...)
        Random restarts used.
    reason : str or ndarray of str, shape (...)
        ``""`` on success; otherwise ``"unreachable"`` (no solution found even ignoring limits: the target
        is probably outside the workspace), ``"limits"`` (a solution exists only outside the joint limits)
        or ``"iterations"`` (the iteration budget ran out while still improving).
    """

    q: np.ndarray
    success: Any
    position_error: Any
    orientation_error: Any
    iterations: Any
    restarts: Any
    reason: Any

    def _repr_html_(self) -> str:
        from ..display import ik_html

        return ik_html(self)


@dataclass(frozen=True)
class AnalyticIKResult:
    """All closed-form IK solutions of one target pose (or of a batch of poses).

    Attributes
    ----------
    solutions : ndarray, shape (k, n) — or (..., K, n) for a batch, NaN rows where ``valid`` is False
        Joint values [rad, m], each verified by the forward kinematics, within the joint limits.
    branches : tuple of str (k,) — or ndarray of str (..., K)
        Branch labels such as ``"shoulder right, elbow up, wrist noflip"`` (definitions in docs/ik.md).
    free : tuple of str (k,) — or ndarray of str (..., K)
        ``""`` for an isolated solution; otherwise the joint combination that stays free along a continuum
        of solutions (coaxial joints, wrist singularity), of which the row is one representative.
    position_error, orientation_error : ndarray (k,) or (..., K)
        FK residual of each solution on the rows the arm controls [m], [rad].
    outside_limits : ndarray, shape (j, n) — or int count per pose for a batch
        Solutions that were found but lie outside the joint limits.
    method : str
        The structure recognised (``pieper``, ``parallel``, ``planar``, ``wrist``, ``position`` …).
    controlled : str
        Which rows of the pose the arm controls (``pose``, ``position``, ``orientation``, ``position+heading``).
    valid : ndarray of bool, shape (..., K) — batch only (all True for one pose)
    """

    solutions: np.ndarray
    branches: Any
    free: Any
    position_error: np.ndarray
    orientation_error: np.ndarray
    outside_limits: Any
    method: str
    controlled: str
    valid: np.ndarray

    def _repr_html_(self) -> str:
        from ..display import ik_html

        return ik_html(self)

    @property
    def count(self):
        """Number of solutions (per pose for a batch)."""
        return self.valid.sum(axis=-1) if self.valid.ndim > 1 else int(self.valid.sum())

    @property
    def continuum(self):
        """True where a solution stands for a continuum (``free`` is not empty)."""
        return np.asarray(self.free, dtype=object) != ""


def row_mask(mask: str | Sequence[bool] | None, dof: int | None = None) -> np.ndarray:
    """Which pose rows (x, y, z, ωx, ωy, ωz) to match: ``"pose"``, ``"position"``, or 6 booleans."""
    if mask is None or (isinstance(mask, str) and mask == "pose"):
        return np.ones(6, dtype=bool)
    if isinstance(mask, str):
        if mask == "position":
            return np.array([True] * 3 + [False] * 3)
        raise ValueError(f"unknown mask {mask!r}; choose 'pose', 'position' or 6 booleans (x, y, z, wx, wy, wz)")
    m = np.asarray(mask, dtype=bool).reshape(-1)
    if m.shape != (6,) or not m.any():
        raise ShapeError(f"mask: expected 6 booleans (x, y, z, wx, wy, wz) with at least one True, got {mask!r}")
    return m


def pose_error(T_target: np.ndarray, T: np.ndarray) -> np.ndarray:
    """Residual (..., 6) = (p_t − p, log(R_t Rᵀ)) in world axes."""
    dp = T_target[..., :3, 3] - T[..., :3, 3]
    dw = rotation_log(T_target[..., :3, :3] @ np.swapaxes(T[..., :3, :3], -1, -2))
    return np.concatenate([dp, dw], axis=-1)


def characteristic_length(robot: DHRobot) -> float:
    """A length scale of the arm [m]: sum of |a| and |d| over the rows and the tool offset (≥ 1 mm)."""
    memo = chain_of(robot).memo
    if "ik_length" not in memo:
        s = sum(abs(l.a) + abs(l.d) for l in robot.links) + float(np.linalg.norm(robot.tool_matrix[:3, 3]))
        memo["ik_length"] = max(s, 1e-3)
    return memo["ik_length"]


class JointLimits:
    """Joint limits as arrays, with the rule that brings q back inside (clip; wrap a full-turn revolute)."""

    def __init__(self, robot: DHRobot, ignore: bool = False) -> None:
        lim = robot.q_limits
        self.revolute = np.array([t is JointType.REVOLUTE for t in robot.joint_types])
        if ignore:
            lim = np.tile([-np.inf, np.inf], (robot.dof, 1))
        self.lo, self.hi = lim[:, 0], lim[:, 1]
        self.full_turn = self.revolute & (self.hi - self.lo >= 2 * np.pi)

    def project(self, q: np.ndarray) -> np.ndarray:
        q = np.where(self.revolute, np.pi - np.mod(np.pi - q, 2 * np.pi), q)  # wrap into (−π, π]
        shift = np.where(q < self.lo, 2 * np.pi, np.where(q > self.hi, -2 * np.pi, 0.0))
        q = np.where(self.revolute & (shift != 0) & (q + shift >= self.lo) & (q + shift <= self.hi), q + shift, q)
        return np.clip(q, self.lo, self.hi)

    def inside(self, q: np.ndarray, tol: float = 1e-12) -> np.ndarray:
        return np.all((q >= self.lo - tol) & (q <= self.hi + tol), axis=-1)

    def sample_bounds(self, scale: float) -> tuple[np.ndarray, np.ndarray]:
        """Where random restarts are drawn: :func:`denavit.model.sampling_ranges` of these limits (±π revolute,
        ±scale prismatic where infinite)."""
        lo, hi = sampling_ranges(np.column_stack([self.lo, self.hi]), self.revolute, scale).T.copy()  # contiguous
        return lo, hi

    def sample(self, rng: np.random.Generator, shape: tuple[int, ...], scale: float) -> np.ndarray:
        lo, hi = self.sample_bounds(scale)
        return rng.uniform(lo, hi, size=shape + (len(lo),))




def limits_of(robot: DHRobot, ignore: bool) -> JointLimits:
    memo = chain_of(robot).memo  # by identity: no hashing of the robot per call
    key = ("ik_limits", ignore)
    if key not in memo:
        memo[key] = JointLimits(robot, ignore)  # read-only after construction: shared between calls
    return memo[key]
