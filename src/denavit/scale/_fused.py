"""The fused task kernel: random joint values → end-effector origin → voxel counts, one pass, without the GIL.

One jitted function per arm does, for every sample of a task, what :func:`denavit.scale._sampler.run_task`
does in numpy passes: draw the joint values, compute the origin, its cell and sub-cell, and count them.

- **Random numbers.**  Block b's words are SplitMix64's (Steele, Lea & Flood, OOPSLA 2014: a Weyl sequence
  through a 64-bit mixing function, which passes BigCrush) from the state K + b·2³²·γ, K from
  ``SeedSequence(seed)`` (:func:`denavit.scale._stream.block_state`): word w is mix(state + (w + 1)·γ), a pure
  function of its counter, so any worker starts any block; each word gives two 32-bit joint values (the
  numpy route's ``_stream.draw`` bit for bit, tested against SplitMix64 stepped in Python integers; the words
  of joints the position program never reads are skipped).  Joint 1 is drawn in the block's stratum (its lo
  and span per block, ``_strata``), so consecutive samples lie in one wedge of the workspace and their counts'
  cache lines are reused.
- **Position.**  The arm's traced ``position`` program (:func:`denavit.codegen.trace_kernels`) made into
  machine code by :func:`denavit.codegen.kernel_intrinsic`, the emitter of ``denavit.compile(robot).position``:
  the same instructions, so the same doubles as :class:`~denavit.scale.CompiledPositionFK`.
- **Cells.**  The arithmetic of ``_sampler._cells`` / ``_sub_cells`` in the same order of operations (no
  fused multiply-adds): the same cells.  Counts go into dense ``uint32`` arrays (an accumulator of the grid's
  size; see ``_sink``): the count in the low 31 bits, bit 31 (FLAG) set on the refined cells, so the load of
  the increment tells whether a sample's sub-cell is wanted (no other look-up for the other samples); with a
  ``touched`` buffer the first hit of each cell is recorded, so a task run in another process returns its
  sparse counts without a sort.

So a task's counts, bounds and reach are identical to the numpy route's with the compiled kernel.
"""

from __future__ import annotations

import threading

import numpy as np
from numba import njit

from ._stream import GAMMA, MIX1, MIX2

__all__ = ["FLAG", "NON_FINITE", "OK", "OUTSIDE", "SUB_ROWS", "block_keys", "fused_kernel"]

#: Rows drawn, positioned and counted per step (their joint values and origins stay in the L2 cache).  Each of
#: the step's loops has a fixed cost (alias checks, vector prologue and remainder, view reference counts): 2048
#: rows rather than 256 took 1.4–1.6 ns off a sample of planar2r (14.2 → 12.6) and of the Puma (24.3 → 22.9).
SUB_ROWS = 2048
#: Status codes of a fused run.
OK, NON_FINITE, OUTSIDE = 0, 1, 2
#: Bit 31 of a cell's uint32 accumulator: the cell is refined (its samples also count in sub-cells).  The count
#: is the low 31 bits (an accumulator is flushed before it could pass 2³¹ − 1).
FLAG = 1 << 31

_kernels: dict = {}
_kernels_lock = threading.Lock()
#: Most arms whose fused kernel a process keeps.
_KEEP = 8


def block_keys(entropy: int, first: int, count: int) -> np.ndarray:
    """Starting states (count,) uint64 of blocks first … first+count−1 (``_stream.block_state``)."""
    from ._stream import block_state

    return block_state(entropy, first + np.arange(count, dtype=np.uint64))


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
            read = {x[2] for op, a, b in steps for x in (a, b) if x is not None and x[0] == "i"}
            read |= {ref[2] for _, ref in outputs if ref[0] == "i"}
            hit = _build(kernel_intrinsic(1, steps, outputs)[1], tuple(k in read for k in range(robot.dof)))
            if len(_kernels) >= _KEEP:
                _kernels.pop(next(iter(_kernels)))
            _kernels[robot] = hit
        return hit


