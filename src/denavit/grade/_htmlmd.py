"""The body of the checked page for a Markdown report: markdown-it tokens, each claim attached by line range.

A claim is attached to the token whose ``map`` (0-based half-open line range) holds its last line: a display
equation (``math_block``, ``math_block_label``, ``amsmath``: the mark goes beside it) or the ``inline`` token
of a paragraph, heading or table cell (the mark goes right after the claim's own formula — the last one on
the claim's lines — or at the end of its last line, and the correction after the paragraph, or after the
whole table).  Raw HTML is off in the parser, so the student's ``<script>`` is text; pictures are shown by
name, never fetched.
"""

from __future__ import annotations

from bisect import bisect_right

from ._html import Numbered, choose_span, corrections_html, display_html, esc, marks_html
from ._markdown import MATH_BLOCKS, markdown_parser
from ._types import GradedReport

__all__ = ["markdown_body"]

_INLINE_MATH = ("math_inline", "math_inline_double")
_CODE = ("fence", "code_block")
_BREAKS = ("softbreak", "hardbreak")


def _inline_lines(token) -> None:
    """Give each child of an ``inline`` token the 0-based report lines it spans (``meta["lines"]``; a line
    break belongs to the line it ends), so the children's first lines never decrease."""
    line = token.map[0]
    for child in token.children or []:
        last = line + child.content.count("\n")
        child.meta = {**(child.meta or {}), "lines": (line, last)}
        line = last + (child.type in _BREAKS)


def _anchors(children, claims: list[Numbered]) -> dict[int, list[Numbered]]:
    """{position among an inline token's children: the claims whose marks go there}.  A claim on lines
    ``line``..``end_line`` goes after the last formula overlapping those lines, else at the end of its last
    line, else at the end (formulas do not overlap, so their lines only grow: bisection, not a scan per claim)."""
    spans = [(child.meta or {}).get("lines", (-1, -1)) for child in children]
    maths = [j for j, child in enumerate(children) if child.type in _INLINE_MATH]
    math_starts = [spans[j][0] for j in maths]
    starts = [a for a, _ in spans]
    at: dict[int, list[Numbered]] = {}
    for k, c in claims:
        first, last = c.line - 1, c.end_line - 1
        m = bisect_right(math_starts, last) - 1
        if m >= 0 and spans[maths[m]][1] >= first:
            pos = maths[m] + 1
        else:  # the end of its last line: before the line break that ends it
            pos = bisect_right(starts, last) or len(children)
            if pos > 0 and children[pos - 1].type in _BREAKS:
                pos -= 1
        at.setdefault(pos, []).append((k, c))
    return at


def _attach_inline(tokens, i: int, claims: list[Numbered], token_cls) -> None:
    """Each claim's mark right after its formula in inline token ``i`` (see :func:`_anchors`); the corrections
    after the block holding it."""
    children = tokens[i].children or []
    at = _anchors(children, claims)
    for pos in sorted(at, reverse=True):
        marks = token_cls("verdict_marks", "", 0)
        marks.meta = {"claims": at[pos]}
        children.insert(pos, marks)
    tokens[i].children = children
    close = i + 1
    if tokens[close].type in ("td_close", "th_close"):  # a table: the correction goes under the whole table
        while close + 1 < len(tokens) and tokens[close].type != "table_close":
            close += 1
    corr = token_cls("verdict_corrections", "", 0)
    corr.block, corr.meta = True, {"claims": claims}
    tokens.insert(close + 1, corr)


def _has_math(token) -> bool:
    return token.type in MATH_BLOCKS or any(c.type in _INLINE_MATH for c in token.children or [])


def _place_claims(tokens, report: GradedReport, token_cls) -> list[Numbered]:
    """Attach every claim to the token of its equation; returns the claims with no token (an empty report)."""
    cand = [i for i, t in enumerate(tokens) if t.map and (t.type in MATH_BLOCKS or t.type == "inline"
                                                           or t.type in _CODE)]
    for i in cand:
        if tokens[i].type == "inline":
            _inline_lines(tokens[i])
    spans = [(tokens[i].map[0], tokens[i].map[1], _has_math(tokens[i])) for i in cand]
    groups: dict[int, list[Numbered]] = {}
    unplaced = []
    for k, c in enumerate(report.claims):
        pick = choose_span(spans, c.line - 1, c.end_line - 1)
        if pick is None:
            unplaced.append((k, c))
        else:
            groups.setdefault(cand[pick], []).append((k, c))
    for i in sorted(groups, reverse=True):  # from the end, so inserted tokens do not shift the indices to come
        group = sorted(groups[i], key=lambda kc: (kc[1].end_line, kc[1].line, kc[0]))
        if tokens[i].type == "inline":
            _attach_inline(tokens, i, group, token_cls)
        else:
            tokens[i].meta = {**(tokens[i].meta or {}), "claims": group}
    return unplaced


def _block(self, tokens, idx, options, env) -> str:
    """A display equation (with its marks) or a code block (marks after it)."""
    t = tokens[idx]
    claims = (t.meta or {}).get("claims", [])
    if t.type in _CODE:
        code = f'<pre data-line="{t.map[0] + 1}"><code>{esc(t.content)}</code></pre>\n'
        return code + (marks_html(claims) + corrections_html(claims) if claims else "")
    label = t.info if t.type == "math_block_label" else ""
    return display_html(t.content.strip("\n"), t.map[0] + 1, t.map[1], label, claims)


def _inline_math(self, tokens, idx, options, env) -> str:
    t = tokens[idx]
    cls = "math-inline" if t.type == "math_inline" else "math-display"
    first, last = (t.meta or {}).get("lines", (-1, -1))
    return f'<span class="{cls}" data-line="{first + 1}" data-end-line="{last + 1}">{esc(t.content)}</span>'


def _image(self, tokens, idx, options, env) -> str:
    """A picture by its description and address only: the page fetches nothing."""
    t = tokens[idx]
    alt = "".join(c.content for c in t.children or []) or t.content
    return f'<span class="image-omitted">[picture: {esc(alt)} — {esc(t.attrGet("src") or "")}]</span>'


def _parser(breaks: bool = False):
    md = markdown_parser(breaks)
    for name in (*MATH_BLOCKS, *_CODE):
        md.add_render_rule(name, _block)
    for name in _INLINE_MATH:
        md.add_render_rule(name, _inline_math)
    md.add_render_rule("image", _image)
    md.add_render_rule("verdict_marks", lambda self, tokens, idx, options, env: marks_html(tokens[idx].meta["claims"]))
    md.add_render_rule("verdict_corrections",
                       lambda self, tokens, idx, options, env: corrections_html(tokens[idx].meta["claims"]))
    return md


def markdown_body(report: GradedReport) -> tuple[str, list[Numbered]]:
    """(the report rendered as HTML with its marks and corrections, the claims that had no place)."""
    from markdown_it.token import Token

    md = _parser(breaks=report.format == "txt")  # plain text: its lines kept
    tokens = md.parse(report.text)
    unplaced = _place_claims(tokens, report, Token)
    return md.renderer.render(tokens, md.options, {}), unplaced
