"""The UR-class closed form (6R, axes 2, 3, 4 parallel, axes 5, 6 meeting) compiled by numba, once per machine
(``cache=True``): see :mod:`._ik_parallel` for the method and the hand-over rules (NEAR_SINGULAR, COND_MAX); the
formulas of :mod:`denavit.ik.forms` (jitted through :mod:`._ik_jit`), verified, folded, merged and sorted by
:func:`._ik_nb_finish.ik_finish`.  The constants (``PARALLEL_LAYOUT``) are arguments.  Imported only where numba is.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from ._ik_finish import DOUBLE_ROOT
from ._ik_jit import atan2, elbow_q2, trig_pairs, trig_roots, wrist_qb
from ._ik_nb_finish import ik_finish

__all__ = ["ik_parallel_packed", "frame1", "next_frame"]


@njit(cache=True, nogil=True)
def ik_parallel_packed(T, K, f, i):
    """All solutions of each pose T[b] of a 6R UR-class arm, the constants in K (PARALLEL_LAYOUT order); outputs as
    ik_elbow_packed: f[b, :k, :6] solutions (folded, sorted), f[b, :k, 6:8] (position, orientation) residuals,
    f[b, :j, 8:] the solutions outside the limits; i[b, :k] label codes (1 shoulder left, 2 elbow down, 4 wrist
    flip), i[b, 8:11] = (k, j, 1 if the plain solver must decide), i[b, 11:20] the batched layout's slots."""
    Q_e, C0i, C = K[0:3], K[3:19].reshape((4, 4)), K[19:131].reshape((7, 4, 4))
    a, sc, lo_lim, hi_lim = K[131:134], K[134:145], K[145:151], K[151:157]
    rev, theta, tols, far, trig = K[157:163], K[163:169], K[169:177], K[177], K[178:186]
    # scratch: two float and one flag allocation per call (not per pose); every view made here, once (a view per
    # pose is an atomic reference count and its release)
    ws = np.empty(76)
    X, perm, vr = ws[0:3], ws[3:11], ws[11:31]  # perm: the candidate in each sorted slot
    V, TC, cols, tl = ws[31:34], ws[34:43].reshape((3, 3)), ws[43:55].reshape((4, 3)), ws[55:67].reshape((4, 3))
    xr, wv, g = ws[67:70], ws[70:73], ws[73:76]
    R2, p2, p3 = C[2, :3, :3], C[2, :3, 3], C[3, :3, 3]
    w = np.empty((27, 36))
    cand, cerr, cs = w[0:8, 0:6], w[0:8, 6:8], w[0:8, 8:20]  # cs: cos, sin of the joints (closed form's, for the FK)
    frames, P, F = w[8:16], w[16:23, 0:12], w[23:27, 0:4]  # frames after joints 1-3 (from the FK, for the labels)
    flags = np.zeros(24, dtype=np.bool_)
    fq, fe, fo, rank = f[:, :, :6], f[:, :, 6:8], f[:, :, 8:], i[:, 11:20]
    ct5, st5 = math.cos(theta[4]), math.sin(theta[4])  # the wrist label's sin(q5 + theta5), by the sum formula
    for b in range(T.shape[0]):
        if not math.sqrt(T[b, 0, 3] ** 2 + T[b, 1, 3] ** 2 + T[b, 2, 3] ** 2) <= far:
            i[b, 8], i[b, 9], i[b, 10] = 0, 0, 1  # beyond every reachable point: the plain solver's stand-in
            continue
        ncand, status = _parallel_candidates(T, b, Q_e, C0i, C, a, sc, trig, tols, cand, cs, V, TC, cols, tl, xr,
                                             wv, g, R2, p2, p3)
        kept, n_out, st = ik_finish(T, b, cand, cerr, ncand, lo_lim, hi_lim, rev, tols, F, frames, flags,
                                    fq, fe, fo, perm, C, cs, True, rank, P, vr)
        for r in range(3):
            X[r] = T[b, r, 0] * Q_e[0] + T[b, r, 1] * Q_e[1] + T[b, r, 2] * Q_e[2] + T[b, r, 3]
        for s in range(kept):
            k = int(perm[s])
            i[b, s] = _parallel_label(frames, k, cs[k, 9] * ct5 + cs[k, 8] * st5, X, C)
        i[b, 8], i[b, 9], i[b, 10] = kept, n_out, max(status, st)


