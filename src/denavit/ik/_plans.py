"""Recognising an arm's structure from its DH table and solving it in closed form: the IK "plans".

A plan is chosen from the geometry of the joint axes (computed from the table, never from the robot's name):

``pieper``    6 joints, the last three revolute axes through one point (spherical wrist); also the mirror
              case (first three axes through one point) by inverting the chain.  Joints 1–3 may be revolute
              or prismatic and may carry any offsets (shoulder offset, a3, d3 …).
``parallel``  6 revolute joints with axes 2, 3, 4 parallel and axes 5, 6 intersecting (UR family), or
              5 joints with axes 2, 3, 4 parallel (e.g. after merging two coaxial joints); also mirrored.
``planar``    2–4 joints whose axes are all parallel (planar 2R/3R, SCARA, PRRR …): at most one prismatic.
``wrist``     3 revolute axes through one point (orientation only).
``position``  any other 3-joint arm: the end-effector origin is placed (position only).
``general``   any other 6R arm: every solution by the Raghavan–Roth / Manocha–Canny eigenvalue method
              (:mod:`._general`), up to 16.

Coaxial consecutive revolute joints are merged first (their sum is all the pose sees); the result then
names the free combination.
"""

from __future__ import annotations

from typing import Callable

import numpy as np

from ..chain import Screws, reverse_screws, screw_axes, screw_pose, screws_of
from ..errors import UnsupportedRobotError
from ..model import DHRobot
from ..numeric import inverse_transform
from ._chain import angle_about_z, solve_trig
from ._closed import closed_position
from ._general import loop_of, rank_formulations, solve_general
from ._plans_6r import parallel_plan, pieper_plan
from ._position3 import Position3
from ._structure import (Plan, arm_scale, axes_meet, axes_parallel, free_text, merge_coaxial, rot_z_angle,
                         sample_configs)
from ._subproblems import rotation3, trig_coefficients

__all__ = ["Plan", "make_plan"]



