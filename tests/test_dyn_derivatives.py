"""Dynamics derivatives (rnea_derivatives, forward_dynamics_derivatives, gravity_derivatives) against outside truth.

Truth: Pinocchio's computeRNEADerivatives / computeABADerivatives / computeGeneralizedGravityDerivatives (an
independent implementation of Carpentier & Mansard's recursive derivative algorithms) on the same arm built by
denavit.peers.to_pinocchio, and fourth-order central differences of the public denavit.rnea /
denavit.forward_dynamics.  Random arms: both conventions, prismatic joints, fixed rows (some carrying mass),
base and tool, friction, motor inertia, gravity in an odd direction.  The error measure is
max|A − B| / max(max|B|, 1e-3) over a matrix (relative to its largest entry; a matrix whose entries are all
below 1e-3, e.g. zero in truth like ∂τ/∂q̇ of a one-joint arm, is held to an absolute 1e-12), required ≤ 1e-9.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

import denavit
from denavit.peers import to_pinocchio
from denavit import LinkInertia, ShapeError
from denavit.errors import ModelError

from hypothesis import example, given, settings
from hypothesis import strategies as st

from _random_robots import random_inertia, random_robot

REL = 1e-9


def rel_err(a, b) -> float:
    a, b = np.asarray(a), np.asarray(b)
    return float(np.max(np.abs(a - b)) / max(np.max(np.abs(b)), 1e-3))


def dynamic_arm(seed: int, n_rows: int | None = None):
    """A random arm of tests/_random_robots with inertia on every row (fixed rows too), odd gravity."""
    rng = np.random.default_rng(seed)
    robot = random_robot(rng, n_rows=n_rows or int(rng.integers(2, 7)))
    links = tuple(dataclasses.replace(link, inertia=random_inertia(rng)) for link in robot.links)
    return robot.replace(links=links, gravity=tuple(rng.normal(size=3) * 5.0))


def state(robot, seed: int, shape=()):
    rng = np.random.default_rng(seed + 1000)
    n = robot.dof
    return (rng.uniform(-np.pi, np.pi, shape + (n,)), rng.uniform(-2, 2, shape + (n,)), rng.uniform(-3, 3, shape + (n,)))


def central(f, x, h=1e-3):
    """∂f/∂x by the fourth-order stencil (f(x−2h) − 8 f(x−h) + 8 f(x+h) − f(x+2h)) / 12h, columns per x_j."""
    cols = []
    for e in np.eye(x.shape[-1]) * h:
        cols.append((f(x - 2 * e) - 8 * f(x - e) + 8 * f(x + e) - f(x + 2 * e)) / (12 * h))
    return np.stack(cols, axis=-1)


SEEDS = [3, 11, 29, 47]


# --- against Pinocchio ---------------------------------------------------------------------------------------
@pytest.mark.peer
@pytest.mark.parametrize("seed", SEEDS)
def test_rnea_derivatives_match_pinocchio(seed):
    pin = pytest.importorskip("pinocchio")
    robot = dynamic_arm(seed)
    model, data, _ = to_pinocchio(robot)
    q, qd, qdd = state(robot, seed)
    dq, dv, _ = pin.computeRNEADerivatives(model, data, q, qd, qdd)
    A, B = denavit.rnea_derivatives(robot, q, qd, qdd, friction=False)
    assert rel_err(A, dq) <= REL and rel_err(B, dv) <= REL
    fv = [link.inertia.viscous for link in robot.joints]
    A, B = denavit.rnea_derivatives(robot, q, qd, qdd)  # friction: + diag(viscous) on ∂τ/∂q̇
    assert rel_err(A, dq) <= REL and rel_err(B, dv + np.diag(fv)) <= REL


@pytest.mark.peer
@pytest.mark.parametrize("seed", SEEDS)
def test_forward_dynamics_derivatives_match_pinocchio(seed):
    pin = pytest.importorskip("pinocchio")
    robot = dynamic_arm(seed)
    model, data, _ = to_pinocchio(robot)
    q, qd, _ = state(robot, seed)
    tau = np.random.default_rng(seed).uniform(-5, 5, robot.dof)
    X, Y, Z = denavit.forward_dynamics_derivatives(robot, q, qd, tau, friction=False)
    ddq, ddv, Minv = pin.computeABADerivatives(model, data, q, qd, tau)
    assert rel_err(X, ddq) <= REL and rel_err(Y, ddv) <= REL and rel_err(Z, Minv) <= REL


@pytest.mark.peer
@pytest.mark.parametrize("seed", SEEDS[:2])
def test_gravity_derivatives_match_pinocchio_and_are_symmetric(seed):
    pin = pytest.importorskip("pinocchio")
    robot = dynamic_arm(seed)
    model, data, _ = to_pinocchio(robot)
    q = state(robot, seed)[0]
    G = denavit.gravity_derivatives(robot, q)
    assert rel_err(G, pin.computeGeneralizedGravityDerivatives(model, data, q)) <= REL
    assert rel_err(G, G.T) <= REL  # ∂²V/∂q²


@pytest.mark.peer
def test_batched_matches_pinocchio_per_configuration():
    pin = pytest.importorskip("pinocchio")
    robot = dynamic_arm(5)
    model, data, _ = to_pinocchio(robot)
    q, qd, qdd = state(robot, 5, (3, 2))
    A, B = denavit.rnea_derivatives(robot, q, qd, qdd, friction=False)
    X, Y, Z = denavit.forward_dynamics_derivatives(robot, q, qd, qdd, friction=False)  # qdd as torques
    G = denavit.gravity_derivatives(robot, q)
    assert A.shape == B.shape == X.shape == Z.shape == G.shape == (3, 2, robot.dof, robot.dof)
    for i in np.ndindex(3, 2):
        dq, dv, _ = pin.computeRNEADerivatives(model, data, q[i], qd[i], qdd[i])
        assert rel_err(A[i], dq) <= REL and rel_err(B[i], dv) <= REL
        ddq, ddv, Minv = pin.computeABADerivatives(model, data, q[i], qd[i], qdd[i])
        assert rel_err(X[i], ddq) <= REL and rel_err(Y[i], ddv) <= REL and rel_err(Z[i], Minv) <= REL
        assert rel_err(G[i], pin.computeGeneralizedGravityDerivatives(model, data, q[i])) <= REL


# --- against central differences of the public functions (friction, motor inertia) ------------------------------
@pytest.mark.parametrize("seed", SEEDS[:3])
def test_rnea_derivatives_match_central_differences(seed):
    robot = dynamic_arm(seed)
    q, qd, qdd = state(robot, seed)
    A, B = denavit.rnea_derivatives(robot, q, qd, qdd)
    assert rel_err(A, central(lambda x: denavit.rnea(robot, x, qd, qdd), q)) <= REL
    assert rel_err(B, central(lambda x: denavit.rnea(robot, q, x, qdd), qd)) <= REL


@pytest.mark.parametrize("seed", SEEDS[:3])
def test_forward_dynamics_derivatives_match_central_differences(seed):
    robot = dynamic_arm(seed)
    q, qd, _ = state(robot, seed)
    tau = np.random.default_rng(seed).uniform(-5, 5, robot.dof)
    fd = denavit.forward_dynamics
    X, Y, Z = denavit.forward_dynamics_derivatives(robot, q, qd, tau)
    assert rel_err(X, central(lambda x: fd(robot, x, qd, tau), q)) <= REL
    assert rel_err(Y, central(lambda x: fd(robot, q, x, tau), qd)) <= REL
    assert rel_err(Z, central(lambda x: fd(robot, q, qd, x), tau)) <= REL
    assert rel_err(Z @ denavit.mass_matrix(robot, q), np.eye(robot.dof)) <= REL


def stencil_rounding(values, h=1e-3) -> float:
    """What rounding alone can put into :func:`central`'s result: each f(x ± k h) good to ~16 ε |f| (a few dozen
    operations), the stencil's weights (1 + 8 + 8 + 1) / 12h."""
    return 16 * np.finfo(float).eps * float(np.max(np.abs(values))) * 18 / (12 * h)


