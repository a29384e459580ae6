"""All inverse-kinematics solutions in closed form, batched over target poses.

Pipeline (the same for every structure): the plan of :mod:`._plans` proposes candidates (the direct closed
forms of :mod:`._closed` for elbow and Stanford Pieper arms) → one batched forward-kinematics pass checks every
candidate → only those whose residual shows lost digits (general root finding near double roots) get a few
Gauss–Newton steps and a second check → revolute angles are folded by whole turns into the joint limits, those
that cannot be are set aside → duplicates are merged → each solution gets a branch label.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache
from typing import Any

import numpy as np

from .. import chain as dh_chain
from .._validate import as_transform
from ..model import DHRobot, JointType
from ..chain import reach_ball, screw_walk, screws_of
from ._chain import damped_solve, wrap_angle
from ._residual import pose_error
from ._plans import Plan, make_plan
from ._kernel import kernel_of, targets_soa
from ..numeric import forward_kinematics

__all__ = ["AnalyticIKResult", "analytic_ik", "ik_structure", "ik_plan"]

SHOULDER, ELBOW, WRIST = ("shoulder right", "shoulder left"), ("elbow up", "elbow down"), ("wrist noflip", "wrist flip")
VERIFY_TOL = 1e-9  # position [m] and orientation [rad] a solution must reproduce
POLISH_STEPS = 30
DUPLICATE_TOL = 1e-6  # joint-space distance under which two solutions are the same [rad, m]
MERGE_RADIUS = 1e-5  # up to this distance two solutions are also the same when their midpoint reproduces the pose
# (copies of one root found to ~√ε; two exact solutions of a pose 1e-4 from a singularity lie ~1e-4 apart and stay)
POLISH_ABOVE = 1e-12  # residual [m] under which a closed-form candidate is kept as it is
PREFILTER = 0.05  # candidates farther than this fraction of the reach are not polished
FOLD_ROUGH = 1e-10  # candidate residual [m, rad] (relative to the reach) above which a root lost ~half its digits
FOLD_SIGMA = 1e-3  # σ_min/σ_max of a polished solution under which the partner of a near-double root is sought
SINGULAR_RCOND = 1e-8  # σ_min/σ_max of such a solution under which it is on the singularity: named a continuum
FOLD_RESIDUAL = 1e-12  # residual [m, rad] a partner found that way must reach (Newton converged, not stalled)
FOLD_STEPS = np.array([1e-2, 1e-3, 1e-4])  # offsets [rad, m] along the singular direction for that search


@dataclass(frozen=True)
class AnalyticIKResult:
    """All closed-form IK solutions of one target pose (or of a batch of poses).

    Attributes
    ----------
    solutions : ndarray, shape (k, n) — or (..., K, n) for a batch, NaN rows where ``valid`` is False
        Joint values [rad, m], each verified by the forward kinematics, within the joint limits.
    branches : tuple of str (k,) — or ndarray of str (..., K)
        Branch labels such as ``"shoulder right, elbow up, wrist noflip"`` (definitions in docs/ik.md).
    free : tuple of str (k,) — or ndarray of str (..., K)
        ``""`` for an isolated solution; otherwise the joint combination that stays free along a continuum
        of solutions (coaxial joints, wrist singularity), of which the row is one representative.
    position_error, orientation_error : ndarray (k,) or (..., K)
        FK residual of each solution on the rows the arm controls [m], [rad].
    outside_limits : ndarray, shape (j, n) — or int count per pose for a batch
        Solutions that were found but lie outside the joint limits.
    method : str
        The structure recognised (``pieper``, ``parallel``, ``planar``, ``wrist``, ``position`` …).
    controlled : str
        Which rows of the pose the arm controls (``pose``, ``position``, ``orientation``, ``position+heading``).
    valid : ndarray of bool, shape (..., K) — batch only (all True for one pose)
    """

    solutions: np.ndarray
    branches: Any
    free: Any
    position_error: np.ndarray
    orientation_error: np.ndarray
    outside_limits: Any
    method: str
    controlled: str
    valid: np.ndarray

    def _repr_html_(self) -> str:
        from ..display import ik_html

        return ik_html(self)

    @property
    def count(self):
        """Number of solutions (per pose for a batch)."""
        return self.valid.sum(axis=-1) if self.valid.ndim > 1 else int(self.valid.sum())

    @property
    def continuum(self):
        """True where a solution stands for a continuum (``free`` is not empty)."""
        return np.asarray(self.free, dtype=object) != ""


def _plan(robot: DHRobot, closed_form: bool = True, general: bool = False) -> Plan:
    """The plan of ``robot``: kept with its chain (found by identity, no hashing per call), built once per
    distinct robot value (an equal robot loaded anew shares it through :func:`_plan_of_value`)."""
    memo = dh_chain.chain_of(robot).memo
    key = ("ik_plan", closed_form, general)
    plan = memo.get(key)
    if plan is None:
        plan = memo[key] = _plan_of_value(robot, closed_form, general)
    return plan


@lru_cache(maxsize=64)
def _plan_of_value(robot: DHRobot, closed_form: bool, general: bool) -> Plan:
    plan = make_plan(robot, closed_form, general)
    if plan.closed is not None:  # what the compiled solver needs besides the geometry (denavit.codegen)
        from ._closed import FREE_TOL, RATIO_TOL
        from ._subproblems import AXES_ALIGNED_TOL

        stanford = plan.route == "closed form (stanford)"  # joint 3 slides: no elbow part in its labels
        plan.closed.update(labels=_label_table((SHOULDER, WRIST) if stanford else (SHOULDER, ELBOW, WRIST)),
                           theta=np.array([l.theta for l in robot.joints], float),
                           tols=np.array([FREE_TOL, RATIO_TOL, VERIFY_TOL, POLISH_ABOVE, DUPLICATE_TOL, MERGE_RADIUS,
                                          AXES_ALIGNED_TOL, _reach(robot)], float),
                           far=2 * _bound(robot) + 1.0)  # farther targets get _solve's stand-in
    return plan


def ik_plan(robot: DHRobot) -> Plan:
    """The closed-form plan of ``robot`` (kind, route, solver; raises UnsupportedRobotError if none)."""
    return _plan(robot, True)


def ik_structure(robot: DHRobot) -> str:
    """Name of the closed-form structure recognised for ``robot`` (raises UnsupportedRobotError if none)."""
    return _plan(robot, True).kind


def _controlled(P: np.ndarray) -> str:
    pos, rot = np.trace(P[:3, :3]) > 0.5, np.trace(P[3:, 3:])
    if pos and rot > 2.5:
        return "pose"
    if pos and rot > 0.5:
        return "position+heading"
    return "position" if pos else "orientation"


def _polish(robot: DHRobot, q: np.ndarray, T: np.ndarray, P: np.ndarray) -> np.ndarray:
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


def _fold(robot: DHRobot, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Revolute angles into (−π, π], then by ±2π into the limits where that helps; inside mask."""
    lim = robot.q_limits
    rev = np.array([t is JointType.REVOLUTE for t in robot.joint_types])
    q = np.where(rev, wrap_angle(q), q)
    for shift in (2 * np.pi, -2 * np.pi):
        out = (q < lim[:, 0] - 1e-12) | (q > lim[:, 1] + 1e-12)
        moved = q + shift
        q = np.where(rev & out & (moved >= lim[:, 0]) & (moved <= lim[:, 1]), moved, q)
    inside = np.all((q >= lim[:, 0] - 1e-12) & (q <= lim[:, 1] + 1e-12), axis=-1)
    return q, inside


