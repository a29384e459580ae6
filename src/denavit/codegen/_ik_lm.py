"""Numeric IK on the generated kernels: Levenberg–Marquardt in numba, one target after another.

The same method as :func:`denavit.solve_ik` (damped least squares on the pose residual e = (p_t − p,
log(R_t Rᵀ)) in world axes, rotation rows scaled by the arm's length L, joint limits enforced by wrapping and
clipping after each step, random restarts inside the limits), but every iteration runs in machine code on the
arm's own FK and Jacobian kernels — no numpy call per step.  The text below is appended to each generated numba
module (it calls that module's ``_fk_jacobian0`` intrinsic: the pose and J0 in one pass); it is fixed text, nothing of the robot
or the user is pasted into it.

References: Levenberg 1944; Marquardt 1963; Nakamura & Hanafusa 1986 (damped least squares); Sugihara 2011
(LM for IK); Murray, Li & Sastry 1994, §2.2 (the rotation logarithm).
"""

from __future__ import annotations

__all__ = ["IK_LM_SOURCE"]

IK_LM_SOURCE = '''

from denavit.codegen._ik_nb_finish import ik_check  # module-level, compiled once per machine


@njit(cache=True, nogil=True)
def _ik_residual(T, P, w, e):
    """e = W (p_t - p, log(R_t R^T)) for the pose P (16 entries, row-major); returns (|position rows|,
    |orientation rows|, cost = |e|^2 / 2) on the masked rows."""
    e[0] = T[0, 3] - P[3]
    e[1] = T[1, 3] - P[7]
    e[2] = T[2, 3] - P[11]
    # R = R_t R^T, entry (i, j) = sum_k T[i, k] P[4 j + k]
    r00 = T[0, 0] * P[0] + T[0, 1] * P[1] + T[0, 2] * P[2]
    r01 = T[0, 0] * P[4] + T[0, 1] * P[5] + T[0, 2] * P[6]
    r02 = T[0, 0] * P[8] + T[0, 1] * P[9] + T[0, 2] * P[10]
    r10 = T[1, 0] * P[0] + T[1, 1] * P[1] + T[1, 2] * P[2]
    r11 = T[1, 0] * P[4] + T[1, 1] * P[5] + T[1, 2] * P[6]
    r12 = T[1, 0] * P[8] + T[1, 1] * P[9] + T[1, 2] * P[10]
    r20 = T[2, 0] * P[0] + T[2, 1] * P[1] + T[2, 2] * P[2]
    r21 = T[2, 0] * P[4] + T[2, 1] * P[5] + T[2, 2] * P[6]
    r22 = T[2, 0] * P[8] + T[2, 1] * P[9] + T[2, 2] * P[10]
    c = min(1.0, max(-1.0, 0.5 * (r00 + r11 + r22 - 1.0)))
    theta = math.acos(c)
    v0, v1, v2 = r21 - r12, r02 - r20, r10 - r01
    if c < -0.9:  # near pi: the axis from the symmetric part (column of the largest diagonal), sign from v
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
    return math.sqrt(pe), math.sqrt(re), 0.5 * cost


@njit(cache=True, nogil=True)
def _ik_project(q, lo, hi, revolute, clip):
    """Revolute angles wrapped into (-pi, pi] and moved by a turn into the limits where that fits; with
    ``clip`` every value then clipped into its limits."""
    for k in range(q.shape[0]):
        x = q[k]
        if revolute[k]:
            x = math.pi - ((math.pi - x) % (2.0 * math.pi))
            if x < lo[k] and x + 2.0 * math.pi <= hi[k]:
                x += 2.0 * math.pi
            elif x > hi[k] and x - 2.0 * math.pi >= lo[k]:
                x -= 2.0 * math.pi
        if clip:
            x = min(hi[k], max(lo[k], x))
        q[k] = x


@njit(cache=True, nogil=True)
def ik_lm(T, q0, lo, hi, slo, shi, revolute, w, L, tol, max_iterations, restarts, seed, first, out_q, out_info):
    """LM for each target T[b] from q0[b], then from random q in [slo, shi]; out_info[b] = (success,
    position error, orientation error, iterations, restarts).  Attempts 0, 2, 4, ... keep q inside the limits
    at every step; the others iterate free and fold the result into the limits (a solution outside them is
    often one turn or one clipped step away from one inside).  The random restarts of target b are drawn
    from a generator seeded by (seed, first + b), first being the index of T[0] in the whole batch: a batch
    split into blocks over threads gives every target the same draws as the whole batch in one call."""
    n = q0.shape[1]
    P = np.empty(16 + 6 * n)   # pose then J0, from the fused kernel
    Pn = np.empty(16 + 6 * n)
    e = np.empty(6)
    en = np.empty(6)
    A = np.empty((n, n))
    g = np.empty(n)
    q = np.empty(n)
    qn = np.empty(n)
    L2 = L * L
    for b in range(T.shape[0]):
        Tb = T[b]
        best_pe, best_re, best_cost = np.inf, np.inf, np.inf
        iterations = 0
        done = False
        attempt = 0
        for attempt in range(restarts + 1):
            if attempt == 0:
                q[:] = q0[b]
            else:
                if attempt == 1:  # this target's own stream (numba's generator state is per thread)
                    np.random.seed((seed + 1000003 * (first + b)) & 0x7FFFFFFF)
                for k in range(n):
                    q[k] = slo[k] + (shi[k] - slo[k]) * np.random.random()
            clip = attempt % 2 == 0
            _ik_project(q, lo, hi, revolute, True)
            fk_jacobian0_1(q, P)
            pe, re, cost = _ik_residual(Tb, P, w, e)
            lam = 1e-3 * L2
            budget = max_iterations if attempt == 0 else max(1, int(0.3 * max_iterations))
            for it in range(budget):
                if pe <= tol and re <= tol:
                    break
                iterations += 1
                # normal equations (J_W^T J_W + lam I) dq = J_W^T W e, J_W = W J0 (J0 at P[16:])
                for i in range(n):
                    s = 0.0
                    for r in range(6):
                        s += w[r] * P[16 + r * n + i] * e[r]
                    g[i] = s
                    for j in range(i + 1):
                        s = 0.0
                        for r in range(6):
                            s += w[r] * w[r] * P[16 + r * n + i] * P[16 + r * n + j]
                        A[i, j] = s
                    A[i, i] += lam
                # Cholesky A = C C^T in the lower triangle, then the two triangular solves
                for j in range(n):
                    s = A[j, j]
                    for k in range(j):
                        s -= A[j, k] * A[j, k]
                    d = math.sqrt(s) if s > 0.0 else 1e-300
                    A[j, j] = d
                    for i in range(j + 1, n):
                        s = A[i, j]
                        for k in range(j):
                            s -= A[i, k] * A[j, k]
                        A[i, j] = s / d
                for i in range(n):
                    s = g[i]
                    for k in range(i):
                        s -= A[i, k] * g[k]
                    g[i] = s / A[i, i]
                for i in range(n - 1, -1, -1):
                    s = g[i]
                    for k in range(i + 1, n):
                        s -= A[k, i] * g[k]
                    g[i] = s / A[i, i]
                for k in range(n):
                    qn[k] = q[k] + g[k]
                _ik_project(qn, lo, hi, revolute, clip)
                fk_jacobian0_1(qn, Pn)
                pe_n, re_n, cost_n = _ik_residual(Tb, Pn, w, en)
                if cost_n < cost:  # accepted: the new point's pose and Jacobian are already in Pn
                    q[:] = qn
                    e[:] = en
                    P[:] = Pn
                    pe, re, cost = pe_n, re_n, cost_n
                    lam = max(lam * 0.1, 1e-12 * L2)
                else:
                    lam *= 10.0
                    if lam > 1e3 * L2:
                        break
            if not clip:  # fold the free result into the limits and judge it there
                _ik_project(q, lo, hi, revolute, True)
                fk_jacobian0_1(q, P)
                pe, re, cost = _ik_residual(Tb, P, w, e)
            inside = True
            for k in range(n):
                inside = inside and lo[k] - 1e-12 <= q[k] <= hi[k] + 1e-12
            if pe <= tol and re <= tol and inside:
                best_pe, best_re = pe, re
                out_q[b] = q
                done = True
                break
            if cost < best_cost:
                best_cost, best_pe, best_re = cost, pe, re
                out_q[b] = q
        out_info[b, 0] = 1.0 if done else 0.0
        out_info[b, 1] = best_pe
        out_info[b, 2] = best_re
        out_info[b, 3] = iterations
        out_info[b, 4] = attempt
'''
