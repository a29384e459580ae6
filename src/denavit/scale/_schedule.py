"""Where tasks run: in this process, a thread or process pool, or a ``dask.distributed`` cluster (given, or a
LocalCluster started here for the run).

Every scheduler runs the same task functions and the driver merges results as they arrive; at most
``IN_FLIGHT`` tasks per worker are submitted at a time, so memory stays bounded whatever the task count.
Ctrl-C cancels what is pending and shuts the pool down before ``KeyboardInterrupt`` propagates.
"""

from __future__ import annotations

import concurrent.futures as cf
import contextlib
import os
import signal
import sys
import time
from typing import Any, Callable, Iterable, Iterator

from .._constants import LOCAL_SCHEDULERS, MAX_WORKERS
from ._cluster import check_address, cluster_failure, connect, local_cluster

__all__ = ["LOCAL_SCHEDULERS", "POOLS", "AUTO_PROCESSES_FROM", "resolve_auto", "IN_FLIGHT", "MAX_WORKERS",
           "check_scheduler", "session", "run", "Progress"]

#: The local schedulers that run without Dask.
POOLS = ("auto", "synchronous", "threads", "processes")
#: "auto" runs on processes from this many samples on (FK threads contend for the GIL), on threads below.
AUTO_PROCESSES_FROM = 10_000_000
#: Tasks submitted ahead per worker (bounds the results held at once).
IN_FLIGHT = 2


def check_scheduler(scheduler: Any) -> None:
    """Refuse a scheduler that is neither a local name, a ``tcp://``/``tls://`` address nor a Client
    (ParseError)."""
    if not isinstance(scheduler, str) or scheduler in LOCAL_SCHEDULERS:
        return
    check_address(scheduler)


def resolve_auto(scheduler: Any, samples: int) -> Any:
    """``"auto"`` → ``"processes"`` for runs of at least AUTO_PROCESSES_FROM samples, else ``"threads"``."""
    if isinstance(scheduler, str) and scheduler == "auto":
        return "processes" if samples >= AUTO_PROCESSES_FROM else "threads"
    return scheduler


def _quiet_worker() -> None:  # process-pool workers leave Ctrl-C to the driver
    signal.signal(signal.SIGINT, signal.SIG_IGN)


class _Inline:
    """A pool of one that runs each task when submitted."""

    def submit(self, fn, *args):
        f: cf.Future = cf.Future()
        try:
            f.set_result(fn(*args))
        except BaseException as exc:  # noqa: BLE001 - re-raised by result()
            if isinstance(exc, KeyboardInterrupt):
                raise
            f.set_exception(exc)
        return f


def _wait(done_order, pending: set):
    """(done, not done) once at least one pending future is done; ``done_order`` is a dask ``as_completed``
    for a cluster (``distributed.wait`` needs a default client, and ours is not made the default)."""
    if done_order is None:
        return cf.wait(pending, return_when=cf.FIRST_COMPLETED)
    done = {next(done_order)}
    return done, pending - done


@contextlib.contextmanager
def session(scheduler: Any, workers: int | None = None) -> Iterator[Any]:
    """The scheduler for every phase of one run: ``"dask"`` starts one LocalCluster (of ``workers`` processes)
    and an address connects one Client, each closed when the run ends; a pool name or a Client passes through.

    A run of several phases (a position screen, then a map) passes what this yields to each :func:`run`, so they
    share one cluster instead of starting one each."""
    check_scheduler(scheduler)
    if not isinstance(scheduler, str) or scheduler in POOLS:
        yield scheduler
    elif scheduler == "dask":
        with local_cluster(min(workers or os.cpu_count() or 1, MAX_WORKERS)) as client:
            yield client
    else:
        client = connect(scheduler)
        try:
            yield client
        finally:
            client.close()


