"""The fused workspace task (denavit.scale._fused / _sink) against the numpy route.

Oracles: SplitMix64 stepped in Python integers (the fused kernel's random words), the numpy route of
``run_task`` (SplitMix64 in numpy, the compiled position kernel's batch call, numpy cell arithmetic and a sort) on
random arms, and the same run on other chunk sizes, workers, accumulators and schedulers (identical counts).
Memory: tracemalloc peaks (not wall clock) and the accumulators' budget arithmetic.
"""

from __future__ import annotations

import dataclasses
import tracemalloc
from types import SimpleNamespace

import numpy as np
import pytest
from _occupancy_same import NumpyRoute, same_occupancy, stanford_routes
from _random_robots import random_robot

import denavit
from denavit import JointType
from denavit.scale import BLOCK, CompiledPositionFK, occupancy

pytest.importorskip("numba")

from denavit.scale import _fused, _sink
from denavit.scale._refine import plan_refinement
from denavit.scale._sampler import make_job, run_task


def _limited(robot):
    """The arm with limits on its prismatic rows (a workspace needs them)."""
    links = tuple(dataclasses.replace(link, q_limits=(-0.4, 0.7)) if link.joint is JointType.PRISMATIC else link
                  for link in robot.links)
    return robot.replace(links=links)


def _sorted(idx, cnt):
    order = np.argsort(idx, kind="stable")
    return np.asarray(idx)[order].astype(np.int64), np.asarray(cnt)[order].astype(np.int64)


def _same_task(a, b):
    for (ia, ca), (ib, cb) in (((a[0], a[1]), (b[0], b[1])), ((a[6], a[7]), (b[6], b[7]))):
        ia, ca = _sorted(ia, ca)
        ib, cb = _sorted(ib, cb)
        assert np.array_equal(ia, ib) and np.array_equal(ca, cb)
    assert np.array_equal(a[2], b[2]) and np.array_equal(a[3], b[3])  # bounds, bit for bit
    assert a[4] == b[4] and a[5] == b[5]  # reach, samples


def _splitmix64(state: int, count: int) -> list[int]:
    """``count`` outputs of SplitMix64 from ``state``, stepped one at a time in Python integers (Vigna's
    splitmix64.c: state += γ, then the output function)."""
    out, m = [], 2**64
    for _ in range(count):
        state = (state + 0x9E3779B97F4A7C15) % m
        z = ((state ^ (state >> 30)) * 0xBF58476D1CE4E5B9) % m
        z = ((z ^ (z >> 27)) * 0x94D049BB133111EB) % m
        out.append(z ^ (z >> 31))
    return out


def test_splitmix64_reference_vector_and_block_starts():
    """The published first outputs of SplitMix64 from state 0; block b of a seed starts 2³² words after
    block b − 1 of one stream keyed by SeedSequence(seed) (blocks cannot overlap)."""
    assert _splitmix64(0, 3) == [0xE220A8397B1DCDAF, 0x6E789E6AA1B965F4, 0x06C45D188009454F]
    key = int(np.random.SeedSequence(77).generate_state(1, np.uint64)[0])
    states = _fused.block_keys(77, 5, 3)
    for i, s in enumerate(states):
        assert int(s) == (key + (5 + i) * 2**32 * 0x9E3779B97F4A7C15) % 2**64


