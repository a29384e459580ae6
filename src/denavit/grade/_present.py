"""The graded report as text for the terminal: one line per judged equation, then the summary."""

from __future__ import annotations

from ._types import GradedReport

__all__ = ["graded_text"]

_MARK = {"correct": "correct", "incorrect": "INCORRECT", "ambiguous": "AMBIGUOUS", "unreadable": "unreadable",
         "not a claim": "not a claim"}


def _place(line: int, end: int) -> str:
    return f"line {line}" if line == end else f"lines {line}-{end}"


def graded_text(report: GradedReport, *, show_all: bool = False) -> str:
    """One line per judged equation (place, what was understood, verdict, reason), a fix under an incorrect one.

    Equations that state no result ("not a claim") are counted in the summary and listed with ``show_all``.
    """
    s = report.summary()
    head = (f"{report.source}: {s['correct']} correct, {s['incorrect']} incorrect, {s['ambiguous']} ambiguous, "
            f"{s['unreadable']} unreadable; {s['not a claim']} "
            + ("equation states" if s["not a claim"] == 1 else "equations state") + " no result")
    lines = [head]
    for arm in report.arms:
        where = f" ({arm.section})" if arm.section else ""
        lines.append(f"arm {arm.name}{where}: {arm.convention} DH, {arm.dof} joints, from the {arm.source}"
                     + "".join(f"; {n}" for n in arm.notes))
    lines += [f"note: {n}" for n in report.notes]
    for c in report.claims:
        if c.verdict == "not a claim" and not show_all:
            continue
        what = f" [{c.understood}]" if c.understood else ""
        lines.append(f"{_place(c.line, c.end_line)}: {_MARK[c.verdict]}{what}: {_one_line(c.message)}")
        if c.verdict == "incorrect" and c.fix:
            lines.append(f"    correct value (LaTeX): {_one_line(c.fix)}")
        for h in c.details.get("hints", [])[:3] if c.verdict == "incorrect" else []:
            lines.append(f"    hint: {_one_line(h)}")
    return "\n".join(lines)


def _one_line(text: str) -> str:
    t = " ".join(str(text).split())
    return t if len(t) <= 400 else t[:397] + "..."
