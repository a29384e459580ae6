"""The ik command: in-process calls of main(), exit codes, JSON keys, degrees, bad input."""

from __future__ import annotations

import json

import numpy as np
import pytest

from denavit import forward_kinematics, load_robot
from denavit.cli import main


def _run(capsys, *argv):
    code = main(list(argv))
    out = capsys.readouterr()
    return code, out.out, out.err


def test_ik_from_q_json_contains_generating_q(capsys):
    q = [0.1, 0.2, -0.3, 0.4, 0.5, 0.6]
    code, out, err = _run(capsys, "ik", "puma560", "--from-q", ",".join(map(str, q)), "--json")
    assert code == 0, err
    data = json.loads(out)
    for key in ("robot", "T", "solutions", "success", "residuals", "branches", "free", "method"):
        assert key in data
    assert data["success"] is True and data["method"] == "analytic"
    sols = np.array(data["solutions"])
    assert np.min(np.abs(sols - q).max(axis=1)) < 1e-9
    robot = load_robot("puma560")
    np.testing.assert_allclose(forward_kinematics(robot, sols), np.broadcast_to(data["T"], (len(sols), 4, 4)),
                               atol=1e-9)


def test_ik_pose_degrees_round_trip(capsys):
    robot = load_robot("ur5")
    q = np.array([0.3, -1.0, 1.2, -0.4, 0.8, 0.2])
    T = forward_kinematics(robot, q)
    from denavit.numeric import rpy_from_rotation

    rpy = np.degrees(rpy_from_rotation(T[:3, :3]))
    pose = ",".join(f"{v:.15g}" for v in list(T[:3, 3]) + list(rpy))
    code, out, err = _run(capsys, "ik", "ur5", "--pose=" + pose, "--deg", "--json")
    assert code == 0, err
    sols = np.radians(np.array(json.loads(out)["solutions"]))
    d = np.abs((sols - q + np.pi) % (2 * np.pi) - np.pi).max(axis=1)
    assert d.min() < 1e-7


def test_ik_T_numeric_method(capsys):
    robot = load_robot("stanford")
    T = forward_kinematics(robot, [0.2, -0.4, 0.6, 0.3, 0.5, -0.2])
    code, out, err = _run(capsys, "ik", "stanford", "--T=" + ",".join(f"{v:.17g}" for v in T.ravel()),
                          "--method", "numeric", "--json")
    assert code == 0, err
    data = json.loads(out)
    assert data["success"] is True and data["reason"] == ""
    np.testing.assert_allclose(forward_kinematics(robot, data["q"]), T, atol=1e-8)


def test_ik_numeric_all_finds_every_analytic_solution(capsys):
    code, out, _ = _run(capsys, "ik", "report004-3-articulated-rrr", "--from-q", "0.3,0.4,0.9", "--json")
    analytic = np.array(json.loads(out)["solutions"])
    code2, out2, _ = _run(capsys, "ik", "report004-3-articulated-rrr", "--from-q", "0.3,0.4,0.9",
                          "--method", "numeric", "--all", "--mask", "position", "--json")
    assert code == code2 == 0
    numeric = np.array(json.loads(out2)["solutions"])
    assert len(numeric) == len(analytic) == 4


def test_ik_auto_falls_back_to_numeric_for_panda(capsys):
    code, out, err = _run(capsys, "ik", "panda", "--from-q", "0.1,0.2,-0.3,-1.5,0.5,1.6,0.1", "--json")
    assert code == 0, err
    assert json.loads(out)["method"] == "numeric"


def test_ik_unreachable_exit_1(capsys):
    code, out, err = _run(capsys, "ik", "puma560", "--pose", "3,0,0,0,0,0", "--json")
    assert code == 1
    assert json.loads(out)["success"] is False
    assert err.strip().count("\n") == 0 and "no solution" in err


def test_ik_text_output_lists_branches(capsys):
    code, out, _ = _run(capsys, "ik", "puma560", "--from-q", "0.1,0.9,-1.2,0.4,0.6,0.3")
    assert code == 0 and "shoulder" in out and "elbow" in out and "wrist" in out


