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
@pytest.mark.slow
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
@pytest.mark.slow
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
    t0 = time.process_time()
    T = forward_kinematics_sym(robot)
    elapsed = time.process_time() - t0  # CPU seconds: a busy machine does not change it
    q = joint_symbols(6).q
    # angle sums collapsed: cos(q2 + q3) appears, and no product cos(q2)*cos(q3) survives
    assert T.has(sp.cos(q[1] + q[2]))
    assert not any(t.has(sp.cos(q[1])) and t.has(sp.cos(q[2])) for t in sp.Add.make_args(T[0, 3]))
    assert len(str(T)) < 3000
    assert elapsed < 30  # a sanity bound on CPU time, not a benchmark (measured: well under 1 s)


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


def _shorthand_back(e, q):
    """Undo the C/S shorthand independently of denavit: C23 → cos(q2 + q3), S1 → sin(q1)."""
    back = {}
    for s in e.free_symbols:
        name = s.name
        if name[:1] in "CS" and name[1:].isdigit():
            angle = sum(q[int(d) - 1] for d in name[1:])
            back[s] = (sp.cos if name[0] == "C" else sp.sin)(angle)
    return e.xreplace(back)


@pytest.mark.parametrize("policy", ["trig", "none"])
@pytest.mark.parametrize("how", ["JointSymbols", "tuple", "list"])
def test_shorthand_matrix_on_puma_t06_collapses_sums_and_means_the_same(policy, how):
    # issue 16: shorthand_matrix(T, joint_symbols(6)) did nothing (it needed .q); with simplify="none" the
    # products cos(q2)cos(q3) − sin(q2)sin(q3) must still read C23.
    from denavit.symbolic import shorthand_matrix

    robot = denavit.load_robot("puma560")
    js = joint_symbols(6)
    q = js.q
    T = forward_kinematics_sym(robot, simplify=policy)
    arg = {"JointSymbols": js, "tuple": tuple(q), "list": list(q)}[how]
    S = shorthand_matrix(T, arg)
    assert not S.atoms(sp.cos, sp.sin)  # every sine and cosine became a C/S symbol: no cos(q2 + q3) left
    assert sp.Symbol("C23", real=True) in S.free_symbols and sp.Symbol("S23", real=True) in S.free_symbols
    assert not any(t.has(sp.Symbol("C2", real=True)) and t.has(sp.Symbol("C3", real=True))
                   for t in sp.Add.make_args(sp.expand(S[0, 3])))
    back = sp.ImmutableMatrix(_shorthand_back(S, q))
    # equal to the original: exactly (trig identities expanded on both sides), and at random angles
    assert sp.expand(sp.expand_trig(back - T)) == sp.zeros(4, 4)
    params = {parameter_symbols(robot)[k]: v for k, v in robot.parameter_values.items()}
    fb = sp.lambdify([q], back.subs(params), "numpy")
    ft = sp.lambdify([q], T.subs(params), "numpy")
    rng = np.random.default_rng(16)
    for qv in rng.uniform(-np.pi, np.pi, (5, 6)):
        np.testing.assert_allclose(fb(qv), ft(qv), atol=1e-12)
        np.testing.assert_allclose(fb(qv), forward_kinematics(robot, qv), atol=1e-9)


def test_shorthand_refuses_what_is_not_joint_variables():
    from denavit.symbolic import shorthand_matrix

    with pytest.raises(TypeError, match="symbols"):
        shorthand_matrix(sp.eye(2), ["q1", "q2"])
