"""Symbolic equations of motion M(q) q̈ + C(q, q̇) q̇ + g(q) (+ τ_f) = τ, and their compact display.

The fast route (:func:`lagrangian_dynamics`) is the Lagrangian one written with Jacobians:
K = ½ q̇ᵀ M q̇ with M = Σ m J_vᵀ J_v + J_ωᵀ R I Rᵀ J_ω over the inertial pieces, P = −Σ m gᵀ p_c, so that
the Euler–Lagrange equations give g = ∂P/∂q = −Σ m J_vᵀ g and the velocity terms follow from the Christoffel
symbols of M (Spong, Hutchinson, Vidyasagar 2006, sec. 7.3, eqs. 7.50–7.58).  Each entry of M is collapsed
with the "trig" policy as it is formed, which keeps the result small and is what makes the Puma 560 quick.
The literal route with every step a report shows is :func:`denavit.symbolic.lagrange_steps`; the
Newton–Euler route is :func:`denavit.symbolic.newton_euler_dynamics`.

Frames: positions and axes are in the base DH frame {0}; gravity is ``robot.gravity`` turned into {0} axes
by the base rotation.  Bodies and pieces as in :mod:`denavit.numeric._dynamics` (a fixed row's inertia is
carried by the preceding moving link).
"""
from __future__ import annotations

from typing import Callable

import sympy as sp

from ..chain import chain_of
from ..model import DHRobot, JointType
from ._kinematics import link_matrices_sym
from ._dynamics_data import friction_vector, gravity_base, inertial_pieces, joint_parameters
from ._dynamics_trig import collect_trig, fourier_form
from ._dynamics_types import DynamicsTerms, InertialPiece, Progress, report_progress
from ._simplify import POLICIES, simplify_expr
from ._symbols import joint_symbols

__all__ = [
    "lagrangian_dynamics",
    "christoffel_symbols",
    "christoffel_matrix",
    "terms_from_tau",
    "make_simplifier",
]


def make_simplifier(robot: DHRobot, policy: str) -> Callable[[sp.Expr], sp.Expr]:
    """The simplification used for dynamics terms.

    ``"trig"`` is the canonical Fourier form in the revolute joint angles
    (:func:`~denavit.symbolic._dynamics_trig.fourier_form`: c2·c23 + s2·s23 → cos q3); ``"none"`` leaves
    entries as formed; ``"full"`` is sympy's ``simplify`` (slow).
    """
    if policy not in POLICIES:
        raise ValueError(f"unknown simplification policy {policy!r}; choose one of {', '.join(POLICIES)}")
    q = joint_symbols(robot.dof).q
    revolute = tuple(t is JointType.REVOLUTE for t in robot.joint_types)
    if policy == "trig":
        return lambda e: fourier_form(e, q, revolute)
    return lambda e: simplify_expr(e, policy)


def _collector(robot: DHRobot, policy: str) -> Callable[[sp.Expr], sp.Expr]:
    """For sums and derivatives of entries already simplified: a cheap collection for "trig"."""
    return collect_trig if policy == "trig" else make_simplifier(robot, policy)



