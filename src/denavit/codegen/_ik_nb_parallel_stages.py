"""The UR-class kernel's candidates as stages over a chunk of poses, in structure-of-arrays form (as the elbow
kernel's, :mod:`._ik_nb_elbow_stages`): each stage a loop over the poses of the chunk whose body is the closed forms
of :mod:`denavit.ik.forms` (jitted through :mod:`._ik_jit`) with no branch and no libm call, which LLVM runs four
poses to an AVX2 register.  Every branch of a pose (q1 root s1, q5 root s5, q3 root s3: branch k = 4 s1 + 2 s5 + s3,
the plain plan's order) is computed, NaN where it has no root; the tests after which the one-pose plan handed a pose
over (see :mod:`._ik_parallel`) are kept as flag rows (1.0 or 0.0) per pose and per branch, with the rounding-error
estimates they read, so that :func:`._ik_nb_parallel.ik_parallel_packed` walks each pose's branches as the one-pose
plan did (skipping the NaN ones, raising the status where a flag of a reached branch is set).

Stages: the target's point Q, T_R C6_Rᵀ and q1 (per pose); frame 1 and the wrist's q5 (per s1); q6, the planar
pair's point P and q3 (per s1, s5); q2 and q4 (per branch).  Scratch: one float vector of ROWS rows of CHUNK floats
(the ``R*`` constants), rows at constant offsets from one pointer (see :mod:`._ik_nb_elbow_stages` for why); the
rows the check and fold stages read are :data:`LAYOUT` (:mod:`._ik_nb_checks`).  Compiled once per machine
(``cache=True``), ``error_model="numpy"``.  Imported only where numba is.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from ._ik_finish import DOUBLE_ROOT
from ._ik_jit import atan2, elbow_q2, select, trig_pairs, trig_roots, wrist_qb
from ._ik_nb_checks import CHUNK, chain_step, copy_targets

__all__ = [
    "FOLD_GROUPS",
    "LAYOUT",
    "RD3",
    "RF6",
    "RFK",
    "ROWS",
    "RPO",
    "RQ1",
    "RQ3",
    "RQ5",
    "RR3",
    "RST",
    "RW5",
    "parallel_stages",
]

# rows of S: per pose
RT, RX, RTC, RST, RE1 = 0, 12, 15, 24, 25  # target's top 3×4; Q (world); T_R C6_Rᵀ (row-major); status; q1's error
RQ1, RC1, RS1 = 26, 28, 30  # per s1: q1, cos, sin
RCOL, REL, RW5, RE5 = 32, 56, 60, 62  # per s1: frame 1 (12 rows each: x, y, z, origin), ell (2 each), flag, q5's error
RQ5, RC5, RS5, RQ6, RC6, RS6 = 64, 68, 72, 76, 80, 84  # per j = 2 s1 + s5
RPP, RXR = 88, 96  # per j: the planar pair's point (P0, P1: 2 rows each), the first column xr of X (3 rows each)
RF6, RR3, RD3, REP, RE3 = 108, 112, 116, 120, 124  # per j: flags (axis 6 ∥ 2-4 or P next to axis 2; no q3
# dependence; q3 next to a double root), the errors of P and of q3
RQ2, RC2, RS2, RQ3, RC3, RS3, RQ4, RC4, RS4, RFK = 128, 136, 144, 152, 160, 168, 176, 184, 192, 200  # per k; RFK:
# flag (the elbow's point next to axis 2, or the error estimate beyond COND_MAX)
# rows of the checks and folds (_ik_nb_checks): frame after joint 3 (12 per k), label bits, residuals, flags
RF3, RL2, RPE, RRE, RVF, RPO, RLB, RFL1, RFL2, RFL = 208, 304, 312, 320, 328, 336, 344, 352, 354, 358
RAE = 366  # per s1: atan2 of ell (q6 = atan2(y) − this)
ROWS = 368
#: the rows as the check and fold stages read them: joint 1 per s1, joints 2-4 per branch, joints 5, 6 per j; the
#: elbow label's far point is the origin of frame 3; the fold's levels: joints 5, 6, then 2, 3, 4
LAYOUT = (RT, RX, RF3, RL2, RPE, RRE, RVF, RPO, RLB, RFL1, RFL2, RFL, 1, RQ1, RC1, RS1, 2, RQ2, RC2, RS2, 0, RQ3, RC3,
          RS3, 0, RQ4, RC4, RS4, 0, RQ5, RC5, RS5, 1, RQ6, RC6, RS6, 1)
FOLD_GROUPS = (4, 5, 1, 2, 3)


@njit(cache=True, nogil=True, error_model="numpy")
def parallel_stages(T, s, n, K, S):
    """The candidates of poses T[s:s + n] (n ≤ CHUNK) of a UR-class arm (constants K: PARALLEL_LAYOUT) into S, with
    the hand-over flags of each branch."""
    Q_e, C0i, C = K[0:3], K[3:19].reshape((4, 4)), K[19:131].reshape((7, 4, 4))
    a, sc, tols, far, trig = K[131:134], K[134:145], K[169:177], K[177], K[178:186]
    wc = (trig[0], trig[1], trig[2], trig[3], trig[4], trig[5], trig[6], trig[7])  # forms.wrist_constants
    tol, reach = tols[1], tols[7]
    g = (tol, sc[9] * reach, max(reach, 1e-3), sc[2])  # the roots' tolerance, NEAR_SINGULAR × reach, scale, rho_w
    copy_targets(T, s, n, S, RT)
    _shoulder(n, Q_e, C0i, C, a, sc[0], far, g, S)
    _wrist5(n, 0, C, sc[1], wc, g, S)
    _wrist5(n, 1, C, sc[1], wc, g, S)
    pair = (sc[6], sc[7], sc[8])
    _planar(n, 0, C, sc, pair, g, S)
    _planar(n, 1, C, sc, pair, g, S)
    _planar(n, 2, C, sc, pair, g, S)
    _planar(n, 3, C, sc, pair, g, S)
    R2, p2, p3 = C[2, :3, :3], C[2, :3, 3], C[3, :3, 3]
    _arm(n, 0, C, R2, p2, p3, sc[10], g, S)
    _arm(n, 1, C, R2, p2, p3, sc[10], g, S)
    _arm(n, 2, C, R2, p2, p3, sc[10], g, S)
    _arm(n, 3, C, R2, p2, p3, sc[10], g, S)
    _arm(n, 4, C, R2, p2, p3, sc[10], g, S)
    _arm(n, 5, C, R2, p2, p3, sc[10], g, S)
    _arm(n, 6, C, R2, p2, p3, sc[10], g, S)
    _arm(n, 7, C, R2, p2, p3, sc[10], g, S)


@njit(cache=True, nogil=True, error_model="numpy", inline="always")
def _t(S, i, b):
    """Entry i (row-major) of pose b's target top 3×4 in the rows RT."""
    return S[(RT + i) * CHUNK + b]


