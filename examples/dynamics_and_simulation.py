"""Dynamics of the PUMA 560 and a simulated two-link arm.

Run: ``python examples/dynamics_and_simulation.py``.  τ = M(q) q̈ + C(q, q̇) q̇ + g(q) + τ_f(q̇): the recursive
Newton–Euler algorithm (``rnea``) against the pieces (``mass_matrix``, ``coriolis_vector``, ``gravity_torques``,
``friction_torques``), forward dynamics as its inverse, and a simulation whose energy is conserved when there is
no torque and no friction.  See docs/dynamics.md.
"""

import numpy as np

import denavit
from denavit.numeric import simulate

robot = denavit.load_robot("puma560")
rng = np.random.default_rng(0)
q, qd, qdd = rng.uniform(-1, 1, (3, robot.dof))

tau = denavit.rnea(robot, q, qd, qdd)  # inverse dynamics, friction included
M = denavit.mass_matrix(robot, q)
c = denavit.coriolis_vector(robot, q, qd)
g = denavit.gravity_torques(robot, q)
tf = denavit.friction_torques(robot, qd)
print("tau =", np.round(tau, 3), "N m")
assert np.allclose(tau, M @ qdd + c + g + tf)  # the equation of motion, piece by piece
assert np.allclose(M, M.T) and np.all(np.linalg.eigvalsh(M) > 0)  # M symmetric positive definite
assert np.allclose(denavit.forward_dynamics(robot, q, qd, tau), qdd)  # forward dynamics inverts the RNEA

# The kinetic energy is ½ q̇ᵀ M q̇.
assert np.isclose(denavit.kinetic_energy(robot, q, qd), 0.5 * qd @ M @ qd)

# A free two-link arm falling from rest, no friction: total energy stays constant.
arm = denavit.load_robot("planar2r")
run = simulate(arm, q0=np.array([0.4, -0.2]), duration=0.5, friction=False)
drift = np.ptp(run.energy) / max(np.ptp(run.potential), 1e-12)
print(f"planar2r: {len(run.t)} samples, energy drift {drift:.1e} of the potential swing")
assert run.success and drift < 1e-6