def _bit_intrinsics():
    """Two intrinsics: uint64 → float64 of the same 64 bits (an LLVM ``bitcast``: no conversion), and the set
    bits of a uint64 (LLVM ``ctpop``: one ``popcnt`` instruction where the CPU has it)."""
    from llvmlite import ir
    from numba import types
    from numba.extending import intrinsic

    @intrinsic
    def as_double(typingctx, x):
        def codegen(context, builder, sig, args):
            return builder.bitcast(args[0], ir.DoubleType())

        return types.float64(types.uint64), codegen

    @intrinsic
    def ctpop(typingctx, x):
        def codegen(context, builder, sig, args):
            return builder.ctpop(args[0])

        return types.uint64(types.uint64), codegen

    return as_double, ctpop


_as_double, _popcount = _bit_intrinsics()
_S32, _ONE, _LOW6, _LOW32 = np.uint64(32), np.uint64(1), np.uint64(63), np.uint64(0xFFFFFFFF)
_GAMMA, _MIX1, _MIX2, _S30, _S27, _S31 = (np.uint64(x) for x in (GAMMA, MIX1, MIX2, 30, 27, 31))
_COUNT, _UONE, _S31U = np.uint32(2**31 - 1), np.uint32(1), np.uint32(31)
_EXP52, _HALF = np.uint64(0x4330000000000000), 2.0**-32  # the bits of 2⁵²: 2⁵² + h for h < 2³² by an OR


@njit(nogil=True, cache=True, inline="always")
def _mix(z):
    """SplitMix64's output function (Steele, Lea & Flood, OOPSLA 2014; Vigna's constants)."""
    z = (z ^ (z >> _S30)) * _MIX1
    z = (z ^ (z >> _S27)) * _MIX2
    return z ^ (z >> _S31)


@njit(nogil=True, cache=True, inline="always")
def _unit(h):
    """h·2⁻³² for h < 2³² (uint64), exactly: (2⁵² + h) − 2⁵² by bits, which vectorises (no int → double)."""
    return (_as_double(_EXP52 | h) - 4503599627370496.0) * _HALF


