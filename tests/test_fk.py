"""Forward kinematics against independent routes.

- a product of elementary 4×4 transforms written out here (not the engine's column algebra);
- the same physical arm written in the other convention (``convert_convention``);
- batch = loop, frames composition, RPY/ZYZ round trips.
"""

import numpy as np
import pytest

import denavit
from denavit import Convention, JointType, convert_convention, forward_kinematics, link_transforms
from denavit.numeric import rotation_from_rpy, rotation_from_zyz, rpy_from_rotation, zyz_from_rotation

from _random_robots import random_q, random_robot

ATOL = 1e-10


def Rz(t):
    c, s = np.cos(t), np.sin(t)
    return np.array([[c, -s, 0, 0], [s, c, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1.0]])


def Rx(t):
    c, s = np.cos(t), np.sin(t)
    return np.array([[1, 0, 0, 0], [0, c, -s, 0], [0, s, c, 0], [0, 0, 0, 1.0]])


def Tz(d):
    T = np.eye(4)
    T[2, 3] = d
    return T


def Tx(a):
    T = np.eye(4)
    T[0, 3] = a
    return T


def elementary_fk(robot, q):
    """T_w_e from elementary motions: Rz Tz Tx Rx (standard) or Rx Tx Rz Tz (modified)."""
    T = robot.base_matrix
    k = 0
    frames = [T]
    for link in robot.links:
        theta, d = link.theta, link.d
        if link.joint is JointType.REVOLUTE:
            theta += q[k]
            k += 1
        elif link.joint is JointType.PRISMATIC:
            d += q[k]
            k += 1
        if robot.convention is Convention.STANDARD:
            A = Rz(theta) @ Tz(d) @ Tx(link.a) @ Rx(link.alpha)
        else:
            A = Rx(link.alpha) @ Tx(link.a) @ Rz(theta) @ Tz(d)
        T = T @ A
        frames.append(T)
    return T @ robot.tool_matrix, np.array(frames)


@pytest.mark.parametrize("seed", range(300))
def test_fk_equals_elementary_product_on_random_robots(seed):
    rng = np.random.default_rng(seed)
    robot = random_robot(rng)
    q = random_q(rng, robot)
    T_ref, frames_ref = elementary_fk(robot, q)
    np.testing.assert_allclose(forward_kinematics(robot, q), T_ref, atol=ATOL)
    np.testing.assert_allclose(link_transforms(robot, q), frames_ref, atol=ATOL)


@pytest.mark.parametrize("seed", range(100))
def test_convert_keeps_the_end_effector_pose(seed):
    rng = np.random.default_rng(1000 + seed)
    robot = random_robot(rng)
    other = convert_convention(robot, "modified" if robot.convention is Convention.STANDARD else "standard")
    assert other.convention is not robot.convention
    back = convert_convention(other, robot.convention)
    q = random_q(rng, robot, (4,))
    np.testing.assert_allclose(forward_kinematics(other, q), forward_kinematics(robot, q), atol=ATOL)
    np.testing.assert_allclose(forward_kinematics(back, q), forward_kinematics(robot, q), atol=ATOL)


@pytest.mark.parametrize("name", denavit.catalogue_names())
def test_catalogue_batch_equals_loop_and_convert(name):
    robot = denavit.load_robot(name)
    rng = np.random.default_rng(7)
    q = random_q(rng, robot, (3, 2))
    T = forward_kinematics(robot, q)
    F = link_transforms(robot, q)
    assert T.shape == (3, 2, 4, 4) and F.shape == (3, 2, robot.n_rows + 1, 4, 4)
    for i in range(3):
        for j in range(2):
            T_ref, F_ref = elementary_fk(robot, q[i, j])
            np.testing.assert_allclose(T[i, j], T_ref, atol=ATOL)
            np.testing.assert_allclose(F[i, j], F_ref, atol=ATOL)
    # frames compose to the pose: T_w_e = T_w_N @ tool
    np.testing.assert_allclose(F[..., -1, :, :] @ robot.tool_matrix, T, atol=ATOL)
    # rotation parts are rotations
    R = T[..., :3, :3]
    np.testing.assert_allclose(R @ np.swapaxes(R, -1, -2), np.broadcast_to(np.eye(3), R.shape), atol=1e-12)
    other = convert_convention(robot, "modified" if robot.convention is Convention.STANDARD else "standard")
    np.testing.assert_allclose(forward_kinematics(other, q), T, atol=ATOL)


