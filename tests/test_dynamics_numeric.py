"""Numeric dynamics against independent ground truth.

Truth here never comes from the code under test: potential energy and COM velocities are computed in
this file from the frames, the two-link formulas are typed in from Spong et al., finite differences give
Ṁ, and Pinocchio (when installed) is an outside oracle.
"""

from __future__ import annotations


import numpy as np
import pytest

import denavit
from denavit import DHLink, DHRobot, LinkInertia, convert_convention
from denavit.model import Convention, JointType
from denavit.numeric import (
    coriolis_matrix,
    forward_dynamics,
    gravity_torques,
    kinetic_energy,
    link_transforms,
    mass_matrix,
    potential_energy,
    rnea,
)

from _random_robots import random_inertia
from conftest import REDUCED

N_RANDOM = 3 if REDUCED else 8
ATOL = 1e-9


# ---------------------------------------------------------------------------------------------------
# random arms (full, non-diagonal inertia tensors, fixed rows, prismatic joints, base transforms)


def _rotation(rng: np.random.Generator) -> np.ndarray:
    Q, R = np.linalg.qr(rng.normal(size=(3, 3)))
    Q = Q * np.sign(np.diag(R))
    return Q if np.linalg.det(Q) > 0 else -Q


def random_robot(rng: np.random.Generator, n: int | None = None, convention: str | None = None,
                 prismatic: bool = True, fixed_rows: bool = True, motor: bool = False,
                 friction: bool = False) -> DHRobot:
    n = n or int(rng.integers(2, 7))
    conv = convention or str(rng.choice(["standard", "modified"]))
    links = []
    for k in range(n):
        if fixed_rows and rng.random() < 0.3:  # a fixed row, sometimes with its own inertia
            inertia = random_inertia(rng, motor=False, friction=False) if rng.random() < 0.5 else None
            links.append(DHLink(a=rng.uniform(-0.5, 0.5), alpha=rng.uniform(-np.pi, np.pi), d=rng.uniform(-0.3, 0.3),
                                theta=rng.uniform(-np.pi, np.pi), joint=JointType.FIXED, inertia=inertia))
        joint = JointType.PRISMATIC if prismatic and k > 0 and rng.random() < 0.3 else JointType.REVOLUTE
        links.append(DHLink(a=rng.uniform(-0.5, 0.5), alpha=rng.uniform(-np.pi, np.pi), d=rng.uniform(-0.3, 0.3),
                            theta=rng.uniform(-np.pi, np.pi), joint=joint,
                            inertia=random_inertia(rng, motor, friction)))
    base = np.eye(4)
    base[:3, :3] = _rotation(rng)
    base[:3, 3] = rng.uniform(-1, 1, 3)
    gravity = tuple(rng.normal(size=3) * 4)
    return DHRobot(name="random", links=tuple(links), convention=Convention(conv), base=base, gravity=gravity)


def random_state(rng, robot, shape=()):
    n = robot.dof
    return (rng.uniform(-np.pi, np.pi, shape + (n,)), rng.uniform(-2, 2, shape + (n,)),
            rng.uniform(-3, 3, shape + (n,)))


# ---------------------------------------------------------------------------------------------------
# independent quantities computed here from the frames only


def owner_of_rows(robot):
    body, out = -1, []
    for link in robot.links:
        body += link.is_joint
        out.append(body)
    return out


def com_world(robot, q):
    """[(mass, world COM (3,), world rotation of the row frame, inertia)] of every moving piece."""
    frames = link_transforms(robot, q)
    out = []
    for r, (link, body) in enumerate(zip(robot.links, owner_of_rows(robot))):
        if link.inertia is None or body < 0:
            continue
        F = frames[r + 1]
        out.append((link.inertia.mass, F[:3, :3] @ np.array(link.inertia.com) + F[:3, 3], F[:3, :3],
                    link.inertia.inertia_matrix))
    return out


def potential_here(robot, q):
    g = np.array(robot.gravity)
    return -sum(m * g @ c for m, c, _, _ in com_world(robot, q))


def mass_matrix_by_fd(robot, q, h=1e-6):
    """M from the kinetic energy of COM velocities and body rates found by central differences."""
    n = robot.dof
    Jv, Jw = [], []
    for j in range(n):
        e = np.zeros(n)
        e[j] = h
        plus, minus = com_world(robot, q + e), com_world(robot, q - e)
        Jv.append([(p[1] - m[1]) / (2 * h) for p, m in zip(plus, minus)])
        w = []
        for p, m in zip(plus, minus):
            Rdot = (p[2] - m[2]) / (2 * h)
            W = Rdot @ ((p[2] + m[2]) / 2).T  # skew(ω)
            w.append(np.array([W[2, 1], W[0, 2], W[1, 0]]))
        Jw.append(w)
    Jv, Jw = np.array(Jv), np.array(Jw)  # (n, P, 3)
    M = np.zeros((n, n))
    for p, (m, _, R, I) in enumerate(com_world(robot, q)):
        Iw = R @ I @ R.T
        M += m * Jv[:, p] @ Jv[:, p].T + Jw[:, p] @ Iw @ Jw[:, p].T
    return M + np.diag([link.inertia.motor_inertia if link.inertia else 0 for link in robot.joints])


