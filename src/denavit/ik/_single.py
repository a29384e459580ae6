"""One-target Levenberg–Marquardt attempt in plain Python floats (the single-call fast path of ``solve_ik``).

For one target, numpy's fixed cost per call (~1–5 µs per ufunc on arrays of 3–36 numbers) dominates the
batched solver of :mod:`._numeric`: one iteration there is ~60 small array operations.  This module runs
the *first* attempt of that solver — from the seed, joint limits ignored during the iteration and the end
point folded by whole turns — with lists of floats and ``math``: the same joint-screw chain
``C0 J1(q1) C1 ⋯ Jn(qn) Cn`` of :mod:`denavit.chain` as :class:`._kernel.Kernel`, the same residual and
geometric Jacobian

    e = W (p_t − p, log(R_t Rᵀ)),   revolute k: J_k = (z_k × (p_e − o_k), z_k),  prismatic k: J_k = (z_k, 0)

(Spong, Hutchinson & Vidyasagar 2006, eq. 4.52–4.53) and the same LM rules (damping ×0.2 on an accepted
step, ×8 on a rejected one, stop when flat, stuck or out of iterations; Marquardt 1963).  The damped normal
equations (JᵀJ + λI) Δq = Jᵀe are solved by a hand-written Cholesky factorisation (the matrix is symmetric
positive definite for λ > 0; Golub & Van Loan 2013, Alg. 4.2.1).

The caller (``solve_ik``) decides success by :func:`forward_kinematics`, as the batched path does, and
falls back to the batched path (random restarts, rescue, reasons) whenever this attempt does not end in a
solution within the limits, so the quality of the result is that of the batched solver.
"""

from __future__ import annotations

from math import acos, hypot, pi, sin, sqrt

import numpy as np

from ..chain import chain_of, screw_walk_floats, screws_of
from ..model import DHRobot
from ..numeric import forward_kinematics
from ._residual import LAMBDA0, LAMBDA_MAX, IKResult, rotation_log

__all__ = ["SingleChain", "single_chain"]

_TWO_PI = 2.0 * pi


def _wrap(x: float) -> float:
    return pi - (pi - x) % _TWO_PI  # into (−π, π], as numpy's pi − mod(pi − x, 2π)


class SingleChain:
    """One arm's residual and Jacobian in floats (build with :func:`single_chain`, cached per robot)."""

    def __init__(self, robot: DHRobot) -> None:
        self.screws = screws_of(robot)
        self.n = self.screws.n
        self.prismatic = self.screws.floats[2]

    def residual(self, q, Rt, pt, w):
        """Weighted residual e (6 floats) and weighted Jacobian columns (n lists of 6 floats) at q."""
        rows, axes = screw_walk_floats(self.screws, q)
        # M = R_t Rᵀ: M[i][j] = Σ_m Rt[i][m] R[j][m]
        pe = (rows[0][3], rows[1][3], rows[2][3])
        M = [[Rt[i][0] * R[0] + Rt[i][1] * R[1] + Rt[i][2] * R[2] for R in rows] for i in range(3)]
        w0, w1, w2, w3, w4, w5 = w
        r0, r1, r2 = _log(M)
        e = [(pt[0] - pe[0]) * w0, (pt[1] - pe[1]) * w1, (pt[2] - pe[2]) * w2, r0 * w3, r1 * w4, r2 * w5]
        J = []
        for k in range(self.n):
            z0, z1, z2, o0, o1, o2 = axes[k]
            if self.prismatic[k]:
                J.append([z0 * w0, z1 * w1, z2 * w2, 0.0, 0.0, 0.0])
            else:
                d0, d1, d2 = pe[0] - o0, pe[1] - o1, pe[2] - o2
                J.append([(z1 * d2 - z2 * d1) * w0, (z2 * d0 - z0 * d2) * w1, (z0 * d1 - z1 * d0) * w2,
                          z0 * w3, z1 * w4, z2 * w5])
        return e, J


