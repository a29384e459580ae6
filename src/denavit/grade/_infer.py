"""An arm for a section that has no DH table (its table was a picture): a catalogue arm its own results fit.

A person grading such a report reads the arm off the derivation; so does this, conservatively.  For every section
no table, ROBOT or ``--arm`` governs (the top-level sections of a report without tables; a section of a report
with tables whose heading names another number of joints and that holds no table of its own), each catalogue
arm with as many joints as the section writes (or its heading names) is tried on the section's first
:data:`SAMPLE` results (cheap kinds only: no singular sets or IK).  An arm is taken only when at
least :data:`MIN_AGREEING` of them agree with it, a share of at least :data:`MIN_SHARE`, and no other arm comes
within :data:`MARGIN` of it; the arm's notes then say it was recognised, not given, and ``--arm`` overrides it.
"""

from __future__ import annotations

import re

from ..check import check_claims
from ..errors import DenavitError
from ..io import catalogue_names, load_robot
from ._arms import arms_of
from ._claims import walk
from ._document import Document, Heading, Math

__all__ = ["infer_arms", "infer_sections", "FIRST_SAMPLE", "SAMPLE", "MIN_AGREEING", "MIN_SHARE", "MARGIN", "MARGIN_LARGE", "MIN_SHARE_LARGE"]

#: Results of a section tried on each candidate arm first, and on the candidates still close after that.
FIRST_SAMPLE = 5
SAMPLE = 20
#: Results that must agree with the arm taken.
MIN_AGREEING = 4
#: Share of the tried results that must agree with the arm taken.
MIN_SHARE = 0.7
#: How far ahead of the next candidate (share of agreeing results) the arm taken must be, after the first
#: sample, and after the larger one (taken when the first left two candidates within MARGIN).
MARGIN = 0.25
MARGIN_LARGE = 0.1
#: Share that must agree on the larger sample (a student's slips weigh more there; the margin still decides).
MIN_SHARE_LARGE = 0.6
_SKIP = ("singularities", "ik_formula", "ik_solutions", "relation", "det_jacobian")
_INDEX = re.compile(r"(?:\\(?:var)?theta|\bq|\bQ|(?<![A-Za-z\\])[cCsS]|\\dot\{?d\}?|\bd)\s*_\s*\{?\s*(\d{1,4})")


def _joints_written(doc: Document, line: int, end: int) -> int:
    """How many joints a section writes: the distinct joint numbers of its formulas."""
    idx = {int(d) for it in doc.items if isinstance(it, Math) and line <= it.line <= end
           for m in _INDEX.finditer(it.latex) for d in m.group(1)}
    idx.discard(0)
    return len(idx)


def _score(doc: Document, source: str, key: str, robot, line: int, end: int, seed: int,
           sample: int) -> tuple[int, int]:
    """(agreeing, judged) of the section's first ``sample`` results with ``robot`` as its arm (an arm that fails
    the first three is dropped early)."""
    pending, _ = walk(doc, arms_of(doc, source, None, {key: robot}))
    agree = judged = 0
    for p in pending:
        if not (line <= p.line <= end) or p.claim is None or p.claim.get("quantity") in _SKIP:
            continue
        try:
            v = check_claims(robot, [dict(p.claim)], seed=seed).verdicts[0]
        except DenavitError:
            continue
        if v.verdict in ("correct", "incorrect"):
            judged += 1
            agree += v.verdict == "correct"
        if judged >= sample or (judged >= 3 and agree <= 1):
            break
    return agree, judged


def _by_dof() -> dict[int, list]:
    by_dof: dict[int, list] = {}
    for name in catalogue_names():
        r = load_robot(name)
        by_dof.setdefault(r.dof, []).append(r)
    return by_dof


def _recognise(doc: Document, source: str, seed: int, key: str, line: int, end: int, candidates: list):
    """(robot, agreeing, judged, runner-up share) of the candidate arm the section's results fit clearly, or None."""
    scores = []
    for robot in candidates:
        agree, judged = _score(doc, source, key, robot, line, end, seed, FIRST_SAMPLE)
        if judged:
            scores.append((agree / judged, agree, judged, robot))
    scores.sort(key=lambda s: (-s[0], -s[1]))
    close = [sc for sc in scores if scores and scores[0][0] - sc[0] < MARGIN][:3]
    if len(close) > 1:  # too close to call on a few results: the close ones on more of them
        scores = []
        for _, _, _, robot in close:
            agree, judged = _score(doc, source, key, robot, line, end, seed, SAMPLE)
            scores.append((agree / judged, agree, judged, robot))
        scores.sort(key=lambda s: (-s[0], -s[1]))
    if not scores:
        return None
    share, agree, judged, robot = scores[0]
    runner = scores[1][0] if len(scores) > 1 else 0.0
    margin, least = (MARGIN_LARGE, MIN_SHARE_LARGE) if len(close) > 1 else (MARGIN, MIN_SHARE)
    if agree >= MIN_AGREEING and share >= least and share - runner >= margin:
        return robot, agree, judged, runner
    return None


def _note(key: str, line: int, found) -> str:
    robot, agree, judged, runner = found
    return (f"section {key!r} (line {line}) has no DH table: its results fit the catalogue arm {robot.name} "
            f"({agree} of {judged} tried agree; the next arm {runner:.0%}); judged against it (give --arm "
            f"{key}=ROBOT to choose another)")


def infer_arms(doc: Document, source: str, seed: int = 0, given: tuple[str, ...] = ()) -> tuple[dict[str, object], list[str]]:
    """Arms recognised for the top-level sections of a report without tables, by section key, and notes."""
    heads = [h for h in doc.items if isinstance(h, Heading)]
    if not heads:
        return {}, []
    levels = [h.level for h in heads]
    top = min(levels)
    if levels.count(top) == 1 and len(set(levels)) > 1:  # a title above the sections
        top = min(v for v in levels if v != top)
    tops = [h for h in heads if h.level == top and h.key]
    by_dof = _by_dof()
    found, notes = {}, []
    for k, h in enumerate(tops):
        if h.key in given:
            continue
        end = tops[k + 1].line - 1 if k + 1 < len(tops) else len(doc.lines)
        n = _joints_written(doc, h.line, end)
        fit = _recognise(doc, source, seed, h.key, h.line, end, by_dof.get(n, []))
        if fit is not None:
            found[h.key] = fit[0]
            notes.append(_note(h.key, h.line, fit))
    return found, notes


def infer_sections(doc: Document, source: str, sections, seed: int = 0) -> tuple[dict[str, object], list[str]]:
    """Arms recognised for sections of a report with tables that are about an arm of another number of joints
    and hold no table of their own (``sections``: (key, first line, last line, joints the heading names)), by
    the same rule as :func:`infer_arms`; a section no catalogue arm fits clearly keeps no arm (and its advice)."""
    by_dof = _by_dof()
    found, notes = {}, []
    for key, line, end, dof in sections:
        fit = _recognise(doc, source, seed, key, line, end, by_dof.get(dof, []))
        if fit is not None:
            found[key] = fit[0]
            notes.append(_note(key, line, fit))
    return found, notes
