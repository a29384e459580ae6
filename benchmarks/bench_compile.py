"""Generated kernels (denavit.compile) against Pinocchio and roboticstoolbox, in one run.

Run:  python benchmarks/bench_compile.py [--batch 200000] [--repeat 7] [--number 5000]
      python benchmarks/bench_compile.py --cold 3     (only the cold compile's CPU time, three fresh processes per arm)
Prints Markdown tables: single calls (µs, ratio to Pinocchio), batched throughput on one core (configurations/s),
and compile times (cold: an empty cache; warm: a new process reading the cache).  Every library is first checked
to agree with denavit on the numbers it is timed on.

Single call: one configuration, best of 3·`repeat` rounds of `number` calls, denavit and Pinocchio taking turns
within each round, each returning what a user gets:
  FK     denavit fast.fk(q) → 4×4 array; Pinocchio framesForwardKinematics + data.oMf[tool] (an SE3); and against
         Pinocchio's bare forwardKinematics(model, data, q) (joint placements only, nothing returned: issue 25's yardstick)
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
from _peers import best_time, best_times, to_pinocchio

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
        ("FK vs bare forwardKinematics", lambda: fast.fk(q), lambda: pin.forwardKinematics(model, data, q),
         lambda a, b: np.allclose(a, pin.updateFramePlacement(model, data, fid).homogeneous, atol=1e-10)),
        ("J", lambda: fast.jacobian(q), lambda: pin.computeFrameJacobian(model, data, q, fid, pin.LOCAL_WORLD_ALIGNED),
         lambda a, b: np.allclose(a, b, atol=1e-10)),
        ("RNEA", lambda: fast.rnea(q, qd, qdd), lambda: pin.rnea(model, data, q, qd, qdd),
         lambda a, b: np.allclose(a, b, atol=1e-9)),
        ("M", lambda: fast.mass_matrix(q), lambda: pin.crba(model, data, q),
         lambda a, b: np.allclose(np.triu(a), np.triu(b), atol=1e-9)),
        ("FD", lambda: fast.forward_dynamics(q, qd, tau), lambda: pin.aba(model, data, q, qd, tau),
         lambda a, b: np.allclose(a, b, atol=1e-8)),
    ]
    plain = {"FK": lambda: denavit.forward_kinematics(robot, q),
             "FK vs bare forwardKinematics": lambda: denavit.forward_kinematics(robot, q), "J": lambda: denavit.geometric_jacobian(robot, q),
             "RNEA": lambda: denavit.rnea(robot, q, qd, qdd, friction=False), "M": lambda: denavit.mass_matrix(robot, q),
             "FD": lambda: denavit.forward_dynamics(robot, q, qd, tau, friction=False)}
    rows = []
    for op, ours, peer, agree in ops:
        assert agree(ours(), peer()), f"{name} {op}: Pinocchio disagrees"
        t_ours, t_peer = best_times([ours, peer], 3 * repeat, number)  # taking turns: the ratio sees one machine
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


def ik_rows(name: str, n_targets: int):
    """Numeric IK, one call per target, 1e-9 within limits: compiled LM against roboticstoolbox's C++ ik_LM.
    Cold: no seed (denavit: mid-limits then random restarts; rtb: random); seeded: q0 = the generating q plus
    N(0, 0.1 rad) noise.  Success re-checked here with denavit's plain FK for both libraries."""
    robot = denavit.load_robot(name)
    fast = denavit.compile(robot)
    rng = np.random.default_rng(2)
    lim = robot.q_limits
    Q = rng.uniform(lim[:, 0], lim[:, 1], (n_targets, robot.dof))
    T = denavit.forward_kinematics(robot, Q)
    seeds = Q + rng.normal(0, 0.1, Q.shape)
    fast.solve_ik(T[0], rng=rng)  # compile / load the solver (both paths)
    fast.solve_ik(T[0], seeds[0], rng=rng)

    def ok(q, Tk):
        if q is None or not (np.all(q >= lim[:, 0] - 1e-12) and np.all(q <= lim[:, 1] + 1e-12)):
            return False
        Tq = denavit.forward_kinematics(robot, q)
        return np.abs(Tq[:3, 3] - Tk[:3, 3]).max() <= 1e-8 and np.abs(Tq[:3, :3] - Tk[:3, :3]).max() <= 1e-8

    def run(solve):
        times, good = [], 0
        for i in range(n_targets):
            t0 = time.perf_counter()
            q = solve(i)
            times.append(time.perf_counter() - t0)
            good += ok(q, T[i])
        return float(np.median(times)) * 1e6, float(np.mean(times)) * 1e6, good / n_targets

    rows = [(name, "denavit.compile solve_ik, cold", *run(lambda i: fast.solve_ik(T[i], rng=rng).q)),
            (name, "denavit.compile solve_ik, seeded", *run(lambda i: fast.solve_ik(T[i], seeds[i], rng=rng).q))]
    try:
        from bench_ik import _fold_limits, rtb_ets

        ets = rtb_ets(robot, name)
    except ImportError:
        ets = None
    if ets is not None:
        def rtb(i, q0=None):
            sol = ets.ik_LM(T[i], q0=q0, tol=RTB_TOL, joint_limits=True, ilimit=100, slimit=100)
            return _fold_limits(robot, sol.q) if sol.success else None

        rows += [(name, "roboticstoolbox ets().ik_LM, cold", *run(rtb)),
                 (name, "roboticstoolbox ets().ik_LM, seeded", *run(lambda i: rtb(i, seeds[i])))]
    return rows


