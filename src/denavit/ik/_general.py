"""Every inverse-kinematics solution of a general 6R arm: Raghavan–Roth elimination, Manocha–Canny eigenproblem.

The arm and its target close a loop of six rotations about local z axes (the joint-screw form of
:mod:`._chain`, target folded in)::

    Z1 G1 Z2 G2 Z3 G3 Z4 G4 Z5 G5 Z6 G6 = I,      Zk = Rz(θk),   G6 = C6 T⁻¹ C0

1. θ6 drops out by looking only at the line of axis 6 (its direction l and one point p): with W = G6⁻¹,
   ``Z3 G3 Z4 G4 Z5 (G5 e_z, G5 e_4) = G2⁻¹ Z2⁻¹ G1⁻¹ Z1⁻¹ (W e_z, W e_4)``.
2. From each side's p and l, the 14 quantities p, l, p·p, p·l, p×l, (p·p) l − 2 (p·l) p are formed.
   Raghavan & Roth (1993) showed that on the left they are linear in {1, s3, c3} ⊗ {1, s4, c4} ⊗ {1, s5, c5}
   and on the right in {1, s1, c1} ⊗ {1, s2, c2}.  The coefficients are obtained *exactly* here by sampling
   each angle at 0, 2π/3, 4π/3 (a three-point discrete Fourier transform) — no hand-derived formulas.
3. The 8 non-constant products of θ1, θ2 are eliminated with the left null space of their 14×8 coefficient
   matrix: 6 equations in θ3, θ4, θ5 remain.  With half-angle tangents x_k and after multiplying by x4 they
   become ``Σ(x3) ν = 0``, Σ a 12×12 matrix quadratic in x3, ν the 12 monomials x4^i x5^j (i ≤ 3, j ≤ 2).
4. det Σ(x3) = 0 is solved as a 24×24 eigenvalue problem (Manocha & Canny 1994): at most 16 real roots
   (the other 8 are x3 = ±i).  θ3 is first shifted by a fixed random angle so that θ3 = π is no
   special case.
5. For each real root, ν spans the null space of Σ(x3); when several solutions share θ3 (a multiple root)
   they are separated by the shift structure of the monomials (ν(i+1, j) = x4 ν(i, j)).  θ4, θ5 follow
   from ratios of ν, θ1, θ2 from the eliminated products by least squares, θ6 from the loop.

Which joint plays θ3 is a choice: the loop can be started at any joint and run either way (12
formulations).  Arms with special geometry make some formulations degenerate (rank-deficient 14×8 matrix
or a singular pencil, det Σ ≡ 0); :func:`choose_formulation` picks one that is regular and reproduces
known configurations.  The candidates are then verified (and polished) by forward kinematics by the caller.

References: M. Raghavan, B. Roth, "Inverse kinematics of the general 6R manipulator and related linkages",
ASME J. Mech. Des. 115 (1993) 502–508; D. Manocha, J. F. Canny, "Efficient inverse kinematics for general
6R manipulators", IEEE Trans. Robot. Autom. 10 (1994) 648–657.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..chain import Screws, screw_pose
from ._chain import joint_motion
from ..numeric import inverse_transform

__all__ = ["Formulation", "loop_of", "formulations", "choose_formulation", "rank_formulations", "solve_general", "MAX_SOLUTIONS"]

MAX_SOLUTIONS = 16
_ANG = 2 * np.pi * np.arange(3) / 3
_VINV = np.linalg.inv(np.stack([np.ones(3), np.sin(_ANG), np.cos(_ANG)], axis=1))  # values at _ANG → (1, s, c)
# (1, s, c)·(1 + x²) as coefficients of (1, x, x²), x = tan(θ/2)
_K1 = np.array([[1.0, 0, 1], [0, 2, 0], [1, 0, -1]])
_K = np.kron(_K1, _K1)
_V2 = np.kron(_VINV, _VINV)  # 9 samples (θa, θb) → 9 coefficients (a, b)
_V3 = np.kron(_V2, _VINV)  # 27 samples → 27 coefficients
REAL_TOL = 1e-6  # |Im x| / (1 + |x|) under which a root of det Σ counts as real
NEAR_REAL_TOL = 1e-2  # a conjugate pair this close to the real axis is a split double root: Re x is tried once
# (the FK check and polish decide; at 1e-4 a double root of jaco2-6dof next to a q2-singular set, split by rounding
# into 0.70275 ± 0.00071i, was dropped with both its solutions)
CLUSTER_TOL = 1e-6  # roots closer than this (relative) are one multiple root
_RHS = np.random.default_rng(5).standard_normal((12, 2))  # fixed right-hand sides of the inverse iteration
PENCIL_RCOND = 1e-11  # reciprocal condition of the leading matrix under which the pencil counts as singular


@dataclass(frozen=True)
class Formulation:
    """Which joint the loop starts at (``shift``) and whether it runs backwards (``reverse``)."""

    shift: int
    reverse: bool
    delta: float = 0.7123  # the fixed shift of θ3 (rad)

    def arrange(self, G: np.ndarray) -> np.ndarray:
        """Loop constants (B, 6, 4, 4) of the original loop → those of this formulation."""
        if self.reverse:
            inv = inverse_transform(G)
            G = np.concatenate([inv[:, 4::-1], inv[:, 5:]], axis=1)
        return np.roll(G, -self.shift, axis=1)

    def joints(self) -> np.ndarray:
        """Original joint index of each formulation joint."""
        base = np.arange(6)[::-1] if self.reverse else np.arange(6)
        return np.roll(base, -self.shift)

    def back(self, theta: np.ndarray) -> np.ndarray:
        """Formulation angles (..., 6) → original joint angles."""
        out = np.empty_like(theta)
        out[..., self.joints()] = -theta if self.reverse else theta
        return out


def formulations() -> list[Formulation]:
    """All 12 ways to run the loop, the plain one first."""
    return [Formulation(k, r) for r in (False, True) for k in range(6)]


def loop_of(chain: Screws, T: np.ndarray) -> np.ndarray:
    """Loop constants G1..G6 (B, 6, 4, 4) of a 6R chain ``C0 Z1 C1 ⋯ Z6 C6 = T`` for targets T (B, 4, 4)."""
    C = chain.consts
    H = C[6] @ inverse_transform(T) @ C[0]
    return np.concatenate([np.broadcast_to(C[1:6], (len(T), 5, 4, 4)), H[:, None]], axis=1)


def _rz(t: np.ndarray) -> np.ndarray:
    return joint_motion(False, t)


def _quantities(T: np.ndarray) -> np.ndarray:
    """The 14 Raghavan–Roth quantities of the line (point T e_4, direction T e_z), (..., 14)."""
    p, l = T[..., :3, 3], T[..., :3, 2]
    pp = np.sum(p * p, -1, keepdims=True)
    pl = np.sum(p * l, -1, keepdims=True)
    return np.concatenate([p, l, pp, pl, np.cross(p, l), pp * l - 2 * pl * p], -1)


def _lhs_coefficients(G: np.ndarray) -> np.ndarray:
    """P (B, 14, 3, 9): LHS = Σ P[:, a, 3b + c] t3_a t4_b t5_c with t = (1, sin, cos)."""
    g = lambda k: G[:, None, None, None, k]  # noqa: E731
    Z = _rz(_ANG)
    T = Z[None, :, None, None] @ g(2) @ Z[None, None, :, None] @ g(3) @ Z[None, None, None, :] @ g(4)
    F = _quantities(T).reshape(len(G), 27, 14)  # samples (θ3, θ4, θ5) in C order
    return np.swapaxes(_V3 @ F, -1, -2).reshape(len(G), 14, 3, 9)


def _rhs_coefficients(G: np.ndarray, W: np.ndarray) -> np.ndarray:
    """R (B, 14, 9): RHS = Σ R[:, 3d + e] t1_d t2_e."""
    Zi = _rz(-_ANG)
    T = (inverse_transform(G[:, None, None, 1]) @ Zi[None, None, :] @ inverse_transform(G[:, None, None, 0])
         @ Zi[None, :, None] @ W[:, None, None])
    F = _quantities(T).reshape(len(G), 9, 14)  # samples (θ1, θ2)
    return np.swapaxes(_V2 @ F, -1, -2)


@dataclass
class _System:
    A: np.ndarray  # (B, 12, 12) Σ(x) = A x² + B x + C
    B: np.ndarray
    C: np.ndarray
    E: np.ndarray  # (B, 6, 3, 9) the 6 equations: Σ_a,k E[:, :, a, k] t3_a m_k(θ4, θ5) = 0 (θ3 unshifted)
    P: np.ndarray  # (B, 14, 3, 9) with the RHS constant moved in
    Qpinv: np.ndarray  # (B, 8, 14)
    W: np.ndarray  # (B, 4, 4)


def _system(G: np.ndarray, delta: float, rng: np.random.Generator) -> _System:
    W = inverse_transform(G[:, 5])
    P = _lhs_coefficients(G)
    R = _rhs_coefficients(G, W)
    P[:, :, 0, 0] -= R[:, :, 0]
    Q = R[:, :, 1:]  # (B, 14, 8)
    Qf, Rf = np.linalg.qr(Q, mode="complete")  # (B, 14, 14), (B, 14, 8)
    diag = np.abs(np.diagonal(Rf[:, :8], axis1=-2, axis2=-1))
    N = np.swapaxes(Qf[:, :, 8:], -1, -2)  # (B, 6, 14): left null space of Q (rank 8)
    Qpinv = np.empty((len(G), 8, 14))
    full = diag.min(axis=-1) > 1e-8 * np.maximum(diag.max(axis=-1), 1e-300)
    if full.any():
        Qpinv[full] = np.linalg.solve(Rf[full, :8], np.swapaxes(Qf[full, :, :8], -1, -2))
    for b in np.flatnonzero(~full):  # (nearly) rank-deficient: SVD; more than 6 equations are free of θ1, θ2
        U, sv, Vt = np.linalg.svd(Q[b])
        r = int(np.sum(sv > 1e-10 * max(sv[0], 1e-300)))
        Nb = U[:, r:].T
        N[b] = Nb[:6] if r == 8 else rng.standard_normal((6, len(Nb))) @ Nb  # 6 random combinations
        Qpinv[b] = Vt[:r].T @ (U[:, :r] / sv[:r]).T
    E = (N @ P.reshape(len(G), 14, 27)).reshape(len(G), 6, 3, 9)
    cd, sd = np.cos(delta), np.sin(delta)
    E0, Es, Ec = E[:, :, 0], E[:, :, 1] * cd - E[:, :, 2] * sd, E[:, :, 1] * sd + E[:, :, 2] * cd

    def big(M6):
        M6 = M6 @ _K
        M = np.zeros((len(G), 12, 12))
        M[:, :6, :9] = M6
        M[:, 6:, 3:] = M6
        return M

    return _System(big(E0 - Ec), big(2 * Es), big(E0 + Ec), E, P, Qpinv, W)


def _roots(S: _System) -> tuple[np.ndarray, np.ndarray]:
    """Real roots x3 (B, 24) (NaN elsewhere) of det Σ(x) and whether the pencil was usable (B,)."""
    B = len(S.A)
    x = np.full((B, 24), np.nan)
    try:
        Ai = np.linalg.inv(S.A)
    except np.linalg.LinAlgError:  # some leading matrix exactly singular: invert one by one
        Ai = np.stack([np.linalg.pinv(a) for a in S.A])
    norm1 = lambda M: np.abs(M).sum(axis=-2).max(axis=-1)  # noqa: E731
    with np.errstate(divide="ignore", invalid="ignore"):
        rcond = 1 / (norm1(S.A) * norm1(Ai))  # 1-norm reciprocal condition
    ok = np.isfinite(rcond) & (rcond > PENCIL_RCOND) & np.all(np.isfinite(Ai), axis=(-1, -2))
    if not ok.any():
        return x, ok
    Ai = Ai[ok]
    L = np.zeros((int(ok.sum()), 24, 24))
    L[:, :12, 12:] = np.eye(12)
    L[:, 12:, :12] = -Ai @ S.C[ok]
    L[:, 12:, 12:] = -Ai @ S.B[ok]
    w = np.linalg.eigvals(L)
    im = np.abs(w.imag) / (1 + np.abs(w))
    real = (im <= REAL_TOL) | ((im <= NEAR_REAL_TOL) & (w.imag > 0))  # a near-real pair: one candidate
    x[ok] = np.where(real, w.real, np.nan)
    return x, ok


def _null_vectors(S: _System, bi: np.ndarray, xs: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Null vector ν (N, 12) of Σ(x) at each root, and whether the null space is one-dimensional.

    Inverse iteration: Σ(x)⁻¹ b for two fixed right-hand sides; both results point along the null vector when
    it is unique (their cosine is 1 to ~σ_min/σ_2), and differ when the null space has more dimensions."""
    x = xs[:, None, None]
    Sig = S.A[bi] * x**2 + S.B[bi] * x + S.C[bi]
    # a shift of 1e-13 ‖Σ‖ keeps an exactly singular Σ(x) solvable and moves ν by ~1e-13 / σ_2 only
    Sig = Sig + 1e-13 * np.abs(Sig).max(axis=(-1, -2), keepdims=True) * np.eye(12)
    with np.errstate(all="ignore"):
        try:
            V = np.linalg.solve(Sig, np.broadcast_to(_RHS, (len(xs), 12, 2)))
        except np.linalg.LinAlgError:  # some Σ(x) exactly singular: per root
            V = np.stack([_null_pair(M) for M in Sig])
        V = V / np.linalg.norm(V, axis=-2, keepdims=True)
        cos = np.abs(np.sum(V[..., 0] * V[..., 1], axis=-1))
    alone = np.isfinite(cos) & (cos > 1 - 1e-8)
    return np.nan_to_num(V[..., 0]), alone


