"""denavit.compile: generated kernels against independent routes and Pinocchio.

Oracles: FK as a product of elementary 4×4 matrices (test_fk.elementary_fk), the Jacobian by central finite
differences of that FK and by the differentiation route, dynamics by Pinocchio built independently from the
DH frames (test_dynamics_numeric.pinocchio_model), plus identities (M symmetric positive definite,
forward dynamics inverts inverse dynamics).  The numpy backend is checked on many random arms (it is quick to
build); the numba backend on a few, against the numpy backend.
"""

from __future__ import annotations

import os
import subprocess
import sys
import textwrap

import numpy as np
import pytest
from _random_robots import random_robot as random_kinematic_robot
from conftest import REDUCED
from test_dynamics_numeric import pinocchio_model, random_robot as random_dynamic_robot, random_state
from test_fk import elementary_fk

import denavit
from denavit.codegen import numba_available
from denavit.errors import ModelError, ShapeError
from denavit.numeric import differentiation_jacobian, friction_torques, transform_from_xyz_rpy

N_KIN = 40 if REDUCED else 150
N_DYN = 15 if REDUCED else 60


@pytest.fixture(autouse=True)
def _cache(tmp_path_factory, monkeypatch):
    """One kernel folder for the run, shared by pytest-xdist's workers (each worker's basetemp is a subfolder of
    the run's): a robot's kernels are compiled once, not once per worker."""
    base = tmp_path_factory.getbasetemp()
    if os.environ.get("PYTEST_XDIST_WORKER"):
        base = base.parent
    monkeypatch.setenv("DENAVIT_CACHE_DIR", str(base / "kernels"))


def fd_jacobian(robot, q, h=1e-6):
    """Base-frame geometric Jacobian by central differences of the elementary-product FK."""
    n = robot.dof
    J = np.zeros((6, n))
    for k in range(n):
        dq = np.zeros(n)
        dq[k] = h
        Tp, _ = elementary_fk(robot, q + dq)
        Tm, _ = elementary_fk(robot, q - dq)
        J[:3, k] = (Tp[:3, 3] - Tm[:3, 3]) / (2 * h)
        dR = (Tp[:3, :3] - Tm[:3, :3]) / (2 * h)
        W = dR @ elementary_fk(robot, q)[0][:3, :3].T  # skew(ω)
        J[3:, k] = (W[2, 1], W[0, 2], W[1, 0])
    return J


@pytest.mark.parametrize("seed", range(N_KIN))
def test_kinematics_kernels_on_random_arms(seed):
    rng = np.random.default_rng(9100 + seed)
    robot = random_kinematic_robot(rng)
    fast = denavit.compile(robot, backend="numpy")
    Q = rng.uniform(-np.pi, np.pi, (3, robot.dof))
    for q in Q:
        T, frames = elementary_fk(robot, q)
        np.testing.assert_allclose(fast.fk(q), T, atol=1e-12)
        np.testing.assert_allclose(fast.position(q), T[:3, 3], atol=1e-12)
        np.testing.assert_allclose(fast.fk(q, frames=True), frames, atol=1e-12)
        J0 = fast.jacobian(q)
        np.testing.assert_allclose(J0, differentiation_jacobian(robot, q), atol=1e-10)
        np.testing.assert_allclose(J0, fd_jacobian(robot, q), atol=1e-6)
        R = T[:3, :3]
        Je = fast.jacobian(q, "tool")
        np.testing.assert_allclose(np.vstack([R @ Je[:3], R @ Je[3:]]), J0, atol=1e-12)
    # a batch is the loop of single calls, whatever its shape
    B = Q.reshape(3, 1, robot.dof)
    np.testing.assert_allclose(fast.fk(B), np.stack([fast.fk(q) for q in Q]).reshape(3, 1, 4, 4), atol=1e-14)
    np.testing.assert_allclose(fast.jacobian(B, "tool"),
                               np.stack([fast.jacobian(q, "tool") for q in Q]).reshape(3, 1, 6, robot.dof),
                               atol=1e-14)
    assert fast.fk(np.zeros((0, robot.dof))).shape == (0, 4, 4)


