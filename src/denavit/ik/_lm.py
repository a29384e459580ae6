"""Levenberg–Marquardt IK of one target, written once in the subset of Python that numba compiles.

One LM run (``attempt`` of :func:`bind`) minimises ½‖W e(q)‖² with e = (p_t − p(q), log(R_t R(q)ᵀ)) (world axes,
rotation rows weighted by the arm's length L, masked rows weighted 0); each step solves the damped normal equations

    (J_Wᵀ J_W + λ I) Δq = J_Wᵀ W e,    J_W = W J0

by Cholesky (Golub & Van Loan 2013, Alg. 4.2.1) and is kept only if it lowers the cost: λ × 0.2 then, × 8 on a
rejected step; the run stops converged (both residual norms ≤ tol / 2, a margin for the FK re-check), flat (an
accepted step that barely lowers the cost: a local minimum), stuck (λ > LAMBDA_MAX L²) or out of iterations
(Levenberg 1944; Marquardt 1963; Nakamura & Hanafusa 1986; Sugihara 2011).  ``solve`` runs it for each target
of a batch from its seed, then from random restarts.

Both solvers run this code: ``denavit.solve_ik`` runs ``attempt`` as the first attempt of one target in plain
Python (:mod:`._single`, on lists of floats), and ``denavit.compile`` jits ``solve`` for each arm (a generated
module's ``ik_lm``), so that every iteration runs in machine code.  Both come from :func:`bind`, with the arm's
fused FK + Jacobian function ``fkj(q, P)`` (P[:16] the pose, P[16:] J0 (6, n), both row-major): the plain chain's
in floats, or the generated module's kernel.  Hence only indexing, arithmetic and ``math`` here, on flat buffers
(a list or a 1-D array alike); numpy only in ``solve`` (its scratch arrays, the restarts' generator).
"""

from __future__ import annotations

import math

import numpy as np

from ._residual import LAMBDA0, LAMBDA_MAX

__all__ = ["CLIP_EVERY", "JITTABLE", "RESTART_ITERATIONS", "bind", "buffers", "damped_step", "fold", "pose_residual"]

TWO_PI = 2.0 * math.pi
RESTART_ITERATIONS = 0.3  # iteration budget of a restart, relative to max_iterations
CLIP_EVERY = 2  # restarts 1, 1 + CLIP_EVERY, ... of ``solve`` iterate inside the limits (the others run free)


def fold(q, lo, hi, revolute, shift, clip):
    """In place: revolute values wrapped into (−π, π]; with ``shift`` then moved by a whole turn into [lo, hi]
    where that lands inside; with ``clip`` then every value clipped into [lo, hi]."""
    for k in range(len(q)):
        x = q[k]
        if revolute[k]:
            x = math.pi - (math.pi - x) % TWO_PI  # into (−π, π], as numpy's π − mod(π − x, 2π)
            if shift:
                if x < lo[k] and lo[k] <= x + TWO_PI <= hi[k]:
                    x += TWO_PI
                elif x > hi[k] and lo[k] <= x - TWO_PI <= hi[k]:
                    x -= TWO_PI
        if clip:
            x = min(hi[k], max(lo[k], x))
        q[k] = x


def pose_residual(Tt, P, w, e):
    """e = W (p_t − p, log(R_t Rᵀ)) for the target Tt and the pose P[:16] (4×4, row-major, flat); returns the
    norms of the position and orientation rows that w selects (unweighted: [m], [rad]) and the cost |e|².
    log M = θ/(2 sin θ) (M − Mᵀ)ᵛ, θ = acos((tr M − 1)/2); near π (cos θ < −0.9) the axis from the symmetric part
    (its column of largest diagonal), the sign from (M − Mᵀ)ᵛ (Murray, Li & Sastry 1994, Sec. 2.2)."""
    e[0] = Tt[3] - P[3]
    e[1] = Tt[7] - P[7]
    e[2] = Tt[11] - P[11]
    # M[i][j] = Σ_k Tt[4i + k] P[4j + k]
    r00 = Tt[0] * P[0] + Tt[1] * P[1] + Tt[2] * P[2]
    r01 = Tt[0] * P[4] + Tt[1] * P[5] + Tt[2] * P[6]
    r02 = Tt[0] * P[8] + Tt[1] * P[9] + Tt[2] * P[10]
    r10 = Tt[4] * P[0] + Tt[5] * P[1] + Tt[6] * P[2]
    r11 = Tt[4] * P[4] + Tt[5] * P[5] + Tt[6] * P[6]
    r12 = Tt[4] * P[8] + Tt[5] * P[9] + Tt[6] * P[10]
    r20 = Tt[8] * P[0] + Tt[9] * P[1] + Tt[10] * P[2]
    r21 = Tt[8] * P[4] + Tt[9] * P[5] + Tt[10] * P[6]
    r22 = Tt[8] * P[8] + Tt[9] * P[9] + Tt[10] * P[10]
    c = min(1.0, max(-1.0, 0.5 * (r00 + r11 + r22 - 1.0)))
    theta = math.acos(c)
    v0, v1, v2 = r21 - r12, r02 - r20, r10 - r01
    if c < -0.9:
        if r00 >= r11 and r00 >= r22:
            u0, u1, u2 = r00 - c, 0.5 * (r10 + r01), 0.5 * (r20 + r02)
        elif r11 >= r22:
            u0, u1, u2 = 0.5 * (r01 + r10), r11 - c, 0.5 * (r21 + r12)
        else:
            u0, u1, u2 = 0.5 * (r02 + r20), 0.5 * (r12 + r21), r22 - c
        f = theta / math.sqrt(u0 * u0 + u1 * u1 + u2 * u2)
        if u0 * v0 + u1 * v1 + u2 * v2 < 0.0:
            f = -f
        e[3], e[4], e[5] = f * u0, f * u1, f * u2
    else:
        f = 0.5 + theta * theta / 12.0 if theta < 1e-6 else theta / (2.0 * math.sin(theta))
        e[3], e[4], e[5] = f * v0, f * v1, f * v2
    pe = 0.0
    re = 0.0
    cost = 0.0
    for i in range(6):
        if w[i] != 0.0:
            if i < 3:
                pe += e[i] * e[i]
            else:
                re += e[i] * e[i]
            e[i] *= w[i]
            cost += e[i] * e[i]
        else:
            e[i] = 0.0
    return math.sqrt(pe), math.sqrt(re), cost


