"""The student's report as blocks with line ranges: Markdown by markdown-it, LaTeX by a small line scanner.

Both presenters of a graded report need the same thing from the report's text: which lines form one block
(a display equation, a paragraph, a table, a list) so a verdict goes under the whole equation and never
inside it.  Markdown is parsed by markdown-it-py (CommonMark, raw HTML **off**: the report is untrusted)
with mdit-py-plugins' ``dollarmath`` (``$…$``, ``$$…$$``, ``$$…$$ (9)``) and ``amsmath`` (top-level
``\\begin{align}`` …), plus two rules of our own for ``\\[…\\]`` blocks and ``\\(…\\)`` / ``\\[…\\]`` inline,
which CommonMark would otherwise read as escaped brackets.  Line numbers here are 0-based and ranges
half-open ``[start, end)``, as markdown-it's ``Token.map``; the presenters convert to the report's 1-based
inclusive ``line``/``end_line``.
"""

from __future__ import annotations

import re
from bisect import bisect_left, bisect_right
from dataclasses import dataclass, field

__all__ = ["MATH_BLOCKS", "MAX_BLOCK_LINES", "Block", "markdown_parser", "markdown_blocks", "tex_blocks", "block_end"]

#: markdown-it token types that are one display equation.
MATH_BLOCKS = ("math_block", "math_block_label", "amsmath")
#: A display block longer than this many lines is not one (a bound on any one scan of a hostile report).
MAX_BLOCK_LINES = 400


@dataclass(frozen=True)
class Block:
    """Lines ``[start, end)`` (0-based) of one block of the report; ``kind`` is ``"math"`` or ``"text"``.

    For LaTeX reports ``body`` is the block's source (the equation without its delimiters for ``"math"``).
    """

    start: int
    end: int
    kind: str
    body: str = ""


def _next(lines: list[int], after: int) -> int | None:
    """The first entry of the sorted ``lines`` that is ``>= after`` (None if there is none)."""
    k = bisect_left(lines, after)
    return lines[k] if k < len(lines) else None


@dataclass
class _LineIndex:
    """Which lines of a source could close a display block, found once per parse, so that every block rule
    asks "where is the next possible end?" by bisection instead of scanning line by line — linear time on a
    report of ten thousand unclosed ``$$`` or ``\\begin{align}`` lines.  ``lines`` are the raw lines of the
    source (a line's end is the same raw and inside a blockquote or list, which is all the index uses)."""

    lines: list[str]
    _ends: dict[str, list[int]] = field(default_factory=dict)
    _labels: list[int] | None = None
    _blanks: list[int] | None = None

    def ending_with(self, suffix: str) -> list[int]:
        if suffix not in self._ends:
            self._ends[suffix] = [k for k, s in enumerate(self.lines) if s.rstrip().endswith(suffix)]
        return self._ends[suffix]

    def dollar_closers(self) -> list[int]:
        """Lines that end a ``$$`` block: ending in ``$$``, or in dollarmath's ``$$ (label)``."""
        if self._labels is None:
            from mdit_py_plugins.dollarmath.index import DOLLAR_EQNO_REV

            labels = {k for k, s in enumerate(self.lines) if "$$" in s and DOLLAR_EQNO_REV.match(s[::-1])}
            self._labels = sorted(labels.union(self.ending_with("$$")))
        return self._labels

    def matching(self, pattern: re.Pattern) -> list[int]:
        """Lines in which ``pattern`` is found."""
        key = "re:" + pattern.pattern
        if key not in self._ends:
            self._ends[key] = [k for k, s in enumerate(self.lines) if pattern.search(s)]
        return self._ends[key]

    def blanks(self) -> list[int]:
        if self._blanks is None:
            self._blanks = [k for k, s in enumerate(self.lines) if not s.strip()]
        return self._blanks


def _index(state) -> _LineIndex:
    cached = state.env.get("denavit.line_index")
    if cached is None or cached[0] is not state.src:
        cached = (state.src, _LineIndex(state.src.split("\n")))
        state.env["denavit.line_index"] = cached
    return cached[1]


def _scan_end(start: int, end_line: int, closing: list[int], blanks: list[int] | None) -> int:
    """How far a block rule opened on ``start`` needs to look: to the first line after it that can close it,
    or only at ``start`` itself when no such line comes before a blank line (for rules that stop at one),
    ``end_line`` or :data:`MAX_BLOCK_LINES` lines."""
    end = min(end_line, start + MAX_BLOCK_LINES)
    close = _next(closing, start + 1)
    blank = _next(blanks, start + 1) if blanks is not None else None
    if close is None or close >= end or (blank is not None and blank < close):
        return start + 1
    return close + 1


