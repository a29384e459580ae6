"""Subcommands on Jacobians: jacobian, velocity, statics, singularities.

Each handler parses, calls the library, and formats; results carry their frame, reference point and row order.
"""

from __future__ import annotations

import argparse
import math

import numpy as np

from ..errors import ParseError
from ._common import (MAX_SYMBOLIC_ANALYSIS_JOINTS, add_common, add_q, check_values, joint_values, load, matrix_text, number_text, numbers_text,
                      require_finite,
                      require_symbolic_size, stage_printer)

ROWS = ("vx", "vy", "vz", "wx", "wy", "wz")
REFERENCE = "end-effector origin (after the tool transform)"


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("jacobian", help="Jacobian J0 (base axes) or Je (tool axes), numeric or symbolic")
    add_common(p)
    add_q(p, required=False)
    _frame(p)
    p.add_argument("--method", choices=["geometric", "differentiation", "propagation"], default="geometric",
                   help="route: joint axes of the frames, differentiation of FK, or Craig's velocity propagation")
    p.add_argument("--symbolic", action="store_true", help="the formulas (the default when -q is not given)")
    p.add_argument("--analytic", choices=["rpy", "zyz"], help="analytic Jacobian: rows (xdot, ydot, zdot, angle rates); numeric with -q, symbolic without")
    p.add_argument("--steps", action="store_true", help="with --method propagation: every omega_i and v_i (symbolic)")
    _sym_format(p)
    p.set_defaults(handler=cmd_jacobian)

    p = sub.add_parser("velocity", help="end-effector twist (v, w) from joint rates, numeric or symbolic")
    add_common(p)
    add_q(p, required=False)
    p.add_argument("--qd", metavar="QD", help="joint rates [rad/s or m/s; deg/s with --deg] (numeric route)")
    _frame(p)
    p.add_argument("--steps", action="store_true", help="omega_i and v_i of every frame (outward propagation)")
    p.add_argument("--symbolic", action="store_true",
                   help="the formulas in q and qd (the default when -q is not given)")
    _sym_format(p)
    p.set_defaults(handler=cmd_velocity)

    p = sub.add_parser("statics", help="joint torques balancing an end-effector wrench (f, n), numeric or symbolic")
    add_common(p)
    add_q(p, required=False)
    p.add_argument("--wrench", metavar="W",
                   help="fx, fy, fz[, nx, ny, nz] [N, N m] exerted by the end effector, at its origin (numeric route)")
    p.add_argument("--frame", choices=["base", "tool"], default=None,
                   help="axes of the wrench: base/world or tool (default base; tool for --symbolic --method "
                        "propagation, whose wrench starts in tool axes)")
    p.add_argument("--method", choices=["jacobian", "propagation"], default="jacobian",
                   help="tau = J^T F, or Craig's inward force propagation")
    p.add_argument("--steps", action="store_true", help="f_i and n_i of every frame (inward propagation)")
    p.add_argument("--symbolic", action="store_true",
                   help="tau as formulas of q and the wrench symbols f_x ... n_z (the default when -q is not given)")
    _sym_format(p)
    p.set_defaults(handler=cmd_statics)

    p = sub.add_parser("singularities", help="singular configurations: factored determinant, conditions, kinds")
    add_common(p)
    add_q(p, required=False)
    p.add_argument("--rows", metavar="ROWS", help="task rows of the Jacobian, e.g. vx,vy,wz (default: all six)")
    _frame(p, what="axes of the Jacobian whose rows are taken")
    _sym_format(p, simplify=False)
    p.set_defaults(handler=cmd_singularities)


def _frame(p, what: str = "axes of the result") -> None:
    p.add_argument("--frame", choices=["base", "tool"], default="base", help=f"{what}: base/world (J0) or tool (Je)")


