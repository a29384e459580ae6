r"""The body of the checked page for a LaTeX report: a simple, safe rendering, not a TeX engine.

Display mathematics (``\[…\]``, ``$$…$$``, ``equation``/``align``/… environments) is typeset by KaTeX with the
marks beside it; everything else is shown as paragraphs of escaped text between blank lines, with ``$…$`` and
``\(…\)`` typeset inline and a paragraph that is one ``\section{…}`` shown as a heading.  Other commands stay
as written.
"""

from __future__ import annotations

import re

from ._html import Numbered, choose_span, corrections_html, display_html, esc, marks_html
from ._markdown import Block
from ._types import GradedReport

__all__ = ["tex_body"]

_INLINE = re.compile(r"(\$[^$]+?\$|\\\(.*?\\\))", re.DOTALL)
_HEADING = re.compile(r"\s*\\(section|subsection|subsubsection)\*?\{([^{}]*)\}\s*\Z")


def _paragraph(text: str, first: int) -> str:
    """Escaped text with its inline formulas as ``math-inline`` spans (``data-line``: the 1-based line)."""
    out = []
    line = first
    for k, part in enumerate(_INLINE.split(text)):
        if k % 2:
            latex = part[1:-1] if part.startswith("$") else part[2:-2]
            out.append(f'<span class="math-inline" data-line="{line}">{esc(latex)}</span>')
        else:
            out.append(esc(part))
        line += part.count("\n")
    return "".join(out)


def _text_block(b: Block, claims: list[Numbered]) -> str:
    m = _HEADING.match(b.body)
    marks = marks_html(claims) if claims else ""
    if m:
        tag = {"section": "h2", "subsection": "h3"}.get(m.group(1), "h4")
        return f'<{tag} data-line="{b.start + 1}">{esc(m.group(2))}{marks}</{tag}>\n' + corrections_html(claims)
    return (f'<p data-line="{b.start + 1}">{_paragraph(b.body, b.start + 1)}{marks}</p>\n'
            + corrections_html(claims))


def tex_body(report: GradedReport, blocks: list[Block]) -> tuple[str, list[Numbered]]:
    """(the report's ``blocks`` as HTML with marks and corrections, the claims that had no place)."""
    spans = [(b.start, b.end, b.kind == "math" or bool(_INLINE.search(b.body))) for b in blocks]
    groups: dict[int, list[Numbered]] = {}
    unplaced = []
    for k, c in enumerate(report.claims):
        pick = choose_span(spans, c.line - 1, c.end_line - 1)
        if pick is None:
            unplaced.append((k, c))
        else:
            groups.setdefault(pick, []).append((k, c))
    out = []
    for i, b in enumerate(blocks):
        claims = sorted(groups.get(i, []), key=lambda kc: (kc[1].end_line, kc[1].line, kc[0]))
        if b.kind == "math":
            out.append(display_html(b.body, b.start + 1, b.end, "", claims))
        else:
            out.append(_text_block(b, claims))
    return "\n".join(out), unplaced