def test_random_values_are_the_halves_of_splitmix64_words_across_calls():
    """Rows drawn in pieces (starting mid-way through a word) are lo + (h·2⁻³²)·span, h the 32-bit halves
    (low first) of the block's SplitMix64 words stepped in Python integers, and the numpy route's rows too; the
    words holding no joint the position program reads are skipped, and only those."""
    from denavit.scale._stream import draw as _draw

    for seed, block, n in ((3, 0, 5), (2**40 + 7, 12, 2), (0, 3, 6), (9, 1, 1)):
        state = _fused.block_keys(seed, block, 1)[0]
        words = _splitmix64(int(state), -(-41 * n // 2))
        h = np.array([half for w in words for half in (w & 0xFFFFFFFF, w >> 32)][:41 * n], float).reshape(41, n)
        lo, hi = np.linspace(-1, 1, n), np.linspace(0.5, 3, n) + 1.0
        span = hi - lo  # as the numpy route computes it
        ref = h * 2.0**-32 * span + lo
        for cut in (3, 4):  # an odd n: half a period, then a start mid-way through a word (3); whole periods (4)
            q = np.empty((n, 41))  # sample i's joint a in q[a, i]
            j = _fused._draw(q, cut, 0, state, lo, span, np.ones(n, bool))
            assert j == cut * n
            assert _fused._draw(q[:, cut:], 41 - cut, j, state, lo, span, np.ones(n, bool)) == 41 * n
            assert np.array_equal(q.T, ref)
        for used in np.eye(n, dtype=bool):  # one joint read: its word drawn, the others' entries left alone
            q = np.full((n, 40), 7.0)
            assert _fused._draw(q, 40, 0, state, lo, span, used) == 40 * n
            assert np.array_equal(q[used], ref[:40, used].T)
            pairs = np.arange(n * 40).reshape(40, n).T // 2  # the word of each value
            drawn = np.isin(pairs, pairs[used])
            assert np.array_equal(q[drawn], ref[:40].T[drawn]) and np.all(q[~drawn] == 7.0)
        job = SimpleNamespace(entropy=seed, limits=np.stack([lo, hi], axis=1))
        assert np.array_equal(_draw(job, block, np.empty((41, n))), ref)
        assert 0 <= h.min() and h.max() < 2**32 and len(np.unique(h)) > 40 * n  # 32 random bits each


def test_joint_values_are_uniform_over_the_limits():
    """Kolmogorov–Smirnov distance of 2¹⁸ joint values of each joint from the uniform law on its range, and the
    correlation of consecutive values (the joints of a sample, and one sample's last with the next one's first),
    within 5 standard errors."""
    from denavit.scale._stream import draw as _draw

    n, m = 3, 2**18
    lo, hi = np.array([-np.pi, -1.0, 0.2]), np.array([np.pi, 2.5, 0.3])
    q = _draw(SimpleNamespace(entropy=12345, limits=np.stack([lo, hi], axis=1)), 4, np.empty((m, n)))
    u = (q - lo) / (hi - lo)
    grid = np.arange(1, m + 1) / m
    for a in range(n):
        assert np.abs(np.sort(u[:, a]) - grid).max() < 1.63 / np.sqrt(m) + 1 / m  # KS at the 1 % level
    flat = u.reshape(-1) - 0.5
    assert abs(np.mean(flat[1:] * flat[:-1]) / np.mean(flat * flat)) < 5 / np.sqrt(flat.size)


def test_fused_tasks_equal_the_numpy_route_on_random_arms():
    rng = np.random.default_rng(11)
    for _ in range(2):
        robot = _limited(random_robot(rng))
        job = make_job(robot, 3 * BLOCK + 777, None, int(rng.integers(2**40)), CompiledPositionFK(robot))
        assert job.fused
        numpy_job = dataclasses.replace(job, fused=False)
        ref = run_task(numpy_job, 0, 4)
        _same_task(run_task(job, 0, 4), ref)  # away from a sink: sparse counts from the first-hit list
        _same_task(run_task(job, 1, 2), run_task(numpy_job, 1, 2))
        counts = np.zeros(job.grid.shape, np.uint64)
        counts.reshape(-1)[ref[0]] += ref[1]
        plan = plan_refinement(counts, 4, 1)
        if plan is not None:  # sub-cells too
            a, b = run_task(dataclasses.replace(job, refine=plan), 1, 3), run_task(
                dataclasses.replace(numpy_job, refine=plan), 1, 3)
            assert a[6].size > 0
            _same_task(a, b)
            _same_task(run_task(job, 0, 4), ref)  # this thread's accumulator again, its refined flags cleared


def test_tilted_plane_cells_are_the_numpy_routes():
    """A planar arm whose plane is no coordinate plane: the projection onto the plane's basis in one order."""
    robot = denavit.load_robot("planar2r")
    tilt = np.eye(4)
    tilt[:3, :3] = np.array([[1, 0, 0], [0, 0.6, -0.8], [0, 0.8, 0.6]])
    robot = robot.replace(base=tilt)
    job = make_job(robot, 2 * BLOCK, None, 5, CompiledPositionFK(robot))
    assert job.grid.dim == 2 and not np.all(np.isin(job.grid.basis, (0.0, 1.0, -1.0)))
    _same_task(run_task(job, 0, 2), run_task(dataclasses.replace(job, fused=False), 0, 2))


def test_coordinate_plane_cells_are_the_numpy_routes():
    """A planar arm in a coordinate plane (the fused kernel reads the plane's two coordinates directly; the numpy
    route projects on the basis): the same cells, refined sub-cells and bounds."""
    robot = denavit.load_robot("planar2r")
    job = make_job(robot, 3 * BLOCK, None, 8, CompiledPositionFK(robot))
    assert job.grid.dim == 2 and np.all(np.isin(job.grid.basis, (0.0, 1.0)))
    numpy_job = dataclasses.replace(job, fused=False)
    ref = run_task(numpy_job, 0, 1)
    _same_task(run_task(job, 0, 1), ref)
    counts = np.zeros(job.grid.shape, np.uint64)
    counts.reshape(-1)[ref[0]] += ref[1]
    plan = plan_refinement(counts, 2, 1)
    a = run_task(dataclasses.replace(job, refine=plan), 1, 2)
    assert a[6].size > 0
    _same_task(a, run_task(dataclasses.replace(numpy_job, refine=plan), 1, 2))


def test_identical_for_chunks_workers_accumulators_and_routes(monkeypatch):
    robot, n, args, ref, fk = stanford_routes()
    monkeypatch.setattr(_sink, "_MOST", BLOCK + 1)  # an accumulator flushed before nearly every task
    monkeypatch.setattr(_sink, "ACC_BUDGET", 1)  # one accumulator for three threads
    same_occupancy(ref, occupancy(robot, n, scheduler="threads", workers=3, chunk=BLOCK, fk=fk, **args))


@pytest.mark.slow
def test_identical_on_a_process_pool_with_the_fused_kernel():
    robot = denavit.load_robot("puma560")
    n = 4 * BLOCK + 5
    ref = occupancy(robot, n, 0.05, seed=8, scheduler="synchronous", fk=NumpyRoute(robot), refine=2)
    same_occupancy(ref, occupancy(robot, n, 0.05, seed=8, scheduler="processes", workers=2, chunk=BLOCK,
                         fk=CompiledPositionFK(robot), refine=2))


def test_auto_runs_fused_tasks_on_threads():
    from denavit.scale._occupancy import _where
    from denavit.scale._sampler import COMPILED_FROM

    robot = denavit.load_robot("planar2r")
    assert _where("auto", COMPILED_FROM, None, robot) == "threads"
    assert _where("auto", 10**8, NumpyRoute(robot), robot) == "processes"  # another FK: the old rule
    assert _where("processes", 10**8, None, robot) == "processes"


def test_accumulators_stay_within_their_budget():
    for cells, refinable in ((256**3, True), (2048**2, True), (2048**2, False), (8**3, False)):
        sink = _sink.Sink(np.zeros(cells, np.uint64), 64, refinable)
        per = 4 * cells + (4 * 2**25 if refinable else 0)
        assert sink.cap == 1 or sink.cap * per <= _sink.ACC_BUDGET
        assert sink.cap <= 64


def test_memory_does_not_grow_with_the_samples():
    """Peak traced allocations (numpy's included) of a run in this process: the same for 4 and 24 blocks, and
    within the grid-sized arrays (driver counts, one accumulator, the estimate's levels) plus scratch."""
    robot = denavit.load_robot("planar2r")
    fk = CompiledPositionFK(robot)
    occupancy(robot, BLOCK, 0.01, seed=1, scheduler="synchronous", fk=fk)  # kernels compiled or loaded first
    peaks = []
    for n in (4 * BLOCK, 24 * BLOCK):
        tracemalloc.start()
        ws = occupancy(robot, n, 0.01, seed=1, scheduler="synchronous", fk=fk, refine=0)
        peaks.append(tracemalloc.get_traced_memory()[1])
        tracemalloc.stop()
    cells = ws.counts.size
    assert peaks[1] <= peaks[0] + 2**20, peaks
    assert peaks[1] <= (8 + 4 + 8) * cells + 16 * 2**20, (peaks, cells)
    job = make_job(robot, 10**9, None, 1, fk)
    sink_job = dataclasses.replace(job, sink="run")
    assert _sink.task_memory(sink_job, 4) == _sink.task_memory(dataclasses.replace(sink_job, samples=BLOCK), 4)
    # a task in the driver's process holds no sample-sized array: less than a double per sample of one block
    assert _sink.task_memory(sink_job, 64) < 8 * BLOCK


def test_progress_line_of_a_fused_run(capsys):
    robot = denavit.load_robot("planar2r")
    occupancy(robot, 3 * BLOCK, seed=0, scheduler="threads", workers=2, chunk=BLOCK, progress=True,
              fk=CompiledPositionFK(robot))
    err = capsys.readouterr().err
    assert "100.0%" in err and "samples/s" in err and "ETA" in err and err.endswith("\n")


def test_a_process_without_numba_takes_the_numpy_route(monkeypatch):
    """A fused job reaching a worker without numba is counted by the numpy route: the same numbers."""
    import denavit.scale._sampler as sampler

    robot = denavit.load_robot("planar2r")
    job = make_job(robot, 2 * BLOCK, None, 3, CompiledPositionFK(robot))
    fused = run_task(job, 0, 2)
    monkeypatch.setattr(sampler, "_has_numba", lambda: False)
    numpy_route = run_task(job, 0, 2)
    assert np.all(np.diff(numpy_route[0]) > 0)  # the numpy route's sorted cells (the fused ones are not)
    _same_task(fused, numpy_route)
