"""The elbow + spherical-wrist closed form compiled by numba, once per machine (``cache=True``): the formulas of
:mod:`denavit.ik.forms` (the plain solver's own, jitted through :mod:`._ik_jit`) for the eight candidates of each
pose, verified, folded, merged and sorted by :func:`._ik_nb_finish.ik_finish`, then labelled (shoulder, elbow,
wrist: the tests of docs/ik.md).  The constants (``ELBOW_LAYOUT`` of :mod:`._ik_elbow`) are arguments, so one
compiled kernel serves every arm of the class.  Imported only where numba is.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from ._ik_nb_elbow_stages import RC1, RC2, RC3, RCA, RCB, RCC, RF2, RQ1, RQ2, RQ3, RQA, RQB, RQC, RS1, RS2, RS3
from ._ik_nb_elbow_stages import RSA, RSB, RSC, RSG, RST, RX, CHUNK, ROWS, elbow_stages
from ._ik_nb_finish import ik_finish

__all__ = ["ik_elbow_packed", "ik_elbow"]


@njit(cache=True, nogil=True)
def ik_elbow_packed(T, K, f, i):
    """:func:`ik_elbow` with the constants packed in one vector K (ELBOW_LAYOUT order) and the outputs in two
    arrays (f: solutions, residuals, outside-limits solutions; i (B, 20): label codes, then k, j, status, then the
    batched layout's slots (ik_finish's out_rank)): four arguments instead of twenty-four to unbox per call."""
    consts, chain = K[16:80].reshape((4, 4, 4)), K[80:192].reshape((7, 4, 4))
    lo_lim, hi_lim, rev, theta, tols = K[271:277], K[277:283], K[283:289], K[289:295], K[295:303]
    ik_elbow(T, K, consts, lo_lim, hi_lim, rev, theta, tols, chain, f[:, :, :6], f[:, :, 6:8], i[:, :8],
             f[:, :, 8:], i[:, 8:11], i[:, 11:20])


@njit(cache=True, nogil=True, inline="always")  # into ik_elbow_packed: no 15-array call
def ik_elbow(T, K, consts, lo_lim, hi_lim, revolute, theta, tols, chain, out_q, out_err, out_label, out_outq,
             out_status, out_rank):
    """All solutions of each pose T[b]: out_q[b, :k] (folded, sorted), out_err[b, :k] = (position, orientation)
    residuals, out_label[b, :k] bit codes (1 shoulder left, 2 elbow down, 4 wrist flip), out_outq[b, :j] the
    solutions outside the limits, out_status[b] = (k, j, 1 if the plain solver must decide), out_rank[b] the slots
    of the batched layout (:func:`._ik_nb_finish.ik_finish`).  The candidates of CHUNK poses at a time come from
    :func:`._ik_nb_elbow_stages.elbow_stages` (every branch, one loop over the poses per stage)."""
    ct5, st5 = math.cos(theta[4]), math.sin(theta[4])  # the wrist label's sin(q5 + theta5), by the sum formula
    # scratch: a few allocations per call (not per pose), viewed without reshapes (a reshape is a helper call)
    ws = np.empty(67)
    x1, y1c, z1, S, E, dW = ws[21:24], ws[24:27], ws[27:30], ws[30:33], ws[33:36], ws[36:39]
    perm, vr = ws[39:47], ws[47:67]  # the candidate in each sorted slot; ik_finish's scratch
    w8 = np.empty((22, 56))  # per candidate: joints, residuals, frames after joints 1-3 (from the FK, for the
    cand, cerr, frames, cs = w8[0:8, 0:6], w8[0:8, 6:8], w8[0:8, 8:44], w8[0:8, 44:56]  # labels), their cos, sin
    PF, F = w8[8:15, 0:12], w8[15:19, 0:4]  # the FK's partial products, its pose
    flags = np.zeros(24, dtype=np.bool_)
    St = np.empty(ROWS * CHUNK)  # the stages' rows (_ik_nb_elbow_stages), CHUNK floats each
    for b in range(T.shape[0]):
        r = b % CHUNK
        if r == 0:  # the next chunk's candidates, every branch
            elbow_stages(T, b, min(CHUNK, T.shape[0] - b), K, St)
        Xw = (St[r], St[CHUNK + r], St[2 * CHUNK + r])
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
                if St[(RF2 + k2) * CHUNK + r] != 0.0:
                    status = 1  # the wrist centre on axis 2: q2 free
                if math.isnan(St[(RQB + 2 * k2) * CHUNK + r]):
                    continue
                for k in range(2 * k2, 2 * k2 + 2):
                    if St[(RSG + k) * CHUNK + r] != 0.0:
                        status = 1  # wrist singular: a continuum
                    _candidate(St, r, s1, k2, k, cand, cs, ncand)
                    ncand += 1
        # verified by the FK, folded into the limits, merged and sorted as the plain solver does (shared with the
        # UR and Stanford kernels); then the labels
        kept, n_out, st = ik_finish(T, b, cand, cerr, ncand, lo_lim, hi_lim, revolute, tols, F, frames, flags,
                                    out_q, out_err, out_outq, perm, chain, cs, True, out_rank, PF, vr)
        status = max(status, st)
        for slot in range(kept):
            best = int(perm[slot])
            # labels: shoulder (x1 . (X - O1)), elbow (side of the shoulder-wrist line), wrist (sin(q5 + theta5));
            # the frames after joints 1, 2 from the verifying FK (of the unfolded candidate: whole turns apart)
            code = 0
            for i in range(3):  # frames[best] indexed, not sliced
                x1[i], y1c[i], z1[i] = frames[best, i], frames[best, 3 + i], frames[best, 6 + i]
                S[i], E[i] = frames[best, 9 + i], frames[best, 21 + i]
            s_right = 0.0
            for i in range(3):
                s_right += x1[i] * (Xw[i] - consts[0, i, 3])
            if s_right < 0.0:
                code |= 1
            for i in range(3):
                dW[i] = Xw[i] - S[i]
            nrm0 = z1[1] * dW[2] - z1[2] * dW[1]
            nrm1 = z1[2] * dW[0] - z1[0] * dW[2]
            nrm2 = z1[0] * dW[1] - z1[1] * dW[0]
            towards = 1.0 if consts[0, 0, 2] * nrm0 + consts[0, 1, 2] * nrm1 + consts[0, 2, 2] * nrm2 >= 0.0 else -1.0
            side = (E[0] - S[0]) * nrm0 + (E[1] - S[1]) * nrm1 + (E[2] - S[2]) * nrm2
            if side * towards < 0.0:
                code |= 2
            if cs[best, 9] * ct5 + cs[best, 8] * st5 < 0.0:  # sin(q5 + theta5) from q5's cos and sin (a sign
                # flip needs it within rounding of 0: the wrist singularity, handed over)
                code |= 4
            out_label[b, slot] = code
        out_status[b, 0] = kept
        out_status[b, 1] = n_out
        out_status[b, 2] = status


@njit(cache=True, nogil=True, inline="always")  # into ik_elbow: no call per candidate
def _candidate(St, r, s1, k2, k, cand, cs, m):
    """Branch k (arm branch k2, shoulder root s1) of pose r of the stages' rows St into cand[m] and the cosines and
    sines of its joints into cs[m] (for the verifying FK: the closed form's normalised (cos, sin) pairs whose atan2
    the joints are; qa's as computed, which differs only where singular, handed over)."""
    a, c, d = s1 * CHUNK + r, k2 * CHUNK + r, k * CHUNK + r  # the pose's column in the rows of s1, k2, k
    cand[m, 0], cand[m, 1], cand[m, 2] = St[RQ1 * CHUNK + a], St[RQ2 * CHUNK + c], St[RQ3 * CHUNK + c]
    cand[m, 3], cand[m, 4], cand[m, 5] = St[RQA * CHUNK + d], St[RQB * CHUNK + d], St[RQC * CHUNK + d]
    cs[m, 0], cs[m, 1], cs[m, 2], cs[m, 3] = St[RC1 * CHUNK + a], St[RS1 * CHUNK + a], St[RC2 * CHUNK + c], \
        St[RS2 * CHUNK + c]
    cs[m, 4], cs[m, 5], cs[m, 6], cs[m, 7] = St[RC3 * CHUNK + c], St[RS3 * CHUNK + c], St[RCA * CHUNK + d], \
        St[RSA * CHUNK + d]
    cs[m, 8], cs[m, 9], cs[m, 10], cs[m, 11] = St[RCB * CHUNK + d], St[RSB * CHUNK + d], St[RCC * CHUNK + d], \
        St[RSC * CHUNK + d]