@settings(max_examples=6)
@given(seed=st.integers(0, 2**32 - 1))
@example(seed=19626)  # ∂τ/∂q̇ of scale < 1e-3 where τ ~ 5: the differences' own rounding (1.2e-12) was > REL·1e-3
def test_property_random_arms_match_central_differences(seed):
    """Any arm of tests/_random_robots (1-7 rows, both conventions, prismatic, fixed rows, base/tool), q̇ away from
    0 so the differences do not straddle Coulomb friction's jump.  Agreement to REL of the derivatives' scale
    (at least 1e-3), plus what rounding alone puts into the differences (:func:`stencil_rounding` of τ)."""
    robot = dynamic_arm(seed)
    q, qd, qdd = state(robot, seed % 1000)
    qd = np.where(qd < 0, -1.0, 1.0) * (0.1 + np.abs(qd))
    A, B = denavit.rnea_derivatives(robot, q, qd, qdd)
    floor = stencil_rounding(denavit.rnea(robot, q, qd, qdd))
    for got, want in ((A, central(lambda x: denavit.rnea(robot, x, qd, qdd), q)),
                      (B, central(lambda x: denavit.rnea(robot, q, x, qdd), qd))):
        assert np.max(np.abs(got - want)) <= REL * max(np.max(np.abs(want)), 1e-3) + floor


