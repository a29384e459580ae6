"""Statics: joint torques from an end-effector wrench, τ = Jᵀ F, and wrench frame changes.

A wrench is (f, n): force [N] and moment [N m] that the end effector exerts on the environment, with the
end-effector origin as reference point; τ are the joint torques [N m] / forces [N] that produce it in
static equilibrium (Craig 3rd ed. eq. 5.105, Siciliano et al. eq. 3.111). The inward force propagation
(:func:`denavit.numeric.force_propagation`) is the second route to the same τ.
"""

from __future__ import annotations

import numpy as np

from .._validate import as_joint_array
from ..errors import ShapeError
from ..model import DHRobot, Frame
from ._jacobians import geometric_jacobian

__all__ = ["as_wrench", "joint_torques", "joint_torques_from_jacobian", "wrench_tool_from_base",
           "wrench_base_from_tool"]


def as_wrench(wrench) -> np.ndarray:
    """A wrench as a float array (..., 6); a (..., 3) input is a pure force (moment zero)."""
    try:
        F = np.asarray(wrench, dtype=float)
    except (TypeError, ValueError):
        raise ShapeError(f"wrench must be numbers, shape (..., 6) or (..., 3); got {wrench!r:.80}") from None
    if F.ndim == 0 or F.shape[-1] not in (3, 6):
        raise ShapeError(f"wrench: expected shape (..., 6) (f, n) or (..., 3) (force only), got {F.shape}")
    if not np.all(np.isfinite(F)):
        raise ShapeError("wrench has non-finite values (NaN or inf)")
    if F.shape[-1] == 3:
        F = np.concatenate([F, np.zeros_like(F)], axis=-1)
    return F


def joint_torques_from_jacobian(J, wrench) -> np.ndarray:
    """τ = Jᵀ F for a Jacobian (..., 6, n) and a wrench (..., 6) or (..., 3) in the same axes."""
    J = np.asarray(J, dtype=float)
    if J.ndim < 2 or J.shape[-2] != 6:
        raise ShapeError(f"J: expected shape (..., 6, n), got {J.shape}")
    return np.einsum("...ij,...i->...j", J, as_wrench(wrench))


def joint_torques(robot: DHRobot, q, wrench, frame: Frame | str = Frame.BASE) -> np.ndarray:
    """Joint torques τ = Jᵀ F (..., n) balancing an end-effector wrench.

    Parameters
    ----------
    robot : DHRobot
    q : array_like, shape (..., n)
    wrench : array_like, shape (..., 6) or (..., 3)
        (f, n) at the end-effector origin [N, N m], exerted by the end effector on the environment.
    frame : Frame or {"base", "tool"}
        Axes of the wrench: world/base (τ = J0ᵀ F) or end effector (τ = Jeᵀ F).

    Notes
    -----
    Virtual work: δqᵀ τ = δxᵀ F for every δx = J δq (Craig eq. 5.103–5.105).
    """
    q = as_joint_array(q, robot.dof)
    return joint_torques_from_jacobian(geometric_jacobian(robot, q, frame), wrench)


def _rot_wrench(R: np.ndarray, F: np.ndarray) -> np.ndarray:
    return np.concatenate([np.einsum("...ij,...j->...i", R, F[..., :3]),
                           np.einsum("...ij,...j->...i", R, F[..., 3:])], axis=-1)


def wrench_tool_from_base(wrench, R_w_e) -> np.ndarray:
    """The same wrench (same reference point) in end-effector axes: (Rᵀ f, Rᵀ n)."""
    R = np.asarray(R_w_e, dtype=float)[..., :3, :3]
    return _rot_wrench(np.swapaxes(R, -1, -2), as_wrench(wrench))


def wrench_base_from_tool(wrench, R_w_e) -> np.ndarray:
    """The same wrench (same reference point) in world/base axes: (R f, R n)."""
    R = np.asarray(R_w_e, dtype=float)[..., :3, :3]
    return _rot_wrench(R, as_wrench(wrench))
