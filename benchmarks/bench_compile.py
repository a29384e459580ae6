"""Generated kernels (denavit.compile) against Pinocchio and roboticstoolbox, in one run.

Run:  python benchmarks/bench_compile.py [--batch 200000] [--repeat 7] [--number 5000]
Prints Markdown tables: single calls (µs, ratio to Pinocchio), batched throughput on one core (configurations/s),
and compile times (cold: an empty cache; warm: a new process reading the cache).  Every library is first checked
to agree with denavit on the numbers it is timed on.

Single call: one configuration, best of `repeat` × `number` calls, each returning what a user gets:
  FK     denavit fast.fk(q) → 4×4 array; Pinocchio framesForwardKinematics + data.oMf[tool] (an SE3)
  J      fast.jacobian(q) (J0); Pinocchio computeFrameJacobian(..., LOCAL_WORLD_ALIGNED) (includes its FK)
  RNEA   fast.rnea(q, qd, qdd); pin.rnea      M  fast.mass_matrix(q); pin.crba (upper triangle only)
  FD     fast.forward_dynamics(q, qd, tau); pin.aba
Friction is left out (compile(robot, friction=False)) as in the peers; motor inertia is in (Pinocchio's armature).  Batch: denavit in one call on (batch, n) arrays; roboticstoolbox's batched C
`rne` on the same arrays for RNEA; Pinocchio has no batch API (a Python loop over it is shown for scale).
"""

from __future__ import annotations

import argparse
import os
import platform
import subprocess
import sys
import tempfile
import time

import numpy as np

import denavit
from _peers import best_time, to_pinocchio

ROBOTS = ("puma560", "panda")