def test_dual_numbers_follow_the_rules_of_differentiation():
    from denavit.numeric import Dual, dual_max, dual_min, dual_sign

    x, y = Dual(0.7, np.array([1.0, 0.0])), Dual(-1.3, np.array([0.0, 1.0]))
    f = (x * y - 2.0) / (y + np.cos(x)) + 3.0 / x - np.sin(x) * 4.0
    # the same function's gradient written out by hand
    u, v, den = 0.7, -1.3, -1.3 + np.cos(0.7)
    dfdx = (v * den - (u * v - 2.0) * (-np.sin(u))) / den**2 - 3.0 / u**2 - 4.0 * np.cos(u)
    dfdy = (u * den - (u * v - 2.0)) / den**2
    np.testing.assert_allclose(f.d, [dfdx, dfdy], rtol=1e-14)
    assert dual_min(x, y).d.tolist() == [0.0, 1.0] and dual_max(x, y).d.tolist() == [1.0, 0.0]
    assert dual_min(x, 5.0).v == 0.7 and dual_sign(y) == -1.0
    batch = Dual(np.array([0.5, 2.0]), np.array([[1.0, 1.0], [0.0, 0.0]]))  # (B,) value, (m, B) tangents
    g = np.array([1.0, 3.0]) * batch * batch  # ndarray on the left: numpy hands the operation to the dual
    assert isinstance(g, Dual) and g.d.tolist() == [[1.0, 12.0], [0.0, 0.0]]
    with pytest.raises(TypeError, match="no truth value"):
        bool(x)


def test_gravity_keyword_and_friction_off():
    robot = dynamic_arm(8)
    q, qd, qdd = state(robot, 8)
    g = np.array([1.5, -2.0, 0.7])
    A, B = denavit.rnea_derivatives(robot, q, qd, qdd, gravity=g, friction=False)
    assert rel_err(A, central(lambda x: denavit.rnea(robot, x, qd, qdd, gravity=g, friction=False), q)) <= REL
    assert rel_err(B, central(lambda x: denavit.rnea(robot, q, x, qdd, gravity=g, friction=False), qd)) <= REL
    G = denavit.gravity_derivatives(robot, q, gravity=g)
    assert rel_err(G, central(lambda x: denavit.gravity_torques(robot, x, gravity=g), q)) <= REL


def test_bad_input_is_a_clear_error():
    robot = denavit.load_robot("puma560")
    with pytest.raises(ShapeError, match="qd: expected shape"):
        denavit.rnea_derivatives(robot, np.zeros(6), np.zeros(5), np.zeros(6))
    with pytest.raises(ShapeError, match="non-finite"):
        denavit.gravity_derivatives(robot, [0, 0, np.nan, 0, 0, 0])
    with pytest.raises(ShapeError, match="do not broadcast"):
        denavit.forward_dynamics_derivatives(robot, np.zeros((2, 6)), np.zeros((3, 6)), np.zeros(6))
    with pytest.raises(ValueError, match="threads must be"):
        denavit.rnea_derivatives(robot, np.zeros(6), np.zeros(6), np.zeros(6), threads=0)
    with pytest.raises(ModelError, match="gravity must be finite"):
        denavit.forward_dynamics_derivatives(robot, np.zeros(6), np.zeros(6), np.zeros(6), gravity=[0, 0, np.inf])


def test_a_batch_split_over_threads_gives_the_rows_of_the_unsplit_call():
    from denavit._threads import MIN_ROWS

    robot = dynamic_arm(29)
    q = state(robot, 29, (2 * MIN_ROWS + 40,))[0]
    one = denavit.gravity_derivatives(robot, q, threads=1)
    two = denavit.gravity_derivatives(robot, q, threads=2)
    assert np.array_equal(one, two)
    assert rel_err(two[-1], denavit.gravity_derivatives(robot, q[-1])) <= REL