@njit(cache=True, nogil=True, error_model="numpy", inline="always")
def _tc(S, b, C, r, j):
    """Entry (r, j) of T_R C6_Rᵀ of pose b into its row RTC + 3 r + j."""
    S[(RTC + 3 * r + j) * CHUNK + b] = _t(S, 4 * r, b) * C[6, j, 0] + _t(S, 4 * r + 1, b) * C[6, j, 1] \
        + _t(S, 4 * r + 2, b) * C[6, j, 2]


@njit(cache=True, nogil=True, error_model="numpy", inline="always")
def _shoulder(n, Q_e, C0i, C, a, c0, far, g, S):
    """Q (world), T_R C6_Rᵀ and the roots q1 of (Rz(q1) a) · V = h + a · pc1 (V: Q in the frame of C0; subproblem 1,
    trig_roots) of each pose, q1's rounding error [eps] (1/sin of the root's distance from the double root) and the
    status: 1.0 beyond every reachable point (``far``: the plain solver's stand-in), Q on or next to axis 1, next to
    a double root, or a wrist with no z-row dependence (rho_w)."""
    tol, wide, scale, rho_w = g
    for b in range(n):
        x0 = _t(S, 0, b) * Q_e[0] + _t(S, 1, b) * Q_e[1] + _t(S, 2, b) * Q_e[2] + _t(S, 3, b)
        x1 = _t(S, 4, b) * Q_e[0] + _t(S, 5, b) * Q_e[1] + _t(S, 6, b) * Q_e[2] + _t(S, 7, b)
        x2 = _t(S, 8, b) * Q_e[0] + _t(S, 9, b) * Q_e[1] + _t(S, 10, b) * Q_e[2] + _t(S, 11, b)
        S[RX * CHUNK + b], S[(RX + 1) * CHUNK + b], S[(RX + 2) * CHUNK + b] = x0, x1, x2
        V0 = C0i[0, 0] * x0 + C0i[0, 1] * x1 + C0i[0, 2] * x2 + C0i[0, 3]
        V1 = C0i[1, 0] * x0 + C0i[1, 1] * x1 + C0i[1, 2] * x2 + C0i[1, 3]
        V2 = C0i[2, 0] * x0 + C0i[2, 1] * x1 + C0i[2, 2] * x2 + C0i[2, 3]
        _tc(S, b, C, 0, 0)  # T_R C6_Rᵀ
        _tc(S, b, C, 0, 1)
        _tc(S, b, C, 0, 2)
        _tc(S, b, C, 1, 0)
        _tc(S, b, C, 1, 1)
        _tc(S, b, C, 1, 2)
        _tc(S, b, C, 2, 0)
        _tc(S, b, C, 2, 1)
        _tc(S, b, C, 2, 2)
        ea, eb = a[0] * V0 + a[1] * V1, a[0] * V1 - a[1] * V0
        q1a, q1b, rho, ratio = trig_roots(ea, eb, c0 - a[2] * V2, tol)
        c1a, s1a, c1b, s1b = trig_pairs(ea, eb, rho, ratio, tol)  # cos, sin of the roots, algebraically
        dist = np.sqrt(_t(S, 3, b) ** 2 + _t(S, 7, b) ** 2 + _t(S, 11, b) ** 2)
        bad = ~(dist <= far) | (rho <= max(wide, 1e-11)) | (abs(abs(ratio) - 1.0) < DOUBLE_ROOT) \
            | (rho_w < 1e-12)
        S[RST * CHUNK + b] = select(bad, 1.0, 0.0)
        r1 = min(1.0, max(-1.0, ratio))
        S[RE1 * CHUNK + b] = max(1.0, scale / rho) / max(np.sqrt(abs((1.0 - r1) * (1.0 + r1))), 1e-300)
        S[RQ1 * CHUNK + b], S[(RQ1 + 1) * CHUNK + b], S[RC1 * CHUNK + b], S[(RC1 + 1) * CHUNK + b] = q1a, q1b, c1a, c1b
        S[RS1 * CHUNK + b], S[(RS1 + 1) * CHUNK + b] = s1a, s1b


