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

from ._ik_finish import DOUBLE_ROOT
from ._ik_jit import (
    WRIST_TOL,
    elbow_plane,
    elbow_q2,
    elbow_roots,
    shoulder_roots,
    wrist_qb,
    wrist_rest,
)
from ._ik_nb_finish import ik_finish

__all__ = ["ik_elbow_packed", "ik_elbow"]



@njit(cache=True, nogil=True)
def ik_elbow_packed(T, K, f, i):
    """:func:`ik_elbow` with the constants packed in one vector K (ELBOW_LAYOUT order) and the outputs in two
    arrays (f: solutions, residuals, outside-limits solutions; i (B, 20): label codes, then k, j, status, then the
    batched layout's slots (ik_finish's out_rank)): four
    arguments instead of twenty-four to unbox per call."""
    K4, K3 = K[0:192].reshape((12, 4, 4)), K[192:252].reshape((20, 3))  # two reshapes; row views are free
    C0i, consts, chain = K4[0], K4[1:5], K4[5:12]
    R6, R1, R2, R4, R5 = K3[0:3], K3[3:6], K3[6:9], K3[9:12], K3[12:15]
    X_e, p1, a, p2, P = K3[15], K3[16], K3[17], K3[18], K3[19]
    sc, trig, lo_lim, hi_lim = K[252:261], K[261:271], K[271:277], K[277:283]
    rev, theta, tols = K[283:289], K[289:295], K[295:303]
    ik_elbow(T, X_e, C0i, R6, R1, p1, a, R2, p2, P, consts, R4, R5, sc, trig, lo_lim, hi_lim, rev, theta, tols, chain,
             f[:, :, :6], f[:, :, 6:8], i[:, :8], f[:, :, 8:], i[:, 8:11], i[:, 11:20])


