"""Symbolic forward kinematics and Jacobian, the C/S shorthand, and the bridge back to numbers.

Run: ``python examples/symbolic_derivation.py``.  ``forward_kinematics_sym`` gives T_0_6 as a sympy matrix with
angle sums collapsed (cos(q2 + q3)); ``shorthand_matrix`` writes it as a person does (C23); ``lambdify`` turns
it back into a function that must agree with the numeric engine.  See docs/jacobians.md.
"""

import numpy as np
import sympy as sp

import denavit
from denavit.symbolic import forward_kinematics_sym, jacobian_sym, joint_symbols, parameter_symbols, shorthand_matrix

robot = denavit.load_robot("puma560")
q = joint_symbols(robot.dof).q
T = forward_kinematics_sym(robot)  # symbolic in q1..q6 and the named lengths a2, a3, d3, d4
short = shorthand_matrix(T, joint_symbols(robot.dof))
print("p_x =", short[0, 3])  # C1*C2*a2 + C1*C23*a3 - C1*S23*d4 + S1*d3
assert not short.atoms(sp.cos, sp.sin) and sp.Symbol("C23", real=True) in short.free_symbols

# Back to numbers: substitute the parameter values, lambdify, compare with the numeric engine.
values = {parameter_symbols(robot)[k]: v for k, v in robot.parameter_values.items()}
f = sp.lambdify([q], T.subs(values), "numpy")
for qv in np.random.default_rng(0).uniform(-np.pi, np.pi, (5, robot.dof)):
    assert np.allclose(f(qv), denavit.forward_kinematics(robot, qv), atol=1e-12)
print("symbolic T_0_6 equals the numeric forward kinematics")

# The Jacobian of a planar two-link arm: the textbook formula.
arm = denavit.load_robot("planar2r")
q1, q2 = joint_symbols(2).q
J = jacobian_sym(arm)
print("J0 (planar2r) =", shorthand_matrix(J[:2, :], joint_symbols(2)).tolist())
free = sorted(J.free_symbols - {q1, q2}, key=str)
L1, L2 = free  # the two link lengths of the file
textbook = sp.Matrix([[-L1 * sp.sin(q1) - L2 * sp.sin(q1 + q2), -L2 * sp.sin(q1 + q2)],
                      [L1 * sp.cos(q1) + L2 * sp.cos(q1 + q2), L2 * sp.cos(q1 + q2)]])
assert sp.simplify(J[:2, :] - textbook) == sp.zeros(2, 2)
