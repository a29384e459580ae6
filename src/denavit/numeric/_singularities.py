"""Numeric measures of how close a Jacobian is to singular, and the velocity / force ellipsoids.

All functions take a Jacobian (..., m, n) — usually J0 or Je, or the rows a task uses (``J[..., rows, :]``)
— and work over leading batch axes. Thresholds are relative to the largest singular value.
Mixing linear [m/s] and angular [rad/s] rows makes the numbers depend on the length unit; pick rows
(e.g. the three linear ones) when that matters.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .._constants import TWIST_ROWS
from ..errors import ShapeError

__all__ = ["singular_values", "manipulability", "condition_number", "smallest_singular_value",
           "jacobian_rank", "is_singular", "Ellipsoid", "velocity_ellipsoid", "force_ellipsoid", "RANK_RTOL",
           "TWIST_ROWS", "select_rows"]

#: A singular value below RANK_RTOL · σ_max counts as zero.
RANK_RTOL = 1e-9


def _as_matrix(J) -> np.ndarray:
    J = np.asarray(J, dtype=float)
    if J.ndim < 2:
        raise ShapeError(f"J: expected shape (..., m, n), got {J.shape}")
    return J


def select_rows(rows: str | list[str] | tuple[str, ...] | None) -> list[int]:
    """Row indices for names like ``"vx,vy,wz"`` (all six rows for None). Raises ValueError on unknown names."""
    if rows is None:
        return list(range(6))
    names = [r.strip().lower() for r in (rows.split(",") if isinstance(rows, str) else rows) if r.strip()]
    out = []
    for r in names:
        if r not in TWIST_ROWS:
            raise ValueError(f"unknown row {r!r}; choose from {', '.join(TWIST_ROWS)}")
        if TWIST_ROWS.index(r) in out:
            raise ValueError(f"row {r!r} given twice")
        out.append(TWIST_ROWS.index(r))
    if not out:
        raise ValueError(f"no rows given; choose from {', '.join(TWIST_ROWS)}")
    return out


def _svd(J: np.ndarray, compute_uv: bool):
    """np.linalg.svd with NaN results (not LinAlgError) for the matrices of a batch that hold NaN or ±inf."""
    bad = ~np.all(np.isfinite(J), axis=(-2, -1))
    if not bad.any():
        return np.linalg.svd(J, full_matrices=False, compute_uv=compute_uv)
    out = np.linalg.svd(np.where(bad[..., None, None], 0.0, J), full_matrices=False, compute_uv=compute_uv)
    if not compute_uv:
        return np.where(bad[..., None], np.nan, out)
    U, s, Vt = out
    return np.where(bad[..., None, None], np.nan, U), np.where(bad[..., None], np.nan, s), Vt


def singular_values(J) -> np.ndarray:
    """Singular values (..., min(m, n)) in decreasing order.

    A Jacobian with a NaN or infinite entry gets NaN singular values (and NaN manipulability, condition
    number, σ_min and ellipsoids; its numerical rank counts as 0), not an exception: one bad configuration
    of a batch does not stop the others.
    """
    return _svd(_as_matrix(J), False)


def manipulability(J) -> np.ndarray:
    """Yoshikawa's manipulability w = √det(J Jᵀ) = ∏ σ_i (..., ) (Yoshikawa 1985, IJRR 4(2)).

    For m > n (fewer joints than task rows) J Jᵀ is always singular and w = 0.
    """
    J = _as_matrix(J)
    s = singular_values(J)
    w = np.prod(s, axis=-1)
    return np.where(J.shape[-2] > J.shape[-1], np.where(np.isnan(w), np.nan, 0.0), w)


def condition_number(J) -> np.ndarray:
    """σ_max / σ_min (..., ); inf at a singularity."""
    s = singular_values(_as_matrix(J))
    with np.errstate(divide="ignore"):
        return np.where(np.isnan(s[..., -1]), np.nan, np.where(s[..., -1] > 0, s[..., 0] / np.where(s[..., -1] > 0, s[..., -1], 1.0), np.inf))


def smallest_singular_value(J) -> np.ndarray:
    """σ_min (..., ): the distance (in the 2-norm) of J to the nearest rank-deficient matrix."""
    return singular_values(J)[..., -1]


def jacobian_rank(J, rtol: float = RANK_RTOL) -> np.ndarray:
    """Numerical rank (..., ): the number of σ_i > rtol · σ_max."""
    s = singular_values(J)
    return np.sum(s > rtol * s[..., :1], axis=-1)


def is_singular(J, rtol: float = RANK_RTOL) -> np.ndarray:
    """True where rank(J) < min(m, n) (..., )."""
    J = _as_matrix(J)
    return jacobian_rank(J, rtol) < min(J.shape[-2:])


@dataclass(frozen=True)
class Ellipsoid:
    """Principal axes (columns of ``axes``, (..., m, k)) and radii (..., k) of an ellipsoid in task space."""

    axes: np.ndarray
    radii: np.ndarray


def velocity_ellipsoid(J) -> Ellipsoid:
    """{J q̇ : |q̇| ≤ 1}: axes = left singular vectors u_i, radii = σ_i (Yoshikawa 1985; Siciliano sec. 3.9).

    Only the k = min(m, n) axes in the range of J are returned; along the others the radius is 0.
    """
    U, s, _ = _svd(_as_matrix(J), True)
    return Ellipsoid(U, s)


def force_ellipsoid(J) -> Ellipsoid:
    """{F : |Jᵀ F| ≤ 1}: same axes as the velocity ellipsoid, radii 1/σ_i (inf where σ_i = 0) (kineto-static duality)."""
    U, s, _ = _svd(_as_matrix(J), True)
    with np.errstate(divide="ignore"):
        radii = np.where(np.isnan(s), np.nan, np.where(s > 0, 1.0 / np.where(s > 0, s, 1.0), np.inf))
    return Ellipsoid(U, radii)
