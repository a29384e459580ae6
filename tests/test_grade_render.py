"""The checked report's presenters: Markdown with blockquotes, offline HTML with marks (and a browser test).

The graded reports are built by hand from small report texts written for these tests (``$$`` blocks, ``\\[ \\]``,
an ``aligned`` block holding two claims, inline mathematics, an ``equation`` environment, a labelled block, a
LaTeX report); the expected place of every verdict is the line number counted by hand in the text below, and
each fixture checks its own line numbers before use.  The browser test opens the HTML in Chromium (Playwright,
Debian's chromium, as tests/test_view_browser.py) and reads back where each mark landed.
"""

from __future__ import annotations

import os
import re
import shutil
from html.parser import HTMLParser
from pathlib import Path

import pytest

from denavit.errors import ParseError
from denavit.grade import (
    ArmInfo,
    GradedClaim,
    GradedReport,
    render_checked_html,
    render_checked_markdown,
    write_checked,
)

MARK = {"correct": "✓", "incorrect": "✗", "ambiguous": "?", "unreadable": "!", "not a claim": "·"}  # issue 24
HOSTILE = 'see <script>alert("m")</script> [a](javascript:alert(1)) *b* `c` $d$ &amp; |e|\n\n# not a heading'

MD_REPORT = r"""# Exercise 1: planar 2R

| i | $a_{i}$ | $\alpha_{i}$ | $d_i$ | $\theta_i$ |
|---|---|---|---|---|
| 1 | $L_1$ | 0 | 0 | $q_1$ |
| 2 | $L_2$ | 0 | 0 | $q_2$ |

The first link transform is
$$
{}^0T_1 = \begin{bmatrix} c_1 & -s_1 & 0 & L_1 c_1 \\ s_1 & c_1 & 0 & L_1 s_1 \\ 0 & 0 & 1 & 0 \\ 0 & 0 & 0 & 1 \end{bmatrix} \quad (1)
$$

\[
A_2 = \begin{bmatrix} c_2 & -s_2 & 0 & L_2 c_2 \\ s_2 & c_2 & 0 & L_2 s_2 \\ 0 & 0 & 1 & 0 \\ 0 & 0 & 0 & 1 \end{bmatrix}
\]

$$
\begin{aligned}
p_x &= L_1 c_1 + L_2 c_{12} \\
p_y &= L_1 s_1 + L_2 c_{12}
\end{aligned}
$$

So the end effector moves with $\det J = L_1 L_2 s_2$ and
the elbow angle is $q_2 = \cos^{-1}\left(\frac{x^2+y^2-L_1^2-L_2^2}{2 L_1 L_2}\right)$.
The arm is singular when the elbow is straight.

<script>alert("pwned")</script> <img src="http://example.com/x.png"> ![photo](http://example.com/y.png)

\begin{equation}
\tau = J^T F
\end{equation}

$$ \theta_1 = \operatorname{atan2}(y, x) + \operatorname{atan2}(L_2 s_2, L_1 + L_2 c_2) $$ (7)
"""

ARM = ArmInfo("exercise-1", "Exercise 1: planar 2R", 1, 34, "table at line 3", "standard", 2)


def _claim(line, end_line, quantity, verdict, latex, message="agrees with the arm", fix="", understood=""):
    return GradedClaim(line, end_line, quantity, "exercise-1", verdict, message, latex=latex, understood=understood,
                       fix=fix)


# (claim, the original line after which its blockquote must come, a piece of the equation it must sit beside)
MD_CLAIMS = [
    (_claim(9, 11, "T_0_1", "correct", "{}^0T_1", understood="{}^0T_1 read as A_1"), 11, "{}^0T_1"),
    (_claim(13, 15, "A_2", "correct", "A_2"), 15, "A_2 ="),
    (_claim(19, 19, "p_x", "correct", "p_x"), 22, "p_x &="),
    (_claim(20, 20, "p_y", "incorrect", "p_y", "the entry differs", fix=r"L_1 s_1 + L_2 s_{12}"), 22, "p_y &="),
    (_claim(24, 24, "det_J", "correct", r"\det J"), 26, r"\det J"),
    (_claim(25, 25, "q_2", "ambiguous", "q_2", "elbow up or down decides"), 26, r"q_2 = \cos^{-1}"),
    (_claim(26, 26, "singular", "unreadable", "", "no condition in the words"), 26, None),
    (_claim(30, 32, "tau", "not a claim", r"\tau", "a definition"), 32, r"\tau = J^T F"),
    (_claim(34, 34, "q_1", "incorrect", r"\theta_1", HOSTILE,
            fix=r"\operatorname{atan2}(y, x) - \operatorname{atan2}(L_2 s_2, L_1 + L_2 c_2)"), 34, r"\operatorname{atan2}"),
]