@njit(cache=True, nogil=True, inline="always")  # into ik_parallel_packed (no call with eleven arrays)
def _parallel_candidates(T, b, Q_e, C0i, C, a, sc, trig, tols, cand, cs, V, TC, cols, tl, xr, w, g, R2, p2, p3):
    """The candidates of pose b in the plain plan's order (q1 root, q5 root, q3 root; + before -) into cand, the
    cosines and sines of their joints into cs (8, 12: cos q1, sin q1, cos q2, …; for the verifying FK, which then
    computes none); trig: the wrist's constants (forms.wrist_constants); V, TC, cols, tl, xr, w, g: scratch; R2, p2,
    p3: views of C (all made once per call of the kernel, not per pose).  Returns (count, status)."""
    c0, sigma, rho_w, ap2, bp2, k0 = sc[0], sc[1], sc[2], sc[6], sc[7], sc[8]
    tol, reach = tols[1], tols[7]
    wide = sc[9] * reach  # NEAR_SINGULAR
    wc = (trig[0], trig[1], trig[2], trig[3], trig[4], trig[5], trig[6], trig[7])  # forms.wrist_constants
    scale = max(reach, 1e-3)
    status = 0
    ncand = 0
    for r in range(3):  # Q in the world, then in the frame of C0
        w[r] = T[b, r, 0] * Q_e[0] + T[b, r, 1] * Q_e[1] + T[b, r, 2] * Q_e[2] + T[b, r, 3]
    for r in range(3):
        V[r] = C0i[r, 0] * w[0] + C0i[r, 1] * w[1] + C0i[r, 2] * w[2] + C0i[r, 3]
    for r in range(3):  # T_R C6_R^T
        for j in range(3):
            TC[r, j] = T[b, r, 0] * C[6, j, 0] + T[b, r, 1] * C[6, j, 1] + T[b, r, 2] * C[6, j, 2]
    # the formulas of denavit.ik.forms (the plain solver's own functions, jitted), in the plain plan's order
    # q1: (Rz(q1) a) . V = h + a . pc1 (subproblem 1, as solve_trig)
    ea, eb = a[0] * V[0] + a[1] * V[1], a[0] * V[1] - a[1] * V[0]
    q1a, q1b, rho, ratio = trig_roots(ea, eb, c0 - a[2] * V[2], tol)
    c1a, s1a, c1b, s1b = trig_pairs(ea, eb, rho, ratio, tol)  # cos, sin of the roots, algebraically
    if rho <= max(wide, 1e-11):
        return 0, 1  # Q on (or next to) axis 1
    if abs(abs(ratio) - 1.0) < DOUBLE_ROOT:
        status = 1  # next to a double root: the plain solver polishes and looks for partners
    if math.isnan(q1a) or rho_w < 1e-12:
        return 0, max(status, 1 if rho_w < 1e-12 else 0)
    r1 = min(1.0, max(-1.0, ratio))
    e1 = max(1.0, scale / rho) / max(math.sqrt((1.0 - r1) * (1.0 + r1)), 1e-300)  # rounding error of q1 [eps]
    for s1 in range(2):  # (COND_MAX; 1/sin of the root's distance from the double root)
        q1, c1, s1v = (q1a, c1a, s1a) if s1 == 0 else (q1b, c1b, s1b)
        frame1(C, c1, s1v, cols)  # F1 = C0 Rz(q1) C1: columns x, y, z, origin
        RL02 = cols[0, 0] * TC[0, 2] + cols[0, 1] * TC[1, 2] + cols[0, 2] * TC[2, 2]
        RL12 = cols[1, 0] * TC[0, 2] + cols[1, 1] * TC[1, 2] + cols[1, 2] * TC[2, 2]
        RL22 = cols[2, 0] * TC[0, 2] + cols[2, 1] * TC[1, 2] + cols[2, 2] * TC[2, 2]
        ell0 = cols[2, 0] * TC[0, 0] + cols[2, 1] * TC[1, 0] + cols[2, 2] * TC[2, 0]
        ell1 = cols[2, 0] * TC[0, 1] + cols[2, 1] * TC[1, 1] + cols[2, 2] * TC[2, 1]
        # q5: r^T Rz(q5) u = m_z, m = (RL e_z) with its z scaled by sigma (axis_angle_roots)
        q5a, q5b, lo, hi, c5a, s5a, c5b, s5b = wrist_qb(RL02, RL12, sigma * RL22, wc, tol)
        if -2.0 * tol < min(lo, hi) < 1e-12:
            status = 1  # the two q5 roots (nearly) coincide
        if math.isnan(q5a):
            continue
        e5 = (1.0 + e1) / max(rho_w * math.sin(0.5 * (q5a - q5b)), 1e-300)
        for s5 in range(2):
            q5, c5, s5v = (q5a, c5a, s5a) if s5 == 0 else (q5b, c5b, s5b)
            t0, t1, t2 = C[4, 2, 0] * c5 + C[4, 2, 1] * s5v, -C[4, 2, 0] * s5v + C[4, 2, 1] * c5, C[4, 2, 2]
            y0 = sigma * (t0 * C[5, 0, 0] + t1 * C[5, 1, 0] + t2 * C[5, 2, 0])
            y1 = sigma * (t0 * C[5, 0, 1] + t1 * C[5, 1, 1] + t2 * C[5, 2, 1])
            if math.sqrt(y0 * y0 + y1 * y1) < sc[9]:
                status = 1  # axis 6 parallel to axes 2-4: q6 and q2 + q3 + q4 coupled (a continuum)
            q6 = atan2(y1, y0) - atan2(ell1, ell0)
            e6 = (1.0 + e1 + e5) / max(math.sqrt(y0 * y0 + y1 * y1), 1e-300)
            eP = 1.0 + e1 + e5 + e6  # of the point P, per reach
            c6, s6v = _angle_between(y0, y1, ell0, ell1)
            _tail(C, c5, s5v, c6, s6v, tl)  # C4 Rz(q5) C5 Rz(q6) C6: rotation columns, origin
            # X = F1^-1 T tail^-1: its origin P and first column xr
            for r in range(3):
                w[r] = T[b, r, 3] - cols[3, r]
                for j in range(3):
                    m_rj = T[b, r, 0] * tl[0, j] + T[b, r, 1] * tl[1, j] + T[b, r, 2] * tl[2, j]  # (T_R Rt^T)[r, j]
                    w[r] -= m_rj * tl[3, j]
            P0 = cols[0, 0] * w[0] + cols[0, 1] * w[1] + cols[0, 2] * w[2]
            P1 = cols[1, 0] * w[0] + cols[1, 1] * w[1] + cols[1, 2] * w[2]
            for r in range(3):
                g[r] = T[b, r, 0] * tl[0, 0] + T[b, r, 1] * tl[1, 0] + T[b, r, 2] * tl[2, 0]
            for r in range(3):
                xr[r] = cols[r, 0] * g[0] + cols[r, 1] * g[1] + cols[r, 2] * g[2]
            # the planar pair (law of cosines for q3, then q2 turns v onto P), as _planar_pair
            if math.sqrt(P0 * P0 + P1 * P1) < wide:
                status = 1  # Q on (or next to) axis 2
            q3a, q3b, rho3, ratio3 = trig_roots(ap2, bp2, P0 * P0 + P1 * P1 + k0, tol)
            c3a, s3a, c3b, s3b = trig_pairs(ap2, bp2, rho3, ratio3, tol)
            if rho3 <= 1e-12:
                status = 1
                continue
            if abs(abs(ratio3) - 1.0) < DOUBLE_ROOT:
                status = 1  # elbow stretched or folded: a double root
            if math.isnan(q3a):
                continue
            r3 = min(1.0, max(-1.0, ratio3))  # sin of the root's distance from the double root: sqrt(1 - r3^2)
            e3 = eP * 2.0 * math.sqrt(P0 * P0 + P1 * P1) * scale / max(rho3 * math.sqrt((1.0 - r3) * (1.0 + r3)),
                                                                          1e-300)
            for s3 in range(2):
                q3, c3, s3v = (q3a, c3a, s3a) if s3 == 0 else (q3b, c3b, s3b)
                q2, _free, vxy, c2, s2v = elbow_q2(P0, P1, c3, s3v, R2, p2, p3, 0.0)
                if vxy < wide:
                    status = 1
                e2 = (eP + e3) * scale / max(min(math.sqrt(P0 * P0 + P1 * P1), vxy), 1e-300)
                if e2 + e3 + eP > sc[10]:  # q4's error is about that sum
                    status = 1  # ill-conditioned (COND_MAX): the two solvers' rounding could differ by > 1e-10
                # q4 = atan2(N10, N00), N = (Rz(q2) R2 Rz(q3) R3)^T X_R: column 0 by R3^T Rz(q3)^T R2^T Rz(q2)^T xr
                z0, z1, z2 = c2 * xr[0] + s2v * xr[1], -s2v * xr[0] + c2 * xr[1], xr[2]
                e0 = C[2, 0, 0] * z0 + C[2, 1, 0] * z1 + C[2, 2, 0] * z2
                e1 = C[2, 0, 1] * z0 + C[2, 1, 1] * z1 + C[2, 2, 1] * z2
                e2 = C[2, 0, 2] * z0 + C[2, 1, 2] * z1 + C[2, 2, 2] * z2
                f0, f1 = c3 * e0 + s3v * e1, -s3v * e0 + c3 * e1
                N00 = C[3, 0, 0] * f0 + C[3, 1, 0] * f1 + C[3, 2, 0] * e2
                N10 = C[3, 0, 1] * f0 + C[3, 1, 1] * f1 + C[3, 2, 1] * e2
                q4 = atan2(N10, N00)
                c4, s4 = _angle_between(N00, N10, 1.0, 0.0)
                cs[ncand, 0], cs[ncand, 1], cs[ncand, 2], cs[ncand, 3] = c1, s1v, c2, s2v
                cs[ncand, 4], cs[ncand, 5], cs[ncand, 6], cs[ncand, 7] = c3, s3v, c4, s4
                cs[ncand, 8], cs[ncand, 9], cs[ncand, 10], cs[ncand, 11] = c5, s5v, c6, s6v
                cand[ncand, 0], cand[ncand, 1], cand[ncand, 2] = q1, q2, q3
                cand[ncand, 3], cand[ncand, 4], cand[ncand, 5] = q4, q5, q6
                ncand += 1
    return ncand, status


