"""Hostile command-line values and output paths (issue 14): the bad-input contract of tests/_hostile.py.

Every command of cli/_viz.py, _ik.py, _dynamics.py and _jacobian.py gets generated bad values for each of its
value options (random text, non-finite and huge numbers, wrong counts, unicode, very long strings, empty) and
bad ``-o`` paths (folders, missing folders, long names, FIFOs, symlinks, existing files, wrong extensions).
Each must give exit 2, one stderr line naming the option, nothing on stdout, no file changed, within the time
bound.  Control cases check that good values still give exit 0.  About 2,300 generated cases in all.
"""

from __future__ import annotations

import errno
import json
import os
import re

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from _hostile import assert_accepted_quietly, assert_refused, run_cli, corpus

N = 2  # planar2r: two revolute joints, limits ±pi, inertia given

# --- strategies for bad value lists ------------------------------------------------------------------------

_GOOD_NUMBER = st.one_of(st.integers(-3, 3).map(str), st.sampled_from(["0.1", "-0.5", "pi/4", "-pi/6", "1e-3"]))
_NONFINITE = st.sampled_from(["nan", "inf", "-inf", "NaN", "Infinity", "1e400", "-1e999", "1e308*10",
                              "9" * 400, "1e308+1e308", "10**400", "0/0", "1/0"])
_GARBAGE = st.one_of(
    st.text(min_size=1, max_size=30).map(lambda t: t + "@"),             # random unicode text, never valid
    st.sampled_from(["@", "__import__('os')", "q1", "x", "sin(", "()", "[1,2", "1,,2", "(1,2", ",", "$", "1e", "--",
                     "\u00b5", "\ud800", "\x00", "1 2 3 4 5", "e3", "2**1000000"]),
    st.integers(1000, 5000).map(lambda k: "1" + "+1" * k + "+"),          # a long expression, cut short
    st.integers(10_000, 60_000).map(lambda k: "x" * k),                   # a very long token
)


def bad_list(n: int, limit: float | None = None, counts: tuple[int, ...] = ()):
    """Text that is NOT a valid list of ``n`` (or ``counts``) finite values (within ±``limit`` when given)."""
    valid = {n, *counts}
    wrong_count = st.integers(0, 3 * n + 2).filter(lambda k: k not in valid).flatmap(
        lambda k: st.lists(_GOOD_NUMBER, min_size=k, max_size=k)).map(",".join)
    one_bad = st.tuples(st.lists(_GOOD_NUMBER, min_size=n, max_size=n), st.integers(0, n - 1),
                        st.one_of(_NONFINITE, _GARBAGE)).map(lambda t: ",".join(t[0][:t[1]] + [t[2]] + t[0][t[1] + 1:]))
    options = [wrong_count, one_bad, _GARBAGE, st.just("")]
    if limit is not None:
        huge = st.floats(min_value=limit * 1.01, max_value=1e308, allow_nan=False).flatmap(
            lambda x: st.tuples(st.sampled_from([x, -x]), st.integers(0, n - 1)))
        options.append(huge.map(lambda t: ",".join(f"{t[0]!r}" if i == t[1] else "0" for i in range(n))))
    return st.one_of(*options)


def _check(folder, argv, mentions=()):
    o = run_cli(argv, folder)
    assert_refused(o, mentions=mentions)
    assert not re.search(r"[A-Za-z]+Warning: ", o.err), o.describe()  # no Python-format warning before the line
    return o


@pytest.fixture(scope="module")
def folder(tmp_path_factory):
    return tmp_path_factory.mktemp("hostile_cli")


MANY = settings(max_examples=corpus(120), deadline=None, derandomize=True)
SOME = settings(max_examples=corpus(60), deadline=None, derandomize=True)


# --- joint vectors and other value lists -------------------------------------------------------------------

