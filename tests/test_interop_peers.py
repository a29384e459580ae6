"""Peers both ways: roboticstoolbox ``DHRobot`` ↔ denavit and denavit → Pinocchio keep the name, limits, gravity,
inertias and motor inertia; the peers' own algorithms (toolbox ``fkine``/``inertia``/``rne``, Pinocchio
``crba``/``rnea``) agree with denavit's on the converted arms."""

from __future__ import annotations

import warnings
from dataclasses import replace

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import denavit
from denavit import DenavitWarning, DHLink

from _random_urdf import with_random_inertia
from conftest import REDUCED, robots

rtb = pytest.importorskip("roboticstoolbox")
pytestmark = pytest.mark.peer

from denavit.peers import expand_q, from_roboticstoolbox, to_pinocchio, to_roboticstoolbox  # noqa: E402

ARMS = [name for name in denavit.catalogue_names() if all(link.is_joint for link in denavit.load_robot(name).links)]


def _plain(robot):
    """The model without the file's expression texts, parameters, poses and prose (what a peer cannot hold)."""
    links = tuple(DHLink(a=l.a, alpha=l.alpha, d=l.d, theta=l.theta, joint=l.joint, q_limits=l.q_limits,
                         inertia=None if l.inertia is None else replace(l.inertia, symbols=()))
                  for l in robot.links)
    return denavit.DHRobot(name=robot.name, links=links, convention=robot.convention, base=robot.base,
                           tool=robot.tool, gravity=robot.gravity)


@pytest.mark.parametrize("name", ARMS)
def test_roboticstoolbox_round_trip_keeps_the_arm(name):
    robot = denavit.load_robot(name)
    peer = to_roboticstoolbox(robot)
    assert peer.name == robot.name
    np.testing.assert_array_equal(peer.gravity, robot.gravity)
    back = from_roboticstoolbox(peer)
    assert back == _plain(robot)


@pytest.mark.parametrize("name", ["puma560", "puma560-mdh", "panda", "ur5", "planar3r"])
def test_toolbox_dynamics_of_the_converted_arm(name, rng):
    robot = denavit.load_robot(name)
    peer = to_roboticstoolbox(robot)
    rows = list(robot.joint_rows)  # fixed rows are toolbox joints held at 0
    for _ in range(3):
        q, qd, qdd = (rng.uniform(-1, 1, robot.dof) for _ in range(3))
        x, xd, xdd = (expand_q(robot, v) for v in (q, qd, qdd))
        np.testing.assert_allclose(peer.fkine(x).A, denavit.forward_kinematics(robot, q), atol=1e-12)
        np.testing.assert_allclose(peer.inertia(x)[np.ix_(rows, rows)], denavit.mass_matrix(robot, q), atol=1e-10)
        np.testing.assert_allclose(peer.rne(x, xd, xdd)[rows], denavit.rnea(robot, q, qd, qdd), atol=1e-9)


def test_toolbox_puma_model_imported(rng):
    """roboticstoolbox's own Puma 560 (gear ratios, motor-side friction, asymmetric Coulomb) → denavit."""
    peer = rtb.models.DH.Puma560()
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        robot = from_roboticstoolbox(peer)
    assert any(issubclass(w.category, DenavitWarning) and "asymmetric" in str(w.message) for w in caught)
    assert robot.name == peer.name and robot.dof == 6
    np.testing.assert_array_equal(robot.q_limits, peer.qlim.T)
    for link, pl in zip(robot.joints, peer.links):
        assert link.inertia.motor_inertia == pytest.approx(pl.Jm * pl.G**2)
    for _ in range(3):
        q, qd = rng.uniform(-1, 1, (2, 6))
        np.testing.assert_allclose(denavit.forward_kinematics(robot, q), peer.fkine(q).A, atol=1e-12)
        np.testing.assert_allclose(denavit.mass_matrix(robot, q), peer.inertia(q), atol=1e-10)
        np.testing.assert_allclose(denavit.gravity_torques(robot, q), peer.gravload(q), atol=1e-10)


@pytest.mark.parametrize("name", ["puma560", "panda", "ur5", "stanford"])
def test_pinocchio_model_keeps_name_limits_gravity_and_motor_inertia(name, rng):
    pin = pytest.importorskip("pinocchio")
    robot = denavit.load_robot(name)
    model, data, fid = to_pinocchio(robot)
    assert model.name == robot.name
    np.testing.assert_array_equal(model.gravity.linear, robot.gravity)
    lim = robot.q_limits
    finite = np.isfinite(lim)
    np.testing.assert_array_equal(model.lowerPositionLimit[finite[:, 0]], lim[finite[:, 0], 0])
    np.testing.assert_array_equal(model.upperPositionLimit[finite[:, 1]], lim[finite[:, 1], 1])
    motor = np.array([link.inertia.motor_inertia if link.inertia else 0.0 for link in robot.joints])
    np.testing.assert_array_equal(model.armature, motor)
    if robot.has_dynamics:
        for _ in range(3):
            q, qd, qdd = (rng.uniform(-1, 1, robot.dof) for _ in range(3))
            M = pin.crba(model, data, q)
            M = np.triu(M) + np.triu(M, 1).T
            np.testing.assert_allclose(M, denavit.mass_matrix(robot, q), atol=1e-10)
            tau = pin.rnea(model, data, q, qd, qdd)  # armature included, as in denavit
            np.testing.assert_allclose(tau, denavit.rnea(robot, q, qd, qdd, friction=False), atol=1e-9)


@settings(max_examples=20 if REDUCED else 60, deadline=None)
@given(robot=robots(fixed_rows=False), seed=st.integers(0, 2**32 - 1))
def test_random_arms_round_trip_through_the_toolbox(robot, seed):
    robot = with_random_inertia(robot, np.random.default_rng(seed))
    assert from_roboticstoolbox(to_roboticstoolbox(robot)) == _plain(robot)
