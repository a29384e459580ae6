"""Kinematic calibration (denavit.calibrate): the issue's Done-when checks and the identification Jacobian.

Simulated data come from the library's forward kinematics of a TRUE arm (the catalogue arm perturbed: a, d by up
to 5 mm, α and θ offsets by up to 0.5°, base and tool by up to 1 cm / 1°) with Gaussian noise of 0.1 mm and 0.01°
per axis; the estimator sees only the nominal arm, the joint readings and the noisy poses.

What "the true value" of a parameter is: a held parameter's error is absorbed by the identified ones (θ1's offset
by the base rotation, the last row by the tool, ...), so the truth of the identified parameters is the minimal
model of the true arm: the calibration of noise-free poses of the true arm.  That it IS the true arm is checked
independently: its forward kinematics (denavit.forward_kinematics of the calibrated DHRobot) equals the true arm's
at fresh random joint values to 1e-9 m / rad.  Then the noisy estimate is compared with it, parameter by parameter,
in units of the reported σ.  Multiple testing: about 30 parameters per arm, so "every one within 3σ" would fail
about 8 % of seeds by chance alone; the tests assert every parameter within 4σ (chance of a false failure about
0.2 %) and at least 95 % of them within 3σ, with a fixed seed (reproducible; not chosen to pass).
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

import denavit
from denavit import DHLink, JointType, ShapeError, calibrate
from denavit.calibration import error_model

from conftest import REDUCED, robots

SIGMA_P = 1e-4  # m, per axis
SIGMA_R = math.radians(0.01)  # rad, per axis


def _small_transform(rng, length: float, angle: float) -> np.ndarray:
    M = np.eye(4)
    M[:3, :3] = Rotation.from_rotvec(rng.uniform(-angle, angle, 3)).as_matrix()
    M[:3, 3] = rng.uniform(-length, length, 3)
    return M


def perturbed(robot, rng):
    """The issue's true arm: every row's a, d by up to 5 mm, α, θ by up to 0.5°; base and tool by 1 cm / 1°."""
    deg = math.radians(0.5)
    links = tuple(DHLink(a=l.a + rng.uniform(-5e-3, 5e-3), alpha=l.alpha + rng.uniform(-deg, deg),
                         d=l.d + rng.uniform(-5e-3, 5e-3), theta=l.theta + rng.uniform(-deg, deg), joint=l.joint,
                         q_limits=l.q_limits, inertia=l.inertia) for l in robot.links)
    return robot.replace(links=links, base=robot.base_matrix @ _small_transform(rng, 0.01, math.radians(1)),
                         tool=robot.tool_matrix @ _small_transform(rng, 0.01, math.radians(1)), symbols=())


def joint_samples(robot, rng, m):
    lim = robot.q_limits
    lim = np.where(np.isfinite(lim), lim, np.sign(lim) * np.pi)
    return rng.uniform(lim[:, 0], lim[:, 1], (m, robot.dof))


def measured(true, q, rng, noise=True):
    """Poses of the true arm (library FK), with noise: position + N(0, σ_p), rotation exp(N(0, σ_r)) · R."""
    T = denavit.forward_kinematics(true, q)
    if noise:
        T[:, :3, 3] += rng.normal(0, SIGMA_P, (len(q), 3))
        T[:, :3, :3] = Rotation.from_rotvec(rng.normal(0, SIGMA_R, (len(q), 3))).as_matrix() @ T[:, :3, :3]
    return T


def check_against_truth(nominal, true, q, rng, result):
    """The identified parameters within 4σ (all) and 3σ (≥ 95 %) of the minimal model of the true arm."""
    exact = calibrate(nominal, q, measured(true, q, rng, noise=False), noise=(SIGMA_P, SIGMA_R), robust="none")
    q_new = joint_samples(nominal, rng, 20)
    np.testing.assert_allclose(denavit.forward_kinematics(exact.robot, q_new), denavit.forward_kinematics(true, q_new),
                               atol=1e-9)  # the minimal model reproduces the true arm: it is the truth
    assert exact.identified == result.identified
    z = np.array([(result.parameter(n).estimate - exact.parameter(n).estimate) / result.parameter(n).sigma
                  for n in result.identified])
    assert np.all(np.abs(z) <= 4), dict(zip(result.identified, np.round(z, 2)))
    assert np.mean(np.abs(z) <= 3) >= 0.95, dict(zip(result.identified, np.round(z, 2)))
    return z


@pytest.mark.slow  # about 1-1.6 CPU-s each; the three together are half the quick subset's budget
@pytest.mark.parametrize("name, rank", [("puma560", 30), ("ur5", 30), ("panda", 34)])
def test_done_when_catalogue_arm_calibrated_to_noise_level(name, rank):
    rng = np.random.default_rng(2026)
    nominal = denavit.load_robot(name)
    true = perturbed(nominal, rng)
    q = joint_samples(nominal, rng, 80)
    result = calibrate(nominal, q, measured(true, q, rng), noise=(SIGMA_P, SIGMA_R), holdout=0.25, seed=1)
    # Everett, Driels & Mooring (1987): 4R + 2P + 6 independent parameters from pose data
    assert result.rank == rank == 4 * nominal.dof + 6
    assert result.converged and result.holdout_after.poses == 20
    # held-out poses: within 1.5x the noise (the RMS of a 3-D error of noise alone is sqrt(3) σ)
    assert result.holdout_before.position_rms > 20 * math.sqrt(3) * SIGMA_P  # the nominal arm was far off
    assert result.holdout_after.position_rms <= 1.5 * math.sqrt(3) * SIGMA_P
    assert result.holdout_after.rotation_rms <= 1.5 * math.sqrt(3) * SIGMA_R
    assert 0.6 < result.variance_factor < 1.6  # the stated noise explains the residuals
    check_against_truth(nominal, true, q[np.isin(np.arange(80), _fitted(80, 0.25, 1))], rng, result)


def _fitted(m, holdout, seed):
    """The indices calibrate fits with ``holdout`` and ``seed`` (its documented split: a seeded permutation)."""
    order = np.random.default_rng(seed).permutation(m)
    return np.sort(order[int(round(holdout * m)):])


def _with_beta(robot, row: int, beta: float):
    """A standard-DH arm with Ry(β) after row ``row`` (0-based), built by hand: Ry(β) = Rz(π/2) Rx(β) Rz(−π/2)."""
    links = list(robot.links)
    links[row + 1:row + 1] = [DHLink(theta=math.pi / 2, alpha=beta, joint=JointType.FIXED),
                              DHLink(theta=-math.pi / 2, joint=JointType.FIXED)]
    return robot.replace(links=tuple(links), symbols=())


def test_nearly_parallel_axes_misalignment_of_005_deg_identified():
    rng = np.random.default_rng(7)
    nominal = denavit.load_robot("puma560")  # axes 2 and 3 parallel (row 2: alpha = 0)
    beta = math.radians(0.05)
    true = _with_beta(nominal, 1, beta)
    q = joint_samples(nominal, rng, 60)
    T = measured(true, q, rng)
    result = calibrate(nominal, q, T, noise=(SIGMA_P, SIGMA_R))
    b = result.parameter("beta2")
    assert abs(b.estimate - beta) <= 3 * b.sigma and b.sigma < beta / 10
    assert "d2" in result.held and "parallel" in result.parameter("d2").reason
    lengths = [p.correction for p in result.parameters if p.identified and p.unit == "m"]
    assert max(map(abs, lengths)) < 1e-3  # a sane DH/β model: no long common normal
    assert result.after.position_rms <= 1.5 * math.sqrt(3) * SIGMA_P
    # plain DH (no β) cannot express the tilt: its orientation residuals stay well above the noise
    plain = calibrate(nominal, q, T, noise=(SIGMA_P, SIGMA_R), parallel_tolerance=0.0)
    assert "beta2" not in [p.name for p in plain.parameters]
    assert result.after.rotation_rms <= 1.5 * math.sqrt(3) * SIGMA_R < plain.after.rotation_rms / 1.5


@pytest.mark.parametrize("name", ["stanford", "scara", "cylindrical-rpp", "puma560-mdh", "jaco2-6dof", "lift-prrr"])
def test_noise_free_poses_give_the_true_arm_with_everetts_count(name):
    """Prismatic joints, both conventions, β rows (SCARA: three parallel axes): the calibrated file's FK is the
    true arm's at fresh joint values, with 4R + 2P + 6 parameters identified (Everett, Driels & Mooring 1987)."""
    rng = np.random.default_rng(3)
    nominal = denavit.load_robot(name)
    true = perturbed(nominal, rng)
    q = joint_samples(nominal, rng, 40)
    result = calibrate(nominal, q, measured(true, q, rng, noise=False), robust="none")
    revolute = sum(t is JointType.REVOLUTE for t in nominal.joint_types)
    assert result.rank == 4 * revolute + 2 * (nominal.dof - revolute) + 6
    q_new = joint_samples(nominal, rng, 10)
    np.testing.assert_allclose(denavit.forward_kinematics(result.robot, q_new), denavit.forward_kinematics(true, q_new),
                               atol=1e-8)