# (argv before the bad value, option, argv after, count, magnitude bound checked, what the error names)
VALUE_CASES = [
    (["jacobian", "planar2r"], "-q", [], N, None, "q"),
    (["jacobian", "planar2r", "--ignore-limits"], "-q", [], N, 1e9, "q"),
    (["velocity", "planar2r", "-q", "0.1,0.2"], "--qd", [], N, 1e9, "qd"),
    (["velocity", "planar2r", "--qd", "1,1"], "-q", [], N, None, "q"),
    (["statics", "planar2r", "-q", "0.1,0.2"], "--wrench", [], 6, 1e9, "wrench"),
    (["singularities", "planar2r"], "-q", [], N, None, "q"),
    (["dynamics", "planar2r"], "-q", [], N, None, "q"),
    (["dynamics", "planar2r", "-q", "0,0"], "--qd", [], N, 1e9, "qd"),
    (["dynamics", "planar2r", "-q", "0,0"], "--qdd", [], N, 1e9, "qdd"),
    (["simulate", "planar2r", "--duration", "0.1"], "--q0", [], N, None, "q0"),
    (["simulate", "planar2r", "--q0", "0,0", "--duration", "0.1"], "--tau", [], N, 1e9, "tau"),
    (["simulate", "planar2r", "--q0", "0,0", "--duration", "0.1"], "--qd0", [], N, 1e9, "qd0"),
    (["ik", "planar2r"], "--pose", [], 6, 1e9, "pose"),
    (["ik", "planar2r"], "--T", [], 16, 1e9, "T"),
    (["ik", "planar2r"], "--from-q", [], N, None, "from-q"),
    (["ik", "planar2r", "--method", "numeric", "--pose", "1,1,0,0,0,0"], "--seed", [], N, 1e9, "seed"),
    (["plot", "planar2r", "-o", "arm.png"], "-q", [], N, None, "q"),
    (["animate", "planar2r", "--to", "0,0", "-o", "a.gif"], "--from", [], N, None, "from"),
    (["view", "planar2r", "-o", "v.html"], "-q", [], N, None, "q"),
]


@pytest.mark.parametrize("head,option,tail,n,limit,name", VALUE_CASES,
                         ids=[f"{c[0][0]}{c[1]}" + ("-big" if c[0][-1] == "--ignore-limits" else "")
                              for c in VALUE_CASES])
def test_bad_value_lists(folder, head, option, tail, n, limit, name):
    @settings(max_examples=corpus(80 if n > 2 else 100), deadline=None, derandomize=True)
    @given(bad_list(n, limit, (3,) if option == "--wrench" else ()))
    def case(text):
        _check(folder, head + [option, text] + tail, mentions=[name])

    case()


@pytest.mark.parametrize("head,option,tail,n,limit,name", VALUE_CASES[:6] + VALUE_CASES[9:12],
                         ids=[f"{c[0][0]}{c[1]}" for c in VALUE_CASES[:6] + VALUE_CASES[9:12]])
def test_good_value_lists_are_accepted(folder, head, option, tail, n, limit, name):
    """Controls: the same options with valid values give exit 0."""
    rng = np.random.default_rng(7)
    for _ in range(3):
        vals = rng.uniform(-1, 1, n) * (3 if option in ("--wrench", "--tau") else 1)
        o = run_cli(head + [option, ",".join(f"{v:.6g}" for v in vals)] + tail, folder)
        assert_accepted_quietly(o)


# --- scalar options ----------------------------------------------------------------------------------------

_BAD_SCALAR = st.one_of(_NONFINITE, _GARBAGE, st.just(""),
                        st.floats(allow_nan=False, allow_infinity=False).map(repr))


def _bad_number(lo: float, hi: float, integer: bool = False):
    def bad(text: str) -> bool:
        try:
            v = int(text) if integer else float(text)
        except (ValueError, OverflowError):
            return True
        return not (lo <= v <= hi) or (not integer and not np.isfinite(v))
    more = st.integers(-10**30, 10**30).map(str) if integer else st.floats(allow_nan=False).map(repr)
    return st.one_of(_BAD_SCALAR, more, st.sampled_from(["1.5", "1e3", "0x10"])).filter(bad)


