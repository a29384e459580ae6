"""Command line: jacobian, velocity, statics, singularities — run in-process through main([...])."""

import json

import numpy as np
import pytest
from conftest import REDUCED, robots
from hypothesis import given, settings
from hypothesis import strategies as st

from denavit import forward_kinematics, load_robot
from denavit import numeric as N
from denavit.cli import main

Q_PUMA = "0, pi/4, -pi/2, 0.3, pi/3, -0.2"
Q_PUMA_VALUES = np.array([0, np.pi / 4, -np.pi / 2, 0.3, np.pi / 3, -0.2])


def run_json(capsys, *argv):
    code = main([*argv, "--json"])
    out, err = capsys.readouterr()
    assert code == 0, err
    return json.loads(out)


def run_error(capsys, *argv):
    code = main(list(argv))
    out, err = capsys.readouterr()
    assert code == 2, (out, err)
    assert err.count("\n") == 1 and "Traceback" not in err
    return err


@pytest.mark.parametrize("method", ["geometric", "differentiation", "propagation"])
@pytest.mark.parametrize("frame", ["base", "tool"])
def test_jacobian_numeric_json_matches_finite_differences(capsys, method, frame):
    data = run_json(capsys, "jacobian", "puma560", "-q", Q_PUMA, "--frame", frame, "--method", method)
    assert data["frame"] == frame and data["rows"] == ["vx", "vy", "vz", "wx", "wy", "wz"]
    assert "end-effector origin" in data["reference_point"]
    robot, h = load_robot("puma560"), 1e-6
    T0 = forward_kinematics(robot, Q_PUMA_VALUES)
    R = T0[:3, :3]
    for k in range(6):
        e = np.eye(6)[k] * h
        dT = (forward_kinematics(robot, Q_PUMA_VALUES + e) - forward_kinematics(robot, Q_PUMA_VALUES - e)) / (2 * h)
        W = dT[:3, :3] @ R.T
        col = np.concatenate([dT[:3, 3], [W[2, 1], W[0, 2], W[1, 0]]])
        if frame == "tool":
            col = np.concatenate([R.T @ col[:3], R.T @ col[3:]])
        np.testing.assert_allclose(np.array(data["J"])[:, k], col, atol=1e-6)


def test_jacobian_symbolic_without_q(capsys):
    data = run_json(capsys, "jacobian", "report004-1-planar2r")
    assert data["J_symbolic"][5] == ["1", "1"]
    assert "L2*sin(q1 + q2)" in data["J_symbolic"][0][1]
    assert main(["jacobian", "report004-1-planar2r", "--shorthand"]) == 0
    out = capsys.readouterr().out
    assert "S₁₂" in out and "reference point" in out
    assert main(["jacobian", "report004-1-planar2r", "--method", "propagation", "--steps", "--latex"]) == 0
    out = capsys.readouterr().out
    assert "omega_2" in out and "\\sin" in out


def test_jacobian_degrees_input(capsys):
    a = run_json(capsys, "jacobian", "puma560", "-q", "0, 45, -90, 0, 60, 0", "--deg")
    b = run_json(capsys, "jacobian", "puma560", "-q", "0, pi/4, -pi/2, 0, pi/3, 0")
    np.testing.assert_allclose(a["J"], b["J"], atol=1e-12)
    np.testing.assert_allclose(a["q"], [0, 45, -90, 0, 60, 0])


def test_symbolic_analytic_jacobian_option(capsys):
    data = run_json(capsys, "jacobian", "report004-6-wrist3r", "--analytic", "rpy")
    assert data["representation"] == "rpy" and len(data["Ja_symbolic"]) == 6
    assert "yaw" in "".join(sum(data["Ja_symbolic"], []))


def test_analytic_jacobian_option(capsys):
    data = run_json(capsys, "jacobian", "puma560", "-q", Q_PUMA, "--analytic", "zyz")
    Ja, _ = N.analytic_jacobian(load_robot("puma560"), Q_PUMA_VALUES, "zyz")
    np.testing.assert_allclose(data["Ja"], Ja)
    assert data["representation"] == "zyz"


