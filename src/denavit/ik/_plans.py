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

from dataclasses import dataclass, field
from typing import Callable

import numpy as np

from ..errors import UnsupportedRobotError
from ..model import DHRobot
from ._closed import closed_position, wrist_angles
from ._general import loop_of, rank_formulations, solve_general
from ..chain import Screws, reverse_screws, screw_axes, screw_pose, screw_walk, screws_of
from ._chain import angle_about_z, solve_trig
from ._position3 import Position3
from ._subproblems import (ALIGNED_EXACT, AXES_ALIGNED_TOL, axis_angle_roots, rotation3, rz_bilinear,
                              trig_coefficients)
from ..numeric import inverse_transform

__all__ = ["Plan", "make_plan", "elbow_constants"]

GEOM_TOL = 1e-9  # relative tolerance of the structural tests (axes parallel / through one point)


@dataclass
class Plan:
    """How an arm is solved: kind, the rows verified, and the batched candidate generator."""

    kind: str
    projector: np.ndarray  # (6, 6) rows of the pose residual the arm controls (world axes)
    solve: Callable  # (B, 4, 4) -> candidates (B, K, n), free (B, K) object array of str
    point_e: np.ndarray | None = None  # wrist / reference point in the end-effector frame, for labels
    notes: list[str] = field(default_factory=list)
    route: str = ""  # how joints 1-3 of a Pieper arm are found: "closed form (elbow|stanford)" or "resultant"
    closed: dict | None = None  # the constants of a direct (unmirrored, unmerged) elbow Pieper arm: the compiled
    # solver of denavit.codegen reads them (see elbow_constants); for a direct unmerged 6R parallel arm an empty
    # dict, which analytic_ik's plan cache fills with labels and tolerances (codegen._ik_parallel adds the geometry)


# ---------------------------------------------------------------------------------------------------
# structural tests


def _scale(chain: Screws) -> float:
    return max(float(np.sum(np.abs(chain.consts[:, :3, 3]))), 1e-3)


def _configs(chain: Screws, rng) -> list[np.ndarray]:
    return [np.zeros(chain.n), rng.uniform(-np.pi, np.pi, chain.n), rng.uniform(-np.pi, np.pi, chain.n)]


def _common_point(pts: np.ndarray, dirs: np.ndarray) -> tuple[np.ndarray, float]:
    """Least-squares point nearest to lines (pts, dirs (k, 3)) and its largest distance to them."""
    A = np.zeros((3, 3))
    b = np.zeros(3)
    for p, d in zip(pts, dirs):
        M = np.eye(3) - np.outer(d, d)
        A += M
        b += M @ p
    x = np.linalg.lstsq(A, b, rcond=None)[0]
    dist = max(np.linalg.norm((np.eye(3) - np.outer(d, d)) @ (x - p)) for p, d in zip(pts, dirs))
    return x, dist


def _intersect(chain: Screws, idx, rng) -> bool:
    """Do the axes ``idx`` pass through one point (and no two of them coincide) in every test pose?"""
    L = _scale(chain)
    for q in _configs(chain, rng):
        pts, dirs = screw_axes(chain, q)
        for a, b in zip(idx[:-1], idx[1:]):
            if np.linalg.norm(np.cross(dirs[a], dirs[b])) < 1e-6:
                return False
        if _common_point(pts[list(idx)], dirs[list(idx)])[1] > GEOM_TOL * L:
            return False
    return True


def _parallel(chain: Screws, idx, rng) -> bool:
    for q in _configs(chain, rng):
        _, dirs = screw_axes(chain, q)
        if any(np.linalg.norm(np.cross(dirs[idx[0]], dirs[k])) > GEOM_TOL for k in idx[1:]):
            return False
    return True


# ---------------------------------------------------------------------------------------------------
# coaxial joints and mirrored chains