def _planar_plan(chain: Screws, names) -> tuple[Callable, np.ndarray, np.ndarray]:
    """All axes parallel (to z of C0): two revolute joints place a point in the plane (law of cosines),
    a prismatic joint sets the height, a third revolute joint the heading."""
    n = chain.n
    rev = [k for k in range(n) if not chain.prismatic[k]]
    pri = [k for k in range(n) if chain.prismatic[k]]
    r1, r2 = rev[0], rev[1]
    pts, dirs = screw_axes(chain, np.zeros(n))
    C0i = inverse_transform(chain.consts[0])
    T0 = screw_pose(chain, np.zeros(n))
    Q = pts[rev[2]] if len(rev) == 3 else T0[:3, 3]
    Q_e = (inverse_transform(T0) @ np.append(Q, 1))[:3]
    c1 = (C0i @ np.append(pts[r1], 1))[:2]
    s1 = np.sign((C0i[:3, :3] @ dirs[r1])[2])

    def point(qfull):  # xy of the reference point in C0, (..., 2)
        Tq = C0i @ screw_pose(chain, qfull)
        return (Tq[..., :3, :3] @ Q_e + Tq[..., :3, 3])[..., :2] - c1

    probe = np.zeros((3, n))
    probe[:, r2] = (0.0, np.pi / 2, np.pi)
    A, Bc, Cc = trig_coefficients(*(np.sum(point(p) ** 2) for p in probe))
    # the point on the second revolute axis (modified DH without a tool offset, say): that joint does not move it,
    # only the heading; it is then taken from the target's heading and named free (for the position)
    L = arm_scale(chain)
    on_axis2 = np.hypot(A, Bc) < 1e-9 * L**2

    def solve(T: np.ndarray):
        B = len(T)
        Tl = C0i @ T
        Qt = (Tl[:, :3, :3] @ Q_e + Tl[:, :3, 3])[:, :2] - c1  # (B, 2)
        if on_axis2:
            q2 = np.where(np.abs(np.sum(Qt**2, -1) - Cc) <= 1e-7 * max(abs(Cc), 1e-12), 0.0, np.nan)[:, None] \
                + np.array([0.0, np.nan])
        else:
            q2 = solve_trig(A, Bc, np.sum(Qt**2, -1) - Cc, tol=1e-7)  # (B, 2)
        q = np.zeros((B, 2, n))
        q[..., r2] = q2
        q[..., r1] = s1 * angle_about_z(np.concatenate([point(np.nan_to_num(q)), np.zeros((B, 2, 1))], -1),
                                         np.concatenate([np.broadcast_to(Qt[:, None], (B, 2, 2)),
                                                         np.zeros((B, 2, 1))], -1))
        if pri:
            p = pri[0]
            Tq = C0i @ screw_pose(chain, np.nan_to_num(q))
            sp = np.sign((C0i[:3, :3] @ dirs[p])[2])
            q[..., p] = sp * (Tl[:, None, 2, 3] - Tq[..., 2, 3])
        if len(rev) == 3:
            r3 = rev[2]
            qq = np.nan_to_num(q)
            pre = screw_pose(chain, qq[..., :r3], upto=r3)
            post = screw_pose(chain, qq[..., r3 + 1:], start=r3 + 1)
            Rz = np.swapaxes(pre[..., :3, :3], -1, -2) @ T[:, None, :3, :3] @ np.swapaxes(post[..., :3, :3], -1, -2)
            q[..., r3] = rot_z_angle(Rz)
        free = np.full((B, 2), "", dtype=object)
        on_axis1 = np.broadcast_to((np.hypot(Qt[:, 0], Qt[:, 1]) < 1e-10 * L)[:, None], (B, 2))
        if on_axis1.any():  # the point on the first revolute axis: that joint is free (the third follows)
            follow = f"; {names[rev[2]]} follows" if len(rev) == 3 else ""
            free = free_text(on_axis1 & np.isfinite(q2), f"{names[r1]} free (point on axis {r1 + 1}{follow})", free)
        if on_axis2:  # the representative with the target's heading
            qq = np.nan_to_num(q)
            pre = screw_pose(chain, qq[..., :r2], upto=r2)
            post = screw_pose(chain, qq[..., r2 + 1:], start=r2 + 1)
            Rz = np.swapaxes(pre[..., :3, :3], -1, -2) @ T[:, None, :3, :3] @ np.swapaxes(post[..., :3, :3], -1, -2)
            q[..., r2] = rot_z_angle(Rz)
            free = free_text(np.isfinite(q2), f"{names[r2]} free (point on axis {r2 + 1})", free)
        q[~np.isfinite(q2)] = np.nan
        return q, free

    n_world = chain.consts[0][:3, 2]
    return solve, Q_e, n_world


def _wrist_plan(chain: Screws, names) -> Callable:
    C = chain.consts

    def solve(T: np.ndarray):
        M = C[0][:3, :3].T @ T[:, :3, :3] @ C[3][:3, :3].T
        q, sing, sign = rotation3(M, C[1][:3, :3], C[2][:3, :3])
        free = np.full(q.shape[:-1], "", dtype=object)
        free = free_text(sing & (sign > 0), f"{names[0]} + {names[2]} fixed (axes 1 and 3 aligned)", free)
        free = free_text(sing & (sign < 0), f"{names[0]} - {names[2]} fixed (axes 1 and 3 aligned)", free)
        return q, free

    return solve


def _position_rank(chain: Screws, rng) -> int:
    """Largest rank of the 3×3 position Jacobian of a 3-joint chain's end point over three configurations
    (finite differences of screw_pose, steps 1e-6: rank is decided at 1e-4 relative)."""
    best = 0
    for q in sample_configs(chain, rng):
        p0 = screw_pose(chain, q)[:3, 3]
        J = np.stack([(screw_pose(chain, q + 1e-6 * e)[:3, 3] - p0) / 1e-6 for e in np.eye(3)], axis=1)
        best = max(best, int(np.linalg.matrix_rank(J, tol=1e-4 * max(np.abs(J).max(), 1e-12))))
    return best


