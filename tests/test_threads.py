"""threads= on batch calls: the splitting helper, then the compiled and plain functions split by it.

The truth for every split call is the same call unsplit (threads=1): the blocks must reproduce it bit for bit.
No timing is asserted here (benchmarks/bench_threads.py measures the speed-up)."""

from __future__ import annotations

import os
import threading
from dataclasses import replace
from itertools import pairwise

import numpy as np
import pytest
from test_dynamics_numeric import random_robot as random_dynamic_robot

import denavit
from denavit._threads import (
    ALIGN,
    MIN_ROWS,
    available_cores,
    blocks,
    resolve_threads,
    run_batch,
    split_call,
    split_rows,
)
from denavit.codegen import numba_available
from denavit.errors import ModelError, ShapeError


# --- the helper --------------------------------------------------------------------------------------------
@pytest.mark.parametrize("rows", [0, 1, 7, MIN_ROWS, 2 * MIN_ROWS - 1, 2 * MIN_ROWS, 3 * MIN_ROWS + 5, 100_003])
@pytest.mark.parametrize("threads", [1, 2, 3, 8])
def test_blocks_cover_the_rows_once_in_order(rows, threads):
    parts = blocks(rows, threads)
    assert parts[0][0] == 0 and parts[-1][1] == rows
    assert all(a[1] == b[0] for a, b in pairwise(parts))  # contiguous, in order, no overlap
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


def test_exception_of_a_worker_block_reaches_the_caller():
    def work(s, e):
        if s > 0:
            raise ArithmeticError(f"block at {s}")

    with pytest.raises(ArithmeticError, match="block at"):
        split_rows(4 * MIN_ROWS, work, threads=2)


def test_nested_split_from_a_worker_runs_inline():
    inner = []

    def work(s, e):
        if s > 0:  # in a worker: its own split must not wait on the pool
            split_rows(10 * MIN_ROWS, lambda a, b: inner.append((a, b)), threads=4)

    split_rows(4 * MIN_ROWS, work, threads=2)
    assert inner == [(0, 10 * MIN_ROWS)]


def _split_in_child(conn):
    seen = []
    split_rows(4 * MIN_ROWS, lambda s, e: seen.append(s), threads=2)
    conn.send(sorted(seen))


@pytest.mark.skipif(not hasattr(os, "fork"), reason="no fork on this platform")
def test_a_forked_child_makes_its_own_pool():
    """A child forked after the pool started has the pool object but none of its threads: it must not queue
    blocks there (they would never run)."""
    import multiprocessing

    split_rows(4 * MIN_ROWS, lambda s, e: None, threads=2)  # the pool exists, with its threads
    ctx = multiprocessing.get_context("fork")
    parent, child = ctx.Pipe()
    p = ctx.Process(target=_split_in_child, args=(child,))
    p.start()
    got = parent.recv() if parent.poll(60) else None
    p.join(10)
    if p.is_alive():  # pragma: no cover (the failure this test is for)
        p.kill()
    assert got == [s for s, _ in blocks(4 * MIN_ROWS, 2)]


def test_run_batch_writes_each_block_of_the_output():
    x = np.random.default_rng(1).normal(size=(3 * MIN_ROWS + 11, 3))
    out = np.full((len(x), 2), np.nan)

    def kernel(a, scale, o):
        o[:, 0] = scale * a.sum(axis=1)
        o[:, 1] = np.sin(a[:, 0])

    run_batch(kernel, [x], [out], threads=3, extra=(2.0,))
    assert np.array_equal(out[:, 0], 2.0 * x.sum(axis=1)) and np.array_equal(out[:, 1], np.sin(x[:, 0]))



