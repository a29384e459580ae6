"""The elbow kernel's candidates as stages over a chunk of poses, in structure-of-arrays form: each stage a loop over
the poses of the chunk whose body is the closed forms of :mod:`denavit.ik.forms` (jitted through :mod:`._ik_jit`)
with no branch and no libm call (their angles by ``forms.atan2``), which LLVM runs four poses to an AVX2 register;
every branch of a pose (q1 root s1, q3 root s3, wrist root s5) is computed, NaN where it has no root, and
:func:`._ik_nb_elbow.ik_elbow` then walks the branches of each pose as the one-pose loop did (skipping the NaN ones,
raising the status where the plain solver must decide).

The scratch ``S`` is one float vector of ROWS rows of CHUNK floats, row ``R`` at ``S[R * CHUNK:(R + 1) * CHUNK]``
(the ``R*`` constants; a flag is stored as 1.0 or 0.0): rows at constant offsets from one pointer are what lets LLVM
prove the loops' stores and loads apart and vectorise them (rows of a 2-D array lie a run-time stride apart: it
refused, "too many memory checks needed").  Each branch has its own call of its stage, and no stage nests a loop in
its loop over the poses (the vectoriser takes innermost loops only; a constant branch makes the offsets constants).
Compiled once per machine (``cache=True``), ``error_model="numpy"`` (a division is the IEEE one: no zero test,
which would be a branch; the forms divide by nothing that can be 0 where their results are used).  Imported only
where numba is.
"""

from __future__ import annotations

import math

import numpy as np

from numba import njit

from ._ik_finish import DOUBLE_ROOT
from ._ik_nb_checks import CHUNK, copy_targets
from ._ik_jit import WRIST_TOL, elbow_plane, elbow_q2, elbow_roots, shoulder_roots, wrist_qb, wrist_rest

#: the scratch layout (rows of S) is shared with the walk over the branches (_ik_nb_elbow)
__all__ = [
    "CHUNK", "ROWS", "elbow_stages", "RC1", "RC2", "RC3", "RCA", "RCB", "RCC", "RF2", "RQ1", "RQ2", "RQ3",
    "RQA", "RQB", "RQC", "RS1", "RS2", "RS3", "RSA", "RSB", "RSC", "RSG", "RST", "RX", "RXW", "RT", "RF3", "RL2",
    "RPE", "RRE", "RVF", "RPO", "RLB", "RW2", "RFL", "LAYOUT", "FOLD_GROUPS",
]
# rows of S: per pose, then per branch (s1: 2, k2 = 2 s1 + s3: 4, k = 2 k2 + s5: 8)
RXW, RW, RY0, RY2, RST = 0, 3, 6, 9, 12  # wrist centre (world, frame of C0), columns 0 and 2 of T_R R6ᵀ, status
RQ1, RC1, RS1, RG, RX = 13, 15, 17, 19, 23  # per s1: q1 and its cos, sin; (g0, g1) at RG + 2 s1; the elbow's x
RQ3, RC3, RS3, RQ2, RC2, RS2, RF2 = 25, 29, 33, 37, 41, 45, 49  # per k2
RM = 53  # per k2: m00, m10, m20, m02, m12, m22 of M = R_0_3ᵀ T_R R6ᵀ at RM + 6 k2
RQB, RCB, RSB, RQA, RQC, RSG, RCA, RSA, RCC, RSC = 77, 85, 93, 101, 109, 117, 125, 133, 141, 149  # per k
# the target's top 3×4 (row-major, copied first: the stages then read no other array); rows of the checks
# (_ik_nb_checks): per k2 the frame after joint 3 (x0, x1, x2, y0, …, p2 at RF3 + 12 k2) and the label's
# shoulder and elbow bits; per k the residuals, the verified and polish flags and the label code
RT, RF3, RL2, RPE, RRE, RVF, RPO, RLB = 157, 169, 217, 221, 229, 237, 245, 253
RW2 = 261  # per k2: 1.0 where the wrist's two roots qb (nearly) coincide (wrist_qb's lo or hi next to 0)
# rows of the fold into the limits (_ik_nb_checks; the joints' rows RQ* then hold the folded values): 1.0 where
# all of a branch's joints so far lie within their limits, plus 2.0 where one of them lies next to an edge of the fold
RFL1, RFL2, RFL = 265, 267, 271  # per s1, per k2, per k
ROWS = 279
#: the rows as the check and fold stages read them (_ik_nb_checks: joint 1 per s1, joints 2, 3 per k2, the wrist's
#: per k; the elbow label's far point is the wrist centre) and the fold's levels (joints 2, 3; then 4, 5, 6)
LAYOUT = (RT, RXW, RF3, RL2, RPE, RRE, RVF, RPO, RLB, RFL1, RFL2, RFL, 0, RQ1, RC1, RS1, 2, RQ2, RC2, RS2, 1, RQ3, RC3,
          RS3, 1, RQA, RCA, RSA, 0, RQB, RCB, RSB, 0, RQC, RCC, RSC, 0)