def _merge_coaxial(chain: Screws):
    """Merge consecutive coaxial revolute joints; returns (chain, expand(q_reduced) -> q, [(group name, text)] of
    the merged groups, representative joint of each reduced joint, name of each reduced joint)."""
    consts, pris = list(chain.consts), list(chain.prismatic)
    groups: list[list[tuple[int, float]]] = [[(0, 1.0)]]
    k = 0
    while k < len(pris) - 1:
        C = consts[k + 1]
        if (not pris[k] and not pris[k + 1] and abs(abs(C[2, 2]) - 1) < 1e-12
                and np.hypot(C[0, 3], C[1, 3]) < 1e-12):
            sign = float(np.sign(C[2, 2]))  # J(q_k) C J(q_k+1) = J(q_k ± q_k+1) C
            orig = groups[-1][-1][0] + 1
            groups[-1].append((orig, sign))
            consts[k + 1] = C @ consts[k + 2]
            del consts[k + 2], pris[k + 1]
            continue
        groups.append([(groups[-1][-1][0] + 1, 1.0)])
        k += 1
    n = chain.n
    free, gnames = [], []
    for g in groups:
        if len(g) > 1:
            terms = f"q{g[0][0] + 1}" + "".join(f" {'+' if s > 0 else '-'} q{i + 1}" for i, s in g[1:])
            free.append((f"({terms})", f"{terms} fixed (coaxial joints)"))
            gnames.append(f"({terms})")  # what the reduced joint stands for, in the free texts of the solvers
        else:
            gnames.append(f"q{g[0][0] + 1}")

    def expand(qr: np.ndarray) -> np.ndarray:
        out = np.zeros(qr.shape[:-1] + (n,))
        for j, g in enumerate(groups):
            out[..., g[0][0]] = qr[..., j]  # representative: the first joint takes the whole sum
        return out

    reps = [g[0][0] for g in groups]
    return Screws(np.array(consts), np.array(pris)), expand, free, reps, gnames


# ---------------------------------------------------------------------------------------------------
# solvers


def _free_text(mask: np.ndarray, text: str, out: np.ndarray) -> np.ndarray:
    if not text or not np.any(mask):
        return out
    add = np.where(out == "", text, out + "; " + text)
    return np.where(mask, add, out)


def _pieper(chain: Screws, rng, names, limits3, closed_form: bool = True,
            limits2=(-np.inf, np.inf)) -> tuple[Callable, np.ndarray, str]:
    L = _scale(chain)
    pts, dirs = screw_axes(chain, np.zeros(6))
    X = _common_point(pts[3:], dirs[3:])[0]
    F3 = screw_pose(chain, np.zeros(3), upto=3)
    P = (chain.consts[3] @ inverse_transform(F3) @ np.append(X, 1))[:3]
    X_e = (inverse_transform(screw_pose(chain, np.zeros(6))) @ np.append(X, 1))[:3]
    fast = closed_position(chain.consts[1], chain.consts[2], P, chain.prismatic[:3], L) if closed_form else None
    pos = fast or Position3(chain.consts[1], chain.consts[2], P, chain.prismatic[:3], L, limits3, rng, limits2)
    C0i, R4, R5, R6 = inverse_transform(chain.consts[0]), chain.consts[4][:3, :3], chain.consts[5][:3, :3], \
        chain.consts[6][:3, :3]

    def solve(T: np.ndarray):
        Xw = T[:, :3, :3] @ X_e + T[:, :3, 3]
        W = Xw @ C0i[:3, :3].T + C0i[:3, 3]
        q123, f123 = pos.solve(W)  # (B, M, 3): the direct closed form where the class allows, else the resultant
        Y = T[:, :3, :3] @ R6.T  # (B, 3, 3)
        if getattr(pos, "free3", False):  # wrist centre on axis 3: q3 free, but the wrist must reach what is left
            q123 = q123.copy()
            q123[..., 2] = _free_q3(chain, q123, Y, R4, R5)
        x, y, z, _ = screw_walk(chain, np.nan_to_num(q123), upto=3)  # columns of R_0_3, each (3, B, M)
        M = np.empty(q123.shape[:2] + (3, 3))  # R_0_3ᵀ R R6ᵀ
        for i, col in enumerate((x, y, z)):
            for j in range(3):
                M[..., i, j] = col[0] * Y[:, None, 0, j] + col[1] * Y[:, None, 1, j] + col[2] * Y[:, None, 2, j]
        q456, sing, sign = wrist_angles(M, R4, R5) if fast is not None else rotation3(M, R4, R5)  # (B, M, 2, 3)
        q = np.concatenate([np.broadcast_to(q123[:, :, None, :], q456.shape), q456], axis=-1)
        free = np.full(q.shape[:-1], "", dtype=object)
        wrist = f"{names[3]}, {names[4]}, {names[5]} follow"  # the wrist turns with a free joint 1, 2 or 3
        free = _free_text(np.broadcast_to((f123 & 1)[..., None] > 0, free.shape),
                          f"{names[0]} free (wrist centre on axis 1; {wrist})", free)
        free = _free_text(np.broadcast_to((f123 & 2)[..., None] > 0, free.shape),
                          f"{names[1]} free (wrist centre on axis 2; {wrist})", free)
        free = _free_text(np.broadcast_to((f123 & 4)[..., None] > 0, free.shape),
                          f"{names[2]} free (wrist centre on axis 3; {wrist})", free)
        free = _free_text(sing & (sign > 0), f"{names[3]} + {names[5]} fixed (wrist singular: axes 4 and 6 aligned)", free)
        free = _free_text(sing & (sign < 0), f"{names[3]} - {names[5]} fixed (wrist singular: axes 4 and 6 aligned)", free)
        B = len(T)
        return q.reshape(B, -1, 6), free.reshape(B, -1)

    solve.closed = None
    if fast is not None and fast.kind == "elbow":
        solve.closed = elbow_constants(chain, fast, X_e, C0i, R4, R5, R6)
    elif fast is not None:  # stanford: codegen._ik_stanford computes its geometry, analytic_ik's plan cache the rest
        solve.closed = {}
    return solve, X_e, (f"closed form ({fast.kind})" if fast is not None else "resultant")


