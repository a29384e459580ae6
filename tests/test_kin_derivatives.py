"""Kinematic derivatives (J̇, the acceleration bias, ∂J/∂q, analytic Jacobians) against independent routes.

Truth: Pinocchio (getFrameJacobianTimeVariation, getFrameKinematicHessian, getFrameClassicalAcceleration) on the
same arm built by :func:`denavit.peers.to_pinocchio`; roboticstoolbox's hessian0 / jacob0_dot; five-point central
differences of :func:`denavit.geometric_jacobian` (truncation O(h⁴) ≈ 1e-12 at h = 1e-3); identities.
"""

from __future__ import annotations

import numpy as np
import pytest

import denavit
from denavit import ShapeError
from _random_robots import random_q, random_robot

RTOL = 1e-9
SEEDS = range(12)


def _rel(a, b) -> float:
    """Max error relative to the larger entry of the truth (at least 1)."""
    a, b = np.asarray(a), np.asarray(b)
    return float(np.abs(a - b).max() / max(1.0, np.abs(b).max())) if b.size else 0.0


def _arm(seed: int, convention: str):
    rng = np.random.default_rng(seed)
    robot = random_robot(rng, convention)
    return robot, random_q(rng, robot), rng.normal(size=robot.dof), rng


def _five_point(f, x, h=1e-3):
    return (-f(x + 2 * h) + 8 * f(x + h) - 8 * f(x - h) + f(x - 2 * h)) / (12 * h)


# --- central differences and identities ---------------------------------------------------------------------

@pytest.mark.parametrize("frame", ["base", "tool"])
@pytest.mark.parametrize("convention", ["standard", "modified"])
@pytest.mark.parametrize("seed", SEEDS)
def test_hessian_and_jdot_match_central_differences_of_the_jacobian(seed, convention, frame):
    robot, q, qd, _ = _arm(seed, convention)
    n = robot.dof
    H = denavit.kinematic_hessian(robot, q, frame)
    for k in range(n):
        e = np.eye(n)[k]
        fd = _five_point(lambda s: denavit.geometric_jacobian(robot, q + s * e, frame), 0.0)
        assert _rel(H[:, :, k], fd) < RTOL, k
    fd = _five_point(lambda s: denavit.geometric_jacobian(robot, q + s * qd, frame), 0.0)
    assert _rel(denavit.jacobian_dot(robot, q, qd, frame), fd) < RTOL


@pytest.mark.parametrize("seed", SEEDS)
def test_identities_sum_symmetry_and_structure(seed):
    robot, q, qd, _ = _arm(seed, None)
    H0, He = denavit.kinematic_hessian(robot, q, "base"), denavit.kinematic_hessian(robot, q, "tool")
    for frame, H in (("base", H0), ("tool", He)):  # J̇ = Σ_k H[:, :, k] q̇_k
        assert _rel(denavit.jacobian_dot(robot, q, qd, frame), H @ qd) < 1e-13
    np.testing.assert_array_equal(H0[:3], np.swapaxes(H0[:3], -1, -2))  # ∂²p/∂q_j∂q_k
    lower = np.tril(np.ones((robot.dof, robot.dof), dtype=bool))  # k ≤ j
    assert not He[:, lower].any()  # a column of Je depends on the joints after it only
    R = denavit.forward_kinematics(robot, q)[:3, :3]
    a0, ae = denavit.acceleration_bias(robot, q, qd, "base"), denavit.acceleration_bias(robot, q, qd, "tool")
    assert _rel(a0, denavit.jacobian_dot(robot, q, qd) @ qd) < 1e-13
    assert _rel(ae, np.concatenate([R.T @ a0[:3], R.T @ a0[3:]])) < 1e-13


def test_batch_equals_loop_and_inputs_broadcast():
    robot, _, _, rng = _arm(7, "modified")
    Q, QD = random_q(rng, robot, (3, 2)), rng.normal(size=(2, robot.dof))
    for frame in ("base", "tool"):
        Jd = denavit.jacobian_dot(robot, Q, QD, frame)
        H = denavit.kinematic_hessian(robot, Q, frame)
        a = denavit.acceleration_bias(robot, Q, QD, frame)
        assert Jd.shape == (3, 2, 6, robot.dof) and H.shape == (3, 2, 6, robot.dof, robot.dof) and a.shape == (3, 2, 6)
        for i in range(3):
            for j in range(2):
                np.testing.assert_allclose(Jd[i, j], denavit.jacobian_dot(robot, Q[i, j], QD[j], frame), rtol=0, atol=1e-14)
                np.testing.assert_allclose(H[i, j], denavit.kinematic_hessian(robot, Q[i, j], frame), rtol=0, atol=1e-14)
                np.testing.assert_allclose(a[i, j], denavit.acceleration_bias(robot, Q[i, j], QD[j], frame), rtol=0,
                                           atol=1e-14)