def _sym_format(p, simplify: bool = True) -> None:
    g = p.add_mutually_exclusive_group()
    g.add_argument("--latex", action="store_true", help="symbolic output as LaTeX")
    g.add_argument("--markdown", action="store_true", help="symbolic output as Markdown with $$ math $$ blocks")
    p.add_argument("--shorthand", action="store_true", help="write cos(q1+q2) as C12, sin(q3) as S3")
    if simplify:
        p.add_argument("--simplify", choices=["none", "trig", "full"], default="trig", help="simplification policy")


def _formatter(args, q):
    import sympy as sp

    from .. import symbolic as S

    show = (lambda M: S.shorthand(M, q) if not hasattr(M, "shape") else S.shorthand_matrix(M, q)) \
        if args.shorthand else (lambda M: M)
    if getattr(args, "markdown", False):
        return lambda M: "$$\n" + sp.latex(show(M)) + "\n$$"
    if getattr(args, "latex", False):
        return lambda M: sp.latex(show(M))
    return lambda M: sp.pretty(show(M), use_unicode=True, wrap_line=False)


def _header(frame: str, what: str = "J") -> str:
    axes = "base/world axes (J0)" if frame == "base" else "tool axes (Je)"
    return f"{what} in {axes}; reference point: {REFERENCE}; rows (vx, vy, vz, wx, wy, wz)"


def _labelled(M: np.ndarray, labels=ROWS) -> str:
    body = matrix_text(M).split("\n")
    width = max(len(lab) for lab in labels)
    return "\n".join(f"{lab:>{width}} {row}" for lab, row in zip(labels, body))


def _q_out(args, robot, q):
    from ..model import JointType

    if not args.deg:
        return q
    rev = np.array([t is JointType.REVOLUTE for t in robot.joint_types])
    return np.where(rev, np.degrees(q), q)


def _q_text(args, robot, q) -> str:
    unit = "deg for revolute joints" if args.deg else "rad"
    return f"q = [{numbers_text(_q_out(args, robot, q))}] ({unit})"


# --- jacobian ------------------------------------------------------------------------------------------


def _symbolic_jacobian(robot, args) -> tuple[dict, list[str]]:
    import sympy as sp

    from .. import symbolic as S

    require_symbolic_size(robot, "jacobian --symbolic")
    q = S.joint_symbols(robot.dof).q
    fmt = _formatter(args, q)
    J = S.jacobian_sym(robot, args.method, args.frame, args.simplify)
    name = "J0" if args.frame == "base" else "Je"
    lines = [f"{robot.name}: symbolic Jacobian by {args.method}", _header(args.frame), f"{name} =", fmt(J)]
    data = {"J_symbolic": J, "J_latex": sp.latex(J)}
    if args.steps:
        if args.method != "propagation":
            raise ParseError("--steps goes with --method propagation")
        lines += ["", "outward velocity propagation (each vector in its own frame's axes):"]
        data["steps"] = _velocity_steps_sym(robot, args, fmt, lines)
    return data, lines


def _velocity_steps_sym(robot, args, fmt, lines: list[str]) -> list[dict]:
    """ω_i and v_i of every frame as formulas (symbolic outward propagation): printed lines appended to
    ``lines``, the JSON records returned."""
    from .. import symbolic as S

    steps = []
    for st in S.velocity_propagation_sym(robot, args.simplify).steps[1:]:
        lines += [f"omega_{st.label} =", fmt(st.omega), f"v_{st.label} =", fmt(st.v)]
        steps.append({"frame": st.label, "joint": st.joint, "omega": [str(e) for e in st.omega],
                      "v": [str(e) for e in st.v]})
    return steps