def elbow_constants(chain: Screws, pos, X_e, C0i, R4, R5, R6) -> dict:
    """Everything the elbow + spherical-wrist closed form needs, as float arrays (for the compiled solver)."""
    r, u = R4[2, :], R5[:, 2]
    a, b, _ = rz_bilinear(r, u)
    br, bu = np.arctan2(np.hypot(r[0], r[1]), r[2]), np.arctan2(np.hypot(u[0], u[1]), u[2])
    scalars = [pos.h, pos.na, pos.nb, pos.base, pos.L, float(np.hypot(a, b)), float(np.arctan2(b, a)), br, bu]
    return dict(X_e=np.array(X_e, float), C0i=np.array(C0i, float), R6=np.array(R6, float), R1=pos.R1.copy(),
                p1=pos.p1.copy(), a=pos.a.copy(), R2=pos.R2.copy(), p2=pos.p2.copy(), P=pos.P.copy(),
                consts=np.array(chain.consts[:4], float), R4=np.array(R4, float), R5=np.array(R5, float),
                scalars=np.array(scalars, float))


def _free_q3(chain: Screws, q123: np.ndarray, Y: np.ndarray, R4: np.ndarray, R5: np.ndarray, samples: int = 24):
    """q3 for a Pieper arm whose wrist centre lies on axis 3 (q3 does not move it; the wrist follows): of
    ``samples`` values the one that puts the wrist's z-row equation ``a cos q5 + b sin q5 = M_zz − g`` farthest
    inside its range (a non-orthogonal wrist cannot reach every rotation, so q3 = 0 may leave no solution)."""
    t = 2 * np.pi * np.arange(samples) / samples
    q = np.broadcast_to(np.nan_to_num(q123)[..., None, :], q123.shape[:2] + (samples, 3)).copy()
    q[..., 2] = t
    z = screw_walk(chain, q, upto=3)[2]  # (3, B, M, S)
    Mzz = sum(z[i] * Y[:, None, None, i, 2] for i in range(3))
    r, u = R4[2, :], R5[:, 2]
    rho = max(float(np.hypot(r[0] * u[0] + r[1] * u[1], r[1] * u[0] - r[0] * u[1])), 1e-300)
    ratio = np.abs(Mzz - r[2] * u[2]) / rho
    return np.where(np.isfinite(q123[..., 2]), t[np.argmin(ratio, axis=-1)], np.nan)


def _planar_pair(P: np.ndarray, p2: np.ndarray, R2: np.ndarray, p3: np.ndarray):
    """q_a, q_b (..., 2) with Rz(q_a)(p2 + R2 Rz(q_b) p3) = P, R2 keeping the z axis (parallel joints).

    Law of cosines: |v|² = |p2|² + |p3|² + 2 p2ᵀ R2 Rz(q_b) p3 with v_z constant, so |P_xy|² = |v_xy|²
    is a cos q_b + b sin q_b = c; then q_a turns v onto P (Spong eq. 3.40–3.43 for the planar elbow).
    """
    a, b, g = rz_bilinear(R2.T @ p2, p3)
    vz = p2[2] + R2[2, 2] * p3[2]
    rhs = np.sum(P[..., :2] ** 2, -1) - p2 @ p2 - p3 @ p3 + vz**2 - 2 * g
    qb = solve_trig(2 * a, 2 * b, rhs, tol=1e-7)
    cb, sb = np.cos(qb), np.sin(qb)
    v = np.stack([cb * p3[0] - sb * p3[1], sb * p3[0] + cb * p3[1], np.full(qb.shape, p3[2])], -1)
    v = p2 + v @ R2.T
    qa = angle_about_z(v, np.broadcast_to(P[..., None, :], v.shape))
    return qa, qb


