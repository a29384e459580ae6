"""Every IK solution of a redundant arm as a function of one held ("free") joint, and where it is feasible.

A 7-joint arm reaches a pose along a one-parameter family (its self-motion).  Holding joint k at a value v leaves
a 6-joint arm that :func:`analytic_ik` solves completely (``locked=`` / ``free=``).  :func:`free_joint_sweep`
samples v densely over joint k's limits, solves at each sample, links the solutions of neighbouring samples into
branches (nearest joint vector, same branch label, at most ``LINK_RADIUS`` apart) and refines each branch's ends by
bisection to ``tol``.  The feasible set of v (at least one solution within every joint limit) is the union of the
branch intervals.

When the held joint is the first or the last joint, every sample is one target of one arm: with the rest of the
chain R(q'), ``FK(q', v) = FK(q', v0) · X(v)`` (last joint, ``X(v) = FK(z, v0)⁻¹ FK(z, v)`` for any z) and
``FK(v, q') = Y(v) · FK(v0, q')`` (first joint, ``Y(v) = FK(v, z) FK(v0, z)⁻¹``), so the arm held at v0 is solved
for the targets ``T X(v)⁻¹`` or ``Y(v)⁻¹ T`` in one batch.  A held middle joint changes the 6-joint arm itself:
one solve per value.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .._validate import as_transform
from ..errors import ModelError, UnsupportedRobotError
from ..model import DHRobot, JointType
from ..numeric import forward_kinematics
from ._analytic import analytic_ik
from ._cross import CROSS_SAMPLES, cross_joint, missed_values, split_unconfirmed, union_intervals
from ._margin import limit_values, without_limits

__all__ = [
    "DENSIFY",
    "LINK_RADIUS",
    "SAMPLES",
    "SWEEP_TOL",
    "FreeJointSweep",
    "SweepBranch",
    "default_free_joint",
    "free_joint_sweep",
]

SAMPLES = 256  #: default number of samples of the held joint over its limits
SWEEP_TOL = 1e-6  #: default bisection tolerance on the branch ends [rad, m]
DENSIFY = 8  #: a sample step where a branch starts or ends is cut into this many (once)
LINK_RADIUS = 0.5  #: largest joint change (max over joints, angles modulo 2π) that links two samples' solutions


@dataclass(frozen=True)
class SweepBranch:
    """One branch: a solution that moves continuously with the held joint, within every joint limit.

    Attributes
    ----------
    label : str
        The branch label of :func:`analytic_ik` (``""`` where the arm has none, e.g. general or mirrored arms).
    interval : (float, float)
        Held values [rad, m] from the first to the last one where the branch was confirmed (ends refined to tol).
    values : ndarray, shape (m,)
        The samples of the held joint on the branch (refined ends included).
    q : ndarray, shape (m, n)
        The solution at each of them (all n joints, the held one included).
    """

    label: str
    interval: tuple[float, float]
    values: np.ndarray
    q: np.ndarray


@dataclass(frozen=True)
class FreeJointSweep:
    """Result of :func:`free_joint_sweep`.

    Attributes
    ----------
    joint : str
        The held joint (``"q7"``).
    limits : (float, float)
        Its limit range, the swept range.
    values : ndarray, shape (S,)
        The samples of the held joint: ``samples`` evenly spaced, plus DENSIFY − 1 more in each step where a
        branch starts or ends, plus the held values of the cross-wise search's solutions found outside every
        branch (:mod:`denavit.ik._cross`) and, for a held end joint, the limit margin's (:mod:`denavit.ik._margin`).
    counts : ndarray of int, shape (S,)
        Solutions within the limits at each sample.
    branches : tuple of SweepBranch
    intervals : tuple of (float, float)
        The feasible set of the held joint: the union of the branch intervals, sorted.
    tol : float
        Bisection tolerance of the interval ends.
    method : str
        The route of the held arm (``analytic_ik(...).method``).
    cross : str
        The joint swept crosswise (:mod:`denavit.ik._cross`: pieces narrower than the sample step), ``""`` if none.
    """

    joint: str
    limits: tuple[float, float]
    values: np.ndarray
    counts: np.ndarray
    branches: tuple[SweepBranch, ...]
    intervals: tuple[tuple[float, float], ...]
    tol: float
    method: str
    cross: str = ""


def _sweep_range(robot: DHRobot, k: int) -> tuple[float, float]:
    """The range swept for joint k: its limits, or one turn [−π, π] for a revolute joint without them
    (:meth:`DHRobot.sampling_ranges`; a prismatic joint without limits is refused before)."""
    lo, hi = robot.sampling_ranges()[k]
    return float(lo), float(hi)


def _middle(robot: DHRobot) -> np.ndarray:
    """(n,) a configuration inside the limits: their middle, 0 for a joint without limits."""
    return robot.sampling_ranges().mean(axis=1)


def default_free_joint(robot: DHRobot) -> str:
    """The joint :func:`free_joint_sweep` holds by default.

    Rule: among the revolute joints whose holding leaves an arm with a closed form (not the general eigenvalue
    route, which is slower and less well conditioned near its double roots), the one with the widest limit range
    (its sweep covers most of the self-motion); on a tie the last such joint (an end joint also lets every sample
    be solved in one batch).  Panda: q7 (q5 and q7 tie at ±2.8973 rad).  Without such a joint: the last joint.
    A revolute joint without limits (Kinova Gen3's q1, q3, q5, q7) counts with its one turn, [−π, π].
    """
    best, width = f"q{robot.dof}", -1.0
    for k in range(robot.dof):
        if robot.joint_types[k] is not JointType.REVOLUTE:
            continue
        lo, hi = _sweep_range(robot, k)
        try:
            res = analytic_ik(robot, forward_kinematics(robot, _middle(robot)), locked={f"q{k + 1}": 0.5 * (lo + hi)})
        except UnsupportedRobotError:
            continue
        w = hi - lo
        if not res.method.startswith("general") and w >= width:
            best, width = f"q{k + 1}", w
    return best


class _Held:
    """Solves the arm with joint k held at many values: one batch (end joint) or one call per value."""

    def __init__(self, robot: DHRobot, T: np.ndarray, k: int) -> None:
        self.robot, self.T, self.k = robot, T, k
        lo, hi = _sweep_range(robot, k)
        self.v0 = 0.5 * (lo + hi)
        self.end = k in (0, robot.dof - 1)
        self.z = _middle(robot)  # any configuration: X(v), Y(v) do not depend on it
        self.method = ""

    def _targets(self, v: np.ndarray) -> np.ndarray:
        z = np.repeat(self.z[None], len(v), axis=0)
        zv = z.copy()
        zv[:, self.k] = v
        z[:, self.k] = self.v0
        F0, Fv = forward_kinematics(self.robot, z), forward_kinematics(self.robot, zv)  # (S, 4, 4)
        if self.k == self.robot.dof - 1:  # T X(v)⁻¹ with X(v) = FK(z, v0)⁻¹ FK(z, v)
            return self.T @ np.linalg.inv(np.linalg.inv(F0) @ Fv)
        return np.linalg.inv(Fv @ np.linalg.inv(F0)) @ self.T  # Y(v)⁻¹ T with Y(v) = FK(v, z) FK(v0, z)⁻¹

    def solve(self, v) -> tuple[np.ndarray, np.ndarray]:
        """Solutions (S, K, n) (NaN rows unused) and their labels (S, K) at the held values v (S,)."""
        v = np.asarray(v, dtype=float).reshape(-1)
        name = f"q{self.k + 1}"
        if self.end:
            res = analytic_ik(self.robot, self._targets(v), locked={name: self.v0})
            q, labels = np.array(res.solutions, dtype=float), np.asarray(res.branches, dtype=object)
            q[..., self.k] = np.where(np.isnan(q[..., self.k]), np.nan, v[:, None])
        else:
            per = [analytic_ik(self.robot, self.T, locked={name: float(x)}) for x in v]
            res = per[0] if per else None
            K = max([r.count for r in per] + [1])
            q = np.full((len(v), K, self.robot.dof), np.nan)
            labels = np.full((len(v), K), "", dtype=object)
            for i, r in enumerate(per):
                q[i, : r.count], labels[i, : r.count] = r.solutions, r.branches
        if res is not None:
            self.method = res.method
        return q, labels


def _distance(robot: DHRobot, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Largest joint difference between rows of a (A, n) and b (B, n) → (A, B); angles modulo 2π."""
    rev = np.array([t is JointType.REVOLUTE for t in robot.joint_types])
    d = np.abs(a[:, None, :] - b[None, :, :])
    d = np.where(rev, np.abs(d - 2 * np.pi * np.rint(d / (2 * np.pi))), d)
    return np.nan_to_num(d.max(axis=-1), nan=np.inf)


def _link(robot, qa, la, qb, lb) -> dict[int, int]:
    """Greedy matching of solutions a → b by distance (closest pairs first), same label, within LINK_RADIUS."""
    if len(qa) == 0 or len(qb) == 0:
        return {}
    D = _distance(robot, qa, qb)
    D[np.asarray(la, dtype=object)[:, None] != np.asarray(lb, dtype=object)[None, :]] = np.inf
    out, used = {}, set()
    for flat in np.argsort(D, axis=None):
        i, j = divmod(int(flat), D.shape[1])
        if not D[i, j] <= LINK_RADIUS:
            break
        if i not in out and j not in used:
            out[i] = j
            used.add(j)
    return out


def _branches(robot, values, q, labels) -> list[dict]:
    """Link the samples' solutions into branches: dicts with label, sample indices and joint vectors."""
    open_: list[dict] = []
    done: list[dict] = []
    for i in range(len(values)):
        ok = ~np.isnan(q[i]).any(axis=-1)
        qi, li = q[i][ok], labels[i][ok]
        last = np.array([b["q"][-1] for b in open_]).reshape(-1, robot.dof)
        match = _link(robot, last, [b["label"] for b in open_], qi, li)
        still = []
        for a, b in enumerate(open_):
            if a in match:
                b["idx"].append(i)
                b["q"].append(qi[match[a]])
                still.append(b)
            else:
                done.append(b)
        taken = set(match.values())
        still += [{"label": li[j], "idx": [i], "q": [qi[j]]} for j in range(len(qi)) if j not in taken]
        open_ = still
    return done + open_


def _refine(robot, held: _Held, ends: list[tuple[float, float, np.ndarray, str]], tol: float) -> list[tuple]:
    """Bisection of every branch end at once: (inside value, outside value, q at inside, label) → the last
    confirmed value and its solution, within tol of where the branch stops (ends to refine, batched per step).

    A midpoint whose solutions do not link to the last confirmed one is kept with them: next to a fold the joints
    move as fast as 1/√(distance), and a half step can exceed LINK_RADIUS while the branch runs on (a Panda end was
    4e-4 rad short).  A nearer midpoint confirmed, they are linked from it again (no extra solve)."""
    ends = [[*e, []] for e in ends]  # + the failed points (previous outside value, q, labels), innermost last
    while ends and max(abs(e[1] - e[0]) for e in ends) > tol:
        live = [e for e in ends if abs(e[1] - e[0]) > tol]
        mids = np.array([0.5 * (e[0] + e[1]) for e in live])
        q, labels = held.solve(mids)
        for e, qm, lm, m in zip(live, q, labels, mids):
            ok = ~np.isnan(qm).any(axis=-1)
            match = _link(robot, e[2][None], [e[3]], qm[ok], lm[ok])
            if not match:
                e[1], e[4] = float(m), e[4] + [(e[1], qm[ok], lm[ok])]
                continue
            e[0], e[2] = float(m), qm[ok][match[0]]
            while e[4] and (back := _link(robot, e[2][None], [e[3]], *e[4][-1][1:])):
                out, qf, _ = e[4].pop()
                e[0], e[1], e[2] = e[1], out, qf[back[0]]
    return [(e[0], e[2]) for e in ends]


def free_joint_sweep(robot: DHRobot, T, joint: str | None = None, *, samples: int = SAMPLES,
                     tol: float = SWEEP_TOL) -> FreeJointSweep:
    """Every IK solution of a redundant arm as a function of one held joint, over that joint's limits (one turn,
    [−π, π], for a revolute joint without limits).

    The held joint's range is sampled at ``samples`` evenly spaced values; at each, every solution within the
    limits comes from :func:`analytic_ik` with ``free={joint: value}``.  Solutions of neighbouring samples are
    linked into branches (closest pairs first, the same branch label, at most ``LINK_RADIUS`` apart in every
    joint) and each branch's ends that fall inside the range are refined by bisection until the last confirmed
    value is within ``tol`` of the first failing one.  A branch whose joints move more than LINK_RADIUS per step
    (next to a singularity) is split in two.

    Pieces narrower than the sample step: a second ("cross") joint is held at ``CROSS_SAMPLES`` values
    (:func:`denavit.ik._cross.cross_joint`: iiwa and Panda q5); the held-joint value of every solution found there
    that lies in no branch is added as a sample, and each linked step touching such a value is confirmed at its
    middle (else the branch is cut there).  A feasible piece is found when it spans more than one sample step of
    the held joint or one cross step of the cross joint.  For a held end joint, pieces cut out by the limits
    between two samples are also looked for along the branches of the arm without limits (:mod:`._margin`); other
    pieces narrow in both joints can still be missed.

    Parameters
    ----------
    robot : DHRobot
        A redundant arm whose held-joint arm has a closed form or goes the general 6R route (Panda, S-R-S arms).
    T : array_like, shape (4, 4)
        Target end-effector pose in the world frame.
    joint : str, optional
        ``"qK"``; default :func:`default_free_joint` (Panda: q7).
    samples : int
        Samples of the held joint (≥ 2).
    tol : float
        Bisection tolerance on the branch ends [rad, m].

    Returns
    -------
    FreeJointSweep

    Examples
    --------
    >>> import numpy as np, denavit
    >>> panda = denavit.load_robot("panda")
    >>> q = np.array([0.2, -0.3, 0.1, -2.0, 0.3, 1.6, 0.5])
    >>> sweep = denavit.free_joint_sweep(panda, denavit.forward_kinematics(panda, q), "q7", samples=64)
    >>> any(lo <= 0.5 <= hi for lo, hi in sweep.intervals)
    True
    """
    T = as_transform(T, "T")
    if T.shape != (4, 4):
        raise ModelError(f"free_joint_sweep: one target pose (4, 4), got shape {T.shape}")
    joint = default_free_joint(robot) if joint is None else joint
    k = int(joint[1:]) - 1 if isinstance(joint, str) and joint[:1] == "q" and joint[1:].isdigit() else -1
    if not 0 <= k < robot.dof:
        raise ModelError(f"free_joint_sweep: {joint!r} is not a joint of {robot.name} (q1 … q{robot.dof})")
    if robot.joint_types[k] is not JointType.REVOLUTE and not np.all(np.isfinite(robot.q_limits[k])):
        raise ModelError(f"free_joint_sweep: {joint} has no finite limits to sweep")
    lo, hi = _sweep_range(robot, k)
    if not (isinstance(samples, (int, np.integer)) and samples >= 2):
        raise ModelError(f"free_joint_sweep: samples must be an integer ≥ 2, got {samples!r}")
    if not (np.isfinite(tol) and tol > 0):
        raise ModelError(f"free_joint_sweep: tol must be a positive number, got {tol!r}")
    held = _Held(robot, T, k)
    values, q, labels, raw = _densified(robot, held, np.linspace(lo, hi, int(samples)))
    values, q, _, raw, cross = _crossed(robot, held, values, q, labels, raw)
    counts = (~np.isnan(q).any(axis=-1)).sum(axis=-1)
    branches = _assemble(robot, held, values, raw, tol)
    branches.sort(key=lambda b: (b.interval, b.label))
    return FreeJointSweep(joint, (lo, hi), values, counts, tuple(branches),
                          union_intervals((b.interval for b in branches), 2 * tol), float(tol), held.method, cross)


def _densified(robot: DHRobot, held: _Held, values: np.ndarray):
    """Solve at the samples, link; then, once, each sample step where a branch starts or ends gets DENSIFY − 1
    more samples (a branch living between two samples, next to a fold or a limit, is found there) and the whole
    set is linked again.  Returns values (S',), q (S', K, n), labels (S', K) and the linked branches."""
    q, labels = held.solve(values)
    raw = _branches(robot, values, q, labels)
    last = len(values) - 1
    steps = sorted({b["idx"][-1] for b in raw if b["idx"][-1] < last} | {b["idx"][0] - 1 for b in raw if b["idx"][0] > 0})
    if not steps:
        return values, q, labels, raw
    frac = np.arange(1, DENSIFY) / DENSIFY
    extra = (values[steps, None] + (values[np.array(steps) + 1, None] - values[steps, None]) * frac).ravel()
    return _merged(robot, held, values, q, labels, extra)


def _merged(robot: DHRobot, held: _Held, values: np.ndarray, q: np.ndarray, labels: np.ndarray, extra: np.ndarray):
    """The samples with ``extra`` held values solved and added (sorted), and the whole set linked again."""
    q2, l2 = held.solve(extra)
    K = max(q.shape[1], q2.shape[1])
    pad = lambda a, fill: np.concatenate(
        [a, np.full(a.shape[:1] + (K - a.shape[1],) + a.shape[2:], fill, dtype=a.dtype)], axis=1)
    order = np.argsort(np.r_[values, extra], kind="stable")
    values = np.r_[values, extra][order]
    q = np.concatenate([pad(q, np.nan), pad(q2, np.nan)])[order]
    labels = np.concatenate([pad(labels, ""), pad(l2, "")])[order]
    return values, q, labels, _branches(robot, values, q, labels)


def _crossed(robot: DHRobot, held: _Held, values, q, labels, raw):
    """Pieces between samples: held values found by the cross-wise search (:mod:`._cross`) outside every branch and,
    for a held end joint, by the limit margin (:mod:`._margin`) are added as samples; the set is linked again and
    every linked step touching an added value confirmed at its middle."""
    c = cross_joint(robot, held.k)
    extra = np.zeros(0)
    if c is not None:
        qc, _ = _Held(robot, held.T, c).solve(np.linspace(*_sweep_range(robot, c), CROSS_SAMPLES))
        extra = missed_values(values, [(values[b["idx"][0]], values[b["idx"][-1]]) for b in raw], qc[..., held.k])
    if held.end:
        found = limit_values(robot, values, _Held(without_limits(robot), held.T, held.k).solve,
                             lambda *a: _link(robot, *a))
        extra = np.union1d(extra, found[~np.isin(found, values)])
    if len(extra):
        values, q, labels, raw = _merged(robot, held, values, q, labels, extra)
        raw = split_unconfirmed(raw, values, np.isin(values, extra), held.solve, lambda *a: _link(robot, *a))
    return values, q, labels, raw, "" if c is None else f"q{c + 1}"


def _assemble(robot: DHRobot, held: _Held, values: np.ndarray, raw: list[dict], tol: float) -> list[SweepBranch]:
    """The linked samples as SweepBranch values, each end inside the range refined by bisection (all at once)."""
    ends = []  # (inside, outside, q, label) for every end strictly inside the range
    for b in raw:
        i0, i1 = b["idx"][0], b["idx"][-1]
        if i0 > 0:
            ends.append((values[i0], values[i0 - 1], b["q"][0], b["label"]))
        if i1 < len(values) - 1:
            ends.append((values[i1], values[i1 + 1], b["q"][-1], b["label"]))
    refined = iter(_refine(robot, held, ends, tol))
    branches = []
    for b in raw:
        i0, i1 = b["idx"][0], b["idx"][-1]
        vs, qs = list(values[b["idx"]]), list(b["q"])
        if i0 > 0:
            v, qq = next(refined)
            vs, qs = [v] + vs, [qq] + qs
        if i1 < len(values) - 1:
            v, qq = next(refined)
            vs, qs = vs + [v], qs + [qq]
        vs, qs = np.array(vs), np.array(qs)
        keep = np.r_[True, np.diff(vs) > 0]  # a refined end equal to its sample is not listed twice
        branches.append(SweepBranch(str(b["label"]), (float(vs[0]), float(vs[-1])), vs[keep], qs[keep]))
    return branches