def test_bad_input_is_refused_with_a_clear_message():
    robot = denavit.load_robot("puma560")
    q = np.zeros(6)
    with pytest.raises(ValueError, match="choose base or tool"):
        denavit.jacobian_dot(robot, q, q, frame="world")
    with pytest.raises(ValueError, match="choose base or tool"):
        denavit.kinematic_hessian(robot, q, frame=2)
    with pytest.raises(ShapeError, match="qd: expected shape"):
        denavit.jacobian_dot(robot, q, np.zeros(5))
    with pytest.raises(ShapeError, match="do not broadcast"):
        denavit.acceleration_bias(robot, np.zeros((3, 6)), np.zeros((2, 6)))
    with pytest.raises(ShapeError, match="non-finite"):
        denavit.kinematic_hessian(robot, [0, 0, np.nan, 0, 0, 0])


# --- Pinocchio ----------------------------------------------------------------------------------------------

def _pin_hessian(pin, model, fid, q, rf):
    """getFrameKinematicHessian as H[:, j, k] = ∂J[:, j]/∂q_k.

    Pinocchio 4.1's binding returns the (6, n, n) tensor with its column-major memory read row-major; the
    reading that agrees with central differences of Pinocchio's own frame Jacobian is taken (so a fixed binding
    keeps working), and that agreement is asserted: the layout is chosen by Pinocchio alone, never by denavit.
    """
    data = model.createData()
    pin.computeJointKinematicHessians(model, data, q)
    pin.updateFramePlacements(model, data)
    raw = np.asarray(pin.getFrameKinematicHessian(model, data, fid, rf))
    n = model.nv
    readings = [raw.reshape(6, n, n), raw.ravel(order="C").reshape((6, n, n), order="F")]

    def J(x):
        d = model.createData()
        pin.computeJointJacobians(model, d, x)
        pin.updateFramePlacements(model, d)
        return np.asarray(pin.getFrameJacobian(model, d, fid, rf)).reshape(6, n)

    fd = np.stack([_five_point(lambda s: J(q + s * np.eye(n)[k]), 0.0) for k in range(n)], axis=-1)
    best = min(readings, key=lambda H: _rel(H, fd))
    assert _rel(best, fd) < 1e-8
    return best


@pytest.mark.parametrize("convention", ["standard", "modified"])
@pytest.mark.parametrize("seed", SEEDS)
def test_against_pinocchio(seed, convention):
    pin = pytest.importorskip("pinocchio")
    from denavit.peers import to_pinocchio

    robot, q, qd, _ = _arm(100 + seed, convention)
    n = robot.dof
    model, data, fid = to_pinocchio(robot)
    pin.computeJointJacobiansTimeVariation(model, data, q, qd)
    pin.updateFramePlacements(model, data)
    frames = (("base", pin.LOCAL_WORLD_ALIGNED), ("tool", pin.LOCAL))
    for frame, rf in frames:
        Jd = np.asarray(pin.getFrameJacobianTimeVariation(model, data, fid, rf)).reshape(6, n)
        assert _rel(denavit.jacobian_dot(robot, q, qd, frame), Jd) < RTOL, frame
        assert _rel(denavit.kinematic_hessian(robot, q, frame), _pin_hessian(pin, model, fid, q, rf)) < RTOL, frame
    pin.forwardKinematics(model, data, q, qd, np.zeros(n))
    pin.updateFramePlacements(model, data)
    for frame, rf in frames:
        a = pin.getFrameClassicalAcceleration(model, data, fid, rf).vector
        assert _rel(denavit.acceleration_bias(robot, q, qd, frame), a) < RTOL, frame


