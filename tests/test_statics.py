"""Statics: τ = Jᵀ F against inward force propagation and against virtual work from finite differences."""

import numpy as np
import pytest

from denavit import DHLink, DHRobot, JointType, forward_kinematics, load_robot
from denavit import numeric as N

from test_jacobians import make_robot

from conftest import REDUCED
N_ROBOTS = 100 if REDUCED else 250
H = 1e-6


@pytest.mark.parametrize("frame", ["base", "tool"])
def test_jacobian_transpose_equals_force_propagation(frame):
    rng = np.random.default_rng(20 + len(frame))
    for _ in range(N_ROBOTS):
        robot = make_robot(rng)
        q = rng.uniform(-np.pi, np.pi, robot.dof)
        F = rng.normal(size=6)
        prop = N.force_propagation(robot, q, F, frame)
        np.testing.assert_allclose(N.joint_torques(robot, q, F, frame), prop.tau, atol=1e-10)


def test_virtual_work_from_finite_displacements():
    """δqᵀ τ = δpᵀ f + δθᵀ n with δp, δθ measured on the forward kinematics (no Jacobian involved)."""
    rng = np.random.default_rng(22)
    for _ in range(N_ROBOTS):
        robot = make_robot(rng)
        q, dq = rng.uniform(-np.pi, np.pi, robot.dof), rng.normal(size=robot.dof)
        F = rng.normal(size=6)
        Tp, Tm, T = (forward_kinematics(robot, x) for x in (q + H * dq, q - H * dq, q))
        dp = (Tp[:3, 3] - Tm[:3, 3]) / (2 * H)
        W = (Tp[:3, :3] - Tm[:3, :3]) / (2 * H) @ T[:3, :3].T
        dth = 0.5 * np.array([W[2, 1] - W[1, 2], W[0, 2] - W[2, 0], W[1, 0] - W[0, 1]])
        work = dp @ F[:3] + dth @ F[3:]
        assert abs(dq @ N.joint_torques(robot, q, F, "base") - work) < 1e-6 * (1 + abs(work))
        assert abs(dq @ N.force_propagation(robot, q, F, "base").tau - work) < 1e-6 * (1 + abs(work))


def test_intermediate_wrenches_are_the_tip_wrench_moved_to_each_frame():
    """f_k = R_w_kᵀ f, n_k = R_w_kᵀ (n + (p_e − p_k) × f): computed here from world frames."""
    rng = np.random.default_rng(23)
    for _ in range(60):
        robot = make_robot(rng)
        q = rng.uniform(-np.pi, np.pi, robot.dof)
        F = rng.normal(size=6)
        frames = N.link_transforms(robot, q)
        p_e = forward_kinematics(robot, q)[:3, 3]
        prop = N.force_propagation(robot, q, F, "base")
        for k, Tk in enumerate(frames):
            R, p = Tk[:3, :3], Tk[:3, 3]
            np.testing.assert_allclose(prop.f[k], R.T @ F[:3], atol=1e-10)
            np.testing.assert_allclose(prop.n[k], R.T @ (F[3:] + np.cross(p_e - p, F[:3])), atol=1e-10)


def test_force_only_wrench_and_frames():
    rng = np.random.default_rng(24)
    for _ in range(40):
        robot = make_robot(rng)
        q = rng.uniform(-np.pi, np.pi, robot.dof)
        f = rng.normal(size=3)
        F6 = np.concatenate([f, np.zeros(3)])
        np.testing.assert_allclose(N.joint_torques(robot, q, f), N.joint_torques(robot, q, F6), atol=1e-14)
        R = forward_kinematics(robot, q)[:3, :3]
        Fe = N.wrench_tool_from_base(F6, R)
        np.testing.assert_allclose(N.joint_torques(robot, q, Fe, "tool"), N.joint_torques(robot, q, F6, "base"),
                                   atol=1e-10)
        np.testing.assert_allclose(N.wrench_base_from_tool(Fe, R), F6, atol=1e-12)


def test_planar_2r_hand_worked_example():
    """Planar 2R, both links 1 m, q = (0, 90°), f = (1, 0) N at the tip: tip at (1, 1) m, so τ1 = −y f_x = −1 N m
    (joint 1 at the origin) and τ2 = −(y − 0) f_x = −1 N m (joint 2 at (1, 0)); worked by hand with τ = (p − o) × f."""
    robot = DHRobot("2r", (DHLink(a=1.0), DHLink(a=1.0)))
    tau = N.joint_torques(robot, [0.0, np.pi / 2], [1.0, 0.0, 0.0])
    np.testing.assert_allclose(tau, [-1.0, -1.0], atol=1e-12)
    tau = N.force_propagation(robot, [0.0, np.pi / 2], [1.0, 0.0, 0.0], "base").tau
    np.testing.assert_allclose(tau, [-1.0, -1.0], atol=1e-12)


@pytest.mark.parametrize("shape", [(), (1,), (3, 2)])
def test_statics_batch_equals_loop(shape):
    rng = np.random.default_rng(25)
    robot = load_robot("puma560")
    q = rng.uniform(-np.pi, np.pi, shape + (6,))
    F = rng.normal(size=shape + (6,))
    for frame in ("base", "tool"):
        tau = N.joint_torques(robot, q, F, frame)
        prop = N.force_propagation(robot, q, F, frame)
        flat_q, flat_F = q.reshape(-1, 6), F.reshape(-1, 6)
        loop = np.stack([N.force_propagation(robot, a, b, frame).tau for a, b in zip(flat_q, flat_F)])
        np.testing.assert_allclose(prop.tau, loop.reshape(tau.shape), atol=1e-12)
        np.testing.assert_allclose(tau, loop.reshape(tau.shape), atol=1e-10)
    # one wrench against many configurations broadcasts
    assert N.force_propagation(robot, q, np.ones(6)).tau.shape == shape + (6,)


def test_bad_wrench_shape():
    robot = load_robot("planar2r")
    with pytest.raises(ValueError, match=r"\(\.\.\., 6\) \(f, n\) or \(\.\.\., 3\)"):
        N.joint_torques(robot, [0, 0], [1, 2, 3, 4])
    with pytest.raises(ValueError, match="non-finite"):
        N.force_propagation(robot, [0, 0], [np.nan, 0, 0])


@pytest.mark.peer
def test_puma560_torques_match_pinocchio_and_rtb():
    rtb = pytest.importorskip("roboticstoolbox")
    robot, peer = load_robot("puma560"), rtb.models.DH.Puma560()
    rng = np.random.default_rng(26)
    for q in rng.uniform(-np.pi, np.pi, (8, 6)):
        F = rng.normal(size=6)
        np.testing.assert_allclose(N.force_propagation(robot, q, F, "base").tau, peer.jacob0(q).T @ F, atol=1e-9)
        np.testing.assert_allclose(N.force_propagation(robot, q, F, "tool").tau, peer.jacobe(q).T @ F, atol=1e-9)
