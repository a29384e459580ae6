"""Symbolic equations of motion: Lagrange (Jacobian form and literal steps) = Newton–Euler = numeric RNEA.

Independent truth: Spong's two-link equations typed in from the book, compared exactly; the
skew-symmetry of Ṁ − 2C checked symbolically; the numeric engine (itself checked against potential-energy
gradients and Pinocchio in test_dynamics_numeric.py) at random states of random arms.
"""

from __future__ import annotations


import numpy as np
import pytest

sp = pytest.importorskip("sympy")

import denavit  # noqa: E402
from denavit import DHLink, DHRobot, LinkInertia  # noqa: E402
from denavit.model import Convention, JointType  # noqa: E402
from denavit.numeric import coriolis_matrix, gravity_torques, mass_matrix, rnea  # noqa: E402
from denavit.symbolic import (  # noqa: E402
    format_dynamics,
    fourier_form,
    lagrange_steps,
    lagrangian_dynamics,
    newton_euler_dynamics,
    time_derivative,
)

from conftest import REDUCED
SEEDS = range(3 if REDUCED else 6)


def _rotation(rng):
    Q, R = np.linalg.qr(rng.normal(size=(3, 3)))
    Q = Q * np.sign(np.diag(R))
    return Q if np.linalg.det(Q) > 0 else -Q


def random_robot(rng, n=3):
    """Small random arm: either convention, a prismatic joint sometimes, a fixed row with inertia, full tensors."""
    def inertia():
        s = rng.uniform(0.01, 0.1, 3)
        R = _rotation(rng)
        I = R @ np.diag([s[1] + s[2], s[0] + s[2], s[0] + s[1]]) @ R.T
        r = lambda x: round(float(x), 3)  # noqa: E731  short decimals keep the exact rationals small
        return LinkInertia(mass=r(rng.uniform(0.5, 2)), com=tuple(r(c) for c in rng.uniform(-0.3, 0.3, 3)),
                           inertia=tuple(r(v) for v in (I[0, 0], I[1, 1], I[2, 2], I[0, 1], I[0, 2], I[1, 2])),
                           motor_inertia=r(rng.uniform(0, 0.3)), viscous=r(rng.uniform(0, 1)),
                           coulomb=r(rng.uniform(0, 1)))
    links = []
    for k in range(n):
        joint = JointType.PRISMATIC if k > 0 and rng.random() < 0.3 else JointType.REVOLUTE
        links.append(DHLink(a=round(rng.uniform(-0.5, 0.5), 3), alpha=float(rng.choice([0, np.pi / 2, -np.pi / 2])),
                            d=round(rng.uniform(-0.3, 0.3), 3), theta=float(rng.choice([0, np.pi / 2])),
                            joint=joint, inertia=inertia()))
        if k == 0 and rng.random() < 0.5:
            links.append(DHLink(a=0.1, alpha=0.3, d=0.05, joint=JointType.FIXED, inertia=inertia()))
    conv = Convention(str(rng.choice(["standard", "modified"])))
    return DHRobot(name="rand", links=tuple(links), convention=conv,
                   gravity=tuple(round(float(x), 2) for x in rng.normal(size=3) * 5))


def evaluate(expr, robot, terms, q, qd, qdd=None):
    """Substitute parameter values and a state into a sympy matrix; a float array."""
    subs = {sp.Symbol(k, real=True): v for k, v in robot.parameters}
    subs.update(zip(terms.q, q))
    subs.update(zip(terms.qd, qd))
    if qdd is not None:
        subs.update(zip(terms.qdd, qdd))
    return np.array(sp.Matrix(expr).subs(subs).evalf(), dtype=float)


