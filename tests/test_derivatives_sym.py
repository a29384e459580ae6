"""Symbolic derivatives (J̇, ∂J/∂q, J̇q̇, ∂τ/∂q, ∂τ/∂q̇, ∂g/∂q) against the numeric engine, and their CLI.

Truth: the numeric functions, an independent route — the kinematic ones are closed forms in the Jacobian's
columns (Haviland & Corke 2023; :mod:`denavit.numeric._kin_derivatives`), the dynamic ones forward mode on the
numeric RNEA (dual numbers, :mod:`denavit.numeric._dyn_derivatives`) — while the symbolic ones differentiate the
symbolic Jacobian and the Lagrangian equations of motion with sympy.  Symbolic results are evaluated at random
q, q̇, q̈ and, for arms with named parameters, at random parameter values (the numeric side gets the same values
through :func:`denavit.with_parameters`).  Plus one textbook check by hand (planar 2R).
"""

from __future__ import annotations

import dataclasses
import json

import numpy as np
import pytest
import sympy as sp

import denavit
from denavit import JointType
from denavit import symbolic as S
from denavit.cli import main
from _evaluate import numeric_function
from _random_robots import random_inertia, random_robot

RTOL = 1e-10


def _point(rng, robot):
    q = rng.uniform(-np.pi, np.pi, robot.dof)
    prismatic = np.array([t is JointType.PRISMATIC for t in robot.joint_types])
    q[prismatic] = rng.uniform(-0.5, 0.5, prismatic.sum())
    return q, rng.uniform(-2, 2, robot.dof), rng.uniform(-2, 2, robot.dof)


