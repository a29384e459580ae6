"""``denavit identify ROBOT DATA.csv [-o identified.yaml]``: dynamic identification from measured joint torques."""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

from ..errors import ParseError
from ._common import add_common, bounded_float, load, number_text
from ._output import add_no_clobber, check_output, output_file

#: File types ``identify -o`` writes (a denavit robot file).
ROBOT_SUFFIXES = (".yaml", ".yml", ".json")


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("identify", help="dynamic identification: base inertial parameters, friction and motor "
                                        "inertia fitted to measured joint torques")
    add_common(p)
    p.add_argument("file", metavar="DATA", help="CSV with columns q1..qn, tau1..taun and either qd1..qdn, qdd1..qddn "
                                                "or t (then qd, qdd come from a zero-phase filter); see "
                                                "docs/calibration.md")
    p.add_argument("-o", "--output", metavar="FILE", help="robot file with the identified (physically consistent) "
                                                          "inertia, friction and motor inertia (.yaml or .json)")
    add_no_clobber(p)
    p.add_argument("--method", choices=["ols", "wls"], default="wls",
                   help="ordinary, or weighted by each joint's noise estimated from the OLS residuals (default wls)")
    p.add_argument("--cutoff", type=bounded_float(0.0, 1e6, open_low=True), metavar="HZ",
                   help="cut-off of the zero-phase low-pass used when the file has t but no qd, qdd (default "
                        "min(10 Hz, sampling rate / 5))")
    p.add_argument("--no-friction", action="store_true", help="no viscous and Coulomb friction in the model")
    p.add_argument("--no-motor-inertia", action="store_true", help="no motor inertia in the model")
    p.set_defaults(handler=cmd_identify)


def cmd_identify(args: argparse.Namespace):
    from ..calibration import identify, read_measurements

    check_output(args, args.output, ROBOT_SUFFIXES)  # before any work
    robot = load(args)
    m = read_measurements(args.file, robot, angle_unit="deg" if args.deg else "rad")
    if m.tau is None:
        raise ParseError(f"{args.file}: no torque columns: identification needs tau1 .. tau{robot.dof}")
    given = (m.qd is not None) + (m.qdd is not None)
    if given == 1:
        raise ParseError(f"{args.file}: give both qd1..qd{robot.dof} and qdd1..qdd{robot.dof}, or neither (with t)")
    if given == 0 and m.t is None:
        raise ParseError(f"{args.file}: no qd, qdd columns and no t column: q alone cannot give the rates")
    if given == 2 and args.cutoff is not None:
        raise ParseError("--cutoff: the file gives qd and qdd, so no filter is used")
    try:
        result = identify(robot, m.q, m.qd, m.qdd, m.tau, t=m.t, method=args.method, friction=not args.no_friction,
                          motor_inertia=not args.no_motor_inertia, filter=args.cutoff)
    except ValueError as exc:  # data the identification cannot use (too few samples, an uneven t, ...)
        raise ParseError(f"{args.file}: {exc}") from None
    if args.output:
        text = _robot_text(result, args)
        with output_file(args.output) as tmp:
            Path(tmp).write_text(text, encoding="utf-8")
    return _json(result, args, m.notes), _text(result, robot, args, m.notes)


def _robot_text(result, args) -> str:
    """The identified robot file: YAML keeps the source's leading comments and says what was identified."""
    from .._text import visible
    from ..io import dump_robot
    from ._calibrate import source_comments

    robot = result.physical.robot
    if Path(args.output).suffix.lower() == ".json":
        return dump_robot(robot, "json")
    ph = result.physical
    head = source_comments(args.robot) + [
        (f"# Inertia, friction and motor inertia identified by denavit identify from {visible(args.file)}: "
         f"{result.samples} samples, {result.method.upper()}, {result.rank} of {len(result.names)} base parameters "
         "identified; a physically consistent full set" + ("" if ph.realisable else
                                                           f" (the estimate itself was not realisable: "
                                                           f"distance {ph.distance:.3g} sigma)")),
        "# Fixed rows after a joint lost their own inertia (merged into the joint's row); names and limits kept."]
    return "\n".join(head) + "\n" + dump_robot(robot)


def _verdict(result) -> str:
    ph = result.physical
    if ph.realisable:
        return (f"physical consistency: the estimate is realisable (a full set with positive masses, positive "
                f"definite inertias and the triangle inequalities reproduces it: distance {ph.distance:.3g} sigma)")
    k = int(np.nanargmax(np.abs(ph.deviation)))
    return (f"physical consistency: the unconstrained estimate is NOT physically realisable; the nearest realisable "
            f"set is at Mahalanobis distance {ph.distance:.3g} (largest deviation {ph.deviation[k]:+.3g} sigma in "
            f"{result.names[k]})" + ("" if ph.success else f"; {ph.message}"))


def _text(result, robot, args, notes) -> str:
    lines = [(f"{robot.name}: dynamic identification from {args.file} ({result.samples} samples, "
              f"{result.method.upper()})"),
             (f"{len(result.names)} base parameters, rank of the data {result.rank}, condition number of the "
              f"stacked base regressor {number_text(result.condition_number, 4)}")]
    lines += [f"note: {n}" for n in notes]
    if result.filter:
        lines.append(f"qd, qdd: {result.filter}")
    lines.append("noise per joint, estimated from the residuals [N m or N]: " + ", ".join(number_text(v, 4)
                                                                                for v in result.noise))
    lines.append("residual RMS per joint [N m or N], the arm as given: " + ", ".join(
        number_text(v, 4) for v in result.nominal_residual_rms))
    lines.append("residual RMS per joint [N m or N], identified:       " + ", ".join(
        number_text(v, 4) for v in result.residual_rms))
    lines.append("base parameters: estimate +- sigma (relative sigma) [kg, kg m, kg m^2, N m s, N m]:")
    width = max(len(nm) for nm in result.names)
    for nm, est, sd, rel, ok in zip(result.names, result.estimate, result.std, result.relative_std,
                                    result.identifiable):
        lines.append(f"  {nm:<{width}} = " + (f"{number_text(est)} +- {number_text(sd, 3)} ({number_text(rel, 3)} %)"
                                             if ok else "not identifiable from these data"))
    if result.unidentifiable:
        lines.append("not identifiable from these data (no value given): " + ", ".join(result.unidentifiable))
    if result.rules:
        lines.append("grouping of the base parameters:")
        lines += [f"  {rule}" for rule in result.rules]
    lines.append(_verdict(result))
    if args.output:
        lines.append(f"wrote {args.output}")
    return "\n".join(lines)


def _json(result, args, notes) -> dict:
    ph = result.physical
    return {"robot": args.shown_names[-1], "data": args.file, "method": result.method, "samples": result.samples,
            "names": list(result.names), "rules": list(result.rules), "estimate": result.estimate, "std": result.std,
            "relative_std": result.relative_std, "identifiable": result.identifiable.tolist(),
            "unidentifiable": list(result.unidentifiable), "noise": result.noise,
            "residual_rms": result.residual_rms, "residual_rms_nominal": result.nominal_residual_rms, "condition_number": result.condition_number,
            "rank": result.rank, "filter": result.filter, "notes": list(notes),
            "physical": {"realisable": ph.realisable, "distance": ph.distance, "deviation": ph.deviation,
                         "names": list(ph.names), "parameters": ph.parameters, "converged": ph.success},
            "output": args.output}
