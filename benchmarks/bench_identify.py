"""Dynamic identification of 10⁴ samples: denavit.identify (WLS, physically consistent fit included).

Run on demand:  python benchmarks/bench_identify.py [--samples 10000] [--repeat 3]

For the Puma 560 and the Panda, torques of the catalogue arm along a random finite-Fourier trajectory (5
harmonics of 0.1 Hz, sampled at 100 Hz) plus 1 % noise; the time of ``denavit.identify(..., method="wls")``
alone (the regressor stack, OLS, the per-joint noise, WLS, the σ, and the barrier fit of the realisable full
set).  Printed: the best of ``repeat`` runs in process CPU seconds and in wall seconds, with the load average
(the machine is shared).  The issue's target: 10⁴ samples in ≤ 10 s.
"""

from __future__ import annotations

import argparse
import os
import time

import numpy as np

import denavit


def trajectory(robot, samples: int, rng: np.random.Generator):
    """A random finite Fourier series (5 harmonics of 0.1 Hz) inside the joint limits, sampled at 100 Hz."""
    n, H, w = robot.dof, 5, 2 * np.pi * 0.1
    t = np.arange(samples) / 100.0
    a, b = rng.normal(size=(2, n, H))
    arg = w * np.outer(t, np.arange(1, H + 1))  # (N, H)
    l = np.arange(1, H + 1)
    q = np.sin(arg) @ (a / (w * l)).T - np.cos(arg) @ (b / (w * l)).T
    qd = np.cos(arg) @ a.T + np.sin(arg) @ b.T
    qdd = (np.cos(arg) * w * l) @ b.T - (np.sin(arg) * w * l) @ a.T
    lim = robot.q_limits
    s = np.minimum(0.8 * 0.5 * (lim[:, 1] - lim[:, 0]) / np.abs(q).max(0), 1.5 / np.abs(qd).max(0))
    return lim.mean(1) + q * s, qd * s, qdd * s


def bench(name: str, samples: int, repeat: int) -> tuple[float, float, object]:
    robot = denavit.load_robot(name)
    rng = np.random.default_rng(0)
    q, qd, qdd = trajectory(robot, samples, rng)
    tau = denavit.rnea(robot, q, qd, qdd)
    tau += rng.normal(size=tau.shape) * 0.01 * np.ptp(tau, axis=0)
    denavit.base_parameters(robot)  # the structural base parameters: computed once per arm, cached
    best_cpu = best_wall = np.inf
    for _ in range(repeat):
        c, w = time.process_time(), time.perf_counter()
        result = denavit.identify(robot, q, qd, qdd, tau, method="wls")
        best_cpu = min(best_cpu, time.process_time() - c)
        best_wall = min(best_wall, time.perf_counter() - w)
    return best_cpu, best_wall, result


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--samples", type=int, default=10_000)
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args()
    print(f"load average {os.getloadavg()[0]:.1f}, {args.samples} samples, best of {args.repeat}")
    for name in ("puma560", "panda"):
        cpu, wall, r = bench(name, args.samples, args.repeat)
        print(f"{name:8s} identify (WLS + physical): {cpu:6.2f} s CPU, {wall:6.2f} s wall; "
              f"{r.rank} base parameters, cond {r.condition_number:.0f}, realisable {r.physical.realisable}, "
              f"{r.physical.evaluations} Newton steps")


if __name__ == "__main__":
    main()
