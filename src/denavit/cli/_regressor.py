"""Subcommand ``regressor``: the standard and base inertial parameters of an arm, and Y(q, q̇, q̈) at a state."""

from __future__ import annotations

import argparse

import numpy as np

from ..errors import ParseError
from ._common import add_common, add_q, bounded_float, joint_values, load, matrix_text, number_text, require_finite
from ._shared import q_out


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("regressor", help="inertial parameters: standard, base (identifiable) and their grouping; "
                                         "Y(q, qd, qdd) with tau = Y pi at a state")
    add_common(p)
    add_q(p, required=False)
    p.add_argument("--qd", metavar="QD", help="joint rates for Y (default zeros)")
    p.add_argument("--qdd", metavar="QDD", help="joint accelerations for Y (default zeros)")
    p.add_argument("--tol", type=bounded_float(1e-15, 0.1), default=None, metavar="TOL",
                   help="rank tolerance of the base parameters, relative (default 1e-8)")
    p.add_argument("--no-friction", action="store_true", help="leave out the friction parameters FV, FC")
    p.add_argument("--no-motor-inertia", action="store_true", help="leave out the motor inertias IA")
    p.add_argument("--symbolic", action="store_true",
                   help="also the grouping rules in the DH symbols (Khalil & Kleinfinger), checked against the numbers")
    p.set_defaults(handler=cmd_regressor)


def cmd_regressor(args: argparse.Namespace):
    from ..numeric import BASE_TOL, base_parameters, regressor

    robot = load(args)
    kw = dict(friction=not args.no_friction, motor_inertia=not args.no_motor_inertia)
    state = None
    if args.q is not None:
        state = [joint_values(args, robot, args.q)] + [
            np.zeros(robot.dof) if text is None else joint_values(args, robot, text, what, rates=True)
            for text, what in ((args.qd, "qd"), (args.qdd, "qdd"))]
    elif args.qd is not None or args.qdd is not None:
        raise ParseError("--qd/--qdd: give the joint values with -q too")
    tol = BASE_TOL if args.tol is None else args.tol
    base = base_parameters(robot, tol=tol, **kw)
    p = len(base.names)
    lines = [f"{robot.name}: {p} standard parameters ({robot.dof} bodies x 10"
             + (", FV, FC" if kw["friction"] else "") + (", IA" if kw["motor_inertia"] else "")
             + f"), {base.rank} base parameters (rank tolerance {tol:g}, {base.samples} random states)"]
    if base.unidentifiable:
        lines.append("no effect on any torque: " + ", ".join(base.unidentifiable))
    others = [base.names[i] for i in range(p) if i not in base.independent and base.names[i] not in base.unidentifiable]
    if others:
        lines.append("grouped into the base parameters: " + ", ".join(others))
    lines.append("grouping rules:")
    lines += [f"  {rule}" for rule in base.rules] or ["  (none)"]
    lines.append("base parameter values of the robot [kg, kg m, kg m^2, N m s, N m]:")
    lines += [f"  {name} = {number_text(v)}" for name, v in zip(base.base_names, base.values)]
    data = {"robot": robot.name, "standard": list(base.names), "n_standard": p, "n_base": base.rank,
            "base": list(base.base_names), "kept": [base.names[i] for i in base.independent],
            "rules": list(base.rules), "values": base.values, "combination": base.combination,
            "unidentifiable": list(base.unidentifiable), "tol": tol, "samples": base.samples}
    if args.symbolic:
        sdata, slines = _symbolic(robot, base)
        data.update(sdata)
        lines += slines
    if state is not None:
        Y = regressor(robot, *state, **kw)
        require_finite("regressor", Y)
        unit = "deg" if args.deg else "rad"
        lines += [f"Y(q, qd, qdd) at q = [{', '.join(number_text(v) for v in q_out(args, robot, state[0]))}] ({unit}), "
                  f"rows tau_1..tau_{robot.dof}, columns {base.names[0]}..{base.names[-1]}:", matrix_text(Y)]
        data.update(q=q_out(args, robot, state[0]), qd=q_out(args, robot, state[1]), qdd=q_out(args, robot, state[2]),
                    angle_unit=unit, Y=Y)
    return data, "\n".join(lines)


def _symbolic(robot, base):
    from ..symbolic import base_parameters_sym, compare_base_parameters

    sym = base_parameters_sym(robot, friction=base.friction, motor_inertia=base.motor_inertia)
    lines = ["grouping rules in the DH symbols (Khalil & Kleinfinger 1987):"]
    lines += [f"  {name} = {expr}" for name, expr in sym.rules] or ["  (none)"]
    if sym.no_effect:
        lines.append("no effect (first links' restricted motion): " + ", ".join(sym.no_effect))
    span, values = compare_base_parameters(robot, sym, base)
    verdict = ("the same span and values" if values else "the same span (other parameters kept)" if span else
               "DIFFERENT spans: this geometry leaves parameters the general rules do not catch")
    lines.append(f"symbolic and numeric base parameters: {verdict}")
    return {"rules_symbolic": [f"{n} = {e}" for n, e in sym.rules], "no_effect_symbolic": list(sym.no_effect),
            "kept_symbolic": list(sym.kept), "symbolic_same_span": span, "symbolic_same_values": values}, lines
