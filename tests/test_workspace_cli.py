"""`denavit workspace` and `denavit reachability` on the command line: results, data files, hostile input."""

from __future__ import annotations

import json
import socket

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

from _hostile import assert_refused, run_cli

TWO_R = """name: two-r
convention: standard
joints:
  - {a: 1.0, alpha: 0, d: 0, theta: q, limits: [-pi, pi]}
  - {a: 0.5, alpha: 0, d: 0, theta: q, limits: [-pi, pi]}
"""


def _ok(o):
    assert o.code == 0 and not o.hung, o.describe()
    assert "Traceback" not in o.err and o.err == "", o.describe()  # quiet: no progress when stderr is no tty
    return json.loads(o.out) if o.out.lstrip().startswith("{") else o.out


def test_workspace_refine_narrows_the_annulus_interval_and_saves_the_sub_cells(tmp_path):
    from denavit.scale import load_occupancy

    argv = ["workspace", "arm.yaml", "--samples", "2.5e5", "--seed", "3", "--resolution", "0.2", "--json"]
    plain = _ok(run_cli(argv + ["--refine", "0"], tmp_path, files={"arm.yaml": TWO_R}))
    data = _ok(run_cli(argv + ["--refine", "8", "--data", "w.npz"], tmp_path, files={"arm.yaml": TWO_R}))
    exact = np.pi * (1.5**2 - 0.5**2)
    (lo, hi), (plo, phi) = data["interval"], plain["interval"]
    assert lo <= exact <= hi and plo <= exact <= phi and hi - lo < 0.5 * (phi - plo)
    assert data["refine"] == 8 and data["refined_cells"] > 0 and data["resolution"] < 0.2 and plain["refine"] == 0
    ws = load_occupancy(tmp_path / "w.npz")
    assert ws.refinement.factor == 8 and [ws.estimate.low, ws.estimate.high] == data["interval"]


@pytest.mark.slow
def test_workspace_json_interval_holds_the_annulus_and_data_loads(tmp_path):
    pytest.importorskip("matplotlib")
    o = run_cli(["workspace", "arm.yaml", "--samples", "4e5", "--seed", "3", "-o", "w.png", "--data", "w.npz",
                 "--json"], tmp_path, files={"arm.yaml": TWO_R})
    data = _ok(o)
    exact = np.pi * (1.5**2 - 0.5**2)
    lo, hi = data["interval"]
    assert data["planar"] and data["volume"] == 0.0 and lo <= exact <= hi and lo <= data["area"] <= hi
    assert data["samples"] == 400_000 and data["seed"] == 3
    with np.load(tmp_path / "w.npz", allow_pickle=False) as z:
        assert int(z["counts"].sum()) == 400_000 and z["counts"].ndim == 2
        assert float(z["reach"]) == pytest.approx(data["reach"])
    assert (tmp_path / "w.png").stat().st_size > 1000
    assert sorted(p.name for p in tmp_path.iterdir()) == ["arm.yaml", "w.npz", "w.png"]


@pytest.mark.slow
def test_workspace_text_and_same_numbers_on_processes(tmp_path):
    base = ["workspace", "puma560", "--samples", "150000", "--seed", "5", "--json"]
    a = _ok(run_cli(base + ["--scheduler", "synchronous"], tmp_path))
    b = _ok(run_cli(base + ["--scheduler", "processes", "--workers", "2"], tmp_path))
    for key in ("voxels", "volume", "interval", "bounds_min", "bounds_max", "reach", "resolution"):
        assert a[key] == b[key], key
    text = _ok(run_cli(base[:-1], tmp_path))
    assert "volume ≈" in text and "between" in text and "seed 5" in text


@pytest.mark.slow
def test_reachability_command(tmp_path):
    pytest.importorskip("matplotlib")
    data = _ok(run_cli(["reachability", "puma560", "--resolution", "0.3", "--orientations", "8", "-o", "r.png",
                        "--data", "r.npz", "--json"], tmp_path))
    assert data["orientations"] == 8 and data["method"] == "analytic" and data["voxels_reached"] > 0
    with np.load(tmp_path / "r.npz", allow_pickle=False) as z:
        f = z["fraction"]
        assert f.min() >= 0 and f.max() <= 1 and int((f > 0).sum()) == data["voxels_reached"]
        assert np.all(z["manipulability"][f == 0] == 0)
    assert (tmp_path / "r.png").stat().st_size > 1000


