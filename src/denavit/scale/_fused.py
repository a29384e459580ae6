"""The fused task kernel: random joint values → end-effector origin → voxel counts, one pass, without the GIL.

One jitted function per arm does, for every sample of a task, what :func:`denavit.scale._sampler.run_task`
does in numpy passes: draw the joint values, compute the origin, its cell and sub-cell, and count them.

- **Random numbers.**  Block b's stream is numpy's own ``Philox`` (Philox4x64-10, Salmon et al., SC 2011,
  "Parallel random numbers: as easy as 1, 2, 3") keyed by ``SeedSequence(seed, spawn_key=(b,))``: the j-th
  64-bit word of the block is word j mod 4 of Philox(counter j div 4 + 1, key), and the j-th double is
  (word >> 11)·2⁻⁵³ — numpy's ``Generator.random`` bit for bit (tested against numpy), so the samples are
  those of the numpy route.  The 64×64 → 128-bit products of the rounds are one LLVM ``mul i128``.
- **Position.**  The arm's traced ``position`` program (:func:`denavit.codegen.trace_kernels`) made into
  machine code by :func:`denavit.codegen.kernel_intrinsic`, the emitter of ``denavit.compile(robot).position``:
  the same instructions, so the same doubles as :class:`~denavit.scale.CompiledPositionFK`.
- **Cells.**  The arithmetic of ``_sampler._cells`` / ``_sub_cells`` in the same order of operations (no
  fused multiply-adds): the same cells.  Counts go into dense ``uint32`` arrays (an accumulator of the grid's
  size; see ``_sink``); with a ``touched`` buffer the first hit of each cell is recorded, so a task run in
  another process returns its sparse counts without a sort.

So a task's counts, bounds and reach are identical to the numpy route's with the compiled kernel.
"""

from __future__ import annotations

import threading

import numpy as np
from numba import njit

__all__ = ["NON_FINITE", "OK", "OUTSIDE", "SUB_ROWS", "block_keys", "fused_kernel"]

#: Rows drawn, positioned and counted per step (their joint values and origins stay in the L1 cache).
SUB_ROWS = 256
#: Status codes of a fused run.
OK, NON_FINITE, OUTSIDE = 0, 1, 2
#: Philox4x64 multipliers and Weyl key increments (Random123, philox.h).
_M0, _M1 = 0xD2E7470EE14C6C93, 0xCA5A826395121157
_W0, _W1 = 0x9E3779B97F4A7C15, 0xBB67AE8584CAA73B

_kernels: dict = {}
_kernels_lock = threading.Lock()
#: Most arms whose fused kernel a process keeps.
_KEEP = 8


def block_keys(entropy: int, first: int, count: int) -> np.ndarray:
    """Philox keys (count, 2) of blocks first … first+count−1: ``SeedSequence(entropy, spawn_key=(b,))``'s first
    two 64-bit words (what ``numpy.random.Philox`` takes as its key; its counter starts at 0)."""
    keys = np.empty((count, 2), dtype=np.uint64)
    for j in range(count):
        keys[j] = np.random.SeedSequence(entropy, spawn_key=(first + j,)).generate_state(2, np.uint64)
    return keys


def _program(spec) -> tuple[tuple, tuple]:
    """``(steps, outputs)`` of a traced kernel in :func:`denavit.codegen.kernel_intrinsic`'s format (the
    literals ``denavit.compile`` writes into its numba module, as values)."""
    tape = spec.tape
    arg_of = {name: k for k, (name, _) in enumerate(spec.inputs)}
    where: dict = {}
    steps = []

    def ref(x):  # an operand: a node's index (int) or a constant (float)
        return ("c", x) if isinstance(x, float) else where[x]

    for i in tape.program(spec.outputs):
        op, a, b = tape.ops[i]
        if op == "input":
            where[i] = ("i", arg_of[a], b)
            continue
        steps.append((op, ref(a), None if b is None else ref(b)))
        where[i] = ("n", len(steps) - 1)
    outputs = tuple(((f,), ("c", float(o)) if isinstance(o, (int, float)) else where[o.i])
                    for f, o in enumerate(spec.outputs))
    return tuple(steps), outputs


def fused_kernel(robot):
    """The jitted fused task function of ``robot`` (built once per process and arm; see :func:`_build`)."""
    with _kernels_lock:
        hit = _kernels.get(robot)
        if hit is None:
            from ..codegen import kernel_intrinsic, trace_kernels

            steps, outputs = _program(trace_kernels(robot, ["position"])["position"])
            hit = _build(kernel_intrinsic(1, steps, outputs)[1])
            if len(_kernels) >= _KEEP:
                _kernels.pop(next(iter(_kernels)))
            _kernels[robot] = hit
        return hit