def damped_step(P, e, w, lam, n, Jw, A, dq):
    """dq solving (J_Wᵀ J_W + λ I) dq = J_Wᵀ e, J_W = W J0 (J0 at P[16:], (6, n) row-major), by Cholesky in A
    (n × n, flat, lower triangle); a zero step where the matrix is numerically not positive definite (rejected
    then as not better).  Jw: scratch for J_W (6 n).  Row offsets are kept in locals: plain Python runs this too."""
    for r in range(6):
        o, wr = r * n, w[r]
        for i in range(n):
            Jw[o + i] = wr * P[16 + o + i]
    n2, n3, n4, n5 = 2 * n, 3 * n, 4 * n, 5 * n
    for i in range(n):
        a0, a1, a2, a3, a4, a5 = Jw[i], Jw[n + i], Jw[n2 + i], Jw[n3 + i], Jw[n4 + i], Jw[n5 + i]
        dq[i] = a0 * e[0] + a1 * e[1] + a2 * e[2] + a3 * e[3] + a4 * e[4] + a5 * e[5]
        ri = i * n
        for j in range(i + 1):
            A[ri + j] = (a0 * Jw[j] + a1 * Jw[n + j] + a2 * Jw[n2 + j] + a3 * Jw[n3 + j] + a4 * Jw[n4 + j]
                         + a5 * Jw[n5 + j])
        A[ri + i] += lam
    for i in range(n):  # A = C Cᵀ, row by row, C in the lower triangle of A
        ri = i * n
        for j in range(i):
            rj = j * n
            s = A[ri + j]
            for k in range(j):
                s -= A[ri + k] * A[rj + k]
            A[ri + j] = s / A[rj + j]
        s = A[ri + i]
        for k in range(i):
            s -= A[ri + k] * A[ri + k]
        if s <= 0.0:
            for k in range(n):
                dq[k] = 0.0
            return
        A[ri + i] = math.sqrt(s)
    for i in range(n):  # C y = b
        ri = i * n
        s = dq[i]
        for k in range(i):
            s -= A[ri + k] * dq[k]
        dq[i] = s / A[ri + i]
    for i in range(n - 1, -1, -1):  # Cᵀ x = y
        s = dq[i]
        for k in range(i + 1, n):
            s -= A[k * n + i] * dq[k]
        dq[i] = s / A[i * n + i]


def bind(fkj):
    """``(attempt, solve)`` bound to the arm's fused kernel ``fkj(q, P)``: P[:16] the pose at q, P[16:] J0 (6, n),
    both row-major.  The kernel is a closure variable, not an argument: numba compiles a call of a closure
    variable as a direct call, while a compiled function passed as an argument is a value whose address numba
    writes into the machine code (which it then refuses to cache)."""
    attempt = _attempt_of(fkj)
    return attempt, _solve_of(fkj, attempt)


