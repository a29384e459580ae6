"""Direct closed forms for the two common Pieper position classes, and a lean three-axis wrist, batched.

The general route of :class:`._position3.Position3` finds joints 1–3 of any Pieper arm from the roots of a
resultant (eigenvalues of a companion matrix) and leaves roots that must be polished.  The two classes most arms
belong to have textbook closed forms that need only ``atan2``/``arccos``/``sqrt``; here they are written once, in
the joint-screw form ``W = Rz(q1) C1 J2(q2) C2 J3(q3) P`` of :mod:`._chain` (W: wrist centre in the frame
before joint 1, P: wrist centre in the frame of joint 3), so both DH conventions, offsets, base and tool are
covered without case distinctions, and evaluated for all poses × branches at once:

``elbow``     joints R R R, axes 2 and 3 parallel, axis 1 not parallel to them (Puma 560, most industrial arms;
              Craig 3rd ed. Sec. 4.7, eqs. 4.65–4.76; Spong, Hutchinson & Vidyasagar 2006, Sec. 5.3.2).
              In the frame after joint 1 every point moved by joints 2, 3 keeps its coordinate along their
              common axis ``a``: ``(Rz(q1) a)·W = a·p1 + v_z`` — one equation ``α cos q1 + β sin q1 = γ``, two
              roots (the shoulder offset equation, Craig eq. 4.65).  Then the law of cosines in the plane of
              joints 2, 3 gives q3 (two roots, the elbow; Craig eq. 4.69), and q2 turns the elbow triangle onto
              the wrist centre (one ``atan2``).
``stanford``  joints R R P, axes 1 and 2 meeting at a point O (Stanford arm; Spong et al. 2006, Sec. 5.3.3).
              Turning about axes 1 and 2 keeps ``|W − O|``, a quadratic in the prismatic q3 (two roots); the
              height along axis 1 is ``α cos q2 + β sin q2 = γ`` (two roots); q1 turns the point onto W.

Where a formula degenerates — the wrist centre on axis 1 or on axis 2, so that joint is free — the joint is set to
0 (one representative of the continuum) and flagged, as the general route does.
"""

from __future__ import annotations

import numpy as np

from ._forms import (
    elbow_plane,
    elbow_q2,
    elbow_roots,
    shoulder_roots,
    stanford_q1,
    stanford_q2,
    stanford_q3,
    wrist_rest,
)
from ._subproblems import axis_angle_pairs

__all__ = ["ElbowPosition", "StanfordPosition", "closed_position", "wrist_angles"]

STRUCT_TOL = 1e-9  # relative tolerance of the structural tests (parallel axes, intersecting axes)
FREE_TOL = 1e-10  # relative distance of the wrist centre to axis 1 or 2 under which that joint is free
# (any value then moves the wrist centre by < 1e-10 L, within the FK check, so 0 is returned and the continuum is
# named; farther out the joint is determined and computed, however ill-conditioned)
NEAR_FREE = 1e-7  # relative distance of the point to axis 2 (Stanford class) under which q2 is named free
RATIO_TOL = 1e-7  # |c/ρ| up to 1 + this counts as the tangent (double) root, as in the general route


