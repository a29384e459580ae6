"""The report grader on a corpus of student-style reports written for the tests (``tests/data/reports/``).

Each fixture is a derivation of a different arm in its own notation, with deliberate slips. Right after each
equation's block (display math, or the paragraph of an inline result) it states the verdict(s) it expects, in
order: ``<!-- expect: correct, incorrect -->`` (``% expect: …`` in a .tex file). A fixture that needs arguments
says so on its first line: ``<!-- denavit-test: robot=planar3r-lagrange -->`` or ``arms=1:planar2r-mdh,2:…``.

The expected verdicts come from an independent derivation (``tests/data/reports/_truth.py``: SymPy, our own DH
products, never denavit's code); ``test_corpus_truth_holds`` re-runs it. The seed reports are not copied here.

What is asserted, per fixture:
- the verdicts of the claims whose ``end_line`` lies in the block before an ``expect`` comment equal the expected
  list, "not a claim" aside (a block expected to hold a definition must have at least one claim reported "not a
  claim"; how many, and any the reader adds beside results, e.g. for a restated q, is the reader's affair);
- no result expected correct (or not a claim, or ambiguous) is judged incorrect, and no equation without an
  ``expect`` comment is judged incorrect (a misreading must never make a correct result "incorrect");
- at least 90 % of the expected results (correct, incorrect, ambiguous) are found and judged.
"""

from __future__ import annotations

import re
import subprocess
import sys
from functools import cache
from pathlib import Path

import pytest

DATA = Path(__file__).parent / "data" / "reports"
FIXTURES = sorted(p for p in DATA.iterdir() if p.suffix in (".md", ".tex", ".txt") and not p.name.startswith("_"))
EXPECT = re.compile(r"^\s*(?:<!--|%)\s*expect:\s*(.*?)\s*(?:-->)?\s*$")
ARGS = re.compile(r"^\s*(?:<!--|%)\s*denavit-test:\s*(.*?)\s*(?:-->)?\s*$")
RESULTS = ("correct", "incorrect", "ambiguous")
KNOWN = RESULTS + ("not a claim", "unreadable")


def _grade_report():
    """denavit.grade.grade_report, or a skip while the reader has not landed."""
    grade = pytest.importorskip("denavit.grade")
    fn = getattr(grade, "grade_report", None)
    if fn is None:
        pytest.skip("denavit.grade.grade_report does not exist yet (issue 24)")
    return fn


def _arguments(path: Path) -> dict:
    """robot= / arms= from the fixture's first line (``arms=1:planar2r-mdh,2:spherical-wrist``)."""
    first = path.read_text(encoding="utf-8").splitlines()[0]
    m = ARGS.match(first)
    kwargs: dict = {}
    if not m:
        return kwargs
    for item in m.group(1).split():
        key, _, value = item.partition("=")
        if key == "robot":
            from denavit.io import load_robot
            kwargs["robot"] = load_robot(value)
        elif key == "arms":
            kwargs["arms"] = dict(pair.split(":", 1) for pair in value.split(","))
        else:
            raise ValueError(f"{path.name}: unknown test argument {item!r}")
    return kwargs


def _blocks(path: Path) -> list[tuple[int, int, int, list[str]]]:
    """(comment line, first, last line of the block above it, expected verdicts); 1-based report lines.

    The block is the run of non-blank lines just above the comment (a display, or a paragraph of prose)."""
    lines = path.read_text(encoding="utf-8").splitlines()
    out = []
    for k, line in enumerate(lines, start=1):
        m = EXPECT.match(line)
        if not m:
            continue
        want = [v.strip() for v in m.group(1).split(",")]
        assert all(v in KNOWN for v in want), f"{path.name}:{k}: unknown verdict in {want}"
        end = k - 1
        start = end
        while start > 1 and lines[start - 2].strip() and not EXPECT.match(lines[start - 2]):
            start -= 1
        assert end >= 1 and lines[end - 1].strip(), f"{path.name}:{k}: an expect comment with no block above it"
        out.append((k, start, end, want))
    return out


