"""The compiled derivative and regressor single calls as CPython built-ins (codegen._fastcall), several results.

After the first call, ``fast.rnea_derivatives`` returns a tuple of two fresh arrays and
``fast.forward_dynamics_derivatives`` a tuple of three, made in machine code; ``gravity_derivatives``,
``jacobian_dot``, ``acceleration_bias``, ``kinematic_hessian`` and ``regressor`` one array each.  The truth: the
plain numpy functions of denavit (forward-mode duals run by numpy, another route than the traced program), and the
Python method of the class on the same object (the route the built-in stands in for).  Reference counts are read
with ``sys.getrefcount``; a leak would show as memory that tracemalloc sees growing over 10⁴ calls.
"""

from __future__ import annotations

import dataclasses
import sys
import tracemalloc

import numpy as np
import pytest
from _random_robots import random_inertia, random_robot

import denavit
from denavit.codegen import CompiledRobot, numba_available
from denavit.errors import ModelError, ShapeError

pytestmark = pytest.mark.skipif(not numba_available(), reason="numba not installed")

DERIVATIVES = ("rnea_derivatives", "forward_dynamics_derivatives", "gravity_derivatives", "jacobian_dot",
               "acceleration_bias", "kinematic_hessian", "regressor")


def _arm():
    """A 3-joint random arm (seeded; a prismatic joint, friction, motor inertia, odd gravity): small, so its
    derivative kernels compile in a few seconds the first time (then the disk cache has them)."""
    rng = np.random.default_rng(3)
    robot = random_robot(rng, n_rows=3)
    while robot.dof != 3 or "prismatic" not in {link.joint.value for link in robot.links}:
        robot = random_robot(rng, n_rows=3)
    links = tuple(dataclasses.replace(link, inertia=random_inertia(rng)) for link in robot.links)
    return robot.replace(links=links, gravity=(0.3, -2.0, -9.0))


@pytest.fixture(scope="module")
def arm():
    robot = _arm()
    fast = denavit.compile(robot)
    z = np.zeros(3)
    for name in DERIVATIVES:  # first calls: the built-ins appear
        getattr(fast, name)(*(z,) * (1 if name in ("gravity_derivatives", "kinematic_hessian") else
                                     2 if name in ("jacobian_dot", "acceleration_bias") else 3))
    return robot, fast


def _rel(a, b):
    return float(np.max(np.abs(a - b)) / max(1.0, float(np.max(np.abs(b)))))


def test_derivative_single_calls_are_builtins_agreeing_with_the_method_and_the_plain_functions(arm, rng):
    robot, fast = arm
    assert all(type(getattr(fast, m)).__name__ == "builtin_function_or_method" for m in DERIVATIVES)
    for q, qd, x in rng.uniform(-2, 2, (5, 3, 3)):
        for name, args, plain in (
                ("rnea_derivatives", (q, qd, x), denavit.rnea_derivatives(robot, q, qd, x)),
                ("forward_dynamics_derivatives", (q, qd, x), denavit.forward_dynamics_derivatives(robot, q, qd, x)),
                ("gravity_derivatives", (q,), denavit.gravity_derivatives(robot, q)),
                ("jacobian_dot", (q, qd), denavit.jacobian_dot(robot, q, qd)),
                ("acceleration_bias", (q, qd), denavit.acceleration_bias(robot, q, qd)),
                ("kinematic_hessian", (q,), denavit.kinematic_hessian(robot, q)),
                ("regressor", (q, qd, x), denavit.regressor(robot, q, qd, x))):
            got = getattr(fast, name)(*args)
            method = getattr(CompiledRobot, name)(fast, *args)  # the Python method: the same program, other code
            assert type(got) is type(method) and type(got) in (tuple, np.ndarray)
            for g, m, p in zip(*((got, method, plain) if isinstance(got, tuple) else ((got,), (method,), (plain,)))):
                assert type(g) is np.ndarray and g.dtype == np.float64 and g.shape == np.shape(p)
                assert g.flags.c_contiguous and g.flags.writeable and g.flags.owndata
                np.testing.assert_array_equal(g, m)
                assert _rel(g, p) < 1e-11, name


def test_each_call_returns_new_arrays_owned_by_the_caller(arm, rng):
    _, fast = arm
    q, qd, qdd = rng.uniform(-1, 1, (3, 3))
    first = fast.forward_dynamics_derivatives(q, qd, qdd)
    second = fast.forward_dynamics_derivatives(q, qd, qdd)
    assert len(first) == 3 and first is not second
    blocks = first + second
    assert not any(np.shares_memory(a, b) for i, a in enumerate(blocks) for b in blocks[i + 1:])
    assert sys.getrefcount(first) == 2  # the name and getrefcount's argument
    A, B = fast.rnea_derivatives(q, qd, qdd)  # the tuple is gone: each array referenced by its name only
    assert sys.getrefcount(A) == sys.getrefcount(B) == 2
    assert sys.getrefcount(fast.gravity_derivatives(q)) == 2
    A[:] = 7.0  # writing a result changes nothing the next call returns
    assert not np.array_equal(fast.rnea_derivatives(q, qd, qdd)[0], A)