FOLD_GROUPS = (1, 2, 3, 4, 5)


@njit(cache=True, nogil=True, error_model="numpy")
def elbow_stages(T, s, n, K, S):
    """The candidates of poses T[s:s + n] (n ≤ CHUNK) into S: the wrist centre and shoulder, the elbow, q2 and the
    wrist's qb, the wrist's qa and qc (one loop over the poses per stage and branch)."""
    C0i, consts = K[0:16].reshape((4, 4)), K[16:80].reshape((4, 4, 4))
    K3 = K[192:252].reshape((20, 3))
    R6, R1, R2, R4, R5 = K3[0:3], K3[3:6], K3[6:9], K3[9:12], K3[12:15]
    X_e, p1, a, p2, P = K3[15], K3[16], K3[17], K3[18], K3[19]
    sc, trig, tols = K[252:261], K[261:271], K[295:303]
    tiny = tols[0] * sc[4]
    copy_targets(T, s, n, S, RT)
    _shoulder(n, X_e, C0i, R6, a, sc[0], tiny, tols[1], sc[5], S)
    _elbow(n, 0, R1, p1, sc[1], sc[2], sc[3], trig[8], trig[9], tols[1], S)
    _elbow(n, 1, R1, p1, sc[1], sc[2], sc[3], trig[8], trig[9], tols[1], S)
    wc = (trig[0], trig[1], trig[2], trig[3], trig[4], trig[5], trig[6], trig[7])  # forms.wrist_constants
    _arm(n, 0, R2, p2, P, tiny, consts, wc, S)
    _arm(n, 1, R2, p2, P, tiny, consts, wc, S)
    _arm(n, 2, R2, p2, P, tiny, consts, wc, S)
    _arm(n, 3, R2, p2, P, tiny, consts, wc, S)
    _wrist(n, 0, R4, R5, S)
    _wrist(n, 1, R4, R5, S)
    _wrist(n, 2, R4, R5, S)
    _wrist(n, 3, R4, R5, S)
    _wrist(n, 4, R4, R5, S)
    _wrist(n, 5, R4, R5, S)
    _wrist(n, 6, R4, R5, S)
    _wrist(n, 7, R4, R5, S)


