"""The cross-wise search of :func:`free_joint_sweep`: feasible pieces of the held joint narrower than its sample step.

A redundant arm's self-motion at a pose is a curve in joint space; sweeping held joint k samples it by the value
of q_k.  A piece of it whose q_k extent is narrower than the sample step (an S-R-S arm with its elbow nearly
straight: the whole self-motion then spans about |q4| of q7, while q3 and q5 turn a full turn together; a curve cut
short by two joint limits) can fall between two samples and be missed.  The same curve is also sampled by a second
("cross") joint c: every solution of the arm with c held at each of ``CROSS_SAMPLES`` values lies on the curve,
and its q_k is a feasible value of the held joint.  A value outside every branch the sweep found is added to the
sweep's samples, whose branch ends are then refined by bisection.

Stated criterion: a feasible piece is found when its extent exceeds one sample step in q_k or one cross step in
q_c (the cross joint's range over CROSS_SAMPLES − 1), and the solutions at the cross samples reach it.  Pieces
narrow in both joints can still be missed.
"""

from __future__ import annotations

from itertools import pairwise

import numpy as np

from ..errors import UnsupportedRobotError
from ..model import DHRobot, JointType
from ..numeric import forward_kinematics
from ._analytic import analytic_ik

__all__ = ["union_intervals", "CROSS_SAMPLES", "cross_joint", "missed_values", "split_unconfirmed"]

CROSS_SAMPLES = 48  #: samples of the cross joint over its range


def cross_joint(robot: DHRobot, k: int) -> int | None:
    """The joint swept crosswise to held joint k (index), or None.

    Rule: among the revolute joints other than k whose holding leaves a closed form (not the general route), the
    one with the widest range (one turn for a joint without limits); on a tie the nearest to the middle joint
    (index dof // 2: an S-R-S arm's q3 or q5, which turn a full turn when the elbow is nearly straight), then the
    later one.  Panda with q7 held: q5; iiwa: q5; Gen3 with q3 held: q1 (q5 and q7 leave the general route).
    """
    ranges = robot.sampling_ranges()
    mid = ranges.mean(axis=1)
    order = sorted((j for j in range(robot.dof) if j != k and robot.joint_types[j] is JointType.REVOLUTE),
                   key=lambda j: (-(ranges[j, 1] - ranges[j, 0]), abs(j - robot.dof // 2), -j))
    T = forward_kinematics(robot, mid)
    for j in order:
        try:
            res = analytic_ik(robot, T, locked={f"q{j + 1}": float(mid[j])})
        except UnsupportedRobotError:
            continue
        if not res.method.startswith("general"):
            return j
    return None


def missed_values(values: np.ndarray, spans: list[tuple[float, float]], held: np.ndarray) -> np.ndarray:
    """Held values of cross solutions that lie in no branch's sample span and on no sample, sorted, distinct.

    values (S,) the sweep's sorted samples; spans the (first, last) sample of each branch; held (C, K) the held
    joint's value in each cross solution (NaN: unused slot).  All are kept: along a piece that turns the other
    joints fast (a nearly straight elbow), the cross samples are the steps at which its solutions still link.
    """
    v = held[~np.isnan(held)]
    if len(spans):
        sp = np.array(spans)
        v = v[~((v[:, None] >= sp[None, :, 0]) & (v[:, None] <= sp[None, :, 1])).any(axis=1)]
    v = np.unique(v[(v > values[0]) & (v < values[-1])])  # the range's ends are samples: nothing beyond them
    v = v[np.r_[True, np.diff(v) > 1e-12]] if len(v) else v
    step = np.searchsorted(values, v)
    return v[np.minimum(v - values[step - 1], values[step] - v) > 1e-12] if len(v) else v


def split_unconfirmed(raw: list[dict], values: np.ndarray, new: np.ndarray, solve, link) -> list[dict]:
    """Branches cut where a step touching an added value is not confirmed at its middle.

    Linking two samples' solutions (at most LINK_RADIUS apart) assumes the branch runs through the step between
    them; next to a fold or a limit two distinct pieces can come that close (a nearly straight elbow: the two
    signs of q4 meet at a limit of q5).  Every linked step with an added value (``new``, bool (S,)) at either end is
    solved at its middle: without a solution linked to both ends, the branch is cut there (its two new ends are
    then refined by bisection like any other).  ``solve(v)`` → (q, labels) as ``_Held.solve``; ``link`` as
    ``_link``.
    """
    steps = [(b, p) for b in raw for p in range(len(b["idx"]) - 1) if new[b["idx"][p]] or new[b["idx"][p + 1]]]
    if not steps:
        return raw
    pairs = sorted({(b["idx"][p], b["idx"][p + 1]) for b, p in steps})  # one solve per step, shared by branches
    q, labels = solve(np.array([0.5 * (values[i] + values[j]) for i, j in pairs]))
    at = {pair: n for n, pair in enumerate(pairs)}
    cuts: dict[int, list[int]] = {}
    for b, p in steps:
        n = at[(b["idx"][p], b["idx"][p + 1])]
        qm, lm = q[n], labels[n]
        ok = ~np.isnan(qm).any(axis=-1)
        ends = np.array([b["q"][p], b["q"][p + 1]])
        m = link(ends, [b["label"]] * 2, qm[ok], lm[ok])
        if not (0 in m and 1 in m and m[0] == m[1]) and not _one_near(ends, qm[ok], lm[ok], b["label"], link):
            cuts.setdefault(id(b), []).append(p + 1)
    out = []
    for b in raw:
        at = [0] + cuts.get(id(b), []) + [len(b["idx"])]
        out += [{"label": b["label"], "idx": b["idx"][s:e], "q": b["q"][s:e]} for s, e in pairwise(at)]
    return out


def _one_near(ends, qm, lm, label, link) -> bool:
    """One middle solution linked to each end on its own (the greedy matching of both at once may pair them
    with two different, nearby solutions)."""
    a, b = link(ends[:1], [label], qm, lm), link(ends[1:], [label], qm, lm)
    return bool(a) and bool(b) and a[0] == b[0]


def union_intervals(intervals, gap: float) -> tuple[tuple[float, float], ...]:
    """Sorted union; pieces less than ``gap`` apart are one (a branch split where its joints jump leaves its two
    refined ends up to 2·tol apart with solutions in between: a gap that narrow is not resolved)."""
    out: list[list[float]] = []
    for a, b in sorted(intervals):
        if out and a <= out[-1][1] + gap:
            out[-1][1] = max(out[-1][1], b)
        else:
            out.append([a, b])
    return tuple((float(a), float(b)) for a, b in out)
