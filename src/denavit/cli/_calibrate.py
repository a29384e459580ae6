"""``denavit calibrate ROBOT MEASUREMENTS.csv [-o calibrated.yaml]``: kinematic calibration from measured poses."""

from __future__ import annotations

import argparse
import math
import os
from pathlib import Path

from ..errors import ParseError
from ._common import add_common, bounded_float, load, nonneg_int, positive_float
from ._output import add_no_clobber, check_output, output_file

#: File types ``calibrate -o`` writes (a denavit robot file).
ROBOT_SUFFIXES = (".yaml", ".yml", ".json")
#: Leading comment lines of the robot file copied into the calibrated file, at most.
MAX_COMMENT_LINES = 60


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("calibrate", help="kinematic calibration: DH table, base and tool fitted to measured poses")
    add_common(p)
    p.add_argument("file", metavar="MEASUREMENTS", help="CSV with columns q1..qn and x,y,z (positions) or "
                                                       "x,y,z,qw,qx,qy,qz (poses); see docs/calibration.md")
    p.add_argument("-o", "--output", metavar="FILE", help="calibrated robot file to write (.yaml or .json)")
    add_no_clobber(p)
    p.add_argument("--kind", choices=["pose", "position"], help="fit poses or positions only (default: pose when the "
                                                                "file has qw qx qy qz, else position)")
    p.add_argument("--noise-pos", type=positive_float, default=1e-4, metavar="M",
                   help="position noise per axis (m, or mm with --mm; default 1e-4 m)")
    p.add_argument("--noise-rot", type=positive_float, default=1e-4, metavar="RAD",
                   help="orientation noise per axis (rad, or deg with --deg; default 1e-4 rad)")
    p.add_argument("--mm", action="store_true", help="lengths in millimetres: the file's positions and prismatic "
                                                     "joints, --noise-pos and the printed lengths")
    p.add_argument("--holdout", type=bounded_float(0.0, 0.9), default=0.2, metavar="FRACTION",
                   help="fraction of the measurements left out of the fit to validate it (default 0.2)")
    p.add_argument("--seed", type=nonneg_int, default=0, help="which measurements are held out (default 0)")
    p.add_argument("--robust", choices=["huber", "cauchy", "none"], default="huber", help="robust loss (default huber)")
    p.add_argument("--no-base", action="store_true", help="keep the base transform as it is")
    p.add_argument("--no-tool", action="store_true", help="keep the tool transform as it is")
    p.set_defaults(handler=cmd_calibrate)


def cmd_calibrate(args: argparse.Namespace):
    from ..calibration import calibrate, read_measurements

    check_output(args, args.output, ROBOT_SUFFIXES)  # before any work
    robot = load(args)
    m = read_measurements(args.file, robot, angle_unit="deg" if args.deg else "rad",
                          length_unit="mm" if args.mm else "m")
    kind = args.kind or ("pose" if m.quaternion is not None else "position")
    if m.position is None:
        raise ParseError(f"{args.file}: no measured positions: calibration needs the columns x y z (and qw qx qy qz "
                         "for poses)")
    if kind == "pose" and m.quaternion is None:
        raise ParseError(f"{args.file}: --kind pose needs the orientation columns qw qx qy qz (or use --kind position)")
    length, angle = (1e-3 if args.mm else 1.0), (math.pi / 180 if args.deg else 1.0)
    measured = m.poses if kind == "pose" else m.position
    result = calibrate(robot, m.q, measured, kind, noise=(args.noise_pos * length, args.noise_rot * angle),
                       base=not args.no_base, tool=not args.no_tool, robust=args.robust, holdout=args.holdout,
                       seed=args.seed, labels=m.lines)
    if args.output:
        text = calibrated_text(result, args.robot, args.file, args.output)
        with output_file(args.output) as tmp:
            Path(tmp).write_text(text, encoding="utf-8")
    return _json(result, args, m.notes), _text(result, args, list(m.notes))


def _source_text(robot_arg: str) -> str:
    """The robot file's text (a YAML file named, or the catalogue's file of a built-in name), else ""."""
    from importlib import resources

    from ..io import catalogue_name

    if os.path.isfile(robot_arg):
        if Path(robot_arg).suffix.lower() not in (".yaml", ".yml"):
            return ""
        with open(robot_arg, encoding="utf-8", errors="replace") as fh:
            return fh.read(256_000)
    try:
        entry = resources.files("denavit") / "data" / "robots" / f"{catalogue_name(robot_arg)}.yaml"
        return entry.read_text(encoding="utf-8")
    except (ParseError, OSError):
        return ""


def source_comments(robot_arg: str) -> list[str]:
    """The leading ``#`` lines of the robot file (YAML, or the catalogue's), each kept only when it is one plain
    comment line (no character YAML or a terminal would read as a line break or a control; tabs allowed)."""
    from .._text import has_unsafe

    out = []
    for line in _source_text(robot_arg).splitlines()[:MAX_COMMENT_LINES]:
        if not line.startswith("#"):
            break
        if not has_unsafe(line, keep="\t"):
            out.append(line)
    return out


