"""The report's dynamics section: the Lagrange steps, M, c, g, and their values at the numeric case.

For a small arm (at most :data:`SYMBOLIC_MAX_DOF` joints) the Euler–Lagrange derivation is printed step by step
as a person writes it (Spong, Hutchinson & Vidyasagar 2006, sec. 7.1–7.4): the centre of mass p_c of each
link and its velocity, ω, the kinetic and potential energies, L = K − P, ∂L/∂q̇_k, d/dt ∂L/∂q̇_k, ∂L/∂q_k and
τ_k, then the split τ = M(q) q̈ + c(q, q̇) + g(q) (+ friction).  Arms of up to :data:`HAND_FORM_MAX_DOF`
joints get M, c, g in closed form entry by entry (``lagrangian_dynamics``, hand form); longer ones (7 joints:
entries of pages) and arms with generic twists as recursions in named link quantities (``recursive_dynamics``,
where ``dynamics_form`` picks it), evaluated at the case.  The numbers at the case come from the numeric engine
(CRBA mass matrix, Christoffel c, gravity torques); the symbolic results evaluated at the same point are
compared with them, and c + g is compared with the recursive Newton–Euler torques at q̈ = 0 (Craig 2005,
sec. 6.5): independent routes.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import sympy as sp

from ..symbolic import HAND_FORM_MAX_DOF
from . import _capabilities
from ._context import Context
from ._derivation import Equation, Numbers, Section, Text

__all__ = ["section_dynamics", "SYMBOLIC_MAX_DOF", "HAND_FORM_MAX_DOF", "symbolic_terms_at"]

SYMBOLIC_MAX_DOF = 3
AGREE_TOL = 1e-9


def _dot_names(expr: Any, n: int) -> dict:
    names = {}
    for s in getattr(expr, "free_symbols", ()):
        t = str(s)
        for pre, cmd in (("qdd", "\\ddot{q}"), ("qd", "\\dot{q}")):
            if t.startswith(pre) and t[len(pre):].isdigit():
                names[s] = f"{cmd}_{{{t[len(pre):]}}}"
                break
    return names


def _tex(ctx: Context, e: Any) -> str:
    """LaTeX with C_12/S_3 shorthand and dotted rates."""
    e = sp.ImmutableMatrix(e) if isinstance(e, sp.MatrixBase) else sp.sympify(e)  # safe: e comes from the library (sympy or a number), never user text
    e = ctx.short(e)
    return sp.latex(e, mat_str="bmatrix", mat_delim="", symbol_names=_dot_names(e, ctx.robot.dof))


def _eq(ctx: Context, lhs: str, e: Any, note: str = "") -> Equation | Text:
    if ctx.too_long(e):
        return Text(f"(${lhs}$ is too long to print usefully.)")
    return Equation(lhs, _tex(ctx, e), note=note, shorthand=True)


def symbolic_terms_at(ctx: Context, terms: Any) -> dict[str, np.ndarray]:
    """The symbolic M, c, g (and friction) evaluated at the numeric case (parameters, q, q̇ substituted)."""
    subs = dict(ctx.param_subs)
    subs.update(zip(terms.q, [sp.Float(v, 30) for v in ctx.q]))
    qd = ctx.qd if ctx.qd is not None else np.zeros(ctx.robot.dof)
    subs.update(zip(terms.qd, [sp.Float(v, 30) for v in qd]))
    out = {}
    for name in ("M", "c", "g", "friction"):
        M = getattr(terms, name)
        val = np.array(M.xreplace(subs).evalf(30).tolist(), dtype=float)
        out[name] = val.reshape(-1) if M.shape[1] == 1 else val
    return out


def _lagrange_steps(ctx: Context, st: Any) -> list:
    """Every step of the Euler–Lagrange derivation (data from denavit.symbolic.lagrange_steps)."""
    steps: list = [Text("Each link's centre of mass $p_{c,i}$ in base axes, its velocity $\\dot p_{c,i} = "
                        "\\sum_j \\frac{\\partial p_{c,i}}{\\partial q_j}\\dot q_j$ (chain rule), its angular velocity "
                        "$\\omega_i$, kinetic energy $K_i = \\tfrac12 m_i \\dot p_{c,i}^T\\dot p_{c,i} + \\tfrac12 "
                        "\\omega_i^T R_i I_i R_i^T \\omega_i$ and potential energy $P_i = -m_i\\, g_0^T p_{c,i}$:")]
    steps.append(_eq(ctx, "g_0", st.gravity, "gravity in base axes"))
    for k, (row, body) in enumerate(st.pieces):
        i = f"{k + 1}"
        steps.append(Text(f"Link {body + 1} (inertial data of DH row {row + 1}):"))
        steps.append(_eq(ctx, f"p_{{c,{i}}}", st.p_c[k]))
        steps.append(_eq(ctx, f"\\dot p_{{c,{i}}}", st.pd_c[k]))
        steps.append(_eq(ctx, f"\\omega_{{{i}}}", st.omega[k]))
        steps.append(_eq(ctx, f"K_{{{i}}}", st.K_parts[k]))
        steps.append(_eq(ctx, f"P_{{{i}}}", st.P_parts[k]))
    if len(st.K_parts) > len(st.pieces):
        steps.append(_eq(ctx, "K_{m}", st.K_parts[-1], "motor (armature) inertia"))
    steps += [Text("The Lagrangian $L = K - P$ with"), _eq(ctx, "K", st.K), _eq(ctx, "P", st.P),
              Text("The Euler-Lagrange equations $\\tau_k = \\frac{d}{dt}\\frac{\\partial L}{\\partial \\dot q_k} - "
                   "\\frac{\\partial L}{\\partial q_k}$ (Spong et al. 2006, eq. 7.39), with $\\frac{d}{dt}$ by the "
                   "chain rule in $q$ and $\\dot q$:")]
    for k in range(len(st.q)):
        j = k + 1
        steps.append(_eq(ctx, f"\\frac{{\\partial L}}{{\\partial \\dot q_{{{j}}}}}", st.dL_dqd[k]))
        steps.append(_eq(ctx, f"\\frac{{d}}{{dt}}\\frac{{\\partial L}}{{\\partial \\dot q_{{{j}}}}}", st.ddt_dL_dqd[k]))
        steps.append(_eq(ctx, f"\\frac{{\\partial L}}{{\\partial q_{{{j}}}}}", st.dL_dq[k]))
        steps.append(_eq(ctx, f"\\tau_{{{j}}}", st.tau[k]))
    return steps


def _symbolic(ctx: Context, steps: list) -> Any:
    """Append the symbolic derivation; return its DynamicsTerms (None when not derived)."""
    robot = ctx.robot
    found = _capabilities.capability("denavit.symbolic", "lagrange_steps")
    if found is None:
        steps.append(Text("The symbolic Lagrange derivation is not available in this installation."))
        return None
    if robot.dof > SYMBOLIC_MAX_DOF:
        hand = _capabilities.capability("denavit.symbolic", "lagrangian_dynamics")
        recursive = _capabilities.capability("denavit.symbolic", "recursive_dynamics")
        form = _capabilities.capability("denavit.symbolic", "dynamics_form")
        # the recursive form where the symbolic engine would pick it (7 joints, or generic twists: a generic
        # 6R's hand form takes more than ten minutes)
        if recursive is not None and (robot.dof > HAND_FORM_MAX_DOF or (form and form[1](robot) == "recursive")):
            _recursive_form(ctx, steps, recursive)
            return None
        if hand is not None and robot.dof <= HAND_FORM_MAX_DOF:
            return _hand_form(ctx, steps, hand)
        steps.append(Text(f"The symbolic Lagrange derivation is printed for arms of at most {SYMBOLIC_MAX_DOF} joints, "
                          f"and M, c, g in closed form for at most {HAND_FORM_MAX_DOF}; for {robot.dof} joints the "
                          "entries run to pages (the function lagrangian_dynamics of denavit.symbolic derives them, "
                          "in under a minute). Shown instead: the same quantities at the numeric case, from the "
                          "numeric engine: the energies $K$ and $P$, then $M$, $C$, $c$ and $g$, with $c + g$ "
                          "checked against the recursive Newton-Euler torques."))
        return None
    try:
        st = found[1](robot, ctx.simplify)
    except Exception as exc:  # another area's function: report, do not crash the report
        steps.append(Text(f"The symbolic derivation ({found[0]}) failed: {type(exc).__name__}: {exc}."))
        return None
    steps += _lagrange_steps(ctx, st)
    t = st.terms
    steps.append(Text("Collecting the terms in $\\ddot q$, in $\\dot q$ and the rest: $\\tau = M(q)\\ddot q + "
                      "c(q, \\dot q) + g(q)$" + (" + \\tau_f(\\dot q)" if any(e != 0 for e in t.friction) else "")
                      + ", with $c = C(q, \\dot q)\\,\\dot q$ and $C$ from the Christoffel symbols of $M$ "
                      "(Spong et al. 2006, eq. 7.57):"))
    steps.append(_eq(ctx, "M(q)", t.M))
    if t.C is not None:
        steps.append(_eq(ctx, "C(q, \\dot q)", t.C))
    steps.append(_eq(ctx, "c(q, \\dot q)", t.c))
    steps.append(_eq(ctx, "g(q)", t.g))
    if any(e != 0 for e in t.friction):
        steps.append(_eq(ctx, "\\tau_f(\\dot q)", t.friction))
    return t


def _hand_form(ctx: Context, steps: list, found) -> Any:
    """M, c, g of a longer arm in closed form, entry by entry (no step-by-step Lagrange derivation)."""
    from ..symbolic import shorthand

    robot = ctx.robot
    try:
        t = found[1](robot, "trig", coriolis=False)
    except Exception as exc:  # another area's function: report, do not crash the report
        steps.append(Text(f"The symbolic dynamics ({found[0]}) failed: {type(exc).__name__}: {exc}."))
        return None
    steps.append(Text(f"For {robot.dof} joints the step-by-step Lagrange derivation runs to pages; M, c and g are "
                      "given in closed form instead, entry by entry (the same Lagrange equations written with "
                      "Jacobians, $M = \\sum m J_v^T J_v + J_\\omega^T I J_\\omega$, $g = -\\sum m J_v^T g_0$, "
                      "$c$ from the Christoffel symbols of $M$; Spong et al. 2006, sec. 7.3). Consecutive joints "
                      "with parallel axes use angle sums ($C_{23} = \\cos(q_2 + q_3)$); row $j$ of $M$ is written in "
                      "the angles after joint $j$, on which it alone depends. $M$ is symmetric: $M_{kj} = M_{jk}$."))

    def entry(lhs: str, e: Any) -> None:
        if ctx.too_long(e):
            steps.append(Text(f"(${lhs}$ is too long to print usefully.)"))
            return
        e = _decimals(e)
        e = shorthand(e, ctx.syms.q, collapse=False)
        steps.append(Equation(lhs, sp.latex(e, symbol_names=_dot_names(e, robot.dof)), shorthand=True))

    n = robot.dof
    for j in range(n):
        for k in range(j, n):
            entry(f"M_{{{j + 1}{k + 1}}}", t.M[j, k])
    for k in range(n):
        entry(f"c_{{{k + 1}}}", t.c[k])
    for k in range(n):
        entry(f"g_{{{k + 1}}}", t.g[k])
    if any(e != 0 for e in t.friction):  # decimals as in M, c, g (was 725227721/125000000 for the file's 5.801821768)
        steps.append(_eq(ctx, "\\tau_f(\\dot q)", t.friction.applyfunc(_decimals)))
    return t


def _decimals(e: Any) -> Any:
    """The exact decimals the symbolic engine keeps (so that terms cancel) shown as decimals: 0.0202, not
    2527/125000 (six significant digits; small fractions such as 5/4 stay)."""
    return e.xreplace({r: sp.Float(r, 6) for r in e.atoms(sp.Rational) if r.q > 12})


def _recursive_form(ctx: Context, steps: list, found) -> None:
    """M, c, g of an arm whose entries run to pages, as recursions in named link quantities (Craig 2005 ch. 6,
    Featherstone 2008 ch. 6), evaluated at the case and checked against the numeric engine."""
    from .. import numeric as N
    from ..symbolic import format_recursive

    robot = ctx.robot
    try:
        rd = found[1](robot)
        tex = format_recursive(rd, "latex")
    except Exception as exc:  # another area's function: report, do not crash the report
        steps.append(Text(f"The symbolic dynamics ({found[0]}) failed: {type(exc).__name__}: {exc}."))
        return
    steps.append(Text(f"For {robot.dof} joints the entries of M, c, g expanded run to pages; they are written as "
                      "recursions over the links instead, each quantity a short formula in the previous ones "
                      "(evaluate in order). Body frame $B_j$: attached to body $j$, $z$ along joint $j$'s axis; "
                      "$m^b, h^b, J^b$: mass, first moment and inertia of body $j$ about the origin of $B_j$; "
                      "$m^c, h^c, J^c$: the same for the composite body $j \\dots n$; $p^k_j, L^k_j$: linear and "
                      "angular momentum (about the origin of $B_j$) of composite body $k$ for a unit rate of joint "
                      "$k$, $M_{jk}$ its $z$ component; $\\omega, \\dot\\omega, a$: Newton-Euler with $\\ddot q = 0$, "
                      "no gravity, $F, N$ what body $j$ needs, $f, n$ what joint $j$ transmits, $c_j = n_{jz}$; "
                      "$e_j$: direction of gravity in $B_j$, $g_j = -g\\,\\hat z\\cdot(h^c_j \\times e_j)$. "
                      "$C_i = \\cos q_i$, $S_i = \\sin q_i$; $M$ is symmetric."))
    body = tex.removeprefix("\\begin{aligned}\n").removesuffix("\n\\end{aligned}")
    for row in body.split(" \\\\\n"):
        if "&=" in row:
            lhs, rhs = (x.strip() for x in row.split("&=", 1))
            steps.append(Equation(lhs, rhs, shorthand=True))
    values = {**dict(ctx.param_subs), **dict(zip(rd.q, ctx.q))}
    values.update(zip(rd.qd, ctx.qd if ctx.qd is not None else np.zeros(robot.dof)))
    M, c, g = rd.at(values)
    qd = ctx.qd if ctx.qd is not None else np.zeros(robot.dof)
    steps.append(Text("Check, these formulas at the case vs the numeric engine: "
                      f"M {_agree(M, N.mass_matrix(robot, ctx.q))}; c {_agree(c, N.coriolis_vector(robot, ctx.q, qd))}; "
                      f"g {_agree(g, N.gravity_torques(robot, ctx.q))}."))


def _agree(a: np.ndarray, b: np.ndarray) -> str:
    err = float(np.max(np.abs(np.asarray(a) - np.asarray(b)))) if np.size(a) else 0.0
    return ("agree" if err < AGREE_TOL * max(1.0, float(np.max(np.abs(b))) if np.size(b) else 1.0) else "DISAGREE") \
        + f" (largest difference {err:.1e})"


def section_dynamics(ctx: Context) -> Section:
    """Lagrange steps and M, c, g (symbolic for small arms) and M, c, g at the numeric case."""
    from .. import numeric as N

    robot = ctx.robot
    lead = (Text("Equations of motion (Lagrange): $M(q)\\ddot q + c(q, \\dot q) + g(q) = \\tau$, from "
                 "$\\frac{d}{dt}\\frac{\\partial L}{\\partial \\dot q_i} - \\frac{\\partial L}{\\partial q_i} = "
                 "\\tau_i$ with $L = K - P$ (Spong et al. 2006, ch. 7)."),)
    if not robot.has_dynamics:
        return Section("dynamics", "Dynamics", lead, status="skipped", reason="the robot file has no inertial data")
    if not all(_capabilities.capability("denavit.numeric", f) for f in ("mass_matrix", "coriolis_vector",
                                                                           "gravity_torques")):
        return Section("dynamics", "Dynamics", lead, status="unavailable",
                       reason="rigid-body dynamics (mass_matrix) is not available in this installation of denavit")
    steps: list = list(lead)
    terms = _symbolic(ctx, steps)
    q = ctx.q
    qd = ctx.qd if ctx.qd is not None else np.zeros(robot.dof)
    M = N.mass_matrix(robot, q)
    c = N.coriolis_vector(robot, q, qd)
    g = N.gravity_torques(robot, q)
    rate = "at the numeric case" + ("" if ctx.qd is not None else " with $\\dot q = 0$ (no --qd given)")
    steps.append(Text(f"Values {rate}, from the numeric engine (mass matrix by the composite-rigid-body algorithm, "
                      "c from the Christoffel symbols of the exact $\\partial M/\\partial q$, g from the potential "
                      "energy gradient):"))
    if terms is None and callable(getattr(N, "potential_energy", None)):
        steps.append(Numbers("K = \\tfrac12\\,\\dot q^T M(q)\\,\\dot q", np.array(0.5 * qd @ M @ qd),
                             note="kinetic energy [J]"))
        steps.append(Numbers("P", np.array(float(N.potential_energy(robot, q))), note="potential energy [J]"))
    steps.append(Numbers("M(q)", M))
    if ctx.qd is not None:
        steps.append(Numbers("\\dot q", qd))
        steps.append(Numbers("C(q, \\dot q)", N.coriolis_matrix(robot, q, qd)))
    steps.append(Numbers("c(q, \\dot q)", c))
    steps.append(Numbers("g(q)", g))
    if terms is not None:
        at = symbolic_terms_at(ctx, terms)
        steps.append(Text(f"Check, the symbolic M, c, g at the case vs the numeric engine: M {_agree(at['M'], M)}; "
                          f"c {_agree(at['c'], c)}; g {_agree(at['g'], g)}."))
    if callable(getattr(N, "rnea", None)):
        tau0 = N.rnea(robot, q, qd, np.zeros(robot.dof))
        fr = N.friction_torques(robot, qd) if callable(getattr(N, "friction_torques", None)) else 0.0
        if np.any(fr != 0):
            steps.append(Numbers("\\tau_f(\\dot q)", fr, note="joint friction: viscous and Coulomb"))
        steps.append(Numbers("\\tau(q, \\dot q, \\ddot q = 0)", tau0,
                             note="recursive Newton-Euler: the torques that hold this motion without acceleration"))
        steps.append(Text(f"Second route: Newton-Euler $\\tau(q, \\dot q, 0)$ vs $c + g + \\tau_f$: "
                          f"{_agree(tau0, c + g + fr)}."))
    return Section("dynamics", "Dynamics", tuple(steps))