def test_velocity_twist_and_degrees(capsys):
    data = run_json(capsys, "velocity", "report004-1-planar2r", "-q", "30, 60", "--qd", "10, 20", "--deg", "--steps")
    # by hand: L1 = 0.5, L2 = 0.4; v = J q̇ with q̇ in rad/s, ω_z = q̇1 + q̇2 = 30 deg/s
    q, qd = np.radians([30, 60]), np.radians([10, 20])
    vx = -(0.5 * np.sin(q[0]) + 0.4 * np.sin(q.sum())) * qd[0] - 0.4 * np.sin(q.sum()) * qd[1]
    vy = (0.5 * np.cos(q[0]) + 0.4 * np.cos(q.sum())) * qd[0] + 0.4 * np.cos(q.sum()) * qd[1]
    np.testing.assert_allclose(data["twist"], [vx, vy, 0, 0, 0, 30], atol=1e-12)
    assert data["steps"][-1]["frame"] == "e"
    tool = run_json(capsys, "velocity", "report004-1-planar2r", "-q", "30, 60", "--qd", "10, 20", "--deg",
                    "--frame", "tool")
    assert np.isclose(np.linalg.norm(tool["v"]), np.hypot(vx, vy))


@pytest.mark.parametrize("method", ["jacobian", "propagation"])
def test_statics_tau(capsys, method):
    data = run_json(capsys, "statics", "puma560", "-q", Q_PUMA, "--wrench", "1, -2, 3, 0.1, 0.2, -0.3",
                    "--method", method, "--frame", "tool")
    J = N.geometric_jacobian(load_robot("puma560"), Q_PUMA_VALUES, "tool")
    np.testing.assert_allclose(data["tau"], J.T @ [1, -2, 3, 0.1, 0.2, -0.3], atol=1e-10)
    force_only = run_json(capsys, "statics", "report004-1-planar2r", "-q", "0, pi/2", "--wrench", "1, 0, 0")
    np.testing.assert_allclose(force_only["tau"], [-0.4, -0.4], atol=1e-12)  # moment of f about each axis, by hand
    assert force_only["units"] == ["N m", "N m"]


@pytest.mark.slow
def test_singularities_json(capsys):
    data = run_json(capsys, "singularities", "report004-1-planar2r", "--rows", "vx,vy", "--deg")
    (cond,) = data["conditions"]
    assert cond["equation"] == "sin(q2) = 0" and cond["kind"] == "elbow"
    np.testing.assert_allclose(sorted(v for s in cond["solutions"] for v in s["values"]), [0, 180], atol=1e-9)
    data = run_json(capsys, "singularities", "report000-6r")
    assert data["everywhere"] and data["generic_rank"] == 5
    data = run_json(capsys, "singularities", "puma560", "-q", "0, 0.5, -1, 0, 0, 0")
    assert data["measures"]["singular"] is True and data["measures"]["rank"] == 5  # q5 = 0: wrist singular
    assert {c["kind"] for c in data["conditions"]} == {"wrist", "elbow", "shoulder"}


def test_singularities_markdown(capsys):
    assert main(["singularities", "report004-3-articulated-rrr", "--rows", "vx,vy,vz", "--markdown"]) == 0
    out = capsys.readouterr().out
    assert out.startswith("## ") and "$$" in out


@pytest.mark.parametrize("argv, what", [
    (["singularities", "puma560", "--rows", "vx,vq"], "--rows"),
    (["statics", "puma560", "-q", Q_PUMA, "--wrench", "1,2,3,4"], "--wrench"),
    (["statics", "puma560", "-q", Q_PUMA, "--wrench", "1,2,foo"], "--wrench"),
    (["velocity", "puma560", "-q", Q_PUMA, "--qd", "1,2"], "qd"),
    (["jacobian", "puma560", "-q", "0,0,0"], "q"),
    (["jacobian", "puma560", "-q", "0,0,0,0,0,0", "--frame", "side"], "--frame"),
    (["jacobian", "puma560", "--analytic", "ypr"], "invalid choice"),
    (["jacobian", "puma560", "--steps"], "--steps"),
    (["jacobian", "no-such-robot"], "no-such-robot"),
])
def test_bad_input_is_one_line_and_exit_2(capsys, argv, what):
    err = run_error(capsys, *argv)
    assert what in err


def test_singularities_of_a_non_square_jacobian_without_common_factor_are_not_called_absent(capsys):
    """A 3-joint arm with all six rows: no common factor of the 3x3 minors does not mean "never singular"."""
    code = main(["singularities", "report004-3-articulated-rrr", "--json"])
    data = json.loads(capsys.readouterr().out)
    assert code == 0
    if not data["conditions"] and not data["everywhere"]:
        assert data["conditions_complete"] is False
    main(["singularities", "report004-1-planar2r", "--rows", "vx,vy", "--json"])
    data = json.loads(capsys.readouterr().out)
    assert data["conditions"] and data["conditions_complete"] is True


