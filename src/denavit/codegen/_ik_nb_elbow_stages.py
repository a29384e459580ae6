"""The elbow kernel's candidates as stages over a chunk of poses, in structure-of-arrays form: each stage a loop over
the poses of the chunk whose body is the closed forms of :mod:`denavit.ik.forms` (jitted through :mod:`._ik_jit`)
with no branch and no libm call (their angles by ``forms.atan2``), meant for LLVM to run four poses to an AVX2
register (it does not yet: docs/performance.md); every branch of a pose (q1 root s1, q3 root s3, wrist root s5) is
computed, NaN where it has no root, and :func:`._ik_nb_elbow.ik_elbow` then walks the branches of each pose as the
one-pose loop did (skipping the NaN ones, raising the status where the plain solver must decide).  Rows of the
scratch ``S`` (ROWS, CHUNK): the module's ``_*`` constants; a flag is stored as 1.0 or 0.0.  Compiled once per
machine (``cache=True``), ``error_model="numpy"`` (a division is the IEEE one: no zero test, which would be a
branch; the forms divide by nothing that can be 0 where their results are used).  Imported only where numba is.
"""

from __future__ import annotations

import math

import numpy as np

from numba import njit

from ._ik_finish import DOUBLE_ROOT
from ._ik_jit import WRIST_TOL, elbow_plane, elbow_q2, elbow_roots, shoulder_roots, wrist_qb, wrist_rest

#: the scratch layout (rows of S) is shared with the walk over the branches (_ik_nb_elbow)
__all__ = [
    "CHUNK", "ROWS", "elbow_stages", "RC1", "RC2", "RC3", "RCA", "RCB", "RCC", "RF2", "RQ1", "RQ2", "RQ3",
    "RQA", "RQB", "RQC", "RS1", "RS2", "RS3", "RSA", "RSB", "RSC", "RSG", "RST", "RX",
]

#: poses per chunk of the stages (its scratch: ROWS × CHUNK floats, 24 kB, in L1)
CHUNK = 16
# rows of S: per pose, then per branch (s1: 2, k2 = 2 s1 + s3: 4, k = 2 k2 + s5: 8)
RXW, RW, RY0, RY2, RST = 0, 3, 6, 9, 12  # wrist centre (world, frame of C0), columns 0 and 2 of T_R R6ᵀ, status
RQ1, RC1, RS1, RG, RX = 13, 15, 17, 19, 23  # per s1: q1 and its cos, sin; (g0, g1) at RG + 2 s1; the elbow's x
RQ3, RC3, RS3, RQ2, RC2, RS2, RF2 = 25, 29, 33, 37, 41, 45, 49  # per k2
RM = 53  # per k2: m00, m10, m20, m02, m12, m22 of M = R_0_3ᵀ T_R R6ᵀ at RM + 6 k2
RQB, RCB, RSB, RQA, RQC, RSG, RCA, RSA, RCC, RSC = 77, 85, 93, 101, 109, 117, 125, 133, 141, 149  # per k
ROWS = 157


@njit(cache=True, nogil=True, error_model="numpy")
def elbow_stages(T, s, n, K, S):
    """The candidates of poses T[s:s + n] (n ≤ CHUNK) into S: the wrist centre and shoulder, the elbow, q2 and the
    wrist's qb, the wrist's qa and qc (four loops over the poses)."""
    C0i, consts = K[0:16].reshape((4, 4)), K[16:80].reshape((4, 4, 4))
    K3 = K[192:252].reshape((20, 3))
    R6, R1, R2, R4, R5 = K3[0:3], K3[3:6], K3[6:9], K3[9:12], K3[12:15]
    X_e, p1, a, p2, P = K3[15], K3[16], K3[17], K3[18], K3[19]
    sc, trig, tols = K[252:261], K[261:271], K[295:303]
    tiny = tols[0] * sc[4]
    _shoulder(T, s, n, X_e, C0i, R6, a, sc[0], tiny, tols[1], sc[5], S)
    for s1 in range(2):
        _elbow(n, s1, R1, p1, sc[1], sc[2], sc[3], trig[8], trig[9], tols[1], S)
    wc = (trig[0], trig[1], trig[2], trig[3], trig[4], trig[5], trig[6], trig[7])  # forms.wrist_constants
    for k2 in range(4):
        _arm(n, k2, R2, p2, P, tiny, consts, wc, S)
    for k in range(8):
        _wrist(n, k, R4, R5, S)


