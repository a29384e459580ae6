"""Symbolic recursive Newton–Euler: outward velocities and accelerations, inward forces and moments.

Each moving body k gets the frame B_k whose z axis is joint k's axis and whose origin lies on it:
standard DH B_k = {i−1}·Rz(θ_i)Tz(d_i), modified DH B_k = {i} (i the row of joint k).  Then, with R, p
the rotation and origin of B_k in B_{k−1} (Craig, *Introduction to Robotics*, 3rd ed., eqs. 6.45–6.53):

    ω_k = Rᵀω_{k−1} + q̇_k ẑ                         (revolute; ω_k = Rᵀω_{k−1} if prismatic)
    ω̇_k = Rᵀω̇_{k−1} + Rᵀω_{k−1} × q̇_k ẑ + q̈_k ẑ
    a_k = Rᵀ(a_{k−1} + ω̇_{k−1} × p + ω_{k−1} × (ω_{k−1} × p))   (+ 2 ω_k × q̇_k ẑ + q̈_k ẑ if prismatic)
    a_c = a_k + ω̇_k × c + ω_k × (ω_k × c),   F = m a_c,   N = I ω̇_k + ω_k × I ω_k
    f_k = R_{k+1} f_{k+1} + Σ F,   n_k = Σ (N + c × F) + R_{k+1} n_{k+1} + p_{k+1} × R_{k+1} f_{k+1}
    τ_k = ẑ·n_k (revolute) or ẑ·f_k (prismatic),  plus I_m q̈_k + τ_f,k

with a_0 = −g (gravity in {0}) so that gravity enters as an acceleration of the base.
"""

from __future__ import annotations

from dataclasses import dataclass

import sympy as sp

from ..chain import Symbolic, chain_of
from ..model import DHRobot, JointType
from ._dynamics import make_simplifier, terms_from_tau
from ._dynamics_data import friction_vector, gravity_base, inertial_pieces, joint_parameters
from ._dynamics_types import DynamicsTerms, Progress, report_progress
from ._symbols import joint_symbols

__all__ = ["NewtonEulerSteps", "newton_euler_dynamics"]

ZHAT = sp.ImmutableMatrix([0, 0, 1])


@dataclass(frozen=True)
class NewtonEulerSteps:
    """Per-body quantities in the body frames B_k (see module notes) and the joint torques.

    ``omega``, ``omega_dot``, ``acc`` (of B_k's origin) and ``f``, ``n`` (exerted on body k by body k−1, at
    B_k's origin) are one 3-vector per joint; ``transforms`` are T_{B_{k−1}, B_k}; ``tau`` includes motor
    inertia and friction; ``terms`` is the split into M, C, c, g.
    """

    q: tuple[sp.Symbol, ...]
    qd: tuple[sp.Symbol, ...]
    qdd: tuple[sp.Symbol, ...]
    transforms: tuple[sp.ImmutableMatrix, ...]
    omega: tuple[sp.ImmutableMatrix, ...]
    omega_dot: tuple[sp.ImmutableMatrix, ...]
    acc: tuple[sp.ImmutableMatrix, ...]
    f: tuple[sp.ImmutableMatrix, ...]
    n: tuple[sp.ImmutableMatrix, ...]
    tau: sp.ImmutableMatrix
    terms: DynamicsTerms


def _body_frames(robot: DHRobot, numeric: bool):
    """T_{B_{k−1},B_k} for every joint, and each row's frame {r} relative to its body frame.

    The body frame B_k ends the head of joint k's row (:meth:`denavit.chain.Symbolic.split`)."""
    chain = chain_of(robot)
    rows = Symbolic(chain, numeric)
    q = joint_symbols(robot.dof).q
    steps, in_body = [], {}
    current = sp.eye(4)  # pose of the frame reached so far, relative to the last body frame
    for i, row in enumerate(chain.rows):
        if row.joint >= 0:
            head, tail = rows.split(chain, i, q)
            steps.append(current * sp.Matrix(head))
            current = sp.Matrix(tail)
        else:
            current = current * sp.Matrix(rows.matrix(chain, i, q))
        in_body[i] = current  # frame {i} relative to the body frame of its joint
    return steps, in_body


