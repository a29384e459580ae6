"""The streaming workspace: voxel occupancy counts of any number of samples, in bounded memory."""

from __future__ import annotations

import dataclasses
import os
from dataclasses import dataclass, field
from typing import Any, Callable

import numpy as np

from .._constants import MAX_SAMPLES
from ..errors import ModelError
from ..model import DHRobot
from ._refine import Refinement, check_factor, pilot_blocks, plan_refinement, refined_levels, refinement
from ._sampler import (BLOCK, CompiledPositionFK, Grid, Job, block_table, default_fk, make_job, positions_block,
                       run_blocks, run_task)
from ._strata import layout
from ._sink import NoSink, open_sink
from ._schedule import POOLS, Progress, resolve_auto, run
from ._volume import MIN_COVERAGE, VolumeEstimate, estimate_volume, level_stats

__all__ = ["Occupancy", "occupancy", "sample_positions", "load_occupancy", "MAX_SAMPLES", "DEFAULT_CHUNK", "SINK_CHUNK",
           "CLUSTER_CHUNK", "MAX_CHUNK", "TAIL_SHARE", "new_seed"]

#: Default samples per task (4 random blocks; about 60 MB of scratch per worker with the default FK).
DEFAULT_CHUNK = 4 * BLOCK
#: Default samples per task on a dask.distributed cluster (fewer, larger tasks: less scheduling per sample).
CLUSTER_CHUNK = 16 * BLOCK
#: Default samples per task of fused tasks counting into this process's accumulators (threads, synchronous):
#: they hand no counts over and their scratch does not grow with them, so fewer, larger tasks (less Python per
#: sample: ~0.15 ms a task).
SINK_CHUNK = 16 * BLOCK
#: Most samples per task.
MAX_CHUNK = 64 * BLOCK
#: A task takes at most 1/TAIL_SHARE of the blocks left (tasks shrink towards the end of a run or a pilot).
TAIL_SHARE = 8


def new_seed() -> int:
    """A fresh 63-bit seed (reported with the results so the run can be repeated)."""
    return int(np.random.SeedSequence().generate_state(2, np.uint64)[0] >> np.uint64(1))


@dataclass(frozen=True)
class Occupancy:
    """Sample counts per cell of the reach box, and the figures derived from them (world frame, metres).

    Attributes
    ----------
    counts : ndarray of uint64, shape (side,) * dim
        Samples per cell at the finest edge ``grid.resolution``; cell index i ↔ coordinates lo + h·[i, i+1)
        along ``grid.basis`` from ``grid.centre``.
    grid : Grid
    samples, seed : int
    bounds_min, bounds_max : ndarray (3,)
        Axis-aligned bounds of the samples [m].
    reach : float
        Largest distance of a sample from the base origin [m].
    estimate : VolumeEstimate
        Narrowest-interval volume (area when ``planar``) over the grid levels and the refined levels.
    levels : list of VolumeEstimate
        The estimate at each level (finest first; refined levels, whose cells are finer than ``counts``'s,
        come first).
    refinement : Refinement or None
        The cells of ``counts`` that also carry sub-cell counts (see :mod:`denavit.scale._refine`).
    fine : ndarray of uint32 (uint64 past 2³² samples after the pilot), or None
        Shape (len(refinement.cells), factor**dim).
        Sub-cell counts of the refined cells (row-major sub-cells; from the samples after the pilot).
    """

    counts: np.ndarray
    grid: Grid
    samples: int
    seed: int
    bounds_min: np.ndarray
    bounds_max: np.ndarray
    reach: float
    estimate: VolumeEstimate
    levels: list = field(default_factory=list)
    refinement: Refinement | None = None
    fine: np.ndarray | None = None

    @property
    def planar(self) -> bool:
        return self.grid.dim == 2

    @property
    def extent(self) -> np.ndarray:
        return self.bounds_max - self.bounds_min

    def occupied_centres(self) -> np.ndarray:
        """World coordinates (k, 3) of the centres of the occupied cells at the finest edge."""
        return self.grid.cell_centres(np.argwhere(self.counts > 0))

    def summary(self) -> dict:
        """The figures as plain data (the keys of ``workspace --json``)."""
        e = self.estimate
        size = {"volume": 0.0 if self.planar else e.value, "area": e.value if self.planar else 0.0}
        return {"samples": self.samples, "seed": self.seed, "resolution": e.resolution,
                "bounds_min": self.bounds_min.tolist(), "bounds_max": self.bounds_max.tolist(),
                "extent": self.extent.tolist(), "reach": self.reach, "voxels": e.occupied,
                "planar": self.planar, **size, "interval": [e.low, e.high], "interior_voxels": e.interior,
                "unseen_voxels": e.unseen, "coverage": e.coverage, "finest_resolution": self.grid.resolution,
                "refine": 0 if self.refinement is None else self.refinement.factor,
                "refined_cells": 0 if self.refinement is None else int(self.refinement.cells.size)}

    def save(self, path) -> None:
        """Write the counts and grid to a ``.npz`` file (read back with :func:`load_occupancy`)."""
        g, e = self.grid, self.estimate
        with open(path, "wb") as fh:  # a file object: numpy adds no '.npz' to the name
            np.savez_compressed(fh, counts=self.counts, centre=g.centre, basis=g.basis,
                            resolution=g.resolution, side=g.side, levels=g.levels, samples=self.samples,
                            seed=np.array(str(self.seed)), bounds_min=self.bounds_min, bounds_max=self.bounds_max,
                            reach=self.reach, estimate=np.array([e.value, e.low, e.high, e.resolution]),
                            **self._refined_arrays())

    def _refined_arrays(self) -> dict:
        r = self.refinement
        if r is None:
            return {}
        return {"refined_cells": r.cells, "refine_factor": r.factor, "pilot_blocks": r.pilot_blocks,
                "fine_counts": self.fine}


