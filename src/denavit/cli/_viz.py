"""Subcommands that draw: plot, animate, view (workspace and reachability: cli/_scale.py)."""

from __future__ import annotations

import argparse
import sys

import numpy as np

from ..errors import ParseError
from ._common import (add_common, add_q, bounded_float, bounded_int, finite_float, joint_values, load, numbers_text,
                      require_finite, stage_printer)
from ._output import add_no_clobber, check_output, output_file
from ._shared import q_out

PROFILES = ("quintic", "trapezoidal", "cartesian")
PICTURES = (".png", ".svg", ".pdf")
ANIMATIONS = (".gif", ".mp4")
PAGES = (".html", ".htm")
#: --dpi range of plot (a 600-dpi picture of the default figure is about 4,800 px square).
DPI_RANGE = (10, 600)
#: animate: longest move [s], highest frame rate, and most frames (--duration × --fps) drawn in one run.
MAX_DURATION = 600.0
MAX_FPS = 60.0
MAX_FRAMES = 1000


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("plot", help="picture of the arm at a configuration (.png, .svg, .pdf)")
    add_common(p)
    add_q(p, required=False)
    p.add_argument("-o", "--output", required=True, metavar="FILE", help="picture to write: .png, .svg or .pdf")
    p.add_argument("--path-to", metavar="Q2", help="also draw the end-effector path of a quintic move to Q2")
    p.add_argument("--no-frames", action="store_true", help="leave out the DH frame triads")
    p.add_argument("--no-labels", action="store_true", help="leave out the frame labels")
    p.add_argument("--elev", type=finite_float, help="view elevation [deg]")
    p.add_argument("--azim", type=finite_float, help="view azimuth [deg]")
    p.add_argument("--dpi", type=bounded_int(*DPI_RANGE), default=120,
                   help=f"resolution of a .png (default 120; {DPI_RANGE[0]} to {DPI_RANGE[1]})")
    add_no_clobber(p)
    p.set_defaults(handler=cmd_plot)

    p = sub.add_parser("animate", help="animation of a move between two configurations (.gif, .mp4)")
    add_common(p)
    p.add_argument("--from", dest="q_from", required=True, metavar="Q1", help="start configuration")
    p.add_argument("--to", dest="q_to", required=True, metavar="Q2", help="end configuration")
    p.add_argument("-o", "--output", required=True, metavar="FILE", help="animation to write: .gif or .mp4")
    p.add_argument("--profile", choices=PROFILES, default="quintic",
                   help="joint-space quintic or trapezoidal velocity, or a straight Cartesian line (IK)")
    p.add_argument("--duration", type=bounded_float(0, MAX_DURATION, open_low=True), default=2.0,
                   help=f"length of the move [s] (default 2, at most {MAX_DURATION:g})")
    p.add_argument("--fps", type=bounded_float(0, MAX_FPS, open_low=True), default=15.0,
                   help=f"frames per second (default 15, at most {MAX_FPS:g}); duration × fps <= {MAX_FRAMES}")
    p.add_argument("--no-frames", action="store_true", help="leave out the DH frame triads")
    p.add_argument("--ignore-limits", action="store_true", help="accept configurations outside the joint limits")
    add_no_clobber(p)
    p.set_defaults(handler=cmd_animate)

    p = sub.add_parser("view", help="interactive 3-D viewer as one self-contained HTML file")
    add_common(p)
    add_q(p, required=False)
    p.add_argument("-o", "--output", required=True, metavar="FILE", help="HTML file to write")
    add_no_clobber(p)
    p.set_defaults(handler=cmd_view)


def _fmt(v) -> str:
    return "[" + numbers_text(v) + "]"


def cmd_plot(args: argparse.Namespace):
    from ..numeric import quintic_trajectory
    from ..viz import arm_geometry, default_configuration
    from ..viz import plot_robot, save_figure

    check_output(args, args.output, PICTURES, kind="picture format")
    robot = load(args)
    q = default_configuration(robot) if args.q is None else joint_values(args, robot, args.q)
    path = None
    if args.path_to is not None:
        q2 = joint_values(args, robot, args.path_to, what="--path-to")
        path = quintic_trajectory(q, q2, 40).q
    geom = arm_geometry(robot, q)
    require_finite("plot", geom.end_effector, geom.joint_positions)
    fig = plot_robot(robot, q, frames=not args.no_frames, labels=not args.no_labels, path=path,
                     elev=args.elev, azim=args.azim)
    with output_file(args.output) as tmp:
        save_figure(fig, tmp, dpi=args.dpi)
    unit = "deg" if args.deg else "rad"
    data = {"robot": robot.name, "q": q_out(args, robot, q), "angle_unit": unit, "output": args.output,
            "T": geom.end_effector, "joint_positions": geom.joint_positions, "skeleton": geom.skeleton}
    return data, f"wrote {args.output} ({robot.name} at q = {_fmt(q_out(args, robot, q))} {unit})"


