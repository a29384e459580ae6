"""denavit export: the C99 source compiles warning-free and, called through ctypes, gives the library's
numbers; the numpy-only Python module does too.  The library side is the plain numeric engine
(forward_kinematics, geometric_jacobian, rnea, mass_matrix, … — checked against Pinocchio elsewhere)."""

from __future__ import annotations

import ctypes
import importlib.util
import shutil
import subprocess
import sys

import numpy as np
import pytest
from _hostile import assert_refused, run_cli
from test_dynamics_numeric import random_robot as random_dynamic_robot, random_state

import denavit
from denavit.codegen import export_sources

CC = shutil.which("cc") or shutil.which("gcc")


def reference(robot, q, qd, qdd):
    """What each exported kernel must return, from the plain numeric functions."""
    out = {"fk": denavit.forward_kinematics(robot, q), "frames": denavit.link_transforms(robot, q),
           "jacobian0": denavit.geometric_jacobian(robot, q, "base"),
           "jacobiane": denavit.geometric_jacobian(robot, q, "tool")}
    if any(link.inertia is not None for link in robot.links):
        tau = denavit.rnea(robot, q, qd, qdd)
        out.update(rnea=tau, mass_matrix=denavit.mass_matrix(robot, q), gravity=denavit.gravity_torques(robot, q),
                   coriolis=denavit.coriolis_vector(robot, q, qd),
                   forward_dynamics=denavit.forward_dynamics(robot, q, qd, tau))
    return out


ROBOTS = ["puma560", "panda", "stanford", "random"]


def _robot(name):
    if name == "random":  # modified or standard, prismatic, fixed rows, motor inertia, friction, base
        return random_dynamic_robot(np.random.default_rng(77), n=5, motor=True, friction=True)
    return denavit.load_robot(name)


@pytest.mark.skipif(CC is None, reason="no C compiler")
@pytest.mark.parametrize("name", ROBOTS)
def test_c_export_compiles_cleanly_and_matches_the_library(name, tmp_path):
    robot = _robot(name)
    files = export_sources(robot, "c", prefix="arm")
    for file, text in files.items():
        (tmp_path / file).write_text(text)
    lib = tmp_path / "libarm.so"
    done = subprocess.run([CC, "-std=c99", "-Wall", "-Wextra", "-Werror", "-pedantic", "-O2", "-shared", "-fPIC",
                           str(tmp_path / "arm.c"), "-o", str(lib), "-lm"], capture_output=True, text=True)
    assert done.returncode == 0 and done.stderr == "", done.stderr
    c = ctypes.CDLL(str(lib))
    rng = np.random.default_rng(4)
    n = robot.dof
    for k in range(4):
        q, qd, qdd = random_state(rng, robot)
        if k == 0:
            q = np.zeros(n)  # axes aligned / arm stretched: singular for the catalogue arms
        expected = reference(robot, q, qd, qdd)
        inputs = {"fk": (q,), "frames": (q,), "jacobian0": (q,), "jacobiane": (q,), "rnea": (q, qd, qdd),
                  "mass_matrix": (q,), "gravity": (q,), "coriolis": (q, qd),
                  "forward_dynamics": (q, qd, expected.get("rnea"))}
        for kernel, want in expected.items():
            size = n + 1 if kernel == "forward_dynamics" else want.size
            out = np.zeros(size)
            args = [np.ascontiguousarray(x, dtype=float).ctypes.data_as(ctypes.POINTER(ctypes.c_double))
                    for x in inputs[kernel]]
            getattr(c, f"arm_{kernel}")(*args, out.ctypes.data_as(ctypes.POINTER(ctypes.c_double)))
            if kernel == "forward_dynamics":
                assert out[-1] > 0  # M regular
                out = out[:-1]
            np.testing.assert_allclose(out.reshape(want.shape), want, atol=1e-9, err_msg=kernel)


