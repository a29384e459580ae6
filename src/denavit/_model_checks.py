"""Bounds and checks behind the model's validation (:mod:`denavit.model` re-exports the bounds).

The frozen types of :mod:`denavit.model` call these in ``__post_init__``; each raises
:class:`~denavit.errors.ModelError` naming the value and the reason.
"""

from __future__ import annotations

import math
import re
from typing import Any

import numpy as np

from .errors import ModelError

__all__ = [
    "MAX_MAGNITUDE",
    "MAX_ANGLE",
    "MAX_JOINTS",
    "MAX_POSES",
    "POSE_LIMIT_TOL",
    "INERTIA_TOLERANCE",
    "TRIANGLE_TOLERANCE",
    "finite",
    "check_inertia_tensor",
    "checked_transform",
    "checked_poses",
]

#: Bound on every length [m], mass [kg], inertia [kg m²], friction coefficient and gravity component [m/s²]
#: of a model: far beyond any real arm, and small enough that products in the dynamics (m·L²·q̇², sums over
#: 32 joints) stay many orders of magnitude below float overflow.
MAX_MAGNITUDE = 1e6
#: Bound on every angle [rad] (DH twists and offsets, revolute limits): about 160 turns.  Beyond it an angle
#: is not a meaningful configuration (and float angles lose their precision).
MAX_ANGLE = 1e3
#: Bound on the number of joint variables of one arm (work grows with n² to n⁴ in Jacobians and dynamics).
MAX_JOINTS = 32
#: Tolerance on the inertia checks (negative principal moments, asymmetry), relative to the largest moment.
INERTIA_TOLERANCE = 1e-9
#: Tolerance on the triangle inequality I1 + I2 >= I3 of principal moments, relative to I3.  Published data
#: sets are not always consistent (the PUMA 560 link 3 of Armstrong et al. misses it by 9 %), so only a clear
#: violation is refused.
TRIANGLE_TOLERANCE = 0.1


def finite(value: float, what: str, bound: float | None = None, unit: str = "") -> float:
    """``value`` as a finite float, at most ``bound`` in magnitude (ModelError naming ``what`` otherwise)."""
    try:
        v = float(value)
    except (TypeError, ValueError, OverflowError):
        raise ModelError(f"{what} must be a number, got {value!r:.60}") from None
    if not math.isfinite(v):
        raise ModelError(f"{what} must be finite, got {value!r:.60}")
    if bound is not None and abs(v) > bound:
        raise ModelError(f"{what} = {v:.6g}{unit} is out of range (at most {bound:g}{unit} in magnitude)")
    return v


def check_inertia_tensor(I: Any, mass: float = 1.0, what: str = "inertia") -> None:
    """Refuse a 3×3 inertia tensor that no rigid body has (ModelError naming the reason).

    Checks: symmetric; principal moments non-negative; and, for a body with mass, the triangle
    inequality I1 + I2 >= I3 of the principal moments (within :data:`TRIANGLE_TOLERANCE`).  A massless
    row may carry a rotational inertia alone (a lumped rotor, as on the PUMA 560's first link).
    """
    I = np.asarray(I, dtype=float)  # (3, 3)
    scale = float(np.abs(I).max()) if I.size else 0.0
    if scale == 0.0:
        return
    if np.abs(I - I.T).max() > INERTIA_TOLERANCE * scale:
        raise ModelError(f"{what}: the 3×3 tensor is not symmetric")
    moments = np.linalg.eigvalsh(I)  # ascending
    if moments[0] < -INERTIA_TOLERANCE * scale:
        raise ModelError(f"{what}: a principal moment is negative ({moments[0]:.3g} kg m²); no body has that")
    if mass > 0 and moments[0] + moments[1] < moments[2] * (1 - TRIANGLE_TOLERANCE):
        raise ModelError(
            f"{what}: principal moments {moments[0]:.3g}, {moments[1]:.3g}, {moments[2]:.3g} break the triangle "
            f"inequality I1 + I2 >= I3; no body has that"
        )


def checked_transform(value: Any, what: str) -> tuple[tuple[float, ...], ...]:
    """A 4×4 homogeneous transform (rotation part orthonormal, translation bounded) as nested float tuples."""
    arr = np.asarray(value, dtype=float)
    if arr.shape != (4, 4):
        raise ModelError(f"{what} must be a 4×4 homogeneous transform, got shape {arr.shape}")
    if not np.all(np.isfinite(arr)):
        raise ModelError(f"{what} has non-finite entries")
    R = arr[:3, :3]
    if not np.allclose(R @ R.T, np.eye(3), atol=1e-6) or np.linalg.det(R) < 0:
        raise ModelError(f"{what} rotation part is not a rotation matrix")
    if not np.allclose(arr[3], [0, 0, 0, 1]):
        raise ModelError(f"{what} last row must be [0, 0, 0, 1]")
    if np.abs(arr[:3, 3]).max() > MAX_MAGNITUDE:
        raise ModelError(f"{what} translation is out of range (at most {MAX_MAGNITUDE:g} m in magnitude)")
    return tuple(tuple(float(x) for x in row) for row in arr)


#: Most named poses (``qz``, ``qr``, …) one robot may carry, and how far [rad, m] a pose may sit outside a limit.
MAX_POSES = 64
#: Pose names that would read as a joint variable (``q3``) where a joint vector is expected.
_RESERVED_POSE_NAME = re.compile(r"q\d+")
POSE_LIMIT_TOL = 1e-9


def checked_poses(poses: Any, limits: np.ndarray) -> tuple[tuple[str, tuple[float, ...]], ...]:
    """Named configurations as ((name, q), ...): names unique, len(q) = dof, finite, within the limits."""
    poses = tuple(poses.items()) if isinstance(poses, dict) else tuple(poses)
    if len(poses) > MAX_POSES:
        raise ModelError(f"too many poses ({len(poses)}; at most {MAX_POSES})")
    out: dict[str, tuple[float, ...]] = {}
    for name, q in poses:
        name = str(name)
        if not name.isidentifier() or len(name) > 40 or name in out:
            raise ModelError(f"pose name {name[:40]!r} must be a unique identifier (letters, digits, _)")
        if _RESERVED_POSE_NAME.fullmatch(name) or name in ("pi", "deg", "q"):
            raise ModelError(f"pose name {name!r} is taken: q, qN (joint variables), pi and deg mean "
                             "something else in joint values; choose another name")
        if not isinstance(q, (tuple, list, np.ndarray)):
            raise ModelError(f"pose {name} must be a sequence of joint values")
        q = tuple(finite(v, f"pose {name}") for v in q)
        if len(q) != len(limits):
            raise ModelError(f"pose {name} has {len(q)} values; the arm has {len(limits)} joints")
        for k, (v, (lo, hi)) in enumerate(zip(q, limits)):
            if not lo - POSE_LIMIT_TOL <= v <= hi + POSE_LIMIT_TOL:
                raise ModelError(f"pose {name}: joint {k + 1} = {v:.6g} is outside its limits [{lo:.6g}, {hi:.6g}]")
        out[name] = q
    return tuple(out.items())