def cmd_jacobian(args: argparse.Namespace):
    from .. import numeric as N

    robot = load(args)
    data: dict = {"robot": robot.name, "frame": args.frame, "method": args.method, "reference_point": REFERENCE,
                  "rows": list(ROWS)}
    lines: list[str] = []
    if args.q is not None:  # a bad -q fails now, not after the symbolic work
        joint_values(args, robot, args.q)
    if args.symbolic or args.q is None:
        sdata, lines = _symbolic_jacobian(robot, args)
        data.update(sdata)
        if args.analytic:
            from .. import symbolic as S
            import sympy as sp

            Ja = S.analytic_jacobian_sym(robot, args.analytic, args.simplify)
            angles = ", ".join(str(a) for a in S.angle_symbols(args.analytic))
            lines += ["", f"analytic Jacobian Ja ({args.analytic}): rows (xdot, ydot, zdot, rates of {angles}), "
                      f"in terms of q and the current angles {angles}", "Ja =",
                      _formatter(args, S.joint_symbols(robot.dof).q)(Ja)]
            data.update({"Ja_symbolic": Ja, "Ja_latex": sp.latex(Ja), "representation": args.analytic})
    if args.q is not None:
        q = joint_values(args, robot, args.q)
        data["q"] = _q_out(args, robot, q)
        if args.analytic:
            Ja, phi = N.analytic_jacobian(robot, q, args.analytic)
            require_finite("jacobian", phi)  # rate rows are NaN at a representation singularity (warned)
            names = ("x", "y", "z") + (("roll", "pitch", "yaw") if args.analytic == "rpy" else ("phi", "theta", "psi"))
            conv = np.degrees(phi) if args.deg else phi
            data.update({"Ja": Ja, "representation": args.analytic, "angles": conv, "analytic_rows": list(names)})
            lines += ["" if lines else "", f"{robot.name}: analytic Jacobian ({args.analytic}) at {_q_text(args, robot, q)}",
                      f"rows (xdot, ydot, zdot, {', '.join(n + 'dot' for n in names[3:])}) in base/world axes",
                      f"angles: {', '.join(f'{n} = {t}' for n, t in zip(names[3:], numbers_text(conv).split(', ')))} "
                      f"({'deg' if args.deg else 'rad'})", _labelled(Ja, names)]
        else:
            J = {"geometric": N.geometric_jacobian, "differentiation": N.differentiation_jacobian,
                 "propagation": N.propagation_jacobian}[args.method](robot, q, args.frame)
            require_finite("jacobian", J)
            data["J"] = J
            if lines:
                lines.append("")
            lines += [f"{robot.name}: Jacobian by {args.method} at {_q_text(args, robot, q)}", _header(args.frame),
                      "(columns: per rad for revolute joints, per m for prismatic ones)", _labelled(J)]
    return data, "\n".join(line for line in lines if line is not None)


# --- velocity ------------------------------------------------------------------------------------------


def _symbolic_velocity(robot, args) -> tuple[dict, list[str]]:
    """v and ω of the end effector as formulas of q and q̇ (J q̇), and with --steps every ω_i, v_i."""
    import sympy as sp

    from .. import symbolic as S

    require_symbolic_size(robot, "velocity --symbolic")
    js = S.joint_symbols(robot.dof)
    fmt = _formatter(args, js.q)
    J = S.jacobian_sym(robot, "geometric", args.frame, args.simplify)
    twist = S.simplify_matrix(J * sp.Matrix(js.qd), args.simplify)
    v, w = sp.ImmutableMatrix(twist[:3, :]), sp.ImmutableMatrix(twist[3:, :])
    lines = [f"{robot.name}: symbolic end-effector twist = J q̇", _header(args.frame, "twist (v, w)"),
             "v =", fmt(v), "w =", fmt(w)]
    data = {"v_symbolic": [str(e) for e in v], "omega_symbolic": [str(e) for e in w],
            "v_latex": sp.latex(v), "omega_latex": sp.latex(w)}
    if args.steps:
        lines += ["", "outward velocity propagation (omega_i, v_i of frame {i} in its own axes; Craig 5.45-5.47):"]
        data["steps"] = _velocity_steps_sym(robot, args, fmt, lines)
    return data, lines


