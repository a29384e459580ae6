"""The symbolic IK derivation of a 6-joint arm with a spherical wrist (kinematic decoupling): wrist centre,
q1 with the shoulder offset, q3 by the law of cosines (or a quadratic for a Stanford-type prismatic joint 3), q2,
then the wrist angles from R_3_6 (Spong, Hutchinson & Vidyasagar 2006, sec. 5.3-5.4; Craig 2005, sec. 4.7)."""

from __future__ import annotations

import numpy as np
import sympy as sp

from ..chain import chain_of
from ..errors import UnsupportedRobotError
from ..model import Convention, DHRobot, JointType
from ._ik_shared import (at_zero, axis_frame_of, cosine_law_steps, inverse_transform, matrix_product,
                         parameter_values, numeric_zero, simplify_trig, target_steps, target_symbols)
from ._ik_types import IKDerivation, IKStep
from ._kinematics import link_matrices_sym, link_transforms_sym
from ._symbols import joint_symbols, row_expressions

__all__ = ["decoupled_derivation"]


def decoupled_derivation(robot: DHRobot) -> IKDerivation:
    if robot.joint_rows != tuple(range(6)):
        raise UnsupportedRobotError(f"{robot.name}: the derivation needs the six joints in DH rows 1-6")
    if robot.joint_types[1] is not JointType.REVOLUTE or any(t is not JointType.REVOLUTE for t in robot.joint_types[3:]):
        raise UnsupportedRobotError(f"{robot.name}: joints 2, 4, 5, 6 must be revolute")
    rng = np.random.default_rng(7)
    q = joint_symbols(6).q
    N = robot.n_rows
    T = link_transforms_sym(robot, "trig")
    A = link_matrices_sym(robot)
    target = target_symbols()
    R, p = target[:3, :3], target[:3, 3]
    steps = target_steps(robot, target, N)

    # wrist centre: axis 4 ∩ axis 5, in frame {3} (Spong eq. 5.12: o_c = o − d6 R k)
    ax = chain_of(robot).axis_frame  # frames of axes 4 and 5 relative to {3}: A_4 ⋯ A_ax
    f4 = at_zero(matrix_product(A[3:ax[3]]), q)
    f5 = at_zero(matrix_product(A[3:ax[4]]), q)
    p1, d1, p2, d2 = f4[:3, 3], f4[:3, 2], f5[:3, 3], f5[:3, 2]
    n12 = d1.cross(d2)
    t = sp.simplify((p2 - p1).cross(d2).dot(n12) / n12.dot(n12))
    c3 = simplify_trig(p1 + t * d1)
    cN = simplify_trig((inverse_transform(at_zero(matrix_product(A[3:N]), q)) * c3.col_join(sp.Matrix([1])))[:3, 0])
    xc, yc, zc = sp.symbols("x_c y_c z_c", real=True)
    pc = sp.Matrix([xc, yc, zc])
    steps.append(IKStep("Wrist centre", pc, simplify_trig(p + R * cN),
                        f"Axes 4, 5, 6 meet at the wrist centre, the point {sp.sstr(list(cN))} of frame {{{N}}} "
                        f"(and {sp.sstr(list(c3))} of frame {{3}}); it depends on q1, q2, q3 only: "
                        "p_c = p + R c (kinematic decoupling).", assign=True))
    T03 = T[3]
    steps.append(IKStep("Position of the wrist centre by joints 1-3", pc, simplify_trig((T03 * c3.col_join(sp.Matrix([1])))[:3, 0]),
                        "Joint 1 turns about z0, so p_c = Rz(q1) g(q2, q3) with g = p_c at q1 = 0."))
    g = simplify_trig(at_zero((T03 * c3.col_join(sp.Matrix([1])))[:3, 0], q[:1]))
    F2 = at_zero(axis_frame_of(robot, T, 2), q[:2])
    u, o2 = F2[:3, 2], F2[:3, 3]
    if sp.simplify(u[2]) != 0:
        raise UnsupportedRobotError(f"{robot.name}: axis 2 is not perpendicular to axis 1")
    uperp = sp.Matrix([-u[1], u[0], 0])
    delta = simplify_trig(g.dot(u))
    if delta.free_symbols & set(q):
        delta = sp.simplify(delta)
    if delta.free_symbols & set(q):
        raise UnsupportedRobotError(f"{robot.name}: joint 3 moves the wrist centre along axis 2 (not an elbow or "
                                    "Stanford-type arm)")
    sig1 = sp.Symbol("sigma1", real=True)
    r, s = sp.symbols("r s", real=True)
    steps.append(IKStep("Offset along axis 2", sp.Symbol("delta"), delta,
                        f"Joints 2 and 3 cannot move the wrist centre along axis 2 (direction {sp.sstr(list(u))} at "
                        "q1 = 0): its component δ there is constant (the shoulder offset)."))
    steps.append(IKStep("Reach in the arm plane", r, sig1 * sp.sqrt(xc**2 + yc**2 - delta**2),
                        "The horizontal distance of p_c from axis 1 splits into δ along axis 2 and r across it; "
                        f"{sig1} = ±1: the two shoulder configurations (arm in front of / behind axis 1).",
                        assign=True))
    gx, gy = r * uperp[0] + delta * u[0], r * uperp[1] + delta * u[1]
    steps.append(IKStep("q1 (two shoulder branches)", q[0], sp.atan2(yc, xc) - sp.atan2(simplify_trig(gy), simplify_trig(gx)),
                        "Rz(q1) turns g = (g_x, g_y) at q1 = 0 onto (x_c, y_c): q1 = atan2(y_c, x_c) − atan2(g_y, g_x) "
                        "(Craig eq. 4.65; Spong eq. 5.19-5.22 for the offset case).", assign=True))
    steps.append(IKStep("Height", s, zc, "The height of p_c is not changed by joint 1.", assign=True))
    r0, s0 = simplify_trig(o2.dot(uperp)), simplify_trig(o2[2])
    vr = simplify_trig(at_zero(g.dot(uperp), q[1:2]) - r0)
    vs = simplify_trig(at_zero(g[2], q[1:2]) - s0)
    lhs_sq = (r - r0) ** 2 + (s - s0) ** 2
    if robot.joint_types[2] is JointType.REVOLUTE:
        more, sig3 = cosine_law_steps(lhs_sq, simplify_trig(sp.expand(vr**2 + vs**2)), q[2], robot, rng,
                                 "Law of cosines in the arm plane",
                                 f"Axis 2 passes through ({sp.sstr(r0)}, {sp.sstr(s0)}) of the arm plane (r, s); the "
                                 "squared distance of p_c from it depends on q3 only (Craig eq. 4.67-4.70; Spong eq. 5.24).")
        steps += more
    else:
        v0 = sp.Matrix([vr.subs(q[2], 0), vs.subs(q[2], 0)])
        w = sp.Matrix([sp.diff(vr, q[2]), sp.diff(vs, q[2])])
        a_, b_, c_ = simplify_trig(w.dot(w)), simplify_trig(v0.dot(w)), simplify_trig(v0.dot(v0))
        sig3 = sp.Symbol("sigma3", real=True)
        steps.append(IKStep("Distance from axis 2 (prismatic joint 3)", lhs_sq,
                            simplify_trig(a_ * q[2] ** 2 + 2 * b_ * q[2] + c_),
                            "The prismatic joint slides the wrist centre along a line across axis 2, so the squared "
                            "distance from axis 2 is a quadratic in q3 (Spong eq. 5.28-5.30, Stanford arm)."))
        steps.append(IKStep("q3 (two roots)", q[2],
                            simplify_trig((-b_ + sig3 * sp.sqrt(b_**2 - a_ * (c_ - lhs_sq))) / a_),
                            f"{sig3} = ±1: the two roots (usually only one lies within the joint limits).", assign=True))
    steps.append(IKStep("q2", q[1], sp.atan2(s - s0, r - r0) - sp.atan2(vs, vr),
                        "Joint 2 turns the vector (v_r, v_s)(q3) from axis 2 to p_c onto (r − r0, s − s0): "
                        "q2 = atan2(s − s0, r − r0) − atan2(v_s, v_r) (Spong eq. 5.25).", assign=True))
    steps += _wrist_steps(robot, T, A, R, q, N, rng)
    return IKDerivation(robot, "decoupled", tuple(steps), target,
                        (sig1, sig3, sp.Symbol("sigma5", real=True)), q, tuple(parameter_values(robot).items()))