def test_measurements_in_a_far_instrument_frame_register_the_base_first():
    """A laser tracker 2 m away, turned 120°: the base is registered by a rigid fit, then calibrated as usual."""
    rng = np.random.default_rng(8)
    nominal = denavit.load_robot("puma560")
    tracker = np.eye(4)
    tracker[:3, :3] = Rotation.from_rotvec(math.radians(120) * np.ones(3) / math.sqrt(3)).as_matrix()
    tracker[:3, 3] = [2.0, -1.0, 0.5]
    true = perturbed(nominal, rng)
    true = true.replace(base=tracker @ true.base_matrix)
    q = joint_samples(nominal, rng, 50)
    P = measured(true, q, rng)[:, :3, 3]
    result = calibrate(nominal, q, P, "position", noise=(SIGMA_P, SIGMA_R), holdout=0.2)
    assert any("registered" in n for n in result.notes)
    assert result.holdout_before.position_rms > 1.0  # metres off before
    assert result.holdout_after.position_rms <= 1.5 * math.sqrt(3) * SIGMA_P
    q_new = joint_samples(nominal, rng, 10)
    err = denavit.forward_kinematics(result.robot, q_new)[:, :3, 3] - denavit.forward_kinematics(true, q_new)[:, :3, 3]
    assert np.abs(err).max() < 3e-4


