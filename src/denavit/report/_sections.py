"""Report sections on the model and forward kinematics: DH table, link transforms, T_0_n, numeric case.

References: J. J. Craig, *Introduction to Robotics*, 3rd ed. (2005), eq. (3.6) (modified DH link
transform); M. W. Spong, S. Hutchinson, M. Vidyasagar, *Robot Modeling and Control* (2006), eq. (3.10)
(standard DH link transform).
"""

from __future__ import annotations

import numpy as np
import sympy as sp

from .. import _text
from .. import symbolic as S
from ..model import Convention, JointType
from ..numeric import forward_kinematics, link_transforms
from ._context import EXACT_TOL, Context
from ._derivation import Equation, Numbers, Section, Table, Text

__all__ = ["section_model", "section_links", "section_fk", "section_case", "frame_label", "latex"]

MAX_EXACT_CHARS = 2_000  # exact case values longer than this are shown as decimals only


def latex(e) -> str:
    """LaTeX of a sympy object, matrices as bmatrix."""
    return sp.latex(e, mat_str="bmatrix", mat_delim="")


def frame_label(i: int | str, j: int | str, letter: str = "T") -> str:
    """``{}^{i}T_{j}``: the pose of frame {j} in frame {i}."""
    return f"{{}}^{{{i}}}{letter}_{{{j}}}"


def _formula_text(conv: Convention) -> str:
    if conv is Convention.STANDARD:
        return ("Standard (distal) DH, Spong et al. (2006) eq. (3.10): "
                "$A_i = {}^{i-1}T_{i} = R_z(\\theta_i)\\,T_z(d_i)\\,T_x(a_i)\\,R_x(\\alpha_i)$; "
                "joint $i$ moves about (or along) $z_{i-1}$.")
    return ("Modified (proximal, Craig) DH, Craig (2005) eq. (3.6): "
            "$A_i = {}^{i-1}T_{i} = R_x(\\alpha_{i-1})\\,T_x(a_{i-1})\\,R_z(\\theta_i)\\,T_z(d_i)$; "
            "joint $i$ moves about (or along) $z_i$.")


def section_model(ctx: Context) -> Section:
    """The DH table as given, the convention and its formula, parameters, base and tool."""
    robot = ctx.robot
    mod = robot.convention is Convention.MODIFIED
    header = ("i", "a_{i-1}" if mod else "a_i", "\\alpha_{i-1}" if mod else "\\alpha_i", "d_i", "\\theta_i", "\\text{joint}")
    rows = []
    for i, (link, row) in enumerate(zip(robot.links, S.row_expressions(robot)), start=1):
        rows.append((str(i), latex(row["a"]), latex(row["alpha"]), latex(row["d"]), latex(row["theta"]),
                     f"\\text{{{link.joint.value}}}"))
    kinds = ", ".join(t.value for t in robot.joint_types)
    steps: list = [
        # free text: one line, and no $ (a Text's $...$ is mathematics, raw LaTeX in a .tex report): ＄ instead
        Text(f"{_text.visible(robot.description or robot.name).replace('$', '＄')}. {robot.dof} joints ({kinds}); "
             f"{robot.n_rows} DH rows."),
        Text(_formula_text(robot.convention)),
        Text("Joint variables are $q_1, \\dots, q_n$: $q_i$ is $\\theta_i$ of a revolute joint and $d_i$ of a "
             "prismatic one.  Lengths in m, angles in rad."),
        Table(header, tuple(rows), caption="DH table"),
    ]
    if robot.parameters:
        steps.append(Table(("\\text{parameter}", "\\text{value}"),
                           tuple((latex(sp.Symbol(k)), f"{v:g}") for k, v in robot.parameters),
                           caption="named parameters (kept as symbols in the formulas)"))
    if not np.allclose(robot.base_matrix, np.eye(4)):
        steps.append(Equation("T_{\\text{base}}", ctx.base_exact, note="pose of {0} in the world frame"))
    if not np.allclose(robot.tool_matrix, np.eye(4)):
        steps.append(Equation("T_{\\text{tool}}", ctx.tool_exact, note="pose of the end effector in {N}"))
    if robot.source:
        steps.append(Text(f"Source: {robot.source}."))
    return Section("model", "Model: DH table and convention", tuple(steps))


def section_links(ctx: Context) -> Section:
    """The general link transform, then each A_i with its row substituted."""
    robot = ctx.robot
    mod = robot.convention is Convention.MODIFIED
    a, al = (sp.Symbol("a_{i-1}"), sp.Symbol(r"\alpha_{i-1}")) if mod else (sp.Symbol("a_i"), sp.Symbol(r"\alpha_i"))
    general = S.dh_matrix_sym(robot.convention, a, al, sp.Symbol("d_i"), sp.Symbol(r"\theta_i"))
    steps: list = [Text("The general link transform of one DH row:"),
                   Equation(frame_label("i-1", "i"), general),
                   Text("Substituting each row of the table ($C_i = \\cos q_i$, $S_i = \\sin q_i$):")]
    for i, A in enumerate(ctx.links_sym, start=1):
        A = S.simplify_matrix(A, ctx.simplify)
        kind = robot.links[i - 1].joint
        note = "fixed row" if kind is JointType.FIXED else f"joint {robot.joint_rows.index(i - 1) + 1} ({kind.value})"
        steps.append(Equation(f"A_{{{i}}} = {frame_label(i - 1, i)}", ctx.short(A), note=note, shorthand=True))
    return Section("links", "Link transforms", tuple(steps))


