"""Presenters of a :class:`~denavit.report.Derivation`: Markdown, LaTeX and self-contained HTML.

Every renderer returns ``(text, attachments)``: the document and the files it refers to (pictures, as
``{file name: bytes}``), which the caller writes beside it.  HTML embeds pictures and the bundled
KaTeX renderer (JavaScript, CSS and fonts, MIT licence, ``assets/katex``), so a report opens offline.
"""

from __future__ import annotations

import base64
import html
import re
from datetime import date
from functools import lru_cache
from importlib import resources
from typing import Any

import numpy as np

from .. import _text
from ._breaking import break_display
from ._derivation import Derivation, Equation, Figure, Heading, Numbers, Section, Table, Text

__all__ = ["render", "render_markdown", "render_latex", "render_html", "math_of", "number_text", "FORMATS",
           "katex_bundle", "KATEX_TYPESET_SCRIPT"]

FORMATS = ("md", "tex", "html")


def number_text(x: float, digits: int = 4) -> str:
    """A decimal for display: ``digits`` decimals, trailing zeros dropped, tiny values shown as 0."""
    if abs(x) < 0.5 * 10.0 ** (-digits):
        return "0"
    s = f"{x:.{digits}f}".rstrip("0").rstrip(".")
    return s


def _matrix(values: np.ndarray, digits: int) -> str:
    A = np.asarray(values, dtype=float)
    if A.ndim == 0:
        return number_text(float(A), digits)
    if A.ndim == 1:
        A = A[:, None]
    body = " \\\\ ".join(" & ".join(number_text(v, digits) for v in row) for row in A)
    return f"\\begin{{bmatrix}} {body} \\end{{bmatrix}}"


def math_of(step: Equation | Numbers) -> str:
    """The LaTeX of an equation or a numbers step (without delimiters); one too wide for the page is an
    ``aligned`` block broken at + and − (:func:`._breaking.break_display`)."""
    note = f"\\text{{({_text_in_math(step.note)})}}" if step.note else ""
    if isinstance(step, Numbers):
        out = f"{step.lhs} \\approx {_matrix(step.values, step.digits)}"
    else:
        from ._sections import latex

        broken = break_display(step.lhs, step.relation, step.expr, note, latex)  # too wide for one line
        if broken is not None:
            return broken
        rhs = step.expr if isinstance(step.expr, str) else latex(step.expr)
        out = f"{step.lhs} {step.relation} {rhs}"
    return out + (f" \\qquad {note}" if note else "")


def _text_in_math(s: str) -> str:
    """Text for ``\\text{...}``: specials escaped, ``$...$`` spans kept as mathematics."""
    parts = s.split("$")
    for i in range(0, len(parts), 2):
        p = re.sub(r"([#%&_{}])", r"\\\1", parts[i].replace("\\", " "))
        parts[i] = p.replace("^", "\\^{}").replace("~", "\\~{}")
    return "$".join(parts)


def _status_line(sec: Section) -> str:
    if sec.status == "done":
        return ""
    word = "Not available" if sec.status == "unavailable" else "Skipped"
    return f"{word}: {sec.reason}."


def _inputs_line(d: Derivation, esc: Any = str, name: Any = str) -> str:
    """The line under the title; ``esc`` escapes its own text for the format, ``name`` the robot's name (free
    text: its ``$`` or ``#`` are characters, never mathematics or markup)."""
    inp = d.inputs
    parts = [esc("robot ") + name(inp["robot"]) + esc(f" ({inp['convention']} DH)")]
    if len(inp.get("cases") or ()) > 1:
        parts.append(esc(f"{len(inp['cases'])} numeric cases"))
        return esc("; ").join(parts)
    parts.append(esc("q = (" + ", ".join(inp["q_exact"]) + ")" + ("" if inp["q_given"] else " (default)")))
    if inp.get("qd") is not None:
        parts.append(esc("qd = (" + ", ".join(f"{v:g}" for v in inp["qd"]) + ")"))
    if inp.get("wrench") is not None:
        parts.append(esc("F = (" + ", ".join(f"{v:g}" for v in inp["wrench"]) + ")"))
    return esc("; ").join(parts)


_MD_PUNCT = re.compile(r"([\\`*_{}\[\]<>#!|$~&])")
_MD_LINE_START = re.compile(r"^(\s*)([-+>]|\d+[.)])")


