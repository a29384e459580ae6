"""The elbow kernel's verification and labels as stages over a chunk of poses, after
:mod:`._ik_nb_elbow_stages` and in its structure-of-arrays scratch: for every branch of every pose of the chunk the
FK of the chain (the walk of :func:`._ik_nb_finish.chain_fk`, the same operations in the same order, from the
closed form's cosines and sines), its position and orientation residuals against the target, whether they verify
it and whether the plain solver would polish it (:func:`._ik_nb_finish.ik_finish`'s tests), and the label code
(shoulder, elbow, wrist: the tests of docs/ik.md, from the frames after joints 1 and 2 of that FK).  Each stage a
loop over the poses with no branch and no libm call (the orientation residual's angle by ``forms.atan2`` where it
is not below 1e-6, its only use then being the polish test's knife edge), which LLVM runs four poses to an AVX2
register; the frames after joint 3 shared by the two wrist roots of an arm branch are computed once, in rows.
Compiled once per machine (``cache=True``), ``error_model="numpy"``.  Imported only where numba is.
"""

from __future__ import annotations

import math

from numba import njit

import numpy as np

from ._ik_finish import FOLD_EDGE
from ._ik_jit import atan2, select
from ._ik_nb_elbow_stages import CHUNK, RC1, RC2, RC3, RCA, RCB, RCC, RF3, RFL, RFL1, RFL2, RLB, RPE, RPO, RQ1, RQ2
from ._ik_nb_elbow_stages import RQ3, RQA, RQB, RQC, RRE, RS1, RS2, RS3, RL2, RSA, RSB, RSC, RT, RVF, RXW

__all__ = ["elbow_checks", "elbow_folds"]

_INV_2PI = 0.5 / math.pi


@njit(cache=True, nogil=True, error_model="numpy")
def elbow_checks(n, K, S):
    """Residuals, verification and polish flags and label codes of every branch of the chunk's first n poses into S
    (rows RF3, RL2, RPE, RRE, RVF, RPO, RLB; the targets' and the candidates' rows from elbow_stages already
    there)."""
    C = K[80:192].reshape((7, 4, 4))  # the chain's constants C0 … C6 (C0 also the kernel's consts[0])
    theta, tols = K[289:295], K[295:303]
    _frame3(n, 0, C, S)
    _frame3(n, 1, C, S)
    _frame3(n, 2, C, S)
    _frame3(n, 3, C, S)
    reach = tols[7]
    c = (math.cos(theta[4]), math.sin(theta[4]), tols[2] * max(1.0, reach), tols[2], reach, 0.05 * max(reach, 1e-3),
         tols[3] * max(reach, 1.0))  # cos, sin of theta5; the verify and polish bounds (ik_finish's)
    _check(n, 0, C, c, S)
    _check(n, 1, C, c, S)
    _check(n, 2, C, c, S)
    _check(n, 3, C, c, S)
    _check(n, 4, C, c, S)
    _check(n, 5, C, c, S)
    _check(n, 6, C, c, S)
    _check(n, 7, C, c, S)


@njit(cache=True, nogil=True, error_model="numpy", inline="always")
def _step(F, c, s, C, m):
    """F Rz(q) C[m] for the 3×4 top F (the tuple (x0, x1, x2, y0, …, z2, p0, p1, p2): columns x, y, z, origin; c, s:
    cos q, sin q), by chain_fk's operations in its order."""
    x0, x1, x2, y0, y1, y2, z0, z1, z2, p0, p1, p2 = F
    x0, y0 = c * x0 + s * y0, c * y0 - s * x0
    x1, y1 = c * x1 + s * y1, c * y1 - s * x1
    x2, y2 = c * x2 + s * y2, c * y2 - s * x2
    a00, a01, a02, a03 = C[m, 0, 0], C[m, 0, 1], C[m, 0, 2], C[m, 0, 3]
    a10, a11, a12, a13 = C[m, 1, 0], C[m, 1, 1], C[m, 1, 2], C[m, 1, 3]
    a20, a21, a22, a23 = C[m, 2, 0], C[m, 2, 1], C[m, 2, 2], C[m, 2, 3]
    p0, p1, p2 = (p0 + x0 * a03 + y0 * a13 + z0 * a23, p1 + x1 * a03 + y1 * a13 + z1 * a23,
                  p2 + x2 * a03 + y2 * a13 + z2 * a23)
    return (x0 * a00 + y0 * a10 + z0 * a20, x1 * a00 + y1 * a10 + z1 * a20, x2 * a00 + y2 * a10 + z2 * a20,
            x0 * a01 + y0 * a11 + z0 * a21, x1 * a01 + y1 * a11 + z1 * a21, x2 * a01 + y2 * a11 + z2 * a21,
            x0 * a02 + y0 * a12 + z0 * a22, x1 * a02 + y1 * a12 + z1 * a22, x2 * a02 + y2 * a12 + z2 * a22,
            p0, p1, p2)