def cmd_velocity(args: argparse.Namespace):
    robot = load(args)
    if args.q is not None and args.qd is None:
        raise ParseError("--qd is required with -q (the joint rates); for formulas leave out -q or add --symbolic")
    if args.symbolic or args.q is None:
        if args.q is not None:  # a bad -q fails now, not after the symbolic work
            joint_values(args, robot, args.q)
            joint_values(args, robot, args.qd, what="qd", rates=True)
        data, lines = _symbolic_velocity(robot, args)
        data.update({"robot": robot.name, "frame": args.frame, "reference_point": REFERENCE})
        if args.q is None:
            return data, "\n".join(lines)
        numeric, text = cmd_velocity_numeric(args, robot)
        data.update(numeric)
        return data, "\n".join(lines + ["", text])
    return cmd_velocity_numeric(args, robot)


def cmd_velocity_numeric(args: argparse.Namespace, robot):
    from .. import numeric as N

    q = joint_values(args, robot, args.q)
    qd = joint_values(args, robot, args.qd, what="qd", rates=True)
    twist = N.end_effector_twist(robot, q, qd, args.frame)
    require_finite("velocity", twist)
    ang = np.degrees if args.deg else (lambda x: x)
    aunit = "deg/s" if args.deg else "rad/s"
    data = {"robot": robot.name, "q": _q_out(args, robot, q), "qd": _q_out(args, robot, qd), "frame": args.frame,
            "reference_point": REFERENCE, "twist": np.concatenate([twist[:3], ang(twist[3:])]),
            "v": twist[:3], "omega": ang(twist[3:]), "angle_unit": "deg" if args.deg else "rad"}
    lines = [f"{robot.name}: end-effector twist at {_q_text(args, robot, q)}", _header(args.frame, "twist (v, w)"),
             f"v = [{numbers_text(twist[:3])}] m/s",
             f"w = [{numbers_text(ang(twist[3:]))}] {aunit}"]
    if args.steps:
        prop = N.velocity_propagation(robot, q, qd)
        lines += ["", "outward propagation (omega_i, v_i of frame {i} in its own axes):"]
        for lab, w, v in zip(prop.labels, prop.omega, prop.v):
            lines.append(f"  {{{lab}}}: omega = [{numbers_text(ang(w))}] {aunit}, v = [{numbers_text(v)}] m/s")
        data["steps"] = [{"frame": lab, "omega": ang(w), "v": v} for lab, w, v in zip(prop.labels, prop.omega, prop.v)]
    return data, "\n".join(lines)


# --- statics -------------------------------------------------------------------------------------------


def _wrench(text: str) -> np.ndarray:
    from ..io import parse_values

    W = parse_values(text, what="--wrench")
    if W.size > 6:
        raise ParseError(f"--wrench: expected 3 values (fx, fy, fz) or 6 (fx, fy, fz, nx, ny, nz), got {W.size}")
    W = check_values(W, "--wrench")
    if W.size not in (3, 6):
        raise ParseError(f"--wrench: expected 3 values (fx, fy, fz) or 6 (fx, fy, fz, nx, ny, nz), got {W.size}")
    return W