TEX_REPORT = r"""\documentclass{article}
\begin{document}
\section{Forward kinematics}

The first transform, with $c_1 = \cos q_1$:
\[
A_1 = \begin{bmatrix} c_1 & -s_1 \\ s_1 & c_1 \end{bmatrix}
\]
\begin{align}
p_x &= L_1 c_1 + L_2 c_{12} \\
p_y &= L_1 s_1 + L_2 c_{12}
\end{align}
The Jacobian determinant is $\det J = L_1 L_2 s_2$. <script>alert(1)</script>
\end{document}
"""

TEX_CLAIMS = [
    (_claim(6, 8, "A_1", "correct", "A_1"), 8, "A_1 ="),
    (_claim(10, 10, "p_x", "correct", "p_x"), 12, "p_x &="),
    (_claim(11, 11, "p_y", "incorrect", "p_y", "the entry differs", fix=r"L_1 s_1 + L_2 s_{12}"), 12, "p_y &="),
    (_claim(13, 13, "det_J", "correct", r"\det J"), 13, r"\det J"),
]


def _report(text: str, fmt: str, claims) -> GradedReport:
    return GradedReport(f"report.{fmt}", text, fmt, (ARM,), tuple(c for c, _, _ in claims))


def test_fixtures_line_numbers_are_what_the_tests_say():
    """The hand-counted lines: every claim's block ends where its expected anchor says, on the line shown."""
    md = MD_REPORT.split("\n")
    assert [md[k - 1] for k in (11, 15, 22, 32)] == ["$$", "\\]", "$$", "\\end{equation}"]
    assert md[18].startswith("p_x") and md[19].startswith("p_y") and md[25].startswith("The arm is singular")
    assert md[33].startswith("$$ \\theta_1") and md[27].startswith("<script>")
    tex = TEX_REPORT.split("\n")
    assert [tex[k - 1] for k in (8, 12)] == ["\\]", "\\end{align}"] and tex[12].startswith("The Jacobian")


# --- Markdown ---------------------------------------------------------------------------------------------


def _inserted(original: str, checked: str) -> dict[int, list[str]]:
    """{number of original lines before an inserted blockquote: its lines}.  Each run of lines starting with
    ``>`` (the fixtures have none of their own) must have a blank line on each side; removing the runs and
    those two blank lines must give the original text back byte for byte."""
    assert not any(line.startswith(">") for line in original.splitlines())
    lines = checked.splitlines(keepends=True)
    kept: list[str] = []
    out: dict[int, list[str]] = {}
    k = 0
    while k < len(lines):
        if not lines[k].startswith(">"):
            kept.append(lines[k])
            k += 1
            continue
        end = k
        while end < len(lines) and lines[end].startswith(">"):
            end += 1
        assert kept and kept[-1] == "\n" and end < len(lines) and lines[end] == "\n", lines[k - 1:end + 1]
        kept.pop()
        out[len(kept)] = lines[k:end]
        k = end + 1
    assert "".join(kept) == original
    return out


@pytest.mark.parametrize("text, fmt, claims", [(MD_REPORT, "md", MD_CLAIMS), (TEX_REPORT, "tex", TEX_CLAIMS)],
                         ids=["markdown", "latex"])
def test_markdown_blockquotes_follow_each_block_and_keep_every_line(text, fmt, claims):
    """Every original line is kept; each claim is quoted once, in the quote right after its block's last line
    (an aligned block's two claims in one quote after the closing $$), with blank lines around the quote."""
    inserted = _inserted(text, render_checked_markdown(_report(text, fmt, claims)))
    assert sorted(inserted) == sorted({after for _, after, _ in claims})
    everything = "".join(line for lines in inserted.values() for line in lines)
    for c, after, _ in claims:
        where = f"(line {c.line})" if c.line == c.end_line else f"(lines {c.line}–{c.end_line})"
        head = f"> {MARK[c.verdict]} **{c.verdict}** {where}"
        assert head in "".join(inserted[after]) and everything.count(head) == 1, head


