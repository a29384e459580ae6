"""The step every compiled closed form ends with, for one pose, as numba functions compiled once per machine
(``cache=True``; nothing of a robot in them: its chain constants are arguments): candidates verified by the FK of
the chain (:func:`chain_fk`), folded into the joint limits, duplicates dropped, the rest sorted as the plain solver
returns them (:func:`ik_finish`); and :func:`ik_check`, the targets' orthonormality test.

The same rules as :func:`denavit.analytic_ik` (its VERIFY_TOL, POLISH_ABOVE, DUPLICATE_TOL and MERGE_RADIUS,
packed in ``tols``); where the plain solver would do more (polish a candidate, merge a pair by the FK of its
midpoint) or where a rounding difference could change the folding, the status asks for the plain solver.
Imported only where numba is (:mod:`._solvers`, for the numba backend).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from ._ik_finish import FOLD_EDGE

__all__ = ["chain_fk", "ik_check", "ik_finish", "ik_placed", "ik_sorted"]

_INV_2PI = 0.5 / math.pi


@njit(cache=True, nogil=True, inline="always")  # into ik_finish: no call passing eight arrays per candidate
def chain_fk(C, revolute, Q, CS, r, P, start, F):
    """F = C0 J1(q1) C1 ⋯ Jn(qn) Cn: the arm's pose from its chain constants C (n+1, 4, 4) (:mod:`denavit.chain`:
    base, DH rows and tool folded in), J = Rz(q) for a revolute joint, Tz(q) for a prismatic one.  The 3×4 top of
    the product is kept in twelve local floats (registers); q = Q[r], its (cos q1, sin q1, cos q2, …) given in
    CS[r] (a prismatic joint's pair unused; rows indexed, not sliced: a view costs an atomic reference count);
    P[k] (n+1, 12) keeps the product after k joints, and the walk
    resumes from P[start] (left there by a call for a q with the same first ``start`` joints: the candidates of a
    closed form come in families sharing q1, or q1 to q3; P[0] must hold C0's top)."""
    x0, x1, x2, y0, y1, y2 = P[start, 0], P[start, 1], P[start, 2], P[start, 3], P[start, 4], P[start, 5]
    z0, z1, z2, p0, p1, p2 = P[start, 6], P[start, 7], P[start, 8], P[start, 9], P[start, 10], P[start, 11]
    for k in range(start, Q.shape[1]):
        if revolute[k] != 0.0:  # F <- F Rz(q_k): columns x, y turn
            c, s = CS[r, 2 * k], CS[r, 2 * k + 1]
            x0, y0 = c * x0 + s * y0, c * y0 - s * x0
            x1, y1 = c * x1 + s * y1, c * y1 - s * x1
            x2, y2 = c * x2 + s * y2, c * y2 - s * x2
        else:  # F <- F Tz(q_k)
            p0, p1, p2 = p0 + Q[r, k] * z0, p1 + Q[r, k] * z1, p2 + Q[r, k] * z2
        m = k + 1  # F <- F C_m (last row of C: 0 0 0 1); C indexed, not sliced: a view is an atomic refcount
        a00, a01, a02, a03 = C[m, 0, 0], C[m, 0, 1], C[m, 0, 2], C[m, 0, 3]
        a10, a11, a12, a13 = C[m, 1, 0], C[m, 1, 1], C[m, 1, 2], C[m, 1, 3]
        a20, a21, a22, a23 = C[m, 2, 0], C[m, 2, 1], C[m, 2, 2], C[m, 2, 3]
        p0, p1, p2 = (p0 + x0 * a03 + y0 * a13 + z0 * a23, p1 + x1 * a03 + y1 * a13 + z1 * a23,
                      p2 + x2 * a03 + y2 * a13 + z2 * a23)
        x0, y0, z0 = (x0 * a00 + y0 * a10 + z0 * a20, x0 * a01 + y0 * a11 + z0 * a21, x0 * a02 + y0 * a12 + z0 * a22)
        x1, y1, z1 = (x1 * a00 + y1 * a10 + z1 * a20, x1 * a01 + y1 * a11 + z1 * a21, x1 * a02 + y1 * a12 + z1 * a22)
        x2, y2, z2 = (x2 * a00 + y2 * a10 + z2 * a20, x2 * a01 + y2 * a11 + z2 * a21, x2 * a02 + y2 * a12 + z2 * a22)
        P[m, 0], P[m, 1], P[m, 2], P[m, 3], P[m, 4], P[m, 5] = x0, x1, x2, y0, y1, y2
        P[m, 6], P[m, 7], P[m, 8], P[m, 9], P[m, 10], P[m, 11] = z0, z1, z2, p0, p1, p2
    F[0, 0], F[0, 1], F[0, 2], F[0, 3] = x0, y0, z0, p0
    F[1, 0], F[1, 1], F[1, 2], F[1, 3] = x1, y1, z1, p1
    F[2, 0], F[2, 1], F[2, 2], F[2, 3] = x2, y2, z2, p2
    F[3, 0], F[3, 1], F[3, 2], F[3, 3] = 0.0, 0.0, 0.0, 1.0


@njit(cache=True, nogil=True)
def _wrap(x):
    """x wrapped into (−π, π] as ``π − ((π − x) mod 2π)``, the mod by floor (numba's float % calls fmod: 48 of them
    were 7% of a kernel call) of a product with 1/2π (a division and math.floor's round trip through an integer
    were the fold's latency); within an ulp of the fmod form, and the fold's knife edges go to the plain solver
    anyway (FOLD_EDGE: the product and the quotient can floor differently only within an ulp of x = ±π)."""
    y = math.pi - x
    return math.pi - (y - 2.0 * math.pi * np.floor(y * _INV_2PI))


@njit(cache=True, nogil=True)
def _near_fold_edge(x, lo, hi):
    """A wrapped angle x within FOLD_EDGE of ±π or of a limit (itself, or shifted by a whole turn)."""
    if math.pi - abs(x) < FOLD_EDGE:
        return True
    for shift in (-2.0 * math.pi, 0.0, 2.0 * math.pi):
        if abs(x + shift - lo) < FOLD_EDGE or abs(x + shift - hi) < FOLD_EDGE:
            return True
    return False


@njit(cache=True, nogil=True, inline="always")  # into each kernel: no call with nineteen arguments per pose
def ik_finish(T, b, cand, cerr, ncand, lo_lim, hi_lim, revolute, tols, F, frames, flags, out_q, out_err, out_outq,
              perm, C, cs, given, out_rank, P, vr):
    """The plain solver's pipeline after the candidates, for pose b of T (B, 4, 4): each verified by the FK (a
    residual that would be polished: status 1), folded into the limits, duplicates dropped (a pair within the merge
    radius: status 1), the ones inside the limits sorted lexicographically into out_q[b] (residuals into
    out_err[b]), the others into out_outq[b], perm[slot] the candidate in each slot; C (7, 4, 4) the arm's chain
    constants (its FK: :func:`chain_fk`); frames[k] (8, 36) the frames after joints 1, 2, 3 of candidate k,
    unfolded (the FK's products P[1:4]: columns x, y, z, origin each), for the labels; cs[k] (8, 12) the cosine and
    sine of each joint of candidate k, given by the closed form (``given``: the very values of math.cos, math.sin
    of those floats, so the FK computes no sine) or computed here; out_rank[b, slot] the rank of each kept solution
    among the verified candidates in candidate order, out_rank[b, 8] their number (the slots of the plain solver's
    batched layout).  Scratch: P (7, 12), the FK's partial products; vr (20,); flags (24,): verified, inside the
    limits, placed (8 each).  The outputs are indexed by b, not sliced (a view per pose is an atomic reference
    count and its release).  Returns (kept, outside, status)."""
    status = _verify(T, b, cand, cerr, ncand, revolute, tols, F, frames, flags, C, cs, given, P)
    kept, n_out, st = ik_sorted(b, cand, cerr, ncand, lo_lim, hi_lim, revolute, tols, flags, out_q, out_err,
                                out_outq, perm, out_rank, vr)
    return kept, n_out, max(status, st)


@njit(cache=True, nogil=True, inline="always")  # into ik_finish and the elbow kernel (verified in its stages)
def ik_sorted(b, cand, cerr, ncand, lo_lim, hi_lim, revolute, tols, flags, out_q, out_err, out_outq, perm, out_rank,
              vr):
    """:func:`ik_finish` after the verification (flags[k]: candidate k verified; cerr[k]: its residuals): the
    verified ones folded, ranked, merged and sorted into pose b's outputs.  Returns (kept, outside, status)."""
    status = _fold(cand, ncand, flags, lo_lim, hi_lim, revolute, vr)
    kept, n_out, st = ik_placed(b, cand, cerr, ncand, revolute, tols, flags, out_q, out_err, out_outq, perm,
                                out_rank, vr)
    return kept, n_out, max(status, st)


@njit(cache=True, nogil=True, inline="always")  # into ik_sorted and the elbow kernel (folded in its stages)
def ik_placed(b, cand, cerr, ncand, revolute, tols, flags, out_q, out_err, out_outq, perm, out_rank, vr):
    """:func:`ik_sorted` after the fold (flags[8 + k]: candidate k's folded joints all within the limits): the
    verified ones ranked, merged and sorted into pose b's outputs.  Returns (kept, outside, status)."""
    nver = 0
    for k in range(ncand):
        if flags[k]:
            vr[k] = nver
            nver += 1
    out_rank[b, 8] = nver
    status = _merge(cand, ncand, flags, revolute, tols[4], tols[5])
    kept, n_out = _sort_out(b, cand, cerr, ncand, flags, out_q, out_err, out_outq, perm, out_rank, vr)
    return kept, n_out, status


@njit(cache=True, nogil=True, inline="always")  # into ik_finish
def _verify(T, b, cand, cerr, ncand, revolute, tols, F, frames, flags, C, cs, given, P):
    """Each candidate's FK (resumed from the joints it shares with the previous one) against T[b]: its position and
    orientation residuals into cerr[k], the frames after joints 1-3 into frames[k], flags[k] whether it reproduces
    T[b] within VERIFY_TOL.  Returns 1 if some residual is one the plain solver would polish, else 0."""
    verify_tol, polish_above, reach = tols[2], tols[3], tols[7]
    status = 0
    for r in range(3):
        P[0, r], P[0, 3 + r], P[0, 6 + r], P[0, 9 + r] = C[0, r, 0], C[0, r, 1], C[0, r, 2], C[0, r, 3]
    for k in range(ncand):
        start = 0
        while k > 0 and start < 5 and cand[k, start] == cand[k - 1, start]:
            start += 1
        if not given:
            for j in range(start, 6):
                cs[k, 2 * j], cs[k, 2 * j + 1] = math.cos(cand[k, j]), math.sin(cand[k, j])
        chain_fk(C, revolute, cand, cs, k, P, start, F)
        for j in range(36):
            frames[k, j] = P[1 + j // 12, j % 12]
        pe = math.sqrt((F[0, 3] - T[b, 0, 3]) ** 2 + (F[1, 3] - T[b, 1, 3]) ** 2 + (F[2, 3] - T[b, 2, 3]) ** 2)
        tr = 0.0  # rotation error: the angle of R_t R^T
        for i in range(3):
            for j in range(3):
                tr += T[b, i, j] * F[i, j]
        v0 = v1 = v2 = 0.0
        for j in range(3):
            v0 += T[b, 2, j] * F[1, j] - T[b, 1, j] * F[2, j]
            v1 += T[b, 0, j] * F[2, j] - T[b, 2, j] * F[0, j]
            v2 += T[b, 1, j] * F[0, j] - T[b, 0, j] * F[1, j]
        sn, co = 0.5 * math.sqrt(v0 * v0 + v1 * v1 + v2 * v2), 0.5 * (tr - 1.0)
        re = sn / co if sn < 1e-6 * co else math.atan2(sn, co)  # atan(t) = t (1 - t²/3 ...): t below 1e-6, t
        cerr[k, 0], cerr[k, 1] = pe, re
        size = pe + reach * re
        if size < 0.05 * max(reach, 1e-3) and size > polish_above * max(reach, 1.0):
            status = 1  # would be polished by the plain solver
        flags[k] = pe <= verify_tol * max(1.0, reach) and re <= verify_tol
    return status


@njit(cache=True, nogil=True, inline="always")  # into ik_finish
def _merge(cand, ncand, flags, revolute, dup_tol, merge_r):
    """Each verified (folded) candidate within DUPLICATE_TOL of an earlier verified one dropped (flags[k] False).
    Returns 1 if some pair lies within the merge radius but beyond that (the plain solver merges such a pair by the
    FK of its midpoint), else 0."""
    status = 0
    for k in range(ncand):
        if not flags[k]:
            continue
        for m in range(k):
            if not flags[m]:
                continue
            dmax = 0.0
            for j in range(6):
                d = abs(cand[k, j] - cand[m, j])
                if revolute[j] != 0.0:
                    d = abs(d - 2.0 * math.pi * np.rint(d * (0.5 / math.pi)))
                dmax = max(dmax, d)
                if dmax >= merge_r:
                    break  # neither a duplicate nor a pair to merge (most pairs differ in q1 already)
            if dmax < dup_tol:
                flags[k] = False
                break
            if dmax < merge_r:
                status = 1
    return status


@njit(cache=True, nogil=True, inline="always")  # into ik_finish
def _sort_out(b, cand, cerr, ncand, flags, out_q, out_err, out_outq, perm, out_rank, vr):
    """The verified candidates outside the limits into out_outq[b] (in candidate order), the others sorted
    lexicographically into out_q[b] with their residuals, perm and out_rank[b] (see ik_finish).  Returns (kept,
    outside)."""
    kept = 0
    n_out = 0
    for k in range(ncand):
        if flags[k] and not flags[8 + k]:
            for j in range(6):
                out_outq[b, n_out, j] = cand[k, j]
            n_out += 1
            flags[k] = False
        elif flags[k]:
            kept += 1
    for k in range(8):
        flags[16 + k] = False
    for slot in range(kept):
        best = -1
        for k in range(ncand):
            if flags[k] and not flags[16 + k]:
                if best < 0:
                    best = k
                else:
                    for j in range(6):
                        if cand[k, j] != cand[best, j]:
                            if cand[k, j] < cand[best, j]:
                                best = k
                            break
        flags[16 + best] = True
        perm[slot] = best
        out_rank[b, slot] = vr[best]
        for j in range(6):
            out_q[b, slot, j] = cand[best, j]
        out_err[b, slot, 0], out_err[b, slot, 1] = cerr[best, 0], cerr[best, 1]
    return kept, n_out


@njit(cache=True, nogil=True, inline="always")  # into ik_finish
def _fold(cand, ncand, flags, lo_lim, hi_lim, revolute, vr):
    """Each verified candidate's joints folded into the limits (revolute: wrapped into (−π, π], then shifted by a
    whole turn where that brings it inside), in place; flags[8 + k] whether all of candidate k's are within them
    (flags[k]: verified).
    Returns 1 if some joint lies within FOLD_EDGE of a decision of the folding (the plain solver decides), else 0.
    The candidates come in families sharing their first joints (the same floats): a joint equal to the one last
    folded reuses its result (held in vr[8:14] and vr[14:20]: the last raw value and its folded value per joint;
    vr[:8] is the caller's)."""
    status = 0
    for j in range(6):
        vr[8 + j] = math.nan  # equal to nothing
    for k in range(ncand):
        if not flags[k]:
            continue
        ins = True
        for j in range(6):
            x = cand[k, j]
            lo, hi = lo_lim[j], hi_lim[j]
            if x == vr[8 + j]:
                x = vr[14 + j]
            else:
                vr[8 + j] = x
                if revolute[j] != 0.0:
                    x = _wrap(x)
                    if _near_fold_edge(x, lo, hi):
                        status = 1  # a rounding difference could fold it elsewhere: the plain solver decides
                    if (x < lo - 1e-12 or x > hi + 1e-12) and lo <= x + 2.0 * math.pi <= hi:
                        x += 2.0 * math.pi
                    if (x < lo - 1e-12 or x > hi + 1e-12) and lo <= x - 2.0 * math.pi <= hi:
                        x -= 2.0 * math.pi
                elif abs(x - lo) < FOLD_EDGE or abs(x - hi) < FOLD_EDGE:
                    status = 1
                vr[14 + j] = x
            cand[k, j] = x
            ins = ins and lo - 1e-12 <= x <= hi + 1e-12
        flags[8 + k] = ins
    return status


@njit(cache=True, nogil=True)
def ik_check(T, Q):
    """The largest |R^T R - I| entry over the targets (the test of denavit's as_transform); inf if a target
    holds a NaN or an infinity, -1 if a seed does."""
    for b in range(Q.shape[0]):
        for k in range(Q.shape[1]):
            if not math.isfinite(Q[b, k]):
                return -1.0
    worst = 0.0
    for b in range(T.shape[0]):
        for i in range(4):
            for j in range(4):
                if not math.isfinite(T[b, i, j]):
                    return np.inf
        for i in range(3):
            for j in range(3):
                s = T[b, 0, i] * T[b, 0, j] + T[b, 1, i] * T[b, 1, j] + T[b, 2, i] * T[b, 2, j]
                d = abs(s - (1.0 if i == j else 0.0))
                if d > worst:
                    worst = d
    return worst