def _md_plain(s: str) -> str:
    """User text (a robot's name) as plain Markdown: one line, every character that can start markup inside a line
    backslash-escaped, and a list or quote marker at its start too (``-``, ``+``, ``1.``); a hyphen inside a name
    such as ``puma560-mdh`` stays as written."""
    text = _MD_PUNCT.sub(r"\\\1", _text.visible(s))
    return _MD_LINE_START.sub(lambda m: m.group(1) + m.group(2)[:-1] + "\\" + m.group(2)[-1], text)


def _tex_plain(s: str) -> str:
    """User text as plain LaTeX: one line, every special character escaped, ``$`` included (no mathematics)."""
    return "".join(_TEX_PLAIN.get(ch, ch) for ch in _text.visible(s))


def _html_plain(s: str) -> str:
    return html.escape(_text.visible(s))


# --------------------------------------------------------------------------------------------------
# Markdown


def render_markdown(d: Derivation, figure_prefix: str = "") -> tuple[str, dict[str, bytes]]:
    """GitHub/Pandoc-style Markdown with ``$$ … $$`` display mathematics."""
    out = [f"# {_md_plain(d.title)}", "",
           f"*Generated by denavit on {date.today().isoformat()}.* {_inputs_line(d, name=_md_plain)}.", ""]
    files: dict[str, bytes] = {}
    for k, sec in enumerate(d.sections, start=1):
        out += [f"## {k}. {sec.title}", ""]
        if sec.status != "done":
            out += [f"> {_status_line(sec)}", ""]
        for step in sec.steps:
            if isinstance(step, Text):
                out += [step.text, ""]
            elif isinstance(step, Heading):
                out += [f"### {step.text}", ""]
            elif isinstance(step, (Equation, Numbers)):
                out += ["$$", math_of(step), "$$", ""]
            elif isinstance(step, Table):
                cell = (lambda c: f"${c}$") if step.math else (lambda c: c)
                if step.caption:
                    out += [f"*{step.caption}*", ""]
                out.append("| " + " | ".join(cell(h) for h in step.header) + " |")
                out.append("|" + "---|" * len(step.header))
                out += ["| " + " | ".join(cell(c) for c in row) + " |" for row in step.rows]
                out.append("")
            elif isinstance(step, Figure):
                name = figure_prefix + step.name
                files[name] = step.png
                out += [f"![{step.caption}]({name})", "", f"*{step.caption}*", ""]
    return "\n".join(out), files


# --------------------------------------------------------------------------------------------------
# LaTeX

_TEX_SPECIAL = {"&": r"\&", "%": r"\%", "#": r"\#", "_": r"\_", "{": r"\{", "}": r"\}", "~": r"\textasciitilde{}",
                "^": r"\textasciicircum{}", "\\": r"\textbackslash{}", "→": r"$\to$", "≈": r"$\approx$",
                "−": r"$-$", "±": r"$\pm$", "×": r"$\times$", "σ": r"$\sigma$", "δ": r"$\delta$", "ω": r"$\omega$",
                "θ": r"$\theta$", "α": r"$\alpha$", "π": r"$\pi$", "≥": r"$\geq$", "≤": r"$\leq$", "≠": r"$\neq$",
                "²": r"$^2$", "ᵀ": r"$^T$", "√": r"$\surd$", "⇔": r"$\Leftrightarrow$", "·": r"$\cdot$",
                "–": "--", "—": "---", "…": r"\ldots{}", "∥": r"$\parallel$", "⟂": r"$\perp$",
                "＄": r"\$"}  # ＄: a dollar of user text (report._sections), never mathematics


_TEX_PLAIN = {**_TEX_SPECIAL, "$": r"\$"}


def _tex_text(s: str) -> str:
    """Escape text for LaTeX, leaving ``$...$`` spans as mathematics."""
    parts = s.split("$")
    for i in range(0, len(parts), 2):
        parts[i] = "".join(_TEX_SPECIAL.get(ch, ch) for ch in parts[i])
    return "$".join(parts)