@pytest.mark.parametrize("robust", ["huber", "cauchy"])
def test_gross_outlier_is_downweighted_and_named_as_the_worst_pose(robust):
    rng = np.random.default_rng(21)
    nominal = denavit.load_robot("puma560")
    true = perturbed(nominal, rng)
    q = joint_samples(nominal, rng, 50)
    T = measured(true, q, rng)
    clean = calibrate(nominal, q, T, noise=(SIGMA_P, SIGMA_R))
    T[17, :3, 3] += [0.01, 0.0, 0.0]  # one pose 1 cm off (a tracker that lost its target)
    labels = np.arange(50) + 100
    huber = calibrate(nominal, q, T, noise=(SIGMA_P, SIGMA_R), labels=labels, robust=robust)
    plain = calibrate(nominal, q, T, noise=(SIGMA_P, SIGMA_R), robust="none")
    assert huber.worst[0].label == 117 and huber.worst[0].position_error > 0.009
    shift = lambda r: max(abs(r.parameter(n).estimate - clean.parameter(n).estimate) / clean.parameter(n).sigma  # noqa: E731
                          for n in clean.identified)
    assert shift(huber) < 1.0 < 3.0 < shift(plain)  # least squares is dragged by many sigma, Huber is not


def test_base_and_tool_can_be_kept_as_they_are():
    rng = np.random.default_rng(12)
    nominal = denavit.load_robot("ur5")
    true = perturbed(nominal, rng).replace(base=nominal.base, tool=nominal.tool)  # only the DH rows are off
    q = joint_samples(nominal, rng, 40)
    result = calibrate(nominal, q, measured(true, q, rng), noise=(SIGMA_P, SIGMA_R), base=False, tool=False)
    for name in ("base_x", "base_rz", "tool_y", "tool_rx"):
        assert name in result.held and result.parameter(name).reason == f"not calibrated ({name[:4]}=False)"
    np.testing.assert_array_equal(result.robot.base_matrix, nominal.base_matrix)
    np.testing.assert_array_equal(result.robot.tool_matrix, nominal.tool_matrix)
    assert result.rank == 4 * 6  # every row's four (beta for d in rows 2, 3): no base or tool to confuse them with
    assert result.after.position_rms <= 1.5 * math.sqrt(3) * SIGMA_P


