"""Units on the command line: degrees with --deg, radians without, metres for prismatic joints, whatever the form.

Regression tests for degrees/radians slips found by the everyday-use audit (session 6): values that say their
unit ("90deg", "pi/2") converted twice under --deg, prismatic joints' metres multiplied by 180/π on output,
degrees typed without --deg, JSON that did not say its angle unit.  In-process through ``denavit.cli.main``.
"""

import contextlib
import io

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

from conftest import REDUCED
from denavit.cli import main

from test_cli_audit import strict_json as _strict  # RFC 8259: no NaN / Infinity


def run(capsys, *argv):
    code = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return code, out, err


def run_captured(*argv):
    """``main(argv)`` with stdout and stderr captured here (for hypothesis tests, where capsys is not per example)."""
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        code = main([str(a) for a in argv])
    return code, out.getvalue(), err.getvalue()


# Degrees typed without --deg: the limit error says so, and a value beyond a full turn on a joint without limits
# draws one warning (the robot-file reader's rule for bare angles, DEGREE_HINT).
NO_LIMITS = """name: free-2r
convention: standard
joints:
  - {a: 1.0, alpha: 0, d: 0, theta: q}
  - {a: 0.5, alpha: 0, d: 0, theta: q}
"""


@settings(max_examples=15 if REDUCED else 40, deadline=None)
@given(st.floats(10, 170), st.floats(-170, -10))
def test_degrees_typed_without_deg_are_named_in_the_limit_error(q2_deg, q3_deg):
    from denavit import forward_kinematics, load_robot

    robot = load_robot("elbow-6r-deg")  # a file in degrees, limits within ±180°
    q_deg = np.array([0.0, q2_deg, q3_deg, 0.0, 0.0, 0.0])
    lim = robot.q_limits
    assert np.all((lim[:, 0] <= np.radians(q_deg)) & (np.radians(q_deg) <= lim[:, 1]))  # inside, in degrees
    assert not lim[1, 0] <= q_deg[1] <= lim[1, 1]  # joint 2 outside, read as radians
    text = ", ".join(repr(float(v)) for v in q_deg)
    code, out, err = run_captured("fk", "elbow-6r-deg", "-q", text)
    lines = err.strip().splitlines()
    assert code == 2 and out == "" and len(lines) == 1 and "add --deg" in lines[0] and "joint 2" in lines[0]
    code, out, err = run_captured("fk", "elbow-6r-deg", "-q", text, "--deg", "--json")
    assert code == 0 and err == ""
    np.testing.assert_allclose(_strict(out)["T"], forward_kinematics(robot, np.radians(q_deg)), atol=1e-12)


def test_a_full_turn_in_radians_draws_one_warning(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "free.yaml").write_text(NO_LIMITS)
    code, out, err = run_captured("fk", "free.yaml", "-q", "90, 45", "--json")
    lines = err.strip().splitlines()
    assert code == 0 and len(lines) == 1 and "warning" in lines[0] and "--deg" in lines[0] and "(and 1 more)" in lines[0]
    _strict(out)  # stdout stays pure JSON
    for argv in (["-q", "90, 45", "--deg"], ["-q", "6.28, -6.28"]):  # degrees said; or within a turn
        code, out, err = run_captured("fk", "free.yaml", *argv)
        assert code == 0 and err == "", err


@pytest.mark.parametrize("deg", [False, True])
def test_simulate_text_names_the_unit_of_its_q_columns(capsys, deg):
    # the summary line said "(11 samples, The solver successfully reached the end of the integration interval.)"
    # and not which unit the q columns were in
    q0 = np.array([0.3, -0.2])
    argv = ["simulate", "planar2r", "--q0", ", ".join(map(str, np.degrees(q0) if deg else q0)), "--duration", "0.1",
            *(["--deg"] if deg else [])]
    code, out, err = run(capsys, *argv)
    assert code == 0 and err == ""
    lines = out.splitlines()
    assert f"(q in {'deg' if deg else 'rad'})" in lines[0] and "solver" not in lines[0]
    first = [float(x) for x in lines[2].split()]  # t, q1, q2, energy at t = 0
    np.testing.assert_allclose(first[1:3], np.degrees(q0) if deg else q0, atol=1e-5)
    code, out, _ = run(capsys, *argv, "--json")
    assert _strict(out)["success"] is True


