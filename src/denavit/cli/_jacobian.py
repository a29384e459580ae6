"""Subcommands on Jacobians: jacobian, velocity, statics (singularities: :mod:`._singularities`).

Each handler parses, calls the library, and formats; results carry their frame, reference point and row order.
"""

from __future__ import annotations

import argparse
import re

import numpy as np

from .._constants import TWIST_ROWS as ROWS
from ..errors import ParseError
from ._common import (add_common, add_q, check_values, joint_values, load, matrix_text, numbers_text, require_finite,
                      require_symbolic_size)
from ._kin_derivatives import (add_kin_derivative_args, analytic_numeric, check_analytic_symbolic, cmd_kin_derivatives,
                               wants_kin_derivatives)
from ._shared import add_sym_format, q_out, q_text, sym_formatter

REFERENCE = "end-effector origin (after the tool transform)"


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("jacobian", help="Jacobian J0 (base axes), Je (tool axes) or iJ (DH frame i's axes), numeric "
                       "or symbolic")
    add_common(p)
    add_q(p, required=False)
    p.add_argument("--frame", type=_frame_arg, default="base", metavar="{base,tool,i}",
                   help="axes of the result: base/world (J0), tool (Je) or the DH frame i = 0 ... N (iJ = "
                        "diag(R_0_i^T, R_0_i^T) J0; same reference point)")
    p.add_argument("--method", choices=["geometric", "differentiation", "propagation"], default="geometric",
                   help="route: joint axes of the frames, differentiation of FK, or Craig's velocity propagation")
    p.add_argument("--symbolic", action="store_true", help="the formulas (the default when -q is not given)")
    p.add_argument("--analytic", choices=["rpy", "zyz", "quaternion", "exp"], help="analytic Jacobian: rows (xdot, ydot, "
                   "zdot, rates of the orientation coordinates); numeric with -q, symbolic without (rpy, zyz)")
    p.add_argument("--steps", action="store_true", help="with --method propagation: every omega_i and v_i (symbolic)")
    add_kin_derivative_args(p)
    add_sym_format(p)
    p.set_defaults(handler=cmd_jacobian)

    p = sub.add_parser("velocity", help="end-effector twist (v, w) from joint rates, numeric or symbolic")
    add_common(p)
    add_q(p, required=False)
    p.add_argument("--qd", metavar="QD", help="joint rates [rad/s or m/s; deg/s with --deg] (numeric route)")
    p.add_argument("--frame", type=_frame_arg, default="base", metavar="{base,tool,i}",
                   help="axes of the twist: base/world (J0 qd), tool (Je qd) or the DH frame i = 0 ... N (iJ qd)")
    p.add_argument("--steps", action="store_true", help="omega_i and v_i of every frame (outward propagation)")
    p.add_argument("--symbolic", action="store_true",
                   help="the formulas in q and qd (the default when -q is not given)")
    add_sym_format(p)
    p.set_defaults(handler=cmd_velocity)

    p = sub.add_parser("statics", help="joint torques balancing an end-effector wrench (f, n), numeric or symbolic")
    add_common(p)
    add_q(p, required=False)
    p.add_argument("--wrench", metavar="W",
                   help="fx, fy, fz[, nx, ny, nz] [N, N m] exerted by the end effector, at its origin (numeric route)")
    p.add_argument("--frame", type=_frame_arg, default=None, metavar="{base,tool,i}",
                   help="axes of the wrench: base/world, tool or the DH frame i = 0 ... N (tau = iJ^T iF) (default "
                        "base; tool for --symbolic --method propagation, whose wrench starts in tool axes)")
    p.add_argument("--method", choices=["jacobian", "propagation"], default="jacobian",
                   help="tau = J^T F, or Craig's inward force propagation")
    p.add_argument("--steps", action="store_true", help="f_i and n_i of every frame (inward propagation)")
    p.add_argument("--symbolic", action="store_true",
                   help="tau as formulas of q and the wrench symbols f_x ... n_z (the default when -q is not given)")
    add_sym_format(p)
    p.set_defaults(handler=cmd_statics)



def _frame_arg(text: str) -> str | int:
    """``--frame``: base, tool or a DH frame index (checked against the arm once it is loaded)."""
    t = text.strip()
    if t in ("base", "tool"):
        return t
    if re.fullmatch(r"[0-9]{1,3}", t):
        return int(t)
    raise argparse.ArgumentTypeError(f"expected base, tool or a DH frame index 0 ... N, got {text[:20]!r}")


def _check_frame(robot, frame: str | int) -> None:
    if isinstance(frame, int) and not 0 <= frame <= robot.n_rows:
        raise ParseError(f"--frame {frame}: {robot.name} has DH frames 0 ... {robot.n_rows} (or use base, tool)")


def _name(frame: str | int) -> str:
    return "J0" if frame == "base" else "Je" if frame == "tool" else f"{frame}J"