@pytest.mark.slow  # importing roboticstoolbox takes seconds
def test_against_roboticstoolbox_hessian0_and_jacob0_dot():
    pytest.importorskip("roboticstoolbox")
    from denavit.peers import expand_q, to_roboticstoolbox

    for seed in range(4):
        robot, q, qd, _ = _arm(200 + seed, None)
        peer = to_roboticstoolbox(robot)
        moving = list(robot.joint_rows)
        H = np.asarray(peer.hessian0(expand_q(robot, q)))[np.ix_(moving, range(6), moving)]  # [k, :, j]
        assert _rel(denavit.kinematic_hessian(robot, q), H.transpose(1, 2, 0)) < RTOL
        Jd = np.asarray(peer.jacob0_dot(expand_q(robot, q), expand_q(robot, qd)))[:, moving]
        assert _rel(denavit.jacobian_dot(robot, q, qd), Jd) < RTOL


def test_threads_split_a_large_batch_with_the_same_result():
    robot, _, _, rng = _arm(3, "standard")
    Q, QD = random_q(rng, robot, (9000,)), rng.normal(size=(9000, robot.dof))  # ≥ 2 × MIN_ROWS: two blocks
    one = denavit.jacobian_dot(robot, Q, QD, threads=1)
    np.testing.assert_array_equal(denavit.jacobian_dot(robot, Q, QD, threads=2), one)
    np.testing.assert_array_equal(one[4567], denavit.jacobian_dot(robot, Q[4567], QD[4567]))
    with pytest.raises(ValueError, match="threads"):
        denavit.kinematic_hessian(robot, Q[0], threads=0)


# --- command line ---------------------------------------------------------------------------------------------

def _cli_json(capsys, *argv):
    import json

    from denavit.cli import main

    code = main([*argv, "--json"])
    out, err = capsys.readouterr()
    assert code == 0, err
    return json.loads(out)


@pytest.mark.parametrize("frame", ["base", "tool"])
def test_cli_jacobian_dot_and_hessian_json(capsys, frame):
    q, qd = np.array([0.1, 0.7, -0.4, 0.3, 1.1, -0.2]), np.array([0.5, -1.0, 2.0, 0.3, -0.7, 1.5])
    data = _cli_json(capsys, "jacobian", "puma560", "-q", ",".join(str(float(x)) for x in q), "--dot", "--qd",
                     ",".join(str(float(x)) for x in qd), "--hessian", "--frame", frame)
    robot = denavit.load_robot("puma560")
    H = denavit.kinematic_hessian(robot, q, frame)
    assert data["frame"] == frame and np.array(data["H"]).shape == (6, 6, 6)
    np.testing.assert_allclose(data["H"], H, rtol=0, atol=1e-15)
    np.testing.assert_allclose(data["Jdot"], H @ qd, rtol=0, atol=1e-12)
    np.testing.assert_allclose(data["Jdot_qd"], (H @ qd) @ qd, rtol=0, atol=1e-12)


def test_cli_rates_in_degrees_and_text_labels(capsys):
    from denavit.cli import main

    rad = _cli_json(capsys, "jacobian", "planar2r", "-q", "0.3, 0.5", "--dot", "--qd", "1, -2")
    deg = _cli_json(capsys, "jacobian", "planar2r", "-q", f"{float(np.degrees(0.3))}, {float(np.degrees(0.5))}",
                    "--dot", "--qd", f"{float(np.degrees(1.0))}, {float(np.degrees(-2.0))}", "--deg")
    np.testing.assert_allclose(deg["Jdot"], rad["Jdot"], rtol=1e-12, atol=1e-15)
    assert main(["jacobian", "planar2r", "-q", "0.3, 0.5", "--hessian", "--frame", "tool"]) == 0
    out = capsys.readouterr().out
    assert "dJ/dq1 =" in out and "dJ/dq2 =" in out and "tool axes" in out and "wz" in out


@pytest.mark.parametrize("argv, message", [
    (["-q", "0.3, 0.5", "--dot"], "--dot needs --qd"),
    (["--hessian"], "give -q"),
    (["-q", "0.3, 0.5", "--qd", "1, 2"], "--qd goes with --dot"),
    (["-q", "0.3, 0.5", "--hessian", "--frame", "1"], "choose base or tool"),
    (["-q", "0.3, 0.5", "--hessian", "--method", "propagation"], "does not go with --method"),
    (["-q", "0.3, 0.5", "--dot", "--qd", "1, 2, 3"], "expected 2 values"),
    (["-q", "0.3, 0.5", "--dot", "--qd", "1, 1e400"], "qd"),
])
def test_cli_bad_input_exits_2_with_one_line(capsys, argv, message):
    from denavit.cli import main

    code = main(["jacobian", "planar2r", *argv])
    out, err = capsys.readouterr()
    assert code == 2 and err.count("\n") == 1 and "Traceback" not in err and message in err, err


