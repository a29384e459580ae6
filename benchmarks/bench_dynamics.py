"""Dynamics speed: denavit vs Pinocchio vs roboticstoolbox-python, in one run.

Run:  python benchmarks/bench_dynamics.py [--batch 10000] [--repeat 5] [--no-symbolic]
Prints a Markdown table.  Before timing, every library is checked to agree with denavit on the
numbers it is timed on (RNEA torques, mass matrix, forward-dynamics accelerations).

Timed operations, each for Puma 560 (6 DOF, standard DH) and Panda (7 DOF, modified DH):
  RNEA        τ = M q̈ + c + g (no friction; motor inertia included, as Pinocchio's armature)
  M           joint-space mass matrix (denavit: CRBA; Pinocchio: crba; rtb: inertia)
  FD          q̈ from τ (denavit: RNEA bias + CRBA + solve; Pinocchio: aba; rtb: accel)
Single call: one configuration, best of `repeat` × k calls.  Batch: `batch` configurations — denavit in one
call on (batch, n) arrays, Pinocchio in a Python loop, roboticstoolbox's C RNEA on (batch, n) arrays.
Symbolic: Puma 560 M, c, g by denavit.symbolic.lagrangian_dynamics (time, and size in characters of str() of
M, c, g), each case in a fresh process; the coriolis=True row also forms the matrix C (not counted in the size).
"""

from __future__ import annotations

import argparse
import os
import platform
import subprocess
import sys
import time

import numpy as np

import denavit
from _peers import best_time, to_pinocchio

ROBOTS = ("puma560", "panda")


def _armature(robot) -> np.ndarray:
    return np.array([j.inertia.motor_inertia if j.inertia else 0.0 for j in robot.joints])


def _states(robot, batch: int):
    rng = np.random.default_rng(0)
    lo, hi = -np.pi, np.pi
    return (rng.uniform(lo, hi, (batch, robot.dof)), rng.uniform(-2, 2, (batch, robot.dof)),
            rng.uniform(-5, 5, (batch, robot.dof)))


def bench_ours(robot, Q, QD, QDD, repeat, number):
    """{op: (single [s], batch rate [1/s])} and the batched results for the agreement checks."""
    B = len(Q)
    tau = denavit.rnea(robot, Q, QD, QDD, friction=False)
    ops = {
        "RNEA": (lambda i: denavit.rnea(robot, Q[i], QD[i], QDD[i], friction=False),
                 lambda: denavit.rnea(robot, Q, QD, QDD, friction=False)),
        "M": (lambda i: denavit.mass_matrix(robot, Q[i]), lambda: denavit.mass_matrix(robot, Q)),
        "FD": (lambda i: denavit.forward_dynamics(robot, Q[i], QD[i], tau[i], friction=False),
               lambda: denavit.forward_dynamics(robot, Q, QD, tau, friction=False)),
    }
    out = {}
    for op, (single, batched) in ops.items():
        s = best_time(lambda: single(0), repeat, number)
        b = best_time(batched, repeat, 1)
        out[op] = (s, B / b)
    return out, tau, denavit.mass_matrix(robot, Q)


def bench_pinocchio(robot, Q, QD, QDD, tau, M, repeat, number):
    import pinocchio as pin

    model, data, _ = to_pinocchio(robot)
    model.armature = _armature(robot)
    data = model.createData()
    k = min(len(Q), 200)
    for i in range(k):  # agreement on the timed inputs
        assert np.allclose(pin.rnea(model, data, Q[i], QD[i], QDD[i]), tau[i], atol=1e-8), "pinocchio rnea"
        Mp = pin.crba(model, data, Q[i])
        assert np.allclose(np.triu(Mp) + np.triu(Mp, 1).T, M[i], atol=1e-8), "pinocchio crba"
        assert np.allclose(pin.aba(model, data, Q[i], QD[i], tau[i]), QDD[i], atol=1e-6), "pinocchio aba"
    ops = {"RNEA": lambda i: pin.rnea(model, data, Q[i], QD[i], QDD[i]),
           "M": lambda i: pin.crba(model, data, Q[i]),
           "FD": lambda i: pin.aba(model, data, Q[i], QD[i], tau[i])}
    out = {}
    for op, fn in ops.items():
        s = best_time(lambda: fn(0), repeat, number * 10)
        t0 = time.perf_counter()
        for i in range(len(Q)):
            fn(i)
        out[op] = (s, len(Q) / (time.perf_counter() - t0))
    return f"Pinocchio {pin.__version__} (Python loop)", out