def _evaluate(texts, robot, q, qd=None, wrench=None):
    """Formulas printed by the CLI (our own output, read back here with sympy) at numbers."""
    import sympy as sp

    from denavit import symbolic as S

    js = S.joint_symbols(robot.dof)
    subs = {**dict(zip(js.q, q)), **{S.parameter_symbols(robot)[k]: v for k, v in robot.parameters}}
    if qd is not None:
        subs.update(zip(js.qd, qd))
    if wrench is not None:
        subs.update(zip(S.wrench_symbols(), wrench))
    names = {str(s): s for s in subs}
    return np.array([float(sp.sympify(t, locals=names).subs(subs)) for t in texts])


@pytest.mark.parametrize("name", ["report004-1-planar2r", "planar3r", "scara", "stanford"])
@pytest.mark.parametrize("frame", ["base", "tool"])
def test_velocity_symbolic_formulas_equal_the_numeric_twist_and_propagation(capsys, name, frame):
    robot = load_robot(name)
    data = run_json(capsys, "velocity", name, "--symbolic", "--steps", "--frame", frame)
    rng = np.random.default_rng(7)
    for _ in range(3):
        q, qd = rng.uniform(-2, 2, robot.dof), rng.uniform(-2, 2, robot.dof)
        twist = N.end_effector_twist(robot, q, qd, frame)
        np.testing.assert_allclose(_evaluate(data["v_symbolic"], robot, q, qd), twist[:3], atol=1e-9)
        np.testing.assert_allclose(_evaluate(data["omega_symbolic"], robot, q, qd), twist[3:], atol=1e-9)
        prop = N.velocity_propagation(robot, q, qd)  # the numeric route, frame by frame
        for step in data["steps"]:
            k = list(prop.labels).index(step["frame"])
            np.testing.assert_allclose(_evaluate(step["omega"], robot, q, qd), prop.omega[k], atol=1e-9)
            np.testing.assert_allclose(_evaluate(step["v"], robot, q, qd), prop.v[k], atol=1e-9)


@pytest.mark.parametrize("name", ["report004-1-planar2r", "planar3r", "stanford"])
@pytest.mark.parametrize("method, frame", [("jacobian", "base"), ("jacobian", "tool"), ("propagation", "tool")])
def test_statics_symbolic_tau_equals_the_numeric_torques(capsys, name, method, frame):
    robot = load_robot(name)
    argv = ["statics", name, "--symbolic", "--method", method, "--frame", frame]
    data = run_json(capsys, *argv + (["--steps"] if method == "propagation" else []))
    rng = np.random.default_rng(8)
    for _ in range(3):
        q, W = rng.uniform(-2, 2, robot.dof), rng.normal(size=6)
        tau = N.joint_torques(robot, q, W, frame)  # τ = Jᵀ F, numerically
        np.testing.assert_allclose(_evaluate(data["tau_symbolic"], robot, q, wrench=W), tau, atol=1e-9)
        if method == "propagation":
            prop = N.force_propagation(robot, q, W, frame)
            for step in data["steps"]:
                k = list(prop.labels).index(step["frame"])
                np.testing.assert_allclose(_evaluate(step["f"], robot, q, wrench=W), prop.f[k], atol=1e-9)
                np.testing.assert_allclose(_evaluate(step["n"], robot, q, wrench=W), prop.n[k], atol=1e-9)


def test_symbolic_velocity_and_statics_defaults_and_refusals(capsys):
    data = run_json(capsys, "statics", "planar2r", "--method", "propagation")  # no -q: formulas, tool axes
    assert data["frame"] == "tool" and len(data["tau_symbolic"]) == 2
    assert "propagation" in run_error(capsys, "statics", "planar2r", "--method", "propagation", "--frame", "base")
    assert "--qd" in run_error(capsys, "velocity", "planar2r", "-q", "0, 1")
    assert "--wrench" in run_error(capsys, "statics", "planar2r", "-q", "0, 1")
    assert "--steps" in run_error(capsys, "statics", "planar2r", "--symbolic", "--steps")


# --- jacobian --frame i: the Jacobian in the axes of DH frame {i} --------------------------------------------------


