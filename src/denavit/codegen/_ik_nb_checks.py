"""The verification, labels and fold of a staged closed-form kernel (the elbow kernel, :mod:`._ik_nb_elbow`, and
the UR-class kernel, :mod:`._ik_nb_parallel`) as stages over a chunk of poses, in the kernel's structure-of-arrays
scratch (row ``R`` of CHUNK floats at ``S[R * CHUNK:]``): for every branch of every pose of the chunk the FK of the
chain (the walk of :func:`._ik_nb_finish.chain_fk`, the same operations in the same order, from the closed form's
cosines and sines), its position and orientation residuals against the target, whether they verify it and whether
the plain solver would polish it (:func:`._ik_nb_finish.ik_finish`'s tests), the label code (shoulder, elbow,
wrist: the tests of docs/ik.md, from the frames after joints 1, 2 and 3 of that FK), and the joints folded into
the limits.  Each stage a loop over the poses with no branch and no libm call (the orientation residual's angle by
``forms.atan2`` where it is not below 1e-6, its only use then being the polish test's knife edge), which LLVM runs
four poses to an AVX2 register; the frames after joint 3 shared by several branches are computed once, in rows.

Where a kernel keeps its rows is its ``layout`` (a tuple of ints, a global constant of the kernel's module: inlined,
its entries are constants, so each loop's rows lie at constant offsets): (RT, RX, RF3, RL2, RPE, RRE, RVF, RPO, RLB,
RFL1, RFL2, RFL, W3), then per joint j (RQ, RC, RS, SH) at 13 + 4 j: the joint's rows of values, cosines and sines,
branch k's at row ``R + (k >> SH)`` (the branches k = 0 … 7 share a joint's value in groups of 2^SH).  RT: the
target's top 3×4; RX: the point of the shoulder label (the wrist centre, or the UR arm's Q); RF3: the frames after
joint 3 (12 rows per group of joint 3); RL2: the shoulder and elbow bits of the label per group of joint 3; RPE,
RRE, RVF, RPO, RLB: per branch the residuals, the verified and polish flags, the label code; RFL1, RFL2, RFL: the
fold's flags per group of joint 1, per group of the middle level, per branch; W3: 1 where the elbow label's far
point W is the origin of frame 3 (the UR arm's), 0 where it is RX (the wrist centre).  The fold runs in three
levels of joints (``groups``: the two joints shared in pairs of branches, then the three of each branch).
Compiled once per machine (``cache=True``), ``error_model="numpy"``.  Imported only where numba is.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from ._ik_finish import FOLD_EDGE
from ._ik_jit import atan2, select

__all__ = ["CHUNK", "chain_step", "copy_targets", "stage_checks", "stage_folds", "take_branch"]

#: poses per chunk of the stages (the elbow kernel's scratch: 279 × CHUNK floats, 36 kB, in L1)
CHUNK = 16
_INV_2PI = 0.5 / math.pi


@njit(cache=True, nogil=True, inline="always")
def copy_targets(T, s, n, S, rt):
    """The top 3×4 of the targets T[s:s + n] into the rows rt … rt + 11 of S, row-major (then the stages read no
    other array; a loop reading T stays scalar: its run-time strides)."""
    for b in range(n):
        t = s + b
        for i in range(3):
            S[(rt + 4 * i) * CHUNK + b], S[(rt + 4 * i + 1) * CHUNK + b] = T[t, i, 0], T[t, i, 1]
            S[(rt + 4 * i + 2) * CHUNK + b], S[(rt + 4 * i + 3) * CHUNK + b] = T[t, i, 2], T[t, i, 3]


@njit(cache=True, nogil=True, error_model="numpy", inline="always")
def stage_checks(n, C, theta, tols, S, L):
    """Residuals, verification and polish flags and label codes of every branch of the chunk's first n poses into S
    (rows RF3, RL2, RPE, RRE, RVF, RPO, RLB of the layout L; the targets' and the candidates' rows already there); C
    (7, 4, 4) the chain's constants, theta the joints' offsets, tols ik_finish's."""
    groups = 8 >> L[13 + 4 * 2 + 3]  # of joint 3 (a constant: each call a loop at constant offsets)
    _frame3(n, 0, C, S, L)
    _frame3(n, 1, C, S, L)
    if groups > 2:
        _frame3(n, 2, C, S, L)
        _frame3(n, 3, C, S, L)
    if groups > 4:
        _frame3(n, 4, C, S, L)
        _frame3(n, 5, C, S, L)
        _frame3(n, 6, C, S, L)
        _frame3(n, 7, C, S, L)
    reach = tols[7]
    c = (math.cos(theta[4]), math.sin(theta[4]), tols[2] * max(1.0, reach), tols[2], reach, 0.05 * max(reach, 1e-3),
         tols[3] * max(reach, 1.0))  # cos, sin of theta5; the verify and polish bounds (ik_finish's)
    _check(n, 0, C, c, S, L)
    _check(n, 1, C, c, S, L)
    _check(n, 2, C, c, S, L)
    _check(n, 3, C, c, S, L)
    _check(n, 4, C, c, S, L)
    _check(n, 5, C, c, S, L)
    _check(n, 6, C, c, S, L)
    _check(n, 7, C, c, S, L)