def _header(frame: str | int, what: str = "J") -> str:
    axes = ("base/world axes (J0)" if frame == "base" else "tool axes (Je)" if frame == "tool" else
            f"the axes of DH frame {{{frame}}} ({frame}J = diag(R_0_{frame}^T, R_0_{frame}^T) J0)")
    return f"{what} in {axes}; reference point: {REFERENCE}; rows (vx, vy, vz, wx, wy, wz)"


def _axes(frame: str | int) -> str:
    return ("base/world axes" if frame == "base" else "tool axes" if frame == "tool" else
            f"the axes of DH frame {{{frame}}}")


def _labelled(M: np.ndarray, labels=ROWS) -> str:
    body = matrix_text(M).split("\n")
    width = max(len(lab) for lab in labels)
    return "\n".join(f"{lab:>{width}} {row}" for lab, row in zip(labels, body))


# --- jacobian ------------------------------------------------------------------------------------------


def _jacobian_sym(robot, method: str, frame: str | int, simplify: str):
    """J0, Je or ⁱJ as formulas (the symbolic side of ``--frame``)."""
    import sympy as sp

    from .. import symbolic as S

    if not isinstance(frame, int):
        return S.jacobian_sym(robot, method, frame, simplify)
    # iJ = diag(R_w_iᵀ, R_w_iᵀ) J0, R_w_i = base · T_0_i (as the numeric route)
    J0 = S.jacobian_sym(robot, method, "base", simplify)
    R = (S.matrix_from_floats(robot.base_matrix) * S.link_transforms_sym(robot, simplify)[frame])[:3, :3]
    J = sp.diag(R.T, R.T) * J0
    if simplify != "none":  # sin² = 1 − cos² first: the rotation leaves sin²(θ) + cos²(θ) of sums of angles
        a = sp.Wild("a")
        J = J.applyfunc(lambda e: sp.expand(sp.expand(e).replace(sp.sin(a) ** 2, 1 - sp.cos(a) ** 2)))
    return S.simplify_matrix(J, simplify)


def _symbolic_jacobian(robot, args) -> tuple[dict, list[str]]:
    import sympy as sp

    from .. import symbolic as S

    require_symbolic_size(robot, "jacobian --symbolic")
    q = S.joint_symbols(robot.dof).q
    fmt = sym_formatter(args, q)
    J = _jacobian_sym(robot, args.method, args.frame, args.simplify)
    name = _name(args.frame)
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
    _check_frame(robot, args.frame)
    if wants_kin_derivatives(args):
        return cmd_kin_derivatives(args, robot)
    data: dict = {"robot": robot.name, "frame": args.frame, "method": args.method, "reference_point": REFERENCE,
                  "rows": list(ROWS)}
    lines: list[str] = []
    if args.q is not None:  # a bad -q fails now, not after the symbolic work
        joint_values(args, robot, args.q)
    if args.symbolic or args.q is None:
        check_analytic_symbolic(args)
        sdata, lines = _symbolic_jacobian(robot, args)
        data.update(sdata)
        if args.analytic:
            from .. import symbolic as S
            import sympy as sp

            Ja = S.analytic_jacobian_sym(robot, args.analytic, args.simplify)
            angles = ", ".join(str(a) for a in S.angle_symbols(args.analytic))
            lines += ["", f"analytic Jacobian Ja ({args.analytic}): rows (xdot, ydot, zdot, rates of {angles}), "
                      f"in terms of q and the current angles {angles}", "Ja =",
                      sym_formatter(args, S.joint_symbols(robot.dof).q)(Ja)]
            data.update({"Ja_symbolic": Ja, "Ja_latex": sp.latex(Ja), "representation": args.analytic})
    if args.q is not None:
        q = joint_values(args, robot, args.q)
        data["q"] = q_out(args, robot, q)
        if args.analytic:
            data.update(analytic_numeric(args, robot, q, lines))
        else:
            route = {"geometric": N.geometric_jacobian, "differentiation": N.differentiation_jacobian,
                     "propagation": N.propagation_jacobian}[args.method]
            if isinstance(args.frame, int) and args.method != "geometric":  # iJ from this route's J0
                J = N.jacobian_tool_from_base(route(robot, q, "base"), N.link_transforms(robot, q)[args.frame])
            else:
                J = route(robot, q, args.frame)
            require_finite("jacobian", J)
            data["J"] = J
            if lines:
                lines.append("")
            lines += [f"{robot.name}: Jacobian by {args.method} at {q_text(args, robot, q)}", _header(args.frame),
                      "(columns: per rad for revolute joints, per m for prismatic ones)", _labelled(J)]
    return data, "\n".join(line for line in lines if line is not None)


# --- velocity ------------------------------------------------------------------------------------------