@njit(cache=True, nogil=True, error_model="numpy", inline="always")
def _wrist5(n, s1, C, sigma, wc, g, S):
    """For the root s1 of each pose: frame 1 (F1 = C0 Rz(q1) C1, the chain's step), the z column of F1ᵀ T_R C6_Rᵀ
    its angle, and the roots q5 of rᵀ Rz(q5) u = m_z (m: that column, its z scaled by sigma; wrist_qb), the flag where they
    (nearly) coincide and q5's rounding error (sin of the roots' half difference from wrist_qb's products)."""
    tol, _wide, _scale, rho_w = g
    F0 = (C[0, 0, 0], C[0, 1, 0], C[0, 2, 0], C[0, 0, 1], C[0, 1, 1], C[0, 2, 1], C[0, 0, 2], C[0, 1, 2], C[0, 2, 2],
          C[0, 0, 3], C[0, 1, 3], C[0, 2, 3])
    oc, j = (RCOL + 12 * s1) * CHUNK, 2 * s1
    for b in range(n):
        F = chain_step(F0, S[(RC1 + s1) * CHUNK + b], S[(RS1 + s1) * CHUNK + b], C, 1)
        S[oc + b], S[oc + CHUNK + b], S[oc + 2 * CHUNK + b], S[oc + 3 * CHUNK + b] = F[0], F[1], F[2], F[3]
        S[oc + 4 * CHUNK + b], S[oc + 5 * CHUNK + b], S[oc + 6 * CHUNK + b] = F[4], F[5], F[6]
        S[oc + 7 * CHUNK + b], S[oc + 8 * CHUNK + b], S[oc + 9 * CHUNK + b] = F[7], F[8], F[9]
        S[oc + 10 * CHUNK + b], S[oc + 11 * CHUNK + b] = F[10], F[11]
        tc = (S[(RTC + 2) * CHUNK + b], S[(RTC + 5) * CHUNK + b], S[(RTC + 8) * CHUNK + b])
        RL02 = F[0] * tc[0] + F[1] * tc[1] + F[2] * tc[2]
        RL12 = F[3] * tc[0] + F[4] * tc[1] + F[5] * tc[2]
        RL22 = F[6] * tc[0] + F[7] * tc[1] + F[8] * tc[2]
        ell0 = F[6] * S[RTC * CHUNK + b] + F[7] * S[(RTC + 3) * CHUNK + b] + F[8] * S[(RTC + 6) * CHUNK + b]
        ell1 = F[6] * S[(RTC + 1) * CHUNK + b] + F[7] * S[(RTC + 4) * CHUNK + b] + F[8] * S[(RTC + 7) * CHUNK + b]
        S[(REL + 2 * s1) * CHUNK + b], S[(REL + 2 * s1 + 1) * CHUNK + b] = ell0, ell1
        S[(RAE + s1) * CHUNK + b] = atan2(ell1, ell0)  # q6's second term, once for both q5 roots
        q5a, q5b, lo, hi, c5a, s5a, c5b, s5b = wrist_qb(RL02, RL12, sigma * RL22, wc, tol)
        least = min(lo, hi)
        S[(RW5 + s1) * CHUNK + b] = select((-2.0 * tol < least) & (least < 1e-12), 1.0, 0.0)
        sx = 2.0 * np.sqrt(max(lo, 0.0) * max(hi, 0.0))  # sin of (q5a − q5b)/2: ((1 − cos x)(1 + cos x))^½
        S[(RE5 + s1) * CHUNK + b] = (1.0 + S[RE1 * CHUNK + b]) / max(rho_w * sx, 1e-300)
        S[(RQ5 + j) * CHUNK + b], S[(RC5 + j) * CHUNK + b], S[(RS5 + j) * CHUNK + b] = q5a, c5a, s5a
        S[(RQ5 + j + 1) * CHUNK + b], S[(RC5 + j + 1) * CHUNK + b], S[(RS5 + j + 1) * CHUNK + b] = q5b, c5b, s5b


