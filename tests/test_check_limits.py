"""The limits of one claims file on the costly kinds: no count cap any more (the 20-claim cap is gone), a bound on
± sign choices and on distinct singularity analyses per file, and a CPU bound on one symbolic singularity analysis
(past it the claim is judged on its own conditions, never called correct)."""

from __future__ import annotations

from pathlib import Path

import pytest
import yaml

import denavit as dn
from denavit.check import MAX_SIGN_CHOICES, MAX_SINGULAR_SETS, check_claims
from denavit.check import _singular
from denavit.errors import ParseError

EXAMPLE = Path(__file__).resolve().parents[1] / "examples" / "claims" / "planar2r-ik-singular-dynamics.yaml"


def test_more_than_twenty_costly_claims_are_judged_as_one_by_one():
    claims = yaml.safe_load(EXAMPLE.read_text())["claims"]
    robot = dn.load_robot("planar2r")
    alone = [v.verdict for v in check_claims(robot, claims).verdicts]
    many = [dict(claims[k % len(claims)]) for k in range(3 * len(claims))]
    costly = sum(c["quantity"] in ("singularities", "ik_formula", "ik_solutions") for c in many)
    assert costly > 20
    res = check_claims(robot, many)
    assert [v.verdict for v in res.verdicts] == alone * 3


def test_sign_choices_of_a_file_are_bounded():
    robot = dn.load_robot("planar2r")
    six = {"quantity": "ik_formula", "value": r"q_1 = \operatorname{atan2}(y, x) " + r"\pm 0 " * 6}
    n = MAX_SIGN_CHOICES // 64
    check_claims(robot, [dict(six) for _ in range(1)])  # one such claim is fine
    with pytest.raises(ParseError, match=f"{(n + 1) * 64} ± sign choices together"):
        check_claims(robot, [dict(six) for _ in range(n + 1)])


def test_distinct_singularity_analyses_of_a_file_are_bounded():
    robot = dn.load_robot("planar2r")
    rows = ["vx,vy", "vx,wz", "vy,wz", "vx,vz", "vy,vz", "vz,wz"][:MAX_SINGULAR_SETS + 1]
    claims = [{"quantity": "singularities", "rows": r, "value": "q_2 = 0"} for r in rows]
    with pytest.raises(ParseError, match=f"{MAX_SINGULAR_SETS + 1} different rows/frame"):
        check_claims(robot, claims)
    assert len(check_claims(robot, claims[:MAX_SINGULAR_SETS]).verdicts) == MAX_SINGULAR_SETS


def _spin(*args):
    while True:  # an analysis that never ends
        pass


def test_a_singularity_analysis_past_its_cpu_bound_is_never_called_correct(monkeypatch):
    robot = dn.load_robot("scara")  # 4 joints: analysed in a child process
    monkeypatch.setattr(_singular, "_analyse", _spin)
    monkeypatch.setattr(_singular, "MAX_ANALYSIS_CPU_SECONDS", 1)
    calls = []
    bounded = _singular.cpu_bounded
    monkeypatch.setattr(_singular, "cpu_bounded", lambda *a, **k: calls.append(a[1]) or bounded(*a, **k))
    _singular._analysis.cache_clear()
    try:
        res = check_claims(robot, [{"quantity": "singularities", "rows": "vx,vy", "value": r"\sin q_2 = 0"},
                                   {"quantity": "singularities", "rows": "vx,vy", "value": "q_2 = 0.7"}])
    finally:
        _singular._analysis.cache_clear()
    good, bad = res.verdicts
    assert good.verdict == "ambiguous" and "was not computed within 1 s of CPU" in good.message, good.message
    assert bad.verdict == "incorrect" and "is not singular" in bad.message, bad.message
    assert len(calls) == 1  # one analysis, stopped once (the second claim shares the cached outcome)


def test_the_bounded_analysis_returns_the_library_result():
    robot = dn.load_robot("scara")
    _singular._analysis.cache_clear()
    try:
        v = check_claims(robot, [{"quantity": "singularities", "rows": "vx,vy", "value": r"\sin q_2 = 0"}]).verdicts[0]
    finally:
        _singular._analysis.cache_clear()
    assert v.verdict == "correct", v.message
