"""Position of a point by three joints, batched: Pieper's reduction done numerically and exactly.

:class:`Position3` works on the joint-screw form of :mod:`denavit.chain` (its notes give the method; docs/ik.md,
"Position of a point by three joints", the tests).  Returns NaN for "no solution" so that every pose of a batch
carries the same number of candidate slots.
"""

from __future__ import annotations

import numpy as np

from ._chain import angle_about_z, damped_solve, joint_motion, solve_trig
from ._roots import batched_roots, root_clusters
from ._subproblems import trig_coefficients

__all__ = ["Position3"]

_KMAX = 6  # harmonics sampled for a revolute sweep joint (the resultant has degree ≤ 4)
_PMAX = 8  # polynomial degree sampled for a prismatic sweep joint (the resultant has degree ≤ 6)
FREE_EPS = 1e-9  # relative size under which an equation is taken not to depend on a joint
WEAK_Q2 = 1e-3  # relative dependence on q2 under which a q3 without a q2 root still gets q2 = 0, π to refine
FREE_AXIS = 1e-10  # distance to axis 1 or 2, relative to the arm's size, under which that joint is named free (as
# FREE_TOL of the closed forms)
REFINE_ABOVE = 1e-13  # residual of the point, relative to the arm's size, above which q1-q3 are refined
REFINE_STEPS = 4
SAME_ROOT = 1e-6  # joint-space distance [rad, m per L] under which a root of the other order is one already found
_ALT_SEED = 20240602  # the other order's structural tests draw from their own fixed stream


