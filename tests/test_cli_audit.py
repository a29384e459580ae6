"""Audit of the command line as a user runs it: strict JSON, no silent overwrites, one-line errors.

Regression tests for problems found by running every command on every catalogue robot with good and
hostile input (see the commit messages).  In-process through ``denavit.cli.main``.
"""

import contextlib
import io
import json
import math

import numpy as np
import pytest

from denavit.cli import main


def run(capsys, *argv):
    code = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return code, out, err


class _Terminal(io.StringIO):
    def isatty(self):
        return True


def run_tty(*argv):
    """``main(argv)`` with stderr a terminal (progress notes shown) and stdout captured."""
    out, err = io.StringIO(), _Terminal()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        code = main([str(a) for a in argv])
    return code, out.getvalue(), err.getvalue()


def strict_json(text):
    """json.loads that rejects NaN / Infinity (RFC 8259), as a browser or jq would."""
    def bad(c):
        raise ValueError(f"non-standard JSON constant {c}")
    return json.loads(text, parse_constant=bad)


def test_json_is_strict_at_a_singular_configuration(capsys):
    # planar 2R stretched out: the force ellipsoid has an infinite radius, which used to print 'Infinity'
    code, out, _ = run(capsys, "singularities", "planar2r", "-q", "0,0", "--json")
    assert code == 0
    data = strict_json(out)
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


# Every command that writes -o FILE: an existing file is replaced (run twice, both succeed); --no-clobber keeps it;
# the old --force is accepted and changes nothing.
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
def test_existing_output_is_replaced_unless_no_clobber(capsys, tmp_path, name, argv, ext):
    path = tmp_path / f"mine{ext}"
    code, out, err = run(capsys, *argv, "-o", path)
    assert code == 0, err
    first = path.read_bytes()
    code, out, err = run(capsys, *argv, "-o", path)  # the same command again: it succeeds, as savefig would
    assert code == 0, err
    assert len(path.read_bytes()) > 0
    path.write_text("precious\n")
    code, out, err = run(capsys, *argv, "-o", path, "--no-clobber")
    assert code == 2
    assert path.read_text() == "precious\n"
    lines = err.strip().splitlines()
    assert len(lines) == 1 and "exists" in lines[0] and "--no-clobber" in lines[0] and "Traceback" not in err
    code, out, err = run(capsys, *argv, "-o", path, "--force")  # the old flag: accepted, replaces as without it
    assert code == 0, err
    assert path.read_bytes() != b"precious\n" and len(path.read_bytes()) > 0
    if ext in (".md", ".yaml"):  # text outputs of a deterministic command: the same bytes each time
        assert path.read_bytes() == first


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
    strict_json(out)


def test_values_may_start_with_a_minus_sign(capsys):
    # argparse alone took "-0.5,0.3" for an unknown option: "--qd: expected one argument"
    from denavit import load_robot
    from denavit.numeric import forward_kinematics

    robot = load_robot("planar2r")
    for text, q in [("-0.5,0.3", [-0.5, 0.3]), ("-pi/4,0.3", [-np.pi / 4, 0.3]), ("-.5,-1e-1", [-0.5, -0.1])]:
        code, out, err = run(capsys, "fk", "planar2r", "-q", text, "--json")
        assert code == 0, err
        assert np.allclose(strict_json(out)["T"], forward_kinematics(robot, np.array(q)), atol=1e-12)
    code, out, err = run(capsys, "dynamics", "planar2r", "-q", "0.1,0.2", "--qd", "-0.5,0.3", "--qdd", "-1,-2", "--json")
    assert code == 0, err
    assert strict_json(out)["qd"] == [-0.5, 0.3]
    code, out, err = run(capsys, "fk", "planar2r", "-q1,2", "--json")   # attached short option still works
    assert code == 0 and strict_json(out)["q"] == [1.0, 2.0]
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


def test_compile_reports_its_stages_on_stderr_only_without_json(capsys, tmp_path, monkeypatch):
    # a first numba compile takes 5 s and more, and printed nothing until it was done
    # (at a terminal: piped, a failure must stay one line on stderr)
    monkeypatch.setenv("DENAVIT_CACHE_DIR", str(tmp_path))
    code, out, err = run_tty("compile", "planar2r", "--backend", "numpy")
    assert code == 0 and "generating the kernels" in err and "compiling and timing" in err
    assert "compiling and timing" not in out and out.startswith("planar2r: 2 joints, backend numpy")
    code, out, err = run_tty("compile", "planar2r", "--backend", "numpy", "--json")
    assert code == 0 and err == "" and strict_json(out)["backend"] == "numpy"
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
    code, out, err = run(capsys, *argv, "-o", tmp_path / "c.gif", "--json")  # piped: nothing on stderr
    assert code == 0 and err == "" and strict_json(out)["frames"] == 2


