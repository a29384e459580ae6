"""Closed-form IK: every solution re-checked by FK, generating q among them, counts vs a dense numeric search."""

from __future__ import annotations


import numpy as np
import pytest

import denavit
from denavit import (Convention, DHLink, DHRobot, UnsupportedRobotError, analytic_ik, convert_convention,
                     forward_kinematics, load_robot, solve_ik)
from denavit.ik import ik_structure
from denavit.numeric import transform_from_xyz_rpy

from conftest import REDUCED, random_q_in_limits as _random_q
N = 60 if REDUCED else 250
SUPPORTED = [n for n in denavit.catalogue_names() if denavit.load_robot(n).dof <= 6]  # 7-joint arms: --free (test_ik_sweep)
CONTROLLED = {  # rows of the pose each kind of arm controls: residual projector built independently here
    "pose": (np.ones(3), np.ones(3)),
    "position": (np.ones(3), np.zeros(3)),
    "orientation": (np.zeros(3), np.ones(3)),
}


def _gap(robot, q, T, controlled):
    """Position gap and rotation angle between FK(q) and T, restricted to what the arm controls."""
    F = forward_kinematics(robot, q)
    dp = np.linalg.norm(F[..., :3, 3] - T[..., :3, 3], axis=-1)
    R = np.swapaxes(F[..., :3, :3], -1, -2) @ T[..., :3, :3]
    v = np.stack([R[..., 2, 1] - R[..., 1, 2], R[..., 0, 2] - R[..., 2, 0], R[..., 1, 0] - R[..., 0, 1]], -1)
    ang = np.arctan2(np.linalg.norm(v, axis=-1) / 2, (np.trace(R, axis1=-2, axis2=-1) - 1) / 2)
    if controlled == "position+heading":  # the heading: the angle between the x axes about the common axis
        ang = np.zeros_like(dp)
    elif controlled == "position":
        ang = np.zeros_like(dp)
    if controlled == "orientation":
        dp = np.zeros_like(dp)
    return dp, ang


def _joint_distance(robot, a, b):
    rev = np.array([t.value == "revolute" for t in robot.joint_types])
    d = a - b
    return np.max(np.where(rev, np.abs((d + np.pi) % (2 * np.pi) - np.pi), np.abs(d)), axis=-1)


ROWS = {"pose": [0, 1, 2, 3, 4, 5], "position": [0, 1, 2], "orientation": [3, 4, 5],
        "position+heading": [0, 1, 2, 5]}


def _sigma_min(robot, q, controlled="pose"):
    J = denavit.geometric_jacobian(robot, q)[..., ROWS[controlled], :]
    return np.linalg.svd(J, compute_uv=False)[..., -1]


@pytest.mark.parametrize("name", SUPPORTED)
def test_analytic_round_trip_and_generating_q(name):
    robot = load_robot(name)
    rng = np.random.default_rng(21)
    q = _random_q(robot, rng, N)
    T = forward_kinematics(robot, q)
    res = analytic_ik(robot, T)
    assert res.solutions.shape[:1] == (N,) and res.valid.shape == res.solutions.shape[:2]
    sols = res.solutions[res.valid]  # every returned solution, checked by FK
    Tk = np.broadcast_to(T[:, None], res.solutions.shape[:2] + (4, 4))[res.valid]
    dp, dw = _gap(robot, sols, Tk, res.controlled)
    assert dp.max() < 1e-8 and dw.max() < 1e-8
    if res.controlled == "position+heading":  # x axes agree after projection on the plane: same heading
        F = forward_kinematics(robot, sols)
        np.testing.assert_allclose(F[:, :3, 3], Tk[:, :3, 3], atol=1e-8)
    lim = robot.q_limits
    assert np.all((sols >= lim[:, 0] - 1e-9) & (sols <= lim[:, 1] + 1e-9))
    # the generating configuration is among the solutions (away from singular poses, where two
    # solutions merge and joint values are ill-conditioned)
    dist = np.nanmin(np.where(res.valid, _joint_distance(robot, res.solutions, q[:, None]), np.inf), axis=1)
    if name == "coaxial-6r":  # (was report000-6r) coaxial joints 1, 2: only q1 + q2 is determined
        qs = q.copy()
        qs[:, 0] += qs[:, 1]
        qs[:, 1] = 0.0
        dist = np.nanmin(np.where(res.valid, _joint_distance(robot, res.solutions, qs[:, None]), np.inf), axis=1)
        assert np.all(res.free[res.valid] != "")
    regular = _sigma_min(robot, q, res.controlled) > 1e-2
    assert np.all(dist[regular] < 1e-6), (name, np.sort(dist)[-3:])


def _distinct(robot, qs, tol=1e-5):
    out = []
    for q in qs:
        if all(_joint_distance(robot, q, p) > tol for p in out):
            out.append(q)
    return out


