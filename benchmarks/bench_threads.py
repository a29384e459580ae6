"""threads=: a batch split over 1, 2, … threads, in one run (compiled kernels and plain numpy functions).

Run:  python benchmarks/bench_threads.py [--batch 1e6] [--plain-batch 1e5] [--robots puma560,panda] [--repeat 5]
Prints Markdown tables, with the load average before and after (the machine is shared: the ratio of two columns
of one run is the figure, not the absolute times).  Before timing, every split result is checked to equal the
unsplit one bit for bit.

Compiled (``denavit.compile(robot)``, numba backend when installed), for FK, J0, RNEA, M, FD, gravity and
coriolis (and the derivative kernels where the compiled object has them):
  call    ``fast.<op>(q, …, threads=t)``: the whole call, a fresh (B, …) output each time (its pages are first
          touched by the kernel, in the threads)
  out=    ``fast.<op>(q, …, threads=t, out=o)``: the whole call into the caller's output, reused across calls
          (every op but FD), with its own ``CPU t/1``
  kernel  ``denavit._threads.run_batch`` of the batch kernel into one output reused across calls: the kernel's
          own throughput, without the page faults of a fresh output
IK (LM): ``fast.solve_ik(T, threads=t)`` on ``--ik-targets`` targets (FK of random q inside the limits, no seeds).
``--first-touch``: instead, where a fresh output's first touch goes (FK and J0 batch kernels of each robot):
  fresh   ``np.empty`` and the kernel in the threads (the public call's way: each thread first-touches its block)
  touch in threads / touch in caller   the output zero-filled first, by each thread for its block or by the
          calling thread, then the kernel (pre-faulting)
  reused  one output across calls (no first touch)
Plain (``denavit.forward_kinematics`` …, numpy): ``f(robot, q, …, threads=t)`` on ``--plain-batch`` rows.
Times are the best of ``--repeat`` rounds, the thread counts taking turns within each round.  ``CPU t/1`` is the
process CPU time (all threads) of the t-thread call over the 1-thread call's: near 1.0, splitting adds no work, so
on idle cores the speed-up is about t / that; on a loaded machine the wall-clock ratio falls below it.
"""

from __future__ import annotations

import argparse
import os
import platform
import sys
import time

import numpy as np

import denavit
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


def _busy() -> tuple[float, float]:
    """(CPU seconds every process has used, CPU seconds this process has used) so far; the first is NaN where
    /proc/stat is missing.  Their increments over a run give the cores the other processes kept busy."""
    try:
        with open("/proc/stat") as f:
            fields = [float(x) for x in f.readline().split()[1:]]
        total = (sum(fields) - fields[3] - fields[4]) / os.sysconf("SC_CLK_TCK")  # all but idle and iowait
    except (OSError, ValueError, IndexError):
        total = float("nan")
    t = os.times()
    return total, t.user + t.system