@njit(cache=True, nogil=True, error_model="numpy", inline="always")
def _planar(n, j, C, sc, pair, g, S):
    """For the pair j = 2 s1 + s5 of each pose: q6 (the rest of the orientation: atan2 of the turned axis y minus
    that of ell), the tail C4 Rz(q5) C5 Rz(q6) C6, X = F1⁻¹ T tail⁻¹ (its origin P and first column xr), the planar
    pair's roots q3 (law of cosines 2α cos q3 + 2β sin q3 = |P_xy|² + k0: trig_roots), into the rows of the
    branches k = 2 j, 2 j + 1; the flags (axis 6 parallel to axes 2-4 or P next to axis 2; no dependence on q3; a
    double root) and the errors of P and of q3 [eps]."""
    tol, wide, scale, _rho_w = g
    ap2, bp2, k0 = pair
    s1, oc, k = j >> 1, (RCOL + 12 * (j >> 1)) * CHUNK, 2 * j
    for b in range(n):
        c5, s5 = S[(RC5 + j) * CHUNK + b], S[(RS5 + j) * CHUNK + b]
        ell0, ell1 = S[(REL + 2 * s1) * CHUNK + b], S[(REL + 2 * s1 + 1) * CHUNK + b]
        t0, t1, t2 = C[4, 2, 0] * c5 + C[4, 2, 1] * s5, -C[4, 2, 0] * s5 + C[4, 2, 1] * c5, C[4, 2, 2]
        y0 = sc[1] * (t0 * C[5, 0, 0] + t1 * C[5, 1, 0] + t2 * C[5, 2, 0])
        y1 = sc[1] * (t0 * C[5, 0, 1] + t1 * C[5, 1, 1] + t2 * C[5, 2, 1])
        ny = np.sqrt(y0 * y0 + y1 * y1)
        q6 = atan2(y1, y0) - S[(RAE + s1) * CHUNK + b]
        e1, e5 = S[RE1 * CHUNK + b], S[(RE5 + s1) * CHUNK + b]
        e6 = (1.0 + e1 + e5) / max(ny, 1e-300)
        eP = 1.0 + e1 + e5 + e6  # of the point P, per reach
        c6, s6 = _angle_between(y0, y1, ell0, ell1)
        tl = _tail(C, c5, s5, c6, s6)
        F = (S[oc + b], S[oc + CHUNK + b], S[oc + 2 * CHUNK + b], S[oc + 3 * CHUNK + b], S[oc + 4 * CHUNK + b],
             S[oc + 5 * CHUNK + b], S[oc + 6 * CHUNK + b], S[oc + 7 * CHUNK + b], S[oc + 8 * CHUNK + b],
             S[oc + 9 * CHUNK + b], S[oc + 10 * CHUNK + b], S[oc + 11 * CHUNK + b])
        w0, w1, w2 = _origin_row(S, b, 0, F, tl), _origin_row(S, b, 1, F, tl), _origin_row(S, b, 2, F, tl)
        P0 = F[0] * w0 + F[1] * w1 + F[2] * w2
        P1 = F[3] * w0 + F[4] * w1 + F[5] * w2
        g0 = _t(S, 0, b) * tl[0] + _t(S, 1, b) * tl[3] + _t(S, 2, b) * tl[6]
        g1 = _t(S, 4, b) * tl[0] + _t(S, 5, b) * tl[3] + _t(S, 6, b) * tl[6]
        g2 = _t(S, 8, b) * tl[0] + _t(S, 9, b) * tl[3] + _t(S, 10, b) * tl[6]
        S[(RXR + 3 * j) * CHUNK + b] = F[0] * g0 + F[1] * g1 + F[2] * g2
        S[(RXR + 3 * j + 1) * CHUNK + b] = F[3] * g0 + F[4] * g1 + F[5] * g2
        S[(RXR + 3 * j + 2) * CHUNK + b] = F[6] * g0 + F[7] * g1 + F[8] * g2
        S[(RPP + 2 * j) * CHUNK + b], S[(RPP + 2 * j + 1) * CHUNK + b] = P0, P1
        nP = np.sqrt(P0 * P0 + P1 * P1)
        q3a, q3b, rho3, ratio3 = trig_roots(ap2, bp2, P0 * P0 + P1 * P1 + k0, tol)
        c3a, s3a, c3b, s3b = trig_pairs(ap2, bp2, rho3, ratio3, tol)
        S[(RF6 + j) * CHUNK + b] = select((ny < sc[9]) | (nP < wide), 1.0, 0.0)
        S[(RR3 + j) * CHUNK + b] = select(rho3 <= 1e-12, 1.0, 0.0)
        S[(RD3 + j) * CHUNK + b] = select(abs(abs(ratio3) - 1.0) < DOUBLE_ROOT, 1.0, 0.0)
        r3 = min(1.0, max(-1.0, ratio3))  # sin of the root's distance from the double root: sqrt(1 - r3^2)
        S[(REP + j) * CHUNK + b] = eP
        S[(RE3 + j) * CHUNK + b] = eP * 2.0 * nP * scale / max(rho3 * np.sqrt(abs((1.0 - r3) * (1.0 + r3))),
                                                                1e-300)
        S[(RQ6 + j) * CHUNK + b], S[(RC6 + j) * CHUNK + b], S[(RS6 + j) * CHUNK + b] = q6, c6, s6
        S[(RQ3 + k) * CHUNK + b], S[(RC3 + k) * CHUNK + b], S[(RS3 + k) * CHUNK + b] = q3a, c3a, s3a
        S[(RQ3 + k + 1) * CHUNK + b], S[(RC3 + k + 1) * CHUNK + b], S[(RS3 + k + 1) * CHUNK + b] = q3b, c3b, s3b