def _with_tool(robot, rng):
    from dataclasses import replace

    return replace(robot, tool=transform_from_xyz_rpy(rng.uniform(-0.5, 0.5, 3), rng.uniform(-np.pi, np.pi, 3)))


@pytest.mark.peer
@pytest.mark.parametrize("seed", range(N_DYN))
def test_dynamics_kernels_equal_pinocchio_on_random_arms(seed):
    pin = pytest.importorskip("pinocchio")
    rng = np.random.default_rng(9300 + seed)
    robot = _with_tool(random_dynamic_robot(rng, motor=True, friction=seed % 2 == 0), rng)
    fast = denavit.compile(robot, backend="numpy")
    model = pinocchio_model(robot)
    data = model.createData()
    for _ in range(3):
        q, qd, qdd = random_state(rng, robot)
        tf = friction_torques(robot, qd)
        np.testing.assert_allclose(fast.rnea(q, qd, qdd) - tf, pin.rnea(model, data, q, qd, qdd), atol=1e-10)
        Mp = pin.crba(model, data, q)
        Mp = np.triu(Mp) + np.triu(Mp, 1).T
        M = fast.mass_matrix(q)
        np.testing.assert_allclose(M, Mp, atol=1e-10)
        np.testing.assert_array_equal(M, M.T)
        assert np.linalg.eigvalsh(M).min() > 0
        np.testing.assert_allclose(fast.gravity(q), pin.computeGeneralizedGravity(model, data, q), atol=1e-10)
        np.testing.assert_allclose(fast.coriolis(q, qd),
                                   pin.nonLinearEffects(model, data, q, qd) - pin.computeGeneralizedGravity(model, data, q),
                                   atol=1e-10)
        tau = rng.normal(size=robot.dof) * 5
        np.testing.assert_allclose(fast.forward_dynamics(q, qd, tau + tf), pin.aba(model, data, q, qd, tau),
                                   atol=1e-8)
        # forward dynamics inverts inverse dynamics (friction included)
        np.testing.assert_allclose(fast.forward_dynamics(q, qd, fast.rnea(q, qd, qdd)), qdd, atol=1e-8)


def test_batches_broadcast_and_equal_single_calls():
    rng = np.random.default_rng(5)
    robot = denavit.load_robot("puma560")
    fast = denavit.compile(robot, backend="numpy")
    q, qd, qdd = random_state(rng, robot, (2, 3))
    tau = fast.rnea(q, qd, qdd[0, 0])  # qdd broadcast over the batch
    assert tau.shape == (2, 3, 6)
    for i in range(2):
        for j in range(3):
            np.testing.assert_allclose(tau[i, j], fast.rnea(q[i, j], qd[i, j], qdd[0, 0]), atol=1e-12)
            np.testing.assert_allclose(fast.mass_matrix(q)[i, j], fast.mass_matrix(q[i, j]), atol=1e-12)
    np.testing.assert_allclose(fast.forward_dynamics(q, qd, tau), np.broadcast_to(qdd[0, 0], (2, 3, 6)),
                               atol=1e-8)
    assert fast.fk(q.tolist()[0][0]).shape == (4, 4)  # lists and integer arrays are converted
    np.testing.assert_allclose(fast.fk(np.zeros(6, dtype=int)), fast.fk(np.zeros(6)))


@pytest.mark.parametrize("name", ["puma560", "panda", "stanford", "ur5"])
def test_singular_configurations(name):
    """At a singular q the kernels still equal the independent routes (nothing divides by a Jacobian)."""
    robot = denavit.load_robot(name)
    fast = denavit.compile(robot, backend="numpy")
    q = np.zeros(robot.dof)  # stretched / aligned axes: singular for these arms
    assert np.linalg.matrix_rank(fast.jacobian(q), tol=1e-9) < 6
    np.testing.assert_allclose(fast.jacobian(q), differentiation_jacobian(robot, q), atol=1e-10)
    np.testing.assert_allclose(fast.fk(q), elementary_fk(robot, q)[0], atol=1e-12)


