"""Feasible pieces of a free-joint sweep cut out by the joint limits between two samples: the limit margin.

Without its limits, an arm's solutions with joint k held at v move continuously along branches; with them, a
branch is feasible where its limit margin m(v) = min_j (distance of q_j(v) inside [lo_j, hi_j]) is ≥ 0 (a revolute
angle by its best whole-turn representative).  A branch that is just outside a limit at two neighbouring samples
may come inside between them (two joints near opposite limits: a piece 0.01 rad wide).  m is 1-Lipschitz in the
joints: joint j's margin m_j changes at most as fast as q_j, so over a step where q_j changes by D_j (the linked
solutions at its ends) m stays below min_j ((m_j,a + m_j,b)/2 + D_j) when every joint moves at most twice its
mean speed over the step.  Every step of a branch
without limits whose bound reaches 0 is cut into SPLIT sub-steps (solved, linked from its start) and the test
repeated on them, ROUNDS times at most; a sub-sample with m ≥ 0 is a feasible held value, added to the sweep.
A step where the branch without limits ends (it meets another and vanishes: a fold between the samples, where
the joints' speed has no bound) is subdivided whenever m < 0 at its other end.

Stated criterion: a piece cut out by the limits is found when, along its branch, the joints move at most twice
their mean speed over each (sub-)step the branch runs through, and it is wider than the step after ROUNDS
subdivisions
(range / (samples − 1) / SPLIT^ROUNDS: 2.4e-5 rad for iiwa7's q7 at 64 samples).
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from ..model import DHRobot, JointType

__all__ = ["ROUNDS", "SPLIT", "limit_values", "margin", "without_limits"]

SPLIT = 4  #: a step whose bound reaches 0 is cut into this many
ROUNDS = 6  #: subdivisions at most
MAX_STEPS = 256  #: steps refined at most per round (the least margin bound first)


def without_limits(robot: DHRobot) -> DHRobot:
    """The same arm with every joint limit removed (its solutions then come back for every pose it reaches)."""
    return replace(robot, links=tuple(replace(link, q_limits=None) if link.joint is not JointType.FIXED else link
                                      for link in robot.links))


def margin(robot: DHRobot, q: np.ndarray, per_joint: bool = False) -> np.ndarray:
    """Limit margin of each row of q (..., n) for ``robot``'s limits: min over joints of min(q − lo, hi − q),
    a revolute angle taken at its best whole-turn shift; −inf for NaN rows, +inf for a joint without limits.
    ``per_joint``: the (..., n) margins of the joints before the min."""
    lo, hi = robot.q_limits[:, 0], robot.q_limits[:, 1]
    rev = np.array([t is JointType.REVOLUTE for t in robot.joint_types])
    shifts = np.where(rev, 2 * np.pi, 0.0)[:, None] * np.array([-1.0, 0.0, 1.0])  # (n, 3)
    x = q[..., None] + shifts  # (..., n, 3)
    with np.errstate(invalid="ignore"):
        m = np.minimum(x - lo[:, None], hi[:, None] - x).max(axis=-1)
    m = np.where(np.isnan(m), -np.inf, m)
    return m if per_joint else m.min(axis=-1)


def _rows(q, labels):
    ok = ~np.isnan(q).any(axis=-1)
    return q[ok], np.asarray(labels, dtype=object)[ok]


def limit_values(robot: DHRobot, values: np.ndarray, solve, link) -> np.ndarray:
    """Held values (sorted) at which a solution within the limits was found between samples by the margin test.

    robot: the arm with its limits; values (S,) the samples; solve(v) → (q, labels) of the arm *without* limits
    (as ``_Held.solve``); link(qa, la, qb, lb) → {i: j} as ``_sweep._link``.
    """
    q, labels = solve(values)
    steps = []  # (v_from, v_to, q_from, q_to or None where the branch without limits ends in the step, label)
    for i in range(len(values) - 1):
        qa, la = _rows(q[i], labels[i])
        qb, lb = _rows(q[i + 1], labels[i + 1])
        m = link(qa, la, qb, lb)
        steps += [(values[i], values[i + 1], qa[a], qb[b], la[a]) for a, b in m.items()]
        steps += [(values[i], values[i + 1], qa[a], None, la[a]) for a in range(len(qa)) if a not in m]
        taken = set(m.values())
        steps += [(values[i + 1], values[i], qb[b], None, lb[b]) for b in range(len(qb)) if b not in taken]
    found: list[float] = []
    for _ in range(ROUNDS):
        steps = _hopeful(robot, steps)
        if not steps:
            break
        steps = _subdivide(robot, steps, solve, link, found)
    return np.unique(np.array(found))


def _hopeful(robot, steps):
    """The steps with m < 0 at the start whose margin bound reaches 0: (m_a + m_b)/2 + D ≥ 0 where the branch
    runs through the step; every one where it ends in the step (a fold between the samples, where the joints'
    speed has no bound).  Least bound first, MAX_STEPS at most."""
    if not steps:
        return []
    ma = margin(robot, np.array([s[2] for s in steps]))
    bound = np.full(len(steps), np.inf)
    both = np.array([s[3] is not None for s in steps])
    if both.any():
        qa = np.array([s[2] for s, b in zip(steps, both) if b])
        qb = np.array([s[3] for s, b in zip(steps, both) if b])
        ja, jb = margin(robot, qa, True), margin(robot, qb, True)  # (N, n) each joint's margin
        rev = np.array([t is JointType.REVOLUTE for t in robot.joint_types])
        D = np.abs(qa - qb)
        D = np.where(rev, np.abs(D - 2 * np.pi * np.rint(D / (2 * np.pi))), D)  # (N, n) angles modulo 2π
        bound[both] = np.where(jb.min(axis=-1) < 0, (0.5 * (ja + jb) + D).min(axis=-1), -np.inf)
    keep = np.flatnonzero((ma < 0) & (bound >= 0))
    keep = keep[np.argsort(-ma[keep], kind="stable")][:MAX_STEPS]
    return [steps[i] for i in keep]


def _subdivide(robot, steps, solve, link, found):
    """Each step cut into SPLIT sub-steps, the inner points solved at once and linked from the step's start; a
    point with margin ≥ 0 goes to ``found``; the sub-steps are returned (a chain that breaks ends there)."""
    frac = np.arange(1, SPLIT) / SPLIT
    pts = np.array([s[0] + (s[1] - s[0]) * frac for s in steps])  # (N, SPLIT − 1)
    q, labels = solve(pts.ravel())
    q = q.reshape(len(steps), SPLIT - 1, *q.shape[1:])
    labels = labels.reshape(len(steps), SPLIT - 1, -1)
    out = []
    for (va, vb, qa, qb, lab), vs, qs, ls in zip(steps, pts, q, labels):
        prev_v, prev_q = va, qa
        for v, qi, li in zip(vs, qs, ls):
            qi, li = _rows(qi, li)
            m = link(prev_q[None], [lab], qi, li)
            if not m:  # the branch without limits ends before v
                out.append((prev_v, float(v), prev_q, None, lab))
                break
            nxt = qi[m[0]]
            if margin(robot, nxt) >= 0:
                found.append(float(v))
            out.append((prev_v, float(v), prev_q, nxt, lab))
            prev_v, prev_q = float(v), nxt
        else:
            out.append((prev_v, vb, prev_q, qb, lab))
    return out