def _rot_z_angle(R: np.ndarray) -> np.ndarray:
    return np.arctan2(R[..., 1, 0], R[..., 0, 0])


def _parallel_plan(chain: Screws, names) -> tuple[Callable, np.ndarray]:
    """Axes 2, 3, 4 parallel; 6 joints with axes 5, 6 meeting at Q, or 5 joints (Q on axis 5).

    In the frame F1 = C0 J1 C1 the parallel joints turn about z, so the z coordinate of any point and of
    any direction fixed to link 4 is constant: that fixes q1 (from Q), then q5 (from the direction of the
    last axis), q6 (from the rest of the orientation), and leaves a planar 3R problem for q2, q3, q4
    (Hawkins 2013 for the UR arms; Lynch & Park 2017, Sec. 6.1.2).
    """
    n = chain.n
    C = chain.consts
    pts, dirs = screw_axes(chain, np.zeros(n))
    if n == 6:
        Q = _common_point(pts[4:], dirs[4:])[0]
    else:
        Q = pts[4]
    T0 = screw_pose(chain, np.zeros(n))
    Q_e = (inverse_transform(T0) @ np.append(Q, 1))[:3]
    F1_0 = screw_pose(chain, np.zeros(1), upto=1)
    h = (inverse_transform(F1_0) @ np.append(Q, 1))[2]  # z of Q in F1: the same for every q2, q3, q4
    Rc1, pc1 = C[1][:3, :3], C[1][:3, 3]
    a = Rc1[:, 2]  # axis 2 in the frame after joint 1
    sigma = np.sign((C[2] @ C[3])[2, 2])  # the parallel joints map z to σ z
    C0i = inverse_transform(C[0])

    def solve(T: np.ndarray):
        B = len(T)
        V = (T[:, :3, :3] @ Q_e + T[:, :3, 3]) @ C0i[:3, :3].T + C0i[:3, 3]
        q1 = solve_trig(a[0] * V[:, 0] + a[1] * V[:, 1], a[0] * V[:, 1] - a[1] * V[:, 0],
                        h + a @ pc1 - a[2] * V[:, 2], tol=1e-7)  # (B, 2)
        F1 = screw_pose(chain, np.nan_to_num(q1)[..., None], upto=1)  # (B, 2, 4, 4)
        RL = np.swapaxes(F1[..., :3, :3], -1, -2) @ T[:, None, :3, :3] @ C[n][:3, :3].T  # (B, 2, 3, 3)
        ell = RL[..., 2, :]  # e_zᵀ R_L
        free = np.full((B, 2, 2), "", dtype=object)
        if n == 6:
            r, u = C[4][2, :3], C[5][:3, 2]
            d_last = RL[..., :, 2]  # axis 6 in F1 axes: (RL e_z); its z component is fixed by q5
            m = np.concatenate([d_last[..., :2], sigma * d_last[..., 2:]], -1)
            q5 = axis_angle_roots(r, u, m, tol=1e-7)  # (B, 2, 2), digits kept next to the singularity
            y = sigma * np.einsum("j,...jk,kl->...l", C[4][2, :3], _rz(q5), C[5][:3, :3])
            ell2 = np.broadcast_to(ell[..., None, :], y.shape)
            yxy = np.hypot(y[..., 0], y[..., 1])
            sing = yxy < AXES_ALIGNED_TOL
            exact = yxy < ALIGNED_EXACT
            q6 = np.where(exact, 0.0, -angle_about_z(y, ell2))
            if exact.any():  # q6 free: the representative whose planar 3R problem is best inside its workspace
                q6 = np.where(exact, _aligned_q6(T, F1, q5, C, exact), q6)
            free = _free_text(sing, f"{names[5]} and {names[1]} + {names[2]} + {names[3]} coupled "
                              "(axis 6 parallel to axes 2-4)", free)
            tail = C[4] @ _jz(q5) @ C[5] @ _jz(q6) @ C[6]
        else:
            y = sigma * C[4][2, :3]
            q5 = -angle_about_z(np.broadcast_to(y, ell.shape), ell)[..., None] * np.ones(2)
            q5[..., 1] = np.nan
            q6 = None
            tail = C[4] @ _jz(q5) @ C[5]
        X = inverse_transform(F1)[..., None, :, :] @ T[:, None, None] @ inverse_transform(tail)  # (B,2,2,4,4)
        P = X[..., :3, 3]
        q2, q3 = _planar_pair(P, C[2][:3, 3], C[2][:3, :3], C[3][:3, 3])  # (B, 2, 2, 2)
        R23 = _rz(q2) @ C[2][:3, :3] @ _rz(q3) @ C[3][:3, :3]
        q4 = _rot_z_angle(np.swapaxes(R23, -1, -2) @ X[..., None, :3, :3])
        shape = q2.shape
        cols = [np.broadcast_to(q1[:, :, None, None], shape), q2, q3, q4,
                np.broadcast_to(q5[..., None], shape)]
        if n == 6:
            cols.append(np.broadcast_to(q6[..., None], shape))
        q = np.stack(cols, axis=-1).reshape(B, -1, n)
        free = np.broadcast_to(free[..., None], shape).reshape(B, -1)
        return q, free

    return solve, Q_e


