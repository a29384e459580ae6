"""Forward kinematics and Jacobians of the PUMA 560, batched, checked against finite differences.

Run: ``python examples/forward_kinematics_and_jacobians.py``.  Topics: ``T_0_6 = forward_kinematics(robot, q)``
over a batch of configurations; the geometric Jacobian ``J0`` (rows v, ω in base axes) and ``Je`` (tool axes);
the twist ``J0 q̇``; manipulability.  See docs/conventions.md and docs/jacobians.md.
"""

import numpy as np

import denavit
from denavit.numeric import geometric_jacobian, manipulability

robot = denavit.load_robot("puma560")
print(robot.name, "-", robot.dof, "joints,", robot.convention.value, "DH")

# Forward kinematics of 10 000 configurations in one call: (10000, 4, 4).
rng = np.random.default_rng(0)
q = rng.uniform(-np.pi, np.pi, (10_000, robot.dof))
T_0_6 = denavit.forward_kinematics(robot, q)
print("T_0_6 batch:", T_0_6.shape)
R = T_0_6[..., :3, :3]
assert np.allclose(R @ np.swapaxes(R, -1, -2), np.eye(3), atol=1e-12)  # every rotation is orthonormal

# The Jacobian at one configuration: J0 (base axes) and Je (tool axes) describe the same twist.
q0 = np.array([0.0, 0.5, -1.0, 0.2, 0.3, 0.1])
J0 = geometric_jacobian(robot, q0)
Je = geometric_jacobian(robot, q0, frame="tool")
R06 = denavit.forward_kinematics(robot, q0)[:3, :3]
assert np.allclose(J0[:3], R06 @ Je[:3]) and np.allclose(J0[3:], R06 @ Je[3:])

# Check J0 against central finite differences of forward kinematics: linear rows dp/dq, angular rows from dR Rᵀ.
h = 1e-6
for k in range(robot.dof):
    dq = np.zeros(robot.dof)
    dq[k] = h
    Tp, Tm = denavit.forward_kinematics(robot, q0 + dq), denavit.forward_kinematics(robot, q0 - dq)
    dp = (Tp[:3, 3] - Tm[:3, 3]) / (2 * h)
    W = (Tp[:3, :3] - Tm[:3, :3]) / (2 * h) @ R06.T  # skew matrix of ω per unit q̇_k
    w = np.array([W[2, 1], W[0, 2], W[1, 0]])
    assert np.allclose(J0[:3, k], dp, atol=1e-7) and np.allclose(J0[3:, k], w, atol=1e-7), k
print("J0 equals finite differences of FK")

# Velocity of the end effector for a joint velocity q̇, and how far from singular the arm is.
qd = np.array([0.1, 0.2, 0.3, 0.0, 0.0, 0.1])
twist = J0 @ qd
print("twist (v, ω) =", np.round(twist, 4))
print("manipulability sqrt(det(J Jᵀ)) =", round(float(manipulability(J0)), 5))
assert np.isclose(manipulability(J0), abs(np.linalg.det(J0)))  # square J: |det J|
