"""Symbolic forward kinematics: equal to the numeric engine at random values, compact, exact where exact."""

import time

import numpy as np
import pytest
import sympy as sp

import denavit
from denavit import forward_kinematics, link_transforms
from denavit.symbolic import (
    forward_kinematics_sym,
    joint_symbols,
    link_matrices_sym,
    link_transforms_sym,
    parameter_symbols,
    shorthand,
)

from _random_robots import random_q, random_robot


def _numeric(robot, M):
    q = joint_symbols(robot.dof).q
    params = parameter_symbols(robot)
    M = M.subs({params[k]: v for k, v in robot.parameter_values.items()})
    return sp.lambdify([q], M, "numpy")


@pytest.mark.parametrize("name", denavit.catalogue_names())
def test_symbolic_fk_equals_numeric_on_catalogue(name):
    robot = denavit.load_robot(name)
    T_sym = forward_kinematics_sym(robot)
    frames = link_transforms_sym(robot)
    f = _numeric(robot, T_sym)
    rng = np.random.default_rng(2)
    for q in random_q(rng, robot, (4,)):
        np.testing.assert_allclose(np.array(f(q), dtype=float), forward_kinematics(robot, q), atol=1e-9)
        F = link_transforms(robot, q)
        np.testing.assert_allclose(np.array(_numeric(robot, frames[-1])(q), dtype=float),
                                   np.linalg.inv(robot.base_matrix) @ F[-1], atol=1e-9)


@pytest.mark.parametrize("seed", range(12))
def test_symbolic_fk_equals_numeric_on_random_robots(seed):
    rng = np.random.default_rng(seed)
    robot = random_robot(rng, n_rows=int(rng.integers(2, 6)))
    f = _numeric(robot, forward_kinematics_sym(robot))
    for q in random_q(rng, robot, (3,)):
        np.testing.assert_allclose(np.array(f(q), dtype=float), forward_kinematics(robot, q), atol=1e-9)


def test_puma_t06_is_compact_and_quick():
    robot = denavit.load_robot("puma560")
    link_transforms_sym.cache_clear()
    forward_kinematics_sym.cache_clear()
    t0 = time.perf_counter()
    T = forward_kinematics_sym(robot)
    elapsed = time.perf_counter() - t0
    q = joint_symbols(6).q
    # angle sums collapsed: cos(q2 + q3) appears, and no product cos(q2)*cos(q3) survives
    assert T.has(sp.cos(q[1] + q[2]))
    assert not any(t.has(sp.cos(q[1])) and t.has(sp.cos(q[2])) for t in sp.Add.make_args(T[0, 3]))
    assert len(str(T)) < 3000
    assert elapsed < 30  # a sanity bound, not a benchmark (measured: well under 1 s)


def test_planar_2r_position_is_textbook_form():
    """L1 c1 + L2 c12: Spong eq. 3.x for the planar elbow arm."""
    robot = denavit.load_robot("planar2r")
    T = forward_kinematics_sym(robot)
    q1, q2 = joint_symbols(2).q
    P = parameter_symbols(robot)
    L1, L2 = P.get("L1"), P.get("L2")
    assert sp.simplify(T[0, 3] - (L1 * sp.cos(q1) + L2 * sp.cos(q1 + q2))) == 0
    assert sp.simplify(T[1, 3] - (L1 * sp.sin(q1) + L2 * sp.sin(q1 + q2))) == 0
    s = shorthand(T[0, 3], (q1, q2))
    assert s.free_symbols >= {sp.Symbol("C1", real=True), sp.Symbol("C12", real=True)}


def test_exact_values_stay_exact():
    """Numeric parameter values and pi/2 twists give exact entries (no 6.1e-17 noise)."""
    robot = denavit.load_robot("report000-6r")
    T = forward_kinematics_sym(robot, numeric=True)
    q = joint_symbols(6).q
    T0 = T.subs({s: 0 for s in q})
    assert all(e.is_Rational or e.is_Integer for e in T0)
    np.testing.assert_allclose(np.array(T0, dtype=float), forward_kinematics(robot, np.zeros(6)), atol=1e-12)
    assert len(link_matrices_sym(robot)) == robot.n_rows
