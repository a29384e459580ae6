"""threads= on batch calls: the splitting helper, then the compiled and plain functions split by it.

The truth for every split call is the same call unsplit (threads=1): the blocks must reproduce it bit for bit.
No timing is asserted here (benchmarks/bench_threads.py measures the speed-up)."""

from __future__ import annotations

import threading

import numpy as np
import pytest

from denavit._threads import ALIGN, MIN_ROWS, available_cores, blocks, resolve_threads, run_batch, split_rows


# --- the helper --------------------------------------------------------------------------------------------
@pytest.mark.parametrize("rows", [0, 1, 7, MIN_ROWS, 2 * MIN_ROWS - 1, 2 * MIN_ROWS, 3 * MIN_ROWS + 5, 100_003])
@pytest.mark.parametrize("threads", [1, 2, 3, 8])
def test_blocks_cover_the_rows_once_in_order(rows, threads):
    parts = blocks(rows, threads)
    assert parts[0][0] == 0 and parts[-1][1] == rows
    assert all(a[1] == b[0] for a, b in zip(parts, parts[1:]))  # contiguous, in order, no overlap
    assert len(parts) <= threads
    if len(parts) > 1:
        assert all(e - s >= MIN_ROWS - ALIGN for s, e in parts)
        assert all(s % ALIGN == 0 for s, _ in parts)
    else:
        assert rows < 2 * MIN_ROWS or threads == 1


def test_small_batches_and_threads_1_run_inline():
    seen = []
    split_rows(2 * MIN_ROWS - 1, lambda s, e: seen.append((s, e, threading.current_thread())), threads=4)
    split_rows(10 * MIN_ROWS, lambda s, e: seen.append((s, e, threading.current_thread())), threads=1)
    assert [(s, e) for s, e, _ in seen] == [(0, 2 * MIN_ROWS - 1), (0, 10 * MIN_ROWS)]
    assert all(t is threading.current_thread() for *_, t in seen)


def test_large_batch_uses_other_threads():
    seen = set()
    lock = threading.Lock()

    def work(s, e):
        with lock:
            seen.add(threading.current_thread().name)

    split_rows(4 * MIN_ROWS, work, threads=4)
    assert threading.current_thread().name in seen and len(seen) >= 2


def test_threads_argument_is_checked():
    assert resolve_threads(None) == available_cores() >= 1
    assert resolve_threads(np.int64(3)) == 3
    for bad in (0, -1, 1.5, True, "2"):
        with pytest.raises(ValueError, match="threads must be None or an integer >= 1"):
            resolve_threads(bad)


def test_first_exception_propagates_after_every_block_finished():
    done = []
    last = blocks(6 * MIN_ROWS, 3)[-1][0]

    def work(s, e):
        if s == 0:
            raise KeyError(s)
        if s == last:
            threading.Event().wait(0.05)  # a slow block: still finished when the error reaches the caller
        done.append(s)

    with pytest.raises(KeyError):
        split_rows(6 * MIN_ROWS, work, threads=3)
    assert sorted(done) == [s for s, _ in blocks(6 * MIN_ROWS, 3)[1:]]


def test_nested_split_from_a_worker_runs_inline():
    inner = []

    def work(s, e):
        if s > 0:  # in a worker: its own split must not wait on the pool
            split_rows(10 * MIN_ROWS, lambda a, b: inner.append((a, b)), threads=4)

    split_rows(4 * MIN_ROWS, work, threads=2)
    assert inner == [(0, 10 * MIN_ROWS)]


def test_run_batch_writes_each_block_of_the_output():
    x = np.random.default_rng(1).normal(size=(3 * MIN_ROWS + 11, 3))
    out = np.full((len(x), 2), np.nan)

    def kernel(a, scale, o):
        o[:, 0] = scale * a.sum(axis=1)
        o[:, 1] = np.sin(a[:, 0])

    run_batch(kernel, [x], [out], threads=3, extra=(2.0,))
    assert np.array_equal(out[:, 0], 2.0 * x.sum(axis=1)) and np.array_equal(out[:, 1], np.sin(x[:, 0]))