SCALAR_CASES = [
    (["plot", "planar2r", "-o", "p.png"], "--dpi", 10, 600, True),
    (["animate", "planar2r", "--from", "0,0", "--to", "1,1", "-o", "a.gif"], "--duration", 5e-324, 600, False),
    (["animate", "planar2r", "--from", "0,0", "--to", "1,1", "-o", "a.gif"], "--fps", 5e-324, 60, False),
    (["workspace", "planar2r"], "--samples", 100, 10**10, True),  # streamed (issue 17): denavit.scale.MAX_SAMPLES
    (["workspace", "planar2r"], "--resolution", 1e-6, 1e6, False),
    (["workspace", "planar2r"], "--seed", 0, 10**19, True),
    (["ik", "planar2r", "--method", "numeric", "--pose", "1,1,0,0,0,0"], "--restarts", 0, 1000, True),
    (["ik", "planar2r", "--method", "numeric", "--pose", "1,1,0,0,0,0"], "--max-iterations", 1, 10_000, True),
    (["ik", "planar2r", "--method", "numeric", "--pose", "1,1,0,0,0,0"], "--tol", 5e-324, np.inf, False),
    (["plot", "planar2r", "-o", "p.png"], "--elev", -np.inf, np.inf, False),
]


@pytest.mark.parametrize("head,option,lo,hi,integer", SCALAR_CASES, ids=[c[1] for c in SCALAR_CASES])
def test_bad_scalars(folder, head, option, lo, hi, integer):
    @settings(max_examples=corpus(70), deadline=None, derandomize=True)
    @given(_bad_number(lo, hi, integer))
    def case(text):
        if option == "--seed" and text.strip().isdigit():
            return  # any whole number >= 0 is a seed
        if option == "--samples" and _whole_count(text, lo, hi):
            return  # a whole count may be written 1e9 or 1000.0 (issue 17)
        _check(folder, head + [f"{option}={text}"], mentions=[option.lstrip("-")])

    case()


def _whole_count(text: str, lo: int, hi: int) -> bool:
    from decimal import Decimal

    t = text.strip()
    if not re.fullmatch(r"\+?[0-9]{1,20}(\.[0-9]{0,20})?([eE]\+?[0-9]{1,3})?", t):
        return False
    return Decimal(t) == Decimal(t).to_integral_value() and lo <= Decimal(t) <= hi


SIM = ["simulate", "planar2r", "--q0", "0,0"]


_NOT_POSITIVE = st.one_of(_NONFINITE, _GARBAGE, st.just(""), st.floats(max_value=0, allow_nan=False).map(repr))


@SOME
@given(st.one_of(_NOT_POSITIVE, st.sampled_from(["1e6", "1e300", "1e9"])))
def test_simulate_duration(folder, text):
    _check(folder, SIM + ["--duration", text], mentions=["duration"])


@SOME
@given(st.one_of(_NOT_POSITIVE, st.sampled_from(["1e-9", "1e-300"])))
def test_simulate_dt(folder, text):
    _check(folder, SIM + ["--duration", "0.1", "--dt", text], mentions=["dt"])


@pytest.mark.slow
def test_simulate_work_is_capped(folder):
    """Torques within the magnitude bound but making the arm spin wildly: refused after a bounded budget."""
    o = run_cli(SIM + ["--duration", "1", "--tau", "1e8,-1e8"], folder, time_limit=90)
    assert_refused(o, mentions=["evaluations"])


_ROWS_OK = {"vx", "vy", "vz", "wx", "wy", "wz"}


@SOME
@given(st.one_of(_GARBAGE, st.just(","), st.lists(st.sampled_from(sorted(_ROWS_OK)), min_size=2, max_size=4)
                 .filter(lambda r: len(set(r)) < len(r)).map(",".join)))
def test_bad_rows(folder, text):
    _check(folder, ["singularities", "planar2r", "--rows", text], mentions=["rows"])


