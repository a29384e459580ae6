"""Audit of the command line as a user runs it: strict JSON, no silent overwrites, one-line errors.

Regression tests for problems found by running every command on every catalogue robot with good and
hostile input (see the commit messages).  In-process through ``denavit.cli.main``.
"""

import json
import math

import contextlib
import io

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

from conftest import REDUCED
from denavit.cli import main


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


class _Terminal(io.StringIO):
    def isatty(self):
        return True


def run_tty(*argv):
    """``main(argv)`` with stderr a terminal (progress notes shown) and stdout captured."""
    out, err = io.StringIO(), _Terminal()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        code = main([str(a) for a in argv])
    return code, out.getvalue(), err.getvalue()


def _strict(text):
    """json.loads that rejects NaN / Infinity (RFC 8259), as a browser or jq would."""
    def bad(c):
        raise ValueError(f"non-standard JSON constant {c}")
    return json.loads(text, parse_constant=bad)


def test_json_is_strict_at_a_singular_configuration(capsys):
    # planar 2R stretched out: the force ellipsoid has an infinite radius, which used to print 'Infinity'
    code, out, _ = run(capsys, "singularities", "planar2r", "-q", "0,0", "--json")
    assert code == 0
    data = _strict(out)
    radii = data["measures"]["force_ellipsoid"]["radii"]
    assert None in radii                          # the infinite radius is null ...
    assert all(r is None or math.isfinite(r) for r in radii)
    code, out, _ = run(capsys, "singularities", "planar2r", "-q", "0,0")
    assert code == 0 and "inf" in out             # ... and still visible in the text output


def test_to_json_maps_nonfinite_to_null():
    from denavit.cli._common import to_json

    got = to_json({"a": np.array([1.0, np.inf, np.nan]), "b": np.float64(-np.inf), "c": [np.int64(3), 2.5]})
    assert got == {"a": [1.0, None, None], "b": None, "c": [3, 2.5]}
    json.dumps(got, allow_nan=False)


# Every command that writes -o FILE: an existing file is kept unless --force.
WRITERS = [
    ("plot", ["plot", "planar2r", "-q", "0.1,0.2"], ".png"),
    ("animate", ["animate", "planar2r", "--from", "0,0", "--to", "0.1,0.1", "--duration", "0.2", "--fps", "5"], ".gif"),
    ("view", ["view", "planar2r"], ".html"),
    ("workspace", ["workspace", "planar2r", "--samples", "200"], ".png"),
    ("simulate", ["simulate", "planar2r", "--q0", "0,0", "--duration", "0.05"], ".png"),
    ("report", ["report", "planar2r", "-q", "0.1,0.2", "--topics", "fk"], ".md"),
    ("convert", ["convert", "planar2r", "--to", "modified"], ".yaml"),
]


@pytest.mark.parametrize("name,argv,ext", WRITERS, ids=[w[0] for w in WRITERS])
def test_existing_output_is_not_overwritten_without_force(capsys, tmp_path, name, argv, ext):
    path = tmp_path / f"mine{ext}"
    path.write_text("precious\n")
    code, out, err = run(capsys, *argv, "-o", path)
    assert code == 2
    assert path.read_text() == "precious\n"
    lines = err.strip().splitlines()
    assert len(lines) == 1 and "exists" in lines[0] and "--force" in lines[0] and "Traceback" not in err
    code, out, err = run(capsys, *argv, "-o", path, "--force")
    assert code == 0, err
    assert path.read_bytes() != b"precious\n"


# Long-running commands report their stages on stderr, and stay quiet with --json (stdout is pure JSON).
PROGRESS = [
    (["report", "planar2r", "-q", "0.1,0.2", "--topics", "fk,jacobian"], "section 2/2: jacobian"),
    (["dynamics", "planar2r", "--symbolic"], "mass matrix"),
    (["singularities", "planar2r", "--rows", "vx,vy"], "factoring"),
]


@pytest.mark.parametrize("argv,stage", PROGRESS, ids=[p[0][0] for p in PROGRESS])
def test_progress_on_stderr_only_without_json(capsys, argv, stage):
    code, out, err = run(capsys, *argv)
    assert code == 0 and stage in err
    assert stage not in out
    code, out, err = run(capsys, *argv, "--json")
    assert code == 0 and err == ""
    _strict(out)


