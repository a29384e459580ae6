"""The report's differentiation route of the Jacobian, step by step: ∂p_e/∂q_i and vee(∂R/∂q_i Rᵀ) as formulas,
checked against a Jacobian the test builds itself (central differences of the forward kinematics)."""

from __future__ import annotations

import re

import numpy as np
import pytest
import sympy as sp

import denavit as dn
from denavit.report import Equation, Text, derive
from denavit.report import _motion

ARMS = ["planar3r", "stanford", "planar3r-mdh", "scara"]
_SHORT = re.compile(r"([CS])(\d+)")


def _value(expr, robot, q):
    """A shorthand formula (C12 = cos(q1 + q2), S3 = sin q3, parameters by name, q_i) at q."""
    env = {}
    for s in expr.free_symbols:
        m = _SHORT.fullmatch(s.name)
        if m:
            angle = sum(q[int(d) - 1] for d in m.group(2))
            env[s] = np.cos(angle) if m.group(1) == "C" else np.sin(angle)
        elif re.fullmatch(r"q\d+", s.name):
            env[s] = q[int(s.name[1:]) - 1]
        else:
            env[s] = dict(robot.parameters)[s.name]
    return np.array(sp.ImmutableMatrix(expr).xreplace(env).evalf(), dtype=float).ravel()


def _differences(robot, q, h=1e-6):
    """J0 by central differences of the numeric forward kinematics: ṗ and vee(Ṙ Rᵀ)."""
    R = dn.forward_kinematics(robot, q)[:3, :3]
    cols = []
    for i in range(robot.dof):
        e = np.zeros(robot.dof)
        e[i] = h
        Tp, Tm = dn.forward_kinematics(robot, q + e), dn.forward_kinematics(robot, q - e)
        D = (Tp - Tm) / (2 * h)
        W = D[:3, :3] @ R.T
        cols.append(np.concatenate([D[:3, 3], [W[2, 1], W[0, 2], W[1, 0]]]))
    return np.array(cols).T


def _random_q(robot, rng):
    lo, hi = robot.q_limits.T
    return rng.uniform(np.maximum(lo, -np.pi), np.minimum(hi, np.pi))


@pytest.mark.parametrize("name", ARMS)
def test_differentiation_steps_equal_the_derivative_of_the_pose(name):
    robot = dn.load_robot(name)
    rng = np.random.default_rng(sum(map(ord, name)))
    q_case = _random_q(robot, rng)
    sec = derive(robot, list(q_case), topics=["jacobian"]).section("jacobian")
    dp = [s for s in sec.steps if isinstance(s, Equation) and s.lhs.startswith("\\frac{\\partial p_e}")]
    dw = [s for s in sec.steps if isinstance(s, Equation) and s.lhs.startswith("J_{\\omega,")]
    assert len(dp) == len(dw) == robot.dof
    for q in (q_case, _random_q(robot, rng)):  # the formulas hold at any q, not only at the case
        J = _differences(robot, q)
        for i in range(robot.dof):
            np.testing.assert_allclose(_value(dp[i].expr, robot, q), J[:3, i], atol=1e-7)
            np.testing.assert_allclose(_value(dw[i].expr, robot, q), J[3:, i], atol=1e-7)
    (line,) = [s.text for s in sec.steps if isinstance(s, Text) and s.text.startswith("Check, the differentiation")]
    assert " agree (" in line


def test_the_differentiation_check_can_fail(monkeypatch):
    robot = dn.load_robot("planar3r")
    real = _motion.N.geometric_jacobian

    def off(r, q, *a, **k):  # a Jacobian with one wrong entry: the report's own check must say so
        J = np.array(real(r, q, *a, **k), dtype=float)
        J[1, 2] += 1e-3
        return J

    monkeypatch.setattr(_motion.N, "geometric_jacobian", off)
    sec = derive(robot, ["0", "pi/4", "pi/3"], topics=["jacobian"]).section("jacobian")
    (line,) = [s.text for s in sec.steps if isinstance(s, Text) and s.text.startswith("Check, the differentiation")]
    assert "DISAGREE" in line