def _symbolic_statics(robot, args) -> tuple[dict, list[str]]:
    """τ as formulas of q and the wrench symbols: J^T F, or Craig's inward propagation (with every f_i, n_i)."""
    import sympy as sp

    from .. import symbolic as S

    require_symbolic_size(robot, "statics --symbolic")
    q = S.joint_symbols(robot.dof).q
    fmt = _formatter(args, q)
    W = sp.Matrix(S.wrench_symbols())
    axes = "base/world" if args.frame == "base" else "tool"
    lines = [f"{robot.name}: symbolic joint torques", f"wrench (f_x, f_y, f_z, n_x, n_y, n_z) exerted by the end "
             f"effector, in {axes} axes, at the {REFERENCE}"]
    data: dict = {"wrench_symbols": [str(x) for x in W]}
    if args.method == "propagation":
        if args.frame == "base":
            raise ParseError("--symbolic --method propagation starts from the wrench in tool axes (Craig 5.80-5.81): "
                             "use --frame tool, or --method jacobian for a wrench in base axes")
        prop = S.force_propagation_sym(robot, args.simplify)
        tau = sp.ImmutableMatrix(prop.tau)
        lines.append("method: inward force propagation (Craig 5.80-5.81): tau_i = n_i . z_i (revolute), f_i . z_i "
                     "(prismatic)")
        if args.steps:
            lines += ["", "inward propagation (f_i, n_i at the origin of {i}, in its axes):"]
            steps = []
            for st in prop.steps:
                lines += [f"f_{st.label} =", fmt(st.f), f"n_{st.label} =", fmt(st.n)]
                steps.append({"frame": st.label, "f": [str(e) for e in st.f], "n": [str(e) for e in st.n],
                              "joint": None if st.joint is None else st.joint + 1,
                              "tau": None if st.tau is None else str(st.tau)})
            data["steps"] = steps
            lines.append("")
    else:
        if args.steps:
            raise ParseError("--steps goes with --method propagation")
        J = S.jacobian_sym(robot, "geometric", args.frame, args.simplify)
        tau = S.simplify_matrix(J.T * W, args.simplify)
        lines.append("method: tau = J^T F")
    lines += ["tau =", fmt(tau)]
    data.update({"tau_symbolic": [str(e) for e in tau], "tau_latex": sp.latex(tau)})
    return data, lines


def cmd_statics(args: argparse.Namespace):
    robot = load(args)
    if args.frame is None:
        args.frame = "tool" if (args.symbolic or args.q is None) and args.method == "propagation" else "base"
    if args.q is not None and args.wrench is None:
        raise ParseError("--wrench is required with -q; for formulas leave out -q or add --symbolic")
    if args.symbolic or args.q is None:
        if args.q is not None:  # a bad -q or --wrench fails now, not after the symbolic work
            joint_values(args, robot, args.q)
            _wrench(args.wrench)
        data, lines = _symbolic_statics(robot, args)
        data.update({"robot": robot.name, "frame": args.frame, "method": args.method, "reference_point": REFERENCE})
        if args.q is None:
            return data, "\n".join(lines)
        numeric, text = cmd_statics_numeric(args, robot)
        data.update(numeric)
        return data, "\n".join(lines + ["", text])
    return cmd_statics_numeric(args, robot)


def cmd_statics_numeric(args: argparse.Namespace, robot):
    from .. import numeric as N
    from ..model import JointType

    q = joint_values(args, robot, args.q)
    W = _wrench(args.wrench)
    prop = N.force_propagation(robot, q, W, args.frame)
    tau = N.joint_torques(robot, q, W, args.frame) if args.method == "jacobian" else prop.tau
    require_finite("statics", tau, prop.f, prop.n)
    units = ["N m" if t is JointType.REVOLUTE else "N" for t in robot.joint_types]
    F6 = N.as_wrench(W)
    data = {"robot": robot.name, "q": _q_out(args, robot, q), "wrench": F6, "frame": args.frame,
            "method": args.method, "reference_point": REFERENCE, "tau": tau, "units": units}
    axes = "base/world" if args.frame == "base" else "tool"
    lines = [f"{robot.name}: joint torques at {_q_text(args, robot, q)}",
             f"wrench (f, n) = [{numbers_text(F6)}] N, N m exerted by the end effector, "
             f"in {axes} axes, at the {REFERENCE}",
             f"method: {'tau = J^T F' if args.method == 'jacobian' else 'inward force propagation (Craig 5.80-5.81)'}"]
    tau_text = numbers_text(tau, sep="\n").split("\n")
    lines += [f"  tau{k + 1} = {t} {u}" for k, (t, u) in enumerate(zip(tau_text, units))]
    if args.steps:
        lines += ["", "inward propagation (f_i, n_i at the origin of {i}, in its axes):"]
        for lab, f, n in zip(prop.labels, prop.f, prop.n):
            lines.append(f"  {{{lab}}}: f = [{numbers_text(f)}] N, n = [{numbers_text(n)}] N m")
        data["steps"] = [{"frame": lab, "f": f, "n": n} for lab, f, n in zip(prop.labels, prop.f, prop.n)]
    return data, "\n".join(lines)