@pytest.mark.parametrize("name", ["stanford", "puma560", "elbow-6r-deg"])
def test_show_json_says_its_angle_unit_and_follows_deg(capsys, name):
    # show --json ignored --deg (radians, unlabelled) where fk --json --deg gives degrees and says so
    from denavit import load_robot

    robot = load_robot(name)
    code, out, _ = run(capsys, "show", name, "--json")
    rad = _strict(out)
    code2, out, _ = run(capsys, "show", name, "--json", "--deg")
    deg = _strict(out)
    assert code == code2 == 0 and rad["angle_unit"] == "rad" and deg["angle_unit"] == "deg"
    for link, r, d in zip(robot.links, rad["rows"], deg["rows"]):
        assert (r["alpha"], r["theta"], r["a"], r["d"]) == (link.alpha, link.theta, link.a, link.d)
        assert d["alpha"] == pytest.approx(np.degrees(link.alpha)) and d["theta"] == pytest.approx(np.degrees(link.theta))
        assert (d["a"], d["d"]) == (link.a, link.d)
        if link.q_limits is not None:
            scale = np.degrees(1.0) if link.joint.value == "revolute" else 1.0
            assert d["limits"] == pytest.approx([v * scale for v in link.q_limits]) and r["limits"] == list(link.q_limits)
    assert rad["poses"] == {k: list(q) for k, q in robot.poses}
    revolute = np.array([t.value == "revolute" for t in robot.joint_types])
    for k, q in robot.poses:
        assert deg["poses"][k] == pytest.approx(np.where(revolute, np.degrees(q), q).tolist())


@settings(max_examples=15 if REDUCED else 50, deadline=None)
@given(st.sampled_from(["scara", "stanford", "puma560", "cylindrical-rpp"]), st.data())
def test_deg_reads_each_value_in_its_own_unit(name, data):
    # with --deg, "90deg" and "pi/2" were converted twice (read as 1.57 degrees), and fk --json gave a prismatic
    # joint's metres multiplied by 180/pi
    from denavit import forward_kinematics, load_robot

    robot = load_robot(name)
    lim = np.clip(robot.q_limits, -3.0, 3.0)
    q = np.array([data.draw(st.floats(lo, hi)) for lo, hi in lim])
    parts = []
    for v, t in zip(q, robot.joint_types):
        if t.value != "revolute":
            parts.append(repr(float(v)))  # metres whatever --deg says
        else:
            form = data.draw(st.sampled_from(["plain", "deg", "pi"]))
            parts.append({"plain": repr(float(np.degrees(v))), "deg": f"{float(np.degrees(v))!r}deg",
                          "pi": f"{float(v / np.pi)!r}*pi"}[form])
    code, out, err = run_captured("fk", name, "-q", ", ".join(parts), "--deg", "--json")
    assert code == 0, err
    got = _strict(out)
    np.testing.assert_allclose(got["T"], forward_kinematics(robot, q), atol=1e-9)
    revolute = np.array([t.value == "revolute" for t in robot.joint_types])
    np.testing.assert_allclose(got["q"], np.where(revolute, np.degrees(q), q), rtol=1e-12, atol=1e-9)


def test_dynamics_deg_keeps_prismatic_joints_in_metres(capsys, tmp_path):
    # dynamics --deg showed a prismatic joint's 0.1 m as 5.73 (all of q, qd, qdd went through np.degrees)
    import pathlib

    from denavit import load_robot, rnea, save_robot
    from denavit.interop import import_urdf

    robot = import_urdf(pathlib.Path(__file__).resolve().parents[1] / "examples" / "urdf" / "small_arm.urdf").robot
    path = tmp_path / "arm.yaml"  # R R P R, with inertial data
    save_robot(robot, path)
    q, qd = np.array([0.2, -0.3, 0.1, 0.4]), np.array([0.5, 0.1, -0.05, 0.2])
    rev = np.array([t.value == "revolute" for t in load_robot(str(path)).joint_types])
    as_deg = lambda v: ", ".join(repr(float(x)) for x in np.where(rev, np.degrees(v), v))  # noqa: E731
    code, out, err = run(capsys, "dynamics", path, "-q", as_deg(q), "--qd", as_deg(qd), "--deg", "--json")
    assert code == 0, err
    got = _strict(out)
    np.testing.assert_allclose(got["q"], np.where(rev, np.degrees(q), q), rtol=1e-12)
    np.testing.assert_allclose(got["qd"], np.where(rev, np.degrees(qd), qd), rtol=1e-12)
    np.testing.assert_allclose(got["tau"], rnea(robot, q, qd, np.zeros(4)), rtol=1e-9, atol=1e-12)
    code, out, err = run(capsys, "simulate", path, "--q0", as_deg(q), "--duration", "0.02", "--deg", "--json")
    assert code == 0, err
    np.testing.assert_allclose(_strict(out)["q"][0], np.where(rev, np.degrees(q), q), rtol=1e-12)
