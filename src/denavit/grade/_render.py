"""Presenters of a :class:`GradedReport`: the student's report handed back with the verdicts in place.

- :func:`render_checked_markdown`: the report's text, every original line kept byte for byte, with a
  blockquote after each judged equation (after the whole block: the closing ``$$`` of a display equation,
  the end of a paragraph or table), one line per claim: mark, what was understood, verdict, message, and
  for an incorrect claim the correct value as ``$$…$$``.
- :func:`render_checked_html`: the report rendered offline with KaTeX (``_htmlmd`` for Markdown, ``_htmltex``
  for LaTeX, the page's pieces in ``_html``), a mark beside every judged equation and the correction under
  each incorrect one.
- :func:`write_checked`: either, chosen by the file's suffix, written atomically.

Everything that comes from the report or from the verdicts is data: it is escaped for the output's syntax
(Markdown backslash escapes, HTML entities), so a message cannot open a link, a raw HTML tag or math mode.
"""

from __future__ import annotations

import os
import re
import tempfile
from collections import defaultdict
from pathlib import Path

from ._html import MARKS, corrections_html, marks_html, page_html
from ._htmlmd import markdown_body
from ._htmltex import tex_body
from ._markdown import block_end, markdown_blocks, markdown_parser, tex_blocks
from ._types import GradedClaim, GradedReport

__all__ = ["render_checked_markdown", "render_checked_html", "write_checked", "CHECKED_FORMATS"]

#: Output suffix → presenter name (``write_checked`` chooses by suffix).
CHECKED_FORMATS = {".html": "html", ".htm": "html", ".md": "md", ".markdown": "md"}

# Every ASCII character that can start Markdown syntax inside a line (emphasis, code, links, images, raw
# HTML and entities, math, tables, strikethrough, headings); CommonMark lets each be backslash-escaped.
_MD_SPECIAL = re.compile(r"([\\`*_\[\]<>&$|~!#])")
_CONTROL = re.compile(r"[\x00-\x1f\x7f\u0085\u2028\u2029]+")


def md_text(s: str) -> str:
    """``s`` as literal Markdown text on one line: control characters and line breaks become spaces and every
    character that could start Markdown syntax is backslash-escaped."""
    return _MD_SPECIAL.sub(r"\\\1", _CONTROL.sub(" ", s)).strip()


def md_math(latex: str) -> str:
    """LaTeX for a one-line ``$$…$$`` block: on one line, and with no ``$`` left that could close it early."""
    return _CONTROL.sub(" ", latex).replace("$", "\\$").strip()


def _lines_of(c: GradedClaim) -> str:
    return f"line {c.line}" if c.end_line == c.line else f"lines {c.line}–{c.end_line}"


def _quote_line(c: GradedClaim) -> str:
    """One claim as a Markdown paragraph (inside the blockquote): mark, understood, verdict, message."""
    parts = [f"{MARKS.get(c.verdict, '?')} **{md_text(c.verdict)}** ({_lines_of(c)})"]
    if c.understood:
        parts.append(f"understood: {md_text(c.understood)}")
    if c.message:
        parts.append(md_text(c.message))
    return " — ".join(parts)


def _blockquote(claims: list[GradedClaim]) -> list[str]:
    """The lines (each ending in a newline) of one blockquote, preceded and followed by a blank line."""
    out = ["\n"]
    for k, c in enumerate(claims):
        if k:
            out.append(">\n")
        out.append(f"> {_quote_line(c)}\n")
        if c.verdict == "incorrect" and c.fix.strip():
            out += [">\n", f"> $$ {md_math(c.fix)} $$\n"]
    out.append("\n")
    return out


def _split_lines(text: str) -> list[str]:
    """The report's lines with their endings; a line ends at ``\\n`` only, as editors and markdown-it count."""
    return text.split("\n") if not text else [s for s in re.split(r"(?<=\n)", text) if s]


def insertion_points(report: GradedReport) -> dict[int, list[GradedClaim]]:
    """{number of original lines to keep before the blockquote: the claims quoted there, in report order}.

    A claim goes after the block (Markdown's top-level block, or a LaTeX display environment / paragraph)
    that holds its ``end_line``; a claim whose ``end_line`` lies outside the text goes after the last line.
    """
    lines = _split_lines(report.text)
    n = len(lines)
    if report.format == "tex":
        blocks = tex_blocks(report.text)
    else:
        blocks = markdown_blocks(markdown_parser().parse(report.text))
    starts = [b.start for b in blocks]
    points: dict[int, list[GradedClaim]] = defaultdict(list)
    for c in sorted(report.claims, key=lambda c: (c.end_line, c.line)):
        last = min(max(c.end_line, 1), n) - 1  # 0-based
        at = min(block_end(blocks, starts, last), n)
        while at - 1 > last and not lines[at - 1].strip():  # a list's range takes in the blank line after it
            at -= 1
        points[at].append(c)
    return dict(points)


def render_checked_markdown(report: GradedReport) -> str:
    """The report's text with a blockquote of verdicts after each judged block; original lines unchanged.

    A blank line is put before and after each blockquote, so it neither joins the paragraph above it nor
    swallows the line below it (CommonMark's lazy continuation).
    """
    lines = _split_lines(report.text)
    points = insertion_points(report)
    out: list[str] = []
    for k in range(len(lines) + 1):
        if k in points:
            if out and not out[-1].endswith("\n"):
                out.append("\n")  # the file's last line had no newline: the quote starts on a line of its own
            out += _blockquote(points[k])
        if k < len(lines):
            out.append(lines[k])
    return "".join(out)


def render_checked_html(report: GradedReport) -> str:
    """The checked report as one self-contained HTML page: the student's text typeset offline by KaTeX,
    a summary and legend on top, a mark beside every judged equation, the correction under each incorrect one
    and every verdict listed at the end.  Raw HTML in the report is shown as text; nothing is fetched."""
    if report.format == "tex":
        body, unplaced = tex_body(report, tex_blocks(report.text))
    else:
        body, unplaced = markdown_body(report)
    if unplaced:  # only when the report has no block at all to hang them on
        body += '\n<div class="unplaced">' + marks_html(unplaced) + corrections_html(unplaced) + "</div>"
    return page_html(report, body)


def write_checked(report: GradedReport, path: str | Path) -> Path:
    """Write the checked report to ``path``, HTML or Markdown by its suffix, atomically (a temporary file
    beside it, then ``os.replace``: a failure leaves any existing file as it was)."""
    from ..errors import ParseError

    path = Path(path)
    fmt = CHECKED_FORMATS.get(path.suffix.lower())
    if fmt is None:
        raise ParseError(f"{str(path)!r}: the checked report's format comes from the suffix; use "
                         + ", ".join(CHECKED_FORMATS))
    text = render_checked_html(report) if fmt == "html" else render_checked_markdown(report)
    fd, tmp = tempfile.mkstemp(prefix=".denavit-", suffix=path.suffix, dir=path.parent)
    try:
        with os.fdopen(fd, "w", encoding="utf-8", newline="") as f:
            f.write(text)
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(tmp, 0o666 & ~umask)  # as a plain open() would have made it (mkstemp gives 0600)
        os.replace(tmp, path)
    finally:
        if os.path.lexists(tmp):
            os.unlink(tmp)
    return path