def test_singular_mass_matrix_and_missing_inertia_raise():
    robot = random_kinematic_robot(np.random.default_rng(1))  # no inertial data
    fast = denavit.compile(robot, backend="numpy")
    assert "rnea" not in fast.kernels
    with pytest.raises(ModelError, match="no inertial data"):
        fast.rnea(*[np.zeros(robot.dof)] * 3)
    rng = np.random.default_rng(3)
    dyn = random_dynamic_robot(rng, n=3, fixed_rows=False, prismatic=False)
    from dataclasses import replace

    last = dyn.links[-1]
    massless = replace(dyn, links=dyn.links[:-1] + (replace(last, inertia=None),))
    fast = denavit.compile(massless, backend="numpy")
    with pytest.raises(ModelError, match="singular"):
        fast.forward_dynamics(np.zeros(3), np.zeros(3), np.ones(3))
    with pytest.raises(ModelError):
        denavit.forward_dynamics(massless, np.zeros(3), np.zeros(3), np.ones(3))  # the plain function agrees


@pytest.mark.parametrize("bad", [np.zeros(5), np.zeros((2, 7)), 0.0, [[1, 2, 3, 4, 5, 6]] * 2 + [[1]]])
def test_bad_shapes_raise_shape_error(bad):
    fast = denavit.compile(denavit.load_robot("puma560"), backend="numpy")
    with pytest.raises((ShapeError, ValueError)):
        fast.fk(bad)
    with pytest.raises(ShapeError):
        fast.rnea(np.zeros((2, 6)), np.zeros((3, 6)), np.zeros(6))


def test_bad_arguments():
    robot = denavit.load_robot("puma560")
    with pytest.raises(ValueError, match="backend"):
        denavit.compile(robot, backend="fortran")
    with pytest.raises(ValueError, match="unknown kernels"):
        denavit.compile(robot, kernels=["fk", "ik"])
    with pytest.raises(ValueError):
        denavit.compile(robot, backend="numpy").jacobian(np.zeros(6), "elbow")
    with pytest.raises(TypeError):
        denavit.compile("puma560")


def test_no_user_text_reaches_generated_code():
    """A robot's name is never pasted into source (it could close a string and run code)."""
    from dataclasses import replace

    evil = '"""\nimport os; os.system("echo pwned")\n"""'
    robot = replace(denavit.load_robot("planar2r"), name=evil)
    fast = denavit.compile(robot, backend="numpy")
    assert "pwned" not in fast.source
    np.testing.assert_allclose(fast.fk([0.1, 0.2]), denavit.forward_kinematics(robot, [0.1, 0.2]), atol=1e-14)


needs_numba = pytest.mark.skipif(not numba_available(), reason="numba (the 'fast' extra) is not installed")


@needs_numba
def test_simd_batches_sine_and_cosine_agree_with_libm():
    """Batches run LANES rows at once with the kernel's own vector sin/cos (Cody–Waite reduction, Taylor
    polynomials; single calls use the same in scalar form); a one-joint arm's T[0, 0] and T[1, 0] are cos q and sin q, compared with numpy's (libm) within
    two ulps of 1 — angles across the reduction's range, at multiples of π/2 (the quadrant edges), huge ones
    (libm's path per lane), ±inf and NaN, and batch lengths that leave a scalar remainder."""
    robot = denavit.robot([denavit.revolute(a=1.0)])
    fast = denavit.compile(robot, backend="numba")
    rng = np.random.default_rng(5)
    k = np.arange(-40, 41)
    q = np.concatenate([rng.uniform(-np.pi, np.pi, 4001), rng.uniform(-1e5, 1e5, 4000),
                        k * np.pi / 2, k * np.pi / 2 + 1e-9, np.nextafter(k * np.pi / 4, np.inf),
                        [1e7, -3e8, 2.0**19 * np.pi / 2 * 1.0001, 1e300, 0.0, -0.0, 5e-324]])
    for n in (len(q), len(q) - 1, 3):
        T = fast.fk(q[:n, None])
        np.testing.assert_allclose(T[:, 0, 0], np.cos(q[:n]), rtol=0, atol=2 * np.finfo(float).eps)
        np.testing.assert_allclose(T[:, 1, 0], np.sin(q[:n]), rtol=0, atol=2 * np.finfo(float).eps)
    for x in np.concatenate([q[::97], q[-90:]]):  # one configuration: the same polynomial, in scalar form
        T = fast.fk(np.array([x]))
        assert abs(T[0, 0] - np.cos(x)) <= 2 * np.finfo(float).eps and abs(T[1, 0] - np.sin(x)) <= 2 * np.finfo(float).eps
    one = np.empty((4, 4))
    fast._m.fk_1(np.array([np.inf]), one)
    assert np.isnan(one[:2, :2]).all()
    odd = np.array([np.inf, 0.3, np.nan, -np.inf, 0.5, 0.7, 0.9])[:, None]
    out = np.empty((7, 4, 4))  # the kernel itself: the wrapper refuses non-finite q
    fast._m.fk_n(odd, out)
    assert np.isnan(out[[0, 2, 3], :2, :2]).all()
    np.testing.assert_allclose(out[[1, 4, 5, 6], 0, 0], np.cos(odd[[1, 4, 5, 6], 0]), atol=2 * np.finfo(float).eps)


