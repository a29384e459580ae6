"""Checking the candidates of a plan: FK verification, Gauss–Newton polish of roots that lost digits, and the
partners of near-double roots (the steps of docs/ik.md "Next to singularities"); the tolerances that decide what
one solution is.
"""

from __future__ import annotations

import numpy as np

from ..model import DHRobot, JointType
from ..numeric import forward_kinematics
from ._chain import damped_solve
from ._kernel import kernel_of, targets_soa
from ._residual import pose_error
from ._structure import Plan

__all__ = ["VERIFY_TOL", "DUPLICATE_TOL", "MERGE_RADIUS", "POLISH_ABOVE", "arm_reach", "polish", "verify",
           "new_solutions", "fold_partners", "null_text"]

VERIFY_TOL = 1e-9  # position [m] and orientation [rad] a solution must reproduce
DUPLICATE_TOL = 1e-6  # joint-space distance under which two solutions are the same [rad, m]
MERGE_RADIUS = 1e-5  # up to this distance two solutions are also the same when their midpoint reproduces the pose
# (copies of one root found to ~√ε; two exact solutions of a pose 1e-4 from a singularity lie ~1e-4 apart and stay)
POLISH_ABOVE = 1e-12  # residual [m] under which a closed-form candidate is kept as it is
POLISH_STEPS = 30
PREFILTER = 0.05  # candidates farther than this fraction of the reach are not polished
FOLD_ROUGH = 1e-12  # candidate residual [m, rad] (relative to the reach) above which a root may be one of a merged
# pair: every polished candidate (1e-10 missed the eigenvalue route's midpoint candidates, residual ~1e-11, between
# two roots 1.5e-5 apart next to a jaco2-6dof fold: the polish reached one, the other was never sought)
FOLD_SIGMA = 1e-3  # σ_min/σ_max of a polished solution under which the partner of a near-double root is sought
SINGULAR_RCOND = 1e-8  # σ_min/σ_max of such a solution under which it is on the singularity: named a continuum
FOLD_RESIDUAL = 1e-12  # residual [m, rad] a partner found that way must reach (Newton converged, not stalled)
FOLD_STEPS = np.array([1e-2, 1e-3, 1e-4])  # offsets [rad, m] along the singular direction for that search

def arm_reach(robot: DHRobot) -> float:
    """Σ |a| + |d| over the rows: the length scale of the tolerances [m]."""
    return sum(abs(l.a) + abs(l.d) for l in robot.links)


def polish(robot: DHRobot, q: np.ndarray, T: np.ndarray, P: np.ndarray) -> np.ndarray:
    """Damped Gauss–Newton steps on P·e until converged (restores the digits lost in root finding).

    Residual and Jacobian come from one pass over the chain (:mod:`._kernel`)."""
    n = robot.dof
    kin = kernel_of(robot)
    Rt, pt = targets_soa(T)
    q = q.copy()
    act = np.arange(len(q))
    w = np.ones(6)
    for _ in range(POLISH_STEPS):
        e, J = kin.residual(q[act], Rt[..., act], pt[:, act], w)
        e = e @ P.T  # (b, 6)
        moving = np.max(np.abs(e), axis=-1) > 1e-15
        act, e, J = act[moving], e[moving], P @ J[moving]
        if act.size == 0:
            break
        Jt = np.swapaxes(J, -1, -2)
        A = Jt @ J + 1e-14 * np.eye(n)
        q[act] += damped_solve(A, np.einsum("bij,bj->bi", Jt, e)[..., None])[..., 0]
    return q


def verify(robot: DHRobot, plan: Plan, Tf: np.ndarray, cand: np.ndarray):
    """FK residual of every candidate; far-off ones dropped, rough ones (roots near double roots) polished and
    re-checked; the rest are kept as computed.  Returns q (B, K, n) (NaN where dropped), ok, position and
    orientation residuals (B, K) on the rows the arm controls."""
    B, K, _ = cand.shape
    L = arm_reach(robot)
    ok = np.all(np.isfinite(cand), axis=-1)
    Tk = np.broadcast_to(Tf[:, None], (B, K, 4, 4))
    q = np.full(cand.shape, np.nan)
    pe = np.full((B, K), np.inf)
    re = np.full((B, K), np.inf)
    if ok.any():  # one FK for all candidates; false roots are far off: drop them before the (costly) polish
        e = pose_error(Tk[ok], forward_kinematics(robot, cand[ok])) @ plan.projector.T
        pe[ok], re[ok] = np.linalg.norm(e[:, :3], axis=-1), np.linalg.norm(e[:, 3:], axis=-1)
        size = np.where(ok, pe + L * np.where(ok, re, 0.0), np.inf)
        near = ok & (size < PREFILTER * max(L, 1e-3))
        rough = near & (size > POLISH_ABOVE * max(L, 1.0))  # only candidates that lost digits are polished
        lost = near & (size > FOLD_ROUGH * max(L, 1.0))  # lost about half the digits: maybe one of a merged pair
        ok = near
        q[ok] = cand[ok]
        if rough.any():
            q[rough] = polish(robot, cand[rough], Tk[rough], plan.projector)
            fine = np.all(np.isfinite(q), axis=-1) & rough
            e = pose_error(Tk[fine], forward_kinematics(robot, q[fine])) @ plan.projector.T
            pe0, re0 = pe.copy(), re.copy()
            pe[fine], re[fine] = np.linalg.norm(e[:, :3], axis=-1), np.linalg.norm(e[:, 3:], axis=-1)
            # next to a singular set (J's σ_min ~1e-9) a step can run off: the polish never makes a candidate worse
            with np.errstate(invalid="ignore"):
                worse = rough & ~(pe + L * re <= pe0 + L * re0)
            q[worse], pe[worse], re[worse] = cand[worse], pe0[worse], re0[worse]
    else:
        lost = np.zeros_like(ok)
    ok &= np.all(np.isfinite(q), axis=-1)
    ok &= (pe <= VERIFY_TOL * max(1.0, L)) & (re <= VERIFY_TOL)
    return q, ok, pe, re, lost


