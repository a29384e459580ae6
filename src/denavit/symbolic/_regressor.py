"""The regressor of the symbolic dynamics, τ = Y(q, q̇, q̈) π, linear in the standard inertial parameters
(Khalil & Dombre 2002, sec. 9.3), computed on the rings of :mod:`~denavit.symbolic._dynamics_ring`."""

from __future__ import annotations

from functools import lru_cache

import sympy as sp

from ..model import DHRobot, JointType
from ._dynamics_ring import RingDynamics, ring_cross, ring_dot
from ._hand_terms import hand_terms
from ._rings import TrigRing
from ._symbols import joint_symbols

__all__ = ["PARAMETER_NAMES", "regressor_sym"]

# --- the regressor: τ = Y(q, q̇, q̈) π, linear in the standard inertial parameters ---------------------------

PARAMETER_NAMES = ("m", "hx", "hy", "hz", "Jxx", "Jyy", "Jzz", "Jxy", "Jxz", "Jyz")
"""Standard inertial parameters of a piece (Khalil & Dombre 2002, sec. 9.3): mass, first moment h = m c and
inertia J about the origin of its DH frame, J = I_c + m(|c|² 1 − c cᵀ) (parallel axis theorem), in frame {row}."""


def _linear_entry(D: RingDynamics, rg: TrigRing, T, j: int, k: int, pis: list):
    """M_jk (j ≤ k) linear in each piece's (m, h, J): m v0_j·v0_k + v0_j·(z_k × R h) + v0_k·(z_j × R h) + w_jᵀ J w_k,
    v0 = z × (o_p − o) (the frame origin of the piece instead of its COM)."""
    ref, zero = D.axis[j], rg.R.zero
    e = zero
    for p, pi in zip(D.pieces, pis):
        if p.body < k:
            continue
        m, h, J = pi[0], pi[1:4], [[pi[4], pi[7], pi[8]], [pi[7], pi[5], pi[9]], [pi[8], pi[9], pi[6]]]
        Tp = T(ref, p.row + 1)
        op = [Tp[i][3] for i in range(3)]
        Rh = [ring_dot(Tp[i][:3], h, zero) for i in range(3)]
        cols = []
        for jj in (j, k):
            Ta = T(ref, D.axis[jj])
            z, o = [Ta[i][2] for i in range(3)], [Ta[i][3] for i in range(3)]
            if D.robot.joint_types[jj] is JointType.PRISMATIC:
                cols.append((z, z, [zero] * 3, True))
            else:
                cols.append((ring_cross(z, [op[i] - o[i] for i in range(3)]), z, T(D.axis[jj], p.row + 1)[2][:3], False))
        (v0j, zj, wj, pj), (v0k, zk, wk, pk) = cols
        e += m * ring_dot(v0j, v0k, zero)
        if not pk:
            e += ring_dot(v0j, ring_cross(zk, Rh), zero)
        if not pj:
            e += ring_dot(v0k, ring_cross(zj, Rh), zero)
        e += ring_dot(wj, [ring_dot(J[r], wk, zero) for r in range(3)], zero)
    return rg.reduce(e)


@lru_cache(maxsize=8)
def regressor_sym(robot: DHRobot):
    """The regressor Y(q, q̇, q̈) with τ = Y π (friction excluded), and π as symbols.

    Returns ``(Y, pi)``: ``Y`` an n × (10 · pieces + n) sympy matrix in hand form, ``pi`` the symbols: for
    every inertial piece k (order of :func:`~denavit.symbolic.inertial_pieces`) its
    :data:`PARAMETER_NAMES` suffixed ``_k``, then the motor inertias ``Ia_1 … Ia_n``. The dynamics is linear in
    these (Khalil & Dombre 2002, sec. 9.3), which is what identification needs; the robot's own inertial values
    are not used, only its kinematics (and which rows carry inertia).

    Examples
    --------
    >>> import denavit
    >>> from denavit.symbolic import regressor_sym
    >>> Y, pi = regressor_sym(denavit.load_robot("planar2r"))
    >>> Y.shape, pi[:4]
    ((2, 22), (m_1, hx_1, hy_1, hz_1))
    """
    D = RingDynamics(robot, False)
    n = D.n
    js = joint_symbols(n)
    pis = [[sp.Symbol(f"{name}_{k + 1}", real=True) for name in PARAMETER_NAMES] for k in range(len(D.pieces))]
    arm = [sp.Symbol(f"Ia_{k + 1}", real=True) for k in range(n)]
    D._exprs += [s for pi in pis for s in pi] + arm
    rg, T = D.ring(0)
    rpis = [[rg.element(s) for s in pi] for pi in pis]
    M = {}
    for j in range(n):
        for k in range(j, n):
            M[j, k] = M[k, j] = _linear_entry(D, rg, T, j, k, rpis) + (rg.element(arm[j]) if j == k else rg.R.zero)
    dM = {(i, j, k): D.diff(rg, M[j, k], i) for i in range(n) for j in range(n) for k in range(n)}
    half = rg.R.domain.convert(sp.Rational(1, 2))
    g0 = [rg.element(x) for x in D.g0]
    allpi = [s for pi in pis for s in pi] + arm
    gens = [rg.gen_of(s) for s in allpi]
    Y = sp.zeros(n, len(allpi))
    for j in range(n):
        tau = {}  # per q̇/q̈ monomial: its polynomial coefficient
        for k in range(n):
            tau[js.qdd[k]] = M[j, k]
        for a in range(n):
            for b in range(a, n):
                G = (dM[a, j, b] + dM[b, j, a] - dM[j, a, b]) * half
                tau[js.qd[a] * js.qd[b]] = G * (1 if a == b else 2)
        grav = rg.R.zero
        for p, pi in zip(D.pieces, rpis):
            if p.body >= j:
                Tp = T(0, p.row + 1)
                op = [Tp[i][3] for i in range(3)]
                Rh = [ring_dot(Tp[i][:3], pi[1:4], rg.R.zero) for i in range(3)]
                if robot.joint_types[j] is JointType.PRISMATIC:
                    Ta = T(0, D.axis[j])
                    v = [Ta[i][2] * pi[0] for i in range(3)]
                else:
                    Ta = T(0, D.axis[j])
                    z, o = [Ta[i][2] for i in range(3)], [Ta[i][3] for i in range(3)]
                    v = ring_cross(z, [pi[0] * (op[i] - o[i]) + Rh[i] for i in range(3)])
                grav -= ring_dot(v, g0, rg.R.zero)
        tau[sp.Integer(1)] = grav
        for col, gen in enumerate(gens):
            Y[j, col] = sp.Add(*[hand_terms(rg, rg.reduce(poly.diff(gen))) * mono for mono, poly in tau.items() if poly])
    return sp.ImmutableMatrix(Y), tuple(allpi)