@njit(cache=True, nogil=True, error_model="numpy", inline="always")
def _shoulder(n, X_e, C0i, R6, a, h, tiny, ratio_tol, rho_w, S):
    """Wrist centre, T_R R6ᵀ and the shoulder's roots of each pose (its target from the rows RT); status 1.0 where
    the plain solver decides (joint 1 free, the shoulder equation independent of q1, next to a double root, a wrist
    with no z-row dependence)."""
    for b in range(n):
        t00, t01, t02, t03 = S[RT * CHUNK + b], S[(RT + 1) * CHUNK + b], S[(RT + 2) * CHUNK + b], \
            S[(RT + 3) * CHUNK + b]
        t10, t11, t12, t13 = S[(RT + 4) * CHUNK + b], S[(RT + 5) * CHUNK + b], S[(RT + 6) * CHUNK + b], \
            S[(RT + 7) * CHUNK + b]
        t20, t21, t22, t23 = S[(RT + 8) * CHUNK + b], S[(RT + 9) * CHUNK + b], S[(RT + 10) * CHUNK + b], \
            S[(RT + 11) * CHUNK + b]
        x0 = t00 * X_e[0] + t01 * X_e[1] + t02 * X_e[2] + t03
        x1 = t10 * X_e[0] + t11 * X_e[1] + t12 * X_e[2] + t13
        x2 = t20 * X_e[0] + t21 * X_e[1] + t22 * X_e[2] + t23
        w0 = C0i[0, 0] * x0 + C0i[0, 1] * x1 + C0i[0, 2] * x2 + C0i[0, 3]
        w1 = C0i[1, 0] * x0 + C0i[1, 1] * x1 + C0i[1, 2] * x2 + C0i[1, 3]
        w2 = C0i[2, 0] * x0 + C0i[2, 1] * x1 + C0i[2, 2] * x2 + C0i[2, 3]
        S[RXW * CHUNK + b], S[(RXW + 1) * CHUNK + b], S[(RXW + 2) * CHUNK + b] = x0, x1, x2
        S[RW * CHUNK + b], S[(RW + 1) * CHUNK + b], S[(RW + 2) * CHUNK + b] = w0, w1, w2
        S[RY0 * CHUNK + b] = t00 * R6[0, 0] + t01 * R6[0, 1] + t02 * R6[0, 2]
        S[(RY0 + 1) * CHUNK + b] = t10 * R6[0, 0] + t11 * R6[0, 1] + t12 * R6[0, 2]
        S[(RY0 + 2) * CHUNK + b] = t20 * R6[0, 0] + t21 * R6[0, 1] + t22 * R6[0, 2]
        S[RY2 * CHUNK + b] = t00 * R6[2, 0] + t01 * R6[2, 1] + t02 * R6[2, 2]
        S[(RY2 + 1) * CHUNK + b] = t10 * R6[2, 0] + t11 * R6[2, 1] + t12 * R6[2, 2]
        S[(RY2 + 2) * CHUNK + b] = t20 * R6[2, 0] + t21 * R6[2, 1] + t22 * R6[2, 2]
        q1a, q1b, free1, ratio, c1a, s1a, c1b, s1b = shoulder_roots(w0, w1, w2, a, h, tiny, ratio_tol)
        bad = free1 | ((ratio == 0.0) & math.isnan(q1a)) | (abs(abs(ratio) - 1.0) < DOUBLE_ROOT) | (rho_w < 1e-12)
        S[RST * CHUNK + b] = 1.0 if bad else 0.0
        S[RQ1 * CHUNK + b], S[(RQ1 + 1) * CHUNK + b], S[RC1 * CHUNK + b], S[(RC1 + 1) * CHUNK + b] = q1a, q1b, c1a, c1b
        S[RS1 * CHUNK + b], S[(RS1 + 1) * CHUNK + b] = s1a, s1b