def _log(M) -> list:
    """Rotation vector of a 3×3 rotation (lists); the near-π case goes to ``rotation_log``."""
    cs = (M[0][0] + M[1][1] + M[2][2] - 1.0) / 2.0
    cs = -1.0 if cs < -1.0 else (1.0 if cs > 1.0 else cs)
    if cs < -0.9:
        return rotation_log(np.array(M)).tolist()
    theta = acos(cs)
    if theta < 1e-6:
        f = 0.5 + theta * theta / 12.0
    else:
        s = sin(theta)
        f = theta / (2.0 * (1.0 if s == 0.0 else s))
    return [(M[2][1] - M[1][2]) * f, (M[0][2] - M[2][0]) * f, (M[1][0] - M[0][1]) * f]


def damped_step(J, e, lam: float) -> list:
    """Δq solving (JᵀJ + λI) Δq = Jᵀe for Jacobian columns J (n lists of 6) by Cholesky, in floats."""
    n = len(J)
    A = [[0.0] * n for _ in range(n)]
    b = [0.0] * n
    for i in range(n):
        Ji = J[i]
        b[i] = Ji[0] * e[0] + Ji[1] * e[1] + Ji[2] * e[2] + Ji[3] * e[3] + Ji[4] * e[4] + Ji[5] * e[5]
        for j in range(i + 1):
            Jj = J[j]
            A[i][j] = Ji[0] * Jj[0] + Ji[1] * Jj[1] + Ji[2] * Jj[2] + Ji[3] * Jj[3] + Ji[4] * Jj[4] + Ji[5] * Jj[5]
        A[i][i] += lam
    Lc = [[0.0] * n for _ in range(n)]  # A = L Lᵀ, row by row
    for i in range(n):
        Li, Ai = Lc[i], A[i]
        for j in range(i + 1):
            Lj = Lc[j]
            s = Ai[j]
            for k in range(j):
                s -= Li[k] * Lj[k]
            if i == j:
                if s <= 0.0:
                    return [0.0] * n  # numerically not positive definite: no step (rejected as not better)
                Li[i] = sqrt(s)
            else:
                Li[j] = s / Lj[j]
    y = [0.0] * n  # L y = b
    for i in range(n):
        Li, s = Lc[i], b[i]
        for k in range(i):
            s -= Li[k] * y[k]
        y[i] = s / Li[i]
    x = [0.0] * n  # Lᵀ x = y
    for i in range(n - 1, -1, -1):
        s = y[i]
        for k in range(i + 1, n):
            s -= Lc[k][i] * x[k]
        x[i] = s / Lc[i][i]
    return x


def first_attempt(chain: SingleChain, q0, T, w, lo, hi, revolute, max_iter: int, tol: float, L: float,
                  lambda0: float, lambda_max: float):
    """LM from q0 (floats), limits ignored while iterating; the end point folded into the limits.

    Returns (q, iterations, status): status ``"ok"`` (converged, folded q inside the limits) or ``"fail"``
    (converged outside the limits, stalled or out of iterations) — the batched solver takes over then.
    """
    Rt = [[float(T[i][j]) for j in range(3)] for i in range(3)]
    pt = [float(T[0][3]), float(T[1][3]), float(T[2][3])]
    n = chain.n
    q = [_wrap(q0[k]) if revolute[k] else q0[k] for k in range(n)]
    e, J = chain.residual(q, Rt, pt, w)
    cost = sum(v * v for v in e)
    lam = lambda0 * L * L
    it = 1
    wp = [1.0 if w[i] > 0 else 0.0 for i in range(3)]
    wr = [1.0 / L if w[i] > 0 else 0.0 for i in range(3, 6)]
    floor, stuck = 1e-12 * L * L, lambda_max * L * L
    while True:
        # converged: the same margin below tol as the batched solver's test
        pe = hypot(e[0] * wp[0], e[1] * wp[1], e[2] * wp[2])
        re = hypot(e[3] * wr[0], e[4] * wr[1], e[5] * wr[2])
        if pe <= 0.5 * tol and re <= 0.5 * tol:
            qf = _fold(q, lo, hi, revolute)
            inside = all(lo[k] - 1e-12 <= qf[k] <= hi[k] + 1e-12 for k in range(n))
            return qf, it, ("ok" if inside else "fail")
        if it > max_iter:
            return q, it, "fail"
        dq = damped_step(J, e, lam)
        q_new = [_wrap(q[k] + dq[k]) if revolute[k] else q[k] + dq[k] for k in range(n)]
        e_new, J_new = chain.residual(q_new, Rt, pt, w)
        c_new = sum(v * v for v in e_new)
        it += 1
        if c_new < cost:
            flat = cost - c_new < 1e-9 * cost
            q, e, J, cost = q_new, e_new, J_new, c_new
            lam = max(lam * 0.2, floor)
            if flat and not _conv(e, wp, wr, tol):
                return q, it, "fail"  # a local minimum with a residual (or unreachable)
        else:
            lam *= 8.0
            if lam > stuck:
                return q, it, "fail"