def _dedupe(robot: DHRobot, q: np.ndarray, keep: np.ndarray, T: np.ndarray | None = None,
            P: np.ndarray | None = None) -> np.ndarray:
    """Drop later copies of the same solution (angles compared modulo 2π), per pose; q (B, K, n).

    A slot is dropped when an earlier kept slot lies within DUPLICATE_TOL of it; only the K(K−1)/2 pairs
    i < j are compared.  With the targets T and projector P, a pair up to MERGE_RADIUS apart is also one solution
    when the midpoint reproduces the target within VERIFY_TOL (merged by FK, not by angle alone)."""
    B, K, _ = q.shape
    if K < 2:
        return keep
    rev = np.array([t is JointType.REVOLUTE for t in robot.joint_types])
    i, j = np.triu_indices(K, 1)
    d = np.abs(q[:, j] - q[:, i])  # (B, P, n)
    d = np.where(rev, np.abs(d - 2 * np.pi * np.rint(d / (2 * np.pi))), d)
    dmax = np.nan_to_num(d.max(axis=-1), nan=np.inf)  # (B, P)
    same = dmax < DUPLICATE_TOL
    hit = np.zeros((B, K, K), dtype=bool)
    hit[:, j, i] = same & keep[:, i]
    keep = keep & ~hit.any(axis=-1)
    # next to a singularity one solution comes out as several copies a little farther apart (roots that merge
    # are found to ~√ε): pairs within MERGE_RADIUS whose midpoint reproduces the pose too are one solution
    close = (dmax >= DUPLICATE_TOL) & (dmax < MERGE_RADIUS) & keep[:, i] & keep[:, j]
    if close.any() and T is not None:
        b, p = np.nonzero(close)
        qi, qj = q[b, i[p]], q[b, j[p]]
        step = np.where(rev, wrap_angle(qj - qi), qj - qi)
        mid = qi + 0.5 * step
        e = pose_error(T[b], forward_kinematics(robot, mid)) @ P.T
        L = max(1.0, _reach(robot))
        one = (np.linalg.norm(e[:, :3], axis=-1) <= VERIFY_TOL * L) & (np.linalg.norm(e[:, 3:], axis=-1) <= VERIFY_TOL)
        for bb, jj, ii in zip(b[one], j[p[one]], i[p[one]]):  # in slot order: a later copy goes, once
            if keep[bb, ii]:
                keep[bb, jj] = False
    return keep


