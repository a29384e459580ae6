"""Numerical inverse kinematics: Levenberg–Marquardt (damped least squares), batched over targets.

Every target of a batch runs its own LM iteration (own damping, own acceptance test), but the arithmetic
of one iteration is done for the whole batch at once with numpy: one forward-kinematics pass, one
Jacobian, one batched n×n solve.  Targets that converge drop out; targets that stall are restarted from
random joint values within the limits.  Success is always decided by re-running the forward kinematics on
the returned joint values, never taken from the iteration's own bookkeeping.
"""

from __future__ import annotations

from typing import Sequence

import numpy as np

from .._validate import as_joint_array, as_transform
from ..model import DHRobot
from ._chain import damped_solve
from ..chain import reach_ball, screws_of
from ._residual import (LAMBDA0, LAMBDA_MAX, IKResult, JointLimits, characteristic_length, limits_of, pose_error, row_mask,
                        rotation_log)
from ._kernel import kernel_of, targets_soa
from ._lm import RESTART_ITERATIONS  # iteration budget of a restart, relative to max_iterations
from ._seeds import rescue
from ._single import solve_single
from ..numeric import forward_kinematics

__all__ = ["IKResult", "solve_ik", "pose_error", "rotation_log", "row_mask", "JointLimits", "characteristic_length",
           "TOL", "MAX_ITERATIONS", "RESTARTS"]

TOL = 1e-9  # default position [m] and orientation [rad] tolerance
MAX_ITERATIONS = 100
RESTARTS = 64
PARALLEL_SEEDS = 32  # at most this many seeds side by side per target once few targets are left
SMALL_BATCH = 512  # "few": at most this many attempts in flight
CLIPPED_SEEDS = 0.1  # share of restarts iterated inside the limits (the rest run free and are folded)
_REASONS = ("", "iterations", "limits", "unreachable")


class _Slots:
    """The LM attempts in flight: one row per attempt, ``tgt`` the target each one works on."""

    def __init__(self, kin, L):
        self.kin, self.L = kin, L
        n = kin.n
        self.tgt = np.zeros(0, dtype=int)
        self.q = np.zeros((0, n))
        self.e = np.zeros((0, 6))
        self.J = np.zeros((0, 6, n))
        self.cost = np.zeros(0)
        self.lam = np.zeros(0)
        self.it = np.zeros(0, dtype=int)
        self.cap = np.zeros(0, dtype=int)
        self.clip = np.zeros(0, dtype=bool)

    def add(self, tgt, q, clip, cap):
        """New attempts; their residual and Jacobian come with the next iteration's evaluation (e = 0 and J = 0
        make that iteration's step zero, and an infinite cost makes it accepted)."""
        m, n, cat = len(tgt), self.kin.n, np.concatenate
        self.tgt, self.q = cat([self.tgt, tgt]), cat([self.q, q])
        self.e, self.J = cat([self.e, np.zeros((m, 6))]), cat([self.J, np.zeros((m, 6, n))])
        self.cost = cat([self.cost, np.full(m, np.inf)])
        self.lam = cat([self.lam, np.full(m, 5.0 * LAMBDA0 * self.L**2)])  # ×0.2 at the first (zero) step
        self.it = cat([self.it, np.zeros(m, dtype=int)])
        self.cap = cat([self.cap, np.full(m, cap + 1)])
        self.clip = cat([self.clip, clip])

    def keep(self, mask):
        for name in ("tgt", "q", "e", "J", "cost", "lam", "it", "cap", "clip"):
            setattr(self, name, getattr(self, name)[mask])