# --- --lock -------------------------------------------------------------------------------------------------

_BAD_LOCK = st.one_of(
    _GARBAGE,
    st.integers(3, 10**40).map(lambda k: f"q{k}=0"),            # not a joint of planar2r (q1, q2)
    st.integers(0, 0).map(lambda k: "q0=0"),
    st.sampled_from(["q1", "q1=", "=0", "q=0", "qx=0", "Q1=0", "q1==0", "q\u0661=0", "q1=nan", "q1=1e400",
                     "q1=1e300", "q²=0"]),
    st.integers(1000, 100_000).map(lambda k: "q" + "1" * k + "=0"),
    st.integers(1000, 100_000).map(lambda k: "q1=" + " " * k),
    st.integers(1000, 100_000).map(lambda k: " " * k + "q1"),
)


@MANY
@given(_BAD_LOCK)
def test_bad_lock(folder, text):
    o = _check(folder, ["ik", "planar2r", "--pose", "1,1,0,0,0,0", f"--lock={text}"], mentions=["lock"])
    assert o.seconds < 3, o.describe()  # CPU seconds


def test_lock_parsing_is_linear(folder):
    for k in (10_000, 200_000):
        o = _check(folder, ["ik", "planar2r", "--pose", "1,1,0,0,0,0", "--lock", "q1" + " " * k + "=" + " " * k + "x"],
                   mentions=["lock"])
        assert o.seconds < 2, o.describe()  # CPU seconds


# --- output paths -------------------------------------------------------------------------------------------

WRITERS = {
    "plot": (["plot", "planar2r", "-q", "0.1,0.2"], ".png"),
    "animate": (["animate", "planar2r", "--from", "0,0", "--to", "0.1,0.1", "--duration", "0.2", "--fps", "5"], ".gif"),
    "view": (["view", "planar2r"], ".html"),
    "workspace": (["workspace", "planar2r", "--samples", "200"], ".png"),
    "simulate": (["simulate", "planar2r", "--q0", "0,0", "--duration", "0.05"], ".png"),
}
ALLOWED = {"plot": {".png", ".svg", ".pdf"}, "workspace": {".png", ".svg", ".pdf"}, "simulate": {".png", ".svg", ".pdf"},
           "animate": {".gif", ".mp4"}, "view": {".html", ".htm"}}
_KINDS = ["dir", "missing", "long", "fifo", "symlink", "existing", "suffix", "empty-suffix", "dev", "empty"]


def _make(folder, kind: str, ext: str, tag: str) -> tuple[str, list[str]]:
    """A bad -o path of ``kind`` (created in folder) and what the error line must name."""
    if kind == "dir":
        (folder / f"d{tag}{ext}").mkdir(exist_ok=True)
        return f"d{tag}{ext}", [f"d{tag}{ext}"]
    if kind == "missing":
        return f"no-such-{tag}/x{ext}", [f"no-such-{tag}"]
    if kind == "long":
        return "n" * (256 + len(tag)) + ext, ["255"]
    if kind == "fifo":
        p = folder / f"f{tag}{ext}"
        if not p.exists():
            os.mkfifo(p)
        return p.name, [p.name]
    if kind == "symlink":
        p = folder / f"l{tag}{ext}"
        if not p.is_symlink():
            p.symlink_to("/dev/full")
        return p.name, [p.name]
    if kind == "existing":
        p = folder / f"e{tag}{ext}"
        p.write_bytes(b"the user's own file " + tag.encode())
        return p.name, [p.name, "--no-clobber"]  # refused with --no-clobber only
    if kind == "suffix":
        return f"out-{tag}.txt", [f"out-{tag}.txt"]
    if kind == "empty-suffix":
        return f"out{tag}", [f"out{tag}"]
    if kind == "empty":
        return "", ["-o"]
    return "/dev/null", ["/dev/null"]


