"""The command line for robots/show/fk/convert: in-process and as a real process."""

import json
import subprocess
import sys

import numpy as np
import pytest

import denavit
from denavit.cli import main


def run(capsys, *argv):
    code = main(list(argv))
    out, err = capsys.readouterr()
    return code, out, err


def test_help_and_version(capsys):
    code, out, _ = run(capsys, "--help")
    assert code == 0 and "fk" in out and "robots" in out
    code, out, _ = run(capsys, "--version")
    assert code == 0 and denavit.__version__ in out


def test_robots_lists_the_catalogue(capsys):
    code, out, _ = run(capsys, "robots", "--json")
    assert code == 0
    names = [r["name"] for r in json.loads(out)["robots"]]
    assert names == denavit.catalogue_names()
    code, out, _ = run(capsys, "robots")
    assert "puma560" in out and "report000-6r" in out


def test_show_prints_table_and_json(capsys):
    code, out, _ = run(capsys, "show", "report000-6r")
    assert code == 0 and "modified" in out and "H1" in out and "fixed" in out
    code, out, _ = run(capsys, "show", "puma560", "--json")
    data = json.loads(out)
    assert data["dof"] == 6 and len(data["rows"]) == 6


def test_fk_json_equals_library(capsys):
    code, out, _ = run(capsys, "fk", "report000-6r", "-q", "0, pi/4, pi/3, -pi/2, -pi/3, pi/6", "--json", "--frames")
    assert code == 0
    data = json.loads(out)
    robot = denavit.load_robot("report000-6r")
    q = [0, np.pi / 4, np.pi / 3, -np.pi / 2, -np.pi / 3, np.pi / 6]
    np.testing.assert_allclose(data["T"], denavit.forward_kinematics(robot, q), atol=1e-12)
    np.testing.assert_allclose(data["frames"], denavit.link_transforms(robot, q), atol=1e-12)
    # the old name loads the renamed arm, whose name is echoed
    assert data["robot"] == "coaxial-6r" and len(data["q"]) == 6 and len(data["rpy"]) == 3


def test_fk_degrees(capsys):
    code, out, _ = run(capsys, "fk", "puma560", "-q", "0 45 -60 -90 -60 30", "--deg", "--json")
    assert code == 0
    data = json.loads(out)
    T = denavit.forward_kinematics(denavit.load_robot("puma560"), np.radians([0, 45, -60, -90, -60, 30]))
    np.testing.assert_allclose(data["T"], T, atol=1e-12)
    assert data["q"][1] == pytest.approx(45)
    code, _, err = run(capsys, "fk", "puma560", "-q", "0 45 60 -90 -60 30", "--deg")
    assert code == 2 and "joint 3 = 60 deg is outside its limits [-225, 45]" in err


def test_fk_symbolic_text_latex_json(capsys):
    code, out, _ = run(capsys, "fk", "planar2r", "--symbolic", "--shorthand")
    assert code == 0 and "C₁₂" in out or "C12" in out
    code, out, _ = run(capsys, "fk", "planar2r", "--symbolic", "--latex")
    assert code == 0 and "\\cos" in out
    code, out, _ = run(capsys, "fk", "planar2r", "--symbolic", "--markdown")
    assert code == 0 and out.count("$$") >= 6 and "\\cos" in out
    code, out, _ = run(capsys, "fk", "planar2r", "--symbolic", "--json")
    data = json.loads(out)
    assert "cos(q1 + q2)" in "".join(sum(data["T_symbolic"], []))


def test_convert_writes_a_file_with_identical_fk(capsys, tmp_path):
    out_file = tmp_path / "puma_mdh.yaml"
    code, out, err = run(capsys, "convert", "puma560", "--to", "modified", "-o", str(out_file))
    assert code == 0, err
    a, b = denavit.load_robot("puma560"), denavit.load_robot(out_file)
    assert b.convention.value == "modified"
    q = np.random.default_rng(1).uniform(-2, 2, (10, 6))
    np.testing.assert_allclose(denavit.forward_kinematics(b, q), denavit.forward_kinematics(a, q), atol=1e-12)
    # --no-clobber refuses and leaves the file as it was; without it the same command runs again
    before = out_file.read_text()
    code, _, err = run(capsys, "convert", "puma560", "--to", "modified", "-o", str(out_file), "--no-clobber")
    assert code == 2 and "--no-clobber" in err and out_file.read_text() == before
    out_file.write_text("mine")
    code, _, err = run(capsys, "convert", "puma560", "--to", "modified", "-o", str(out_file))
    assert code == 0 and out_file.read_text() == before