def test_values_may_start_with_a_minus_sign(capsys):
    # argparse alone took "-0.5,0.3" for an unknown option: "--qd: expected one argument"
    from denavit import load_robot
    from denavit.numeric import forward_kinematics

    robot = load_robot("planar2r")
    for text, q in [("-0.5,0.3", [-0.5, 0.3]), ("-pi/4,0.3", [-np.pi / 4, 0.3]), ("-.5,-1e-1", [-0.5, -0.1])]:
        code, out, err = run(capsys, "fk", "planar2r", "-q", text, "--json")
        assert code == 0, err
        assert np.allclose(_strict(out)["T"], forward_kinematics(robot, np.array(q)), atol=1e-12)
    code, out, err = run(capsys, "dynamics", "planar2r", "-q", "0.1,0.2", "--qd", "-0.5,0.3", "--qdd", "-1,-2", "--json")
    assert code == 0, err
    assert _strict(out)["qd"] == [-0.5, 0.3]
    code, out, err = run(capsys, "fk", "planar2r", "-q1,2", "--json")   # attached short option still works
    assert code == 0 and _strict(out)["q"] == [1.0, 2.0]
    code, out, err = run(capsys, "fk", "planar2r", "-q", "-0.5")        # a wrong count is still an error
    assert code == 2 and len(err.strip().splitlines()) == 1


LONG = "x" * 20000
HOSTILE = [
    ["fk", LONG, "-q", "0"],                                     # was: internal error OSError (name too long)
    ["show", LONG],
    ["convert", "planar2r", "--to", LONG],                       # was: the whole string echoed on stderr
    ["report", "planar2r", "--topics", LONG],
    ["fk", "planar2r", "-q", LONG],
    ["singularities", "planar3r", "-q", "1,2"],                  # was: progress lines, then the error
    ["dynamics", "planar2r", "--symbolic", "-q", "1"],
    ["workspace", "planar2r", "--samples", "200", "--seed", "-1"],  # was: internal error ValueError
    ["check", "planar2r", "examples/claims/planar2r.yaml", "--seed", "-1"],
    ["ik", "planar2r", "--from-q", "0.1,0.2", "--method", "numeric", "--tol", "1e999"],  # was: accepted
    ["ik", "planar2r", "--from-q", "0.1,0.2", "--method", "numeric", "--restarts", "-1"],
    ["plot", "planar2r", "-o", "never.png", "--elev", "nan"],   # was: accepted with RuntimeWarnings
    ["fk", "planar2r", "-q", '__import__("os"),0'],
    ["fk", "planar2r", "-q", "9**9**9,0"],
    ["fk", "planar2r", "-q", "1e999,0"],
    ["fk", "planar2r", "-q", "nan,0"],
    ["fk", "planar2r", "-q", ""],
    ["fk", "nosuchrobot", "-q", "0,0"],
]


@pytest.mark.parametrize("argv", HOSTILE, ids=lambda a: " ".join(a)[:40])
def test_hostile_input_gives_one_short_line(capsys, tmp_path, monkeypatch, argv):
    import pathlib

    monkeypatch.chdir(pathlib.Path(__file__).resolve().parents[1])
    argv = [str(tmp_path / a) if a == "never.png" else a for a in argv]
    code, out, err = run(capsys, *argv)
    lines = err.strip().splitlines()
    assert code in (1, 2), (code, err[:200])
    assert len(lines) == 1, err[:500]
    assert len(lines[0]) < 500 and "internal error" not in err and "Traceback" not in err
    assert lines[0].startswith("denavit")
    assert not (tmp_path / "never.png").exists()


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


def test_compile_reports_its_stages_on_stderr_only_without_json(capsys, tmp_path, monkeypatch):
    # a first numba compile takes 5 s and more, and printed nothing until it was done
    # (at a terminal: piped, a failure must stay one line on stderr)
    monkeypatch.setenv("DENAVIT_CACHE_DIR", str(tmp_path))
    code, out, err = run_tty("compile", "planar2r", "--backend", "numpy")
    assert code == 0 and "generating the kernels" in err and "compiling and timing" in err
    assert "compiling and timing" not in out and out.startswith("planar2r: 2 joints, backend numpy")
    code, out, err = run_tty("compile", "planar2r", "--backend", "numpy", "--json")
    assert code == 0 and err == "" and _strict(out)["backend"] == "numpy"
    code, out, err = run(capsys, "compile", "planar2r", "--backend", "numpy")
    assert code == 0 and err == ""