def _evaluator(robot, *matrices):
    """The matrices (2-D, or a (6, n, n) array) as one function of (q, q̇, q̈, parameter values)."""
    js = S.joint_symbols(robot.dof)
    params = list(S.parameter_symbols(robot).values())
    flat = [m if len(m.shape) == 2 else m.reshape(m.shape[0], len(m) // m.shape[0]).tomatrix() for m in matrices]
    f = numeric_function([*js.q, *js.qd, *js.qdd, *params], flat)
    shapes = [m.shape for m in matrices]

    def at(q, qd, qdd, values):
        return [np.asarray(x).reshape(s) for x, s in zip(f(*q, *qd, *qdd, *values), shapes)]

    return at


def _close(actual, desired):
    scale = 1.0 + np.abs(desired).max()
    np.testing.assert_allclose(actual, desired, rtol=0, atol=RTOL * scale)


def _random_values(rng, robot):
    """Random positive parameter values (lengths and masses alike), and the numeric robot that has them."""
    values = {k: float(rng.uniform(0.3, 1.5)) for k in robot.parameter_values}
    return list(values.values()), denavit.with_parameters(robot, **values) if values else robot


def _three_joint_arm(seed: int, convention: str):
    """A random R-P-R arm (generic twists, base and tool) with random inertia, motor inertia and friction."""
    rng = np.random.default_rng(seed)
    rough = random_robot(rng, convention, n_rows=3, fixed_rows=False, base_tool=True)
    kinds = (JointType.REVOLUTE, JointType.PRISMATIC, JointType.REVOLUTE)
    links = tuple(dataclasses.replace(link, joint=k, inertia=random_inertia(rng)) for link, k in zip(rough.links, kinds))
    return rough.replace(links=links)


KIN_ARMS = [("planar2r", None), ("cylindrical-rpp", None), ("spherical-rrp", None),
            ("random-standard", 15), ("random-modified", 12),  # both with a generic twist; 15 with base and tool
            pytest.param("random-standard", 13, marks=pytest.mark.slow)]  # two generic twists, base, tool: ~4 CPU-s


def _arm(name, seed):
    if name.startswith("random-"):
        return _three_joint_arm(seed, name.split("-")[1])
    return denavit.load_robot(name)


@pytest.mark.parametrize("frame", ["base", "tool"])
@pytest.mark.parametrize("name, seed", KIN_ARMS)
def test_kinematic_derivatives_match_the_numeric_closed_forms(name, seed, frame):
    robot = _arm(name, seed)
    rng = np.random.default_rng(7)
    H = S.kinematic_hessian_sym(robot, frame)
    assert H.shape == (6, robot.dof, robot.dof)
    at = _evaluator(robot, H, S.jacobian_dot_sym(robot, frame), S.acceleration_bias_sym(robot, frame))
    for _ in range(3):
        values, numeric_robot = _random_values(rng, robot)
        q, qd, _ = _point(rng, robot)
        H_v, Jd_v, a_v = at(q, qd, np.zeros(robot.dof), values)
        _close(H_v, denavit.kinematic_hessian(numeric_robot, q, frame))
        _close(Jd_v, denavit.jacobian_dot(numeric_robot, q, qd, frame))
        _close(a_v.ravel(), denavit.acceleration_bias(numeric_robot, q, qd, frame))


# standard-convention random arms cost the symbolic dynamics 2-10 CPU-s (the modified ones < 1 s): slow
DYN_ARMS = [("planar2r", None), ("planar3r", None), ("random-modified", 22),
            pytest.param("random-standard", 29, marks=pytest.mark.slow),
            pytest.param("random-standard", 21, marks=pytest.mark.slow)]


@pytest.mark.parametrize("name, seed", DYN_ARMS)
def test_dynamics_derivatives_match_forward_mode_on_the_numeric_rnea(name, seed):
    """Friction (viscous) and motor inertia included on the random arms."""
    robot = _arm(name, seed)
    rng = np.random.default_rng(8)
    dq, dqd = S.rnea_derivatives_sym(robot)
    at = _evaluator(robot, dq, dqd, S.gravity_derivatives_sym(robot))
    for _ in range(3):
        values, numeric_robot = _random_values(rng, robot)
        q, qd, qdd = _point(rng, robot)
        dq_v, dqd_v, dg_v = at(q, qd, qdd, values)
        want_q, want_qd = denavit.rnea_derivatives(numeric_robot, q, qd, qdd)
        _close(dq_v, want_q)
        _close(dqd_v, want_qd)
        _close(dg_v, denavit.gravity_derivatives(numeric_robot, q))
        np.testing.assert_allclose(dg_v, dg_v.T, atol=RTOL * (1 + np.abs(dg_v).max()))  # ∂²V/∂q²


def test_friction_flag_removes_exactly_the_viscous_diagonal():
    robot = _three_joint_arm(22, "modified")
    _, with_f = S.rnea_derivatives_sym(robot)
    _, without = S.rnea_derivatives_sym(robot, friction=False)
    viscous = [link.inertia.viscous for link in robot.joints]
    assert min(viscous) > 0
    q, qd, qdd = _point(np.random.default_rng(9), robot)
    diff, = _evaluator(robot, with_f - without)(q, qd, qdd, [])
    np.testing.assert_allclose(diff, np.diag(viscous), rtol=0, atol=1e-12)


def test_planar_2r_by_hand():
    """Spong et al. (2006) sec. 7.4.1 with point masses at the link ends (the catalogue's planar2r):
    τ2 = m2 L2² (q̈1 + q̈2) + m2 L1 L2 (cos q2 q̈1 + sin q2 q̇1²) + m2 g L2 cos(q1 + q2), differentiated by hand;
    J̇ of the 2R's end point p = (L1 c1 + L2 c12, L1 s1 + L2 s12) by hand."""
    robot = denavit.load_robot("planar2r")
    q1, q2 = S.joint_symbols(2).q
    qd1, qd2 = S.joint_symbols(2).qd
    qdd1, _ = S.joint_symbols(2).qdd
    L1, L2, m2 = sp.symbols("L1 L2 m2", real=True)
    g = sp.Rational(981, 100)
    dq, dqd = S.rnea_derivatives_sym(robot)
    by_hand_q2 = m2 * L1 * L2 * (-sp.sin(q2) * qdd1 + sp.cos(q2) * qd1 ** 2) - m2 * g * L2 * sp.sin(q1 + q2)
    assert sp.expand(dq[1, 1] - by_hand_q2) == 0
    assert sp.expand(dqd[1, 0] - 2 * m2 * L1 * L2 * sp.sin(q2) * qd1) == 0 and dqd[1, 1] == 0
    Jd = S.jacobian_dot_sym(robot)
    assert sp.expand(Jd[0, 0] - (-L1 * sp.cos(q1) * qd1 - L2 * sp.cos(q1 + q2) * (qd1 + qd2))) == 0
    assert sp.expand(Jd[1, 1] - (-L2 * sp.sin(q1 + q2) * (qd1 + qd2))) == 0
    assert Jd[3:, :] == sp.zeros(3, 2)


def test_hessian_layout_and_slice():
    robot = denavit.load_robot("planar2r")
    q = S.joint_symbols(2).q
    J = S.geometric_jacobian_sym(robot)
    H = S.kinematic_hessian_sym(robot)
    for k in range(2):
        assert (S.hessian_slice_sym(H, k) - J.diff(q[k])).applyfunc(sp.expand) == sp.zeros(6, 2)


def test_one_entry_beyond_the_bound_and_a_clear_refusal():
    robot = denavit.load_robot("planar3r")
    dq, dqd = S.rnea_derivatives_sym(robot)
    assert sp.expand(S.rnea_derivative_entry_sym(robot, 2, "q", 1) - dq[2, 1]) == 0
    assert sp.expand(S.rnea_derivative_entry_sym(robot, 0, "qd", 0) - dqd[0, 0]) == 0
    with pytest.raises(ValueError, match="out of range"):
        S.rnea_derivative_entry_sym(robot, 3, "q", 0)
    panda = denavit.load_robot("panda")
    assert panda.dof > S.DERIVATIVES_MAX_DOF
    with pytest.raises(denavit.UnsupportedRobotError, match=f"{S.DERIVATIVES_MAX_DOF} joints"):
        S.rnea_derivatives_sym(panda)
    with pytest.raises(denavit.UnsupportedRobotError, match="DERIVATIVES_MAX_DOF"):
        S.gravity_derivatives_sym(panda)



def test_policies_and_numeric_parameters_give_the_same_values():
    """simplify="none" (entries as differentiated) and numeric=True (values substituted) are the same functions."""
    robot = denavit.load_robot("planar2r")
    rng = np.random.default_rng(10)
    values = list(robot.parameter_values.values())
    q, qd, qdd = _point(rng, robot)
    trig = _evaluator(robot, *S.rnea_derivatives_sym(robot), S.jacobian_dot_sym(robot, "tool"))(q, qd, qdd, values)
    none = _evaluator(robot, *S.rnea_derivatives_sym(robot, simplify="none"),
                      S.jacobian_dot_sym(robot, "tool", simplify="none"))(q, qd, qdd, values)
    numeric = S.rnea_derivatives_sym(robot, numeric=True)
    assert not any(m.free_symbols & set(S.parameter_symbols(robot).values()) for m in numeric)
    for a, b in zip(trig, none):
        _close(b, a)
    for a, b in zip(trig, _evaluator(robot, *numeric)(q, qd, qdd, values)):
        _close(b, a)
    with pytest.raises(ValueError, match="choose one of"):
        S.rnea_derivatives_sym(robot, simplify="fast")

# --- command line ------------------------------------------------------------------------------------------------

def _cli(capsys, *argv):
    code = main(list(argv))
    out, err = capsys.readouterr()
    assert code == 0, err
    return out


def _parse(entries, symbols):
    """JSON strings → sympy, read with a namespace of the expected symbols only (the test's own output)."""
    ns = {s.name: s for s in symbols}
    return sp.Matrix([[sp.sympify(e, locals=ns) for e in row] for row in entries])


@pytest.mark.parametrize("frame", ["base", "tool"])
def test_cli_jacobian_dot_and_hessian_symbolic(capsys, frame):
    robot = denavit.load_robot("planar2r")
    js = S.joint_symbols(2)
    syms = [*js.q, *js.qd, *S.parameter_symbols(robot).values()]
    data = json.loads(_cli(capsys, "jacobian", "planar2r", "--dot", "--hessian", "--symbolic", "--frame", frame,
                           "--json"))
    at = {**dict(zip(js.q, (0.3, -0.8))), **dict(zip(js.qd, (1.5, 0.4))), **{s: v for s, v in zip(
        S.parameter_symbols(robot).values(), robot.parameter_values.values())}}
    Jd = np.array(_parse(data["Jdot_symbolic"], syms).subs(at), dtype=float)
    np.testing.assert_allclose(Jd, denavit.jacobian_dot(robot, [0.3, -0.8], [1.5, 0.4], frame), atol=1e-12)
    a = np.array(_parse(data["Jdot_qd_symbolic"], syms).subs(at), dtype=float).ravel()
    np.testing.assert_allclose(a, Jd @ [1.5, 0.4], atol=1e-12)
    H = np.array([[[float(sp.sympify(e, locals={s.name: s for s in syms}).subs(at)) for e in row] for row in plane]
                  for plane in data["H_symbolic"]])
    np.testing.assert_allclose(H, denavit.kinematic_hessian(robot, [0.3, -0.8], frame), atol=1e-12)
    assert len(data["H_latex"]) == 2 and data["Jdot_latex"].startswith("\\left[")
    text = _cli(capsys, "jacobian", "planar2r", "--dot", "--hessian", "--symbolic", "--frame", frame)
    assert "dJ/dq2 =" in text and ("dJ0/dt =" if frame == "base" else "dJe/dt =") in text
    assert "qd" in text and "cos" in text
    latex = _cli(capsys, "jacobian", "planar2r", "--dot", "--symbolic", "--latex")
    assert "\\cos{\\left(q_{1} + q_{2} \\right)}" in latex


def test_cli_symbolic_with_numbers_prints_both(capsys):
    data = json.loads(_cli(capsys, "jacobian", "planar2r", "--dot", "--symbolic", "-q", "0.3, 0.5", "--qd", "1, -2",
                           "--json"))
    assert "Jdot_symbolic" in data and np.array(data["Jdot"]).shape == (6, 2)


def test_cli_dynamics_derivatives_symbolic(capsys):
    robot = denavit.load_robot("planar2r")
    js = S.joint_symbols(2)
    params = S.parameter_symbols(robot)
    syms = [*js.q, *js.qd, *js.qdd, *params.values()]
    data = json.loads(_cli(capsys, "dynamics", "planar2r", "--symbolic", "--derivatives", "--json"))
    q, qd, qdd = (0.4, -1.1), (0.7, 1.3), (-0.5, 2.0)
    at = {**dict(zip(js.q, q)), **dict(zip(js.qd, qd)), **dict(zip(js.qdd, qdd)),
          **{params[k]: v for k, v in robot.parameter_values.items()}}
    want_q, want_qd = denavit.rnea_derivatives(robot, q, qd, qdd)
    for key, want in (("dtau_dq", want_q), ("dtau_dqd", want_qd), ("dg_dq", denavit.gravity_derivatives(robot, q))):
        got = np.array(_parse(data[f"{key}_symbolic"], syms).subs(at), dtype=float)
        np.testing.assert_allclose(got, want, atol=1e-12)
        assert data[f"{key}_latex"].startswith("\\left[")
    text = _cli(capsys, "dynamics", "planar2r", "--symbolic", "--derivatives")
    assert "dtau/dq[2,2] = C2*L1*L2*m2*qd1**2 - L1*L2*S2*m2*qdd1 - L2*S12*g*m2" in text
    assert "dg/dq[1,2] = -L2*S12*g*m2" in text


@pytest.mark.parametrize("argv, message", [
    (["jacobian", "planar2r", "--dot"], "or --symbolic for the formulas"),
    (["jacobian", "planar2r", "--dot", "--symbolic", "--qd", "1, 2"], "--qd goes with -q"),
    (["jacobian", "planar2r", "--hessian", "--symbolic", "--method", "propagation"], "does not go with --method"),
    (["jacobian", "planar2r", "--hessian", "--symbolic", "--frame", "1"], "choose base or tool"),
    (["jacobian", "planar2r", "--dot", "--symbolic", "--analytic", "rpy"], "does not go with --analytic"),
    (["dynamics", "planar2r", "--derivatives"], "or --symbolic for the formulas"),
    (["dynamics", "planar2r", "--derivatives", "--symbolic", "--method", "newton-euler"], "drop --method"),
    (["dynamics", "panda", "--derivatives", "--symbolic"], f"limited to {S.DERIVATIVES_MAX_DOF} joints"),
])
def test_cli_bad_combinations_exit_2_with_one_line(capsys, argv, message):
    code = main(argv)
    out, err = capsys.readouterr()
    assert code == 2 and err.count("\n") == 1 and "Traceback" not in err and message in err, err
