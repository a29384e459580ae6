"""The batch entries behind ``CompiledRobot.analytic_ik`` on poses (..., 4, 4): each closed-form kernel run over
blocks of BLOCK poses (its scratch allocated and its views made once per block, not once per pose), each pose's
answer scattered straight into the plain solver's batched layout.  Compiled once per machine (``cache=True``);
imported only where numba is.

The layout (as :func:`denavit.analytic_ik` batched): slot k of a pose holds its k-th verified candidate in candidate
order (the kernel's rank of each kept solution), every other slot a NaN row with NaN residuals, ``valid`` False
and label code -1; a pose the kernel hands over (status 1) or a refused target (status 2: NaN, inf or a rotation
further than BAD_TARGET from orthonormal, the test of ``as_transform``) gets such rows alone.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from ._ik_nb_elbow import ik_elbow_packed
from ._ik_nb_entry import BAD_TARGET
from ._ik_nb_parallel import ik_parallel_packed
from ._ik_nb_stanford import ik_stanford_packed

__all__ = ["BLOCK", "BATCH", "ik_batch_elbow", "ik_batch_parallel", "ik_batch_stanford"]

#: poses solved by one call of a kernel (its scratch: a few kB; the block's outputs: BLOCK × 1.1 kB, in L1/L2)
BLOCK = 64


@njit(cache=True, nogil=True, inline="always")  # into each entry
def _target_error(T, b):
    """The largest |RᵀR − I| entry of the target T[b] (the test of denavit's as_transform); inf if it holds a NaN
    or an infinity.  T indexed, not sliced (a view per pose is a reference count)."""
    for i in range(4):
        for j in range(4):
            if not math.isfinite(T[b, i, j]):
                return math.inf
    worst = 0.0
    for i in range(3):
        for j in range(3):
            s = T[b, 0, i] * T[b, 0, j] + T[b, 1, i] * T[b, 1, j] + T[b, 2, i] * T[b, 2, j]
            worst = max(worst, abs(s - (1.0 if i == j else 0.0)))
    return worst


@njit(cache=True, nogil=True, inline="always")  # into each entry
def _scatter(f, i, r, b, bad, sol, pe, re, valid, codes, outside, status):
    """Pose b's answer (row r of a kernel's outputs f (BLOCK, 8, 14), i (BLOCK, 20)) into the batched layout:
    kept solution s into slot i[r, 11 + s]; ``bad``: a refused target (status 2).  Returns the number of slots the
    pose uses (0 unless answered)."""
    st = 2 if bad else int(i[r, 10])
    status[b] = st
    for col in range(sol.shape[1]):
        for j in range(sol.shape[2]):
            sol[b, col, j] = np.nan
        pe[b, col], re[b, col], valid[b, col], codes[b, col] = np.nan, np.nan, False, -1
    if st != 0:
        outside[b] = 0
        return 0
    outside[b] = int(i[r, 9])
    for s in range(int(i[r, 8])):
        col = int(i[r, 11 + s])
        for j in range(sol.shape[2]):
            sol[b, col, j] = f[r, s, j]
        pe[b, col], re[b, col], valid[b, col], codes[b, col] = f[r, s, 6], f[r, s, 7], True, int(i[r, s])
    return int(i[r, 19])


@njit(cache=True, nogil=True, inline="always")  # into each entry (numba's IR: the entries stay cacheable)
def _blocks(kernel, T, K, sol, pe, re, valid, codes, outside, status):
    """Every pose T[b] by ``kernel`` (a closed form's packed kernel), BLOCK at a time, into the batched layout."""
    f, i = np.empty((BLOCK, 8, 14)), np.empty((BLOCK, 20))
    most, first, err = 0, -1, 0.0
    for s in range(0, T.shape[0], BLOCK):
        e = min(s + BLOCK, T.shape[0])
        kernel(T[s:e], K, f[: e - s], i[: e - s])
        for b in range(s, e):
            x = _target_error(T, b)
            if first < 0 and not x <= BAD_TARGET:
                first, err = b, x
            most = max(most, _scatter(f, i, b - s, b, not x <= BAD_TARGET, sol, pe, re, valid, codes, outside,
                                      status))
    return most, first, err


# One entry per kernel, each the loop above around it (a kernel passed from Python would be an argument numba
# keys its cache by, which no later process hits): T (B, 4, 4) C-contiguous; sol (B, 8, n), pe, re (B, 8), valid,
# codes (B, 8), outside, status (B,).  Returned: the most slots an answered pose uses, and the first refused pose
# with its orthonormality error (-1, 0.0 if none).

@njit(cache=True, nogil=True)
def ik_batch_elbow(T, K, sol, pe, re, valid, codes, outside, status):
    """Every pose T[b] by the elbow kernel, BLOCK at a time, into the batched layout."""
    return _blocks(ik_elbow_packed, T, K, sol, pe, re, valid, codes, outside, status)


@njit(cache=True, nogil=True)
def ik_batch_parallel(T, K, sol, pe, re, valid, codes, outside, status):
    """:func:`ik_batch_elbow` by the UR-class kernel."""
    return _blocks(ik_parallel_packed, T, K, sol, pe, re, valid, codes, outside, status)


@njit(cache=True, nogil=True)
def ik_batch_stanford(T, K, sol, pe, re, valid, codes, outside, status):
    """:func:`ik_batch_elbow` by the Stanford-class kernel."""
    return _blocks(ik_stanford_packed, T, K, sol, pe, re, valid, codes, outside, status)


#: the batch entry of each closed form
BATCH = {"elbow": ik_batch_elbow, "parallel": ik_batch_parallel, "stanford": ik_batch_stanford}
