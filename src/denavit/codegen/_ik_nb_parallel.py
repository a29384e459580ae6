"""The UR-class closed form (6R, axes 2, 3, 4 parallel, axes 5, 6 meeting) compiled by numba, once per machine
(``cache=True``): see :mod:`._ik_parallel` for the method and the hand-over rules (NEAR_SINGULAR, COND_MAX).  The
candidates of CHUNK poses at a time come from stages (:mod:`._ik_nb_parallel_stages`: the formulas of
:mod:`denavit.ik.forms`, jitted through :mod:`._ik_jit`, every branch, with the hand-over tests as flags), are
verified, labelled and folded into the limits in stages (:mod:`._ik_nb_checks`), then each pose's branches are
walked in the one-pose plan's order, merged and sorted as the plain solver does
(:func:`._ik_nb_finish.ik_placed`).  The constants (``PARALLEL_LAYOUT``) are arguments.  Imported only where numba
is.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from ._ik_nb_checks import CHUNK, stage_checks, stage_folds, take_branch
from ._ik_nb_finish import ik_placed
from ._ik_nb_parallel_stages import (
    FOLD_GROUPS,
    LAYOUT,
    RD3,
    RF6,
    RFK,
    ROWS,
    RPO,
    RQ1,
    RQ3,
    RQ5,
    RR3,
    RST,
    RW5,
    parallel_stages,
)

__all__ = ["frame1", "ik_parallel_packed", "next_frame", "parallel_checks", "parallel_folds"]


@njit(cache=True, nogil=True)
def ik_parallel_packed(T, K, f, i):
    """All solutions of each pose T[b] of a 6R UR-class arm, the constants in K (PARALLEL_LAYOUT order); outputs as
    ik_elbow_packed: f[b, :k, :6] solutions (folded, sorted), f[b, :k, 6:8] (position, orientation) residuals,
    f[b, :j, 8:] the solutions outside the limits; i[b, :k] label codes (1 shoulder left, 2 elbow down, 4 wrist
    flip), i[b, 8:11] = (k, j, 1 if the plain solver must decide), i[b, 11:20] the batched layout's slots."""
    rev, tols = K[157:163], K[169:177]
    ws = np.empty(36)  # scratch: a few allocations per call (not per pose)
    perm, vr, codes = ws[0:8], ws[8:28], ws[28:36]  # the candidate in each sorted slot; ik_sorted's; label codes
    w8 = np.empty((8, 8))
    cand, cerr = w8[:, 0:6], w8[:, 6:8]  # per candidate: joints, residuals
    flags = np.zeros(24, dtype=np.bool_)
    St = np.empty(ROWS * CHUNK)  # the stages' rows (_ik_nb_parallel_stages), CHUNK floats each
    fq, fe, fo, rank = f[:, :, :6], f[:, :, 6:8], f[:, :, 8:], i[:, 11:20]
    for b in range(T.shape[0]):
        r = b % CHUNK
        if r == 0:  # the next chunk's candidates, checks and folds, every branch
            n = min(CHUNK, T.shape[0] - b)
            parallel_stages(T, b, n, K, St)
            parallel_checks(n, K, St)
            parallel_folds(n, K, St)
        status, ncand = _walk(St, r, cand, cerr, flags, codes)
        kept, n_out, st = ik_placed(b, cand, cerr, ncand, rev, tols, flags, fq, fe, fo, perm, rank, vr)
        for slot in range(kept):
            i[b, slot] = codes[int(perm[slot])]
        i[b, 8], i[b, 9], i[b, 10] = kept, n_out, max(status, st)


