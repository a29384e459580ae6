"""Reachability and manipulability maps (denavit.scale.reachability).

Oracles: numeric IK (a converged solve within the limits proves a pose reachable), a finite-difference Jacobian
for the manipulability, the sampled workspace (FK route) for the reachable volume, and the same map on other
schedulers.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

import denavit
from denavit.errors import UnsupportedRobotError
from denavit.scale import occupancy
from denavit.scale._reach import _analytic_task, _poses, orientation_set, reachability


@settings(max_examples=20, deadline=None)
@given(st.integers(1, 500))
def test_orientation_set_is_rotations_spread_over_so3(k):
    R = orientation_set(k)
    assert R.shape == (k, 3, 3)
    np.testing.assert_allclose(R @ R.transpose(0, 2, 1), np.broadcast_to(np.eye(3), R.shape), atol=1e-12)
    np.testing.assert_allclose(np.linalg.det(R), 1.0, atol=1e-12)
    if k >= 100:  # near-uniform: the mean rotation of a uniform set is ~0, and no two coincide
        assert np.abs(R.mean(axis=0)).max() < 0.1
        tr = np.einsum("aij,bij->ab", R, R)  # trace(Ra^T Rb) = 1 + 2 cos(angle)
        np.fill_diagonal(tr, -1)
        assert tr.max() < 3 - 1e-6


def _fd_manipulability(robot, q, eps=1e-6):
    """√det(J Jᵀ) with J by central differences of the FK (position rows and the rotation's axial part)."""
    cols = []
    for i in range(robot.dof):
        dq = np.zeros(robot.dof)
        dq[i] = eps
        Tp, Tm = denavit.forward_kinematics(robot, q + dq), denavit.forward_kinematics(robot, q - dq)
        v = (Tp[:3, 3] - Tm[:3, 3]) / (2 * eps)
        dR = (Tp[:3, :3] - Tm[:3, :3]) / (2 * eps) @ denavit.forward_kinematics(robot, q)[:3, :3].T
        cols.append(np.concatenate([v, [dR[2, 1], dR[0, 2], dR[1, 0]]]))
    J = np.array(cols).T
    return np.sqrt(max(np.linalg.det(J @ J.T), 0.0))


@pytest.mark.slow
def test_analytic_reachability_agrees_with_numeric_ik():
    robot = denavit.load_robot("puma560")
    rmap = reachability(robot, 0.25, 6, scheduler="synchronous", screen=False)
    g = rmap.grid
    rng = np.random.default_rng(0)
    reached, missed = np.argwhere(rmap.fraction > 0), np.argwhere(rmap.fraction == 0)
    assert len(reached) >= 5 and len(missed) >= 2
    # reached cells (a random draw of all cells was ~95 % outside the workspace: nothing checked the reached
    # ones) and a few missed ones (each failing numeric solve costs ~0.3 s of restarts)
    cells = np.concatenate([reached[rng.choice(len(reached), 5, replace=False)],
                            missed[rng.choice(len(missed), 2, replace=False)]])
    T = _poses(g, cells, rmap.orientations)  # (7, 6, 4, 4)
    agree = total = solved = 0
    for i, c in enumerate(cells):
        for k in range(len(rmap.orientations)):
            num = denavit.solve_ik(robot, T[i, k], restarts=6, rng=np.random.default_rng(k)).success
            res = denavit.analytic_ik(robot, T[i, k])
            ana = res.solutions.shape[0] > 0
            if num:
                assert ana, (c, k)  # numeric success proves the pose reachable within the limits
            solved += num
            agree += num == ana
            total += 1
        f_direct = np.mean([denavit.analytic_ik(robot, T[i, k]).solutions.shape[0] > 0
                            for k in range(len(rmap.orientations))])
        assert rmap.fraction[tuple(c)] == pytest.approx(f_direct)
    assert agree >= 0.9 * total and solved >= 5


def test_manipulability_is_the_best_solution_averaged():
    robot = denavit.load_robot("puma560")
    rng = np.random.default_rng(1)
    q = rng.uniform(-1, 1, 6)
    p = denavit.forward_kinematics(robot, q)[:3, 3]
    rmap = reachability(robot, 0.2, 5, scheduler="synchronous", screen=False)
    g = rmap.grid
    cell = np.floor((p - g.centre - g.lo) / g.resolution).astype(int)[None]
    cells, frac, w = _analytic_task(robot, g, cell, rmap.orientations)
    T = _poses(g, cell, rmap.orientations)[0]
    best = []
    for k in range(len(T)):
        sols = denavit.analytic_ik(robot, T[k]).solutions
        if len(sols):
            best.append(max(_fd_manipulability(robot, s) for s in sols))
    assert frac[0] == pytest.approx(len(best) / len(T))
    assert w[0] == pytest.approx(np.mean(best) if best else 0.0, rel=1e-5, abs=1e-9)
    assert rmap.fraction[tuple(cell[0])] == pytest.approx(frac[0])


@pytest.mark.slow
def test_reachable_volume_matches_the_sampled_workspace():
    robot = denavit.load_robot("puma560")
    rmap = reachability(robot, 0.1, 12)
    ws = occupancy(robot, 2_000_000, seed=3)
    e = ws.estimate
    # cells whose centre is reachable vs the FK-sampled volume: two routes, same set (to a boundary layer)
    assert 0.85 * e.low <= rmap.summary()["reachable_volume"] <= 1.15 * e.high


def test_same_map_on_every_scheduler():
    robot = denavit.load_robot("ur5")
    a = reachability(robot, 0.3, 4, scheduler="synchronous")
    b = reachability(robot, 0.3, 4, scheduler="threads", workers=2)
    assert np.array_equal(a.fraction, b.fraction) and np.array_equal(a.manipulability, b.manipulability)
    assert a.fraction.max() > 0 and a.summary()["voxels_reached"] > 0


def test_screen_keeps_the_reached_cells():
    robot = denavit.load_robot("stanford")
    full = reachability(robot, 0.3, 4, scheduler="synchronous", screen=False)
    screened = reachability(robot, 0.3, 4, scheduler="synchronous")
    assert np.array_equal(full.fraction, screened.fraction) and screened.voxels <= full.voxels


def test_arms_that_do_not_set_the_pose_are_refused():
    with pytest.raises(UnsupportedRobotError, match="6 or more joints"):
        reachability(denavit.load_robot("planar3r"), 0.1, 10)


def test_save(tmp_path):
    rmap = reachability(denavit.load_robot("puma560"), 0.4, 3, scheduler="synchronous")
    rmap.save(tmp_path / "r.npz")
    with np.load(tmp_path / "r.npz", allow_pickle=False) as z:
        assert np.array_equal(z["fraction"], rmap.fraction) and z["orientations"].shape == (3, 3, 3)


def test_progress_covers_the_screen_and_the_map(capsys, monkeypatch):
    """The position screen (seconds on a fine grid) drew no progress line; counts read 49,531, not 4.95e+04."""
    monkeypatch.setattr("denavit.scale._reach.SCREEN_SAMPLES", 2**17)
    rmap = reachability(denavit.load_robot("ur5"), 0.2, 2, scheduler="synchronous", progress=True)
    lines = capsys.readouterr().err.replace("\r", "\n").split("\n")
    screen = [ln for ln in lines if "samples" in ln]
    voxels = [ln for ln in lines if "voxels" in ln]
    assert screen and f"{2**17:,}/{2**17:,} samples" in screen[-1]
    assert voxels and f"{rmap.voxels:,}/{rmap.voxels:,} voxels" in voxels[-1] and rmap.voxels >= 1000
    assert lines.index(screen[-1]) < lines.index(voxels[0])  # the screen first, then the map
