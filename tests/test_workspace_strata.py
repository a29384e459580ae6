"""The sampling order of denavit.scale._strata: sweeps over strata of joint 1 with multinomial counts.

Oracles: the moments of the multinomial law (mean n/S, variance n·p(1 − p), covariance −n·p²), the plain
stream's blocks (one stratum a sweep), the uniform law (Kolmogorov–Smirnov) of the joint values, an independent
i.i.d. sampler (numpy's generator and the planar 2R arm's closed-form FK) for the statistics the volume estimate
reads (occupied cells, cells hit once and twice), the closed-form area π(l1 + l2)², an independent binning
(numpy.histogramdd), and the same run on other routes, workers and schedulers (identical counts).
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from _occupancy_same import same_occupancy, stanford_routes

import denavit
from denavit.scale import BLOCK, occupancy, sample_positions
from denavit.scale import _strata
from denavit.scale._refine import pilot_blocks
from denavit.scale._sampler import block_table, make_job, run_blocks
from denavit.scale._stream import draw

KS_1PC = 1.63  # Kolmogorov–Smirnov critical value √n·D at the 1 % level


@pytest.fixture
def strata(monkeypatch):
    """Strata from 2¹⁰ samples on (instead of 2¹⁸), so runs of a few blocks are stratified."""
    monkeypatch.setattr(_strata, "STRATUM_SAMPLES", 2**10)


def _ks(u: np.ndarray) -> float:
    """√n times the Kolmogorov–Smirnov distance of u from the uniform law on [0, 1)."""
    u = np.sort(u)
    n = u.size
    return float(np.sqrt(n) * max((np.arange(1, n + 1) / n - u).max(), (u - np.arange(n) / n).max()))


def test_stratum_counts_have_the_multinomial_moments():
    n, S, runs = 1000, 8, 3000
    c = np.array([_strata.multinomial_halves(seed, 1, n, S) for seed in range(runs)], dtype=float)
    assert c.shape == (runs, S) and np.all(c.sum(axis=1) == n) and c.min() >= 0
    p = 1 / S
    var = n * p * (1 - p)
    assert np.all(np.abs(c.mean(axis=0) - n * p) < 5 * np.sqrt(var / runs))
    assert np.all(np.abs(c.var(axis=0) / var - 1) < 5 * np.sqrt(2 / runs))
    cov = np.cov(c, rowvar=False)[np.triu_indices(S, 1)]
    assert abs(cov.mean() / (-n * p * p) - 1) < 0.1  # the pairs of any two strata, not only siblings
    # a fixed (proportional) allocation would give variance 0: this is the multinomial's spread
    assert _strata.multinomial_halves(7, 0, n, 1).tolist() == [n]
    assert np.array_equal(_strata.multinomial_halves(7, 0, n, S), _strata.multinomial_halves(7, 0, n, S))
    assert not np.array_equal(_strata.multinomial_halves(7, 0, n, S), _strata.multinomial_halves(7, 1, n, S))


def test_strata_per_sweep():
    m = _strata.STRATUM_SAMPLES
    assert [_strata.strata_for(k) for k in (0, m - 1, m, 2 * m - 1, 2 * m, 5 * m, 10**12)] == [
        1, 1, 1, 1, 2, 4, _strata.MAX_STRATA]


def test_one_stratum_is_the_plain_stream():
    """Runs below two strata a sweep keep the plain stream's blocks (BLOCK samples each, joint 1 over its range)."""
    robot = denavit.load_robot("puma560")
    n = 2 * BLOCK + 99
    assert n - BLOCK < 2 * _strata.STRATUM_SAMPLES
    job = make_job(robot, n, None, 3)
    assert [c.size for c in job.layout.counts] == [1, 1]
    plain = dataclasses.replace(job, layout=None)
    assert run_blocks(job) == run_blocks(plain) == 3
    for a, b in zip(block_table(job, 0, 3), block_table(plain, 0, 3)):
        assert np.array_equal(a, b)
    assert block_table(job, 0, 3)[0].tolist() == [BLOCK] * 2 + [99]


def test_layout_blocks_cover_each_stratum(strata):
    samples = 7 * BLOCK + 321
    lay = _strata.layout(5, samples, BLOCK)
    assert pilot_blocks(8) == 1
    assert [c.size for c in lay.counts] == [64, 256]  # 65 536 and 393 537 samples over 2¹⁰ a stratum
    sizes, strat, S = lay.sizes(0, lay.blocks)
    assert sizes.sum() == samples and sizes.max() <= BLOCK and sizes.min() >= 1
    assert sizes[:lay.pilot_end].sum() == BLOCK  # the pilot: one plain block's worth of samples
    for w, (a, b) in enumerate(((0, lay.pilot_end), (lay.pilot_end, lay.blocks))):
        assert np.all(S[a:b] == lay.counts[w].size) and np.all(np.diff(strat[a:b]) >= 0)  # in order of joint 1
        assert np.array_equal(np.bincount(strat[a:b], sizes[a:b], minlength=S[a]), lay.counts[w])


