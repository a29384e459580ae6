"""The joint-torque regressor, single call: compiled denavit against Pinocchio in the same process.

Run on demand:  python benchmarks/bench_regressor.py [--repeat 7] [--number 20000]

For the Puma 560 and the Panda (catalogue arms; the Pinocchio model from denavit.peers.to_pinocchio), one
configuration per call, from Python: ``fast.regressor(q, qd, qdd)`` (Y with the 10 n inertial columns, then
FV, FC, IA) against ``pin.computeJointTorqueRegressor`` (the 10 n inertial columns).  The inertial columns are
checked equal before timing.  Times: best over rounds of the mean of ``number`` calls, the contenders taking
turns within each round (the machine is shared: read the ratios, and the load average printed with them).
"""

from __future__ import annotations

import argparse
import os

import numpy as np

import denavit
from _peers import best_times, to_pinocchio


def bench(name: str, repeat: int, number: int) -> tuple[float, float, float]:
    import pinocchio as pin

    robot = denavit.load_robot(name)
    fast = denavit.compile(robot)
    rng = np.random.default_rng(0)
    q, qd, qdd = rng.uniform(-1.0, 1.0, robot.dof), rng.normal(size=robot.dof), rng.normal(size=robot.dof)
    model, data, _ = to_pinocchio(robot)
    n = robot.dof

    def theirs():
        return pin.computeJointTorqueRegressor(model, data, q, qd, qdd)

    def ours():
        return fast.regressor(q, qd, qdd)

    assert np.abs(ours()[:, :10 * n] - theirs()).max() < 1e-9 * max(1.0, np.abs(theirs()).max())
    t_ours, t_theirs = best_times([ours, theirs], repeat, number)
    return t_ours * 1e6, t_theirs * 1e6, t_ours / t_theirs


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--repeat", type=int, default=7)
    ap.add_argument("--number", type=int, default=20000)
    args = ap.parse_args(argv)
    print(f"load average {os.getloadavg()[0]:.2f} on {os.cpu_count()} cores")
    print(f"{'arm':10} {'denavit µs':>11} {'Pinocchio µs':>13} {'ratio':>6}")
    for name in ("puma560", "panda"):
        ours, theirs, ratio = bench(name, args.repeat, args.number)
        print(f"{name:10} {ours:11.2f} {theirs:13.2f} {ratio:6.2f}")
    print(f"load average {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
