"""Grading a report: read it, find its arms and results, have the one checker judge them, place the verdicts.

The reader only decides *what* each equation claims; :func:`denavit.check.check_claims` decides whether it is
right, exactly as for a YAML claims file.  What the reader cannot be sure of never becomes "incorrect": a
left-hand side with two readings (``T_1^0`` or its inverse), a guessed name (``x`` for the end effector's x), or
a number stated without its case is "ambiguous" when the default reading disagrees, and says which reading decides.
"""

from __future__ import annotations

import dataclasses
import re
import time
from pathlib import Path
from typing import Any

from ..check import check_claims, read_input_text
from ..errors import DenavitError, ParseError
from ..model import DHRobot
from ..tables import find_tables
from ._arms import arms_of, compare_tables
from ._infer import infer_arms, infer_sections
from ._claims import Pending, walk
from ._document import read_document
from ._types import ArmInfo, GradedClaim, GradedReport
from ._values import missing_plus

__all__ = ["grade_report", "grade_text", "REPORT_SUFFIXES", "MAX_JUDGED"]

#: Report suffixes and the format each is read as.
REPORT_SUFFIXES = {".md": "md", ".markdown": "md", ".tex": "tex", ".txt": "txt", ".text": "txt"}
#: Most equations judged in one report (the rest are listed as not judged).
MAX_JUDGED = 600
#: CPU seconds one report may spend on judging; equations after that are "unreadable: not judged (time)".
MAX_GRADING_CPU = 240.0
_UNKNOWN = re.compile(r"unknown symbol '\\*((?:dot\{?\\*)?[A-Za-z]+)|unsupported LaTeX command \\*(partial|delta|nabla|int)")
_RESULT_LETTERS = {"T", "A", "R", "J", "e", "z", "p", "P", "F", "f", "n", "I", "O", "tau", "omega", "w", "v", "E",
                   "M", "K", "dot{p", "dotp", "dot{x", "vartheta", "nu", "x", "y", "hat"}


def _judge(robot: DHRobot, claim: dict[str, Any], seed: int) -> Any:
    try:
        return check_claims(robot, [dict(claim)], seed=seed).verdicts[0]
    except DenavitError as exc:
        from ..check import Verdict
        return Verdict("", str(claim.get("quantity")), "unreadable", f"could not be judged: {str(exc)[:300]}")


def _constant(robot: DHRobot, claim: dict[str, Any]) -> bool:
    """A quantity that does not depend on q (a fixed row's transform): a number without a case is fine there."""
    rows = robot.links
    if claim.get("quantity") == "link_transform":
        k = claim.get("index", 0)
        return isinstance(k, int) and 1 <= k <= len(rows) and not rows[k - 1].is_joint
    if claim.get("quantity") == "transform":
        a, b = sorted((claim.get("from", 0), claim.get("to", len(rows))))
        return all(not r.is_joint for r in rows[a:b])
    return False