def _commonmark_html(markdown: str) -> str:
    """The Markdown as a permissive viewer would show it: raw HTML allowed, TeX mathematics recognised."""
    from markdown_it import MarkdownIt
    from mdit_py_plugins.dollarmath import dollarmath_plugin

    return MarkdownIt("commonmark", {"html": True}).use(dollarmath_plugin).render(markdown)


def test_markdown_message_cannot_break_out_of_its_blockquote():
    """A message is data: its tags, link, emphasis, code, math, entity and blank line stay literal text, inside
    the quote, even in a viewer that renders raw HTML."""
    claim = MD_CLAIMS[-1][0]
    out = render_checked_markdown(GradedReport("r.md", "$$ x = 1 $$\n", "md", (ARM,), (claim,)))
    html = _commonmark_html(out)
    assert "<script" not in html and "<a " not in html and "<h1>" not in html and "<em>" not in html
    assert "<code>" not in html and html.count("<blockquote>") == 1
    quote = html[html.index("<blockquote>"):html.index("</blockquote>")]
    assert "&lt;script&gt;alert(&quot;m&quot;)&lt;/script&gt;" in quote and "[a](javascript:alert(1))" in quote
    assert "*b* `c` $d$ &amp;amp; |e|" in quote and "# not a heading" in quote


def test_markdown_fix_is_display_math_inside_the_quote():
    """An incorrect claim's fix comes back as one $$…$$ block inside the quote, its LaTeX unchanged."""
    from markdown_it import MarkdownIt
    from mdit_py_plugins.dollarmath import dollarmath_plugin

    out = render_checked_markdown(_report(MD_REPORT, "md", MD_CLAIMS))
    tokens = MarkdownIt("commonmark").use(dollarmath_plugin).parse(out)
    depth, in_quote = 0, []
    for t in tokens:
        depth += t.nesting if t.type.startswith("blockquote") else 0
        if t.type == "math_block" and depth > 0:
            in_quote.append(t.content.strip())
    assert in_quote == [c.fix for c, _, _ in MD_CLAIMS if c.verdict == "incorrect"]


def test_markdown_last_line_without_newline_and_crlf_lines_are_kept():
    text = "Intro\r\n\r\n$$\r\nA_1 = 1\r\n$$"
    claim = GradedClaim(3, 5, "A_1", "a", "correct", "ok")
    out = render_checked_markdown(GradedReport("r.md", text, "md", (ARM,), (claim,)))
    assert out.startswith(text + "\n\n> ✓ **correct** (lines 3–5) — ok\n")


def test_markdown_claim_outside_the_text_goes_at_the_end():
    claim = GradedClaim(40, 41, "x", "a", "unreadable", "lost")
    out = render_checked_markdown(GradedReport("r.md", "one\ntwo\n", "md", (ARM,), (claim,)))
    assert out == "one\ntwo\n\n> ! **unreadable** (lines 40–41) — lost\n\n"


# --- HTML (no browser) ------------------------------------------------------------------------------------


class _Tags(HTMLParser):
    def __init__(self):
        super().__init__()
        self.tags: list[tuple[str, dict]] = []

    def handle_starttag(self, tag, attrs):
        self.tags.append((tag, dict(attrs)))


def _tags(html: str) -> list[tuple[str, dict]]:
    p = _Tags()
    p.feed(html)
    return p.tags


@pytest.mark.parametrize("text, fmt, claims", [(MD_REPORT, "md", MD_CLAIMS), (TEX_REPORT, "tex", TEX_CLAIMS)],
                         ids=["markdown", "latex"])
def test_html_student_markup_is_text_and_every_claim_has_one_mark(text, fmt, claims):
    """The report's <script>, <img> and picture are shown as text (only our two scripts run, no <img>, no
    javascript: link); every claim has exactly one mark carrying its lines, and the tooltip its message."""
    html = render_checked_html(_report(text, fmt, claims))
    tags = _tags(html)
    assert [t for t, _ in tags].count("script") == 2 and not any(t == "img" for t, _ in tags)
    assert not any("javascript:" in (attrs.get("href") or "") + (attrs.get("src") or "") for _, attrs in tags)
    assert "&lt;script&gt;alert(" in html
    marks = [a for t, a in tags if "data-claim" in a and "verdict" in a.get("class", "")]
    assert sorted(int(a["data-claim"]) for a in marks) == list(range(len(claims)))
    for a in marks:
        c = claims[int(a["data-claim"])][0]
        assert (int(a["data-line"]), int(a["data-end-line"]), a["data-verdict"]) == (c.line, c.end_line, c.verdict)
        assert c.message in a["title"]
    corrections = [a for t, a in tags if a.get("class") == "correction"]
    assert sorted(int(a["data-claim"]) for a in corrections) == [k for k, (c, _, _) in enumerate(claims)
                                                                  if c.verdict == "incorrect"]