def lagrangian_dynamics(robot: DHRobot, simplify: str = "trig", numeric: bool = False,
                        progress: Progress | None = None, coriolis: bool = True) -> DynamicsTerms:
    """Equations of motion by the Lagrangian route in Jacobian form, with C from Christoffel symbols.

    Parameters
    ----------
    robot : DHRobot
        With inertial data; named parameters (``m1``, ``Lc1``, ``I1``…) stay symbols unless ``numeric``.
    simplify : {"none", "trig", "full"}
        ``"trig"`` (default): computed on polynomials in the sines and cosines of the link angles
        (:mod:`~denavit.symbolic._dynamics_ring`: angle sums C23 for parallel axes, each entry a sum of
        parameter groups times sines and cosines; Puma 560 in about a second, Panda in under a minute);
        ``"none"``/``"full"``: the entries as formed by sympy, or through ``simplify`` (slow).
    progress : callable(stage, done, total), optional
        Called as the work proceeds (for long derivations).
    coriolis : bool
        Also form the matrix C (c is always formed).

    Notes
    -----
    .. math::
        M = \\sum_p m_p J_{v,p}^T J_{v,p} + J_{\\omega,p}^T R_p I_p R_p^T J_{\\omega,p},\\quad
        g = -\\sum_p m_p J_{v,p}^T g_0,\\quad
        C_{kj} = \\sum_i \\tfrac12 (\\partial_i M_{kj} + \\partial_j M_{ki} - \\partial_k M_{ij}) \\dot q_i

    (Spong, Hutchinson, Vidyasagar 2006, eqs. 7.46, 7.57; motor inertia adds to M's diagonal, eq. 7.97.)
    """
    js = joint_symbols(robot.dof)
    q, qd, qdd = js.q, js.qd, js.qdd
    if simplify == "trig":  # the same formulas on polynomials, in hand form (C23 …): _dynamics_ring
        from ._dynamics_ring import ring_dynamics

        M, C, c, g, size, g_unit = ring_dynamics(robot, numeric, coriolis, progress)
        report_progress(progress, "done", 1, 1)
        return DynamicsTerms(M, C, c, g, friction_vector(robot, qd, numeric), q, qd, qdd, "hand", size, g_unit)
    n = robot.dof
    pieces = inertial_pieces(robot, numeric)
    armature, _, _ = joint_parameters(robot, numeric)
    chain = _Chain(robot, numeric)
    simp = make_simplifier(robot, simplify)
    M = sp.zeros(n, n)
    total = n * (n + 1) // 2
    done = 0
    for j in range(n):
        for k in range(j, n):
            report_progress(progress, "mass matrix", done, total)
            done += 1
            e = sum((_mass_entry(robot, chain, p, j, k) for p in pieces if p.body >= k), sp.Integer(0))
            M[j, k] = M[k, j] = simp(e + (armature[j] if j == k else 0))
    M = sp.ImmutableMatrix(M)
    g = _gravity_vector(robot, chain, pieces, simp)
    gamma = christoffel_symbols(M, q, _collector(robot, simplify), progress)
    C = _coriolis_from_gamma(gamma, qd) if coriolis else None
    c = _velocity_from_gamma(gamma, qd)
    report_progress(progress, "done", 1, 1)
    return DynamicsTerms(M, C, c, g, friction_vector(robot, qd, numeric), q, qd, qdd)


class _Chain:
    """Relative transforms T_a_b = A_{a+1} ⋯ A_b between DH frames, built once (rows and axis frames from
    :mod:`denavit.chain`)."""

    def __init__(self, robot: DHRobot, numeric: bool) -> None:
        self.A = link_matrices_sym(robot, numeric)
        self.cache: dict[tuple[int, int], sp.ImmutableMatrix] = {}
        self.axis_frame = list(chain_of(robot).axis_frame)

    def __call__(self, a: int, b: int) -> sp.ImmutableMatrix:
        if (a, b) not in self.cache:
            if b == a:
                T = sp.ImmutableMatrix(sp.eye(4))
            else:
                T = sp.ImmutableMatrix(self(a, b - 1) * self.A[b - 1])
            self.cache[a, b] = T
        return self.cache[a, b]


def _jacobian_column(robot: DHRobot, chain: _Chain, p: InertialPiece, ref: int, j: int):
    """(v, ω_local) of piece p for unit rate of joint j, v in the axes of frame {ref}, ω in the piece's axes."""
    a = chain.axis_frame[j]
    T_rp = chain(ref, p.row + 1)
    c = T_rp[:3, :3] * p.com + T_rp[:3, 3]  # COM in {ref}
    T_ra = chain(ref, a)
    z, o = T_ra[:3, 2], T_ra[:3, 3]
    if robot.joint_types[j] is JointType.PRISMATIC:
        return z, sp.zeros(3, 1)
    w_local = chain(a, p.row + 1)[2, :3].T  # ẑ of axis j in the piece's axes: R_a_pᵀ ẑ
    return z.cross(c - o), w_local


def _mass_entry(robot: DHRobot, chain: _Chain, p: InertialPiece, j: int, k: int) -> sp.Expr:
    """Piece p's part of M_jk (j ≤ k), worked in the axis frame of joint j, where M_jk needs no q_1…q_j."""
    ref = chain.axis_frame[j]
    vj, wj = _jacobian_column(robot, chain, p, ref, j)
    vk, wk = _jacobian_column(robot, chain, p, ref, k)
    return p.mass * vj.dot(vk) + (wj.T * p.inertia * wk)[0]