def _fd_J0(robot, q, h=1e-6):
    """J0 by central differences of FK (world axes, end-effector origin): no Jacobian code involved."""
    from denavit import forward_kinematics

    R = forward_kinematics(robot, q)[:3, :3]
    cols = []
    for k in range(robot.dof):
        e = np.eye(robot.dof)[k] * h
        dT = (forward_kinematics(robot, q + e) - forward_kinematics(robot, q - e)) / (2 * h)
        W = dT[:3, :3] @ R.T
        cols.append(np.concatenate([dT[:3, 3], [W[2, 1], W[0, 2], W[1, 0]]]))
    return np.array(cols).T


def _in_frame(robot, q, J0, i):
    """ⁱJ from J0: both blocks rotated by R_0_iᵀ, R_0_i the world orientation of DH frame i (FK's frames)."""
    from denavit import link_transforms

    R = link_transforms(robot, q)[i][:3, :3]
    return np.vstack([R.T @ J0[:3], R.T @ J0[3:]])


@settings(max_examples=6 if REDUCED else 25)
@given(robot=robots(), seed=st.integers(0, 2**32 - 1), method=st.sampled_from(["geometric", "differentiation",
                                                                                "propagation"]))
def test_jacobian_frame_i_is_finite_difference_J0_rotated_into_frame_i(tmp_path_factory, robot, seed, method):
    from _hostile import run_cli

    from denavit import dump_robot

    rng = np.random.default_rng(seed)
    folder = tmp_path_factory.mktemp("frame")
    (folder / "arm.json").write_text(dump_robot(robot, "json"))
    arm = load_robot(str(folder / "arm.json"))
    q = rng.uniform(-np.pi, np.pi, arm.dof)
    i = int(rng.integers(0, arm.n_rows + 1))
    o = run_cli(["jacobian", "arm.json", "-q", ", ".join(repr(float(x)) for x in q), "--frame", str(i), "--method",
                 method, "--json"], folder)
    assert o.code == 0, o.describe()
    data = json.loads(o.out)
    assert data["frame"] == i and data["method"] == method
    np.testing.assert_allclose(np.array(data["J"]), _in_frame(arm, q, _fd_J0(arm, q), i), atol=1e-6)
    np.testing.assert_allclose(N.geometric_jacobian(arm, q, frame=i), np.array(data["J"]), atol=1e-6)


def test_jacobian_frame_i_text_and_identities(capsys):
    """Frame 0 of an arm without a base is J0; its last frame without a tool is Je; the text names the frame."""
    robot = load_robot("puma560")
    assert np.allclose(robot.base_matrix, np.eye(4)) and np.allclose(robot.tool_matrix, np.eye(4))
    J = {f: np.array(run_json(capsys, "jacobian", "puma560", "-q", Q_PUMA, "--frame", f)["J"])
         for f in ("base", "tool", "0", str(robot.n_rows), "3")}
    np.testing.assert_allclose(J["0"], J["base"], atol=1e-12)
    np.testing.assert_allclose(J[str(robot.n_rows)], J["tool"], atol=1e-12)
    np.testing.assert_allclose(J["3"], _in_frame(robot, Q_PUMA_VALUES, _fd_J0(robot, Q_PUMA_VALUES), 3), atol=1e-6)
    assert main(["jacobian", "puma560", "-q", "0, 45, -90, 0, 60, 0", "--deg", "--frame", "3"]) == 0
    out = capsys.readouterr().out
    assert "axes of DH frame {3}" in out and "3J" in out
    rows = [line.split()[0] for line in out.splitlines()[-6:]]
    assert rows == ["vx", "vy", "vz", "wx", "wy", "wz"]
    deg = np.array(run_json(capsys, "jacobian", "puma560", "-q", "0, 45, -90, 0, 60, 0", "--deg", "--frame", "3")["J"])
    np.testing.assert_allclose(deg, _in_frame(robot, np.radians([0, 45, -90, 0, 60, 0]),
                                              _fd_J0(robot, np.radians([0, 45, -90, 0, 60, 0])), 3), atol=1e-6)


@pytest.mark.parametrize("name, frame, method", [("planar3r", 3, "geometric"), ("stanford", 4, "differentiation")])
def test_jacobian_frame_i_symbolic_equals_the_rotated_finite_differences(capsys, name, frame, method, rng):
    robot = load_robot(name)
    data = run_json(capsys, "jacobian", name, "--frame", str(frame), "--method", method)
    assert data["frame"] == frame
    for q in rng.uniform(-np.pi, np.pi, (2, robot.dof)):
        got = np.array([_evaluate(row, robot, q) for row in data["J_symbolic"]])
        np.testing.assert_allclose(got, _in_frame(robot, q, _fd_J0(robot, q), frame), atol=1e-6)