def _aligned_q6(T, F1, q5, C, exact, samples: int = 24) -> np.ndarray:
    """q6 for the continuum of a UR-type arm with axis 6 parallel to axes 2-4 (every q6 gives a pose of the
    same family, the planar joints follow): of ``samples`` values the one whose planar 3R problem has the
    law-of-cosines ratio farthest inside ±1 (so the representative is reachable whenever the family is)."""
    t = 2 * np.pi * np.arange(samples) / samples
    tail = C[4] @ _jz(q5[..., None]) @ C[5] @ _jz(t) @ C[6]  # (B, 2, 2, S, 4, 4)
    X = inverse_transform(F1)[:, :, None, None] @ T[:, None, None, None] @ inverse_transform(tail)
    a, b, g = rz_bilinear(C[2][:3, :3].T @ C[2][:3, 3], C[3][:3, 3])
    p2, p3, R2 = C[2][:3, 3], C[3][:3, 3], C[2][:3, :3]
    vz = p2[2] + R2[2, 2] * p3[2]
    rhs = np.sum(X[..., :2, 3] ** 2, -1) - p2 @ p2 - p3 @ p3 + vz**2 - 2 * g
    ratio = np.abs(rhs) / max(2 * np.hypot(a, b), 1e-300)
    return t[np.argmin(np.nan_to_num(ratio, nan=np.inf), axis=-1)]


def _rz(t):
    t = np.asarray(t, dtype=float)
    c, s = np.cos(t), np.sin(t)
    R = np.zeros(t.shape + (3, 3))
    R[..., 0, 0], R[..., 0, 1], R[..., 1, 0], R[..., 1, 1], R[..., 2, 2] = c, -s, s, c, 1.0
    return R


def _jz(t):
    J = np.zeros(np.shape(t) + (4, 4))
    J[..., :3, :3] = _rz(t)
    J[..., 3, 3] = 1.0
    return J


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
    L = _scale(chain)
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
            q[..., r3] = _rot_z_angle(Rz)
        free = np.full((B, 2), "", dtype=object)
        on_axis1 = np.broadcast_to((np.hypot(Qt[:, 0], Qt[:, 1]) < 1e-10 * L)[:, None], (B, 2))
        if on_axis1.any():  # the point on the first revolute axis: that joint is free (the third follows)
            follow = f"; {names[rev[2]]} follows" if len(rev) == 3 else ""
            free = _free_text(on_axis1 & np.isfinite(q2), f"{names[r1]} free (point on axis {r1 + 1}{follow})", free)
        if on_axis2:  # the representative with the target's heading
            qq = np.nan_to_num(q)
            pre = screw_pose(chain, qq[..., :r2], upto=r2)
            post = screw_pose(chain, qq[..., r2 + 1:], start=r2 + 1)
            Rz = np.swapaxes(pre[..., :3, :3], -1, -2) @ T[:, None, :3, :3] @ np.swapaxes(post[..., :3, :3], -1, -2)
            q[..., r2] = _rot_z_angle(Rz)
            free = _free_text(np.isfinite(q2), f"{names[r2]} free (point on axis {r2 + 1})", free)
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
        free = _free_text(sing & (sign > 0), f"{names[0]} + {names[2]} fixed (axes 1 and 3 aligned)", free)
        free = _free_text(sing & (sign < 0), f"{names[0]} - {names[2]} fixed (axes 1 and 3 aligned)", free)
        return q, free

    return solve


