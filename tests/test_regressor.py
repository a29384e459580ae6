"""The regressor τ = Y π, the energy regressors and the base parameters, against independent routes.

Truth never comes from the code under test: τ from denavit.rnea (the robot's own parameters through the COM
form of the pieces), K from the CRBA's M (½ q̇ᵀ M q̇), U from the COM heights of denavit.potential_energy,
Pinocchio's computeJointTorqueRegressor and Inertia.toDynamicParameters, an SVD for the rank, and the planar
2R arm's base parameters counted by hand.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

import denavit
from denavit import DHLink, DHRobot, LinkInertia, ShapeError
from denavit.numeric import (base_parameters, base_regressor, inertial_parameters, kinetic_energy,
                             kinetic_energy_regressor, parameter_names, potential_energy, potential_energy_regressor,
                             regressor)

from _random_robots import random_inertia
from _random_robots import random_robot as random_kinematics
from conftest import REDUCED

SEEDS = range(4 if REDUCED else 10)


def random_arm(seed: int) -> DHRobot:
    """Random kinematics (both conventions, prismatic joints, fixed rows, base/tool) with inertia on most rows
    (fixed rows included), friction, motor inertia and an odd gravity."""
    rng = np.random.default_rng(seed)
    robot = random_kinematics(rng)
    links = tuple(DHLink(a=l.a, alpha=l.alpha, d=l.d, theta=l.theta, joint=l.joint,
                         inertia=random_inertia(rng) if rng.random() < 0.85 else None) for l in robot.links)
    return robot.replace(links=links, gravity=tuple(rng.normal(size=3) * 4))


def random_state(rng, robot, shape=()):
    n = robot.dof
    return (rng.uniform(-np.pi, np.pi, shape + (n,)), rng.uniform(-2, 2, shape + (n,)),
            rng.uniform(-3, 3, shape + (n,)))


@pytest.mark.parametrize("seed", SEEDS)
def test_regressor_times_parameters_is_rnea_single_and_batched(seed):
    robot = random_arm(seed)
    rng = np.random.default_rng(100 + seed)
    pi = inertial_parameters(robot)
    assert pi.shape == (len(parameter_names(robot)),) == (13 * robot.dof,)
    for shape in ((), (3,), (2, 3)):
        q, qd, qdd = random_state(rng, robot, shape)
        Y = regressor(robot, q, qd, qdd)
        assert Y.shape == shape + (robot.dof, 13 * robot.dof)
        tau = denavit.rnea(robot, q, qd, qdd)
        np.testing.assert_allclose(Y @ pi, tau, rtol=0, atol=1e-10 * max(1.0, np.abs(tau).max()))
    # without friction / motor inertia: the columns and parameters drop together
    q, qd, qdd = random_state(rng, robot, (4,))
    Y = regressor(robot, q, qd, qdd, friction=False, motor_inertia=False)
    pi = inertial_parameters(robot, friction=False, motor_inertia=False)
    no_motor = robot.replace(links=tuple(
        l if l.inertia is None else dataclasses.replace(l, inertia=LinkInertia(mass=l.inertia.mass, com=l.inertia.com,
                                                                 inertia=l.inertia.inertia))
        for l in robot.links))
    tau = denavit.rnea(no_motor, q, qd, qdd, friction=False)
    np.testing.assert_allclose(Y @ pi, tau, rtol=0, atol=1e-10 * max(1.0, np.abs(tau).max()))


def test_regressor_batch_rows_equal_single_calls_and_threads_split_bitwise():
    robot = random_arm(3)
    rng = np.random.default_rng(7)
    q, qd, qdd = random_state(rng, robot, (600,))
    Y1 = regressor(robot, q, qd, qdd, threads=1)
    Y2 = regressor(robot, q, qd, qdd, threads=2)
    assert np.array_equal(Y1, Y2)
    for b in (0, 299, 599):
        np.testing.assert_allclose(Y1[b], regressor(robot, q[b], qd[b], qdd[b]), rtol=0, atol=1e-12)


@pytest.mark.parametrize("seed", SEEDS)
def test_regressor_against_pinocchio(seed):
    pin = pytest.importorskip("pinocchio")
    from denavit.peers import to_pinocchio

    robot = random_arm(seed)
    n = robot.dof
    model, data, _ = to_pinocchio(robot)
    q, qd, qdd = random_state(np.random.default_rng(seed), robot)
    Yp = pin.computeJointTorqueRegressor(model, data, q, qd, qdd)  # (n, 10 n): joint frames, m, mc, I about origin
    Y = regressor(robot, q, qd, qdd)
    assert np.abs(Y[:, :10 * n] - Yp).max() <= 1e-9 * max(1.0, np.abs(Yp).max())
    pp = np.concatenate([model.inertias[k + 1].toDynamicParameters() for k in range(n)])
    np.testing.assert_allclose(inertial_parameters(robot)[:10 * n], pp, rtol=0, atol=1e-12)


@pytest.mark.parametrize("seed", SEEDS)
def test_energy_regressors_against_mass_matrix_and_com_heights(seed):
    robot = random_arm(seed)
    rng = np.random.default_rng(seed + 50)
    pi = inertial_parameters(robot)
    for shape in ((), (2, 3)):
        q, qd, _ = random_state(rng, robot, shape)
        K = kinetic_energy(robot, q, qd)  # ½ q̇ᵀ M q̇, M by the CRBA
        np.testing.assert_allclose(kinetic_energy_regressor(robot, q, qd) @ pi, K, rtol=1e-11, atol=1e-11)
        U = potential_energy(robot, q)  # −Σ m gᵀ c over the pieces' COMs
        np.testing.assert_allclose(potential_energy_regressor(robot, q) @ pi, U, rtol=1e-11, atol=1e-11)


@pytest.mark.parametrize("seed", SEEDS)
def test_base_parameters_reproduce_rnea_and_have_the_svd_rank(seed):
    robot = random_arm(seed)
    base = base_parameters(robot)
    rng = np.random.default_rng(seed + 200)  # states the base parameters were not found from
    q, qd, qdd = random_state(rng, robot, (40,))
    tau = denavit.rnea(robot, q, qd, qdd)
    Yb = base_regressor(robot, q, qd, qdd, base)
    assert Yb.shape == (40, robot.dof, base.rank)
    np.testing.assert_allclose(Yb @ base.values, tau, rtol=0, atol=1e-10 * max(1.0, np.abs(tau).max()))
    Y = regressor(robot, q, qd, qdd)
    W = Y.reshape(-1, Y.shape[-1])
    np.testing.assert_allclose(Yb.reshape(-1, base.rank) @ base.combination, W, rtol=0, atol=1e-9 * np.abs(W).max())
    norms = np.linalg.norm(W, axis=0)
    reach = norms > 1e-8 * norms.max()  # columns of roundoff size (an axis' 1e-17 components) count as zero
    s = np.linalg.svd(W[:, reach] / norms[reach], compute_uv=False)
    assert base.rank == int(np.sum(s > 1e-8 * s[0]))
    zero = [base.names.index(name) for name in base.unidentifiable]
    assert not reach[zero].any()
    assert base.rank + len(base.unidentifiable) <= len(base.names)


def test_planar_2r_base_parameters_by_hand():
    """A planar 2R arm with gravity in its plane: only ZZ1R, MX1R, MY1R, ZZ2, MX2, MY2 reach τ
    (axes parallel, so XX, XY, XZ, YZ, MZ of both links and link 1's mass have no effect; M2 joins MX1)."""
    m = LinkInertia(mass=1.0, com=(-0.5, 0.0, 0.0), inertia=(0.01, 0.1, 0.1, 0.0, 0.0, 0.0))
    robot = DHRobot(name="p2r", links=(DHLink(a=1.0, inertia=m), DHLink(a=0.8, inertia=m)), gravity=(0, -9.81, 0))
    base = base_parameters(robot, friction=False, motor_inertia=False)
    assert base.rank == 6
    kept = {base.names[i] for i in base.independent}
    assert kept == {"MX1", "MY1", "ZZ1", "MX2", "MY2", "ZZ2"}
    rule = dict(line.split(" = ") for line in base.rules)
    assert rule["MX1R"] == "MX1 + M2"  # standard DH: frame 1 turned by q1 sits at joint 1, frame 2's origin at a1 x1
    assert rule["ZZ1R"] == "ZZ1 + M2"  # a1² M2 with a1 = 1


def test_bad_input_is_one_clear_error():
    robot = random_arm(1)
    n = robot.dof
    with pytest.raises(ShapeError):
        regressor(robot, np.zeros(n + 1), np.zeros(n), np.zeros(n))
    with pytest.raises(ValueError, match="samples"):
        base_parameters(robot, samples=1)
    with pytest.raises(ValueError, match="tol"):
        base_parameters(robot, tol=2.0)


# --- symbolic grouping rules against the numeric base parameters ------------------------------------------


@pytest.mark.parametrize("case", ["puma560", "stanford", "scara", "planar2r", 0, 5, 8])
def test_symbolic_rules_span_the_numeric_base_parameters(case):
    from denavit.symbolic import base_parameters_sym, compare_base_parameters

    robot = denavit.load_robot(case) if isinstance(case, str) else random_arm(case)
    sym = base_parameters_sym(robot)
    base = base_parameters(robot)
    assert len(sym.kept) == base.rank
    assert compare_base_parameters(robot, sym, base) == (True, True)


def test_symbolic_rules_of_the_puma_are_khalils():
    """Khalil & Dombre 2002, §14.4 (Stäubli RX-90 / PUMA structure, modified DH there; the same grouping in the
    joint frames here): ZZR1 collects YY2, YY3 and the masses beyond joint 2 at their distances from axis 1."""
    from denavit.symbolic import base_parameters_sym

    sym = base_parameters_sym(denavit.load_robot("puma560"))
    rules = {name: str(e) for name, e in sym.rules}
    assert rules["XX6R"] == "XX6 - YY6"
    assert rules["ZZ5R"] == "YY6 + ZZ5"
    assert rules["MX2R"] == "M3*a2 + M4*a2 + M5*a2 + M6*a2 + MX2"
    assert rules["ZZ1R"].startswith("IA1 + M3*a2**2") and "YY2 + YY3 + ZZ1" in rules["ZZ1R"]
    assert {"XX1", "XY1", "XZ1", "YZ1", "MX1", "MY1"} == set(sym.no_effect)  # axis 1 along gravity


# --- command line -------------------------------------------------------------------------------------------


def test_cli_regressor_prints_counts_rules_values_and_y(capsys):
    import json

    from denavit.cli import main

    assert main(["regressor", "planar2r", "--json", "-q", "0.3, 0.5", "--qd", "1, 2", "--qdd", "0, 1"]) == 0
    data = json.loads(capsys.readouterr().out)
    robot = denavit.load_robot("planar2r")
    assert data["n_standard"] == 26 and data["n_base"] == len(data["values"]) == 11
    Y = np.array(data["Y"])
    np.testing.assert_allclose(Y @ inertial_parameters(robot), denavit.rnea(robot, [0.3, 0.5], [1, 2], [0, 1]),
                               atol=1e-9)
    assert main(["regressor", "puma560", "--symbolic"]) == 0
    out = capsys.readouterr().out
    assert "52 base parameters" in out and "XX6R = XX6 - YY6" in out and "the same span and values" in out


@pytest.mark.parametrize("argv", [["regressor", "puma560", "-q", "1, 2"], ["regressor", "puma560", "--tol", "5"],
                                  ["regressor", "puma560", "--qd", "1,2,3,4,5,6"],
                                  ["regressor", "puma560", "-q", "0,0,0,0,0,0", "--qdd", "1,x,3,4,5,6"]])
def test_cli_regressor_bad_input_is_one_line_exit_2(argv, capsys):
    from denavit.cli import main

    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith("denavit regressor: error:")


# --- compiled kernel ----------------------------------------------------------------------------------------


def test_compiled_regressor_equals_plain_single_batched_and_threaded():
    robot = random_arm(5)  # modified DH, a prismatic joint, fixed rows with inertia, odd gravity
    compiled = denavit.compile(robot)
    rng = np.random.default_rng(11)
    q, qd, qdd = random_state(rng, robot)
    Y = compiled.regressor(q, qd, qdd)
    assert Y.shape == (robot.dof, 13 * robot.dof)
    np.testing.assert_allclose(Y, regressor(robot, q, qd, qdd), rtol=0, atol=1e-11)
    Q, QD, QDD = random_state(rng, robot, (3, 4))
    YB = compiled.regressor(Q, QD, QDD, threads=2)
    np.testing.assert_allclose(YB, regressor(robot, Q, QD, QDD), rtol=0, atol=1e-11)
    tau = denavit.rnea(robot, Q, QD, QDD)
    np.testing.assert_allclose(YB @ inertial_parameters(robot), tau, rtol=0, atol=1e-10 * np.abs(tau).max())
