"""Dynamics-derivative speed: compiled denavit vs Pinocchio, single call, in one process.

Run:  python benchmarks/bench_derivatives.py [--repeat 5] [--number 2000] [--batch 100000]
Prints a Markdown table.  Before timing, both libraries are checked to agree on the inputs they are timed on.

Timed operations, for Puma 560 (6 DOF, standard DH) and Panda (7 DOF, modified DH), no friction (Pinocchio's
RNEA has none), motor inertia included (Pinocchio's armature):
  RNEA derivatives  ∂τ/∂q, ∂τ/∂q̇   denavit: compile(robot).rnea_derivatives;  pin.computeRNEADerivatives
  ABA derivatives   ∂q̈/∂q, ∂q̈/∂q̇, M⁻¹  denavit: compile(robot).forward_dynamics_derivatives;  pin.computeABADerivatives
Single call: one configuration from Python, best of `repeat` rounds of the mean CPU time (time.process_time: time
spent descheduled on a loaded machine does not count) of `number` calls, the two libraries taking turns within each
round, so load on a shared machine reaches both alike.
Batch: `batch` configurations in one call of the compiled object on one thread (rows per second, CPU time, best of
`repeat` calls), and its batch kernel alone writing into one output reused across calls (no page faults of a fresh
58 MB output: the kernel's own throughput); Pinocchio's rate is a Python loop of `batch`/20 single calls, taking
turns with the two (it has no batch call), and the ratios are throughput ÷ that rate.
"""

from __future__ import annotations

import argparse
import platform
import time

import numpy as np

import denavit
from _peers import to_pinocchio

ROBOTS = ("puma560", "panda")


def cpu_best_times(fns, repeat: int, number: int) -> list[float]:
    """As _peers.best_times, in CPU seconds of this process per call."""
    best = [np.inf] * len(fns)
    for _ in range(repeat):
        for i, fn in enumerate(fns):
            t0 = time.process_time()
            for _ in range(number):
                fn()
            best[i] = min(best[i], (time.process_time() - t0) / number)
    return best


def _check(fast, model, data, q, qd, qdd, tau):
    import pinocchio as pin

    A, B = fast.rnea_derivatives(q, qd, qdd)
    dq, dv, _ = pin.computeRNEADerivatives(model, data, q, qd, qdd)
    assert np.allclose(A, dq, atol=1e-8) and np.allclose(B, dv, atol=1e-8), "rnea derivatives disagree"
    X, Y, Z = fast.forward_dynamics_derivatives(q, qd, tau)
    ddq, ddv, Minv = pin.computeABADerivatives(model, data, q, qd, tau)
    assert np.allclose(X, ddq, atol=1e-7) and np.allclose(Y, ddv, atol=1e-7) and np.allclose(Z, Minv, atol=1e-8), \
        "aba derivatives disagree"


def rows(repeat: int, number: int, batch: int):
    import pinocchio as pin

    out = []
    for name in ROBOTS:
        robot = denavit.load_robot(name)
        fast = denavit.compile(robot, friction=False)
        model, data, _ = to_pinocchio(robot)
        rng = np.random.default_rng(0)
        q, qd, qdd = (rng.uniform(-1, 1, robot.dof) for _ in range(3))
        tau = denavit.rnea(robot, q, qd, qdd, friction=False)
        fast.rnea_derivatives(q, qd, qdd)  # compiles the group (or loads it from the disk cache)
        fast.forward_dynamics_derivatives(q, qd, tau)
        _check(fast, model, data, q, qd, qdd, tau)
        ours_r, pin_r, ours_a, pin_a = cpu_best_times([
            lambda: fast.rnea_derivatives(q, qd, qdd), lambda: pin.computeRNEADerivatives(model, data, q, qd, qdd),
            lambda: fast.forward_dynamics_derivatives(q, qd, tau),
            lambda: pin.computeABADerivatives(model, data, q, qd, tau)], repeat, number)
        Q = rng.uniform(-1, 1, (batch, robot.dof))
        QD, QDD = rng.uniform(-1, 1, (2, batch, robot.dof))
        fast.rnea_derivatives(Q[:8], QD[:8], QDD[:8])  # the batch kernel compiles (or loads) before it is timed
        kernel, reused = fast._many["rnea_derivatives"], np.empty((batch, 2, robot.dof, robot.dof))
        kernel(Q, QD, QDD, reused)  # its pages touched once, here
        calls = max(1, batch // 20)  # Pinocchio's rate from a loop of single calls, taking turns with the batch

        def pin_loop():
            for i in range(calls):
                pin.computeRNEADerivatives(model, data, Q[i], QD[i], QDD[i])

        b, k, p = cpu_best_times([lambda: fast.rnea_derivatives(Q, QD, QDD, threads=1),
                                  lambda: kernel(Q, QD, QDD, reused), pin_loop], repeat, 1)
        out.append((name, "RNEA derivatives", ours_r, pin_r, (batch / b, batch / k, calls / p)))
        out.append((name, "ABA derivatives", ours_a, pin_a, None))
    return out, pin.__version__


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--repeat", type=int, default=5)
    p.add_argument("--number", type=int, default=2000)
    p.add_argument("--batch", type=int, default=100_000)
    args = p.parse_args()
    table, version = rows(args.repeat, args.number, args.batch)
    print(f"Python {platform.python_version()}, Pinocchio {version}, {platform.machine()}\n")
    print("| robot | operation | denavit compiled [µs] | Pinocchio [µs] | ratio | batch, 1 thread [M/s] "
          "| its kernel, reused output [M/s] | Pinocchio, a loop of calls [M/s] | batch ÷ Pinocchio | kernel ÷ Pinocchio |")
    print("|---|---|---:|---:|---:|---:|---:|---:|---:|---:|")
    for name, op, ours, peer, rates in table:
        batch = (" | ".join(f"{r / 1e6:.2f}" for r in rates) + f" | {rates[0] / rates[2]:.1f} | {rates[1] / rates[2]:.1f}"
                 if rates else " | | | | ")
        print(f"| {name} | {op} | {ours * 1e6:.2f} | {peer * 1e6:.2f} | {ours / peer:.2f} | {batch} |")


if __name__ == "__main__":
    main()
