"""What a cold compile builds: the batch forms of a generated module in one numba function, and the single call of a
kernel with a built-in answered by the built-in (its own njit function compiled only when a call needs it).

Counts of compiled overloads, not times: the point is which programs get compiled.  Results are checked against the
plain numpy functions.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

import denavit
from denavit.codegen import numba_available

pytestmark = pytest.mark.skipif(not numba_available(), reason="numba not installed")


@pytest.fixture
def fresh(tmp_path, monkeypatch):
    """A planar 2R arm nobody else compiles (its own gravity: its own generated module), on an empty cache."""
    monkeypatch.setenv("DENAVIT_CACHE_DIR", str(tmp_path / "kernels"))
    robot = replace(denavit.load_robot("planar2r"), gravity=(0.3, -9.7, 0.1))
    return robot, denavit.compile(robot)


def overloads(dispatcher) -> int:
    return len(dispatcher.overloads)


def test_single_calls_go_through_the_builtin_without_the_njit_single(fresh, rng):
    robot, fast = fresh
    q, qd, qdd = (rng.uniform(-1, 1, 2) for _ in range(3))
    np.testing.assert_allclose(fast.fk(q), denavit.forward_kinematics(robot, q), atol=1e-12)
    np.testing.assert_allclose(fast.rnea(q, qd, qdd), denavit.rnea(robot, q, qd, qdd), atol=1e-12)
    tau = denavit.rnea(robot, q, qd, qdd)
    np.testing.assert_allclose(fast.forward_dynamics(q, qd, tau), qdd, atol=1e-9)
    assert type(fast.fk).__name__ == "builtin_function_or_method"
    m = fast._m
    assert (overloads(m.fk_1), overloads(m.rnea_1), overloads(m.forward_dynamics_1)) == (0, 0, 0)
    # a call the built-in hands back (a keyword) compiles the kernel's own single form, once, and is right
    np.testing.assert_allclose(fast.fk(q, frames=False), denavit.forward_kinematics(robot, q), atol=1e-12)
    np.testing.assert_allclose(fast.fk(list(q)), denavit.forward_kinematics(robot, q), atol=1e-12)
    assert overloads(m.fk_1) == 1


def test_batches_of_every_kernel_share_one_compiled_function(fresh, rng):
    robot, fast = fresh
    seconds = fast.warm()
    assert set(seconds) == set(fast.kernels) - {"fk_jacobian0"}  # the IK solvers' kernel: compiled with them
    m = fast._m
    assert overloads(m.group_n) == 1
    assert all(overloads(getattr(m, f"{k}_n")) == 0 for k in fast.kernels)
    assert overloads(m.fk_jacobian0_1) == 0
    Q, QD, QDD = (rng.uniform(-1, 1, (5, 2)) for _ in range(3))
    np.testing.assert_allclose(fast.fk(Q), denavit.forward_kinematics(robot, Q), atol=1e-12)
    np.testing.assert_allclose(fast.fk(Q, frames=True), denavit.link_transforms(robot, Q), atol=1e-12)
    np.testing.assert_allclose(fast.jacobian(Q, "tool"), denavit.geometric_jacobian(robot, Q, frame="tool"),
                               atol=1e-12)
    np.testing.assert_allclose(fast.rnea(Q, QD, QDD), denavit.rnea(robot, Q, QD, QDD), atol=1e-12)
    np.testing.assert_allclose(fast.coriolis(Q, QD), denavit.coriolis_vector(robot, Q, QD), atol=1e-12)
    np.testing.assert_allclose(fast.mass_matrix(Q), denavit.mass_matrix(robot, Q), atol=1e-12)
    assert overloads(m.group_n) == 1


def test_kernels_compile_with_one_o3_pass_and_the_rest_of_numba_untouched(fresh, rng):
    """The kernels' compiles skip numba's per-function -O3 pass (denavit.codegen._lean); the IK solvers of the same
    module, and numba outside the block, keep numba's pipeline; the lean kernels' numbers are the plain functions'."""
    from numba.core import codegen

    from denavit.codegen import _lean

    robot, fast = fresh
    m = fast._m
    original = codegen.CPUCodeLibrary._optimize_functions
    assert getattr(m.group_n.compile, "_denavit_lean", False)
    assert getattr(m.rnea_1.compile, "_denavit_lean", False)
    solvers = [v for k, v in vars(m).items() if "ik" in k and hasattr(v, "compile")]
    assert solvers and not any(getattr(v.compile, "_denavit_lean", False) for v in solvers)
    with _lean.lean():
        assert codegen.CPUCodeLibrary._optimize_functions is _lean._layout_only
        with _lean.lean():  # nested: still lean, and the outer block restores numba's own
            pass
        assert codegen.CPUCodeLibrary._optimize_functions is _lean._layout_only
    assert codegen.CPUCodeLibrary._optimize_functions is original
    Q = rng.uniform(-1, 1, (7, 2))
    np.testing.assert_allclose(fast.mass_matrix(Q), denavit.mass_matrix(robot, Q), atol=1e-12)
    np.testing.assert_allclose(fast.jacobian(Q[0]), denavit.geometric_jacobian(robot, Q[0]), atol=1e-12)


def test_the_builtins_of_a_module_come_from_one_numba_compile(fresh, rng):
    """The first built-in asked for compiles those of every kernel of the module at once (one cfunc, one LLVM
    module: numba's fixed cost paid once); each then answers its own call, with the plain functions' numbers."""
    from denavit.codegen import _fastcall

    robot, fast = fresh
    q, qd, qdd = (rng.uniform(-1, 1, 2) for _ in range(3))
    np.testing.assert_allclose(fast.fk(q), denavit.forward_kinematics(robot, q), atol=1e-12)
    made = {k: v for (mod, k), v in _fastcall._CFUNCS.items() if mod == fast._m.__name__}
    assert set(made) == {"fk", "position", "jacobian0", "rnea", "mass_matrix", "gravity", "coriolis",
                         "forward_dynamics"}
    assert len({id(cf) for cf, _ in made.values()}) == 1 and len({a for _, a in made.values()}) == 8
    np.testing.assert_allclose(fast.position(q), denavit.forward_kinematics(robot, q)[:3, 3], atol=1e-12)
    np.testing.assert_allclose(fast.jacobian(q), denavit.geometric_jacobian(robot, q), atol=1e-12)
    np.testing.assert_allclose(fast.mass_matrix(q), denavit.mass_matrix(robot, q), atol=1e-12)
    np.testing.assert_allclose(fast.gravity(q), denavit.gravity_torques(robot, q), atol=1e-12)
    np.testing.assert_allclose(fast.coriolis(q, qd), denavit.coriolis_vector(robot, q, qd), atol=1e-12)
    np.testing.assert_allclose(fast.rnea(q, qd, qdd), denavit.rnea(robot, q, qd, qdd), atol=1e-12)
    for method in ("fk", "position", "jacobian", "mass_matrix", "gravity", "coriolis", "rnea"):
        assert type(getattr(fast, method)).__name__ == "builtin_function_or_method", method
