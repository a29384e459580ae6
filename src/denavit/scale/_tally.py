"""Jitted passes over count grids: the statistics of one level in one pass, the 2×2(×2) sums of the next level,
the neighbours of refined cells, and the accumulators' merge and flags (``_sink``).

``_volume`` needs, at each level, the occupied cells |O|, the interior cells |I| (every one of the 3^d − 1
neighbours occupied: the Moore erosion of O), f1 and f2 (cells hit once and twice) and the samples N; its numpy
route builds them with a boolean grid, three shifted ANDs and four more passes over a grid of up to 2²⁴ cells
(128 MiB of uint64 counts), each pass with fresh arrays whose page faults cost as much as the arithmetic.  Here
one pass over the counts reads each count once and keeps the erosion in three planes (the erosion is separable:
the AND of a cell's three neighbours along the last axis, then of those along the middle axis, then along the
first, over planes p − 1, p, p + 1), so the only large array is the interior mask when it is asked for.  A
planar grid (S, S) is taken as (1, S, S) eroded along its last two axes.  Integer counts and booleans: the
numbers are those of the numpy route exactly (tested against it, and it against the brute-force erosion).
"""

from __future__ import annotations

import numpy as np
from numba import njit

__all__ = ["children3", "coarsen3", "flag", "merge", "neighbour_slots3", "stats3"]

_FLAG, _COUNT = np.uint32(1 << 31), np.uint32(2**31 - 1)  # bit 31 of a uint32 accumulator, the count bits


@njit(cache=True, nogil=True)
def _erode_plane(c, p, occ, row, out):
    """out (J, K) = the erosion of plane p of c along its last two axes, with occ (J, K) its occupancy; returns
    (occupied, f1, f2, N) of the plane.  Cells on the faces are not interior."""
    J, K = occ.shape
    n_occ = f1 = f2 = 0
    total = np.uint64(0)
    for j in range(J):
        for k in range(K):
            v = c[p, j, k]
            occ[j, k] = v > 0
            n_occ += v > 0
            f1 += v == 1
            f2 += v == 2
            total += v
    for j in range(J):  # along the last axis, into out
        out[j, 0] = out[j, K - 1] = False
        for k in range(1, K - 1):
            out[j, k] = occ[j, k - 1] & occ[j, k] & occ[j, k + 1]
    row[:] = out[0]  # along the middle axis, row by row (row holds the previous row, not yet eroded)
    out[0, :] = False
    for j in range(1, J - 1):
        for k in range(K):
            x = row[k] & out[j, k] & out[j + 1, k]
            row[k] = out[j, k]
            out[j, k] = x
    out[J - 1, :] = False
    return n_occ, f1, f2, total


@njit(cache=True, nogil=True)
def stats3(c, d, inner):
    """(|O|, |I|, f1, f2, N) of counts c (I, J, K), the erosion along the last ``d`` axes (d = 3: a 3-D grid;
    d = 2: a planar grid as (1, J, K)); the interior mask into ``inner`` (I, J, K) bool unless it is empty."""
    I, J, K = c.shape
    write = inner.size > 0
    occ = np.empty((J, K), np.bool_)
    row = np.empty(K, np.bool_)
    e = np.empty((3, J, K), np.bool_)  # planes p − 1, p, p + 1 eroded along the last two axes (slot p mod 3)
    n_occ = n_in = f1 = f2 = 0
    total = np.uint64(0)
    for p in range(I + 1):
        if p < I:
            a, b, g, t = _erode_plane(c, p, occ, row, e[p % 3])
            n_occ, f1, f2, total = n_occ + a, f1 + b, f2 + g, total + t
        q = p - 1  # plane q is finished: its neighbours q − 1 and q + 1 are eroded
        if q < 0:
            continue
        mid = e[q % 3]
        if d == 3 and (q == 0 or q == I - 1):
            if write:
                inner[q, :, :] = False
            continue
        lo, hi = e[(q + 2) % 3], e[(q + 1) % 3]
        for j in range(J):
            for k in range(K):
                x = mid[j, k] & (lo[j, k] & hi[j, k] if d == 3 else True)
                n_in += x
                if write:
                    inner[q, j, k] = x
    return n_occ, n_in, f1, f2, total