@njit(cache=True, nogil=True, error_model="numpy", inline="always")
def _rows(L, j, k):
    """Rows of joint j's value, cosine and sine for branch k in the layout L."""
    d = k >> L[16 + 4 * j]
    return L[13 + 4 * j] + d, L[14 + 4 * j] + d, L[15 + 4 * j] + d


@njit(cache=True, nogil=True, error_model="numpy", inline="always")
def chain_step(F, c, s, C, m):
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
def _frame3(n, f, C, S, L):
    """For the group f of joint 3 (its branches k = f << SH3 …) of each pose: the frame after joint 3 (C0 Rz(q1) C1
    Rz(q2) C2 Rz(q3) C3) into the rows RF3 + 12 f, and the shoulder and elbow bits of the label into row RL2 + f
    (the wrist's are added by _check): 1 shoulder left (x1 · (X − O1) < 0, X the point of row RX, O1 C0's origin),
    2 elbow down (the origin E of frame 2 on the far side of the line from the origin S of frame 1 to W, seen along
    axis 1, normal z1 × (W − S); W = X, or the origin of frame 3 where W3)."""
    k = f << L[13 + 4 * 2 + 3]
    r1, r2, r3 = _rows(L, 0, k), _rows(L, 1, k), _rows(L, 2, k)
    rx, of, w3 = L[1] * CHUNK, (L[2] + 12 * f) * CHUNK, L[12]
    F0 = (C[0, 0, 0], C[0, 1, 0], C[0, 2, 0], C[0, 0, 1], C[0, 1, 1], C[0, 2, 1], C[0, 0, 2], C[0, 1, 2], C[0, 2, 2],
          C[0, 0, 3], C[0, 1, 3], C[0, 2, 3])
    for b in range(n):
        F1 = chain_step(F0, S[r1[1] * CHUNK + b], S[r1[2] * CHUNK + b], C, 1)
        F2 = chain_step(F1, S[r2[1] * CHUNK + b], S[r2[2] * CHUNK + b], C, 2)
        F3 = chain_step(F2, S[r3[1] * CHUNK + b], S[r3[2] * CHUNK + b], C, 3)
        S[of + b], S[of + CHUNK + b], S[of + 2 * CHUNK + b], S[of + 3 * CHUNK + b] = F3[0], F3[1], F3[2], F3[3]
        S[of + 4 * CHUNK + b], S[of + 5 * CHUNK + b], S[of + 6 * CHUNK + b] = F3[4], F3[5], F3[6]
        S[of + 7 * CHUNK + b], S[of + 8 * CHUNK + b], S[of + 9 * CHUNK + b] = F3[7], F3[8], F3[9]
        S[of + 10 * CHUNK + b], S[of + 11 * CHUNK + b] = F3[10], F3[11]
        X0, X1, X2 = S[rx + b], S[rx + CHUNK + b], S[rx + 2 * CHUNK + b]
        s_right = F1[0] * (X0 - F0[9]) + F1[1] * (X1 - F0[10]) + F1[2] * (X2 - F0[11])
        if w3:
            d0, d1, d2 = F3[9] - F1[9], F3[10] - F1[10], F3[11] - F1[11]
        else:
            d0, d1, d2 = X0 - F1[9], X1 - F1[10], X2 - F1[11]
        n0, n1, n2 = F1[7] * d2 - F1[8] * d1, F1[8] * d0 - F1[6] * d2, F1[6] * d1 - F1[7] * d0
        towards = select(F0[6] * n0 + F0[7] * n1 + F0[8] * n2 >= 0.0, 1.0, -1.0)
        side = (F2[9] - F1[9]) * n0 + (F2[10] - F1[10]) * n1 + (F2[11] - F1[11]) * n2
        S[(L[3] + f) * CHUNK + b] = select(s_right < 0.0, 1.0, 0.0) + select(side * towards < 0.0, 2.0, 0.0)