@njit(cache=True, nogil=True, error_model="numpy", inline="always")
def _frame3(n, k2, C, S):
    """For the arm branch k2 = 2 s1 + s3 of each pose: the frame after joint 3 (C0 Rz(q1) C1 Rz(q2) C2 Rz(q3) C3)
    into the rows RF3 + 12 k2, and the shoulder and elbow bits of the label into row RL2 + k2 (the wrist's
    codes are added by _check): 1 shoulder left (x1 · (X − O1) < 0, X the wrist centre, O1 C0's origin), 2 elbow
    down (the origin E of frame 2 on the far side of the line from the origin S of frame 1 to X, seen along axis
    1, normal z1 × (X − S))."""
    o1, o2, of = (k2 >> 1) * CHUNK, k2 * CHUNK, (RF3 + 12 * k2) * CHUNK
    F0 = (C[0, 0, 0], C[0, 1, 0], C[0, 2, 0], C[0, 0, 1], C[0, 1, 1], C[0, 2, 1], C[0, 0, 2], C[0, 1, 2], C[0, 2, 2],
          C[0, 0, 3], C[0, 1, 3], C[0, 2, 3])
    for b in range(n):
        F1 = _step(F0, S[RC1 * CHUNK + o1 + b], S[RS1 * CHUNK + o1 + b], C, 1)
        F2 = _step(F1, S[RC2 * CHUNK + o2 + b], S[RS2 * CHUNK + o2 + b], C, 2)
        F3 = _step(F2, S[RC3 * CHUNK + o2 + b], S[RS3 * CHUNK + o2 + b], C, 3)
        S[of + b], S[of + CHUNK + b], S[of + 2 * CHUNK + b], S[of + 3 * CHUNK + b] = F3[0], F3[1], F3[2], F3[3]
        S[of + 4 * CHUNK + b], S[of + 5 * CHUNK + b], S[of + 6 * CHUNK + b] = F3[4], F3[5], F3[6]
        S[of + 7 * CHUNK + b], S[of + 8 * CHUNK + b], S[of + 9 * CHUNK + b] = F3[7], F3[8], F3[9]
        S[of + 10 * CHUNK + b], S[of + 11 * CHUNK + b] = F3[10], F3[11]
        X0, X1, X2 = S[RXW * CHUNK + b], S[(RXW + 1) * CHUNK + b], S[(RXW + 2) * CHUNK + b]
        s_right = F1[0] * (X0 - F0[9]) + F1[1] * (X1 - F0[10]) + F1[2] * (X2 - F0[11])
        d0, d1, d2 = X0 - F1[9], X1 - F1[10], X2 - F1[11]
        n0, n1, n2 = F1[7] * d2 - F1[8] * d1, F1[8] * d0 - F1[6] * d2, F1[6] * d1 - F1[7] * d0
        towards = select(F0[6] * n0 + F0[7] * n1 + F0[8] * n2 >= 0.0, 1.0, -1.0)
        side = (F2[9] - F1[9]) * n0 + (F2[10] - F1[10]) * n1 + (F2[11] - F1[11]) * n2
        S[(RL2 + k2) * CHUNK + b] = select(s_right < 0.0, 1.0, 0.0) + select(side * towards < 0.0, 2.0, 0.0)


