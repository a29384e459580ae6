"""Excitation trajectories (denavit.excitation_trajectory, ``denavit excite``) against independent routes.

Truth never comes from the code under test: the series is re-evaluated here from its coefficients by the
textbook formula (Swevers et al. 1997, eq. 9) on a grid 40 times finer than the optimiser's; the derivatives
are checked by central differences of the samples; the condition number and the rank by numpy's SVD of the
base regressor stacked here; the CSV is read back by read_measurements (and its header by the csv module).
"""

from __future__ import annotations

import csv
import json

import numpy as np
import pytest

import denavit
from denavit import ShapeError
from denavit.calibration import excitation_trajectory
from denavit.cli import main
from denavit.numeric import base_parameters, base_regressor

ROBOTS = ("puma560", "panda")
#: A cheap design (the default budget is 2 starts x 10 iterations of 5 harmonics): enough to test the contract.
CHEAP = {"harmonics": 3, "starts": 1, "max_iterations": 4, "instants": 16, "samples": 400}


@pytest.fixture(scope="module", params=ROBOTS)
def designed(request):
    robot = denavit.load_robot(request.param)
    return robot, excitation_trajectory(robot, seed=3, **CHEAP)


def series(res, t):
    """q, q̇, q̈ at t from the coefficients, written out term by term (not the module's basis matrices)."""
    w = 2 * np.pi * res.base_freq
    q = np.tile(res.q0, (t.size, 1))
    qd, qdd = np.zeros_like(q), np.zeros_like(q)
    for l in range(1, res.a.shape[1] + 1):
        s, c = np.sin(w * l * t)[:, None], np.cos(w * l * t)[:, None]
        a, b = res.a[:, l - 1], res.b[:, l - 1]
        q += a / (w * l) * s - b / (w * l) * c
        qd += a * c + b * s
        qdd += -a * w * l * s + b * w * l * c
    return q, qd, qdd


def test_excite_limits_hold_between_the_optimiser_instants(designed):
    robot, res = designed
    lim = robot.q_limits
    width = lim[:, 1] - lim[:, 0]
    np.testing.assert_allclose(res.q_limits, np.column_stack([lim[:, 0] + 0.05 * width, lim[:, 1] - 0.05 * width]))
    t = np.linspace(0.0, res.period, 20_000)  # 40x the optimiser's constraint grid of 8 per harmonic
    q, qd, qdd = series(res, t)
    assert np.all(q >= res.q_limits[:, 0] - 1e-12) and np.all(q <= res.q_limits[:, 1] + 1e-12)
    assert np.all(np.abs(qd) <= res.qd_max + 1e-12) and np.all(np.abs(qdd) <= res.qdd_max + 1e-12)
    np.testing.assert_allclose(res.qd_max, 1.0)  # the stated defaults of a robot file without rate limits
    np.testing.assert_allclose(res.qdd_max, 4.0)
    # the trajectory uses its room: some limit of each joint is (nearly) reached, and 'active' says which
    used = np.column_stack([np.abs(q - res.q_limits.mean(axis=1)).max(0) * 2 / (res.q_limits[:, 1] - res.q_limits[:, 0]),
                            np.abs(qd).max(0) / res.qd_max, np.abs(qdd).max(0) / res.qdd_max])
    np.testing.assert_allclose(res.usage, used, atol=1e-4)
    assert np.array_equal(res.active, res.usage >= 1 - 1e-3) and res.active.any()