@pytest.mark.parametrize("seed", SEEDS)
@pytest.mark.slow
def test_lagrange_newton_euler_and_numeric_rnea_agree(seed):
    rng = np.random.default_rng(seed)
    robot = random_robot(rng)
    lag = lagrangian_dynamics(robot)
    ne = newton_euler_dynamics(robot)
    steps = lagrange_steps(robot)
    for _ in range(2):
        q, qd, qdd = rng.uniform(-2, 2, (3, robot.dof))
        expected = rnea(robot, q, qd, qdd)
        for tau in (lag.tau, ne.tau, steps.tau):
            np.testing.assert_allclose(evaluate(tau, robot, lag, q, qd, qdd).ravel(), expected, atol=1e-9)
        np.testing.assert_allclose(evaluate(lag.M, robot, lag, q, qd), mass_matrix(robot, q), atol=1e-10)
        np.testing.assert_allclose(evaluate(lag.g, robot, lag, q, qd).ravel(), gravity_torques(robot, q), atol=1e-10)
        np.testing.assert_allclose(evaluate(lag.C, robot, lag, q, qd), coriolis_matrix(robot, q, qd), atol=1e-10)
        np.testing.assert_allclose(evaluate(ne.terms.M, robot, lag, q, qd), mass_matrix(robot, q), atol=1e-10)


def test_two_link_matches_spong_exactly():
    """Spong, Hutchinson, Vidyasagar (2006) sec. 7.4.3: planar elbow arm, symbols m_i, l_i, lc_i, I_i, g."""
    m1, m2, l1, l2, lc1, lc2, I1, I2 = sp.symbols("m1 m2 l1 l2 lc1 lc2 I1 I2", real=True)
    params = {"m1": 1.3, "m2": 0.7, "l1": 1.1, "l2": 0.9, "lc1": 0.4, "lc2": 0.5, "I1": 0.2, "I2": 0.1}
    data = {
        "name": "spong", "convention": "standard", "parameters": params, "gravity": [0, -9.81, 0],
        "joints": [
            {"a": "l1", "alpha": 0, "d": 0, "theta": "q",
             "inertia": {"mass": "m1", "com": ["lc1 - l1", 0, 0], "inertia": [0, "I1", "I1", 0, 0, 0]}},
            {"a": "l2", "alpha": 0, "d": 0, "theta": "q",
             "inertia": {"mass": "m2", "com": ["lc2 - l2", 0, 0], "inertia": [0, "I2", "I2", 0, 0, 0]}},
        ],
    }
    robot = denavit.robot_from_dict(data)
    g = sp.Rational(981, 100)
    for terms in (lagrangian_dynamics(robot), newton_euler_dynamics(robot).terms, lagrange_steps(robot).terms):
        q1, q2 = terms.q
        qd1, qd2 = terms.qd
        c2 = sp.cos(q2)
        d11 = m1 * lc1**2 + m2 * (l1**2 + lc2**2 + 2 * l1 * lc2 * c2) + I1 + I2
        d12 = m2 * (lc2**2 + l1 * lc2 * c2) + I2
        d22 = m2 * lc2**2 + I2
        h = -m2 * l1 * lc2 * sp.sin(q2)
        phi1 = (m1 * lc1 + m2 * l1) * g * sp.cos(q1) + m2 * lc2 * g * sp.cos(q1 + q2)
        phi2 = m2 * lc2 * g * sp.cos(q1 + q2)
        M = sp.Matrix([[d11, d12], [d12, d22]])
        C = sp.Matrix([[h * qd2, h * qd2 + h * qd1], [-h * qd1, 0]])  # Spong eq. 7.87
        assert sp.simplify(sp.expand_trig(terms.M - M)) == sp.zeros(2, 2)
        assert sp.simplify(sp.expand_trig(terms.g - sp.Matrix([phi1, phi2]))) == sp.zeros(2, 1)
        assert sp.simplify(sp.expand_trig(terms.C - C)) == sp.zeros(2, 2)
        assert sp.simplify(sp.expand_trig(terms.c - C * sp.Matrix([qd1, qd2]))) == sp.zeros(2, 1)


def test_mdot_minus_2c_is_skew_symmetric_symbolically():
    robot = denavit.load_robot("report000-planar3r")
    t = lagrangian_dynamics(robot)
    Mdot = time_derivative(t.M, t.q, t.qd)
    N = Mdot - 2 * t.C
    assert sp.simplify(sp.expand_trig(N + N.T)) == sp.zeros(3, 3)