def analytic_ik(robot: DHRobot, T, locked: dict[str, float] | None = None) -> AnalyticIKResult:
    """All inverse-kinematics solutions in closed form, each verified by FK, within the joint limits.

    The structure is recognised from the DH table (either convention, offsets, fixed rows, base and tool
    included): 6-joint arms with a spherical wrist (Pieper 1968; Craig 3rd ed. Sec. 4.6–4.7), 6R arms with
    three parallel axes (UR family), planar and SCARA arms, 3R wrists and other 3-joint arms.  See
    ``docs/ik.md`` for the derivations and the branch labels.

    Any other 6R arm that can reach general poses is solved exactly by the Raghavan–Roth / Manocha–Canny
    eigenvalue method (up to 16 solutions; ``method == "general"``).  Redundant arms are solved for given
    values of the joints named in ``locked`` (IKFast's "free joints"): e.g. Panda with ``{"q7": 0.3}``.

    Parameters
    ----------
    robot : DHRobot
    T : array_like, shape (4, 4) or (..., 4, 4)
        Target end-effector pose(s) in the world frame.
    locked : dict, optional
        Joint names (``"q1"`` … ``"qN"``, numbered as in the DH table) and the values they are held at
        [rad, m]; they are returned unchanged in every solution.

    Returns
    -------
    AnalyticIKResult
        Zero solutions for an unreachable target (not an exception).

    Raises
    ------
    UnsupportedRobotError
        The arm's structure has no closed form here; use :func:`solve_ik`.

    Examples
    --------
    >>> import numpy as np, denavit
    >>> robot = denavit.load_robot("puma560")
    >>> q = np.array([0.3, 0.5, -0.6, 0.7, 0.8, 0.9])
    >>> res = denavit.analytic_ik(robot, denavit.forward_kinematics(robot, q))
    >>> res.solutions.shape[0] <= 8, bool(np.min(np.abs(res.solutions - q).max(axis=1)) < 1e-9)
    (True, True)
    """
    T = as_transform(T, "T")
    plan = None if locked else _plan(robot, True)
    # targets far beyond the reach (1e300 m, say) overflow on the way to "no solution"; every candidate is
    # verified by FK, so those intermediate infinities are no news to the caller
    with np.errstate(over="ignore", invalid="ignore"):
        if locked:
            return _solve_locked(robot, T, locked)
        return _solve(robot, T, plan)