def analytic_rows(name: str, n_targets: int):
    """All analytic solutions of one pose per call: compiled, plain, and ik-geo (Rust) when installed."""
    from bench_ik import _stats, bench_ikgeo

    robot = denavit.load_robot(name)
    fast = denavit.compile(robot)
    rng = np.random.default_rng(3)
    lim = robot.q_limits
    T = denavit.forward_kinematics(robot, rng.uniform(lim[:, 0], lim[:, 1], (n_targets, robot.dof)))
    fast.analytic_ik(T[0])
    rows = []
    for label, solve in (("denavit.compile analytic_ik", fast.analytic_ik),
                         ("denavit.analytic_ik (plain)", lambda Tk: denavit.analytic_ik(robot, Tk))):
        times, count = [], []
        for Tk in T:
            t0 = time.perf_counter()
            res = solve(Tk)
            times.append(time.perf_counter() - t0)
            count.append(res.count)
        rows.append((name, label, *_stats(times), float(np.mean(count))))
    geo = bench_ikgeo(robot, T)
    if geo is not None:
        rows.append((name, "ik-geo get_ik (Rust)", geo[1], geo[2], geo[3]))
    return rows


#: roboticstoolbox stops when E = ½ eᵀ W e < tol: 5e-19 asks for |e| ≤ 1e-9, the precision denavit is timed at.
RTB_TOL = 5e-19

COLD = """
import json, time, numpy as np
import numba  # the numba import itself is not part of the compile time
import denavit
robot = denavit.load_robot({name!r})
q = np.zeros(robot.dof)
marks = [(time.perf_counter(), time.process_time())]
fast = denavit.compile(robot)  # from the cache: the module only, no kernel loaded
marks.append((time.perf_counter(), time.process_time()))
fast.fk(q)  # the first kernel: numba's own start-up (its typing and target registries) and fk_1
marks.append((time.perf_counter(), time.process_time()))
fast.jacobian(q)  # another kernel's first call: that kernel alone
marks.append((time.perf_counter(), time.process_time()))
fast.warm()  # every other kernel, single and batch
marks.append((time.perf_counter(), time.process_time()))
print(json.dumps([[b[0] - a[0], b[1] - a[1]] for a, b in zip(marks, marks[1:])]))
"""


COLD_ONLY = """
import json, resource, time
import numba  # numba's import is not part of the compile time (numba's start-up on the first kernel call is)
import denavit
robot = denavit.load_robot({name!r})
t = time.process_time()
fast = denavit.compile(robot)
fast.warm()  # every base kernel: its single call (the built-in where it has one) and its batch form
children = resource.getrusage(resource.RUSAGE_CHILDREN)  # any process it started (none expected), counted too
print(json.dumps(time.process_time() - t + children.ru_utime + children.ru_stime))
"""


def cold_rows(name: str, runs: int):
    """CPU seconds of ``compile(robot)`` + ``warm()`` in a fresh process on an empty cache folder, ``runs`` times."""
    import json

    times = []
    for _ in range(runs):
        with tempfile.TemporaryDirectory() as cache:
            env = {**os.environ, "DENAVIT_CACHE_DIR": cache}
            times.append(json.loads(subprocess.run([sys.executable, "-c", COLD_ONLY.format(name=name)], env=env,
                                                   capture_output=True, text=True, check=True).stdout))
    return name, times