def _position_rank(chain: Screws, rng) -> int:
    """Largest rank of the 3×3 position Jacobian of a 3-joint chain's end point over three configurations
    (finite differences of screw_pose, steps 1e-6: rank is decided at 1e-4 relative)."""
    best = 0
    for q in _configs(chain, rng):
        p0 = screw_pose(chain, q)[:3, 3]
        J = np.stack([(screw_pose(chain, q + 1e-6 * e)[:3, 3] - p0) / 1e-6 for e in np.eye(3)], axis=1)
        best = max(best, int(np.linalg.matrix_rank(J, tol=1e-4 * max(np.abs(J).max(), 1e-12))))
    return best


def _position_plan(chain: Screws, rng, names, limits3, limits2=(-np.inf, np.inf)) -> Callable:
    C = chain.consts
    # the direct closed forms where the class allows (articulated RRR with axes 2 ∥ 3, spherical RRP), as for the
    # wrist centre of a Pieper arm: the resultant has multiple roots on some of these (spherical-rrp: a 6-fold one
    # next to q3 = 0, whose roots came out 1e-2 apart), else the resultant route
    pos = closed_position(C[1], C[2], C[3][:3, 3], chain.prismatic, _scale(chain)) or \
        Position3(C[1], C[2], C[3][:3, 3], chain.prismatic, _scale(chain), limits3, rng, limits2)
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
        free = _free_text((f & 1) > 0, f"{names[0]} free (point on axis 1)", free)
        free = _free_text((f & 2) > 0, f"{names[1]} free", free)
        free = _free_text((f & 4) > 0, f"{names[2]} free (point on axis 3)", free)
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
    chain, expand, groups, reps, names = _merge_coaxial(full)
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
        if not chain.prismatic[3:].any() and _intersect(chain, (3, 4, 5), rng):
            solve, point, route = _pieper(chain, rng, names, tuple(lim[reps[2]]), closed_form, tuple(lim[reps[1]]))
            kind = "pieper"
            closed = solve.closed if not groups else None
        elif not chain.prismatic[:3].any() and _intersect(chain, (0, 1, 2), rng):
            s, _, route = _pieper(rev, rng, rnames, tuple(-lim[reps[3]][::-1]), closed_form)
            solve, kind = _mirrored(s), "pieper (mirrored: spherical joint at the base)"
    if solve is None and m in (5, 6) and all_rev and _generic_rank(robot, rng) == m:
        # (full rank only: with all five axes parallel, say, the parallel joints leave a continuum unsolved)
        if _parallel(chain, (1, 2, 3), rng) and (m == 5 or _intersect(chain, (4, 5), rng)):
            solve, point = _parallel_plan(chain, names)
            kind = "parallel"
            closed = {} if m == 6 and not groups else None
        elif _parallel(rev, (1, 2, 3), rng) and (m == 5 or _intersect(rev, (4, 5), rng)):
            s, _ = _parallel_plan(rev, rnames)
            solve, kind = _mirrored(s), "parallel (mirrored)"
    if solve is None and 2 <= m <= 4 and _parallel(chain, tuple(range(m)), rng) \
            and chain.prismatic.sum() <= 1 and 2 <= (~chain.prismatic).sum() <= 3:
        solve, point, n_w = _planar_plan(chain, names)
        kind = "planar"
        P = np.zeros((6, 6))
        P[:3, :3] = np.eye(3)
        if (~chain.prismatic).sum() == 3:
            P[3:, 3:] = np.outer(n_w, n_w)
    if solve is None and m == 3:
        if all_rev and _intersect(chain, (0, 1, 2), rng):
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
                "do not resolve; use the numerical solver (solve_ik / --method numeric, with a row mask)")
        raise UnsupportedRobotError(
            f"{robot.name}: no closed-form inverse kinematics for this {full.n}-joint {types} structure "
            "(known: 6 joints with a spherical wrist, UR-type 6R with three parallel axes, any other 6R arm, "
            "planar/SCARA arms, 3-joint arms); use the numerical solver (solve_ik / --method numeric)")

    def run(T: np.ndarray):
        q, free = solve(T)
        for gname, text in groups:  # the sum of coaxial joints is fixed, unless the solver found it free
            named_free = np.array([f"{gname} free" in f for f in free.ravel()], dtype=bool).reshape(free.shape)
            free = _free_text(~named_free, text, free)
        return expand(q), free

    return Plan(kind, P, run, point, [coaxial] if coaxial else [], route, closed)