def test_animate_says_it_is_rendering_on_stderr_only_without_json(capsys, tmp_path):
    # a default 2 s move of the PUMA took 5 s to render with nothing on the terminal
    pytest.importorskip("matplotlib")
    # (at a terminal: piped, a failure such as a full disk must stay one line on stderr)
    argv = ["animate", "planar2r", "--from", "0,0", "--to", "0.1,0.1", "--duration", "0.2", "--fps", "5"]
    code, out, err = run_tty(*argv, "-o", tmp_path / "a.gif")
    assert code == 0 and err.strip() == f"denavit animate: rendering 2 frames to {tmp_path / 'a.gif'}"
    assert out.startswith(f"wrote {tmp_path / 'a.gif'} (2 frames")
    code, out, err = run_tty(*argv, "-o", tmp_path / "b.gif", "--json")
    assert code == 0 and err == "" and _strict(out)["frames"] == 2
    code, out, err = run(capsys, *argv, "-o", tmp_path / "c.gif")
    assert code == 0 and err == ""


ONE_JOINT = """name: one
convention: standard
joints:
  - {a: 1.0, alpha: 0, d: 0, theta: q}
"""


def test_one_joint_arm_reads_in_the_singular(capsys, tmp_path, monkeypatch):
    # "1 joints (R)" in show, "1 joints q1 … q1" in export-urdf
    monkeypatch.chdir(tmp_path)
    (tmp_path / "one.yaml").write_text(ONE_JOINT)
    code, out, _ = run(capsys, "show", "one.yaml")
    assert code == 0 and "1 joint (R)" in out and "joints" not in out.splitlines()[1]
    code, out, _ = run(capsys, "export-urdf", "one.yaml", "-o", "one.urdf")
    assert code == 0 and "1 joint q1," in out and "joints" not in out
    code, out, _ = run(capsys, "show", "puma560")
    assert "6 joints (RRRRRR)" in out


def test_a_missing_convention_says_it_is_missing(capsys, tmp_path, monkeypatch):
    # was: "'convention' must be standard or modified, got None"
    monkeypatch.chdir(tmp_path)
    (tmp_path / "arm.yaml").write_text(ONE_JOINT.replace("convention: standard\n", ""))
    code, out, err = run(capsys, "show", "arm.yaml")
    lines = err.strip().splitlines()
    assert code == 2 and out == "" and len(lines) == 1
    assert "arm.yaml: convention" in lines[0] and "missing" in lines[0] and "None" not in lines[0]


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


@pytest.mark.parametrize("name", ["stanford", "puma560", "ur5"])
def test_export_notes_what_the_file_cannot_carry(capsys, tmp_path, name):
    # an arm without inertial data went out with placeholder masses (MJCF) or none (URDF) and not a word said
    from denavit import load_robot

    robot = load_robot(name)
    joints = [link.inertia for link in robot.joints]
    for fmt, ext in (("urdf", ".urdf"), ("mjcf", ".xml")):
        path = tmp_path / f"{name}{ext}"
        code, out, err = run(capsys, f"export-{fmt}", name, "-o", path)
        assert code == 0
        notes = [ln for ln in out.splitlines() if ln.startswith("note: ")]
        code, jout, _ = run(capsys, f"export-{fmt}", name, "--json")
        assert code == 0 and [f"note: {n}" for n in _strict(jout)["notes"]] == notes
        text = path.read_text()
        if all(li is None for li in joints):
            assert len(notes) == 1 and "no inertial data" in notes[0]
            assert ("<inertial" not in text) if fmt == "urdf" else ('mass="1e-06"' in text)
        elif fmt == "urdf" and any(li.motor_inertia > 0 for li in joints):
            assert len(notes) == 1 and "motor" in notes[0]
        else:
            assert notes == []


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


def test_symbolic_dynamics_progress_is_a_few_lines_per_stage(capsys, monkeypatch):
    # the mass matrix of a 6-joint arm printed a line per entry (22 lines), and so did every later stage
    import collections

    import denavit.cli._dynamics as dyn

    def stages(every):
        monkeypatch.setattr(dyn, "PROGRESS_EVERY", every)
        code, out, err = run(capsys, "dynamics", "planar3r", "--symbolic")
        assert code == 0 and out
        lines = [ln.removeprefix("denavit dynamics: ") for ln in err.splitlines()]
        return collections.Counter(ln.rsplit(" ", 1)[0] for ln in lines), lines

    quiet, qlines = stages(1e9)
    every, elines = stages(0.0)
    assert "mass matrix" in quiet and set(quiet) == set(every)
    assert max(quiet.values()) <= 2 and len(elines) > len(qlines) and max(every.values()) > 2
