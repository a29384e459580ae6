"""The issue-30 Done-when check for redundant arms at many random poses, run outside the suite (CI keeps its budget).

    python scripts/ik_free_check.py panda --poses 1000 --part sweep
    python scripts/ik_free_check.py iiwa7 --poses 1000 --part complete

``complete``: at each pose (q uniform within the limits, T = FK(q)) one joint is held at q's value (the default
free joint at even poses, the other joints in turn at odd ones; an elbow that cannot be held is skipped) and
``analytic_ik(free=)`` is compared with a dense Levenberg–Marquardt search of the held arm from 120 random seeds
(tests/test_ik_sweep.py's ``_dense``/``_missing``): a numeric solution missing from the analytic set is a failure.
``sweep``: ``free_joint_sweep`` over the default joint (64 samples) and tests/test_ik_sweep.py's ``_sweep_checks``:
every listed solution reproduces T within the limits, the generating value lies in a feasible interval, every
interval is confirmed by ``analytic_ik(free=)`` solutions near both ends and at two random inner points, and it
finds none 1e-4 past each end (outside every interval), the dense search finds no solution at the middle of each gap (``--gaps-every N``: at every Nth pose only), and the batch
counts agree with the intervals.
The checks are the test module's own functions (imported), so the suite and this run judge alike.
Prints one line per failure and a summary with CPU seconds.
"""

from __future__ import annotations

import argparse
import sys
import time
import traceback
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))

from test_ik_sweep import _check_solutions, _dense, _missing, _sweep_checks

import denavit
from denavit.errors import UnsupportedRobotError
from denavit.ik import default_free_joint


def _complete(robot, qi, Ti, k, rng):
    res = denavit.analytic_ik(robot, Ti, free={f"q{k + 1}": qi[k]})
    _check_solutions(robot, Ti, res.solutions)
    numeric = _dense(robot, Ti, k, qi[k], rng)
    _check_solutions(robot, Ti, numeric)
    missing = int(_missing(robot, k, numeric, res.solutions).sum())
    assert missing == 0, f"{missing} numeric solution(s) missing from analytic_ik(free=q{k + 1})"
    return res.count, len(numeric)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("robot")
    ap.add_argument("--poses", type=int, default=1000)
    ap.add_argument("--part", choices=("complete", "sweep"), default="sweep")
    ap.add_argument("--samples", type=int, default=64)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--start", type=int, default=0, help="check poses start … stop-1 of the --poses drawn (to split a run)")
    ap.add_argument("--stop", type=int, default=None)
    ap.add_argument("--gaps-every", type=int, default=1,
                    help="the dense search in the gaps between intervals at every Nth pose only (its 120 LM starts "
                         "per gap are most of the sweep check's time)")
    args = ap.parse_args(argv)
    robot = denavit.load_robot(args.robot)
    rng = np.random.default_rng(args.seed)
    lim = np.where(np.isfinite(robot.q_limits), robot.q_limits, np.array([-np.pi, np.pi]))
    q = rng.uniform(*lim.T, (args.poses, robot.dof))
    T = denavit.forward_kinematics(robot, q)
    joint = default_free_joint(robot)
    k0 = int(joint[1:]) - 1
    t0, fails, tally = time.process_time(), 0, np.zeros(3, dtype=int)
    for i, (qi, Ti) in enumerate(zip(q, T)):
        if not args.start <= i < (args.poses if args.stop is None else args.stop):
            continue
        try:
            if args.part == "sweep":
                sweep = denavit.free_joint_sweep(robot, Ti, joint, samples=args.samples)
                _sweep_checks(robot, Ti, qi, sweep, rng, gaps=i % args.gaps_every == 0)
                tally += (len(sweep.intervals), len(sweep.branches), 1)
            else:
                k = k0 if i % 2 == 0 else (i // 2) % robot.dof
                try:
                    tally += (*_complete(robot, qi, Ti, k, rng), 1)
                except UnsupportedRobotError:  # the S-R-S elbow: held, it leaves a continuum or nothing
                    pass
        except AssertionError as e:
            fails += 1
            print(f"pose {i}: FAILED {str(e).splitlines()[0] if str(e) else traceback.format_exc(limit=1)}; "
                  f"q = {np.array2string(qi, precision=17, separator=', ', max_line_width=10**4)}", flush=True)
        if (i + 1) % 50 == 0:
            print(f"  {i + 1} poses, {fails} failed, {time.process_time() - t0:.0f} CPU-s", flush=True)
    what = ("intervals, branches" if args.part == "sweep" else "analytic solutions, numeric hits")
    stop = args.poses if args.stop is None else args.stop
    print(f"{args.robot} {args.part} ({joint} default): poses {args.start}-{stop - 1} of {args.poses} ({tally[2]} checked), {fails} failed; "
          f"{what}: {tally[0]}, {tally[1]}; {time.process_time() - t0:.0f} CPU-s")
    return 1 if fails else 0


if __name__ == "__main__":
    sys.exit(main())