ONE_JOINT = """name: one
convention: standard
joints:
  - {a: 1.0, alpha: 0, d: 0, theta: q}
"""


def test_one_joint_arm_reads_in_the_singular(capsys, tmp_path, monkeypatch):
    import pathlib

    # "1 joints (R)" in show, "1 joints q1 … q1" in export-urdf
    monkeypatch.chdir(tmp_path)
    (tmp_path / "one.yaml").write_text(ONE_JOINT)
    code, out, _ = run(capsys, "show", "one.yaml")
    assert code == 0 and "1 joint (R)" in out and "joints" not in out.splitlines()[1]
    code, out, _ = run(capsys, "export-urdf", "one.yaml", "-o", "one.urdf")
    assert code == 0 and "1 joint q1," in out and "joints" not in out
    code, out, _ = run(capsys, "convert", "one.yaml", "--to", "standard", "-o", "same.yaml")
    assert code == 0 and out.strip() == "wrote same.yaml (standard DH, 1 row) (it was already in that convention: " \
                                         "rows unchanged)"
    code, out, _ = run(capsys, "convert", "one.yaml", "--to", "modified", "-o", "mdh.yaml")
    assert code == 0 and out.startswith("wrote mdh.yaml (modified DH, ") and "already" not in out
    code, out, _ = run(capsys, "show", "puma560")
    assert "6 joints (RRRRRR)" in out
    urdf = pathlib.Path(__file__).resolve().parents[1] / "examples" / "urdf" / "small_arm.urdf"
    code, out, _ = run(capsys, "import-urdf", urdf, "--tip", "shoulder")  # the pan joint alone
    first = out.splitlines()[0]
    assert code == 0 and first.endswith("as 1 standard DH row") and "1 joint (R)" in out


def test_a_missing_convention_says_it_is_missing(capsys, tmp_path, monkeypatch):
    # was: "'convention' must be standard or modified, got None"
    monkeypatch.chdir(tmp_path)
    (tmp_path / "arm.yaml").write_text(ONE_JOINT.replace("convention: standard\n", ""))
    code, out, err = run(capsys, "show", "arm.yaml")
    lines = err.strip().splitlines()
    assert code == 2 and out == "" and len(lines) == 1
    assert "arm.yaml: convention" in lines[0] and "missing" in lines[0] and "None" not in lines[0]


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
        assert code == 0 and [f"note: {n}" for n in strict_json(jout)["notes"]] == notes
        text = path.read_text()
        if all(li is None for li in joints):
            assert len(notes) == 1 and "no inertial data" in notes[0]
            assert ("<inertial" not in text) if fmt == "urdf" else ('mass="1e-06"' in text)
        elif fmt == "urdf" and any(li.motor_inertia > 0 for li in joints):
            assert len(notes) == 1 and "motor" in notes[0]
        else:
            assert notes == []


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


NO_ANGLES = [
    ["workspace", "planar2r", "--samples", "2000", "--seed", "3", "--scheduler", "synchronous"],
    ["convert", "puma560", "--to", "modified"],
    ["export-urdf", "stanford"],
    ["check", "planar2r", "examples/claims/planar2r.yaml"],
]


@pytest.mark.parametrize("argv", NO_ANGLES, ids=[a[0] for a in NO_ANGLES])
def test_deg_says_it_has_no_effect_where_there_are_no_angles(capsys, monkeypatch, argv):
    # `workspace --help` promised "angles in and out in degrees" for a command without angles: --deg changes nothing
    import pathlib

    monkeypatch.chdir(pathlib.Path(__file__).resolve().parents[1])
    code, out, _ = run(capsys, *argv, "--json")
    code_deg, out_deg, _ = run(capsys, *argv, "--json", "--deg")
    assert code == code_deg == 0 and strict_json(out) == strict_json(out_deg)


def test_help_of_commands_without_angles_says_deg_has_no_effect():
    # every command takes --deg (README); where it changes nothing, its help says so
    from denavit.cli import build_parser

    sub = next(a for a in build_parser()._actions if a.dest == "command").choices
    for name, parser in sub.items():
        deg = next((a for a in parser._actions if a.dest == "deg"), None)
        if deg is None:
            continue
        quiet = name in {"workspace", "reachability", "convert", "check", "compile", "export", "export-urdf",
                         "export-mjcf"}
        assert ("no effect" in deg.help) == quiet, name
