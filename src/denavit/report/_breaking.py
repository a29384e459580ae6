"""Long display formulas broken over lines, as a textbook does (issue 31).

A formula whose estimated width passes :data:`LINE_EM` is written as an ``aligned`` block: a sum is broken
before a ``+`` or ``−`` (at brace depth 0; inside brackets too, whose ``\\left( … \\right)`` become
``\\bigl( … \\bigr)`` so that a line may end inside them), each continuation line indented by ``\\quad`` under the
first; a matrix too wide for a line is written entry by entry (``[T]_{12} = …``, or ``m_{12} = …`` when the left
side is a matrix of names), each entry broken the same way.  Short formulas are left as they were.

The width estimate (:func:`width_em`) counts KaTeX's display-style glyph widths roughly (letters 0.55 em,
operators with their spacing 1.2 em, sub/superscripts at 70 %, fractions as their wider part); measured on the
Puma 560's report in Chromium it is within 5 % of the typeset width at 19 px per em.  The report's column is
960 px (60rem), 50 em: :data:`LINE_EM` = 40 em leaves room for the error of the estimate.
"""

from __future__ import annotations

import re

__all__ = ["LINE_EM", "width_em", "break_display"]

#: Widest line, in em of KaTeX's display style (the HTML report's column holds about 50).
LINE_EM = 40.0

_CMD_EM = {"cos": 1.6, "sin": 1.3, "tan": 1.5, "cdot": 0.78, "quad": 1.0, "qquad": 2.0, "approx": 1.3,
           "sqrt": 0.9, "dot": 0.0, "ddot": 0.0, "mathcal": 0.0, "mathbf": 0.0, "left": 0.0, "right": 0.0,
           "bigl": 0.0, "bigr": 0.0, ",": 0.17, ";": 0.28, "!": -0.17, "\\": 0.0}


def _group(s: str, i: int) -> tuple[str, int]:
    """The ``{…}`` group, command or character at ``s[i]``, and the index after it."""
    if i < len(s) and s[i] == "{":
        depth = 0
        for j in range(i, len(s)):
            depth += (s[j] == "{") - (s[j] == "}")
            if depth == 0:
                return s[i + 1:j], j + 1
        return s[i + 1:], len(s)
    m = re.match(r"\\(?:[A-Za-z]+|.)", s[i:])
    if m:
        return m.group(0), i + len(m.group(0))
    return s[i:i + 1], i + 1


def width_em(s: str) -> float:
    """Estimated width of the LaTeX ``s`` typeset by KaTeX in display style [em] (see the module notes)."""
    w, i = 0.0, 0
    while i < len(s):
        ch = s[i]
        if ch in "_^":
            g, i = _group(s, i + 1)
            w += 0.7 * width_em(g)
        elif ch == "\\":
            m = re.match(r"\\([A-Za-z]+|.)", s[i:])
            name, i = m.group(1), i + len(m.group(0))
            if name == "frac":
                a, i = _group(s, i)
                b, i = _group(s, i)
                w += max(width_em(a), width_em(b)) + 0.2
            elif name in ("text", "mathrm", "operatorname"):
                g, i = _group(s, i)
                w += 0.5 * len(g) if name == "text" else width_em(g)
            elif name == "def":  # \def\name{…}: no output
                i = _group(s, _group(s, i)[1])[1]
            else:
                w += _CMD_EM.get(name, 0.6)
        else:
            w += 0 if ch in "{} &" else 1.2 if ch in "+-=<>" else 0.3 if ch in "()[],.|" else 0.55
            i += 1
    return w


def _pieces(rhs: str) -> list[str]:
    """``rhs`` cut before each ``+``/``-`` at brace depth 0 (not the leading sign), brackets made breakable."""
    rhs = re.sub(r"\\left(\(|\[|\\\{|\|)", r"\\bigl\1", rhs)
    rhs = re.sub(r"\\right(\)|\]|\\\}|\|)", r"\\bigr\1", rhs)
    cuts, depth = [0], 0
    for k, ch in enumerate(rhs):
        depth += (ch == "{") - (ch == "}")
        if depth == 0 and k > 0 and rhs.startswith((" + ", " - "), k) and rhs[:k].strip():
            cuts.append(k + 1)
    return [rhs[a:b].strip() for a, b in zip(cuts, cuts[1:] + [len(rhs)])]


def _lines(label: str, relation: str, rhs: str, budget: float) -> list[str]:
    """Aligned rows ``label &relation …`` / ``&\\quad + …`` of at most ``budget`` em where the terms allow."""
    head = f"{label} &{relation} "
    rows, current = [], head
    for piece in _pieces(rhs):
        if current not in (head, "&\\quad ") and width_em(current + " " + piece) > budget:
            rows.append(current.rstrip())
            current = "&\\quad "
        current += ("" if current in (head, "&\\quad ") else " ") + piece
    rows.append(current.rstrip())
    return rows


def _entries(text: str) -> list[list[str]] | None:
    """The entries of ``text`` when it is one ``\\begin{bmatrix}…\\end{bmatrix}`` (no environment inside),
    rows of equal length; else None."""
    m = re.fullmatch(r"\s*\\begin\{bmatrix\}(.*)\\end\{bmatrix\}\s*", text, re.S)
    if m is None or "\\begin{" in m.group(1):
        return None
    rows = [[c.strip() for c in row.split("&")] for row in m.group(1).split("\\\\")]
    return rows if all(len(r) == len(rows[0]) for r in rows) else None


def break_display(lhs: str, relation: str, rhs, note: str = "", latex=None) -> str | None:
    """``lhs relation rhs`` as an ``aligned`` block when one line would be wider than :data:`LINE_EM`, else None.

    ``rhs`` is a LaTeX string or a sympy expression/matrix (``latex`` prints one); ``note`` is LaTeX set after
    the formula (on its own row when the formula is broken).
    """
    text = rhs if isinstance(rhs, str) else latex(rhs)
    if width_em(f"{lhs} {relation} {text} {note}") <= LINE_EM:
        return None
    if hasattr(rhs, "shape") and len(rhs.shape) == 2:
        entries = [[latex(rhs[i, j]) for j in range(rhs.shape[1])] for i in range(rhs.shape[0])]
    else:
        entries = _entries(text)
    if entries is not None and (len(entries), len(entries[0])) != (1, 1):
        n, m = len(entries), len(entries[0])
        names = _entries(lhs)
        names = names if names and (len(names), len(names[0])) == (n, m) else None
        rows: list[str] = []
        for i in range(n):
            for j in range(m):
                label = names[i][j] if names else f"\\left[{lhs}\\right]_{{{i + 1}{j + 1 if m > 1 else ''}}}"
                rows += _lines(label, relation, entries[i][j], LINE_EM)
    elif "\\begin{" in text:
        return None  # another typeset structure given as text: not broken
    else:
        rows = _lines(lhs, relation, text, LINE_EM)
    if note:
        rows.append(f"&{note}")
    return "\\begin{aligned}" + " \\\\ ".join(rows) + "\\end{aligned}"