def _decide(p: Pending, seed: int) -> tuple[str, str, str, dict[str, Any]]:
    """(verdict, message, fix, details) of one pending claim."""
    robot = p.arm.robot
    v = _judge(robot, p.claim, seed)
    details = v.to_json()
    if v.verdict == "correct" or v.verdict == "ambiguous":
        return v.verdict, v.message, "", details
    if v.verdict == "unreadable" and p.not_a_claim_if_unreadable:
        return "not a claim", "not judged: a relation in names the relation reader does not know", "", details
    if v.verdict == "unreadable":
        m = _UNKNOWN.search(v.message)
        name = m and (m.group(1) or m.group(2))
        if name and (name in _RESULT_LETTERS or name[:1] in ("T", "J", "R") or m.group(2)):
            return "not a claim", ("not judged: written in terms of other results (" + name + " …): a "
                                   "definition or a relation between them"), "", details
        for alt, words in p.equivalent:
            w = _judge(robot, alt, seed)
            if w.verdict == "correct":
                return "correct", f"correct ({words})", "", w.to_json()
        if re.search(r"the formula for q\d+ uses q\d+ itself", v.message):
            return "incorrect", (v.message + ": it does not solve for the joint (a formula for it must use the "
                                 "target's entries r_ij, p_x … and joints found before it)"), "", details
        return "unreadable", v.message, "", details
    closest = None  # the other form of the result that fits best: the written shape, the fewest entries wrong
    for alt, words in p.equivalent:
        w = _judge(robot, alt, seed)
        if w.verdict == "correct":
            return "correct", f"correct ({words})", "", w.to_json()
        if w.verdict == "incorrect" and "shape:" not in w.message and (
                closest is None or len(w.entries) < len(closest[0].entries)):
            closest = w, words
    if closest is not None and ("shape:" in v.message or len(closest[0].entries) < len(v.entries)):
        v = dataclasses.replace(closest[0], message=f"read as {closest[1]}: {closest[0].message}")
        details = v.to_json()
    other = _other_gravity(p, seed) if p.arm.gravity_assumed else None
    if other is not None:
        return "ambiguous", (f"correct with gravity along {other}; the report does not say which way gravity "
                             f"points and −y (a vertical plane, y up) was taken: {v.message}"), "", details
    for alt, words in p.alternatives:
        w = _judge(robot, alt, seed)
        if w.verdict == "correct":
            return "ambiguous", (f"correct if the left-hand side means {words}; read as {p.understood} it is not "
                                 f"({v.message})"), "", details
    if not p.sure:
        return "ambiguous", f"read as {p.understood} (a guess from the name), it is not: {v.message}", "", details
    if p.numeric_without_rates:
        return "ambiguous", ("numbers, but no joint rates (q̇ = (…)) stated before them; at random rates: "
                             f"{v.message}"), "", details
    if p.numeric_without_wrench:
        return "ambiguous", ("numbers, but no wrench (F = (…)) stated before them; at random wrenches: "
                             f"{v.message}"), "", details
    if p.numeric_without_case and not _constant(robot, p.claim):
        return "ambiguous", ("numbers, but no configuration (Case …: q = (…)) stated before them; at random "
                             f"configurations: {v.message}"), "", details
    slip = _missing_plus(p, seed)
    message = v.message + (f"; with a '+' {slip} it is correct (a '+' left out?)" if slip else "")
    return "incorrect", message, str(v.extra.get("expected_latex") or ""), details


def _missing_plus(p: Pending, seed: int) -> str | None:
    """Where a '+' put between two squares makes an incorrect claim right (:func:`._values.missing_plus`)."""
    value = p.claim.get("value")
    if not isinstance(value, str):
        return None
    for variant, where in missing_plus(value):
        if _judge(p.arm.robot, {**p.claim, "value": variant}, seed).verdict == "correct":
            return where
    return None


_GRAVITY_WAYS = (("−x", (-9.81, 0.0, 0.0)), ("+x", (9.81, 0.0, 0.0)), ("+y", (0.0, 9.81, 0.0)),
                 ("−z (a horizontal plane: no gravity torques)", (0.0, 0.0, -9.81)))


def _other_gravity(p: Pending, seed: int) -> str | None:
    """The direction of gravity, other than the −y taken, under which the claim is right (None: none is)."""
    robot = p.arm.robot
    for words, g in _GRAVITY_WAYS:
        if _judge(robot.replace(gravity=g), p.claim, seed).verdict == "correct":
            return words
    return None


def _graded(p: Pending, seed: int) -> GradedClaim:
    arm = p.arm.info.name if p.arm is not None else ""
    if p.claim is None:
        return GradedClaim(p.line, p.end_line, p.quantity, arm, p.verdict, p.message, p.latex, p.understood)
    try:
        verdict, message, fix, details = _decide(p, seed)
    except Exception as exc:  # noqa: BLE001 - one equation's failure is that equation's verdict
        verdict, message, fix, details = ("unreadable", f"could not be judged: the checker failed on it "
                                          f"({type(exc).__name__}: {str(exc)[:160]})", "", {})
    return GradedClaim(p.line, p.end_line, p.quantity, arm, verdict, message, p.latex, p.understood, fix, details)


