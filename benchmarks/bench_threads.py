"""threads=: a batch split over 1, 2, … threads, in one run (compiled kernels and plain numpy functions).

Run:  python benchmarks/bench_threads.py [--batch 1e6] [--plain-batch 1e5] [--robots puma560,panda] [--repeat 5]
Prints Markdown tables, with the load average before and after (the machine is shared: the ratio of two columns
of one run is the figure, not the absolute times).  Before timing, every split result is checked to equal the
unsplit one bit for bit.

Compiled (``denavit.compile(robot)``, numba backend when installed), for FK, J0, RNEA, M, FD, gravity and
coriolis (and the derivative kernels where the compiled object has them):
  call    ``fast.<op>(q, …, threads=t)``: the whole call, a fresh (B, …) output each time (its pages are first
          touched by the kernel, in the threads)
  kernel  ``denavit._threads.run_batch`` of the batch kernel into one output reused across calls: the kernel's
          own throughput, without the page faults of a fresh output
IK (LM): ``fast.solve_ik(T, threads=t)`` on ``--ik-targets`` targets (FK of random q inside the limits, no seeds).
Plain (``denavit.forward_kinematics`` …, numpy): ``f(robot, q, …, threads=t)`` on ``--plain-batch`` rows.
Times are the best of ``--repeat`` rounds, the thread counts taking turns within each round.
"""

from __future__ import annotations

import argparse
import os
import platform
import sys

import numpy as np

import denavit
from _peers import best_times
from denavit._threads import available_cores, run_batch

OPS = ("fk", "jacobian", "rnea", "mass_matrix", "forward_dynamics", "gravity", "coriolis")
LABEL = {"fk": "FK", "jacobian": "J0", "rnea": "RNEA", "mass_matrix": "M", "forward_dynamics": "FD",
         "gravity": "g", "coriolis": "c", "solve_ik": "IK (LM)", "rnea_derivatives": "∂RNEA", "forward_dynamics_derivatives": "∂FD"}
KERNEL = {"jacobian": "jacobian0"}
ARGS = {"fk": 1, "jacobian": 1, "mass_matrix": 1, "gravity": 1, "coriolis": 2, "rnea": 3, "forward_dynamics": 3,
        "rnea_derivatives": 3, "forward_dynamics_derivatives": 3}
PLAIN = {"fk": denavit.forward_kinematics, "jacobian": denavit.geometric_jacobian, "rnea": denavit.rnea,
         "mass_matrix": denavit.mass_matrix, "forward_dynamics": denavit.forward_dynamics,
         "gravity": denavit.gravity_torques, "coriolis": denavit.coriolis_vector}


def _inputs(n: int, rows: int):
    rng = np.random.default_rng(0)
    return rng.uniform(-np.pi, np.pi, (rows, n)), rng.uniform(-2, 2, (rows, n)), rng.uniform(-3, 3, (rows, n))


def _same(results) -> bool:
    first = results[0]
    if isinstance(first, tuple):
        return all(all(np.array_equal(a, b) for a, b in zip(first, r)) for r in results[1:])
    return all(np.array_equal(first, r) for r in results[1:])


