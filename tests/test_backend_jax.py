"""denavit.compile(robot, backend="jax") and ``denavit export --lang jax``: values against the numpy backend,
gradients by jax.jacfwd / jax.jacrev against denavit's analytic derivatives, jax.jit and vmap, errors (checks in
tests/_tensor_backends.py, shared with the PyTorch backend).

float64 needs JAX's x64 mode, switched on around each test here (float32 inputs stay float32 in it), not for the
process: other tests and the docs' examples keep JAX's default.  JAX run
op by op compiles each primitive for each new shape and dtype (about 30 ms each, 0.4 s per shape for FK): the tests
use few shapes and arms, and those over 2 CPU-s (whichever meets a shape first pays) are marked slow."""

from __future__ import annotations

import re
import sys
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

jax = pytest.importorskip("jax")
jnp = jax.numpy

import _tensor_backends as checks  # noqa: E402
from _random_robots import random_robot as random_kinematic_robot  # noqa: E402
from conftest import robots  # noqa: E402
from test_dynamics_numeric import random_robot as random_dynamic_robot  # noqa: E402

import denavit  # noqa: E402
from denavit.cli import main  # noqa: E402
from denavit.errors import MissingDependencyError, ModelError, ShapeError  # noqa: E402

SEEDS = st.integers(0, 2**32 - 1)


class Jax:
    name = "jax"

    @staticmethod
    def tensor(x, bits):
        return jnp.asarray(np.asarray(x), dtype=jnp.float64 if bits == 64 else jnp.float32)

    @staticmethod
    def numpy(t):
        return np.asarray(t)

    @staticmethod
    def dtype_bits(t):
        return {jnp.dtype(jnp.float64): 64, jnp.dtype(jnp.float32): 32}[t.dtype]

    @staticmethod
    def jacobian(f, *xs):
        """Forward mode for one input, reverse mode for several: both of JAX's routes are exercised."""
        if len(xs) == 1:
            return jax.jacfwd(f)(xs[0])
        return jax.jacrev(f, argnums=tuple(range(len(xs))))(*xs)


@pytest.fixture(autouse=True)
def _cache(tmp_path_factory, monkeypatch):
    monkeypatch.setenv("DENAVIT_CACHE_DIR", str(tmp_path_factory.getbasetemp() / "kernels"))


@pytest.fixture(autouse=True)
def _x64():
    with jax.enable_x64(True):
        yield


def dynamic_arm(seed, n=None):
    """A random arm with inertial data, motor inertia and friction (both conventions, prismatic, fixed rows)."""
    return random_dynamic_robot(np.random.default_rng(seed), n=n, motor=True, friction=True)


@pytest.mark.slow
@settings(max_examples=4)
@given(robot=robots(), seed=SEEDS)
def test_kinematics_equal_the_numpy_backend_on_random_arms(robot, seed):
    checks.check_kinematics_values(Jax, robot, np.random.default_rng(seed), shapes=((), (3, 2)))


@pytest.mark.slow
@settings(max_examples=2)
@given(seed=SEEDS)
def test_dynamics_equal_the_numpy_backend_on_random_arms(seed):
    checks.check_dynamics_values(Jax, dynamic_arm(seed, n=2 + seed % 3), np.random.default_rng(seed))


@pytest.mark.slow
@settings(max_examples=2)
@given(robot=robots(), seed=SEEDS)
def test_jacfwd_through_fk_and_jacobian_equals_the_analytic_derivatives(robot, seed):
    checks.check_kinematics_gradients(Jax, robot, np.random.default_rng(seed))


@pytest.mark.slow
@settings(max_examples=2)
@given(seed=SEEDS)
def test_jacrev_through_rnea_and_forward_dynamics_equals_the_analytic_derivatives(seed):
    checks.check_dynamics_gradients(Jax, dynamic_arm(seed, n=2 + seed % 2), np.random.default_rng(seed))