def _bracket_block(state, start_line: int, end_line: int, silent: bool) -> bool:
    r"""Block rule: ``\[`` at the start of a line up to a line ending in ``\]`` (no blank line between)."""
    if state.sCount[start_line] - state.blkIndent >= 4:  # an indented code block
        return False
    pos = state.bMarks[start_line] + state.tShift[start_line]
    first = state.src[pos:state.eMarks[start_line]]
    if not first.startswith("\\["):
        return False
    idx = _index(state)
    end_line = _scan_end(start_line, end_line, idx.ending_with("\\]"), idx.blanks())
    line, parts = start_line, [first[2:]]
    while not parts[-1].rstrip().endswith("\\]"):
        line += 1
        if line >= end_line:
            return False
        text = state.src[state.bMarks[line] + state.tShift[line]:state.eMarks[line]]
        if not text.strip():
            return False
        parts.append(text)
    if silent:
        return True
    body = "\n".join(parts).rstrip()[:-2]
    state.line = line + 1
    token = state.push("math_block", "math", 0)
    token.block, token.content, token.markup, token.map = True, body, "\\[", [start_line, line + 1]
    return True


def _bracket_inline(state, silent: bool) -> bool:
    r"""Inline rule: ``\(…\)`` as inline mathematics and ``\[…\]`` as display mathematics inside a paragraph."""
    src, pos = state.src, state.pos
    if src[pos:pos + 2] not in ("\\(", "\\["):
        return False
    close = "\\)" if src[pos + 1] == "(" else "\\]"
    cache = state.env.setdefault("denavit.last_close", {})
    if close not in cache or cache[close][0] is not src:  # found once per text: 10^5 "\\(" on a line stay linear
        cache[close] = (src, src.rfind(close))
    end = src.find(close, pos + 2) if cache[close][1] >= pos + 2 else -1
    if end < 0 or not src[pos + 2:end].strip():
        return False
    if not silent:
        token = state.push("math_inline" if close == "\\)" else "math_inline_double", "math", 0)
        token.content, token.markup = src[pos + 2:end], src[pos:pos + 2]
    state.pos = end + 2
    return True


def _fix_amsmath_maps(state) -> None:
    """amsmath's tokens end their ``map`` on the ``\\end`` line (inclusive); make it half-open as all others."""
    for token in state.tokens:
        if token.type == "amsmath" and token.map:
            token.map = [token.map[0], token.map[0] + token.content.rstrip("\n").count("\n") + 1]


def _dollar_end(state, start: int, end_line: int) -> int:
    """dollarmath's ``$$`` block closes on a line ending in ``$$`` or ``$$ (label)`` and stops at a blank line."""
    idx = _index(state)
    return _scan_end(start, end_line, idx.dollar_closers(), idx.blanks())


def _amsmath_end(state, start: int, end_line: int) -> int:
    """amsmath's ``\\begin{env}`` closes on a line ending in the same ``\\end{env}`` (blank lines allowed)."""
    from mdit_py_plugins.amsmath import RE_OPEN

    m = re.match(RE_OPEN, state.src[state.bMarks[start] + state.tShift[start]:state.eMarks[start]])
    if not m:
        return start + 1
    return _scan_end(start, end_line, _index(state).ending_with(f"\\end{{{m.group(1)}{m.group(2)}}}"), None)


def _bounded(rule, scan_end):
    """A plugin's block rule made safe for us: it looks only as far as ``scan_end`` says (linear time on a
    hostile report), and a silent call (may it interrupt a paragraph?) leaves no token and no line moved —
    dollarmath's rule pushes its token even when asked silently."""
    def bounded(state, start_line: int, end_line: int, silent: bool) -> bool:
        end_line = scan_end(state, start_line, end_line)
        if not silent:
            return rule(state, start_line, end_line, False)
        n, line = len(state.tokens), state.line
        try:
            return rule(state, start_line, end_line, True)
        finally:
            del state.tokens[n:]
            state.line = line

    return bounded


