"""Splitting a batch over threads: the one helper behind every ``threads=`` keyword.

A batch call computes row b of its output from row b of its inputs only, so the rows can be cut into
contiguous blocks and each block handed to a thread.  Threads only help when the work releases the GIL:
the compiled numba kernels do (``@njit(nogil=True)``: the whole batch loop runs without it), numpy does
inside its ufunc and matmul loops (but not between them, in the Python that strings them together).

Rules (the same for every caller):

- ``threads=None`` means every core this process may run on (``os.sched_getaffinity``, else
  ``os.cpu_count()``); ``threads=1`` runs the call inline in the calling thread, as if there were no helper.
  Anything else than ``None`` or an integer ≥ 1 is a ``ValueError``.
- A thread gets at least ``min_rows`` rows (``MIN_ROWS`` by default): a small batch runs inline, a middling
  one on fewer threads than asked.  Handing a block to a thread costs some tens of microseconds; below a few
  thousand rows of the cheapest kernel (FK, ~30 M rows/s) that is more than the work.
- Block boundaries are multiples of ``ALIGN`` rows (the SIMD batch kernels compute 4 rows at once), and the
  blocks are in order: block 0 runs in the calling thread, the others on a shared pool of worker threads.
- Results are bitwise those of the unsplit call: each row's arithmetic does not depend on which block holds it.
- The first exception raised by any block is re-raised in the caller, after every block has finished (no
  block is left writing into the output when the call returns).
- The plain numpy functions (:func:`split_call`) also cut each thread's block into pieces of NUMPY_CHUNK rows,
  run one after another: numpy's temporaries then stay in the CPU cache (less work per row, threads or not).
- A call made from inside a worker (a batched function calling another) runs inline: workers never wait for
  workers, so the pool cannot deadlock.

Oversubscription: the compiled kernels are serial (numba's ``parallel=True``/``prange`` is not used, so
numba's own threading layer never starts), and numpy's products of small (4×4, 6×n) matrices stay below the
size at which a threaded BLAS starts its own threads, so ``threads=T`` keeps T cores busy, not more.  Work that
is already parallel calls with ``threads=1``: the workspace and reachability tasks (:mod:`denavit.scale`) do,
since Dask runs the tasks side by side.  Next to other multi-threaded code (a numba ``parallel=True`` function of
your own, a threaded BLAS on large matrices) give each a share: ``threads=`` here, ``numba.set_num_threads`` /
``OMP_NUM_THREADS`` there.
"""

from __future__ import annotations

import os
import threading
from concurrent.futures import ThreadPoolExecutor

import numpy as np

__all__ = ["ALIGN", "MIN_ROWS", "NUMPY_CHUNK", "available_cores", "blocks", "resolve_threads", "run_batch",
           "split_call", "split_rows"]

#: Fewest rows a thread is given (a batch below 2 × MIN_ROWS runs inline).
MIN_ROWS = 4096
#: Block boundaries fall on multiples of this many rows.
ALIGN = 8
#: Rows per piece of a plain numpy function's batch (:func:`split_call`): its temporaries, a few dozen arrays of
#: this many doubles, then stay in the CPU cache.  Measured on Puma 560 and Panda (10⁵ rows, one thread, process
#: CPU time): one pass over the whole batch took 1.1–1.2× (FK), 1.05× (J), 1.4–1.6× (RNEA, M, FD, g, c) the pieces'.
NUMPY_CHUNK = 16384

_local = threading.local()
_lock = threading.Lock()
_pool: list = [None, 0, 0]  # the executor, its number of workers, the process id that made it


def available_cores() -> int:
    """Cores this process may run on: ``len(os.sched_getaffinity(0))`` where the platform has it, else
    ``os.cpu_count()`` (1 if unknown)."""
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except (AttributeError, OSError):  # pragma: no cover (macOS, Windows)
        return max(1, os.cpu_count() or 1)


def resolve_threads(threads) -> int:
    """The number of threads ``threads=`` asks for: ``None`` → :func:`available_cores`; an integer ≥ 1 as is."""
    if threads is None:
        return available_cores()
    if isinstance(threads, bool) or not isinstance(threads, int) and not hasattr(threads, "__index__"):
        raise ValueError(f"threads must be None or an integer >= 1, got {threads!r}")
    t = int(threads.__index__())
    if t < 1:
        raise ValueError(f"threads must be None or an integer >= 1, got {t}")
    return t