@pytest.mark.parametrize("threads", [1, 2, 3])
@pytest.mark.parametrize("chunk", [None, 1000, 4099])
def test_split_call_joins_blocks_and_pieces_in_order(threads, chunk):
    x = np.random.default_rng(2).normal(size=(3, 4 * MIN_ROWS + 5, 2))
    y = np.random.default_rng(3).normal(size=(3, 4 * MIN_ROWS + 5, 4))
    calls = []

    def func(a, b):
        calls.append(len(a))
        return np.stack([a.sum(axis=1), np.sin(b[:, 0]), b[:, 1] * a[:, 0]], axis=1)[:, :, None] * [1.0, 2.0]

    whole = func(x.reshape(-1, 2), y.reshape(-1, 4)).reshape(3, -1, 3, 2)
    calls.clear()
    got = split_call(func, (x, y), threads, chunk=chunk)
    if threads == 1 and chunk is None:
        assert got is None and calls == []  # one block, no pieces: the caller computes it whole
        return
    assert got.shape == whole.shape and np.array_equal(got, whole)
    assert sum(calls) == x.shape[0] * x.shape[1] and max(calls) <= (chunk or len(x.reshape(-1, 2)))


def test_split_call_small_batches_are_left_to_the_caller():
    assert split_call(lambda a: a, (np.zeros((MIN_ROWS, 2)),), 4, chunk=None) is None
    assert split_call(lambda a: a, (np.zeros(2),), 4) is None
    with pytest.raises(ValueError, match="threads"):
        split_call(lambda a: a, (np.zeros(2),), 0)


# --- the batch functions -------------------------------------------------------------------------------------
ODD = 2 * MIN_ROWS + 2 * ALIGN + 3  # two or three blocks, the last one short, not a multiple of the SIMD width


@pytest.fixture(autouse=True)
def _cache(tmp_path_factory, monkeypatch):
    """The kernel folder test_codegen uses (one per run, shared by xdist workers)."""
    base = tmp_path_factory.getbasetemp()
    if os.environ.get("PYTEST_XDIST_WORKER"):
        base = base.parent
    monkeypatch.setenv("DENAVIT_CACHE_DIR", str(base / "kernels"))


def _calls(robot, fast=None):
    """name -> f(q, qd, qdd_or_tau, threads) for the plain functions, or the compiled object's methods."""
    if fast is None:
        d = denavit
        return {"fk": lambda q, qd, a, t: d.forward_kinematics(robot, q, threads=t),
                "frames": lambda q, qd, a, t: d.link_transforms(robot, q, threads=t),
                "J0": lambda q, qd, a, t: d.geometric_jacobian(robot, q, threads=t),
                "Je": lambda q, qd, a, t: d.geometric_jacobian(robot, q, "tool", threads=t),
                "J1": lambda q, qd, a, t: d.geometric_jacobian(robot, q, 1, threads=t),
                "rnea": lambda q, qd, a, t: d.rnea(robot, q, qd, a, threads=t),
                "M": lambda q, qd, a, t: d.mass_matrix(robot, q, threads=t),
                "g": lambda q, qd, a, t: d.gravity_torques(robot, q, threads=t),
                "c": lambda q, qd, a, t: d.coriolis_vector(robot, q, qd, threads=t),
                "FD": lambda q, qd, a, t: d.forward_dynamics(robot, q, qd, a, threads=t)}
    f = fast
    return {"fk": lambda q, qd, a, t: f.fk(q, threads=t), "frames": lambda q, qd, a, t: f.fk(q, True, threads=t),
            "position": lambda q, qd, a, t: f.position(q, threads=t),
            "J0": lambda q, qd, a, t: f.jacobian(q, threads=t), "Je": lambda q, qd, a, t: f.jacobian(q, "tool", threads=t),
            "rnea": lambda q, qd, a, t: f.rnea(q, qd, a, threads=t), "M": lambda q, qd, a, t: f.mass_matrix(q, threads=t),
            "g": lambda q, qd, a, t: f.gravity(q, threads=t), "c": lambda q, qd, a, t: f.coriolis(q, qd, threads=t),
            "FD": lambda q, qd, a, t: f.forward_dynamics(q, qd, a, threads=t)}