@pytest.mark.parametrize("name", ROBOTS)
def test_python_export_needs_only_numpy_and_matches_the_library(name, tmp_path):
    robot = _robot(name)
    (file, text), = export_sources(robot, "python", prefix="arm_kernels").items()
    assert "denavit" not in [line.split()[1] for line in text.splitlines() if line.startswith(("import ", "from "))]
    path = tmp_path / file
    path.write_text(text)
    spec = importlib.util.spec_from_file_location("arm_kernels", path)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    rng = np.random.default_rng(5)
    q, qd, qdd = random_state(rng, robot, (4,))
    for i in range(4):
        expected = reference(robot, q[i], qd[i], qdd[i])
        np.testing.assert_allclose(mod.fk(q[i]), expected["fk"], atol=1e-12)
        np.testing.assert_allclose(mod.jacobiane(q[i]), expected["jacobiane"], atol=1e-12)
        if "rnea" in expected:
            np.testing.assert_allclose(mod.rnea(q[i], qd[i], qdd[i]), expected["rnea"], atol=1e-9)
            np.testing.assert_allclose(mod.forward_dynamics(q[i], qd[i], expected["rnea"]), qdd[i], atol=1e-8)
    np.testing.assert_allclose(mod.frames(q), denavit.link_transforms(robot, q), atol=1e-12)  # a batch
    np.testing.assert_allclose(mod.jacobian0(q), denavit.geometric_jacobian(robot, q), atol=1e-12)
    if hasattr(mod, "mass_matrix"):
        np.testing.assert_allclose(mod.mass_matrix(q), denavit.mass_matrix(robot, q), atol=1e-9)
        np.testing.assert_allclose(mod.gravity(q), denavit.gravity_torques(robot, q), atol=1e-9)
        np.testing.assert_allclose(mod.coriolis(q, qd), denavit.coriolis_vector(robot, q, qd), atol=1e-9)
    with pytest.raises(ValueError):
        mod.fk(np.zeros(robot.dof + 1))


def test_export_cli_writes_both_languages_and_replaces_existing_files(tmp_path):
    out = tmp_path / "gen"
    done = subprocess.run([sys.executable, "-m", "denavit", "export", "puma560", "--lang", "c", "-o", str(out),
                           "--json"], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    assert sorted(p.name for p in out.iterdir()) == ["puma560.c", "puma560.h"]
    header = (out / "puma560.h").read_text()
    assert "void puma560_fk(const double q[6], double out[16]);" in header and "Usage:" in header
    (out / "puma560.h").write_text("mine")
    again = run_cli(["export", "puma560", "--lang", "c", "-o", str(out), "--no-clobber"], tmp_path, {})
    assert_refused(again, mentions=["puma560.h", "--no-clobber"])
    assert (out / "puma560.h").read_text() == "mine"
    again = run_cli(["export", "puma560", "--lang", "c", "-o", str(out)], tmp_path, {})
    assert again.code == 0, again.err
    assert (out / "puma560.h").read_text() == header  # replaced, by the same text
    assert sorted(p.name for p in out.iterdir()) == ["puma560.c", "puma560.h"]  # no temporary file left
    done = subprocess.run([sys.executable, "-m", "denavit", "export", "puma560", "--lang", "python", "-o", str(out),
                           "--prefix", "puma_fast"], capture_output=True, text=True)
    assert done.returncode == 0 and (out / "puma_fast.py").exists()


@pytest.mark.parametrize("argv, mentions", [
    (["--prefix", "9lives"], ["--prefix"]),
    (["--prefix", "a;b"], ["--prefix"]),
    (["--prefix", "x" * 41], ["--prefix"]),
    (["--lang", "fortran"], ["--lang"]),
])
def test_export_cli_refuses_bad_values(argv, mentions, tmp_path):
    base = ["export", "puma560", "-o", str(tmp_path / "gen")]
    if "--lang" not in argv:
        base += ["--lang", "c"]
    assert_refused(run_cli(base + argv, tmp_path, {}), mentions=mentions)


def test_export_cli_refuses_a_file_or_a_missing_parent_as_folder(tmp_path):
    (tmp_path / "file.txt").write_text("keep")
    assert_refused(run_cli(["export", "puma560", "--lang", "c", "-o", str(tmp_path / "file.txt")], tmp_path, {}),
                   mentions=["not a folder"])
    assert (tmp_path / "file.txt").read_text() == "keep"
    assert_refused(run_cli(["export", "puma560", "--lang", "c", "-o", str(tmp_path / "no" / "such")], tmp_path, {}),
                   mentions=["parent"])
