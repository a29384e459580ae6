"""Simulation: energy conservation, the small-oscillation period of a pendulum, and controllers."""

from __future__ import annotations

import numpy as np
import pytest

import denavit
from denavit import DHLink, DHRobot, LinkInertia
from denavit.numeric import kinetic_energy, potential_energy
from denavit.numeric._simulate import computed_torque_controller, pd_controller, simulate

ENERGY_RTOL = 1e-6  # stated tolerance: relative drift of K + V over the run, torque-free and frictionless


def test_energy_conserved_without_torque_and_friction():
    robot = denavit.load_robot("report000-planar3r")
    res = simulate(robot, [0.3, -0.5, 0.8], [0.5, 0.0, -1.0], duration=2.0, dt=0.02, rtol=1e-11, atol=1e-11)
    assert res.success
    E = res.energy
    scale = np.abs(res.kinetic).max() + np.abs(res.potential).max()
    assert np.abs(E - E[0]).max() <= ENERGY_RTOL * scale
    assert np.ptp(res.kinetic) > 0.1 * scale  # energy really moved between K and V
    # energies recomputed independently from the sampled states
    np.testing.assert_allclose(res.kinetic, kinetic_energy(robot, res.q, res.qd), atol=1e-12)
    np.testing.assert_allclose(res.potential, potential_energy(robot, res.q), atol=1e-12)


def test_pendulum_small_oscillation_period():
    """A rigid pendulum (mass m, COM at l, inertia I about the COM) swings with T = 2π √((I + m l²)/(m g l))."""
    m, l, I, g = 1.5, 0.6, 0.02, 9.81
    robot = DHRobot(name="pendulum", links=(DHLink(a=l, inertia=LinkInertia(mass=m, inertia=(I, I, I, 0, 0, 0))),),
                    gravity=(0.0, -g, 0.0))
    expected = 2 * np.pi * np.sqrt((I + m * l * l) / (m * g * l))
    res = simulate(robot, [-np.pi / 2 + 0.01], duration=3 * expected, dt=1e-3)
    # hanging straight down is q = −π/2; find upward zero crossings of the deviation
    x = res.q[:, 0] + np.pi / 2
    idx = np.flatnonzero((x[:-1] < 0) & (x[1:] >= 0))
    times = res.t[idx] - x[idx] * (res.t[idx + 1] - res.t[idx]) / (x[idx + 1] - x[idx])
    period = np.diff(times).mean()
    assert abs(period - expected) < 1e-3 * expected


def test_friction_dissipates_energy():
    robot = denavit.load_robot("puma560")
    res = simulate(robot, np.zeros(6), np.ones(6), duration=0.3, dt=0.03, stiction_velocity=0.05,
                   tau=lambda t, q, qd: denavit.numeric.gravity_torques(robot, q))
    assert np.all(np.diff(res.kinetic) < 1e-9)


def test_pd_controller_reaches_target_and_computed_torque_tracks():
    robot = denavit.load_robot("planar2r")
    target = np.array([0.5, -0.7])
    res = simulate(robot, [0.0, 0.0], duration=4.0, tau=pd_controller(robot, target, kp=80.0, kd=20.0), dt=0.05)
    np.testing.assert_allclose(res.q[-1], target, atol=1e-3)

    def ref(t):
        return np.array([np.sin(t), np.cos(t)]), np.array([np.cos(t), -np.sin(t)]), np.array([-np.sin(t), -np.cos(t)])

    res = simulate(robot, [0.0, 1.0], [1.0, 0.0], duration=2.0, tau=computed_torque_controller(robot, ref, 100.0, 20.0))
    expected = np.array([ref(t)[0] for t in res.t])
    np.testing.assert_allclose(res.q, expected, atol=1e-6)


def test_bad_inputs():
    robot = denavit.load_robot("planar2r")
    with pytest.raises(denavit.ShapeError):
        simulate(robot, [0.0, 0.0, 0.0], duration=1.0)
    with pytest.raises(denavit.ShapeError, match="duration"):
        simulate(robot, [0.0, 0.0], duration=-1.0)
    with pytest.raises(denavit.ShapeError, match="must return shape"):
        simulate(robot, [0.0, 0.0], duration=0.1, tau=lambda t, q, qd: np.zeros(3))
