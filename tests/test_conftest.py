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