@njit(cache=True, nogil=True, inline="always")  # into ik_parallel_packed: no call per pose
def _walk(St, r, cand, cerr, flags, codes):
    """The branches of pose r of the stages' rows St in the one-pose plan's order (q1 root, q5 root, q3 root), the
    ones with no root skipped, into the candidates; the status raised where a flag of a branch the plan reaches is
    set (the plain solver decides).  Returns (status, count)."""
    status = int(St[RST * CHUNK + r])
    ncand = 0
    if status != 0 or math.isnan(St[RQ1 * CHUNK + r]):
        return status, 0
    for s1 in range(2):
        if St[(RW5 + s1) * CHUNK + r] != 0.0:
            status = 1  # the two q5 roots (nearly) coincide
        if math.isnan(St[(RQ5 + 2 * s1) * CHUNK + r]):
            continue
        for j in range(2 * s1, 2 * s1 + 2):
            if St[(RF6 + j) * CHUNK + r] != 0.0:
                status = 1  # axis 6 parallel to axes 2-4 (a continuum), or P next to axis 2
            if St[(RR3 + j) * CHUNK + r] != 0.0:
                status = 1
                continue
            if St[(RD3 + j) * CHUNK + r] != 0.0:
                status = 1  # elbow stretched or folded: a double root
            if math.isnan(St[(RQ3 + 2 * j) * CHUNK + r]):
                continue
            for k in range(2 * j, 2 * j + 2):
                if St[(RFK + k) * CHUNK + r] != 0.0 or St[(RPO + k) * CHUNK + r] != 0.0:
                    status = 1  # ill-conditioned (COND_MAX), or a residual the plain solver would polish
                if take_branch(St, r, k, LAYOUT, cand, cerr, flags, codes, ncand):
                    status = 1  # verified, and a joint next to an edge of the fold: the plain solver decides
                ncand += 1
    return status, ncand


@njit(cache=True, nogil=True, error_model="numpy")
def parallel_checks(n, K, S):
    """The verifying FK, residuals, verification and polish flags and label codes of every branch of the chunk's
    first n poses into S (:func:`._ik_nb_checks.stage_checks` on the UR-class kernel's rows)."""
    stage_checks(n, K[19:131].reshape((7, 4, 4)), K[163:169], K[169:177], S, LAYOUT)


@njit(cache=True, nogil=True, error_model="numpy")
def parallel_folds(n, K, S):
    """Every branch's joints of the chunk's first n poses folded into the limits in place, with the fold's flags
    (:func:`._ik_nb_checks.stage_folds` on the UR-class kernel's rows)."""
    stage_folds(n, K[145:151], K[151:157], S, LAYOUT, FOLD_GROUPS)


@njit(cache=True, nogil=True, inline="always")  # no call passing arrays
def frame1(C, c, s, cols):
    """Columns x, y, z and origin of C0 Rz(q1) C1 into cols (4, 3), c, s = cos q1, sin q1 (as the chain's
    walker: x <- c x + s y, ...)."""
    for r in range(3):
        x, y, z = C[0, r, 0], C[0, r, 1], C[0, r, 2]
        x, y = c * x + s * y, c * y - s * x
        cols[0, r] = x * C[1, 0, 0] + y * C[1, 1, 0] + z * C[1, 2, 0]
        cols[1, r] = x * C[1, 0, 1] + y * C[1, 1, 1] + z * C[1, 2, 1]
        cols[2, r] = x * C[1, 0, 2] + y * C[1, 1, 2] + z * C[1, 2, 2]
        cols[3, r] = C[0, r, 3] + x * C[1, 0, 3] + y * C[1, 1, 3] + z * C[1, 2, 3]


@njit(cache=True, nogil=True, inline="always")  # no call passing arrays
def next_frame(cols, c, s, Ck, out):
    """Columns and origin of F Rz(q) Ck into out (4, 3), F given by its columns cols (4, 3), c, s = cos q, sin q
    (out may be cols)."""
    for r in range(3):
        x, y, z = c * cols[0, r] + s * cols[1, r], c * cols[1, r] - s * cols[0, r], cols[2, r]
        out[0, r] = x * Ck[0, 0] + y * Ck[1, 0] + z * Ck[2, 0]
        out[1, r] = x * Ck[0, 1] + y * Ck[1, 1] + z * Ck[2, 1]
        out[2, r] = x * Ck[0, 2] + y * Ck[1, 2] + z * Ck[2, 2]
        out[3, r] = cols[3, r] + x * Ck[0, 3] + y * Ck[1, 3] + z * Ck[2, 3]