def newton_euler_dynamics(robot: DHRobot, simplify: str = "trig", numeric: bool = False,
                          progress: Progress | None = None) -> NewtonEulerSteps:
    """Joint torques τ(q, q̇, q̈) by the symbolic recursive Newton–Euler algorithm (see module notes)."""
    js = joint_symbols(robot.dof)
    qd, qdd = js.qd, js.qdd
    n = robot.dof
    simp = make_simplifier(robot, simplify)
    vs = lambda v: sp.ImmutableMatrix(sp.Matrix(v).applyfunc(simp))  # noqa: E731
    steps, in_body = _body_frames(robot, numeric)
    pieces = inertial_pieces(robot, numeric)
    w, wd, a = sp.zeros(3, 1), sp.zeros(3, 1), -sp.Matrix(gravity_base(robot))
    W, WD, ACC, F_body, N_body = [], [], [], [], []
    for k in range(n):
        report_progress(progress, "Newton-Euler: outward", k, n)
        R, p = steps[k][:3, :3], steps[k][:3, 3]
        a = R.T * (a + wd.cross(p) + w.cross(w.cross(p)))
        wd, w = R.T * wd, R.T * w
        if robot.joint_types[k] is JointType.REVOLUTE:
            wd = wd + w.cross(qd[k] * ZHAT) + qdd[k] * ZHAT
            w = w + qd[k] * ZHAT
        else:
            a = a + 2 * w.cross(qd[k] * ZHAT) + qdd[k] * ZHAT
        w, wd, a = vs(w), vs(wd), vs(a)
        W.append(w), WD.append(wd), ACC.append(a)
        fk, nk = sp.zeros(3, 1), sp.zeros(3, 1)
        for piece in (pc for pc in pieces if pc.body == k):
            X = in_body[piece.row]
            c = X[:3, :3] * piece.com + X[:3, 3]
            I = X[:3, :3] * piece.inertia * X[:3, :3].T
            F = piece.mass * (a + wd.cross(c) + w.cross(w.cross(c)))
            fk += F
            nk += I * wd + w.cross(I * w) + c.cross(F)
        F_body.append(fk), N_body.append(nk)
    return _inward(robot, js, steps, W, WD, ACC, F_body, N_body, simp, numeric, progress)


def _inward(robot, js, steps, W, WD, ACC, F_body, N_body, simp, numeric, progress) -> NewtonEulerSteps:
    n = robot.dof
    q, qd, qdd = js.q, js.qd, js.qdd
    vs = lambda v: sp.ImmutableMatrix(sp.Matrix(v).applyfunc(simp))  # noqa: E731
    f_out, n_out = [None] * n, [None] * n
    f, m = sp.zeros(3, 1), sp.zeros(3, 1)
    rigid = [sp.Integer(0)] * n
    for k in range(n - 1, -1, -1):
        report_progress(progress, "Newton-Euler: inward", n - 1 - k, n)
        if k < n - 1:
            R, p = steps[k + 1][:3, :3], steps[k + 1][:3, 3]
            f_next = R * f
            m = R * m + p.cross(f_next)
            f = f_next
        f, m = vs(f + F_body[k]), vs(m + N_body[k])
        f_out[k], n_out[k] = f, m
        rigid[k] = m[2] if robot.joint_types[k] is JointType.REVOLUTE else f[2]
    armature, _, _ = joint_parameters(robot, numeric)
    rigid = [simp(r + armature[k] * qdd[k]) for k, r in enumerate(rigid)]
    friction = friction_vector(robot, qd, numeric)
    terms = terms_from_tau(sp.Matrix(rigid), q, qd, qdd, friction, simp)
    report_progress(progress, "done", 1, 1)
    return NewtonEulerSteps(q, qd, qdd, tuple(sp.ImmutableMatrix(s) for s in steps), tuple(W), tuple(WD),
                            tuple(ACC), tuple(f_out), tuple(n_out),
                            sp.ImmutableMatrix([r + fr for r, fr in zip(rigid, friction)]), terms)
