"""Subcommand ``excite``: an excitation trajectory for dynamic identification, written as a measurement CSV."""

from __future__ import annotations

import argparse
import sys
import time

import numpy as np

from ..errors import ParseError
from ._common import (
    add_common,
    bounded_float,
    bounded_int,
    load,
    nonneg_int,
    number_text,
    positive_float,
)
from ._output import add_no_clobber, check_output

#: Seconds of optimisation after which the progress lines appear on a terminal's stderr.
PROGRESS_AFTER = 2.0


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("excite", help="an excitation trajectory (finite Fourier series within the joint limits, "
                                      "minimising the condition number of the base regressor) -> CSV t, q, qd, qdd")
    add_common(p)
    p.add_argument("-o", "--output", metavar="FILE", help="the trajectory to write (.csv: t, q1..qn, qd1..qdn, "
                                                          "qdd1..qddn; read by read_measurements, identify); "
                                                          "only the summary without it")
    p.add_argument("--harmonics", type=bounded_int(1, 20), default=5, metavar="N", help="harmonics (default 5)")
    p.add_argument("--period", type=bounded_float(0.01, 1e5), default=10.0, metavar="S",
                   help="period of the base harmonic [s] (default 10)")
    p.add_argument("--duration", type=positive_float, default=None, metavar="S",
                   help="length of the file [s] (default one period; longer repeats it)")
    p.add_argument("--rate", type=bounded_float(0.0, 1e5, open_low=True), default=100.0, metavar="HZ",
                   help="samples per second in the file (default 100)")
    p.add_argument("--seed", type=nonneg_int, default=0, metavar="N", help="seed of the random starts (default 0)")
    p.add_argument("--starts", type=bounded_int(1, 20), default=2, metavar="N",
                   help="random starts of the optimisation (default 2)")
    p.add_argument("--iterations", type=bounded_int(1, 1000), default=10, metavar="N",
                   help="SLSQP iterations per start (default 10)")
    p.add_argument("--margin", type=bounded_float(0.0, 0.49), default=0.05, metavar="F",
                   help="each side of the position limits moved in by this fraction of the range (default 0.05)")
    p.add_argument("--center", action="store_true",
                   help="hold each joint's offset q0 at the middle of its position window (else optimised)")
    p.add_argument("--qd-max", metavar="QD", help="velocity limits: one value or one per joint (rad/s, deg/s "
                                                  "with --deg, m/s; default 1 rad/s, 0.25 m/s)")
    p.add_argument("--qdd-max", metavar="QDD", help="acceleration limits, likewise (default 4 rad/s^2, 1 m/s^2)")
    p.add_argument("--no-friction", action="store_true", help="leave out the friction parameters FV, FC")
    p.add_argument("--no-motor-inertia", action="store_true", help="leave out the motor inertias IA")
    add_no_clobber(p)
    p.set_defaults(handler=cmd_excite)


def cmd_excite(args: argparse.Namespace):
    from ..calibration import excitation_trajectory, write_measurements

    check_output(args, args.output, (".csv",))  # before any work
    robot = load(args)
    duration = args.period if args.duration is None else args.duration
    samples = round(duration * args.rate)
    if not 2 <= samples <= 10**6:
        raise ParseError(f"--duration {duration:g} s at --rate {args.rate:g} Hz is {samples} samples; "
                         "between 2 and 1000000 can be written")
    rates = [_rate_limits(args, robot, text, what) for text, what in ((args.qd_max, "--qd-max"),
                                                                       (args.qdd_max, "--qdd-max"))]
    res = excitation_trajectory(robot, harmonics=args.harmonics, base_freq=1.0 / args.period, duration=duration,
                                samples=samples, margin=args.margin, qd_max=rates[0], qdd_max=rates[1],
                                friction=not args.no_friction, motor_inertia=not args.no_motor_inertia,
                                seed=args.seed, starts=args.starts, max_iterations=args.iterations,
                                center=args.center, progress=_progress(args))
    scale = _scale(args, robot)
    if args.output is not None:
        write_measurements(args.output, {"t": res.t, "q": res.q * scale, "qd": res.qd * scale,
                                         "qdd": res.qdd * scale},
                           comment=f"denavit excite {robot.name}: {res.harmonics} harmonics of "
                                   f"{number_text(res.base_freq)} Hz, cond {res.cond:.4g}; units "
                                   f"{'deg' if args.deg else 'rad'} for revolute joints, m for prismatic; "
                                   "periodic, not at rest at t = 0")
    return _report(args, robot, res, scale)


