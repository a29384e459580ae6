"""What grading a report produces: data only (the presenters live in ``_render``)."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

__all__ = ["VERDICTS", "ArmInfo", "GradedClaim", "GradedReport"]

#: Every verdict a judged equation can get, in the order the summary lists them.
VERDICTS = ("correct", "incorrect", "ambiguous", "unreadable", "not a claim")


@dataclass(frozen=True)
class ArmInfo:
    """One arm of a report: where it came from and which part of the report it governs.

    ``section`` is the section's title as written ("" for the whole report), ``line``/``end_line`` the
    report lines (1-based, inclusive) the arm governs, ``source`` where the arm came from (``"table at
    line 14"``, ``"ROBOT puma560"``, ``"--arm 3=articulated-rrr"``) and ``table`` the DH rows as read.
    """

    name: str
    section: str
    line: int
    end_line: int
    source: str
    convention: str
    dof: int
    notes: tuple[str, ...] = ()

    def to_json(self) -> dict[str, Any]:
        return {"name": self.name, "section": self.section, "line": self.line, "end_line": self.end_line,
                "source": self.source, "convention": self.convention, "dof": self.dof, "notes": list(self.notes)}


@dataclass(frozen=True)
class GradedClaim:
    """The verdict on one equation of the report, placed by its report lines (1-based, inclusive).

    ``latex`` is the equation as written (the part that was judged), ``understood`` says in words what
    its left-hand side was read as (``"{}^{2}T_{3} read as A_3, the link transform of DH row 3"``),
    ``verdict`` one of :data:`VERDICTS`, ``message`` the reason in one or two sentences, ``fix`` the
    correct value in LaTeX for an incorrect one (else ""), ``details`` the checker's full verdict
    (entries that differ, counterexample, hints) as in ``denavit check --json`` of a claims file.
    """

    line: int
    end_line: int
    quantity: str
    arm: str
    verdict: str
    message: str
    latex: str = ""
    understood: str = ""
    fix: str = ""
    details: dict[str, Any] = field(default_factory=dict)

    def to_json(self) -> dict[str, Any]:
        return {"line": self.line, "end_line": self.end_line, "quantity": self.quantity, "arm": self.arm,
                "verdict": self.verdict, "message": self.message, "latex": self.latex,
                "understood": self.understood, "fix": self.fix, "details": self.details}


@dataclass(frozen=True)
class GradedReport:
    """Every judged equation of one report, with the arms it was judged against and the report's text."""

    source: str
    text: str
    format: str  # "md" | "tex" | "txt"
    arms: tuple[ArmInfo, ...]
    claims: tuple[GradedClaim, ...]
    notes: tuple[str, ...] = ()

    def count(self, verdict: str) -> int:
        return sum(c.verdict == verdict for c in self.claims)

    def summary(self) -> dict[str, int]:
        return {v: self.count(v) for v in VERDICTS}

    def to_json(self) -> dict[str, Any]:
        return {"report": self.source, "format": self.format, "summary": self.summary(),
                "notes": list(self.notes), "arms": [a.to_json() for a in self.arms],
                "claims": [c.to_json() for c in self.claims]}