def _symbolic_velocity(robot, args) -> tuple[dict, list[str]]:
    """v and ω of the end effector as formulas of q and q̇ (J q̇), and with --steps every ω_i, v_i."""
    import sympy as sp

    from .. import symbolic as S

    require_symbolic_size(robot, "velocity --symbolic")
    js = S.joint_symbols(robot.dof)
    fmt = sym_formatter(args, js.q)
    J = _jacobian_sym(robot, "geometric", args.frame, args.simplify)
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
    _check_frame(robot, args.frame)
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
    if isinstance(args.frame, int):  # ⁱJ q̇ (geometric_jacobian rotates J0 into DH frame i's axes)
        twist = N.geometric_jacobian(robot, q, frame=args.frame) @ qd
    else:
        twist = N.end_effector_twist(robot, q, qd, args.frame)
    require_finite("velocity", twist)
    ang = np.degrees if args.deg else (lambda x: x)
    aunit = "deg/s" if args.deg else "rad/s"
    data = {"robot": robot.name, "q": q_out(args, robot, q), "qd": q_out(args, robot, qd), "frame": args.frame,
            "reference_point": REFERENCE, "twist": np.concatenate([twist[:3], ang(twist[3:])]),
            "v": twist[:3], "omega": ang(twist[3:]), "angle_unit": "deg" if args.deg else "rad"}
    lines = [f"{robot.name}: end-effector twist at {q_text(args, robot, q)}", _header(args.frame, "twist (v, w)"),
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
    fmt = sym_formatter(args, q)
    W = sp.Matrix(S.wrench_symbols())
    lines = [f"{robot.name}: symbolic joint torques", f"wrench (f_x, f_y, f_z, n_x, n_y, n_z) exerted by the end "
             f"effector, in {_axes(args.frame)}, at the {REFERENCE}"]
    data: dict = {"wrench_symbols": [str(x) for x in W]}
    if args.method == "propagation":
        if args.frame != "tool":
            raise ParseError("--symbolic --method propagation starts from the wrench in tool axes (Craig 5.80-5.81): "
                             f"use --frame tool, or --method jacobian for a wrench in {_axes(args.frame)}")
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
        J = _jacobian_sym(robot, "geometric", args.frame, args.simplify)
        tau = S.simplify_matrix(J.T * W, args.simplify)
        lines.append("method: tau = J^T F")
    lines += ["tau =", fmt(tau)]
    data.update({"tau_symbolic": [str(e) for e in tau], "tau_latex": sp.latex(tau)})
    return data, lines


def cmd_statics(args: argparse.Namespace):
    robot = load(args)
    if args.frame is None:
        args.frame = "tool" if (args.symbolic or args.q is None) and args.method == "propagation" else "base"
    _check_frame(robot, args.frame)
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
    if isinstance(args.frame, int):  # τ = ⁱJᵀ ⁱF; the propagation starts from the same wrench in world axes
        W_w = N.wrench_base_from_tool(W, N.link_transforms(robot, q)[args.frame])  # R_w_i: base · T_0_i
        prop = N.force_propagation(robot, q, W_w, "base")
        tau = N.joint_torques_from_jacobian(N.geometric_jacobian(robot, q, frame=args.frame), W)
    else:
        prop = N.force_propagation(robot, q, W, args.frame)
        tau = N.joint_torques(robot, q, W, args.frame)
    tau = tau if args.method == "jacobian" else prop.tau
    require_finite("statics", tau, prop.f, prop.n)
    units = ["N m" if t is JointType.REVOLUTE else "N" for t in robot.joint_types]
    F6 = N.as_wrench(W)
    data = {"robot": robot.name, "q": q_out(args, robot, q), "wrench": F6, "frame": args.frame,
            "method": args.method, "reference_point": REFERENCE, "tau": tau, "units": units}
    lines = [f"{robot.name}: joint torques at {q_text(args, robot, q)}",
             f"wrench (f, n) = [{numbers_text(F6)}] N, N m exerted by the end effector, "
             f"in {_axes(args.frame)}, at the {REFERENCE}",
             f"method: {'tau = J^T F' if args.method == 'jacobian' else 'inward force propagation (Craig 5.80-5.81)'}"]
    tau_text = numbers_text(tau, sep="\n").split("\n")
    lines += [f"  tau{k + 1} = {t} {u}" for k, (t, u) in enumerate(zip(tau_text, units))]
    if args.steps:
        lines += ["", "inward propagation (f_i, n_i at the origin of {i}, in its axes):"]
        for lab, f, n in zip(prop.labels, prop.f, prop.n):
            lines.append(f"  {{{lab}}}: f = [{numbers_text(f)}] N, n = [{numbers_text(n)}] N m")
        data["steps"] = [{"frame": lab, "f": f, "n": n} for lab, f, n in zip(prop.labels, prop.f, prop.n)]
    return data, "\n".join(lines)