def _rate_limits(args, robot, text, what):
    """One value or dof values (plain numbers; degrees for revolute joints with --deg), each > 0."""
    if text is None:
        return None
    from ..io import parse_values

    values = parse_values(text, what=what)
    if values.size not in (1, robot.dof):
        raise ParseError(f"{what}: expected 1 or {robot.dof} values, got {values.size}")
    values = np.broadcast_to(values, (robot.dof,)) / _scale(args, robot)
    if not np.all(np.isfinite(values) & (values > 0)) or np.max(values) > 1e6:
        raise ParseError(f"{what}: every limit must be a number > 0 (and at most 1e6), got {text[:60]!r}")
    return values


def _scale(args, robot) -> np.ndarray:
    """Output unit per radian or metre, per joint: degrees for revolute joints with --deg."""
    from ..model import JointType

    rev = np.array([t is JointType.REVOLUTE for t in robot.joint_types])
    return np.where(rev & bool(args.deg), 180.0 / np.pi, 1.0)


def _progress(args):
    """Progress lines on a terminal's stderr once the optimisation has run PROGRESS_AFTER seconds (never --json)."""
    if args.json or not sys.stderr.isatty():
        return None
    start = time.monotonic()

    def show(stage: str) -> None:
        if time.monotonic() - start > PROGRESS_AFTER:
            print(f"denavit excite: {stage}", file=sys.stderr, flush=True)

    return show


def _report(args, robot, res, scale):
    unit = ("deg", "deg/s", "deg/s^2") if args.deg else ("rad", "rad/s", "rad/s^2")
    n, k = robot.dof, res.t.size
    duration = k * (res.t[1] - res.t[0])
    where = f" -> {args.output}" if args.output else " (no -o: nothing written)"
    lines = [(f"{robot.name}: {res.harmonics} harmonics of {number_text(res.base_freq)} Hz (period "
              f"{number_text(res.period)} s), {k} samples over {number_text(duration)} s{where}"),
             (f"cond of the stacked base regressor at {res.instants.size} instants: {res.cond_initial:.4g} (random "
              f"start) -> {res.cond:.4g} (optimised); rank {res.rank} of {res.n_base} base parameters"),
             (f"SLSQP: {res.starts} start(s), {res.iterations} iterations, {res.evaluations} regressor stacks "
              f"(budget {res.starts} x {args.iterations} iterations); {res.message}"),
             f"limits used ({unit[0]} for revolute joints, m for prismatic; * = active, use = fraction used):",
             "  joint  q window                     use     qd max     use     qdd max    use"]
    for j in range(n):
        lo, hi = res.q_limits[j] * scale[j]
        use = [f"{u:5.3f}{'*' if a else ' '}" for u, a in zip(res.usage[j], res.active[j])]
        lines.append(f"  {j + 1:<5}  [{number_text(lo):>10}, {number_text(hi):>10}]  {use[0]}  "
                     f"{number_text(res.qd_max[j] * scale[j]):>9}  {use[1]}  {number_text(res.qdd_max[j] * scale[j]):>9}"
                     f"  {use[2]}")
    if res.rank < res.n_base:
        lines.append(f"the trajectory excites only {res.rank} of the {res.n_base} base parameters: the others cannot "
                     "be identified from it (a longer --period, higher --qd-max or --qdd-max, more --iterations or "
                     "--starts)")
    lines.append("a periodic series: q and its rates join smoothly from one period to the next, but the motion "
                 "does not start or end at rest (qd(0) is not 0): ramp in from rest on a real arm")
    data = {"robot": robot.name, "output": args.output, "harmonics": res.harmonics, "base_freq": res.base_freq,
            "period": res.period, "duration": duration, "samples": k, "rate": args.rate, "seed": args.seed,
            "angle_unit": unit[0], "cond_initial": res.cond_initial, "cond": res.cond, "rank": res.rank,
            "n_base": res.n_base, "instants": res.instants.size, "q0": res.q0 * scale,
            "a": res.a * scale[:, None], "b": res.b * scale[:, None],
            "limits": {"q": res.q_limits * scale[:, None], "qd": res.qd_max * scale, "qdd": res.qdd_max * scale},
            "usage": {"q": res.usage[:, 0], "qd": res.usage[:, 1], "qdd": res.usage[:, 2]},
            "active": {"q": res.active[:, 0].tolist(), "qd": res.active[:, 1].tolist(),
                       "qdd": res.active[:, 2].tolist()},
            "starts": res.starts, "iterations": res.iterations, "evaluations": res.evaluations,
            "message": res.message, "at_rest": False}
    return data, "\n".join(lines)
