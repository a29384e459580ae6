"""Report sections on differential kinematics and statics: Jacobian, velocity, joint torques.

The Jacobian is derived column by column from the symbolic frames (Siciliano et al., *Robotics:
Modelling, Planning and Control*, 2009, eq. 3.30): a revolute joint i contributes
[z_i × (p_e − p_i); z_i], a prismatic one [z_i; 0], with z_i, p_i the joint axis and a point on it in
base axes.  Statics uses the duality τ = Jᵀ F (Craig 2005, eq. 5.105) and, as a second route, inward
force propagation (Craig eq. 5.80-5.82), when the numeric engine provides it.
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np
import sympy as sp

from .. import numeric as N
from .. import symbolic as S
from ..chain import chain_of
from ..model import JointType
from ._context import Context
from ._derivation import Equation, Numbers, Section, Table, Text
from ._sections import MAX_EXACT_CHARS

__all__ = ["section_jacobian", "section_velocity", "section_statics", "jacobian_sym", "jacobian_case"]


def jacobian_sym(ctx: Context) -> sp.ImmutableMatrix:
    """J0 (6×n, rows v, ω, base axes, reference point the end-effector origin) from z_i and p_i."""
    cached = getattr(ctx, "_J_sym", None)
    if cached is not None:
        return cached
    J = _jacobian_from_axes(sp.ImmutableMatrix(ctx.fk_sym[:3, 3]), tuple(ctx.joint_frames_sym),
                            tuple(ctx.robot.joint_types), ctx.simplify)
    ctx._J_sym = J  # type: ignore[attr-defined]
    return J


@lru_cache(maxsize=64)
def _jacobian_from_axes(p_e: sp.ImmutableMatrix, axes: tuple, types: tuple, simplify: str) -> sp.ImmutableMatrix:
    """Columns [z_i × (p_e − p_i); z_i] (revolute) or [z_i; 0] (prismatic), simplified: a pure function of its
    arguments, remembered (every report of an arm derives the same J0, and its trigsimp pass costs a second)."""
    cols = []
    for (z, p), jt in zip(axes, types):
        if jt is JointType.REVOLUTE:
            v = z.cross(p_e - p)
            cols.append(list(v) + list(z))
        else:
            cols.append(list(z) + [0, 0, 0])
    J = S.simplify_matrix(sp.Matrix(cols).T, simplify)
    if simplify != "none":
        J = J.applyfunc(_pythagoras)
    return J


def _pythagoras(e: sp.Expr) -> sp.Expr:
    """Collapse sin² + cos² left over by the trig policy (cross products of unit axes produce them)."""
    if not any(isinstance(p.base, (sp.sin, sp.cos)) for p in e.atoms(sp.Pow)):
        return e
    out = sp.factor_terms(sp.trigsimp(e))
    return out if sp.count_ops(out) < sp.count_ops(e) else e


def jacobian_case(ctx: Context) -> sp.ImmutableMatrix:
    """J0 at the numeric case, exact: the same column formula applied to the exact frames at q."""
    cached = getattr(ctx, "_J_case", None)
    if cached is not None:
        return cached
    frames = ctx.frames_case
    p_e = sp.ImmutableMatrix((frames[-1] * ctx.tool_exact)[:3, 3])
    cols = []
    for f, jt in zip(chain_of(ctx.robot).axis_frame, ctx.robot.joint_types):
        z, p = frames[f][:3, 2], frames[f][:3, 3]
        cols.append(list(z.cross(p_e - p)) + list(z) if jt is JointType.REVOLUTE else list(z) + [0, 0, 0])
    J = sp.ImmutableMatrix(sp.Matrix(cols).T.applyfunc(lambda e: sp.radsimp(sp.expand(e))))
    ctx._J_case = J  # type: ignore[attr-defined]
    return J


def _max_diff(a, b) -> float:
    """Largest entry difference; a sympy column and a 1-D array compare entry by entry."""
    b = np.asarray(b, dtype=float)
    a = np.asarray(a, dtype=float).reshape(b.shape)
    return float(np.max(np.abs(a - b)))


def _agree(err: float) -> str:
    return ("agree" if err < 1e-9 else "DISAGREE") + f" (largest difference {err:.1e})"


def _symbolic_columns(ctx: Context) -> list:
    """z_i, p_i and column J_i of every joint, then J0 (shorthand)."""
    J = jacobian_sym(ctx)
    steps: list = []
    for k, ((z, p), jt) in enumerate(zip(ctx.joint_frames_sym, ctx.robot.joint_types), start=1):
        steps.append(Equation(f"z_{{{k}}}", ctx.short(z), shorthand=True))
        if jt is JointType.REVOLUTE:
            steps.append(Equation(f"p_{{{k}}}", ctx.short(S.simplify_matrix(p, ctx.simplify)), shorthand=True))
        steps.append(Equation(f"J_{{{k}}}", ctx.short(J[:, k - 1]), note=jt.value, shorthand=True))
    steps.append(Equation("J_0", ctx.short(J), shorthand=True))
    return steps


def _position_derivatives(ctx: Context) -> tuple:
    """∂p_e/∂q_i of the end-effector position (world axes), one 3-vector per joint, and ∂T/∂q_i unsimplified."""
    cached = getattr(ctx, "_dT_sym", None)
    if cached is not None:
        return cached
    ctx._dT_sym = _derivatives_of(ctx.fk_sym, tuple(ctx.q_syms), ctx.simplify)  # type: ignore[attr-defined]
    return ctx._dT_sym


@lru_cache(maxsize=64)
def _derivatives_of(T: sp.ImmutableMatrix, q: tuple, simplify: str) -> tuple:
    """(∂p/∂q_i simplified, ∂T/∂q_i) of T(q): a pure function of its arguments, remembered."""
    dT = tuple(sp.ImmutableMatrix(T.diff(qi)) for qi in q)
    dp = tuple(S.simplify_matrix(sp.ImmutableMatrix(d[:3, 3]), simplify) for d in dT)
    return dp, dT


def _differentiation_steps(ctx: Context) -> list:
    """The Jacobian by differentiating T(q): ∂p_e/∂q_i (linear rows) and vee(∂R/∂q_i Rᵀ) (angular rows)."""
    dp, _ = _position_derivatives(ctx)
    steps: list = [Text(
        "Second route, by differentiation (Spong et al. 2006, sec. 4.6; Siciliano et al. 2009, sec. 3.1): the "
        "linear rows are the partial derivatives of the end-effector position, $J_{v,i} = \\partial p_e/\\partial "
        "q_i$; the angular rows come from the rotation, $S(\\omega) = \\dot R R^T$, so $J_{\\omega,i} = "
        "\\mathrm{vee}(\\partial R/\\partial q_i\\,R^T)$.  Writing $R = R_a\\,R_z(q_i)\\,R_b$ with $R_a$ the "
        "rotation of the frame whose $z$ is joint $i$'s axis, $\\partial R/\\partial q_i\\,R^T = R_a S(\\hat z) "
        "R_a^T = S(R_a \\hat z)$: the axis $z_i$ for a revolute joint, $0$ for a prismatic one.")]
    for k, ((z, _), jt) in enumerate(zip(ctx.joint_frames_sym, ctx.robot.joint_types), start=1):
        steps.append(Equation(f"\\frac{{\\partial p_e}}{{\\partial q_{{{k}}}}}", ctx.short(dp[k - 1]),
                              shorthand=True))
        w = z if jt is JointType.REVOLUTE else sp.ImmutableMatrix([0, 0, 0])
        steps.append(Equation(f"J_{{\\omega,{k}}} = \\mathrm{{vee}}\\left(\\frac{{\\partial R}}{{\\partial q_{{{k}}}}}"
                              "R^T\\right)", ctx.short(w), shorthand=True))
    return steps


def _differentiation_check(ctx: Context, J_num: np.ndarray) -> float:
    """Largest difference, at the case, between J_num and (a) ∂p/∂q_i, vee(∂R/∂q_i Rᵀ) of the unsimplified
    derivatives of T(q) evaluated directly, (b) the formulas the report prints."""
    dp, dT = _position_derivatives(ctx)
    subs = {**ctx.param_subs, **dict(zip(ctx.q_syms, ctx.q))}

    def num(M) -> np.ndarray:
        return np.array(sp.ImmutableMatrix(M).xreplace(ctx.param_subs).xreplace(subs).evalf(), dtype=float)

    R = num(ctx.fk_sym)[:3, :3]
    worst = 0.0
    for k, ((z, _), jt) in enumerate(zip(ctx.joint_frames_sym, ctx.robot.joint_types)):
        D = num(dT[k])
        W = D[:3, :3] @ R.T
        raw = np.concatenate([D[:3, 3], [W[2, 1], W[0, 2], W[1, 0]]])
        shown = np.concatenate([num(dp[k]).ravel(), num(z).ravel() if jt is JointType.REVOLUTE else np.zeros(3)])
        worst = max(worst, _max_diff(raw, J_num[:, k]), _max_diff(shown, J_num[:, k]))
    return worst


def section_jacobian(ctx: Context) -> Section:
    """The geometric Jacobian: z_i and p_i per column, J0 symbolic, J0 and Je at the numeric case."""
    robot = ctx.robot
    steps: list = [Text(
        "Geometric Jacobian $J_0$ (rows $v, \\omega$ in base axes; reference point the end-effector origin "
        "$p_e$), column by column (Siciliano et al. 2009, eq. 3.30): a revolute joint gives "
        "$J_i = [z_i \\times (p_e - p_i);\\ z_i]$, a prismatic one $J_i = [z_i;\\ 0]$, where $z_i$ and $p_i$ are "
        "the joint axis and a point on it"
        + (" (standard DH: $z_{i-1}$ and $o_{i-1}$)." if robot.convention.value == "standard"
           else " (modified DH: $z_i$ and $o_i$)."))]
    J_num = N.geometric_jacobian(robot, ctx.q)
    if ctx.symbolic_jacobian_ok:
        steps += _symbolic_columns(ctx)
        steps += _differentiation_steps(ctx)
        J_at_q = jacobian_sym(ctx).xreplace(ctx.param_subs).xreplace(dict(zip(ctx.q_syms, ctx.q)))
        steps.append(Text("Check: the symbolic $J_0$ at the numeric case against the numeric engine's "
                          f"geometric_jacobian: {_agree(_max_diff(J_at_q.evalf(), J_num))}."))
        steps.append(Text("Check, the differentiation route at the numeric case ($\\partial p_e/\\partial q_i$ and "
                          "$\\mathrm{vee}(\\partial R/\\partial q_i\\,R^T)$ of $T(q)$ evaluated directly, and the "
                          f"formulas above) against geometric_jacobian: {_agree(_differentiation_check(ctx, J_num))}."))
    else:
        steps.append(Text("The symbolic Jacobian of this arm is too long to read usefully; it is shown at the "
                          "numeric case."))
    if ctx.exact_ok:
        J_exact = jacobian_case(ctx)
        if len(str(J_exact)) <= MAX_EXACT_CHARS:
            steps.append(Equation("J_0(q)", J_exact, note="exact, at the numeric case"))
        steps.append(Text(f"Check, exact vs numeric: {_agree(_max_diff(J_exact.evalf(), J_num))}."))
    steps.append(Numbers("J_0(q)", J_num, note="decimals, numeric engine"))
    for name, label in (("differentiation_jacobian", "differentiating T(q)"),
                        ("propagation_jacobian", "velocity propagation")):
        fn = getattr(N, name, None)
        if fn is not None:
            other = fn(robot, ctx.q, frame="base")
            steps.append(Text(f"Second route, {label} ({name}): {_agree(_max_diff(other, J_num))}."))
    Je = N.geometric_jacobian(robot, ctx.q, frame="tool")
    steps.append(Text("In end-effector axes, $J_e = \\mathrm{diag}(R^T, R^T)\\, J_0$ with $R$ the end-effector "
                      "orientation:"))
    steps.append(Numbers("J_e(q)", Je, note="decimals"))
    rank = int(np.linalg.matrix_rank(J_num, tol=1e-9 * max(1.0, np.abs(J_num).max())))
    steps.append(Text(f"Rank of $J_0$ at this configuration: {rank} (of at most {min(6, robot.dof)})."))
    return Section("jacobian", "Jacobian", tuple(steps))


def section_velocity(ctx: Context) -> Section:
    """The end-effector twist ν = J0 q̇ at the numeric case."""
    rel = Text("The end-effector twist is $\\nu = \\begin{bmatrix} v \\\\ \\omega \\end{bmatrix} = J_0(q)\\,\\dot q$.")
    if ctx.qd is None:
        return Section("velocity", "Velocity", (rel,), status="skipped", reason="no joint rates given (--qd)")
    robot = ctx.robot
    qd = sp.ImmutableMatrix(ctx.qd_exact)
    steps: list = [rel, Equation("\\dot q", qd)]
    fn = getattr(N, "end_effector_twist", None)
    tw = fn(robot, ctx.q, ctx.qd) if fn is not None else N.geometric_jacobian(robot, ctx.q) @ ctx.qd
    if ctx.exact_ok:
        tw_exact = sp.ImmutableMatrix((jacobian_case(ctx) * qd).applyfunc(lambda e: sp.radsimp(sp.expand(e))))
        if len(str(tw_exact)) <= MAX_EXACT_CHARS:
            steps.append(Equation("\\nu", tw_exact, note="exact"))
        steps.append(Text(f"Check, exact vs numeric: {_agree(_max_diff(tw_exact.evalf(), tw))}."))
    steps.append(Numbers("\\nu", tw, note="$v$ in m/s, $\\omega$ in rad/s, base axes; numeric engine"))
    prop = getattr(N, "velocity_propagation", None)
    if prop is not None:
        vp = prop(robot, ctx.q, ctx.qd)
        rows = tuple((lab, _vec(w), _vec(v)) for lab, w, v in zip(vp.labels, vp.omega, vp.v))
        steps.append(Text("Second route, outward velocity propagation (Craig 2005, eq. 5.45-5.48), each frame's "
                          "$\\omega$ and $v$ in its own axes:"))
        steps.append(Table(("\\text{frame } k", "{}^k\\omega_k", "{}^k v_k"), rows))
        steps.append(Text(f"Propagated twist in base axes vs $J_0 \\dot q$: {_agree(_max_diff(vp.twist('base'), tw))}."))
        if ctx.symbolic_jacobian_ok:
            steps += _velocity_steps_sym(ctx, vp)
    return Section("velocity", "Velocity", tuple(steps))


def _velocity_steps_sym(ctx: Context, vp) -> list:
    """The propagation written out: ω_k, v_k of every frame as formulas of q, q̇, checked at the case."""
    prop = S.velocity_propagation_sym(ctx.robot, ctx.simplify)
    if ctx.robot.convention.value == "standard":
        rule = ("standard DH: ${}^{i}\\omega_{i} = {}^{i}R_{i-1}({}^{i-1}\\omega_{i-1} + \\dot q_i \\hat z)$, "
                "${}^{i}v_{i} = {}^{i}R_{i-1}({}^{i-1}v_{i-1} + {}^{i-1}\\omega_{i} \\times {}^{i-1}P_{i})$ (revolute)")
    else:
        rule = ("modified DH: ${}^{i+1}\\omega_{i+1} = {}^{i+1}R_{i}\\,{}^{i}\\omega_{i} + \\dot q_{i+1} \\hat z$, "
                "${}^{i+1}v_{i+1} = {}^{i+1}R_{i}({}^{i}v_{i} + {}^{i}\\omega_{i} \\times {}^{i}P_{i+1})$ (revolute)")
    out: list = [Text(f"The same propagation as formulas (Craig 2005, eq. 5.45-5.47; {rule}):")]
    worst = 0.0
    subs = {**ctx.param_subs, **dict(zip(prop.q, ctx.q)), **dict(zip(prop.qd, ctx.qd))}
    for st in prop.steps[1:]:
        out.append(Equation(f"{{}}^{{{st.label}}}\\omega_{{{st.label}}}", ctx.short(st.omega), shorthand=True))
        out.append(Equation(f"{{}}^{{{st.label}}}v_{{{st.label}}}", ctx.short(st.v), shorthand=True))
        k = list(vp.labels).index(st.label)
        at = [float(e) for e in st.omega.xreplace(subs).evalf()] + [float(e) for e in st.v.xreplace(subs).evalf()]
        worst = max(worst, _max_diff(at, np.concatenate([vp.omega[k], vp.v[k]])))
    out.append(Text(f"Check, the formulas at the numeric case vs the table above: {_agree(worst)}."))
    return out


def _vec(x, digits: int = 4) -> str:
    vals = [0.0 if abs(v) < 0.5 * 10 ** -digits else float(v) for v in np.asarray(x, dtype=float)]
    return "(" + ",\\ ".join(f"{v:.{digits}g}" for v in vals) + ")"


def section_statics(ctx: Context) -> Section:
    """Joint torques balancing an end-effector wrench: τ = J0ᵀ F and inward force propagation."""
    rel = Text("By the principle of virtual work, $\\delta q^T \\tau = \\delta x^T F$ for every virtual "
               "displacement, and $\\delta x = J_0\\,\\delta q$, so $\\tau = J_0^T F$ (Craig 2005, eq. 5.105), "
               "with $F = (f, n)$ the wrench the end effector exerts, in base axes, about its origin.")
    if ctx.wrench is None:
        return Section("statics", "Statics", (rel,), status="skipped", reason="no wrench given (--wrench)")
    robot = ctx.robot
    F = sp.ImmutableMatrix(ctx.wrench_exact)
    steps: list = [rel, Equation("F", F)]
    fn = getattr(N, "joint_torques", None)
    tau = fn(robot, ctx.q, ctx.wrench) if fn is not None else N.geometric_jacobian(robot, ctx.q).T @ ctx.wrench
    if ctx.exact_ok:
        J_exact = jacobian_case(ctx)
        tau_exact = sp.ImmutableMatrix((J_exact.T * F).applyfunc(lambda e: sp.radsimp(sp.expand(e))))
        if len(str(J_exact)) <= MAX_EXACT_CHARS:
            steps.append(Equation("J_0^T(q)", sp.ImmutableMatrix(J_exact.T)))
        if len(str(tau_exact)) <= MAX_EXACT_CHARS:
            steps.append(Equation("\\tau", tau_exact, note="exact, route 1: $J^T F$"))
        steps.append(Text(f"Check, exact vs numeric: {_agree(_max_diff(tau_exact.evalf(), tau))}."))
    steps.append(Numbers("\\tau", tau, note="N m or N; numeric engine"))
    prop = getattr(N, "force_propagation", None)
    if prop is None:
        steps.append(Text("Route 2 (force propagation) is not available in this installation."))
    else:
        fp = prop(robot, ctx.q, ctx.wrench, frame="base")
        steps.append(Text("Route 2, inward force propagation (Craig 2005, eq. 5.80-5.81): "
                          "${}^i f_i = {}^iR_{i+1}\\,{}^{i+1}f_{i+1}$, "
                          "${}^i n_i = {}^iR_{i+1}\\,{}^{i+1}n_{i+1} + {}^iP_{i+1} \\times {}^i f_i$, and "
                          "$\\tau_i$ is the $z$ component of $n$ (revolute) or $f$ (prismatic) on the joint axis:"))
        rows = tuple((lab, _vec(f), _vec(n)) for lab, f, n in zip(fp.labels, fp.f, fp.n))
        steps.append(Table(("\\text{frame } k", "{}^k f_k", "{}^k n_k"), rows))
        steps.append(Numbers("\\tau", fp.tau, note="route 2"))
        steps.append(Text(f"The two routes {_agree(_max_diff(fp.tau, tau))}."))
        if ctx.symbolic_jacobian_ok:
            steps += _force_steps_sym(ctx)
    return Section("statics", "Statics", tuple(steps))


def _force_steps_sym(ctx: Context) -> list:
    """The inward propagation as formulas of q and a wrench (f_x, …, n_z) in tool axes, checked at the case."""
    prop = S.force_propagation_sym(ctx.robot, ctx.simplify)
    out: list = [Text("The same propagation as formulas, for a wrench $(f_x, f_y, f_z, n_x, n_y, n_z)$ given in "
                      "tool axes (Craig's setting):")]
    for st in prop.steps:
        out.append(Equation(f"{{}}^{{{st.label}}}f_{{{st.label}}}", ctx.short(st.f), shorthand=True))
        out.append(Equation(f"{{}}^{{{st.label}}}n_{{{st.label}}}", ctx.short(st.n), shorthand=True))
    out.append(Equation("\\tau", ctx.short(sp.ImmutableMatrix(prop.tau)), shorthand=True))
    R = N.forward_kinematics(ctx.robot, ctx.q)[:3, :3]
    W_tool = np.concatenate([R.T @ ctx.wrench[:3], R.T @ ctx.wrench[3:6]]) if len(ctx.wrench) == 6 else \
        np.concatenate([R.T @ ctx.wrench[:3], np.zeros(3)])
    subs = {**ctx.param_subs, **dict(zip(ctx.q_syms, ctx.q)), **dict(zip(prop.wrench, W_tool))}
    at = [float(e) for e in sp.ImmutableMatrix(prop.tau).xreplace(subs).evalf()]
    tau = N.joint_torques(ctx.robot, ctx.q, ctx.wrench)
    out.append(Text("Check, $\\tau$ from these formulas at the numeric case (the wrench turned into tool axes) vs "
                    f"route 1: {_agree(_max_diff(at, tau))}."))
    return out