@needs_numba
@pytest.mark.slow
@pytest.mark.parametrize("name", ["puma560", "panda"])
def test_numba_backend_equals_numpy_backend(name):
    rng = np.random.default_rng(11)
    robot = denavit.load_robot(name)
    jit = denavit.compile(robot, backend="numba")
    ref = denavit.compile(robot, backend="numpy")
    q, qd, qdd = random_state(rng, robot, (7,))  # 4 rows in SIMD, 3 by the scalar loop
    for method, args in [("fk", (q,)), ("position", (q,)), ("jacobian", (q,)), ("rnea", (q, qd, qdd)), ("mass_matrix", (q,)),
                         ("gravity", (q,)), ("coriolis", (q, qd)), ("forward_dynamics", (q, qd, qdd))]:
        a, b = getattr(jit, method)(*args), getattr(ref, method)(*args)
        np.testing.assert_allclose(a, b, rtol=1e-12, atol=1e-12)
        one = getattr(jit, method)(*(x[0] for x in args))
        np.testing.assert_allclose(one, b[0], rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(jit.jacobian(q[0], "tool"), ref.jacobian(q[0], "tool"), atol=1e-12)
    np.testing.assert_allclose(jit.fk(q, frames=True), ref.fk(q, frames=True), atol=1e-12)


@needs_numba
@pytest.mark.slow
def test_numba_kernels_are_cached_on_disk_for_the_next_process(tmp_path):
    """The second process compiles nothing: numba reports cache hits and no misses."""
    script = textwrap.dedent("""
        import numpy as np, denavit
        fast = denavit.compile(denavit.load_robot("planar3r"))
        fast.fk(np.zeros(3), frames=True); fast.jacobian(np.zeros((2, 3)))  # a numba single; the batch group
        m = fast._m
        hits = sum(m.frames_1.stats.cache_hits.values()) + sum(m.group_n.stats.cache_hits.values())
        misses = sum(m.frames_1.stats.cache_misses.values()) + sum(m.group_n.stats.cache_misses.values())
        print(fast.backend, hits, misses)
    """)
    env = {**os.environ, "DENAVIT_CACHE_DIR": str(tmp_path)}
    first = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, env=env, check=True)
    second = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, env=env, check=True)
    backend, _, misses1 = first.stdout.split()
    _, hits2, misses2 = second.stdout.split()
    assert backend == "numba" and int(misses1) > 0
    assert int(hits2) > 0 and int(misses2) == 0
    assert any(p.suffix == ".nbi" for p in tmp_path.rglob("*"))


