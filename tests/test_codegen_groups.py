"""Registered kernels (codegen.register_kernel): compiled by group on first use, cached on disk, exported.

The toy kernels of tests/_toy_kernels.py (q·q; (q[:2]·w, q_0 sin w_0, w_1) with w of length 2; Σq for arms with
inertial data) are checked against numpy computing the same formulas on the same inputs.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import textwrap
from pathlib import Path

import _toy_kernels  # noqa: F401  (registers the toy kernels)
import numpy as np
import pytest

import denavit
from denavit.cli import main
from denavit.codegen import export_sources, numba_available, register_kernel
from denavit.errors import ModelError, ShapeError

TESTS = Path(__file__).resolve().parent


@pytest.fixture
def cache(tmp_path, monkeypatch):
    folder = tmp_path / "kernels"
    monkeypatch.setenv("DENAVIT_CACHE_DIR", str(folder))
    return folder


def modules(folder: Path) -> list[str]:
    return sorted(p.name for p in folder.glob("_denavit_kernels_*.py"))


def test_group_is_built_on_first_call_not_at_compile(cache, rng):
    from dataclasses import replace

    # gravity of its own: a key no other test (in this process) has loaded, so its files are written here
    robot = replace(denavit.load_robot("puma560"), gravity=(0.0, 0.0, -9.81 + rng.uniform(0.0, 1e-3)))
    fast = denavit.compile(robot, backend="numpy")
    assert "toy_qq" not in fast.kernels and len(modules(cache)) == 1
    q = rng.uniform(-2, 2, 6)
    np.testing.assert_allclose(fast._call("toy_qq", (q,), ("q",)), [np.dot(q, q)], rtol=1e-14)
    assert {"toy_qq", "toy_mix", "toy_sum"} <= set(fast.kernels) and len(modules(cache)) == 2
    Q, W = rng.uniform(-2, 2, (4, 1, 6)), rng.uniform(-2, 2, (3, 2))  # batch axes (4, 1) and (3,) broadcast
    out = fast._call("toy_mix", (Q, W), ("q", "w"))
    assert out.shape == (4, 3, 3)
    np.testing.assert_allclose(out[..., 0], Q[..., 0] * W[:, 0] + Q[..., 1] * W[:, 1], rtol=1e-14)
    np.testing.assert_allclose(out[..., 1], Q[..., 0] * np.sin(W[:, 0]), rtol=1e-14)
    np.testing.assert_allclose(out[..., 2], np.broadcast_to(W[:, 1], (4, 3)), rtol=0)
    again = denavit.compile(robot, backend="numpy")  # another object: the group module comes from the cache
    np.testing.assert_allclose(again._call("toy_sum", (Q[:, 0],), ("q",))[:, 0], Q[:, 0].sum(-1), rtol=1e-14)
    assert len(modules(cache)) == 2


def test_group_inputs_are_checked_and_refusals_explained(cache):
    fast = denavit.compile(denavit.load_robot("puma560"), backend="numpy")
    with pytest.raises(ShapeError, match=r"w: expected shape \(\.\.\., 2\), got \(5,\)"):
        fast._call("toy_mix", (np.zeros(6), np.zeros(5)), ("q", "w"))
    with pytest.raises(ShapeError, match=r"q: expected shape \(\.\.\., 6\) for a 6-joint robot"):
        fast._call("toy_qq", (np.zeros(3),), ("q",))
    with pytest.raises(ShapeError, match="do not broadcast"):
        fast._call("toy_mix", (np.zeros((3, 6)), np.zeros((4, 2))), ("q", "w"))
    scara = denavit.compile(denavit.load_robot("scara"), backend="numpy")  # no inertial data
    assert scara._call("toy_qq", (np.ones(4),), ("q",))[0] == 4.0
    with pytest.raises(ModelError, match="inertia"):
        scara._call("toy_sum", (np.ones(4),), ("q",))


def test_compile_kernels_names_registered_ones(cache):
    robot = denavit.load_robot("planar2r")
    fast = denavit.compile(robot, backend="numpy", kernels=["fk", "toy_qq"])
    assert fast.kernels == ("fk", "toy_qq")  # the group was built now, as asked
    assert fast._call("toy_qq", ([3.0, 4.0],), ("q",))[0] == 25.0
    with pytest.raises(ModelError, match="left it out"):
        fast._call("toy_mix", ([1.0, 2.0], [1.0, 1.0]), ("q", "w"))
    with pytest.raises(ModelError, match="left it out"):
        fast.jacobian([0.0, 0.0])
    with pytest.raises(ValueError, match="unknown kernels.*toy_qq"):
        denavit.compile(robot, backend="numpy", kernels=["fk", "nope"])


def test_register_kernel_refuses_bad_names_and_docs():
    def trace(robot, friction):  # pragma: no cover - never traced
        raise AssertionError

    shape = {"inputs": lambda n: (("q", n),), "shape": lambda n: (1,), "trace": trace}
    with pytest.raises(ValueError, match="lower-case identifier"):
        register_kernel("Bad-Name", group="toys", doc="x", **shape)
    with pytest.raises(ValueError, match="lower-case identifier"):
        register_kernel("fine", group="a group", doc="x", **shape)
    with pytest.raises(ValueError, match="built-in"):
        register_kernel("rnea", group="toys", doc="x", **shape)
    with pytest.raises(ValueError, match="one line"):
        register_kernel("fine", group="toys", doc='a """ quote', **shape)
    with pytest.raises(ValueError, match="already registered"):
        register_kernel("toy_qq", group="elsewhere", doc="x", **shape)