def test_html_summary_counts_and_arms():
    html = render_checked_html(_report(MD_REPORT, "md", MD_CLAIMS))
    head = html[html.index('<header class="grade">'):html.index("</header>")]
    for verdict, n in [("correct", 4), ("incorrect", 2), ("ambiguous", 1), ("unreadable", 1), ("not a claim", 1)]:
        assert f"</span> {n} {verdict}</span>" in head
    assert "exercise-1" in head and "table at line 3" in head and "Legend" in head


def test_html_bracket_delimiters_are_mathematics_not_escaped_brackets():
    r"""CommonMark reads ``\(`` and ``\[`` as escaped brackets; in a report they delimit mathematics."""
    text = "Inline \\(x = 1\\) and display \\[y = 2\\] in a line.\n\\[ z = 3 \\]\n"
    tags = _tags(render_checked_html(GradedReport("r.md", text, "md", (ARM,), ())))
    classes = [a.get("class") for t, a in tags if t in ("span", "div") and "math" in (a.get("class") or "")]
    assert classes == ["math-inline", "math-display", "math-display"]


def test_claims_in_a_table_row_and_a_list_item():
    """A claim in a table row: its mark in the row's cell with the formula, its correction under the whole table
    (never inside a row); a claim in a list item: its mark after its formula; both Markdown quotes after the
    table and after the whole list, never inside them."""
    text = ("| i | $a_i$ |\n|---|---|\n| 1 | $a_1 = L_1$ |\n| 2 | $a_2 = 0$ |\n\n"
            "- first $p_x = 1$\n- second $p_y = 2$\n\nEnd.\n")
    claims = (GradedClaim(4, 4, "a_2", "a", "incorrect", "a_2 is L_2", fix="L_2"),
              GradedClaim(7, 7, "p_y", "a", "correct", "ok"))
    report = GradedReport("r.md", text, "md", (ARM,), claims)
    page = render_checked_html(report)
    body = page[page.index('<article class="report">'):page.index("</article>")]
    mark0, mark1 = body.index('data-claim="0" data-line="4"'), body.index('data-claim="1" data-line="7"')
    assert body.index("a_2 = 0") < mark0 < body.index("</td>", body.index("a_2 = 0")) < body.index("</table>")
    assert body.index("</table>") < body.index('<div class="correction" data-claim="0"') < body.index("<ul>")
    assert body.index("p_y = 2") < mark1 < body.index("</li>", body.index("p_y = 2"))
    inserted = _inserted(text, render_checked_markdown(report))
    assert sorted(inserted) == [4, 7]  # after the table's last row, after the list's last item


@pytest.mark.slow
@pytest.mark.parametrize("unit, fmt", [("\\[\n", "md"), ("\\begin{align}\n", "md"), ("$$ a\nb $$ c\n", "md"),
                                       ("\\(", "md"), ("\\[\n", "tex"), ("\\begin{align}\n\\end{x}\n", "tex")])
def test_hostile_report_costs_no_more_than_plain_text(unit, fmt):
    """12,000 unclosed openers cost under ten times the CPU of 12,000 lines of plain text (0.1 s at least):
    a rescan to the end of the block window for each opener used to cost 20-40 times.  The 499 claims on it
    are all placed."""
    import time

    def cpu(text):
        claims = tuple(GradedClaim(k, k, "q", "a", "incorrect", "m", fix="x") for k in range(1, 500))
        report = GradedReport("r", text, fmt, (ARM,), claims)
        t = time.process_time()
        page, md = render_checked_html(report), render_checked_markdown(report)
        assert page.count('class="verdict v-incorrect" id="claim-') == 499 and md.count("> ✗ **incorrect**") == 499
        return time.process_time() - t

    cpu("x\n" * 200)  # warm-up: imports and the KaTeX bundle
    assert cpu(unit * 12000) < 10 * max(cpu("word x\n" * 12000), 0.1)