def test_singular_mass_matrix_is_a_model_error():
    from denavit import DHLink, DHRobot

    point = LinkInertia(mass=1.0)  # a point mass on the axis of a one-joint arm: M = 0
    robot = DHRobot(name="pointmass", links=(DHLink(a=0.0, alpha=0.0, d=0.0, inertia=point),))
    with pytest.raises(ModelError, match="singular"):
        denavit.forward_dynamics_derivatives(robot, [0.1], [0.0], [1.0])


# --- the command line -------------------------------------------------------------------------------------------
def test_cli_dynamics_derivatives_json_and_text(capsys):
    from denavit.cli import main
    import json

    q, qd, qdd = np.array([0.1, 0.2, -0.3, 0.4, 0.5, 0.6]), np.array([1.0, -0.5, 0.3, 0.2, -1, 1]), np.array([0, 1.0, 0, 0, 0, 0])
    # no q̇ at 0: the differences would straddle Coulomb friction's jump
    argv = ["dynamics", "puma560", "-q", "0.1, 0.2, -0.3, 0.4, 0.5, 0.6", "--qd", "1,-0.5,0.3,0.2,-1,1", "--qdd", "0,1,0,0,0,0"]
    assert main(argv + ["--derivatives", "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    robot = denavit.load_robot("puma560")
    assert rel_err(data["dtau_dq"], central(lambda x: denavit.rnea(robot, x, qd, qdd), q)) <= REL
    assert rel_err(data["dtau_dqd"], central(lambda x: denavit.rnea(robot, q, x, qdd), qd)) <= REL
    assert main(argv + ["--derivatives"]) == 0
    text = capsys.readouterr().out
    assert "dtau/dq [" in text and "dtau/dqd [" in text
    assert main(argv) == 0
    assert "dtau/dq" not in capsys.readouterr().out


@pytest.mark.parametrize("argv, message", [
    (["dynamics", "puma560", "--derivatives"], "--derivatives: give the joint values with -q"),
    (["dynamics", "puma560", "-q", "1, 2", "--derivatives"], "q: expected 6 values"),
    (["dynamics", "puma560", "-q", "0,0,0,0,0,0", "--qd", "nan,0,0,0,0,0", "--derivatives"], "qd"),
])
def test_cli_dynamics_derivatives_bad_input_is_one_line_exit_2(capsys, argv, message):
    from denavit.cli import main

    assert main(argv) == 2
    err = capsys.readouterr().err
    assert message in err and len(err.strip().splitlines()) == 1


# --- compiled (the same code traced on the tape) ------------------------------------------------------------------
@pytest.fixture(scope="module")
def compiled_arm():
    """A random arm (prismatic joint, fixed rows, base/tool, friction, motor inertia, odd gravity), numpy backend."""
    robot = dynamic_arm(29)
    return robot, denavit.compile(robot, backend="numpy")


def _compiled_matches_plain(robot, fast, friction=True):
    q, qd, qdd = state(robot, 4)
    for shape in ((), (3, 2)):
        q, qd, qdd = state(robot, 4, shape)
        pairs = list(zip(fast.rnea_derivatives(q, qd, qdd), denavit.rnea_derivatives(robot, q, qd, qdd, friction=friction)))
        pairs += zip(fast.forward_dynamics_derivatives(q, qd, qdd),
                     denavit.forward_dynamics_derivatives(robot, q, qd, qdd, friction=friction))
        pairs.append((fast.gravity_derivatives(q), denavit.gravity_derivatives(robot, q)))
        for a, b in pairs:
            assert a.shape == shape + (robot.dof, robot.dof)
            assert rel_err(a, b) <= REL


def test_compiled_matches_plain_single_and_batched(compiled_arm):
    robot, fast = compiled_arm
    _compiled_matches_plain(robot, fast)
    assert {"rnea_derivatives", "forward_dynamics_derivatives", "gravity_derivatives"} <= set(fast.kernels)


def test_compiled_without_friction_and_bad_input(compiled_arm):
    robot, _ = compiled_arm
    _compiled_matches_plain(robot, denavit.compile(robot, backend="numpy", friction=False), friction=False)
    fast = compiled_arm[1]
    with pytest.raises(ShapeError, match="qd: expected shape"):
        fast.rnea_derivatives(np.zeros(robot.dof), np.zeros(robot.dof + 1), np.zeros(robot.dof))
    with pytest.raises(ValueError, match="threads must be"):
        fast.gravity_derivatives(np.zeros((2, robot.dof)), threads=0)


def test_compiled_singular_mass_matrix_is_a_model_error():
    from denavit import DHLink, DHRobot

    robot = DHRobot(name="pointmass", links=(DHLink(a=0.0, alpha=0.0, d=0.0, inertia=LinkInertia(mass=1.0)),))
    fast = denavit.compile(robot, backend="numpy")
    with pytest.raises(ModelError, match="singular"):
        fast.forward_dynamics_derivatives(np.array([0.1]), np.array([0.0]), np.array([1.0]))


@pytest.mark.peer
@pytest.mark.slow
def test_compiled_numba_matches_pinocchio():
    pin = pytest.importorskip("pinocchio")
    pytest.importorskip("numba")
    robot = denavit.load_robot("puma560")
    fast = denavit.compile(robot, backend="numba", friction=False)
    model, data, _ = to_pinocchio(robot)
    q, qd, qdd = state(robot, 6)
    A, B = fast.rnea_derivatives(q, qd, qdd)
    dq, dv, _ = pin.computeRNEADerivatives(model, data, q, qd, qdd)
    assert rel_err(A, dq) <= REL and rel_err(B, dv) <= REL
    for a, b in zip(fast.forward_dynamics_derivatives(q, qd, qdd), pin.computeABADerivatives(model, data, q, qd, qdd)):
        assert rel_err(a, b) <= REL
    Q = state(robot, 7, (4,))
    A, B = fast.rnea_derivatives(*Q)
    for i in range(4):
        dq, dv, _ = pin.computeRNEADerivatives(model, data, Q[0][i], Q[1][i], Q[2][i])
        assert rel_err(A[i], dq) <= REL and rel_err(B[i], dv) <= REL


def test_exported_python_has_the_derivative_kernels(tmp_path):
    """`denavit export --lang python --kernels ...`: the numpy-only module computes what the plain functions do."""
    import importlib.util

    from denavit.codegen import export_sources

    robot = dynamic_arm(5)
    names = ["rnea_derivatives", "forward_dynamics_derivatives", "gravity_derivatives"]
    (tmp_path / "arm.py").write_text(export_sources(robot, "python", "arm", kernels=names)["arm.py"], encoding="utf-8")
    spec = importlib.util.spec_from_file_location("arm", tmp_path / "arm.py")
    arm = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(arm)
    q, qd, qdd = state(robot, 5, (3,))
    D = arm.rnea_derivatives(q, qd, qdd)  # (3, 2, n, n)
    A, B = denavit.rnea_derivatives(robot, q, qd, qdd)
    assert rel_err(D[:, 0], A) <= REL and rel_err(D[:, 1], B) <= REL
    assert rel_err(arm.gravity_derivatives(q), denavit.gravity_derivatives(robot, q)) <= REL
    n = robot.dof
    r = arm.forward_dynamics_derivatives(q, qd, qdd)  # (3, 3 n² + 1): the blocks, then the regularity flag
    assert (r[:, -1] > 0).all()
    X = r[:, :-1].reshape(3, 3, n, n)
    for k, ref in enumerate(denavit.forward_dynamics_derivatives(robot, q, qd, qdd)):
        assert rel_err(X[:, k], ref) <= REL


@pytest.mark.parametrize(("name", "budget"), [("puma560", 4_850), ("panda", 12_000)])
def test_traced_rnea_derivatives_stay_within_their_operation_budget(name, budget):
    """An operation count, not a time: the traced ∂RNEA kernel (what every backend runs) of the Puma had 5,152
    operations before the body wrench's inertia terms moved into body axes, 4,809 after (Panda 12,719 → 11,891).
    A change of the RNEA or of the tracer that adds work fails here; every operation still counts (no dead code)."""
    from denavit.codegen import registered_kernels

    spec = registered_kernels()["rnea_derivatives"].trace(denavit.load_robot(name), True)
    ops = [spec.tape.ops[i][0] for i in spec.tape.program(spec.outputs)]
    count = sum(op != "input" for op in ops)
    assert 0.8 * budget < count <= budget  # far below: the kernel lost work it should do (or the count broke)