class Position3:
    """Three joints (revolute or prismatic, any geometry) placing a point: all solutions, batched.

    ``W = J1(q1) C1 J2(q2) C2 J3(q3) P`` (coordinates of the frame before joint 1).  With g = C1 J2 C2 J3 P,
    joint 1 leaves two quantities unchanged: for a revolute joint the height g_z and the squared distance
    |g − c|² to a point c of its axis; for a prismatic joint g_x and g_y.  Both are of the form
    A(q3) cos q2 + B(q3) sin q2 + C(q3) (or a quadratic in a prismatic q2).  Eliminating q2 (the resultant
    of the two, Sylvester) leaves one equation in q3, a trigonometric polynomial of degree ≤ 4 (a polynomial
    of degree ≤ 6 for a prismatic q3) whose roots are all found at once as eigenvalues of a companion
    matrix.  This is Pieper's reduction (Pieper 1968; Craig 3rd ed. Sec. 4.6, eqs. 4.68–4.80, where the
    resultant is the quartic in tan(θ3/2)), obtained here numerically: the coefficient functions are
    sampled from the chain itself, which is exact because their degree is known.
    """

    def __init__(self, C1: np.ndarray, C2: np.ndarray, P: np.ndarray, prismatic: np.ndarray, scale: float,
                 limits3: tuple[float, float], rng: np.random.Generator,
                 limits2: tuple[float, float] = (-np.inf, np.inf), swap: bool = False) -> None:
        self.C1, self.C2, self.P = C1, C2, np.append(P, 1.0)
        self.pr1, self.pr2, self.pr3 = (bool(x) for x in prismatic)
        # the joint eliminated (u) and the joint whose polynomial is solved (v): q2 and q3, or q3 and q2 (swap)
        self.swap = swap
        self.pu, self.pv = (self.pr3, self.pr2) if swap else (self.pr2, self.pr3)
        self.L = scale
        self.c = self._axis_foot() if not self.pr1 else np.zeros(3)
        if self.pv:
            lo, hi = limits2 if swap else limits3
            lo, hi = (lo if np.isfinite(lo) else -2 * scale), (hi if np.isfinite(hi) else 2 * scale)
            self.mid, self.half = 0.5 * (lo + hi), max(0.5 * (hi - lo), 1e-3 * scale)
            nodes = np.cos(np.pi * (np.arange(_PMAX + 1) + 0.5) / (_PMAX + 1))  # Chebyshev nodes
            self.nodes = self.mid + self.half * nodes
            self.fit = np.linalg.inv(np.vander(nodes, _PMAX + 1))  # samples → monomials (highest first)
        else:
            self.nodes = 2 * np.pi * np.arange(2 * _KMAX + 1) / (2 * _KMAX + 1)
        self.coef = self._coefficients(self.nodes)  # (2, 3, N): rows k, (A, B, C)
        self.degree = self._effective_degree(rng)
        # the point on axis 3 (revolute): q3 does not move it, q1 and q2 place it, q3 is free (a continuum)
        self.free3 = self.degree <= 0 and not self.pr3 and not swap and self._on_axis3(rng)  # (≡ 0, or const in q3)
        self.alt = None  # the other elimination order, for poses whose roots cluster (see solve)
        if swap:
            return
        if self.degree > 0 and not self.free3:
            try:
                alt = Position3(C1, C2, P, prismatic, scale, limits3, np.random.default_rng(_ALT_SEED), limits2, True)
                self.alt = alt if alt.degree > 0 else None
            except Exception:  # noqa: BLE001 — no second order for this arm: the first one is used alone
                self.alt = None
        if self.degree < 0 and not self.free3:
            from ..errors import UnsupportedRobotError

            raise UnsupportedRobotError("joints 1-3 cannot place the point independently (every target reached is "
                                        "reached along a continuum the closed form does not resolve); use the "
                                        "numerical solver (solve_ik / --method numeric)")

    # -- robot-only parts ------------------------------------------------------------------------
    def _on_axis3(self, rng) -> bool:
        """Does the point stay put when q3 turns (it lies on axis 3)?"""
        q2 = rng.uniform(-3, 3, 4)
        g0, g1 = self.g(q2, 0.0), self.g(q2, rng.uniform(-3, 3, 4))
        return bool(np.max(np.abs(g1 - g0)) < FREE_EPS * self.L)

    def _axis_foot(self) -> np.ndarray:
        """Foot on axis 1 (the z axis) of the common normal with axis 2; origin if they are parallel."""
        o, d = self.C1[:3, 3], self.C1[:3, 2]
        s = 1.0 - d[2] ** 2
        if s < 1e-12:
            return np.zeros(3)
        t = (o[2] - d[2] * np.dot(d, o)) / s  # closest point z·t on the z axis
        return np.array([0.0, 0.0, t])

    def _guv(self, u, v) -> np.ndarray:
        """g with the eliminated joint u and the solved joint v in their places."""
        return self.g(v, u) if self.swap else self.g(u, v)

    def g(self, q2, q3) -> np.ndarray:
        """C1 J2(q2) C2 J3(q3) P, shape broadcast(q2, q3) + (3,)."""
        q2, q3 = np.broadcast_arrays(np.asarray(q2, float), np.asarray(q3, float))
        T = self.C1 @ joint_motion(self.pr2, q2) @ self.C2 @ joint_motion(self.pr3, q3)
        return (T @ self.P)[..., :3]

    def invariants(self, g: np.ndarray) -> np.ndarray:
        """The two quantities joint 1 cannot change, (..., 2)."""
        if self.pr1:
            return g[..., :2]
        return np.stack([g[..., 2], np.sum((g - self.c) ** 2, axis=-1)], axis=-1)

    def _coefficients(self, q3) -> np.ndarray:
        """(A, B, C) of both invariants in the eliminated joint (q2) at the given solved joint (q3), shape (2, 3) +
        q3.shape."""
        if self.pu:
            s = self.L
            G = [self.invariants(self._guv(v, q3)) for v in (-s, 0.0, s)]
            C = G[1]
            A = (G[0] + G[2] - 2 * C) / (2 * s * s)
            B = (G[2] - G[0]) / (2 * s)
        else:
            A, B, C = trig_coefficients(*(self.invariants(self._guv(v, q3)) for v in (0.0, np.pi / 2, np.pi)))
        return np.moveaxis(np.stack([A, B, C], axis=0), -1, 0)  # (2, 3, ...)

    def _effective_degree(self, rng) -> int:
        """Degree of the resultant for this arm (found on random reachable points; −1: identically zero)."""
        q3 = rng.uniform(self.nodes.min(), self.nodes.max(), 16) if self.pv else rng.uniform(-3, 3, 16)
        c = np.abs(self._poly(self.invariants(self._guv(rng.uniform(-3, 3, 16), q3))))  # (16, m+1)
        rel = c.max(axis=0) / max(c.max(), 1e-300)
        nz = np.flatnonzero(rel > 1e-9)
        if nz.size == 0 or c.max() < 1e-12 * self.L ** 8:
            return -1
        if self.pv:
            return c.shape[1] - 1 - int(nz[0])
        return int(np.max(np.abs(_KMAX - nz)))

    # -- per target -------------------------------------------------------------------------------
    def _resultant_samples(self, w: np.ndarray) -> np.ndarray:
        A, B, C = self.coef[:, 0], self.coef[:, 1], self.coef[:, 2] - w[..., :, None]  # (..., 2, N)
        A1, B1, C1, A2, B2, C2 = A[0], B[0], C[..., 0, :], A[1], B[1], C[..., 1, :]
        if not self.pu:
            D = A1 * B2 - A2 * B1
            return (B1 * C2 - B2 * C1) ** 2 + (A2 * C1 - A1 * C2) ** 2 - D**2
        if np.max(np.abs(A1)) + np.max(np.abs(A2)) < FREE_EPS:
            return B1 * C2 - B2 * C1
        return (A1 * C2 - A2 * C1) ** 2 - (A1 * B2 - A2 * B1) * (B1 * C2 - B2 * C1)

    def _poly(self, w: np.ndarray) -> np.ndarray:
        """Coefficients (highest first) of the resultant in z = e^{iq3} (revolute) or in x (prismatic)."""
        R = self._resultant_samples(w)  # (..., N)
        if self.pv:
            return R @ self.fit.T
        N = R.shape[-1]
        k = np.arange(_KMAX, -_KMAX - 1, -1)
        return (R @ np.exp(-1j * np.outer(self.nodes, k))) / N  # c_K … c_{-K}

    def _q3_candidates(self, w: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Real roots of the resultant in the solved joint (B, m); which poses have roots that cluster (B,) (a
        multiple root split by rounding, see :func:`._roots.root_clusters`, or a resultant that vanishes); and the
        centroid of the largest cluster (B,) in the solved joint (NaN where none)."""
        p = self._poly(w)  # (B, 2K+1) or (B, P+1)
        if self.pv:
            top = p.shape[-1] - 1 - self.degree
            p = p[:, top:]
        else:
            p = p[:, _KMAX - self.degree: _KMAX + self.degree + 1]
        roots = batched_roots(p)
        clustered, centre = root_clusters(roots, self.pv)
        clustered |= np.all(np.isnan(roots), axis=1)  # the resultant vanishes at this pose
        if self.pv:
            ok = np.abs(roots.imag) < 1e-4 * (1 + np.abs(roots.real))
            centre = np.where(clustered, self.mid + self.half * centre.real, np.nan)
            return np.where(ok, self.mid + self.half * roots.real, np.nan), clustered, centre
        ok = np.abs(np.abs(roots) - 1.0) < 1e-3
        return np.where(ok, np.angle(roots), np.nan), clustered, np.where(clustered, np.angle(centre), np.nan)

    def solve(self, W: np.ndarray):
        """All (q1, q2, q3) placing the point at W (B, 3).

        Returns q (B, M, 3) with NaN rows for unused slots and free (B, M) int flags:
        bit 1 = q1 undetermined (point on axis 1), bit 2 = q2 undetermined, bit 4 = q3 undetermined (point on
        axis 3: 0 is returned).
        """
        w = self.invariants(W)
        clustered = np.zeros(len(W), dtype=bool)
        if self.free3:
            q3 = np.zeros((len(W), 1))
        elif self.degree > 0:
            q3, clustered, centre = self._q3_candidates(w)
        else:
            q3 = np.full((len(W), 1), np.nan)
        q, free = self._from_q3(q3, w, W)
        if clustered.any():
            q, free = self._clustered(q, free, W, w, clustered, centre)
        return q, free

    def _from_q3(self, q3: np.ndarray, w: np.ndarray, W: np.ndarray):
        """Candidates (B, M, 3) and free flags from the roots q3 (B, m) of the solved joint."""
        q2, free2 = self._q2_candidates(q3, w)  # (B, M, 2)
        q3 = np.broadcast_to(q3[..., None], q2.shape)
        if self.swap:  # solved q2, eliminated q3 (a q3 without effect is no continuum here: the point on axis 3)
            q2, q3, free2 = q3, q2, np.zeros_like(free2)
        g = self.g(np.nan_to_num(q2), np.nan_to_num(q3))  # (B, M, 2, 3)
        Wb = W[:, None, None, :]
        if self.pr1:
            q1 = Wb[..., 2] - g[..., 2]
            free1 = np.zeros(q1.shape, dtype=bool)
        else:
            free1 = (np.hypot(g[..., 0], g[..., 1]) < 1e-7 * self.L) & (np.hypot(Wb[..., 0], Wb[..., 1]) < 1e-7 * self.L)
            # the continuum is named within 1e-7 L of axis 1, but the row stays the exact solution off the axis
            exact = free1 & (np.hypot(Wb[..., 0], Wb[..., 1]) < 1e-12 * self.L)
            q1 = np.where(exact, 0.0, angle_about_z(g, np.broadcast_to(Wb, g.shape)))
        q = np.stack([q1, q2, q3], axis=-1).reshape(len(W), -1, 3)
        bad = ~np.all(np.isfinite(q), axis=-1)
        q[bad] = np.nan
        free = (free1 * 1 + free2 * 2 + 4 * self.free3).reshape(len(W), -1)
        q = self._refine(q, W, free)
        if not self.pr1 and np.any(free & 1):
            q = self._off_axis1(q, W, (free & 1) > 0)
        return q, np.where(bad, 0, self._free_after(q, W, free))

    def _off_axis1(self, q: np.ndarray, W: np.ndarray, near: np.ndarray) -> np.ndarray:
        """Rows named "q1 free" (the target within 1e-7 L of axis 1) whose point misses a target that is not
        exactly on the axis: q1 cannot be read from a point that the root put on the axis itself (where its distance
        to axis 1 has a double root in q3, say, the candidate misses the target by the target's own distance
        r ~ 1e-9 to the axis).  First order in (δ2, δ3): the height equation is linear, the distance to the axis
        |a + B δ| = r a quadratic along its solution line; the smaller root is taken, q1 then by the angle."""
        Wb = np.broadcast_to(W[:, None], q.shape)
        r = np.hypot(Wb[..., 0], Wb[..., 1])
        rows = near & np.all(np.isfinite(q), -1) & (r >= 1e-12 * self.L)
        rows &= np.linalg.norm(self.point(np.nan_to_num(q)) - Wb, axis=-1) > REFINE_ABOVE * self.L
        if not rows.any():
            return q
        x, Wr, rr = q[rows], Wb[rows], r[rows]
        h = 1e-6
        g0 = self.g(x[:, 1], x[:, 2])
        V = np.stack([(self.g(x[:, 1] + h * d[0], x[:, 2] + h * d[1]) - self.g(x[:, 1] - h * d[0], x[:, 2] - h * d[1]))
                      / (2 * h) for d in ((1.0, 0.0), (0.0, 1.0))], -1)  # (b, 3, 2): ∂g/∂(q2, q3)
        vz = V[:, 2]  # height: vz · δ = W_z − g0_z
        nz = np.maximum(np.sum(vz**2, -1), 1e-300)
        d0 = vz * ((Wr[:, 2] - g0[:, 2]) / nz)[:, None]
        n = np.stack([-vz[:, 1], vz[:, 0]], -1) / np.sqrt(nz)[:, None]
        a = g0[:, :2] + np.einsum("bij,bj->bi", V[:, :2], d0)
        Bn = np.einsum("bij,bj->bi", V[:, :2], n)
        A2, A1, A0 = np.sum(Bn**2, -1), 2 * np.sum(a * Bn, -1), np.sum(a**2, -1) - rr**2
        disc = np.maximum(A1**2 - 4 * A2 * A0, 0.0)
        with np.errstate(divide="ignore", invalid="ignore"):
            ts = np.stack([(-A1 + np.sqrt(disc)) / (2 * A2), (-A1 - np.sqrt(disc)) / (2 * A2)], -1)
        t = np.take_along_axis(ts, np.argmin(np.abs(np.nan_to_num(ts, nan=np.inf)), -1)[:, None], -1)[:, 0]
        y = x.copy()
        y[:, 1:] += d0 + np.nan_to_num(t)[:, None] * n
        y[:, 0] = angle_about_z(self.g(y[:, 1], y[:, 2]), Wr)
        better = np.linalg.norm(self.point(y) - Wr, axis=-1) < np.linalg.norm(self.point(x) - Wr, axis=-1)
        out = q.copy()
        out[rows] = np.where(better[:, None], y, x)
        return out

    def _clustered(self, q, free, W, w, clustered, centre):
        """More candidates for the poses whose resultant roots cluster: a multiple root of this order's resultant
        (the point crossing axis 2, say) came out as roots ~ε^(1/k) apart or complex, and the generating branch
        could be lost.  The other order's resultant (q2 and q3 swap roles) has simple roots there; where it has
        none (it vanishes: the point exactly on axis 2, q2 free) the centroid of the cluster is the root."""
        sub = np.flatnonzero(clustered)
        if self.alt is not None:
            qa, fa = self.alt.solve(W[sub])
        else:
            qa, fa = np.full((len(sub), 0, 3), np.nan), np.zeros((len(sub), 0), dtype=free.dtype)
        none = ~np.all(np.isfinite(qa), -1).any(-1)
        if none.any():
            qn, fn = self._from_q3(centre[sub[none], None], w[sub[none]], W[sub[none]])
            width = max(qa.shape[1], qn.shape[1])
            pad = lambda a, v: np.concatenate([a, np.full((len(a), width - a.shape[1]) + a.shape[2:], v)], 1)  # noqa
            qa, fa = pad(qa, np.nan), pad(fa, 0)
            qa[none], fa[none] = pad(qn, np.nan), pad(fn, 0)
        # a root both orders found is kept once, the copy that reproduces the point better (the copies would
        # only cost downstream: every pose of the batch gets as many slots as the pose with most candidates)
        rev = ~np.array([self.pr1, self.pr2, self.pr3])
        qc = q[sub]
        d = qa[:, :, None] - qc[:, None]  # (b, Ma, M, 3)
        d = np.nan_to_num(np.where(rev, np.abs(d - 2 * np.pi * np.rint(d / (2 * np.pi))), np.abs(d)).max(-1),
                          nan=np.inf)
        near = np.argmin(d, axis=-1)  # (b, Ma)
        same = np.take_along_axis(d, near[..., None], -1)[..., 0] < SAME_ROOT * max(self.L, 1.0)
        Wc = W[sub][:, None]
        ra = np.linalg.norm(self.point(np.nan_to_num(qa)) - Wc, axis=-1)
        rm = np.take_along_axis(np.linalg.norm(self.point(np.nan_to_num(qc)) - Wc, axis=-1), near, -1)
        bi, ai = np.nonzero(same & (ra < rm))
        qc[bi, near[bi, ai]] = qa[bi, ai]
        q[sub] = qc
        qa = np.where(same[..., None], np.nan, qa)
        extra = np.full((len(W),) + qa.shape[1:], np.nan)
        extra[sub] = qa
        fe = np.zeros(extra.shape[:2], dtype=free.dtype)
        fe[sub] = fa
        q, free = np.concatenate([q, extra], 1), np.concatenate([free, fe], 1)
        # the slots some pose uses, found ones first (the other poses' empty slots would cost downstream)
        found = np.all(np.isfinite(q), -1)
        order = np.argsort(~found, axis=1, kind="stable")[:, : max(int(found.sum(1).max()), 1)]
        q, free = np.take_along_axis(q, order[..., None], 1), np.take_along_axis(free, order, 1)
        return q, free

    def _free_after(self, q: np.ndarray, W: np.ndarray, free: np.ndarray) -> np.ndarray:
        """The free flags again from the refined joints: the point within FREE_AXIS · L of axis 2 (q2 revolute)
        or, with the target, of axis 1 (q1 revolute) — the flags first set from roots that lost digits can miss."""
        qq = np.nan_to_num(q)
        out = free.copy()
        if not self.pr2:  # distance of C2 J3(q3) P from axis 2 (the z axis of the frame of joint 2)
            v = (self.C2 @ joint_motion(self.pr3, qq[..., 2]) @ self.P)[..., :2]
            out |= 2 * (np.hypot(v[..., 0], v[..., 1]) < FREE_AXIS * self.L)
        if not self.pr1:
            Wb = np.broadcast_to(W[:, None], q.shape)
            g = self.g(qq[..., 1], qq[..., 2])
            out |= 1 * ((np.hypot(g[..., 0], g[..., 1]) < FREE_AXIS * self.L)
                        & (np.hypot(Wb[..., 0], Wb[..., 1]) < FREE_AXIS * self.L))
        return np.where(np.all(np.isfinite(q), -1), out, free)

    def point(self, q: np.ndarray) -> np.ndarray:
        """J1(q1) C1 J2(q2) C2 J3(q3) P, (..., 3)."""
        g = self.g(q[..., 1], q[..., 2])
        if self.pr1:
            return g + np.stack([np.zeros_like(q[..., 0]), np.zeros_like(q[..., 0]), q[..., 0]], -1)
        c, s = np.cos(q[..., 0]), np.sin(q[..., 0])
        return np.stack([c * g[..., 0] - s * g[..., 1], s * g[..., 0] + c * g[..., 1], g[..., 2]], -1)

    def _refine(self, q: np.ndarray, W: np.ndarray, free: np.ndarray) -> np.ndarray:
        """A few Newton steps on the three position equations for roots that lost digits (REFINE_ABOVE · L):
        what follows them (the wrist of a Pieper arm) is then solved from an accurate q1-q3, which a later
        polish on the whole pose cannot always recover at a wrist singularity (J singular there).  The Jacobian
        by central differences (step 1e-6: error ~1e-12, so each step gains ~12 digits)."""
        Wb = np.broadcast_to(W[:, None], q.shape)
        r = self.point(np.nan_to_num(q)) - Wb
        todo = np.all(np.isfinite(q), -1) & (np.linalg.norm(r, axis=-1) > REFINE_ABOVE * self.L) & (free == 0)
        if not todo.any():
            return q
        x, w = q[todo], Wb[todo]
        h = 1e-6
        for _ in range(REFINE_STEPS):
            e = self.point(x) - w
            if np.max(np.abs(e)) <= 1e-15 * self.L:
                break
            J = np.stack([(self.point(x + h * d) - self.point(x - h * d)) / (2 * h) for d in np.eye(3)], -1)
            Jt = np.swapaxes(J, -1, -2)
            JtJ = Jt @ J
            # damping relative to the row's own scale: a zero column (the point on axis 1, say) stays solvable
            damp = 1e-14 * np.maximum(np.trace(JtJ, axis1=-2, axis2=-1), self.L**2)[:, None, None] * np.eye(3)
            dx = damped_solve(JtJ + damp, Jt @ e[..., None])[..., 0]
            x = np.where(np.isfinite(dx), x - dx, x)
            continue
        out = q.copy()
        out[todo] = np.where(np.linalg.norm(self.point(x) - w, axis=-1)[:, None]
                             <= np.linalg.norm(self.point(q[todo]) - w, axis=-1)[:, None], x, q[todo])
        return out

    def _q2_candidates(self, q3: np.ndarray, w: np.ndarray):
        co = self._coefficients(np.nan_to_num(q3))  # (2, 3, B, M)
        A, B, C = co[:, 0], co[:, 1], co[:, 2] - np.moveaxis(w, -1, 0)[:, :, None]  # (2, B, M)
        size = np.abs(A) + np.abs(B)
        k = np.argmax(size, axis=0)  # the row that depends most on q2
        pick = lambda X, i: np.take_along_axis(X, i[None], 0)[0]  # noqa: E731
        Ak, Bk, Ck = pick(A, k), pick(B, k), pick(C, k)
        Ao, Bo, Co = pick(A, 1 - k), pick(B, 1 - k), pick(C, 1 - k)
        scale = self.L ** np.array([1.0, 2.0])[1 - k] if not self.pr1 else self.L
        free = pick(size, k) < FREE_EPS * np.maximum(scale, 1e-12)
        if self.pu:
            lin = np.abs(Ak) < FREE_EPS * np.abs(Bk)
            disc = Bk**2 - 4 * Ak * Ck
            # a double root (the point at the turning height of q2) leaves disc ≈ 0 up to the error of Ck, which
            # carries that of the q3 root (~1e-8 relative): the tolerance scales with A L² too, not with B² alone
            # (B = 0 there, say); as for the revolute case the candidates are re-checked by FK
            wk = pick(np.broadcast_to(np.abs(np.moveaxis(w, -1, 0))[:, :, None], A.shape), k)
            sq = np.sqrt(np.where(disc >= -1e-7 * (Bk**2 + np.abs(Ak) * (self.L**2 + wk)), np.maximum(disc, 0.0),
                                  np.nan))
            with np.errstate(divide="ignore", invalid="ignore"):
                quad = np.stack([(-Bk + sq) / (2 * Ak), (-Bk - sq) / (2 * Ak)], axis=-1)
                line = np.stack([-Ck / Bk, np.full(Ck.shape, np.nan)], axis=-1)
            q2 = np.where(lin[..., None], line, quad)
        else:
            q2 = solve_trig(Ak, Bk, -Ck, tol=1e-7)
        q2 = np.where(free[..., None], np.stack([np.zeros(Ck.shape), np.full(Ck.shape, np.nan)], -1), q2)
        # the other invariant must hold too (loose test: the candidates are polished and re-checked later)
        with np.errstate(invalid="ignore"):
            if self.pu:
                other = Ao[..., None] * q2**2 + Bo[..., None] * q2 + Co[..., None]
            else:
                other = Ao[..., None] * np.cos(q2) + Bo[..., None] * np.sin(q2) + Co[..., None]
            ok = np.abs(other) <= 1e-2 * (np.abs(Ao) + np.abs(Bo) + np.abs(Co) + scale)[..., None]
        q2 = np.where(ok | free[..., None], q2, np.nan)
        if not self.pu:  # a q3 next to a multiple root with q2 nearly free (the point ~1e-6 from axis 2): no root
            # of a slightly wrong equation; 0 and π are tried instead, refined with q1-q3 and checked by FK later
            weak = ~np.isfinite(q2).any(-1) & np.isfinite(q3) & (pick(size, k) < WEAK_Q2 * np.maximum(scale, 1e-12))
            q2 = np.where(weak[..., None], np.array([0.0, np.pi]), q2)
        return q2, np.broadcast_to(free[..., None], q2.shape)

