"""A left-hand side as students write it, taken apart: accents, left and right scripts, base, arguments.

``{}^{0}T_{1}``, ``^{0}_{1}T``, ``T_0^1``, ``\\dot{p}_{c3}``, ``J_{\\vartheta_2}^T``, ``M(\\theta)``, ``\\det(J)``:
each becomes a :class:`Symbol` (base ``T``, left superscript ``0``, right subscript ``1`` …).  Pure string work,
linear in the length; nothing is evaluated.
"""

from __future__ import annotations

import re
from dataclasses import dataclass

__all__ = ["Symbol", "read_symbol", "frame_token", "MAX_LHS"]

#: Longest left-hand side taken apart (characters); a longer one is no name.
MAX_LHS = 160

_STYLE = re.compile(r"\\(?:mathbf|boldsymbol|bm|hat|mathrm|mathit|mathsf|mathcal|vec|mathbb|operatorname|text|textbf)"
                    r"\s*(?=\{)")
_SPACES = re.compile(r"\\(?:left|right|,|;|!|:|quad|qquad|big|Big|bigl|bigr)(?![A-Za-z])|\s+")


@dataclass(frozen=True)
class Symbol:
    base: str
    pre_sup: str = ""
    pre_sub: str = ""
    sub: str = ""
    sup: str = ""
    dots: int = 0
    args: str = ""
    transpose: bool = False
    det: bool = False


def _group(s: str, k: int) -> tuple[str, int] | None:
    """The script argument starting at ``k``: ``{…}`` (balanced), a command ``\\alpha`` or one character."""
    if k >= len(s):
        return None
    if s[k] == "{":
        depth = 0
        for j in range(k, len(s)):
            depth += {"{": 1, "}": -1}.get(s[j], 0)
            if depth == 0:
                return s[k + 1:j], j + 1
        return None
    m = re.match(r"\\[A-Za-z]+|[^\\{}^_]", s[k:])
    return (m.group(0), k + m.end()) if m else None


def _unbrace(s: str) -> str:
    """``\\mathbf{J}_v`` → ``J_v``: style wrappers removed with their braces (balanced), a bounded number."""
    for _ in range(20):
        m = _STYLE.search(s)
        if not m:
            break
        g = _group(s, m.end())
        if g is None:
            break
        s = s[:m.start()] + g[0] + s[g[1]:]
    return s


def _scripts(s: str, k: int) -> tuple[str, str, int]:
    """Subscript and superscript following position ``k`` (either order, each once)."""
    sub = sup = ""
    for _ in range(2):
        if k < len(s) and s[k] in "_^":
            g = _group(s, k + 1)
            if g is None:
                break
            if s[k] == "_" and not sub:
                sub = g[0]
            elif s[k] == "^" and not sup:
                sup = g[0]
            else:
                break
            k = g[1]
    return sub, sup, k


def read_symbol(lhs: str) -> Symbol | None:
    """The parts of a left-hand side, or None when it is not a single (decorated) name."""
    s = _SPACES.sub("", _unbrace(lhs.strip()))
    if not s or len(s) > MAX_LHS:
        return None
    s = re.sub(r"^(?:\\Rightarrow|\\therefore|\\implies)", "", s)
    det = False
    m = re.match(r"^(?:\\det|\|)", s)
    if m:
        det, s = True, s[m.end():]
        if s.startswith("(") and s.endswith(")"):
            s = s[1:-1]
        elif s.endswith("|"):
            s = s[:-1]
    s = s.replace("{}", "")
    dots = 0
    m = re.match(r"^\\(dot|ddot)\s*", s)
    if m:
        dots = 1 if m.group(1) == "dot" else 2
        s = s[m.end():]
        g = _group(s, 0)
        if g is not None and s.startswith("{"):
            s = g[0] + s[g[1]:]
    m = re.fullmatch(r"(theta|q|d|tau|omega)(\d{1,2})", s)
    if m:  # plain text: theta1, q2, d3, tau1
        return Symbol(m.group(1), sub=m.group(2))
    m = re.fullmatch(r"([TAR])(\d)(\d?)", s)
    if m:  # T01, T12, A1
        return Symbol(m.group(1), sub=m.group(2), sup=m.group(3))
    pre_sub, pre_sup, k = _scripts(s, 0)
    m = re.match(r"\\[A-Za-z]+|[A-Za-z]", s[k:])
    if not m:
        return None
    base = m.group(0).lstrip("\\")
    k += m.end()
    sub, sup, k = _scripts(s, k)
    transpose = sup in ("T", "\\top", "\\intercal") or s[k:k + 2] in ("^T",)
    if s[k:k + 2] == "^T" or s[k:k + 3] == "^{T":
        transpose = True
        k = s.find("}", k) + 1 if s[k + 1] == "{" else k + 2
    if transpose and sup in ("T", "\\top", "\\intercal"):
        sup = ""
    rest = s[k:]
    args = ""
    if rest.startswith("(") and rest.endswith(")"):
        args, rest = rest[1:-1], ""
    if rest:
        return None
    return Symbol(base, pre_sup, pre_sub, sub, sup, dots, args, transpose, det)


def frame_token(tok: str) -> int | str | None:
    """A frame written in a script: its number, ``"base"``, ``"ee"``, or a symbolic index such as ``"i-1"``."""
    t = re.sub(r"\s+|[{}]", "", tok)
    if t.isdigit() and len(t) <= 3:
        return int(t)
    if t in ("B", "b", "W", "w", "base", "world"):
        return "base"
    if t in ("E", "e", "EE", "ee", "tool", "H", "h"):
        return "ee"
    if re.fullmatch(r"[ijkn](?:[+-]1)?", t):
        return t
    return None