def load_occupancy(path) -> Occupancy:
    """An :class:`Occupancy` saved by :meth:`Occupancy.save` (plain arrays; no pickle)."""
    with np.load(path, allow_pickle=False) as z:
        grid = Grid(z["centre"], z["basis"], float(z["resolution"]), int(z["side"]), int(z["levels"]))
        counts = z["counts"]
        ref = fine = None
        if "refined_cells" in z.files:
            cells = z["refined_cells"].astype(np.int64)
            ref = refinement(cells, int(z["refine_factor"]), int(z["pilot_blocks"]))
            fine = z["fine_counts"]
        best, levels = _estimate(counts, grid, ref, fine)
        return Occupancy(counts, grid, int(z["samples"]), int(str(z["seed"])), z["bounds_min"], z["bounds_max"],
                         float(z["reach"]), best, levels, ref, fine)


def _estimate(counts: np.ndarray, grid: Grid, ref: Refinement | None, fine) -> tuple[VolumeEstimate, list]:
    """The narrowest trusted interval over the grid's levels and, with a refinement, its finer levels."""
    stats = level_stats(counts, mask=ref is not None)  # the finest level's, once
    best, levels = estimate_volume(counts, grid.resolution, grid.levels, stats=stats)
    if ref is None:
        return best, levels
    levels = refined_levels(counts, grid.resolution, ref, fine, stats=stats) + levels
    trusted = [e for e in levels if e.coverage >= MIN_COVERAGE] or [best]
    return min(trusted, key=lambda e: (e.high - e.low, -e.resolution)), levels


