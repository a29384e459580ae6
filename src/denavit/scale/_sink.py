"""Where fused tasks count: dense per-task accumulators, merged by the driver (no hand-off per sample).

In this process (``threads`` and ``synchronous`` schedulers) a run opens a :class:`Sink`: a pool of dense
``uint32`` accumulators of the grid's size (and of the refined sub-cells').  A task takes one, counts into it
with the GIL released (``_fused``), gives it back and returns no counts at all; the driver adds the
accumulators into its ``uint64`` counts at the pilot's barrier and at the end (``flush``, a jitted pass over the
nonzero entries; an accumulator untouched since its last flush is skipped).  The first accumulator to count
sub-cells counts them straight into the driver's sub-cell array when that is ``uint32``.  An accumulator is
also flushed before its samples could pass 2³¹ − 1 (no cell's count, the low 31 bits, can overflow: bit 31
flags the refined cells of a refined run, ``Sink.flag``, so a task tells them from the count it loads anyway).
At most ``cap`` accumulators exist (ACC_BUDGET bytes; a task waits for a free one), so memory does not grow
with the workers beyond that.

In another process (a process pool, a cluster) a task counts into a zeroed per-thread accumulator (its refined
cells flagged) and records the first hit of each cell; it returns those cells and their counts (as the numpy
route does after its sort) and zeroes those counts again.

Integer sums commute, so the counts are those of the numpy route for any tasks, workers and accumulators.
"""

from __future__ import annotations

import itertools
import threading

import numpy as np

from ..errors import DenavitError, ModelError
from ._refine import REFINE_CELLS, slot_map

__all__ = ["ACC_BUDGET", "NoSink", "Sink", "close_sink", "open_sink", "run_fused", "task_memory"]

#: Most bytes of accumulators a run keeps in this process (at least one accumulator is always made).
ACC_BUDGET = 3 * 2**27
#: Most samples an accumulator takes between flushes (the 31 count bits of its uint32 cells cannot overflow;
#: bit 31 flags the refined cells, ``_fused.FLAG``).
_MOST = 2**31 - 1

_sinks: dict = {}
_sinks_lock = threading.Lock()
_tokens = itertools.count()
_E32, _E64, _SLOTS = np.empty(0, np.int32), np.empty(0, np.int64), np.empty((0, 2), np.uint64)
_NONE = np.empty(0, np.uint32)  # no counts (read-only use: nothing is ever written to it)


def _flag(acc: np.ndarray, cells: np.ndarray, on: bool) -> None:
    from ._tally import flag

    flag(acc, cells, on)


class _Accumulator:
    def __init__(self, cells: int, refined: np.ndarray | None = None) -> None:
        self.counts = np.zeros(cells, dtype=np.uint32)
        if refined is not None:
            _flag(self.counts, refined, True)
        self.fine: np.ndarray | None = None
        self.tally = 0  # samples since the last flush