# --- writing ----------------------------------------------------------------------------------------------


def test_write_checked_chooses_by_suffix_and_replaces_atomically(tmp_path):
    report = _report(MD_REPORT, "md", MD_CLAIMS)
    md, page = tmp_path / "out.markdown", tmp_path / "out.HTML"
    page.write_text("old")
    write_checked(report, md)
    write_checked(report, page)
    assert md.read_text(encoding="utf-8") == render_checked_markdown(report)
    assert page.read_text(encoding="utf-8").startswith("<!DOCTYPE html>")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out.HTML", "out.markdown"]  # no temporary file left
    with pytest.raises(ParseError, match=r"out\.pdf.*\.html"):
        write_checked(report, tmp_path / "out.pdf")
    assert not (tmp_path / "out.pdf").exists()


# --- in a real browser ------------------------------------------------------------------------------------

CHROMIUM = os.environ.get("DENAVIT_CHROMIUM", "/usr/bin/chromium")
LAUNCH_ARGS = ["--headless", "--no-sandbox", "--disable-gpu", "--disable-background-networking",
               "--disable-component-update", "--disable-sync", "--no-first-run"]

# The TeX source of the closest report formula before claim k's mark, in document order (KaTeX keeps the
# source in an <annotation>); corrections' formulas are left out: they come after the mark.
_BEFORE_MARK = """k => {
  const mark = document.querySelector(`article.report .verdict[data-claim="${k}"]`);
  if (!mark) return {found: false};
  let prev = null;
  for (const m of document.querySelectorAll('article.report .math-display:not(.fix), article.report .math-inline'))
    if (m.compareDocumentPosition(mark) & Node.DOCUMENT_POSITION_FOLLOWING) prev = m;
  const ann = prev && prev.querySelector('annotation[encoding="application/x-tex"]');
  const corr = document.querySelector(`article.report .correction[data-claim="${k}"]`);
  return {found: true, tex: ann ? ann.textContent : null, text: mark.parentElement.closest('p, div').textContent,
          title: mark.title, correctionAfter: !!corr && !!(mark.compareDocumentPosition(corr) & 4),
          fixTypeset: !!corr && corr.querySelectorAll('.katex').length > 0};
}"""


@pytest.fixture(scope="module")
def browser():
    from conftest import CI

    def unavailable(reason):
        if CI:
            pytest.fail(f"browser test cannot run under CI: {reason}")
        pytest.skip(reason)

    try:
        from playwright.sync_api import sync_playwright
    except ImportError:
        unavailable("playwright is not installed (pip install playwright)")
    if not (Path(CHROMIUM).exists() or shutil.which(CHROMIUM)):
        unavailable(f"no chromium at {CHROMIUM} (apt-get install chromium)")
    with sync_playwright() as pw:
        b = pw.chromium.launch(executable_path=CHROMIUM, args=LAUNCH_ARGS, headless=True)
        yield b
        b.close()


@pytest.mark.browser
@pytest.mark.parametrize("text, fmt, claims", [(MD_REPORT, "md", MD_CLAIMS), (TEX_REPORT, "tex", TEX_CLAIMS)],
                         ids=["markdown", "latex"])
def test_checked_html_in_chromium_marks_sit_after_their_equations(browser, tmp_path, text, fmt, claims):
    """Opened offline in Chromium: KaTeX typesets every formula with no error and no console message, nothing
    is requested beyond the file itself (the report's remote picture is not fetched), and each claim's mark
    comes right after its own equation, with the correction of an incorrect one after the mark, typeset."""
    path = tmp_path / "checked.html"
    write_checked(_report(text, fmt, claims), path)
    page = browser.new_page(viewport={"width": 1000, "height": 800})
    problems: list[str] = []
    requests: list[str] = []
    page.on("console", lambda m: problems.append(f"console {m.type}: {m.text}") if m.type in ("error", "warning")
            else None)
    page.on("pageerror", lambda e: problems.append(f"page error: {e}"))
    page.on("request", lambda r: requests.append(r.url))
    page.goto(path.as_uri())
    page.wait_for_function("document.querySelectorAll('.katex').length > 0")
    n_math = page.evaluate("document.querySelectorAll('.math-display, .math-inline').length")
    assert page.evaluate("document.querySelectorAll('.katex-error').length") == 0
    assert page.evaluate("document.querySelectorAll('.math-display .katex, .math-inline .katex').length") >= n_math
    for k, (c, _, tex) in enumerate(claims):
        got = page.evaluate(_BEFORE_MARK, k)
        assert got["found"], c
        if tex is None:  # a claim in words: its mark ends the sentence that states it
            assert "singular when the elbow is straight" in got["text"]
        else:
            assert tex in re.sub(r"\s+", " ", got["tex"] or ""), (c, got["tex"])
        assert c.message.split("\n")[0] in got["title"]
        assert got["correctionAfter"] == got["fixTypeset"] == (c.verdict == "incorrect")
    page.close()
    assert problems == []
    assert requests and all(u == path.as_uri() or u.startswith("data:") for u in requests), requests


