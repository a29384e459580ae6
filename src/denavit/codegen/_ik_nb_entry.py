"""The one machine-code call behind ``CompiledRobot.analytic_ik`` for one pose: the target's check and the arm's
closed-form kernel (elbow, UR class or Stanford class: one entry each) in one compiled function, every output in
one float vector (one allocation and one call from Python; the check, the kernel call, two output arrays and the
result's views were half of a call's time).  Compiled once per machine (``cache=True``); imported only where numba is.

Layout of the output vector ``o`` (OUT_SIZE floats): ``o[:112]`` the (8, 14) block of the kernels (solutions,
residuals, solutions outside the limits), ``o[112:120]`` the label codes, ``o[120]`` kept, ``o[121]`` outside,
``o[122]`` status (0 answered, 1 for the plain solver, 2 a bad target), ``o[123:131]`` each kept solution's slot
in the plain solver's batched layout (its rank among the verified candidates), ``o[131]`` their number, ``o[132]``
the target's orthonormality error (inf for NaN or inf entries).  A batch is solved pose by pose into one such
vector and scattered into the plain solver's batched layout in the same loop (:func:`ik_many_elbow`).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from ._ik_nb_elbow import ik_elbow_packed
from ._ik_nb_parallel import ik_parallel_packed
from ._ik_nb_stanford import ik_stanford_packed

__all__ = ["OUT_SIZE", "ENTRIES", "BAD_TARGET", "pose_error"]

OUT_SIZE = 133
#: a target whose rotation is this far from orthonormal (the largest |RᵀR − I| entry) is refused
BAD_TARGET = 1e-6


@njit(cache=True, nogil=True)
def pose_error(T):
    """The largest |RᵀR − I| entry of the 4×4 target T (the test of denavit's as_transform); inf if it holds a NaN
    or an infinity."""
    for i in range(4):
        for j in range(4):
            if not math.isfinite(T[i, j]):
                return math.inf
    worst = 0.0
    for i in range(3):
        for j in range(3):
            s = T[0, i] * T[0, j] + T[1, i] * T[1, j] + T[2, i] * T[2, j]
            worst = max(worst, abs(s - (1.0 if i == j else 0.0)))
    return worst


@njit(cache=True, nogil=True)
def _checked(T, o):
    """Record T's orthonormality error in o; False (status 2, nothing found) for a bad target."""
    err = pose_error(T)
    o[132] = err
    if err > BAD_TARGET:
        o[120], o[121], o[122] = 0.0, 0.0, 2.0
        return False
    return True


# one entry per kernel (each arm compiles only its own), for one pose (T (4, 4) C-contiguous, o (OUT_SIZE,)); the
# batch entries are below

@njit(cache=True, nogil=True)
def ik_one_elbow(T, K, o):
    """Every closed-form solution of the one pose T into o (layout in the module notes): the elbow kernel.  Returns
    the status o[122] (read from Python as a float, not as a numpy scalar)."""
    if _checked(T, o):
        ik_elbow_packed(T.reshape((1, 4, 4)), K, o[:112].reshape((1, 8, 14)), o[112:132].reshape((1, 20)))
    return o[122]


@njit(cache=True, nogil=True)
def ik_one_parallel(T, K, o):
    """:func:`ik_one_elbow` by the UR-class kernel."""
    if _checked(T, o):
        ik_parallel_packed(T.reshape((1, 4, 4)), K, o[:112].reshape((1, 8, 14)), o[112:132].reshape((1, 20)))
    return o[122]


@njit(cache=True, nogil=True)
def ik_one_stanford(T, K, o):
    """:func:`ik_one_elbow` by the Stanford-class kernel."""
    if _checked(T, o):
        ik_stanford_packed(T.reshape((1, 4, 4)), K, o[:112].reshape((1, 8, 14)), o[112:132].reshape((1, 20)))
    return o[122]


@njit(cache=True, nogil=True)
def _scatter(o, b, sol, pe, re, valid, codes, outside, status):
    """Pose b's answer (the output vector o of a one-pose entry) into the batched layout of the plain solver: kept
    solution s into slot o[123 + s] (its rank among the verified candidates), every other slot of the row a NaN row,
    residuals NaN, valid False, label code -1; a pose handed over (status 1) or refused (2) gets such a row alone.
    Returns the number of slots the pose uses (0 unless answered)."""
    st = o[122]
    status[b] = np.int8(st)
    for col in range(sol.shape[1]):
        for j in range(sol.shape[2]):
            sol[b, col, j] = np.nan
        pe[b, col], re[b, col], valid[b, col], codes[b, col] = np.nan, np.nan, False, -1
    if st != 0.0:
        outside[b] = 0
        return 0
    outside[b] = int(o[121])
    for s in range(int(o[120])):
        col = int(o[123 + s])
        for j in range(sol.shape[2]):
            sol[b, col, j] = o[14 * s + j]
        pe[b, col], re[b, col], valid[b, col], codes[b, col] = o[14 * s + 6], o[14 * s + 7], True, np.int8(o[112 + s])
    return int(o[131])


# the batch entries: every pose T[b] (T (B, 4, 4) C-contiguous) solved into one output vector kept in the cache and
# scattered straight into the batched layout (sol (B, 8, n), pe, re (B, 8), valid, codes (B, 8), outside, status
# (B,)); returned: the most slots an answered pose uses, and the first refused pose with its orthonormality error
# (-1, 0.0 if none)

@njit(cache=True, nogil=True)
def ik_many_elbow(T, K, sol, pe, re, valid, codes, outside, status):
    """:func:`ik_one_elbow` for each pose T[b], into the batched layout (see above)."""
    o = np.empty(OUT_SIZE)
    most, bad, err = 0, -1, 0.0
    for b in range(T.shape[0]):
        ik_one_elbow(T[b], K, o)
        most = max(most, _scatter(o, b, sol, pe, re, valid, codes, outside, status))
        if bad < 0 and o[122] == 2.0:
            bad, err = b, o[132]
    return most, bad, err


@njit(cache=True, nogil=True)
def ik_many_parallel(T, K, sol, pe, re, valid, codes, outside, status):
    """:func:`ik_one_parallel` for each pose T[b], into the batched layout."""
    o = np.empty(OUT_SIZE)
    most, bad, err = 0, -1, 0.0
    for b in range(T.shape[0]):
        ik_one_parallel(T[b], K, o)
        most = max(most, _scatter(o, b, sol, pe, re, valid, codes, outside, status))
        if bad < 0 and o[122] == 2.0:
            bad, err = b, o[132]
    return most, bad, err


@njit(cache=True, nogil=True)
def ik_many_stanford(T, K, sol, pe, re, valid, codes, outside, status):
    """:func:`ik_one_stanford` for each pose T[b], into the batched layout."""
    o = np.empty(OUT_SIZE)
    most, bad, err = 0, -1, 0.0
    for b in range(T.shape[0]):
        ik_one_stanford(T[b], K, o)
        most = max(most, _scatter(o, b, sol, pe, re, valid, codes, outside, status))
        if bad < 0 and o[122] == 2.0:
            bad, err = b, o[132]
    return most, bad, err


#: (one pose, batch) entries of each closed form
ENTRIES = {"elbow": (ik_one_elbow, ik_many_elbow), "parallel": (ik_one_parallel, ik_many_parallel),
           "stanford": (ik_one_stanford, ik_many_stanford)}
