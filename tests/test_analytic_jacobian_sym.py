"""Symbolic analytic Jacobian (RPY / ZYZ rates) against the numeric one and against finite differences of φ(q)."""

import numpy as np
import pytest
import sympy as sp

import denavit
from denavit.numeric import analytic_jacobian, forward_kinematics, rpy_from_rotation, zyz_from_rotation
from denavit.symbolic import analytic_jacobian_sym, angle_symbols, joint_symbols, parameter_symbols


@pytest.mark.parametrize("name", ["puma560", "report004-6-wrist3r", "stanford"])
@pytest.mark.parametrize("rep", ["rpy", "zyz"])
@pytest.mark.slow
def test_symbolic_analytic_jacobian_equals_numeric_and_finite_differences(name, rep):
    robot = denavit.load_robot(name)
    Ja = analytic_jacobian_sym(robot, rep)
    q_syms = joint_symbols(robot.dof).q
    params = {parameter_symbols(robot)[k]: v for k, v in robot.parameters}
    f = sp.lambdify([q_syms, angle_symbols(rep)], Ja.subs(params), "numpy")
    extract = rpy_from_rotation if rep == "rpy" else zyz_from_rotation
    rng = np.random.default_rng(4)
    for q in rng.uniform(-1.2, 1.2, (4, robot.dof)):
        phi = extract(forward_kinematics(robot, q)[:3, :3])
        got = np.array(f(q, phi), dtype=float)
        numeric, phi_n = analytic_jacobian(robot, q, rep)
        np.testing.assert_allclose(phi_n, phi, atol=1e-12)
        np.testing.assert_allclose(got, numeric, atol=1e-9)
        # independent route: central differences of the angles along each joint
        h = 1e-6
        for k in range(robot.dof):
            dq = np.zeros(robot.dof)
            dq[k] = h
            d_phi = (extract(forward_kinematics(robot, q + dq)[:3, :3]) - extract(forward_kinematics(robot, q - dq)[:3, :3])) / (2 * h)
            d_p = (forward_kinematics(robot, q + dq)[:3, 3] - forward_kinematics(robot, q - dq)[:3, 3]) / (2 * h)
            np.testing.assert_allclose(got[:3, k], d_p, atol=1e-6)
            np.testing.assert_allclose(got[3:, k], d_phi, atol=1e-5)
