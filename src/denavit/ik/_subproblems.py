"""Subproblems of the analytic IK, batched: three-axis orientation, planar pairs, an axis turning a vector.

All work on the joint-screw form ``C0 J1 C1 ⋯`` of :mod:`._chain` and return NaN for "no solution"
so that every pose of a batch carries the same number of candidate slots.
"""

from __future__ import annotations

import numpy as np

from ._chain import angle_about_z
from ._forms import ALIGNED_EXACT, AXES_ALIGNED_TOL, WRIST_TOL, wrist_constants, wrist_qb

__all__ = ["rotation3", "trig_coefficients", "rz_bilinear", "axis_angle_roots", "axis_angle_pairs", "split_aligned",
           "AXES_ALIGNED_TOL", "ALIGNED_EXACT"]

# ALIGNED_EXACT: below this angle [rad] the representative of the continuum is taken with qa = 0; AXES_ALIGNED_TOL:
# angle [rad] between the two outer axes of a three-axis wrist (or between axis 6 and the parallel axes of a UR-type
# arm) under which a solution is reported as the continuum of the aligned axes (both kept in ._forms)


def axis_angle_roots(r: np.ndarray, u: np.ndarray, m: np.ndarray, tol: float = WRIST_TOL) -> np.ndarray:
    """All θ with ``rᵀ Rz(θ) u = m_z`` for unit vectors r, u (3,) and unit m (..., 3), shape (..., 2).

    The same roots as ``solve_trig`` on ``a cos θ + b sin θ = m_z − r_z u_z`` (θ = base ± x), but x is computed
    from the angle φ = ∠(m, e_z), taken from all of m with atan2, instead of from arccos(m_z): next to the double
    root (the aligned axes of a wrist singularity, φ ≈ |β_r − β_u|) arccos loses half the digits (x = 1e-8
    comes out as ±1.5e-8), this keeps them.  With β_r, β_u the angles of r and u to the z axis,
    ``(1 − cos x)/2 = sin((φ + Δ)/2) sin((φ − Δ)/2) / (sin β_r sin β_u)``, Δ = β_r − β_u, and
    ``(1 + cos x)/2`` likewise with Σ = β_r + β_u; the smaller one gives x.  NaN where there is no root.
    """
    return axis_angle_pairs(r, u, m, tol)[0]


def axis_angle_pairs(r: np.ndarray, u: np.ndarray, m: np.ndarray, tol: float = WRIST_TOL):
    """:func:`axis_angle_roots` (..., 2) with the cosines and sines of the roots (..., 2) each, by the same formulas
    (``forms.wrist_qb``: no cos or sin of the roots)."""
    a, b, _ = rz_bilinear(r, u)
    rho, base = float(np.hypot(a, b)), float(np.arctan2(b, a))
    br, bu = np.arctan2(np.hypot(r[0], r[1]), r[2]), np.arctan2(np.hypot(u[0], u[1]), u[2])
    wc = wrist_constants(rho, base, br, bu)
    plus, minus, _, _, cp, sp, cm, sm = wrist_qb(m[..., 0], m[..., 1], m[..., 2], wc, tol)  # the one copy (numba too)
    return np.stack([plus, minus], axis=-1), np.stack([cp, cm], axis=-1), np.stack([sp, sm], axis=-1)