# --- singularities -------------------------------------------------------------------------------------


def _value_text(v: float, revolute: bool, deg: bool) -> str:
    if not revolute:
        return f"{number_text(v)} m"
    if deg:
        return f"{number_text(math.degrees(v))}°"
    return f"{number_text(v)} rad ({number_text(math.degrees(v))}°)"


def _condition_lines(cond, robot, args, fmt) -> list[str]:
    import sympy as sp

    from ..model import JointType

    eq = fmt(sp.Eq(cond.factor, 0, evaluate=False)) if (args.latex or args.markdown) else f"{cond.factor} = 0"
    if args.shorthand and not (args.latex or args.markdown):
        eq = f"{fmt(cond.factor)} = 0" if "\n" not in fmt(cond.factor) else eq
    lines = [f"- {eq}"]
    if cond.solutions:
        parts: dict[str, list[str]] = {}
        for s in cond.solutions:
            k = int(s.variable[1:]) - 1
            rev = robot.joint_types[k] is JointType.REVOLUTE
            vals = ", ".join(_value_text(v, rev, args.deg) + ("" if ok else " (outside limits)")
                             for v, ok in zip(s.values, s.in_limits))
            expr = f"{s.expression} = " if s.expression is not None and not s.expression.is_number else ""
            parts.setdefault(s.variable, []).append(expr + vals)
        lines.append("    → " + "; ".join(f"{var} = {', '.join(vals)}" for var, vals in parts.items()))
    else:
        lines.append("    (kept as an equation: no closed form in one variable)")
    lines.append(f"    kind: {cond.kind} — {cond.explanation}")
    return lines


def _measures(robot, args, rows_idx) -> tuple[dict, list[str]]:
    from .. import numeric as N

    q = joint_values(args, robot, args.q)
    J = N.geometric_jacobian(robot, q, args.frame)[rows_idx, :]
    require_finite("singularities", J)
    s = N.singular_values(J)
    lin = [i for i, r in enumerate(rows_idx) if r < 3] or list(range(len(rows_idx)))
    vel, frc = N.velocity_ellipsoid(J[lin]), N.force_ellipsoid(J[lin])
    which = ", ".join(ROWS[rows_idx[i]] for i in lin)
    data = {"q": _q_out(args, robot, q), "J": J, "singular_values": s, "manipulability": float(N.manipulability(J)),
            "condition_number": float(N.condition_number(J)), "smallest_singular_value": float(s[-1]),
            "rank": int(N.jacobian_rank(J)), "singular": bool(N.is_singular(J)),
            "ellipsoid_rows": [ROWS[rows_idx[i]] for i in lin],
            "velocity_ellipsoid": {"axes": vel.axes, "radii": vel.radii},
            "force_ellipsoid": {"axes": frc.axes, "radii": frc.radii}}
    lines = ["", f"numeric measures at {_q_text(args, robot, q)} (rows {', '.join(ROWS[i] for i in rows_idx)}):",
             f"  singular values: {numbers_text(s)}",
             f"  rank {data['rank']} of {min(J.shape)} (threshold 1e-9 · largest singular value)"
             + ("  → SINGULAR" if data["singular"] else ""),
             f"  manipulability (Yoshikawa) sqrt(det J J^T) = "
             f"{number_text(data['manipulability'], scale=float(np.prod(s[:-1])) if len(s) > 1 else 1.0)}",
             f"  condition number = {number_text(data['condition_number'])}, smallest singular value = "
             f"{number_text(s[-1], scale=s[0])}",
             f"  velocity ellipsoid (rows {which}, |qd| <= 1): radii {numbers_text(vel.radii)}",
             f"  force ellipsoid (rows {which}, |tau| <= 1): radii {numbers_text(frc.radii)}",
             "  axes (columns, same for both):", matrix_text(vel.axes, indent="    ")]
    return data, lines