@njit(cache=True, nogil=True, error_model="numpy", inline="always")
def _origin_row(S, b, r, F, tl):
    """Row r of T_p − F1_p − (T_R tl_Rᵀ) tl_p (pose b's target, F1's origin F[9:12], the tail's columns tl), the
    one-pose plan's sums in its order."""
    w = _t(S, 4 * r + 3, b) - F[9 + r]
    w -= (_t(S, 4 * r, b) * tl[0] + _t(S, 4 * r + 1, b) * tl[3] + _t(S, 4 * r + 2, b) * tl[6]) * tl[9]
    w -= (_t(S, 4 * r, b) * tl[1] + _t(S, 4 * r + 1, b) * tl[4] + _t(S, 4 * r + 2, b) * tl[7]) * tl[10]
    w -= (_t(S, 4 * r, b) * tl[2] + _t(S, 4 * r + 1, b) * tl[5] + _t(S, 4 * r + 2, b) * tl[8]) * tl[11]
    return w


@njit(cache=True, nogil=True, error_model="numpy", inline="always")
def _arm(n, k, C, R2, p2, p3, cond_max, g, S):
    """For the branch k = 2 j + s3 of each pose: q2 turning the elbow's point onto P about axis 2 (elbow_q2), the
    flag (that point next to axis 2, or the summed error estimate of q2, q3, P beyond COND_MAX), and q4 = atan2(N10,
    N00) with N = (Rz(q2) R2 Rz(q3) R3)ᵀ X_R (its column 0 from xr)."""
    _tol, wide, scale, _rho_w = g
    j = k >> 1
    for b in range(n):
        P0, P1 = S[(RPP + 2 * j) * CHUNK + b], S[(RPP + 2 * j + 1) * CHUNK + b]
        c3, s3 = S[(RC3 + k) * CHUNK + b], S[(RS3 + k) * CHUNK + b]
        q2, _free, vxy, c2, s2 = elbow_q2(P0, P1, c3, s3, R2, p2, p3, 0.0)
        eP, e3 = S[(REP + j) * CHUNK + b], S[(RE3 + j) * CHUNK + b]
        e2 = (eP + e3) * scale / max(min(np.sqrt(P0 * P0 + P1 * P1), vxy), 1e-300)
        S[(RFK + k) * CHUNK + b] = select((vxy < wide) | (e2 + e3 + eP > cond_max), 1.0, 0.0)
        x0, x1, x2 = S[(RXR + 3 * j) * CHUNK + b], S[(RXR + 3 * j + 1) * CHUNK + b], S[(RXR + 3 * j + 2) * CHUNK + b]
        z0, z1, z2 = c2 * x0 + s2 * x1, -s2 * x0 + c2 * x1, x2
        d0 = C[2, 0, 0] * z0 + C[2, 1, 0] * z1 + C[2, 2, 0] * z2
        d1 = C[2, 0, 1] * z0 + C[2, 1, 1] * z1 + C[2, 2, 1] * z2
        d2 = C[2, 0, 2] * z0 + C[2, 1, 2] * z1 + C[2, 2, 2] * z2
        f0, f1 = c3 * d0 + s3 * d1, -s3 * d0 + c3 * d1
        N00 = C[3, 0, 0] * f0 + C[3, 1, 0] * f1 + C[3, 2, 0] * d2
        N10 = C[3, 0, 1] * f0 + C[3, 1, 1] * f1 + C[3, 2, 1] * d2
        c4, s4 = _angle_between(N00, N10, 1.0, 0.0)
        S[(RQ2 + k) * CHUNK + b], S[(RC2 + k) * CHUNK + b], S[(RS2 + k) * CHUNK + b] = q2, c2, s2
        S[(RQ4 + k) * CHUNK + b], S[(RC4 + k) * CHUNK + b], S[(RS4 + k) * CHUNK + b] = atan2(N10, N00), c4, s4


