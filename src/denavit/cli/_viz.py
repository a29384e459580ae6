"""Subcommands that draw: plot, animate, view, workspace."""

from __future__ import annotations

import argparse
import math

import numpy as np

from ..errors import ParseError
from ._common import add_common, add_force, finite_float, nonneg_int, add_q, joint_values, load, refuse_overwrite

PROFILES = ("quintic", "trapezoidal", "cartesian")


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
    p.add_argument("--dpi", type=int, default=120, help="resolution of a .png (default 120)")
    add_force(p)
    p.set_defaults(handler=cmd_plot)

    p = sub.add_parser("animate", help="animation of a move between two configurations (.gif, .mp4)")
    add_common(p)
    p.add_argument("--from", dest="q_from", required=True, metavar="Q1", help="start configuration")
    p.add_argument("--to", dest="q_to", required=True, metavar="Q2", help="end configuration")
    p.add_argument("-o", "--output", required=True, metavar="FILE", help="animation to write: .gif or .mp4")
    p.add_argument("--profile", choices=PROFILES, default="quintic",
                   help="joint-space quintic or trapezoidal velocity, or a straight Cartesian line (IK)")
    p.add_argument("--duration", type=float, default=2.0, help="length of the move [s] (default 2)")
    p.add_argument("--fps", type=float, default=15.0, help="frames per second (default 15)")
    p.add_argument("--no-frames", action="store_true", help="leave out the DH frame triads")
    p.add_argument("--ignore-limits", action="store_true", help="accept configurations outside the joint limits")
    add_force(p)
    p.set_defaults(handler=cmd_animate)

    p = sub.add_parser("view", help="interactive 3-D viewer as one self-contained HTML file")
    add_common(p)
    add_q(p, required=False)
    p.add_argument("-o", "--output", required=True, metavar="FILE", help="HTML file to write")
    add_force(p)
    p.set_defaults(handler=cmd_view)

    p = sub.add_parser("workspace", help="reachable workspace by sampling: size, volume, picture")
    add_common(p)
    p.add_argument("-o", "--output", metavar="FILE", help="picture to write (.png, .svg, .pdf); numbers only if absent")
    p.add_argument("--samples", type=int, default=100_000, help="random configurations (default 100000)")
    p.add_argument("--resolution", type=float, help="voxel edge [m] (default: longest side / 40)")
    p.add_argument("--seed", type=nonneg_int, help="random seed, for repeatable figures")
    add_force(p)
    p.set_defaults(handler=cmd_workspace)


def _out_q(args, robot, q: np.ndarray) -> np.ndarray:
    from ..model import JointType

    if not args.deg:
        return q
    rev = np.array([t is JointType.REVOLUTE for t in robot.joint_types])
    return np.where(rev, np.degrees(q), q)


def _fmt(v) -> str:
    return "[" + ", ".join(f"{x:.6g}" for x in np.ravel(v)) + "]"


def cmd_plot(args: argparse.Namespace):
    from ..numeric import quintic_trajectory
    from ..viz import arm_geometry, default_configuration
    from ..viz._plot import figure_format, plot_robot, save_figure

    robot = load(args)
    figure_format(args.output)
    refuse_overwrite(args, args.output)
    q = default_configuration(robot) if args.q is None else joint_values(args, robot, args.q)
    path = None
    if args.path_to is not None:
        q2 = joint_values(args, robot, args.path_to, what="--path-to")
        path = quintic_trajectory(q, q2, 40).q
    if args.dpi <= 0:
        raise ParseError(f"--dpi must be positive, got {args.dpi}")
    fig = plot_robot(robot, q, frames=not args.no_frames, labels=not args.no_labels, path=path,
                     elev=args.elev, azim=args.azim)
    save_figure(fig, args.output, dpi=args.dpi)
    geom = arm_geometry(robot, q)
    unit = "deg" if args.deg else "rad"
    data = {"robot": robot.name, "q": _out_q(args, robot, q), "angle_unit": unit, "output": args.output,
            "T": geom.end_effector, "joint_positions": geom.joint_positions, "skeleton": geom.skeleton}
    return data, f"wrote {args.output} ({robot.name} at q = {_fmt(_out_q(args, robot, q))} {unit})"


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
    from ..viz._plot import figure_format

    robot = load(args)
    figure_format(args.output, ("gif", "mp4"))
    refuse_overwrite(args, args.output)
    if not (math.isfinite(args.duration) and args.duration > 0):
        raise ParseError(f"--duration must be a positive number of seconds, got {args.duration}")
    if not (math.isfinite(args.fps) and 0 < args.fps <= 100):
        raise ParseError(f"--fps must be in (0, 100], got {args.fps}")
    q1 = joint_values(args, robot, args.q_from, what="--from")
    q2 = joint_values(args, robot, args.q_to, what="--to")
    k = max(2, int(round(args.duration * args.fps)) + 1)
    qs, cp = _move(args, robot, q1, q2, k)
    animate_robot(robot, qs, args.output, fps=args.fps, frames=not args.no_frames)
    ee = forward_kinematics(robot, qs)[:, :3, 3]
    unit = "deg" if args.deg else "rad"
    data = {"robot": robot.name, "q_from": _out_q(args, robot, q1), "q_to": _out_q(args, robot, q2),
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

    robot = load(args)
    refuse_overwrite(args, args.output)
    q = default_configuration(robot) if args.q is None else joint_values(args, robot, args.q)
    path = write_viewer(robot, args.output, q)
    size = path.stat().st_size
    data = {"robot": robot.name, "q": _out_q(args, robot, q), "angle_unit": "deg" if args.deg else "rad",
            "output": str(path), "bytes": size}
    return data, f"wrote {path} ({size // 1024} KiB, self-contained: open it in any browser, no network needed)"


def cmd_workspace(args: argparse.Namespace):
    from ..viz import plot_workspace, workspace

    robot = load(args)
    if args.output:
        from ..viz._plot import figure_format

        figure_format(args.output)
        refuse_overwrite(args, args.output)
    if args.samples < 100 or args.samples > 20_000_000:
        raise ParseError(f"--samples must be between 100 and 20000000, got {args.samples}")
    if args.resolution is not None and not (math.isfinite(args.resolution) and args.resolution > 0):
        raise ParseError(f"--resolution must be a positive length in metres, got {args.resolution}")
    rng = np.random.default_rng(args.seed)
    ws = workspace(robot, args.samples, args.resolution, rng)
    if args.output:
        from ..viz._plot import save_figure

        save_figure(plot_workspace(ws, robot.name), args.output)
    data = {"robot": robot.name, "output": args.output, "seed": args.seed, **ws.summary()}
    size = (f"area ≈ {ws.area:.4g} m² (planar arm; {ws.voxels} cells of {ws.resolution:.3g} m)" if ws.planar
            else f"volume ≈ {ws.volume:.4g} m³ ({ws.voxels} voxels of {ws.resolution:.3g} m)")
    lines = [f"{robot.name} workspace from {ws.samples} samples within the joint limits",
             f"x: [{ws.bounds_min[0]:.4g}, {ws.bounds_max[0]:.4g}] m   y: [{ws.bounds_min[1]:.4g}, "
             f"{ws.bounds_max[1]:.4g}] m   z: [{ws.bounds_min[2]:.4g}, {ws.bounds_max[2]:.4g}] m",
             f"extent: {ws.extent[0]:.4g} × {ws.extent[1]:.4g} × {ws.extent[2]:.4g} m, reach from base origin "
             f"{ws.reach:.4g} m", size]
    if args.output:
        lines.append(f"wrote {args.output}")
    return data, "\n".join(lines)
