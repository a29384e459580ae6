"""Observability of the calibration unknowns: which parameters the data can identify, and what the others move as.

The weighted identification Jacobian J (residuals in units of their noise, one column per unknown) is scaled to
unit column norms (column equilibration: the answer no longer depends on metres versus radians).  Columns are
then taken greedily in a fixed order of preference (base, tool, then the rows from the base, each row's θ, d, a,
α, β): a column is kept when the part of it orthogonal to the columns kept before is at least ``rank_tol`` of its
norm (sine of its angle to their span), else it is held at its nominal value and named with the combination of
kept parameters it moves the arm as (least squares J_held ≈ Σ c_j J_j).  This is column-pivoted QR (Golub & Van
Loan, *Matrix Computations*, 4th ed., §5.4.2) with the pivot order fixed by preference instead of by column norm,
so that the parameters held are the redundant ones of the DH table (θ1 and d1 against the base, the last row
against the tool: Everett, Driels & Mooring 1987, 4R + 2P + 6 independent parameters for pose data) rather
than a numerical accident.  The condition number is that of the kept, equilibrated columns.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["Observability", "observability", "RANK_TOLERANCE"]

#: A column whose part orthogonal to the kept columns is below this fraction of its norm is not identifiable.
RANK_TOLERANCE = 1e-6
#: Terms of a held parameter's combination shown (the largest contributions).
_TERMS = 3
#: Terms contributing less than this fraction of the largest are left out of a combination's text.
_SHOWN = 1e-3


@dataclass(frozen=True, eq=False)  # holds arrays: compared by identity
class Observability:
    """Which unknowns are identified (indices into the candidates), which are held and why."""

    identified: tuple[int, ...]
    held: dict[int, str]
    rank: int
    condition_number: float
    singular_values: np.ndarray


def _combination(J: np.ndarray, kept: list[int], k: int, names: tuple[str, ...]) -> str:
    """``moves the arm as +1·base_rz - 0.5·d3`` for a held column k (largest scaled terms first)."""
    coef, *_ = np.linalg.lstsq(J[:, kept], J[:, k], rcond=None)
    weight = np.abs(coef) * np.linalg.norm(J[:, kept], axis=0)  # each term's share of the column
    order = [i for i in np.argsort(-weight) if weight[i] > _SHOWN * weight.max()][:_TERMS]
    terms = " ".join(f"{'+' if coef[i] >= 0 else '-'} {abs(coef[i]):.3g}·{names[kept[i]]}" for i in order)
    more = " ..." if np.count_nonzero(weight > _SHOWN * weight.max()) > _TERMS else ""
    return f"not separable: moves the arm as {terms.lstrip('+ ')}{more}"


def observability(J: np.ndarray, order: list[int], names: tuple[str, ...], held: dict[int, str],
                  rank_tol: float = RANK_TOLERANCE) -> Observability:
    """Greedy identifiability of the columns of ``J`` (N, p) taken in ``order``; ``held`` are held from the start.

    Parameters
    ----------
    J : ndarray, shape (N, p)
        Identification Jacobian of the weighted residuals.
    order : list of int
        Column indices in order of preference.
    names : tuple of str
        The parameters' names (for the combinations).
    held : dict
        Columns held before looking (index → reason); returned with the new ones added.
    """
    norms = np.linalg.norm(J, axis=0)
    scale = norms.max() if norms.size and norms.max() > 0 else 1.0
    held = dict(held)
    kept: list[int] = []
    basis = np.zeros((J.shape[0], 0))
    for k in order:
        if k in held:
            continue
        if norms[k] <= 1e-12 * scale:
            held[k] = "no effect on the measurements (not observable from this kind of data)"
            continue
        v = J[:, k] / norms[k]
        for _ in range(2):  # Gram-Schmidt twice: orthogonal to working precision (Giraud et al. 2005)
            v = v - basis @ (basis.T @ v)
        if np.linalg.norm(v) < rank_tol:
            held[k] = _combination(J, kept, k, names)
            continue
        kept.append(k)
        basis = np.column_stack([basis, v / np.linalg.norm(v)])
    sv = np.linalg.svd(J[:, kept] / norms[kept], compute_uv=False) if kept else np.zeros(0)
    cond = float(sv[0] / sv[-1]) if kept and sv[-1] > 0 else float("inf")
    return Observability(tuple(kept), held, len(kept), cond, sv)