def run(fn: Callable, tasks: Iterable[tuple], scheduler: Any = "threads", workers: int | None = None
        ) -> Iterator[Any]:
    """Yield ``fn(*task)`` for every task, in completion order, on the given scheduler ("auto": threads).

    A task ``None`` is a barrier: the results of all tasks before it are yielded before the iterator of tasks
    is asked for the next one (so a generator of tasks may read what the caller made of those results).
    ``"dask"`` or an address starts or connects a cluster for this call alone (see :func:`session`)."""
    with session(resolve_auto(scheduler, 0), workers) as where:
        yield from _run(fn, tasks, where, workers)


def _run(fn: Callable, tasks: Iterable[tuple], scheduler: Any, workers: int | None) -> Iterator[Any]:
    client, pool = (None, None) if isinstance(scheduler, str) else (scheduler, None)
    done_order = None
    if client is not None:
        from distributed import as_completed

        width = max(1, sum(client.nthreads().values()))
        done_order = as_completed(loop=client.loop)

        def submit(*a):
            future = client.submit(*a, pure=False)
            done_order.add(future)
            return future
    else:
        width = workers or os.cpu_count() or 1
        if scheduler == "synchronous":
            pool, width = _Inline(), 1
        elif scheduler == "threads":
            pool = cf.ThreadPoolExecutor(width)
        else:
            pool = cf.ProcessPoolExecutor(width, initializer=_quiet_worker)
        submit = pool.submit
    it, pending = iter(tasks), set()
    try:
        for task in it:
            if task is None:  # a barrier: every earlier task's result is yielded before the next task is drawn
                while pending:
                    done, pending = _wait(done_order, pending)
                    pending = set(pending)
                    for f in done:
                        yield _result(f, client)
                continue
            pending.add(submit(fn, *task))
            while len(pending) >= IN_FLIGHT * width:
                done, pending = _wait(done_order, pending)
                pending = set(pending)
                for f in done:
                    yield _result(f, client)
        while pending:
            done, pending = _wait(done_order, pending)
            pending = set(pending)
            for f in done:
                yield _result(f, client)
    finally:
        for f in pending:
            f.cancel()
        if isinstance(pool, cf.Executor):
            pool.shutdown(wait=True, cancel_futures=True)


def _result(future, client):
    """The task's result; on a cluster, a failure of the cluster itself becomes one DenavitError line."""
    try:
        return future.result()
    except Exception as exc:
        failure = None if client is None else cluster_failure(exc)
        if failure is None:
            raise
        raise failure from None


class Progress:
    """A one-line progress report with rate and ETA on stderr, redrawn at most every ``every`` seconds."""

    def __init__(self, total: int, unit: str, enabled: bool | None = None, every: float = 0.5) -> None:
        self.total, self.unit, self.every = total, unit, every
        self.enabled = sys.stderr.isatty() if enabled is None else enabled
        self.done, self.t0, self.shown = 0, time.perf_counter(), 0.0

    def update(self, n: int) -> None:
        self.done += n
        now = time.perf_counter()
        if self.enabled and (now - self.shown >= self.every or self.done >= self.total):
            self.shown = now
            dt = max(now - self.t0, 1e-9)
            rate = self.done / dt
            eta = (self.total - self.done) / rate if rate > 0 else float("inf")
            pct = 100.0 * self.done / max(self.total, 1)
            sys.stderr.write(f"\r{pct:5.1f}%  {_count(self.done)}/{_count(self.total)} {self.unit}  "
                             f"{rate:.3g} {self.unit}/s  ETA {_clock(eta)}   ")
            sys.stderr.flush()

    def close(self) -> None:
        if self.enabled:
            sys.stderr.write("\n")
            sys.stderr.flush()


def _count(n: int) -> str:
    """A count as people read it: 49,531 below a million, 2.5e+08 above."""
    return f"{n:,}" if n < 10**6 else f"{n:.3g}"


def _clock(seconds: float) -> str:
    if seconds != seconds or seconds == float("inf"):
        return "--:--"
    s = int(round(seconds))
    return f"{s // 3600}:{s % 3600 // 60:02d}:{s % 60:02d}" if s >= 3600 else f"{s // 60}:{s % 60:02d}"