def _rx(a):
    return sp.Matrix([[1, 0, 0], [0, sp.cos(a), -sp.sin(a)], [0, sp.sin(a), sp.cos(a)]])


def _rz(a):
    return sp.Matrix([[sp.cos(a), -sp.sin(a), 0], [sp.sin(a), sp.cos(a), 0], [0, 0, 1]])


def _wrist_steps(robot, T, A, R, q, N, rng) -> list[IKStep]:
    """R_3_6 = R_0_3ᵀ R and the ZYZ-like atan2 formulas of the orthogonal spherical wrist (Spong eq. 2.28-2.32)."""
    std = robot.convention is Convention.STANDARD
    rows = row_expressions(robot)
    th0 = [rows[k]["theta"].subs(q[k], 0) for k in range(6)]
    alpha = [rows[k]["alpha"] for k in range(N)]
    P = sp.eye(3) if std else _rx(alpha[3])
    a, b = (alpha[3], alpha[4]) if std else (alpha[4], alpha[5])
    S = sp.eye(3) if not std else _rx(alpha[5])
    S = S * matrix_product(A[6:N])[:3, :3]  # trailing fixed rows belong to the last frame
    if not all(x in (sp.pi / 2, -sp.pi / 2) for x in (a, b)):
        raise UnsupportedRobotError(f"{robot.name}: the wrist twists are not ±90° (only orthogonal spherical wrists "
                                    "are derived symbolically; analytic_ik solves the general case numerically)")
    ea, eb = (1 if a == sp.pi / 2 else -1), (1 if b == sp.pi / 2 else -1)
    th = [q[k] + th0[k] for k in (3, 4, 5)]
    R36 = simplify_trig(matrix_product(A[3:N])[:3, :3])
    model = _rz(th[0]) * _rx(a) * _rz(th[1]) * _rx(b) * _rz(th[2])
    if not all(numeric_zero(e, robot, q[3:], rng) for e in (P.T * R36 * S.T - model)):
        raise UnsupportedRobotError(f"{robot.name}: R_3_6 does not factor as Rz Rx Rz Rx Rz")
    R03 = T[3][:3, :3]
    m = sp.Matrix(3, 3, sp.symbols("m11 m12 m13 m21 m22 m23 m31 m32 m33", real=True))
    sig5 = sp.Symbol("sigma5", real=True)
    pre = "" if P == sp.eye(3) else "Rx(α)ᵀ "
    post = "" if S == sp.eye(3) else " S⁻¹"
    steps = [
        IKStep("Orientation of frame {3}", sp.Symbol("R_0_3"), R03,
               "q1, q2, q3 are known now, so R_0_3 is a known matrix."),
        IKStep("What the wrist must do", m, simplify_trig(P.T * R03.T * R * S.T),
               f"M = {pre}R_0_3ᵀ R{post}: the rotation left for joints 4-6 (R_3_{N} = R_0_3ᵀ R).", assign=True),
        IKStep(f"R_3_{N} in q4, q5, q6", sp.Symbol(f"R_3_{N}"), R36,
               "The product of the wrist's link rotations; its third column and third row give the angles."),
        IKStep("q5 (two wrist branches)", q[4],
               sp.atan2(sig5 * sp.sqrt(m[0, 2] ** 2 + m[1, 2] ** 2), -ea * eb * m[2, 2]) - th0[4],
               f"m33 = {sp.sstr(-ea * eb * sp.cos(th[1]))} and m13² + m23² = sin²({sp.sstr(th[1])}); "
               f"{sig5} = ±1 is the sign of sin({sp.sstr(th[1])}) (wrist flip). At sin = 0 (axes 4 and 6 aligned) "
               "only q4 ± q6 is determined.", assign=True),
        IKStep("q4", q[3], sp.atan2(sig5 * eb * m[1, 2], sig5 * eb * m[0, 2]) - th0[3],
               f"(m13, m23) = {sp.sstr(eb)}·sin({sp.sstr(th[1])})·(cos({sp.sstr(th[0])}), sin({sp.sstr(th[0])})).",
               assign=True),
        IKStep("q6", q[5], sp.atan2(-sig5 * ea * m[2, 1], sig5 * ea * m[2, 0]) - th0[5],
               f"(m31, m32) = {sp.sstr(ea)}·sin({sp.sstr(th[1])})·(cos({sp.sstr(th[2])}), −sin({sp.sstr(th[2])})).",
               assign=True),
    ]
    return steps