def _position_plan(chain: Screws, rng, names, limits3, limits2=(-np.inf, np.inf)) -> Callable:
    C = chain.consts
    # the direct closed forms where the class allows (articulated RRR with axes 2 ∥ 3, spherical RRP), as for the
    # wrist centre of a Pieper arm: the resultant has multiple roots on some of these (spherical-rrp: a 6-fold one
    # next to q3 = 0, whose roots came out 1e-2 apart), else the resultant route
    pos = closed_position(C[1], C[2], C[3][:3, 3], chain.prismatic, arm_scale(chain)) or \
        Position3(C[1], C[2], C[3][:3, 3], chain.prismatic, arm_scale(chain), limits3, rng, limits2)
    if _position_rank(chain, rng) < 3 - getattr(pos, "free3", False):  # e.g. two prismatic joints along one direction
        raise UnsupportedRobotError(
            "the joints of this 3-joint arm cannot place its end point in 3-D (the position rows of its Jacobian "
            "have lower rank everywhere): every reachable point is reached along a continuum the closed forms do "
            "not resolve; use the numerical solver (solve_ik / --method numeric --mask position)")
    C0i = inverse_transform(C[0])

    def solve(T: np.ndarray):
        W = T[:, :3, 3] @ C0i[:3, :3].T + C0i[:3, 3]
        q, f = pos.solve(W)
        free = np.full(q.shape[:-1], "", dtype=object)
        free = free_text((f & 1) > 0, f"{names[0]} free (point on axis 1)", free)
        free = free_text((f & 2) > 0, f"{names[1]} free", free)
        free = free_text((f & 4) > 0, f"{names[2]} free (point on axis 3)", free)
        return q, free

    return solve


def _mirrored(solve: Callable) -> Callable:
    """Solve the reversed chain for T⁻¹ and map back: q_k = −q'_{n+1−k}."""
    def run(T: np.ndarray):
        q, free = solve(inverse_transform(T))
        return -q[..., ::-1], free
    return run


def _generic_rank(robot: DHRobot, rng) -> int:
    """Largest rank of the geometric Jacobian over a few random configurations."""
    from ..numeric import geometric_jacobian

    J = geometric_jacobian(robot, rng.uniform(-np.pi, np.pi, (3, robot.dof)))
    return int(max(np.linalg.matrix_rank(Jk, tol=1e-9 * max(1.0, np.abs(Jk).max())) for Jk in J))


def _general_plan(chain: Screws, rng):
    """The eigenvalue solver of :mod:`._general` for a 6R chain, or None if every formulation degenerates.

    Targets where the best formulation's pencil is singular are solved again with the next one (and so on):
    one formulation chosen on a few random targets can be singular on a few per cent of others."""
    forms = rank_formulations(chain, rng)
    if not forms:
        return None

    def solve(T: np.ndarray):
        G = loop_of(chain, T)
        cand, usable = solve_general(G, forms[0])
        for form in forms[1:]:
            bad = np.flatnonzero(~usable)
            if bad.size == 0:
                break
            c2, u2 = solve_general(G[bad], form)
            if c2.shape[1] > cand.shape[1]:
                cand = np.concatenate([cand, np.full((len(cand), c2.shape[1] - cand.shape[1], 6), np.nan)], 1)
            cand[bad] = np.nan
            cand[bad, : c2.shape[1]] = c2
            usable[bad] = u2
        return cand, np.full(cand.shape[:-1], "", dtype=object)

    form = forms[0]
    return solve, f"eigenvalue ({'reversed, ' if form.reverse else ''}loop from joint {form.shift + 1})"