@njit(cache=True, nogil=True, error_model="numpy", inline="always")
def _check(n, k, C, c, S):
    """For the branch k = 2 k2 + s5 of each pose: the FK from the frame after joint 3 on (joints qa, qb, qc), its
    residuals against the target (rows RPE, RRE: ik_finish's), 1.0 in row RVF where they verify it, in row RPO where
    the plain solver would polish it, and the label code in row RLB (the wrist bit 4 where sin(q5 + theta5) < 0)."""
    ct5, st5, pe_tol, re_tol, reach, polish_below, polish_above = c
    ok, f3 = k * CHUNK, (RF3 + 12 * (k >> 1)) * CHUNK
    for b in range(n):
        F = (S[f3 + b], S[f3 + CHUNK + b], S[f3 + 2 * CHUNK + b], S[f3 + 3 * CHUNK + b], S[f3 + 4 * CHUNK + b],
             S[f3 + 5 * CHUNK + b], S[f3 + 6 * CHUNK + b], S[f3 + 7 * CHUNK + b], S[f3 + 8 * CHUNK + b],
             S[f3 + 9 * CHUNK + b], S[f3 + 10 * CHUNK + b], S[f3 + 11 * CHUNK + b])
        cb, sb = S[RCB * CHUNK + ok + b], S[RSB * CHUNK + ok + b]
        F = _step(F, S[RCA * CHUNK + ok + b], S[RSA * CHUNK + ok + b], C, 4)
        F = _step(F, cb, sb, C, 5)
        x0, x1, x2, y0, y1, y2, z0, z1, z2, p0, p1, p2 = _step(F, S[RCC * CHUNK + ok + b], S[RSC * CHUNK + ok + b],
                                                               C, 6)
        t = (S[RT * CHUNK + b], S[(RT + 1) * CHUNK + b], S[(RT + 2) * CHUNK + b], S[(RT + 3) * CHUNK + b],
             S[(RT + 4) * CHUNK + b], S[(RT + 5) * CHUNK + b], S[(RT + 6) * CHUNK + b], S[(RT + 7) * CHUNK + b],
             S[(RT + 8) * CHUNK + b], S[(RT + 9) * CHUNK + b], S[(RT + 10) * CHUNK + b], S[(RT + 11) * CHUNK + b])
        pe = math.sqrt((p0 - t[3]) ** 2 + (p1 - t[7]) ** 2 + (p2 - t[11]) ** 2)
        # the angle of R_t Rᵀ, summed in ik_finish's order
        tr = 0.0 + t[0] * x0 + t[1] * y0 + t[2] * z0 + t[4] * x1 + t[5] * y1 + t[6] * z1 + t[8] * x2 + t[9] * y2 \
            + t[10] * z2
        v0 = ((0.0 + (t[8] * x1 - t[4] * x2)) + (t[9] * y1 - t[5] * y2)) + (t[10] * z1 - t[6] * z2)
        v1 = ((0.0 + (t[0] * x2 - t[8] * x0)) + (t[1] * y2 - t[9] * y0)) + (t[2] * z2 - t[10] * z0)
        v2 = ((0.0 + (t[4] * x0 - t[0] * x1)) + (t[5] * y0 - t[1] * y1)) + (t[6] * z0 - t[2] * z1)
        sn, co = 0.5 * math.sqrt(v0 * v0 + v1 * v1 + v2 * v2), 0.5 * (tr - 1.0)
        re = select(sn < 1e-6 * co, sn / co, atan2(sn, co))  # atan(t) = t (1 - t²/3 ...): t below 1e-6, t
        size = pe + reach * re
        S[RPE * CHUNK + ok + b], S[RRE * CHUNK + ok + b] = pe, re
        S[RVF * CHUNK + ok + b] = select((pe <= pe_tol) & (re <= re_tol), 1.0, 0.0)
        S[RPO * CHUNK + ok + b] = select((size < polish_below) & (size > polish_above), 1.0, 0.0)
        S[RLB * CHUNK + ok + b] = S[(RL2 + (k >> 1)) * CHUNK + b] + select(sb * ct5 + cb * st5 < 0.0, 4.0, 0.0)


@njit(cache=True, nogil=True, error_model="numpy")
def elbow_folds(n, K, S):
    """Every branch's joints of the chunk's first n poses folded into the limits in place (the rows RQ1 … RQC;
    :func:`._ik_nb_finish.ik_sorted`'s fold of a revolute joint, the same operations), and per branch whether all
    of its joints lie within them and whether one lies within FOLD_EDGE of a decision of the folding (rows RFL).
    The elbow class is 6R (joints 1-3 revolute with axes 2 ∥ 3, a spherical wrist)."""
    lo, hi = K[271:277], K[277:283]
    _fold1(n, 0, lo[0], hi[0], S)
    _fold1(n, 1, lo[0], hi[0], S)
    _fold2(n, 0, lo[1], hi[1], lo[2], hi[2], S)
    _fold2(n, 1, lo[1], hi[1], lo[2], hi[2], S)
    _fold2(n, 2, lo[1], hi[1], lo[2], hi[2], S)
    _fold2(n, 3, lo[1], hi[1], lo[2], hi[2], S)
    lims = (lo[3], hi[3], lo[4], hi[4], lo[5], hi[5])
    _fold3(n, 0, lims, S)
    _fold3(n, 1, lims, S)
    _fold3(n, 2, lims, S)
    _fold3(n, 3, lims, S)
    _fold3(n, 4, lims, S)
    _fold3(n, 5, lims, S)
    _fold3(n, 6, lims, S)
    _fold3(n, 7, lims, S)