def _null_pair(M: np.ndarray) -> np.ndarray:
    """Inverse iteration for one 12×12 Σ(x); if it is exactly singular, its null vector(s) from the SVD (the
    same vector twice when the null space is one-dimensional)."""
    try:
        return np.linalg.solve(M, _RHS)
    except np.linalg.LinAlgError:
        _, sv, Vt = np.linalg.svd(M)
        return Vt[[-1, -1]].T if sv[-2] > 1e-6 * sv[0] else Vt[[-1, -2]].T


def _pairs_at(E3: np.ndarray, rng: np.random.Generator) -> np.ndarray:
    """Every (θ4, θ5) (m, 2) solving the 6 equations E3 m(θ4, θ5) = 0 (E3 (6, 9)) for a known θ3.

    Used at multiple roots, where the null space of Σ(x3) mixes several solutions (and, on special arms,
    spurious vectors).  θ4 is shifted by a fixed angle, x5 monomials (1, x5, x5²) are kept as the unknown
    vector and x4 as the eigenvalue of a quadratic 3×3 pencil from three random combinations of the
    equations; candidates that do not satisfy all six equations are dropped."""
    import scipy.linalg

    d4 = 0.4142
    cd, sd = np.cos(d4), np.sin(d4)
    E = E3.reshape(6, 3, 3)  # (row, θ4 basis, θ5 basis)
    E = np.stack([E[:, 0], E[:, 1] * cd - E[:, 2] * sd, E[:, 1] * sd + E[:, 2] * cd], axis=1).reshape(6, 9)
    Sg = E @ _K  # (6, 9) over μ = x4^i x5^j (index 3i + j)
    F = (rng.standard_normal((3, 6)) @ Sg).reshape(3, 3, 3).transpose(1, 0, 2)  # F[i] (3 × 3) multiplies x4^i
    L = np.zeros((6, 6))
    L[:3, 3:] = np.eye(3)
    L[3:, :3], L[3:, 3:] = -F[0], -F[1]
    M = np.eye(6)
    M[3:, 3:] = F[2]
    w, V = scipy.linalg.eig(L, M)
    out = []
    for x4, v in zip(w, V.T):
        if np.isfinite(x4) and abs(x4.imag) > NEAR_REAL_TOL * (1 + abs(x4)):
            continue
        v = v[:3] if np.isfinite(x4) else v[3:]
        v = v / v[np.argmax(np.abs(v))]
        if np.max(np.abs(v.imag)) > 1e-6:
            continue
        v = v.real
        t5 = 2 * np.arctan2(v[1], v[0]) if abs(v[0]) + abs(v[1]) >= abs(v[1]) + abs(v[2]) else \
            2 * np.arctan2(v[2], v[1])
        t4 = (2 * np.arctan(x4.real) if np.isfinite(x4) else np.pi) + d4
        m = np.kron(_trig(np.array(t4)), _trig(np.array(t5)))
        if np.linalg.norm(E3 @ m) <= 1e-4 * np.linalg.norm(E3) * np.linalg.norm(m):  # loose: FK decides
            out.append((t4, t5))
    return np.array(out).reshape(-1, 2)