def _move(args, robot, q1: np.ndarray, q2: np.ndarray, k: int):
    from ..numeric import cartesian_path, quintic_trajectory, trapezoidal_trajectory

    if args.profile == "quintic":
        return quintic_trajectory(q1, q2, k, duration=args.duration).q, None
    if args.profile == "trapezoidal":
        return trapezoidal_trajectory(q1, q2, k, duration=args.duration).q, None
    cp = cartesian_path(robot, q1, q2, k, duration=args.duration)
    return cp.q, cp


def cmd_animate(args: argparse.Namespace):
    from ..numeric import forward_kinematics
    from ..viz import animate_robot

    check_output(args, args.output, ANIMATIONS, kind="animation format")
    if args.duration * args.fps > MAX_FRAMES:
        raise ParseError(f"--duration {args.duration:g} × --fps {args.fps:g} gives "
                         f"{args.duration * args.fps:.0f} frames; at most {MAX_FRAMES} per animation")
    robot = load(args)
    q1 = joint_values(args, robot, args.q_from, what="--from")
    q2 = joint_values(args, robot, args.q_to, what="--to")
    k = max(2, int(round(args.duration * args.fps)) + 1)
    qs, cp = _move(args, robot, q1, q2, k)
    ee = forward_kinematics(robot, qs)[:, :3, 3]
    require_finite("animate", qs, ee)
    show = stage_printer(args, "animate") if sys.stderr.isatty() else None  # at a terminal: a failure stays one line
    if show:  # a few seconds for a default 2 s move; no per-frame progress from the renderer
        show(f"rendering {k} frames to {args.output}")
    with output_file(args.output) as tmp:
        animate_robot(robot, qs, tmp, fps=args.fps, frames=not args.no_frames)
    unit = "deg" if args.deg else "rad"
    data = {"robot": robot.name, "q_from": q_out(args, robot, q1), "q_to": q_out(args, robot, q2),
            "angle_unit": unit, "profile": args.profile, "duration": args.duration, "fps": args.fps, "frames": k,
            "output": args.output, "end_effector_path": ee, "success": True}
    text = [f"wrote {args.output} ({k} frames, {args.duration:g} s, {args.profile} profile)"]
    if cp is not None:
        lim = robot.q_limits
        inside = bool(np.all((qs >= lim[:, 0] - 1e-9) & (qs <= lim[:, 1] + 1e-9)))
        data.update({"success": cp.success, "max_position_error": float(cp.position_error.max()),
                     "max_orientation_error": float(cp.orientation_error.max()),
                     "orientation_tracked": cp.orientation_tracked, "within_limits": inside})
        text.append(f"straight line followed: {'yes' if cp.success else 'NO'} (max position error "
                    f"{cp.position_error.max():.2e} m" + (f", orientation {cp.orientation_error.max():.2e} rad"
                                                          if cp.orientation_tracked else ", position only") + ")")
        if not inside:
            text.append("warning: the IK path leaves the joint limits")
    return data, "\n".join(text)


def cmd_view(args: argparse.Namespace):
    from ..viz import default_configuration, write_viewer

    from pathlib import Path

    check_output(args, args.output, PAGES)
    robot = load(args)
    q = default_configuration(robot) if args.q is None else joint_values(args, robot, args.q)
    with output_file(args.output) as tmp:
        write_viewer(robot, tmp, q)
        size = Path(tmp).stat().st_size
    path = Path(args.output)
    data = {"robot": robot.name, "q": q_out(args, robot, q), "angle_unit": "deg" if args.deg else "rad",
            "output": str(path), "bytes": size}
    return data, f"wrote {path} ({size // 1024} KiB, self-contained: open it in any browser, no network needed)"

