"""Roots of the resultant of :class:`._position3.Position3`, batched: companion-matrix eigenvalues, and the
clusters into which rounding splits a multiple root.

A k-fold root of a polynomial with coefficients exact to ε comes out as k roots ~ε^(1/k) apart (some complex);
the mean of those k roots is exact to rounding (their sum is a coefficient's), so it is returned as the cluster's
centre.  Companion matrix: Golub & Van Loan, Matrix Computations 4th ed., Sec. 7.4.6.
"""

from __future__ import annotations

import numpy as np

__all__ = ["CLUSTER_SIZE", "CLUSTER_SPREAD", "batched_roots", "root_clusters"]

CLUSTER_SPREAD = 10.0  # k roots of the resultant within CLUSTER_SPREAD · ε^(1/k) of one (relative) are taken for a
# k-fold root split by rounding (~ε^(1/k) apart: 6e-5 for k = 3, 1e-3 for 4, 2.5e-2 for 6); those poses are solved
# in the other elimination order too
CLUSTER_SIZE = 3  # smallest such k (a double root is split ~√ε only and handled by the refinement)


def batched_roots(p: np.ndarray) -> np.ndarray:
    """Roots of polynomials (B, m+1), highest coefficient first, via batched companion matrices → (B, m)."""
    B, m1 = p.shape
    m = m1 - 1
    if m <= 0:
        return np.full((B, 0), np.nan + 0j)
    bad = ~np.all(np.isfinite(p), axis=1) | ~np.any(p != 0, axis=1)
    if bad.any():  # no roots for a pose whose coefficients overflowed or all vanish (the resultant ≡ 0 there)
        out = np.full((B, m), np.nan + 0j)
        if (~bad).any():
            out[~bad] = batched_roots(p[~bad])
        return out
    lead = p[:, :1]
    tiny = np.abs(lead) < 1e-13 * np.max(np.abs(p), axis=1, keepdims=True)
    lead = np.where(tiny, 1e-13 * np.max(np.abs(p), axis=1, keepdims=True) + 1e-300, lead)
    comp = np.zeros((B, m, m), dtype=np.result_type(p, float))
    comp[:, 0, :] = -p[:, 1:] / lead
    if m > 1:
        comp[:, np.arange(1, m), np.arange(m - 1)] = 1.0
    return np.linalg.eigvals(comp)


def root_clusters(roots: np.ndarray, prismatic: bool) -> tuple[np.ndarray, np.ndarray]:
    """Which rows of roots (B, m) hold a cluster, (B,): k ≥ CLUSTER_SIZE roots near the real line (prismatic: roots
    in the scaled length) or the unit circle (revolute: roots in e^{iq}), within CLUSTER_SPREAD · ε^(1/k) of one
    another (relative); and the centroid of each row's largest cluster (B,) complex (meaningful where clustered)."""
    near = np.abs(roots.imag) < 0.1 * (1 + np.abs(roots.real)) if prismatic else np.abs(np.abs(roots) - 1.0) < 0.1
    m = roots.shape[1]
    gap = np.abs(roots[:, :, None] - roots[:, None, :]) / (1 + np.abs(roots[:, :, None]))
    gap[:, np.arange(m), np.arange(m)] = np.inf
    gap = np.where(near[:, :, None] & near[:, None, :], np.nan_to_num(gap, nan=np.inf), np.inf)
    # root i and its k − 1 nearest others form a cluster when they lie within CLUSTER_SPREAD · ε^(1/k)
    ks = np.arange(CLUSTER_SIZE, max(m, CLUSTER_SIZE - 1) + 1)
    reach = np.sort(gap, axis=2)[:, :, ks - 2]  # (B, m, len(ks)): distance to the (k−1)-th nearest other
    fits = reach < CLUSTER_SPREAD * np.finfo(float).eps ** (1.0 / ks)
    clustered = fits.any(axis=(1, 2))
    kbest = np.where(fits, ks, 0).max(axis=2, initial=0)  # (B, m): the largest cluster around each root
    b, big = np.arange(len(roots)), np.argmax(kbest, axis=1)
    kb = kbest[b, big]
    radius = reach[b, big, np.maximum(kb - CLUSTER_SIZE, 0)] if ks.size else np.zeros(len(roots))
    member = gap[b, big] <= np.where(kb > 0, radius, -1.0)[:, None]  # the cluster of the largest k
    member[b, big] = True
    centre = np.sum(np.where(member, np.nan_to_num(roots), 0), axis=1) / member.sum(axis=1)
    return clustered, centre