def _search(robot, q0, Tf, w, limits, max_iter, restarts, tol, L, rng, clip0=None):
    """Levenberg–Marquardt from q0 (B, n), restarting each target from random seeds until it is solved within
    the limits or its restarts are used up.  Every attempt is a row of one batch: an attempt that ends
    (converged outside the limits, stalled, out of iterations) is replaced at once by the target's next seed,
    so the batch stays full; when few targets are left, each gets several seeds side by side.

    Returns q (B, n) (the solution, or the best point found), iterations, restarts, stalled (B,).
    """
    B, n = q0.shape
    Rt, pt = targets_soa(Tf)
    S = _Slots(kernel_of(robot), L)
    lo, hi, rev = limits.lo, limits.hi, limits.revolute
    out = q0.copy()
    best = np.full(B, np.inf)
    iters = np.zeros(B, dtype=int)
    n_restarts = np.zeros(B, dtype=int)
    stalled = np.zeros(B, dtype=bool)
    done = np.zeros(B, dtype=bool)
    # first attempt without limits, folded back by whole turns afterwards: the clipped iteration is slow and
    # cannot pass a limit, while the free one converges in a few steps
    S.add(np.arange(B), q0.copy(), np.zeros(B, dtype=bool) if clip0 is None else clip0, max_iter)
    eye = np.eye(n)
    while S.tgt.size:
        Jt = np.swapaxes(S.J, -1, -2)
        dq = damped_solve(Jt @ S.J + S.lam[:, None, None] * eye, np.einsum("bij,bj->bi", Jt, S.e)[..., None])[..., 0]
        q_new = _wrap(S.q + dq, rev)
        # clipped attempts: folded by whole turns first, so a limit beyond ±π (Panda joint 6) stays reachable
        q_new = np.where(S.clip[:, None], np.clip(_fold(q_new, lo, hi, rev), lo, hi), q_new)
        e_new, J_new = S.kin.residual(q_new, Rt[..., S.tgt], pt[:, S.tgt], w)
        c_new = np.einsum("bi,bi->b", e_new, e_new)
        better = c_new < S.cost
        # an accepted step that barely lowers the cost: a local minimum with a residual (or unreachable)
        with np.errstate(invalid="ignore"):
            flat = better & (S.cost - c_new < 1e-9 * S.cost)
        np.add.at(iters, S.tgt, 1)
        S.q[better], S.e[better], S.J[better], S.cost[better] = q_new[better], e_new[better], J_new[better], c_new[better]
        S.lam = np.where(better, np.maximum(S.lam * 0.2, 1e-12 * L * L), S.lam * 8.0)
        S.it += 1
        stop = flat | (~better & (S.lam > LAMBDA_MAX * L * L)) | (S.it >= S.cap)
        conv = _converged(S.e, w, tol, tol, L)
        qf = _fold(S.q, lo, hi, rev)
        ok = conv & np.all((qf >= lo - 1e-12) & (qf <= hi + 1e-12), axis=-1)
        ended = ok | conv | stop
        cand = np.zeros(0, dtype=int)
        if ended.any():
            # record the best end point of every finished attempt (for failures), then the solved targets
            fin = np.flatnonzero(ended)
            score = np.where(ok[fin], -1.0, S.cost[fin])
            fin = fin[np.argsort(-score)]  # worst first: for a target ending twice, the best is written last
            t, sc = S.tgt[fin], np.sort(score)[::-1]
            upd = (sc < best[t]) & ~done[t]
            best[t[upd]], out[t[upd]] = sc[upd], qf[fin[upd]]
            done[S.tgt[ok]] = True
            stalled[t[(stop & (S.it < S.cap))[fin]]] = True  # some attempt ended in a local minimum
            S.keep(~ended & ~done[S.tgt])
            cand = np.unique(t[~done[t]])
        if S.tgt.size + cand.size <= SMALL_BATCH // 8:
            cand = np.union1d(cand, S.tgt)  # few left: every target gets seeds side by side
        if cand.size:
            _reseed(S, cand, B, n_restarts, restarts, limits, rng, L, max(int(max_iter * RESTART_ITERATIONS), 1))
    return out, iters, n_restarts, stalled


