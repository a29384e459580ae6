"""The jitted one-pass level statistics (``scale._tally``) against the numpy route and the brute-force erosion."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

from denavit.scale._volume import _coarsen_numpy, _level_stats_numpy, coarsen, level_stats

pytest.importorskip("numba")

SHAPES = [(7, 7, 7), (9, 8, 11), (3, 3, 3), (5, 6), (8, 7), (3, 3), (4, 12, 5)]


def _counts(seed: int, shape: tuple, dtype) -> np.ndarray:
    rng = np.random.default_rng(seed)
    hit = rng.random(shape) < rng.uniform(0.4, 1.0)  # holes and faces of every kind
    return (rng.integers(1, 4, shape) * hit).astype(dtype)


@settings(max_examples=60, deadline=None)
@given(st.integers(0, 2**32 - 1), st.sampled_from(SHAPES), st.sampled_from([np.uint64, np.uint32]))
def test_level_stats_jitted_equal_numpy_route(seed, shape, dtype):
    c = _counts(seed, shape, dtype)
    got, want = level_stats(c, mask=True), _level_stats_numpy(c, mask=True)
    assert got[:5] == tuple(int(v) for v in want[:5])
    assert got[5].shape == c.shape and np.array_equal(got[5], want[5])
    assert level_stats(c)[:5] == got[:5] and level_stats(c)[5] is None


@settings(max_examples=30, deadline=None)
@given(st.integers(0, 2**32 - 1), st.sampled_from(SHAPES))
def test_level_stats_interior_is_the_moore_erosion(seed, shape):
    """Brute force: a cell is interior when the 3^d block around it (outside the grid: empty) is occupied."""
    c = _counts(seed, shape, np.uint64)
    inner = level_stats(c, mask=True)[5]
    padded = np.pad(c > 0, 1)
    for idx in np.ndindex(c.shape):
        assert inner[idx] == padded[tuple(slice(i, i + 3) for i in idx)].all()
    assert level_stats(c)[1] == int(inner.sum())
    assert level_stats(c)[2:5] == (int((c == 1).sum()), int((c == 2).sum()), int(c.sum()))


@settings(max_examples=40, deadline=None)
@given(st.integers(0, 2**32 - 1), st.sampled_from(SHAPES), st.sampled_from([np.uint64, np.uint32]))
def test_coarsen_jitted_equal_numpy_route(seed, shape, dtype):
    c = _counts(seed, shape, dtype)
    got = coarsen(c)
    assert got.dtype == np.uint64 and np.array_equal(got, _coarsen_numpy(c))
    assert int(got.sum()) == int(c.sum())


def test_float_and_strided_counts_take_the_numpy_route():
    c = _counts(3, (6, 6, 6), np.uint64)
    assert level_stats(c.astype(float))[:4] == level_stats(c)[:4]
    assert np.array_equal(coarsen(c[:, ::-1]), _coarsen_numpy(c[:, ::-1]))


@settings(max_examples=40, deadline=None)
@given(st.integers(0, 2**32 - 1), st.sampled_from([(9, 9, 9), (6, 6, 6), (12, 12), (7, 7)]))
def test_neighbour_rows_jitted_equal_numpy_route(seed, shape):
    """The row of each neighbour of the refined boundary cells: slot, no data (r) or interior (r + 1)."""
    from denavit.scale._refine import _neighbour_rows_numpy, neighbour_rows, refinement

    rng = np.random.default_rng(seed)
    c = _counts(seed, shape, np.uint64)
    flat_in = level_stats(c, mask=True)[5].reshape(-1)
    cells = np.flatnonzero(rng.random(c.size) < rng.uniform(0.05, 0.9))
    if cells.size == 0:
        return
    ref = refinement(cells, 2, 1)
    rows = np.flatnonzero(rng.random(cells.size) < 0.7)
    got = neighbour_rows(shape, ref, rows, flat_in)
    assert got.shape == (3 ** len(shape), rows.size)
    assert np.array_equal(got, _neighbour_rows_numpy(shape, ref, rows, flat_in))


@settings(max_examples=30, deadline=None)
@given(st.integers(0, 2**32 - 1), st.integers(1, 200), st.sampled_from([np.uint64, np.uint32]))
def test_merge_adds_the_counts_without_flags_and_zeroes_the_part(seed, size, dtype):
    from denavit.scale._tally import merge

    rng = np.random.default_rng(seed)
    part = (rng.integers(0, 2**31, size) * (rng.random(size) < rng.uniform(0, 0.3))).astype(np.uint32)
    part |= np.where(rng.random(size) < 0.2, np.uint32(2**31), np.uint32(0))  # flagged cells, counted or not
    total = rng.integers(0, 2**20, size).astype(dtype)
    want = total + (part & np.uint32(2**31 - 1)).astype(dtype)
    merge(total, part)
    assert np.array_equal(total, want) and not part.any()


@settings(max_examples=40, deadline=None)
@given(st.integers(0, 2**32 - 1), st.sampled_from([(9, 9, 9), (8, 8, 8), (7, 10, 6), (12, 12), (13, 11)]))
def test_shell_children_jitted_equal_numpy_route(seed, shape):
    """The cells to refine: children (off ``inner``) of the shell's parents, listed in one pass or by numpy."""
    from denavit.scale._refine import _children_numpy, _shell_cells
    from denavit.scale._tally import children3

    rng = np.random.default_rng(seed)
    inner = rng.random(shape) < 0.3
    shell = rng.random(tuple((s + 1) // 2 for s in shape)) < rng.uniform(0.1, 0.9)
    lift = (1,) * (3 - len(shape))
    out = np.empty(inner.size, np.int64)
    n = children3(shell.reshape(lift + shell.shape), inner.reshape(lift + inner.shape), out)
    want = _children_numpy(shell, inner)
    assert np.array_equal(out[:n], want)
    up = shell[tuple(np.indices(shape) // 2)]  # the grid upsampled: the definition, by a third route
    assert np.array_equal(want, np.flatnonzero(up & ~inner))
    c = _counts(seed, shape, np.uint64)
    inner_c = level_stats(c, mask=True)[5]
    assert np.all(np.diff(_shell_cells(c, inner_c)) > 0)


def test_a_run_without_numba_gives_the_same_estimate():
    """The whole occupancy run in a process where numba cannot be imported (every pass on its numpy route: the
    sampler, the level statistics, the plan, the refined levels) against this process's (jitted passes)."""
    import json
    import subprocess
    import sys

    import denavit
    from denavit.scale import PositionFK, occupancy

    code = ("import sys, json; sys.modules['numba'] = None\n"
            "import denavit; from denavit.scale import occupancy\n"
            "for name in ('planar2r', 'puma560'):\n"
            "    ws = occupancy(denavit.load_robot(name), 300_000, seed=5, scheduler='synchronous', refine=2)\n"
            "    print(json.dumps([ws.counts.sum().item(), ws.refinement.cells.tolist(), int(ws.fine.sum()),\n"
            "                      [e.summary() for e in ws.levels]]))\n")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout.splitlines()
    for name, line in zip(("planar2r", "puma560"), out):
        robot = denavit.load_robot(name)
        ws = occupancy(robot, 300_000, seed=5, scheduler="synchronous", refine=2, fk=PositionFK(robot))
        total, cells, fine, levels = json.loads(line)
        assert total == int(ws.counts.sum()) and cells == ws.refinement.cells.tolist() and fine == int(ws.fine.sum())
        assert levels == [e.summary() for e in ws.levels]