# --- analytic Jacobians --------------------------------------------------------------------------------------

@pytest.mark.parametrize("representation", ["rpy", "zyz", "quaternion", "exp"])
def test_analytic_jacobian_rates_match_differences_of_the_coordinates(representation):
    """d/dt of the extracted coordinates along q(t) = q + t q̇ (five-point differences) equals Ja[3:] q̇, and the
    position rows are J0's; configurations near a coordinate jump (the differences straddle it) are skipped."""
    from denavit.numeric import analytic_jacobian, geometric_jacobian

    checked = 0
    for seed in range(10):
        robot, q, qd, _ = _arm(300 + seed, None)
        Ja, phi = analytic_jacobian(robot, q, representation)
        steps = [analytic_jacobian(robot, q + s * qd, representation)[1] for s in (-2e-3, -1e-3, 1e-3, 2e-3)]
        if max(np.abs(x - phi).max() for x in steps) > 0.1:  # wrapped angle, sign flip, θ = π
            continue
        fd = (steps[0] - 8 * steps[1] + 8 * steps[2] - steps[3]) / 12e-3
        assert Ja.shape == (7 if representation == "quaternion" else 6, robot.dof)
        np.testing.assert_array_equal(Ja[:3], geometric_jacobian(robot, q)[:3])
        assert _rel(Ja[3:] @ qd, fd) < 1e-9
        checked += 1
    assert checked >= 7


def test_analytic_jacobian_new_coordinates_batch_and_edge_cases():
    from denavit.numeric import analytic_jacobian, exp_rate_matrix, quaternion_rate_matrix

    robot, _, _, rng = _arm(11, "standard")
    Q = random_q(rng, robot, (4, 3))
    for rep in ("quaternion", "exp"):
        Ja, phi = analytic_jacobian(robot, Q, rep)
        np.testing.assert_allclose(Ja[2, 1], analytic_jacobian(robot, Q[2, 1], rep)[0], rtol=0, atol=1e-14)
    quat = analytic_jacobian(robot, Q, "quaternion")[1]
    np.testing.assert_allclose(np.linalg.norm(quat, axis=-1), 1.0, atol=1e-15)
    assert (quat[..., 0] >= 0).all()
    # Gᵀ G = I/4 (G's columns are orthogonal and of length 1/2 for a unit quaternion)
    G = quaternion_rate_matrix(quat)
    np.testing.assert_allclose(np.swapaxes(G, -1, -2) @ G, np.broadcast_to(np.eye(3) / 4, G.shape[:-2] + (3, 3)),
                               atol=1e-15)
    # the inverse of the left Jacobian J_l = I + (1 − cos θ)/θ² K + (θ − sin θ)/θ³ K² (its definition; series
    # 1/2 − θ²/24, 1/6 − θ²/120 for small θ), on both sides of the series switch and up to θ = π
    u = np.array([0.6, 0.0, 0.8])
    for theta in (0.0, 0.99e-4, 1.01e-4, 0.3, 2.0, np.pi - 1e-9, np.pi):
        r = u * theta
        K = np.array([[0, -r[2], r[1]], [r[2], 0, -r[0]], [-r[1], r[0], 0]])
        a, b = ((0.5 - theta**2 / 24, 1 / 6 - theta**2 / 120) if theta < 1e-3 else
                ((1 - np.cos(theta)) / theta**2, (theta - np.sin(theta)) / theta**3))
        Jl = np.eye(3) + a * K + b * K @ K
        np.testing.assert_allclose(exp_rate_matrix(r) @ Jl, np.eye(3), rtol=0, atol=1e-14)
    with pytest.raises(ValueError, match="quaternion, exp"):
        analytic_jacobian(robot, Q, "xyz")


# --- compiled ----------------------------------------------------------------------------------------------------

@pytest.fixture(scope="module")
def compiled_arms():
    """Two arms compiled once: the Puma 560 (numba when installed: the machine-code entry points of the single
    call) and a random modified-DH arm with a prismatic joint, a fixed row, base and tool (numpy backend: the same
    generated code, without a second numba compile's CPU time)."""
    rng = np.random.default_rng(17)
    arm = random_robot(rng, "modified", n_rows=5)
    while not {"prismatic", "fixed"} <= {link.joint.value for link in arm.links} or np.allclose(arm.tool_matrix, np.eye(4)):
        arm = random_robot(rng, "modified", n_rows=5)
    puma = denavit.load_robot("puma560")
    return [(puma, denavit.compile(puma)), (arm, denavit.compile(arm, backend="numpy"))]


