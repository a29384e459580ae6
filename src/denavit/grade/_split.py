"""A block of mathematics into the equations it states.

Rows of ``aligned``/``align``/``split`` environments (a row starting with ``=``, ``+`` or ``-`` continues the one
before), ``⇒`` chains (``\\Rightarrow``, ``\\implies``, ``\\to``), several equations on one line separated by
``\\quad`` or by a comma between two equations, and a chain ``A = B = C`` kept as its parts.  Scanning is linear
in the text and never looks inside ``{…}`` or a matrix environment when splitting.
"""

from __future__ import annotations

import re
from dataclasses import dataclass

from ..check import bracket_depths

__all__ = ["Equation", "split_block", "top_level_split", "clean"]

_WRAP_ENV = re.compile(r"\\(begin|end)\{(aligned|align|split|gather|gathered|equation|multline|eqnarray|flalign|"
                       r"alignat|displaymath|array)\*?\}(\{[^{}]{0,40}\})?")
_MATRIX_ENV = re.compile(r"\\(begin|end)\{(?:[bBpvV]?matrix|smallmatrix|cases|array)\*?\}")
_ARROWS = ("\\Longrightarrow", "\\Rightarrow", "\\implies", "\\rightarrow", "\\longrightarrow", "⇒", "=>", "\\to ",
           "\\therefore", "\\Leftrightarrow", "\\iff")
_TEXT = re.compile(r"\\(?:text|textrm|mathrm|mbox|textbf|textit)\s*\{([^{}]{0,200})\}")
_EQNUM = re.compile(r"(?:\\q?quad\s*)?\(\s*\d{1,4}[a-z]?\s*\)\s*$|\\tag\*?\{[^{}]{0,40}\}")


@dataclass(frozen=True)
class Equation:
    """One stated equation: its parts (split at top-level ``=``), the relation (``=``, ``\\neq``, …), lines."""

    line: int
    end_line: int
    text: str
    parts: tuple[str, ...]
    relation: str


def _levels(text: str):
    """Yield (index, depth) for every character, depth counting braces, brackets and matrix environments."""
    return bracket_depths(text, _MATRIX_ENV, clamp=True)


def top_level_split(text: str, seps: tuple[str, ...]) -> list[str]:
    """``text`` split at each separator outside brackets, braces and matrix environments."""
    out, start, skip_to = [], 0, -1
    for k, depth in _levels(text):
        if k < skip_to or depth:
            continue
        for s in seps:
            if text.startswith(s, k) and not (s[1:2].isalpha() and text[k + len(s):k + len(s) + 1].isalpha()):
                out.append(text[start:k])
                start = skip_to = k + len(s)
                break
    out.append(text[start:])
    return out


def clean(text: str) -> str:
    """Alignment marks, equation numbers and spacing dropped; the mathematics kept."""
    text = re.sub(r"=\s+>", lambda _: " \\Rightarrow ", text)
    t = "".join(" " if text[k] == "&" and d == 0 else text[k] for k, d in _levels(text))
    t = re.sub(r"\\label\{[^{}]{0,200}\}", " ", t)
    t = re.sub(r"\\(?:nonumber|notag|displaystyle|qquad|quad)(?![A-Za-z])|\\[,;!:]|(?<!\\)\\ ", " ", t)
    t = _EQNUM.sub(" ", t.strip())
    return re.sub(r"\s+", " ", t).strip().strip(",.;").strip()


def _rows(body: str) -> list[tuple[int, str]]:
    """(line offset, text) of each row of an aligned environment (top-level ``\\\\``), continuations joined."""
    rows: list[tuple[int, str]] = []
    offset, start = 0, 0
    for piece in top_level_split(body, ("\\\\",)):
        lead = len(piece) - len(piece.lstrip())
        line_off = body.count("\n", 0, start + lead)
        start += len(piece) + 2
        t = re.sub(r"^\s*(\[[^\]]{0,20}\])?", "", piece)  # \\[2pt] spacing
        s = t.replace("&", " ").replace("\\quad", " ").replace("\\qquad", " ").strip()
        if not s or s.startswith("\\hline"):
            continue
        if rows and (s[0] in "+-=" or s.startswith("\\cdot") or s.startswith("\\times") or "=" not in s
                     and not any(a in s for a in _ARROWS)):
            rows[-1] = (rows[-1][0], rows[-1][1] + " " + t)
        else:
            rows.append((line_off, t))
        offset = line_off
    del offset
    return rows


def _unwrap(latex: str) -> str:
    return _WRAP_ENV.sub(" ", latex)


def _pieces(row: str) -> list[str]:
    """A row split at arrows, at ``\\quad`` between equations and at a comma between equations."""
    row = re.sub(r"=\s+>", lambda _: " \\Rightarrow ", row)
    row = re.sub(r"\\[,;:!]", " ", row)  # thin spaces, before the comma split
    row = _TEXT.sub(lambda m: " \\Rightarrow " if m.group(1).strip().lower() in ("or", "and", "or when", "and when")
                    else " ", row)
    out: list[str] = []
    subject = ""
    for piece in top_level_split(row, _ARROWS):
        if subject and re.match(r"\s*\\begin\{[pbB]?matrix\}", piece) and "=" in piece:
            piece = subject + " = " + piece  # "T(1:3,4) = {x_c, …} → [⋯] = [P_x …]": the matrix is T(1:3,4)'s value
        first = top_level_split(piece, ("=",))[0]
        subject = first.strip() if "=" in piece and "\\begin" not in first else ""
        sub = top_level_split(piece, ("\\qquad", "\\quad"))
        merged = _merge(sub, " ")
        for m in merged:
            out += _merge(top_level_split(m, (",", ";")), ", ")
    return [p for p in out if p.strip()]


def _merge(parts: list[str], joiner: str) -> list[str]:
    """Keep a split only between two pieces that are each an equation; otherwise join them back."""
    out: list[str] = []
    for p in parts:
        if out and not ("=" in p and "=" in out[-1]):
            out[-1] = out[-1] + joiner + p
        else:
            out.append(p)
    return out


def split_block(latex: str, line: int, end_line: int) -> list[Equation]:
    """The equations of one block of mathematics (lines ``line``…``end_line`` of the report)."""
    aligned = bool(re.search(r"\\begin\{(aligned|align|split|gather|gathered|eqnarray|flalign|alignat)\*?\}",
                             latex))
    body = _unwrap(latex)
    rows = _rows(body) if aligned or "\\\\" in _top_only(body) else [(0, body)]
    eqs = []
    for off, row in rows:
        first = min(line + off, end_line)
        for piece in _pieces(row):
            t = clean(piece)
            if not t:
                continue
            rel = "neq" if re.search(r"\\neq?(?![A-Za-z])|≠", t) and "=" not in t.replace("\\neq", "") else "="
            parts = tuple(p.strip() for p in top_level_split(t, ("=",)))
            n_lines = piece.strip().count("\n")
            eqs.append(Equation(first, min(first + n_lines, end_line) if len(rows) > 1 else end_line, t, parts, rel))
    return eqs


def _top_only(text: str) -> str:
    """The characters of ``text`` at depth 0 (to see whether ``\\\\`` separates rows at the top level)."""
    return "".join(text[k] for k, d in _levels(text) if d == 0)
