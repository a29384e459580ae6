"""The tokens of mathematics written by people (LaTeX or plain text): the first stage of :mod:`._latex`.

Names as written (:class:`Ident`), the resolver type, the caps on input length, digits and tokens, and the
tokenizer itself (one regular expression, linear time).
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from typing import Callable

from ..errors import ParseError

__all__ = ["Ident", "Resolver", "tokenize", "normalize", "GREEK", "FUNCS", "WRAP_CMDS", "MAX_CHARS", "MAX_DEPTH",
           "MAX_TOKENS", "MAX_TREE_DEPTH", "MAX_DIGITS"]

MAX_CHARS = 20_000
MAX_DEPTH = 40
MAX_TOKENS = 6_000
#: Longest chain of operators in one expression (``1+1+…+1`` with more terms is refused): the trees are walked
#: recursively, so this keeps every walker far from Python's recursion limit.
MAX_TREE_DEPTH = 400
#: Most digits in one number or subscript (a double has about 17 significant digits and overflows past 309).
MAX_DIGITS = 40

GREEK = ("alpha", "beta", "gamma", "delta", "epsilon", "varepsilon", "zeta", "eta", "theta", "vartheta", "iota",
         "kappa", "lambda", "mu", "nu", "xi", "rho", "sigma", "tau", "phi", "varphi", "chi", "psi", "omega", "ell")
_UNICODE = {"θ": r"\theta ", "α": r"\alpha ", "β": r"\beta ", "π": r"\pi ", "φ": r"\phi ", "ψ": r"\psi ",
            "ω": r"\omega ", "σ": r"\sigma ", "τ": r"\tau ", "·": r"\cdot ", "×": r"\times ", "−": "-", "–": "-", "√": r"\sqrt ",
            "²": "^2", "³": "^3", "ϑ": r"\vartheta ", "°": r"\degree "}
FUNCS = {"sin": "sin", "cos": "cos", "tan": "tan", "arcsin": "asin", "arccos": "acos", "arctan": "atan",
         "asin": "asin", "acos": "acos", "atan": "atan", "atan2": "atan2", "arctan2": "atan2", "sqrt": "sqrt",
         "exp": "exp", "ln": "log", "log": "log", "abs": "abs"}
_SKIP_CMDS = {"left", "right", "big", "Big", "bigg", "Bigg", "bigl", "bigr", "Bigl", "Bigr", "quad", "qquad",
              "displaystyle", "textstyle", "limits", "nonumber"}
WRAP_CMDS = {"mathrm", "text", "mathit", "mathbf", "boldsymbol", "bm", "mathsf", "operatorname", "textrm", "rm"}
_TOKEN = re.compile(
    r"(?P<ws>\s+|\\[,;:! ]|~)"
    r"|(?P<num>(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?)"  # 1e3, 2.5E-4: a number, never 1·e3
    r"|(?P<cmd>\\[A-Za-z]+)"
    r"|(?P<word>[A-Za-z]+[0-9]*)"
    r"|(?P<op>\*\*|[-+*/^_(){}\[\],=|&']|\\\\|\\\{|\\\})"
)


@dataclass(frozen=True)
class Ident:
    """A name as written: ``base`` (``"theta"``, ``"L"``, ``"C"``), ``sub`` (subscript text, e.g. ``"12"``),
    ``sub_tree`` (the subscript read as an expression, when it is one), ``dots`` (0, 1 or 2 time dots)."""

    base: str
    sub: str = ""
    sub_tree: tuple | None = None
    dots: int = 0

    @property
    def plain(self) -> str:
        """``L_1`` → ``"L1"``, ``Lc_{2}`` → ``"Lc2"``."""
        return self.base + re.sub(r"[^A-Za-z0-9]", "", self.sub)


Resolver = Callable[[Ident], tuple]


_JOINT_SPACE = re.compile(r"(\\(?:var)?theta|\\dot\{?\\theta\}?|\\ddot\{?\\theta\}?)\s+(\d)(?![\d.])"
                          r"|(\\d?dot\{\\theta)(?:\}\s*(\d)(?![\d.])|\s*(\d)\})")  # \dot{\theta}2, \dot{\theta 2}
_OF_TIME = re.compile(r"(?<=[A-Za-z0-9}])\s*\(\s*t\s*\)")


def _joint_subscript(m: re.Match) -> str:
    if m.group(1):
        return f"{m.group(1)}_{{{m.group(2)}}}"
    return f"{m.group(3)}}}_{{{m.group(4) or m.group(5)}}}"


def normalize(text: str) -> str:
    """Unicode letters and operators spelled as LaTeX, ``\\theta 2`` → ``\\theta_{2}``, ``(t)`` dropped."""
    text = re.sub(r"\\operatorname\{atan\}_\{?2\}?", r"\\operatorname{atan2}", text)  # sympy's atan2
    text = re.sub(r"([θαβφψωτϑσ])(\d+)", lambda m: _UNICODE[m.group(1)].strip() + "_{" + m.group(2) + "}", text)
    for k, v in _UNICODE.items():
        text = text.replace(k, v)
    text = _JOINT_SPACE.sub(_joint_subscript, text)  # \\theta 2 → \\theta_{2}
    return _OF_TIME.sub("", text)  # \\theta_1(t) → \\theta_1


def tokenize(text: str) -> list[tuple[str, str]]:
    """The tokens ``(kind, text)`` of a formula (kinds num, cmd, word, op), spacing commands dropped; capped."""
    if len(text) > MAX_CHARS:
        raise ParseError(f"expression longer than {MAX_CHARS} characters")
    text = normalize(text)
    out: list[tuple[str, str]] = []
    pos = 0
    while pos < len(text):
        m = _TOKEN.match(text, pos)
        if not m:
            raise ParseError(f"unexpected character {text[pos]!r} at position {pos + 1}")
        pos = m.end()
        kind = m.lastgroup or "op"
        if kind == "ws":
            continue
        tok = m.group(kind)
        if kind == "num" and len(tok) > MAX_DIGITS:
            raise ParseError(f"number with more than {MAX_DIGITS} digits at position {m.start() + 1}")
        if kind == "num" and text.startswith(".", pos):
            raise ParseError(f"malformed number {text[m.start():pos + 1]!r} at position {m.start() + 1}")
        if kind == "word" and len(tok) > MAX_DIGITS:
            raise ParseError(f"name longer than {MAX_DIGITS} characters at position {m.start() + 1}")
        if kind == "cmd" and tok[1:] in _SKIP_CMDS:
            continue
        out.append((kind, tok))
        if len(out) > MAX_TOKENS:
            raise ParseError(f"expression has more than {MAX_TOKENS} tokens")
    return out
