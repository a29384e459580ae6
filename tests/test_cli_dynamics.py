"""The dynamics and simulate commands, in-process: exit codes, JSON keys, one-line errors."""

from __future__ import annotations

import json

import numpy as np
import pytest

import denavit
from denavit.cli import main
from denavit.numeric import gravity_torques, mass_matrix, rnea


def run(capsys, *argv):
    code = main(list(argv))
    out, err = capsys.readouterr()
    return code, out, err


def test_dynamics_json_matches_library(capsys):
    code, out, _ = run(capsys, "dynamics", "puma560", "-q", "0.1, 0.2, -0.3, 0.4, 0.5, 0.6", "--qd", "1,0,0,0,0,1",
                       "--qdd", "0,1,0,0,0,0", "--json")
    assert code == 0
    data = json.loads(out)
    robot = denavit.load_robot("puma560")
    q = np.array([0.1, 0.2, -0.3, 0.4, 0.5, 0.6])
    np.testing.assert_allclose(data["M"], mass_matrix(robot, q))
    np.testing.assert_allclose(data["g"], gravity_torques(robot, q))
    np.testing.assert_allclose(data["tau"], rnea(robot, q, [1, 0, 0, 0, 0, 1], [0, 1, 0, 0, 0, 0]))
    for key in ("robot", "q", "qd", "qdd", "C", "c", "friction"):
        assert key in data


def test_dynamics_deg_converts_input(capsys):
    _, out_deg, _ = run(capsys, "dynamics", "planar2r", "-q", "90, 0", "--deg", "--json")
    _, out_rad, _ = run(capsys, "dynamics", "planar2r", "-q", "pi/2, 0", "--json")
    np.testing.assert_allclose(json.loads(out_deg)["g"], json.loads(out_rad)["g"])


def test_dynamics_symbolic_text_and_progress(capsys):
    code, out, err = run(capsys, "dynamics", "report000-planar3r", "--symbolic")
    assert code == 0 and "M[1,1] = " in out and "C23" in out
    assert "mass matrix" in err  # progress lines on stderr
    code, out, _ = run(capsys, "dynamics", "planar2r", "--symbolic", "--format", "latex", "--json")
    assert code == 0 and "begin{aligned}" in json.loads(out)["symbolic_text"]


@pytest.mark.parametrize("argv, fragment", [
    (("dynamics", "stanford", "-q", "0,0,0,0,0,0"), "no inertial data"),
    (("dynamics", "planar2r", "-q", "0, zz"), "q: value 2"),
    (("dynamics", "planar2r", "-q", "0, 0", "--qd", "1"), "qd: expected 2 values"),
    (("simulate", "planar2r", "--q0", "0,0", "--duration", "-1"), "--duration"),
    (("simulate", "planar2r", "--q0", "0,0", "--duration", "1", "--tau", "1,2,3"), "tau"),
])
def test_bad_input_one_line_exit_2(capsys, argv, fragment):
    code, _, err = run(capsys, *argv)
    assert code == 2
    assert fragment in err and len(err.strip().splitlines()) == 1 and "Traceback" not in err


def test_simulate_json_and_plot(capsys, tmp_path):
    code, out, _ = run(capsys, "simulate", "planar2r", "--q0", "0.2, 0", "--duration", "0.5", "--dt", "0.05",
                       "--json")
    assert code == 0
    data = json.loads(out)
    assert len(data["t"]) == 11 and np.shape(data["q"]) == (11, 2) and data["success"]
    assert data["energy_drift"] < 1e-6 * (1 + abs(data["energy"][0]))
    pytest.importorskip("matplotlib")
    png = tmp_path / "sim.png"
    code, _, _ = run(capsys, "simulate", "planar2r", "--q0", "0.2, 0", "--duration", "0.2", "-o", str(png))
    assert code == 0 and png.read_bytes()[:4] == b"\x89PNG"