def test_export_lang_jax_writes_a_module_giving_the_same_values(tmp_path, rng):
    checks.check_export(Jax, denavit.load_robot("puma560"), tmp_path, rng)
    assert main(["export", "puma560", "--lang", "jax", "-o", str(tmp_path / "out")]) == 0
    text = (tmp_path / "out" / "puma560.py").read_text()
    assert "import jax.numpy as xp" in text and "numpy as np" not in text and "denavit" not in text.split('"""')[2]
    # fk, jacobian0, jacobiane: the polynomials, on the columns moved first
    assert text.count("_sincos(xp.moveaxis(q, -1, 0))") >= 3 and "xp.sin(q_" not in text


@pytest.mark.slow
def test_jit_grad_and_vmap_give_the_eager_values(rng):
    """jax.jit of FK (batched) and of the gradient of a loss through it, and vmap over single configurations."""
    fast = denavit.compile(denavit.load_robot("puma560"), backend="jax")
    q = jnp.asarray(rng.uniform(-np.pi, np.pi, (5, 6)))
    eager = fast.fk(q)
    checks.assert_close(jax.jit(fast.fk)(q), eager, 1e-12, "jit fk")
    checks.assert_close(jax.vmap(fast.fk)(q), eager, 1e-12, "vmap fk")

    def loss(q):
        return jnp.sum(fast.position(q) ** 2)

    checks.assert_close(jax.jit(jax.grad(loss))(q), jax.grad(loss)(q), 1e-12, "jit grad")


def test_the_polynomial_sine_and_cosine_are_numpys_to_an_ulp_or_two_with_libm_beyond_their_range():
    """The generated module's _sincos (vectorisable polynomials instead of XLA's per-element libm calls) against
    numpy's sin and cos: float64 to 2 ulp of 1 on |x| < 100 (the quadrant boundaries k·π/4 included) and up to the
    reduction's range, angles beyond it (libm), ±inf and NaN as numpy gives them; float32 to 1 ulp of 1 in float32
    (against float64 at the same rounded x); under vmap one lax.cond still; derivatives cos and −sin through
    jax.jacfwd; a sine computed once."""
    from denavit.codegen import _llvm, _tensor_emit

    assert _tensor_emit._PIO2_64 == _llvm._PIO2 and _tensor_emit._SIN_TAYLOR == _llvm._SIN  # the numba kernels' own
    assert _tensor_emit._COS_TAYLOR == _llvm._COS and _tensor_emit._RANGE_64 == _llvm._REDUCTION_RANGE
    fast = denavit.compile(denavit.load_robot("puma560"), backend="jax", kernels=["fk"])
    fk_source = fast.source.split("def fk")[1]
    assert fast.source.count("_sincos(xp.moveaxis(q, -1, 0))") == 1 and "xp.sin(" not in fk_source
    sincos = fast.module._sincos
    rng = np.random.default_rng(5)
    near = np.concatenate([np.arange(-400, 401) * (np.pi / 4), rng.uniform(-100, 100, 4000)])
    far = rng.uniform(-8e5, 8e5, 1000)
    tol, x = 2 * np.finfo(np.float64).eps, np.concatenate([near, far])
    s, c = sincos(jnp.asarray(x))
    assert np.abs(np.asarray(s) - np.sin(x)).max() <= tol and np.abs(np.asarray(c) - np.cos(x)).max() <= tol
    odd = np.array([1e7, -3e12, 1e300, np.inf, -np.inf, np.nan, 0.5])  # beyond the range: libm (XLA's sin, cos)
    s, c = sincos(jnp.asarray(odd))
    with np.errstate(invalid="ignore"):
        np.testing.assert_allclose(np.asarray(s), np.sin(odd), rtol=0, atol=1e-15)
        np.testing.assert_allclose(np.asarray(c), np.cos(odd), rtol=0, atol=1e-15)
    x32 = near.astype(np.float32)
    s, c = sincos(jnp.asarray(x32))
    assert s.dtype == jnp.float32
    ulp = np.finfo(np.float32).eps
    assert np.abs(np.asarray(s) - np.sin(x32.astype(np.float64))).max() <= ulp
    assert np.abs(np.asarray(c) - np.cos(x32.astype(np.float64))).max() <= ulp
    x = jnp.asarray(rng.uniform(-4, 4, (2, 3)))  # vmap: the batch at once, still one lax.cond (no select of both)
    checks.assert_close(jax.vmap(sincos)(x)[0], np.sin(np.asarray(x)), 2.3e-16, "vmap sin")
    assert "stablehlo.case" in jax.jit(jax.vmap(sincos)).lower(x).as_text()
    x = x[0]
    ds, dc = jax.jacfwd(sincos)(x)
    checks.assert_close(ds, np.diag(np.cos(np.asarray(x))), 1e-15, "d sin")
    checks.assert_close(dc, -np.diag(np.sin(np.asarray(x))), 1e-15, "d cos")