def _mulhilo_intrinsic():
    """The intrinsic (a, b) → (high, low) 64-bit words of the 128-bit product a·b (uint64): one ``mul i128``."""
    from llvmlite import ir
    from numba import types
    from numba.extending import intrinsic

    @intrinsic
    def mulhilo(typingctx, a, b):
        sig = types.UniTuple(types.uint64, 2)(types.uint64, types.uint64)

        def codegen(context, builder, sig, args):
            i128, i64 = ir.IntType(128), ir.IntType(64)
            p = builder.mul(builder.zext(args[0], i128), builder.zext(args[1], i128))
            hi = builder.trunc(builder.lshr(p, ir.Constant(i128, 64)), i64)
            return context.make_tuple(builder, sig.return_type, (hi, builder.trunc(p, i64)))

        return sig, codegen

    return mulhilo


_mulhilo = _mulhilo_intrinsic()
_M0, _M1, _W0, _W1 = np.uint64(_M0), np.uint64(_M1), np.uint64(_W0), np.uint64(_W1)
_Z, _S32, _ONE, _LOW6, _LOW32 = np.uint64(0), np.uint64(32), np.uint64(1), np.uint64(63), np.uint64(0xFFFFFFFF)
_HALF = 2.0**-32


@njit(nogil=True, cache=True)
def _philox(c0, k0, k1):
    """Philox4x64-10 of the counter (c0, 0, 0, 0) under the key (k0, k1): 4 words (Random123's philox.h)."""
    c1 = c2 = c3 = _Z
    for r in range(10):
        if r:
            k0 = k0 + _W0
            k1 = k1 + _W1
        hi0, lo0 = _mulhilo(_M0, c0)
        hi1, lo1 = _mulhilo(_M1, c2)
        c0, c1, c2, c3 = hi1 ^ c1 ^ k0, lo1, hi0 ^ c3 ^ k1, lo0
    return c0, c1, c2, c3