@cache
def _graded(name: str):
    path = DATA / name
    return _grade_report()(path, **_arguments(path))


def _in_block(report, start: int, end: int) -> list:
    return sorted((c for c in report.claims if start <= c.end_line <= end), key=lambda c: c.line)


def _got(claims) -> list[str]:
    """The verdicts of a block other than "not a claim" (a block may hold several definitions, or restate a
    given beside its results: how many "not a claim" entries the reader reports is its own affair)."""
    return [c.verdict for c in claims if c.verdict != "not a claim"]


def _mismatch(claims, want: list[str]) -> bool:
    """The results differ from the expected ones, in order; or a block expected to hold a definition (not a
    claim) has none reported as such."""
    if _got(claims) != [w for w in want if w != "not a claim"]:
        return True
    return "not a claim" in want and not any(c.verdict == "not a claim" for c in claims)


def _describe(claims) -> str:
    return "; ".join(f"{c.quantity or '?'} -> {c.verdict}: {c.message[:90]}" for c in claims) or "nothing found"


def test_corpus_is_well_formed():
    """Every fixture has expectations, 40 to 150 lines, and parses its own arguments."""
    assert len(FIXTURES) >= 10
    for path in FIXTURES:
        n = len(path.read_text(encoding="utf-8").splitlines())
        assert 40 <= n <= 150, f"{path.name}: {n} lines"
        assert _blocks(path), f"{path.name}: no expect comments"
        _arguments(path)


@pytest.mark.slow
def test_corpus_truth_holds():
    """The independent derivation agrees with every expectation (a correct result equals the truth, a slip
    differs from it) and the records match the fixtures' expect comments."""
    run = subprocess.run([sys.executable, str(DATA / "_truth.py")], check=False, capture_output=True,
                         text=True, timeout=600)
    assert run.returncode == 0, run.stdout[-3000:] + run.stderr[-3000:]


@pytest.mark.parametrize("path", FIXTURES, ids=lambda p: p.name)
def test_verdicts_as_expected(path):
    report = _graded(path.name)
    wrong = []
    for k, start, end, want in _blocks(path):
        claims = _in_block(report, start, end)
        if _mismatch(claims, want):
            wrong.append(f"{path.name}:{start}-{end} (expect on line {k}): expected {want}, got {[c.verdict for c in claims]} "
                         f"[{_describe(claims)}]")
    assert not wrong, f"{len(wrong)} block(s) judged otherwise than expected:\n" + "\n".join(wrong)


@pytest.mark.parametrize("path", FIXTURES, ids=lambda p: p.name)
def test_no_correct_result_called_incorrect_and_most_found(path):
    report = _graded(path.name)
    blocks = _blocks(path)
    bad, found, expected = [], 0, 0
    for k, start, end, want in blocks:
        claims = _in_block(report, start, end)
        got, results = _got(claims), [w for w in want if w != "not a claim"]
        if len(got) == len(results):
            bad += [f"{path.name}:{start}-{end}: result {i + 1} expected {w}, judged incorrect [{_describe(claims)}]"
                    for i, (w, g) in enumerate(zip(results, got)) if g == "incorrect" and w != "incorrect"]
        elif got.count("incorrect") > want.count("incorrect"):
            bad.append(f"{path.name}:{start}-{end}: {got.count('incorrect')} judged incorrect, "
                       f"{want.count('incorrect')} expected [{_describe(claims)}]")
        n = sum(w in RESULTS for w in want)
        expected += n
        found += min(n, sum(g in RESULTS for g in got))
    covered = [(start, end) for _, start, end, _ in blocks]
    bad += [f"{path.name}:{c.line}-{c.end_line}: judged incorrect outside every annotated block: "
            f"{c.quantity} {c.message[:90]}" for c in report.claims
            if c.verdict == "incorrect" and not any(s <= c.end_line <= e for s, e in covered)]
    assert not bad, "\n".join(bad)
    assert found >= 0.9 * expected, f"{path.name}: {found} of {expected} expected results found and judged"