ROBOT = random_dynamic_robot(np.random.default_rng(25), n=3, friction=True)
_NUMBA = pytest.mark.skipif(not numba_available(), reason="numba not installed")


@pytest.fixture(scope="module", params=[None, "numpy", pytest.param("numba", marks=[pytest.mark.slow, _NUMBA])],
                ids=["plain", "numpy", "numba"])
def subject(request):
    """The plain functions, and the compiled object on each backend (numba's ten kernels compile in ~20 s
    on a busy machine: slow; test_numba_blocks_bit_for_bit covers its batch loop quickly)."""
    return ROBOT, request.param


@_NUMBA
def test_numba_blocks_bit_for_bit():
    """The SIMD batch loop (4 rows at once, the last lanes masked) gives each row the same bits whatever
    block holds it, on block boundaries that are not multiples of 4 from the batch's end."""
    fast = denavit.compile(ROBOT, backend="numba", kernels=("fk",))
    q = np.random.default_rng(9).uniform(-3, 3, (ODD, ROBOT.dof))
    ref = fast.fk(q, threads=1)
    np.testing.assert_allclose(ref, denavit.forward_kinematics(ROBOT, q), rtol=0, atol=1e-12)
    for t in (2, 3, None):
        assert np.array_equal(fast.fk(q, threads=t), ref)
    assert np.array_equal(fast.fk(q[:0], threads=2), np.zeros((0, 4, 4)))



@_NUMBA
def test_generated_batch_loops_release_the_gil():
    """What the threads rely on: every generated batch function and the IK batch solver are jitted with
    nogil=True (read from numba's own options of the loaded module, not from the generator's text)."""
    module = denavit.compile(ROBOT, backend="numba")._m  # numba compiles each function on its first call only
    loops = [getattr(module, k) for k in dir(module) if k.endswith("_n") or k in ("ik_lm", "ik_check")]
    assert {"fk_n", "rnea_n", "forward_dynamics_n", "ik_lm"} <= set(dir(module))
    assert all(f.targetoptions.get("nogil") is True for f in loops)


def _functions(subject):
    robot, backend = subject
    return _calls(robot, None if backend is None else denavit.compile(robot, backend=backend))