@njit(nogil=True, cache=True)
def _draw(q, r, j, k0, k1, lo, span, buf):
    """Rows 0 … r−1 of q (C-contiguous) from values j, j+1 … of the block's stream; returns the next value's
    index.  Value v is the low (v even) or high (v odd) 32-bit half h of word v div 2, word w is word w mod 4 of
    Philox(w div 4 + 1); the joint value is lo + (h·2⁻³²)·span (as ``_sampler._draw``).  ``buf``: scratch of at
    least r·n/2 + 8 words (the Philox outputs, then converted in one straight loop)."""
    n = q.shape[1]
    end = j + r * n
    c0, c1 = (j >> 1) >> 2, ((end - 1) >> 1) >> 2  # the Philox counters (minus one) these values come from
    for c in range(c0, c1 + 1):
        w0, w1, w2, w3 = _philox(np.uint64(c + 1), k0, k1)
        o = 4 * (c - c0)
        buf[o], buf[o + 1], buf[o + 2], buf[o + 3] = w0, w1, w2, w3
    flat = q.reshape(-1)
    m = r * n
    if j & 1:  # a start in the middle of a word (not reached by run: blocks start at 0, steps are even)
        for v in range(m):
            w = j + v - 8 * c0
            flat[v] = np.int64((buf[w >> 1] >> (_S32 * np.uint64(w & 1))) & _LOW32) * _HALF
    else:
        off = (j >> 1) - 4 * c0
        for p in range(m // 2):  # both halves of each word
            w = buf[off + p]
            flat[2 * p] = np.int64(w & _LOW32) * _HALF
            flat[2 * p + 1] = np.int64(w >> _S32) * _HALF
        if m & 1:
            flat[m - 1] = np.int64(buf[off + m // 2] & _LOW32) * _HALF
    for i in range(r):
        for a in range(n):
            flat[i * n + a] = flat[i * n + a] * span[a] + lo[a]
    return end


@njit(nogil=True, cache=True)
def _popcount(x):
    x = x - ((x >> _ONE) & np.uint64(0x5555555555555555))
    x = (x & np.uint64(0x3333333333333333)) + ((x >> np.uint64(2)) & np.uint64(0x3333333333333333))
    x = (x + (x >> np.uint64(4))) & np.uint64(0x0F0F0F0F0F0F0F0F)
    return (x * np.uint64(0x0101010101010101)) >> np.uint64(56)


@njit(nogil=True, cache=True)
def _coordinates(P, r, grid, basis, ident, origin, T, R2):
    """T[a, i] = (u_a − lo)/h, u = (p_i − centre) in the grid's basis (u_a = (d0·b_a0 + d1·b_a1) + d2·b_a2 unless
    the basis is the identity), and R2[i] = |p_i − origin|² ((dx² + dy²) + dz²), for i < r: straight loops with
    no branches (vectorised)."""
    cx, cy, cz, glo, inv = grid[0], grid[1], grid[2], grid[3], grid[4]
    ox, oy, oz = origin[0], origin[1], origin[2]
    for i in range(r):
        dx, dy, dz = P[i, 0] - ox, P[i, 1] - oy, P[i, 2] - oz
        R2[i] = dx * dx + dy * dy + dz * dz
    if ident:
        for i in range(r):
            T[0, i] = (P[i, 0] - cx - glo) * inv
            T[1, i] = (P[i, 1] - cy - glo) * inv
            T[2, i] = (P[i, 2] - cz - glo) * inv
        return
    for a in range(basis.shape[0]):
        b0, b1, b2 = basis[a, 0], basis[a, 1], basis[a, 2]
        for i in range(r):
            T[a, i] = ((P[i, 0] - cx) * b0 + (P[i, 1] - cy) * b1 + (P[i, 2] - cz) * b2 - glo) * inv


@njit(nogil=True, cache=True)
def _cells(P, r, grid, basis, ident, side, origin, words, prefix, cells, subs, stats, T, R2):
    """Bounds and squared reach (into stats: min xyz, max xyz, max |p − origin|²; sqrt is monotone, so the root
    is taken at the end), cells (cells[:r]) and the sub-cells of those in refined cells (subs[:ns], in order) of
    the origins P[:r]; returns (status, ns).  The arithmetic of ``_sampler._cells`` / ``_sub_cells``, in their order."""
    dim, k = basis.shape[0], int(grid[5])
    _coordinates(P, r, grid, basis, ident, origin, T, R2)
    x0, y0, z0, x1, y1, z1, reach = stats[0], stats[1], stats[2], stats[3], stats[4], stats[5], stats[6]
    for i in range(r):
        x, y, z = P[i, 0], P[i, 1], P[i, 2]
        x0, y0, z0, x1, y1, z1 = min(x0, x), min(y0, y), min(z0, z), max(x1, x), max(y1, y), max(z1, z)
        reach = max(reach, R2[i])
    stats[0], stats[1], stats[2], stats[3], stats[4], stats[5], stats[6] = x0, y0, z0, x1, y1, z1, reach
    bad = False
    for i in range(r):
        flat = 0
        for a in range(dim):
            f = np.floor(T[a, i])
            bad |= not (f >= 0 and f < side)  # NaN fails too
            flat = flat * side + int(f)
        cells[i] = flat
    if bad:
        for i in range(r):
            if not (np.isfinite(P[i, 0]) and np.isfinite(P[i, 1]) and np.isfinite(P[i, 2])):
                return 1, 0
        return 2, 0
    ns = 0
    if words.size:  # branch-free: every sample's index is written, only those in refined cells are kept
        for i in range(r):
            flat = cells[i]
            word = words[flat >> 6]
            b = np.uint64(flat) & _LOW6
            idx = prefix[flat >> 6] + np.int64(_popcount(word & ((_ONE << b) - _ONE)))
            for a in range(dim):
                idx = idx * k + int(np.floor(T[a, i] * k) - k * np.floor(T[a, i]))
            subs[ns] = idx
            ns += np.int64((word >> b) & _ONE)
    return 0, ns


@njit(nogil=True, cache=True)
def _add(cells, r, acc, touched, nt):
    """acc[cells[i]] += 1 for i < r; the first hit of each cell appended to touched (when it has room: a buffer
    of the task's size, or none); returns the new length of touched.  A loop of its own: its increments are
    independent, so the cache misses of a large grid overlap."""
    if touched.size:
        for i in range(r):
            c = cells[i]
            if acc[c] == 0:
                touched[nt] = c
                nt += 1
            acc[c] += 1
    else:
        for i in range(r):
            acc[cells[i]] += 1
    return nt


def _build(rows):
    """The fused task function around ``rows`` (a ``kernel_intrinsic`` batch form of the position program):
    ``run(keys, sizes, lo, span, grid, basis, ident, side, origin, acc, touched, words, prefix, fine, ftouched,
    q, P, cells, subs, stats) -> (nt, nft, status)`` over every block of a task (keys (blocks, 2), sizes
    (blocks,) samples each), SUB_ROWS rows at a time (q, P, cells, subs: scratch of that many rows)."""

    @njit(nogil=True)
    def run(keys, sizes, lo, span, grid, basis, ident, side, origin, acc, touched, words, prefix, fine, ftouched,
            q, P, cells, subs, stats):
        nt = nft = 0
        buf = np.empty(q.shape[0] * q.shape[1] // 2 + 8, dtype=np.uint64)
        T, R2 = np.empty((3, q.shape[0])), np.empty(q.shape[0])
        for blk in range(keys.shape[0]):
            k0, k1 = keys[blk, 0], keys[blk, 1]
            j = 0
            for s in range(0, sizes[blk], q.shape[0]):
                r = min(q.shape[0], sizes[blk] - s)
                qs, Ps = q[:r], P[:r]
                j = _draw(qs, r, j, k0, k1, lo, span, buf)
                for b in range(0, r, 4):
                    rows(qs, Ps, b)
                status, ns = _cells(Ps, r, grid, basis, ident, side, origin, words, prefix, cells, subs, stats, T,
                                    R2)
                if status:
                    return nt, nft, status
                nt = _add(cells, r, acc, touched, nt)
                nft = _add(subs, ns, fine, ftouched, nft)
        return nt, nft, 0

    return run