# ---------------------------------------------------------------------------------------------------
# ground truth


@pytest.mark.parametrize("seed", range(N_RANDOM))
def test_gravity_torques_equal_gradient_of_potential(seed):
    rng = np.random.default_rng(seed)
    robot = random_robot(rng)
    q = rng.uniform(-np.pi, np.pi, robot.dof)
    h = 1e-6
    grad = np.array([(potential_here(robot, q + h * e) - potential_here(robot, q - h * e)) / (2 * h)
                     for e in np.eye(robot.dof)])
    np.testing.assert_allclose(gravity_torques(robot, q), grad, atol=1e-6)
    assert np.abs(grad).max() > 1e-3  # the check is not trivially zero
    np.testing.assert_allclose(potential_energy(robot, q), potential_here(robot, q), atol=1e-12)


@pytest.mark.parametrize("seed", range(N_RANDOM))
def test_mass_matrix_equals_kinetic_energy_by_finite_differences(seed):
    rng = np.random.default_rng(100 + seed)
    robot = random_robot(rng, motor=True)
    q = rng.uniform(-np.pi, np.pi, robot.dof)
    np.testing.assert_allclose(mass_matrix(robot, q), mass_matrix_by_fd(robot, q), atol=1e-7)


def spong_two_link(q, qd, qdd, m1, m2, l1, lc1, lc2, I1, I2, g):
    """Spong, Hutchinson, Vidyasagar (2006), sec. 7.4.3 (planar elbow manipulator), typed in from the book."""
    c2 = np.cos(q[1])
    d11 = m1 * lc1**2 + m2 * (l1**2 + lc2**2 + 2 * l1 * lc2 * c2) + I1 + I2
    d12 = m2 * (lc2**2 + l1 * lc2 * c2) + I2
    d22 = m2 * lc2**2 + I2
    h = -m2 * l1 * lc2 * np.sin(q[1])
    phi1 = (m1 * lc1 + m2 * l1) * g * np.cos(q[0]) + m2 * lc2 * g * np.cos(q[0] + q[1])
    phi2 = m2 * lc2 * g * np.cos(q[0] + q[1])
    tau1 = d11 * qdd[0] + d12 * qdd[1] + 2 * h * qd[0] * qd[1] + h * qd[1] ** 2 + phi1
    tau2 = d12 * qdd[0] + d22 * qdd[1] - h * qd[0] ** 2 + phi2
    return np.array([tau1, tau2])


@pytest.mark.parametrize("seed", range(N_RANDOM))
def test_rnea_matches_spong_two_link_closed_form(seed):
    rng = np.random.default_rng(200 + seed)
    m1, m2, l1, l2, I1, I2 = rng.uniform(0.5, 2.0, 6)
    lc1, lc2 = l1 * rng.uniform(0.2, 0.8), l2 * rng.uniform(0.2, 0.8)
    g = 9.81
    # standard DH frame i sits at the far end of link i; products Ixz, Iyz and a z offset of the COM
    # must not change the planar torques (N_z = Izz ω̇ when ω ∥ z)
    def inertia(m, lc, l, Izz):
        return LinkInertia(mass=m, com=(lc - l, 0.0, 0.05), inertia=(Izz * 1.5, Izz * 1.2, Izz, 0.0, 0.01, -0.02))
    robot = DHRobot(name="spong", links=(DHLink(a=l1, inertia=inertia(m1, lc1, l1, I1)),
                                         DHLink(a=l2, inertia=inertia(m2, lc2, l2, I2))),
                    gravity=(0.0, -g, 0.0))
    for _ in range(5):
        q, qd, qdd = rng.uniform(-3, 3, (3, 2))
        expected = spong_two_link(q, qd, qdd, m1, m2, l1, lc1, lc2, I1, I2, g)
        np.testing.assert_allclose(rnea(robot, q, qd, qdd), expected, atol=ATOL)


@pytest.mark.parametrize("seed", range(N_RANDOM))
def test_standard_and_modified_descriptions_give_same_torques(seed):
    rng = np.random.default_rng(300 + seed)
    robot = random_robot(rng, convention="standard", motor=True, friction=True)
    other = convert_convention(robot, "modified")
    q, qd, qdd = random_state(rng, robot, (4,))
    np.testing.assert_allclose(rnea(other, q, qd, qdd), rnea(robot, q, qd, qdd), atol=ATOL)
    back = convert_convention(other, "standard")
    np.testing.assert_allclose(mass_matrix(back, q), mass_matrix(robot, q), atol=ATOL)


