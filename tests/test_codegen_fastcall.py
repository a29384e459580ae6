"""The compiled object's single call as a CPython built-in (codegen._fastcall): same numbers, same behaviour.

After the first call, ``fast.fk`` and the other single-call methods are built-in functions taking float64 vectors
in machine code; everything else must behave exactly as the Python methods do.  The truth: the plain numpy
functions of denavit on the same inputs, and the compiled batch path (another machine-code route).
"""

from __future__ import annotations

import sys

import numpy as np
import pytest

import denavit
from denavit.codegen import numba_available
from denavit.errors import ShapeError

pytestmark = pytest.mark.skipif(not numba_available(), reason="numba not installed")


@pytest.fixture(scope="module")
def puma(tmp_path_factory):
    mp = pytest.MonkeyPatch()
    mp.setenv("DENAVIT_CACHE_DIR", str(tmp_path_factory.mktemp("kernels")))
    robot = denavit.load_robot("puma560")
    fast = denavit.compile(robot, kernels=["fk", "frames", "jacobian0", "jacobiane", "rnea", "mass_matrix",
                                           "forward_dynamics"])
    q = np.zeros(6)
    fast.fk(q), fast.jacobian(q), fast.rnea(q, q, q), fast.mass_matrix(q)  # first calls: the built-ins appear
    fast.forward_dynamics(q, q, q)
    yield robot, fast
    mp.undo()


def test_single_calls_become_builtins_with_the_same_numbers(puma, rng):
    robot, fast = puma
    assert all(type(getattr(fast, m)).__name__ == "builtin_function_or_method"
               for m in ("fk", "jacobian", "rnea", "mass_matrix", "forward_dynamics"))
    for q, qd, qdd in rng.uniform(-3, 3, (20, 3, 6)):
        T = fast.fk(q)
        assert T.shape == (4, 4) and T.dtype == np.float64 and T.flags.c_contiguous and T.flags.writeable
        np.testing.assert_array_equal(T, fast.fk(q[None])[0])  # the batch kernel: same program, same rounding
        np.testing.assert_allclose(T, denavit.forward_kinematics(robot, q), atol=1e-13)
        np.testing.assert_allclose(fast.jacobian(q), denavit.geometric_jacobian(robot, q), atol=1e-13)
        np.testing.assert_allclose(fast.rnea(q, qd, qdd), denavit.rnea(robot, q, qd, qdd), rtol=1e-12, atol=1e-11)
        np.testing.assert_allclose(fast.mass_matrix(q), denavit.mass_matrix(robot, q), rtol=1e-12, atol=1e-12)
        acc = fast.forward_dynamics(q, qd, qdd)  # qdd stands for τ here
        assert acc.shape == (6,)
        np.testing.assert_array_equal(acc, fast.forward_dynamics(q[None], qd[None], qdd[None])[0])
        np.testing.assert_allclose(acc, denavit.forward_dynamics(robot, q, qd, qdd), rtol=1e-9, atol=1e-9)
    assert fast.fk(q) is not fast.fk(q)  # a fresh array each call


def test_other_inputs_take_the_python_method(puma, rng):
    robot, fast = puma
    q = rng.uniform(-3, 3, 6)
    want = denavit.forward_kinematics(robot, q)
    strided = np.zeros(12)
    strided[::2] = q
    readonly = q.copy()
    readonly.flags.writeable = False
    class Sub(np.ndarray):
        pass

    for x in (strided[::2], readonly, q.tolist(), tuple(q), q.astype(">f8"), q.view(Sub)):
        np.testing.assert_allclose(fast.fk(x), want, atol=1e-13)
    np.testing.assert_allclose(fast.fk(q.astype(np.float32)), want, atol=1e-6)
    assert fast.fk(np.tile(q, (3, 2, 1))).shape == (3, 2, 4, 4)
    assert fast.fk(q, frames=True).shape == (len(robot.links) + 1, 4, 4)
    assert fast.fk(q, threads=1).shape == (4, 4)
    np.testing.assert_allclose(fast.jacobian(q, "tool"), denavit.geometric_jacobian(robot, q, frame="tool"),
                               atol=1e-13)
    np.testing.assert_allclose(fast.fk(q=q), want, atol=1e-13)
    for bad in (np.zeros(5), np.zeros((2, 5)), np.float64(1.0)):
        with pytest.raises(ShapeError, match=r"expected shape \(\.\.\., 6\)"):
            fast.fk(bad)
    with pytest.raises(ShapeError):
        fast.rnea(q, q, np.zeros(7))
    with pytest.raises(TypeError):
        fast.rnea(q, q)
    with pytest.raises(ValueError):
        fast.fk(["a"] * 6)


def test_no_references_leak(puma, rng):
    _, fast = puma
    q = rng.uniform(-1, 1, 6)
    before = sys.getrefcount(q)
    for _ in range(1000):
        fast.fk(q)
        fast.rnea(q, q, q)
    assert sys.getrefcount(q) == before
    assert sys.getrefcount(fast.fk(q)) == 2  # the call's result, referenced only by getrefcount's argument


def test_forward_dynamics_where_m_is_singular_raises_through_the_method(tmp_path, monkeypatch):
    """The built-in hands a call whose regularity flag is not > 0 to the method, which raises."""
    from dataclasses import replace

    from denavit.errors import ModelError

    monkeypatch.setenv("DENAVIT_CACHE_DIR", str(tmp_path))
    robot = denavit.load_robot("planar2r")
    massless = replace(robot, links=robot.links[:-1] + (replace(robot.links[-1], inertia=None),))
    fast = denavit.compile(massless, kernels=["forward_dynamics"])
    with pytest.raises(ModelError, match="singular"):
        fast.forward_dynamics(np.zeros(2), np.zeros(2), np.ones(2))  # the first call: the method itself
    assert type(fast.forward_dynamics).__name__ == "builtin_function_or_method"
    with pytest.raises(ModelError, match="singular"):
        fast.forward_dynamics(np.zeros(2), np.zeros(2), np.ones(2))