@njit(cache=True, nogil=True, error_model="numpy", inline="always")
def _check(n, k, C, c, S, L):
    """For the branch k of each pose: the FK from the frame after joint 3 on (joints 4, 5, 6), its residuals
    against the target (rows RPE, RRE: ik_finish's), 1.0 in row RVF where they verify it, in row RPO where the
    plain solver would polish it, and the label code in row RLB (the wrist bit 4 where sin(q5 + theta5) < 0)."""
    ct5, st5, pe_tol, re_tol, reach, polish_below, polish_above = c
    f = k >> L[13 + 4 * 2 + 3]
    r4, r5, r6 = _rows(L, 3, k), _rows(L, 4, k), _rows(L, 5, k)
    ok, f3, rt = k * CHUNK, (L[2] + 12 * f) * CHUNK, L[0] * CHUNK
    for b in range(n):
        F = (S[f3 + b], S[f3 + CHUNK + b], S[f3 + 2 * CHUNK + b], S[f3 + 3 * CHUNK + b], S[f3 + 4 * CHUNK + b],
             S[f3 + 5 * CHUNK + b], S[f3 + 6 * CHUNK + b], S[f3 + 7 * CHUNK + b], S[f3 + 8 * CHUNK + b],
             S[f3 + 9 * CHUNK + b], S[f3 + 10 * CHUNK + b], S[f3 + 11 * CHUNK + b])
        cb, sb = S[r5[1] * CHUNK + b], S[r5[2] * CHUNK + b]
        F = chain_step(F, S[r4[1] * CHUNK + b], S[r4[2] * CHUNK + b], C, 4)
        F = chain_step(F, cb, sb, C, 5)
        x0, x1, x2, y0, y1, y2, z0, z1, z2, p0, p1, p2 = chain_step(F, S[r6[1] * CHUNK + b], S[r6[2] * CHUNK + b],
                                                                    C, 6)
        t = (S[rt + b], S[rt + CHUNK + b], S[rt + 2 * CHUNK + b], S[rt + 3 * CHUNK + b], S[rt + 4 * CHUNK + b],
             S[rt + 5 * CHUNK + b], S[rt + 6 * CHUNK + b], S[rt + 7 * CHUNK + b], S[rt + 8 * CHUNK + b],
             S[rt + 9 * CHUNK + b], S[rt + 10 * CHUNK + b], S[rt + 11 * CHUNK + b])
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
        S[L[4] * CHUNK + ok + b], S[L[5] * CHUNK + ok + b] = pe, re
        S[L[6] * CHUNK + ok + b] = select((pe <= pe_tol) & (re <= re_tol), 1.0, 0.0)
        S[L[7] * CHUNK + ok + b] = select((size < polish_below) & (size > polish_above), 1.0, 0.0)
        S[L[8] * CHUNK + ok + b] = S[(L[3] + f) * CHUNK + b] + select(sb * ct5 + cb * st5 < 0.0, 4.0, 0.0)


@njit(cache=True, nogil=True, error_model="numpy", inline="always")
def stage_folds(n, lo, hi, S, L, G):
    """Every branch's joints of the chunk's first n poses folded into the limits lo, hi in place (the joints' rows
    RQ of the layout L; :func:`._ik_nb_finish.ik_sorted`'s fold of a revolute joint, the same operations), and per
    branch whether all of its joints lie within them and whether one lies within FOLD_EDGE of a decision of the
    folding (rows RFL1, RFL2, RFL).  Levels: joint 1 (SH 2), the joints G[0], G[1] (SH 1), then G[2], G[3], G[4]
    (SH 0).  The kernels' arms are 6R."""
    q1, a, b, c, d, e = L[13], L[13 + 4 * G[0]], L[13 + 4 * G[1]], L[13 + 4 * G[2]], L[13 + 4 * G[3]], \
        L[13 + 4 * G[4]]
    f1, f2, f3 = L[9], L[10], L[11]
    _fold1(n, 0, q1, lo[0], hi[0], f1, S)
    _fold1(n, 1, q1, lo[0], hi[0], f1, S)
    l2 = (lo[G[0]], hi[G[0]], lo[G[1]], hi[G[1]])
    _fold2(n, 0, a, b, l2, f1, f2, S)
    _fold2(n, 1, a, b, l2, f1, f2, S)
    _fold2(n, 2, a, b, l2, f1, f2, S)
    _fold2(n, 3, a, b, l2, f1, f2, S)
    l3 = (lo[G[2]], hi[G[2]], lo[G[3]], hi[G[3]], lo[G[4]], hi[G[4]])
    _fold3(n, 0, c, d, e, l3, f2, f3, S)
    _fold3(n, 1, c, d, e, l3, f2, f3, S)
    _fold3(n, 2, c, d, e, l3, f2, f3, S)
    _fold3(n, 3, c, d, e, l3, f2, f3, S)
    _fold3(n, 4, c, d, e, l3, f2, f3, S)
    _fold3(n, 5, c, d, e, l3, f2, f3, S)
    _fold3(n, 6, c, d, e, l3, f2, f3, S)
    _fold3(n, 7, c, d, e, l3, f2, f3, S)