def section_fk(ctx: Context) -> Section:
    """T_0_N as the product of the link transforms, simplified, and the end-effector position."""
    robot = ctx.robot
    N = robot.n_rows
    prod = " ".join(frame_label(i - 1, i) for i in range(1, N + 1))
    steps: list = [Text(f"Forward kinematics is the product of the link transforms (simplification policy "
                        f"'{ctx.simplify}'):"),
                   Equation(frame_label(0, N), prod, note="definition")]
    T0N = ctx.frames_sym[-1]
    if ctx.too_long(T0N):
        steps.append(Text("The symbolic product is too long to print usefully; see the numeric case below."))
    else:
        steps.append(Equation(frame_label(0, N), ctx.short(T0N), shorthand=True))
    T = ctx.fk_sym
    if ctx.has_base_or_tool:
        steps.append(Text("With the base and tool transforms, the end-effector pose in the world frame is "
                          f"$T_{{we}} = T_{{\\text{{base}}}}\\,{frame_label(0, N)}\\,T_{{\\text{{tool}}}}$:"))
        if not ctx.too_long(T):
            steps.append(Equation("T_{we}", ctx.short(T), shorthand=True))
    steps.append(Text("End-effector position (the last column):"))
    for name, e in zip("xyz", T[:3, 3]):
        steps.append(Equation(f"p_{name}", ctx.short(e), shorthand=True))
    return Section("fk", "Forward kinematics", tuple(steps))


def _exact_ok(M) -> bool:
    return len(str(M)) <= MAX_EXACT_CHARS


def _q_text(ctx: Context) -> str:
    vals = ", ".join(latex(v) for v in ctx.q_exact)
    return f"$q = ({vals})$"


def section_case(ctx: Context) -> Section:
    """The numeric case: each A_i and T at the given q, exactly (sympy) and as decimals (numpy engine)."""
    robot = ctx.robot
    lead = "The numeric case" if ctx.q_given else "No q was given; the numeric case uses a default configuration"
    steps: list = [Text(f"{lead}: {_q_text(ctx)}.  Exact values come from the symbolic engine with q "
                        "substituted exactly; decimals come from the numeric engine.")]
    frames = link_transforms(robot, ctx.q)  # (N+1, 4, 4) world frames
    T_num = forward_kinematics(robot, ctx.q)
    label = "T_{we}" if ctx.has_base_or_tool else frame_label(0, robot.n_rows)
    if not ctx.exact_ok:
        steps.append(Text("Some joint value is not a multiple of $\\pi/12$, so exact values would be long "
                          "expressions of sines and cosines; decimals only."))
        for i in range(1, robot.n_rows + 1):
            steps.append(Numbers(f"A_{{{i}}}", np.linalg.solve(frames[i - 1], frames[i])))
        steps.append(Numbers(label, T_num, note="numeric engine"))
        return Section("case", "Numeric case", tuple(steps) + _pose_steps(T_num))
    for i, A in enumerate(S.link_matrices_sym(robot, numeric=True), start=1):
        A = ctx.at_case(A)
        A_num = np.linalg.solve(frames[i - 1], frames[i])  # A_i = T_{i-1}^{-1} T_i
        steps.append(Equation(f"A_{{{i}}}", A) if _exact_ok(A) else Numbers(f"A_{{{i}}}", A_num))
    T_exact = sp.ImmutableMatrix(ctx.frames_case[-1] * ctx.tool_exact)
    err = float(np.max(np.abs(np.array(T_exact.evalf(), dtype=float) - T_num)))
    if _exact_ok(T_exact):
        steps.append(Equation(label, T_exact, note="exact"))
    steps.append(Numbers(label, T_num, note="decimals, numeric engine"))
    verdict = "agree" if err < EXACT_TOL else "DISAGREE"
    steps.append(Text(f"Check: the exact and numeric results {verdict} (largest difference {err:.1e})."))
    return Section("case", "Numeric case", tuple(steps) + _pose_steps(T_num))


def _pose_steps(T_num: np.ndarray) -> tuple:
    from ..numeric import rpy_from_rotation

    return (Numbers("(x, y, z)", T_num[:3, 3], note="position [m]"),
            Numbers("(\\text{roll}, \\text{pitch}, \\text{yaw})", rpy_from_rotation(T_num[:3, :3]),
                    note="RPY angles [rad]"))