def bench_rtb(Q, QD, QDD, tau, M, repeat, number):
    """roboticstoolbox's own Puma 560 model (Armstrong/Corke dynamics = our catalogue puma560), no friction."""
    import roboticstoolbox as rtb

    peer = rtb.models.DH.Puma560().nofriction(coulomb=True, viscous=True)
    k = min(len(Q), 200)
    assert np.allclose(peer.rne(Q[:k], QD[:k], QDD[:k]), tau[:k], atol=1e-8), "rtb rne"
    assert np.allclose(peer.inertia(Q[:k]), M[:k], atol=1e-8), "rtb inertia"
    assert np.allclose(peer.accel(Q[:20], QD[:20], tau[:20]), QDD[:20], atol=1e-6), "rtb accel"
    out = {"RNEA": (best_time(lambda: peer.rne(Q[0], QD[0], QDD[0]), repeat, number),
                    len(Q) / best_time(lambda: peer.rne(Q, QD, QDD), repeat, 1))}
    kb = min(len(Q), 1000)
    out["M"] = (best_time(lambda: peer.inertia(Q[0]), repeat, max(number // 10, 5)),
                kb / best_time(lambda: peer.inertia(Q[:kb]), 1, 1))
    out["FD"] = (best_time(lambda: peer.accel(Q[0], QD[0], tau[0]), repeat, max(number // 10, 5)),
                 kb / best_time(lambda: peer.accel(Q[:kb], QD[:kb], tau[:kb]), 1, 1))
    return f"roboticstoolbox {rtb.__version__} (C rne, batched arrays)", out


def numeric_rows(batch: int, repeat: int, number: int):
    rows = []
    for name in ROBOTS:
        robot = denavit.load_robot(name)
        Q, QD, QDD = _states(robot, batch)
        ours, tau, M = bench_ours(robot, Q, QD, QDD, repeat, number)
        rows.append((name, "denavit (numpy)", ours))
        try:
            rows.append((name, *bench_pinocchio(robot, Q, QD, QDD, tau, M, repeat, number)))
        except ImportError:
            rows.append((name, "Pinocchio: not installed", {}))
        if name == "puma560":
            try:
                rows.append((name, *bench_rtb(Q, QD, QDD, tau, M, repeat, number)))
            except ImportError:
                rows.append((name, "roboticstoolbox: not installed", {}))
    return rows


SYMBOLIC_CASES = (("trig", False), ("none", False), ("trig", True))


def symbolic_one(case: int) -> None:
    """Time one symbolic case (run in a fresh process, so that no case profits from sympy's caches)."""
    from denavit.symbolic import lagrangian_dynamics

    simplify, coriolis = SYMBOLIC_CASES[case]
    robot = denavit.load_robot("puma560")
    t0 = time.perf_counter()
    terms = lagrangian_dynamics(robot, simplify=simplify, coriolis=coriolis)
    dt = time.perf_counter() - t0
    size = sum(len(str(m)) for m in (terms.M, terms.c, terms.g))
    print(f"{dt} {size}")


def symbolic_rows():
    rows = []
    for case, (simplify, coriolis) in enumerate(SYMBOLIC_CASES):
        out = subprocess.run([sys.executable, __file__, "--symbolic-one", str(case)], capture_output=True,
                             text=True, check=True).stdout.split()
        rows.append((f"simplify={simplify!r}, coriolis={coriolis}", float(out[0]), int(out[1])))
    return rows


def _fmt(single: float, rate: float) -> str:
    s = f"{single * 1e6:.1f}" if single < 1e-4 else f"{single * 1e6:.0f}"
    return f"{s} | {rate / 1e6:.3f} M"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--batch", type=int, default=10_000)
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--number", type=int, default=200, help="calls per single-call timing run")
    ap.add_argument("--no-symbolic", action="store_true")
    ap.add_argument("--symbolic-one", type=int, help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.symbolic_one is not None:
        return symbolic_one(args.symbolic_one)
    load = os.getloadavg()[0] if hasattr(os, "getloadavg") else float("nan")
    print(f"machine: {platform.processor() or platform.machine()}, {os.cpu_count()} cores, load {load:.2f}, "
          f"Python {platform.python_version()}, numpy {np.__version__}; batch {args.batch}")
    print("\n| robot | library | RNEA single [µs] | RNEA batch [configs/s] | M single [µs] | M batch [configs/s] "
          "| FD single [µs] | FD batch [configs/s] |\n|---|---|---:|---:|---:|---:|---:|---:|")
    for name, lib, res in numeric_rows(args.batch, args.repeat, args.number):
        cells = " | ".join(_fmt(*res[op]) if op in res else "n/a | n/a" for op in ("RNEA", "M", "FD"))
        print(f"| {name} | {lib} | {cells} |")
    if not args.no_symbolic:
        print("\n| Puma 560 M, c, g (symbolic) | time [s] | size [chars] |\n|---|---:|---:|")
        for label, dt, size in symbolic_rows():
            print(f"| denavit lagrangian_dynamics({label}) | {dt:.1f} | {size:,} |")
    print(f"\nload after: {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