def test_cache_key_follows_the_numbers_not_the_name(tmp_path, monkeypatch):
    from dataclasses import replace

    from denavit.codegen import robot_key

    robot = denavit.load_robot("puma560")
    key = robot_key(robot, "numpy", True, ("fk",))
    assert robot_key(replace(robot, name="other"), "numpy", True, ("fk",)) == key
    moved = replace(robot, gravity=(0.0, 0.0, -9.80665))
    assert robot_key(moved, "numpy", True, ("fk",)) != key
    link = robot.links[2]
    heavier = replace(robot, links=robot.links[:2] + (replace(link, inertia=replace(link.inertia, mass=link.inertia.mass
                                                                                     + 1e-9)),) + robot.links[3:])
    assert robot_key(heavier, "numpy", True, ("fk",)) != key
    assert robot_key(robot, "numpy", False, ("fk",)) != key
    # the kernels of the changed robot are its own, not the cached ones of the first
    q = np.full(6, 0.3)
    a = denavit.compile(robot, backend="numpy").gravity(q)
    b = denavit.compile(moved, backend="numpy").gravity(q)
    np.testing.assert_allclose(b, denavit.gravity_torques(moved, q), atol=1e-10)
    assert not np.allclose(a, b, atol=1e-6)


def test_unwritable_cache_folder_falls_back_to_a_private_temporary_one(tmp_path, monkeypatch):
    blocker = tmp_path / "file"
    blocker.write_text("not a folder")
    monkeypatch.setenv("DENAVIT_CACHE_DIR", str(blocker / "kernels"))
    fast = denavit.compile(denavit.load_robot("planar3r"), backend="numpy", kernels=["fk"])
    folder = fast.path.parent
    assert folder.name.startswith("denavit-kernels-") and (folder.stat().st_mode & 0o077) == 0
    assert blocker.read_text() == "not a folder"
    np.testing.assert_allclose(fast.fk(np.zeros(3)), denavit.forward_kinematics(fast.robot, np.zeros(3)), atol=1e-14)


@needs_numba
@pytest.mark.slow
@pytest.mark.parametrize("name", ["puma560", "panda"])
def test_compiled_numeric_ik_solves_reachable_targets_within_limits(name):
    """Targets made by FK of random q inside the limits: every one solved, judged by the plain FK."""
    robot = denavit.load_robot(name)
    fast = denavit.compile(robot)
    rng = np.random.default_rng(21)
    lim = robot.q_limits
    n_targets = 60 if REDUCED else 300
    Q = rng.uniform(lim[:, 0], lim[:, 1], (n_targets, robot.dof))
    T = denavit.forward_kinematics(robot, Q)
    for i in range(n_targets):  # one call per target, cold (no seed)
        res = fast.solve_ik(T[i], rng=rng)
        assert res.success and res.reason == ""
        assert np.all(res.q >= lim[:, 0] - 1e-12) and np.all(res.q <= lim[:, 1] + 1e-12)
        Tq = denavit.forward_kinematics(robot, res.q)
        assert np.abs(Tq[:3, 3] - T[i, :3, 3]).max() <= 1e-9
        assert np.abs(Tq[:3, :3] - T[i, :3, :3]).max() <= 1e-8
    seeded = fast.solve_ik(T[:10], Q[:10] + rng.normal(0, 0.05, (10, robot.dof)), rng=rng)  # a batch, seeded
    assert seeded.success.all() and seeded.q.shape == (10, robot.dof)
    np.testing.assert_allclose(denavit.forward_kinematics(robot, seeded.q), T[:10], atol=1e-8)
    assert np.median(seeded.iterations) <= 10  # near seeds converge in a few LM steps
    # one LM (denavit.ik.lm): from the same seeds without restarts, the compiled and the plain single-target run
    # take the same steps (their FK and Jacobian differ by rounding only); seeds beyond a limit are projected into
    # the limits by both (Q near a limit plus the noise: several of the 30 are outside)
    for i in range(30):
        q0 = Q[i] + rng.normal(0, 0.05, robot.dof)
        a, b = fast.solve_ik(T[i], q0, restarts=0), denavit.solve_ik(robot, T[i], q0, restarts=0)
        assert a.success == b.success
        if b.success:  # a failed first attempt goes on to the plain solver's search: compared above
            assert a.iterations == b.iterations
            np.testing.assert_allclose(a.q, b.q, atol=1e-9)