def test_no_reference_or_memory_leak_over_ten_thousand_calls(arm, rng):
    _, fast = arm
    q, qd, qdd = rng.uniform(-1, 1, (3, 3))
    counts = [sys.getrefcount(x) for x in (q, qd, qdd)]
    for _ in range(200):  # numpy's small-block caches filled before measuring
        fast.rnea_derivatives(q, qd, qdd), fast.forward_dynamics_derivatives(q, qd, qdd)
    tracemalloc.start()
    try:
        start = tracemalloc.get_traced_memory()[0]
        for _ in range(10_000):
            fast.rnea_derivatives(q, qd, qdd)
            fast.forward_dynamics_derivatives(q, qd, qdd)
            fast.regressor(q, qd, qdd)
        grown = tracemalloc.get_traced_memory()[0] - start
    finally:
        tracemalloc.stop()
    assert grown < 64_000  # one leaked 3 × 3 block per call would be 10⁴ × (72 bytes of data + the object)
    assert [sys.getrefcount(x) for x in (q, qd, qdd)] == counts


def test_other_calls_take_the_python_method(arm, rng):
    robot, fast = arm
    q, qd, qdd = rng.uniform(-1, 1, (3, 3))
    want = denavit.rnea_derivatives(robot, q, qd, qdd)
    strided = np.repeat(q, 2)[::2]  # the built-in reads any stride; a list goes to the method
    for args in ((list(q), qd, qdd), (strided, qd, qdd)):
        for g, w in zip(fast.rnea_derivatives(*args), want):
            assert _rel(g, w) < 1e-11
    got = fast.rnea_derivatives(q, qd, qdd, threads=1)
    assert isinstance(got, tuple) and all(_rel(g, w) < 1e-11 for g, w in zip(got, want))
    batch = fast.rnea_derivatives(np.tile(q, (4, 1)), qd, qdd)
    assert batch[0].shape == (4, 3, 3) and _rel(batch[0][2], want[0]) < 1e-11
    assert fast.jacobian_dot(q, qd, "tool").shape == (6, 3)
    with pytest.raises(ShapeError, match="qdd: expected shape"):
        fast.rnea_derivatives(q, qd, np.zeros(4))
    with pytest.raises(ShapeError, match="tau: expected shape"):
        fast.forward_dynamics_derivatives(q, qd, np.zeros(2))
    with pytest.raises(TypeError):
        fast.regressor(q, qd)


def test_singular_mass_matrix_raises_through_the_builtin():
    """The built-in releases its result and hands a call whose regularity flag is not > 0 to the method."""
    robot = denavit.load_robot("planar2r")
    massless = robot.replace(links=robot.links[:-1] + (dataclasses.replace(robot.links[-1], inertia=None),))
    fast = denavit.compile(massless)
    with pytest.raises(ModelError, match="singular"):
        fast.forward_dynamics_derivatives(np.zeros(2), np.zeros(2), np.ones(2))  # the first call: the method
    assert type(fast.forward_dynamics_derivatives).__name__ == "builtin_function_or_method"
    for _ in range(3):
        with pytest.raises(ModelError, match="singular"):
            fast.forward_dynamics_derivatives(np.zeros(2), np.zeros(2), np.ones(2))


@pytest.mark.parametrize("shape", [(), (2, 3)])
def test_out_on_the_one_array_calls(arm, rng, shape):
    """gravity_derivatives, jacobian_dot (both frames), acceleration_bias, kinematic_hessian and regressor write into
    ``out=`` and return it; the values are those of the call without it; a wrong out is one ShapeError."""
    _, fast = arm
    q, qd, qdd = rng.uniform(-2, 2, (3,) + shape + (3,))
    for name, args, kw in (("gravity_derivatives", (q,), {}), ("jacobian_dot", (q, qd), {}),
                           ("jacobian_dot", (q, qd), {"frame": "tool"}), ("acceleration_bias", (q, qd), {}),
                           ("kinematic_hessian", (q,), {}), ("regressor", (q, qd, qdd), {})):
        call = getattr(fast, name)
        want = call(*args, **kw)
        out = np.full(want.shape, np.nan)
        assert call(*args, **kw, out=out) is out, name
        np.testing.assert_array_equal(out, want)
        with pytest.raises(ShapeError, match=r"^out: expected a writeable C-contiguous float64 array of shape"):
            call(*args, **kw, out=np.zeros(want.shape + (1,)))
