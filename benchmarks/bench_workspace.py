"""Workspace and reachability at scale (denavit.scale): throughput, memory and the volume interval vs samples.

Run:  python benchmarks/bench_workspace.py [--robot puma560] [--samples 1e5,1e6,1e7] [--scheduler threads]
              [--workers 2] [--reach 0.05x100] [--markdown FILE]
Each row is one run in this process: wall time, samples/s, peak resident memory of the process so far
(ru_maxrss, grows only), and the reported volume with its interval.  ``--cluster`` also runs the largest
sample count on a local dask.distributed cluster (2 worker processes) and checks the counts are identical.
"""

from __future__ import annotations

import argparse
import os
import resource
import time

import numpy as np

import denavit
from denavit.scale import occupancy, reachability


def peak_mb() -> float:
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024


def run_samples(robot, counts, scheduler, workers) -> list[str]:
    rows = ["| samples | wall [s] | samples/s | peak RSS [MB] | cell edge [m] | coverage | volume [m³] "
            "| interval [m³] |",
            "|---:|---:|---:|---:|---:|---:|---:|---|"]
    for n in counts:
        t0 = time.perf_counter()
        ws = occupancy(robot, n, seed=1, scheduler=scheduler, workers=workers, progress=None)
        dt = time.perf_counter() - t0
        e = ws.estimate
        rows.append(f"| {n:.0e} | {dt:.1f} | {n / dt:.3g} | {peak_mb():.0f} | {e.resolution:.3g} | "
                    f"{e.coverage:.4f} | {e.value:.4g} | [{e.low:.4g}, {e.high:.4g}] |")
        print(rows[-1], flush=True)
    return rows


def run_cluster(robot, n, trim: bool) -> str:
    import dask
    from distributed import Client, LocalCluster

    if trim:  # dask's nanny sets 64 kB by default: FK's large temporaries are then returned and re-faulted
        dask.config.set({"distributed.nanny.pre-spawn-environ.MALLOC_TRIM_THRESHOLD_": 2**30})

    t0 = time.perf_counter()
    ref = occupancy(robot, n, seed=1, scheduler="processes", workers=2)
    t_ref = time.perf_counter() - t0
    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as cluster, \
            Client(cluster) as client:
        t0 = time.perf_counter()
        ws = occupancy(robot, n, seed=1, scheduler=client)
        dt = time.perf_counter() - t0
    same = np.array_equal(ws.counts, ref.counts)
    note = ", MALLOC_TRIM_THRESHOLD_=1 GiB" if trim else ""
    return (f"LocalCluster(2 processes{note}): {n:.0e} samples in {dt:.1f} s ({n / dt:.3g}/s); local process "
            f"pool (2): {t_ref:.1f} s ({n / t_ref:.3g}/s); identical counts: {same}")


def run_reach(robot, spec: str, scheduler, workers) -> str:
    h, k = spec.split("x")
    t0 = time.perf_counter()
    m = reachability(robot, float(h), int(k), scheduler=scheduler, workers=workers, progress=None)
    dt = time.perf_counter() - t0
    s = m.summary()
    return (f"reachability {robot.name} {float(h):g} m × {k} orientations ({s['method']} IK): {dt:.0f} s, "
            f"{s['voxels_tested']} voxels tested, {s['voxels_reached']} reached, peak RSS {peak_mb():.0f} MB, "
            f"reachable {s['reachable_volume']:.3g} m³, ≥50 % of orientations {s['dexterous_volume']:.3g} m³")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--robot", default="puma560")
    ap.add_argument("--samples", default="1e5,1e6,1e7")
    ap.add_argument("--scheduler", default="threads")
    ap.add_argument("--workers", type=int)
    ap.add_argument("--cluster", action="store_true")
    ap.add_argument("--trim", action="store_true", help="raise the workers' MALLOC_TRIM_THRESHOLD_ to 1 GiB")
    ap.add_argument("--reach", help="e.g. 0.05x100: resolution [m] x orientations")
    ap.add_argument("--markdown")
    a = ap.parse_args()
    robot = denavit.load_robot(a.robot)
    lines = [f"{a.robot}, scheduler {a.scheduler}, workers {a.workers or os.cpu_count()}, "
             f"load average {os.getloadavg()[0]:.2f}", ""]
    lines += run_samples(robot, [int(float(x)) for x in a.samples.split(",")], a.scheduler, a.workers)
    if a.cluster:
        lines.append(run_cluster(robot, int(float(a.samples.split(",")[-1])), a.trim))
        print(lines[-1], flush=True)
    if a.reach:
        lines.append(run_reach(robot, a.reach, a.scheduler, a.workers))
        print(lines[-1], flush=True)
    if a.markdown:
        with open(a.markdown, "w") as fh:
            fh.write("\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
