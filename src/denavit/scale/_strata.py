"""The order in which a run draws its samples: sweeps over strata of joint 1, each with multinomial counts.

A run of N samples is drawn in two *sweeps*, the pilot (the first ``pilot_blocks`` · BLOCK samples, see
``_refine``) and the rest.  A sweep of m samples cuts the range of joint 1 into S equal strata (S a power of
two, :func:`strata_for`), gives stratum s the count m_s of a multinomial draw (m; 1/S, …, 1/S) — conditional
binomials of probability 1/2 down a binary tree, from numpy's ``Generator.binomial`` on a Philox stream keyed by
``SeedSequence(seed, spawn_key=(STRATA_KEY, sweep))`` — and draws m_s samples uniform in that stratum (joint 1
uniform in its slice, the other joints uniform in their limits), strata in the order of joint 1.

Why: consecutive samples then lie in one wedge of the workspace, so the increments of the counts hit lines of
the accumulator that are already in the cache (a random increment into a 16–64 MiB grid was an L2 miss per
sample).  What it does to the statistics: nothing.  N i.i.d. uniform samples, taken as an unordered set, are
exactly this: the numbers falling in each stratum are multinomial (N; 1/S, …), and given those numbers the
samples in a stratum are i.i.d. uniform in it (each sample independently picks stratum s with probability
1/S, then a point uniform in s: the law of the numbers m_s and of the points factors as the multinomial
N!/∏m_s! · S^−N times the uniform laws in the strata).  The counts per
cell, the bounds and the reach depend on the set only, not its order, so every estimator (Good–Turing coverage,
Chao1, the volume interval, the pilot's plan, whose sweep is a set of its own) sees exactly the law of i.i.d.
sampling.  This is not proportional stratified sampling (fixed m/S per stratum), which would lower the
variance but break the Poisson/multinomial model Chao1 rests on.

A *block* is now a run of at most BLOCK samples of one stratum of one sweep (the last block of a stratum may
be shorter); blocks are numbered through the sweeps and strata in order, and block b draws from the SplitMix64
words of block b (``_stream.block_state``).  With S = 1 in both sweeps (runs shorter than 2·STRATUM_SAMPLES a
sweep) the blocks are the plain stream's, so those runs are unchanged; a run with more strata is not a prefix of
a longer one (its stratum counts depend on N).
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np

__all__ = ["STRATUM_SAMPLES", "MAX_STRATA", "STRATA_KEY", "Layout", "layout", "multinomial_halves", "strata_for"]

#: A sweep has S strata with S the largest power of two ≤ its samples / STRATUM_SAMPLES (at least one):
#: enough samples per stratum that a wedge's lines of the counts are reused while they are in the cache (2¹⁶
#: rather than 2¹⁸: 5 % less CPU for the Puma at 10⁸ samples, whose pilot then has 128 strata instead of 32).
STRATUM_SAMPLES = 2**16
#: Most strata per sweep.
MAX_STRATA = 256
#: First spawn key of the generator of the stratum counts (sweep w: (STRATA_KEY, w)).
STRATA_KEY = 0x5354524154


def strata_for(samples: int) -> int:
    """Strata of a sweep of ``samples``: the largest power of two ≤ samples / STRATUM_SAMPLES, 1 … MAX_STRATA."""
    s = 1
    while 2 * s <= min(MAX_STRATA, samples // STRATUM_SAMPLES):
        s *= 2
    return s


def multinomial_halves(entropy: int, sweep: int, samples: int, strata: int) -> np.ndarray:
    """Counts (strata,) int64 of a multinomial (samples; 1/strata, …) draw, strata a power of two: each node of a
    binary tree splits its count by a binomial of probability 1/2 (given its parent, a half of equal cells gets a
    Binomial(count, 1/2) share: the conditional law of a multinomial's margins), level by level."""
    c = np.array([samples], dtype=np.int64)
    if strata > 1:
        rng = np.random.Generator(np.random.Philox(np.random.SeedSequence(entropy, spawn_key=(STRATA_KEY, sweep))))
        while c.size < strata:
            left = rng.binomial(c, 0.5).astype(np.int64)
            c = np.stack([left, c - left], axis=1).reshape(-1)
    return c


@dataclass(frozen=True, eq=False)
class Layout:
    """The blocks of one run (picklable, a few kB: one count per stratum).

    Attributes
    ----------
    counts : tuple of ndarray (int64)
        Samples per stratum of joint 1, one array per sweep (its length the sweep's strata, a power of two).
    block : int
        Most samples per block (BLOCK).
    """

    counts: tuple
    block: int

    @cached_property
    def _table(self):
        """Per (sweep, stratum): samples, blocks, stratum index, strata of its sweep, and the blocks' cumsum (kept:
        a few kB, read by every task)."""
        n = np.concatenate(self.counts)
        nb = -(-n // self.block)
        s = np.concatenate([np.arange(c.size) for c in self.counts])
        S = np.concatenate([np.full(c.size, c.size) for c in self.counts])
        return n, nb, s, S, np.cumsum(nb)

    @property
    def blocks(self) -> int:
        """Blocks of the run."""
        return int(sum(int((-(-c // self.block)).sum()) for c in self.counts))

    @property
    def pilot_end(self) -> int:
        """Blocks of the first sweep (the pilot's when the run has one)."""
        return int((-(-self.counts[0] // self.block)).sum())

    def sizes(self, first: int, count: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Samples (count,) int64, stratum and strata (count,) of blocks first … first+count−1."""
        n, nb, s, S, cum = self._table
        b = np.arange(first, first + count)
        k = np.searchsorted(cum, b, side="right")
        j = b - (cum[k] - nb[k])
        return np.minimum(self.block, n[k] - j * self.block).astype(np.int64), s[k], S[k]

    def limits(self, first: int, count: int, limits: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Samples (count,) of blocks first … first+count−1 and joint 1's (lo, span) (count, 2) for each: stratum
        s of S spans lo₁ + s·w … lo₁ + (s+1)·w, w = (hi₁ − lo₁)/S (exact: S a power of two); the value
        lo_s + u·w (u ∈ [0, 1)) is joint 1's, computed in this order by both routes."""
        sizes, s, S = self.sizes(first, count)
        lo, span = float(limits[0, 0]), float(limits[0, 1] - limits[0, 0])
        w = span / S
        out = np.empty((count, 2))
        out[:, 0] = np.where(S == 1, lo, lo + s * w)  # S = 1: lo itself (the plain stream's numbers)
        out[:, 1] = w
        return sizes, out


def layout(entropy: int, samples: int, block: int) -> Layout:
    """The layout of a run of ``samples``: a pilot sweep of ``_refine.pilot_blocks``·``block`` samples (of the
    plain block count; none for a run of one block) — whether or not the run refines, so the counts of a seed
    do not depend on ``refine`` — and a sweep of the rest, each with :func:`strata_for` strata and multinomial
    stratum counts."""
    from ._refine import pilot_blocks

    first = min(samples, pilot_blocks(-(-samples // block)) * block)
    sweeps = [m for m in (first, samples - first) if m > 0]
    return Layout(tuple(multinomial_halves(entropy, w, m, strata_for(m)) for w, m in enumerate(sweeps)), block)
