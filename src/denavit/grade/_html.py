"""The pieces of the checked report's HTML page: marks, corrections, display equations, summary, legend.

The page body comes from ``_htmlmd`` (Markdown reports) or ``_htmltex`` (LaTeX reports); this module holds
what both share and assembles the page.  Mathematics is typeset by the KaTeX that ``denavit report -o x.html``
ships (:func:`denavit.report.katex_bundle`, :data:`denavit.report.KATEX_TYPESET_SCRIPT`): every element of
class ``math-display``/``math-inline`` is typeset from its text.  Everything from the report or a verdict is
HTML-escaped here, once, at the point it is written into the page.
"""

from __future__ import annotations

import html
from pathlib import PurePath

from ._types import VERDICTS, GradedClaim, GradedReport

__all__ = ["MARKS", "LEGEND", "Numbered", "esc", "mark_html", "marks_html", "corrections_html", "display_html",
           "choose_span", "page_html"]

#: The mark of each verdict, in the page and in the Markdown blockquotes.
MARKS = {"correct": "✓", "incorrect": "✗", "ambiguous": "?", "unreadable": "!", "not a claim": "·"}

#: What each mark means (the page's legend).
LEGEND = {
    "correct": "the result agrees with the one derived from the arm",
    "incorrect": "the result differs; the correction is shown under the equation",
    "ambiguous": "the equation can be read in more than one way and the readings disagree (see the tooltip)",
    "unreadable": "the equation could not be read; the reason is in the tooltip",
    "not a claim": "a definition or a restated given: nothing to judge",
}

#: A claim with its index in ``GradedReport.claims`` (the index names its mark: ``id="claim-K"``).
Numbered = tuple[int, GradedClaim]

_CSS = """
body { font-family: system-ui, -apple-system, "Segoe UI", sans-serif; max-width: 60rem; margin: 2rem auto;
       padding: 0 1rem; line-height: 1.5; color: #1d1d1f; }
header.grade { border: 1px solid #ddd; border-radius: 6px; padding: .6rem 1rem; background: #fafafa; }
header.grade h1 { font-size: 1.4rem; margin: .2rem 0 .5rem; }
.counts span { margin-right: 1.2rem; white-space: nowrap; } .legend li, .arms li { margin: .1rem 0; }
article.report { margin-top: 1.5rem; }
.math-display { overflow-x: auto; overflow-y: hidden; padding: .3rem 0; }
.eq { display: flex; align-items: center; gap: .6rem; } .eq > .math-display { flex: 1 1 auto; min-width: 0; }
.eqno { color: #555; }
.verdict { display: inline-block; min-width: 1.3em; text-align: center; font-weight: bold; border-radius: 3px;
           cursor: help; margin: 0 .15rem; padding: 0 .2rem; }
.v-correct { color: #fff; background: #2e7d32; } .v-incorrect { color: #fff; background: #c62828; }
.v-ambiguous { color: #000; background: #f9a825; } .v-unreadable { color: #fff; background: #6a1b9a; }
.v-not-a-claim, .v-unknown { color: #333; background: #ddd; }
.correction { border-left: 4px solid #c62828; background: #fdecea; padding: .2rem .8rem; margin: .3rem 0 1rem; }
.correction p { margin: .3rem 0; }
.image-omitted { color: #555; font-style: italic; }
table { border-collapse: collapse; margin: .8rem 0; } td, th { border: 1px solid #ccc; padding: .2rem .5rem; }
table.verdicts td { vertical-align: top; font-size: .92rem; }
pre { background: #f5f5f5; padding: .5rem; overflow-x: auto; }
"""


def esc(s: object) -> str:
    """Text as HTML (quotes too, so it is safe inside an attribute)."""
    return html.escape(str(s), quote=True)


def _slug(verdict: str) -> str:
    return verdict.replace(" ", "-") if verdict in MARKS else "unknown"


def _lines(c: GradedClaim) -> str:
    return f"Line {c.line}" if c.end_line == c.line else f"Lines {c.line}–{c.end_line}"


def mark_html(k: int, c: GradedClaim) -> str:
    """One verdict mark; its tooltip is the verdict, the message and what was understood."""
    tip = f"{c.verdict}: {c.message}" + (f" (understood: {c.understood})" if c.understood else "")
    return (f'<span class="verdict v-{_slug(c.verdict)}" id="claim-{k}" data-claim="{k}" data-line="{c.line}" '
            f'data-end-line="{c.end_line}" data-verdict="{esc(c.verdict)}" title="{esc(tip)}" role="img" '
            f'aria-label="{esc(c.verdict)}">{MARKS.get(c.verdict, "?")}</span>')


def marks_html(claims: list[Numbered]) -> str:
    return '<span class="marks">' + "".join(mark_html(k, c) for k, c in claims) + "</span>"