BAD_INPUT = [
    (["fk", "puma560", "-q", "1, 2"], "expected 6 values, got 2"),
    (["fk", "puma560", "-q", "1, 2, 3, 4, 5, nan"], "unknown symbol 'nan'"),
    (["fk", "puma560", "-q", "1, 2, 3, 4, 5, __import__('os')"], "value 6"),
    (["fk", "puma560", "-q", "0, 0, 0, 0, 0, 9**9**9"], "exponent"),
    (["fk", "puma560", "-q", "0, 0, 0, 0, 0, 100"], "outside its limits"),
    (["fk", "no-such-robot", "-q", "0"], "unknown robot"),
    (["fk", "puma560"], "give joint values"),
    (["fk", "puma560", "-q", "0,0,0,0,0,0", "--param", "L9=1"], "no parameter"),
    (["show", "missing.yaml"], "no such robot file"),
    (["convert", "puma560", "--to", "sideways"], "invalid choice"),
    (["nosuchcommand"], "invalid choice"),
]


@pytest.mark.parametrize("argv, message", BAD_INPUT)
def test_bad_input_one_line_exit_2(capsys, argv, message):
    code, out, err = run(capsys, *argv)
    assert code == 2
    assert message in err
    assert len(err.strip().splitlines()) == 1
    assert "Traceback" not in err


def test_bad_robot_file_names_file_row_field(capsys, tmp_path):
    p = tmp_path / "bad.yaml"
    p.write_text("convention: standard\njoints:\n  - {a: 1, theta: q}\n  - {a: \"L2 +\", theta: q}\n")
    code, _, err = run(capsys, "show", str(p))
    assert code == 2 and str(p) in err and "row 2" in err and "'a'" in err
    assert len(err.strip().splitlines()) == 1


def test_console_script_runs_as_a_process():
    proc = subprocess.run([sys.executable, "-m", "denavit", "fk", "planar2r", "-q", "0, 0", "--json"],
                          capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0, proc.stderr
    assert json.loads(proc.stdout)["T"][0][3] == pytest.approx(
        denavit.forward_kinematics(denavit.load_robot("planar2r"), [0, 0])[0, 3])
    proc = subprocess.run([sys.executable, "-m", "denavit", "fk", "planar2r", "-q", "0"],
                          capture_output=True, text=True, timeout=120)
    assert proc.returncode == 2 and "Traceback" not in proc.stderr


def test_fk_text_prints_no_rounding_noise_and_no_negative_zero(capsys):
    """At qr the Puma's tool points straight up: pitch is -0.0 and some entries are ~1e-17 in floating point.
    The text shows them as 0 (the JSON keeps the raw numbers)."""
    import re

    assert main(["fk", "puma560", "-q", "qr"]) == 0
    out = capsys.readouterr().out
    assert not re.search(r"(?<![\w.])-0(?![.\d])", out), out
    assert not re.search(r"e-1[0-9]", out), out


def test_show_is_the_dh_table_of_print_robot(capsys):
    """One presenter: ``denavit show`` prints ``print(robot)``'s table (limits as the file wrote them: the Puma
    file writes -160deg in a radian file), plus whether inertial data is there."""
    import denavit

    robot = denavit.load_robot("puma560")
    assert main(["show", "puma560"]) == 0
    out = capsys.readouterr().out
    assert out == str(robot) + "\ninertial data: yes\n"
    assert "[-160°, 160°]" in out
    assert main(["show", "puma560", "--deg"]) == 0  # --deg: every angle in degrees
    assert "90°" in capsys.readouterr().out


def test_main_called_twice_in_one_process_keeps_no_state(capsys):
    """main() reuses one parser per process: options given to one call (an appended --param, --deg) must not
    reach the next; each answer equals the same command's answer alone in a fresh parser."""
    from denavit.cli import build_parser, main

    def run(argv):
        assert main(argv) == 0
        return json.loads(capsys.readouterr().out)

    plain = ["fk", "planar2r", "-q", "0.3,0.2", "--json"]
    first = run(plain)
    changed = run([*plain[:-1], "--param", "L1=2", "--param", "L2=0.5", "--deg", "--json"])
    again = run(plain)
    assert again == first
    assert changed != first
    fresh = build_parser().parse_args(plain)
    assert fresh.param == [] and not fresh.deg