def test_excite_samples_are_the_series_and_its_finite_differences(designed):
    _, res = designed
    dt = res.period / 400
    np.testing.assert_allclose(res.t, np.arange(400) * dt, rtol=0, atol=1e-12)
    q, qd, qdd = series(res, res.t)
    for got, want in ((res.q, q), (res.qd, qd), (res.qdd, qdd)):
        np.testing.assert_allclose(got, want, rtol=0, atol=1e-10)
    # central differences of the samples: error <= dt²/6 max|third derivative| (bounded by the coefficients)
    w = 2 * np.pi * res.base_freq * np.arange(1, res.a.shape[1] + 1)
    c = np.hypot(res.a, res.b)
    for f, df, k in ((res.q, res.qd, 2), (res.qd, res.qdd, 3)):
        bound = dt**2 / 6 * (c * w**k).sum(axis=1)
        err = np.abs((f[2:] - f[:-2]) / (2 * dt) - df[1:-1])
        assert np.all(err <= bound + 1e-9), (err.max(axis=0), bound)
        assert err.max() > 0  # the differences are not copies


def test_excite_lowers_the_condition_number_with_full_rank(designed):
    robot, res = designed
    base = base_parameters(robot)
    assert res.n_base == base.rank and res.rank == base.rank
    q, qd, qdd = series(res, res.instants)
    W = base_regressor(robot, q, qd, qdd).reshape(-1, base.rank)
    s = np.linalg.svd(W, compute_uv=False)
    np.testing.assert_allclose(res.cond, s[0] / s[-1], rtol=1e-6)
    assert res.cond < 0.8 * res.cond_initial
    assert np.linalg.matrix_rank(W) == base.rank
    # the whole sampled trajectory, not only the instants of the optimisation, identifies every base parameter
    Wall = base_regressor(robot, res.q[::4], res.qd[::4], res.qdd[::4]).reshape(-1, base.rank)
    assert np.linalg.matrix_rank(Wall) == base.rank


def test_excite_cli_writes_a_csv_that_reads_back(tmp_path, capsys):
    path = tmp_path / "traj.csv"
    code = main(["excite", "puma560", "-o", str(path), "--harmonics", "2", "--starts", "1", "--iterations", "3",
                 "--period", "4", "--rate", "25", "--seed", "5", "--center", "--json"])
    out = capsys.readouterr().out
    assert code == 0
    data = json.loads(out)
    assert data["samples"] == 100 and data["cond"] < data["cond_initial"] and data["rank"] == data["n_base"] == 52
    assert data["at_rest"] is False and len(data["active"]["qd"]) == 6
    lim = denavit.load_robot("puma560").q_limits  # --center: q0 in the middle of the limits (symmetric margin)
    np.testing.assert_allclose(data["q0"], lim.mean(axis=1), atol=1e-9)
    m = denavit.read_measurements(path, denavit.load_robot("puma560"))
    assert m.t.shape == (100,) and m.q.shape == m.qd.shape == m.qdd.shape == (100, 6) and m.tau is None
    with open(path, newline="") as fh:  # the header, read by the csv module
        header = next(row for row in csv.reader(fh) if not row[0].startswith("#"))
    assert header == ["t"] + [f"{g}{i}" for g in ("q", "qd", "qdd") for i in range(1, 7)]
    np.testing.assert_allclose(m.t, np.arange(100) / 25, atol=1e-12)
    res = type("R", (), {"base_freq": 0.25, "q0": np.array(data["q0"]), "a": np.array(data["a"]),
                         "b": np.array(data["b"])})
    for got, want in zip((m.q, m.qd, m.qdd), series(res, m.t)):
        np.testing.assert_allclose(got, want, rtol=0, atol=1e-12)


def test_excite_cli_deg_writes_degrees(tmp_path, capsys):
    paths = [tmp_path / "rad.csv", tmp_path / "deg.csv"]
    for path, extra in zip(paths, ([], ["--deg", "--qd-max", "57.29577951308232"])):
        assert main(["excite", "planar2r", "-o", str(path), "--harmonics", "1", "--starts", "1", "--iterations", "2",
                     "--rate", "2", *extra]) == 0
    text = capsys.readouterr().out
    assert "deg" in text and "does not start or end at rest" in text
    robot = denavit.load_robot("planar2r")
    rad, deg = (np.loadtxt(p, delimiter=",", comments="#", skiprows=2) for p in paths)
    np.testing.assert_allclose(deg[:, 1:], np.degrees(rad[:, 1:]), rtol=1e-9, atol=1e-9)
    back = denavit.read_measurements(paths[1], robot, angle_unit="deg")
    np.testing.assert_allclose(back.q, rad[:, 1:3], rtol=1e-12, atol=1e-12)


