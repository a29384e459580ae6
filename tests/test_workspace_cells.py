"""The fused kernel's cell step (``scale._fused._cells``) against numpy: cells, sub-cells, bounds, reach and
the status of origins outside the grid or not finite."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

pytest.importorskip("numba")

from denavit.scale._fused import NON_FINITE, OK, OUTSIDE, _cells  # noqa: E402

SIDE, H, K = 64, 0.05, 4
CENTRE, ORIGIN = np.array([0.1, -0.2, 0.3]), np.array([0.05, 0.0, -0.1])
LO = -0.5 * SIDE * H


def _grid():
    return np.array([*CENTRE, LO, 1.0 / H, K])


def _basis(kind: str) -> tuple[np.ndarray, np.ndarray]:
    if kind == "3d":
        return np.eye(3), np.arange(3)
    if kind == "xz":
        return np.eye(3)[[0, 2]], np.array([0, 2])
    b = np.linalg.qr(np.random.default_rng(7).normal(size=(3, 3)))[0][:2]  # a tilted plane
    return np.ascontiguousarray(b), np.empty(0, np.int64)


def _run(P: np.ndarray, kind: str, steps: int = 1):
    """Cells, sub-cells and stats of P (3, m), in ``steps`` equal steps as the kernel takes them."""
    basis, axes = _basis(kind)
    m = P.shape[1]
    cells, sub = np.empty(m, np.int32), np.empty(m, np.int32)
    stats = np.array([np.inf] * 3 + [-np.inf] * 3 + [0.0])
    statuses = []
    for part in np.array_split(np.arange(m), steps):
        Pp = np.ascontiguousarray(P[:, part])
        c, t = np.empty(part.size, np.int32), np.empty(part.size, np.int32)
        statuses.append(_cells(Pp, part.size, _grid(), basis, axes, SIDE, ORIGIN, c, stats, t))
        cells[part], sub[part] = c, t
    return cells, sub, stats, statuses


@settings(max_examples=40, deadline=None)
@given(st.integers(0, 2**32 - 1), st.sampled_from(["3d", "xz", "tilted"]), st.integers(1, 5))
def test_cells_bounds_and_reach_are_numpys(seed, kind, steps):
    rng = np.random.default_rng(seed)
    basis, _ = _basis(kind)
    u = rng.uniform(LO * 0.99, -LO * 0.99, (basis.shape[0], 300))  # inside the grid, in its basis
    P = (CENTRE[:, None] + basis.T @ u)  # (3, m): on the plane for a planar grid
    cells, sub, stats, statuses = _run(P, kind, steps)
    assert statuses == [OK] * steps
    T = (((P - CENTRE[:, None]).T @ basis.T).T - LO) / H  # (dim, m) coordinates in cell edges
    want = np.ravel_multi_index(tuple(np.floor(T).astype(int)), (SIDE,) * basis.shape[0])
    assert np.array_equal(cells, want)
    fine = np.floor(T * K).astype(int)  # the sub-cell grid K times finer: its index within the cell, row-major
    assert np.array_equal(sub, np.ravel_multi_index(tuple(fine - K * np.floor(T).astype(int)), (K,) * len(T)))
    assert np.array_equal(stats[:3], P.min(axis=1)) and np.array_equal(stats[3:6], P.max(axis=1))
    d = P - ORIGIN[:, None]
    assert stats[6] == (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).max()


@pytest.mark.parametrize("kind", ["3d", "xz", "tilted"])
@pytest.mark.parametrize("bad", [np.nan, np.inf, -np.inf])
def test_a_non_finite_origin_fails_the_step(kind, bad):
    rng = np.random.default_rng(1)
    basis, _ = _basis(kind)
    P = CENTRE[:, None] + basis.T @ rng.uniform(-0.5, 0.5, (basis.shape[0], 50))
    for axis in range(3):  # also the coordinate off a planar grid's plane
        Q = P.copy()
        Q[axis, 17] = bad
        assert _run(Q, kind)[3] == [NON_FINITE]


@pytest.mark.parametrize("kind", ["3d", "xz", "tilted"])
def test_a_finite_origin_outside_the_grid_is_reported(kind):
    basis, _ = _basis(kind)
    P = np.repeat(CENTRE[:, None], 20, axis=1)
    P[:, 5] += basis[0] * (-LO * 1.01)  # just past the grid's face along its first axis
    assert _run(P, kind)[3] == [OUTSIDE]