# ---- hostile ---------------------------------------------------------------------------------------------------

@pytest.mark.parametrize("argv,mention", [
    (["workspace", "planar2r", "--samples", "1e11"], "samples"),
    (["workspace", "planar2r", "--samples", "0"], "samples"),
    (["workspace", "planar2r", "--samples", "2.5e2.5"], "samples"),
    (["workspace", "planar2r", "--samples", "nan"], "samples"),
    (["workspace", "planar2r", "--samples", "1" + "0" * 400], "samples"),
    (["workspace", "puma560", "--resolution", "1e-5"], "resolution"),
    (["workspace", "puma560", "--resolution", "1e6"], "resolution"),
    (["workspace", "planar2r", "--workers", "0"], "workers"),
    (["workspace", "planar2r", "--workers", "100000"], "workers"),
    (["workspace", "planar2r", "--data", "w.txt"], "--data"),
    (["workspace", "planar2r", "--data", "nofolder/w.npz"], "nofolder"),
    (["workspace", "planar2r", "--scheduler", "tcp://"], "scheduler"),
    (["workspace", "planar2r", "--scheduler", "cluster"], "scheduler"),
    (["workspace", "planar2r", "--refine", "3"], "refine"),
    (["workspace", "planar2r", "--refine", "16"], "refine"),
    (["reachability", "puma560", "--orientations", "0"], "orientations"),
    (["reachability", "puma560", "--orientations", "99999999"], "orientations"),
    (["reachability", "puma560", "--resolution", "0.001"], "resolution"),
    (["reachability", "puma560", "--resolution", "0"], "resolution"),
    (["reachability", "puma560", "--ik", "magic"], "ik"),
    (["reachability", "puma560", "--scheduler", "host:99999"], "scheduler"),
])
def test_bad_sizes_and_schedulers_are_one_line(tmp_path, argv, mention):
    assert_refused(run_cli(argv, tmp_path), mentions=[mention])


@settings(max_examples=40, deadline=None)
@given(st.text(min_size=0, max_size=80).filter(lambda s: s.strip() not in ("threads", "processes", "synchronous",
                                                                          "auto", "dask")
                                               and not s.startswith("-")))
def test_any_bad_scheduler_text_is_one_line(tmp_path_factory, text):
    from denavit.scale import check_scheduler
    from denavit.errors import ParseError

    try:
        check_scheduler(text)
    except ParseError:
        pass
    else:
        return  # a well-formed address: would try to connect (covered below)
    assert_refused(run_cli(["workspace", "planar2r", "--scheduler", text], tmp_path_factory.mktemp("s")),
                   mentions=["scheduler"])


def test_unreachable_scheduler_is_one_line(tmp_path, monkeypatch):
    pytest.importorskip("distributed")
    import denavit.scale._cluster as cluster_module

    monkeypatch.setattr(cluster_module, "CONNECT_TIMEOUT", 1.0)
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    o = run_cli(["workspace", "planar2r", "--scheduler", f"tcp://127.0.0.1:{port}", "--data", "w.npz"], tmp_path)
    assert_refused(o, mentions=[f"127.0.0.1:{port}"])
    assert o.seconds < 15


def test_existing_data_file_is_kept_with_no_clobber(tmp_path):
    (tmp_path / "w.npz").write_bytes(b"mine")
    assert_refused(run_cli(["workspace", "planar2r", "--samples", "200", "--data", "w.npz", "--no-clobber"],
                           tmp_path), mentions=["w.npz", "--no-clobber"])
    assert (tmp_path / "w.npz").read_bytes() == b"mine"
    _ok(run_cli(["workspace", "planar2r", "--samples", "200", "--data", "w.npz"], tmp_path))
    assert (tmp_path / "w.npz").read_bytes()[:2] == b"PK"  # a zip (.npz), replaced


