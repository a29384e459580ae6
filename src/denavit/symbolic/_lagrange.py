"""The Lagrangian derivation step by step, as a person writes it (and as reports print it).

p_ci → ṗ_ci (chain rule) → ω_i → K_i, P_i → L = K − P → ∂L/∂q̇ → d/dt ∂L/∂q̇ → ∂L/∂q → τ.
Time derivatives use the chain rule d/dt f = Σ ∂f/∂q_i q̇_i + ∂f/∂q̇_i q̈_i, never sympy ``Function(t)``,
so every step prints and lambdifies in the plain symbols q1…, qd1…, qdd1….
Meant for arms of a few joints: for a 6-joint arm use :func:`lagrangian_dynamics` (same result, faster).

References
----------
M. W. Spong, S. Hutchinson, M. Vidyasagar, *Robot Modeling and Control*, 2006, sec. 7.1–7.4.
"""

from __future__ import annotations

from dataclasses import dataclass

import sympy as sp

from ..model import DHRobot, JointType
from ._dynamics import make_simplifier, terms_from_tau
from ._dynamics_data import friction_vector, gravity_base, inertial_pieces, joint_axes_sym, joint_parameters
from ._dynamics_types import DynamicsTerms, Progress, report_progress
from ._kinematics import link_transforms_sym
from ._symbols import joint_symbols

__all__ = ["LagrangeSteps", "lagrange_steps", "time_derivative"]


def time_derivative(expr, q, qd, qdd=None):
    """d/dt of an expression (or matrix) in q, q̇ by the chain rule Σ ∂/∂q_i·q̇_i (+ ∂/∂q̇_i·q̈_i)."""
    out = sum((sp.diff(expr, qi) * qdi for qi, qdi in zip(q, qd)), sp.zeros(*expr.shape) if hasattr(expr, "shape") else 0)
    if qdd is not None:
        out = out + sum((sp.diff(expr, qdi) * qddi for qdi, qddi in zip(qd, qdd)),
                        sp.zeros(*expr.shape) if hasattr(expr, "shape") else 0)
    return out


@dataclass(frozen=True)
class LagrangeSteps:
    """Every step of the Lagrangian derivation (all sympy, frame {0} axes).

    ``pieces[i]`` is (row, joint) of the i-th inertial piece; ``p_c``, ``pd_c``, ``omega``, ``K_parts``,
    ``P_parts`` follow that order (``K_parts`` ends with the motors' ½ I_m q̇² when present).
    ``tau`` holds the equations τ_k = d/dt ∂L/∂q̇_k − ∂L/∂q_k + τ_f,k; ``terms`` splits them into M, C, c, g.
    """

    q: tuple[sp.Symbol, ...]
    qd: tuple[sp.Symbol, ...]
    qdd: tuple[sp.Symbol, ...]
    pieces: tuple[tuple[int, int], ...]
    gravity: sp.ImmutableMatrix
    p_c: tuple[sp.ImmutableMatrix, ...]
    pd_c: tuple[sp.ImmutableMatrix, ...]
    omega: tuple[sp.ImmutableMatrix, ...]
    K_parts: tuple[sp.Expr, ...]
    P_parts: tuple[sp.Expr, ...]
    K: sp.Expr
    P: sp.Expr
    L: sp.Expr
    dL_dqd: tuple[sp.Expr, ...]
    ddt_dL_dqd: tuple[sp.Expr, ...]
    dL_dq: tuple[sp.Expr, ...]
    tau: sp.ImmutableMatrix
    terms: DynamicsTerms


def lagrange_steps(robot: DHRobot, simplify: str = "trig", numeric: bool = False,
                   progress: Progress | None = None) -> LagrangeSteps:
    """The Euler–Lagrange equations d/dt ∂L/∂q̇ − ∂L/∂q = τ, derived literally, every step kept.

    Parameters
    ----------
    robot : DHRobot
        With inertial data; parameters stay symbols unless ``numeric``.
    simplify : {"none", "trig", "full"}
        Policy for each step ("trig": canonical sums of cos/sin of joint-angle combinations).
    """
    js = joint_symbols(robot.dof)
    q, qd, qdd = js.q, js.qd, js.qdd
    simp = make_simplifier(robot, simplify)
    vsimp = lambda M: sp.ImmutableMatrix(M.applyfunc(simp))  # noqa: E731
    T = link_transforms_sym(robot, "trig", numeric)
    axes = joint_axes_sym(robot, T)
    g0 = gravity_base(robot)
    pieces = inertial_pieces(robot, numeric)
    p_c, pd_c, omega, K_parts, P_parts = [], [], [], [], []
    for idx, p in enumerate(pieces):
        report_progress(progress, "Lagrange: energies", idx, len(pieces))
        F = T[p.row + 1]
        R = F[:3, :3]
        pc = vsimp(R * p.com + F[:3, 3])
        pdc = vsimp(time_derivative(pc, q, qd))
        w = sp.zeros(3, 1)
        for j in range(p.body + 1):
            if robot.joint_types[j] is JointType.REVOLUTE:
                w += axes[j][0] * qd[j]
        w = vsimp(w)
        Iw = R * p.inertia * R.T
        p_c.append(pc)
        pd_c.append(pdc)
        omega.append(w)
        K_parts.append(simp(p.mass * (pdc.T * pdc)[0] / 2 + (w.T * Iw * w)[0] / 2))
        P_parts.append(simp(-p.mass * (g0.T * pc)[0]))
    armature, _, _ = joint_parameters(robot, numeric)
    motor = sum((armature[k] * qd[k] ** 2 / 2 for k in range(robot.dof)), sp.Integer(0))
    if motor != 0:
        K_parts.append(motor)
    K = simp(sp.Add(*K_parts))
    P = simp(sp.Add(*P_parts))
    L = K - P
    report_progress(progress, "Lagrange: Euler-Lagrange equations", 0, 1)
    dL_dqd = tuple(simp(sp.diff(L, s)) for s in qd)
    ddt = tuple(simp(time_derivative(e, q, qd, qdd)) for e in dL_dqd)
    dL_dq = tuple(simp(sp.diff(L, s)) for s in q)
    friction = friction_vector(robot, qd, numeric)
    rigid = [simp(a - b) for a, b in zip(ddt, dL_dq)]
    tau = sp.ImmutableMatrix([r + f for r, f in zip(rigid, friction)])
    terms = terms_from_tau(sp.Matrix(rigid), q, qd, qdd, friction, simp)
    report_progress(progress, "done", 1, 1)
    return LagrangeSteps(
        q, qd, qdd, tuple((p.row, p.body) for p in pieces), g0, tuple(p_c), tuple(pd_c), tuple(omega),
        tuple(K_parts), tuple(P_parts), K, P, L, dL_dqd, ddt, dL_dq, tau, terms,
    )