def test_split_results_are_the_unsplit_ones_bit_for_bit(subject):
    robot, _ = subject
    rng = np.random.default_rng(7)
    q, qd, a = (rng.uniform(-3, 3, (ODD, robot.dof)) for _ in range(3))
    for name, f in _functions(subject).items():
        whole = np.stack([f(q[k], qd[k], a[k], 1) for k in (0, ODD // 2, ODD - 1)])  # single calls: no batch code
        ref = f(q, qd, a, 1)
        np.testing.assert_allclose(ref[[0, ODD // 2, ODD - 1]], whole, rtol=1e-12, atol=1e-12, err_msg=name)
        for t in (2, 3, None):
            got = f(q, qd, a, t)
            assert got.shape == ref.shape and np.array_equal(got, ref), (name, t)


def test_plain_pieces_are_the_whole_batch_bit_for_bit(monkeypatch):
    """The plain functions cut a batch into NUMPY_CHUNK-row pieces even on one thread: the same bits as one
    pass over the whole batch (NUMPY_CHUNK made larger than the batch)."""
    import denavit._threads as threads_module

    rng = np.random.default_rng(11)
    q, qd, a = (rng.uniform(-3, 3, (2 * threads_module.NUMPY_CHUNK + 17, ROBOT.dof)) for _ in range(3))
    calls = _calls(ROBOT)
    pieces = {name: f(q, qd, a, 1) for name, f in calls.items()}
    monkeypatch.setattr(threads_module, "NUMPY_CHUNK", 10**9)
    for name, f in calls.items():
        whole = f(q, qd, a, 1)
        assert np.array_equal(pieces[name], whole), name


def test_batch_shapes_kept_and_empty_batches(subject):
    robot, _ = subject
    n = robot.dof
    rng = np.random.default_rng(8)
    q, qd, a = (rng.uniform(-3, 3, (2, MIN_ROWS + 1, n)) for _ in range(3))  # 2 x 4097: split, 3-D
    for name, f in _functions(subject).items():
        got = f(q, qd, a, 2)
        flat = f(q.reshape(-1, n), qd.reshape(-1, n), a.reshape(-1, n), 1)
        assert got.shape == (2, MIN_ROWS + 1) + flat.shape[1:], name
        assert np.array_equal(got.reshape(flat.shape), flat), name
        assert np.array_equal(f(q, qd[0], a[0, 0], 3), f(q, np.broadcast_to(qd[0], q.shape), np.broadcast_to(
            a[0, 0], q.shape), 1)), name  # inputs broadcast before the split
        empty = f(np.zeros((0, n)), np.zeros((0, n)), np.zeros((0, n)), 2)
        assert empty.shape == (0,) + flat.shape[1:], name


def test_bad_shapes_and_bad_threads_refused(subject):
    robot, _ = subject
    n = robot.dof
    for f in _functions(subject).values():
        with pytest.raises(ShapeError):
            f(np.zeros((3 * MIN_ROWS, n + 1)), np.zeros((3 * MIN_ROWS, n + 1)), np.zeros((3 * MIN_ROWS, n + 1)), 2)
        with pytest.raises(ValueError, match="threads"):
            f(np.zeros((5, n)), np.zeros((5, n)), np.zeros((5, n)), 0)
    f = _functions(subject)["rnea"]
    with pytest.raises(ValueError, match="broadcast"):  # batches that do not broadcast (ShapeError compiled)
        f(np.zeros((3 * MIN_ROWS, n)), np.zeros((2, n)), np.zeros(n), 2)


def test_singular_block_raises_in_the_caller():
    rng = np.random.default_rng(3)
    dyn = random_dynamic_robot(rng, n=3, fixed_rows=False, prismatic=False)
    last = dyn.links[-1]
    massless = replace(dyn, links=dyn.links[:-1] + (replace(last, inertia=None),))  # M singular everywhere
    q = np.zeros((3 * MIN_ROWS, 3))
    with pytest.raises(ModelError, match="singular"):
        denavit.forward_dynamics(massless, q, q, q + 1.0, threads=3)
    with pytest.raises(ModelError, match="singular"):
        denavit.compile(massless, backend="numpy").forward_dynamics(q, q, q + 1.0, threads=3)


@_NUMBA
@pytest.mark.slow
def test_compiled_solve_ik_batch_independent_of_threads():
    """Each target's random restarts come from its own stream: the answers (and iteration and restart counts)
    of a split batch are those of the whole batch in one thread; the answers are judged by the plain FK."""
    robot = denavit.load_robot("puma560")
    fast = denavit.compile(robot)
    lim = robot.q_limits
    Q = np.random.default_rng(4).uniform(lim[:, 0], lim[:, 1], (203, robot.dof))
    T = denavit.forward_kinematics(robot, Q).reshape(7, 29, 4, 4)
    runs = [fast.solve_ik(T, rng=np.random.default_rng(5), threads=t) for t in (1, 2, 3)]
    assert runs[0].q.shape == (7, 29, 6) and runs[0].success.shape == (7, 29)
    assert runs[0].restarts.sum() > 0  # some targets needed random restarts: their streams are compared too
    for r in runs[1:]:
        for field in ("q", "success", "iterations", "restarts", "position_error", "orientation_error"):
            assert np.array_equal(getattr(r, field), getattr(runs[0], field)), field
    ok = runs[0].success
    assert ok.mean() > 0.9
    np.testing.assert_allclose(denavit.forward_kinematics(robot, runs[0].q[ok]), T[ok], atol=1e-8)