def compile_rows(name: str):
    """Two fresh processes on an empty cache folder: the first compiles (cold), the second loads.  Each stage as
    (wall, CPU) seconds: compile(), the first kernel call, a second kernel's first call, warm() of the rest."""
    import json

    with tempfile.TemporaryDirectory() as cache:
        env = {**os.environ, "DENAVIT_CACHE_DIR": cache}
        runs = [json.loads(subprocess.run([sys.executable, "-c", COLD.format(name=name)], env=env,
                                          capture_output=True, text=True, check=True).stdout) for _ in range(2)]
    cold = [sum(x[i] for x in runs[0]) for i in (0, 1)]
    return name, cold, runs[1]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--batch", type=int, default=200_000)
    ap.add_argument("--repeat", type=int, default=7)
    ap.add_argument("--number", type=int, default=5000)
    ap.add_argument("--targets", type=int, default=1000, help="IK targets per arm")
    ap.add_argument("--parts", default="single,batch,ik,analytic,compile",
                    help="comma-separated tables to run (default all): single, batch, ik, analytic, compile")
    ap.add_argument("--cold", type=int, default=0, metavar="RUNS",
                    help="only the cold compile: CPU time of compile() + warm() on an empty cache, RUNS fresh processes "
                         "per arm (CPU time: it holds on a loaded machine where wall time does not)")
    args = ap.parse_args()
    if args.cold:
        print(f"load average {os.getloadavg()[0]:.1f}\n")
        print("| robot | cold compile() + warm(), CPU [s] per run | min–max |\n|---|---|---|")
        for name in ROBOTS:
            r, times = cold_rows(name, args.cold)
            print(f"| {r} | {', '.join(f'{t:.2f}' for t in times)} | {min(times):.2f}–{max(times):.2f} |")
        return
    parts = set(args.parts.split(","))
    import numba
    import pinocchio as pin

    print(f"Python {platform.python_version()}, numpy {np.__version__}, numba {numba.__version__}, "
          f"Pinocchio {pin.__version__}, load average {os.getloadavg()[0]:.1f}\n")
    if "single" in parts:
        single_table(args.repeat, args.number)
    if "batch" in parts:
        batch_table(args.batch, args.repeat)
    if "ik" in parts:
        ik_table(args.targets)
    if "analytic" in parts:
        analytic_table(args.targets)
    if "compile" in parts:
        compile_table()


def single_table(repeat: int, number: int) -> None:
    print("| robot | op | denavit.compile [µs] | Pinocchio [µs] | ratio | plain denavit [µs] |")
    print("|---|---|---:|---:|---:|---:|")
    for name in ROBOTS:
        for r in single_rows(name, repeat, number):
            print(f"| {r[0]} | {r[1]} | {r[2]:.2f} | {r[3]:.2f} | {r[4]:.2f} | {r[5]:.1f} |")


def batch_table(batch: int, repeat: int) -> None:
    print(f"\n| robot | op | numba [configs/s] | numpy backend [configs/s] | roboticstoolbox batched C [configs/s] |")
    print("|---|---|---:|---:|---:|")
    for name in ROBOTS:
        for r in batch_rows(name, batch, max(3, repeat // 2)):
            peer = f"{r[4] / 1e6:.2f} M" if r[4] else "—"
            print(f"| {r[0]} | {r[1]} | {r[2] / 1e6:.2f} M | {r[3] / 1e6:.2f} M | {peer} |")


def ik_table(targets: int) -> None:
    print("\n| robot | IK solver | median / solve [µs] | mean / solve [µs] | success (1e-8, in limits) |")
    print("|---|---|---:|---:|---:|")
    for name in ("puma560", "ur5", "panda"):
        for r in ik_rows(name, targets):
            print(f"| {r[0]} | {r[1]} | {r[2]:.1f} | {r[3]:.1f} | {100 * r[4]:.1f} % |")


def analytic_table(targets: int) -> None:
    print("\n| robot | analytic IK, one pose per call | median [µs] | p95 [µs] | solutions / pose |")
    print("|---|---|---:|---:|---:|")
    for name in ("puma560", "ur5", "stanford"):  # elbow + spherical wrist; UR class (axes 2-4 parallel); R R P
        for r in analytic_rows(name, targets):
            print(f"| {r[0]} | {r[1]} | {r[2]:.1f} | {r[3]:.1f} | {r[4]:.2f} |")


def compile_table() -> None:
    print("\n| robot | cold: compile + every kernel [s] (CPU) | from the cache: compile() [ms] (CPU) | first kernel "
          "call [ms] (CPU) | a second kernel's first call [ms] (CPU) | every other kernel [ms] (CPU) |")
    print("|---|---:|---:|---:|---:|---:|")
    for name in ROBOTS:
        r, cold, warm = compile_rows(name)
        cells = " | ".join(f"{1e3 * w:.0f} ({1e3 * c:.0f})" for w, c in warm)
        print(f"| {r} | {cold[0]:.2f} ({cold[1]:.2f}) | {cells} |")


if __name__ == "__main__":
    main()
