r"""The body of the checked page for a LaTeX report: a simple, safe rendering, not a TeX engine.

Display mathematics (``\[…\]``, ``$$…$$``, ``equation``/``align``/… environments) is typeset by KaTeX with the
marks beside it; everything else is shown as paragraphs of escaped text between blank lines, with ``$…$`` and
``\(…\)`` typeset inline, ``\section{…}`` shown as a heading and a ``tabular`` (the DH table) as a table, the
preamble (``\documentclass``, ``\usepackage``, ``\begin{document}``) left out.  Other commands stay as written.
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


_PIECES = re.compile(r"(\\(?:section|subsection|subsubsection)\*?\{[^{}]*\}"
                     r"|\\begin\{tabular\}\{[^{}]{0,80}\}.*?\\end\{tabular\})", re.DOTALL)
_PREAMBLE = re.compile(r"\\(?:documentclass|usepackage)(?:\[[^\]]*\])?\{[^{}]*\}|\\(?:begin|end)\{document\}|\\maketitle")


def _table(text: str, first: int) -> str:
    """A ``tabular`` as an HTML table: rows at ``\\\\``, cells at ``&``, rules dropped, cells as paragraphs."""
    body = re.sub(r"^\\begin\{tabular\}\{[^{}]*\}|\\end\{tabular\}$", "", text.strip())
    rows = [r for r in (re.sub(r"\\(?:hline|toprule|midrule|bottomrule)", "", r).strip() for r in body.split("\\\\"))
            if r]
    cells = "".join("<tr>" + "".join(f"<td>{_paragraph(c.strip(), first)}</td>" for c in r.split("&")) + "</tr>"
                    for r in rows)
    return f'<table class="tex-table" data-line="{first}">{cells}</table>'


def _text_block(b: Block, claims: list[Numbered]) -> str:
    """A paragraph of the report: its headings (``\\section{…}``) and tables (``tabular``) as HTML, the rest as text
    with inline formulas; the preamble's commands left out."""
    marks = marks_html(claims) if claims else ""
    out, line = [], b.start + 1
    for k, piece in enumerate(_PIECES.split(_PREAMBLE.sub("", b.body))):
        m = _HEADING.match(piece) if k % 2 else None
        if m:
            tag = {"section": "h2", "subsection": "h3"}.get(m.group(1), "h4")
            out.append(f'<{tag} data-line="{line}">{esc(m.group(2))}</{tag}>')
        elif k % 2:
            out.append(_table(piece, line))
        elif piece.strip():
            at = line + piece[:len(piece) - len(piece.lstrip())].count("\n")  # the line its text starts on
            out.append(f'<p data-line="{at}">{_paragraph(piece.strip(), at)}</p>')
        line += piece.count("\n")
    if not out or (marks and out[-1].startswith("<table")):
        out.append(f'<p data-line="{b.start + 1}"></p>')
    out[-1] = out[-1][:out[-1].rindex("</")] + marks + out[-1][out[-1].rindex("</"):]
    return "\n".join(out) + "\n" + corrections_html(claims)


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