def new_solutions(robot: DHRobot, q: np.ndarray, ok: np.ndarray, q2: np.ndarray, ok2: np.ndarray) -> np.ndarray:
    """Which of the extra solutions q2 (B, E, n) are farther than DUPLICATE_TOL from every solution of q (B, K, n)
    of their pose (the extras among themselves are left to the merging of :mod:`._analytic`)."""
    rev = np.array([t is JointType.REVOLUTE for t in robot.joint_types])
    b = np.flatnonzero(ok2.any(axis=1))
    d = np.abs(q2[b][:, :, None] - q[b][:, None])  # (b, E, K, n)
    d = np.where(rev, np.abs(d - 2 * np.pi * np.rint(d / (2 * np.pi))), d).max(axis=-1)
    dup = (np.where(ok[b][:, None], np.nan_to_num(d, nan=np.inf), np.inf) < DUPLICATE_TOL).any(axis=-1)
    out = ok2.copy()
    out[b] &= ~dup
    return out


def fold_partners(robot: DHRobot, plan: Plan, Tf: np.ndarray, q: np.ndarray, fold: np.ndarray):
    """Candidates for the second root of a pair that nearly coincide (a pose within ~FOLD_SIGMA of a
    singularity, where root finding returns one root for two): from each polished solution whose controlled
    Jacobian has σ_min < FOLD_SIGMA · σ_max, Newton steps from q ± t v (v: the singular direction, t = FOLD_STEPS).
    Returns candidates (B, E, n) for :func:`verify` (None when no solution is that close to a singularity), and
    the solutions that sit on a singularity (σ_min < SINGULAR_RCOND · σ_max): pose and slot indices and the
    null direction of J, for the name of their continuum."""
    from ..numeric import geometric_jacobian

    b, k = np.nonzero(fold)
    J = plan.projector @ geometric_jacobian(robot, q[b, k])
    n = q.shape[-1]
    sv = np.linalg.svd(J, compute_uv=False)
    at = sv[:, n - 1] < SINGULAR_RCOND * sv[:, 0]  # on the singularity (to rounding): a continuum, no partner
    near = ~at & (sv[:, n - 1] < FOLD_SIGMA * sv[:, 0])
    singular = (b[at], k[at], np.linalg.svd(J[at])[2][:, n - 1] if at.any() else np.zeros((0, n)))
    if not near.any():
        return None, singular
    b, k, v = b[near], k[near], np.linalg.svd(J[near])[2][:, n - 1]  # (m,), (m, n)
    steps = np.concatenate([FOLD_STEPS, -FOLD_STEPS])
    seeds = q[b, k][:, None] + steps[None, :, None] * v[:, None]  # (m, S, n)
    m, S = seeds.shape[:2]
    flat = polish(robot, seeds.reshape(-1, n), np.repeat(Tf[b], S, axis=0), plan.projector)
    # per pose: the seeds of all its near-singular solutions, in extra slots
    per = np.bincount(b, minlength=len(Tf)) * S
    out = np.full((len(Tf), int(per.max()), n), np.nan)
    slot = np.arange(m * S) - np.repeat(np.concatenate([[0], np.cumsum(per)[:-1]])[b], S)
    out[np.repeat(b, S), slot] = flat
    return out, singular


def null_text(v: np.ndarray) -> str:
    """The continuum through a solution where J is singular, named by its null direction v (unit, (n,)):
    e.g. ``0.71 q4 - 0.71 q6 free (J singular: its null direction)``."""
    v = v * np.sign(v[np.argmax(np.abs(v))])
    terms = [(c, k) for k, c in enumerate(v) if abs(c) > 0.05]
    text = " ".join(f"{'-' if c < 0 else '+'} {abs(c):.2f} q{k + 1}" for c, k in terms).lstrip("+ ")
    return f"{text} free (J singular: its null direction)"
