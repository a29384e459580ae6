"""The workspace sampler's random stream: SplitMix64 words keyed by the seed, one run of them per random block.

Block b's words are those of one SplitMix64 stream (Steele, Lea & Flood, OOPSLA 2014) keyed by
``SeedSequence(seed)``, from position b·2³² on: word w of the block is mix(s + (w + 1)·γ), s the block's starting
state, a pure function of its counter (any worker starts any block); each word gives two 32-bit joint values.
The numpy route draws here; the fused kernel (``_fused``) computes the same words.
"""

from __future__ import annotations

import functools

import numpy as np

__all__ = ["HALF_WORD", "GAMMA", "MIX1", "MIX2", "BLOCK_STRIDE", "block_state", "mix64", "draw"]

#: 2⁻³²: a 32-bit random half-word as a number in [0, 1).
HALF_WORD = 2.0**-32
#: SplitMix64's Weyl increment γ (the golden ratio's 64 fraction bits) and its output multipliers.
GAMMA, MIX1, MIX2 = 0x9E3779B97F4A7C15, 0xBF58476D1CE4E5B9, 0x94D049BB133111EB
#: Words of the stream between the starts of two blocks (a block takes at most BLOCK·n/2 of them).
BLOCK_STRIDE = 2**32


def block_state(entropy: int, blocks) -> np.ndarray:
    """Starting states (uint64, shaped as ``blocks``) of the random blocks ``blocks`` of seed ``entropy``:
    K + b·2³²·γ (mod 2⁶⁴), K the first 64-bit word of ``SeedSequence(entropy)``.  Block b's words are those of
    one SplitMix64 stream from position b·2³² on, so blocks never overlap (b < 2³², a block < 2³² words)."""
    key = _key(entropy)
    with np.errstate(over="ignore"):
        return key + np.asarray(blocks, dtype=np.uint64) * np.uint64(BLOCK_STRIDE * GAMMA % 2**64)


@functools.lru_cache(maxsize=64)
def _key(entropy: int) -> np.uint64:
    """K: the first 64-bit word of ``SeedSequence(entropy)`` (kept: every task asks for it)."""
    return np.random.SeedSequence(entropy).generate_state(1, np.uint64)[0]


def mix64(z: np.ndarray) -> np.ndarray:
    """SplitMix64's output function on uint64 words, in place (Steele, Lea & Flood, OOPSLA 2014)."""
    z ^= z >> np.uint64(30)
    z *= np.uint64(MIX1)
    z ^= z >> np.uint64(27)
    z *= np.uint64(MIX2)
    z ^= z >> np.uint64(31)
    return z


def draw(job, block: int, q: np.ndarray, joint1=None) -> np.ndarray:
    """Fill q (m, n) (C-contiguous) with the joint values of random block ``block`` (its first m samples) of
    ``job`` (its ``entropy`` and ``limits`` (n, 2)); ``joint1`` = (lo, span) replaces joint 1's lo and hi − lo
    (the block's stratum, ``_strata``).

    Value v of the block (row-major: sample v div n, joint v mod n) is u = h·2⁻³², h the low (v even) or high
    (v odd) 32 bits of word w = v div 2, and word w is SplitMix64's mix(s + (w + 1)·γ) with s the block's
    starting state (:func:`block_state`); the joint value is lo + u·(hi − lo).  (32 bits a joint value: steps
    of 2⁻³² of its range.)"""
    m, n = q.shape
    words = np.arange(1, -(-m * n // 2) + 1, dtype=np.uint64)
    words *= np.uint64(GAMMA)
    words += block_state(job.entropy, block)
    mix64(words)
    flat = q.reshape(-1)
    flat[0::2] = words[:(m * n + 1) // 2] & np.uint64(0xFFFFFFFF)  # exact: below 2³²
    flat[1::2] = words[:m * n // 2] >> np.uint64(32)
    lo, span = job.limits[:, 0].copy(), job.limits[:, 1] - job.limits[:, 0]
    if joint1 is not None:
        lo[0], span[0] = joint1[0], joint1[1]
    q *= HALF_WORD
    q *= span
    q += lo  # = lo + u·(hi − lo), in place
    return q
