"""Small pieces the analytic IK is built from: joint motions as matrices, angle wrapping, Paden–Kahan
subproblems in scalar form, and a damped solve that never raises.

The solvers work on the arm as ``T_w_e = C0 J1(q1) C1 J2(q2) ⋯ Jn(qn) Cn`` (constant ``C_k``, J_k = Rz(q) or
Tz(q)): :class:`denavit.chain.Screws`, walked by :func:`denavit.chain.screw_walk` (the one place that splits DH
rows of either convention into constants and joint motions is :mod:`denavit.chain`), so they treat both
conventions, offsets and fixed rows alike (no per-convention derivation to get wrong).  The subproblems are
those of Paden (1986) and Kahan, as collected in Murray, Li & Sastry (1994), Sec. 3.3.
"""

from __future__ import annotations

import numpy as np

from ._forms import trig_roots

__all__ = ["damped_solve", "joint_motion", "solve_trig", "angle_about_z", "wrap_angle"]


def joint_motion(prismatic: bool, q: np.ndarray) -> np.ndarray:
    """Rz(q) or Tz(q), shape q.shape + (4, 4)."""
    q = np.asarray(q, dtype=float)
    J = np.zeros(q.shape + (4, 4))
    J[..., 3, 3] = 1.0
    J[..., 2, 2] = 1.0
    if prismatic:
        J[..., 0, 0] = J[..., 1, 1] = 1.0
        J[..., 2, 3] = q
    else:
        c, s = np.cos(q), np.sin(q)
        J[..., 0, 0], J[..., 0, 1], J[..., 1, 0], J[..., 1, 1] = c, -s, s, c
    return J


def wrap_angle(x: np.ndarray) -> np.ndarray:
    """Angles wrapped into (−π, π]."""
    return np.pi - np.mod(np.pi - np.asarray(x, dtype=float), 2 * np.pi)


def solve_trig(a, b, c, tol: float = 1e-9) -> np.ndarray:
    """All θ with ``a cos θ + b sin θ = c`` (Paden–Kahan subproblem 1 in scalar form), shape (..., 2).

    θ = atan2(b, a) ± arccos(c / √(a² + b²)); NaN where there is no solution (|c| > ρ) or the equation does
    not depend on θ (ρ ≈ 0).  A ratio within ``tol`` beyond ±1 is taken as the tangent (double) root.
    """
    a, b, c = np.broadcast_arrays(*(np.asarray(x, dtype=float) for x in (a, b, c)))
    plus, minus, _, _ = trig_roots(a, b, c, tol)  # the one copy of the formula (numba compiles it too)
    return np.stack([plus, minus], axis=-1)


def angle_about_z(u: np.ndarray, v: np.ndarray) -> np.ndarray:
    """θ with Rz(θ) u ≈ v in the xy-plane (Paden–Kahan subproblem 2 about z), shape (...)."""
    return np.arctan2(v[..., 1], v[..., 0]) - np.arctan2(u[..., 1], u[..., 0])


def damped_solve(A: np.ndarray, b: np.ndarray) -> np.ndarray:
    """``np.linalg.solve(A, b)`` for a batch of damped normal matrices A = JᵀJ + λI (..., n, n), b (..., n, k).

    The damping can vanish against JᵀJ (a target 1e6 m away makes JᵀJ ~1e12 and λ lost to rounding on an arm
    whose J lacks rank): such an A is exactly singular in floating point and LAPACK raises; those systems get
    the least-squares step of their pseudo-inverse instead (no bare LinAlgError from the IK functions)."""
    try:
        return np.linalg.solve(A, b)
    except np.linalg.LinAlgError:
        return np.linalg.pinv(np.nan_to_num(A, nan=0.0, posinf=0.0, neginf=0.0)) @ b
