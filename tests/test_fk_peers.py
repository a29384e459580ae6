"""Forward kinematics against roboticstoolbox-python on random robots of both conventions.

Fixed rows are given to the peer as revolute joints held at q = 0 (their θ as offset).
"""

import numpy as np
import pytest

from denavit import Convention, JointType, forward_kinematics, load_robot

from _random_robots import random_q, random_robot

rtb = pytest.importorskip("roboticstoolbox")
pytestmark = pytest.mark.peer

from denavit.peers import expand_q, to_pinocchio  # noqa: E402
from denavit.peers import to_roboticstoolbox as to_rtb  # noqa: E402


@pytest.mark.parametrize("seed", range(200))
def test_fk_matches_roboticstoolbox_on_random_robots(seed):
    rng = np.random.default_rng(5000 + seed)
    robot = random_robot(rng)
    peer = to_rtb(robot)
    for q in random_q(rng, robot, (3,)):
        np.testing.assert_allclose(forward_kinematics(robot, q), peer.fkine(expand_q(robot, q)).A, atol=1e-10)


@pytest.mark.parametrize("seed", range(60))
def test_fk_matches_pinocchio_on_random_robots(seed):
    pin = pytest.importorskip("pinocchio")
    rng = np.random.default_rng(9000 + seed)
    robot = random_robot(rng)
    model, data, fid = to_pinocchio(robot)
    for q in random_q(rng, robot, (3,)):
        pin.framesForwardKinematics(model, data, q)
        np.testing.assert_allclose(forward_kinematics(robot, q), data.oMf[fid].homogeneous, atol=1e-10)


@pytest.mark.parametrize("ours, theirs", [("puma560", "Puma560"), ("stanford", "Stanford"), ("panda", "Panda"),
                                          ("ur5", "UR5")])
def test_catalogue_arms_match_published_models(ours, theirs):
    """The catalogue's textbook arms reproduce roboticstoolbox's published DH models."""
    robot = load_robot(ours)
    peer = getattr(rtb.models.DH, theirs)()
    if ours == "panda":
        peer.tool = np.eye(4)  # the toolbox adds a gripper, Tz(0.103) Rz(-pi/4); ours ends at the flange
    if ours == "ur5":
        peer.links[0].d = 0.089159  # Universal Robots' published d1; the toolbox has 0.089459
    rng = np.random.default_rng(11)
    for q in random_q(rng, robot, (5,)):
        T_peer = peer.fkine(q).A
        T = forward_kinematics(robot, q)
        np.testing.assert_allclose(T[:3, :3], T_peer[:3, :3], atol=1e-9)
        np.testing.assert_allclose(T[:3, 3], T_peer[:3, 3], atol=1e-9)
