"""The compiled one-pose analytic IK as a CPython built-in (codegen._ik_fastcall): same answers, same behaviour.

After its first call, ``fast.analytic_ik`` of an arm with a compiled closed form (elbow: Puma 560, UR class: UR5,
Stanford class) is a built-in function that checks T, runs the kernel and builds the result in machine code.  The
truth: the Python method it replaced (``type(fast).analytic_ik``, which the built-in hands every other call and
every pose the kernel does not answer), field by field and exactly, and the plain forward kinematics for the
solutions themselves.  The compiled and plain solvers' agreement is test_codegen_ik's.
"""

from __future__ import annotations

import dataclasses
import gc
import inspect
import sys

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import denavit
from denavit.errors import ShapeError

pytest.importorskip("numba")

# the hand-overs are counted in _solvers; install is replaced in _ik_fastcall
from denavit.codegen import _ik_fastcall, _solvers

ARMS = ("puma560", "ur5", "stanford")


@pytest.fixture(scope="module")
def arms(tmp_path_factory):
    mp = pytest.MonkeyPatch()
    mp.setenv("DENAVIT_CACHE_DIR", str(tmp_path_factory.mktemp("kernels")))
    out = {}
    for name in ARMS:
        robot = denavit.load_robot(name)
        fast = denavit.compile(robot, kernels=["fk", "fk_jacobian0"])
        fast.analytic_ik(np.eye(4))  # the first call: the built-in appears
        out[name] = robot, fast
    yield out
    mp.undo()


class _Sub(np.ndarray):
    """An ndarray subclass (not exactly ndarray: the built-in leaves it to the method)."""


def _method(fast):
    """The Python method the built-in replaced, bound to ``fast``."""
    return type(fast).analytic_ik.__get__(fast)


def _identical(a, b) -> None:
    """The same result type and every field equal, arrays bit for bit (NaN where NaN) with the same dtype and shape."""
    assert type(a) is type(b)
    for f in dataclasses.fields(denavit.AnalyticIKResult):
        x, y = getattr(a, f.name), getattr(b, f.name)
        if isinstance(y, np.ndarray):
            assert isinstance(x, np.ndarray) and (x.shape, x.dtype) == (y.shape, y.dtype), f.name
            np.testing.assert_array_equal(x, y, err_msg=f.name)
        else:
            assert x == y, f.name


def _outcome(f, *args, **kwargs):
    """f's result, or (exception type, message)."""
    try:
        return f(*args, **kwargs)
    except Exception as exc:  # noqa: BLE001 — compared, not hidden
        return type(exc), str(exc)


def _layouts(T: np.ndarray) -> list[np.ndarray]:
    """T in other memory layouts: Fortran order, every other element of a larger array, reversed strides."""
    big = np.zeros((8, 12))
    big[1::2, ::3] = T
    return [np.asfortranarray(T), big[1::2, ::3], np.ascontiguousarray(T[::-1, ::-1])[::-1, ::-1]]


def test_one_pose_calls_become_a_builtin(arms):
    for robot, fast in arms.values():
        assert type(fast.analytic_ik).__name__ == "builtin_function_or_method"
        assert fast.analytic_ik.__doc__ == type(fast).analytic_ik.__doc__
        assert fast.analytic_ik.__name__ == "analytic_ik"


@settings(max_examples=40)
@given(arm=st.sampled_from(ARMS), u=st.lists(st.floats(0.0, 1.0), min_size=6, max_size=6), wrist=st.booleans())
def test_builtin_answers_as_the_method(arms, arm, u, wrist):
    """Random poses (and wrist-singular ones, q5 = 0: the kernel hands them to the plain solver), in four memory
    layouts: the built-in's result is the method's, field for field; its solutions reproduce T by the plain FK."""
    robot, fast = arms[arm]
    lim = np.clip(robot.q_limits, -np.pi, np.pi)
    q = lim[:, 0] + np.array(u) * (lim[:, 1] - lim[:, 0])
    if wrist:
        q[4] = 0.0
    T = denavit.forward_kinematics(robot, q)
    calls = []
    with pytest.MonkeyPatch.context() as mp:  # the plain solver's calls, by way of the method
        mp.setattr(_solvers, "analytic_ik", lambda *a: calls.append(1) or denavit.analytic_ik(*a))
        got = [fast.analytic_ik(X) for X in [T, *_layouts(T)]]
        handed = len(calls)
        want = _method(fast)(T)
    assert handed == 4 * (len(calls) - handed)  # each built-in call went to the plain solver iff the method does
    assert handed == 4 or not wrist  # a wrist singularity is the plain solver's
    for a in got:
        _identical(a, want)
    if a.count:
        F = denavit.forward_kinematics(robot, a.solutions)
        assert np.abs(F - T).max() < 1e-9
    assert a.count >= 1 or wrist  # q itself is a solution unless the plain solver sees it as a continuum's member


