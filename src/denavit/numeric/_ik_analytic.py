"""All inverse-kinematics solutions in closed form, batched over target poses.

Pipeline (the same for every structure): the plan of :mod:`._ik_plans` proposes candidates → a few
Newton steps polish each (root finding loses digits near double roots) → every candidate is re-checked
by the forward kinematics → revolute angles are folded by whole turns into the joint limits, those that
cannot be are set aside → duplicates are merged → each solution gets a branch label.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache
from typing import Any

import numpy as np

from .._validate import as_transform
from ..model import DHRobot, JointType
from ._ik_chain import chain_of, chain_fk, wrap_angle
from ._ik_numeric import pose_error
from ._ik_plans import Plan, make_plan
from ._ik_kernel import kernel_of, targets_soa
from ._kinematics import forward_kinematics
from ._transforms import inverse_transform

__all__ = ["AnalyticIKResult", "analytic_ik", "ik_structure"]

VERIFY_TOL = 1e-9  # position [m] and orientation [rad] a solution must reproduce
POLISH_STEPS = 30
DUPLICATE_TOL = 1e-6
POLISH_ABOVE = 1e-12  # residual [m] under which a closed-form candidate is kept as it is
PREFILTER = 0.05  # candidates farther than this fraction of the reach are not polished  # joint-space distance under which two solutions are the same [rad, m]


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

    @property
    def count(self):
        """Number of solutions (per pose for a batch)."""
        return self.valid.sum(axis=-1) if self.valid.ndim > 1 else int(self.valid.sum())

    @property
    def continuum(self):
        """True where a solution stands for a continuum (``free`` is not empty)."""
        return np.asarray(self.free, dtype=object) != ""


@lru_cache(maxsize=64)
def _plan(robot: DHRobot) -> Plan:
    return make_plan(robot)


def ik_structure(robot: DHRobot) -> str:
    """Name of the closed-form structure recognised for ``robot`` (raises UnsupportedRobotError if none)."""
    return _plan(robot).kind


def _controlled(P: np.ndarray) -> str:
    pos, rot = np.trace(P[:3, :3]) > 0.5, np.trace(P[3:, 3:])
    if pos and rot > 2.5:
        return "pose"
    if pos and rot > 0.5:
        return "position+heading"
    return "position" if pos else "orientation"


def _polish(robot: DHRobot, q: np.ndarray, T: np.ndarray, P: np.ndarray) -> np.ndarray:
    """Damped Gauss–Newton steps on P·e until converged (restores the digits lost in root finding).

    Residual and Jacobian come from one pass over the chain (:mod:`._ik_kernel`)."""
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
        q[act] += np.linalg.solve(A, np.einsum("bij,bj->bi", Jt, e)[..., None])[..., 0]
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


def _dedupe(robot: DHRobot, q: np.ndarray, keep: np.ndarray) -> np.ndarray:
    """Drop later copies of the same solution (angles compared modulo 2π), per pose; q (B, K, n)."""
    rev = np.array([t is JointType.REVOLUTE for t in robot.joint_types])
    d = q[:, :, None, :] - q[:, None, :, :]  # (B, K, K, n)
    d = np.where(rev, np.abs(wrap_angle(d)), np.abs(d))
    same = np.nan_to_num(d.max(axis=-1), nan=np.inf) < DUPLICATE_TOL
    K = q.shape[1]
    earlier = np.tril(np.ones((K, K), dtype=bool), -1)  # j < i
    dup = np.any(same & earlier[None] & keep[:, None, :], axis=-1)
    return keep & ~dup


def analytic_ik(robot: DHRobot, T) -> AnalyticIKResult:
    """All inverse-kinematics solutions in closed form, each verified by FK, within the joint limits.

    The structure is recognised from the DH table (either convention, offsets, fixed rows, base and tool
    included): 6-joint arms with a spherical wrist (Pieper 1968; Craig 3rd ed. Sec. 4.6–4.7), 6R arms with
    three parallel axes (UR family), planar and SCARA arms, 3R wrists and other 3-joint arms.  See
    ``docs/ik.md`` for the derivations and the branch labels.

    Parameters
    ----------
    robot : DHRobot
    T : array_like, shape (4, 4) or (..., 4, 4)
        Target end-effector pose(s) in the world frame.

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
    plan = _plan(robot)
    batch = T.shape[:-2]
    Tf = T.reshape(-1, 4, 4)
    B, n = len(Tf), robot.dof
    cand, free = plan.solve(Tf)  # (B, K, n)
    K = cand.shape[1]
    ok = np.all(np.isfinite(cand), axis=-1)
    Tk = np.broadcast_to(Tf[:, None], (B, K, 4, 4))
    q = np.full(cand.shape, np.nan)
    if ok.any():  # false roots are far off: drop them before the (costly) polish
        e0 = pose_error(Tk[ok], forward_kinematics(robot, cand[ok])) @ plan.projector.T
        size = np.linalg.norm(e0[:, :3], axis=-1) + _reach(robot) * np.linalg.norm(e0[:, 3:], axis=-1)
        near = np.zeros_like(ok)
        near[ok] = size < PREFILTER * max(_reach(robot), 1e-3)
        rough = np.zeros_like(ok)  # only candidates that lost digits (near double roots) are polished
        rough[ok] = size > POLISH_ABOVE * max(_reach(robot), 1.0)
        ok &= near
        q[ok] = cand[ok]
        rough &= ok
        if rough.any():
            q[rough] = _polish(robot, cand[rough], Tk[rough], plan.projector)
    ok &= np.all(np.isfinite(q), axis=-1)
    pe = np.full((B, K), np.inf)
    re = np.full((B, K), np.inf)
    if ok.any():
        e = pose_error(Tk[ok], forward_kinematics(robot, q[ok])) @ plan.projector.T
        pe[ok], re[ok] = np.linalg.norm(e[:, :3], axis=-1), np.linalg.norm(e[:, 3:], axis=-1)
    ok &= (pe <= VERIFY_TOL * max(1.0, _reach(robot))) & (re <= VERIFY_TOL)
    # keep only the slots some pose uses: the verified candidates first, the rest dropped
    order = np.argsort(~ok, axis=1, kind="stable")[:, : max(int(ok.sum(axis=1).max()), 1)]
    take = lambda a: np.take_along_axis(a, order.reshape(order.shape + (1,) * (a.ndim - 2)), 1)  # noqa: E731
    q, ok, free, pe, re = take(q), take(ok), take(free), take(pe), take(re)
    q, inside = _fold(robot, np.where(ok[..., None], q, 0.0))
    ok = _dedupe(robot, np.where(ok[..., None], q, np.nan), ok)
    outside = ok & ~inside
    ok &= inside
    labels = _labels(robot, plan, q, Tf)
    return _pack(batch, q, ok, labels, free, pe, re, outside, plan)


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
    """Branch labels (B, K); definitions in docs/ik.md."""
    B, K, n = q.shape
    out = np.full((B, K), "", dtype=object)
    chain = chain_of(robot)
    qq = np.nan_to_num(q)
    rev = ~chain.prismatic
    theta = np.array([l.theta for l in robot.joints])
    parts = []
    if plan.kind.startswith(("pieper", "parallel", "position")) and plan.point_e is not None or plan.kind == "position":
        pe = plan.point_e if plan.point_e is not None else np.zeros(3)
        X = T[:, None, :3, :3] @ pe + T[:, None, :3, 3]  # (B, 1, 3)
        if rev[0]:
            F1 = chain_fk(chain, qq[..., :1], upto=1)
            x1 = np.einsum("bkji,bkj->bki", F1[..., :3, :3], X - F1[..., :3, 3])[..., 0]
            parts.append(np.where(x1 >= 0, "shoulder right", "shoulder left"))
        if n >= 3 and rev[1] and rev[2]:
            pts = [chain_fk(chain, qq[..., :k], upto=k)[..., :3, 3] if k else np.broadcast_to(chain.consts[0][:3, 3], X.shape)
                   for k in (1, 2)]
            S, E = pts
            up = chain.consts[0][:3, 2]
            v = X - S
            v = v / np.maximum(np.linalg.norm(v, axis=-1, keepdims=True), 1e-300)
            u = up - np.sum(up * v, -1, keepdims=True) * v
            parts.append(np.where(np.sum((E - S) * u, -1) >= 0, "elbow up", "elbow down"))
        if n == 6 and rev[4] and plan.kind.startswith(("pieper", "parallel")):
            parts.append(np.where(np.sin(qq[..., 4] + theta[4]) >= 0, "wrist noflip", "wrist flip"))
    elif plan.kind == "planar":
        r = np.flatnonzero(rev)
        parts.append(np.where(np.sin(qq[..., r[1]] + theta[r[1]]) >= 0, "elbow up", "elbow down"))
    elif plan.kind == "wrist":
        parts.append(np.where(np.sin(qq[..., 1] + theta[1]) >= 0, "wrist noflip", "wrist flip"))
    for p in parts:
        out = np.where(out == "", p, out + ", " + p)
    return out