@njit(cache=True, nogil=True, inline="always")  # into ik_elbow_packed: no 26-array call (0.2-0.3 µs a pose)
def ik_elbow(T, X_e, C0i, R6, R1, p1, a, R2, p2, P, consts, R4, R5, sc, trig, lo_lim, hi_lim, revolute, theta, tols,
             chain, out_q, out_err, out_label, out_outq, out_status, out_rank):
    """All solutions of each pose T[b]: out_q[b, :k] (folded, sorted), out_err[b, :k] = (position, orientation)
    residuals, out_label[b, :k] bit codes (1 shoulder left, 2 elbow down, 4 wrist flip), out_outq[b, :j] the
    solutions outside the limits, out_status[b] = (k, j, 1 if the plain solver must decide), out_rank[b] the slots
    of the batched layout (:func:`._ik_nb_finish.ik_finish`)."""
    h, na, nb, base3, L, rho_w = sc[0], sc[1], sc[2], sc[3], sc[4], sc[5]
    free_tol, ratio_tol = tols[0], tols[1]  # the others: _ik_finish's
    tiny = free_tol * L
    ct5, st5 = math.cos(theta[4]), math.sin(theta[4])  # the wrist label's sin(q5 + theta5), by the sum formula
    wc = (trig[0], trig[1], trig[2], trig[3], trig[4], trig[5], trig[6], trig[7])  # forms.wrist_constants
    cb3, sb3 = trig[8], trig[9]  # cos, sin of base3
    # scratch: two float and one flag allocation per call (not per pose), viewed without reshapes (a reshape is a
    # helper call)
    ws = np.empty(67)
    Xw, W, cx, cy, cz = ws[6:9], ws[9:12], ws[12:15], ws[15:18], ws[18:21]
    x1, y1c, z1, S, E, dW = ws[21:24], ws[24:27], ws[27:30], ws[30:33], ws[33:36], ws[36:39]
    perm, vr = ws[39:47], ws[47:67]  # the candidate in each sorted slot; ik_finish's scratch
    w8 = np.empty((25, 56))  # per candidate: joints, residuals, frames after joints 1-3 (from the FK, for the
    cand, cerr, frames, cs = w8[0:8, 0:6], w8[0:8, 6:8], w8[0:8, 8:44], w8[0:8, 44:56]  # labels), their cos, sin
    PF, F, Y, M = w8[8:15, 0:12], w8[15:19, 0:4], w8[19:22, 0:3], w8[22:25, 0:3]  # the FK's partial products, ...
    flags = np.zeros(24, dtype=np.bool_)
    ok = flags[0:8]
    for b in range(T.shape[0]):
        status = 0
        # wrist centre and the target rotation without the last constant
        for i in range(3):
            Xw[i] = T[b, i, 0] * X_e[0] + T[b, i, 1] * X_e[1] + T[b, i, 2] * X_e[2] + T[b, i, 3]
        for i in range(3):
            W[i] = C0i[i, 0] * Xw[0] + C0i[i, 1] * Xw[1] + C0i[i, 2] * Xw[2] + C0i[i, 3]
        for i in range(3):
            for j in range(3):
                Y[i, j] = T[b, i, 0] * R6[j, 0] + T[b, i, 1] * R6[j, 1] + T[b, i, 2] * R6[j, 2]
        # the closed form of denavit.ik.forms (the plain solver's own functions, jitted): shoulder, elbow, wrist
        q1a, q1b, free1, ratio, c1a, s1a, c1b, s1b = shoulder_roots(W[0], W[1], W[2], a, h, tiny, ratio_tol)
        if free1 or (ratio == 0.0 and math.isnan(q1a)):
            status = 1  # joint 1 free, or the shoulder equation independent of q1
        if abs(abs(ratio) - 1.0) < DOUBLE_ROOT:
            status = 1  # next to a double root (DOUBLE_ROOT: beyond it both roots are verified as they are)
        if rho_w < 1e-12:
            status = 1
        ncand = 0
        for k in range(8):
            ok[k] = False
        for s1 in range(2 if status == 0 else 0):
            q1, c1, s1c = (q1a, c1a, s1a) if s1 == 0 else (q1b, c1b, s1b)
            if math.isnan(q1):
                continue
            g0, g1 = elbow_plane(c1, s1c, W[0], W[1], W[2], R1, p1)
            q3a, q3b, x, c3a, s3a, c3b, s3b = elbow_roots(math.sqrt(g0 * g0 + g1 * g1), na, nb, base3, cb3, sb3,
                                                          ratio_tol)
            if math.isnan(x):
                continue
            if x < 1e-6 or math.pi - x < 1e-6:
                status = 1  # folded or stretched elbow: a double root
            for s3 in range(2):
                q3, c3, s3v = (q3a, c3a, s3a) if s3 == 0 else (q3b, c3b, s3b)
                q2, free2, _vxy, c2, s2v = elbow_q2(g0, g1, c3, s3v, R2, p2, P, tiny)
                if free2:
                    status = 1
                # R_0_3 = C0 Rz(q1) C1 Rz(q2) C2 Rz(q3) C3, column by column
                for i in range(3):
                    cx[i], cy[i], cz[i] = consts[0, i, 0], consts[0, i, 1], consts[0, i, 2]
                for kk in range(3):
                    ck, sk = (c1, s1c) if kk == 0 else ((c2, s2v) if kk == 1 else (c3, s3v))
                    for i in range(3):
                        xi, yi = cx[i], cy[i]
                        cx[i], cy[i] = ck * xi + sk * yi, ck * yi - sk * xi
                    m = kk + 1  # consts[m] indexed, not sliced: a view is an atomic reference count
                    c00, c01, c02 = consts[m, 0, 0], consts[m, 0, 1], consts[m, 0, 2]
                    c10, c11, c12 = consts[m, 1, 0], consts[m, 1, 1], consts[m, 1, 2]
                    c20, c21, c22 = consts[m, 2, 0], consts[m, 2, 1], consts[m, 2, 2]
                    for i in range(3):
                        xi, yi, zi = cx[i], cy[i], cz[i]
                        cx[i] = xi * c00 + yi * c10 + zi * c20
                        cy[i] = xi * c01 + yi * c11 + zi * c21
                        cz[i] = xi * c02 + yi * c12 + zi * c22
                for j in range(3):
                    M[0, j] = cx[0] * Y[0, j] + cx[1] * Y[1, j] + cx[2] * Y[2, j]
                    M[1, j] = cy[0] * Y[0, j] + cy[1] * Y[1, j] + cy[2] * Y[2, j]
                    M[2, j] = cz[0] * Y[0, j] + cz[1] * Y[1, j] + cz[2] * Y[2, j]
                qba, qbb, _lo, _hi, cba, sba, cbb, sbb = wrist_qb(M[0, 2], M[1, 2], M[2, 2], wc, WRIST_TOL)
                if math.isnan(qba):
                    continue
                for s5 in range(2):
                    qb, cb, sb = (qba, cba, sba) if s5 == 0 else (qbb, cbb, sbb)
                    qa, qc, singular, _sign, _vxy, _cb, _sb, ca, sa, cc, sc = wrist_rest(
                        qb, cb, sb, M[0, 0], M[1, 0], M[2, 0], M[0, 2], M[1, 2], R4, R5)
                    if singular:
                        status = 1  # wrist singular: a continuum
                    cand[ncand, 0], cand[ncand, 1], cand[ncand, 2] = q1, q2, q3
                    cand[ncand, 3], cand[ncand, 4], cand[ncand, 5] = qa, qb, qc
                    # cos, sin of the joints for the verifying FK (of these very floats, or their closed form's
                    # normalised (cos, sin) pairs whose atan2 they are)
                    cs[ncand, 0], cs[ncand, 1], cs[ncand, 2], cs[ncand, 3] = c1, s1c, c2, s2v
                    cs[ncand, 4], cs[ncand, 5], cs[ncand, 6], cs[ncand, 7] = c3, s3v, ca, sa  # qa as computed:
                    cs[ncand, 8], cs[ncand, 9] = cb, sb  # it differs only where singular (handed over)
                    cs[ncand, 10], cs[ncand, 11] = cc, sc
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