@pytest.mark.browser
def test_a_report_graded_by_the_cli_opens_in_chromium_with_every_mark(browser, tmp_path):
    """End to end: `denavit check REPORT -o checked.html` on the example report, opened offline: no KaTeX error,
    one mark per claim of the JSON (placed, with its verdict), a typeset correction under each incorrect one."""
    import json as _json
    import subprocess
    import sys

    report = Path(__file__).resolve().parents[1] / "examples" / "reports" / "planar2r-homework.md"
    out = tmp_path / "checked.html"
    res = subprocess.run([sys.executable, "-m", "denavit", "check", str(report), "-o", str(out), "--json"],
                         capture_output=True, text=True, timeout=900)
    assert res.returncode == 0, res.stderr
    claims = _json.loads(res.stdout)["claims"]
    assert any(c["verdict"] == "incorrect" for c in claims) and any(c["verdict"] == "correct" for c in claims)
    page = browser.new_page(viewport={"width": 1280, "height": 900})
    page.goto(out.as_uri())
    page.wait_for_function("document.querySelectorAll('.katex').length > 0")
    assert page.evaluate("document.querySelectorAll('.katex-error').length") == 0
    marks = page.evaluate("""() => [...document.querySelectorAll('article.report .verdict[data-claim]')]
        .map(m => [Number(m.dataset.claim), m.dataset.verdict, Number(m.dataset.line)])""")
    assert sorted(marks) == sorted([k, c["verdict"], c["line"]] for k, c in enumerate(claims))
    n_wrong = sum(c["verdict"] == "incorrect" for c in claims)
    assert page.evaluate("document.querySelectorAll('article.report .correction .katex').length") >= n_wrong
    page.close()


def test_latex_sections_and_the_dh_tabular_are_a_heading_and_a_table_and_the_preamble_is_left_out():
    """A paragraph ``\\section{DH parameters} Text \\begin{tabular}…\\end{tabular}`` is a heading, a paragraph and a
    table of escaped cells (a cell's markup stays text); ``\\documentclass``/``\\begin{document}`` are not shown."""
    text = ("\\documentclass{article}\n\\begin{document}\n\\section{DH parameters}\nThe table:\n"
            "\\begin{tabular}{|c|c|}\n\\hline\n$a_i$ & $\\alpha_i$ \\\\\n\\hline\n"
            "<script>alert(1)</script> & 0 \\\\\n\\end{tabular}\n\\end{document}\n")
    html = render_checked_html(GradedReport("r.tex", text, "tex", (ARM,), ()))
    tags = [t for t, _ in _tags(html)]
    assert "h2" in tags and tags.count("table") >= 1 and tags.count("td") >= 4
    body = html[html.index('<article'):html.index('</article>')]
    assert "documentclass" not in body and "begin{document}" not in body and "hline" not in body
    assert '<p data-line="4">The table:</p>' in body  # the line its text is on
    assert "&lt;script&gt;alert(1)&lt;/script&gt;" in html and tags.count("script") == 2


def test_a_plain_text_report_keeps_its_lines():
    """One equation a line in a .txt report stays one a line on the page (a paragraph's line breaks are kept;
    Markdown and LaTeX reports reflow as their formats do)."""
    text = "x = L1 cos θ1 + L2 cos(θ1 + θ2)\ny = L1 sin θ1 + L2 sin(θ1 + θ2)\n"
    page = render_checked_html(GradedReport("r.txt", text, "txt", (ARM,), ()))
    body = page[page.index("<article"):page.index("</article>")]
    assert body.count("<br") == 1
    same = render_checked_html(GradedReport("r.md", text, "md", (ARM,), ()))
    assert same[same.index("<article"):same.index("</article>")].count("<br") == 0
