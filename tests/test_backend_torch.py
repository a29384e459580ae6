"""denavit.compile(robot, backend="torch") and ``denavit export --lang torch``: values against the numpy backend,
gradients by torch.autograd against denavit's analytic derivatives, torch.compile, errors (checks in
tests/_tensor_backends.py, shared with the JAX backend)."""

from __future__ import annotations

import os
import sys

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

torch = pytest.importorskip("torch")

import _tensor_backends as checks  # noqa: E402
from _random_robots import random_robot as random_kinematic_robot  # noqa: E402
from conftest import robots  # noqa: E402
from test_dynamics_numeric import random_robot as random_dynamic_robot  # noqa: E402

import denavit  # noqa: E402
from denavit.cli import main  # noqa: E402
from denavit.errors import MissingDependencyError, ModelError, ShapeError  # noqa: E402

SEEDS = st.integers(0, 2**32 - 1)


class Torch:
    name = "torch"

    @staticmethod
    def tensor(x, bits):
        return torch.tensor(np.asarray(x), dtype=torch.float64 if bits == 64 else torch.float32)

    @staticmethod
    def numpy(t):
        return t.detach().cpu().numpy()

    @staticmethod
    def dtype_bits(t):
        return {torch.float64: 64, torch.float32: 32}[t.dtype]

    @staticmethod
    def jacobian(f, *xs):
        out = torch.autograd.functional.jacobian(f, xs if len(xs) > 1 else xs[0])
        return out


@pytest.fixture(autouse=True)
def _cache(tmp_path_factory, monkeypatch):
    monkeypatch.setenv("DENAVIT_CACHE_DIR", str(tmp_path_factory.getbasetemp() / "kernels"))


def dynamic_arm(seed, n=None):
    """A random arm with inertial data, motor inertia and friction (both conventions, prismatic, fixed rows)."""
    return random_dynamic_robot(np.random.default_rng(seed), n=n, motor=True, friction=True)


@settings(max_examples=8)
@given(robot=robots(), seed=SEEDS)
def test_kinematics_equal_the_numpy_backend_on_random_arms(robot, seed):
    checks.check_kinematics_values(Torch, robot, np.random.default_rng(seed))


@settings(max_examples=2)
@given(seed=SEEDS)
def test_dynamics_equal_the_numpy_backend_on_random_arms(seed):
    checks.check_dynamics_values(Torch, dynamic_arm(seed), np.random.default_rng(seed))


@settings(max_examples=3)
@given(robot=robots(), seed=SEEDS)
def test_autograd_through_fk_and_jacobian_equals_the_analytic_derivatives(robot, seed):
    checks.check_kinematics_gradients(Torch, robot, np.random.default_rng(seed))


@settings(max_examples=2)
@given(seed=SEEDS)
def test_autograd_through_rnea_and_forward_dynamics_equals_the_analytic_derivatives(seed):
    checks.check_dynamics_gradients(Torch, dynamic_arm(seed, n=3 + seed % 2), np.random.default_rng(seed))


def test_export_lang_torch_writes_a_module_giving_the_same_values(tmp_path, rng):
    checks.check_export(Torch, denavit.load_robot("puma560"), tmp_path, rng)
    assert main(["export", "puma560", "--lang", "torch", "-o", str(tmp_path / "out")]) == 0
    text = (tmp_path / "out" / "puma560.py").read_text()
    assert "import torch" in text and "numpy" not in text and "denavit" not in text.split('"""')[2]


def test_results_keep_the_input_dtype_and_batch_shape_and_accept_lists():
    fast = denavit.compile(denavit.load_robot("puma560"), backend="torch")
    q = torch.zeros(2, 1, 3, 6, dtype=torch.float32, requires_grad=True)
    T = fast.fk(q)
    assert T.shape == (2, 1, 3, 4, 4) and T.dtype == torch.float32 and T.device == q.device
    T[..., :3, 3].sum().backward()
    assert q.grad.shape == q.shape
    assert fast.jacobian([0, 0, 0, 0, 0, 0], "tool").dtype == torch.get_default_dtype()  # integers: default float
    assert fast.mass_matrix(torch.zeros(0, 6, dtype=torch.float64)).shape == (0, 6, 6)


def test_bad_inputs_raise_clear_errors():
    fast = denavit.compile(denavit.load_robot("puma560"), backend="torch")
    with pytest.raises(ShapeError, match=r"q: expected shape \(\.\.\., 6\) for a 6-joint robot, got \(5,\)"):
        fast.fk(torch.zeros(5))
    with pytest.raises(ShapeError, match="do not broadcast"):
        fast.rnea(torch.zeros(2, 6), torch.zeros(3, 6), torch.zeros(6))
    with pytest.raises(ValueError, match="frame must be 'base' or 'tool', got 'world'"):
        fast.jacobian(torch.zeros(6), "world")
    kinematic = denavit.compile(random_kinematic_robot(np.random.default_rng(1), n_rows=2), backend="torch")
    with pytest.raises(ModelError, match="no inertial data"):
        kinematic.rnea(torch.zeros(2), torch.zeros(2), torch.zeros(2))
    with pytest.raises(ValueError, match="unknown kernels"):
        denavit.compile(denavit.load_robot("planar2r"), backend="torch", kernels=["fk", "nope"])


def test_missing_torch_names_the_pip_line(monkeypatch):
    monkeypatch.setitem(sys.modules, "torch", None)
    with pytest.raises(MissingDependencyError, match=r"pip install 'denavit\[torch\]'"):
        denavit.compile(denavit.load_robot("planar2r"), backend="torch")


@pytest.mark.slow
@pytest.mark.skipif(os.environ.get("DENAVIT_TEST_TORCH_COMPILE") != "1",
                    reason="torch.compile builds C++ for 18 CPU-s: run with DENAVIT_TEST_TORCH_COMPILE=1")
def test_torch_compile_gives_the_eager_values():
    """torch.compile (dynamo + inductor) of FK and its gradient gives the eager values; fullgraph=True: no graph
    break (an in-place write or a Python branch on a tensor would make one)."""
    fast = denavit.compile(denavit.load_robot("puma560"), backend="torch")
    q = torch.linspace(-1, 1, 24, dtype=torch.float64).reshape(4, 6)

    def loss(q):
        return fast.fk(q)[..., :3, 3].square().sum()

    compiled = torch.compile(loss, fullgraph=True)  # fullgraph: a graph break (an in-place write, say) fails
    q1, q2 = q.clone().requires_grad_(), q.clone().requires_grad_()
    eager, jitted = loss(q1), compiled(q2)
    np.testing.assert_allclose(jitted.item(), eager.item(), rtol=1e-12)
    eager.backward()
    jitted.backward()
    np.testing.assert_allclose(q2.grad.numpy(), q1.grad.numpy(), rtol=1e-12, atol=1e-12)
