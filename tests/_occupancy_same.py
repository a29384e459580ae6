"""Shared by the workspace identity tests (tests/test_workspace_fused.py, tests/test_workspace_strata.py): one
occupancy run compared with another, bit for bit, and the run of the Stanford arm that both files check across
routes, chunks and workers."""

from __future__ import annotations

import numpy as np

import denavit
from denavit.scale import BLOCK, CompiledPositionFK, occupancy


class NumpyRoute(CompiledPositionFK):
    """The same compiled kernel, but not the exact class: tasks take the numpy route."""


def same_occupancy(a, b) -> None:
    """Two runs agree exactly: counts, bounds, reach, the volume estimate and the refined sub-cells."""
    assert np.array_equal(a.counts, b.counts) and a.estimate == b.estimate and a.reach == b.reach
    assert np.array_equal(a.bounds_min, b.bounds_min) and np.array_equal(a.bounds_max, b.bounds_max)
    assert (a.fine is None) == (b.fine is None)
    if a.fine is not None:
        assert np.array_equal(a.fine, b.fine) and np.array_equal(a.refinement.cells, b.refinement.cells)


def stanford_routes():
    """The Stanford arm's run by the numpy route in one chunk per block (the reference, with refined cells), checked
    against the fused kernel in chunks of two blocks and on two threads; returns what a caller checks further:
    ``(robot, n, args, ref, fk)``."""
    robot = denavit.load_robot("stanford")
    n = 5 * BLOCK + 999
    args = {"resolution": 0.1, "seed": 42, "refine": 4}
    ref = occupancy(robot, n, scheduler="synchronous", chunk=BLOCK, fk=NumpyRoute(robot), **args)
    assert ref.refinement is not None and ref.fine.sum() > 0
    fk = CompiledPositionFK(robot)
    same_occupancy(ref, occupancy(robot, n, scheduler="synchronous", chunk=2 * BLOCK, fk=fk, **args))
    same_occupancy(ref, occupancy(robot, n, scheduler="threads", workers=2, chunk=BLOCK, fk=fk, **args))
    return robot, n, args, ref, fk