def test_stratified_joint_values(strata):
    """Each block's joint 1 lies in its stratum, each stratum holds its multinomial count, and the pooled joint
    values of the run are uniform over the limits (KS), joint 1 within each stratum too."""
    robot = denavit.load_robot("stanford")
    n = 6 * BLOCK + 777
    job = make_job(robot, n, None, 21)
    lim = job.limits
    sizes, joint1 = block_table(job, 0, run_blocks(job))
    q = np.concatenate([draw(job, b, np.empty((int(sizes[b]), robot.dof)), joint1[b]) for b in range(sizes.size)])
    assert q.shape == (n, robot.dof)
    lo, w = joint1[:, :1], joint1[:, 1:]
    first = np.repeat(np.arange(sizes.size), sizes)
    t = (q[:, 0] - lo[first, 0]) / w[first, 0]
    assert t.min() >= 0 and t.max() <= 1
    for a in range(robot.dof):
        assert _ks((q[:, a] - lim[a, 0]) / (lim[a, 1] - lim[a, 0])) < KS_1PC
    assert _ks(t) < KS_1PC  # within the strata
    w0 = (lim[0, 1] - lim[0, 0]) / np.array([c.size for c in job.layout.counts])
    pilot = job.layout.pilot_end
    stratum = np.floor((q[:, 0] - lim[0, 0]) / np.repeat(np.where(np.arange(sizes.size) < pilot, w0[0], w0[1]),
                                                           sizes))
    split = int(sizes[:pilot].sum())
    for c, s in ((job.layout.counts[0], stratum[:split]), (job.layout.counts[1], stratum[split:])):
        assert c.size > 1 and np.array_equal(np.bincount(np.minimum(s, c.size - 1).astype(int), minlength=c.size), c)


def _planar2r_positions(rng, n):
    """An independent i.i.d. sampler: planar 2R (l1 = l2 = 1), joints uniform in [−π, π), closed-form FK."""
    t1, t2 = rng.uniform(-np.pi, np.pi, (2, n))
    return np.stack([np.cos(t1) + np.cos(t1 + t2), np.sin(t1) + np.sin(t1 + t2)], axis=1)


def _hit_statistics(p, edge=0.02):
    h, _, _ = np.histogram2d(p[:, 0], p[:, 1], bins=int(round(4 / edge)), range=[(-2, 2), (-2, 2)])
    return np.array([np.count_nonzero(h), np.count_nonzero(h == 1), np.count_nonzero(h == 2)], dtype=float)


def test_stratified_sampling_has_the_statistics_of_iid_sampling(strata):
    """Occupied cells, cells hit once (f1) and twice (f2) — what coverage and Chao1 read — of stratified runs
    against an independent i.i.d. sampler, over 24 seeds each: the means agree within 5 standard errors."""
    robot = denavit.load_robot("planar2r")
    n, runs = 2**15, 24
    assert [c.size for c in _strata.layout(0, n, BLOCK).counts] == [32]
    ours = np.array([_hit_statistics(sample_positions(robot, n, seed=s)[:, :2]) for s in range(runs)])
    rng = np.random.default_rng(2024)
    iid = np.array([_hit_statistics(_planar2r_positions(rng, n)) for _ in range(runs)])
    se = np.sqrt(ours.var(axis=0, ddof=1) / runs + iid.var(axis=0, ddof=1) / runs)
    assert np.all(np.abs(ours.mean(axis=0) - iid.mean(axis=0)) < 5 * se), (ours.mean(axis=0), iid.mean(axis=0), se)
    assert ours[:, 1].mean() > 1000  # a sparse regime: f1 matters


@pytest.mark.slow
def test_stratified_run_holds_the_area(strata):
    robot = denavit.load_robot("planar2r")
    ws = occupancy(robot, 2**20, seed=4, scheduler="synchronous")  # 16 and 256 strata
    e = ws.estimate
    assert e.coverage >= 0.99 and e.low <= np.pi * 2.0**2 <= e.high and int(ws.counts.sum()) == 2**20
    ws = occupancy(robot, 2**20, 0.05, seed=5, scheduler="synchronous", refine=4)  # sub-cells after the pilot
    e = ws.estimate
    assert ws.refinement is not None and e.resolution < 0.05 and e.low <= np.pi * 2.0**2 <= e.high


@pytest.mark.slow
def test_stratified_counts_are_the_histogram_of_the_sampled_positions(strata):
    robot = denavit.load_robot("puma560")
    n = 3 * BLOCK + 123
    ws = occupancy(robot, n, seed=11, scheduler="synchronous")
    p = sample_positions(robot, n, seed=11)
    g = ws.grid
    hist, _ = np.histogramdd(p - g.centre, bins=g.side, range=[(g.lo, -g.lo)] * 3)  # independent binning
    assert np.array_equal(hist.astype(np.uint64), ws.counts) and int(ws.counts.sum()) == n
    np.testing.assert_array_equal(ws.bounds_min, p.min(axis=0))


@pytest.mark.slow
def test_stratified_runs_are_identical_for_routes_workers_and_chunks(strata):
    pytest.importorskip("numba")
    robot, n, args, ref, fk = stanford_routes()
    same_occupancy(ref, occupancy(robot, n, scheduler="processes", workers=2, chunk=3 * BLOCK, fk=fk, **args))
    plain = occupancy(robot, n, scheduler="synchronous", fk=fk, **args | {"refine": 0})
    assert np.array_equal(plain.counts, ref.counts)  # the layout does not depend on refine