def test_lagrange_steps_of_report000_planar3r_follow_the_hand_derivation():
    """The steps are those of seed report 000 (p_c, ṗ_c, K, P, L); their values are checked against
    independent formulas written here, not copied from the report (which contains mistakes)."""
    robot = denavit.load_robot("report000-planar3r")
    s = lagrange_steps(robot)
    L1, L2, Lc1, Lc2, Lc3 = sp.symbols("L1 L2 Lc1 Lc2 Lc3", real=True)
    q1, q2, q3 = s.q
    pc3 = sp.Matrix([L1 * sp.cos(q1) + L2 * sp.cos(q1 + q2) + Lc3 * sp.cos(q1 + q2 + q3),
                     L1 * sp.sin(q1) + L2 * sp.sin(q1 + q2) + Lc3 * sp.sin(q1 + q2 + q3), 0])
    assert sp.simplify(sp.expand_trig(s.p_c[2] - pc3)) == sp.zeros(3, 1)
    pc2 = sp.Matrix([L1 * sp.cos(q1) + Lc2 * sp.cos(q1 + q2), L1 * sp.sin(q1) + Lc2 * sp.sin(q1 + q2), 0])
    assert sp.simplify(sp.expand_trig(s.pd_c[1] - time_derivative(pc2, s.q, s.qd))) == sp.zeros(3, 1)
    assert s.L == s.K - s.P
    # the equations equal M q̈ + c + g assembled from the separately derived terms
    fast = lagrangian_dynamics(robot)
    assert sp.simplify(sp.expand_trig(s.tau - fast.tau)) == sp.zeros(3, 1)
    # the report's form: τ depends on q2, q3 and on q1 only through gravity
    assert not fast.M.has(q1)


@pytest.mark.slow
def test_puma560_mass_matrix_and_gravity_match_numeric():
    robot = denavit.load_robot("puma560")
    t = lagrangian_dynamics(robot, numeric=True, coriolis=False)
    rng = np.random.default_rng(3)
    q, qd = rng.uniform(-2, 2, (2, 6))
    np.testing.assert_allclose(evaluate(t.M, robot, t, q, qd), mass_matrix(robot, q), atol=1e-10)
    np.testing.assert_allclose(evaluate(t.g, robot, t, q, qd).ravel(), gravity_torques(robot, q), atol=1e-10)
    c = rnea(robot, q, qd, np.zeros(6), gravity=np.zeros(3), friction=False)
    np.testing.assert_allclose(evaluate(t.c, robot, t, q, qd).ravel(), c, atol=1e-10)
    assert not t.M.has(t.q[0])  # M never depends on the first joint angle


def test_fourier_form_is_canonical_and_exact():
    q1, q2, q3 = sp.symbols("q1:4", real=True)
    a = sp.Symbol("a")
    e = sp.cos(q2) * sp.cos(q2 + q3) + sp.sin(q2) * sp.sin(q2 + q3) + a * sp.sin(q1) ** 2
    f = fourier_form(e, (q1, q2, q3))
    assert f == sp.cos(q3) + a / 2 - a * sp.cos(2 * q1) / 2
    rng = np.random.default_rng(0)
    for _ in range(5):
        vals = dict(zip((q1, q2, q3, a), rng.uniform(-3, 3, 4)))
        assert abs(float((e - f).subs(vals))) < 1e-12


def test_format_dynamics_styles_and_cse():
    t = lagrangian_dynamics(denavit.load_robot("report000-planar3r"))
    text = format_dynamics(t, "text")
    assert "M[1,1] = " in text and "g[3] = " in text
    latex = format_dynamics(t, "latex")
    assert latex.startswith("\\begin{aligned}") and "M_{11}" in latex
    md = format_dynamics(t, "markdown")
    assert "$$" in md
    with pytest.raises(ValueError, match="choose one of"):
        format_dynamics(t, "html")


def test_no_inertia_raises_model_error():
    robot = DHRobot(name="bare", links=(DHLink(a=1.0), DHLink(a=1.0)))
    with pytest.raises(denavit.ModelError, match="no inertial data"):
        lagrangian_dynamics(robot)