class Sink:
    """The accumulators of one run in this process, and the driver's arrays they are flushed into."""

    def __init__(self, counts: np.ndarray, workers: int, refinable: bool) -> None:
        self.counts, self.fine = counts.reshape(-1), None
        per = 4 * self.counts.size + (4 * REFINE_CELLS if refinable else 0)
        self.cap = max(1, min(workers, ACC_BUDGET // per))
        self.all: list[_Accumulator] = []
        self.free: list[_Accumulator] = []
        self.cond = threading.Condition()
        self.owner: _Accumulator | None = None  # the accumulator counting sub-cells straight into self.fine
        self.refined: np.ndarray | None = None  # the refined cells, flagged in every accumulator

    def acquire(self, samples: int, fine_size: int) -> _Accumulator:
        """A free accumulator (made while fewer than ``cap`` exist, else waited for) with room for
        ``samples`` more and, when ``fine_size``, sub-cell counts of that size."""
        with self.cond:
            while not self.free and len(self.all) >= self.cap:
                self.cond.wait()
            if self.free:
                acc = self.free.pop()
            else:
                acc = _Accumulator(self.counts.size, self.refined)
                self.all.append(acc)
            if acc.tally + samples > _MOST:
                self._flush_one(acc)
            if fine_size and (acc.fine is None or acc.fine.size != fine_size):
                acc.fine = self._fine_for(acc, fine_size)
        acc.tally += samples
        return acc

    def _fine_for(self, acc: _Accumulator, size: int) -> np.ndarray:
        """Sub-cell counts for ``acc``: the driver's own array for the first accumulator that asks when it is
        uint32 (fewer than 2³² samples after the pilot, so it cannot overflow) — no second array of up to
        128 MiB to fault in and merge — else a zeroed one of its own."""
        f = self.fine
        if self.owner is None and f is not None and f.dtype == np.uint32 and f.size == size:
            self.owner = acc
            return f
        return np.zeros(size, dtype=np.uint32)

    def release(self, acc: _Accumulator) -> None:
        with self.cond:
            self.free.append(acc)
            self.cond.notify()

    def _flush_one(self, acc: _Accumulator) -> None:
        from ._tally import merge

        if acc.tally == 0:  # nothing counted since the last flush: the accumulator is all zeros
            return
        merge(self.counts, acc.counts)
        if self.refined is not None:
            _flag(acc.counts, self.refined, True)  # merge zeroed the flags with the counts
        if acc.fine is not None and self.fine is not None and acc.fine is not self.fine:
            merge(self.fine, acc.fine)  # uint32 into uint32 (fewer than 2³² samples after the pilot) or uint64
        acc.tally = 0

    def close(self) -> None:
        close_sink(self.token)

    def flag(self, cells: np.ndarray) -> None:
        """Flag the refined cells ``cells`` in every accumulator, now and to come (called when no task runs)."""
        with self.cond:
            self.refined = cells
            for acc in self.all:
                _flag(acc.counts, cells, True)

    def flush(self, fine: np.ndarray | None = None) -> None:
        """Add every accumulator into the driver's counts (and into ``fine``, the sub-cell counts, once they
        exist); called when no task runs (a barrier, the end)."""
        with self.cond:
            if fine is not None:
                self.fine = fine
            for acc in self.all:
                self._flush_one(acc)


class NoSink:
    """A run without a sink (its tasks return their counts): the same calls, doing nothing."""

    token = None

    def flush(self, fine: np.ndarray | None = None) -> None:
        pass

    def flag(self, cells: np.ndarray) -> None:
        pass

    def close(self) -> None:
        pass


def open_sink(counts: np.ndarray, workers: int, refinable: bool) -> Sink:
    """A registered :class:`Sink` flushing into ``counts``; its ``token`` travels with the run's tasks and
    ``close()`` forgets it."""
    sink = Sink(counts, workers, refinable)
    sink.token = f"sink-{next(_tokens)}"
    with _sinks_lock:
        _sinks[sink.token] = sink
    return sink


def close_sink(token: str) -> None:
    with _sinks_lock:
        _sinks.pop(token, None)


class _Work(threading.local):
    """Per-thread arrays kept from task to task: zeroed accumulators of tasks run away from their driver
    (``dense``; zeroed again after each task) and scratch (``get``; contents undefined)."""

    def dense(self, name: str, size: int) -> np.ndarray:
        a = self.__dict__.get(name)
        if a is None or a.size != size:
            a = self.__dict__[name] = np.zeros(size, dtype=np.uint32)
            self.__dict__.pop(name + ":flags", None)
        return a

    def flagged(self, name: str, size: int, ref) -> np.ndarray:
        """``dense(name, size)`` with FLAG on the cells of the Refinement ``ref`` (None: on none); the flags
        are redone only when ``ref`` changes (its counts are zero between tasks)."""
        a = self.dense(name, size)
        want = None if ref is None else ref.token
        if self.__dict__.get(name + ":flags", None) != want:
            a[:] = 0
            if ref is not None:
                _flag(a, ref.cells, True)
            self.__dict__[name + ":flags"] = want
        return a

    def get(self, name: str, shape: tuple, dtype) -> np.ndarray:
        a = self.__dict__.get(name)
        size = int(np.prod(shape))
        if a is None or a.size < size or a.dtype != dtype:
            a = self.__dict__[name] = np.empty(size, dtype=dtype)
        return a[:size].reshape(shape)


_work = _Work()


def task_memory(job, count: int) -> int:
    """Bytes a fused task allocates beyond the accumulators: keys, sizes, scratch rows (joint values and
    origins, doubles; cells, sub-cells and the refined rows, 4 + 4 + 8 bytes) and — away from the driver — the
    first-hit buffers (4 + 8 bytes per sample with sub-cells).  Independent of ``job.samples``."""
    from ._fused import SUB_ROWS
    from ._sampler import BLOCK

    n = len(job.limits)
    touched = 0 if job.sink else (4 + (8 if job.refine is not None else 0)) * count * BLOCK
    return 24 * count + SUB_ROWS * (8 * (n + 3) + 16) + touched


def run_fused(job, first: int, count: int) -> tuple:
    """What :func:`denavit.scale._sampler.run_task` returns for blocks first … first+count−1, from the fused
    kernel; into the run's sink when ``job.sink`` names one in this process (then no cells are returned)."""
    from ._fused import SUB_ROWS, block_keys, fused_kernel
    from ._sampler import block_table

    g, ref, n = job.grid, job.refine, len(job.limits)
    sizes, joint1 = block_table(job, first, count)
    total = int(sizes.sum())
    lo = np.ascontiguousarray(job.limits[:, 0])
    span = job.limits[:, 1] - job.limits[:, 0]
    grid = np.array([*g.centre, g.lo, 1.0 / g.resolution, ref.factor if ref is not None else 0], dtype=float)
    unit = (g.basis == 1) & (np.abs(g.basis).sum(axis=1, keepdims=True) == 1)  # rows that are coordinate axes
    axes = np.flatnonzero(unit) % 3 if unit.any(axis=1).all() else _E64
    slots = slot_map(ref, g.side**g.dim) if ref is not None else _SLOTS
    fine_size = 0 if ref is None else ref.cells.size * ref.factor**g.dim
    stats = np.array([np.inf] * 3 + [-np.inf] * 3 + [0.0])
    args = (block_keys(job.entropy, first, count), sizes, joint1, lo, span, grid, np.ascontiguousarray(g.basis), axes,
            g.side, job.base_origin)
    if g.dim == 3 and not np.array_equal(g.basis, np.eye(3)):
        raise DenavitError("the fused kernel counts a 3-D grid along the world axes only (internal error)")
    scratch = (_work.get("fq", (n, SUB_ROWS), np.float64), _work.get("fP", (3, SUB_ROWS), np.float64),
               _work.get("fcells", (SUB_ROWS,), np.int32), _work.get("fsubs", (SUB_ROWS if ref else 0,), np.int64),
               stats)
    kernel = fused_kernel(job.fk.robot)
    sink = _sinks.get(job.sink) if job.sink else None
    if sink is not None:
        idx, cnt, fidx, fcnt = _into_sink(kernel, args, scratch, sink, total, slots, fine_size)
    else:
        idx, cnt, fidx, fcnt = _sparse(kernel, args, scratch, g.side**g.dim, total, slots, fine_size, ref)
    return idx, cnt, stats[:3], stats[3:6], float(np.sqrt(stats[6])), total, fidx, fcnt


def _into_sink(kernel, args, scratch, sink: Sink, total: int, slots, fine_size: int) -> tuple:
    """Count into a free accumulator of the run's sink; no cells returned (empty arrays)."""
    acc = sink.acquire(total, fine_size)
    try:
        _, _, status = kernel(*args, acc.counts, _E32, slots, acc.fine if fine_size else _NONE, _E64,
                              *scratch)
    finally:
        sink.release(acc)
    _check(status)
    return _E32, _NONE, _E64, _NONE


def _sparse(kernel, args, scratch, cells: int, total: int, slots, fine_size: int, ref) -> tuple:
    """Count into this thread's zeroed accumulators (the refined cells of ``ref`` flagged); return the cells hit
    and their counts (and the sub-cells'), and zero those counts again."""
    acc, fine = _work.flagged("cells", cells, ref), _work.dense("fine", fine_size)
    touched = _work.get("ftouch", (total,), np.int32)
    ftouched = _work.get("fftouch", (total if fine_size else 0,), np.int64)
    nt = nft = 0
    try:
        nt, nft, status = kernel(*args, acc, touched, slots, fine, ftouched, *scratch)
        idx, fidx = touched[:nt].copy(), ftouched[:nft].copy()
        cnt, fcnt = acc[idx] & np.uint32(2**31 - 1), fine[fidx]
    finally:
        acc[touched[:nt]] &= np.uint32(2**31)  # the kernel reports errors by status, with nt and nft counted so far
        fine[ftouched[:nft]] = 0
    _check(status)
    return idx, cnt, fidx, fcnt


def _check(status: int) -> None:
    from ._fused import NON_FINITE

    if status == NON_FINITE:
        raise ModelError("the forward kinematics gave non-finite positions (values too large for float64)")
    if status:
        raise DenavitError("a sample fell outside the reach bound (internal error in the sampler's grid)")