def test_export_includes_registered_kernels_when_asked(tmp_path, rng):
    robot = denavit.load_robot("puma560")
    assert "toy_qq" not in export_sources(robot, "python", "arm")["arm.py"]
    text = export_sources(robot, "python", "arm", kernels=["fk", "toy_qq", "toy_mix"])["arm.py"]
    (tmp_path / "arm.py").write_text(text)
    q, w = rng.uniform(-1, 1, (5, 6)), rng.uniform(-1, 1, 2)
    code = f"import arm, numpy as np; print(arm.toy_mix(np.array({q.tolist()}), np.array({w.tolist()})).tolist())"
    run = subprocess.run([sys.executable, "-c", code], cwd=tmp_path, capture_output=True, text=True, check=True)
    got = np.array(json.loads(run.stdout))
    np.testing.assert_allclose(got[:, 0], q[:, :2] @ w, rtol=1e-14)
    header = export_sources(robot, "c", "arm", kernels="all")["arm.h"]
    assert "void arm_toy_mix(const double q[6], const double w[2], double out[3]);" in header
    assert main(["export", "puma560", "--lang", "c", "-o", str(tmp_path / "c"), "--kernels", "fk,toy_qq"]) == 0
    written = (tmp_path / "c" / "puma560.h").read_text()
    assert "puma560_toy_qq(" in written and "puma560_toy_mix(" not in written and "puma560_rnea(" not in written
    assert main(["export", "puma560", "--lang", "c", "-o", str(tmp_path / "d"), "--kernels", "fk,nope"]) == 2


SCRIPT = textwrap.dedent("""
    import numpy as np, denavit, _toy_kernels
    fast = denavit.compile(denavit.load_robot("planar2r"))
    before = "toy_qq" in fast.kernels
    one = fast._call("toy_qq", (np.array([3.0, 4.0]),), ("q",))[0]
    many = fast._call("toy_qq", (np.array([[1.0, 2.0], [2.0, 2.0], [0.0, 1.0], [1.0, 1.0], [3.0, 0.0]]),), ("q",))
    m = fast._groups["toys"][0]
    hits = sum(m.toy_qq_1.stats.cache_hits.values()) + sum(m.group_n.stats.cache_hits.values())
    misses = sum(m.toy_qq_1.stats.cache_misses.values()) + sum(m.group_n.stats.cache_misses.values())
    print(fast.backend, before, one, many[:, 0].tolist(), hits, misses)
""")


@pytest.mark.skipif(not numba_available(), reason="numba not installed")
def test_numba_group_compiled_on_first_call_and_loaded_by_the_next_process(tmp_path):
    env = {**os.environ, "DENAVIT_CACHE_DIR": str(tmp_path),
           "PYTHONPATH": os.pathsep.join([str(TESTS), os.environ.get("PYTHONPATH", "")])}
    runs = [subprocess.run([sys.executable, "-c", SCRIPT], capture_output=True, text=True, env=env, check=True)
            .stdout.split(maxsplit=4) for _ in range(2)]
    for backend, before, one, rest in ((r[0], r[1], r[2], r[3] + " " + r[4]) for r in runs):
        assert backend == "numba" and before == "False" and float(one) == 25.0
        assert rest.startswith("[5.0, 8.0, 1.0, 2.0, 9.0]")
    hits1, misses1 = map(int, runs[0][4].split()[-2:])
    hits2, misses2 = map(int, runs[1][4].split()[-2:])
    assert misses1 == 2 and hits1 == 0  # compiled: the single and the group's batch function
    assert hits2 == 2 and misses2 == 0  # the second process loads both from the disk cache
