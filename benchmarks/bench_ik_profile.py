"""Where a pose of the compiled analytic IK's batch loop goes (issue 30): the kernel's steps cut one at a time.

Run:  python benchmarks/bench_ik_profile.py [--robot puma560] [--n 100000]

Each variant is a numba loop over the same n poses (FK of random joint values within the limits, seeded) running
the kernel's steps up to one point, timed by CPU time on one core (best of five interleaved rounds); the
differences between consecutive rows are the steps' costs.  Elbow kernel (puma560, offset-6r): "stages" (the
candidates of every branch, ``_ik_nb_elbow_stages``), "+ checks" (verifying FK, residuals, labels:
``_ik_nb_elbow.elbow_checks``), "kernel" (its fold, the walk over the branches, merge and sort too:
``ik_elbow_packed`` over blocks of 64 poses), "batch entry" (the target check and the scatter into the plain
solver's batched layout).  UR-class kernel (ur5): the same rows (``_ik_nb_parallel_stages``,
``_ik_nb_parallel.parallel_checks``, ``ik_parallel_packed``).  Report the load
(``uptime``) with the figures: the machine is shared.
"""

from __future__ import annotations

import argparse
import os
import time

import numpy as np
from numba import njit

import denavit
from denavit import forward_kinematics, load_robot
from denavit.codegen._ik_nb_elbow import elbow_checks, ik_elbow_packed
from denavit.codegen._ik_nb_elbow_stages import CHUNK, ROWS, RQA, elbow_stages
from denavit.codegen._ik_nb_parallel import ik_parallel_packed, parallel_checks
from denavit.codegen._ik_nb_parallel_stages import ROWS as UR_ROWS
from denavit.codegen._ik_nb_parallel_stages import RQ2 as UR_RQ2
from denavit.codegen._ik_nb_parallel_stages import parallel_stages


@njit(nogil=True)
def _stages(stages, check, rows, probe, T, K, checks):
    """The stage loop of a kernel (``stages``, then ``check`` when ``checks``) over T in chunks; ``probe``: a row read
    so the work is not optimised away."""
    St, acc = np.empty(rows * CHUNK), 0.0
    for b in range(0, T.shape[0], CHUNK):
        n = min(CHUNK, T.shape[0] - b)
        stages(T, b, n, K, St)
        if checks:
            check(n, K, St)
        acc += St[probe * CHUNK]
    return acc


@njit(nogil=True)
def _kernel(packed, T, K):
    f, i = np.empty((64, 8, 14)), np.empty((64, 20))
    for s in range(0, T.shape[0], 64):
        e = min(s + 64, T.shape[0])
        packed(T[s:e], K, f[: e - s], i[: e - s])
    return f[0, 0, 0]


def profile(name, n):
    robot = load_robot(name)
    fast = denavit.compile(robot, kernels=["fk", "fk_jacobian0"])
    kern = fast._analytic_solver()
    K, many = kern[0], kern[3]
    rng = np.random.default_rng(8)
    lim = np.clip(robot.q_limits, -np.pi, np.pi)
    T = np.ascontiguousarray(forward_kinematics(robot, rng.uniform(lim[:, 0], lim[:, 1], (n, robot.dof))))
    outs = (np.empty((n, 8, 6)), np.empty((n, 8)), np.empty((n, 8)), np.empty((n, 8), dtype=bool),
            np.empty((n, 8), dtype=np.int8), np.empty(n, dtype=np.int64), np.empty(n, dtype=np.int8))
    elbow, ur = (elbow_stages, elbow_checks, ROWS, RQA), (parallel_stages, parallel_checks, UR_ROWS, UR_RQ2)
    if kern[1][1] == "parallel":
        runs = {"stages": lambda: _stages(*ur, T, K, False), "+ checks": lambda: _stages(*ur, T, K, True),
                "kernel": lambda: _kernel(ik_parallel_packed, T, K)}
    else:
        runs = {"stages": lambda: _stages(*elbow, T, K, False), "+ checks": lambda: _stages(*elbow, T, K, True),
                "kernel": lambda: _kernel(ik_elbow_packed, T, K)}
    runs["batch entry"] = lambda: many(T, K, *outs)
    for f in runs.values():
        f()
    best = {}
    for _ in range(5):
        for who, f in runs.items():
            t0 = time.process_time()
            f()
            best[who] = min(best.get(who, np.inf), time.process_time() - t0)
    return {who: dt / n * 1e9 for who, dt in best.items()}


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--robot", action="append", help="catalogue arm (repeatable; default puma560, ur5, offset-6r)")
    ap.add_argument("--n", type=int, default=100_000, help="poses (default 100000)")
    args = ap.parse_args(argv)
    try:
        os.sched_setaffinity(0, {min(os.sched_getaffinity(0))})
    except (AttributeError, OSError):
        pass
    for name in args.robot or ["puma560", "ur5", "offset-6r"]:
        print(name, " | ".join(f"{who} {ns:.0f} ns/pose" for who, ns in profile(name, args.n).items()),
              "| load", os.getloadavg()[0])


if __name__ == "__main__":
    main()