def corrections_html(claims: list[Numbered]) -> str:
    """Under a block: for each incorrect claim, its message and the right value typeset."""
    out = []
    for k, c in claims:
        if c.verdict != "incorrect":
            continue
        what = f" ({esc(c.understood)})" if c.understood else ""
        fix = f'<div class="math-display fix">{esc(c.fix)}</div>' if c.fix.strip() else ""
        out.append(f'<div class="correction" data-claim="{k}" data-line="{c.line}" data-end-line="{c.end_line}">'
                   f"<p>{MARKS['incorrect']} <b>{_lines(c)}</b>{what}: {esc(c.message)}</p>{fix}</div>")
    return "\n".join(out)


def display_html(latex: str, first: int, last: int, label: str, claims: list[Numbered]) -> str:
    """A display equation of report lines ``first``–``last`` (1-based) with its marks beside it and the
    corrections of its incorrect claims under it."""
    eqno = f'<span class="eqno">({esc(label)})</span>' if label else ""
    return (f'<div class="eq{" judged" if claims else ""}">'
            f'<div class="math-display" data-line="{first}" data-end-line="{last}">{esc(latex)}</div>'
            f'{eqno}{marks_html(claims) if claims else ""}</div>\n' + corrections_html(claims))


def choose_span(spans: list[tuple[int, int, bool]], first: int, last: int) -> int | None:
    """Index of the span (0-based half-open line range, holds mathematics?) that a claim on 0-based lines
    ``first``..``last`` is shown at: the smallest span holding ``last`` (one with mathematics preferred, then
    the later one), else one overlapping the claim, else the last span starting before it, else the first."""
    def best(idx: list[int]) -> int:
        return min(idx, key=lambda i: (spans[i][1] - spans[i][0], not spans[i][2], -i))

    holding = [i for i, (a, b, _) in enumerate(spans) if a <= last < b]
    if holding:
        return best(holding)
    overlapping = [i for i, (a, b, _) in enumerate(spans) if a <= last and first < b]
    if overlapping:
        return best(overlapping)
    before = [i for i, (a, _, _) in enumerate(spans) if a <= last]
    return before[-1] if before else (0 if spans else None)


def _header(report: GradedReport, title: str) -> str:
    """Counts per verdict, the arms used, the report's notes and the legend."""
    counts = "".join(f'<span><span class="verdict v-{_slug(v)}">{MARKS[v]}</span> {n} {esc(v)}</span>'
                     for v, n in report.summary().items())
    arms = "".join(f"<li><b>{esc(a.name)}</b> ({esc(a.convention)} DH, {a.dof} joints) — "
                   f"{'section “' + esc(a.section) + '”, ' if a.section else ''}lines {a.line}–{a.end_line}; "
                   f"from {esc(a.source)}{'; ' + esc('; '.join(a.notes)) if a.notes else ''}</li>"
                   for a in report.arms)
    notes = "".join(f"<li>{esc(n)}</li>" for n in report.notes)
    legend = "".join(f'<li><span class="verdict v-{_slug(v)}">{MARKS[v]}</span> <b>{esc(v)}</b>: {esc(LEGEND[v])}'
                     "</li>" for v in VERDICTS)
    return (f'<header class="grade"><h1>{esc(title)}</h1>\n<p class="counts">{counts}</p>\n'
            f'<p>{len(report.claims)} equations judged against {len(report.arms)} arm(s):</p>'
            f'<ul class="arms">{arms}</ul>\n' + (f'<ul class="notes">{notes}</ul>\n' if notes else "")
            + f'<details class="legend" open><summary>Legend</summary><ul>{legend}</ul>'
            "<p>Hover a mark for its message; every verdict is listed at the end.</p></details></header>")


def _table(report: GradedReport) -> str:
    """Every verdict in report order, each line linking to its mark."""
    rows = "".join(f'<tr><td><a href="#claim-{k}">{_lines(c)}</a></td><td>{MARKS.get(c.verdict, "?")} '
                   f"{esc(c.verdict)}</td><td>{esc(c.quantity)}</td><td>{esc(c.arm)}</td><td>{esc(c.understood)}"
                   f"</td><td>{esc(c.message)}</td></tr>" for k, c in enumerate(report.claims))
    return ('<section class="all-verdicts"><h2>Every verdict</h2><table class="verdicts"><thead><tr><th>where</th>'
            "<th>verdict</th><th>quantity</th><th>arm</th><th>understood as</th><th>message</th></tr></thead>"
            f"<tbody>{rows}</tbody></table></section>")


def page_html(report: GradedReport, body: str) -> str:
    """The whole page: summary and legend, the report's body, the list of verdicts, the inlined KaTeX."""
    from ..report import KATEX_TYPESET_SCRIPT, katex_bundle

    css, js = katex_bundle()
    title = f"Checked: {PurePath(report.source).name or report.source}"
    return ("<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">"
            f"<title>{esc(title)}</title>\n<style>{css}</style>\n<style>{_CSS}</style></head>\n<body>\n"
            + _header(report, title) + f'\n<article class="report">\n{body}\n</article>\n' + _table(report)
            + "\n<noscript><p>JavaScript is off: the mathematics above is shown as LaTeX source.</p></noscript>\n"
            f"<script>{js}</script>\n<script>{KATEX_TYPESET_SCRIPT}</script>\n</body></html>\n")
