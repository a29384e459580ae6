"""Subcommands that sweep the workspace at scale: workspace, reachability (denavit.scale)."""

from __future__ import annotations

import argparse
import contextlib
import re
import sys

import numpy as np

from ._common import add_common, bounded_float, bounded_int, load, nonneg_int, number_text, require_finite
from ._output import add_no_clobber, check_output, output_file

PICTURES = (".png", ".svg", ".pdf")
DATA = (".npz",)
#: workspace: --samples range per run, and the --resolution range [m].
SAMPLES_MIN = 100
RESOLUTION_RANGE = (1e-6, 1e6)
#: reachability: --resolution range [m].
REACH_RESOLUTION_RANGE = (1e-3, 1e3)
_WHOLE = re.compile(r"\+?[0-9]{1,20}(?:\.[0-9]{0,20})?(?:[eE]\+?[0-9]{1,3})?")


def sample_count(lo: int, hi: int):
    """argparse type: a whole number in [lo, hi], also written like 1e9 or 2.5e6."""
    def parse(text: str) -> int:
        # imported here, not at the top: only --samples needs it (decimal is 6 ms of every command's start-up)
        from decimal import Decimal, InvalidOperation

        t = text.strip()
        try:
            value = Decimal(t) if _WHOLE.fullmatch(t) else None
        except InvalidOperation:
            value = None
        if value is None or value != value.to_integral_value():
            raise argparse.ArgumentTypeError(f"expected a whole number in [{lo}, {hi:.0e}] (1e9 is fine), "
                                             f"got {text[:40]!r}")
        if not lo <= value <= hi:
            raise argparse.ArgumentTypeError(f"expected a whole number in [{lo}, {hi:.0e}], got {text[:40]!r}")
        return int(value)
    return parse


def scheduler_name(text: str) -> str:
    """argparse type: threads, processes, synchronous or a dask scheduler address (checked before any work)."""
    from ..errors import ParseError
    from ..scale import check_scheduler

    try:
        check_scheduler(text)
    except ParseError as exc:
        raise argparse.ArgumentTypeError(str(exc)) from None
    return text


def _add_run_options(p: argparse.ArgumentParser) -> None:
    from .._constants import LOCAL_SCHEDULERS, MAX_WORKERS

    p.add_argument("--scheduler", type=scheduler_name, default="auto", metavar="WHERE",
                   help=f"{', '.join(LOCAL_SCHEDULERS)} (default auto: processes for 1e7 samples or more, threads "
                        "below; dask: a private dask.distributed LocalCluster of --workers processes on TLS, "
                        "started for the run) or the address of a dask.distributed scheduler you trust (it "
                        "receives pickles), tcp://HOST:PORT or tls://HOST:PORT (dask and addresses need "
                        "denavit[scale])")
    p.add_argument("--dashboard", action="store_true",
                   help="with --scheduler dask: serve Dask's dashboard on 127.0.0.1 at a free port, printed on "
                        "stderr (needs bokeh; readable by any local user)")
    p.add_argument("--workers", type=bounded_int(1, MAX_WORKERS), metavar="N",
                   help=f"local threads or processes (default: the CPU count; at most {MAX_WORKERS})")
    p.add_argument("--progress", action=argparse.BooleanOptionalAction, default=None,
                   help="progress line with ETA on stderr (default: when stderr is a terminal)")
    p.add_argument("--data", metavar="FILE", help="also save the arrays to FILE.npz (numpy.load reads it)")


def check_dashboard(args: argparse.Namespace) -> None:
    """--dashboard only with --scheduler dask (a cluster of the user's serves its own), refused before any work."""
    from ..errors import ParseError

    if args.dashboard and args.scheduler != "dask":
        raise ParseError("--dashboard: only with --scheduler dask (a scheduler of your own serves its own "
                         "dashboard)")


@contextlib.contextmanager
def where_to_run(args: argparse.Namespace):
    """The scheduler to pass on: ``args.scheduler``, or with --dashboard the Client of a LocalCluster started
    here with a dashboard (its address printed on stderr), closed afterwards."""
    if not args.dashboard:
        yield args.scheduler
        return
    from ..scale import local_cluster

    with local_cluster(args.workers, dashboard=True) as client:
        print(f"denavit {args.command}: Dask dashboard at {client.dashboard_link}", file=sys.stderr, flush=True)
        yield client


def register(sub: argparse._SubParsersAction) -> None:
    from .._constants import DEFAULT_ORIENTATIONS, MAX_ORIENTATIONS, MAX_SAMPLES

    p = sub.add_parser("workspace", help="reachable workspace by streamed sampling: bounds, volume with an interval")
    add_common(p, angles=False)
    p.add_argument("-o", "--output", metavar="FILE", help="picture to write (.png, .svg, .pdf); numbers only if absent")
    p.add_argument("--samples", type=sample_count(SAMPLES_MIN, MAX_SAMPLES), default=100_000,
                   help=f"random configurations (default 100000; {SAMPLES_MIN} to {MAX_SAMPLES:.0e}; 1e9 is fine)")
    p.add_argument("--resolution", type=bounded_float(*RESOLUTION_RANGE),
                   help="voxel edge [m] (default: chosen from the sample count; 1e-6 to 1e6)")
    p.add_argument("--seed", type=nonneg_int, help="random seed (default: a fresh one, reported)")
    p.add_argument("--refine", choices=("auto", "0", "2", "4", "8"), default="auto",
                   help="sub-cells per side of the boundary cells, counted after a pilot of 1/8 of the samples "
                        "(default auto: when the pilot fills the finest grid and no --resolution is given; 0: off)")
    _add_run_options(p)
    add_no_clobber(p)
    p.set_defaults(handler=cmd_workspace)

    p = sub.add_parser("reachability", help="per voxel, the share of orientations the arm reaches; manipulability")
    add_common(p, angles=False)
    p.add_argument("-o", "--output", metavar="FILE", help="picture of horizontal slices (.png, .svg, .pdf)")
    p.add_argument("--resolution", type=bounded_float(*REACH_RESOLUTION_RANGE), default=0.05,
                   help="voxel edge [m] (default 0.05; 0.001 to 1000)")
    p.add_argument("--orientations", type=bounded_int(1, MAX_ORIENTATIONS), default=DEFAULT_ORIENTATIONS,
                   help=f"orientations per voxel (default {DEFAULT_ORIENTATIONS}; at most {MAX_ORIENTATIONS})")
    p.add_argument("--ik", choices=("auto", "analytic", "numeric"), default="auto",
                   help="closed-form IK when the arm has it (auto), or force one")
    p.add_argument("--seed", type=nonneg_int, default=0, help="seed of the position screen and numeric restarts")
    p.add_argument("--no-screen", action="store_true", help="test every voxel of the reach ball")
    _add_run_options(p)
    add_no_clobber(p)
    p.set_defaults(handler=cmd_reachability)


