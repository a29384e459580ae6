"""The checks of the torch and JAX backends (tests/test_backend_torch.py, tests/test_backend_jax.py), written once
against a small adapter per framework.

Oracles: the numpy backend (the same traced programs run by numpy: an independent runtime for the values), the
compiled Jacobian kernel (cross products of the joint axes, not differentiation) for the gradient of FK, the
library's analytic derivatives (denavit.kinematic_hessian, rnea_derivatives, forward_dynamics_derivatives of
denavit.numeric, not traced) for the other gradients, and M itself for ∂τ/∂q̈.
"""

from __future__ import annotations

import importlib.util

import numpy as np

import denavit

# denavit.compile(...) of the numpy backend, by (robot, friction): the oracle of several checks on one arm
_ORACLES: dict = {}


def numpy_backend(robot):
    key = robot
    if key not in _ORACLES:
        _ORACLES.clear()  # one arm at a time: random arms are not met twice
        _ORACLES[key] = denavit.compile(robot, backend="numpy")
    return _ORACLES[key]


def assert_close(actual, desired, rel: float, what: str = "") -> None:
    """max |actual − desired| ≤ rel · max(1, max |desired|) (relative to the result's scale: torques of tens of N·m
    and unit rotation entries alike), and equal shapes."""
    actual, desired = np.asarray(actual, dtype=np.float64), np.asarray(desired, dtype=np.float64)
    assert actual.shape == desired.shape, f"{what}: shape {actual.shape} != {desired.shape}"
    scale = max(1.0, float(np.abs(desired).max(initial=0.0)))
    err = float(np.abs(actual - desired).max(initial=0.0))
    assert err <= rel * scale, f"{what}: max error {err:.3g} > {rel:g} x {scale:.3g}"


KINEMATICS = (("fk", ()), ("position", ()), ("jacobian", ("base",)), ("jacobian", ("tool",)))


def check_kinematics_values(fw, robot, rng, shapes=((), (1,), (3, 2))) -> None:
    """fk, frames, position, J0 and Je of the framework equal the numpy backend's: float64 to 1e-12, float32 to 1e-5
    (relative, against float64 at the same rounded q), on batches of the given shapes."""
    ref, fast = numpy_backend(robot), denavit.compile(robot, backend=fw.name)
    for shape in shapes:
        q = rng.uniform(-np.pi, np.pi, shape + (robot.dof,))
        q32 = q.astype(np.float32)
        for name, args in KINEMATICS + (("fk", (True,)),):
            want = getattr(ref, name)(q, *args)
            got = getattr(fast, name)(fw.tensor(q, 64), *args)
            assert fw.dtype_bits(got) == 64
            assert_close(fw.numpy(got), want, 1e-12, f"{name}{args} float64 {shape}")
            got32 = getattr(fast, name)(fw.tensor(q32, 32), *args)
            assert fw.dtype_bits(got32) == 32
            assert_close(fw.numpy(got32), getattr(ref, name)(q32.astype(np.float64), *args), 1e-5,
                         f"{name}{args} float32 {shape}")


def check_dynamics_values(fw, robot, rng) -> None:
    """rnea, M, g, c and forward dynamics of the framework equal the numpy backend's (float64 1e-12, float32 1e-5
    relative; forward dynamics in float32 1e-5 times the condition number of M, which the solve amplifies the
    float32 rounding of M and the bias by), with q̇ of shape (n,) broadcast against a (2, 3) batch of q."""
    ref, fast = numpy_backend(robot), denavit.compile(robot, backend=fw.name)
    n = robot.dof
    q, qd, qdd = rng.uniform(-np.pi, np.pi, (2, 3, n)), rng.uniform(-2, 2, n), rng.uniform(-3, 3, (2, 3, n))
    cases = (("rnea", (q, qd, qdd)), ("mass_matrix", (q,)), ("gravity", (q,)), ("coriolis", (q, qd)),
             ("forward_dynamics", (q, qd, qdd)))
    for name, args in cases:
        want = getattr(ref, name)(*args)
        assert_close(fw.numpy(getattr(fast, name)(*[fw.tensor(a, 64) for a in args])), want, 1e-12, f"{name} float64")
        args32 = [a.astype(np.float32) for a in args]
        want32 = getattr(ref, name)(*[a.astype(np.float64) for a in args32])
        got32 = getattr(fast, name)(*[fw.tensor(a, 32) for a in args32])
        assert fw.dtype_bits(got32) == 32
        rel = 1e-5
        if name == "forward_dynamics":  # seen: cond(M) 166, error 2.4e-4 on results of 13.9 (bias 148)
            rel *= max(1.0, float(np.linalg.cond(ref.mass_matrix(args32[0].astype(np.float64))).max()))
        assert_close(fw.numpy(got32), want32, rel, f"{name} float32")


