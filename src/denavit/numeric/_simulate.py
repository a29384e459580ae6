"""Simulation of the arm's motion over time: q̈ = M⁻¹(τ − C q̇ − g − τ_f), integrated by scipy's solve_ivp.

Joint torques are given as a constant vector, a function ``tau(t, q, qd)``, or one of the controllers
built here (:func:`pd_controller`, :func:`computed_torque_controller`).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np

from .._validate import as_joint_array
from ..errors import DenavitError, ShapeError
from ..model import DHRobot
from ._dynamics import forward_dynamics, gravity_torques, kinetic_energy, potential_energy, rnea

__all__ = ["SimulationResult", "simulate", "pd_controller", "computed_torque_controller"]

Torque = Callable[[float, np.ndarray, np.ndarray], np.ndarray]


@dataclass(frozen=True)
class SimulationResult:
    """Sampled trajectory: times t (m,), q, qd, tau (m, n), energies (m,) [J], and the solver's status."""

    t: np.ndarray
    q: np.ndarray
    qd: np.ndarray
    tau: np.ndarray
    kinetic: np.ndarray
    potential: np.ndarray
    success: bool
    message: str

    @property
    def energy(self) -> np.ndarray:
        """Total mechanical energy K + V [J]."""
        return self.kinetic + self.potential


def pd_controller(robot: DHRobot, q_target, kp, kd, gravity_compensation: bool = True) -> Torque:
    """τ = Kp (q* − q) − Kd q̇ (+ g(q)): a joint-space PD regulator (Spong et al. 2006, sec. 8.3)."""
    qt = as_joint_array(q_target, robot.dof, "q_target")
    kp, kd = np.broadcast_to(np.asarray(kp, float), qt.shape), np.broadcast_to(np.asarray(kd, float), qt.shape)

    def tau(t: float, q: np.ndarray, qd: np.ndarray) -> np.ndarray:
        out = kp * (qt - q) - kd * qd
        return out + gravity_torques(robot, q) if gravity_compensation else out

    return tau


def computed_torque_controller(robot: DHRobot, reference: Callable[[float], tuple], kp, kd) -> Torque:
    """τ = M(q)(q̈_r + Kd ė + Kp e) + C q̇ + g + τ_f with e = q_r − q (Spong et al. 2006, sec. 8.4).

    ``reference(t)`` returns (q_r, q̇_r, q̈_r).
    """
    kp, kd = np.asarray(kp, float), np.asarray(kd, float)

    def tau(t: float, q: np.ndarray, qd: np.ndarray) -> np.ndarray:
        qr, qdr, qddr = (np.asarray(x, float) for x in reference(t))
        v = qddr + kd * (qdr - qd) + kp * (qr - q)
        return rnea(robot, q, qd, v)

    return tau


def _torque_function(robot: DHRobot, tau) -> Torque:
    if tau is None:
        return lambda t, q, qd: np.zeros(robot.dof)
    if callable(tau):
        def checked(t, q, qd):
            out = np.asarray(tau(t, q, qd), dtype=float)
            if out.shape != (robot.dof,):
                raise ShapeError(f"tau(t, q, qd) must return shape ({robot.dof},), got {out.shape}")
            return out
        return checked
    const = as_joint_array(tau, robot.dof, "tau")
    if const.shape != (robot.dof,):
        raise ShapeError(f"tau: expected shape ({robot.dof},) or a function, got {const.shape}")
    return lambda t, q, qd: const


def _friction_coefficients(robot: DHRobot) -> tuple[np.ndarray, np.ndarray]:
    fv = np.array([link.inertia.viscous if link.inertia else 0.0 for link in robot.joints])
    fc = np.array([link.inertia.coulomb if link.inertia else 0.0 for link in robot.joints])
    return fv, fc


def simulate(robot: DHRobot, q0, qd0=None, duration: float = 1.0, tau=None, *, dt: float = 0.01,
             method: str = "DOP853", rtol: float = 1e-9, atol: float = 1e-10, friction: bool = True,
             gravity=None, stiction_velocity: float = 1e-3) -> SimulationResult:
    """Integrate the equations of motion from (q0, q̇0) for ``duration`` seconds.

    Parameters
    ----------
    q0, qd0 : array_like, shape (n,)
        Initial positions and rates (rates default to zero).
    duration : float
        Length of the run [s] (> 0).
    tau : None, array_like (n,) or callable(t, q, qd) -> (n,)
        Applied joint torques/forces: zero, constant, or a function (e.g. :func:`pd_controller`).
    dt : float
        Sampling interval of the returned trajectory [s] (the integrator picks its own steps).
    method, rtol, atol
        Passed to :func:`scipy.integrate.solve_ivp` (an adaptive explicit Runge–Kutta by default).
    friction : bool
        Apply joint friction.  For integration Coulomb friction coulomb·sign(q̇) is smoothed to
        coulomb·tanh(q̇ / stiction_velocity) [rad/s or m/s]: a discontinuous right-hand side would make
        an adaptive integrator stall where q̇ changes sign.

    Returns
    -------
    SimulationResult
    """
    from scipy.integrate import solve_ivp

    n = robot.dof
    q0 = as_joint_array(q0, n, "q0")
    qd0 = np.zeros(n) if qd0 is None else as_joint_array(qd0, n, "qd0")
    if q0.shape != (n,) or qd0.shape != (n,):
        raise ShapeError(f"q0 and qd0 must have shape ({n},)")
    if not (np.isfinite(duration) and duration > 0):
        raise ShapeError(f"duration must be a positive number of seconds, got {duration!r}")
    if not (np.isfinite(dt) and 0 < dt):
        raise ShapeError(f"dt must be positive, got {dt!r}")
    torque = _torque_function(robot, tau)

    fv, fc = _friction_coefficients(robot) if friction else (np.zeros(n), np.zeros(n))

    def rhs(t, x):
        q, qd = x[:n], x[n:]
        tau_f = fv * qd + fc * np.tanh(qd / stiction_velocity)
        qdd = forward_dynamics(robot, q, qd, torque(t, q, qd) - tau_f, gravity=gravity, friction=False)
        return np.concatenate([qd, qdd])

    t_eval = np.linspace(0.0, duration, int(round(duration / dt)) + 1)
    sol = solve_ivp(rhs, (0.0, duration), np.concatenate([q0, qd0]), method=method, t_eval=t_eval,
                    rtol=rtol, atol=atol)
    if sol.status < 0 and sol.y.shape[1] == 0:
        raise DenavitError(f"simulation failed at the start: {sol.message}")
    q, qd = sol.y[:n].T, sol.y[n:].T
    taus = np.array([torque(t, a, b) for t, a, b in zip(sol.t, q, qd)]).reshape(len(sol.t), n)
    return SimulationResult(sol.t, q, qd, taus, kinetic_energy(robot, q, qd),
                            potential_energy(robot, q, gravity=gravity), bool(sol.success), str(sol.message))
