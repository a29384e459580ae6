"""Streaming workspace sampler: counter-based random blocks → FK → voxel counts.

The unit of randomness is the *block* of :data:`BLOCK` samples: block ``b`` draws its joint values from the
words of one SplitMix64 stream keyed by ``SeedSequence(seed)``, from position b·2³² on (``_stream.block_state``;
two 32-bit joint values a word), so sample ``i`` is the same number whichever task, worker or chunk size computes it.
A run's blocks follow its ``_strata.Layout``: each block lies in one stratum of joint 1 of one sweep (at most
BLOCK samples; one stratum a sweep below 2·STRATUM_SAMPLES samples: the plain stream).  A *task* is any
run of whole blocks; tasks return sparse voxel counts (sorted cell index, count) that the driver adds into one
grid.  Integer sums commute, so the counts, bounds and reach are bit-identical for any number of workers and
any chunk size.  This module is the numpy route; with the compiled position kernel tasks run the fused kernel
of ``_fused`` instead (one pass, no GIL), which computes the same numbers.
"""

from __future__ import annotations

import math
import threading
from dataclasses import dataclass
from typing import Callable

import numpy as np

from ..errors import DenavitError, ModelError
from ..model import DHRobot, JointType
from ._refine import Refinement, popcount, slot_map
from ._strata import Layout, layout
from ._stream import draw

__all__ = ["BLOCK", "Grid", "Job", "PositionFK", "CompiledPositionFK", "default_fk", "COMPILED_FROM", "make_job",
           "reach_bound", "sampling_limits", "positions_block", "run_task", "block_table", "FINE_CELLS", "MAX_CELLS",
           "FLAT_TOLERANCE", "PILOT"]

#: Samples per random block: the unit of randomness (fixed, independent of chunking and workers).
BLOCK = 65_536
#: Samples of block 0 used to decide whether the workspace is planar (same for every run with a seed).
PILOT = 4096
#: Relative thickness (smallest / largest singular value of the pilot cloud) below which the arm is planar.
FLAT_TOLERANCE = 1e-9
#: Default cells along a side of the finest grid (3-D, 2-D).
FINE_CELLS = {3: 256, 2: 2048}
#: Most cells in the finest grid (uint64 counts: 128 MiB).
MAX_CELLS = 2**24
#: Coarsest level kept: at least this many cells along a side.
MIN_CELLS = 8
#: Runs of at least this many samples use the compiled position kernel by default (when numba is installed).
COMPILED_FROM = 2_000_000


def sampling_limits(robot: DHRobot) -> np.ndarray:
    """Per-joint sampling ranges, shape (n, 2): the limits, [−π, π] for an unlimited revolute joint.

    Raises
    ------
    ModelError
        A prismatic joint has no limits (its workspace is unbounded).
    """
    lim = np.array(robot.q_limits, dtype=float)  # (n, 2)
    for k, kind in enumerate(robot.joint_types):
        if not np.all(np.isfinite(lim[k])):
            if kind is JointType.PRISMATIC:
                raise ModelError(f"joint {k + 1} is prismatic without limits: give it limits to sample a workspace")
            lim[k] = np.clip(lim[k], -np.pi, np.pi)
    return lim


def reach_bound(robot: DHRobot) -> tuple[np.ndarray, float]:
    """Centre c (3,) and radius R [m] of a ball that holds every end-effector origin within the limits.

    With the chain T = C0 · J1(q1) · C1 ⋯ Jn(qn) · Cn (J a rotation about z or a translation along z),
    |p − t(C0)| ≤ Σ_{k≥1} |t(C_k)| + Σ_prismatic max |q_k|  (rotations keep lengths).
    """
    from ..chain import reach_ball, screws_of

    lim = sampling_limits(robot)
    return reach_ball(screws_of(robot), lim[:, 0], lim[:, 1])


