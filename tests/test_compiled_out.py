"""``out=`` on the compiled object's calls: the result written into the caller's array, which is returned.

The truth is the same call without ``out=`` (a fresh array: the route every other test checks against the plain
functions); a wrong ``out`` is refused with one ShapeError line naming what was expected and what was given.
"""

from __future__ import annotations

import numpy as np
import pytest

import denavit
from denavit.errors import ShapeError


@pytest.fixture(scope="module")
def puma():
    robot = denavit.load_robot("puma560")
    return robot, denavit.compile(robot)


def _calls(fast, q, qd, qdd):
    """(call, its inputs) for every method taking out=."""
    return [(fast.fk, (q,), {}), (fast.fk, (q,), {"frames": True}), (fast.position, (q,), {}),
            (fast.jacobian, (q,), {}), (fast.jacobian, (q, "tool"), {}), (fast.rnea, (q, qd, qdd), {}),
            (fast.mass_matrix, (q,), {}), (fast.gravity, (q,), {}), (fast.coriolis, (q, qd), {})]


@pytest.mark.parametrize("shape", [(), (3, 2)])
def test_out_receives_the_result_and_is_returned(puma, rng, shape):
    robot, fast = puma
    q, qd, qdd = rng.uniform(-2, 2, (3,) + shape + (6,))
    for call, args, kw in _calls(fast, q, qd, qdd):
        want = call(*args, **kw)
        out = np.full(want.shape, np.nan)
        got = call(*args, **kw, out=out)
        assert got is out
        np.testing.assert_array_equal(out, want)


def test_out_split_over_threads_equals_the_fresh_unsplit_call(puma, rng):
    robot, fast = puma
    Q = rng.uniform(-3, 3, (10_000, 6))  # over 2 × MIN_ROWS: split in two blocks
    out = np.empty((10_000, 4, 4))
    assert fast.fk(Q, threads=2, out=out) is out
    np.testing.assert_array_equal(out, fast.fk(Q, threads=1))
    J = np.empty((10_000, 6, 6))
    np.testing.assert_array_equal(fast.jacobian(Q, threads=2, out=J), fast.jacobian(Q, threads=1))


def test_out_overlapping_an_input_gets_the_result_of_the_original_input(puma, rng):
    _, fast = puma
    q, qd, qdd = rng.uniform(-2, 2, (3, 5, 6))
    want = fast.rnea(q, qd, qdd)
    assert fast.rnea(q, qd, qdd, out=q) is q
    np.testing.assert_array_equal(q, want)
    g = rng.uniform(-2, 2, 6)
    want = fast.gravity(g)
    np.testing.assert_array_equal(fast.gravity(g, out=g), want)


def test_a_wrong_out_is_one_shape_error_line(puma):
    _, fast = puma
    q = np.zeros((4, 6))
    readonly = np.zeros((4, 4, 4))
    readonly.flags.writeable = False
    for out, says in ((np.zeros((4, 4)), r"shape \(4, 4, 4\), got float64 array of shape \(4, 4\)"),
                      (np.zeros((4, 4, 4), np.float32), "got float32 array"),
                      (np.zeros((4, 4, 8))[..., ::2], "not C-contiguous"),
                      (readonly, "read-only"),
                      ([[0.0] * 4] * 4, "got list")):
        with pytest.raises(ShapeError, match=r"^out: expected a writeable C-contiguous float64 array of shape "
                                             r"\(4, 4, 4\), got ") as err:
            fast.fk(q, out=out)
        assert "\n" not in str(err.value)
        assert err.match(says)
    with pytest.raises(ShapeError, match=r"shape \(6,\), got float64 array of shape \(1, 6\)"):
        fast.rnea(np.zeros(6), np.zeros(6), np.zeros(6), out=np.zeros((1, 6)))