@pytest.mark.parametrize("command", sorted(WRITERS))
def test_bad_output_paths(folder, command):
    argv, ext = WRITERS[command]

    @settings(max_examples=corpus(45), deadline=None, derandomize=True)
    @given(st.sampled_from(_KINDS), st.text(alphabet="abcdefghij0123456789-_", min_size=1, max_size=12),
           st.sampled_from(["", ".PNG", ".svg", ".pdf", ".gif", ".mp4", ".html", ".yaml", ".png.txt"]))
    def case(kind, tag, other_ext):
        if kind == "suffix":
            e = ".txt" if other_ext.lower() in ALLOWED[command] else other_ext
            path, mentions = f"out-{tag}{e}", [f"out-{tag}{e}"]
        else:
            path, mentions = _make(folder, kind, ext, tag)
        o = _check(folder, argv + ["-o", path] + ["--no-clobber"] * (kind == "existing"), mentions=mentions)
        assert o.seconds < 5, o.describe()  # CPU seconds

    case()


@pytest.mark.parametrize("command", sorted(WRITERS))
def test_existing_file_replaced_unless_no_clobber(folder, command, tmp_path):
    argv, ext = WRITERS[command]
    (tmp_path / f"mine{ext}").write_bytes(b"keep me")
    assert_refused(run_cli(argv + ["-o", f"mine{ext}", "--no-clobber"], tmp_path), mentions=[f"mine{ext}", "clobber"])
    assert (tmp_path / f"mine{ext}").read_bytes() == b"keep me"
    o = run_cli(argv + ["-o", f"mine{ext}"], tmp_path)
    assert_accepted_quietly(o)
    written = (tmp_path / f"mine{ext}").read_bytes()
    assert written != b"keep me" and len(written) > 100
    assert [p.name for p in tmp_path.iterdir()] == [f"mine{ext}"]  # no temporary file left behind
    umask = os.umask(0)
    os.umask(umask)
    assert (tmp_path / f"mine{ext}").stat().st_mode & 0o777 == 0o666 & ~umask  # as open() would make it


@pytest.mark.parametrize("command", ["plot", "workspace", "simulate", "view", "animate"])
def test_full_disk_leaves_nothing(command, tmp_path, monkeypatch):
    """ENOSPC while writing (simulated): exit 2 naming the path, no partial or temporary file left."""
    import denavit.viz._plot as plot_mod
    import denavit.viz as viz_mod
    import denavit.cli._dynamics as dyn_mod

    def full(target):
        with open(target, "wb") as fh:
            fh.write(b"partial")
        raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setattr(plot_mod, "save_figure", lambda fig, path, dpi=None: full(path))
    monkeypatch.setattr(viz_mod, "write_viewer", lambda robot, path, q=None: full(path))
    monkeypatch.setattr(viz_mod, "animate_robot", lambda robot, qs, path, **kw: full(path))
    monkeypatch.setattr(dyn_mod, "_plot", lambda res, robot, path, deg: full(path))
    argv, ext = WRITERS[command]
    o = run_cli(argv + ["-o", f"out{ext}"], tmp_path)
    assert_refused(o, mentions=[f"out{ext}", "space"])
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("argv", [
    ["workspace", "planar2r", "--samples", "100000000000"],  # streamed since issue 17: 2e7 is fine, 1e11 is not
    ["plot", "planar2r", "--dpi", "100000", "-o", "p.png"],
    ["animate", "planar2r", "--from", "0,0", "--to", "1,1", "--duration", "100000", "-o", "a.gif"],
    ["simulate", "planar2r", "--q0", "0,0", "--duration", "1000", "--dt", "1e-6"],
])
def test_memory_bombs_refused_under_a_memory_limit(tmp_path, argv):
    from _hostile import run_cli_limited

    assert_refused(run_cli_limited(argv, tmp_path), mentions=[argv[-3] if argv[-2] == "-o" else argv[-2]])