def _conv(e, wp, wr, tol):
    pe = hypot(e[0] * wp[0], e[1] * wp[1], e[2] * wp[2])
    re = hypot(e[3] * wr[0], e[4] * wr[1], e[5] * wr[2])
    return pe <= 0.5 * tol and re <= 0.5 * tol


def _fold(q, lo, hi, revolute):
    """Revolute angles wrapped into (−π, π], shifted by a whole turn into [lo, hi] where that helps."""
    out = []
    for k, v in enumerate(q):
        if revolute[k]:
            v = _wrap(v)
            shift = _TWO_PI if v < lo[k] else (-_TWO_PI if v > hi[k] else 0.0)
            if shift != 0.0 and lo[k] <= v + shift <= hi[k]:
                v += shift
        out.append(v)
    return out


def single_chain(robot: DHRobot) -> SingleChain:
    """The float chain of a robot (kept with its :func:`denavit.chain.chain_of`: found without hashing it)."""
    memo = chain_of(robot).memo
    single = memo.get("ik_single")
    if single is None:
        single = memo["ik_single"] = SingleChain(robot)
    return single


def solve_single(robot: DHRobot, q0: np.ndarray, T: np.ndarray, w: np.ndarray, w_mask: np.ndarray, limits,
                 max_iter: int, tol: float, L: float):
    """The first attempt of ``solve_ik`` for one target in floats; an ``IKResult`` when it ends in a solution
    within the limits (checked by :func:`forward_kinematics`, as the batched path does), else None."""
    qf, it, status = first_attempt(single_chain(robot), q0.tolist(), T.tolist(), w.tolist(), limits.lo.tolist(),
                                   limits.hi.tolist(), limits.revolute.tolist(), max_iter, tol, L, LAMBDA0,
                                   LAMBDA_MAX)
    if status != "ok":
        return None
    q = limits.project(np.array(qf))
    pe, re = _fk_error(robot, q, T, w_mask.tolist())
    if not (pe <= tol and re <= tol and limits.inside(q)):
        return None
    return IKResult(q, True, pe, re, it, 0, "")


def _fk_error(robot: DHRobot, q: np.ndarray, T: np.ndarray, mask: list) -> tuple[float, float]:
    """Position and orientation error norms of ``forward_kinematics(robot, q)`` against T on the masked rows:
    ``pose_error`` of :mod:`._numeric` for one pose, in floats."""
    F, Tl = forward_kinematics(robot, q).tolist(), T.tolist()
    dp = [(Tl[i][3] - F[i][3]) if mask[i] else 0.0 for i in range(3)]
    M = [[Tl[i][0] * F[j][0] + Tl[i][1] * F[j][1] + Tl[i][2] * F[j][2] for j in range(3)] for i in range(3)]
    dw = [v if mask[3 + i] else 0.0 for i, v in enumerate(_log(M))]
    return hypot(dp[0], dp[1], dp[2]), hypot(dw[0], dw[1], dw[2])
