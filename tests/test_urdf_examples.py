"""Real arms as they ship (the ``example-robot-data`` package's URDFs): imported DH models against Pinocchio on the
original URDF — FK of the tip link, RNEA and the mass matrix at random configurations.

Joints off the chosen chain (a gripper's fingers) are locked at their neutral value in Pinocchio
(``buildReducedModel``), as the import locks them at 0.
"""

from __future__ import annotations

import importlib.metadata

import numpy as np
import pytest

import denavit
from denavit.interop import import_urdf

pin = pytest.importorskip("pinocchio")

ARMS = [  # (file under robots/, base link, tip link)
    ("ur_description/urdf/ur5_robot.urdf", None, "tool0"),
    ("ur_description/urdf/ur10_robot.urdf", None, "tool0"),
    ("ur_description/urdf/ur3_robot.urdf", "base_link", "ee_link"),
    ("panda_description/urdf/panda.urdf", None, "panda_hand"),
    ("kinova_description/robots/kinova.urdf", None, "j2s6s200_end_effector"),
    ("xarm_description/urdf/xarm7.urdf", None, None),
    ("z1_description/urdf/z1.urdf", None, None),
    ("so_arm_description/urdf/so100.urdf", None, None),
    ("double_pendulum_description/urdf/double_pendulum.urdf", None, None),
    ("double_pendulum_description/urdf/double_pendulum_continuous.urdf", None, None),
]


def _robots_dir():
    try:
        files = importlib.metadata.files("example-robot-data") or []
    except importlib.metadata.PackageNotFoundError:
        pytest.skip("example-robot-data is not installed")
    for f in files:
        if str(f).endswith("ur_description/urdf/ur5_robot.urdf"):
            return f.locate().parents[2]
    pytest.skip("example-robot-data has no UR5 URDF")


def _pin_chain(path: str, joint_names):
    """Pinocchio's model of the URDF with every joint not in ``joint_names`` locked at its neutral value."""
    model = pin.buildModelFromUrdf(path)
    keep = set(joint_names)
    lock = [model.getJointId(n) for n in model.names[1:] if n not in keep]
    if lock:
        model = pin.buildReducedModel(model, lock, pin.neutral(model))
    return model, model.createData()


def _pin_q(model, names, q):
    """Pinocchio configuration from one value per named joint (continuous joints as (cos, sin))."""
    x = pin.neutral(model)
    for name, v in zip(names, q):
        j = model.joints[model.getJointId(name)]
        if j.nq == 2:
            x[j.idx_q:j.idx_q + 2] = np.cos(v), np.sin(v)
        else:
            x[j.idx_q] = v
    return x


@pytest.mark.peer
@pytest.mark.parametrize("convention", ["standard", "modified"])
@pytest.mark.parametrize("arm", ARMS, ids=[a[0].split("/")[-1] for a in ARMS])
def test_shipped_urdf_matches_pinocchio(arm, convention, rng):
    rel, base, tip = arm
    path = str(_robots_dir() / rel)
    result = import_urdf(path, base, tip, convention)
    robot = result.robot
    # 1e-10, not rounding alone: angles within 1e-9 of a multiple of pi/2 are taken as it (interop._urdf_snap;
    # the UR files write pi/2 as 1.57079632679, 4.9e-12 short), so the model is that far from the file's numbers
    assert result.position_error < 1e-10 and result.rotation_error < 1e-10
    model, data = _pin_chain(path, result.joint_names)
    assert model.nv == robot.dof
    vidx = [model.joints[model.getJointId(n)].idx_v for n in result.joint_names]
    fid = model.getFrameId(result.tip_link)
    for _ in range(10):
        q, qd, qdd = (rng.uniform(-np.pi, np.pi, robot.dof) for _ in range(3))
        x = _pin_q(model, result.joint_names, q)
        v, a = np.zeros(model.nv), np.zeros(model.nv)
        v[vidx], a[vidx] = qd, qdd
        pin.framesForwardKinematics(model, data, x)
        np.testing.assert_allclose(denavit.forward_kinematics(robot, q), data.oMf[fid].homogeneous, atol=1e-10)
        if robot.has_dynamics:
            tau = pin.rnea(model, data, x, v, a)[vidx]
            np.testing.assert_allclose(denavit.rnea(robot, q, qd, qdd, friction=False), tau,
                                       atol=1e-9 * max(1.0, np.abs(tau).max()))
            M = pin.crba(model, data, x)
            M = (np.triu(M) + np.triu(M, 1).T)[np.ix_(vidx, vidx)]
            np.testing.assert_allclose(denavit.mass_matrix(robot, q), M, atol=1e-10 * max(1.0, np.abs(M).max()))