def _times(fns, repeat: int) -> tuple[list[float], list[float]]:
    """(best wall time, least process CPU time — every thread's) of one call of each of ``fns`` over ``repeat``
    rounds, the functions taking turns within each round [s]."""
    wall, cpu = [np.inf] * len(fns), [np.inf] * len(fns)
    for _ in range(repeat):
        for i, fn in enumerate(fns):
            c0, t0 = time.process_time(), time.perf_counter()
            fn()
            wall[i], cpu[i] = min(wall[i], time.perf_counter() - t0), min(cpu[i], time.process_time() - c0)
    return wall, cpu


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
        call = _times(calls, repeat)
        kernel = None
        name = KERNEL.get(op, op)
        if hasattr(fast._m, f"{name}_n") and op in OPS:
            k = getattr(fast._m, f"{name}_n")
            o = np.empty((rows,) + fast._shapes[name])
            k(*[np.ascontiguousarray(a) for a in args], o)  # touch the output's pages once
            kernel = _times([lambda t=t, k=k, a=args, o=o: run_batch(k, a, (o,), t) for t in threads], repeat)[0]
        reuse = None
        if op in OPS and op != "forward_dynamics":
            o = np.empty_like(calls[0]())  # its pages touched once, here
            reuse = _times([lambda t=t, m=method, a=args, o=o: m(*a, threads=t, out=o) for t in threads], repeat)
        out.append((op, call, kernel, reuse))
    if ik_targets:  # numeric IK on targets made by FK of q inside the limits, no seeds (restarts drawn)
        lim = robot.q_limits
        Q = np.random.default_rng(1).uniform(lim[:, 0], lim[:, 1], (ik_targets, robot.dof))
        T = denavit.forward_kinematics(robot, Q)
        calls = [lambda t=t: fast.solve_ik(T, rng=np.random.default_rng(2), threads=t) for t in threads]
        if not _same([c().q for c in calls]):
            sys.exit("solve_ik: split results differ from the unsplit call")
        out.append(("solve_ik", _times(calls, max(2, repeat // 2)), None, None, ik_targets))
    return fast.backend, out


def _plain_rows(robot, threads, rows, repeat):
    xs = _inputs(robot.dof, rows)
    out = []
    for op, f in PLAIN.items():
        args = xs[:ARGS[op]]
        calls = [lambda t=t, f=f, a=args: f(robot, *a, threads=t) for t in threads]
        if not _same([c() for c in calls]):
            sys.exit(f"plain {op}: split results differ from the unsplit call")
        out.append((op, _times(calls, repeat), None, None))
    return out


def _table(title, rows, threads, batch):
    head = " | ".join(f"{t} thr [ms]" for t in threads)
    ratio = " | ".join(f"1/{t}" for t in threads[1:])
    cpu = " | ".join(f"CPU {t}/1" for t in threads[1:])
    print(f"\n{title}, batch {batch:,}\n")
    print(f"| op | {head} | 1 thr [M rows/s] | call {ratio} | {cpu} | out= {ratio} | out= {cpu} | kernel {ratio} |")
    print("|---" * (2 + len(threads) + 5 * (len(threads) - 1)) + "|")
    for op, (call, cpu_s), kernel, reuse, *count in rows:
        times = " | ".join(f"{1e3 * c:.1f}" for c in call)
        n = count[0] if count else batch
        rc = " | ".join(f"{call[0] / c:.2f}" for c in call[1:])
        rp = " | ".join(f"{c / cpu_s[0]:.2f}" for c in cpu_s[1:])
        rk = " | ".join(f"{kernel[0] / k:.2f}" for k in kernel[1:]) if kernel else " | ".join("–" for _ in call[1:])
        dash = " | ".join("–" for _ in call[1:])
        ro = " | ".join(f"{reuse[0][0] / k:.2f}" for k in reuse[0][1:]) if reuse else dash
        ru = " | ".join(f"{k / reuse[1][0]:.2f}" for k in reuse[1][1:]) if reuse else dash
        label = f"{LABEL[op]}{'' if n == batch else f' ({n:,})'}"
        print(f"| {label} | {times} | {n / call[0] / 1e6:.2f} | {rc} | {rp} | {ro} | {ru} | {rk} |")


def _filled(shape) -> np.ndarray:
    o = np.empty(shape)
    o.fill(0.0)  # every page touched here, in the calling thread
    return o


def _first_touch(robot, threads, rows: int, repeat: int) -> None:
    """Best wall time and CPU t/1 of the FK and J0 batch kernels into a fresh, pre-faulted or reused output."""
    from denavit._threads import split_rows

    fast = denavit.compile(robot)
    fast.warm()
    q = _inputs(robot.dof, rows)[0]
    for name in ("fk", "jacobian0"):
        k, shape = getattr(fast._m, f"{name}_n"), (rows,) + fast._shapes[name]
        kept = np.zeros(shape)

        def touch_in(t, k=k, shape=shape):
            o = np.empty(shape)

            def work(s, e):
                o[s:e].fill(0.0)
                k(q[s:e], o[s:e])
            split_rows(rows, work, t)

        variants = {"fresh": lambda t, k=k, shape=shape: run_batch(k, (q,), (np.empty(shape),), t),
                    "touch in threads": touch_in,
                    "touch in caller": lambda t, k=k, shape=shape: run_batch(k, (q,), (_filled(shape),), t),
                    "reused": lambda t, k=k, kept=kept: run_batch(k, (q,), (kept,), t)}
        names = [(v, t) for v in variants for t in threads]
        wall, cpu = _times([lambda v=v, t=t: variants[v](t) for v, t in names], repeat)
        best = dict(zip(names, zip(wall, cpu)))
        print(f"\n{robot.name} {LABEL.get(name, name)}, {rows:,} rows, output {np.prod(shape) * 8 / 2**20:.0f} MiB\n")
        print("| output | " + " | ".join(f"{t} thr [ms]" for t in threads) + " | " +
              " | ".join(f"1/{t} | CPU {t}/1" for t in threads[1:]) + " |")
        print("|---" * (1 + len(threads) + 2 * (len(threads) - 1)) + "|")
        for v in variants:
            w = [best[(v, t)] for t in threads]
            print(f"| {v} | " + " | ".join(f"{1e3 * x[0]:.1f}" for x in w) + " | " +
                  " | ".join(f"{w[0][0] / x[0]:.2f} | {x[1] / w[0][1]:.2f}" for x in w[1:]) + " |")


def main(argv=None) -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--batch", type=float, default=1e6)
    p.add_argument("--plain-batch", type=float, default=1e5)
    p.add_argument("--robots", default="puma560,panda")
    p.add_argument("--threads", default="1,2")
    p.add_argument("--repeat", type=int, default=5)
    p.add_argument("--no-plain", action="store_true")
    p.add_argument("--no-compiled", action="store_true")
    p.add_argument("--ik-targets", type=int, default=2000, help="numeric IK batch (0: none)")
    p.add_argument("--first-touch", action="store_true", help="fresh, pre-faulted and reused outputs only")
    a = p.parse_args(argv)
    threads = [int(t) for t in a.threads.split(",")]
    print(f"{platform.processor() or platform.machine()}, {available_cores()} cores available, numpy {np.__version__}, "
          f"load average before: {' '.join(f'{x:.2f}' for x in os.getloadavg())}")
    start, wall = _busy(), time.perf_counter()
    for name in a.robots.split(","):
        robot = denavit.load_robot(name)
        if a.first_touch:
            _first_touch(robot, threads, int(a.batch), a.repeat)
            continue
        if not a.no_compiled:
            backend, rows = _compiled_rows(robot, threads, int(a.batch), a.repeat, a.ik_targets)
            _table(f"{name}: compiled ({backend})", rows, threads, int(a.batch))
        if not a.no_plain:
            _table(f"{name}: plain numpy functions", _plain_rows(robot, threads, int(a.plain_batch), a.repeat),
                   threads, int(a.plain_batch))
    end, wall = _busy(), time.perf_counter() - wall
    print(f"\nload average after: {' '.join(f'{x:.2f}' for x in os.getloadavg())}; other processes kept "
          f"{((end[0] - start[0]) - (end[1] - start[1])) / wall:.2f} cores busy on average during the run")


if __name__ == "__main__":
    main()