def blocks(rows: int, threads=None, min_rows: int = MIN_ROWS) -> list[tuple[int, int]]:
    """The (start, stop) blocks ``rows`` rows are cut into: as many as the threads asked for, each at least
    ``min_rows`` rows long (so one block, the whole batch, below 2 × min_rows), boundaries on multiples of
    ALIGN, sizes as equal as that allows.  Inside a worker thread always one block."""
    t = resolve_threads(threads)
    if getattr(_local, "worker", False):
        t = 1
    t = max(1, min(t, rows // max(1, int(min_rows))))
    if t == 1:
        return [(0, rows)]
    units = -(-rows // ALIGN)  # ALIGN-row units, the last possibly short
    cuts = [min(rows, (units * k // t) * ALIGN) for k in range(t + 1)]
    return [(cuts[k], cuts[k + 1]) for k in range(t) if cuts[k + 1] > cuts[k]]


def _executor(workers: int) -> ThreadPoolExecutor:
    with _lock:
        # a forked child inherits the pool object but not its threads (work queued there would never run):
        # it makes its own
        if _pool[1] < workers or _pool[2] != os.getpid():  # grown, never shrunk; the old pool is dropped (not
            # shut down: a caller may still be submitting to it), its idle threads end once it is collected
            workers = max(workers, available_cores() - 1)
            _pool[0] = ThreadPoolExecutor(max_workers=workers, thread_name_prefix="denavit",
                                          initializer=_mark_worker)
            _pool[1], _pool[2] = workers, os.getpid()
        return _pool[0]


def _mark_worker() -> None:
    _local.worker = True


def split_rows(rows: int, work, threads=None, min_rows: int = MIN_ROWS) -> None:
    """Call ``work(start, stop)`` once per block of :func:`blocks` (block 0 in this thread, the others on the
    pool), wait for all, and re-raise the first exception any raised."""
    if rows < 2 * min_rows:  # one block whatever the cores: no look at them
        if threads is not None:
            resolve_threads(threads)
        work(0, rows)
        return
    parts = blocks(rows, threads, min_rows)
    if len(parts) == 1:
        work(0, rows)
        return
    pool = _executor(len(parts) - 1)
    futures = [pool.submit(work, s, e) for s, e in parts[1:]]
    error = None
    try:
        work(*parts[0])
    except BaseException as exc:  # noqa: BLE001 (re-raised below, once the workers are done)
        error = exc
    for f in futures:
        exc = f.exception()  # waits
        if exc is not None and error is None:
            error = exc
    if error is not None:
        raise error


def run_batch(kernel, inputs, outputs, threads=None, min_rows: int = MIN_ROWS, extra=()):
    """``kernel(*inputs[s:e], *extra, *outputs[s:e])`` over the blocks of the rows: the inputs and outputs are
    arrays whose leading axis is the batch (the same length B), ``extra`` arguments are passed whole.  Returns
    ``outputs``.  The kernel must write row b of each output from row b of the inputs only."""
    rows = len(outputs[0])

    def work(s: int, e: int) -> None:
        kernel(*[x[s:e] for x in inputs], *extra, *[o[s:e] for o in outputs])

    split_rows(rows, work, threads, min_rows)
    return outputs


def split_call(func, arrays, threads=None, min_rows: int = MIN_ROWS, chunk: int | None = -1):
    """``func(*arrays)`` computed block by block, or None when the batch is small enough to be computed whole
    (the caller then does, as it would without threads).

    ``arrays`` are already checked and broadcast to one shape (..., k) (the trailing axis may differ between
    them); ``func`` takes pieces of them, shaped (rows, k), and returns one array (rows,) + trailing.  The rows
    are cut into the blocks of :func:`blocks` (one per thread), and each block, in its thread, into pieces of
    at most ``chunk`` rows (default :data:`NUMPY_CHUNK`; None: no pieces) run one after another.  The pieces' results are joined into
    (...,) + trailing: exactly the array ``func`` returns for the whole batch when each row's result depends on
    that row only.
    """
    if threads is not None:
        resolve_threads(threads)  # refused even where it is not used (a single row)
    batch = arrays[0].shape[:-1]
    rows = 1
    for s in batch:
        rows *= s
    if chunk == -1:
        chunk = NUMPY_CHUNK
    piece = rows if chunk is None else max(1, int(chunk))
    if rows < 2 * min_rows and rows <= piece:  # the common small call: no look at the cores
        return None
    parts = blocks(rows, threads, min_rows)
    if len(parts) == 1 and rows <= piece:
        return None
    flat = [a.reshape(rows, a.shape[-1]) for a in arrays]
    results: dict = {}

    def work(s: int, e: int) -> None:
        for a in range(s, e, piece):
            results[a] = func(*[x[a:min(e, a + piece)] for x in flat])

    split_rows(rows, work, threads, min_rows)
    out = np.concatenate([results[a] for a in sorted(results)], axis=0)
    return out.reshape(batch + out.shape[1:])
