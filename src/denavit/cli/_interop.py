"""Subcommands that talk to other formats: import-urdf, export-urdf, export-mjcf."""

from __future__ import annotations

import argparse
from pathlib import Path

from ..errors import ParseError
from ._common import add_common, load
from ._output import add_no_clobber, check_output, output_file

#: File types ``import-urdf -o`` writes (a denavit robot file).
ROBOT_SUFFIXES = (".yaml", ".yml", ".json")


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("import-urdf", help="a URDF's serial chain as a DH robot file (with an FK self-check)")
    p.add_argument("urdf", metavar="URDF", help="the .urdf file (untrusted XML: no DTD/entities, size-capped)")
    p.add_argument("--base", metavar="LINK", help="first link of the chain (default: the URDF's root link)")
    p.add_argument("--tip", metavar="LINK", help="last link of the chain (default: the one leaf; needed when the "
                                                  "tree branches)")
    p.add_argument("--convention", choices=["standard", "modified"], default="standard", help="DH convention")
    p.add_argument("--xacro", action="store_true", help="expand a xacro file first (needs denavit[xacro]); xacro "
                                                         "evaluates Python expressions: only for files you trust")
    inertia = p.add_mutually_exclusive_group()
    inertia.add_argument("--fix-inertia", dest="inertia", action="store_const", const="fix", default="check",
                         help="replace a link's inertia that no rigid body has (triangle inequality broken) by the "
                              "nearest physical tensor, stated in the notes (default: warn and import without "
                              "inertial data)")
    inertia.add_argument("--no-inertia", dest="inertia", action="store_const", const="none",
                         help="import the kinematics only, without inertial data")
    p.add_argument("-o", "--output", metavar="FILE", help="robot file to write (.yaml or .json); stdout if absent")
    add_no_clobber(p)
    p.add_argument("--json", action="store_true", help="machine-readable JSON on stdout")
    p.add_argument("--deg", action="store_true", help="the printed DH table's angles in degrees (the robot file is "
                                                      "written in radians, as every robot file denavit writes)")
    p.set_defaults(handler=cmd_import_urdf)

    for fmt, suffix, help_text in (("urdf", ".urdf", "the arm as URDF (links, joints, limits, inertials, visuals)"),
                                   ("mjcf", ".xml", "the arm as MJCF for MuJoCo (bodies, joints, inertials, armature)")):
        p = sub.add_parser(f"export-{fmt}", help=help_text)
        add_common(p, angles=False)
        p.add_argument("-o", "--output", metavar="FILE", help=f"file to write ({suffix}); stdout if absent")
        add_no_clobber(p)
        p.set_defaults(handler=cmd_export, fmt=fmt, suffixes=(suffix,) if fmt == "mjcf" else (".urdf", ".xml"))


def cmd_import_urdf(args: argparse.Namespace):
    from ..display import dh_table
    from ..interop import import_urdf
    from ..io import dump_robot, robot_to_dict

    check_output(args, args.output, ROBOT_SUFFIXES)  # before any work
    if Path(args.urdf).suffix.lower() in (".yaml", ".yml", ".toml", ".json"):  # was: "malformed XML" at line 1
        raise ParseError(f"{args.urdf[:200]}: a robot file, not a URDF: other commands take it as ROBOT as it is "
                         "(denavit show, fk, export-urdf ...)")
    result = import_urdf(args.urdf, args.base, args.tip, args.convention, xacro=args.xacro, inertia=args.inertia)
    robot = result.robot
    width = max([len("URDF joint")] + [len(n) for n in result.joint_names])
    lines = [f"{robot.name}: the chain {result.base_link} -> {result.tip_link} of {args.urdf} as {robot.dof} "
             f"{robot.convention.value} DH row{'s' * (robot.dof != 1)}", "",
             f"row  {'URDF joint'.ljust(width)}  axis and the next one"]
    lines += [f"{k + 1:>3}  {name.ljust(width)}  {case}"
              for k, (name, case) in enumerate(zip(result.joint_names, result.cases))]
    lines += ["", f"FK self-check at {result.samples} random configurations: worst position error "
                  f"{result.position_error:.2g} m, rotation error {result.rotation_error:.2g}"]
    lines += [f"note: {note}" for note in result.notes]
    lines += ["", dh_table(robot, deg=True if args.deg else None)]
    fmt = "json" if args.output and Path(args.output).suffix.lower() == ".json" else "yaml"
    if args.output:
        with output_file(args.output) as tmp:
            Path(tmp).write_text(dump_robot(robot, fmt), encoding="utf-8")
        lines += ["", f"wrote {args.output}"]
    else:
        lines += ["", dump_robot(robot)]
    data = {"urdf": args.urdf, "base_link": result.base_link, "tip_link": result.tip_link,
            "convention": robot.convention.value, "joints": list(result.joint_names), "cases": list(result.cases),
            "self_check": {"samples": result.samples, "position_error": result.position_error,
                           "rotation_error": result.rotation_error},
            "notes": list(result.notes), "output": args.output, "robot_file": robot_to_dict(robot)}
    return data, "\n".join(lines)


def cmd_export(args: argparse.Namespace):
    from ..interop import to_mjcf, to_urdf

    check_output(args, args.output, args.suffixes)  # before any work
    robot = load(args)
    text = (to_urdf if args.fmt == "urdf" else to_mjcf)(robot)
    data = {"robot": robot.name, "format": args.fmt, "output": args.output, "joints": [f"q{k + 1}" for k in range(robot.dof)],
            "dynamics": robot.has_dynamics}
    notes = _export_notes(robot, args.fmt)
    data["notes"] = notes
    if args.output:
        with output_file(args.output) as tmp:
            Path(tmp).write_text(text, encoding="utf-8")
        return data, "\n".join([f"wrote {args.output} ({args.fmt.upper()}, {_joints(robot.dof)}, tool frame 'tool')"]
                               + [f"note: {n}" for n in notes])
    data["text"] = text
    return data, text


def _export_notes(robot, fmt: str) -> list[str]:
    """What the exported file cannot carry of the arm (its JSON lists them; written to stdout they would mix with
    the XML, so the text shows them only with -o)."""
    from ..interop import MJCF_MIN_MASS

    rows = [link.inertia for link in robot.joints]
    if not robot.has_dynamics:
        missing = sum(li is None for li in rows)
        which = "" if missing == robot.dof else f" for {missing} of its {robot.dof} joints"
        return [f"{robot.name} has no inertial data{which}: " + (
            "those links have no <inertial> (dynamics in other tools are not the arm's)" if fmt == "urdf" else
            f"those bodies get a placeholder mass of {MJCF_MIN_MASS:g} kg (MuJoCo's dynamics are not the arm's)")]
    if fmt == "urdf" and any(li.motor_inertia for li in rows if li is not None):
        return ["URDF has no place for motor (rotor) inertia: left out, so M differs from denavit's on its diagonal"]
    return []


def _joints(n: int) -> str:
    """``1 joint q1``, ``2 joints q1, q2``, ``6 joints q1 … q6``."""
    return {1: "1 joint q1", 2: "2 joints q1, q2"}.get(n, f"{n} joints q1 … q{n}")
