"""``denavit calibrate``: the report, the calibrated robot file, and bad input as one line with exit code 2."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

import denavit
from denavit.cli import main
from denavit.numeric import quaternion_from_rotation


def _simulate(path, kind="pose", m=30, seed=4, deg=False):
    """Poses of the Puma with a2 1 mm longer and joint 3's offset 0.2° off (the library's FK), 0.05 mm noise."""
    rng = np.random.default_rng(seed)
    nominal = denavit.load_robot("puma560")
    links = list(nominal.links)
    links[1] = denavit.DHLink(a=links[1].a + 1e-3, alpha=links[1].alpha, joint=links[1].joint,
                              q_limits=links[1].q_limits, inertia=links[1].inertia)
    links[2] = denavit.DHLink(a=links[2].a, alpha=links[2].alpha, d=links[2].d, theta=math.radians(0.2),
                              joint=links[2].joint, q_limits=links[2].q_limits, inertia=links[2].inertia)
    true = nominal.replace(links=tuple(links), symbols=())
    q = rng.uniform(-1.2, 1.2, (m, 6))
    T = denavit.forward_kinematics(true, q)
    p = T[:, :3, 3] + rng.normal(0, 5e-5, (m, 3))
    cols = {"q": np.degrees(q) if deg else q, "x": p[:, 0], "y": p[:, 1], "z": p[:, 2]}
    if kind == "pose":
        quat = quaternion_from_rotation(T[:, :3, :3])
        cols.update(qw=quat[:, 0], qx=quat[:, 1], qy=quat[:, 2], qz=quat[:, 3])
    denavit.write_measurements(path, cols, comment="simulated Puma 560 poses")
    return true, q


def test_calibrate_prints_report_and_writes_a_robot_that_matches_the_truth(tmp_path, capsys):
    data, out = tmp_path / "poses.csv", tmp_path / "cal.yaml"
    true, _ = _simulate(data)
    assert main(["calibrate", "puma560", str(data), "-o", str(out), "--noise-pos", "5e-5", "--noise-rot", "1e-6"]) == 0
    text = capsys.readouterr().out
    for fragment in ("rank 30 of 37 parameters", "after, held out", "a2", "theta3_offset", "worst poses",
                     "held at their nominal value", f"wrote {out}"):
        assert fragment in text
    cal = denavit.load_robot(str(out))
    assert cal.name == "puma560" and cal.has_dynamics  # names, inertia, limits kept
    np.testing.assert_array_equal(cal.q_limits, denavit.load_robot("puma560").q_limits)
    head = out.read_text().splitlines()
    assert head[0].startswith("# Source: P. Corke")  # the catalogue file's leading comments are kept
    assert any(line.startswith("# Kinematics calibrated by denavit calibrate from") for line in head[:15])
    q = np.random.default_rng(9).uniform(-1, 1, (10, 6))
    p_true = denavit.forward_kinematics(true, q)[:, :3, 3]
    err = np.abs(denavit.forward_kinematics(cal, q)[:, :3, 3] - p_true).max()
    nominal_err = np.abs(denavit.forward_kinematics(denavit.load_robot("puma560"), q)[:, :3, 3] - p_true).max()
    assert err < 1e-4 < 5e-4 < nominal_err  # 0.05 mm noise; the nominal arm is off by about a millimetre


def test_calibrate_json_degrees_and_positions(tmp_path, capsys):
    data = tmp_path / "pos.csv"
    _simulate(data, kind="position", deg=True)
    assert main(["calibrate", "puma560", str(data), "--deg", "--json", "--holdout", "0"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["kind"] == "position" and out["residuals"]["holdout_after"] is None
    names = {p["name"]: p for p in out["parameters"]}
    assert names["tool_rx"]["identified"] is False and names["tool_rx"]["sigma"] is None
    assert abs(names["a2"]["correction"] - 1e-3) < 5 * names["a2"]["sigma"]  # metres in JSON, whatever --deg says


@pytest.mark.parametrize("args, fragment", [
    (["calibrate", "puma560", "{missing}"], "No such file"),
    (["calibrate", "puma560", "{bad}"], "bad.csv:3: column 'q2': 'x' is not a number"),
    (["calibrate", "puma560", "{pos}", "--kind", "pose"], "needs the orientation columns qw qx qy qz"),
    (["calibrate", "puma560", "{noxyz}"], "no measured positions"),
    (["calibrate", "puma560", "{pos}", "-o", "{dir}/cal.png"], "unsupported file type '.png'"),
    (["calibrate", "puma560", "{pos}", "--holdout", "2"], "expected a number in [0, 0.9]"),
    (["calibrate", "puma560", "{few}"], "too few measurements"),
    (["calibrate", "puma560", "{pos}", "--noise-pos", "-1"], "expected a number > 0"),
])
def test_bad_input_exits_2_with_one_line(tmp_path, capsys, args, fragment):
    _simulate(tmp_path / "pos.csv", kind="position")
    (tmp_path / "bad.csv").write_text("q1,q2,q3,q4,q5,q6,x,y,z\n0,0,0,0,0,0,1,2,3\n0,x,0,0,0,0,1,2,3\n")
    (tmp_path / "noxyz.csv").write_text("q1,q2,q3,q4,q5,q6\n0,0,0,0,0,0\n1,1,1,1,1,1\n")
    _simulate(tmp_path / "few.csv", kind="position", m=6)
    names = {"missing": tmp_path / "missing.csv", "bad": tmp_path / "bad.csv", "pos": tmp_path / "pos.csv",
             "noxyz": tmp_path / "noxyz.csv", "few": tmp_path / "few.csv", "dir": tmp_path}
    assert main([a.format(**names) for a in args]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and fragment in err, err
    assert not list(tmp_path.glob("*.png")) and not list(tmp_path.glob(".denavit-*"))


def test_calibrated_file_keeps_plain_leading_comments_only(tmp_path, capsys):
    data, out = tmp_path / "poses.csv", tmp_path / "cal.yaml"
    _simulate(data, m=20)
    text = denavit.dump_robot(denavit.load_robot("puma560")).replace("# puma560: written by denavit\n", "")
    robot = tmp_path / "arm.yaml"
    robot.write_text("# bench arm 7, serial 1234\n#\tmeasured 2026\n# \u202ered\n" + text, encoding="utf-8")
    assert main(["calibrate", str(robot), str(data), "-o", str(out), "--holdout", "0"]) == 0
    lines = out.read_text(encoding="utf-8").splitlines()
    assert lines[:2] == ["# bench arm 7, serial 1234", "#\tmeasured 2026"]
    assert not any("\u202e" in line for line in lines)  # a bidi override is never copied
    assert denavit.load_robot(str(out)).dof == 6


def test_millimetres_and_a_json_robot_file(tmp_path, capsys):
    data, out = tmp_path / "poses.csv", tmp_path / "cal.json"
    true, q = _simulate(tmp_path / "m.csv", kind="position")
    m = denavit.read_measurements(tmp_path / "m.csv", true)
    denavit.write_measurements(data, {"q": m.q, "x": m.position[:, 0] * 1e3, "y": m.position[:, 1] * 1e3,
                                      "z": m.position[:, 2] * 1e3})  # the same positions in millimetres
    assert main(["calibrate", "puma560", str(data), "--mm", "--noise-pos", "0.05", "--holdout", "0", "-o",
                 str(out)]) == 0
    text = capsys.readouterr().out
    assert "a2 " in text and " mm" in text
    cal = denavit.load_robot(str(out))
    q_new = np.random.default_rng(2).uniform(-1, 1, (10, 6))
    err = np.abs(denavit.forward_kinematics(cal, q_new)[:, :3, 3] - denavit.forward_kinematics(true, q_new)[:, :3, 3])
    assert err.max() < 2e-4  # metres: --mm read the file's millimetres
