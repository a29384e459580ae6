"""Volume (or area) of the reachable set from voxel counts, with an interval.

At a cell edge h, let O be the occupied cells (at least one sample), I ⊂ O the *interior* cells (every one of
the 3^d − 1 neighbours occupied too) and m̂ the Chao1 estimate of cells that meet the reachable set W but have
not been hit yet (from the cells hit once, f1, and twice, f2; Chao 1984, bias-corrected form, Chao 2005):

    m̂ = f1 (f1 − 1) / (2 (f2 + 1)),   var m̂ = Chao (2005) eq. for the bias-corrected form.

Bounds:  |I| h^d ≤ vol W ≤ (|O| + m̂ + 2 sd(m̂)) h^d.

Why: every cell meeting W together covers W (upper), and a cell that sticks out of W through a boundary that
is flat at the scale of 3h has a whole neighbour outside W, so it is not interior (lower).  Empty cells inside
W only move cells from I to the boundary (the lower bound stays a lower bound).  The estimate is the interval's
midpoint.  Counts are kept at the finest edge and added up 2×2×2 for each coarser level; among the levels
whose Good–Turing sample coverage 1 − f1/N is at least MIN_COVERAGE (Chao1 is only trusted there: at low
coverage it under-counts the unseen cells badly) the one with the narrowest interval is reported, so the
interval shrinks as samples fill finer levels (width ≈ boundary area × 3h).  Assumptions (stated in
docs/workspace.md): a boundary smooth at the scale of 3h (thin slivers and holes narrower than a cell are not
resolved) and the Chao1 model for the unseen cells.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["VolumeEstimate", "estimate_volume", "coarsen", "interior", "chao1", "level_stats", "MIN_COVERAGE"]

#: Least Good–Turing coverage 1 − f1/N at which a level's interval is used (else only as a last resort).
MIN_COVERAGE = 0.99


@dataclass(frozen=True)
class VolumeEstimate:
    """Size of the reachable set at one cell edge.

    Attributes
    ----------
    value, low, high : float
        Estimate (midpoint) and bounds [m³, or m² for a planar arm].
    resolution : float
        Cell edge of the level used [m].
    occupied, interior : int
        Occupied cells and those whose every neighbour is occupied.
    unseen : float
        Chao1 estimate of cells meeting the workspace that no sample hit yet.
    dim : int
        3 (volume) or 2 (area of a planar arm).
    coverage : float
        Good–Turing sample coverage 1 − f1/N at this level (the share of the sampling density's mass in cells
        already hit; below MIN_COVERAGE the interval is not trusted).
    """

    value: float
    low: float
    high: float
    resolution: float
    occupied: int
    interior: int
    unseen: float
    dim: int
    coverage: float

    def __post_init__(self):
        # Python numbers, whatever numpy scalars the counting produced (they print as np.float64(...) in numpy 2)
        for name, kind in (("value", float), ("low", float), ("high", float), ("resolution", float),
                           ("occupied", int), ("interior", int), ("unseen", float), ("dim", int),
                           ("coverage", float)):
            object.__setattr__(self, name, kind(getattr(self, name)))

    @property
    def half_width(self) -> float:
        return 0.5 * (self.high - self.low)

    def summary(self) -> dict:
        return {"value": self.value, "low": self.low, "high": self.high, "resolution": self.resolution,
                "occupied": self.occupied, "interior": self.interior, "unseen": self.unseen, "dim": self.dim,
                "coverage": self.coverage}


def coarsen(counts: np.ndarray) -> np.ndarray:
    """Sum 2×2(×2) blocks of cells (an odd last row is dropped into a padded zero row); uint64."""
    c3 = _jit_view(counts)
    if c3 is not None:
        from ._tally import coarsen3

        out = np.zeros(tuple((s + 1) // 2 for s in c3.shape[counts.ndim == 2:]), dtype=np.uint64)
        coarsen3(c3, out.reshape(c3.shape[:3 - counts.ndim] + out.shape))
        return out
    return _coarsen_numpy(counts)


def _coarsen_numpy(counts: np.ndarray) -> np.ndarray:
    pad = [(0, s % 2) for s in counts.shape]
    c = np.pad(counts, pad) if any(p for _, p in pad) else counts
    c = c.astype(np.uint64, copy=False)
    for ax in range(c.ndim):  # pairs along each axis in turn (integer sums: any order gives the same)
        even, odd = [slice(None)] * c.ndim, [slice(None)] * c.ndim
        even[ax], odd[ax] = slice(0, None, 2), slice(1, None, 2)
        c = c[tuple(even)] + c[tuple(odd)]
    return c


def _jit_view(counts: np.ndarray) -> np.ndarray | None:
    """``counts`` as (I, J, K) for ``_tally`` (a planar grid as (1, J, K)) when numba is installed and the counts
    are a C-contiguous 2-D or 3-D grid of unsigned integers at least 3 cells a side; else None (the numpy
    route)."""
    import importlib.util

    ok = (counts.ndim in (2, 3) and counts.dtype.kind == "u" and counts.flags.c_contiguous and min(counts.shape) >= 3
          and importlib.util.find_spec("numba") is not None)
    return (counts.reshape((1,) * (3 - counts.ndim) + counts.shape)) if ok else None


def level_stats(counts: np.ndarray, mask: bool = False) -> tuple:
    """(|O|, |I|, f1, f2, N, inner) of one level: occupied cells, interior cells (:func:`interior`), cells hit
    once and twice, samples, and — when ``mask`` — the interior mask (shape of counts, bool; else None).  One
    jitted pass (``_tally``) when numba is installed, else numpy: the same integers."""
    c3 = _jit_view(counts)
    if c3 is None:
        return _level_stats_numpy(counts, mask)
    from ._tally import stats3

    inner = np.empty(counts.shape, dtype=bool) if mask else np.empty((0, 0, 0), dtype=bool)
    n_occ, n_in, f1, f2, total = stats3(c3, counts.ndim, inner.reshape(c3.shape) if mask else inner)
    return int(n_occ), int(n_in), int(f1), int(f2), int(total), inner if mask else None


def _level_stats_numpy(counts: np.ndarray, mask: bool = False) -> tuple:
    occ = counts > 0
    inner = interior(occ)
    return (int(np.count_nonzero(occ)), int(np.count_nonzero(inner)), int(np.count_nonzero(counts == 1)),
            int(np.count_nonzero(counts == 2)), counts.sum(), inner if mask else None)


def interior(occupied: np.ndarray) -> np.ndarray:
    """Occupied cells whose 3^d − 1 neighbours are all occupied (erosion by a full 3×…×3 block; cells on the
    grid's faces have neighbours outside it, which are empty)."""
    out = occupied
    for ax in range(occupied.ndim):  # the full block is separable: AND of shifts along each axis in turn
        sl = [slice(None)] * out.ndim
        left, mid, right = list(sl), list(sl), list(sl)
        left[ax], mid[ax], right[ax] = slice(0, -2), slice(1, -1), slice(2, None)
        new = np.zeros_like(out)
        np.logical_and(out[tuple(left)], out[tuple(mid)], out=new[tuple(mid)])
        np.logical_and(new[tuple(mid)], out[tuple(right)], out=new[tuple(mid)])
        out = new
    return out


def chao1(f1: int, f2: int) -> tuple[float, float]:
    """Bias-corrected Chao1 unseen count and its standard deviation (Chao 2005)."""
    f1, f2 = float(f1), float(f2)
    m = max(f1 * (f1 - 1) / (2 * (f2 + 1)), 0.0)
    var = m + f1 * (2 * f1 - 1) ** 2 / (4 * (f2 + 1) ** 2) + f1**2 * f2 * (f1 - 1) ** 2 / (4 * (f2 + 1) ** 4)
    return m, float(np.sqrt(max(var, 0.0)))


def _at_level(counts: np.ndarray, h: float, stats: tuple | None = None) -> VolumeEstimate:
    n_occ, n_in, f1, f2, total, _ = level_stats(counts) if stats is None else stats
    m, sd = chao1(f1, f2)
    cell = h ** counts.ndim
    low, high = n_in * cell, (n_occ + m + 2 * sd) * cell
    coverage = 1.0 - f1 / max(float(total), 1.0)
    return VolumeEstimate(0.5 * (low + high), low, high, h, n_occ, n_in, m, counts.ndim, coverage)


def estimate_volume(counts: np.ndarray, resolution: float, levels: int, *,
                    stats: tuple | None = None) -> tuple[VolumeEstimate, list]:
    """The narrowest-interval estimate over ``levels`` cell edges (resolution·2^j) and all of them (``stats``:
    :func:`level_stats` of ``counts`` when the caller has it already)."""
    found, c, h = [], counts, resolution
    for j in range(levels):
        if j:
            c, h = coarsen(c), 2 * h
        found.append(_at_level(c, h, None if j else stats))
    trusted = [e for e in found if e.coverage >= MIN_COVERAGE] or found[-1:]
    best = min(trusted, key=lambda e: (e.high - e.low, -e.resolution))
    return best, found