def markdown_parser(breaks: bool = False):
    """A markdown-it parser for student reports: CommonMark + tables + TeX mathematics, raw HTML disabled.

    A display block may start right under a line of text (``…is\n$$``, as students write), as a fence may.
    ``breaks``: every line break kept (a plain-text report: one equation a line).
    """
    from markdown_it import MarkdownIt
    from mdit_py_plugins.amsmath import amsmath_block, amsmath_plugin
    from mdit_py_plugins.dollarmath import dollarmath_plugin
    from mdit_py_plugins.dollarmath.index import math_block_dollar

    md = MarkdownIt("commonmark", {"html": False, "linkify": False, "typographer": False, "breaks": breaks})
    md.enable("table")
    md.use(dollarmath_plugin, allow_labels=True, allow_space=True, allow_digits=True, double_inline=True)
    md.use(amsmath_plugin)
    interrupts = {"alt": ["paragraph", "reference", "blockquote", "list"]}
    md.block.ruler.at("math_block", _bounded(math_block_dollar(True, None), _dollar_end), interrupts)
    md.block.ruler.at("amsmath", _bounded(amsmath_block, _amsmath_end), interrupts)
    md.block.ruler.before("paragraph", "bracket_math", _bracket_block, interrupts)
    md.inline.ruler.before("escape", "bracket_math_inline", _bracket_inline)
    md.core.ruler.push("amsmath_map", _fix_amsmath_maps)
    return md


def markdown_blocks(tokens) -> list[Block]:
    """The top-level blocks of a parsed Markdown report (one per level-0 token that has a ``map``)."""
    out = []
    for t in tokens:
        if t.level == 0 and t.map and t.nesting >= 0:
            out.append(Block(t.map[0], t.map[1], "math" if t.type in MATH_BLOCKS else "text"))
    return out


_TEX_ENVS = ("equation", "align", "gather", "multline", "alignat", "flalign", "eqnarray", "displaymath", "math")
_TEX_OPEN = re.compile(r"\s*(\\\[|\$\$|\\begin\{(" + "|".join(_TEX_ENVS) + r")\*?\})")
_TEX_SKIP = re.compile(r"\s*\\(documentclass|usepackage|begin\{document\}|end\{document\}|maketitle)(?![A-Za-z])")


def _tex_math_end(idx: _LineIndex, k: int, opener: re.Match) -> tuple[int, str]:
    """(line after the display block opened on line ``k``, its mathematics); ``(k, "")`` if it does not close
    before a blank line (TeX ends display mathematics there) or within :data:`MAX_BLOCK_LINES` lines.  Only the
    lines up to the first one that can close it are read (linear time over the whole report)."""
    lines, env = idx.lines, opener.group(2)
    if env:  # the environment is kept whole: KaTeX typesets \begin{align}…\end{align} itself
        closer = re.compile(r"\\end\{" + re.escape(env) + r"\*?\}")
        segs = [lines[k][opener.start(1):]]
    else:
        closer = re.compile(re.escape("\\]" if opener.group(1) == "\\[" else "$$"))
        segs = [lines[k][opener.end():]]
    stop = _scan_end(k, len(lines), idx.matching(closer), idx.blanks())
    for j in range(k, stop):
        if j > k:
            segs.append(lines[j])
        m = closer.search(segs[-1])
        if m:
            segs[-1] = segs[-1][:m.end() if env else m.start()]
            return j + 1, "\n".join(segs).strip("\n")
    return k, ""


def tex_blocks(text: str) -> list[Block]:
    r"""A LaTeX report as blocks: display mathematics (``\[…\]``, ``$$…$$``, ``equation``/``align``/…
    environments) and paragraphs of text between blank lines; preamble commands are left out."""
    lines = text.split("\n")
    idx = _LineIndex(lines)
    out: list[Block] = []
    k, para = 0, -1
    while k < len(lines):
        m = _TEX_OPEN.match(lines[k])
        end, body = _tex_math_end(idx, k, m) if m else (k, "")
        if end > k:
            if para >= 0:
                out.append(Block(para, k, "text", "\n".join(lines[para:k])))
                para = -1
            out.append(Block(k, end, "math", body))
            k = end
            continue
        blank = not lines[k].strip() or bool(_TEX_SKIP.match(lines[k]))
        if blank and para >= 0:
            out.append(Block(para, k, "text", "\n".join(lines[para:k])))
            para = -1
        elif not blank and para < 0:
            para = k
        k += 1
    if para >= 0:
        out.append(Block(para, len(lines), "text", "\n".join(lines[para:])))
    return out


def block_end(blocks: list[Block], starts: list[int], line: int) -> int:
    """The (0-based, exclusive) end of the block holding 0-based ``line``; ``line + 1`` between blocks.
    ``blocks`` are in order and do not overlap (as both readers above make them); ``starts`` their starts."""
    k = bisect_right(starts, line) - 1
    return blocks[k].end if k >= 0 and line < blocks[k].end else line + 1