def test_other_calls_are_the_methods(arms):
    """Whatever the built-in does not take (lists, other dtypes and shapes, batches, subclasses, keywords, bad
    counts of arguments, bad targets) gives exactly what the method gives: its result or its error."""
    robot, fast = arms["puma560"]
    T = denavit.forward_kinematics(robot, np.array([0.3, -0.6, 0.4, 0.2, 0.9, -0.4]))
    bad = T.copy()
    bad[0, 1] += 0.5
    nan = T.copy()
    nan[2, 3] = np.nan
    cases = [((T.tolist(),), {}), ((T.astype(np.float32),), {}), ((T.astype(">f8"),), {}),
             ((np.eye(4, dtype=int),), {}),
             ((T.view(_Sub),), {}), ((T[:3],), {}), ((np.stack([T, T]),), {}), ((T.reshape(1, 4, 4),), {}),
             ((), {"T": T}), ((), {}), ((T, T), {}), ((bad,), {}), ((nan,), {}), ((np.full((4, 4), np.inf),), {}),
             ((T.reshape(16),), {}), (("T",), {})]
    method = _method(fast)
    for args, kwargs in cases:
        a, b = _outcome(fast.analytic_ik, *args, **kwargs), _outcome(method, *args, **kwargs)
        if isinstance(b, tuple):
            assert a == b, (args, kwargs)
        else:
            _identical(a, b)
    assert _outcome(fast.analytic_ik, bad)[0] is ShapeError and "orthonormal" in _outcome(fast.analytic_ik, bad)[1]


def test_references_are_kept_and_released(arms):
    """Each result holds one new reference to (labels, kind) and the only one to its output vector; a hand-over
    (wrist-singular pose) and a refused pose leave no reference behind; views outlive the result."""
    robot, fast = arms["ur5"]
    K, m = fast._elbow[0], fast._elbow[1]
    T = denavit.forward_kinematics(robot, np.array([0.3, -1.1, 1.4, 0.2, 0.9, -0.4]))
    singular = denavit.forward_kinematics(robot, np.array([0.3, -1.1, 1.4, 0.2, 0.0, -0.4]))
    bad = np.full((4, 4), np.nan)
    gc.collect()
    k0, m0 = sys.getrefcount(K), sys.getrefcount(m)
    results = [fast.analytic_ik(T) for _ in range(50)]
    assert sys.getrefcount(m) == m0 + 50 and sys.getrefcount(K) == k0
    held = sys.getrefcount(results[0]._o)  # outside the assert (pytest's rewriting keeps the operand)
    assert held == 2  # the slot, and the argument of getrefcount
    solutions = results[-1].solutions.copy()
    view = results[-1].solutions
    del results
    gc.collect()
    assert sys.getrefcount(m) == m0
    np.testing.assert_array_equal(view, solutions)
    for _ in range(20):
        fast.analytic_ik(singular)
        _outcome(fast.analytic_ik, bad)
    gc.collect()
    assert (sys.getrefcount(K), sys.getrefcount(m)) == (k0, m0)


def test_the_method_stays_when_no_builtin_can_be_made(arms, monkeypatch):
    """install failing (another numba, another platform) leaves the Python method in place, answering the same."""
    robot, fast = arms["stanford"]

    def broken(*args, **kwargs):
        raise RuntimeError("no built-in here")

    monkeypatch.setattr(_ik_fastcall, "install", broken)
    other = denavit.compile(robot, kernels=["fk", "fk_jacobian0"])
    T = denavit.forward_kinematics(robot, np.array([0.3, -0.6, 0.4, 0.2, 0.9, -0.4]))
    _identical(other.analytic_ik(T), fast.analytic_ik(T))
    assert inspect.ismethod(other.analytic_ik)
    _identical(other.analytic_ik(T), fast.analytic_ik(T))


def test_threads_get_the_same_answers(arms):
    """The built-in lets go of the GIL while its kernel runs (as numba's entry of the nogil kernels did): calls from
    two threads at once answer as one thread does."""
    from concurrent.futures import ThreadPoolExecutor

    robot, fast = arms["puma560"]
    rng = np.random.default_rng(3)
    lim = np.clip(robot.q_limits, -np.pi, np.pi)
    Ts = list(denavit.forward_kinematics(robot, rng.uniform(lim[:, 0], lim[:, 1], (200, 6))))
    with ThreadPoolExecutor(2) as pool:
        together = list(pool.map(fast.analytic_ik, Ts))
    for a, T in zip(together, Ts):
        _identical(a, _method(fast)(T))
