"""Report sections that plug in library capabilities when they exist: singularities, IK, dynamics, figures.

Each section looks the functions it needs up at build time.  When one is missing from this
installation, the section says so (``status="unavailable"``) rather than faking a result.  Every
number taken from such a function is checked here by an independent route where one is cheap:
IK solutions by forward kinematics, singular values against the Jacobian's rank.
"""

from __future__ import annotations

import importlib
from typing import Any, Callable

import numpy as np

from .. import numeric as N
from ._context import Context
from ._derivation import Equation, Figure, Numbers, Section, Table, Text
from ._sections import latex

__all__ = ["section_singularities", "section_ik", "section_dynamics", "section_figures", "capability"]


def capability(module: str, *names: str) -> tuple[str, Callable[..., Any]] | None:
    """The first of ``names`` that ``module`` provides, as (name, function); None if none does."""
    try:
        mod = importlib.import_module(module)
    except ImportError as exc:
        if exc.name and not exc.name.startswith("denavit"):
            return None
        return None
    for name in names:
        fn = getattr(mod, name, None)
        if callable(fn):
            return name, fn
    return None


def _unavailable(key: str, title: str, what: str, lead: tuple = ()) -> Section:
    return Section(key, title, lead, status="unavailable",
                   reason=f"{what} is not available in this installation of denavit")


def section_singularities(ctx: Context) -> Section:
    """Symbolic singular conditions with their classification when the library derives them;
    measures of the Jacobian at the numeric case otherwise."""
    robot = ctx.robot
    steps: list = [Text("A configuration is singular when $J_0$ loses rank: the arm cannot move (or resist) "
                        "in some direction.")]
    sym = capability("denavit.symbolic", "singularity_analysis", "singularities_sym", "singular_conditions")
    heavy = robot.dof > 6 or not ctx.symbolic_jacobian_ok
    if sym is not None and heavy:
        steps.append(Text("The symbolic analysis is left out for this arm (more than six joints or a long pose "
                          "formula: it would take minutes); numeric measures at the numeric case follow."))
    elif sym is not None:
        try:
            result = sym[1](robot)
        except Exception as exc:  # another area's function: report, do not crash the report
            steps.append(Text(f"The symbolic analysis ({sym[0]}) failed: {type(exc).__name__}: {exc}."))
        else:
            steps += _singular_result_steps(result)
    J = N.geometric_jacobian(robot, ctx.q)
    sv = np.linalg.svd(J, compute_uv=False)
    steps.append(Numbers("\\sigma(J_0(q))", sv, note="singular values at the numeric case"))
    manip = capability("denavit.numeric", "manipulability")
    if manip is not None:
        steps.append(Numbers("w(q)", np.atleast_1d(manip[1](J)),
                             note="manipulability $\\sqrt{\\det(J J^T)}$ (Yoshikawa 1985)"))
    if sym is None:
        return Section("singularities", "Singularities", tuple(steps), status="unavailable",
                       reason="the symbolic singularity analysis (conditions and their classification) is not "
                              "available in this installation; numeric measures at q are shown")
    return Section("singularities", "Singularities", tuple(steps))


def _singular_result_steps(result: Any) -> list:
    """Present a singularity analysis: the measure, its factors, each condition solved and classified."""
    steps: list = []
    measure = getattr(result, "measure", "")
    det = getattr(result, "determinant", None)
    if det is not None and hasattr(det, "free_symbols") and len(str(det)) < 4000:
        steps.append(Text(f"Measure: {measure}." if measure else "Determinant:"))
        steps.append(Equation("\\det", det))
    if getattr(result, "reason", ""):
        steps.append(Text(f"Note: {result.reason}."))
    rows = []
    for c in getattr(result, "conditions", ()):
        sols = "; ".join(f"{s.variable} = " + ", ".join(f"{v:.4g}" for v in s.values)
                         for s in getattr(c, "solutions", ()))
        factor = getattr(c, "factor", getattr(c, "condition", ""))
        rows.append((latex(factor) + " = 0" if hasattr(factor, "free_symbols") else str(factor),
                     f"\\text{{{getattr(c, 'kind', '')}}}", f"\\text{{{sols or '-'}}}"))
        if getattr(c, "explanation", ""):
            steps.append(Text(f"${latex(factor)} = 0$ ({getattr(c, 'kind', '')}): {c.explanation}"))
    if rows:
        steps.insert(len(steps) - sum(isinstance(s, Text) and s.text.startswith("$") for s in steps),
                     Table(("\\text{condition}", "\\text{kind}", "\\text{solutions [rad or m]}"), tuple(rows),
                           caption="singular configurations"))
    elif not getattr(result, "reason", ""):
        steps.append(Text("No singular configurations were found."))
    return steps