@needs_numba
@pytest.mark.slow
def test_compiled_numeric_ik_failures_and_bad_input():
    robot = denavit.load_robot("puma560")
    fast = denavit.compile(robot)
    far = np.eye(4)
    far[:3, 3] = (5.0, 0.0, 0.0)  # 5 m away: outside the workspace
    res = fast.solve_ik(far, restarts=2, rng=np.random.default_rng(0))
    assert not res.success and res.reason == "unreachable"
    bad = np.eye(4)
    bad[0, 0] = 2.0
    with pytest.raises(ShapeError, match="orthonormal"):
        fast.solve_ik(bad)
    with pytest.raises(ShapeError, match="non-finite"):
        fast.solve_ik(np.full((4, 4), np.nan))
    with pytest.raises(ShapeError):
        fast.solve_ik(np.eye(4), np.array([np.nan] * 6))
    with pytest.raises(ShapeError):
        fast.solve_ik(np.eye(3))
    # the numpy backend answers with the plain solver
    slow = denavit.compile(robot, backend="numpy")
    T = denavit.forward_kinematics(robot, np.full(6, 0.2))
    res = slow.solve_ik(T, rng=np.random.default_rng(1))
    assert res.success and np.allclose(denavit.forward_kinematics(robot, res.q), T, atol=1e-8)


@needs_numba
@pytest.mark.slow
@pytest.mark.parametrize("seed", range(2 if REDUCED else 4))
def test_numba_backend_on_random_arms_equals_pinocchio(seed):
    """Random arms (both conventions, prismatic joints, fixed rows, motor inertia, friction, base and tool)."""
    pin = pytest.importorskip("pinocchio")
    rng = np.random.default_rng(9500 + seed)
    robot = _with_tool(random_dynamic_robot(rng, motor=True, friction=True), rng)
    fast = denavit.compile(robot, backend="numba", kernels=["fk", "jacobian0", "rnea", "mass_matrix"])
    model = pinocchio_model(robot)
    data = model.createData()
    q, qd, qdd = random_state(rng, robot, (5,))
    tau = fast.rnea(q, qd, qdd) - friction_torques(robot, qd)
    for i in range(5):
        np.testing.assert_allclose(tau[i], pin.rnea(model, data, q[i], qd[i], qdd[i]), atol=1e-10)
        Mp = pin.crba(model, data, q[i])
        np.testing.assert_allclose(fast.mass_matrix(q[i]), np.triu(Mp) + np.triu(Mp, 1).T, atol=1e-10)
        np.testing.assert_allclose(fast.fk(q[i]), elementary_fk(robot, q[i])[0], atol=1e-12)
        np.testing.assert_allclose(fast.jacobian(q[i]), differentiation_jacobian(robot, q[i]), atol=1e-10)
    # the numba and numpy backends agree to rounding
    ref = denavit.compile(robot, backend="numpy")
    np.testing.assert_allclose(fast.mass_matrix(q), ref.mass_matrix(q), rtol=1e-13, atol=1e-13)
    with pytest.raises(ModelError, match="not compiled"):
        fast.gravity(q[0])


def test_without_numba_compile_falls_back_to_numpy(monkeypatch):
    from denavit.codegen import _compiled
    from denavit.errors import MissingDependencyError

    monkeypatch.setattr(_compiled, "numba_available", lambda: False)
    robot = denavit.load_robot("planar3r")
    fast = denavit.compile(robot)
    assert fast.backend == "numpy"
    np.testing.assert_allclose(fast.fk(np.ones(3)), denavit.forward_kinematics(robot, np.ones(3)), atol=1e-14)
    with pytest.raises(MissingDependencyError, match="fast"):
        denavit.compile(robot, backend="numba")


def _same_analytic(a, b):
    assert a.solutions.shape == b.solutions.shape
    np.testing.assert_allclose(a.solutions, b.solutions, atol=1e-9)
    assert np.array_equal(np.asarray(a.branches, dtype=object), np.asarray(b.branches, dtype=object))
    assert np.array_equal(np.asarray(a.free, dtype=object), np.asarray(b.free, dtype=object))
    np.testing.assert_allclose(np.asarray(a.outside_limits), np.asarray(b.outside_limits), atol=1e-9)
    assert a.method == b.method and a.controlled == b.controlled