def single_rows(name: str, repeat: int, number: int):
    import pinocchio as pin

    robot = denavit.load_robot(name)
    fast = denavit.compile(robot, friction=False)
    fast.warm()
    model, data, fid = to_pinocchio(robot)
    rng = np.random.default_rng(0)
    q, qd, qdd = (rng.uniform(-1, 1, robot.dof) for _ in range(3))
    tau = fast.rnea(q, qd, qdd)

    def pin_fk():
        pin.framesForwardKinematics(model, data, q)
        return data.oMf[fid]

    ops = [
        ("FK", lambda: fast.fk(q), pin_fk, lambda a, b: np.allclose(a, b.homogeneous, atol=1e-10)),
        ("J", lambda: fast.jacobian(q), lambda: pin.computeFrameJacobian(model, data, q, fid, pin.LOCAL_WORLD_ALIGNED),
         lambda a, b: np.allclose(a, b, atol=1e-10)),
        ("RNEA", lambda: fast.rnea(q, qd, qdd), lambda: pin.rnea(model, data, q, qd, qdd),
         lambda a, b: np.allclose(a, b, atol=1e-9)),
        ("M", lambda: fast.mass_matrix(q), lambda: pin.crba(model, data, q),
         lambda a, b: np.allclose(np.triu(a), np.triu(b), atol=1e-9)),
        ("FD", lambda: fast.forward_dynamics(q, qd, tau), lambda: pin.aba(model, data, q, qd, tau),
         lambda a, b: np.allclose(a, b, atol=1e-8)),
    ]
    plain = {"FK": lambda: denavit.forward_kinematics(robot, q), "J": lambda: denavit.geometric_jacobian(robot, q),
             "RNEA": lambda: denavit.rnea(robot, q, qd, qdd, friction=False), "M": lambda: denavit.mass_matrix(robot, q),
             "FD": lambda: denavit.forward_dynamics(robot, q, qd, tau, friction=False)}
    rows = []
    for op, ours, peer, agree in ops:
        assert agree(ours(), peer()), f"{name} {op}: Pinocchio disagrees"
        t_ours = best_time(ours, repeat, number)
        t_peer = best_time(peer, repeat, number)
        t_plain = best_time(plain[op], max(2, repeat // 2), max(100, number // 20))
        rows.append((name, op, t_ours * 1e6, t_peer * 1e6, t_ours / t_peer, t_plain * 1e6))
    return rows


def batch_rows(name: str, batch: int, repeat: int):
    robot = denavit.load_robot(name)
    fast = denavit.compile(robot, friction=False)
    fast.warm()
    numpy_fast = denavit.compile(robot, backend="numpy", friction=False)
    rng = np.random.default_rng(1)
    Q, QD, QDD = (rng.uniform(-1, 1, (batch, robot.dof)) for _ in range(3))
    TAU = fast.rnea(Q, QD, QDD)

    def rate(fn):
        best = np.inf
        for _ in range(repeat):
            t0 = time.perf_counter()
            fn()
            best = min(best, time.perf_counter() - t0)
        return batch / best

    ops = {"FK": lambda f: f.fk(Q), "J": lambda f: f.jacobian(Q), "RNEA": lambda f: f.rnea(Q, QD, QDD),
           "M": lambda f: f.mass_matrix(Q), "FD": lambda f: f.forward_dynamics(Q, QD, TAU)}
    rtb_rate = None
    try:
        import roboticstoolbox as rtb

        peer = rtb.models.DH.Puma560().nofriction(coulomb=True, viscous=True)  # = catalogue puma560
        if name == "puma560":
            assert np.allclose(peer.rne(Q[:50], QD[:50], QDD[:50]), fast.rnea(Q[:50], QD[:50], QDD[:50]), atol=1e-8)
            rtb_rate = rate(lambda: peer.rne(Q, QD, QDD))
    except ImportError:
        pass
    rows = []
    for op, fn in ops.items():
        rows.append((name, op, rate(lambda: fn(fast)), rate(lambda: fn(numpy_fast)),
                     rtb_rate if op == "RNEA" else None))
    return rows


COLD = """
import time, numpy as np
t0 = time.perf_counter()
import numba  # the numba import itself is not part of the compile time
import denavit
robot = denavit.load_robot({name!r})
t1 = time.perf_counter()
fast = denavit.compile(robot)
times = fast.warm()
print(time.perf_counter() - t1, t1 - t0)
"""


def compile_rows(name: str):
    with tempfile.TemporaryDirectory() as cache:
        env = {**os.environ, "DENAVIT_CACHE_DIR": cache}
        runs = []
        for _ in range(2):
            out = subprocess.run([sys.executable, "-c", COLD.format(name=name)], env=env, capture_output=True,
                                 text=True, check=True).stdout.split()
            runs.append((float(out[0]), float(out[1])))
    return name, runs[0][0], runs[1][0], runs[0][1]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--batch", type=int, default=200_000)
    ap.add_argument("--repeat", type=int, default=7)
    ap.add_argument("--number", type=int, default=5000)
    args = ap.parse_args()
    import numba
    import pinocchio as pin

    print(f"Python {platform.python_version()}, numpy {np.__version__}, numba {numba.__version__}, "
          f"Pinocchio {pin.__version__}, load average {os.getloadavg()[0]:.1f}\n")
    print("| robot | op | denavit.compile [µs] | Pinocchio [µs] | ratio | plain denavit [µs] |")
    print("|---|---|---:|---:|---:|---:|")
    for name in ROBOTS:
        for r in single_rows(name, args.repeat, args.number):
            print(f"| {r[0]} | {r[1]} | {r[2]:.2f} | {r[3]:.2f} | {r[4]:.2f} | {r[5]:.1f} |")
    print(f"\n| robot | op | numba [configs/s] | numpy backend [configs/s] | roboticstoolbox batched C [configs/s] |")
    print("|---|---|---:|---:|---:|")
    for name in ROBOTS:
        for r in batch_rows(name, args.batch, max(3, args.repeat // 2)):
            peer = f"{r[4] / 1e6:.2f} M" if r[4] else "—"
            print(f"| {r[0]} | {r[1]} | {r[2] / 1e6:.2f} M | {r[3] / 1e6:.2f} M | {peer} |")
    print("\n| robot | compile, empty cache [s] | compile, from the cache [s] | numba + denavit import [s] |")
    print("|---|---:|---:|---:|")
    for name in ROBOTS:
        r = compile_rows(name)
        print(f"| {r[0]} | {r[1]:.2f} | {r[2]:.3f} | {r[3]:.2f} |")


if __name__ == "__main__":
    main()