def _lock(robot: DHRobot, locked: dict[str, float]) -> tuple[DHRobot, list[int], np.ndarray]:
    """The arm with the named joints turned into fixed rows at their values; their indices and values."""
    from dataclasses import replace

    from ..errors import ModelError

    idx, vals = [], []
    for name, value in locked.items():
        k = int(name[1:]) - 1 if isinstance(name, str) and name[:1] == "q" and name[1:].isdigit() else -1
        if not 0 <= k < robot.dof:
            raise ModelError(f"locked: {name!r} is not a joint of {robot.name} (q1 … q{robot.dof})")
        v = float(value)
        lo, hi = robot.q_limits[k]
        if not (np.isfinite(v) and lo - 1e-12 <= v <= hi + 1e-12):
            raise ModelError(f"locked: {name} = {v:g} is outside its limits [{lo:g}, {hi:g}]")
        idx.append(k)
        vals.append(v)
    chain = dh_chain.chain_of(robot)
    links = list(robot.links)
    for k, v in zip(idx, vals):
        i = chain.joint_rows[k]
        link = links[i]
        theta, d = dh_chain.joint_motion(chain.rows[i], {k: v}, link.theta, link.d)  # v into θ or d
        links[i] = replace(link, theta=theta, d=d, joint=JointType.FIXED, q_limits=None, symbols=())
    order = np.argsort(idx)
    return replace(robot, links=tuple(links), poses=()), [idx[i] for i in order], np.array(vals)[order]


def _solve_locked(robot: DHRobot, T: np.ndarray, locked: dict[str, float]) -> AnalyticIKResult:
    """Solve the arm with the named joints held (fixed rows), then put their values back into every row."""
    from dataclasses import replace

    reduced, idx, vals = _lock(robot, locked)
    res = _solve(reduced, T, _plan(reduced, True))

    def widen(q):  # ascending indices: each insert lands at its final place; unused (NaN) rows stay NaN
        q = np.asarray(q, dtype=float)
        unused = np.isnan(q).all(axis=-1, keepdims=True)
        for k, v in zip(idx, vals):
            q = np.insert(q, k, v, axis=-1)
        return np.where(unused, np.nan, q)

    outside = widen(res.outside_limits) if np.ndim(res.outside_limits) == 2 else res.outside_limits
    names = ", ".join(f"q{k + 1}" for k in idx)
    return replace(res, solutions=widen(res.solutions), outside_limits=outside, method=f"{res.method} ({names} locked)")