@njit(cache=True, nogil=True, inline="always")  # into each kernel's walk: no call per candidate
def take_branch(St, r, k, L, cand, cerr, flags, codes, m):
    """Branch k of pose r of the stages' rows St (layout L) into candidate m: its joints cand[m] (folded),
    residuals cerr[m], whether they verify the pose flags[m], whether its joints lie within the limits flags[8 + m]
    and its label code codes[m].  Returns whether it is verified with a joint next to an edge of the fold."""
    # (the layout's entries by literal indices: constants, where a variable index is a switch over the tuple)
    cand[m, 0], cand[m, 1] = St[(L[13] + (k >> L[16])) * CHUNK + r], St[(L[17] + (k >> L[20])) * CHUNK + r]
    cand[m, 2], cand[m, 3] = St[(L[21] + (k >> L[24])) * CHUNK + r], St[(L[25] + (k >> L[28])) * CHUNK + r]
    cand[m, 4], cand[m, 5] = St[(L[29] + (k >> L[32])) * CHUNK + r], St[(L[33] + (k >> L[36])) * CHUNK + r]
    d = k * CHUNK + r
    cerr[m, 0], cerr[m, 1], flags[m] = St[L[4] * CHUNK + d], St[L[5] * CHUNK + d], St[L[6] * CHUNK + d] != 0.0
    codes[m] = St[L[8] * CHUNK + d]
    fold = St[L[11] * CHUNK + d]
    flags[8 + m] = fold == 1.0 or fold == 3.0
    return flags[m] and fold >= 2.0


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
def _fold1(n, s1, rq, lo, hi, rf, S):
    """Joint 1 of the shoulder root s1 (row rq + s1) folded; row rf + s1: 1.0 inside, plus 2.0 near an edge."""
    for b in range(n):
        x, inside, edge = _fold(S[(rq + s1) * CHUNK + b], lo, hi)
        S[(rq + s1) * CHUNK + b] = x
        S[(rf + s1) * CHUNK + b] = select(inside, 1.0, 0.0) + select(edge, 2.0, 0.0)


@njit(cache=True, nogil=True, error_model="numpy", inline="always")
def _fold2(n, g, ra, rb, lims, rp, rf, S):
    """The two joints of rows ra + g, rb + g folded; row rf + g: joint 1 (flags rp + (g >> 1)) and both inside
    (1.0), plus 2.0 if one is near an edge."""
    for b in range(n):
        xa, ina, ea = _fold(S[(ra + g) * CHUNK + b], lims[0], lims[1])
        xb, inb, eb = _fold(S[(rb + g) * CHUNK + b], lims[2], lims[3])
        f1 = S[(rp + (g >> 1)) * CHUNK + b]
        S[(ra + g) * CHUNK + b], S[(rb + g) * CHUNK + b] = xa, xb
        S[(rf + g) * CHUNK + b] = select(ina & inb & ((f1 == 1.0) | (f1 == 3.0)), 1.0, 0.0) \
            + select(ea | eb | (f1 >= 2.0), 2.0, 0.0)


@njit(cache=True, nogil=True, error_model="numpy", inline="always")
def _fold3(n, k, ra, rb, rc, lims, rp, rf, S):
    """The three joints of rows ra + k, rb + k, rc + k of the branch k folded; row rf + k: all six joints inside
    (1.0; the others' flags at rp + (k >> 1)), plus 2.0 if one is near an edge."""
    for b in range(n):
        xa, ina, ea = _fold(S[(ra + k) * CHUNK + b], lims[0], lims[1])
        xb, inb, eb = _fold(S[(rb + k) * CHUNK + b], lims[2], lims[3])
        xc, inc, ec = _fold(S[(rc + k) * CHUNK + b], lims[4], lims[5])
        f2 = S[(rp + (k >> 1)) * CHUNK + b]
        S[(ra + k) * CHUNK + b], S[(rb + k) * CHUNK + b], S[(rc + k) * CHUNK + b] = xa, xb, xc
        S[(rf + k) * CHUNK + b] = select(ina & inb & inc & ((f2 == 1.0) | (f2 == 3.0)), 1.0, 0.0) \
            + select(ea | eb | ec | (f2 >= 2.0), 2.0, 0.0)