def section_ik(ctx: Context) -> Section:
    """Inverse kinematics of the pose reached at the numeric case: analytic branches or a numeric solution,
    each checked by forward kinematics."""
    robot = ctx.robot
    target = N.forward_kinematics(robot, ctx.q)
    steps: list = [Text("Target: the end-effector pose of the numeric case."), Numbers("T_{\\text{target}}", target)]
    analytic = capability("denavit.numeric", "analytic_ik", "solve_ik_analytic", "ik_analytic")
    numeric = capability("denavit.numeric", "solve_ik", "ik_numeric")
    if analytic is None and numeric is None:
        return _unavailable("ik", "Inverse kinematics", "inverse kinematics", tuple(steps))
    solutions: list[np.ndarray] = []
    used = ""
    structure = capability("denavit.numeric", "ik_structure")
    if structure is not None:
        try:
            kind = structure[1](robot)
        except Exception:  # a structure the recogniser does not name
            kind = None
        if kind:
            steps.append(Text(f"Structure recognised from the DH table: {kind} "
                              + ("(closed form by kinematic decoupling at the wrist centre, Pieper 1968; "
                                 "Craig 2005, sec. 4.6-4.7; see docs/ik.md)." if kind == "pieper"
                                 else "(closed form; see docs/ik.md for the derivation).")))
    if analytic is not None:
        try:
            res = analytic[1](robot, target)
            sols = np.atleast_2d(np.asarray(getattr(res, "solutions", res), dtype=float))
            solutions = [s for s in sols if s.size == robot.dof and np.all(np.isfinite(s))]
            used = f"analytic ({analytic[0]})"
        except Exception as exc:  # e.g. UnsupportedRobotError for a non-Pieper arm
            steps.append(Text(f"No analytic solution: {exc}."))
    if not solutions and numeric is not None:
        res = numeric[1](robot, target, rng=np.random.default_rng(0)) if numeric[0] == "solve_ik" else numeric[1](robot, target)
        q_sol = np.asarray(getattr(res, "q", res), dtype=float)
        solutions = [q_sol.reshape(-1)]
        used = f"numeric ({numeric[0]})"
    if not solutions:
        return Section("ik", "Inverse kinematics", tuple(steps), status="done")
    rows = []
    for k, s in enumerate(solutions, start=1):
        err = float(np.max(np.abs(N.forward_kinematics(robot, s) - target)))
        rows.append((str(k), "(" + ",\\ ".join(f"{v:.4f}" for v in s) + ")", f"{err:.1e}"))
    steps.append(Text(f"Solutions by the {used} solver; the residual is $\\max|T(q_{{sol}}) - T_{{target}}|$, "
                      "computed by forward kinematics:"))
    steps.append(Table(("k", "q_{sol}", "\\text{residual}"), tuple(rows)))
    return Section("ik", "Inverse kinematics", tuple(steps))


def section_dynamics(ctx: Context) -> Section:
    """M(q), c(q, q̇), g(q) when the robot has inertial data and the library computes them."""
    robot = ctx.robot
    lead = (Text("Equations of motion (Lagrange): $M(q)\\ddot q + c(q, \\dot q) + g(q) = \\tau$, from "
                 "$\\frac{d}{dt}\\frac{\\partial L}{\\partial \\dot q_i} - \\frac{\\partial L}{\\partial q_i} = "
                 "\\tau_i$ with $L = K - P$ (Spong et al. 2006, ch. 7)."),)
    if not robot.has_dynamics:
        return Section("dynamics", "Dynamics", lead, status="skipped", reason="the robot file has no inertial data")
    mass = capability("denavit.numeric", "mass_matrix")
    grav = capability("denavit.numeric", "gravity_torques", "gravity_vector")
    if mass is None:
        return _unavailable("dynamics", "Dynamics", "rigid-body dynamics (mass_matrix)", lead)
    steps: list = list(lead)
    sym = capability("denavit.symbolic", "lagrangian_dynamics")
    if sym is not None and robot.dof <= 3:
        try:
            terms = sym[1](robot)
            for name in ("M", "c", "g"):
                value = getattr(terms, name, None)
                if value is not None and not ctx.too_long(value):
                    steps.append(Equation(name, ctx.short(value), shorthand=True))
        except Exception as exc:
            steps.append(Text(f"The symbolic derivation ({sym[0]}) failed: {type(exc).__name__}: {exc}."))
    steps.append(Numbers("M(q)", mass[1](robot, ctx.q), note="at the numeric case"))
    cor = capability("denavit.numeric", "coriolis_vector")
    if cor is not None and ctx.qd is not None:
        steps.append(Numbers("c(q, \\dot q)", cor[1](robot, ctx.q, ctx.qd), note="at the numeric case"))
    if grav is not None:
        steps.append(Numbers("g(q)", grav[1](robot, ctx.q), note="at the numeric case"))
    return Section("dynamics", "Dynamics", tuple(steps))


def section_figures(ctx: Context) -> Section:
    """The arm drawn at the numeric case with its frames, when pictures are available."""
    plot = capability("denavit.viz", "plot_robot")
    if plot is None:
        return _unavailable("figures", "Figures", "drawing the arm (denavit.viz.plot_robot)")
    try:
        import io

        out = plot[1](ctx.robot, ctx.q)
        fig = out if hasattr(out, "savefig") else getattr(out, "figure", None)
        if fig is None and isinstance(out, tuple):
            fig = next((o for o in out if hasattr(o, "savefig")), None)
        buf = io.BytesIO()
        fig.savefig(buf, format="png", dpi=110)
    except ImportError as exc:
        return Section("figures", "Figures", (), status="unavailable", reason=str(exc))
    except Exception as exc:
        return Section("figures", "Figures", (), status="unavailable",
                       reason=f"the picture could not be drawn ({type(exc).__name__}: {exc})")
    caption = "The arm at the numeric case, with its DH frames."
    return Section("figures", "Figures", (Figure(buf.getvalue(), caption, f"{ctx.robot.name}-arm.png"),))