class PositionFK:
    """The default FK callable: joint values (m, n) → end-effector origins (m, 3) by ``forward_kinematics``.

    Any callable with the same contract may replace it (e.g. a compiled kernel); one returning (m, 4, 4)
    poses is accepted too.  It must be picklable for the ``processes`` and cluster schedulers.
    """

    def __init__(self, robot: DHRobot) -> None:
        self.robot = robot

    def __call__(self, q: np.ndarray) -> np.ndarray:
        from ..numeric import forward_kinematics

        return forward_kinematics(self.robot, q, threads=1)[:, :3, 3]  # the scheduler runs the tasks in parallel


class CompiledPositionFK:
    """FK callable from the generated position kernel (``denavit.compile(robot).position``), built lazily.

    Pickles as the robot alone: each worker process compiles (or loads from the on-disk cache) on first use.
    """

    def __init__(self, robot: DHRobot) -> None:
        self.robot = robot
        self._kernel = None

    def __getstate__(self):
        return {"robot": self.robot, "_kernel": None}

    def __call__(self, q: np.ndarray) -> np.ndarray:
        if self._kernel is None:
            from ..codegen import compile as compile_robot

            self._kernel = compile_robot(self.robot, kernels=["position"]).position
        return self._kernel(np.ascontiguousarray(q, dtype=float), threads=1)  # one task, one thread


def default_fk(robot: DHRobot, samples: int) -> Callable:
    """The FK callable a run uses when none is given: the compiled position kernel when numba is installed
    and the run has at least COMPILED_FROM samples (its first compile of an arm costs seconds), else
    :class:`PositionFK`."""
    if samples >= COMPILED_FROM:
        import importlib.util

        if importlib.util.find_spec("numba") is not None:
            return CompiledPositionFK(robot)
    return PositionFK(robot)


@dataclass(frozen=True)
class Grid:
    """A regular grid of cubic (or, for a planar arm, square) cells in the workspace's coordinates.

    Coordinates are u = (p − centre) · basisᵀ (basis rows orthonormal; the world axes for a 3-D workspace);
    cell i spans lo + h·[i, i+1) on every axis; shape is (side,) * dim.
    """

    centre: np.ndarray  # (3,)
    basis: np.ndarray  # (dim, 3)
    resolution: float
    side: int
    levels: int

    @property
    def dim(self) -> int:
        return int(self.basis.shape[0])

    @property
    def lo(self) -> float:
        return -0.5 * self.side * self.resolution

    @property
    def shape(self) -> tuple[int, ...]:
        return (self.side,) * self.dim

    def cell_centres(self, index: np.ndarray, level: int = 0) -> np.ndarray:
        """World coordinates (k, 3) of the centres of cells with integer indices (k, dim) at a level."""
        h = self.resolution * 2**level
        u = self.lo + (np.asarray(index, dtype=float) + 0.5) * h  # (k, dim)
        return self.centre + u @ self.basis


@dataclass(frozen=True)
class Job:
    """Everything a task needs (picklable): sampler, FK callable and grid."""

    fk: Callable
    limits: np.ndarray  # (n, 2)
    entropy: int
    samples: int
    grid: Grid
    base_origin: np.ndarray  # (3,)
    refine: Refinement | None = None  # sub-cell counts in these cells (blocks after the pilot)
    fused: bool = False  # tasks run the fused kernel (``_fused``: same numbers as fk, a CompiledPositionFK)
    sink: str | None = None  # the run's accumulators in the driver's process (``_sink``), for in-process tasks
    layout: Layout | None = None  # the blocks' strata (``_strata``); None: the plain stream, BLOCK samples a block


