"""All inverse-kinematics solutions in closed form, batched over target poses.

Pipeline (the same for every structure): the plan of :mod:`._plans` proposes candidates (the direct closed
forms of :mod:`._closed` for elbow and Stanford Pieper arms) → one batched forward-kinematics pass checks every
candidate → only those whose residual shows lost digits (general root finding near double roots) get a few
Gauss–Newton steps and a second check → revolute angles are folded by whole turns into the joint limits, those
that cannot be are set aside → duplicates are merged → each solution gets a branch label.
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np

from .. import chain as dh_chain
from .._validate import as_transform
from ..chain import reach_ball, screws_of
from ..model import DHRobot, JointType
from ..numeric import forward_kinematics
from ._candidates import (DUPLICATE_TOL, FOLD_RESIDUAL, MERGE_RADIUS, POLISH_ABOVE, VERIFY_TOL, arm_reach,
                          fold_partners, new_solutions, null_text, verify)
from ._chain import wrap_angle
from ._labels import ELBOW, SHOULDER, WRIST, branch_labels, label_table
from ._plans import Plan, make_plan
from ._residual import AnalyticIKResult, pose_error

__all__ = ["AnalyticIKResult", "analytic_ik", "ik_structure", "ik_plan"]


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
        plan.closed.update(labels=label_table((SHOULDER, WRIST) if stanford else (SHOULDER, ELBOW, WRIST)),
                           theta=np.array([l.theta for l in robot.joints], float),
                           tols=np.array([FREE_TOL, RATIO_TOL, VERIFY_TOL, POLISH_ABOVE, DUPLICATE_TOL, MERGE_RADIUS,
                                          AXES_ALIGNED_TOL, arm_reach(robot)], float),
                           far=2 * _bound(robot) + 1.0)  # farther targets get _solve's stand-in
    return plan


def ik_plan(robot: DHRobot) -> Plan:
    """The closed-form plan of ``robot`` (kind, route, solver; raises UnsupportedRobotError if none)."""
    return _plan(robot, True)


def ik_structure(robot: DHRobot) -> str:
    """Name of the closed-form structure recognised for ``robot`` (raises UnsupportedRobotError if none)."""
    return _plan(robot, True).kind


def controlled_rows(P: np.ndarray) -> str:
    pos, rot = np.trace(P[:3, :3]) > 0.5, np.trace(P[3:, 3:])
    if pos and rot > 2.5:
        return "pose"
    if pos and rot > 0.5:
        return "position+heading"
    return "position" if pos else "orientation"


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
        L = max(1.0, arm_reach(robot))
        one = (np.linalg.norm(e[:, :3], axis=-1) <= VERIFY_TOL * L) & (np.linalg.norm(e[:, 3:], axis=-1) <= VERIFY_TOL)
        for bb, jj, ii in zip(b[one], j[p[one]], i[p[one]]):  # in slot order: a later copy goes, once
            if keep[bb, ii]:
                keep[bb, jj] = False
    return keep


def analytic_ik(robot: DHRobot, T, locked: dict[str, float] | None = None, *,
                free: dict[str, float] | None = None) -> AnalyticIKResult:
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
    free : dict, optional
        The same as ``locked`` under issue 30's name (the held joint is the free parameter of a redundant arm's
        self-motion): ``free={"q7": 0.3}``; give one of the two.

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
    if free is not None:  # one code path: free= is locked= under another name
        if locked is not None:
            from ..errors import ModelError

            raise ModelError("analytic_ik: give locked= or free= (the same thing), not both")
        locked = free
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
                                np.zeros(batch, dtype=int), plan.kind, controlled_rows(plan.projector),
                                np.zeros(batch + (0,), dtype=bool))
    # a target beyond every reachable point (|p| above the bound below) has no solution: the plan is given a
    # reachable stand-in instead (its candidates then fail the FK check against the real target), so that
    # targets like 1e300 m never reach the root finders, whose intermediate quantities would overflow
    far = np.linalg.norm(Tf[:, :3, 3], axis=-1) > 2 * _bound(robot) + 1.0
    cand, free = plan.solve(np.where(far[:, None, None], _stand_in(robot), Tf) if far.any() else Tf)  # (B, K, n)
    q, ok, pe, re, lost = verify(robot, plan, Tf, cand)
    fold = ok & lost & (free == "")
    if fold.any():  # roots near a double root that needed polishing: look for the partner of the pair
        extra, (sb, sk, null) = fold_partners(robot, plan, Tf, q, fold)
        if len(sb):  # polished onto a singularity: a continuum the plan could not name; named by J's null space
            free[sb, sk] = [null_text(v) for v in null]
        if extra is not None:
            q2, ok2, pe2, re2, _ = verify(robot, plan, Tf, extra)
            # a true partner is a regular root: Newton lands on it to rounding; a seed that crawls towards the
            # fold itself stops at a residual ~ its distance to the target, which must not pass as a solution
            ok2 &= (pe2 <= FOLD_RESIDUAL * max(1.0, arm_reach(robot))) & (re2 <= FOLD_RESIDUAL)
            ok2 &= new_solutions(robot, q, ok, q2, ok2)  # most seeds land back on a solution already there
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
    labels = branch_labels(robot, plan, q, Tf)
    return _pack(batch, q, ok, labels, free, pe, re, outside, plan)


def _bound(robot: DHRobot) -> float:
    """An upper bound of |p| over every configuration within the limits (inf with an unbounded prismatic joint):
    |c| + R of the chain's :func:`~denavit.chain.reach_ball`."""
    lim = robot.q_limits
    centre, R = reach_ball(screws_of(robot), lim[:, 0], lim[:, 1])
    return float(np.linalg.norm(centre)) + R


def _stand_in(robot: DHRobot) -> np.ndarray:
    return forward_kinematics(robot, np.zeros(robot.dof))


def _pack(batch, q, ok, labels, free, pe, re, outside, plan) -> AnalyticIKResult:
    n = q.shape[-1]
    ctrl = controlled_rows(plan.projector)
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