@njit(cache=True, nogil=True, error_model="numpy", inline="always")
def _fold(x, lo, hi):
    """(x folded, inside, near an edge) for a revolute joint x with limits lo, hi: wrapped into (−π, π] (as
    _ik_nb_finish._wrap), then shifted by a whole turn where that brings it inside (as _ik_nb_finish._fold, with
    selects for its branches); near an edge: within FOLD_EDGE of ±π or of a limit, itself or a whole turn off."""
    y = math.pi - x
    x = math.pi - (y - 2.0 * math.pi * np.floor(y * _INV_2PI))
    edge = (math.pi - abs(x) < FOLD_EDGE) | (abs(x + -2.0 * math.pi - lo) < FOLD_EDGE) \
        | (abs(x + -2.0 * math.pi - hi) < FOLD_EDGE) | (abs(x + 0.0 - lo) < FOLD_EDGE) \
        | (abs(x + 0.0 - hi) < FOLD_EDGE) | (abs(x + 2.0 * math.pi - lo) < FOLD_EDGE) \
        | (abs(x + 2.0 * math.pi - hi) < FOLD_EDGE)
    up = x + 2.0 * math.pi
    x = select(((x < lo - 1e-12) | (x > hi + 1e-12)) & (lo <= up) & (up <= hi), up, x)
    down = x - 2.0 * math.pi
    x = select(((x < lo - 1e-12) | (x > hi + 1e-12)) & (lo <= down) & (down <= hi), down, x)
    return x, (lo - 1e-12 <= x) & (x <= hi + 1e-12), edge


@njit(cache=True, nogil=True, error_model="numpy", inline="always")
def _fold1(n, s1, lo, hi, S):
    """q1 of the shoulder root s1 folded; row RFL1 + s1: 1.0 inside, plus 2.0 near an edge."""
    for b in range(n):
        x, inside, edge = _fold(S[(RQ1 + s1) * CHUNK + b], lo, hi)
        S[(RQ1 + s1) * CHUNK + b] = x
        S[(RFL1 + s1) * CHUNK + b] = select(inside, 1.0, 0.0) + select(edge, 2.0, 0.0)


@njit(cache=True, nogil=True, error_model="numpy", inline="always")
def _fold2(n, k2, lo2, hi2, lo3, hi3, S):
    """q2, q3 of the arm branch k2 folded; row RFL2 + k2: q1 to q3 all inside (1.0), plus 2.0 if one is near an
    edge."""
    for b in range(n):
        x2, in2, e2 = _fold(S[(RQ2 + k2) * CHUNK + b], lo2, hi2)
        x3, in3, e3 = _fold(S[(RQ3 + k2) * CHUNK + b], lo3, hi3)
        f1 = S[(RFL1 + (k2 >> 1)) * CHUNK + b]
        S[(RQ2 + k2) * CHUNK + b], S[(RQ3 + k2) * CHUNK + b] = x2, x3
        S[(RFL2 + k2) * CHUNK + b] = select(in2 & in3 & ((f1 == 1.0) | (f1 == 3.0)), 1.0, 0.0) \
            + select(e2 | e3 | (f1 >= 2.0), 2.0, 0.0)


@njit(cache=True, nogil=True, error_model="numpy", inline="always")
def _fold3(n, k, lims, S):
    """qa, qb, qc of the branch k folded; row RFL + k: all six joints inside (1.0), plus 2.0 if one is near an
    edge."""
    for b in range(n):
        xa, ina, ea = _fold(S[(RQA + k) * CHUNK + b], lims[0], lims[1])
        xb, inb, eb = _fold(S[(RQB + k) * CHUNK + b], lims[2], lims[3])
        xc, inc, ec = _fold(S[(RQC + k) * CHUNK + b], lims[4], lims[5])
        f2 = S[(RFL2 + (k >> 1)) * CHUNK + b]
        S[(RQA + k) * CHUNK + b], S[(RQB + k) * CHUNK + b], S[(RQC + k) * CHUNK + b] = xa, xb, xc
        S[(RFL + k) * CHUNK + b] = select(ina & inb & inc & ((f2 == 1.0) | (f2 == 3.0)), 1.0, 0.0) \
            + select(ea | eb | ec | (f2 >= 2.0), 2.0, 0.0)