def render_latex(d: Derivation, figure_prefix: str = "") -> tuple[str, dict[str, bytes]]:
    """A complete LaTeX document (amsmath, graphicx, adjustbox for wide matrices)."""
    out = [
        r"\documentclass[10pt]{article}",
        r"\usepackage[margin=2cm]{geometry}",
        r"\usepackage{amsmath,amssymb,graphicx,adjustbox}",
        r"\setcounter{MaxMatrixCols}{20}",
        r"\allowdisplaybreaks",  # a formula broken over many lines may continue on the next page
        r"\sloppy",  # long identifiers (function names) move to the next line instead of into the margin
        r"\renewcommand{\arraystretch}{1.4}",
        rf"\title{{{_tex_plain(d.title)}}}",
        r"\author{denavit}",
        rf"\date{{{date.today().isoformat()}}}",
        r"\begin{document}",
        r"\maketitle",
        _inputs_line(d, _tex_text, _tex_plain) + ".",
        "",
    ]
    files: dict[str, bytes] = {}
    for sec in d.sections:
        out += [rf"\section{{{_tex_text(sec.title)}}}", ""]
        if sec.status != "done":
            out += [r"\emph{" + _tex_text(_status_line(sec)) + "}", ""]
        for step in sec.steps:
            if isinstance(step, Text):
                out += [_tex_text(step.text), ""]
            elif isinstance(step, Heading):
                out += [rf"\subsection*{{{_tex_text(step.text)}}}", ""]
            elif isinstance(step, (Equation, Numbers)):
                m = math_of(step)
                if m.startswith(r"\begin{aligned}"):  # broken over lines: align* may break across pages
                    out += [r"\begin{align*}" + m[len(r"\begin{aligned}"):-len(r"\end{aligned}")] + r"\end{align*}", ""]
                else:
                    out += [r"\begin{center}\begin{adjustbox}{max width=\linewidth}$\displaystyle "
                            + m + r"$\end{adjustbox}\end{center}", ""]
            elif isinstance(step, Table):
                cell = (lambda c: f"${c}$") if step.math else _tex_text
                out += [r"\begin{center}\small", r"\begin{adjustbox}{max width=\linewidth}",
                        r"\begin{tabular}{" + "c" * len(step.header) + "}", r"\hline",
                        " & ".join(cell(h) for h in step.header) + r" \\ \hline"]
                out += [" & ".join(cell(c) for c in row) + r" \\" for row in step.rows]
                out += [r"\hline", r"\end{tabular}", r"\end{adjustbox}"]
                if step.caption:
                    out.append(r"\\[2pt] \emph{" + _tex_text(step.caption) + "}")
                out += [r"\end{center}", ""]
            elif isinstance(step, Figure):
                name = figure_prefix + step.name
                files[name] = step.png
                out += [r"\begin{figure}[h]\centering", rf"\includegraphics[width=0.7\linewidth]{{{name}}}",
                        rf"\caption{{{_tex_text(step.caption)}}}", r"\end{figure}", ""]
    out.append(r"\end{document}")
    return "\n".join(out), files


# --------------------------------------------------------------------------------------------------
# HTML

_CSS = """
body { font-family: system-ui, -apple-system, "Segoe UI", sans-serif; max-width: 60rem; margin: 2rem auto;
       padding: 0 1rem; line-height: 1.5; color: #1d1d1f; }
h1 { font-size: 1.7rem; } h2 { margin-top: 2.2rem; border-bottom: 1px solid #ddd; padding-bottom: .2rem; }
.math-display { overflow-x: auto; overflow-y: hidden; padding: .3rem 0; }
.status { background: #fff6d6; border-left: 4px solid #e0b000; padding: .4rem .8rem; }
.table-wrap { max-width: 100%; overflow-x: auto; }
table.dh { border-collapse: collapse; margin: .8rem 0; font-size: .92rem; } table.dh td, table.dh th {
       border: 1px solid #ccc; padding: .25rem .6rem; text-align: center; }
table.dh.text td { white-space: normal; } table.dh .num { white-space: nowrap; font-variant-numeric: tabular-nums; }
figure img { max-width: 100%; } .meta { color: #555; }
"""

_NUMBER = re.compile(r"[-+−]?[0-9.]+(e[-+][0-9]+)?")  # a plain-text number cell: kept on one line

_STRETCH = "\\def\\arraystretch{1.45}"  # room for fractions inside matrices

#: Typesets every ``.math-display`` / ``.math-inline`` element with KaTeX (run after ``katex_bundle()``'s JS).
KATEX_TYPESET_SCRIPT = """
document.querySelectorAll('.math-display, .math-inline').forEach(function (el) {
  try { katex.render(el.textContent, el, {displayMode: el.classList.contains('math-display'),
                                          throwOnError: false, maxSize: 20, strict: false}); }
  catch (e) { el.title = String(e); }
});
"""