def _solve(robot: DHRobot, T: np.ndarray, plan: Plan) -> AnalyticIKResult:
    """The pipeline of the module notes for one plan (``_plan(robot, False)`` forces the general route)."""
    batch = T.shape[:-2]
    Tf = T.reshape(-1, 4, 4)
    if len(Tf) == 0:  # an empty batch: the same arrays with no pose (and no slot)
        n = robot.dof
        return AnalyticIKResult(np.zeros(batch + (0, n)), np.zeros(batch + (0,), dtype=object),
                                np.zeros(batch + (0,), dtype=object), np.zeros(batch + (0,)), np.zeros(batch + (0,)),
                                np.zeros(batch, dtype=int), plan.kind, _controlled(plan.projector),
                                np.zeros(batch + (0,), dtype=bool))
    # a target beyond every reachable point (|p| above the bound below) has no solution: the plan is given a
    # reachable stand-in instead (its candidates then fail the FK check against the real target), so that
    # targets like 1e300 m never reach the root finders, whose intermediate quantities would overflow
    far = np.linalg.norm(Tf[:, :3, 3], axis=-1) > 2 * _bound(robot) + 1.0
    cand, free = plan.solve(np.where(far[:, None, None], _stand_in(robot), Tf) if far.any() else Tf)  # (B, K, n)
    q, ok, pe, re, lost = _verify(robot, plan, Tf, cand)
    fold = ok & lost & (free == "")
    if fold.any():  # roots near a double root that needed polishing: look for the partner of the pair
        extra, (sb, sk, null) = _fold_partners(robot, plan, Tf, q, fold)
        if len(sb):  # polished onto a singularity: a continuum the plan could not name; named by J's null space
            free[sb, sk] = [_null_text(v) for v in null]
        if extra is not None:
            q2, ok2, pe2, re2, _ = _verify(robot, plan, Tf, extra)
            # a true partner is a regular root: Newton lands on it to rounding; a seed that crawls towards the
            # fold itself stops at a residual ~ its distance to the target, which must not pass as a solution
            ok2 &= (pe2 <= FOLD_RESIDUAL * max(1.0, _reach(robot))) & (re2 <= FOLD_RESIDUAL)
            ok2 &= _new(robot, q, ok, q2, ok2)  # most seeds land back on a solution already there
            if ok2.any():
                keep = np.argsort(~ok2, axis=1, kind="stable")[:, : int(ok2.sum(axis=1).max())]
                pick = lambda a: np.take_along_axis(a, keep.reshape(keep.shape + (1,) * (a.ndim - 2)), 1)  # noqa
                q2, ok2, pe2, re2 = pick(q2), pick(ok2), pick(pe2), pick(re2)
                q, ok = np.concatenate([q, q2], 1), np.concatenate([ok, ok2], 1)
                pe, re = np.concatenate([pe, pe2], 1), np.concatenate([re, re2], 1)
                free = np.concatenate([free, np.full(ok2.shape, "", dtype=object)], 1)
    # keep only the slots some pose uses: the verified candidates first (continua first), the rest dropped
    # continuum representatives before isolated rows, so that a copy of one (a root next to the singular set)
    # is merged into the named continuum, not the other way round
    rank = np.where(ok, np.where(free != "", 0, 1), 2)
    order = np.argsort(rank, axis=1, kind="stable")[:, : max(int(ok.sum(axis=1).max()), 1)]
    take = lambda a: np.take_along_axis(a, order.reshape(order.shape + (1,) * (a.ndim - 2)), 1)  # noqa: E731
    q, ok, free, pe, re = take(q), take(ok), take(free), take(pe), take(re)
    q, inside = _fold(robot, np.where(ok[..., None], q, 0.0))
    ok = _dedupe(robot, np.where(ok[..., None], q, np.nan), ok, Tf, plan.projector)
    outside = ok & ~inside
    ok &= inside
    labels = _labels(robot, plan, q, Tf)
    return _pack(batch, q, ok, labels, free, pe, re, outside, plan)


def _verify(robot: DHRobot, plan: Plan, Tf: np.ndarray, cand: np.ndarray):
    """FK residual of every candidate; far-off ones dropped, rough ones (roots near double roots) polished and
    re-checked; the rest are kept as computed.  Returns q (B, K, n) (NaN where dropped), ok, position and
    orientation residuals (B, K) on the rows the arm controls."""
    B, K, _ = cand.shape
    L = _reach(robot)
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
            q[rough] = _polish(robot, cand[rough], Tk[rough], plan.projector)
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