@pytest.mark.parametrize("name", ["puma560", "ur5", "stanford", "report001-6r", "report004-3-articulated-rrr",
                                  "scara", "planar3r", "report004-4-rrp"])
def test_analytic_count_equals_dense_numeric_search(name):
    robot = load_robot(name)
    rng = np.random.default_rng(5)
    poses, seeds = (2, 150) if REDUCED else (4, 400)
    res_kind = analytic_ik(robot, forward_kinematics(robot, _random_q(robot, rng, 1))[0])
    mask = {"pose": "pose", "position": "position", "position+heading": [1, 1, 1, 0, 0, 1]}[res_kind.controlled]
    for q in _random_q(robot, rng, poses):
        T = forward_kinematics(robot, q)
        an = analytic_ik(robot, T)
        num = solve_ik(robot, np.broadcast_to(T, (seeds, 4, 4)), _random_q(robot, rng, seeds), mask=mask,
                       restarts=0, rng=rng)
        found = _distinct(robot, num.q[num.success])
        assert len(found) == an.count, (name, q, len(found), an.count)
        for f in found:
            assert np.min(_joint_distance(robot, an.solutions, f)) < 1e-6


def test_conventions_give_the_same_solutions():
    std, mdh = load_robot("puma560"), load_robot("puma560-mdh")
    conv = convert_convention(std, Convention.MODIFIED)
    rng = np.random.default_rng(9)
    T = forward_kinematics(std, _random_q(std, rng, 20))
    a, b, c = analytic_ik(std, T), analytic_ik(mdh, T), analytic_ik(conv, T)
    np.testing.assert_array_equal(a.valid.sum(1), b.valid.sum(1))
    np.testing.assert_array_equal(a.valid.sum(1), c.valid.sum(1))
    for i in range(20):
        for s in a.solutions[i][a.valid[i]]:
            assert np.min(_joint_distance(std, b.solutions[i][b.valid[i]], s)) < 1e-8


def _random_pieper(rng, convention):
    """A random 6R arm whose last three axes meet at a point (any offsets in joints 1-3, any wrist angles)."""
    if convention == "standard":
        links = [DHLink(a=rng.uniform(-.5, .5), alpha=rng.uniform(-3, 3), d=rng.uniform(-.5, .5),
                        theta=rng.uniform(-3, 3)) for _ in range(3)]
        links[2] = DHLink(a=0.0 if rng.random() < 0.3 else rng.uniform(-.5, .5), alpha=rng.uniform(-3, 3),
                          d=links[2].d, theta=links[2].theta)
        links += [DHLink(a=0.0, alpha=rng.uniform(0.3, 2.8), d=rng.uniform(0.2, 0.6), theta=rng.uniform(-3, 3)),
                  DHLink(a=0.0, alpha=rng.uniform(0.3, 2.8), d=0.0, theta=rng.uniform(-3, 3)),
                  DHLink(a=rng.uniform(-.2, .2), alpha=rng.uniform(-3, 3), d=rng.uniform(-.2, .2))]
    else:
        links = [DHLink(a=rng.uniform(-.5, .5), alpha=rng.uniform(-3, 3), d=rng.uniform(-.5, .5),
                        theta=rng.uniform(-3, 3)) for _ in range(3)]
        links += [DHLink(a=rng.uniform(-.5, .5), alpha=rng.uniform(-3, 3), d=rng.uniform(0.2, 0.6)),
                  DHLink(a=0.0, alpha=rng.uniform(0.3, 2.8), d=0.0, theta=rng.uniform(-3, 3)),
                  DHLink(a=0.0, alpha=rng.uniform(0.3, 2.8), d=0.0, theta=rng.uniform(-3, 3))]
    tool = transform_from_xyz_rpy(rng.uniform(-.2, .2, 3), rng.uniform(-3, 3, 3))
    base = transform_from_xyz_rpy(rng.uniform(-.2, .2, 3), rng.uniform(-3, 3, 3))
    return DHRobot("random-pieper", tuple(links), convention=convention, base=base, tool=tool)


@pytest.mark.parametrize("convention", ["standard", "modified"])
def test_random_pieper_arms(convention):
    rng = np.random.default_rng(17 if convention == "standard" else 18)
    for _ in range(4 if REDUCED else 10):
        robot = _random_pieper(rng, convention)
        assert ik_structure(robot) == "pieper"
        q = rng.uniform(-np.pi, np.pi, (30, 6))
        T = forward_kinematics(robot, q)
        res = analytic_ik(robot, T)
        assert np.all(res.valid.sum(1) <= 16)
        Tk = np.broadcast_to(T[:, None], res.solutions.shape[:2] + (4, 4))[res.valid]
        dp, dw = _gap(robot, res.solutions[res.valid], Tk, "pose")
        assert dp.max() < 1e-8 and dw.max() < 1e-8
        dist = np.min(np.where(res.valid, _joint_distance(robot, res.solutions, q[:, None]), np.inf), axis=1)
        regular = _sigma_min(robot, q) > 1e-2
        assert np.all(dist[regular] < 1e-6)


