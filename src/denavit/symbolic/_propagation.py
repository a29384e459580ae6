"""Craig's propagation, symbolic: ω_i, v_i outward and f_i, n_i inward, every step kept for display.

Frames are labelled ``"0" … "N"`` (one per DH row, fixed rows included) and ``"e"`` when the robot has a
non-identity tool transform. The equations are those of :mod:`denavit.numeric._propagation`
(Craig 3rd ed. eqs. 5.45–5.47 and 5.80–5.81; for standard DH the joint acts about ẑ_{i-1}).
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import numpy as np
import sympy as sp

from ..model import Convention, DHRobot, JointType
from ._kinematics import link_matrices_sym
from ._symbols import joint_symbols, matrix_from_floats

__all__ = ["VelocityStep", "VelocityPropagationSym", "ForceStep", "ForcePropagationSym",
           "velocity_propagation_sym", "force_propagation_sym", "wrench_symbols", "chain_sym"]

ZHAT = sp.ImmutableMatrix([0, 0, 1])


@dataclass(frozen=True)
class VelocityStep:
    """One outward step to frame ``label``: R = R_{prev,label}, P = origin of {label} in {prev}.

    ``joint`` is "revolute", "prismatic" or None (fixed row / tool); ``rate`` its symbol (qdk) or None;
    ``omega`` and ``v`` are 3×1 in the axes of {label}.
    """

    label: str
    R: sp.ImmutableMatrix
    P: sp.ImmutableMatrix
    joint: str | None
    rate: sp.Symbol | None
    omega: sp.ImmutableMatrix
    v: sp.ImmutableMatrix


@dataclass(frozen=True)
class VelocityPropagationSym:
    """Outward propagation, with the tool-frame Jacobian Je read off the last step (rows v, ω)."""

    convention: Convention
    steps: tuple[VelocityStep, ...]
    Je: sp.ImmutableMatrix
    q: tuple[sp.Symbol, ...]
    qd: tuple[sp.Symbol, ...]


@dataclass(frozen=True)
class ForceStep:
    """One inward step to frame ``label`` (R = R_{label,next}, P = origin of {next} in {label}); f, n 3×1
    in {label} axes at its origin; ``tau`` the joint torque/force read here (or None)."""

    label: str
    R: sp.ImmutableMatrix
    P: sp.ImmutableMatrix
    f: sp.ImmutableMatrix
    n: sp.ImmutableMatrix
    joint: int | None
    tau: sp.Expr | None


@dataclass(frozen=True)
class ForcePropagationSym:
    """Inward propagation from the end-effector wrench (fx, fy, fz, nx, ny, nz) in tool axes.

    ``steps`` run from the end effector inward; ``tau`` (n×1) equals Jeᵀ F.
    """

    steps: tuple[ForceStep, ...]
    tau: sp.ImmutableMatrix
    wrench: tuple[sp.Symbol, ...]


def wrench_symbols() -> tuple[sp.Symbol, ...]:
    """fx, fy, fz, nx, ny, nz as real symbols."""
    return tuple(sp.symbols("f_x f_y f_z n_x n_y n_z", real=True))


def chain_sym(robot: DHRobot, numeric: bool = False) -> list[tuple[str, sp.ImmutableMatrix, str | None, int | None]]:
    """(label, A, joint kind, joint index) per row, plus the tool as ("e", tool, None, None) if not identity."""
    out = []
    k = 0
    for i, (link, A) in enumerate(zip(robot.links, link_matrices_sym(robot, numeric)), start=1):
        kind = link.joint.value if link.is_joint else None
        out.append((str(i), A, kind, k if link.is_joint else None))
        k += link.is_joint
    if not np.allclose(robot.tool_matrix, np.eye(4), atol=0):
        out.append(("e", matrix_from_floats(robot.tool_matrix), None, None))
    return out


def _cross(a: sp.MatrixBase, b: sp.MatrixBase) -> sp.ImmutableMatrix:
    return sp.ImmutableMatrix(a.cross(b))


@lru_cache(maxsize=32)
def velocity_propagation_sym(robot: DHRobot, simplify: str = "trig", numeric: bool = False) -> VelocityPropagationSym:
    """Symbolic outward velocity propagation from the resting base {0} to the end effector.

    Examples
    --------
    >>> import denavit, denavit.symbolic as S
    >>> prop = S.velocity_propagation_sym(denavit.load_robot("report004-1-planar2r"))
    >>> prop.steps[-1].v.T
    Matrix([[L1*qd1*sin(q2), L1*qd1*cos(q2) + L2*qd1 + L2*qd2, 0]])
    """
    from ._jacobians import simplify_kinematic

    js = joint_symbols(robot.dof)
    std = robot.convention is Convention.STANDARD
    w = v = sp.ImmutableMatrix([0, 0, 0])
    steps = [VelocityStep("0", sp.ImmutableMatrix(sp.eye(3)), sp.ImmutableMatrix([0, 0, 0]), None, None, w, v)]
    for label, A, kind, k in chain_sym(robot, numeric):
        R, P = A[:3, :3], A[:3, 3]
        rate = js.qd[k] if k is not None else None
        rw = rate * ZHAT if kind == JointType.REVOLUTE.value else sp.zeros(3, 1)
        rv = rate * ZHAT if kind == JointType.PRISMATIC.value else sp.zeros(3, 1)
        if std:
            w_link = w + rw
            v = R.T * (v + rv + _cross(w_link, P))
            w = R.T * w_link
        else:  # Craig 5.45, 5.47
            v = R.T * (v + _cross(w, P)) + rv
            w = R.T * w + rw
        w, v = simplify_kinematic(w, simplify, js.q), simplify_kinematic(v, simplify, js.q)
        steps.append(VelocityStep(label, sp.ImmutableMatrix(R), sp.ImmutableMatrix(P), kind, rate, w, v))
    twist = sp.Matrix.vstack(v, w)
    Je = sp.ImmutableMatrix(twist.jacobian(js.qd))
    return VelocityPropagationSym(robot.convention, tuple(steps), simplify_kinematic(Je, simplify, js.q), js.q, js.qd)


@lru_cache(maxsize=32)
def force_propagation_sym(robot: DHRobot, simplify: str = "trig", numeric: bool = False) -> ForcePropagationSym:
    """Symbolic inward force propagation of the wrench (f, n) the end effector exerts, given in tool axes."""
    from ._jacobians import simplify_kinematic

    q = joint_symbols(robot.dof).q
    W = wrench_symbols()
    f, n = sp.ImmutableMatrix(W[:3]), sp.ImmutableMatrix(W[3:])
    chain = chain_sym(robot, numeric)
    labels = ["0"] + [c[0] for c in chain]
    shift = 0 if robot.convention is Convention.STANDARD else 1
    axis_frame = {r + shift: k for k, r in enumerate(robot.joint_rows)}  # frame index → joint index
    types = robot.joint_types
    taus: list[sp.Expr | None] = [None] * robot.dof

    def read(idx: int, f, n):
        k = axis_frame.get(idx)
        if k is None:
            return None, None
        tau = n[2] if types[k] is JointType.REVOLUTE else f[2]
        taus[k] = tau
        return k, tau

    k, tau = read(len(labels) - 1, f, n)
    steps = [ForceStep(labels[-1], sp.ImmutableMatrix(sp.eye(3)), sp.ImmutableMatrix([0, 0, 0]), f, n, k, tau)]
    for idx in range(len(chain) - 1, -1, -1):  # Craig 5.80, 5.81
        A = chain[idx][1]
        R, P = A[:3, :3], A[:3, 3]
        f = simplify_kinematic(R * f, simplify, q)
        n = simplify_kinematic(R * n + _cross(P, f), simplify, q)
        k, tau = read(idx, f, n)
        steps.append(ForceStep(labels[idx], sp.ImmutableMatrix(R), sp.ImmutableMatrix(P), f, n, k, tau))
    return ForcePropagationSym(tuple(steps), sp.ImmutableMatrix(taus), W)