def _new(robot: DHRobot, q: np.ndarray, ok: np.ndarray, q2: np.ndarray, ok2: np.ndarray) -> np.ndarray:
    """Which of the extra solutions q2 (B, E, n) are farther than DUPLICATE_TOL from every solution of q (B, K, n)
    of their pose (the extras among themselves are left to :func:`_dedupe`)."""
    rev = np.array([t is JointType.REVOLUTE for t in robot.joint_types])
    b = np.flatnonzero(ok2.any(axis=1))
    d = np.abs(q2[b][:, :, None] - q[b][:, None])  # (b, E, K, n)
    d = np.where(rev, np.abs(d - 2 * np.pi * np.rint(d / (2 * np.pi))), d).max(axis=-1)
    dup = (np.where(ok[b][:, None], np.nan_to_num(d, nan=np.inf), np.inf) < DUPLICATE_TOL).any(axis=-1)
    out = ok2.copy()
    out[b] &= ~dup
    return out


def _fold_partners(robot: DHRobot, plan: Plan, Tf: np.ndarray, q: np.ndarray, fold: np.ndarray):
    """Candidates for the second root of a pair that nearly coincide (a pose within ~FOLD_SIGMA of a
    singularity, where root finding returns one root for two): from each polished solution whose controlled
    Jacobian has σ_min < FOLD_SIGMA · σ_max, Newton steps from q ± t v (v: the singular direction, t = FOLD_STEPS).
    Returns candidates (B, E, n) for :func:`_verify` (None when no solution is that close to a singularity), and
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
    flat = _polish(robot, seeds.reshape(-1, n), np.repeat(Tf[b], S, axis=0), plan.projector)
    # per pose: the seeds of all its near-singular solutions, in extra slots
    per = np.bincount(b, minlength=len(Tf)) * S
    out = np.full((len(Tf), int(per.max()), n), np.nan)
    slot = np.arange(m * S) - np.repeat(np.concatenate([[0], np.cumsum(per)[:-1]])[b], S)
    out[np.repeat(b, S), slot] = flat
    return out, singular


def _null_text(v: np.ndarray) -> str:
    """The continuum through a solution where J is singular, named by its null direction v (unit, (n,)):
    e.g. ``0.71 q4 - 0.71 q6 free (J singular: its null direction)``."""
    v = v * np.sign(v[np.argmax(np.abs(v))])
    terms = [(c, k) for k, c in enumerate(v) if abs(c) > 0.05]
    text = " ".join(f"{'-' if c < 0 else '+'} {abs(c):.2f} q{k + 1}" for c, k in terms).lstrip("+ ")
    return f"{text} free (J singular: its null direction)"


def _bound(robot: DHRobot) -> float:
    """An upper bound of |p| over every configuration within the limits (inf with an unbounded prismatic joint):
    |c| + R of the chain's :func:`~denavit.chain.reach_ball`."""
    lim = robot.q_limits
    centre, R = reach_ball(screws_of(robot), lim[:, 0], lim[:, 1])
    return float(np.linalg.norm(centre)) + R


def _stand_in(robot: DHRobot) -> np.ndarray:
    return forward_kinematics(robot, np.zeros(robot.dof))


def _reach(robot: DHRobot) -> float:
    return sum(abs(l.a) + abs(l.d) for l in robot.links)


def _pack(batch, q, ok, labels, free, pe, re, outside, plan) -> AnalyticIKResult:
    n = q.shape[-1]
    ctrl = _controlled(plan.projector)
    if batch == ():
        sel = ok[0]
        order = np.lexsort(q[0][sel].T[::-1]) if sel.any() else np.zeros(0, int)
        return AnalyticIKResult(
            q[0][sel][order], tuple(labels[0][sel][order]), tuple(free[0][sel][order]), pe[0][sel][order],
            re[0][sel][order], q[0][outside[0]], plan.kind, ctrl, np.ones(int(sel.sum()), dtype=bool))
    K = q.shape[1]
    qn = np.where(ok[..., None], q, np.nan)
    return AnalyticIKResult(
        qn.reshape(batch + (K, n)), np.where(ok, labels, "").reshape(batch + (K,)),
        np.where(ok, free, "").reshape(batch + (K,)), np.where(ok, pe, np.nan).reshape(batch + (K,)),
        np.where(ok, re, np.nan).reshape(batch + (K,)), outside.sum(axis=-1).reshape(batch), plan.kind, ctrl,
        ok.reshape(batch + (K,)))


