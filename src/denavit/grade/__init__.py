"""Grading a report as written: a student's Markdown/LaTeX derivation in, a verdict on every result out.

``grade_report(path, robot=None, arms=None)`` reads the report's DH table(s) (or uses the arm(s) given),
finds every stated result (display math, inline results, ``⇒`` chains), turns each into the claims the
YAML claims format already expresses and has :mod:`denavit.check` judge them — one judging engine.
See ``docs/grading.md``.
"""

from __future__ import annotations

from ._grade import MAX_GRADING_CPU, MAX_JUDGED, REPORT_SUFFIXES, grade_report, grade_text
from ._present import graded_text
from ._render import CHECKED_FORMATS, render_checked_html, render_checked_markdown, write_checked
from ._types import VERDICTS, ArmInfo, GradedClaim, GradedReport

__all__ = ["VERDICTS", "ArmInfo", "GradedClaim", "GradedReport", "grade_report", "grade_text", "REPORT_SUFFIXES",
           "MAX_JUDGED", "MAX_GRADING_CPU", "graded_text",
           "render_checked_markdown", "render_checked_html", "write_checked", "CHECKED_FORMATS"]
