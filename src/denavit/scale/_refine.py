"""Boundary refinement: finer cells only where the workspace's boundary runs.

The volume interval is as wide as the layer of boundary cells (|O| − |I| cells of edge h), so it stops
narrowing once the finest grid is filled.  A dense grid k times finer would cost k^d times the memory; the
boundary layer is a thin shell, so only its cells are subdivided:

1. a *pilot* — the first 1/PILOT_SHARE of the random blocks (whole blocks: the same for any workers or chunk
   size) — fills the grid of edge h;
2. the cells to refine are fixed from the pilot's counts, read at edge 2h (each cell's parent, occupied when
   one of its 2^d cells is): the cells whose parent is occupied or next to an occupied
   one, and not deep inside — its 5^d block of parents all occupied (two erosions) — except the cells interior at
   edge h (R = up(dilate(O₂) \\ erode²(O₂)) \\ I).  Cells interior in the pilot stay interior (more samples
   only occupy more cells).  Edge 2h, because the pilot leaves cells of edge h empty that more samples fill: at
   edge h every such hole made nine cells "boundary" (at 10⁸ samples of the 2R arm, 29 % of the grid), at 2h a
   parent holds 2^d times the samples and holes are rare; the shell of 2h-cells is wider than the boundary layer
   (≈ 8 instead of 3 cells of edge h), so the cells of edge h that end in the boundary are in R unless a hole
   narrower than 2h lies deep inside (not resolved anyway, see docs/workspace.md);
3. the remaining blocks count, besides the grid of edge h, each sample that falls in a cell of R in that cell's
   k^d sub-cells of edge h/k (k a power of two, at most MAX_REFINE, with |R|·k^d ≤ REFINE_CELLS).

The refined interval at edge h/j (j = k, k/2, … 2), with O, I the occupied and interior cells of edge h of the
whole run, B = O \\ I and f1, f2 the sub-cells of B ∩ R hit once and twice by the refined samples:

    low  = |I|·h^d + (sub-cells of B ∩ R whose 3^d − 1 neighbours are occupied)·(h/j)^d
    high = (|I| + |B \\ R|)·h^d + (occupied sub-cells of B ∩ R + m̂ + 2 sd m̂)·(h/j)^d + (m̂_h + 2 sd m̂_h)·h^d

(m̂: Chao1 of the sub-cells, m̂_h: of the cells of edge h).  A sub-cell's neighbour in an interior cell of
edge h counts as occupied, in any other cell without sub-cell counts as empty (the lower bound only gets
lower).  The same reasoning as at one edge (``_volume``) makes it a bracket under the same assumptions, at the
scale of the sub-cells; its width is about the boundary area × 3h/j.
"""

from __future__ import annotations

import hashlib
import importlib.util
import itertools
import threading
from dataclasses import dataclass

import numpy as np

from ._volume import VolumeEstimate, chao1, coarsen, interior, level_stats

__all__ = ["PILOT_SHARE", "PROJECTED_COVERAGE", "REFINE_COVERAGE", "MAX_REFINE", "REFINE_CELLS", "Refinement",
           "plan_refinement", "projected_coverage", "refined_levels", "slot_map", "popcount", "pilot_blocks",
           "check_factor", "refinement"]

#: The pilot is the first 1/PILOT_SHARE of the random blocks (at least one).
PILOT_SHARE = 8
#: Automatic refinement when the pilot alone fills the finest grid to this Good–Turing coverage.
REFINE_COVERAGE = 0.9
#: Automatic refinement takes the largest factor whose projected sub-cell coverage reaches this (the refined
#: levels are used from MIN_COVERAGE = 0.99 on; the projection is low by 0.03–0.04, see projected_coverage).
PROJECTED_COVERAGE = 0.95
#: Most sub-cells per side of a refined cell (a power of two).
MAX_REFINE = 8
#: Most sub-cells in all (uint32 counts: 128 MiB; uint64 past 2³² samples).
REFINE_CELLS = 2**25
_HALO_CHUNK = 2**15  # refined cells per step of the sub-cell erosion (bounds its scratch memory)


@dataclass(frozen=True, eq=False)
class Refinement:
    """Which cells of the finest grid carry sub-cell counts, and how finely (picklable; travels with tasks).

    Attributes
    ----------
    cells : ndarray of int64, shape (r,)
        Sorted flat indices (row-major) of the refined cells of the grid of edge ``grid.resolution``.
    factor : int
        Sub-cells per side (a power of two, 2 … MAX_REFINE).
    pilot_blocks : int
        Blocks of the pilot: sub-cell counts come from the blocks after them.
    token : str
        Digest of ``cells`` (each process builds the bitmap of :func:`slot_map` once per token).
    """

    cells: np.ndarray
    factor: int
    pilot_blocks: int
    token: str


