"""Cartesian straight lines between two poses: position linear, orientation along the SO(3) geodesic (slerp)."""

from __future__ import annotations

import numpy as np

from .._validate import as_transform
from ..errors import ModelError
from ..numeric import rotation_log

__all__ = ["cartesian_line", "interpolate_pose"]


def _exp_so3(w: np.ndarray) -> np.ndarray:
    """Rotation matrix of rotation vectors (..., 3) by Rodrigues' formula (Murray, Li, Sastry 1994, (2.14))."""
    n = np.linalg.norm(w, axis=-1)[..., None]  # (..., 1)
    k = w / np.where(n > 1e-300, n, 1.0)  # unit axis (0 for no rotation)
    th = n[..., None]  # (..., 1, 1)
    K = np.zeros(w.shape[:-1] + (3, 3))
    K[..., 0, 1], K[..., 0, 2], K[..., 1, 2] = -k[..., 2], k[..., 1], -k[..., 0]
    K = K - np.swapaxes(K, -1, -2)
    return np.eye(3) + np.sin(th) * K + (1 - np.cos(th)) * (K @ K)


def interpolate_pose(Ta: np.ndarray, Tb: np.ndarray, s: np.ndarray) -> np.ndarray:
    """Poses (len(s), 4, 4) between Ta (s = 0) and Tb (s = 1): position linear, R = exp(s·log(Rb Raᵀ)) Ra
    (the geodesic of SO(3), i.e. slerp)."""
    s = np.asarray(s, dtype=float)
    w = rotation_log(Tb[:3, :3] @ Ta[:3, :3].T)
    T = np.zeros(s.shape + (4, 4))
    T[..., :3, :3] = _exp_so3(s[..., None] * w) @ Ta[:3, :3]
    T[..., :3, 3] = Ta[:3, 3] + s[..., None] * (Tb[:3, 3] - Ta[:3, 3])
    T[..., 3, 3] = 1.0
    return T


def cartesian_line(T_start, T_end, step: float = 0.01, angle_step: float = 0.05) -> np.ndarray:
    """Poses along the Cartesian straight line from ``T_start`` to ``T_end``, shape (m, 4, 4), both ends included.

    The position moves linearly, the orientation along the geodesic R(s) = exp(s·log(R_e R_sᵀ)) R_s (slerp);
    m − 1 = max(⌈|Δp|/step⌉, ⌈θ/angle_step⌉, 1) equal steps in s.

    Parameters
    ----------
    T_start, T_end : array_like, shape (4, 4)
    step : float
        Largest position step [m].
    angle_step : float
        Largest rotation step [rad].
    """
    Ta, Tb = as_transform(T_start, "T_start"), as_transform(T_end, "T_end")
    if Ta.shape != (4, 4) or Tb.shape != (4, 4):
        raise ModelError("cartesian_line: T_start and T_end must be single 4x4 poses")
    if not (np.isfinite(step) and step > 0 and np.isfinite(angle_step) and angle_step > 0):
        raise ModelError(f"cartesian_line: step and angle_step must be finite and > 0, got {step!r}, {angle_step!r}")
    dist = float(np.linalg.norm(Tb[:3, 3] - Ta[:3, 3]))
    theta = float(np.linalg.norm(rotation_log(Tb[:3, :3] @ Ta[:3, :3].T)))
    segments = max(int(np.ceil(dist / step)), int(np.ceil(theta / angle_step)), 1)
    if segments > 1_000_000:
        raise ModelError(f"cartesian_line: {segments} steps; use a larger step")
    return interpolate_pose(Ta, Tb, np.linspace(0.0, 1.0, segments + 1))