def run_blocks(job: Job) -> int:
    """Blocks of the run (of its layout)."""
    return -(-job.samples // BLOCK) if job.layout is None else job.layout.blocks


def block_table(job: Job, first: int, count: int) -> tuple[np.ndarray, np.ndarray]:
    """Samples (count,) int64 of blocks first … first+count−1 and joint 1's (lo, span) (count, 2) in each: its
    stratum (``_strata.Layout.limits``), or its whole range without a layout."""
    if job.layout is not None:
        return job.layout.limits(first, count, job.limits)
    sizes = np.array([min(BLOCK, job.samples - b * BLOCK) for b in range(first, first + count)], dtype=np.int64)
    return sizes, np.tile([job.limits[0, 0], job.limits[0, 1] - job.limits[0, 0]], (count, 1))


def positions_block(job: Job, block: int, rows: int | None = None) -> np.ndarray:
    """End-effector origins (m, 3) of random block ``block`` (its first ``rows`` samples)."""
    sizes, bounds = block_table(job, block, 1)
    m = int(sizes[0]) if rows is None else rows
    return _positions(job.fk(draw(job, block, np.empty((m, len(job.limits))), bounds[0])))


def _positions(out) -> np.ndarray:
    p = np.asarray(out, dtype=float)
    if p.ndim == 3 and p.shape[1:] == (4, 4):
        p = p[:, :3, 3]
    if p.ndim != 2 or p.shape[1] != 3:
        raise DenavitError(f"the FK callable returned shape {p.shape}; expected (m, 3) or (m, 4, 4)")
    return p


class _Scratch(threading.local):
    """Per-thread work arrays, kept from task to task.

    A task allocates nothing of the size of its samples beyond what the FK callable returns: fresh large
    arrays cost page faults on every task wherever the allocator hands them back to the system at once (the
    C library does so for every block above 64 kB under ``MALLOC_TRIM_THRESHOLD_=65536``, which Dask's
    nanny sets in its workers), and that made a Dask worker ~40 % slower than a plain process."""

    def get(self, name: str, shape: tuple, dtype) -> np.ndarray:
        a = self.__dict__.get(name)
        size = math.prod(shape)
        if a is None or a.size < size or a.dtype != dtype:
            a = np.empty(max(size, 0 if a is None else a.size), dtype=dtype)
            self.__dict__[name] = a
        return a[:size].reshape(shape)


_scratch = _Scratch()


def _cells(job: Job, P: np.ndarray, flat: np.ndarray, T: np.ndarray | None = None) -> None:
    """Row-major flat cell indices (as numpy.ravel_multi_index) of the positions P (m, 3), into ``flat``;
    with T (dim, m), also the coordinates in cell edges from the grid's corner (before flooring)."""
    g = job.grid
    m = P.shape[0]
    D = _scratch.get("D", (m, 3), np.float64)
    np.subtract(P, g.centre, out=D)
    if g.dim == 3 and np.array_equal(g.basis, np.eye(3)):
        U = D  # (m, dim)
    else:  # u_a = (d0·b_a0 + d1·b_a1) + d2·b_a2, in this order (as the fused kernel; BLAS may fuse or reorder)
        U = _scratch.get("U", (m, g.dim), np.float64)
        e = _scratch.get("e", (m,), np.float64)
        for a in range(g.dim):
            np.multiply(D[:, 0], g.basis[a, 0], out=U[:, a])
            for j in (1, 2):
                np.multiply(D[:, j], g.basis[a, j], out=e)
                U[:, a] += e
    c = _scratch.get("c", (m,), np.int32)
    flat[:] = 0
    for a in range(g.dim):
        t = _scratch.get("t", (m,), np.float64)
        np.subtract(U[:, a], g.lo, out=t)
        t *= 1.0 / g.resolution  # the reciprocal once (the fused kernel too): a multiplication per sample
        if T is not None:
            T[a] = t
        np.floor(t, out=t)
        if not (t.min() >= 0 and t.max() < g.side):  # NaN fails too
            raise DenavitError("a sample fell outside the reach bound (internal error in the sampler's grid)")
        c[:] = t  # < MAX_CELLS = 2^24: int32 sorts faster than int64
        flat *= g.side
        flat += c


def _sub_cells(job: Job, flat: np.ndarray, T: np.ndarray, out: np.ndarray) -> int:
    """Sub-cell indices (slot·k^d + row-major sub-cell) of the samples that fall in refined cells, into the
    front of ``out``; returns how many."""
    ref, g = job.refine, job.grid
    k = ref.factor
    slots = slot_map(ref, g.side**g.dim)
    words, prefix = slots[:, 0], slots[:, 1].view(np.int64)
    w = np.right_shift(flat, 6, out=_scratch.get("w", flat.shape, np.int32))
    b = np.bitwise_and(flat, 63, out=_scratch.get("b", flat.shape, np.uint64), casting="unsafe")
    word = np.take(words, w, out=_scratch.get("word", flat.shape, np.uint64))
    bit = np.right_shift(word, b, out=_scratch.get("bit", flat.shape, np.uint64))
    bit &= np.uint64(1)
    sel = np.flatnonzero(bit)
    if sel.size == 0:
        return 0
    below = np.left_shift(np.uint64(1), b[sel]) - np.uint64(1)  # the bits below the cell's own
    idx = prefix[w[sel]] + popcount(word[sel] & below)  # its slot in ref.cells
    for a in range(g.dim):
        t = T[a, sel]
        sub = np.floor(t * k) - k * np.floor(t)  # exact: k is a power of two
        idx *= k
        idx += sub.astype(np.int64)
    out[:sel.size] = idx
    return sel.size


def _distance_max(P: np.ndarray, origin: np.ndarray) -> float:
    D = _scratch.get("D", P.shape, np.float64)
    np.subtract(P, origin, out=D)
    D *= D
    return float(np.sqrt(D.sum(axis=1, out=_scratch.get("t", (P.shape[0],), np.float64)).max()))


def run_task(job: Job, first: int, count: int) -> tuple:
    """Blocks first … first+count−1: sorted flat cell indices, their counts, bounds (3,), (3,), reach, samples,
    and — when ``job.refine`` is set — sorted sub-cell indices and their counts (else empty arrays).

    With ``job.fused`` the fused kernel computes the same (``_sink.run_fused``; cells unsorted, and none at all
    when ``job.sink`` holds them in this process)."""
    if job.fused and _has_numba():  # a cluster worker without numba takes the numpy route: the same numbers
        from ._sink import run_fused

        return run_fused(job, first, count)
    sizes, bounds = block_table(job, first, count)
    total = int(sizes.sum())
    flat = _scratch.get("flat", (total,), np.int32)
    fine = _scratch.get("fine", (total,), np.int64) if job.refine is not None else None
    lo, hi, reach, done, kept = np.full(3, np.inf), np.full(3, -np.inf), 0.0, 0, 0
    for b in range(first, first + count):
        m = int(sizes[b - first])
        P = _positions(job.fk(draw(job, b, _scratch.get("q", (m, len(job.limits)), np.float64), bounds[b - first])))
        lo, hi = np.minimum(lo, P.min(axis=0)), np.maximum(hi, P.max(axis=0))  # NaN and inf reach these
        if not (np.all(np.isfinite(lo)) and np.all(np.isfinite(hi))):
            raise ModelError("the forward kinematics gave non-finite positions (values too large for float64)")
        reach = max(reach, _distance_max(P, job.base_origin))
        if fine is None:
            _cells(job, P, flat[done:done + m])
        else:
            T = _scratch.get("T", (job.grid.dim, m), np.float64)
            _cells(job, P, flat[done:done + m], T)
            kept += _sub_cells(job, flat[done:done + m], T, fine[kept:])
        done += m
    idx, cnt = _runs(flat)
    fidx, fcnt = _runs(fine[:kept]) if kept else (np.empty(0, np.int64), np.empty(0, np.uint32))
    return idx, cnt, lo, hi, reach, total, fidx, fcnt


def _runs(flat: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Sorted distinct values of ``flat`` and how often each occurs (as numpy.unique; sorts ``flat`` in place)."""
    flat.sort()
    m = flat.shape[0]
    step = _scratch.get("step", (m,), np.bool_)
    step[0] = True
    np.not_equal(flat[1:], flat[:-1], out=step[1:])
    starts = np.flatnonzero(step)
    cnt = np.empty(starts.shape[0], dtype=np.uint32)
    np.subtract(starts[1:], starts[:-1], out=cnt[:-1], casting="unsafe")
    cnt[-1] = m - starts[-1]
    return flat[starts], cnt


def _plane(points: np.ndarray) -> np.ndarray | None:
    """Orthonormal basis (2, 3) of the plane holding the pilot cloud, or None if it has thickness."""
    centred = points - points.mean(axis=0)
    _, sv, Vt = np.linalg.svd(centred, full_matrices=False)
    if len(sv) < 3 or sv[2] > FLAT_TOLERANCE * max(sv[0], 1e-300):
        return None
    normal = Vt[2]
    axis = int(np.argmax(np.abs(normal)))
    if abs(normal[axis]) > 1 - 1e-9:  # a world coordinate plane: keep the other two world axes
        return np.delete(np.eye(3), axis, axis=0)
    return Vt[:2]


def make_job(robot: DHRobot, samples: int, resolution: float | None, seed: int, fk: Callable | None = None) -> Job:
    """Sampler, grid (finest resolution, levels) and FK callable for one run."""
    limits = sampling_limits(robot)
    centre, R = reach_bound(robot)
    fk = default_fk(robot, samples) if fk is None else fk
    base_origin = np.array(robot.base_matrix[:3, 3], dtype=float)
    probe = Job(fk, limits, seed, max(samples, PILOT), Grid(centre, np.eye(3), 1.0, 1, 1), base_origin)
    pilot = positions_block(probe, 0, rows=PILOT)
    if not np.all(np.isfinite(pilot)):
        raise ModelError("the forward kinematics gave non-finite positions (values too large for float64)")
    basis = _plane(pilot)
    basis = np.eye(3) if basis is None else basis
    dim = basis.shape[0]
    R = R * (1 + 1e-9) + 1e-12
    if R <= 1e-12 * (1 + float(np.abs(centre).max())):
        raise ModelError(f"{robot.name}: the end effector does not move, so it has no workspace to measure")
    cap = int(round(MAX_CELLS ** (1 / dim)))
    if resolution is None:
        side = FINE_CELLS[dim]
        h = 2 * R / side
        levels = int(math.log2(side // MIN_CELLS)) + 1
    else:
        h = float(resolution)
        if not (h > 0 and math.isfinite(h)):
            raise ModelError(f"resolution must be a positive length in metres, got {resolution}")
        cells = 2 * R / h
        if cells > cap:
            raise ModelError(f"resolution {h:g} m gives {cells:.3g} cells along the {2 * R:.4g} m reach box "
                             f"(at most {cap} per side, {MAX_CELLS} in all): use a resolution of at least "
                             f"{2 * R / cap:.3g} m")
        if cells < MIN_CELLS:
            raise ModelError(f"resolution {h:g} m leaves {cells:.3g} cells along the {2 * R:.4g} m reach box (at "
                             f"least {MIN_CELLS}): use a resolution of at most {2 * R / MIN_CELLS:.3g} m")
        side, levels = math.ceil(cells), 1
    return Job(fk, limits, seed, samples, Grid(centre, basis, h, side, levels), base_origin,
               fused=type(fk) is CompiledPositionFK and _has_numba(), layout=layout(seed, samples, BLOCK))


def _has_numba() -> bool:
    import sys

    if "numba" in sys.modules:
        return True
    import importlib.util

    return importlib.util.find_spec("numba") is not None