@lru_cache(maxsize=1)
def katex_bundle() -> tuple[str, str]:
    """KaTeX CSS (fonts inlined as data: URIs, woff2 only) and JavaScript, from the bundled assets."""
    root = resources.files("denavit.report") / "assets" / "katex"
    css = (root / "katex.min.css").read_text(encoding="utf-8")
    css = re.sub(r',url\(fonts/[^)]*\.(?:woff|ttf)\) format\("[a-z]+"\)', "", css)

    def inline(m: re.Match) -> str:
        data = (root / "fonts" / m.group(1)).read_bytes()
        return "url(data:font/woff2;base64," + base64.b64encode(data).decode("ascii") + ")"

    css = re.sub(r"url\(fonts/([A-Za-z0-9_-]+\.woff2)\)", inline, css)
    js = (root / "katex.min.js").read_text(encoding="utf-8").replace("</script", "<\\/script")
    return css, js


def _html_text(s: str) -> str:
    """Escape text, turning ``$...$`` spans into inline mathematics."""
    parts = s.split("$")
    out = []
    for i, p in enumerate(parts):
        out.append(html.escape(p) if i % 2 == 0 else f'<span class="math-inline">{html.escape(p)}</span>')
    return "".join(out)


def _html_step(step: Any) -> str:
    if isinstance(step, Text):
        return f"<p>{_html_text(step.text)}</p>"
    if isinstance(step, Heading):
        return f"<h3>{_html_text(step.text)}</h3>"
    if isinstance(step, (Equation, Numbers)):
        return f'<div class="math-display">{html.escape(_STRETCH + math_of(step))}</div>'
    if isinstance(step, Table):
        cell = ((lambda c: f'<span class="math-inline">{html.escape(c)}</span>') if step.math else _html_text)
        td = (lambda c: "<td>" if step.math or not _NUMBER.fullmatch(c) else '<td class="num">')
        head = "".join(f"<th>{cell(h)}</th>" for h in step.header)
        body = "".join("<tr>" + "".join(f"{td(c)}{cell(c)}</td>" for c in row) + "</tr>" for row in step.rows)
        cap = f"<caption>{html.escape(step.caption)}</caption>" if step.caption else ""
        kind = "dh" if step.math else "dh text"
        return (f'<div class="table-wrap"><table class="{kind}">{cap}<thead><tr>{head}</tr></thead>'
                f"<tbody>{body}</tbody></table></div>")
    if isinstance(step, Figure):
        data = base64.b64encode(step.png).decode("ascii")
        return (f'<figure><img alt="{html.escape(step.caption)}" src="data:image/png;base64,{data}">'
                f"<figcaption>{html.escape(step.caption)}</figcaption></figure>")
    raise TypeError(f"unknown step {type(step).__name__}")


def render_html(d: Derivation) -> tuple[str, dict[str, bytes]]:
    """One self-contained HTML file: mathematics typeset offline by the bundled KaTeX."""
    css, js = katex_bundle()
    body = [f"<h1>{_html_plain(d.title)}</h1>",
            f'<p class="meta">Generated by denavit on {date.today().isoformat()}. '
            f'{_inputs_line(d, html.escape, _html_plain)}.</p>']
    for k, sec in enumerate(d.sections, start=1):
        body.append(f'<section id="{sec.key}"><h2>{k}. {html.escape(sec.title)}</h2>')
        if sec.status != "done":
            body.append(f'<p class="status">{html.escape(_status_line(sec))}</p>')
        body += [_html_step(s) for s in sec.steps]
        body.append("</section>")
    doc = ("<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">"
           f"<title>{_html_plain(d.title)}</title>\n<style>{css}</style>\n<style>{_CSS}</style></head>\n<body>\n"
           + "\n".join(body)
           + "\n<noscript><p>JavaScript is off: the mathematics above is shown as LaTeX source.</p></noscript>\n"
           f"<script>{js}</script>\n<script>{KATEX_TYPESET_SCRIPT}</script>\n</body></html>\n")
    return doc, {}


def render(d: Derivation, fmt: str, figure_prefix: str = "") -> tuple[str, dict[str, bytes]]:
    """Render in ``fmt``, one of :data:`FORMATS`."""
    if fmt == "md":
        return render_markdown(d, figure_prefix)
    if fmt == "tex":
        return render_latex(d, figure_prefix)
    if fmt == "html":
        return render_html(d)
    from ..errors import ParseError

    raise ParseError(f"unknown report format {fmt!r}; choose one of {', '.join(FORMATS)} or pdf")