def _labels(robot: DHRobot, plan: Plan, q: np.ndarray, T: np.ndarray) -> np.ndarray:
    """Branch labels (B, K); definitions in docs/ik.md.

    Each part of a label is a boolean test of q; the label is looked up from the combined bits (no string
    arithmetic per solution)."""
    B, K, n = q.shape
    chain = screws_of(robot)
    qq = np.nan_to_num(q)
    rev = ~chain.prismatic
    theta = _thetas(robot)
    parts = []  # (test (B, K) bool, label where True, label where False)
    if plan.kind.startswith(("pieper", "parallel", "position")) and plan.point_e is not None or plan.kind == "position":
        pe = plan.point_e if plan.point_e is not None else np.zeros(3)
        X = (T[:, :3, :3] @ pe + T[:, :3, 3]).T[:, :, None]  # (3, B, 1)
        x1, _, _, S = screw_walk(chain, qq[..., :1], upto=1)  # frame after joint 1 (shoulder), (3, B, K)
        if rev[0]:  # measured from axis 1 (not from S, which a shoulder offset a1 moves along x1)
            O1 = chain.consts[0][:3, 3][:, None, None]  # a point of axis 1
            parts.append((np.sum(x1 * (X - O1), axis=0) >= 0, *SHOULDER))
        if n >= 3 and rev[1] and rev[2]:
            # in the plane normal to axis 2 the two elbows are mirror images across the line from the shoulder S
            # to the point W the joints 2-3 place (the wrist centre; UR: a point of axis 4, parallel to axis 2):
            # the side of that line, with n = a2 × (W − S) oriented towards axis 1, tells them apart
            a2 = screw_walk(chain, qq[..., :1], upto=1)[2]  # axis 2, (3, B, K)
            E = screw_walk(chain, qq[..., :2], upto=2)[3]  # a point of axis 3
            W = screw_walk(chain, qq[..., :3], upto=3)[3] if plan.kind.startswith("parallel") and n >= 4 else X
            up = chain.consts[0][:3, 2][:, None, None]
            nrm = np.cross(a2, W - S, axis=0)
            towards = np.where(np.sum(up * nrm, axis=0) >= 0, 1.0, -1.0)
            parts.append((np.sum((E - S) * nrm, axis=0) * towards >= 0, *ELBOW))
        if n == 6 and rev[4] and plan.kind.startswith(("pieper", "parallel")):
            parts.append((np.sin(qq[..., 4] + theta[4]) >= 0, *WRIST))
    elif plan.kind == "planar":
        r = np.flatnonzero(rev)
        parts.append((np.sin(qq[..., r[1]] + theta[r[1]]) >= 0, "elbow up", "elbow down"))
    elif plan.kind == "wrist":
        parts.append((np.sin(qq[..., 1] + theta[1]) >= 0, "wrist noflip", "wrist flip"))
    code = np.zeros((B, K), dtype=np.intp)
    for i, (test, _, _) in enumerate(parts):
        code |= np.where(test, 0, 1 << i)
    return _label_table(tuple(p[1:] for p in parts))[code]


@lru_cache(maxsize=64)
def _label_table(names: tuple) -> np.ndarray:
    """Label of every bit code: bit i set picks the second name of part i."""
    return np.array([", ".join(p[(c >> i) & 1] for i, p in enumerate(names)) for c in range(1 << len(names))],
                    dtype=object)


def _thetas(robot: DHRobot) -> np.ndarray:
    memo = dh_chain.chain_of(robot).memo
    if "ik_thetas" not in memo:
        memo["ik_thetas"] = np.array([l.theta for l in robot.joints])  # read-only use
    return memo["ik_thetas"]
