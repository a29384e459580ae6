"""Inverse kinematics: every analytic solution of the PUMA 560, and the numerical solver.

Run: ``python examples/inverse_kinematics.py``.  ``analytic_ik`` returns every solution (up to 8 for an elbow
arm with a spherical wrist) with its branch labels; ``solve_ik`` (Levenberg–Marquardt with restarts) returns
one solution within the joint limits.  Each result is checked here by forward kinematics: FK(IK(T)) = T.
See docs/ik.md.
"""

import numpy as np

import denavit

robot = denavit.load_robot("puma560")
q_true = np.array([0.3, -0.6, 0.4, 0.8, -0.5, 1.2])
T = denavit.forward_kinematics(robot, q_true)  # the target pose T_0_6

# Every solution, in closed form: those within the joint limits, and those found outside them.
res = denavit.analytic_ik(robot, T)
print(f"{len(res.solutions)} analytic solutions within the limits ({res.method}):")
for q, branch in zip(res.solutions, res.branches):
    print("  ", np.round(q, 4), branch)
    assert np.allclose(denavit.forward_kinematics(robot, q), T, atol=1e-9)  # FK(IK(T)) = T
print(f"{len(res.outside_limits)} more outside the joint limits:")
for q in res.outside_limits:
    print("  ", np.round(q, 4))
    assert np.allclose(denavit.forward_kinematics(robot, q), T, atol=1e-9)
    assert np.any((q < robot.q_limits[:, 0]) | (q > robot.q_limits[:, 1]))
assert len(res.solutions) + len(res.outside_limits) == 8  # a generic pose: 2 shoulders x 2 elbows x 2 wrists
wrapped = np.angle(np.exp(1j * (res.solutions - q_true)))  # angle differences modulo 2π
assert np.min(np.abs(wrapped).max(axis=1)) < 1e-8  # the configuration we started from is among them

# Batched: 1 000 random poses in one call, each solution re-checked.
rng = np.random.default_rng(1)
lim = robot.q_limits
Q = rng.uniform(lim[:, 0], lim[:, 1], (1000, robot.dof))
batch = denavit.analytic_ik(robot, denavit.forward_kinematics(robot, Q))
print("solutions per pose:", np.bincount(batch.valid.sum(axis=1)))
assert np.all(batch.position_error[batch.valid] < 1e-9)

# The numerical solver: one solution within the limits, from a seed.
num = denavit.solve_ik(robot, T, q0=np.zeros(6), rng=np.random.default_rng(2))
print("solve_ik:", bool(num.success), np.round(num.q, 4), f"position error {num.position_error:.1e} m")
assert num.success and np.allclose(denavit.forward_kinematics(robot, num.q), T, atol=1e-8)