def _tasks(blocks: int, chunk: int, start: int = 0):
    """(first block, blocks) of each task from block ``start`` to ``blocks``: ``chunk`` // BLOCK blocks each,
    fewer towards the end (at most 1/TAIL_SHARE of what is left), so workers finish together before a barrier
    or the end of the run.  Results do not depend on the split."""
    most = max(1, chunk // BLOCK)
    first = start
    while first < blocks:
        per = min(most, max(1, -(-(blocks - first) // TAIL_SHARE)))
        yield first, per
        first += per


def _where(scheduler: Any, samples: int, fk: Callable | None, robot: DHRobot) -> Any:
    """``"auto"``: threads when the tasks run the fused kernel (the default FK from COMPILED_FROM samples with
    numba: no GIL held, no counts handed over), else :func:`resolve_auto`'s choice."""
    if isinstance(scheduler, str) and scheduler == "auto" and fk is None and (
            type(default_fk(robot, samples)) is CompiledPositionFK):
        return "threads"
    return resolve_auto(scheduler, samples)


def _sink_for(job: Job, counts: np.ndarray, scheduler: Any, workers: int | None, pilot: int):
    """The run's accumulators in this process when its tasks are fused and run here (threads, synchronous)."""
    if job.fused and isinstance(scheduler, str) and scheduler in ("threads", "synchronous"):
        return open_sink(counts, workers or os.cpu_count() or 1, pilot > 0)
    return NoSink()


def _check_sizes(samples: int, chunk: int) -> None:
    if isinstance(samples, bool) or int(samples) != samples or not 1 <= samples <= MAX_SAMPLES:
        raise ModelError(f"samples must be a whole number from 1 to {MAX_SAMPLES:.0e}, got {samples}")
    if isinstance(chunk, bool) or int(chunk) != chunk or not BLOCK <= chunk <= MAX_CHUNK:
        raise ModelError(f"chunk must be a whole number of samples from {BLOCK} to {MAX_CHUNK}, got {chunk}")


def occupancy(robot: DHRobot, samples: int = 1_000_000, resolution: float | None = None, seed: int | None = None,
              *, scheduler: Any = "auto", workers: int | None = None, chunk: int | None = None,
              fk: Callable | None = None, progress: bool | None = False, refine: int | None = None) -> Occupancy:
    """Stream ``samples`` uniform joint configurations through FK into voxel counts; volume with an interval.

    Parameters
    ----------
    robot : DHRobot
    samples : int
        Configurations, uniform inside the joint limits (unlimited revolute joints: [−π, π]); 1 … 10¹⁰.
    resolution : float, optional
        Cell edge [m].  Default: the reach box / 256 (3-D) or / 2048 (planar), and coarser levels ×2, ×4 …
        from which the narrowest volume interval is reported.  Given: that edge only.
    seed : int, optional
        Seed of the counter-based random stream and of the strata's counts (:mod:`denavit.scale._strata`);
        ``None`` draws one (returned in the result).
    scheduler : {"auto", "threads", "processes", "synchronous"}, str address or distributed.Client
        Where the tasks run; ``"auto"``: threads when the tasks run the fused kernel (the default FK from
        COMPILED_FROM samples with numba), else processes from AUTO_PROCESSES_FROM samples on, threads below;
        ``"tcp://host:8786"`` connects to a dask.distributed scheduler.
    workers : int, optional
        Local pool size (default: the CPU count).
    chunk : int, optional
        Samples per task (rounded down to whole blocks of 65 536); default SINK_CHUNK for fused tasks on
        threads or in this process, DEFAULT_CHUNK on other local pools, CLUSTER_CHUNK on a cluster.  Results
        do not depend on it.
    fk : callable, optional
        Joint values (m, n) → end-effector origins (m, 3) or poses (m, 4, 4); default
        :func:`default_fk`: the compiled position kernel (``denavit.compile``) for runs of at least
        COMPILED_FROM samples when numba is installed, else :class:`PositionFK` (``denavit.forward_kinematics``).
    progress : bool or None
        Progress line with ETA on stderr (``None``: when stderr is a terminal).
    refine : {None, 0, 2, 4, 8}
        Sub-cells per side of the boundary cells (see :mod:`denavit.scale._refine`): the first 1/8 of the
        samples (the pilot, a sweep of its own: :mod:`denavit.scale._strata`) fix which cells of the finest grid
        are refined, the later samples also count
        those cells' sub-cells, and the interval is also computed at the sub-cell edges.  ``None`` (default):
        when the pilot alone fills the finest grid to coverage REFINE_COVERAGE and no ``resolution`` is given,
        with the largest factor whose sub-cells fit REFINE_CELLS; 0: never; 2, 4, 8: always (lowered to fit).

    Returns
    -------
    Occupancy

    Examples
    --------
    >>> import denavit
    >>> from denavit.scale import occupancy
    >>> ws = occupancy(denavit.load_robot("planar2r"), 200_000, seed=1, scheduler="synchronous")
    >>> ws.planar, ws.estimate.low <= 3.1416 * 2.0**2 <= ws.estimate.high
    (True, True)
    """
    _check_sizes(samples, DEFAULT_CHUNK if chunk is None else chunk)
    refine = check_factor(refine)
    scheduler = _where(scheduler, samples, fk, robot)
    seed = new_seed() if seed is None else int(seed)
    if seed < 0:
        raise ModelError(f"seed must be a whole number >= 0, got {seed}")
    job = make_job(robot, int(samples), resolution, seed, fk)
    g = job.grid
    counts = np.zeros(g.shape, dtype=np.uint64)
    flat = counts.reshape(-1)
    lo, hi, reach = np.full(3, np.inf), np.full(3, -np.inf), 0.0
    blocks = -(-job.samples // BLOCK)
    pilot = pilot_blocks(blocks) if refine != 0 and (refine is not None or resolution is None) else 0
    sink = _sink_for(job, counts, scheduler, workers, pilot)
    if chunk is None:
        chunk = SINK_CHUNK if sink.token else DEFAULT_CHUNK if isinstance(scheduler, str) and scheduler in POOLS \
            else CLUSTER_CHUNK
    job = dataclasses.replace(job, sink=sink.token)
    state = {"job": job, "fine": None}

    def tasks():
        if not pilot:
            yield from ((job, f, c) for f, c in _tasks(run_blocks(job), chunk))
            return
        yield from ((job, f, c) for f, c in _tasks(job.layout.pilot_end, chunk))
        yield None  # barrier: every pilot result is merged into counts before the plan is made
        sink.flush()
        ref = plan_refinement(counts, refine, pilot, blocks)
        if ref is not None:
            state["job"] = dataclasses.replace(job, refine=ref)
            small = job.samples - pilot * BLOCK < 2**32  # no sub-cell count can overflow uint32
            state["fine"] = np.zeros(ref.cells.size * ref.factor**g.dim, dtype=np.uint32 if small else np.uint64)
            sink.flush(state["fine"])
            sink.flag(ref.cells)  # the fused tasks find a refined cell by bit 31 of its count
        yield from ((state["job"], f, c) for f, c in _tasks(run_blocks(job), chunk, job.layout.pilot_end))

    bar = Progress(int(samples), "samples", progress)
    try:
        for idx, cnt, bmin, bmax, r, m, fidx, fcnt in run(run_task, tasks(), scheduler, workers):
            flat[idx] += cnt  # idx is unique within a task
            if fidx.size:
                state["fine"][fidx] += fcnt
            lo, hi, reach = np.minimum(lo, bmin), np.maximum(hi, bmax), max(reach, r)
            bar.update(m)
        sink.flush(state["fine"])
    finally:
        bar.close()
        sink.close()
    ref = state["job"].refine
    fine = None if ref is None else state["fine"].reshape(ref.cells.size, -1)
    best, levels = _estimate(counts, g, ref, fine)
    return Occupancy(counts, g, int(samples), seed, lo, hi, reach, best, levels, ref, fine)


def sample_positions(robot: DHRobot, samples: int, seed: int = 0, *, fk: Callable | None = None,
                     as_dask: bool = False, chunk: int = DEFAULT_CHUNK):
    """End-effector origins (samples, 3) of the same random stream :func:`occupancy` uses.

    From 2·STRATUM_SAMPLES samples a sweep (:mod:`denavit.scale._strata`) the rows come in the order of joint 1's
    strata: the rows as a set are i.i.d. uniform in the joint limits, but a leading part of them is not (shuffle
    before taking a subset).

    With ``as_dask=True`` a lazy ``dask.array`` of the same values, one chunk per task (needs
    ``denavit[scale]``); compute it on any scheduler.
    """
    _check_sizes(samples, chunk)
    job = Job(*_job_args(robot, int(samples), int(seed), fk))
    spans = list(_tasks(run_blocks(job), chunk))
    if not as_dask:
        return np.concatenate([positions_block(job, b) for f, c in spans for b in range(f, f + c)])
    try:
        import dask
        import dask.array as da
    except ImportError:
        from ..errors import MissingDependencyError

        raise MissingDependencyError("as_dask needs dask: pip install 'denavit[scale]'") from None
    parts = []
    for f, c in spans:
        rows = int(block_table(job, f, c)[0].sum())
        block = dask.delayed(_span_positions)(job, f, c)
        parts.append(da.from_delayed(block, shape=(rows, 3), dtype=float))
    return da.concatenate(parts)


def _span_positions(job: Job, first: int, count: int) -> np.ndarray:
    return np.concatenate([positions_block(job, b) for b in range(first, first + count)])


def _job_args(robot, samples, seed, fk):
    from ._sampler import default_fk, sampling_limits

    return (default_fk(robot, samples) if fk is None else fk, sampling_limits(robot), seed, samples,
            Grid(np.zeros(3), np.eye(3), 1.0, 1, 1), np.array(robot.base_matrix[:3, 3], dtype=float), None, False,
            None, layout(seed, samples, BLOCK))