def pilot_blocks(blocks: int) -> int:
    """Blocks of the pilot for a run of ``blocks`` blocks (0: too short to refine)."""
    return 0 if blocks < 2 else max(1, -(-blocks // PILOT_SHARE))


def plan_refinement(counts: np.ndarray, factor: int | None, pilot: int,
                    blocks: int | None = None) -> Refinement | None:
    """The refinement the pilot's counts call for (``factor`` None: automatic — only when the pilot's coverage
    of the grid reaches REFINE_COVERAGE; the factor is then the largest that fits REFINE_CELLS and whose
    sub-cells' coverage, projected from the pilot (:func:`projected_coverage`; ``blocks``: the run's, default
    PILOT_SHARE·pilot), reaches PROJECTED_COVERAGE)."""
    _, _, f1, _, total, inner = level_stats(counts, mask=True)
    if factor is None and (total == 0 or 1.0 - f1 / float(total) < REFINE_COVERAGE):
        return None
    cells = _shell_cells(counts, inner)
    if cells.size == 0:
        return None
    k = MAX_REFINE if factor is None else int(factor)
    while k >= 2 and cells.size * k**counts.ndim > REFINE_CELLS:
        k //= 2
    if factor is None:
        later = ((PILOT_SHARE * pilot if blocks is None else blocks) - pilot) / max(pilot, 1)
        pilot_counts = counts.reshape(-1)[cells]
        while k >= 2 and projected_coverage(pilot_counts, later / k**counts.ndim) < PROJECTED_COVERAGE:
            k //= 2
    if k < 2:
        return None
    return refinement(cells, k, pilot)


def projected_coverage(pilot_counts: np.ndarray, share: float) -> float:
    """Good–Turing coverage 1 − f1/N the sub-cells of cells with pilot counts ``pilot_counts`` would reach if
    each got, after the pilot, Poisson counts of mean ``share``·c (its cell's share of the later samples, spread
    evenly over its sub-cells): E f1 / E N = Σ c·e^(−share·c) / Σ c.  A boundary cell's samples fall in its
    sub-cells inside the workspace only, so these get more and the projection is low (by 0.03–0.04 on planar2r
    and the Puma at 10⁸: 0.962 / 0.915 / 0.998 projected for ×8 / ×4 / ×2 against 0.992 / 0.952 / 0.9988)."""
    c = pilot_counts.astype(float)
    n = c.sum()
    return 1.0 - float((c * np.exp(-share * c)).sum() / n) if n else 0.0


def _dilate(occ: np.ndarray) -> np.ndarray:
    """Cells occupied or next to an occupied one (dilation by the 3×…×3 block, axis by axis)."""
    grown = occ.copy()
    for ax in range(occ.ndim):
        g = grown.copy()
        sl = [slice(None)] * occ.ndim
        lo, hi = list(sl), list(sl)
        lo[ax], hi[ax] = slice(0, -1), slice(1, None)
        g[tuple(lo)] |= grown[tuple(hi)]
        g[tuple(hi)] |= grown[tuple(lo)]
        grown = g
    return grown


def _shell_cells(counts: np.ndarray, inner: np.ndarray) -> np.ndarray:
    """Sorted flat indices of the cells of edge h (counts ``counts``) whose parent of edge 2h is in
    dilate(O₂) \\ erode²(O₂), O₂ the parents holding an occupied cell (the 2×2(×2) sums, an odd side padded),
    and that are not in ``inner``.  The cells are listed in one jitted pass (``_tally.children3``) or, without
    numba, as the children of the shell's parents (those past the grid dropped); the grid is not upsampled."""
    occ2 = coarsen(counts) > 0
    shell = _dilate(occ2) & ~interior(interior(occ2))
    if importlib.util.find_spec("numba") is None:
        return _children_numpy(shell, inner)
    from ._tally import children3

    d = counts.ndim
    out = np.empty(np.count_nonzero(shell) * 2**d, dtype=np.int64)
    lift = (1,) * (3 - d)
    n = children3(shell.reshape(lift + shell.shape), inner.reshape(lift + inner.shape), out)
    return out[:n].copy()


def _children_numpy(shell: np.ndarray, inner: np.ndarray) -> np.ndarray:
    d = inner.ndim
    parents = np.argwhere(shell)  # (p, d)
    kids = (2 * parents[:, None, :] + np.array(list(itertools.product((0, 1), repeat=d)))).reshape(-1, d)
    kids = kids[np.all(kids < np.array(inner.shape), axis=1)]
    flat = np.ravel_multi_index(tuple(kids.T), inner.shape).astype(np.int64)
    flat = flat[~inner.reshape(-1)[flat]]
    flat.sort()
    return flat


def refinement(cells: np.ndarray, factor: int, pilot: int) -> Refinement:
    """A :class:`Refinement` of the sorted flat cell indices ``cells`` (its token computed)."""
    cells = np.ascontiguousarray(cells, dtype=np.int64)
    return Refinement(cells, int(factor), int(pilot), hashlib.blake2b(cells.tobytes(), digest_size=16).hexdigest())


_maps: dict = {}
_maps_lock = threading.Lock()


def slot_map(ref: Refinement, size: int) -> np.ndarray:
    """Per process, for a grid of ``size`` cells: the refined cells as a bitmap of 64-bit words (bit i of word
    w ↔ cell 64·w + i) beside, per word, how many refined cells come before it: ``slots[w] = (word, count)``,
    uint64 (w, 2) — a sample's test and its slot read one cache line (size/4 bytes in all).  The slot of a
    refined cell is the count plus the set bits below it in its word."""
    with _maps_lock:
        hit = _maps.get(ref.token)
        if hit is None or hit.shape[0] != -(-size // 64):
            mask = np.zeros(-(-size // 64) * 64, dtype=bool)
            mask[ref.cells] = True
            words = np.packbits(mask, bitorder="little").view(np.uint64)
            hit = np.zeros((words.size, 2), dtype=np.uint64)
            hit[:, 0] = words
            hit[1:, 1] = np.cumsum(popcount(words)[:-1])
            _maps.clear()  # one run at a time per process: keep memory bounded
            _maps[ref.token] = hit
        return hit


_POP8 = np.array([bin(i).count("1") for i in range(256)], dtype=np.int64)


def popcount(x: np.ndarray) -> np.ndarray:
    """Set bits of each uint64 (int64 result)."""
    if hasattr(np, "bitwise_count"):  # numpy >= 2.0
        return np.bitwise_count(x).astype(np.int64)
    return _POP8[np.ascontiguousarray(x).view(np.uint8)].reshape(x.shape + (8,)).sum(axis=-1)


def _coarsen_sub(F: np.ndarray, d: int) -> np.ndarray:
    """Sum 2^d blocks of sub-cells inside each refined cell: (r, j, …) → (r, j/2, …), in F's dtype (uint32 only
    when fewer than 2³² samples follow the pilot, so no sum of sub-cells can overflow it)."""
    for ax in range(1, d + 1):  # pairs along each sub-cell axis in turn
        even, odd = [slice(None)] * (d + 1), [slice(None)] * (d + 1)
        even[ax], odd[ax] = slice(0, None, 2), slice(1, None, 2)
        F = F[tuple(even)] + F[tuple(odd)]
    return F


def _sub_interior(Fo: np.ndarray, rows: np.ndarray, neighbour_slots: list, d: int) -> int:
    """Occupied sub-cells of refined cells ``rows`` whose 3^d − 1 neighbours are occupied.

    Fo: (r + 2, j, …) occupancy with row r all False (no data: empty) and row r + 1 all True (interior cell);
    neighbour_slots[o] (len(rows),): the row holding the cell at offset o of each of ``rows``."""
    j = Fo.shape[1]
    count = 0
    offsets = list(itertools.product((-1, 0, 1), repeat=d))
    for s in range(0, rows.size, _HALO_CHUNK):
        part = slice(s, s + _HALO_CHUNK)
        n = rows[part].size
        H = np.empty((n,) + (j + 2,) * d, dtype=bool)
        for o, slots in zip(offsets, neighbour_slots):
            dst = tuple(slice(0, 1) if x < 0 else slice(j + 1, j + 2) if x > 0 else slice(1, j + 1) for x in o)
            src = tuple(slice(j - 1, j) if x < 0 else slice(0, 1) if x > 0 else slice(0, j) for x in o)
            H[(slice(None),) + dst] = Fo[(slice(None),) + src][slots[part]]
        for ax in range(1, d + 1):  # erosion by the full block, axis by axis (the halo is consumed)
            a, b, c = ([slice(None)] * (d + 1) for _ in range(3))
            a[ax], b[ax], c[ax] = slice(0, -2), slice(1, -1), slice(2, None)
            H = H[tuple(a)] & H[tuple(b)] & H[tuple(c)]
        count += int(H.sum())
    return count


def neighbour_rows(shape: tuple, ref: Refinement, rows: np.ndarray, flat_in: np.ndarray) -> np.ndarray:
    """The row of each neighbour (offset o, in ``itertools.product((-1, 0, 1), repeat=d)`` order) of each refined
    cell ``ref.cells[rows]``: its slot, r (no data, or off the grid) or r + 1 (interior), (3^d, len(rows))
    int64; jitted (``_tally``) when numba is installed."""
    r, d = ref.cells.size, len(shape)
    if importlib.util.find_spec("numba") is not None:
        from ._tally import neighbour_slots3

        out = np.empty((3**d, rows.size), dtype=np.int64)
        shape3 = np.array((1,) * (3 - d) + tuple(shape), dtype=np.int64)
        neighbour_slots3(ref.cells[rows], shape3, d, slot_map(ref, int(np.prod(shape))), flat_in, r, out)
        return out
    return _neighbour_rows_numpy(shape, ref, rows, flat_in)


def _neighbour_rows_numpy(shape: tuple, ref: Refinement, rows: np.ndarray, flat_in: np.ndarray) -> np.ndarray:
    r = ref.cells.size
    index = np.array(np.unravel_index(ref.cells[rows], shape))  # (d, nb)
    out = []
    for o in itertools.product((-1, 0, 1), repeat=len(shape)):
        nb = index + np.array(o)[:, None]
        inside = np.all((nb >= 0) & (nb < np.array(shape)[:, None]), axis=0)
        flat = np.ravel_multi_index(np.where(inside, nb, 0), shape)
        pos = np.minimum(np.searchsorted(ref.cells, flat), r - 1)
        slot = np.where(ref.cells[pos] == flat, pos, r)
        slot = np.where(flat_in[flat], r + 1, slot)
        out.append(np.where(inside, slot, r))
    return np.array(out, dtype=np.int64).reshape(3 ** len(shape), rows.size)


def refined_levels(counts: np.ndarray, h: float, ref: Refinement, fine: np.ndarray, *,
                   stats: tuple | None = None) -> list:
    """The refined estimates at edges h/k, h/(k/2), … h/2 (finest first) from the counts of edge h (whole run)
    and the sub-cell counts ``fine`` (r, k^d) of the refined cells (``stats``: ``level_stats(counts, mask=True)``
    when the caller has it already)."""
    d, k, r = counts.ndim, ref.factor, ref.cells.size
    n_occ, n_in, f1h, f2h, total, inner = level_stats(counts, mask=True) if stats is None else stats
    flat_in = inner.reshape(-1)
    boundary = (counts.reshape(-1)[ref.cells] > 0) & ~flat_in[ref.cells]  # refined cells in B
    rows = np.flatnonzero(boundary)
    n_unrefined = n_occ - n_in - rows.size  # cells of B without sub-cell counts
    m_h, sd_h = chao1(f1h, f2h)
    cover_h = 1.0 - f1h / max(float(total), 1.0)
    neighbour_slots = neighbour_rows(counts.shape, ref, rows, flat_in)
    F = fine.reshape((r,) + (k,) * d)
    out, j = [], k
    while j >= 2:
        Fo = np.concatenate([F > 0, np.zeros((1,) + F.shape[1:], bool), np.ones((1,) + F.shape[1:], bool)])
        sub_in = _sub_interior(Fo, rows, neighbour_slots, d)
        per = F.reshape(r, -1)[rows]  # the rows in B
        f1, f2 = np.count_nonzero(per == 1), np.count_nonzero(per == 2)
        N, n_occ = float(per.sum(dtype=np.uint64)), np.count_nonzero(per)
        m, sd = chao1(f1, f2)
        K, cell, big = j**d, (h / j) ** d, h**d
        low = n_in * big + sub_in * cell
        high = (n_in + n_unrefined) * big + (n_occ + m + 2 * sd) * cell + (m_h + 2 * sd_h) * big
        coverage = min(1.0 - f1 / max(N, 1.0), cover_h) if N else 0.0
        out.append(VolumeEstimate(0.5 * (low + high), low, high, h / j, (n_in + n_unrefined) * K + n_occ,
                                  n_in * K + sub_in, m + m_h * K, d, coverage))
        if j > 2:
            F = _coarsen_sub(F, d)
        j //= 2
    return out


def check_factor(factor) -> int | None:
    """None (automatic), 0 (never) or a power of two 2 … MAX_REFINE; anything else is a ModelError."""
    from ..errors import ModelError

    if factor is None:
        return None
    ok = not isinstance(factor, bool) and isinstance(factor, (int, np.integer)) and (
        factor == 0 or (2 <= factor <= MAX_REFINE and factor & (factor - 1) == 0))
    if not ok:
        raise ModelError(f"refine must be None (automatic), 0 (off) or a power of two from 2 to {MAX_REFINE}, "
                         f"got {factor!r}")
    return int(factor)