def _attempt_of(fkj):
    def attempt(Tt, q, lo, hi, revolute, w, L, tol, max_iter, clip, buf):
        """One LM run from q, changed in place to its end point (folded into the limits when converged); without
        ``clip`` it ignores the limits (revolute values wrapped), with it every step is folded and clipped into them.
        ``buf``: :func:`buffers`.  Returns (iterations, converged within the limits, the end point's position
        error, orientation error and cost as :func:`pose_residual`'s)."""
        P, Pn, e, en, A, dq, qn = buf
        n = len(q)
        fold(q, lo, hi, revolute, clip, clip)
        fkj(q, P)
        pe, re, cost = pose_residual(Tt, P, w, e)
        lam, floor, stuck, half, it = LAMBDA0 * L * L, 1e-12 * L * L, LAMBDA_MAX * L * L, 0.5 * tol, 1
        while True:
            if pe <= half and re <= half:
                for k in range(n):
                    qn[k] = q[k]
                fold(q, lo, hi, revolute, True, False)
                inside, moved = True, False
                for k in range(n):  # moved: the folded point judged on its own pose
                    inside = inside and lo[k] - 1e-12 <= q[k] <= hi[k] + 1e-12
                    moved = moved or q[k] != qn[k]
                if moved:
                    fkj(q, P)
                    pe, re, cost = pose_residual(Tt, P, w, e)
                return it, inside, pe, re, cost
            if it > max_iter:
                return it, False, pe, re, cost
            damped_step(P, e, w, lam, n, Pn, A, dq)  # Pn as J_W's scratch: the trial point's pose comes next
            for k in range(n):
                qn[k] = q[k] + dq[k]
            fold(qn, lo, hi, revolute, clip, clip)
            fkj(qn, Pn)
            pe_n, re_n, cost_n = pose_residual(Tt, Pn, w, en)
            it += 1
            if cost_n < cost:  # accepted: the new point's pose and Jacobian are already in Pn
                flat = cost - cost_n < 1e-9 * cost
                for k in range(n):
                    q[k] = qn[k]
                P, Pn, e, en = Pn, P, en, e
                pe, re, cost = pe_n, re_n, cost_n
                lam = max(lam * 0.2, floor)
                if flat and not (pe <= half and re <= half):
                    return it, False, pe, re, cost  # a local minimum with a residual (or unreachable)
            else:
                lam *= 8.0
                if lam > stuck:
                    return it, False, pe, re, cost

    return attempt


def buffers(n):
    """The scratch of ``attempt`` for n joints, as arrays."""
    m = 16 + 6 * n
    return np.empty(m), np.empty(m), np.empty(6), np.empty(6), np.empty(n * n), np.empty(n), np.empty(n)


def _solve_of(fkj, attempt):
    def solve(T, q0, lo, hi, slo, shi, revolute, w, L, tol, max_iterations, restarts, seed, first, out_q, out_info):
        """``attempt`` for each target T[b] (B, 4, 4) from q0[b] brought into the limits (iterating freely, as the plain solver's first
        attempt), then from random q in [slo, shi] (restarts 1, 1 + CLIP_EVERY, ... iterated inside the limits, the
        others freely) until one converges within the limits; out_q[b] that solution or the best end point,
        out_info[b] = (success, position error, orientation error, iterations, restarts), the errors of out_q[b]
        on its own pose.  The restarts of target b are drawn from a generator seeded by (seed, first + b), first
        being the index of T[0] in the whole batch: a batch split into blocks over threads gives every target the
        draws of the whole batch in one call (numba's generator state is per thread)."""
        n = q0.shape[1]
        buf = buffers(n)
        q = np.empty(n)
        T16 = T.reshape((T.shape[0], 16))
        for b in range(T.shape[0]):
            Tt = T16[b]
            best_pe, best_re, best_cost = np.inf, np.inf, np.inf
            iterations = 0
            done = False
            used = 0
            for used in range(restarts + 1):
                if used == 0:  # the seed projected into the limits, as solve_ik does (JointLimits.project)
                    for k in range(n):
                        q[k] = q0[b, k]
                    fold(q, lo, hi, revolute, True, True)
                else:
                    if used == 1:
                        np.random.seed((seed + 1000003 * (first + b)) & 0x7FFFFFFF)
                    for k in range(n):
                        q[k] = slo[k] + (shi[k] - slo[k]) * np.random.random()
                budget = max_iterations if used == 0 else max(1, int(RESTART_ITERATIONS * max_iterations))
                it, ok, pe, re, cost = attempt(Tt, q, lo, hi, revolute, w, L, tol, budget, used % CLIP_EVERY == 1,
                                               buf)
                iterations += it
                if ok and pe <= tol and re <= tol:
                    best_pe, best_re = pe, re
                    for k in range(n):
                        out_q[b, k] = q[k]
                    done = True
                    break
                if cost < best_cost:
                    best_cost, best_pe, best_re = cost, pe, re
                    for k in range(n):
                        out_q[b, k] = q[k]
            out_info[b, 0] = 1.0 if done else 0.0
            out_info[b, 1] = best_pe
            out_info[b, 2] = best_re
            out_info[b, 3] = iterations
            out_info[b, 4] = used

    return solve


#: What ``denavit.compile`` makes callable from numba-compiled code (numba.extending.register_jitable), with the
#: two functions of :func:`bind`.
JITTABLE = (fold, pose_residual, damped_step, buffers)