@njit(cache=True, nogil=True, error_model="numpy", inline="always")
def _shoulder(T, s, n, X_e, C0i, R6, a, h, tiny, ratio_tol, rho_w, S):
    """Wrist centre, T_R R6ᵀ and the shoulder's roots of each pose; status 1.0 where the plain solver decides (joint
    1 free, the shoulder equation independent of q1, next to a double root, a wrist with no z-row dependence)."""
    for b in range(n):
        t = s + b
        x0 = T[t, 0, 0] * X_e[0] + T[t, 0, 1] * X_e[1] + T[t, 0, 2] * X_e[2] + T[t, 0, 3]
        x1 = T[t, 1, 0] * X_e[0] + T[t, 1, 1] * X_e[1] + T[t, 1, 2] * X_e[2] + T[t, 1, 3]
        x2 = T[t, 2, 0] * X_e[0] + T[t, 2, 1] * X_e[1] + T[t, 2, 2] * X_e[2] + T[t, 2, 3]
        w0 = C0i[0, 0] * x0 + C0i[0, 1] * x1 + C0i[0, 2] * x2 + C0i[0, 3]
        w1 = C0i[1, 0] * x0 + C0i[1, 1] * x1 + C0i[1, 2] * x2 + C0i[1, 3]
        w2 = C0i[2, 0] * x0 + C0i[2, 1] * x1 + C0i[2, 2] * x2 + C0i[2, 3]
        S[RXW, b], S[RXW + 1, b], S[RXW + 2, b], S[RW, b], S[RW + 1, b], S[RW + 2, b] = x0, x1, x2, w0, w1, w2
        for i in range(3):
            S[RY0 + i, b] = T[t, i, 0] * R6[0, 0] + T[t, i, 1] * R6[0, 1] + T[t, i, 2] * R6[0, 2]
            S[RY2 + i, b] = T[t, i, 0] * R6[2, 0] + T[t, i, 1] * R6[2, 1] + T[t, i, 2] * R6[2, 2]
        q1a, q1b, free1, ratio, c1a, s1a, c1b, s1b = shoulder_roots(w0, w1, w2, a, h, tiny, ratio_tol)
        bad = free1 | ((ratio == 0.0) & math.isnan(q1a)) | (abs(abs(ratio) - 1.0) < DOUBLE_ROOT) | (rho_w < 1e-12)
        S[RST, b] = 1.0 if bad else 0.0
        S[RQ1, b], S[RQ1 + 1, b], S[RC1, b], S[RC1 + 1, b] = q1a, q1b, c1a, c1b
        S[RS1, b], S[RS1 + 1, b] = s1a, s1b


@njit(cache=True, nogil=True, error_model="numpy", inline="always")
def _elbow(n, s1, R1, p1, na, nb, base3, cb3, sb3, ratio_tol, S):
    """The elbow's two roots q3 for the shoulder root s1 of each pose (elbow_plane, elbow_roots)."""
    for b in range(n):
        g0, g1 = elbow_plane(S[RC1 + s1, b], S[RS1 + s1, b], S[RW, b], S[RW + 1, b], S[RW + 2, b], R1, p1)
        q3a, q3b, x, c3a, s3a, c3b, s3b = elbow_roots(np.sqrt(g0 * g0 + g1 * g1), na, nb, base3, cb3, sb3,
                                                      ratio_tol)
        S[RG + 2 * s1, b], S[RG + 2 * s1 + 1, b], S[RX + s1, b] = g0, g1, x
        k = 2 * s1
        S[RQ3 + k, b], S[RC3 + k, b], S[RS3 + k, b] = q3a, c3a, s3a
        S[RQ3 + k + 1, b], S[RC3 + k + 1, b], S[RS3 + k + 1, b] = q3b, c3b, s3b