def test_os_error_on_a_named_file_is_exit_2(tmp_path, monkeypatch):
    """An OSError reaching main() (a robot path that is a folder, unreadable ...) is exit 2 naming the path."""
    import denavit.cli._jacobian as jac

    def boom(args):
        raise IsADirectoryError(errno.EISDIR, "Is a directory", "some-folder")

    monkeypatch.setattr(jac, "load", boom)
    assert_refused(run_cli(["jacobian", "some-folder", "-q", "0,0"], tmp_path), mentions=["some-folder", "directory"])


# --- work caps for symbolic routes --------------------------------------------------------------------------

def _chain(n: int) -> str:
    rows = "\n".join(f"  - {{a: 0.1, alpha: {'pi/2' if k % 2 else '-pi/2'}, d: 0.05, theta: q}}" for k in range(n))
    return f"name: chain{n}\nconvention: standard\njoints:\n{rows}\n"


@pytest.mark.parametrize("argv,limit", [
    (["jacobian", "big.yaml", "--symbolic"], 8),
    (["jacobian", "big.yaml"], 8),
    (["jacobian", "big.yaml", "--analytic", "rpy"], 8),
    (["fk", "big.yaml", "--symbolic"], 8),
    (["singularities", "big.yaml"], 7),
    (["singularities", "big.yaml", "--rows", "vx,vy,vz"], 7),
])
@pytest.mark.parametrize("extra", [1, 4, 24])
def test_symbolic_routes_refuse_large_arms(tmp_path, argv, limit, extra):
    from denavit.cli._common import MAX_SYMBOLIC_ANALYSIS_JOINTS, MAX_SYMBOLIC_JOINTS

    assert limit == (MAX_SYMBOLIC_JOINTS if argv[0] in ("fk", "jacobian") else MAX_SYMBOLIC_ANALYSIS_JOINTS)
    n = limit + extra
    o = run_cli(argv, tmp_path, files={"big.yaml": _chain(n)}, time_limit=5)
    assert_refused(o, mentions=[f"{n} joints", f"limited to {limit}"])


def test_symbolic_dynamics_refuses_large_arms(tmp_path):
    rows = "\n".join(f"  - {{a: 0.1, alpha: pi/2, d: 0, theta: q, inertia: {{mass: 1, com: [0, 0, 0], "
                     f"inertia: [0.01, 0.01, 0.01, 0, 0, 0]}}}}" for _ in range(8))
    o = run_cli(["dynamics", "d8.yaml", "--symbolic"], tmp_path, time_limit=5,
                files={"d8.yaml": f"name: d8\nconvention: standard\njoints:\n{rows}\n"})
    assert_refused(o, mentions=["8 joints", "limited to 7"])


def test_numeric_jacobian_of_a_large_arm_is_quick_and_right(tmp_path):
    """32 joints numerically: allowed, fast, and J matches finite differences of the end-effector position."""
    from denavit.io import load_robot
    from denavit.numeric import forward_kinematics

    (tmp_path / "big.yaml").write_text(_chain(32))
    q = np.random.default_rng(3).uniform(-1, 1, 32)
    o = run_cli(["jacobian", "big.yaml", "-q", ",".join(repr(float(v)) for v in q), "--json"], tmp_path)
    assert_accepted_quietly(o)
    assert o.seconds < 5, o.describe()  # CPU seconds
    J = np.array(json.loads(o.out)["J"])
    robot = load_robot(str(tmp_path / "big.yaml"))
    h = 1e-6
    for k in range(32):
        dq = np.zeros(32)
        dq[k] = h
        dp = (forward_kinematics(robot, q + dq)[:3, 3] - forward_kinematics(robot, q - dq)[:3, 3]) / (2 * h)
        assert np.allclose(J[:3, k], dp, atol=1e-6)


# --- warnings -----------------------------------------------------------------------------------------------