def _angle_pairs(nu: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """θ4, θ5 (N,) from monomial vectors ν (N, 12) = x4^i x5^j on a 4×3 grid, scale-free."""
    if len(nu) == 0:
        return np.zeros(0), np.zeros(0)
    nu = nu / np.take_along_axis(nu, np.argmax(np.abs(nu), axis=-1)[:, None], -1)
    g = nu.real.reshape(-1, 4, 3)
    lo, up = g[:, :3, :], g[:, 1:, :]
    pick = np.argmax((np.abs(lo) + np.abs(up)).reshape(len(g), -1), axis=-1)
    t4 = 2 * np.arctan2(up.reshape(len(g), -1)[np.arange(len(g)), pick], lo.reshape(len(g), -1)[np.arange(len(g)), pick])
    lo, up = g[:, :, :2], g[:, :, 1:]
    pick = np.argmax((np.abs(lo) + np.abs(up)).reshape(len(g), -1), axis=-1)
    t5 = 2 * np.arctan2(up.reshape(len(g), -1)[np.arange(len(g)), pick], lo.reshape(len(g), -1)[np.arange(len(g)), pick])
    return t4, t5


def _trig(t: np.ndarray) -> np.ndarray:
    return np.stack([np.ones_like(t), np.sin(t), np.cos(t)], axis=-1)


def solve_general(G: np.ndarray, form: Formulation, rng: np.random.Generator | None = None
                  ) -> tuple[np.ndarray, np.ndarray]:
    """Candidate solutions (B, 16 or more, 6) (NaN rows unused) of loops G (B, 6, 4, 4), original joint order.

    Also returns, per target, whether the formulation was usable (regular pencil)."""
    rng = rng or np.random.default_rng(7)
    Gf = form.arrange(G)
    S = _system(Gf, form.delta, rng)
    x, usable = _roots(S)
    B = len(G)
    cand = np.full((B, 24, 6), np.nan)
    xsorted = np.sort(x, axis=1)  # NaN last
    bi, ri = np.nonzero(np.isfinite(xsorted))  # by target, then by root value
    if bi.size == 0:
        return cand[:, :MAX_SOLUTIONS], usable
    v = xsorted[bi, ri]
    new = np.ones(len(v), dtype=bool)  # a multiple root comes out as a cluster of nearby roots
    new[1:] = (bi[1:] != bi[:-1]) | (np.abs(v[1:] - v[:-1]) > CLUSTER_TOL * (1 + np.abs(v[1:])))
    starts = np.flatnonzero(new)
    k = np.diff(np.append(starts, len(v)))  # multiplicity
    xs = np.add.reduceat(v, starts) / k  # the centre of each cluster
    bi = bi[starts]
    t3 = 2 * np.arctan(xs) + form.delta
    nu, alone = _null_vectors(S, bi, xs)
    simple = (k == 1) & alone
    t4, t5 = _angle_pairs(nu[simple])
    rows_b, rows_t = [bi[simple]], [np.stack([t3[simple], t4, t5], -1)]
    for n in np.flatnonzero(~simple):  # multiple roots: solve for (θ4, θ5) at the known θ3
        E3 = np.einsum("pak,a->pk", S.E[bi[n]], _trig(t3[n]))
        pairs = _pairs_at(E3, rng)
        rows_b.append(np.full(len(pairs), bi[n]))
        rows_t.append(np.column_stack([np.full(len(pairs), t3[n]), pairs]))
    rows_b = np.concatenate(rows_b)
    t3, t4, t5 = np.concatenate(rows_t).T
    # θ1, θ2 from the eliminated products: Q n = P(θ3) m(θ4, θ5)
    m = (_trig(t4)[:, :, None] * _trig(t5)[:, None, :]).reshape(-1, 9)
    lhs = ((S.P[rows_b] @ m[:, None, :, None])[..., 0] @ _trig(t3)[..., None])[..., 0]  # (n, 14)
    n = (S.Qpinv[rows_b] @ lhs[..., None])[..., 0]  # columns 3d + e − 1 of (1, s1, c1) ⊗ (1, s2, c2)
    t1 = np.arctan2(n[:, 2], n[:, 5])
    t2 = np.arctan2(n[:, 0], n[:, 1])
    Gr = Gf[rows_b]
    M = _rz(t1) @ Gr[:, 0] @ _rz(t2) @ Gr[:, 1] @ _rz(t3) @ Gr[:, 2] @ _rz(t4) @ Gr[:, 3] @ _rz(t5) @ Gr[:, 4]
    Z6 = inverse_transform(M) @ S.W[rows_b]
    t6 = np.arctan2(Z6[:, 1, 0], Z6[:, 0, 0])
    theta = form.back(np.stack([t1, t2, t3, t4, t5, t6], axis=-1))
    order = np.argsort(rows_b, kind="stable")
    rb = rows_b[order]
    first = np.searchsorted(rb, rb)  # slot = position within the target's group
    slot = np.arange(len(rb)) - first
    keep = slot < cand.shape[1]
    cand[rb[keep], slot[keep]] = theta[order][keep]
    used = int(slot.max()) + 1 if len(slot) else 0
    return cand[:, : max(MAX_SOLUTIONS, used)], usable


def choose_formulation(chain: Screws, rng: np.random.Generator, tries: int = 4) -> Formulation | None:
    """The best-conditioned formulation for this arm, or None if every one degenerates.

    Each formulation solves ``tries`` targets made from random configurations; its score is the worst
    distance between a generating configuration and its nearest candidate (before any polishing).  Special
    arms make some formulations singular and others ill-conditioned (every root double, as when the joint
    playing θ3 cannot tell a wrist flip); the lowest score wins, and only a score under 1e-6 counts."""
    ranked = rank_formulations(chain, rng, tries)
    return ranked[0] if ranked else None


def rank_formulations(chain: Screws, rng: np.random.Generator, tries: int = 4) -> list[Formulation]:
    """Every formulation that solves the ``tries`` test targets (score under 1e-6, see
    :func:`choose_formulation`), best first.  The later ones are the fall-backs for targets where the first one's
    pencil is singular: on special arms (axes 2-4 parallel, say) a formulation can be regular for most poses
    and singular for a few, which the test targets need not show."""

    q = rng.uniform(-np.pi, np.pi, (tries, 6))
    G = loop_of(chain, screw_pose(chain, q))
    scored = []
    for form in formulations():
        cand, usable = solve_general(G, form, np.random.default_rng(11))
        if not usable.all():
            continue
        d = np.abs(np.angle(np.exp(1j * (cand - q[:, None])))).max(axis=-1)
        score = float(np.max(np.min(np.where(np.isfinite(d), d, np.inf), axis=1)))
        if score < 1e-6:
            scored.append((score, len(scored), form))
    return [f for _, _, f in sorted(scored)]