def test_unbatched_and_empty_batch_shapes():
    robot = denavit.load_robot("puma560")
    assert forward_kinematics(robot, np.zeros(6)).shape == (4, 4)
    assert forward_kinematics(robot, np.zeros((0, 6))).shape == (0, 4, 4)
    assert link_transforms(robot, np.zeros((1, 6))).shape == (1, 7, 4, 4)


def test_inputs_not_mutated_and_outputs_fresh():
    robot = denavit.load_robot("puma560")
    q = np.linspace(-1, 1, 6)
    q0 = q.copy()
    T = forward_kinematics(robot, q)
    T[:] = 0
    np.testing.assert_array_equal(q, q0)
    assert np.abs(forward_kinematics(robot, q)).sum() > 0
    robot.base_matrix[:] = 0
    np.testing.assert_array_equal(robot.base_matrix, np.eye(4))


@pytest.mark.parametrize("bad", [np.zeros(5), np.zeros((2, 7)), [np.nan] * 6, [np.inf] * 6, 3.0, "abc"])
def test_bad_joint_arrays_raise_shape_error(bad):
    robot = denavit.load_robot("puma560")
    with pytest.raises(denavit.ShapeError, match="expected|non-finite|numbers"):
        forward_kinematics(robot, bad)


def test_rpy_and_zyz_round_trip_including_gimbal_lock():
    rng = np.random.default_rng(3)
    angles = rng.uniform(-np.pi, np.pi, (500, 3))
    angles[:50, 1] = np.pi / 2
    angles[50:100, 1] = -np.pi / 2
    R = rotation_from_rpy(angles)
    np.testing.assert_allclose(rotation_from_rpy(rpy_from_rotation(R)), R, atol=1e-9)
    Z = rotation_from_zyz(angles)
    zyz = angles.copy()
    zyz[:50, 1] = 0.0
    zyz[50:100, 1] = np.pi
    Z2 = rotation_from_zyz(zyz)
    np.testing.assert_allclose(rotation_from_zyz(zyz_from_rotation(Z)), Z, atol=1e-9)
    np.testing.assert_allclose(rotation_from_zyz(zyz_from_rotation(Z2)), Z2, atol=1e-9)


def test_report000_arm_known_geometry_at_zero():
    """At q = 0 the report-000 arm (Craig DH) is stretched along x: reach L1+L2+L3+L4, height H1.

    Computed by hand from the table (rows 3-6 rotate about parallel axes after the pi/2 twist).
    """
    robot = denavit.load_robot("report000-6r")
    p = robot.parameter_values
    T = forward_kinematics(robot, np.zeros(6))
    np.testing.assert_allclose(T[:3, 3], [p["L1"] + p["L2"] + p["L3"] + p["L4"], 0, p["H1"]], atol=1e-12)


def test_prismatic_joint_moves_along_its_axis():
    robot = denavit.load_robot("stanford")
    k = robot.joint_types.index(JointType.PRISMATIC)
    q = np.array([0.3, -0.4, 0.5, 0.2, 0.7, -0.1])
    dq = np.zeros(6)
    dq[k] = 0.25
    F = link_transforms(robot, q)
    axis = F[robot.joint_rows[k], :3, 2]  # standard DH: z_{k-1}
    delta = forward_kinematics(robot, q + dq)[:3, 3] - forward_kinematics(robot, q)[:3, 3]
    np.testing.assert_allclose(delta, 0.25 * axis, atol=1e-12)
