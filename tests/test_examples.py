"""Every script in examples/ runs in its own process, exits 0 (each asserts its own checks) and prints its result."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
SCRIPTS = sorted(EXAMPLES.glob("*.py"))
#: a line each script prints once its checks have passed (the scripts' asserts come before or around it)
SHOWS = {
    "forward_kinematics_and_jacobians.py": "J0 equals finite differences of FK",
    "inverse_kinematics.py": "solve_ik: True",
    "dynamics_and_simulation.py": "energy drift",
    "symbolic_derivation.py": "p_x = C1*C2*a2 + C1*C23*a3 - C1*S23*d4 + S1*d3",
    "checking_claims.py": "[INCORRECT] position with a sign slip",
}
TIMEOUT = 120  # s; each takes a few seconds on a quiet machine


def test_every_example_is_listed_here_and_in_the_index():
    names = {p.name for p in SCRIPTS}
    assert names == set(SHOWS), names ^ set(SHOWS)
    index = (EXAMPLES / "README.md").read_text(encoding="utf-8")
    assert all(f"]({n})" in index for n in names)


#: scripts that take more than a few seconds (sympy work): run in the full suite only
SLOW = {"symbolic_derivation.py", "checking_claims.py"}


@pytest.mark.parametrize("script", [pytest.param(p, id=p.stem, marks=[pytest.mark.slow] if p.name in SLOW else [])
                                    for p in SCRIPTS])
def test_example_runs_and_checks_itself(script, tmp_path):
    env = dict(os.environ, MPLBACKEND="Agg", PYTHONHASHSEED="0")
    done = subprocess.run([sys.executable, str(script)], cwd=tmp_path, env=env, capture_output=True, text=True,
                          timeout=TIMEOUT)
    assert done.returncode == 0, done.stderr[-2000:]
    assert SHOWS[script.name] in done.stdout, done.stdout[-2000:]
    assert "Traceback" not in done.stderr
    assert not any(tmp_path.iterdir())  # examples write nothing unasked