def test_library_warning_is_one_line_and_json_stays_clean(tmp_path):
    """The ZYZ angles of a planar arm are at their representation singularity: a warning, in one line."""
    o = run_cli(["jacobian", "planar2r", "-q", "0.1,0.2", "--analytic", "zyz", "--json"], tmp_path)
    assert_accepted_quietly(o)
    lines = o.err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("denavit jacobian: warning: ") and "singularity" in lines[0]
    assert "UserWarning" not in o.err and "warnings.warn" not in o.err
    json.loads(o.out)


def test_no_runtime_warning_at_a_singular_configuration(tmp_path):
    o = run_cli(["singularities", "planar2r", "-q", "0,0", "--json"], tmp_path)
    assert_accepted_quietly(o)
    assert "RuntimeWarning" not in o.err and "divide" not in o.err


# --- output polish: noise printed as 0, ik --all lists solutions outside the limits -------------------------

_NUMBER = re.compile(r"(?<![\w.])-?\d+(?:\.\d+)?(?:e[-+]?\d+)?(?![\w.])")


@settings(max_examples=corpus(12), deadline=None, derandomize=True)
@given(st.lists(st.floats(-1.5, 1.5), min_size=6, max_size=6), st.sampled_from(["base", "tool"]))
def test_no_rounding_noise_in_text(tmp_path_factory, qs, frame):
    folder = tmp_path_factory.mktemp("noise")
    q = ",".join(f"{v!r}" for v in qs)
    outputs = [run_cli(argv + ["--ignore-limits"], folder) for argv in (
        ["velocity", "puma560", "-q", q, "--qd", "1,0,0,0,0,0", "--frame", frame, "--steps"],
        ["statics", "puma560", "-q", q, "--wrench", "1,0,0", "--frame", frame, "--steps"],
        ["jacobian", "puma560", "-q", q, "--frame", frame],
        ["dynamics", "puma560", "-q", q],
    )]
    for o in outputs:
        assert_accepted_quietly(o)
        for tok in _NUMBER.findall(o.out):
            v = float(tok)
            assert v == 0 or abs(v) > 1e-12, f"rounding noise {tok!r} printed\n{o.out}"


@settings(max_examples=corpus(200), deadline=None, derandomize=True)
@given(st.lists(st.one_of(st.floats(-1e6, 1e6), st.floats(-1e-15, 1e-15)), min_size=1, max_size=8))
def test_numbers_text(values):
    from denavit.cli._common import NOISE, numbers_text

    parts = numbers_text(values).split(", ")
    scale = max(abs(v) for v in values)
    for v, t in zip(values, parts):
        if abs(v) <= NOISE * max(1.0, scale):
            assert t == "0"
        else:
            assert np.isclose(float(t), v, rtol=1e-5, atol=0)


def test_ik_all_lists_solutions_outside_the_limits(tmp_path):
    from denavit.io import load_robot
    from denavit.numeric import forward_kinematics

    robot = load_robot("puma560")
    q = np.array([0.1, 0.2, 0.3, 0.4, 0.5, 0.6])
    o = run_cli(["ik", "puma560", "--from-q", ",".join(map(str, q)), "--all"], tmp_path)
    assert_accepted_quietly(o)
    data = json.loads(run_cli(["ik", "puma560", "--from-q", ",".join(map(str, q)), "--json"], tmp_path).out)
    lines = o.out.splitlines()
    start = next(i for i, line in enumerate(lines) if "outside the joint limits" in line)
    outside = [line for line in lines[start + 1:] if "outside limits:" in line]
    assert len(outside) == len(data["outside_limits"]) > 0
    T = forward_kinematics(robot, q)
    lim = robot.q_limits
    for line in outside:
        vals = np.array([float(v) for v in line.split("[")[1].split("]")[0].split(",")])
        assert np.allclose(forward_kinematics(robot, vals), T, atol=1e-4)  # a real solution of the target
        marked = set(line.split("outside limits:")[1].replace(" ", "").split(","))
        really = {f"q{j + 1}" for j in range(6) if not lim[j, 0] <= vals[j] <= lim[j, 1]}
        assert marked == really and really
    # without --all they are counted, not listed
    o2 = run_cli(["ik", "puma560", "--from-q", ",".join(map(str, q))], tmp_path)
    assert "--all lists them" in o2.out and "outside limits:" not in o2.out