def test_reachability_of_an_arm_without_full_pose_is_one_line(tmp_path):
    o = run_cli(["reachability", "planar2r"], tmp_path)
    assert o.code in (1, 2) and len(o.err.strip().splitlines()) == 1 and "6 or more joints" in o.err
    assert o.out == "" and "Traceback" not in o.err


@pytest.mark.slow
@pytest.mark.parametrize("scheduler", ["threads", "processes"])
def test_ctrl_c_stops_cleanly(tmp_path, scheduler):
    """SIGINT mid-run: exit 130 within seconds, one line on stderr, no traceback, no partial --data file."""
    import os
    import signal
    import re
    import subprocess
    import sys
    import threading
    import time

    import importlib.util

    if importlib.util.find_spec("numba") is not None:  # the run's kernel from the cache: the signal lands mid-run,
        import numpy as np  # not in numba's first compile of it (seconds on a cold CI cache, not interruptible)

        import denavit

        denavit.compile(denavit.load_robot("puma560"), kernels=["position"]).position(np.zeros((4, 6)))
    proc = subprocess.Popen([sys.executable, "-m", "denavit", "workspace", "puma560", "--samples", "1e9",
                             "--scheduler", scheduler, "--workers", "2", "--data", "w.npz", "--progress"],
                            cwd=tmp_path, stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    err = bytearray()
    reader = threading.Thread(target=lambda: [err.extend(c) for c in iter(lambda: proc.stderr.read1(4096), b"")],
                              daemon=True)
    reader.start()
    deadline = time.monotonic() + 180  # the first progress redraw: a task is done, the run is under way
    while b"%" not in err and proc.poll() is None and time.monotonic() < deadline:
        time.sleep(0.2)
    assert b"%" in err, bytes(err)[-800:]
    proc.send_signal(signal.SIGINT)
    t0 = time.perf_counter()
    proc.wait(timeout=120)
    reader.join(60)
    assert proc.returncode == 130, err
    assert time.perf_counter() - t0 < 60  # an interrupt answered in about a second; 60 s holds on a busy machine
    lines = [t.strip() for t in re.split(r"[\r\n]", err.decode(errors="replace"))]
    lines = [t for t in lines if t and not re.match(r"^\d+(\.\d+)?%", t)]  # progress redraws aside
    assert proc.stdout.read() == b"" and lines == ["denavit: interrupted"], lines
    assert os.listdir(tmp_path) == []


def test_reachability_on_dask_starts_one_cluster_for_the_screen_and_the_map(tmp_path, monkeypatch):
    """`--scheduler dask` runs the position screen and the map on one LocalCluster (counted at its constructor;
    built in-process here to keep the test cheap), closed at the end; the map equals the synchronous one."""
    distributed = pytest.importorskip("distributed")
    import denavit
    from denavit.scale import reach_bound
    from denavit.scale._sampler import MIN_CELLS

    assert 2 * reach_bound(denavit.load_robot("ur5"))[1] / 0.2 > MIN_CELLS  # fine enough for the screen to run

    real, started = distributed.LocalCluster, []

    def counting(*args, **kwargs):
        started.append(real(*args, **{**kwargs, "processes": False}))
        return started[-1]

    monkeypatch.setattr(distributed, "LocalCluster", counting)
    monkeypatch.setattr("denavit.scale._reach.SCREEN_SAMPLES", 2**17)  # a smaller screen, the same in both runs
    argv = ["reachability", "ur5", "--resolution", "0.2", "--orientations", "4", "--json", "--seed", "5"]
    ref = _ok(run_cli(argv + ["--scheduler", "synchronous", "--data", "s.npz"], tmp_path))
    assert ref["voxels_reached"] > 0
    got = _ok(run_cli(argv + ["--scheduler", "dask", "--workers", "2", "--data", "d.npz"], tmp_path))
    assert len(started) == 1 and started[0].status.name == "closed"
    assert {k: v for k, v in got.items() if k not in ("scheduler", "data")} == \
        {k: v for k, v in ref.items() if k not in ("scheduler", "data")}
    with np.load(tmp_path / "s.npz") as s, np.load(tmp_path / "d.npz") as d:
        for key in ("fraction", "manipulability"):
            assert np.array_equal(s[key], d[key]), key