@njit(cache=True, nogil=True, inline="always")  # no libm call
def _angle_between(x0, x1, u0, u1):
    """(cos θ, sin θ) of θ = atan2(x1, x0) − atan2(u1, u0), the angle from u to x (the normalised dot and cross
    products; within a few ulps of cos and sin of the difference of the two atan2), (1, 0) where x or u is 0."""
    d, c = x0 * u0 + x1 * u1, u0 * x1 - u1 * x0
    h = math.sqrt(d * d + c * c)
    if h == 0.0:
        return 1.0, 0.0
    return d / h, c / h


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


@njit(cache=True, nogil=True, inline="always")  # no call passing arrays
def _tail(C, c5, s5, c6, s6, tl):
    """Columns and origin of C4 Rz(q5) C5 Rz(q6) C6 into tl (4, 3), from the cosines and sines of q5, q6."""
    for r in range(3):
        x, y, z, p = C[4, r, 0], C[4, r, 1], C[4, r, 2], C[4, r, 3]
        x, y = c5 * x + s5 * y, c5 * y - s5 * x
        x, y, z, p = (x * C[5, 0, 0] + y * C[5, 1, 0] + z * C[5, 2, 0],
                      x * C[5, 0, 1] + y * C[5, 1, 1] + z * C[5, 2, 1],
                      x * C[5, 0, 2] + y * C[5, 1, 2] + z * C[5, 2, 2],
                      p + x * C[5, 0, 3] + y * C[5, 1, 3] + z * C[5, 2, 3])
        x, y = c6 * x + s6 * y, c6 * y - s6 * x
        tl[0, r] = x * C[6, 0, 0] + y * C[6, 1, 0] + z * C[6, 2, 0]
        tl[1, r] = x * C[6, 0, 1] + y * C[6, 1, 1] + z * C[6, 2, 1]
        tl[2, r] = x * C[6, 0, 2] + y * C[6, 1, 2] + z * C[6, 2, 2]
        tl[3, r] = p + x * C[6, 0, 3] + y * C[6, 1, 3] + z * C[6, 2, 3]