def test_jacobian_frame_3_of_the_planar_3r_is_craigs_form(capsys):
    """Planar 3R, end-effector point L3 along x3 (Craig 2005, sec. 5.8, with the reference point moved to the tip):
    ³J's linear rows are [L1 s23 + L2 s3, L2 s3, 0; L1 c23 + L2 c3 + L3, L2 c3 + L3, L3] — short, not a rotated J0."""
    data = run_json(capsys, "jacobian", "planar3r", "--frame", "3")
    assert data["J_symbolic"][0] == ["L1*sin(q2 + q3) + L2*sin(q3)", "L2*sin(q3)", "0"]
    assert data["J_symbolic"][1] == ["L1*cos(q2 + q3) + L2*cos(q3) + L3", "L2*cos(q3) + L3", "L3"]


@pytest.mark.parametrize("value, mentions", [
    ("99", ["--frame", "99"]), ("7", ["--frame", "7", "0 ... 6"]), ("-1", ["--frame", "-1"]), ("x", ["--frame"]),
    ("", ["--frame"]), ("1e1", ["--frame"]), ("3.0", ["--frame"]), ("٣", ["--frame"]), ("9" * 5000, ["--frame"]),
    ("base,tool", ["--frame"]), ("Base", ["--frame"]), ("0x3", ["--frame"]), ("+3", ["--frame"]),
])
@pytest.mark.parametrize("symbolic", [False, True])
def test_jacobian_bad_frame_values_are_refused_in_one_line(tmp_path, value, mentions, symbolic):
    from _hostile import assert_refused, run_cli

    argv = ["jacobian", "puma560", "--frame", value] + ([] if symbolic else ["-q", Q_PUMA])
    assert_refused(run_cli(argv, tmp_path), mentions=mentions)
    assert_refused(run_cli(["jacobian", "puma560", f"--frame={value}", "-q", Q_PUMA, "--json"], tmp_path),
                   mentions=["--frame"])


def test_geometric_jacobian_frame_index_batches_and_refuses_bad_values(rng):
    robot = load_robot("stanford")
    Q = rng.uniform(-np.pi, np.pi, (3, 2, robot.dof))
    for i in (0, 2, np.int64(robot.n_rows)):
        batch = N.geometric_jacobian(robot, Q, frame=i)
        assert batch.shape == (3, 2, 6, robot.dof)
        for idx in np.ndindex(3, 2):
            np.testing.assert_allclose(batch[idx], _in_frame(robot, Q[idx], _fd_J0(robot, Q[idx]), int(i)), atol=1e-6)
    for bad in (-1, robot.n_rows + 1, True, "3", 2.0, "side"):
        with pytest.raises(ValueError, match="base, tool"):
            N.geometric_jacobian(robot, Q[0, 0], frame=bad)


# --- velocity and statics --frame i: the twist and the wrench in the axes of DH frame {i} --------------------------


def _numbers(x) -> str:
    return ", ".join(repr(float(v)) for v in x)


@settings(max_examples=6 if REDUCED else 25)
@given(robot=robots(), seed=st.integers(0, 2**32 - 1))
def test_velocity_and_statics_frame_i_are_rotated_finite_differences_and_virtual_work(tmp_path_factory, robot, seed):
    """velocity --frame i: ⁱJ q̇ with ⁱJ = J0 (differences of FK) rotated by R_0_i; statics --frame i, both methods:
    the wrench F_w given in frame i's axes (ⁱF = diag(R_0_iᵀ, R_0_iᵀ) F_w) balances τ = J0ᵀ F_w (virtual work)."""
    from _hostile import run_cli

    from denavit import dump_robot, link_transforms

    rng = np.random.default_rng(seed)
    folder = tmp_path_factory.mktemp("frame_i")
    (folder / "arm.json").write_text(dump_robot(robot, "json"))
    arm = load_robot(str(folder / "arm.json"))
    q, qd = rng.uniform(-np.pi, np.pi, arm.dof), rng.uniform(-2, 2, arm.dof)
    i = int(rng.integers(0, arm.n_rows + 1))
    J0 = _fd_J0(arm, q)
    o = run_cli(["velocity", "arm.json", "-q", _numbers(q), "--qd", _numbers(qd), "--frame", str(i), "--json"], folder)
    assert o.code == 0, o.describe()
    data = json.loads(o.out)
    assert data["frame"] == i
    np.testing.assert_allclose(data["twist"], _in_frame(arm, q, J0, i) @ qd, atol=1e-6 * (1 + np.abs(qd).sum()))
    R = link_transforms(arm, q)[i][:3, :3]
    F_w = rng.normal(size=6)
    F_i = np.concatenate([R.T @ F_w[:3], R.T @ F_w[3:]])
    for method in ("jacobian", "propagation"):
        o = run_cli(["statics", "arm.json", "-q", _numbers(q), "--wrench", _numbers(F_i), "--frame", str(i),
                     "--method", method, "--json"], folder)
        assert o.code == 0, o.describe()
        data = json.loads(o.out)
        assert data["frame"] == i and data["method"] == method
        np.testing.assert_allclose(data["tau"], J0.T @ F_w, atol=1e-6 * (1 + np.abs(F_w).sum()))