def rz_bilinear(m: np.ndarray, p: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(α, β, γ) with mᵀ Rz(θ) p = α cos θ + β sin θ + γ, for vectors (..., 3)."""
    a = m[..., 0] * p[..., 0] + m[..., 1] * p[..., 1]
    b = m[..., 1] * p[..., 0] - m[..., 0] * p[..., 1]
    return a, b, m[..., 2] * p[..., 2]


def trig_coefficients(G0, G90, G180):
    """(A, B, C) of G(θ) = A cos θ + B sin θ + C from its values at θ = 0, π/2, π."""
    C = 0.5 * (G0 + G180)
    return 0.5 * (G0 - G180), G90 - C, C


def rotation3(M: np.ndarray, Ra: np.ndarray, Rb: np.ndarray):
    """All (qa, qb, qc) with Rz(qa) Ra Rz(qb) Rb Rz(qc) = M: three revolute axes through one point.

    The z-row of the equation does not involve qa or qc: (Raᵀ e_z)ᵀ Rz(qb) (Rb e_z) = M_zz, an equation
    a cos qb + b sin qb = c with two roots (the wrist flip); then qa aligns Ra Rz(qb) Rb e_z with M e_z and
    qc is read from (Rz(qa) Ra Rz(qb) Rb)ᵀ M (Paden–Kahan subproblems 2 and 1; Murray, Li & Sastry 1994,
    Sec. 3.3; for the orthogonal ZYZ wrist this is Craig 3rd ed. eq. 2.71 / Spong eq. 2.28).

    Parameters
    ----------
    M : (..., 3, 3)
    Ra, Rb : (3, 3) constant rotations between the joints.

    Returns
    -------
    q : (..., 2, 3) with NaN rows where there is no solution
    singular : (..., 2) bool — axes a and c aligned within AXES_ALIGNED_TOL: only qa ± qc is determined (a
        continuum).  The row is the exact solution there; qa is set to 0 only where the axes are aligned
        within ALIGNED_EXACT (then any qa with the same qa ± qc reproduces M as well)
    sign : (..., 2) — +1 where qa + qc is the determined combination at the singularity, −1 for qa − qc
    """
    r, u = Ra[2, :], Rb[:, 2]  # Raᵀ e_z and Rb e_z
    qb = axis_angle_roots(r, u, M[..., :, 2])  # (..., 2)
    Rzb = _rz3(qb)  # (..., 2, 3, 3)
    v = np.einsum("ij,...jk,k->...i", Ra, Rzb, u)  # Ra Rz(qb) u, (..., 2, 3)
    m = np.broadcast_to(M[..., None, :, 2], v.shape)
    vxy = np.hypot(v[..., 0], v[..., 1])
    singular = vxy < AXES_ALIGNED_TOL  # reported as the continuum; qa = 0 only where that changes nothing
    qa = np.where(vxy < ALIGNED_EXACT, 0.0, angle_about_z(v, m))
    W = _rz3(qa) @ Ra @ Rzb @ Rb  # (..., 2, 3, 3)
    N = np.swapaxes(W, -1, -2) @ M[..., None, :, :]
    qc = np.arctan2(N[..., 1, 0], N[..., 0, 0])
    sign = np.where(v[..., 2] >= 0, 1.0, -1.0)
    exact = vxy < ALIGNED_EXACT
    qa0, qc = split_aligned(exact, sign, qc)
    qa = np.where(exact, qa0, qa)
    return np.stack([qa, qb, qc], axis=-1), singular & np.isfinite(qb), sign


def split_aligned(exact: np.ndarray, sign: np.ndarray, qc: np.ndarray):
    """The representative of an aligned-axes continuum computed with qa = 0 (so qc carries the determined
    qa ± qc), moved to the middle of the family: qa = ±w/2, qc = w/2 with w = qc wrapped into (−π, π] (both
    within ±π/2, so inside usual wrist limits).  Returns (qa, qc); unchanged where ``exact`` is False."""
    w = np.pi - np.mod(np.pi - qc, 2 * np.pi)
    return np.where(exact, sign * w / 2, 0.0), np.where(exact, w / 2, qc)


def _rz3(t: np.ndarray) -> np.ndarray:
    t = np.asarray(t, dtype=float)
    c, s = np.cos(t), np.sin(t)
    R = np.zeros(t.shape + (3, 3))
    R[..., 0, 0], R[..., 0, 1], R[..., 1, 0], R[..., 1, 1], R[..., 2, 2] = c, -s, s, c, 1.0
    return R