@njit(cache=True, nogil=True, error_model="numpy", inline="always")
def _elbow(n, s1, R1, p1, na, nb, base3, cb3, sb3, ratio_tol, S):
    """The elbow's two roots q3 for the shoulder root s1 of each pose (elbow_plane, elbow_roots)."""
    k = 2 * s1
    o1, og, oq, oc, on = s1 * CHUNK, (RG + k) * CHUNK, (RQ3 + k) * CHUNK, (RC3 + k) * CHUNK, (RS3 + k) * CHUNK
    for b in range(n):
        g0, g1 = elbow_plane(S[RC1 * CHUNK + o1 + b], S[RS1 * CHUNK + o1 + b], S[RW * CHUNK + b],
                             S[(RW + 1) * CHUNK + b], S[(RW + 2) * CHUNK + b], R1, p1)
        q3a, q3b, x, c3a, s3a, c3b, s3b = elbow_roots(np.sqrt(g0 * g0 + g1 * g1), na, nb, base3, cb3, sb3,
                                                      ratio_tol)
        S[og + b], S[og + CHUNK + b], S[RX * CHUNK + o1 + b] = g0, g1, x
        S[oq + b], S[oc + b], S[on + b] = q3a, c3a, s3a
        S[oq + CHUNK + b], S[oc + CHUNK + b], S[on + CHUNK + b] = q3b, c3b, s3b


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
    R_0_3 = C0 Rz(q1) C1 Rz(q2) C2 Rz(q3) C3), the wrist's two roots qb (wrist_qb) and whether they (nearly)
    coincide: the wrist's axes coplanar, a singularity of any three-axis wrist (for the Puma's, axes 4 and 6 are
    then aligned too; for a wrist of other twists the two roots merge while qa and qc stay determined)."""
    s1, k = k2 >> 1, 2 * k2
    o1, o2, om, ob = s1 * CHUNK, k2 * CHUNK, (RM + 6 * k2) * CHUNK, k * CHUNK
    C0 = (consts[0, 0, 0], consts[0, 1, 0], consts[0, 2, 0], consts[0, 0, 1], consts[0, 1, 1], consts[0, 2, 1],
          consts[0, 0, 2], consts[0, 1, 2], consts[0, 2, 2])  # the columns of C0
    for b in range(n):
        c1, sn1, c3, sn3 = S[RC1 * CHUNK + o1 + b], S[RS1 * CHUNK + o1 + b], S[RC3 * CHUNK + o2 + b], \
            S[RS3 * CHUNK + o2 + b]
        q2, free2, _vxy, c2, sn2 = elbow_q2(S[RG * CHUNK + 2 * o1 + b], S[(RG + 1) * CHUNK + 2 * o1 + b], c3, sn3,
                                            R2, p2, P, tiny)
        S[RQ2 * CHUNK + o2 + b], S[RC2 * CHUNK + o2 + b], S[RS2 * CHUNK + o2 + b] = q2, c2, sn2
        S[RF2 * CHUNK + o2 + b] = 1.0 if free2 else 0.0
        F = _turn(consts, 2, c2, sn2, _turn(consts, 1, c1, sn1, C0))
        x0, x1, x2, y0, y1, y2, z0, z1, z2 = _turn(consts, 3, c3, sn3, F)
        u0, u1, u2 = S[RY0 * CHUNK + b], S[(RY0 + 1) * CHUNK + b], S[(RY0 + 2) * CHUNK + b]
        S[om + b] = x0 * u0 + x1 * u1 + x2 * u2
        S[om + CHUNK + b] = y0 * u0 + y1 * u1 + y2 * u2
        S[om + 2 * CHUNK + b] = z0 * u0 + z1 * u1 + z2 * u2
        u0, u1, u2 = S[RY2 * CHUNK + b], S[(RY2 + 1) * CHUNK + b], S[(RY2 + 2) * CHUNK + b]
        m02, m12, m22 = x0 * u0 + x1 * u1 + x2 * u2, y0 * u0 + y1 * u1 + y2 * u2, z0 * u0 + z1 * u1 + z2 * u2
        S[om + 3 * CHUNK + b], S[om + 4 * CHUNK + b], S[om + 5 * CHUNK + b] = m02, m12, m22
        qba, qbb, lo, hi, cba, sba, cbb, sbb = wrist_qb(m02, m12, m22, wc, WRIST_TOL)
        least = min(lo, hi)
        S[RW2 * CHUNK + o2 + b] = 1.0 if (least < 1e-12) & (least > -2.0 * WRIST_TOL) else 0.0
        S[RQB * CHUNK + ob + b], S[RCB * CHUNK + ob + b], S[RSB * CHUNK + ob + b] = qba, cba, sba
        S[(RQB + 1) * CHUNK + ob + b], S[(RCB + 1) * CHUNK + ob + b], S[(RSB + 1) * CHUNK + ob + b] = qbb, cbb, sbb


@njit(cache=True, nogil=True, error_model="numpy", inline="always")
def _wrist(n, k, R4, R5, S):
    """For the candidate k = 2 k2 + s5 of each pose: qa, qc (wrist_rest), their cos and sin, the singular flag."""
    m, o = (RM + 6 * (k >> 1)) * CHUNK, k * CHUNK
    for b in range(n):
        qa, qc, singular, _sign, _vxy, _cb, _sb, ca, sa, cc, sc = wrist_rest(
            S[RQB * CHUNK + o + b], S[RCB * CHUNK + o + b], S[RSB * CHUNK + o + b], S[m + b], S[m + CHUNK + b],
            S[m + 2 * CHUNK + b], S[m + 3 * CHUNK + b], S[m + 4 * CHUNK + b], R4, R5)
        S[RQA * CHUNK + o + b], S[RQC * CHUNK + o + b], S[RSG * CHUNK + o + b] = qa, qc, 1.0 if singular else 0.0
        S[RCA * CHUNK + o + b], S[RSA * CHUNK + o + b], S[RCC * CHUNK + o + b], S[RSC * CHUNK + o + b] = ca, sa, cc, sc
