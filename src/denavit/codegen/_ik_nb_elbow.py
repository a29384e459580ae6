"""The elbow + spherical-wrist closed form compiled by numba, once per machine (``cache=True``): the formulas of
:mod:`denavit.ik.forms` (the plain solver's own, jitted through :mod:`._ik_jit`) for the eight candidates of each
pose, verified, labelled (shoulder, elbow, wrist: the tests of docs/ik.md) and folded into the limits in stages over
chunks of poses, then merged and sorted by :func:`._ik_nb_finish.ik_placed`.  The constants (``ELBOW_LAYOUT`` of
:mod:`._ik_elbow`) are arguments, so one compiled kernel serves every arm of the class.  Imported only where numba
is.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from ._ik_nb_checks import CHUNK, stage_checks, stage_folds, take_branch
from ._ik_nb_elbow_stages import FOLD_GROUPS, LAYOUT, RF2, RPO, RQ1, RQB, ROWS, RSG, RST, RW2, RX
from ._ik_nb_elbow_stages import elbow_stages
from ._ik_nb_finish import ik_placed

__all__ = ["ik_elbow_packed", "ik_elbow", "elbow_checks", "elbow_folds"]


@njit(cache=True, nogil=True)
def ik_elbow_packed(T, K, f, i):
    """:func:`ik_elbow` with the constants packed in one vector K (ELBOW_LAYOUT order) and the outputs in two
    arrays (f: solutions, residuals, outside-limits solutions; i (B, 20): label codes, then k, j, status, then the
    batched layout's slots (ik_finish's out_rank)): four arguments instead of twenty-four to unbox per call."""
    ik_elbow(T, K, K[283:289], K[295:303], f[:, :, :6], f[:, :, 6:8], i[:, :8], f[:, :, 8:], i[:, 8:11],
             i[:, 11:20])


@njit(cache=True, nogil=True, inline="always")  # into ik_elbow_packed: no 10-array call
def ik_elbow(T, K, revolute, tols, out_q, out_err, out_label, out_outq, out_status, out_rank):
    """All solutions of each pose T[b]: out_q[b, :k] (folded, sorted), out_err[b, :k] = (position, orientation)
    residuals, out_label[b, :k] bit codes (1 shoulder left, 2 elbow down, 4 wrist flip), out_outq[b, :j] the
    solutions outside the limits, out_status[b] = (k, j, 1 if the plain solver must decide), out_rank[b] the slots
    of the batched layout (:func:`._ik_nb_finish.ik_finish`).  Every branch of CHUNK poses at a time comes from the
    stages (:func:`._ik_nb_elbow_stages.elbow_stages`: the candidates; :func:`elbow_checks`:
    their verifying FK, residuals and labels; :func:`elbow_folds`: the fold into the limits),
    then each pose's branches are walked in the one-pose order, merged and sorted as the plain solver does
    (:func:`._ik_nb_finish.ik_placed`)."""
    # scratch: a few allocations per call (not per pose), viewed without reshapes (a reshape is a helper call)
    ws = np.empty(36)
    perm, vr, codes = ws[0:8], ws[8:28], ws[28:36]  # the candidate in each sorted slot; ik_sorted's; label codes
    w8 = np.empty((8, 8))
    cand, cerr = w8[:, 0:6], w8[:, 6:8]  # per candidate: joints, residuals
    flags = np.zeros(24, dtype=np.bool_)
    St = np.empty(ROWS * CHUNK)  # the stages' rows (_ik_nb_elbow_stages), CHUNK floats each
    for b in range(T.shape[0]):
        r = b % CHUNK
        if r == 0:  # the next chunk's candidates and checks, every branch
            n = min(CHUNK, T.shape[0] - b)
            elbow_stages(T, b, n, K, St)
            elbow_checks(n, K, St)
            elbow_folds(n, K, St)
        # the branches of the pose in the one-pose loop's order (q1 root, q3 root, wrist root), the ones with no
        # root skipped; the status raised where the plain solver must decide
        status = int(St[RST * CHUNK + r])
        ncand = 0
        for s1 in range(2 if status == 0 else 0):
            x = St[(RX + s1) * CHUNK + r]
            if math.isnan(St[(RQ1 + s1) * CHUNK + r]) or math.isnan(x):
                continue
            if x < 1e-6 or math.pi - x < 1e-6:
                status = 1  # folded or stretched elbow: a double root
            for s3 in range(2):
                k2 = 2 * s1 + s3
                if St[(RF2 + k2) * CHUNK + r] != 0.0 or St[(RW2 + k2) * CHUNK + r] != 0.0:
                    status = 1  # the wrist centre on axis 2 (q2 free), or the wrist's two roots qb meeting
                if math.isnan(St[(RQB + 2 * k2) * CHUNK + r]):
                    continue
                for k in range(2 * k2, 2 * k2 + 2):
                    if St[(RSG + k) * CHUNK + r] != 0.0 or St[(RPO + k) * CHUNK + r] != 0.0:
                        status = 1  # wrist singular (a continuum), or a residual the plain solver would polish
                    if take_branch(St, r, k, LAYOUT, cand, cerr, flags, codes, ncand):
                        status = 1  # verified, and a joint next to an edge of the fold: the plain solver decides
                    ncand += 1
        # (folded into the limits in the stages) merged and sorted as the plain solver does (shared with the UR and
        # Stanford kernels); then the labels
        kept, n_out, st = ik_placed(b, cand, cerr, ncand, revolute, tols, flags, out_q, out_err, out_outq, perm,
                                    out_rank, vr)
        for slot in range(kept):
            out_label[b, slot] = codes[int(perm[slot])]
        out_status[b, 0] = kept
        out_status[b, 1] = n_out
        out_status[b, 2] = max(status, st)


@njit(cache=True, nogil=True, error_model="numpy")
def elbow_checks(n, K, S):
    """The verifying FK, residuals, verification and polish flags and label codes of every branch of the chunk's
    first n poses into S (:func:`._ik_nb_checks.stage_checks` on the elbow kernel's rows)."""
    stage_checks(n, K[80:192].reshape((7, 4, 4)), K[289:295], K[295:303], S, LAYOUT)


@njit(cache=True, nogil=True, error_model="numpy")
def elbow_folds(n, K, S):
    """Every branch's joints of the chunk's first n poses folded into the limits in place, with the fold's flags
    (:func:`._ik_nb_checks.stage_folds` on the elbow kernel's rows)."""
    stage_folds(n, K[271:277], K[277:283], S, LAYOUT, FOLD_GROUPS)