# ---------------------------------------------------------------------------------------------------
# identities and route agreement


@pytest.mark.parametrize("shape", [(), (1,), (3, 2)])
def test_batch_equals_loop_with_distinct_rows(shape):
    rng = np.random.default_rng(7)
    robot = random_robot(rng, n=5, motor=True, friction=True)
    q, qd, qdd = random_state(rng, robot, shape)
    tau = rnea(robot, q, qd, qdd)
    M = mass_matrix(robot, q)
    C = coriolis_matrix(robot, q, qd)
    qdd_fd = forward_dynamics(robot, q, qd, tau)
    assert tau.shape == shape + (5,) and M.shape == shape + (5, 5) and C.shape == shape + (5, 5)
    for idx in np.ndindex(*shape):
        np.testing.assert_allclose(tau[idx], rnea(robot, q[idx], qd[idx], qdd[idx]), atol=1e-12)
        np.testing.assert_allclose(M[idx], mass_matrix(robot, q[idx]), atol=1e-12)
        np.testing.assert_allclose(C[idx], coriolis_matrix(robot, q[idx], qd[idx]), atol=1e-12)
        np.testing.assert_allclose(qdd_fd[idx], qdd[idx], atol=1e-8)
    if len(shape) and shape[0] > 1:
        assert not np.allclose(tau[0], tau[1])  # rows really differ


@pytest.mark.parametrize("seed", range(N_RANDOM))
def test_mass_matrix_symmetric_positive_definite_and_equals_rnea_columns(seed):
    rng = np.random.default_rng(400 + seed)
    robot = random_robot(rng, motor=True)
    q = rng.uniform(-np.pi, np.pi, robot.dof)
    M = mass_matrix(robot, q)
    np.testing.assert_allclose(M, M.T, atol=1e-13)
    assert np.linalg.eigvalsh(M).min() > 0
    zero = np.zeros(robot.dof)
    cols = np.array([rnea(robot, q, zero, e, gravity=np.zeros(3), friction=False) for e in np.eye(robot.dof)]).T
    np.testing.assert_allclose(M, cols, atol=ATOL)


@pytest.mark.parametrize("seed", range(N_RANDOM))
def test_coriolis_matrix_skew_property_and_velocity_term(seed):
    rng = np.random.default_rng(500 + seed)
    robot = random_robot(rng, motor=True)
    q, qd, _ = random_state(rng, robot)
    h = 1e-6
    Mdot = (mass_matrix(robot, q + h * qd) - mass_matrix(robot, q - h * qd)) / (2 * h)
    C = coriolis_matrix(robot, q, qd)
    N = Mdot - 2 * C
    np.testing.assert_allclose(N, -N.T, atol=1e-6)
    c = rnea(robot, q, qd, np.zeros(robot.dof), gravity=np.zeros(3), friction=False)
    np.testing.assert_allclose(C @ qd, c, atol=ATOL)
    assert np.abs(c).max() > 1e-3


@pytest.mark.parametrize("seed", range(N_RANDOM))
def test_forward_dynamics_inverts_inverse_dynamics_with_friction(seed):
    rng = np.random.default_rng(600 + seed)
    robot = random_robot(rng, motor=True, friction=True)
    q, qd, qdd = random_state(rng, robot, (3,))
    tau = rnea(robot, q, qd, qdd)
    np.testing.assert_allclose(forward_dynamics(robot, q, qd, tau), qdd, atol=1e-8)


def test_kinetic_energy_rate_equals_power_without_gravity_and_friction():
    """d/dt K = q̇ᵀ τ when g = 0 and no friction (work–energy theorem), by finite differences in time."""
    rng = np.random.default_rng(11)
    robot = random_robot(rng, n=4, motor=True).replace(gravity=(0.0, 0.0, 0.0))
    q, qd, qdd = random_state(rng, robot)
    tau = rnea(robot, q, qd, qdd)
    h = 1e-6
    K = lambda t: kinetic_energy(robot, q + qd * t + 0.5 * qdd * t * t, qd + qdd * t)  # noqa: E731
    np.testing.assert_allclose((K(h) - K(-h)) / (2 * h), qd @ tau, rtol=1e-6, atol=1e-7)