def test_ik_all_with_huge_limits(tmp_path):
    """Limits far beyond a turn (±1000 rad, the most a robot file allows): seeds stay finite, solutions right.
    Limits of ±1e308 (an internal error once) are refused by the robot file's checks, or solved the same way."""
    def wide(x):
        return ("name: wide\nconvention: standard\njoints:\n"
                f"  - {{a: 1, alpha: 0, d: 0, theta: q, limits: [-{x}, {x}]}}\n"
                f"  - {{a: 1, alpha: 0, d: 0, theta: q, limits: [-{x}, {x}]}}\n")

    for x in ("1000", "1e308"):
        for method in ("numeric", "analytic"):
            o = run_cli(["ik", "wide.yaml", "--pose", "1,1,0,0,0,0", "--all", "--method", method, "--json"],
                        tmp_path, files={"wide.yaml": wide(x)})
            if x == "1e308" and o.code == 2:
                assert_refused(o, mentions=["wide.yaml"])
                continue
            assert_accepted_quietly(o)
            sols = np.array(json.loads(o.out)["solutions"])
            assert len(sols) >= 1 and np.all(np.isfinite(sols))
            for s in sols:  # each reaches (1, 1): independent check by the planar 2R formula
                assert np.allclose([np.cos(s[0]) + np.cos(s[0] + s[1]), np.sin(s[0]) + np.sin(s[0] + s[1])],
                                   [1, 1], atol=1e-6)


@pytest.mark.parametrize("command", ["jacobian", "velocity", "statics", "singularities", "ik", "dynamics",
                                     "simulate", "plot", "animate", "view", "workspace"])
def test_every_command_takes_json_and_deg(command):
    from denavit.cli import build_parser

    sub = next(a for a in build_parser()._actions if a.dest == "command")
    opts = {s for a in sub.choices[command]._actions for s in a.option_strings}
    assert {"--json", "--deg"} <= opts


def test_non_finite_results_are_refused_not_printed():
    """The last guard: a result that is inf/NaN from accepted values is a ParseError (exit 2), never printed."""
    from denavit.cli._common import check_values, require_finite
    from denavit.errors import ParseError

    require_finite("x", np.eye(3), None)
    for bad in (np.array([1.0, np.inf]), np.array([[np.nan]])):
        with pytest.raises(ParseError, match="not finite"):
            require_finite("x", np.eye(2), bad)
    assert check_values(np.array([1e9, -1e9]), "v").tolist() == [1e9, -1e9]
    with pytest.raises(ParseError, match="v: value 2"):
        check_values(np.array([0.0, 1.0000001e9]), "v")


def test_degrees_warning_from_a_robot_file_is_one_line(tmp_path):
    """A newcomer's slip (alpha: 90 without angle_unit: deg) warns once, in the CLI's one-line format."""
    from denavit import errors

    if not hasattr(errors, "DenavitWarning"):
        pytest.skip("DenavitWarning not defined yet")
    yaml = ("name: slip\nconvention: standard\njoints:\n"
            "  - {a: 1, alpha: 90, d: 0, theta: q}\n  - {a: 1, alpha: 0, d: 0, theta: q}\n")
    for extra in ([], ["--json"]):
        o = run_cli(["jacobian", "slip.yaml", "-q", "0.1,0.2"] + extra, tmp_path, files={"slip.yaml": yaml})
        assert_accepted_quietly(o)
        lines = o.err.strip().splitlines()
        assert len(lines) == 1 and lines[0].startswith("denavit jacobian: warning: ") and "deg" in lines[0], o.err
        if extra:
            json.loads(o.out)
    # with an error as well, only the error line is printed
    o = run_cli(["jacobian", "slip.yaml", "-q", "0.1,x"], tmp_path, files={"slip.yaml": yaml})
    assert_refused(o, mentions=["q"])