def _blocked_module(monkeypatch):
    """A 2-joint arm's module (XLA compiles its kernels quickly) running batches from 16 rows on in blocks of 8
    (the module's own: 2**17 and 2048)."""
    mod = denavit.compile(denavit.load_robot("planar2r"), backend="jax", kernels=["fk", "position", "rnea"]).module
    assert (mod._BLOCKED_FROM, mod._BLOCK) == (2**17, 2048)
    monkeypatch.setattr(mod, "_BLOCK", 8)
    monkeypatch.setattr(mod, "_BLOCKED_FROM", 16)
    return mod


def test_large_batches_run_in_blocks_with_the_same_values(monkeypatch, rng):
    """From _BLOCKED_FROM rows on a kernel runs its rows in blocks inside one lax.fori_loop, the last block
    overlapping the one before (39 rows: 5 blocks of 8): the numpy backend's values, dtype and batch shape kept;
    below, one pass."""
    mod = _blocked_module(monkeypatch)
    q = jnp.asarray(rng.uniform(-np.pi, np.pi, (3, 13, 2)))
    fk = jax.jit(lambda x: mod.fk(x))
    assert "while" in fk.lower(q).as_text() and "while" not in fk.lower(q[0]).as_text()
    checks.assert_close(fk(q), checks.numpy_backend(denavit.load_robot("planar2r")).fk(np.asarray(q)), 1e-12, "fk")
    T32 = fk(q.astype(jnp.float32))
    assert T32.dtype == jnp.float32 and T32.shape == (3, 13, 4, 4)
    checks.assert_close(T32, fk(q), 1e-6, "fk float32")


@pytest.mark.slow
def test_large_batches_in_blocks_give_one_pass_derivatives_vmap_and_broadcast_inputs(monkeypatch, rng):
    """Through the blocks (a scan for reverse mode): jax.grad, jacfwd, vmap (13 rows per call under it: one pass)
    and rnea on inputs broadcast first, all as in one pass."""
    mod = _blocked_module(monkeypatch)
    q, qd, qdd = (jnp.asarray(rng.uniform(-np.pi, np.pi, shape)) for shape in ((3, 13, 2), (13, 2), (2,)))

    def runs():  # fresh functions each time (jax.jit keeps a trace per function), jitted (op by op is slow)
        return (jax.jit(jax.grad(lambda x: jnp.sum(mod.fk(x) ** 2)))(q),
                jax.jit(jax.jacfwd(lambda x: mod.position(x).sum(0)))(q[0]),
                jax.jit(jax.vmap(lambda x: mod.fk(x)))(q), jax.jit(lambda *a: mod.rnea(*a))(q, qd, qdd))

    blocked = runs()
    monkeypatch.setattr(mod, "_BLOCKED_FROM", 2**17)
    for what, a, b in zip(("grad", "jacfwd", "vmap", "rnea"), blocked, runs()):
        checks.assert_close(a, b, 1e-13, what)