def test_catalogue_robots_with_dynamics_are_consistent():
    for name in denavit.catalogue_names():
        robot = denavit.load_robot(name)
        if not robot.has_dynamics:
            continue
        rng = np.random.default_rng(0)
        q, qd, qdd = random_state(rng, robot, (2,))
        tau = rnea(robot, q, qd, qdd)
        M = mass_matrix(robot, q)
        if np.linalg.eigvalsh(M)[..., 0].min() < 1e-10 * np.abs(M).max():  # e.g. ur5: point masses only
            with pytest.raises(denavit.ModelError, match="singular"):
                forward_dynamics(robot, q, qd, tau)
            with pytest.raises(denavit.ModelError, match="singular"):  # the unbatched (float) path too
                forward_dynamics(robot, q[0], qd[0], tau[0])
            continue
        np.testing.assert_allclose(forward_dynamics(robot, q, qd, tau), qdd, atol=1e-7, err_msg=name)


def test_bad_shapes_and_missing_inertia_raise():
    robot = denavit.load_robot("planar2r")
    with pytest.raises(denavit.ShapeError, match="expected .* got"):
        rnea(robot, [0, 0, 0], [0, 0], [0, 0])
    with pytest.raises(denavit.ShapeError):
        mass_matrix(robot, [[0.0]])
    from denavit.numeric._dynamics import require_dynamics

    with pytest.raises(denavit.ModelError, match="no inertial data"):
        require_dynamics(DHRobot(name="bare", links=(DHLink(a=1.0), DHLink(a=1.0))))


# ---------------------------------------------------------------------------------------------------
# Pinocchio as an outside oracle


def _rz_tz(theta, d):
    c, s = np.cos(theta), np.sin(theta)
    T = np.eye(4)
    T[:2, :2] = [[c, -s], [s, c]]
    T[2, 3] = d
    return T


def pinocchio_model(robot):
    """A pinocchio Model with JointModelRZ/PZ, placements from the DH transforms at q = 0."""
    pin = pytest.importorskip("pinocchio")
    q0 = np.zeros(robot.dof)
    F = link_transforms(robot, q0)
    B = []  # frame moved by joint k: standard {i-1}·Rz(θ)Tz(d), modified {i}
    for i in robot.joint_rows:
        link = robot.links[i]
        B.append(F[i] @ _rz_tz(link.theta, link.d) if robot.convention is Convention.STANDARD else F[i + 1])
    model = pin.Model()
    parent, prev, ids = 0, np.eye(4), []
    for k, kind in enumerate(robot.joint_types):
        joint = pin.JointModelRZ() if kind is JointType.REVOLUTE else pin.JointModelPZ()
        X = np.linalg.inv(prev) @ B[k]
        parent = model.addJoint(parent, joint, pin.SE3(X[:3, :3], X[:3, 3]), f"joint{k + 1}")
        ids.append(parent)
        prev = B[k]
    for r, (link, body) in enumerate(zip(robot.links, owner_of_rows(robot))):
        if link.inertia is None or body < 0:
            continue
        X = np.linalg.inv(B[body]) @ F[r + 1]
        R = X[:3, :3]
        inertia = pin.Inertia(link.inertia.mass, R @ np.array(link.inertia.com) + X[:3, 3],
                              R @ link.inertia.inertia_matrix @ R.T)
        model.appendBodyToJoint(ids[body], inertia, pin.SE3.Identity())
    model.gravity.linear = np.array(robot.gravity)
    model.armature = np.array([link.inertia.motor_inertia if link.inertia else 0.0 for link in robot.joints])
    return model


@pytest.mark.peer
@pytest.mark.parametrize("name_or_seed", ["puma560", "puma560-mdh", "report000-planar3r", 0, 1, 2, 3])
def test_against_pinocchio(name_or_seed):
    pin = pytest.importorskip("pinocchio")
    if isinstance(name_or_seed, str):
        robot = denavit.load_robot(name_or_seed)
        rng = np.random.default_rng(0)
    else:
        rng = np.random.default_rng(700 + name_or_seed)
        robot = random_robot(rng, motor=True)
    model = pinocchio_model(robot)
    data = model.createData()
    for _ in range(5):
        q, qd, qdd = random_state(rng, robot)
        np.testing.assert_allclose(rnea(robot, q, qd, qdd, friction=False), pin.rnea(model, data, q, qd, qdd),
                                   atol=1e-10)
        Mp = pin.crba(model, data, q)
        Mp = np.triu(Mp) + np.triu(Mp, 1).T
        np.testing.assert_allclose(mass_matrix(robot, q), Mp, atol=1e-10)
        np.testing.assert_allclose(coriolis_matrix(robot, q, qd), pin.computeCoriolisMatrix(model, data, q, qd),
                                   atol=1e-10)
        np.testing.assert_allclose(gravity_torques(robot, q), pin.computeGeneralizedGravity(model, data, q),
                                   atol=1e-10)
        tau = rng.normal(size=robot.dof) * 5
        np.testing.assert_allclose(forward_dynamics(robot, q, qd, tau, friction=False),
                                   pin.aba(model, data, q, qd, tau), atol=1e-8)