def _skew(w):
    return np.array([[0.0, -w[2], w[1]], [w[2], 0.0, -w[0]], [-w[1], w[0], 0.0]])


def check_kinematics_gradients(fw, robot, rng) -> None:
    """∂T/∂q_k by the framework's autodiff through fk is (J0[:3, k]; skew(J0[3:, k]) R) from the compiled Jacobian
    kernel, and ∂J0/∂q through the Jacobian kernel is the compiled kinematic Hessian, to 1e-8."""
    ref, fast = numpy_backend(robot), denavit.compile(robot, backend=fw.name)
    q = rng.uniform(-np.pi, np.pi, robot.dof)
    dT = fw.numpy(fw.jacobian(fast.fk, fw.tensor(q, 64)))  # (4, 4, n)
    J0, R = ref.jacobian(q), ref.fk(q)[:3, :3]
    for k in range(robot.dof):
        assert_close(dT[:3, 3, k], J0[:3, k], 1e-8, f"dp/dq{k}")
        assert_close(dT[:3, :3, k], _skew(J0[3:, k]) @ R, 1e-8, f"dR/dq{k}")
        assert_close(dT[3, :, k], np.zeros(4), 0.0, f"d(last row)/dq{k}")
    dJ = fw.numpy(fw.jacobian(fast.jacobian, fw.tensor(q, 64)))  # (6, n, n): [:, j, k] = ∂J[:, j]/∂q_k
    assert_close(dJ, denavit.kinematic_hessian(robot, q), 1e-8, "dJ0/dq")


def check_dynamics_gradients(fw, robot, rng) -> None:
    """∂τ/∂(q, q̇, q̈) through rnea are the compiled RNEA derivatives and M; ∂q̈/∂(q, q̇, τ) through forward
    dynamics (the framework's solve) are the compiled forward-dynamics derivatives; to 1e-8."""
    ref, fast = numpy_backend(robot), denavit.compile(robot, backend=fw.name)
    n = robot.dof
    q, qd, x = rng.uniform(-np.pi, np.pi, n), rng.uniform(-2, 2, n), rng.uniform(-3, 3, n)
    args = [fw.tensor(a, 64) for a in (q, qd, x)]
    d_q, d_qd, d_qdd = (fw.numpy(d) for d in fw.jacobian(fast.rnea, *args))
    want_q, want_qd = denavit.rnea_derivatives(robot, q, qd, x)
    assert_close(d_q, want_q, 1e-8, "dtau/dq")
    assert_close(d_qd, want_qd, 1e-8, "dtau/dqd")
    assert_close(d_qdd, ref.mass_matrix(q), 1e-8, "dtau/dqdd")
    got = [fw.numpy(d) for d in fw.jacobian(fast.forward_dynamics, *args)]
    for g, w, what in zip(got, denavit.forward_dynamics_derivatives(robot, q, qd, x), ("q", "qd", "tau")):
        assert_close(g, w, 1e-8, f"dqdd/d{what}")


def load_exported(files: dict, folder) -> object:
    """Write an export's files into ``folder`` and import its one module from the file (no subprocess)."""
    (name, text), = files.items()
    path = folder / name
    path.write_text(text, encoding="utf-8")
    spec = importlib.util.spec_from_file_location(f"exported_{path.stem}_{id(files)}", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def check_export(fw, robot, folder, rng) -> None:
    """The standalone module of ``denavit export --lang <fw>`` gives the numpy backend's values."""
    from denavit.codegen import export_sources

    mod = load_exported(export_sources(robot, fw.name), folder)
    ref = numpy_backend(robot)
    q, qd, x = (rng.uniform(-1, 1, (4, robot.dof)) for _ in range(3))
    assert_close(fw.numpy(mod.fk(fw.tensor(q, 64))), ref.fk(q), 1e-12, "exported fk")
    assert_close(fw.numpy(mod.jacobian0(fw.tensor(q, 64))), ref.jacobian(q), 1e-12, "exported jacobian0")
    assert_close(fw.numpy(mod.jacobiane(fw.tensor(q, 64))), ref.jacobian(q, "tool"), 1e-12, "exported jacobiane")
    if hasattr(mod, "rnea"):
        args = [fw.tensor(a, 64) for a in (q, qd, x)]
        assert_close(fw.numpy(mod.rnea(*args)), ref.rnea(q, qd, x), 1e-12, "exported rnea")
        assert_close(fw.numpy(mod.forward_dynamics(*args)), ref.forward_dynamics(q, qd, x), 1e-12,
                     "exported forward_dynamics")