def _vm_flags(address: int) -> list[str]:
    """The kernel's flags (VmFlags) of the mapping holding ``address``, from /proc/self/smaps."""
    inside = False
    for line in Path("/proc/self/smaps").read_text().splitlines():
        span = re.match(r"([0-9a-f]+)-([0-9a-f]+) ", line)
        if span:
            inside = int(span[1], 16) <= address < int(span[2], 16)
        elif inside and line.startswith("VmFlags:"):
            return line.split()[1:]
    raise AssertionError(f"no mapping holds {address:#x}")


@pytest.mark.slow
@pytest.mark.skipif(not Path("/sys/kernel/mm/transparent_hugepage/enabled").exists(),
                    reason="needs Linux with transparent huge pages")
def test_large_outputs_are_advised_huge_pages_and_exported_modules_start_from_zeros(rng, tmp_path):
    """From _BLOCKED_FROM rows on, the blocks write into XLA's own result buffer, left uninitialised and advised
    huge pages on CPU as numpy advises its large arrays (madvise(MADV_HUGEPAGE): the flag "hg" of its mapping in
    /proc/self/smaps), with the numpy backend's values; the exported module (JAX only) starts from XLA's zeros:
    no advice.  Results of 64 MB: above glibc's largest mmap threshold (32 MB), each a mapping of its own."""
    robot = denavit.load_robot("planar2r")
    exported = checks.load_exported(denavit.codegen.export_sources(robot, "jax", kernels=["fk"]), tmp_path)
    cached = denavit.compile(robot, backend="jax", kernels=["fk"]).module
    q = rng.uniform(-np.pi, np.pi, (2**19, 2))  # from 2**17 rows on: blocks
    ref = checks.numpy_backend(robot).fk(q)
    for module, advised in ((exported, False), (cached, True)):
        T = jax.jit(lambda x, m=module: m.fk(x))(jnp.asarray(q))
        checks.assert_close(T, ref, 1e-12, "fk")
        assert ("hg" in _vm_flags(T.unsafe_buffer_pointer() + T.nbytes // 2)) is advised, module.__name__


def test_results_keep_the_input_dtype_and_batch_shape_and_accept_lists():
    fast = denavit.compile(denavit.load_robot("puma560"), backend="jax")
    T = fast.fk(jnp.zeros((2, 1, 3, 6), dtype=jnp.float32))
    assert T.shape == (2, 1, 3, 4, 4) and T.dtype == jnp.float32
    assert fast.jacobian([0, 0, 0, 0, 0, 0], "tool").shape == (6, 6)  # integers: the default float
    assert fast.mass_matrix(jnp.zeros((0, 6))).shape == (0, 6, 6)


def test_bad_inputs_raise_clear_errors():
    fast = denavit.compile(denavit.load_robot("puma560"), backend="jax")
    with pytest.raises(ShapeError, match=r"q: expected shape \(\.\.\., 6\) for a 6-joint robot, got \(5,\)"):
        fast.fk(jnp.zeros(5))
    with pytest.raises(ShapeError, match="do not broadcast"):
        fast.rnea(jnp.zeros((2, 6)), jnp.zeros((3, 6)), jnp.zeros(6))
    with pytest.raises(ValueError, match="frame must be 'base' or 'tool', got 'world'"):
        fast.jacobian(jnp.zeros(6), "world")
    kinematic = denavit.compile(random_kinematic_robot(np.random.default_rng(1), n_rows=2), backend="jax")
    with pytest.raises(ModelError, match="no inertial data"):
        kinematic.rnea(jnp.zeros(2), jnp.zeros(2), jnp.zeros(2))


def test_missing_jax_names_the_pip_line(monkeypatch):
    monkeypatch.setitem(sys.modules, "jax.numpy", None)
    with pytest.raises(MissingDependencyError, match=r"pip install 'denavit\[jax\]'"):
        denavit.compile(denavit.load_robot("planar2r"), backend="jax")
