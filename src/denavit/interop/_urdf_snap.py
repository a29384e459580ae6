"""Rounding noise of a URDF's numbers taken out of the DH model it gives (issue 31).

URDF files write π/2 rounded (``1.57079632679``: 4.9e-12 short), so an extracted offset came out
``q2 - 4.89657e-12`` and the tool ``rpy = (4.89659e-12, 0, 0)``, noise a reader takes for a real offset.  An angle
within :data:`ANGLE_SNAP` of a multiple of π/2 is taken as that multiple, and a rotation within ANGLE_SNAP
(entrywise) of a signed permutation (the frames of a URDF are usually turned by multiples of 90°) as it, so the
printed table and the written file say the same (``q2``, ``pi/2``).  The FK self-check of the import compares the
snapped model with the URDF chain, so the change stays visible there (at most ~1e-9 per snapped angle).
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["ANGLE_SNAP", "snap_angle", "snap_pose"]

#: Angles and rotation entries closer than this to a multiple of π/2 (to 0 or ±1) are taken as it [rad].
ANGLE_SNAP = 1e-9


def snap_angle(x: float) -> float:
    """``k π/2`` when ``|x − k π/2| < ANGLE_SNAP`` for an integer k, else ``x``."""
    k = round(float(x) / (math.pi / 2))
    exact = {0: 0.0, 1: math.pi / 2, -1: -math.pi / 2, 2: math.pi, -2: -math.pi}.get(k, k * (math.pi / 2))
    return exact if abs(float(x) - exact) < ANGLE_SNAP else float(x)


def snap_pose(T) -> np.ndarray:
    """The 4×4 pose ``T`` with its rotation replaced by the nearest signed permutation matrix when every entry is
    within ANGLE_SNAP of it (and that matrix is a rotation), and translations within ANGLE_SNAP of 0 set to 0."""
    T = np.array(T, dtype=float)
    R = np.round(T[:3, :3])
    if np.max(np.abs(T[:3, :3] - R)) < ANGLE_SNAP and np.allclose(R @ R.T, np.eye(3)) and np.linalg.det(R) > 0:
        T[:3, :3] = R + 0.0  # + 0.0: no -0.0 entries
    T[:3, 3] = np.where(np.abs(T[:3, 3]) < ANGLE_SNAP, 0.0, T[:3, 3])
    return T