def _reseed(S, cand, B, n_restarts, restarts, limits, rng, L, cap):
    """New random seeds for the targets ``cand`` (one each, or several side by side when few are left)."""
    live = np.bincount(S.tgt, minlength=B)
    in_flight = np.count_nonzero(live[cand] == 0) + np.count_nonzero(live)
    k = int(np.clip(SMALL_BATCH // max(in_flight, 1), 1, PARALLEL_SEEDS)) if in_flight * 2 <= SMALL_BATCH else 1
    m = np.clip(np.minimum(k - live[cand], restarts - n_restarts[cand]), 0, None)
    tg = np.repeat(cand, m)
    if tg.size:
        n_restarts[cand] += m
        S.add(tg, limits.sample(rng, (tg.size,), L), rng.random(tg.size) < CLIPPED_SEEDS, cap)


def _wrap(q, revolute):
    return np.where(revolute, np.pi - np.mod(np.pi - q, 2 * np.pi), q)


def _fold(q, lo, hi, revolute):
    """Revolute angles wrapped into (−π, π], then shifted by a whole turn into [lo, hi] where that helps."""
    q = _wrap(q, revolute)
    shift = np.where(q < lo, 2 * np.pi, np.where(q > hi, -2 * np.pi, 0.0))
    moved = q + shift
    return np.where(revolute & (shift != 0) & (moved >= lo) & (moved <= hi), moved, q)


def _converged(e, w, tol_p, tol_r, L):
    wp = np.where(w[:3] > 0, 1.0, 0.0)
    wr = np.where(w[3:] > 0, 1.0 / L, 0.0)
    pe = np.sqrt(np.einsum("bi,bi->b", e[:, :3] * wp, e[:, :3] * wp))
    re = np.sqrt(np.einsum("bi,bi->b", e[:, 3:] * wr, e[:, 3:] * wr))
    # a margin below tol so that the FK re-check (a second computation) passes too
    return (pe <= 0.5 * tol_p) & (re <= 0.5 * tol_r)


def _residuals(robot, q, T_t, mask):
    e = pose_error(T_t, forward_kinematics(robot, q))
    return _norm3(e[..., :3] * mask[:3]), _norm3(e[..., 3:] * mask[3:])


def _norm3(v: np.ndarray) -> np.ndarray:
    """|v| over the last axis (3) without overflow for components up to the largest float."""
    return np.hypot(np.hypot(v[..., 0], v[..., 1]), v[..., 2])


def _out_of_reach(robot: DHRobot, Tf: np.ndarray, w_mask: np.ndarray, limits, tol: float) -> np.ndarray:
    """Targets (B,) whose (masked) position is farther from the base than the arm reaches within the limits.

    |p(q) − t(C0)| ≤ Σ_{k≥1} |t(C_k)| + Σ_prismatic max |q_k| for the chain C0 J1 C1 ⋯ Jn Cn (rotations keep
    lengths), and a masked distance is at most the full one: such a target is unreachable for every q, with
    no iteration.  Arms with an unlimited prismatic joint reach everywhere: nothing is screened."""
    centre, R = reach_ball(screws_of(robot), limits.lo, limits.hi)
    if not np.isfinite(R):
        return np.zeros(len(Tf), dtype=bool)
    d = _norm3((Tf[:, :3, 3] - centre) * w_mask[:3])
    return ~(d <= R * (1.0 + 1e-12) + tol)  # NaN distances too: never iterated


def solve_ik(robot: DHRobot, T, q0=None, *, mask: str | Sequence[bool] | None = "pose", tol: float = TOL,
             max_iterations: int = MAX_ITERATIONS, restarts: int = RESTARTS, respect_limits: bool = True,
             rng: np.random.Generator | None = None) -> IKResult:
    """Numerical inverse kinematics by Levenberg–Marquardt, batched over targets.

    Minimises ½‖W e(q)‖² with e = (p_t − p(q), log(R_t R(q)ᵀ)) (world axes, rows selected by ``mask``,
    rotation rows scaled by the arm's characteristic length L so both parts are lengths).  Each step solves

    .. math:: (J_W^T J_W + \\lambda I)\\, \\Delta q = J_W^T W e, \\qquad J_W = W J_0

    and is accepted only if it lowers the cost; λ shrinks on success and grows on rejection
    (Levenberg 1944; Marquardt 1963; Nakamura & Hanafusa 1986 for the damped least-squares form;
    Sugihara 2011 for LM in IK).  After each step q is brought back inside the joint limits (clipped;
    revolute joints wrapped into (−π, π] first).  Targets that stall restart from random q within limits.

    Parameters
    ----------
    robot : DHRobot
    T : array_like, shape (..., 4, 4)
        Target end-effector poses in the world frame (``T_w_e``).
    q0 : array_like, shape (n,) or (..., n), optional
        Seed configuration(s); default: the middle of the limits (0 for unlimited revolute joints).
    mask : "pose", "position" or 6 booleans
        Rows of (x, y, z, ωx, ωy, ωz) to match; use "position" or a mask for arms with fewer than 6 joints
        when the target's orientation is not reachable.
    tol : float
        Success tolerance on the position [m] and orientation [rad] residual norms.
    max_iterations : int
        LM iterations per attempt.
    restarts : int
        Random restarts for targets not solved from the seed.
    respect_limits : bool
        Keep q within the joint limits (default) or ignore them.
    rng : numpy.random.Generator, optional
        Source of the random restarts.

    Returns
    -------
    IKResult
        Unreachable targets are results with ``success=False`` and a ``reason``, not exceptions.

    Examples
    --------
    >>> import numpy as np, denavit
    >>> robot = denavit.load_robot("puma560")
    >>> T = denavit.forward_kinematics(robot, [0.1, 0.2, -0.3, 0.4, 0.5, 0.6])
    >>> res = denavit.solve_ik(robot, T, rng=np.random.default_rng(0))
    >>> bool(res.success), bool(np.allclose(denavit.forward_kinematics(robot, res.q), T, atol=1e-8))
    (True, True)
    """
    T = as_transform(T, "T")
    batch = T.shape[:-2]
    w_mask = row_mask(mask)
    n, L = robot.dof, characteristic_length(robot)
    w = np.where(w_mask, 1.0, 0.0) * np.array([1, 1, 1, L, L, L])
    limits = limits_of(robot, not respect_limits)
    Tf = T.reshape(-1, 4, 4)
    B = Tf.shape[0]
    if q0 is None:
        q = np.tile(np.mean(limits.sample_bounds(L), axis=0), (B, 1))  # the middle of the limits, 0 without
    else:
        q = np.broadcast_to(as_joint_array(q0, n, "q0"), batch + (n,)).reshape(B, n).copy()
    q = limits.project(q)
    q_seed = q
    far = _out_of_reach(robot, Tf, w_mask, limits, tol)
    if far.any():  # answered without iterating; the others solved as a batch of their own
        pe, re = _residuals(robot, q, Tf, w_mask)
        success, iters, used = np.zeros(B, dtype=bool), np.zeros(B, dtype=int), np.zeros(B, dtype=int)
        reason = np.full(B, "unreachable", dtype=object)
        near = np.flatnonzero(~far)
        if len(near):
            rest = solve_ik(robot, Tf[near], q[near], mask=mask, tol=tol, max_iterations=max_iterations,
                            restarts=restarts, respect_limits=respect_limits, rng=rng)
            q[near], success[near], pe[near], re[near] = rest.q, rest.success, rest.position_error, rest.orientation_error
            iters[near], used[near], reason[near] = rest.iterations, rest.restarts, rest.reason
        return _pack(batch, n, q, success, pe, re, iters, used, reason)
    if batch == ():  # one target: its first attempt in floats; the batched search below if that fails
        single = solve_single(robot, q[0], Tf[0], w, w_mask, limits, max_iterations, tol, L)
        if single is not None:
            return single
    rng = np.random.default_rng() if rng is None else rng
    with np.errstate(over="ignore", invalid="ignore"):  # targets ~1e300 m away (an unlimited prismatic joint)
        return _solve_batch(robot, batch, n, q, q_seed, Tf, w, w_mask, mask, limits, max_iterations, restarts,
                            respect_limits, tol, L, rng)


def _solve_batch(robot, batch, n, q, q_seed, Tf, w, w_mask, mask, limits, max_iterations, restarts, respect_limits,
                 tol, L, rng) -> IKResult:
    """The batched search of :func:`solve_ik`: LM with restarts, then the rescue, then the reasons.  Overflow on
    the way (a target 1e300 m away) makes non-finite steps, which fail the FK test like any bad step."""
    q, iters, n_restarts, stalled = _search(robot, q, Tf, w, limits, max_iterations, restarts, tol, L, rng)
    q = limits.project(q)
    pe, re = _residuals(robot, q, Tf, w_mask)
    success = (pe <= tol) & (re <= tol) & limits.inside(q)
    if restarts > 0 and not success.all():  # the few left: closed-form and bank seeds, polished by LM
        fail = np.flatnonzero(~success)
        def polish(q0, T, clip):
            return _search(robot, q0, T, w, limits, max_iterations, 0, tol, L, rng, clip)[0]

        polish.tol = tol
        q_new, used = rescue(robot, Tf[fail], q_seed[fail], w_mask, limits, L, polish)
        got = np.isfinite(q_new).all(axis=-1)  # the rescue's choice, checked here again by FK
        pe_n, re_n = _residuals(robot, q_new[got], Tf[fail[got]], w_mask)
        ok = (pe_n <= tol) & (re_n <= tol) & limits.inside(q_new[got])
        fix = fail[got][ok]
        q[fix], pe[fix], re[fix], success[fix] = q_new[got][ok], pe_n[ok], re_n[ok], True
        n_restarts[fail] += used
    reason = _reasons(robot, q, Tf, mask, success, stalled, tol, rng, respect_limits, max_iterations)
    return _pack(batch, n, q, success, pe, re, iters, n_restarts, reason)


def _reasons(robot, q, Tf, mask, success, stalled, tol, rng, respect_limits, max_iterations) -> np.ndarray:
    """Why each failed target failed (see :class:`IKResult`)."""
    reason = np.full(len(q), "", dtype=object)
    failed = np.flatnonzero(~success)
    if failed.size == 0:
        return reason
    reason[failed] = "unreachable"
    lim = limits_of(robot, False)
    restricts = not np.all(lim.full_turn | (np.isinf(lim.lo) & np.isinf(lim.hi)))
    # does a solution exist when the limits are ignored?  (Not asked when the limits allow every value: that
    # re-solve with restarts and the bank rescue cost ~0.1 s per failed target and could only blame the limits
    # for what the iterations did not reach — 50 s on 200 seeds at one singular pose of elbow-6r-deg.)
    if respect_limits and restricts:
        free = solve_ik(robot, Tf[failed], q[failed], mask=mask, tol=tol, max_iterations=max_iterations,
                        restarts=3, respect_limits=False, rng=rng)
        ok = np.atleast_1d(free.success)
        reason[failed[ok]] = "limits"
    still = failed[(reason[failed] == "unreachable") & ~stalled[failed]]
    reason[still] = "iterations"
    return reason


def _pack(batch, n, q, success, pe, re, iters, n_restarts, reason) -> IKResult:
    if batch == ():
        return IKResult(q[0], bool(success[0]), float(pe[0]), float(re[0]), int(iters[0]), int(n_restarts[0]),
                        str(reason[0]))
    return IKResult(q.reshape(batch + (n,)), success.reshape(batch), pe.reshape(batch), re.reshape(batch),
                    iters.reshape(batch), n_restarts.reshape(batch), reason.reshape(batch))