def make_plan(robot: DHRobot, closed_form: bool = True, general: bool = False) -> Plan:
    """Recognise the structure of an arm and build its closed-form solver (see module notes).

    ``closed_form=False`` keeps Pieper arms of the elbow and Stanford classes on the general resultant route
    (:class:`Position3`) instead of the direct formulas of :mod:`._closed` (used to cross-check them).
    ``general=True`` sends every 6R arm to the ``general`` eigenvalue solver, closed form or not (the same
    cross-check for the closed forms of Pieper and UR-type arms).

    Raises
    ------
    UnsupportedRobotError
        No closed form is known for this structure (use the numerical solver).
    """
    rng = np.random.default_rng(20240601)  # fixed: the structural tests must not depend on call order
    full = screws_of(robot)
    chain, expand, groups, reps, names = merge_coaxial(full)
    coaxial = "; ".join(text for _, text in groups)
    m = chain.n
    rnames = names[::-1]
    rev = reverse_screws(chain)
    lim = robot.q_limits
    eye = np.eye(6)
    all_rev = not chain.prismatic.any()
    solve, point, kind, P, route = None, None, "", eye, ""
    closed = None
    if general:
        if m != 6 or not all_rev:
            raise UnsupportedRobotError(f"{robot.name}: the general solver takes 6 revolute joints")
        found = _general_plan(chain, rng)
        if found is None:
            raise UnsupportedRobotError(f"{robot.name}: every formulation of the general 6R solver degenerates")
        solve, route = found
        kind = "general"
    if m == 6 and solve is None:
        if not chain.prismatic[3:].any() and axes_meet(chain, (3, 4, 5), rng):
            solve, point, route = pieper_plan(chain, rng, names, tuple(lim[reps[2]]), closed_form, tuple(lim[reps[1]]))
            kind = "pieper"
            closed = solve.closed if not groups else None
        elif not chain.prismatic[:3].any() and axes_meet(chain, (0, 1, 2), rng):
            s, _, route = pieper_plan(rev, rng, rnames, tuple(-lim[reps[3]][::-1]), closed_form)
            solve, kind = _mirrored(s), "pieper (mirrored: spherical joint at the base)"
    if solve is None and m in (5, 6) and all_rev and _generic_rank(robot, rng) == m:
        # (full rank only: with all five axes parallel, say, the parallel joints leave a continuum unsolved)
        if axes_parallel(chain, (1, 2, 3), rng) and (m == 5 or axes_meet(chain, (4, 5), rng)):
            solve, point = parallel_plan(chain, names)
            kind = "parallel"
            closed = {} if m == 6 and not groups else None
        elif axes_parallel(rev, (1, 2, 3), rng) and (m == 5 or axes_meet(rev, (4, 5), rng)):
            s, _ = parallel_plan(rev, rnames)
            solve, kind = _mirrored(s), "parallel (mirrored)"
    if solve is None and 2 <= m <= 4 and axes_parallel(chain, tuple(range(m)), rng) \
            and chain.prismatic.sum() <= 1 and 2 <= (~chain.prismatic).sum() <= 3:
        solve, point, n_w = _planar_plan(chain, names)
        kind = "planar"
        P = np.zeros((6, 6))
        P[:3, :3] = np.eye(3)
        if (~chain.prismatic).sum() == 3:
            P[3:, 3:] = np.outer(n_w, n_w)
    if solve is None and m == 3:
        if all_rev and axes_meet(chain, (0, 1, 2), rng):
            solve, kind = _wrist_plan(chain, names), "wrist"
            P = np.zeros((6, 6))
            P[3:, 3:] = np.eye(3)
        else:
            solve, kind = _position_plan(chain, rng, names, tuple(lim[reps[2]]), tuple(lim[reps[1]])), "position"
            P = np.zeros((6, 6))
            P[:3, :3] = np.eye(3)
    if solve is None and m == 6 and all_rev:
        found = _general_plan(chain, rng)
        if found is not None:
            (solve, route), kind = found, "general"
    if solve is None:
        types = "".join("P" if p else "R" for p in full.prismatic)
        rank = _generic_rank(robot, rng)
        if full.n >= 6 and rank < 6:
            raise UnsupportedRobotError(
                f"{robot.name}: this {full.n}-joint {types} arm cannot place its tool in a general pose (its "
                f"Jacobian has rank {rank} everywhere): no inverse kinematics for full poses; use the numerical "
                "solver with a position or row mask (solve_ik / --method numeric --mask)")
        if rank < full.n:
            raise UnsupportedRobotError(
                f"{robot.name}: the joints of this {full.n}-joint {types} arm are redundant (its Jacobian has "
                f"rank {rank} everywhere): every reachable target is reached along a continuum the closed forms "
                "do not resolve; use the numerical solver (solve_ik / --method numeric"
                + (", with a row mask)" if rank < 6 else ")"))
        raise UnsupportedRobotError(
            f"{robot.name}: no closed-form inverse kinematics for this {full.n}-joint {types} structure "
            "(known: 6 joints with a spherical wrist, UR-type 6R with three parallel axes, any other 6R arm, "
            "planar/SCARA arms, 3-joint arms); use the numerical solver (solve_ik / --method numeric)")

    def run(T: np.ndarray):
        q, free = solve(T)
        for gname, text in groups:  # the sum of coaxial joints is fixed, unless the solver found it free
            named_free = np.array([f"{gname} free" in f for f in free.ravel()], dtype=bool).reshape(free.shape)
            free = free_text(~named_free, text, free)
        return expand(q), free

    return Plan(kind, P, run, point, [coaxial] if coaxial else [], route, closed)
