"""Workspace and reachability at scale (denavit.scale): throughput, memory and the volume interval vs samples.

Run:  python benchmarks/bench_workspace.py [--robot puma560] [--samples 1e5,1e6,1e7] [--scheduler threads]
              [--workers 2] [--cluster [--repeat 5]] [--reach 0.05x100] [--kernel-ratio 1e8 [--pin 1]
              [--rounds 2] [--refine 0] [--strata-ab]] [--markdown FILE]
``--kernel-ratio N`` compares, in one process, the bare compiled position kernel (``compile(robot).position`` on
a batch of 65 536 configurations, one thread) with the whole pipeline (``occupancy`` of N samples on the threads
scheduler: random numbers, FK, cells, counts, merge, volume), both per CPU-second (so per core, whatever else
the machine runs) and per wall second; ``--pin CORE`` pins the process to one core first (the pipeline then
runs on one thread: its per-core rate without the other thread's cache traffic), ``--rounds R`` interleaves
R kernel/pipeline pairs (best of each), ``--refine K`` sets the pipeline's boundary refinement (0: off) and
``--strata-ab`` adds, in each round, the pipeline drawn without strata (``_strata.MAX_STRATA = 1``: the plain
stream's order, as before the strata) to compare the two in one process.
Each row is one run in this process: wall time, samples/s, peak resident memory so far (ru_maxrss, grows
only) of this process and of the largest finished worker process, the peak PSS of the whole process tree
during the run (sampled every 0.5 s; shared library pages split between the processes), the 1-minute load
average at the end of the run, the refinement (cells refined × sub-cells per side) and the reported volume
with its interval.  ``--cluster`` also runs the largest sample count on a local process pool and on a local
dask.distributed cluster (2 worker processes; Dask's defaults, then scale.LOCAL_CLUSTER_CONFIG; one cluster at
a time), ``--repeat`` times each, and checks the counts are identical.
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


class TreeMemory:
    """Largest proportional set size (PSS: shared pages split between the processes sharing them) of this
    process and all its descendants, sampled every ``every`` seconds in a thread (needs psutil; else nan)."""

    def __init__(self, every: float = 0.5) -> None:
        import threading

        self.every, self.peak, self._stop = every, float("nan"), threading.Event()
        self._thread = threading.Thread(target=self._run, daemon=True)

    def _run(self) -> None:
        try:
            import psutil
        except ImportError:
            return
        me = psutil.Process()
        self.peak = 0.0
        while True:
            stop = self._stop.is_set()  # one last sample after the run
            total = 0
            for p in [me] + me.children(recursive=True):
                try:
                    total += p.memory_full_info().pss
                except (psutil.Error, OSError):
                    pass
            self.peak = max(self.peak, total / 2**20)
            if stop:
                return
            self._stop.wait(self.every)

    def __enter__(self):
        self._thread.start()
        return self

    def __exit__(self, *exc) -> None:
        self._stop.set()
        self._thread.join()


def run_samples(robot, counts, scheduler, workers) -> list[str]:
    rows = ["| samples | wall [s] | samples/s | peak RSS [MB] driver / largest worker | peak PSS of all "
            "processes [MB] | load | refined cells × k | cell edge [m] | coverage | volume [m³] | interval [m³] "
            "| width [m³] |",
            "|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---|---:|"]
    for n in counts:
        t0 = time.perf_counter()
        with TreeMemory() as tree:
            ws = occupancy(robot, n, seed=1, scheduler=scheduler, workers=workers, progress=None)
        dt = time.perf_counter() - t0
        e, r = ws.estimate, ws.refinement
        kids = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss / 1024
        ref = "–" if r is None else f"{r.cells.size} × {r.factor}"
        rows.append(f"| {n:.0e} | {dt:.1f} | {n / dt:.3g} | {peak_mb():.0f} / {kids:.0f} | {tree.peak:.0f} | "
                    f"{os.getloadavg()[0]:.1f} | "
                    f"{ref} | {e.resolution:.3g} | {e.coverage:.4f} | {e.value:.4g} | [{e.low:.4g}, {e.high:.4g}] | "
                    f"{e.high - e.low:.3g} |")
        print(rows[-1], flush=True)
    return rows


def _cpu() -> float:
    r = resource.getrusage(resource.RUSAGE_SELF)
    return r.ru_utime + r.ru_stime


def _children_cpu() -> float:
    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime


def run_cluster(robot, n, repeat: int = 1) -> list[str]:
    """A local process pool of 2 against a LocalCluster of 2 single-threaded worker processes, one cluster at a
    time (an idle cluster's workers and scheduler would take CPU from every other measurement): first with
    Dask's default settings, then with ``scale.LOCAL_CLUSTER_CONFIG`` (what ``scheduler="dask"`` starts).  For
    each, pool and cluster runs alternate ``repeat`` times (same seed); medians of wall time and of CPU time
    (all processes of the setup: the driver, which also hosts the Dask scheduler, and the workers).  The
    cluster is started before the timings; each pool run starts its pool (spawn and kernel load included)."""
    import dask
    from distributed import Client, LocalCluster

    from denavit.scale import LOCAL_CLUSTER_CONFIG

    lines = [f"2 workers, {n:.0e} samples, medians of {repeat} alternating runs, one cluster at a time", "",
             "| cluster settings | pool wall [s] | cluster wall [s] | wall ratio | pool CPU ns/sample | cluster CPU "
             "ns/sample | CPU ratio | load | identical counts |",
             "|---|---:|---:|---:|---:|---:|---:|---|---|"]
    kw = dict(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None)
    for name, config in (("Dask defaults", {}), ("LOCAL_CLUSTER_CONFIG", LOCAL_CLUSTER_CONFIG)):
        wall, cpu, same, load = {"pool": [], "cluster": []}, {"pool": [], "cluster": []}, True, []
        with dask.config.set(config):
            cluster = LocalCluster(**kw)
        with cluster, Client(cluster) as client:
            occupancy(robot, 4 * 65536, seed=1, scheduler=client)  # warm the workers (kernel load)
            for _ in range(repeat):
                m0, k0, t0 = _cpu(), _children_cpu(), time.perf_counter()
                ref = occupancy(robot, n, seed=1, scheduler="processes", workers=2)
                wall["pool"].append(time.perf_counter() - t0)
                cpu["pool"].append(_cpu() - m0 + _children_cpu() - k0)
                w0, m0, t0 = sum(client.run(_cpu).values()), _cpu(), time.perf_counter()
                ws = occupancy(robot, n, seed=1, scheduler=client)
                wall["cluster"].append(time.perf_counter() - t0)
                cpu["cluster"].append(_cpu() - m0 + sum(client.run(_cpu).values()) - w0)
                same &= bool(np.array_equal(ws.counts, ref.counts))
                load.append(os.getloadavg()[0])
        w = {k: float(np.median(v)) for k, v in wall.items()}
        c = {k: float(np.median(v)) / n * 1e9 for k, v in cpu.items()}
        lines.append(f"| {name} | {w['pool']:.2f} | {w['cluster']:.2f} | {w['pool'] / w['cluster']:.2f} | "
                     f"{c['pool']:.0f} | {c['cluster']:.0f} | {c['pool'] / c['cluster']:.2f} | "
                     f"{min(load):.1f}–{max(load):.1f} | {same} |")
        print(lines[-1], flush=True)
    return lines


def kernel_ratio(robot, n: int, workers, rounds: int = 1, refine: int | None = None, ab: bool = False) -> list[str]:
    """Bare position kernel vs the pipeline, same process: throughput per CPU-second (per core, whatever else
    the machine runs) and per wall second, ``rounds`` interleaved kernel/pipeline pairs (best of each).  The
    kernel: ``compile(robot).position`` on one block of 65 536 configurations within the limits, 256 calls a
    round (about 0.2 CPU-s), best of 3 rounds, one thread."""
    from denavit.scale import CompiledPositionFK, sampling_limits

    c = denavit.compile(robot, kernels=["position"])
    lim = sampling_limits(robot)
    Q = lim[:, 0] + np.random.default_rng(0).random((65536, robot.dof)) * (lim[:, 1] - lim[:, 0])
    c.position(Q)
    occupancy(robot, 8 * 65536, seed=2, scheduler="threads", workers=workers, fk=CompiledPositionFK(robot))  # warm
    rows = ["| what | samples | wall [s] | CPU [s] | samples/s (wall) | samples per CPU-second (per core) | load |",
            "|---|---:|---:|---:|---:|---:|---:|"]
    from denavit.scale import _strata

    figures, strata = {}, _strata.MAX_STRATA
    for what in ("kernel",) + (("pipeline", "unstratified", "kernel") if ab else ("pipeline", "kernel")) * rounds:
        best = None
        for _ in range(3 if what == "kernel" else 1):
            t, cpu = time.perf_counter(), time.process_time()
            if what == "kernel":
                m = 256 * len(Q)
                for _ in range(256):
                    c.position(Q)
            else:
                m = n
                _strata.MAX_STRATA = 1 if what == "unstratified" else strata
                try:
                    occupancy(robot, n, seed=1, scheduler="threads", workers=workers, progress=None, refine=refine)
                finally:
                    _strata.MAX_STRATA = strata
            wall, cpu = time.perf_counter() - t, time.process_time() - cpu
            if best is None or cpu < best[1]:
                best = (wall, cpu)
        wall, cpu = best
        figures.setdefault(what, []).append(m / cpu)
        rows.append(f"| {what} | {m:.3g} | {wall:.2f} | {cpu:.2f} | {m / wall:.3g} | {m / cpu:.3g} | "
                    f"{os.getloadavg()[0]:.1f} |")
        print(rows[-1], flush=True)
    k, p = max(figures["kernel"]), max(figures["pipeline"])
    how = "refinement automatic" if refine is None else "no refinement" if refine == 0 else f"refine {refine}"
    rows.append(f"\npipeline ÷ kernel per core: {p / k:.2f} ({robot.name}, {workers or os.cpu_count()} threads, {how})")
    if ab:
        u = max(figures["unstratified"])
        rows.append(f"unstratified pipeline ÷ kernel per core: {u / k:.2f}; stratified ÷ unstratified: {p / u:.2f}")
    print("\n".join(rows[-2 if ab else -1:]), flush=True)
    return rows


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
    ap.add_argument("--repeat", type=int, default=1, help="cluster comparison: runs of each, alternating (medians)")
    ap.add_argument("--reach", help="e.g. 0.05x100: resolution [m] x orientations")
    ap.add_argument("--kernel-ratio", type=float, help="pipeline of this many samples vs the bare kernel")
    ap.add_argument("--pin", type=int, help="pin the process to this core (and run one worker thread)")
    ap.add_argument("--rounds", type=int, default=1, help="--kernel-ratio: interleaved kernel/pipeline pairs")
    ap.add_argument("--refine", type=int, help="--kernel-ratio: the pipeline's refine (default automatic; 0 off)")
    ap.add_argument("--strata-ab", action="store_true", help="--kernel-ratio: also the pipeline without strata")
    ap.add_argument("--markdown")
    a = ap.parse_args()
    robot = denavit.load_robot(a.robot)
    if a.pin is not None:
        os.sched_setaffinity(0, {a.pin})
        a.workers = 1
    lines = [f"{a.robot}, scheduler {a.scheduler}, workers {a.workers or os.cpu_count()}"
             f"{'' if a.pin is None else f', pinned to core {a.pin}'}, load average {os.getloadavg()[0]:.2f}", ""]
    if a.kernel_ratio:
        lines += kernel_ratio(robot, int(a.kernel_ratio), a.workers, a.rounds, a.refine, a.strata_ab)
    lines += run_samples(robot, [int(float(x)) for x in a.samples.split(",") if x], a.scheduler, a.workers)
    if a.cluster:
        more = run_cluster(robot, int(float(a.samples.split(",")[-1])), a.repeat)
        print("\n".join(more), flush=True)
        lines += more
    if a.reach:
        lines.append(run_reach(robot, a.reach, a.scheduler, a.workers))
        print(lines[-1], flush=True)
    if a.markdown:
        with open(a.markdown, "w") as fh:
            fh.write("\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