def grade_text(text: str, fmt: str = "md", *, robot: DHRobot | None = None,
               arms: dict[str, DHRobot] | None = None, source: str = "<report>", seed: int = 0) -> GradedReport:
    """Grade the report ``text`` (see :func:`grade_report`)."""
    doc = read_document(text, fmt)
    given = dict(arms or {})
    inferred: dict[str, DHRobot] = {}
    inferred_notes: list[str] = []
    if robot is None and not find_tables(list(doc.lines)):
        inferred, inferred_notes = infer_arms(doc, source, seed, tuple(given))
        given = {**inferred, **given}
    governed = arms_of(doc, source, robot, given, frozenset(inferred))
    wanted = [(s.heading.key, s.line, s.end_line, a.wants_dof) for s, a in governed
              if a is not None and a.robot is None and a.wants_dof and s.heading is not None and s.heading.key]
    if wanted:  # sections about another arm, without a table of their own: an arm their results fit
        more, more_notes = infer_sections(doc, source, wanted, seed)
        if more:
            inferred, inferred_notes = {**inferred, **more}, inferred_notes + more_notes
            given = {**more, **given}
            governed = arms_of(doc, source, robot, given, frozenset(inferred))
    pending, read_notes = walk(doc, governed)
    notes = list(doc.notes) + inferred_notes + read_notes
    if len(pending) > MAX_JUDGED:
        notes.append(f"only the first {MAX_JUDGED} equations were judged ({len(pending)} found)")
    graded = []
    start = time.process_time()
    for p in pending[:MAX_JUDGED]:
        if time.process_time() - start > MAX_GRADING_CPU and p.claim is not None:
            graded.append(GradedClaim(p.line, p.end_line, p.quantity, p.arm.info.name if p.arm else "", "unreadable",
                                      f"not judged: the report used its {MAX_GRADING_CPU:.0f} s of checking time",
                                      p.latex, p.understood))
            continue
        graded.append(_graded(p, seed))
    if robot is not None:
        graded[:0] = compare_tables(doc, robot, source)
    seen: dict[str, ArmInfo] = {}
    for _, arm in governed:
        if arm is not None and arm.info.name and arm.info.name not in seen:
            seen[arm.info.name] = arm.info
        if arm is not None and arm.problem and arm.problem not in notes:
            notes.append(arm.problem)
            if arm.advice:
                notes.append(arm.advice)
    if not seen:
        notes.append("no DH table found in the report: give the arm (denavit check ROBOT REPORT)")
    arms_in_order = tuple(sorted(seen.values(), key=lambda a: a.line))  # as the report runs (spans are ordered
    # most specific first, which listed report 004's eight arms by the length of their sections)
    return GradedReport(source, text, fmt, arms_in_order, tuple(graded), tuple(notes))


def grade_report(path: str | Path, robot: DHRobot | str | None = None, arms: dict[str, Any] | None = None, *,
                 seed: int = 0) -> GradedReport:
    """Grade a student's report as written: every stated result judged in place.

    Parameters
    ----------
    path : str or Path
        A ``.md``/``.markdown``/``.tex``/``.txt`` report (UTF-8, at most ``denavit.check.MAX_FILE_BYTES``).
    robot : DHRobot, optional
        The arm for the whole report; without it each DH table of the report governs its part.
    arms : dict, optional
        Arms for sections, by section key (the heading's number, ``"3"`` for "3) …" or "## 3. …"): robots or
        catalogue names.
    """
    from ..io import load_robot

    path = Path(path)
    where = str(path)
    fmt = REPORT_SUFFIXES.get(path.suffix.lower())
    if fmt is None:
        raise ParseError(f"not a report: {where!r} (a report is .md, .markdown, .tex or .txt)")
    text = read_input_text(path, "report", "utf-8-sig")
    given = {str(k): (v if isinstance(v, DHRobot) else load_robot(str(v))) for k, v in (arms or {}).items()}
    if robot is not None and not isinstance(robot, DHRobot):
        robot = load_robot(str(robot))
    return grade_text(text, fmt, robot=robot, arms=given, source=where, seed=seed)