def cmd_singularities(args: argparse.Namespace):
    import sympy as sp

    from .. import symbolic as S
    from ..numeric import select_rows

    robot = load(args)
    try:
        rows_idx = select_rows(args.rows)
    except ValueError as exc:
        raise ParseError(f"--rows: {exc}") from None
    rows = "auto" if args.rows is None else ",".join(ROWS[i] for i in rows_idx)
    if args.q is not None:
        joint_values(args, robot, args.q)  # a bad -q fails now, not after minutes of symbolic work
    require_symbolic_size(robot, "singularities", MAX_SYMBOLIC_ANALYSIS_JOINTS)
    res = S.singularity_analysis(robot, rows, args.frame, progress=stage_printer(args, "singularities"))
    rows_idx = [ROWS.index(r) for r in res.rows]  # the task rows analysed (an arm of < 6 joints: its own)
    fmt = _formatter(args, S.joint_symbols(robot.dof).q)
    det_text = fmt(res.determinant)
    lines = [f"{robot.name}: singularities", f"matrix: {res.matrix_note}", f"measure: {res.measure}"]
    if args.markdown:
        lines = [f"## {robot.name}: singularities", "", f"matrix: {res.matrix_note}", "", f"measure: {res.measure}", ""]
    lines += ["matrix =", fmt(res.matrix), f"{res.measure} =", det_text]
    if res.constant_factors:
        lines.append("constant factors (assumed non-zero): " + ", ".join(str(c) for c in res.constant_factors))
    if res.everywhere:
        lines += ["", f"SINGULAR EVERYWHERE: rank {res.generic_rank} of {res.full_rank} for every q ({res.reason})"]
    elif res.conditions:
        lines += ["", "singular when:"]
        for cond in res.conditions:
            lines += _condition_lines(cond, robot, args, fmt)
    elif "minors" in res.measure:
        # Non-square J: a common factor of all minors is sufficient for a rank loss, not necessary. Without
        # one, singular configurations (if any) are where all minors vanish together: not solved here.
        lines += ["", "no common factor of the minors: any singular configuration lies where ALL the minors vanish "
                  "together, which is not solved symbolically here (redundant arms, e.g. 7 joints, do have such "
                  "configurations); check a configuration with -q (rank, smallest singular value), or pick a "
                  "square sub-Jacobian with --rows"]
    else:
        lines += ["", "no singular configuration: the determinant never vanishes"]
    data = {"robot": robot.name, "rows": list(res.rows), "frame": args.frame, "matrix_note": res.matrix_note,
            "measure": res.measure, "matrix": res.matrix, "determinant": str(res.determinant),
            "determinant_latex": sp.latex(res.determinant), "constant_factors": [str(c) for c in res.constant_factors],
            "everywhere": res.everywhere, "generic_rank": res.generic_rank, "full_rank": res.full_rank,
            "reason": res.reason, "angle_unit": "deg" if args.deg else "rad",
            # False when J is not square and its minors share no factor: the singular set is not solved then
            "conditions_complete": not ("minors" in res.measure and not res.conditions and not res.everywhere),
            "conditions": [{"equation": f"{c.factor} = 0", "latex": sp.latex(c.factor) + " = 0",
                            "variables": list(c.variables), "kind": c.kind, "explanation": c.explanation,
                            "solutions": [{"variable": s.variable,
                                           "expression": None if s.expression is None else str(s.expression),
                                           "values": [math.degrees(v) if args.deg and _is_rev(robot, s.variable) else v
                                                      for v in s.values],
                                           "in_limits": list(s.in_limits)} for s in c.solutions]}
                           for c in res.conditions]}
    if args.q is not None:
        mdata, mlines = _measures(robot, args, rows_idx)
        data["measures"] = mdata
        lines += mlines
    return data, "\n".join(lines)


def _is_rev(robot, var: str) -> bool:
    from ..model import JointType

    return robot.joint_types[int(var[1:]) - 1] is JointType.REVOLUTE
