"""Benchmark of inverse kinematics: denavit (numeric LM batched, analytic all-solutions batched) against peers.

Run:  python benchmarks/bench_ik.py [--n 10000] [--peer-n 500] [--robot puma560] [--markdown docs/ik_bench.md]

Targets: FK of random joint values uniformly within the joint limits (seeded).  Success = the returned q is
within the joint limits and reproduces the target to 1e-6 m and 1e-6 rad, checked with denavit's FK (the same
check for every library).  Times are wall-clock per solve: for denavit the batch time divided by the number of
targets (median and p95 over repeated batches of 1,000); for the peers one call per target.
Peers (skipped when not importable): roboticstoolbox-python ``ets().ik_LM`` (C++), IKPy, ik-geo.
"""

from __future__ import annotations

import argparse
import platform
import time

import numpy as np

import denavit
from denavit import analytic_ik, forward_kinematics, load_robot, solve_ik

TOL = 1e-6


def _targets(robot, n, seed=0):
    rng = np.random.default_rng(seed)
    lim = robot.q_limits
    q = rng.uniform(lim[:, 0], lim[:, 1], (n, robot.dof))
    return q, forward_kinematics(robot, q)


def _ok(robot, q, T):
    q = np.asarray(q, dtype=float)
    if q.shape[-1] != robot.dof or not np.all(np.isfinite(q)):
        return False
    lim = robot.q_limits
    if np.any(q < lim[:, 0] - 1e-9) or np.any(q > lim[:, 1] + 1e-9):
        return False
    F = forward_kinematics(robot, q)
    R = F[:3, :3].T @ T[:3, :3]
    v = np.array([R[2, 1] - R[1, 2], R[0, 2] - R[2, 0], R[1, 0] - R[0, 1]])
    ang = np.arctan2(np.linalg.norm(v) / 2, (np.trace(R) - 1) / 2)
    return np.linalg.norm(F[:3, 3] - T[:3, 3]) <= TOL and ang <= TOL


def _stats(times):
    t = np.asarray(times) * 1e6
    return float(np.median(t)), float(np.percentile(t, 95))


def bench_denavit_numeric(robot, T, chunk=1000):
    rng = np.random.default_rng(1)
    per, qs = [], []
    for i in range(0, len(T), chunk):
        t0 = time.perf_counter()
        res = solve_ik(robot, T[i:i + chunk], rng=rng)
        per.append((time.perf_counter() - t0) / len(T[i:i + chunk]))
        qs.append(res.q)
    q = np.concatenate(qs)
    succ = np.mean([_ok(robot, a, b) for a, b in zip(q, T)])
    return succ, *_stats(per)


def bench_denavit_analytic(robot, q_true, T, chunk=1000):
    per, found = [], []
    for i in range(0, len(T), chunk):
        t0 = time.perf_counter()
        res = analytic_ik(robot, T[i:i + chunk])
        per.append((time.perf_counter() - t0) / len(T[i:i + chunk]))
        rev = np.array([t.value == "revolute" for t in robot.joint_types])
        d = res.solutions - q_true[i:i + chunk, None]
        d = np.where(rev, np.abs((d + np.pi) % (2 * np.pi) - np.pi), np.abs(d))
        found.append(np.nanmin(np.where(res.valid, d.max(axis=-1), np.inf), axis=1) < 1e-6)
    return float(np.mean(np.concatenate(found))), *_stats(per)


def bench_rtb(robot, name, T):
    try:
        import roboticstoolbox as rtb
    except ImportError:
        return None
    if robot.convention.value != "standard" or any(not l.is_joint for l in robot.links):
        return None
    links = []
    for link in robot.links:  # the same DH table, so both libraries solve the very same arm
        kw = dict(a=link.a, alpha=link.alpha, qlim=list(link.q_limits) if link.q_limits else None)
        if link.joint.value == "revolute":
            links.append(rtb.RevoluteDH(d=link.d, offset=link.theta, **kw))
        else:
            links.append(rtb.PrismaticDH(theta=link.theta, offset=link.d, **kw))
    ets = rtb.DHRobot(links, name=name).ets()
    times, ok = [], []
    for Tk in T:
        t0 = time.perf_counter()
        sol = ets.ik_LM(Tk, tol=1e-12, joint_limits=True, ilimit=100, slimit=100)
        times.append(time.perf_counter() - t0)
        ok.append(bool(sol.success) and _ok(robot, sol.q, Tk))
    return float(np.mean(ok)), *_stats(times)


def bench_ikpy(robot, T):
    try:
        import ikpy.chain  # noqa: F401
    except ImportError:
        return None
    return None  # IKPy needs a URDF chain; not wired up (see docs/ik.md)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=10000, help="targets for denavit (default 10000)")
    ap.add_argument("--peer-n", type=int, default=500, help="targets for the per-call peers (default 500)")
    ap.add_argument("--robot", action="append", help="catalogue arm (repeatable; default puma560, ur5, stanford)")
    ap.add_argument("--markdown", help="also write the table to this Markdown file")
    args = ap.parse_args(argv)
    rows = []
    for name in args.robot or ["puma560", "ur5", "stanford"]:
        robot = load_robot(name)
        q, T = _targets(robot, args.n)
        s, med, p95 = bench_denavit_numeric(robot, T)
        rows.append((name, "denavit solve_ik (LM, batched)", args.n, s, med, p95))
        s, med, p95 = bench_denavit_analytic(robot, q, T)
        rows.append((name, "denavit analytic_ik (all solutions, batched)", args.n, s, med, p95))
        r = bench_rtb(robot, name, T[: args.peer_n])
        if r is not None:
            rows.append((name, "roboticstoolbox ets().ik_LM (per call)", args.peer_n, *r))
        for row in rows[-3:]:
            print(f"{row[0]:10s} {row[1]:48s} n={row[2]:6d} success {row[3]:.4f}  median {row[4]:8.1f} us  "
                  f"p95 {row[5]:8.1f} us")
    table = ["| arm | solver | targets | success (in limits, 1e-6) | median / solve [µs] | p95 / solve [µs] |",
             "|---|---|---:|---:|---:|---:|"]
    table += [f"| {a} | {b} | {c} | {d:.4f} | {e:.1f} | {f:.1f} |" for a, b, c, d, e, f in rows]
    head = f"Measured {time.strftime('%Y-%m-%d')} on {platform.machine()} / Python {platform.python_version()} " \
           f"/ numpy {np.__version__} / denavit {denavit.__version__}."
    text = head + "\n\n" + "\n".join(table) + "\n"
    print(text)
    if args.markdown:
        with open(args.markdown, "w", encoding="utf-8") as fh:
            fh.write(text)


if __name__ == "__main__":
    main()
