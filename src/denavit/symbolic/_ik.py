"""Closed-form inverse kinematics derived symbolically, step by step: kinematic decoupling and planar arms.

The derivation is built from the robot's own DH table (its named parameters stay symbols), not from a
template, so offsets such as the PUMA's a3 and d3, a wrist-to-flange distance d6, DH angle offsets, the
modified convention and a trailing fixed row all appear where they belong.  Two classes are covered:

``decoupled``  6 joints with a spherical wrist (Pieper 1968): joint 1 about z0 through the origin of {0},
               axis 2 perpendicular to axis 1, joint 3 revolute with axis 3 parallel to axis 2 (elbow arms:
               PUMA, report003) or prismatic across axis 2 (Stanford arm), wrist axes 4-6 through one point
               with ±90° twists between them.  Spong, Hutchinson & Vidyasagar (2006), Sec. 5.3-5.4;
               Craig (2005), Sec. 4.7 (PUMA 560); Siciliano et al. (2009), Sec. 2.12.
``planar``     2 or 3 revolute joints with parallel axes (planar 2R/3R): law of cosines, then the heading.
               Spong et al. (2006), Sec. 5.2 (the planar elbow); Craig (2005), Sec. 4.4 (Example 4.1).

Every formula that computes a quantity is an *assignment* step (``IKStep.assign``) whose right-hand side
uses only the target symbols, the sign symbols σ and quantities assigned before it, so the steps can be
evaluated in order (``IKDerivation.formulas``).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import lru_cache
from typing import Any

import numpy as np
import sympy as sp

from ..codegen import numeric_function
from ..chain import chain_of
from ..errors import UnsupportedRobotError
from ..model import Convention, DHRobot, JointType
from ._kinematics import link_matrices_sym, link_transforms_sym
from ._simplify import simplify_expr, simplify_matrix
from ._symbols import joint_symbols, matrix_from_floats, parameter_symbols, row_expressions

__all__ = ["IKStep", "IKDerivation", "ik_derivation"]


@dataclass(frozen=True)
class IKStep:
    """One step of a derivation: ``lhs relation rhs`` with an explanation.

    ``assign`` marks a formula that computes ``lhs`` (a symbol or a column of symbols) from quantities known
    at that point; other steps are displayed facts (the equations being solved).
    """

    title: str
    lhs: Any
    rhs: Any
    text: str = ""
    relation: str = "="
    assign: bool = False


@dataclass(frozen=True)
class IKDerivation:
    """A closed-form IK derivation as data; render with :meth:`to_text`, :meth:`to_latex`, :meth:`to_markdown`.

    Attributes
    ----------
    robot : DHRobot
    kind : str
        ``"decoupled"`` (6 joints, spherical wrist) or ``"planar"``.
    steps : tuple of IKStep
    target : sympy.ImmutableMatrix, shape (4, 4)
        The symbols of the solved pose ``T_0_N = B⁻¹ T_w_e E⁻¹`` (DH frame {N} in {0}; B, E base and tool):
        ``r11 … r33, p_x, p_y, p_z``.
    branches : tuple of sympy.Symbol
        Sign symbols σ, each +1 or −1; every sign combination is one candidate solution.
    joints : tuple of sympy.Symbol
        q1 … qn.
    parameters : tuple of (sympy.Symbol, float)
        The robot's named parameters and their values.
    """

    robot: DHRobot
    kind: str
    steps: tuple[IKStep, ...]
    target: sp.ImmutableMatrix
    branches: tuple[sp.Symbol, ...]
    joints: tuple[sp.Symbol, ...]
    parameters: tuple[tuple[sp.Symbol, float], ...] = field(default=())

    @property
    def formulas(self) -> tuple[tuple[Any, Any], ...]:
        """The assignments ``(lhs, rhs)`` in evaluation order."""
        return tuple((s.lhs, s.rhs) for s in self.steps if s.assign)

    def to_text(self) -> str:
        """Plain text (sympy's one-line printer)."""
        out = [f"Inverse kinematics of {self.robot.name} ({self.kind}), derived from its DH table", ""]
        for k, s in enumerate(self.steps, start=1):
            out.append(f"{k}. {s.title}")
            if s.text:
                out.append(f"   {s.text}")
            if s.lhs is not None:
                out.append(f"   {_text(s.lhs)} {s.relation} {_text(s.rhs)}")
            out.append("")
        return "\n".join(out).rstrip() + "\n"

    def to_latex(self) -> str:
        """A LaTeX fragment (``\\subsection*`` per step, ``align*`` for the formulas)."""
        out = [f"\\section*{{Inverse kinematics of {_tex_text(self.robot.name)}}}"]
        for s in self.steps:
            out.append(f"\\subsection*{{{_tex_text(s.title)}}}")
            if s.text:
                out.append(_tex_text(s.text))
            if s.lhs is not None:
                out.append(f"\\begin{{align*}}\n{_latex(s.lhs)} &{_rel(s.relation)} {_latex(s.rhs)}\n\\end{{align*}}")
        return "\n".join(out) + "\n"

    def to_markdown(self) -> str:
        """Markdown with ``$$ … $$`` display math."""
        out = [f"## Inverse kinematics of {self.robot.name}", ""]
        for s in self.steps:
            out += [f"### {s.title}", ""]
            if s.text:
                out += [s.text, ""]
            if s.lhs is not None:
                out += [f"$$ {_latex(s.lhs)} {_rel(s.relation)} {_latex(s.rhs)} $$", ""]
        return "\n".join(out)

    def _repr_markdown_(self) -> str:
        return self.to_markdown()


def _text(e: Any) -> str:
    if isinstance(e, sp.MatrixBase):
        return "[" + "; ".join(", ".join(str(x) for x in e.row(i)) for i in range(e.rows)) + "]"
    return str(e)


def _latex(e: Any) -> str:
    """sympy's LaTeX, with frame names written as Craig does: T_0_6 → {}^{0}T_{6}."""
    names = {}
    for sym in getattr(e, "free_symbols", ()):
        parts = str(sym).split("_")
        if len(parts) == 3 and parts[0] in ("T", "R") and parts[1].isdigit() and parts[2].isdigit():
            names[sym] = f"{{}}^{{{parts[1]}}}{parts[0]}_{{{parts[2]}}}"
    return sp.latex(e, symbol_names=names) if names else sp.latex(e)


def _rel(r: str) -> str:
    return {"=": "=", "≡": "\\equiv", ":=": ":="}.get(r, r)


def _tex_text(s: str) -> str:
    for a, b in (("\\", "\\textbackslash{}"), ("_", "\\_"), ("%", "\\%"), ("&", "\\&"), ("#", "\\#")):
        s = s.replace(a, b)
    return s


# ---------------------------------------------------------------------------------------------------------
# shared pieces


def _target() -> sp.ImmutableMatrix:
    r = sp.symbols("r11 r12 r13 r21 r22 r23 r31 r32 r33", real=True)
    p = sp.symbols("p_x p_y p_z", real=True)
    return sp.ImmutableMatrix([[r[0], r[1], r[2], p[0]], [r[3], r[4], r[5], p[1]], [r[6], r[7], r[8], p[2]],
                               [0, 0, 0, 1]])


def _prod(ms) -> sp.Matrix:
    out = sp.eye(4)
    for m in ms:
        out = out * m
    return out


def _inv(T: sp.MatrixBase) -> sp.Matrix:
    R, p = T[:3, :3], T[:3, 3]
    out = sp.eye(4)
    out[:3, :3] = R.T
    out[:3, 3] = -R.T * p
    return out


def _simp(M):
    if isinstance(M, sp.MatrixBase):
        return simplify_matrix(M, "trig")
    return simplify_expr(M, "trig")


def _at_zero(M, qs):
    return M.subs({s: 0 for s in qs})


def _param_values(robot: DHRobot) -> dict:
    syms = parameter_symbols(robot)
    return {syms[k]: v for k, v in robot.parameter_values.items()}


def _numeric_zero(expr, robot: DHRobot, qs, rng: np.random.Generator, tol: float = 1e-9) -> bool:
    """Is ``expr`` zero for the robot's parameter values at random joint values (a cheap identity test)?"""
    f = numeric_function(sp.sympify(expr).subs(_param_values(robot)), list(qs))  # safe: expr is built by this module, never user text
    for _ in range(4):
        if np.max(np.abs(np.asarray(f(*rng.uniform(-3, 3, len(qs))), dtype=complex))) > tol:
            return False
    return True


def _axis_frame(robot: DHRobot, T, k: int):
    """The frame whose z axis is joint k (1-based), by the chain's rule (:attr:`denavit.chain.Chain.axis_frame`)."""
    return T[chain_of(robot).axis_frame[k - 1]]


def _check_prefix(robot: DHRobot) -> None:
    first = robot.links[0]
    if not first.is_joint:
        raise UnsupportedRobotError(f"{robot.name}: the derivation needs joint 1 in the first DH row")
    if robot.convention is Convention.MODIFIED:
        rows = row_expressions(robot)
        if rows[0]["a"] != 0 or rows[0]["alpha"] != 0:
            raise UnsupportedRobotError(f"{robot.name}: the derivation needs joint 1 about z0 through the origin "
                                        "of {0} (a0 = alpha0 = 0 in the first modified-DH row)")


def _target_steps(robot: DHRobot, target, n_rows: int) -> list[IKStep]:
    steps = []
    B, E = robot.base_matrix, robot.tool_matrix
    name = sp.Symbol(f"T_0_{n_rows}")
    if not (np.allclose(B, np.eye(4), atol=0) and np.allclose(E, np.eye(4), atol=0)):
        Tw = sp.MatrixSymbol("T_we", 4, 4)
        rhs = sp.MatMul(matrix_from_floats(np.linalg.inv(B)), Tw, matrix_from_floats(np.linalg.inv(E)), evaluate=False)
        steps.append(IKStep("Base and tool removed", name, rhs,
                            "The DH chain sees the target with the base transform B and the tool E taken off: "
                            f"T_0_{n_rows} = B⁻¹ T_w_e E⁻¹."))
    steps.append(IKStep("Target", name, target,
                        f"Entries of the pose of DH frame {{{n_rows}}} to be reached (r_ij: rotation R, p: position)."))
    return steps


def _cosine_law(lhs_sq, expr_q, q, robot, rng, title, text):
    """Steps solving ``lhs_sq = K0 + K1 cos q + K2 sin q`` for q (two roots, sign σ)."""
    K0 = sp.expand((expr_q.subs(q, 0) + expr_q.subs(q, sp.pi)) / 2)
    K1 = sp.expand((expr_q.subs(q, 0) - expr_q.subs(q, sp.pi)) / 2)
    K2 = sp.expand(expr_q.subs(q, sp.pi / 2) - K0)
    if not _numeric_zero(expr_q - (K0 + K1 * sp.cos(q) + K2 * sp.sin(q)), robot, [q], rng):
        raise UnsupportedRobotError(f"{robot.name}: the reach does not depend on {q} as A + B cos + C sin")
    if K1 == 0 and K2 == 0:
        raise UnsupportedRobotError(f"{robot.name}: the reach does not depend on {q}")
    f = sp.gcd(K1, K2) if (K1 != 0 and K2 != 0) else (K1 if K2 == 0 else K2)
    f = sp.factor_terms(f)
    if float(f.subs(_param_values(robot))) < 0:
        f = -f  # divide by a positive number only: atan2 must keep its quadrants
    k1, k2 = sp.simplify(K1 / f), sp.simplify(K2 / f)
    Ksym, sig = sp.Symbol("K", real=True), sp.Symbol(f"sigma{str(q)[1:]}", real=True)
    c = sp.cos(q)
    s = sp.sin(q)
    return [
        IKStep(title, lhs_sq, K0 + K1 * c + K2 * s, text),
        IKStep(f"The constant K of the law of cosines", Ksym, sp.factor_terms((lhs_sq - K0) / f),
               f"Dividing by {sp.sstr(f)}: {sp.sstr(k1 * c + k2 * s)} = K.", assign=True),
        IKStep(f"{q} (two roots)", q,
               sp.atan2(k2, k1) + sig * sp.atan2(sp.sqrt(k1**2 + k2**2 - Ksym**2), Ksym),
               f"a cos {q} + b sin {q} = K ⇔ cos({q} − atan2(b, a)) = K/√(a² + b²); "
               f"{sig} = ±1 gives the two roots (no real root when K² > a² + b²: out of reach).",
               assign=True),
    ], sig


# ---------------------------------------------------------------------------------------------------------
# 6 joints, spherical wrist


def _decoupled(robot: DHRobot) -> IKDerivation:
    if robot.joint_rows != tuple(range(6)):
        raise UnsupportedRobotError(f"{robot.name}: the derivation needs the six joints in DH rows 1-6")
    if robot.joint_types[1] is not JointType.REVOLUTE or any(t is not JointType.REVOLUTE for t in robot.joint_types[3:]):
        raise UnsupportedRobotError(f"{robot.name}: joints 2, 4, 5, 6 must be revolute")
    rng = np.random.default_rng(7)
    q = joint_symbols(6).q
    N = robot.n_rows
    T = link_transforms_sym(robot, "trig")
    A = link_matrices_sym(robot)
    target = _target()
    R, p = target[:3, :3], target[:3, 3]
    steps = _target_steps(robot, target, N)

    # wrist centre: axis 4 ∩ axis 5, in frame {3} (Spong eq. 5.12: o_c = o − d6 R k)
    ax = chain_of(robot).axis_frame  # frames of axes 4 and 5 relative to {3}: A_4 ⋯ A_ax
    f4 = _at_zero(_prod(A[3:ax[3]]), q)
    f5 = _at_zero(_prod(A[3:ax[4]]), q)
    p1, d1, p2, d2 = f4[:3, 3], f4[:3, 2], f5[:3, 3], f5[:3, 2]
    n12 = d1.cross(d2)
    t = sp.simplify((p2 - p1).cross(d2).dot(n12) / n12.dot(n12))
    c3 = _simp(p1 + t * d1)
    cN = _simp((_inv(_at_zero(_prod(A[3:N]), q)) * c3.col_join(sp.Matrix([1])))[:3, 0])
    xc, yc, zc = sp.symbols("x_c y_c z_c", real=True)
    pc = sp.Matrix([xc, yc, zc])
    steps.append(IKStep("Wrist centre", pc, _simp(p + R * cN),
                        f"Axes 4, 5, 6 meet at the wrist centre, the point {sp.sstr(list(cN))} of frame {{{N}}} "
                        f"(and {sp.sstr(list(c3))} of frame {{3}}); it depends on q1, q2, q3 only: "
                        "p_c = p + R c (kinematic decoupling).", assign=True))
    T03 = T[3]
    steps.append(IKStep("Position of the wrist centre by joints 1-3", pc, _simp((T03 * c3.col_join(sp.Matrix([1])))[:3, 0]),
                        "Joint 1 turns about z0, so p_c = Rz(q1) g(q2, q3) with g = p_c at q1 = 0."))
    g = _simp(_at_zero((T03 * c3.col_join(sp.Matrix([1])))[:3, 0], q[:1]))
    F2 = _at_zero(_axis_frame(robot, T, 2), q[:2])
    u, o2 = F2[:3, 2], F2[:3, 3]
    if sp.simplify(u[2]) != 0:
        raise UnsupportedRobotError(f"{robot.name}: axis 2 is not perpendicular to axis 1")
    uperp = sp.Matrix([-u[1], u[0], 0])
    delta = _simp(g.dot(u))
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
    steps.append(IKStep("q1 (two shoulder branches)", q[0], sp.atan2(yc, xc) - sp.atan2(_simp(gy), _simp(gx)),
                        "Rz(q1) turns g = (g_x, g_y) at q1 = 0 onto (x_c, y_c): q1 = atan2(y_c, x_c) − atan2(g_y, g_x) "
                        "(Craig eq. 4.65; Spong eq. 5.19-5.22 for the offset case).", assign=True))
    steps.append(IKStep("Height", s, zc, "The height of p_c is not changed by joint 1.", assign=True))
    r0, s0 = _simp(o2.dot(uperp)), _simp(o2[2])
    vr = _simp(_at_zero(g.dot(uperp), q[1:2]) - r0)
    vs = _simp(_at_zero(g[2], q[1:2]) - s0)
    lhs_sq = (r - r0) ** 2 + (s - s0) ** 2
    if robot.joint_types[2] is JointType.REVOLUTE:
        more, sig3 = _cosine_law(lhs_sq, _simp(sp.expand(vr**2 + vs**2)), q[2], robot, rng,
                                 "Law of cosines in the arm plane",
                                 f"Axis 2 passes through ({sp.sstr(r0)}, {sp.sstr(s0)}) of the arm plane (r, s); the "
                                 "squared distance of p_c from it depends on q3 only (Craig eq. 4.67-4.70; Spong eq. 5.24).")
        steps += more
    else:
        v0 = sp.Matrix([vr.subs(q[2], 0), vs.subs(q[2], 0)])
        w = sp.Matrix([sp.diff(vr, q[2]), sp.diff(vs, q[2])])
        a_, b_, c_ = _simp(w.dot(w)), _simp(v0.dot(w)), _simp(v0.dot(v0))
        sig3 = sp.Symbol("sigma3", real=True)
        steps.append(IKStep("Distance from axis 2 (prismatic joint 3)", lhs_sq,
                            _simp(a_ * q[2] ** 2 + 2 * b_ * q[2] + c_),
                            "The prismatic joint slides the wrist centre along a line across axis 2, so the squared "
                            "distance from axis 2 is a quadratic in q3 (Spong eq. 5.28-5.30, Stanford arm)."))
        steps.append(IKStep("q3 (two roots)", q[2],
                            _simp((-b_ + sig3 * sp.sqrt(b_**2 - a_ * (c_ - lhs_sq))) / a_),
                            f"{sig3} = ±1: the two roots (usually only one lies within the joint limits).", assign=True))
    steps.append(IKStep("q2", q[1], sp.atan2(s - s0, r - r0) - sp.atan2(vs, vr),
                        "Joint 2 turns the vector (v_r, v_s)(q3) from axis 2 to p_c onto (r − r0, s − s0): "
                        "q2 = atan2(s − s0, r − r0) − atan2(v_s, v_r) (Spong eq. 5.25).", assign=True))
    steps += _wrist_steps(robot, T, A, R, q, N, rng)
    return IKDerivation(robot, "decoupled", tuple(steps), target,
                        (sig1, sig3, sp.Symbol("sigma5", real=True)), q, tuple(_param_values(robot).items()))


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
    S = S * _prod(A[6:N])[:3, :3]  # trailing fixed rows belong to the last frame
    if not all(x in (sp.pi / 2, -sp.pi / 2) for x in (a, b)):
        raise UnsupportedRobotError(f"{robot.name}: the wrist twists are not ±90° (only orthogonal spherical wrists "
                                    "are derived symbolically; analytic_ik solves the general case numerically)")
    ea, eb = (1 if a == sp.pi / 2 else -1), (1 if b == sp.pi / 2 else -1)
    th = [q[k] + th0[k] for k in (3, 4, 5)]
    R36 = _simp(_prod(A[3:N])[:3, :3])
    model = _rz(th[0]) * _rx(a) * _rz(th[1]) * _rx(b) * _rz(th[2])
    if not all(_numeric_zero(e, robot, q[3:], rng) for e in (P.T * R36 * S.T - model)):
        raise UnsupportedRobotError(f"{robot.name}: R_3_6 does not factor as Rz Rx Rz Rx Rz")
    R03 = T[3][:3, :3]
    m = sp.Matrix(3, 3, sp.symbols("m11 m12 m13 m21 m22 m23 m31 m32 m33", real=True))
    sig5 = sp.Symbol("sigma5", real=True)
    pre = "" if P == sp.eye(3) else "Rx(α)ᵀ "
    post = "" if S == sp.eye(3) else " S⁻¹"
    steps = [
        IKStep("Orientation of frame {3}", sp.Symbol("R_0_3"), R03,
               "q1, q2, q3 are known now, so R_0_3 is a known matrix."),
        IKStep("What the wrist must do", m, _simp(P.T * R03.T * R * S.T),
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


# ---------------------------------------------------------------------------------------------------------
# planar 2R / 3R


def _planar(robot: DHRobot) -> IKDerivation:
    n, N = robot.dof, robot.n_rows
    if n not in (2, 3) or any(t is not JointType.REVOLUTE for t in robot.joint_types):
        raise UnsupportedRobotError(f"{robot.name}: planar derivation covers 2 or 3 revolute joints")
    rng = np.random.default_rng(7)
    q = joint_symbols(n).q
    T = link_transforms_sym(robot, "trig")
    TN = T[N]
    if not _numeric_zero(TN[2, 2] - 1, robot, q, rng):
        raise UnsupportedRobotError(f"{robot.name}: the joint axes are not all parallel to z0 in the same direction")
    target = _target()
    R, p = target[:3, :3], target[:3, 3]
    steps = _target_steps(robot, target, N)
    xw, yw = sp.symbols("x_w y_w", real=True)
    o = sp.Matrix([0, 0, 0, 1])
    if n == 3:
        F3 = _axis_frame(robot, T, 3)
        cN = _simp((_inv(_at_zero(_inv(F3) * TN, q)) * o)[:3, 0])
        ref = F3 * o
        what = f"the point {sp.sstr(list(cN))} of frame {{{N}}} on axis 3 (the wrist of the planar arm)"
    else:
        cN = sp.zeros(3, 1)
        ref = TN * o
        what = f"the origin of frame {{{N}}}"
    w = _simp(p + R * cN)
    steps.append(IKStep("Point placed by joints 1 and 2", sp.Matrix([xw, yw]), w[:2, 0],
                        f"Joints 1 and 2 place {what}.", assign=True))
    g = _simp(_at_zero(ref[:3, 0], q[:1]))
    steps.append(IKStep("Position of that point", sp.Matrix([xw, yw]), _simp(ref[:2, 0]),
                        "Joint 1 turns about z0 through the origin: the point is Rz(q1) g(q2)."))
    more, sig2 = _cosine_law(xw**2 + yw**2, _simp(sp.expand(g[0] ** 2 + g[1] ** 2)), q[1], robot, rng,
                             "Law of cosines", "The distance of the point from axis 1 depends on q2 only "
                             "(Spong eq. 5.8-5.10; Craig Example 4.1).")
    steps += more
    steps.append(IKStep("q1", q[0], sp.atan2(yw, xw) - sp.atan2(g[1], g[0]),
                        "Rz(q1) turns g(q2) onto (x_w, y_w) (Spong eq. 5.11).", assign=True))
    branches = [sig2]
    if n == 3:
        c = _simp(sp.atan2(_at_zero(TN[1, 0], q), _at_zero(TN[0, 0], q)))
        phi = sp.Symbol("phi", real=True)
        if not _numeric_zero(sp.sin(sum(q) + c) - TN[1, 0], robot, q, rng):
            raise UnsupportedRobotError(f"{robot.name}: the heading is not q1 + q2 + q3 + const")
        steps.append(IKStep("Heading", phi, sp.atan2(target[1, 0], target[0, 0]),
                            "All axes are parallel, so the heading of the last frame is the sum of the joint angles.",
                            assign=True))
        steps.append(IKStep("q3", q[2], phi - q[0] - q[1] - c, f"φ = {sp.sstr(q[0] + q[1] + q[2] + c)}.",
                            assign=True))
    return IKDerivation(robot, "planar", tuple(steps), target, tuple(branches), q,
                        tuple(_param_values(robot).items()))


@lru_cache(maxsize=32)
def ik_derivation(robot: DHRobot) -> IKDerivation:
    """Derive the closed-form inverse kinematics of ``robot`` symbolically, step by step.

    Covered: 6-joint arms with an orthogonal spherical wrist whose first three joints form an elbow
    (R ⟂ R ∥ R, e.g. PUMA 560) or a Stanford-type R ⟂ R P arm, with any offsets (shoulder offset, a3, d3, d6),
    DH angle offsets, either DH convention, base and tool; planar 2R and 3R arms.  The steps follow
    Spong, Hutchinson & Vidyasagar (2006), ch. 5 and Craig (2005), ch. 4: wrist centre p_c = p + R c
    (p − d6 R z for the usual flange), q1 from atan2 with the shoulder offset (two branches), q3 from the
    law of cosines (two branches), q2, then M = R_0_3ᵀ R = R_3_6 and q4, q5, q6 by atan2 (two branches).

    Parameters
    ----------
    robot : DHRobot

    Returns
    -------
    IKDerivation
        Steps as data; evaluate ``formulas`` in order for each sign combination of ``branches``.

    Raises
    ------
    UnsupportedRobotError
        The arm is outside the covered classes (the numeric ``analytic_ik`` may still solve it).

    Examples
    --------
    >>> import denavit
    >>> from denavit.symbolic import ik_derivation
    >>> d = ik_derivation(denavit.load_robot("puma560"))
    >>> d.kind, [str(s) for s in d.branches]
    ('decoupled', ['sigma1', 'sigma3', 'sigma5'])
    """
    from ..ik import ik_structure

    try:
        kind = ik_structure(robot)
    except UnsupportedRobotError as exc:
        raise UnsupportedRobotError(f"{robot.name}: no closed form to derive ({exc})") from None
    _check_prefix(robot)
    if kind == "pieper" and robot.dof == 6:
        return _decoupled(robot)
    if kind == "planar" and all(t is JointType.REVOLUTE for t in robot.joint_types) and robot.dof in (2, 3):
        return _planar(robot)
    raise UnsupportedRobotError(
        f"{robot.name}: the symbolic derivation covers 6-joint arms with a spherical wrist (elbow or Stanford "
        f"type) and planar 2R/3R arms, not this '{kind}' structure; analytic_ik solves it numerically"
        + (" (general 6R eigenvalue method; its steps are in docs/ik.md)" if kind == "general" else ""))
