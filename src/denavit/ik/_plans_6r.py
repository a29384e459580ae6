"""The closed-form plans of 6-joint arms: Pieper arms (three axes through one point: spherical wrist, elbow and
Stanford classes, any joints 1–3 by the resultant route) and UR-class arms (three parallel axes, the last two
meeting).  Chosen and wrapped (mirroring, coaxial merging) by :func:`._plans.make_plan`.
"""

from __future__ import annotations

from typing import Callable

import numpy as np

from ..chain import Screws, screw_axes, screw_pose, screw_walk
from ..numeric import inverse_transform
from ._chain import angle_about_z, solve_trig
from ._closed import closed_position, wrist_angles
from ._forms import elbow_q2, trig_pairs, trig_roots
from ._position3 import Position3
from ._structure import arm_scale, common_point, free_text, rot_z_angle
from ._subproblems import (
    ALIGNED_EXACT,
    AXES_ALIGNED_TOL,
    axis_angle_roots,
    rotation3,
    rz_bilinear,
)

__all__ = ["pieper_plan", "parallel_plan", "elbow_constants"]

def pieper_plan(chain: Screws, rng, names, limits3, closed_form: bool = True,
            limits2=(-np.inf, np.inf)) -> tuple[Callable, np.ndarray, str]:
    L = arm_scale(chain)
    pts, dirs = screw_axes(chain, np.zeros(6))
    X = common_point(pts[3:], dirs[3:])[0]
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
        free = free_text(np.broadcast_to((f123 & 1)[..., None] > 0, free.shape),
                          f"{names[0]} free (wrist centre on axis 1; {wrist})", free)
        free = free_text(np.broadcast_to((f123 & 2)[..., None] > 0, free.shape),
                          f"{names[1]} free (wrist centre on axis 2; {wrist})", free)
        free = free_text(np.broadcast_to((f123 & 4)[..., None] > 0, free.shape),
                          f"{names[2]} free (wrist centre on axis 3; {wrist})", free)
        free = free_text(sing & (sign > 0), f"{names[3]} + {names[5]} fixed (wrist singular: axes 4 and 6 aligned)", free)
        free = free_text(sing & (sign < 0), f"{names[3]} - {names[5]} fixed (wrist singular: axes 4 and 6 aligned)", free)
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
    a2, b2, rhs = np.broadcast_arrays(2.0 * a, 2.0 * b, rhs)
    qp, qm, rho, ratio = trig_roots(a2, b2, rhs, 1e-7)  # as solve_trig, with the roots' cos and sin (._forms)
    cp, sp, cm, sm = trig_pairs(a2, b2, rho, ratio, 1e-7)
    qb, cb, sb = np.stack([qp, qm], -1), np.stack([cp, cm], -1), np.stack([sp, sm], -1)
    qa = elbow_q2(P[..., None, 0], P[..., None, 1], cb, sb, R2, p2, p3, 0.0)[0]  # turns v onto P (._forms)
    return qa, qb


def parallel_plan(chain: Screws, names) -> tuple[Callable, np.ndarray]:
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
        Q = common_point(pts[4:], dirs[4:])[0]
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
            free = free_text(sing, f"{names[5]} and {names[1]} + {names[2]} + {names[3]} coupled "
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
        q4 = rot_z_angle(np.swapaxes(R23, -1, -2) @ X[..., None, :3, :3])
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