def test_compiled_kernels_equal_the_plain_functions(compiled_arms):
    rng = np.random.default_rng(5)
    for robot, fast in compiled_arms:
        q, qd = random_q(rng, robot), rng.normal(size=robot.dof)
        Q, QD = random_q(rng, robot, (4, 3)), rng.normal(size=(3, robot.dof))
        for frame in ("base", "tool"):
            for method, args, batch in (("jacobian_dot", (q, qd), (Q, QD)), ("acceleration_bias", (q, qd), (Q, QD)),
                                        ("kinematic_hessian", (q,), (Q,))):
                plain = getattr(denavit, method)
                assert _rel(getattr(fast, method)(*args, frame=frame), plain(robot, *args, frame=frame)) < 1e-13
                got = getattr(fast, method)(*batch, frame=frame, threads=2)
                assert _rel(got, plain(robot, *batch, frame=frame)) < 1e-13
                assert got.shape == plain(robot, *batch, frame=frame).shape
        assert _rel(fast.jacobian_dot(list(q), qd.tolist()), denavit.jacobian_dot(robot, q, qd)) < 1e-13


def test_compiled_bad_input(compiled_arms):
    robot, fast = compiled_arms[0]
    with pytest.raises(ValueError, match="choose base or tool"):
        fast.jacobian_dot(np.zeros(6), np.zeros(6), frame="world")
    with pytest.raises(ShapeError, match="qd: expected shape"):
        fast.acceleration_bias(np.zeros(6), np.zeros(5))
    with pytest.raises(ValueError, match="threads"):
        fast.kinematic_hessian(np.zeros((2, 6)), threads=0)
    with pytest.raises(ValueError, match="threads"):
        fast.jacobian_dot(np.zeros(6), np.zeros(6), threads=-1)


def test_exported_python_and_c_carry_the_kernels(tmp_path):
    import importlib.util
    import shutil
    import subprocess

    from denavit.codegen import export_sources

    robot, q, qd, rng = _arm(23, "standard")
    names = ("jacobian_dot0", "acceleration_biase", "kinematic_hessiane")
    (file, text), = export_sources(robot, "python", prefix="kin_kernels", kernels=names).items()
    (tmp_path / file).write_text(text)
    spec = importlib.util.spec_from_file_location("kin_kernels", tmp_path / file)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    Q = random_q(rng, robot, (3,))
    assert _rel(mod.jacobian_dot0(q, qd), denavit.jacobian_dot(robot, q, qd)) < 1e-13
    assert _rel(mod.acceleration_biase(q, qd), denavit.acceleration_bias(robot, q, qd, "tool")) < 1e-13
    assert _rel(mod.kinematic_hessiane(Q), denavit.kinematic_hessian(robot, Q, "tool")) < 1e-13
    files = export_sources(robot, "c", prefix="arm", kernels=names)
    assert all(f"arm_{name}(" in files["arm.h"] for name in names)
    if shutil.which("cc"):
        for name, body in files.items():
            (tmp_path / name).write_text(body)
        subprocess.run(["cc", "-std=c99", "-c", str(tmp_path / "arm.c"), "-o", str(tmp_path / "arm.o")], check=True)


@pytest.mark.parametrize("representation, rows", [("quaternion", 7), ("exp", 6)])
def test_cli_analytic_quaternion_and_exp(capsys, representation, rows):
    from denavit.cli import main
    from denavit.numeric import analytic_jacobian

    q = "0.1, -0.6, -0.9, 0.2, 0.7, -0.3"
    data = _cli_json(capsys, "jacobian", "puma560", "-q", q, "--analytic", representation, "--deg")
    Ja, phi = analytic_jacobian(denavit.load_robot("puma560"), np.radians([0.1, -0.6, -0.9, 0.2, 0.7, -0.3]),
                                representation)
    assert np.array(data["Ja"]).shape == (rows, 6) and len(data["analytic_rows"]) == rows
    np.testing.assert_allclose(data["Ja"], Ja, rtol=0, atol=1e-14)
    np.testing.assert_allclose(data["angles"], phi, rtol=0, atol=1e-15)  # not converted to degrees
    assert main(["jacobian", "puma560", "--analytic", representation]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "is numeric: give -q" in err
