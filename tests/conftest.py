"""Shared test settings: the CI flag, hypothesis profiles, random joint values, the seed-report folder.

- ``CI`` (and the ``ci`` fixture): true when the environment variable ``CI`` is ``"true"`` (``.ci/run`` sets it).
  ``REDUCED``: true on CI and in the quick subset; tests use it to run fewer random cases (what each case
  asserts does not change).
- Hypothesis profiles: ``ci`` (derandomized, so a CI failure reproduces) and ``dev`` (random), chosen by
  ``CI``; neither has a deadline nor the "input generation is slow" health check (the machine may be busy); ``HYPOTHESIS_PROFILE=...`` overrides.  Example counts
  stay those of each test's own ``@settings``.
- ``robots(**options)``: a hypothesis strategy of random DH arms (``_random_robots.random_robot``: both
  conventions, prismatic joints, offsets, fixed rows, base and tool), drawn from a seed so a failure reproduces.
- ``random_q_in_limits(robot, rng, n)``: n configurations uniform within the joint limits (±π where a limit
  is infinite); the ``rng`` fixture is a fresh ``numpy.random.Generator`` per test (seeded, reproducible).
- ``SEED_REPORTS``: the project's shared seed reports (``../shared/seeds`` beside the clone, outside the
  repository); the tests that read them (test_import_table.py) skip with a reason when they are absent.
- Slow tests carry ``@pytest.mark.slow``, or are listed in tests/slow_tests.txt (those over 2 s in a
  ``--durations`` report, scripts/slow_tests.py); tests marked ``browser`` are slow too (a real browser starts), so
  ``python -m pytest -m "not slow"`` is the quick subset.  In the quick subset the generated hostile-input
  corpora (tests/test_hostile_*.py) run a fifth of their cases (``_hostile.corpus``); the full suite, and CI,
  run them all.
"""

from __future__ import annotations

import os
from pathlib import Path

# One BLAS thread per process.  pytest-xdist already runs a worker per core; OpenBLAS's own threads on top (for
# the SVDs, QRs and least squares of stacked regressors and Jacobians) wait for a core by spinning, which on a
# busy machine cost a third of the CPU of the regressor and calibration tests (13.8 → 9.1 CPU-s, same tests).
# Set before numpy loads OpenBLAS; inherited by the xdist workers and by every subprocess a test starts; a value
# already in the environment is kept.  What any test computes is unchanged.
for _pool in ("OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_pool, "1")

import numpy as np  # noqa: E402  (after the thread-pool settings above)
import pytest  # noqa: E402
from hypothesis import HealthCheck, settings
from hypothesis import strategies as st

from _random_robots import random_robot

CI = os.environ.get("CI") == "true"
#: Run fewer random cases (what each asserts is the same): on CI, and in the quick subset (set in pytest_configure,
#: which runs before the test modules import it).
REDUCED = CI

settings.register_profile("ci", deadline=None, derandomize=True, print_blob=True,
                          suppress_health_check=[HealthCheck.too_slow])
settings.register_profile("dev", deadline=None, suppress_health_check=[HealthCheck.too_slow])
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "ci" if CI else "dev"))

_HERE = Path(__file__).resolve().parent
#: the project's shared folder of seed reports: ``shared/seeds`` beside the clone (CI clones main with
#: ``shared/`` next to it); absent in a plain clone, and the tests reading it then skip.
SEED_REPORTS = next((p for p in (_HERE.parents[1] / "shared" / "seeds", _HERE.parents[2] / "shared" / "seeds")
                     if p.is_dir()), _HERE.parents[1] / "shared" / "seeds")


def random_q_in_limits(robot, rng: np.random.Generator, n: int) -> np.ndarray:
    """(n, dof) joint values uniform within the robot's limits; an infinite limit counts as ±π."""
    lim = robot.q_limits
    lim = np.where(np.isfinite(lim), lim, np.sign(lim) * np.pi)
    return rng.uniform(lim[:, 0], lim[:, 1], (n, robot.dof))


def robots(**options) -> st.SearchStrategy:
    """Random arms for ``@given``; ``options`` go to ``random_robot`` (convention, n_rows, fixed_rows, base_tool)."""
    return st.integers(0, 2**32 - 1).map(lambda seed: random_robot(np.random.default_rng(seed), **options))


@pytest.fixture
def ci() -> bool:
    """True on CI and in the quick subset: run fewer random cases."""
    return REDUCED


@pytest.fixture
def rng(request) -> np.random.Generator:
    """A generator seeded from the test's node id: reproducible, different per test."""
    return np.random.default_rng(sum(request.node.nodeid.encode()) + 16)


def pytest_configure(config):
    """The quick subset (``-m "not slow"``) runs the reduced random case counts of CI, and the hostile corpora a
    fifth of their cases."""
    global REDUCED
    if "not slow" in " ".join((config.getoption("markexpr", "") or "").split()):
        os.environ["DENAVIT_QUICK_TESTS"] = "1"
        REDUCED = True


#: Tests that took more than 2 s in the quick subset (tests/slow_tests.txt, written by scripts/slow_tests.py from
#: a --durations report): marked ``slow`` here, so that the quick subset stays within about two minutes of CPU.
SLOW_TESTS = frozenset(line.strip() for line in (_HERE / "slow_tests.txt").read_text(encoding="utf-8").splitlines()
                       if line.strip() and not line.startswith("#"))


def pytest_collection_modifyitems(config, items):
    slow = pytest.mark.slow
    for item in items:
        if item.get_closest_marker("browser") is not None or item.nodeid in SLOW_TESTS:
            item.add_marker(slow)


#: ``DENAVIT_CPU_TIMES=FILE``: append each test's CPU seconds (this process and the child processes it waited for,
#: setup + call + teardown) to FILE, one ``seconds node-id`` a line — what a test costs on any machine, busy or
#: not (wall-clock ``--durations`` grow with the load).  ``scripts/slow_tests.py --cpu FILE`` reads it.
_CPU_TIMES = os.environ.get("DENAVIT_CPU_TIMES")

if _CPU_TIMES:
    import resource

    def _cpu() -> float:
        me, kids = resource.getrusage(resource.RUSAGE_SELF), resource.getrusage(resource.RUSAGE_CHILDREN)
        return me.ru_utime + me.ru_stime + kids.ru_utime + kids.ru_stime

    @pytest.hookimpl(hookwrapper=True)
    def pytest_runtest_protocol(item, nextitem):
        start = _cpu()
        yield
        with open(_CPU_TIMES, "a", encoding="utf-8") as f:
            f.write(f"{_cpu() - start:.3f} {item.nodeid}\n")
