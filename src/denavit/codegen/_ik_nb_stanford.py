"""The Stanford-class closed form (R R P with axes 1, 2 meeting, spherical wrist) compiled by numba, once per
machine (``cache=True``): see :mod:`._ik_stanford` for the method and the hand-over rules; the formulas of
:mod:`denavit.ik.forms` (jitted through :mod:`._ik_jit`), verified, folded, merged and sorted by
:func:`._ik_nb_finish.ik_finish`.  The constants (``STANFORD_LAYOUT``) are arguments.  Imported only where numba is.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from ._ik_finish import DOUBLE_ROOT
from ._ik_jit import (
    WRIST_TOL,
    stanford_q1,
    stanford_q2,
    stanford_q3,
    wrist_constants,
    wrist_qb,
    wrist_rest,
)
from ._ik_nb_finish import ik_finish
from ._ik_nb_parallel import frame1, next_frame

__all__ = ["ik_stanford_packed"]

#: |x1 . (X - O1)| (relative) under which the shoulder label is on its knife edge and the pose goes to the plain solver
#: (seed 273 of test_random_stanford_class_arms_compiled_equals_plain: q2 = 3e-15 against the plain solver's -9e-16
#: on the singular set q2 = 0, labelled left against right)
LABEL_EDGE = 1e-12



@njit(cache=True, nogil=True)
def ik_stanford_packed(T, K, f, i):
    """All solutions of each pose T[b] of a Stanford-class arm, the constants in K (STANFORD_LAYOUT order); outputs
    as ik_elbow_packed (label codes: 1 shoulder left, 2 wrist flip)."""
    X_e, C0i, C = K[0:3], K[3:19].reshape((4, 4)), K[19:131].reshape((7, 4, 4))
    geom, sc, lo_lim, hi_lim = K[131:140], K[140:149], K[149:155], K[155:161]
    rev, theta, tols, far = K[161:167], K[167:173], K[173:181], K[181]
    ws = np.empty(159)
    cand, cerr, X, F = ws[0:48].reshape((8, 6)), ws[48:64].reshape((8, 2)), ws[64:67], ws[67:83].reshape((4, 4))
    perm, vr = ws[131:139], ws[139:159]
    flags = np.zeros(24, dtype=np.bool_)
    w = np.empty((23, 36))
    frames = w[0:8]  # ik_finish's frames after joints 1-3 (unused here: the labels need q1 only)
    cs, P = w[8:16, 0:12], w[16:23, 0:12]  # cos, sin of each candidate's joints (ik_finish's, for its FK); its FK's
    fq, fe, fo, rank = f[:, :, :6], f[:, :, 6:8], f[:, :, 8:], i[:, 11:20]
    for b in range(T.shape[0]):
        if not math.sqrt(T[b, 0, 3] ** 2 + T[b, 1, 3] ** 2 + T[b, 2, 3] ** 2) <= far:
            i[b, 8], i[b, 9], i[b, 10] = 0, 0, 1  # beyond the bound of _solve (prismatic travel included): its stand-in
            continue
        for r in range(3):
            X[r] = T[b, r, 0] * X_e[0] + T[b, r, 1] * X_e[1] + T[b, r, 2] * X_e[2] + T[b, r, 3]
        ncand, status = _stanford_candidates(T[b], X, C0i, C, geom, sc, tols, cand, ws[89:131])
        kept, n_out, st = ik_finish(T, b, cand, cerr, ncand, lo_lim, hi_lim, rev, tols, F, frames, flags,
                                    fq, fe, fo, perm, C, cs, False, rank, P, vr)
        for s in range(kept):
            i[b, s] = _stanford_label(f[b, s, :6], X, C, theta)
            if i[b, s] < 0.0:  # the shoulder label on its knife edge: the plain solver's rounding decides
                status = 1
        i[b, 8], i[b, 9], i[b, 10] = kept, n_out, max(status, st)


@njit(cache=True, nogil=True)
def _stanford_candidates(Tb, X, C0i, C, geom, sc, tols, cand, ws):
    """The candidates of one pose in the plain plan's order (q3 root, q2 root, wrist root; + before -) into cand
    (ws: 42 floats of scratch); returns (count, status)."""
    uz, uperp, L, rho_w, base_w, br, bu, near = sc[0], sc[1], sc[2], sc[3], sc[4], sc[5], sc[6], sc[7]
    wc = wrist_constants(rho_w, base_w, br, bu)
    tol = tols[1]
    wide = near * L
    D, Y, cols, M = ws[0:3], ws[3:12].reshape((3, 3)), ws[12:24].reshape((4, 3)), ws[24:33].reshape((3, 3))
    for r in range(3):  # wrist centre from O, in the frame of C0
        D[r] = C0i[r, 0] * X[0] + C0i[r, 1] * X[1] + C0i[r, 2] * X[2] + C0i[r, 3] - geom[r]
    for r in range(3):  # T_R C6_R^T
        for j in range(3):
            Y[r, j] = Tb[r, 0] * C[6, j, 0] + Tb[r, 1] * C[6, j, 1] + Tb[r, 2] * C[6, j, 2]
    status = 0
    if math.hypot(D[0], D[1]) < wide or rho_w < 1e-12:
        return 0, 1  # wrist centre on or next to axis 1: q1 free or ill-conditioned
    # the closed form of denavit.ik.forms (the plain solver's own functions, jitted): q3, then q2, then q1
    q3a, q3b, disc, root = stanford_q3(D[0], D[1], D[2], uz, uperp, L)
    if disc < near * L * L:
        status = 1  # q3 next to its double root (or none)
    if math.isnan(q3a):
        return 0, status
    e3 = 1.0 + L / max(root, 1e-300)  # rounding error of q3 [eps, per L]: as COND_MAX of _ik_parallel
    ncand = 0
    for s3 in range(2):
        q3 = q3a if s3 == 0 else q3b
        w0, w1, w2 = geom[3] + q3 * geom[6], geom[4] + q3 * geom[7], geom[5] + q3 * geom[8]
        if math.hypot(w0, w1) < wide:
            status = 1  # the arm next to axis 2: q2 free or ill-conditioned
        q2a, q2b, rho, ratio = stanford_q2(w0, w1, w2, D[2], C[1, 2, :3], tol)
        if rho <= 1e-12:
            status = 1
            continue
        if abs(abs(ratio) - 1.0) < DOUBLE_ROOT:
            status = 1  # next to a double root of q2
        if math.isnan(q2a):
            continue
        delta = math.acos(min(1.0, max(-1.0, ratio)))
        e2 = (1.0 + e3) * max(1.0, L / rho) / max(math.sin(delta), 1e-300)
        for s2 in range(2):
            q2 = q2a if s2 == 0 else q2b
            c2, s2v = math.cos(q2), math.sin(q2)
            q1, ex, ey = stanford_q1(q2, w0, w1, w2, D[0], D[1], C[1, :3, :3])
            e1 = (1.0 + e2 + e3) * L / max(min(math.hypot(D[0], D[1]), math.hypot(ex, ey)), 1e-300)
            # R_0_3 = C0 Rz(q1) C1 Rz(q2) C2 C3 (joint 3 slides): its columns, then M = R_0_3^T Y
            frame1(C, math.cos(q1), math.sin(q1), cols)
            next_frame(cols, c2, s2v, C[2], cols)
            next_frame(cols, 1.0, 0.0, C[3], cols)  # joint 3 slides: no turn
            for r in range(3):
                for j in range(3):
                    M[r, j] = cols[r, 0] * Y[0, j] + cols[r, 1] * Y[1, j] + cols[r, 2] * Y[2, j]
            ncand, status = _stanford_wrist(M, C, q1, q2, q3, wc, near, cand, ncand, status,
                                            1.0 + e1 + e2 + e3, sc[8])
    return ncand, status


@njit(cache=True, nogil=True)
def _stanford_wrist(M, C, q1, q2, q3, wc, near, cand, ncand, status, eM, cond_max):
    """The two wrist solutions of Rz(q4) R4 Rz(q5) R5 Rz(q6) = M (as wrist_angles: q5 from the z-row in the
    half-angle form, q4 turns R4 Rz(q5) R5 e_z onto M e_z, q6 from the x-row), appended to cand; eM: the
    rounding error of M [eps], for the COND_MAX test."""
    qba, qbb, lo, hi, cba, sba, cbb, sbb = wrist_qb(M[0, 2], M[1, 2], M[2, 2], wc, WRIST_TOL)  # denavit.ik.forms
    if -2e-7 < min(lo, hi) < 1e-12:
        status = 1  # the two wrist roots (nearly) coincide
    if math.isnan(qba):
        return ncand, status
    e5 = eM / max(wc[0] * math.sin(0.5 * (qba - qbb)), 1e-300)
    for s5 in range(2):
        qb, cb, sb = (qba, cba, sba) if s5 == 0 else (qbb, cbb, sbb)
        qa, qc, _singular, _sign, vxy, _cb, _sb, _ca, _sa, _cc, _sc = wrist_rest(
            qb, cb, sb, M[0, 0], M[1, 0], M[2, 0], M[0, 2], M[1, 2], C[4, :3, :3], C[5, :3, :3])
        if vxy < near:
            status = 1  # wrist singular (axes 4 and 6 aligned): a continuum, or next to one
        if eM + e5 + (eM + e5) / max(vxy, 1e-300) > cond_max:
            status = 1  # ill-conditioned (COND_MAX): the two solvers' rounding could differ by > 1e-10
        cand[ncand, 0], cand[ncand, 1], cand[ncand, 2] = q1, q2, q3
        cand[ncand, 3], cand[ncand, 4], cand[ncand, 5] = qa, qb, qc
        ncand += 1
    return ncand, status


@njit(cache=True, nogil=True)
def _stanford_label(qs, X, C, theta):
    """Label code of one solution (docs/ik.md): 1 shoulder left (x1 . (X - O1) < 0, X the wrist centre),
    2 wrist flip (sin(q5 + theta5) < 0); -1 where |x1 . (X - O1)| is below LABEL_EDGE times the arm's size (the wrist
    centre next to the plane that decides the shoulder label: a rounding difference could flip it)."""
    c1, s1 = math.cos(qs[0]), math.sin(qs[0])
    s_right = 0.0
    for r in range(3):
        x, y, z = C[0, r, 0], C[0, r, 1], C[0, r, 2]
        x, y = c1 * x + s1 * y, c1 * y - s1 * x
        s_right += (x * C[1, 0, 0] + y * C[1, 1, 0] + z * C[1, 2, 0]) * (X[r] - C[0, r, 3])
    if abs(s_right) < LABEL_EDGE * (1.0 + abs(X[0] - C[0, 0, 3]) + abs(X[1] - C[0, 1, 3]) + abs(X[2] - C[0, 2, 3])):
        return -1
    code = 1 if s_right < 0.0 else 0
    if math.sin(qs[4] + theta[4]) < 0.0:
        code |= 2
    return code