def calibrated_text(result, robot_arg: str, measurements: str, output: str) -> str:
    """The calibrated robot file's text: YAML keeps the source file's leading comments and adds one saying what the
    calibration did; JSON has no comments."""
    from .._text import visible
    from ..io import dump_robot

    if Path(output).suffix.lower() == ".json":
        return dump_robot(result.robot, "json")
    a = result.holdout_after or result.after
    head = source_comments(robot_arg)
    head += [f"# Kinematics calibrated by denavit calibrate from {visible(measurements)}: {result.after.poses} "
             f"{result.kind}s fitted, rank {result.rank}; residual position RMS {a.position_rms:.3g} m"
             + (f", rotation RMS {a.rotation_rms:.3g} rad" if a.rotation_rms is not None else "")
             + (" (held-out poses)" if result.holdout_after else ""),
             "# Rows with a Hayati beta are written as two fixed rows after (standard) or before (modified) the row."
             if result.beta_rows and any(p.name.startswith("beta") and p.identified for p in result.parameters)
             else "# Names, limits, inertia and named poses are those of the nominal arm."]
    return "\n".join(head) + "\n" + dump_robot(result.robot)


def _scale(unit: str, args) -> tuple[float, str]:
    if unit == "m":
        return (1e3, "mm") if args.mm else (1.0, "m")
    return (180 / math.pi, "deg") if args.deg else (1.0, "rad")


def _stats_line(label: str, s, args) -> str:
    fl, ul = _scale("m", args)
    fa, ua = _scale("rad", args)
    text = f"  {label:<18} position RMS {s.position_rms * fl:.4g} {ul}, max {s.position_max * fl:.4g} {ul}"
    if s.rotation_rms is not None:
        text += f"; rotation RMS {s.rotation_rms * fa:.4g} {ua}, max {s.rotation_max * fa:.4g} {ua}"
    return text + f"  ({s.poses} poses)"


def _text(result, args, notes: list[str]) -> str:
    lines = [f"{result.nominal.name}: kinematic calibration from {args.file} ({result.kind} data, "
             f"{result.after.poses} fitted" + (f", {result.holdout_after.poses} held out" if result.holdout_after
                                                else "") + ")",
             f"rank {result.rank} of {len(result.parameters)} parameters, condition number "
             f"{result.condition_number:.3g}; Levenberg-Marquardt {result.iterations} iterations"
             f"{'' if result.converged else ' (not converged)'}; residual variance factor {result.variance_factor:.3g}",
             "", "residuals (model - measured):", _stats_line("before, fitted", result.before, args),
             _stats_line("after, fitted", result.after, args)]
    if result.holdout_after is not None:
        lines += [_stats_line("before, held out", result.holdout_before, args),
                  _stats_line("after, held out", result.holdout_after, args)]
    width = max(len(p.name) for p in result.parameters)
    lines += ["", f"  {'parameter'.ljust(width)}  {'nominal':>12}  {'estimate':>12}  {'correction':>12}  "
                  f"{'sigma':>10}  unit"]
    for p in result.parameters:
        if p.identified:
            f, u = _scale(p.unit, args)
            lines.append(f"  {p.name.ljust(width)}  {p.nominal * f:12.6g}  {p.estimate * f:12.6g}  "
                         f"{p.correction * f:12.4g}  {p.sigma * f:10.2g}  {u}")
    held = [p for p in result.parameters if not p.identified]
    if held:
        lines += ["", "held at their nominal value (not identifiable from these measurements):"]
        lines += [f"  {p.name.ljust(width)}  {p.reason}" for p in held]
    fl, ul = _scale("m", args)
    fa, ua = _scale("rad", args)
    lines += ["", "worst poses after calibration (file line: position error"
              + (", rotation error)" if result.kind == "pose" else ")")]
    lines += [f"  line {w.label}: {w.position_error * fl:.4g} {ul}"
              + (f", {w.rotation_error * fa:.4g} {ua}" if w.rotation_error is not None else "")
              for w in result.worst]
    lines += [f"note: {n}" for n in [*notes, *result.notes]]
    if args.output:
        lines += ["", f"wrote {args.output}"]
    return "\n".join(lines)


def _json(result, args, notes) -> dict:
    def stats(s):
        return None if s is None else {"poses": s.poses, "position_rms": s.position_rms,
                                       "position_max": s.position_max, "rotation_rms": s.rotation_rms,
                                       "rotation_max": s.rotation_max}

    return {"robot": result.nominal.name, "measurements": args.file, "kind": result.kind,
            "noise": {"position": result.noise[0], "rotation": result.noise[1]}, "units": "m, rad",
            "rank": result.rank, "condition_number": result.condition_number, "iterations": result.iterations,
            "converged": result.converged, "variance_factor": result.variance_factor,
            "residuals": {"before": stats(result.before), "after": stats(result.after),
                          "holdout_before": stats(result.holdout_before), "holdout_after": stats(result.holdout_after)},
            "parameters": [{"name": p.name, "unit": p.unit, "nominal": p.nominal, "estimate": p.estimate,
                            "correction": p.correction, "sigma": p.sigma if p.identified else None,
                            "identified": p.identified, "reason": p.reason} for p in result.parameters],
            "worst": [{"line": w.label, "position_error": w.position_error, "rotation_error": w.rotation_error}
                      for w in result.worst],
            "notes": [*notes, *result.notes], "output": args.output}