def test_joint_never_moved_names_what_cannot_be_identified():
    rng = np.random.default_rng(11)
    nominal = denavit.load_robot("puma560")
    true = perturbed(nominal, rng)
    q = joint_samples(nominal, rng, 50)
    q[:, 3] = 0.3  # joint 4 never moves
    result = calibrate(nominal, q, measured(true, q, rng), noise=(SIGMA_P, SIGMA_R))
    assert result.rank == 4 * 5 + 6  # Everett: joint 4 does not count
    assert any("joint 4 never moved" in n for n in result.notes)
    usual = {"theta1_offset", "d1", "d2", "theta6_offset", "d6", "a6", "alpha6"}  # held with every joint moving
    lost = set(result.held) - usual
    assert len(lost) == 4 and all(n[-1] in "45" or n[-8] in "45" for n in lost), lost
    for name in result.held:  # no number for them: nominal value, no σ
        p = result.parameter(name)
        assert p.correction == 0.0 and math.isnan(p.sigma) and p.reason


def test_position_data_holds_the_tool_orientation():
    rng = np.random.default_rng(5)
    nominal = denavit.load_robot("ur5")
    true = perturbed(nominal, rng)
    q = joint_samples(nominal, rng, 60)
    P = measured(true, q, rng)[:, :3, 3]
    result = calibrate(nominal, q, P, "position", noise=(SIGMA_P, SIGMA_R))
    for name in ("tool_rx", "tool_ry", "tool_rz"):
        assert name in result.held and "no effect" in result.parameter(name).reason
    assert result.rank == 4 * 6 + 6 - 3  # Everett: 4R + 2P + 3 for positions
    assert result.after.rotation_rms is None
    assert result.after.position_rms <= 1.5 * math.sqrt(3) * SIGMA_P


@settings(max_examples=6 if REDUCED else 15)
@given(robots(), st.integers(0, 2**32 - 1))
def test_identification_jacobian_matches_finite_differences(robot, seed):
    rng = np.random.default_rng(seed)
    model = error_model(robot)
    q = rng.uniform(-np.pi, np.pi, (3, robot.dof))
    x = rng.normal(0, 0.05, len(model.parameters))
    T, J = model.pose_and_jacobian(q, x)
    h = 1e-6
    for k in range(len(x)):
        e = np.zeros_like(x)
        e[k] = h
        Tp, Tm = model.pose(q, x + e), model.pose(q, x - e)
        dp = (Tp[:, :3, 3] - Tm[:, :3, 3]) / (2 * h)
        W = (Tp[:, :3, :3] - Tm[:, :3, :3]) / (2 * h) @ np.swapaxes(T[:, :3, :3], 1, 2)  # [δφ]×
        dphi = np.stack([W[:, 2, 1], W[:, 0, 2], W[:, 1, 0]], axis=-1)
        scale = 1 + np.abs(T[:, :3, 3]).max()
        np.testing.assert_allclose(J[:, :3, k], dp, atol=1e-7 * scale, err_msg=model.parameters[k].name)
        np.testing.assert_allclose(J[:, 3:, k], dphi, atol=1e-7, err_msg=model.parameters[k].name)


@settings(max_examples=6 if REDUCED else 15)
@given(robots(), st.integers(0, 2**32 - 1))
def test_error_model_and_calibrated_robot_agree_with_library_kinematics(robot, seed):
    """Zero corrections: the library's FK; random corrections (β included): the written robot's FK."""
    rng = np.random.default_rng(seed)
    model = error_model(robot, parallel_tolerance=math.radians(1.0))
    q = rng.uniform(-np.pi, np.pi, (4, robot.dof))
    np.testing.assert_allclose(model.pose(q, np.zeros(len(model.parameters))), denavit.forward_kinematics(robot, q),
                               atol=1e-12)
    from denavit.calibration._kinematic_robot import calibrated_robot  # the writer's private half, tested alone

    x = rng.normal(0, 0.01, len(model.parameters))
    np.testing.assert_allclose(denavit.forward_kinematics(calibrated_robot(robot, model, x), q), model.pose(q, x),
                               atol=1e-10)


def test_bad_inputs_are_shape_errors():
    robot = denavit.load_robot("puma560")
    q = np.zeros((10, 6))
    T = np.broadcast_to(np.eye(4), (10, 4, 4))
    with pytest.raises(ShapeError, match="kind"):
        calibrate(robot, q, T, "poses")
    with pytest.raises(ShapeError, match=r"expected shape \(10, 4, 4\)"):
        calibrate(robot, q, T[:, :3, 3])
    with pytest.raises(ShapeError, match="noise"):
        calibrate(robot, q, T, noise=(0.0, 1e-3))
    with pytest.raises(ShapeError, match="too few measurements"):
        calibrate(robot, np.random.default_rng(0).uniform(-1, 1, (3, 6)), np.broadcast_to(np.eye(4), (3, 4, 4)))