@pytest.mark.parametrize("argv, what", [
    (["--harmonics", "0"], "--harmonics"),
    (["--harmonics", "x"], "--harmonics"),
    (["--period", "-1"], "--period"),
    (["--rate", "0"], "--rate"),
    (["--rate", "1e5", "--duration", "1e4"], "samples"),
    (["--qd-max", "1, 2"], "--qd-max"),
    (["--qd-max", "-1"], "--qd-max"),
    (["--qdd-max", "nan"], "--qdd-max"),
    (["--qdd-max", "__import__('os')"], "--qdd-max"),
    (["-o", "traj.txt"], "-o"),
    (["--seed", "-3"], "--seed"),
])
def test_excite_cli_bad_input_exits_2_with_one_line(tmp_path, capsys, monkeypatch, argv, what):
    monkeypatch.chdir(tmp_path)
    code = main(["excite", "puma560", *argv])
    err = capsys.readouterr().err
    assert code == 2
    assert err.count("\n") == 1 and "Traceback" not in err and what in err, err


def test_excite_cli_unknown_robot_exits_2(capsys):
    assert main(["excite", "no-such-arm", "-o", "x.csv"]) == 2
    assert capsys.readouterr().err.count("\n") == 1


def test_excite_refuses_bad_arguments():
    robot = denavit.load_robot("planar2r")
    with pytest.raises(ValueError, match="harmonics"):
        excitation_trajectory(robot, harmonics=0)
    with pytest.raises(ValueError, match="base_freq"):
        excitation_trajectory(robot, base_freq=float("nan"))
    with pytest.raises(ShapeError, match="q_limits"):
        excitation_trajectory(robot, q_limits=[[-1, 1]])
    with pytest.raises(ShapeError, match="qd_max"):
        excitation_trajectory(robot, qd_max=[1, 2, 3])
    with pytest.raises(ValueError, match="qdd_max"):
        excitation_trajectory(robot, qdd_max=0)
    with pytest.raises(denavit.ModelError, match="joint 2"):
        excitation_trajectory(robot, q_limits=[[-1, 1], [0.5, 0.5]])


def test_excite_reports_progress_per_start_and_iteration():
    seen = []
    res = excitation_trajectory(denavit.load_robot("planar2r"), harmonics=2, starts=2, max_iterations=3, seed=2,
                                progress=seen.append)
    starts = [s for s in seen if "iteration" not in s]
    assert [s.split(":")[0] for s in starts] == ["start 1/2", "start 2/2"]
    assert float(starts[0].split("cond ")[1]) == pytest.approx(res.cond_initial, rel=1e-3)
    assert len(seen) - len(starts) == res.iterations  # one line per SLSQP iteration


@pytest.mark.parametrize("duration", [4.0, 15.0])
def test_excite_durations_other_than_a_period(duration):
    # shorter: the limits are imposed (and hold) on [0, duration] only; longer: the period repeats
    res = excitation_trajectory(denavit.load_robot("planar2r"), harmonics=2, starts=1, max_iterations=3,
                                duration=duration, samples=int(duration * 20), seed=4)
    assert res.t[-1] == pytest.approx(duration - 0.05)
    t = np.linspace(0.0, min(duration, res.period), 5000)
    q, qd, qdd = series(res, t)
    assert np.all(q >= res.q_limits[:, 0] - 1e-12) and np.all(q <= res.q_limits[:, 1] + 1e-12)
    assert np.all(np.abs(qd) <= res.qd_max + 1e-12) and np.all(np.abs(qdd) <= res.qdd_max + 1e-12)
    if duration > res.period:
        later = res.t >= res.period
        np.testing.assert_allclose(res.q[later], res.q[: later.sum()], atol=1e-9)