def test_pieper_general_arm_has_up_to_eight_and_matches_numeric():
    rng = np.random.default_rng(4)
    robot = _random_pieper(rng, "standard")
    q = rng.uniform(-np.pi, np.pi, 6)
    T = forward_kinematics(robot, q)
    an = analytic_ik(robot, T)
    num = solve_ik(robot, np.broadcast_to(T, (300, 4, 4)), rng.uniform(-np.pi, np.pi, (300, 6)), restarts=0)
    assert len(_distinct(robot, num.q[num.success])) == an.count


def test_unreachable_gives_zero_solutions():
    robot = load_robot("puma560")
    res = analytic_ik(robot, transform_from_xyz_rpy([3.0, 0, 0], [0, 0, 0]))
    assert res.count == 0 and res.solutions.shape == (0, 6)


def test_wrist_singularity_is_a_named_continuum():
    robot = load_robot("puma560")
    q = np.array([0.2, 0.4, -0.9, 0.7, 0.0, 0.5])  # q5 = 0: axes 4 and 6 aligned
    T = forward_kinematics(robot, q)
    res = analytic_ik(robot, T)
    assert res.count >= 1
    sing = [f for f in res.free if f]
    assert sing and all("q4 + q6" in f for f in sing)
    # the representative and the generating q agree in q1-q3, q5 and in q4 + q6
    i = int(np.argmin(np.abs(res.solutions[:, :3] - q[:3]).max(axis=1)))
    s = res.solutions[i]
    assert abs(((s[3] + s[5]) - (q[3] + q[5]) + np.pi) % (2 * np.pi) - np.pi) < 1e-7
    dp, dw = _gap(robot, res.solutions, np.broadcast_to(T, (res.count, 4, 4)), "pose")
    assert dp.max() < 1e-9 and dw.max() < 1e-9


def test_boundary_of_workspace_planar_arm():
    """Stretched planar 2R (q2 = 0): the two elbow branches merge into one solution."""
    robot = load_robot("planar2r")
    T = forward_kinematics(robot, [0.7, 0.0])
    res = analytic_ik(robot, T)
    assert res.count == 1
    np.testing.assert_allclose(res.solutions[0], [0.7, 0.0], atol=1e-7)
    near = analytic_ik(robot, forward_kinematics(robot, [0.7, 1e-4]))
    assert near.count == 2 and set(near.branches) == {"elbow up", "elbow down"}


def test_branch_labels_puma_distinct():
    robot = load_robot("puma560")
    T = forward_kinematics(robot, [0.1, 0.9, -1.2, 0.4, 0.6, 0.3])
    res = analytic_ik(robot, T)
    assert len(set(res.branches)) == res.count
    assert all(b.startswith("shoulder") and "elbow" in b and "wrist" in b for b in res.branches)


def test_batch_equals_loop():
    robot = load_robot("ur5")
    rng = np.random.default_rng(2)
    T = forward_kinematics(robot, _random_q(robot, rng, 6)).reshape(3, 2, 4, 4)
    res = analytic_ik(robot, T)
    for i in range(3):
        for j in range(2):
            one = analytic_ik(robot, T[i, j])
            got = res.solutions[i, j][res.valid[i, j]]
            assert len(got) == one.count
            for s in one.solutions:
                assert np.min(_joint_distance(robot, got, s)) < 1e-12


def test_unsupported_structure_raises():
    with pytest.raises(UnsupportedRobotError, match="numeric"):
        analytic_ik(load_robot("panda"), np.eye(4))


def test_peer_roboticstoolbox_puma_analytic():
    """RTB's closed-form Puma 560 solver (ikine_a) finds configurations that are among ours."""
    rtb = pytest.importorskip("roboticstoolbox")
    puma = rtb.models.DH.Puma560()
    ours = load_robot("puma560")
    rng = np.random.default_rng(0)
    checked = 0
    for q in _random_q(ours, rng, 5):
        T = forward_kinematics(ours, q)
        res = analytic_ik(ours, T)
        for config in ("lun", "ldn", "run", "rdn", "luf", "rdf"):
            sol = puma.ikine_a(T, config)
            if not sol.success:
                continue
            qp = np.asarray(sol.q)
            if np.all((qp >= ours.q_limits[:, 0]) & (qp <= ours.q_limits[:, 1])):
                assert np.min(_joint_distance(ours, res.solutions, qp)) < 1e-6
                checked += 1
    assert checked >= 5