@njit(cache=True, nogil=True, inline="always")  # no call passing arrays
def _parallel_label(fr, k, s5, X, C):
    """Label code of one solution (docs/ik.md): 1 shoulder left (x1 . (X - O1) < 0, X the point Q), 2 elbow down
    (the point E of axis 3 on the far side of the line from S to W, a point of axis 4, in the plane normal to
    axis 2, seen from axis 1), 4 wrist flip (s5 = sin(q5 + theta5) < 0, from q5's cosine and sine: it differs in
    sign from the sine of the float only within rounding of 0, the wrist singularity, which is handed over).  fr[k] (36,): columns x, y, z and origin of the
    frames after joints 1, 2, 3, three floats each (from the verifying FK, before the folding into the limits,
    which moves the angles by whole turns; indexed, not sliced: a view is a reference count)."""
    code = 0
    s_right = 0.0
    for r in range(3):
        s_right += fr[k, r] * (X[r] - C[0, r, 3])
    if s_right < 0.0:
        code |= 1
    d0, d1, d2 = fr[k, 33] - fr[k, 9], fr[k, 34] - fr[k, 10], fr[k, 35] - fr[k, 11]  # W - S (origins, joints 3, 1)
    n0 = fr[k, 7] * d2 - fr[k, 8] * d1  # z1 x (W - S)
    n1 = fr[k, 8] * d0 - fr[k, 6] * d2
    n2 = fr[k, 6] * d1 - fr[k, 7] * d0
    towards = 1.0 if C[0, 0, 2] * n0 + C[0, 1, 2] * n1 + C[0, 2, 2] * n2 >= 0.0 else -1.0
    side = (fr[k, 21] - fr[k, 9]) * n0 + (fr[k, 22] - fr[k, 10]) * n1 + (fr[k, 23] - fr[k, 11]) * n2  # (E - S) . n
    if side * towards < 0.0:
        code |= 2
    if s5 < 0.0:
        code |= 4
    return code
