"""ik --free / --sweep: a redundant arm held at one joint, or every solution over that joint's range.

``--free qN=V`` is ``--lock qN=V`` under issue 30's name (one code path: both end in ``analytic_ik(locked=)``);
``--free qN --sweep [--samples S]`` lists the branches of :func:`denavit.free_joint_sweep` and the feasible
intervals of qN.
"""

from __future__ import annotations

import argparse

import numpy as np

from ..errors import ParseError
from ._common import bounded_int, number_text

#: most samples of the held joint a --sweep may ask for
MAX_SAMPLES = 100_000


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("--free", metavar="qN=V", action="append",
                   help="analytic: hold joint qN at V and solve the others (the same as --lock); with --sweep: "
                        "qN alone, the joint to sweep")
    p.add_argument("--sweep", action="store_true",
                   help="redundant arm: every solution as a function of the --free joint over its limits (default "
                        "joint: a closed-form choice, panda q7), with the branches and the feasible intervals")
    p.add_argument("--samples", type=bounded_int(2, MAX_SAMPLES), default=None,
                   help="with --sweep: samples of the held joint (default 256)")


def check(args) -> None:
    """The combinations that make no sense, refused with one line."""
    if args.samples is not None and not args.sweep:
        raise ParseError("--samples goes with --sweep")
    if args.sweep and (args.lock or args.method == "numeric" or args.all):
        raise ParseError("--sweep goes with --free qN (analytic); not with --lock, --all or --method numeric")
    if args.free and args.method == "numeric":
        raise ParseError("--free goes with the analytic solver (--method analytic or auto)")


def sweep_joint(args, robot) -> str | None:
    """``--free q3`` → "q3" (None when not given: the library's default joint)."""
    if not args.free:
        return None
    if len(args.free) != 1:
        raise ParseError("--sweep: give one --free qN (the joint to sweep)")
    name = args.free[0].strip()
    digits = name[1:]
    if not (name[:1] == "q" and digits.isascii() and digits.isdigit() and len(digits) <= 4
            and 1 <= int(digits) <= robot.dof):
        raise ParseError(f"--free: {name[:40]!r} is not a joint of {robot.name} (q1 … q{robot.dof}); with --sweep "
                         f"give the joint alone, e.g. --free q{robot.dof}")
    return f"q{int(digits)}"


def _added(res, k: int, dof: int) -> str:
    """Where free_joint_sweep adds samples between the evenly spaced ones (ik/_sweep.py, _cross.py, _margin.py)."""
    where = ["next to branch ends"] + ([f"from the cross-wise {res.cross} search"] if res.cross else [])
    return ", ".join(where + (["from the limit margin"] if k in (0, dof - 1) else []))


def cmd_sweep(args, robot, T):
    """(data, lines) of ``ik --sweep``: the branches over the held joint's range and its feasible intervals."""
    from ..ik import SAMPLES, free_joint_sweep
    from ..model import JointType

    joint = sweep_joint(args, robot)
    samples = args.samples or SAMPLES
    res = free_joint_sweep(robot, T, joint, samples=samples)
    k = int(res.joint[1:]) - 1
    deg = args.deg and robot.joint_types[k] is JointType.REVOLUTE
    unit = (lambda v: float(np.degrees(v))) if deg else float
    qunit = (lambda q: np.where([t is JointType.REVOLUTE for t in robot.joint_types], np.degrees(q), q)
             if args.deg else np.asarray(q))
    fmt = lambda v: number_text(unit(v), 6)
    data = {"method": "analytic sweep", "structure": res.method, "joint": res.joint,
            "limits": [unit(v) for v in res.limits], "samples": samples, "evaluated": len(res.values), "tol": unit(res.tol),
            "intervals": [[unit(a), unit(b)] for a, b in res.intervals], "success": bool(res.intervals),
            "branches": [{"label": b.label, "interval": [unit(v) for v in b.interval], "values": [unit(v) for v in b.values],
                          "solutions": qunit(b.q)} for b in res.branches]}
    span = lambda ab: f"[{fmt(ab[0])}, {fmt(ab[1])}]"
    lines = [(f"{res.joint} swept over {span(res.limits)} ({samples} samples + {len(res.values) - samples} added: {_added(res, k, robot.dof)}; "
             f"ends to {number_text(unit(res.tol), 3)}; held arm: {res.method})"),
             f"feasible {res.joint} (a solution within every joint limit): "
             + (", ".join(span(ab) for ab in res.intervals) if res.intervals else "none"),
             f"{len(res.branches)} branch(es):"]
    for n, b in enumerate(res.branches, start=1):
        mid = b.q[len(b.q) // 2]
        lines.append(f"  {n}: {res.joint} in {span(b.interval)}" + (f"   {b.label}" if b.label else "")
                     + f"   e.g. q = [{', '.join(number_text(v, 6) for v in qunit(mid))}]")
    return data, lines


__all__ = ["add_arguments", "check", "cmd_sweep", "sweep_joint"]