def _compiled_rows(robot, threads, rows, repeat, ik_targets):
    fast = denavit.compile(robot)
    fast.warm()
    xs = _inputs(robot.dof, rows)
    ops = OPS + tuple(op for op in ("rnea_derivatives", "forward_dynamics_derivatives") if hasattr(fast, op))
    out = []
    for op in ops:
        method = getattr(fast, op)
        args = xs[:ARGS[op]]
        calls = [lambda t=t, m=method, a=args: m(*a, threads=t) for t in threads]
        if not _same([c() for c in calls]):
            sys.exit(f"{op}: split results differ from the unsplit call")
        call = best_times(calls, repeat, 1)
        kernel = None
        name = KERNEL.get(op, op)
        if hasattr(fast._m, f"{name}_n") and op in OPS:
            k = getattr(fast._m, f"{name}_n")
            o = np.empty((rows,) + fast._shapes[name])
            k(*[np.ascontiguousarray(a) for a in args], o)  # touch the output's pages once
            kernel = best_times([lambda t=t, k=k, a=args, o=o: run_batch(k, a, (o,), t) for t in threads], repeat, 1)
        out.append((op, call, kernel))
    if ik_targets:  # numeric IK on targets made by FK of q inside the limits, no seeds (restarts drawn)
        lim = robot.q_limits
        Q = np.random.default_rng(1).uniform(lim[:, 0], lim[:, 1], (ik_targets, robot.dof))
        T = denavit.forward_kinematics(robot, Q)
        calls = [lambda t=t: fast.solve_ik(T, rng=np.random.default_rng(2), threads=t) for t in threads]
        if not _same([c().q for c in calls]):
            sys.exit("solve_ik: split results differ from the unsplit call")
        out.append(("solve_ik", best_times(calls, max(2, repeat // 2), 1), None, ik_targets))
    return fast.backend, out


def _plain_rows(robot, threads, rows, repeat):
    xs = _inputs(robot.dof, rows)
    out = []
    for op, f in PLAIN.items():
        args = xs[:ARGS[op]]
        calls = [lambda t=t, f=f, a=args: f(robot, *a, threads=t) for t in threads]
        if not _same([c() for c in calls]):
            sys.exit(f"plain {op}: split results differ from the unsplit call")
        out.append((op, best_times(calls, repeat, 1), None))
    return out


def _table(title, rows, threads, batch):
    head = " | ".join(f"{t} thr [ms]" for t in threads)
    ratio = " | ".join(f"1/{t}" for t in threads[1:])
    print(f"\n{title}, batch {batch:,}\n")
    print(f"| op | {head} | 1 thr [M rows/s] | call {ratio} | kernel {ratio} |")
    print("|---" * (2 + len(threads) + 2 * (len(threads) - 1)) + "|")
    for op, call, kernel, *count in rows:
        times = " | ".join(f"{1e3 * c:.1f}" for c in call)
        n = count[0] if count else batch
        rc = " | ".join(f"{call[0] / c:.2f}" for c in call[1:])
        rk = " | ".join(f"{kernel[0] / k:.2f}" for k in kernel[1:]) if kernel else " | ".join("–" for _ in call[1:])
        print(f"| {LABEL[op]}{'' if n == batch else f' ({n:,})'} | {times} | {n / call[0] / 1e6:.2f} | {rc} | {rk} |")


def main(argv=None) -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--batch", type=float, default=1e6)
    p.add_argument("--plain-batch", type=float, default=1e5)
    p.add_argument("--robots", default="puma560,panda")
    p.add_argument("--threads", default="1,2")
    p.add_argument("--repeat", type=int, default=5)
    p.add_argument("--no-plain", action="store_true")
    p.add_argument("--ik-targets", type=int, default=2000, help="numeric IK batch (0: none)")
    a = p.parse_args(argv)
    threads = [int(t) for t in a.threads.split(",")]
    print(f"{platform.processor() or platform.machine()}, {available_cores()} cores available, numpy {np.__version__}, "
          f"load average before: {' '.join(f'{x:.2f}' for x in os.getloadavg())}")
    for name in a.robots.split(","):
        robot = denavit.load_robot(name)
        backend, rows = _compiled_rows(robot, threads, int(a.batch), a.repeat, a.ik_targets)
        _table(f"{name}: compiled ({backend})", rows, threads, int(a.batch))
        if not a.no_plain:
            _table(f"{name}: plain numpy functions", _plain_rows(robot, threads, int(a.plain_batch), a.repeat),
                   threads, int(a.plain_batch))
    print(f"\nload average after: {' '.join(f'{x:.2f}' for x in os.getloadavg())}")


if __name__ == "__main__":
    main()