def _write_data(args, result) -> None:
    if args.data:
        with output_file(args.data, "--data") as tmp:
            result.save(tmp)


def cmd_workspace(args: argparse.Namespace):
    from ..scale import BLOCK, MIN_COVERAGE, occupancy

    check_output(args, args.output, PICTURES, kind="picture format")
    check_output(args, args.data, DATA, what="--data")
    check_dashboard(args)
    robot = load(args)
    with where_to_run(args) as where:
        ws = occupancy(robot, args.samples, args.resolution, args.seed, scheduler=where, workers=args.workers,
                       progress=args.progress, refine=None if args.refine == "auto" else int(args.refine))
    require_finite("workspace", ws.bounds_min, ws.bounds_max, ws.reach)
    if args.output:
        from ..viz import plot_occupancy, save_figure

        fig = plot_occupancy(ws, robot.name)
        with output_file(args.output) as tmp:
            save_figure(fig, tmp)
    _write_data(args, ws)
    e = ws.estimate
    data = {"robot": robot.name, "output": args.output, "data": args.data, "scheduler": args.scheduler,
            **ws.summary()}
    what, unit = ("area", "m²") if ws.planar else ("volume", "m³")
    big = float(max(np.abs(ws.bounds_min).max(), np.abs(ws.bounds_max).max()))
    b = lambda x: number_text(x, 4, big)  # noqa: E731
    lines = [f"{robot.name} workspace from {ws.samples} samples within the joint limits (seed {ws.seed})",
             f"x: [{b(ws.bounds_min[0])}, {b(ws.bounds_max[0])}] m   y: [{b(ws.bounds_min[1])}, "
             f"{b(ws.bounds_max[1])}] m   z: [{b(ws.bounds_min[2])}, {b(ws.bounds_max[2])}] m",
             f"extent: {b(ws.extent[0])} × {b(ws.extent[1])} × {b(ws.extent[2])} m, reach from base origin "
             f"{ws.reach:.4g} m",
             f"{what} ≈ {e.value:.4g} {unit}, between {e.low:.4g} and {e.high:.4g} {unit}"
             + (" (planar arm)" if ws.planar else "")
             + f" ({e.occupied} cells of {e.resolution:.3g} m, sample coverage {e.coverage:.4f})"]
    if ws.refinement is not None:
        r = ws.refinement
        lines.append(f"boundary refined: {r.cells.size} cells of {ws.grid.resolution:.3g} m split {r.factor} per "
                     f"side, counted after a pilot of {r.pilot_blocks} block{'s' * (r.pilot_blocks != 1)} "
                     f"of {BLOCK} samples")
    if e.coverage < MIN_COVERAGE:
        lines.append(f"too few samples for a trusted interval (coverage below {MIN_COVERAGE}): use more samples")
    lines += [f"wrote {p}" for p in (args.output, args.data) if p]
    return data, "\n".join(lines)


def cmd_reachability(args: argparse.Namespace):
    from ..scale import reachability

    check_output(args, args.output, PICTURES, kind="picture format")
    check_output(args, args.data, DATA, what="--data")
    check_dashboard(args)
    robot = load(args)
    with where_to_run(args) as where:
        rmap = reachability(robot, args.resolution, args.orientations, ik=args.ik, scheduler=where,
                            workers=args.workers, seed=args.seed, screen=not args.no_screen, progress=args.progress)
    if args.output:
        from ..viz import plot_reachability, save_figure

        fig = plot_reachability(rmap, robot.name)
        with output_file(args.output) as tmp:
            save_figure(fig, tmp)
    _write_data(args, rmap)
    s = rmap.summary()
    data = {"robot": robot.name, "output": args.output, "data": args.data, "scheduler": args.scheduler, **s}
    lines = [f"{robot.name} reachability: {s['orientations']} orientations per {s['resolution']:.3g} m voxel, "
             f"{s['method']} IK, {s['voxels_tested']} voxels tested",
             f"reached at some orientation: {s['voxels_reached']} voxels ({s['reachable_volume']:.4g} m³); "
             f"at half of the orientations or more: {s['dexterous_volume']:.4g} m³",
             f"mean share of orientations over reached voxels {s['mean_fraction']:.3f}; "
             f"largest manipulability {s['max_manipulability']:.4g}"]
    lines += [f"wrote {p}" for p in (args.output, args.data) if p]
    return data, "\n".join(lines)