@pytest.mark.parametrize("name, frame", [("planar3r", 2), ("stanford", 3)])
def test_velocity_and_statics_frame_i_symbolic_equal_the_rotated_finite_differences(capsys, name, frame, rng):
    robot = load_robot(name)
    vel = run_json(capsys, "velocity", name, "--frame", str(frame))
    sta = run_json(capsys, "statics", name, "--frame", str(frame))
    assert vel["frame"] == sta["frame"] == frame
    for q in rng.uniform(-np.pi, np.pi, (2, robot.dof)):
        qd, F_i = rng.normal(size=robot.dof), rng.normal(size=6)
        J_i = _in_frame(robot, q, _fd_J0(robot, q), frame)
        twist = np.concatenate([_evaluate(vel["v_symbolic"], robot, q, qd),
                                _evaluate(vel["omega_symbolic"], robot, q, qd)])
        np.testing.assert_allclose(twist, J_i @ qd, atol=1e-6)
        np.testing.assert_allclose(_evaluate(sta["tau_symbolic"], robot, q, wrench=F_i), J_i.T @ F_i, atol=1e-6)


def test_velocity_and_statics_frame_i_text_and_end_frames(capsys):
    """Frame 0 of an arm without a base is the base; its last frame without a tool is the tool; the text says so."""
    robot = load_robot("puma560")
    N_ = str(robot.n_rows)
    vel = {f: run_json(capsys, "velocity", "puma560", "-q", Q_PUMA, "--qd", "1, -2, 3, 0.5, -1, 2", "--frame", f)
           for f in ("base", "0", "tool", N_)}
    np.testing.assert_allclose(vel["0"]["twist"], vel["base"]["twist"], atol=1e-12)
    np.testing.assert_allclose(vel[N_]["twist"], vel["tool"]["twist"], atol=1e-12)
    sta = {f: run_json(capsys, "statics", "puma560", "-q", Q_PUMA, "--wrench", "1, 2, -3, 0.4, 0.5, -0.6", "--frame", f)
           for f in ("base", "0", "tool", N_)}
    np.testing.assert_allclose(sta["0"]["tau"], sta["base"]["tau"], atol=1e-12)
    np.testing.assert_allclose(sta[N_]["tau"], sta["tool"]["tau"], atol=1e-12)
    assert main(["statics", "puma560", "-q", Q_PUMA, "--wrench", "0, 0, -10", "--frame", "3"]) == 0
    assert "in the axes of DH frame {3}" in capsys.readouterr().out
    assert main(["velocity", "puma560", "-q", Q_PUMA, "--qd", "1, 0, 0, 0, 0, 0", "--frame", "3"]) == 0
    assert "axes of DH frame {3}" in capsys.readouterr().out
    assert "tool" in run_error(capsys, "statics", "planar2r", "--method", "propagation", "--frame", "1")


@pytest.mark.parametrize("value, mentions", [
    ("99", ["--frame", "99"]), ("7", ["--frame", "7", "0 ... 6"]), ("-1", ["--frame", "-1"]), ("x", ["--frame"]),
    ("1e1", ["--frame"]), ("+3", ["--frame"]), ("9" * 5000, ["--frame"]),
])
@pytest.mark.parametrize("command", ["velocity", "statics"])
@pytest.mark.parametrize("symbolic", [False, True])
def test_velocity_and_statics_bad_frame_values_are_refused_in_one_line(tmp_path, value, mentions, command, symbolic):
    from _hostile import assert_refused, run_cli

    values = ["--qd", "1, 2, 3, 4, 5, 6"] if command == "velocity" else ["--wrench", "1, 2, 3"]
    argv = [command, "puma560", "--frame", value] + ([] if symbolic else ["-q", Q_PUMA, *values])
    assert_refused(run_cli(argv, tmp_path), mentions=mentions)