@needs_numba
@pytest.mark.slow
@pytest.mark.parametrize("name", ["puma560", "puma560-mdh"])
def test_compiled_analytic_ik_equals_the_plain_solver(name):
    """Every solution, label and out-of-limits solution of denavit.analytic_ik, pose by pose: at random poses
    (the compiled closed form answers) and at singular ones (it hands them to the plain solver)."""
    from denavit.ik import ik_plan

    robot = denavit.load_robot(name)
    assert ik_plan(robot).closed is not None  # the elbow + spherical-wrist class
    fast = denavit.compile(robot)
    rng = np.random.default_rng(31)
    lim = robot.q_limits
    Q = rng.uniform(lim[:, 0], lim[:, 1], (150 if REDUCED else 600, robot.dof))
    singular = Q[:40].copy()
    singular[:10, 4] = 0.0  # wrist: axes 4 and 6 aligned
    singular[10:20, 2] = np.arctan2(robot.links[3].d, robot.links[2].a) if name == "puma560" else 0.0  # stretched
    singular[20:40] = np.round(singular[20:40], 1)
    for k, q in enumerate(np.concatenate([Q, singular])):
        T = denavit.forward_kinematics(robot, q)
        a, b = fast.analytic_ik(T), denavit.analytic_ik(robot, T)
        _same_analytic(a, b)
        if k < len(Q):
            assert a.count >= 1  # q itself is a solution (inside the limits)
    batch = denavit.forward_kinematics(robot, Q[:5])
    _same_analytic(fast.analytic_ik(batch), denavit.analytic_ik(robot, batch))  # a batch: the compiled loop, in the plain layout


@needs_numba
@pytest.mark.slow
def test_compiled_analytic_ik_other_arms_and_bad_input():
    from denavit.errors import UnsupportedRobotError

    for name in ("stanford", "ur5", "scara"):  # compiled (UR, Stanford classes: tests/test_codegen_ik.py) or plain
        robot = denavit.load_robot(name)
        fast = denavit.compile(robot, kernels=["fk", "fk_jacobian0"])
        T = denavit.forward_kinematics(robot, np.full(robot.dof, 0.3))
        _same_analytic(fast.analytic_ik(T), denavit.analytic_ik(robot, T))
    panda = denavit.compile(denavit.load_robot("panda"), kernels=["fk", "fk_jacobian0"])
    with pytest.raises(UnsupportedRobotError):
        panda.analytic_ik(np.eye(4))
    fast = denavit.compile(denavit.load_robot("puma560"))
    bad = np.eye(4)
    bad[0, 1] = 0.5
    with pytest.raises(ShapeError, match="orthonormal"):
        fast.analytic_ik(bad)
    with pytest.raises(ShapeError, match="non-finite"):
        fast.analytic_ik(np.full((4, 4), np.inf))
    far = np.eye(4)
    far[:3, 3] = (9.0, 0.0, 0.0)
    assert fast.analytic_ik(far).count == 0



@needs_numba
def test_each_arm_binds_its_own_lm_under_its_own_symbol_names():
    """The LM that a generated module binds (denavit.codegen.numba_ik_lm) calls that module's kernel, and numba
    names machine code by module, qualified name and a per-process counter: the closures of two arms share code,
    module and name, so two arms compiled in two processes and loaded from the cache into a third could run one
    arm's kernel for both (seen: ur5's ik_lm took 34 steps where the plain solver took 6).  Each binding's
    closures are named after their module (what numba's symbol names are made of, read the way numba reads it)."""
    from numba.core.bytecode import FunctionIdentity

    from denavit.codegen import numba_ik_lm

    def kernel(q, P):
        pass

    names = []
    for owner in ("_denavit_kernels_numba_a", "_denavit_kernels_numba_b"):
        solve, check = numba_ik_lm(kernel, owner)
        attempt = dict(zip(solve.__code__.co_freevars, (c.cell_contents for c in solve.__closure__)))["attempt"]
        for f in (solve, attempt):
            name = FunctionIdentity.from_function(f).func_qualname
            assert name.startswith(owner + ".")
            names.append(name)
    assert len(set(names)) == 4 and callable(check)
