"""Catalogue arms against their makers' descriptions: UR3e/UR10e/UR16e and Kinova Gen3 7-DOF (issue 30, item 4).

The makers' numbers come from extracts kept in tests/data (sources, commits and BSD licences in their headers):
the UR joint origins and link masses/centres of mass of Universal Robots' ROS 2 description, walked here as a
URDF chain (origin, then a turn about z); Kinova's Gen3 URDF, read by Pinocchio (kinematics, mass matrix and
gravity torques). Neither route uses denavit's DH chain or its URDF importer.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import yaml
from scipy.spatial.transform import Rotation

from denavit import (
    analytic_ik,
    forward_kinematics,
    geometric_jacobian,
    gravity_torques,
    link_transforms,
    load_robot,
    mass_matrix,
    solve_ik,
    with_parameters,
)

DATA = Path(__file__).parent / "data"
UR = ("ur3e", "ur10e", "ur16e")
UR_LINKS = ("shoulder", "upper_arm", "forearm", "wrist_1", "wrist_2", "wrist_3")


def _origin(xyz, rpy):
    A = np.eye(4)
    A[:3, :3], A[:3, 3] = Rotation.from_euler("xyz", rpy).as_matrix(), xyz  # URDF rpy: fixed axes x, y, z
    return A


def _turn_z(q):
    A = np.eye(4)
    A[:3, :3] = Rotation.from_rotvec([0.0, 0.0, q]).as_matrix()
    return A


@pytest.fixture(scope="module")
def ur_description():
    return yaml.safe_load((DATA / "ur_e_series_description.yaml").read_text(encoding="utf-8"))


def _ur_frames(arm, q):
    """(6, 4, 4) the link frames shoulder_link … wrist_3_link in base_link_inertia (UR's DH base frame)."""
    T, out = np.eye(4), []
    for name, qi in zip(UR_LINKS, q):
        j = arm["joints"][name]
        T = T @ _origin(j[:3], j[3:]) @ _turn_z(qi)
        out.append(T)
    return np.array(out)


@pytest.mark.parametrize("name", UR)
def test_ur_e_series_matches_the_ros2_description(name, ur_description):
    """FK to the ROS description's wrist_3_link (its rpy are π/2 to 1e-9, hence the 1e-9) and every link's
    centre of mass at the same world point; the masses are the same numbers."""
    robot, arm = load_robot(name), ur_description[name]
    q = np.random.default_rng(3).uniform(-np.pi, np.pi, (40, 6))
    frames = np.array([_ur_frames(arm, qi) for qi in q])  # (40, 6, 4, 4)
    assert np.abs(forward_kinematics(robot, q) - frames[:, -1]).max() < 1e-9
    L = link_transforms(robot, q)  # (40, 7, 4, 4)
    for i, (link, name_i) in enumerate(zip(robot.links, UR_LINKS)):
        mass, *cog = arm["links"][name_i]
        assert link.inertia.mass == mass
        ours = L[:, i + 1] @ np.r_[link.inertia.com, 1.0]
        theirs = frames[:, i] @ np.r_[cog, 1.0]
        assert np.abs(ours - theirs).max() < 1e-9, name_i


@pytest.mark.parametrize("name", UR)
def test_ur_e_series_every_ik_solution_reproduces_the_pose(name):
    """The UR-class closed form: up to 8 solutions (fewer where a branch's planar elbow cannot reach), each
    FK(q) = T, the generating q among them, and a numeric search from 32 random seeds finds none outside the set."""
    robot = load_robot(name)
    rng = np.random.default_rng(4)
    q = rng.uniform(-np.pi, np.pi, (6, 6))
    T = forward_kinematics(robot, q)
    for qi, Ti in zip(q, T):
        res = analytic_ik(robot, Ti)
        assert res.method == "parallel" and res.count in (2, 4, 6, 8)
        assert np.abs(forward_kinematics(robot, res.solutions) - Ti).max() < 1e-9
        d = res.solutions - qi
        assert np.abs(np.angle(np.exp(1j * d))).max(axis=1).min() < 1e-8
        num = solve_ik(robot, np.broadcast_to(Ti, (32, 4, 4)), rng.uniform(-np.pi, np.pi, (32, 6)), restarts=0,
                       rng=rng)
        hits = num.q[num.success]
        assert len(hits)
        gap = np.abs(np.angle(np.exp(1j * (hits[:, None] - res.solutions[None])))).max(axis=-1).min(axis=-1)
        # LM stops at a 1e-9 pose residual, which fixes q only to ~1e-9/σ_min(J) (×100), or 1e-6
        sigma = np.linalg.svd(geometric_jacobian(robot, hits), compute_uv=False)[:, -1]
        assert np.all(gap < np.maximum(1e-6, 100 * 1e-9 / sigma))


# --- Kinova Gen3 7-DOF ----------------------------------------------------------------------------------------

@pytest.fixture(scope="module")
def gen3_pin():
    pin = pytest.importorskip("pinocchio")
    model = pin.buildModelFromXML((DATA / "gen3_7dof.urdf").read_text(encoding="utf-8"))
    return pin, model


def _pin_q(model, q):
    """Pinocchio's configuration: a continuous joint is (cos q, sin q), a revolute one q."""
    out = []
    for j, qi in zip(list(model.joints)[1:], q):
        out += [np.cos(qi), np.sin(qi)] if j.nq == 2 else [qi]
    return np.array(out)


def _gen3_q(n, seed):
    robot = load_robot("gen3")
    lim = np.where(np.isfinite(robot.q_limits), robot.q_limits, [-np.pi, np.pi])
    return robot, np.random.default_rng(seed).uniform(*lim.T, (n, 7))


def test_gen3_matches_kinovas_urdf(gen3_pin):
    """FK to the URDF's end_effector_link: within 0.5 mm and 2e-5 (the user guide's table rounds to 0.1 mm, the
    URDF's wrist has two 0.175 mm offsets and rpy rounded to 1e-4); the same joint directions and zero. With the
    URDF's own lengths, its rpy snapped to multiples of π/2 and the wrist offsets dropped, equal to 1e-12."""
    pin, model = gen3_pin
    data = model.createData()
    frame = model.getFrameId("end_effector_link")
    robot, q = _gen3_q(30, 5)

    def urdf_fk(model, data):
        out = []
        for qi in q:
            pin.framesForwardKinematics(model, data, _pin_q(model, qi))
            out.append(data.oMf[frame].homogeneous)
        return np.array(out)

    F, U = forward_kinematics(robot, q), urdf_fk(model, data)
    assert np.linalg.norm(F[:, :3, 3] - U[:, :3, 3], axis=-1).max() < 0.5e-3
    assert np.abs(F[:, :3, :3] - U[:, :3, :3]).max() < 2e-5
    for k in range(1, model.njoints):  # snap: each placement's rotation to the nearest signed permutation
        M = model.jointPlacements[k]
        R = np.round(M.rotation)
        p = np.where(np.abs(M.translation) < 1e-3, 0.0, M.translation)  # the 0.175 mm wrist offsets
        model.jointPlacements[k] = pin.SE3(R, p)
    fid = model.frames[frame]
    fid.placement = pin.SE3(np.round(fid.placement.rotation), fid.placement.translation)
    model.frames[frame] = fid
    t = [np.abs(model.jointPlacements[k].translation).max() for k in range(1, 8)] + [0.061525]
    exact = with_parameters(robot, d1=t[0] + t[1], d2=0.005375 + 0.006375, d3=t[2] + t[3],
                            d4=0.006375 + 0.006375, d5=t[4] + t[5], d7=t[6] + t[7])
    assert np.abs(forward_kinematics(exact, q) - urdf_fk(model, model.createData())).max() < 1e-12


def test_gen3_dynamics_match_pinocchio_on_kinovas_urdf(gen3_pin):
    """Mass matrix and gravity torques from the catalogue file's inertial data (re-expressed in DH frames) against
    Pinocchio's CRBA and generalized gravity on the URDF, to the URDF's kinematic rounding (0.5 mm in 0.4 m)."""
    pin, model = gen3_pin
    data = model.createData()
    robot, q = _gen3_q(12, 6)
    for qi in q:
        qp = _pin_q(model, qi)
        M = pin.crba(model, data, qp)
        M = np.triu(M) + np.triu(M, 1).T
        g = pin.computeGeneralizedGravity(model, data, qp)
        assert np.abs(mass_matrix(robot, qi) - M).max() < 2e-3 * np.abs(M).max()
        assert np.abs(gravity_torques(robot, qi) - g).max() < 3e-3 * np.abs(g).max()


def test_gen3_limits_are_the_urdfs(gen3_pin):
    _, model = gen3_pin
    robot = load_robot("gen3")
    for k, j in enumerate(list(model.joints)[1:]):
        lo, hi = robot.q_limits[k]
        if j.nq == 2:  # continuous in the URDF: no limits here either
            assert (lo, hi) == (-np.inf, np.inf)
        else:
            assert (lo, hi) == (model.lowerPositionLimit[j.idx_q], model.upperPositionLimit[j.idx_q])