class ElbowPosition:
    """Joints 1–3 revolute with axes 2 ∥ 3 (see the module notes); ``solve(W)`` → q (B, 4, 3), free (B, 4)."""

    kind = "elbow"

    def __init__(self, C1: np.ndarray, C2: np.ndarray, P: np.ndarray, scale: float) -> None:
        self.R1, self.p1 = C1[:3, :3], C1[:3, 3]
        self.a = C1[:3, 2]  # axis 2 (and 3) in the frame after joint 1
        R2, p2 = C2[:3, :3], C2[:3, 3]
        self.R2, self.p2, self.P, self.L = R2, p2, np.asarray(P, float), scale
        sigma = float(np.sign(R2[2, 2]))
        self.vz = p2[2] + sigma * self.P[2]  # height of the wrist centre along axis 2, constant
        self.h = float(self.a @ self.p1 + self.vz)
        m = R2.T @ p2  # |v|² = |p2|² + |P|² + 2 mᵀ Rz(q3) P
        self.alpha = m[0] * self.P[0] + m[1] * self.P[1]
        self.beta = m[1] * self.P[0] - m[0] * self.P[1]
        self.gamma = m[2] * self.P[2]
        self.k = float(p2 @ p2 + self.P @ self.P - self.vz**2 + 2 * self.gamma)
        self.na, self.nb = float(np.hypot(p2[0], p2[1])), float(np.hypot(self.P[0], self.P[1]))
        self.base = float(np.arctan2(self.beta, self.alpha))
        self.cb, self.sb = float(np.cos(self.base)), float(np.sin(self.base))

    @classmethod
    def recognise(cls, C1, C2, P, prismatic, scale) -> "ElbowPosition | None":
        if any(prismatic[:3]):
            return None
        a, R2, p2 = C1[:3, 2], C2[:3, :3], C2[:3, 3]
        if abs(abs(R2[2, 2]) - 1.0) > STRUCT_TOL or np.hypot(a[0], a[1]) < 1e-6:
            return None  # axes 2, 3 not parallel, or axis 1 parallel to them (planar, not an elbow)
        m = R2.T @ p2
        if np.hypot(m[0], m[1]) * np.hypot(P[0], P[1]) < 1e-6 * scale**2:
            return None  # the elbow does not change the reach: not this class
        return cls(C1, C2, P, scale)

    def solve(self, W: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """All (q1, q2, q3) placing the wrist centre at W (B, 3).

        Returns q (B, 4, 3), NaN rows where there is none, and free (B, 4) int flags as
        :meth:`Position3.solve`: bit 1 = q1 free (wrist centre on axis 1), bit 2 = q2 free (on axis 2)."""
        Wx, Wy, Wz = W[:, 0], W[:, 1], W[:, 2]
        tiny = FREE_TOL * self.L
        # the formulas are :mod:`._forms`' (the one copy, compiled by numba for denavit.compile as well), here on
        # the batch with the branches on trailing axes: q1 (B, 2), then q3 and q2 (B, 2, 2)
        # shoulder: (Rz(q1) a)·W = h  (Craig eq. 4.65 in joint-screw form); on axis 1 every q1 (0 returned)
        q1a, q1b, free1, _, c1a, s1a, c1b, s1b = shoulder_roots(Wx, Wy, Wz, self.a, self.h, tiny, RATIO_TOL)
        q1 = np.stack([q1a, q1b], -1)  # (B, 2)
        c1, s1 = np.stack([c1a, c1b], -1), np.stack([s1a, s1b], -1)  # cos q1, sin q1 (B, 2)
        g0, g1 = elbow_plane(c1, s1, Wx[:, None], Wy[:, None], Wz[:, None], self.R1, self.p1)  # wrist centre, frame 2
        # elbow: law of cosines |g_xy|² = |v_xy|², v = p2 + R2 Rz(q3) P (Craig eq. 4.69), with (1 ∓ cos x)/2 as
        # products (Kahan's triangle angles) so that a folded or stretched elbow keeps its digits
        q3a, q3b, _, c3a, s3a, c3b, s3b = elbow_roots(np.sqrt(g0 * g0 + g1 * g1), self.na, self.nb, self.base, self.cb,
                                                       self.sb, RATIO_TOL)
        q3 = np.stack([q3a, q3b], -1)  # (B, 2, 2)
        c3, s3 = np.stack([c3a, c3b], -1), np.stack([s3a, s3b], -1)  # cos q3, sin q3 (B, 2, 2)
        q2, free2 = elbow_q2(g0[..., None], g1[..., None], c3, s3, self.R2, self.p2, self.P, tiny)[:2]  # on axis 2: 0
        q = np.stack([np.broadcast_to(q1[..., None], q2.shape), q2, q3], -1).reshape(len(W), 4, 3)
        return q, _flags(q, free1[:, None, None] * 1 + free2 * 2)


class StanfordPosition:
    """Joints R R P with axes 1 and 2 meeting (see the module notes); ``solve(W)`` → q (B, 4, 3), free (B, 4)."""

    kind = "stanford"

    def __init__(self, C1: np.ndarray, C2: np.ndarray, P: np.ndarray, s0: float, scale: float) -> None:
        self.R1, p1 = C1[:3, :3], C1[:3, 3]
        self.O = p1 + s0 * C1[:3, 2]  # the meeting point, on the z axis
        R2, p2 = C2[:3, :3], C2[:3, 3]
        self.u = p2 + R2 @ P - np.array([0.0, 0.0, s0])  # wrist centre at q3 = 0, from O, frame of joint 2
        self.z = R2[:, 2]  # direction of the prismatic joint 3 in the frame of joint 2
        self.uz = float(self.u @ self.z)
        self.uperp = float(np.linalg.norm(self.u - self.uz * self.z))  # distance of the prismatic axis from O
        self.r = self.R1[2, :]  # axis 1 in the frame of joint 2 (times Rz(q2))
        self.L = scale

    @classmethod
    def recognise(cls, C1, C2, P, prismatic, scale) -> "StanfordPosition | None":
        if prismatic[0] or prismatic[1] or not prismatic[2]:
            return None
        a, p1 = C1[:3, 2], C1[:3, 3]
        n2 = a[0] ** 2 + a[1] ** 2
        if n2 < 1e-12:
            return None  # axes 1 and 2 parallel
        s0 = -(p1[0] * a[0] + p1[1] * a[1]) / n2  # the point of axis 2 nearest to axis 1
        if np.hypot(p1[0] + s0 * a[0], p1[1] + s0 * a[1]) > STRUCT_TOL * scale:
            return None  # axes 1 and 2 do not meet
        return cls(C1, C2, P, float(s0), scale)

    def solve(self, W: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """All (q1, q2, q3) placing the wrist centre at W (B, 3); q (B, 4, 3) and free (B, 4) as ElbowPosition."""
        D = W - self.O  # (B, 3)
        tiny = FREE_TOL * self.L
        # the formulas are :mod:`._forms`' (the one copy, compiled by numba for denavit.compile as well)
        q3a, q3b, _, _ = stanford_q3(D[:, 0], D[:, 1], D[:, 2], self.uz, self.uperp, self.L)
        q3 = np.stack([q3a, q3b], -1)  # (B, 2)
        w = self.u + q3[..., None] * self.z  # (B, 2, 3)
        # height along axis 1: D_z = rᵀ Rz(q2) w
        r = self.r
        q2a, q2b, _, _ = stanford_q2(w[..., 0], w[..., 1], w[..., 2], D[:, None, 2], r, RATIO_TOL)
        q2 = np.stack([q2a, q2b], -1)  # (B, 2, 2)
        wxy = np.hypot(w[..., 0], w[..., 1])
        # next to axis 2 (within NEAR_FREE · L: q3 there is known only to ~√ε L, the double root above) q2 is named
        # free; the row stays the solution of the equation as computed, its tangent root if rounding left none
        near2 = wxy < NEAR_FREE * self.L
        if near2.any():
            loose = np.stack(stanford_q2(w[..., 0], w[..., 1], w[..., 2], D[:, None, 2], r, np.inf)[:2], -1)
            q2 = np.where((near2 & ~np.isfinite(q2).any(-1))[..., None], loose, q2)
        q2 = np.where((wxy < tiny)[..., None], [0.0, np.nan], q2)  # w on axis 2: every q2 (0 returned)
        free2 = near2
        free1 = np.broadcast_to((np.hypot(D[:, 0], D[:, 1]) < tiny)[:, None, None], q2.shape)  # W − O on axis 1
        q1, _, _ = stanford_q1(q2, *(w[..., None, k] for k in range(3)), D[:, None, None, 0], D[:, None, None, 1],
                               self.R1)
        q1 = np.where(free1, 0.0, q1)
        q = np.stack([q1, q2, np.broadcast_to(q3[..., None], q2.shape)], -1).reshape(len(W), 4, 3)
        return q, _flags(q, free1 * 1 + free2[..., None] * 2)


def _flags(q: np.ndarray, bits: np.ndarray) -> np.ndarray:
    """Free flags (B, 4) of the candidate slots, 0 where the slot holds no solution."""
    bits = np.broadcast_to(bits, q.shape[:1] + (2, 2)).reshape(len(q), 4)
    return np.where(np.all(np.isfinite(q), axis=-1), bits, 0)


def closed_position(C1, C2, P, prismatic, scale):
    """The direct closed-form solver for joints 1–3 of a Pieper arm, or None when neither class applies."""
    return ElbowPosition.recognise(C1, C2, P, prismatic, scale) or \
        StanfordPosition.recognise(C1, C2, P, prismatic, scale)


def wrist_angles(M: np.ndarray, Ra: np.ndarray, Rb: np.ndarray):
    """All (qa, qb, qc) with Rz(qa) Ra Rz(qb) Rb Rz(qc) = M, the same result as :func:`rotation3`, elementwise.

    qb from the z-row ``(Raᵀ e_z)ᵀ Rz(qb) (Rb e_z) = M_zz`` (two roots: the wrist flip), qa turns
    ``v = Ra Rz(qb) Rb e_z`` onto ``M e_z``, qc from ``(Rz(qa) Ra Rz(qb) Rb)ᵀ M`` (Paden–Kahan subproblems 1
    and 2; Murray, Li & Sastry 1994, Sec. 3.3; Craig 3rd ed. eq. 2.71 for the orthogonal ZYZ wrist).
    Written out per component so that no (…, 3, 3) intermediates are built.

    Returns q (..., 2, 3), singular (..., 2), sign (..., 2) as :func:`._subproblems.rotation3`.
    """
    r, u = Ra[2, :], Rb[:, 2]
    qb, cb, sb = axis_angle_pairs(r, u, M[..., :, 2])  # (..., 2): digits kept next to the wrist singularity
    Mt = np.moveaxis(M, (-2, -1), (0, 1))[..., None]  # M[i, j] of each pose, against the two roots of qb
    qa, qc, singular, sign = wrist_rest(qb, cb, sb, Mt[0, 0], Mt[1, 0], Mt[2, 0], Mt[0, 2], Mt[1, 2], Ra,
                                        Rb)[:4]  # the one copy (numba compiles it too)
    return np.stack([qa, qb, qc], -1), singular, sign