@njit(nogil=True, cache=True)
def _draw(q, r, j, state, lo, span, used):
    """Columns 0 … r−1 of q (n, rows) — sample i's joint a in q[a, i] — from values j, j+1 … (j a multiple of
    n) of the block whose starting state is ``state``; returns the next value's index.  Value v (sample v div n,
    joint v mod n) is the low (v even) or high (v odd) 32-bit half h of word w = v div 2, word w is SplitMix64's
    mix(state + (w + 1)·γ) (``_stream.draw``); the joint value is lo + (h·2⁻³²)·span, in that order.  Words of
    joints that ``used`` marks unread (by the position program) are not computed: their entries of q are left as
    they were.  For each word of a period (a sample, or two of an odd n) a straight loop over the periods,
    which vectorises; a start in the middle of a word or half a period (the last step of a block of an odd
    length, for an odd n) takes the values one by one."""
    n = q.shape[0]
    per = 1 if n % 2 == 0 else 2  # samples of a whole number of words
    words = per * n // 2
    if j & 1 or r % per:
        for v in range(r * n):
            w = _mix(state + (np.uint64((j + v) >> 1) + _ONE) * _GAMMA)
            h = (w >> (_S32 * np.uint64((j + v) & 1))) & _LOW32
            q[v % n, v // n] = _unit(h) * span[v % n] + lo[v % n]
        return j + r * n
    base, step = state + np.uint64((j >> 1) + 1) * _GAMMA, np.uint64(words) * _GAMMA
    for k in range(words):
        a0, a1, s0, s1 = (2 * k) % n, (2 * k + 1) % n, (2 * k) // n, (2 * k + 1) // n
        if not (used[a0] or used[a1]):
            continue
        X, Y, l0, w0, l1, w1 = q[a0], q[a1], lo[a0], span[a0], lo[a1], span[a1]
        z = base + np.uint64(k) * _GAMMA  # the state of word t·words + k, by additions (an induction: 1.6×)
        if per == 1:
            for t in range(r):
                w = _mix(z)
                z += step
                X[t] = _unit(w & _LOW32) * w0 + l0
                Y[t] = _unit(w >> _S32) * w1 + l1
        else:
            for t in range(r // 2):
                w = _mix(z)
                z += step
                X[2 * t + s0] = _unit(w & _LOW32) * w0 + l0
                Y[2 * t + s1] = _unit(w >> _S32) * w1 + l1
    return j + r * n


@njit(nogil=True, cache=True)
def _cells(P, r, grid, basis, axes, side, origin, cells, stats, sub):
    """Cells (cells[:r]) and sub-cells (sub[:r], row-major among the k^d of a cell, k = grid[5]: floor(T·k) −
    k·floor(T) on each axis) of the coordinates T_a = (u_a − lo)/h (u = (p_i − centre) in the grid's basis) of
    the origins P[:, :r] (3, r), and their bounds and squared reach into stats (min xyz, max xyz,
    max |p − origin|²; sqrt is monotone: the root is taken at the end); returns the status.  The arithmetic of
    ``_sampler._cells`` / ``_sub_cells`` in its order (no fused multiply-adds), so the same cells; the loops
    are straight and vectorise (their reductions are integer counts), and the exact min/max pass
    (``_extremes``) runs only on the steps where some origin lies beyond the bounds so far (rarer as the run
    goes on: the bounds are the same)."""
    if basis.shape[0] == 3:
        bad, out = _cells3(P, r, grid, side, origin, cells, stats, sub)
    else:
        bad, out = _cells2(P, r, grid, basis, axes, side, origin, cells, stats, sub)
    if bad:  # outside [0, side) on some axis, NaN, or (planar) a non-finite coordinate off the plane
        for i in range(r):
            if not (np.isfinite(P[0, i]) and np.isfinite(P[1, i]) and np.isfinite(P[2, i])):
                return NON_FINITE
        return OUTSIDE
    if out:
        _extremes(P, r, origin, stats)
    return OK


@njit(nogil=True, cache=True, inline="always")
def _fine(k):
    """(k, k − 1, log2 k) for the sub-cells per side k = 2, 4, 8 (1, 0, 0 for none: no sub-cells).  With T ≥ 0
    and k a power of two, T·k is exact and u = floor(T·k) holds the cell floor(T) = u >> log2 k and the
    sub-cell floor(T·k) − k·floor(T) = u & (k − 1): one truncation per axis for both."""
    kf, lk = max(k, 1.0), 0
    while (1 << lk) < kf:
        lk += 1
    return kf, np.int32((1 << lk) - 1), np.int32(lk)


@njit(nogil=True, cache=True, inline="always")
def _beyond(x, y, z, q, stats):
    """Whether (x, y, z), |·−origin|² = q, lies beyond the bounds so far (as an integer: OR-reduced)."""
    return ((x < stats[0]) | (y < stats[1]) | (z < stats[2]) | (x > stats[3]) | (y > stats[4]) | (z > stats[5])
            | (q > stats[6]))


@njit(nogil=True, cache=True)
def _cells3(P, r, grid, side, origin, cells, stats, sub):
    """:func:`_cells` of a 3-D grid (its basis the world axes, ``make_job``; ``run_fused`` checks):
    (samples outside, samples beyond the bounds)."""
    s, glo, inv, si = float(side), grid[3], grid[4], np.int32(side)
    kf, km, lk = _fine(grid[5])
    c0, c1, c2, ox, oy, oz = grid[0], grid[1], grid[2], origin[0], origin[1], origin[2]
    X, Y, Z = P[0], P[1], P[2]
    bad = out = 0
    for i in range(r):
        x, y, z = X[i], Y[i], Z[i]
        dx, dy, dz = x - ox, y - oy, z - oz
        q = dx * dx + dy * dy + dz * dz
        t0, t1, t2 = (x - c0 - glo) * inv, (y - c1 - glo) * inv, (z - c2 - glo) * inv
        bad += not ((t0 >= 0.0) & (t0 < s) & (t1 >= 0.0) & (t1 < s) & (t2 >= 0.0) & (t2 < s))
        out |= _beyond(x, y, z, q, stats)
        u0, u1, u2 = np.int32(t0 * kf), np.int32(t1 * kf), np.int32(t2 * kf)  # floor(T·k), the cell's bits above
        cells[i] = ((u0 >> lk) * si + (u1 >> lk)) * si + (u2 >> lk)
        sub[i] = ((((u0 & km) << lk) + (u1 & km)) << lk) + (u2 & km)
    return bad, out


@njit(nogil=True, cache=True)
def _cells2(P, r, grid, basis, axes, side, origin, cells, stats, sub):
    """:func:`_cells` of a planar grid.  When every basis row is a coordinate axis (``axes[a]`` its index; else
    ``axes`` is empty) u_a is d_axes[a]: the same double as ((d0·b_a0 + d1·b_a1) + d2·b_a2) (the other products
    are zeros; −0 + 0 only changes the sign of a zero, and zero − lo is −lo).  A non-finite coordinate off the
    plane shows in |p − origin|²."""
    s, glo, inv, si = float(side), grid[3], grid[4], np.int32(side)
    kf, km, lk = _fine(grid[5])
    cx, cy, cz, ox, oy, oz = grid[0], grid[1], grid[2], origin[0], origin[1], origin[2]
    b00, b01, b02, b10, b11, b12 = basis[0, 0], basis[0, 1], basis[0, 2], basis[1, 0], basis[1, 1], basis[1, 2]
    plain = axes.size > 0
    k0, k1 = (axes[0], axes[1]) if plain else (0, 1)
    bad = out = 0
    for i in range(r):
        x, y, z = P[0, i], P[1, i], P[2, i]
        dx, dy, dz = x - ox, y - oy, z - oz
        q = dx * dx + dy * dy + dz * dz
        if plain:
            t0, t1 = (P[k0, i] - grid[k0] - glo) * inv, (P[k1, i] - grid[k1] - glo) * inv
        else:
            ex, ey, ez = x - cx, y - cy, z - cz
            t0 = (ex * b00 + ey * b01 + ez * b02 - glo) * inv
            t1 = (ex * b10 + ey * b11 + ez * b12 - glo) * inv
        bad += not ((t0 >= 0.0) & (t0 < s) & (t1 >= 0.0) & (t1 < s) & (q < np.inf))
        out |= _beyond(x, y, z, q, stats)
        u0, u1 = np.int32(t0 * kf), np.int32(t1 * kf)
        cells[i] = (u0 >> lk) * si + (u1 >> lk)
        sub[i] = ((u0 & km) << lk) + (u1 & km)
    return bad, out


@njit(nogil=True, cache=True, fastmath={"nnan", "ninf", "nsz"})
def _extremes(P, r, origin, stats):
    """stats[:7] = min xyz, max xyz, max |p − origin|² ((dx² + dy²) + dz²) over P[:, :r] and what stats held.
    Exact for finite values (the only ones here: ``_cells`` fails a step with others first): the flags allow no
    contraction or reassociation, and min and max do not round."""
    ox, oy, oz = origin[0], origin[1], origin[2]
    x0, y0, z0, x1, y1, z1, reach = stats[0], stats[1], stats[2], stats[3], stats[4], stats[5], stats[6]
    for i in range(r):
        x, y, z = P[0, i], P[1, i], P[2, i]
        dx, dy, dz = x - ox, y - oy, z - oz
        x0, y0, z0, x1, y1, z1 = min(x0, x), min(y0, y), min(z0, z), max(x1, x), max(y1, y), max(z1, z)
        reach = max(reach, dx * dx + dy * dy + dz * dz)
    stats[0], stats[1], stats[2], stats[3], stats[4], stats[5], stats[6] = x0, y0, z0, x1, y1, z1, reach


@njit(nogil=True, cache=True)
def _count(cells, r, acc, touched, nt, slots, subs, sub, kd, rare):
    """acc[cells[i]] += 1 for i < r (the count in the low 31 bits; bit 31 is FLAG, set on the refined cells of a
    refined run); the first hit of each cell appended to touched when it has room; returns (nt, ns) with the
    sub-cells of the samples in refined cells in subs[:ns], in order: slot·k^d + sub[i] (kd = k^d).

    The refined flag comes with the count's own load, so a sample outside the refined cells costs no look-up
    (the bitmap of ``slots`` is read only for the flagged ones).  Its increments are independent, so the cache
    misses of a large grid overlap.  ``rare`` (the last step's guess): the flagged rows listed by a branch in
    that loop (planar2r's 2 %: 0.5 ns less a sample), else by a branch-free second loop (the Puma's 20 %: 0.65)."""
    ns = 0
    if slots.shape[0] == 0:  # no refined cells, no flags
        return _add(cells, r, acc, touched, nt), 0
    if touched.size:
        for i in range(r):
            c = cells[i]
            v = acc[c]
            if (v & _COUNT) == 0:
                touched[nt] = c
                nt += 1
            acc[c] = v + _UONE
            subs[ns] = i
            ns += np.int64(v >> _S31U)
    elif rare:
        for i in range(r):
            c = cells[i]
            v = acc[c]
            acc[c] = v + _UONE
            if v >> _S31U:
                subs[ns] = i
                ns += 1
    else:
        for i in range(r):  # the flag of each sample's cell into subs[i] (no loop-carried dependence)
            c = cells[i]
            v = acc[c]
            acc[c] = v + _UONE
            subs[i] = v >> _S31U
        for i in range(r):  # branch-free: the rows in refined cells, in order, into subs[:ns]
            f = subs[i]
            subs[ns] = i
            ns += f
    for t in range(ns):  # their sub-cells: the slot of the cell (bitmap and counts) and the sub-cell in it
        i = subs[t]
        flat = cells[i]
        word, before = slots[flat >> 6, 0], slots[flat >> 6, 1]
        subs[t] = np.int64(before + _popcount(word & ((_ONE << (np.uint64(flat) & _LOW6)) - _ONE))) * kd + sub[i]
    return nt, ns


@njit(nogil=True, cache=True)
def _add(cells, r, acc, touched, nt):
    """acc[cells[i]] += 1 for i < r (sub-cell counts: no flag); the first hit of each cell appended to touched
    (when it has room: a buffer of the task's size, or none); returns the new length of touched."""
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


def _build(rows, used):
    """The fused task function around ``rows`` (a ``kernel_intrinsic`` batch form of the position program, which
    reads the joints ``used`` marks): ``run(keys, sizes, joint1, lo, span, grid, basis, axes, side, origin, acc,
    touched, slots, fine, ftouched, q, P, cells, subs, stats) -> (nt, nft, status)`` over every block of a task
    (keys (blocks,), sizes (blocks,) samples each, joint1 (blocks, 2) joint 1's lo and span in each: its
    stratum, ``_strata``), SUB_ROWS rows at a time (q (n, rows), P (3, rows), cells, subs: scratch of that many
    rows)."""

    @njit(nogil=True)
    def run(keys, sizes, joint1, lo, span, grid, basis, axes, side, origin, acc, touched, slots, fine, ftouched,
            q, P, cells, subs, stats):
        nt = nft = 0
        n, most = q.shape
        kd, rare = int(grid[5]) ** basis.shape[0], True
        sub = np.empty(most, np.int32)
        lo_b, span_b, use = lo.copy(), span.copy(), np.empty(n, np.bool_)
        for a in range(n):
            use[a] = used[a]
        for blk in range(keys.shape[0]):
            lo_b[0], span_b[0] = joint1[blk, 0], joint1[blk, 1]  # joint 1 in the block's stratum
            state = keys[blk]
            j = 0
            for s in range(0, sizes[blk], most):
                r = min(most, sizes[blk] - s)
                j = _draw(q, r, j, state, lo_b, span_b, use)
                qs = q[:, :r].T  # (r, n)
                for b in range(0, r, 4):
                    rows(qs, P.T, b)  # the origins into P (3, rows): the cells' loops read it contiguously
                status = _cells(P, r, grid, basis, axes, side, origin, cells, stats, sub)
                if status:
                    return nt, nft, status
                nt, ns = _count(cells, r, acc, touched, nt, slots, subs, sub, kd, rare)
                rare = 16 * ns < r  # fewer than 1 in 16 flagged: the branch is cheaper
                nft = _add(subs, ns, fine, ftouched, nft)
        return nt, nft, 0

    return run