@njit(cache=True, nogil=True)
def coarsen3(c, out):
    """out (⌈I/2⌉, ⌈J/2⌉, ⌈K/2⌉) uint64, zeroed = the sums of 2×2×2 blocks of c (I, J, K) (a planar grid as
    (1, J, K): 2×2 blocks); an odd last row counts alone (as padded with zeros)."""
    I, J, K = c.shape
    for i in range(I):
        for j in range(J):
            o = out[i >> 1, j >> 1]
            for k in range(K >> 1):
                o[k] += np.uint64(c[i, j, 2 * k]) + np.uint64(c[i, j, 2 * k + 1])
            if K & 1:
                o[K >> 1] += np.uint64(c[i, j, K - 1])


@njit(cache=True, nogil=True, inline="always")
def _bits(x):
    """Set bits of a uint64 (the SWAR sum, which LLVM turns into one ``popcnt``)."""
    x = x - ((x >> np.uint64(1)) & np.uint64(0x5555555555555555))
    x = (x & np.uint64(0x3333333333333333)) + ((x >> np.uint64(2)) & np.uint64(0x3333333333333333))
    x = (x + (x >> np.uint64(4))) & np.uint64(0x0F0F0F0F0F0F0F0F)
    return (x * np.uint64(0x0101010101010101)) >> np.uint64(56)


@njit(cache=True, nogil=True)
def neighbour_slots3(cells, shape, d, slots, flat_in, r, out):
    """out[o, b] = the row holding the neighbour at offset o (the 3^d offsets in ``itertools.product((-1, 0, 1),
    repeat=d)`` order over the last d axes of ``shape`` (I, J, K)) of the refined cell ``cells[b]`` (flat): r + 1
    when it is interior (``flat_in``), its slot when it is refined (``slots``: ``_refine.slot_map``'s bitmap and
    counts), else r (no data; also off the grid)."""
    I, J, K = shape[0], shape[1], shape[2]
    for b in range(cells.size):
        c = cells[b]
        i, j, k = c // (J * K), (c // K) % J, c % K
        for o in range(3**d):
            di = o // 9 - 1 if d == 3 else 0
            dj, dk = (o // 3) % 3 - 1, o % 3 - 1
            a, e, f = i + di, j + dj, k + dk
            if a < 0 or a >= I or e < 0 or e >= J or f < 0 or f >= K:
                out[o, b] = r
                continue
            g = (a * J + e) * K + f
            if flat_in[g]:
                out[o, b] = r + 1
                continue
            word, bit = slots[g >> 6, 0], np.uint64(g & 63)
            if (word >> bit) & np.uint64(1):
                out[o, b] = np.int64(slots[g >> 6, 1] + _bits(word & ((np.uint64(1) << bit) - np.uint64(1))))
            else:
                out[o, b] = r


@njit(nogil=True, cache=True)
def merge(total, part):
    """total += the counts of part (low 31 bits: no FLAG), part = 0 (the caller flags the refined cells again),
    touching only the runs of 16 entries holding a nonzero one (an OR of 16 loads: vectorised; most runs of a
    workspace's grid are empty): 0.02 s for the Puma's 2²⁴ cells into a fresh uint64 array, 0.07 s entry by
    entry, 0.24–0.52 s writing every entry (twice the page faults)."""
    n = part.size
    m = n - n % 16
    for c in range(0, m, 16):
        seen = np.uint32(0)
        for i in range(c, c + 16):
            seen |= part[i]
        if seen:
            for i in range(c, c + 16):
                total[i] += part[i] & _COUNT
                part[i] = 0
    for i in range(m, n):
        total[i] += part[i] & _COUNT
        part[i] = 0


@njit(nogil=True, cache=True)
def flag(acc, cells, on):
    """Set (``on``) or clear bit 31 (FLAG) of acc at ``cells``: the refined cells of a run."""
    for c in cells:
        acc[c] = (acc[c] | _FLAG) if on else (acc[c] & _COUNT)


@njit(cache=True, nogil=True)
def children3(shell, inner, out):
    """The flat indices, ascending, of the cells of ``inner``'s grid (I, J, K) whose parent (i, j, k) // 2 is in
    ``shell`` (⌈I/2⌉, ⌈J/2⌉, ⌈K/2⌉) and which are not in ``inner``, into out; returns how many (a planar grid as
    (1, J, K), its parents' as (1, ⌈J/2⌉, ⌈K/2⌉))."""
    I, J, K = inner.shape
    n = 0
    for i in range(I):
        for j in range(J):
            row = shell[i >> 1, j >> 1]
            for k in range(K):
                if row[k >> 1] and not inner[i, j, k]:
                    out[n] = (i * J + j) * K + k
                    n += 1
    return n