@njit(cache=True, nogil=True, error_model="numpy", inline="always")
def _angle_between(x0, x1, u0, u1):
    """(cos θ, sin θ) of θ = atan2(x1, x0) − atan2(u1, u0), the angle from u to x (the normalised dot and cross
    products; within a few ulps of cos and sin of the difference of the two atan2), (1, 0) where x or u is 0."""
    d, c = x0 * u0 + x1 * u1, u0 * x1 - u1 * x0
    h = np.sqrt(d * d + c * c)
    zero = h == 0.0
    h = select(zero, 1.0, h)
    return select(zero, 1.0, d / h), select(zero, 0.0, c / h)


@njit(cache=True, nogil=True, error_model="numpy", inline="always")
def _tail(C, c5, s5, c6, s6):
    """Columns x, y, z and origin of C4 Rz(q5) C5 Rz(q6) C6 (the tuple (x0, x1, x2, y0, …, p2)), from the cosines
    and sines of q5, q6."""
    F = (C[4, 0, 0], C[4, 1, 0], C[4, 2, 0], C[4, 0, 1], C[4, 1, 1], C[4, 2, 1], C[4, 0, 2], C[4, 1, 2], C[4, 2, 2],
         C[4, 0, 3], C[4, 1, 3], C[4, 2, 3])
    return chain_step(chain_step(F, c5, s5, C, 5), c6, s6, C, 6)