def test_ik_bad_input_one_line_exit_2(capsys):
    for argv in (["ik", "puma560", "--pose", "1,2,3"],
                 ["ik", "puma560", "--T", "1,0,0,0,0,1,0,0,0,0,2,0,0,0,0,1"],
                 ["ik", "puma560", "--from-q", "0,0,0,0,0,abc"],
                 ["ik", "no-such-robot", "--pose", "0,0,0,0,0,0"],
                 ["ik", "puma560"]):
        code, _, err = _run(capsys, *argv)
        assert code == 2, argv
        assert err.strip() and err.strip().count("\n") == 0 and "Traceback" not in err


@pytest.mark.slow
def test_cli_general_6r_and_lock(tmp_path):
    """jaco2-6dof goes to the general eigenvalue method; panda --lock q7 gives solutions that keep q7."""
    import json
    import subprocess
    import sys

    def run(*args):
        return subprocess.run([sys.executable, "-m", "denavit", "ik", *args], capture_output=True, text=True)

    r = run("jaco2-6dof", "--from-q", "0.1,0.2,0.3,0.4,0.5,0.6", "--json")
    assert r.returncode == 0, r.stderr
    d = json.loads(r.stdout)
    assert d["structure"] == "general" and len(d["solutions"]) >= 2
    assert min(max(abs(a - b) for a, b in zip(s, [0.1, 0.2, 0.3, 0.4, 0.5, 0.6])) for s in d["solutions"]) < 1e-9
    r = run("panda", "--deg", "--from-q", "10,20,30,-80,50,100,40", "--lock", "q7=40", "--json")
    assert r.returncode == 0, r.stderr
    d = json.loads(r.stdout)
    assert d["locked"] == {"q7": pytest.approx(40.0)}
    assert all(abs(s[6] - 40.0) < 1e-9 for s in d["solutions"])
    for bad, msg in ((["--lock", "q9=1"], "not a joint"), (["--lock", "q7=__import__"], "unknown symbol"),
                     (["--lock", "q7=9"], "outside its limits"), (["--lock", "x"], "not qN=VALUE"),
                     (["--lock", "q7=1", "--method", "numeric"], "analytic")):
        r = run("panda", "--from-q", "0.1,0.2,0.3,-1.4,0.5,1.6,0.7", *bad)
        assert r.returncode == 2 and msg in r.stderr and "Traceback" not in r.stderr
        assert len(r.stderr.strip().splitlines()) == 1


def test_ik_pose_and_seed_with_deg_take_each_value_in_its_own_unit(capsys):
    """--deg: plain roll/pitch/yaw numbers are degrees, a value written with deg or pi keeps its unit (was converted
    twice); a --seed's prismatic entry stays in metres."""
    from denavit.numeric import transform_from_xyz_rpy

    robot = load_robot("puma560")
    T = forward_kinematics(robot, [0.2, -0.3, 0.4, 0.5, 0.6, 0.7])
    from denavit.numeric import rpy_from_rotation

    r, p, y = np.degrees(rpy_from_rotation(T[:3, :3]))
    x = ",".join(f"{v:.15g}" for v in T[:3, 3])
    for pose in (f"{x},{r:.15g},{p:.15g},{y:.15g}", f"{x},{r:.15g}deg,{p:.15g},{np.radians(y):.15g}*pi/pi"):
        code, out, err = _run(capsys, "ik", "puma560", "--pose=" + pose, "--deg", "--json")
        assert code == 0, err
        data = json.loads(out)
        np.testing.assert_allclose(data["T"], T, atol=1e-9)
        sols = np.radians(np.array(data["solutions"]))
        np.testing.assert_allclose(forward_kinematics(robot, sols), np.broadcast_to(T, (len(sols), 4, 4)), atol=1e-8)
    stanford = load_robot("stanford")
    q = np.array([0.2, -0.4, 0.6, 0.3, 0.5, -0.2])  # joint 3 prismatic [m]
    Ts = forward_kinematics(stanford, q)
    seed = ",".join(f"{v:.15g}" for v in [np.degrees(q[0]), np.degrees(q[1]), q[2], *np.degrees(q[3:])])
    code, out, err = _run(capsys, "ik", "stanford", "--T=" + ",".join(f"{v:.17g}" for v in Ts.ravel()),
                          "--method", "numeric", "--seed", seed, "--deg", "--json")
    assert code == 0, err
    data = json.loads(out)
    assert data["success"] is True and data["iterations"] <= 3  # the seed is the solution: nothing to iterate
    assert abs(data["q"][2] - q[2]) < 1e-9  # metres, not degrees
