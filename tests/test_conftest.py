"""The shared test helpers of conftest.py do what the tests rely on."""

import numpy as np
from hypothesis import given, settings, strategies as st

import denavit
from conftest import CI, REDUCED, random_q_in_limits, robots


@settings(max_examples=30)
@given(robot=robots(), seed=st.integers(0, 2**32 - 1))
def test_random_q_in_limits_stays_inside_and_fills_them(robot, seed):
    rng = np.random.default_rng(seed)
    q = random_q_in_limits(robot, rng, 200)
    lim = robot.q_limits
    lo = np.where(np.isfinite(lim[:, 0]), lim[:, 0], -np.pi)
    hi = np.where(np.isfinite(lim[:, 1]), lim[:, 1], np.pi)
    assert q.shape == (200, robot.dof)
    assert np.all((q >= lo) & (q <= hi))
    assert np.all(q.max(axis=0) - q.min(axis=0) > 0.8 * (hi - lo))  # spread over the whole range, not a corner
    assert np.all(np.isfinite(denavit.forward_kinematics(robot, q)))


def test_robots_strategy_gives_both_conventions_and_prismatic_joints():
    seen = set()

    @given(robots())
    def collect(robot):
        seen.add(robot.convention.value)
        seen.update(t.value for t in robot.joint_types)

    collect()
    assert {"standard", "modified", "revolute", "prismatic"} <= seen


def test_ci_fixture_is_the_flag(ci, request):
    """The fixture says "fewer random cases": on CI, and in the quick subset (-m "not slow")."""
    import os

    quick = "not slow" in " ".join((request.config.getoption("markexpr", "") or "").split())
    assert ci is REDUCED and REDUCED == (CI or quick)
    assert (os.environ.get("DENAVIT_QUICK_TESTS") == "1") == quick


def test_rng_fixture_is_seeded_per_test(rng, request):
    again = np.random.default_rng(sum(request.node.nodeid.encode()) + 16)
    assert rng.random() == again.random()


def test_cpu_times_are_written_per_test_and_read_by_the_slow_list_script(tmp_path):
    """DENAVIT_CPU_TIMES: each test's CPU seconds, a line each; a test burning CPU is over the threshold, an idle
    sleeping one is not (CPU, not wall-clock: what a busy machine does not inflate)."""
    import importlib.util
    import os
    import subprocess
    import sys
    from pathlib import Path

    here = Path(__file__).resolve().parent
    (tmp_path / "conftest.py").write_text((here / "conftest.py").read_text(encoding="utf-8"), encoding="utf-8")
    (tmp_path / "slow_tests.txt").write_text("", encoding="utf-8")
    (tmp_path / "_random_robots.py").write_text((here / "_random_robots.py").read_text(encoding="utf-8"),
                                                encoding="utf-8")
    (tmp_path / "test_two.py").write_text(
        "import time\n"
        "def test_burn():\n    t = time.process_time()\n    while time.process_time() - t < 0.6: pass\n"
        "def test_sleep():\n    time.sleep(0.6)\n", encoding="utf-8")
    out = tmp_path / "cpu.txt"
    env = {**os.environ, "DENAVIT_CPU_TIMES": str(out)}
    subprocess.run([sys.executable, "-m", "pytest", "-q", "-n", "0", "-p", "no:cacheprovider",
                    "--rootdir", str(tmp_path), "-o", "addopts=", str(tmp_path / "test_two.py")],
                   cwd=tmp_path, env=env, check=True, capture_output=True, timeout=300)
    lines = dict(reversed(line.split(" ", 1)) for line in out.read_text(encoding="utf-8").splitlines())
    assert float(lines["test_two.py::test_burn"]) >= 0.5
    assert float(lines["test_two.py::test_sleep"]) < 0.3
    spec = importlib.util.spec_from_file_location("slow_tests", here.parent / "scripts" / "slow_tests.py")
    script = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(script)
    assert script.slow_ids_cpu(out.read_text(encoding="utf-8"), 0.4) == {"test_two.py::test_burn"}


def test_numeric_function_equals_lambdify_on_random_formulas():
    """tests/_evaluate.numeric_function (the DAG evaluator test_symbolic_dynamics uses for the Panda's formulas)
    gives lambdify's values on random expressions that share sub-expressions, and refuses what it cannot do."""
    import pytest
    import sympy as sp

    from _evaluate import numeric_function

    rng = np.random.default_rng(5)
    x, y, z = sp.symbols("x y z", real=True)
    for _ in range(30):
        pool = [x, y, z, sp.Rational(int(rng.integers(-9, 9)), int(rng.integers(1, 9))), sp.Float(rng.normal())]
        for _ in range(12):  # each new node reuses earlier ones: a DAG
            a, b = (pool[int(k)] for k in rng.integers(0, len(pool), 2))
            op = int(rng.integers(0, 6))
            pool.append([a + b, a * b, a - 3 * b, sp.sin(a) * b, sp.cos(a + b), a**2 + b**3][op])
        M = sp.Matrix(2, 2, pool[-4:])
        point = rng.uniform(-2, 2, 3)
        (got,) = numeric_function([x, y, z], [M])(*point)
        want = np.array(sp.lambdify([x, y, z], M, "numpy")(*point), dtype=float)
        np.testing.assert_allclose(got, want, rtol=1e-12, atol=1e-12)
    with pytest.raises(TypeError, match="no rule for"):
        numeric_function([x], [sp.Matrix([sp.besselj(0, x)])])(1.0)
    with pytest.raises(KeyError, match="no value for symbol y"):
        numeric_function([x], [sp.Matrix([x * y])])(1.0)


def test_slow_tests_budget_lists_the_costliest_until_the_rest_fit():
    """scripts/slow_tests.py --budget: the most expensive tests (repeated lines summed) are listed until the others
    sum to at most the budget; already listed tests neither count nor get listed again."""
    import importlib.util
    from pathlib import Path

    here = Path(__file__).resolve().parent
    spec = importlib.util.spec_from_file_location("slow_tests", here.parent / "scripts" / "slow_tests.py")
    script = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(script)
    rng = np.random.default_rng(3)
    cost = {f"t.py::test_{k}": float(c) for k, c in enumerate(rng.uniform(0.01, 3.0, 40))}
    report = "".join(f"{c / 2:.3f} {node}\n{c / 2:.3f} {node}\n" for node, c in cost.items()) + "garbage line\n"
    listed = {"t.py::test_0"}
    for budget in (0.0, 5.0, 20.0, 1e6):
        out = script.within_budget(report, budget, listed)
        rest = {node: c for node, c in cost.items() if node not in out and node not in listed}
        assert sum(rest.values()) <= budget + 1e-3 * len(cost)
        assert not out & listed
        if out:  # nothing cheaper was listed while a dearer one stayed
            assert min(cost[n] for n in out) >= max(rest.values(), default=0.0) - 2e-3
    assert script.within_budget(report, 1e6, listed) == set()