@njit(cache=True, nogil=True, error_model="numpy", inline="always")
def _turn(C, m, c, s, F):
    """The columns (x, y, z; row i of each as x_i, y_i, z_i) of F Rz(q) C[m] from those of F (the tuple (x0, x1, x2,
    y0, …, z2); c, s: cos q, sin q)."""
    x0, x1, x2, y0, y1, y2, z0, z1, z2 = F
    x0, y0 = c * x0 + s * y0, c * y0 - s * x0
    x1, y1 = c * x1 + s * y1, c * y1 - s * x1
    x2, y2 = c * x2 + s * y2, c * y2 - s * x2
    return (x0 * C[m, 0, 0] + y0 * C[m, 1, 0] + z0 * C[m, 2, 0], x1 * C[m, 0, 0] + y1 * C[m, 1, 0] + z1 * C[m, 2, 0],
            x2 * C[m, 0, 0] + y2 * C[m, 1, 0] + z2 * C[m, 2, 0], x0 * C[m, 0, 1] + y0 * C[m, 1, 1] + z0 * C[m, 2, 1],
            x1 * C[m, 0, 1] + y1 * C[m, 1, 1] + z1 * C[m, 2, 1], x2 * C[m, 0, 1] + y2 * C[m, 1, 1] + z2 * C[m, 2, 1],
            x0 * C[m, 0, 2] + y0 * C[m, 1, 2] + z0 * C[m, 2, 2], x1 * C[m, 0, 2] + y1 * C[m, 1, 2] + z1 * C[m, 2, 2],
            x2 * C[m, 0, 2] + y2 * C[m, 1, 2] + z2 * C[m, 2, 2])


@njit(cache=True, nogil=True, error_model="numpy", inline="always")
def _arm(n, k2, R2, p2, P, tiny, consts, wc, S):
    """For the arm branch k2 = 2 s1 + s3 of each pose: q2 (elbow_q2), M = R_0_3ᵀ T_R R6ᵀ (its columns 0 and 2,
    R_0_3 = C0 Rz(q1) C1 Rz(q2) C2 Rz(q3) C3) and the wrist's two roots qb (wrist_qb)."""
    s1 = k2 >> 1
    for b in range(n):
        c1, sn1, c3, sn3 = S[RC1 + s1, b], S[RS1 + s1, b], S[RC3 + k2, b], S[RS3 + k2, b]
        q2, free2, _vxy, c2, sn2 = elbow_q2(S[RG + 2 * s1, b], S[RG + 2 * s1 + 1, b], c3, sn3, R2, p2, P, tiny)
        S[RQ2 + k2, b], S[RC2 + k2, b], S[RS2 + k2, b], S[RF2 + k2, b] = q2, c2, sn2, 1.0 if free2 else 0.0
        F = (consts[0, 0, 0], consts[0, 1, 0], consts[0, 2, 0], consts[0, 0, 1], consts[0, 1, 1], consts[0, 2, 1],
             consts[0, 0, 2], consts[0, 1, 2], consts[0, 2, 2])  # the columns of C0
        F = _turn(consts, 2, c2, sn2, _turn(consts, 1, c1, sn1, F))
        x0, x1, x2, y0, y1, y2, z0, z1, z2 = _turn(consts, 3, c3, sn3, F)
        m = RM + 6 * k2
        for j in range(2):
            r = RY0 if j == 0 else RY2
            S[m + 3 * j, b] = x0 * S[r, b] + x1 * S[r + 1, b] + x2 * S[r + 2, b]
            S[m + 3 * j + 1, b] = y0 * S[r, b] + y1 * S[r + 1, b] + y2 * S[r + 2, b]
            S[m + 3 * j + 2, b] = z0 * S[r, b] + z1 * S[r + 1, b] + z2 * S[r + 2, b]
        qba, qbb, _lo, _hi, cba, sba, cbb, sbb = wrist_qb(S[m + 3, b], S[m + 4, b], S[m + 5, b], wc, WRIST_TOL)
        k = 2 * k2
        S[RQB + k, b], S[RCB + k, b], S[RSB + k, b] = qba, cba, sba
        S[RQB + k + 1, b], S[RCB + k + 1, b], S[RSB + k + 1, b] = qbb, cbb, sbb


@njit(cache=True, nogil=True, error_model="numpy", inline="always")
def _wrist(n, k, R4, R5, S):
    """For the candidate k = 2 k2 + s5 of each pose: qa, qc (wrist_rest), their cos and sin, the singular flag."""
    m = RM + 6 * (k >> 1)
    for b in range(n):
        qa, qc, singular, _sign, _vxy, _cb, _sb, ca, sa, cc, sc = wrist_rest(
            S[RQB + k, b], S[RCB + k, b], S[RSB + k, b], S[m, b], S[m + 1, b], S[m + 2, b], S[m + 3, b],
            S[m + 4, b], R4, R5)
        S[RQA + k, b], S[RQC + k, b], S[RSG + k, b] = qa, qc, 1.0 if singular else 0.0
        S[RCA + k, b], S[RSA + k, b], S[RCC + k, b], S[RSC + k, b] = ca, sa, cc, sc
