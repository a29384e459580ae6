"""The step every compiled closed form ends with, for one pose: candidates verified by the arm's compiled FK,
folded into the joint limits, duplicates dropped, the rest sorted as the plain solver returns them.

The same rules as :func:`denavit.analytic_ik` (its VERIFY_TOL, POLISH_ABOVE, DUPLICATE_TOL and MERGE_RADIUS,
packed in ``tols``); where the plain solver would do more (polish a candidate, merge a pair by the FK of its
midpoint) or where a rounding difference could change the folding, the status asks for the plain solver.  The
text is appended to each generated numba module beside the elbow, UR and Stanford kernels that call it.
"""

from __future__ import annotations

__all__ = ["IK_FINISH_SOURCE", "FOLD_EDGE", "pack_constants"]

#: Distance [rad, m] of a folded candidate from a decision of the folding — a joint limit, the limit ∓ 2π, or ±π where
#: angles wrap — under which the pose goes to the plain solver: a rounding difference there moves a solution by a
#: whole turn or across a limit (hypothesis found q3 = −1.3e-15 against the plain solver's +0 at a limit of −2π).
FOLD_EDGE = 1e-9

def pack_constants(values: dict, layout: tuple, what: str):
    """The constants of a closed-form kernel as one float64 vector, ``layout``'s (name, size) pairs in order (one
    argument to unbox per call instead of twenty); ValueError naming ``what`` if the sizes do not add up."""
    import numpy as np

    K = np.concatenate([np.asarray(values[name], dtype=np.float64).ravel() for name, _ in layout])
    expected = sum(size for _, size in layout)
    if K.size != expected:
        raise ValueError(f"{what} IK constants: {K.size} numbers for the layout's {expected}")
    return K


IK_FINISH_SOURCE = f"\n_FOLD_EDGE = {FOLD_EDGE!r}\n" + '''

@njit(cache=True, nogil=True)
def _near_fold_edge(x, lo, hi):
    """A wrapped angle x within _FOLD_EDGE of ±π or of a limit (itself, or shifted by a whole turn)."""
    if math.pi - abs(x) < _FOLD_EDGE:
        return True
    for shift in (-2.0 * math.pi, 0.0, 2.0 * math.pi):
        if abs(x + shift - lo) < _FOLD_EDGE or abs(x + shift - hi) < _FOLD_EDGE:
            return True
    return False


@njit(cache=True, nogil=True)
def _ik_finish(Tb, cand, cerr, ncand, lo_lim, hi_lim, revolute, tols, F, q, flags, out_q, out_err, out_outq, perm):
    """The plain solver's pipeline after the candidates, for one pose: each verified by the FK (a residual that
    would be polished: status 1), folded into the limits, duplicates dropped (a pair within the merge radius:
    status 1), the ones inside the limits sorted lexicographically into out_q (residuals into out_err), the
    others into out_outq, perm[slot] the candidate in each slot.  Returns (kept, outside, status)."""
    verify_tol, polish_above, dup_tol, merge_r, reach = tols[2], tols[3], tols[4], tols[5], tols[7]
    ok, inside, used = flags[0:8], flags[8:16], flags[16:24]
    status = 0
    for k in range(ncand):
        for j in range(6):
            q[j] = cand[k, j]
        fk_1(q, F)
        pe = math.sqrt((F[0, 3] - Tb[0, 3]) ** 2 + (F[1, 3] - Tb[1, 3]) ** 2 + (F[2, 3] - Tb[2, 3]) ** 2)
        tr = 0.0  # rotation error: the angle of R_t R^T
        for i in range(3):
            for j in range(3):
                tr += Tb[i, j] * F[i, j]
        v0 = v1 = v2 = 0.0
        for j in range(3):
            v0 += Tb[2, j] * F[1, j] - Tb[1, j] * F[2, j]
            v1 += Tb[0, j] * F[2, j] - Tb[2, j] * F[0, j]
            v2 += Tb[1, j] * F[0, j] - Tb[0, j] * F[1, j]
        re = math.atan2(0.5 * math.sqrt(v0 * v0 + v1 * v1 + v2 * v2), 0.5 * (tr - 1.0))
        cerr[k, 0], cerr[k, 1] = pe, re
        size = pe + reach * re
        if size < 0.05 * max(reach, 1e-3) and size > polish_above * max(reach, 1.0):
            status = 1  # would be polished by the plain solver
        ok[k] = pe <= verify_tol * max(1.0, reach) and re <= verify_tol
    for k in range(ncand):
        if not ok[k]:
            continue
        ins = True
        for j in range(6):
            x = cand[k, j]
            if revolute[j] != 0.0:
                x = math.pi - ((math.pi - x) % (2.0 * math.pi))
                if _near_fold_edge(x, lo_lim[j], hi_lim[j]):
                    status = 1  # a rounding difference could fold it elsewhere: the plain solver decides
                if (x < lo_lim[j] - 1e-12 or x > hi_lim[j] + 1e-12) and lo_lim[j] <= x + 2.0 * math.pi <= hi_lim[j]:
                    x += 2.0 * math.pi
                if (x < lo_lim[j] - 1e-12 or x > hi_lim[j] + 1e-12) and lo_lim[j] <= x - 2.0 * math.pi <= hi_lim[j]:
                    x -= 2.0 * math.pi
            elif abs(x - lo_lim[j]) < _FOLD_EDGE or abs(x - hi_lim[j]) < _FOLD_EDGE:
                status = 1
            cand[k, j] = x
            ins = ins and lo_lim[j] - 1e-12 <= x <= hi_lim[j] + 1e-12
        inside[k] = ins
        for m in range(k):
            if not ok[m]:
                continue
            dmax = 0.0
            for j in range(6):
                d = abs(cand[k, j] - cand[m, j])
                if revolute[j] != 0.0:
                    d = abs(d - 2.0 * math.pi * np.rint(d / (2.0 * math.pi)))
                dmax = max(dmax, d)
            if dmax < dup_tol:
                ok[k] = False
                break
            if dmax < merge_r:
                status = 1  # the plain solver merges such a pair by the FK of its midpoint
    kept = 0
    n_out = 0
    for k in range(ncand):
        if ok[k] and not inside[k]:
            for j in range(6):
                out_outq[n_out, j] = cand[k, j]
            n_out += 1
            ok[k] = False
        elif ok[k]:
            kept += 1
    for k in range(8):
        used[k] = False
    for slot in range(kept):
        best = -1
        for k in range(ncand):
            if ok[k] and not used[k]:
                if best < 0:
                    best = k
                else:
                    for j in range(6):
                        if cand[k, j] != cand[best, j]:
                            if cand[k, j] < cand[best, j]:
                                best = k
                            break
        used[best] = True
        perm[slot] = best
        for j in range(6):
            out_q[slot, j] = cand[best, j]
        out_err[slot, 0], out_err[slot, 1] = cerr[best, 0], cerr[best, 1]
    return kept, n_out, status
'''
