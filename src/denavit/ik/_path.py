"""Inverse kinematics along a path: the joint trajectory that stays on one branch, and where that branch ends.

For poses T_0 … T_{m−1} the trajectory continues a branch pose by pose.  At pose i the closed-form solutions
(:func:`analytic_ik`) are the candidates; the one chosen has the branch label of the previous q and is nearest
to it (revolute angles compared modulo 2π).  A step is accepted when it is continuous — no larger than twice
what the first-order model implies,

.. math:: \\|\\Delta q\\|_\\infty \\le 2\\,\\|J^{+}(q_{i-1})\\, \\Delta x\\|_\\infty + \\epsilon, \\qquad
          \\Delta x = (p_i - p_{i-1},\\ \\log(R_i R_{i-1}^T))

(J the base Jacobian J0, rows (v, ω); Siciliano et al. 2009, Sec. 3.5, (3.47) for the pseudo-inverse) — and no
larger than ``max_step``.  Otherwise the Cartesian segment is halved (poses interpolated as in
:func:`cartesian_line`), at most :data:`MAX_HALVINGS` times.  Where the closed form has no answer (arms without
one, or a continuum) the numeric solver is seeded at the previous q without restarts.  The branch ends at:

- ``"singularity"``: σ_min/σ_max of J (translation rows divided by the arm's characteristic length L) below
  :data:`SINGULAR_RTOL`, or the branch cannot be continued within the step bound after every halving while
  another branch can (branches merge there);
- ``"joint limit"``: the pose has solutions only outside the joint limits, or the nearest continuation lies
  outside them;
- ``"workspace boundary"``: no solution at all, even outside the limits;
- ``"step bound"``: ``max_step`` cannot be met after every halving;
- ``"no convergence"`` (numeric route only): the solver seeded at the previous q ran out of iterations.

Redundant arms (more than 6 joints) hold one joint (``hold``, default the last one) at q0's value — the
null-space motion chosen is "that joint does not move"; the other joints follow the rules above.  With
``redundancy="nearest"`` every pose is solved numerically from the previous q instead (least joint motion).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .._validate import as_joint_array, as_transform
from ..errors import ModelError, UnsupportedRobotError
from ..model import DHRobot, JointType
from ..numeric import forward_kinematics, geometric_jacobian
from ._analytic import analytic_ik
from ._line import interpolate_pose
from ._numeric import solve_ik
from ._residual import characteristic_length, pose_error

__all__ = [
    "MAX_HALVINGS",
    "SINGULAR_RTOL",
    "STEP_FACTOR",
    "PathResult",
    "PathTrajectory",
    "ik_path",
]

#: σ_min/σ_max of the scaled Jacobian below which a configuration counts as singular (the branch ends there).
SINGULAR_RTOL = 1e-4
#: Most halvings of one Cartesian segment (so at most 2**MAX_HALVINGS − 1 inserted poses per segment).
MAX_HALVINGS = 8
#: A step may be this many times what J⁺·Δx implies.
STEP_FACTOR = 2.0
_STEP_ATOL = 1e-9  # [rad, m]: steps of (nearly) repeated poses
_FK_TOL = 1e-8  # numeric refinement tolerance [m, rad]


@dataclass(frozen=True)
class PathTrajectory:
    """One joint trajectory along a path.

    Attributes
    ----------
    q : ndarray, shape (k, n)
        Joint values [rad, m] at every sample, inserted ones included.
    s : ndarray, shape (k,)
        Path parameter of each sample: pose index, fractional for inserted poses.
    reached : int
        Index of the last pose reached (−1 when not even the first).
    branch : str
        Branch label (``""`` for arms without labels).
    status : str
        ``"complete"`` or ``"stopped"``.
    stop_index : int or None
        The pose that could not be reached.
    reason : str
        ``""``, or why: ``"singularity"``, ``"joint limit"``, ``"workspace boundary"``, ``"step bound"``, with
        details after a colon.
    labels : tuple of str (k,)
        The branch label of each sample: ``branch`` throughout, except where a label's test changes sign away
        from any singular set (see :func:`_switch`): the configuration continues, its label changes.
    """

    q: np.ndarray
    s: np.ndarray
    reached: int
    branch: str
    status: str
    stop_index: int | None
    reason: str
    labels: tuple = ()


@dataclass(frozen=True)
class PathResult:
    """Result of :func:`ik_path`: one trajectory per branch followed, the poses, and the held joint."""

    trajectories: tuple[PathTrajectory, ...]
    poses: np.ndarray
    held: str

    @property
    def complete(self) -> tuple[PathTrajectory, ...]:
        return tuple(t for t in self.trajectories if t.status == "complete")


class _Context:
    """The arm, its held joint and how one pose is solved (read-only after construction)."""

    def __init__(self, robot: DHRobot, q0, hold: str | None, max_step: float | None, redundancy: str = "hold"):
        n = robot.dof
        self.robot, self.n, self.max_step = robot, n, max_step
        self.rev = np.array([t is JointType.REVOLUTE for t in robot.joint_types])
        self.L = characteristic_length(robot)
        self.lo, self.hi = robot.q_limits[:, 0], robot.q_limits[:, 1]
        if redundancy not in ("hold", "nearest"):
            raise ModelError(f"redundancy: {redundancy!r}; choose 'hold' or 'nearest'")
        self.locked, self.free = None, np.arange(n)
        if redundancy == "nearest" and hold is None and n > 6:  # LM from the previous q: no closed form
            self.analytic = False
            return
        if hold is None and n > 6:
            hold = f"q{n}"
        if hold is not None:
            k = int(hold[1:]) - 1 if hold[:1] == "q" and hold[1:].isdigit() else -1
            if not 0 <= k < n:
                raise ModelError(f"hold: {hold!r} is not a joint of {robot.name} (q1 … q{n})")
            mid = float(robot.sampling_ranges()[k].mean())  # the middle of its limits, 0 without
            self.locked = {hold: float(q0[k]) if q0 is not None else mid}
            self.free = np.delete(np.arange(n), k)
        try:
            analytic_ik(robot, forward_kinematics(robot, np.zeros(n) if q0 is None else q0), locked=self.locked)
            self.analytic = True
        except UnsupportedRobotError:
            if self.locked is not None:
                raise
            self.analytic = False

    def solve(self, T: np.ndarray):
        """Candidates of poses T (4, 4) or (m, 4, 4): (solutions (k, n), labels), or a list of them per pose."""
        none = (np.zeros((0, self.n)), ())
        if not self.analytic:
            return [none] * len(T) if T.ndim == 3 else none
        res = analytic_ik(self.robot, T, locked=self.locked)
        if T.ndim == 2:
            return res.solutions, tuple(res.branches)
        return [(res.solutions[i][res.valid[i]], tuple(res.branches[i][res.valid[i]])) for i in range(len(T))]

    def diff(self, q: np.ndarray, ref: np.ndarray) -> np.ndarray:
        """q − ref with revolute differences wrapped into (−π, π]."""
        d = q - ref
        return np.where(self.rev, np.pi - np.mod(np.pi - d, 2 * np.pi), d)

    def jacobian(self, q: np.ndarray) -> np.ndarray:
        return geometric_jacobian(self.robot, q)[:, self.free]  # (6, n_free): the held joint does not move

    def sigma_ratio(self, q: np.ndarray) -> float:
        J = self.jacobian(q) * np.array([1 / self.L] * 3 + [1.0] * 3)[:, None]  # rows made dimensionless
        s = np.linalg.svd(J, compute_uv=False)
        return float(s[-1] / s[0]) if s[0] > 0 else 0.0

    def bound(self, q: np.ndarray, Ta: np.ndarray, Tb: np.ndarray) -> float:
        """STEP_FACTOR · |J⁺(q) Δx|_∞ + ε with Δx = pose_error(Tb, Ta) (world axes, rows (v, ω))."""
        dq = np.linalg.lstsq(self.jacobian(q), pose_error(Tb, Ta), rcond=None)[0]
        return STEP_FACTOR * float(np.max(np.abs(dq), initial=0.0)) + _STEP_ATOL

    def numeric(self, q: np.ndarray, T: np.ndarray):
        """LM seeded at q, no restarts: (the solution continued from q, "") or (None, solve_ik's reason)."""
        res = solve_ik(self.robot, T, q, restarts=0, tol=_FK_TOL)
        return (q + self.diff(res.q, q), "") if res.success else (None, str(res.reason))


def _step(ctx: _Context, q, label, Ta, Tb, cand):
    """One step from q (at Ta) to Tb: (q_new, None, "") or (None, kind, detail); kind "continuity" or "max step"
    may be cured by halving the segment, the others end the branch."""
    sols, labels = ctx.solve(Tb) if cand is None else cand
    bound = ctx.bound(q, Ta, Tb)
    if ctx.analytic:
        same = [k for k, b in enumerate(labels) if b == label]
        step = np.inf
        if same:
            d = ctx.diff(sols[same], q)
            k = int(np.argmin(np.max(np.abs(d), axis=1)))
            q_new, step = q + d[k], float(np.max(np.abs(d[k]), initial=0.0))
            if not np.all((q_new >= ctx.lo - 1e-12) & (q_new <= ctx.hi + 1e-12)):
                q_new = sols[same][k]  # the unwrapped value leaves the limits: the folded one (same configuration)
        if step > bound:  # is the continuation there, but outside the limits? (the only case called a limit)
            out = np.reshape(analytic_ik(ctx.robot, Tb, locked=ctx.locked).outside_limits, (-1, ctx.n))
            if len(out) and np.min(np.max(np.abs(ctx.diff(out, q)), axis=1)) <= bound:
                return None, "joint limit", "the branch's continuation lies outside the joint limits"
            if not len(sols) and not len(out):
                return None, "workspace boundary", "no solution at this pose"
            if not same:
                return None, "continuity", "the branch has no solution here"
    else:
        q_new, why = ctx.numeric(q, Tb)
        if q_new is None:  # solve_ik's reasons: "limits" (a solution only outside them), "unreachable", "iterations"
            kind = {"limits": "joint limit", "unreachable": "workspace boundary"}.get(why, "no convergence")
            return None, kind, f"the numeric solver seeded at the previous q found no solution ({why})"
        step = float(np.max(np.abs(ctx.diff(q_new, q)), initial=0.0))
    if step > bound:
        return None, "continuity", f"step {step:.3g} > {bound:.3g} = {STEP_FACTOR:g}·|J⁺Δx|"
    if ctx.max_step is not None and step > ctx.max_step:
        return None, "max step", f"step {step:.3g} rad > max_step {ctx.max_step:g}"
    ratio = ctx.sigma_ratio(q_new)
    if ratio < SINGULAR_RTOL:
        return None, "singularity", f"σ_min/σ_max = {ratio:.2g} < {SINGULAR_RTOL:g}"
    return q_new, None, ""


def _segment(ctx, q, label, Ta, Tb, cand, depth=0):
    """Samples [(t, q, label)] (t in (0, 1]) from q at Ta to Tb, halving where a step is too large; and why it
    stopped (None, or (kind, detail))."""
    q_new, kind, detail = _step(ctx, q, label, Ta, Tb, cand)
    if kind is None:
        return [(1.0, q_new, label)], None
    if kind not in ("continuity", "max step"):
        return [], (kind, detail)
    if depth >= MAX_HALVINGS:
        switch = _switch(ctx, q, label, Ta, Tb, cand) if kind == "continuity" else None
        return ([(1.0, *switch)], None) if switch else ([], _verdict(ctx, q, label, Tb, kind, detail, cand))
    Tm = interpolate_pose(Ta, Tb, np.array(0.5))
    left, why = _segment(ctx, q, label, Ta, Tm, None, depth + 1)
    left = [(0.5 * t, x, b) for t, x, b in left]
    if why is not None:
        return left, why
    right, why = _segment(ctx, left[-1][1], left[-1][2], Tm, Tb, cand, depth + 1)
    return left + [(0.5 + 0.5 * t, x, b) for t, x, b in right], why


def _switch(ctx, q, label, Ta, Tb, cand):
    """After every halving: a solution of another label that continues q within the step bound, when no singular
    configuration lies between them — a label's test changing sign away from a singular set (the labels are
    tests of q, docs/ik.md), not a branch ending.  σ_min/σ_max is checked at 9 points of the joint-space step:
    a true crossing of a singular set (the Puma's q5 = 0) passes through it.  (q_new, label) or None."""
    if not ctx.analytic:
        return None
    sols, labels = ctx.solve(Tb) if cand is None else cand
    other = [k for k, b in enumerate(labels) if b != label]
    if not other:
        return None
    d = ctx.diff(sols[other], q)
    step = np.max(np.abs(d), axis=1)
    k = int(np.argmin(step))
    if step[k] > ctx.bound(q, Ta, Tb) or (ctx.max_step is not None and step[k] > ctx.max_step):
        return None
    if min(ctx.sigma_ratio(q + t * d[k]) for t in np.linspace(0.0, 1.0, 9)) < SINGULAR_RTOL:
        return None
    q_new = q + d[k]
    if not np.all((q_new >= ctx.lo - 1e-12) & (q_new <= ctx.hi + 1e-12)):
        q_new = sols[other][k]
    return q_new, labels[other[k]]


def _verdict(ctx, q, label, Tb, kind, detail, cand):
    """Why a step still fails after every halving: a step bound, a joint limit, or a singularity."""
    if kind == "max step":
        return "step bound", f"{detail} after {MAX_HALVINGS} halvings"
    labels = (ctx.solve(Tb) if cand is None else cand)[1]
    ratio = ctx.sigma_ratio(q)
    if ctx.analytic and label not in labels:  # its sheet of solutions ends (e.g. an elbow fold at full reach)
        return "workspace boundary", (f"branch {label!r} has no solution beyond here ({MAX_HALVINGS} halvings; "
                                      f"σ_min/σ_max = {ratio:.2g} at the last sample)")
    others = sorted({b for b in labels if b != label})
    meet = f"; it meets {', '.join(repr(b) for b in others)}" if others else ""
    return "singularity", (f"branch {label!r} cannot be continued ({detail} after {MAX_HALVINGS} halvings; "
                           f"σ_min/σ_max = {ratio:.2g} at the last sample{meet})")


def _follow(ctx: _Context, poses: np.ndarray, cands, q_start: np.ndarray, label: str) -> PathTrajectory:
    """The trajectory from q_start (a solution of pose 0) along every following pose, until the branch ends."""
    qs, ss, ls = [q_start], [0.0], [label]  # the start is a solution even when singular: steps away are judged
    for i in range(1, len(poses)):
        samples, why = _segment(ctx, qs[-1], ls[-1], poses[i - 1], poses[i], cands[i])
        qs += [x for _, x, _ in samples]
        ss += [i - 1 + t for t, _, _ in samples]
        ls += [b for _, _, b in samples]
        if why is not None:
            held = "".join(f" ({k} held at {v:.6g})" for k, v in (ctx.locked or {}).items())
            return PathTrajectory(np.array(qs), np.array(ss), i - 1, label, "stopped", i, f"{why[0]}: {why[1]}{held}",
                                  tuple(ls))
    return PathTrajectory(np.array(qs), np.array(ss), len(poses) - 1, label, "complete", None, "", tuple(ls))


def ik_path(robot: DHRobot, poses, q0=None, *, hold: str | None = None, max_step: float | None = None,
            redundancy: str = "hold") -> PathResult:
    """Joint trajectories along a sequence of poses, each staying on one IK branch (module notes: the rules).

    Parameters
    ----------
    robot : DHRobot
    poses : array_like, shape (m, 4, 4)
        End-effector poses in the world frame, in path order (e.g. from :func:`cartesian_line`).
    q0 : array_like, shape (n,), optional
        The configuration to continue: the trajectory starts at pose 0's solution nearest to q0 and keeps its
        branch.  Without it, one trajectory per solution of pose 0.
    hold : str, optional
        Redundant arms: the joint held at q0's value (default the last joint; the middle of its limits when q0
        is None).  The held joint never moves: that is the null-space motion chosen.
    redundancy : {"hold", "nearest"}
        Redundant arms: ``"hold"`` one joint (above), every closed-form solution of the rest; ``"nearest"``: the
        numeric solver (Levenberg–Marquardt, no restarts) seeded at the previous q for every pose — its damped
        least-squares steps are the least joint motion that reduces the pose error, so the self-motion is not
        driven and the trajectory stays near the previous q (one trajectory, no labels).
    max_step : float, optional
        Largest joint step between samples [rad, m]; segments are halved (poses inserted) to respect it, at
        most :data:`MAX_HALVINGS` times, else the trajectory stops with ``"step bound"``.

    Returns
    -------
    PathResult
        Stopped trajectories name the pose they could not reach and why (not an exception).

    Examples
    --------
    >>> import numpy as np, denavit
    >>> robot = denavit.load_robot("puma560")
    >>> q0 = np.array([0.1, 0.4, -0.5, 0.3, 0.8, 0.2])
    >>> T0 = denavit.forward_kinematics(robot, q0)
    >>> T1 = T0.copy(); T1[:3, 3] += [0.0, 0.1, -0.05]
    >>> path = denavit.ik_path(robot, denavit.cartesian_line(T0, T1, step=0.01), q0)
    >>> t = path.trajectories[0]
    >>> t.status, bool(np.allclose(t.q[0], q0))
    ('complete', True)
    """
    T = as_transform(poses, "poses")
    if T.ndim != 3 or len(T) == 0:
        raise ModelError(f"poses: expected shape (m, 4, 4) with m ≥ 1, got {T.shape}")
    if max_step is not None and not (np.isfinite(max_step) and max_step > 0):
        raise ModelError(f"max_step must be a finite number > 0, got {max_step!r}")
    if q0 is not None:
        q0 = as_joint_array(q0, robot.dof, "q0")
        if q0.ndim != 1:
            raise ModelError(f"q0: expected one configuration of shape ({robot.dof},), got {q0.shape}")
    ctx = _Context(robot, q0, hold, max_step, redundancy)
    cands = ctx.solve(T)
    held = next(iter(ctx.locked), "") if ctx.locked else ""
    sols, labels = _starts(ctx, T[0], cands[0], q0)
    if not len(sols):
        out = np.size(analytic_ik(robot, T[0], locked=ctx.locked).outside_limits) if ctx.analytic else 0
        why = ("joint limit: pose 0 has solutions only outside the joint limits" if out else
               "workspace boundary: no solution at pose 0")
        empty = PathTrajectory(np.zeros((0, robot.dof)), np.zeros(0), -1, "", "stopped", 0, why, ())
        return PathResult((empty,), T, held)
    return PathResult(tuple(_follow(ctx, T, cands, s, b) for s, b in zip(sols, labels)), T, held)


def _starts(ctx: _Context, T0: np.ndarray, cand, q0):
    """Where the trajectories start: pose 0's solution nearest to q0 (q0's own turn of each angle when that stays
    within the limits), or every solution of pose 0; the numeric route: LM from q0 (or zero)."""
    sols, labels = cand
    if not ctx.analytic:
        start = ctx.numeric(np.zeros(ctx.n) if q0 is None else q0, T0)[0]
        sols, labels = (np.zeros((0, ctx.n)), ()) if start is None else (start[None], ("",))
    if q0 is not None and len(sols):
        d = ctx.diff(sols, q0)
        k = int(np.argmin(np.max(np.abs(d), axis=1)))
        start = q0 + d[k]
        inside = np.all((start >= ctx.lo - 1e-12) & (start <= ctx.hi + 1e-12))
        sols, labels = (start if inside else sols[k])[None], labels[k:k + 1]
    return sols, labels