def _gravity_vector(robot: DHRobot, chain: _Chain, pieces, simp) -> sp.ImmutableMatrix:
    """g_j = −Σ m (z_j × (c − o_j))·g, each term in the axis frame of joint j (gravity turned into it)."""
    g0 = gravity_base(robot)
    out = []
    for j in range(robot.dof):
        ref = chain.axis_frame[j]
        g_ref = chain(0, ref)[:3, :3].T * g0
        e = sum((-p.mass * _jacobian_column(robot, chain, p, ref, j)[0].dot(g_ref) for p in pieces if p.body >= j),
                sp.Integer(0))
        out.append(simp(e))
    return sp.ImmutableMatrix(out)


def christoffel_symbols(M: sp.MatrixBase, q, simp: Callable[[sp.Expr], sp.Expr] = sp.expand,
                        progress: Progress | None = None) -> dict[tuple[int, int, int], sp.Expr]:
    """Γ_ijk = ½(∂M_kj/∂q_i + ∂M_ki/∂q_j − ∂M_ij/∂q_k) for i ≤ j (Γ_ijk = Γ_jik), Spong eq. 7.51."""
    n = len(q)
    dM = {}
    for i in range(n):
        for j in range(n):
            for k in range(j, n):
                dM[i, j, k] = dM[i, k, j] = sp.diff(M[j, k], q[i])
    gamma = {}
    for k in range(n):
        report_progress(progress, "Christoffel symbols", k, n)
        for i in range(n):
            for j in range(i, n):
                gamma[i, j, k] = simp((dM[i, k, j] + dM[j, k, i] - dM[k, i, j]) / 2)
    return gamma


def _gamma(gamma, i, j, k):
    return gamma[(i, j, k) if i <= j else (j, i, k)]


def christoffel_matrix(M: sp.MatrixBase, q, qd, simp: Callable[[sp.Expr], sp.Expr] = sp.expand,
                       progress: Progress | None = None) -> sp.ImmutableMatrix:
    """C(q, q̇) with C_kj = Σ_i Γ_ijk q̇_i (Spong eq. 7.52); Ṁ − 2C is skew-symmetric."""
    gamma = christoffel_symbols(M, q, simp, progress)
    return _coriolis_from_gamma(gamma, qd)


def _coriolis_from_gamma(gamma, qd) -> sp.ImmutableMatrix:
    n = len(qd)
    return sp.ImmutableMatrix(n, n, [sum((_gamma(gamma, i, j, k) * qd[i] for i in range(n)), sp.Integer(0))
                                     for k in range(n) for j in range(n)])


def _velocity_from_gamma(gamma, qd) -> sp.ImmutableMatrix:
    """c_k = Σ_{i≤j} (2 − δ_ij) Γ_ijk q̇_i q̇_j, each coefficient kept as simplified."""
    n = len(qd)
    return sp.ImmutableMatrix([
        sum(((1 if i == j else 2) * gamma[i, j, k] * qd[i] * qd[j] for i in range(n) for j in range(i, n)),
            sp.Integer(0))
        for k in range(n)])


def terms_from_tau(tau: sp.MatrixBase, q, qd, qdd, friction: sp.MatrixBase,
                   simp: Callable[[sp.Expr], sp.Expr] = sp.expand, coriolis: bool = True) -> DynamicsTerms:
    """Split τ(q, q̇, q̈) (friction excluded) into M = ∂τ/∂q̈, g = τ|_{q̇=q̈=0}, c = τ − M q̈ − g."""
    n = len(q)
    zero = {**{s: 0 for s in qd}, **{s: 0 for s in qdd}}
    tau = [sp.expand(t) for t in tau]
    M = sp.ImmutableMatrix(n, n, [simp(tau[k].diff(qdd[j])) for k in range(n) for j in range(n)])
    g = sp.ImmutableMatrix([simp(tau[k].subs(zero)) for k in range(n)])
    c = sp.ImmutableMatrix([simp(tau[k].subs({s: 0 for s in qdd}) - g[k]) for k in range(n)])
    C = christoffel_matrix(M, q, qd, simp) if coriolis else None
    return DynamicsTerms(M, C, c, g, sp.ImmutableMatrix(friction), tuple(q), tuple(qd), tuple(qdd))
