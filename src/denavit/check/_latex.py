"""A restricted reader for mathematics written by people: LaTeX or plain text, into :mod:`denavit._expr` trees.

Claims files and pasted tables are untrusted.  This module reads them with a hand-written tokenizer and a
recursive-descent parser; nothing reaches ``eval``, ``exec``, ``sympify`` or ``parse_expr``.  Its output
is the same tiny tree as :mod:`denavit._expr` (``("num", "0.5")``, ``("name", "q1")``, ``("bin", "+", a, b)``
...), so evaluation and conversion to sympy reuse that module.

Accepted: numbers, decimals and powers of ten (``1e3``, ``2.5E-4``), ``+ - * / ^``, ``\\cdot``, ``\\times``, implicit multiplication
(``2 L_1 \\cos\\theta_1``), parentheses ``( ) [ ] { } \\left( \\right)``, ``\\frac{a}{b}``, ``\\sqrt{x}``,
``\\sin \\cos \\tan \\arctan \\operatorname{atan2}``, ``\\sin^2 x``, ``\\pi``, Greek letters, subscripts
(``\\theta_1``, ``L_{1}``, ``a_{i-1}``), dots (``\\dot\\theta_1``), shorthand ``C_1``, ``S_{12}``, ``c_{123}``,
``C_{\\theta_1}``, and matrices ``\\begin{bmatrix} … & … \\\\ … \\end{bmatrix}`` (also pmatrix, Bmatrix, matrix).
Names are resolved by a caller-supplied function, which decides what ``L_1`` or ``\\theta_2`` means.
Input length and nesting are capped.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from typing import Callable

from .. import _expr
from ..errors import ParseError

__all__ = ["Ident", "RaggedMatrix", "tokenize", "parse_math", "parse_matrix", "split_matrix", "MAX_CHARS", "MAX_DEPTH", "MAX_TREE_DEPTH",
           "MAX_DIGITS", "Resolver"]

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
_WRAP_CMDS = {"mathrm", "text", "mathit", "mathbf", "boldsymbol", "bm", "mathsf", "operatorname", "textrm", "rm"}
_TOKEN = re.compile(
    r"(?P<ws>\s+|\\[,;:! ]|~)"
    r"|(?P<num>(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?)"  # 1e3, 2.5E-4: a number, never 1·e3
    r"|(?P<cmd>\\[A-Za-z]+)"
    r"|(?P<word>[A-Za-z]+[0-9]*)"
    r"|(?P<op>\*\*|[-+*/^_(){}\[\],=|&']|\\\\|\\\{|\\\})"
)


class RaggedMatrix(ParseError):
    """A matrix whose rows have different lengths (for a claim: a value of the wrong shape, not unreadable)."""


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


_JOINT_SPACE = re.compile(r"(\\(?:var)?theta|\\dot\{?\\theta\}?|\\ddot\{?\\theta\}?)\s+(\d)(?![\d.])")
_OF_TIME = re.compile(r"(?<=[A-Za-z0-9}])\s*\(\s*t\s*\)")


def _normalize(text: str) -> str:
    text = re.sub(r"\\operatorname\{atan\}_\{?2\}?", r"\\operatorname{atan2}", text)  # sympy's atan2
    text = re.sub(r"([θαβφψωτϑσ])(\d+)", lambda m: _UNICODE[m.group(1)].strip() + "_{" + m.group(2) + "}", text)
    for k, v in _UNICODE.items():
        text = text.replace(k, v)
    text = _JOINT_SPACE.sub(lambda m: f"{m.group(1)}_{{{m.group(2)}}}", text)  # \\theta 2 → \\theta_{2}
    return _OF_TIME.sub("", text)  # \\theta_1(t) → \\theta_1


def tokenize(text: str) -> list[tuple[str, str]]:
    """The tokens ``(kind, text)`` of a formula (kinds num, cmd, word, op), spacing commands dropped; capped."""
    return _tokens(text)


def _tokens(text: str) -> list[tuple[str, str]]:
    if len(text) > MAX_CHARS:
        raise ParseError(f"expression longer than {MAX_CHARS} characters")
    text = _normalize(text)
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


_OPEN = {"(": ")", "[": "]", "{": "}", "\\{": "\\}"}


class _Parser:
    def __init__(self, text: str, resolve: Resolver) -> None:
        self.text = text
        self.toks = _tokens(text)
        self.i = 0
        self.depth = 0
        self.resolve = resolve

    # --- helpers ---------------------------------------------------------------------------------
    def peek(self, k: int = 0) -> tuple[str, str] | None:
        j = self.i + k
        return self.toks[j] if j < len(self.toks) else None

    def take(self, text: str | None = None) -> tuple[str, str]:
        tok = self.peek()
        if tok is None:
            raise ParseError(f"unexpected end of expression{f' (expected {text!r})' if text else ''}")
        if text is not None and tok[1] != text:
            raise ParseError(f"expected {text!r} but found {tok[1]!r}")
        self.i += 1
        return tok

    def enter(self) -> None:
        self.depth += 1
        if self.depth > MAX_DEPTH:
            raise ParseError(f"expression nested too deeply (more than {MAX_DEPTH} levels)")

    def group_text(self) -> str:
        """The raw tokens of a ``{...}`` group (or one token) joined, for subscripts and \\text."""
        tok = self.take()
        if tok[1] != "{":
            return tok[1]
        parts, level = [], 1
        while True:
            t = self.take()
            if t[1] == "{":
                level += 1
            elif t[1] == "}":
                level -= 1
                if level == 0:
                    return " ".join(parts)
            parts.append(t[1])

    # --- grammar ---------------------------------------------------------------------------------
    def expr(self) -> tuple:
        self.enter()
        node = self.term()
        while (t := self.peek()) is not None and t[1] in ("+", "-"):
            self.take()
            node = ("bin", t[1], node, self.term())
        self.depth -= 1
        return node

    def _starts_atom(self, t: tuple[str, str] | None) -> bool:
        if t is None:
            return False
        kind, s = t
        return kind in ("num", "word") or (kind == "cmd" and s not in ("\\cdot", "\\times")) or s in ("(", "[", "{", "\\{")

    def term(self) -> tuple:
        node = self.unary()
        while True:
            t = self.peek()
            if t is not None and t[1] in ("*", "/", "\\cdot", "\\times"):
                self.take()
                op = "/" if t[1] == "/" else "*"
                node = ("bin", op, node, self.unary())
            elif self._starts_atom(t):
                node = ("bin", "*", node, self.power())
            else:
                return node

    def unary(self) -> tuple:
        t = self.peek()
        if t is not None and t[1] in ("+", "-"):
            self.take()
            self.enter()
            inner = self.unary()
            self.depth -= 1
            return ("neg", inner) if t[1] == "-" else inner
        return self.power()

    def power(self) -> tuple:
        base = self.atom()
        while (t := self.peek()) is not None and t[1] in ("^", "**", "\\degree"):
            self.take()
            if t[1] == "\\degree":  # 30° (a degree sign: the value in radians)
                base = ("call", "deg", (base,))
                continue
            nxt, nxt2 = self.peek(), self.peek(1)
            if nxt is not None and nxt[1] == "\\circ":  # 30^\circ
                self.take()
                base = ("call", "deg", (base,))
            elif nxt is not None and nxt[1] == "{" and nxt2 is not None and nxt2[1] == "\\circ":  # 30^{\circ}
                self.take()
                self.take()
                self.take("}")
                base = ("call", "deg", (base,))
            else:
                base = ("bin", "^", base, self.exponent())
        if (t := self.peek()) is not None and t[1] == "'":
            raise ParseError("primes (') are not supported; write derivatives with \\dot")
        return base

    def exponent(self) -> tuple:
        t = self.peek()
        if t is not None and t[1] == "{":
            self.take()
            node = self.expr()
            self.take("}")
            return node
        if t is not None and t[1] == "-":
            self.take()
            return ("neg", self.atom())
        if t is not None and t[0] == "num" and len(t[1]) > 1 and "." not in t[1]:
            self.take()  # x^23 in LaTeX means x^2 · 3; refuse rather than guess
            raise ParseError(f"ambiguous exponent ^{t[1]}; write ^{{{t[1]}}}")
        return self.atom()

    def atom(self) -> tuple:
        self.enter()
        try:
            return self._atom()
        finally:
            self.depth -= 1

    def _atom(self) -> tuple:
        kind, s = self.take()
        if kind == "num":
            return ("num", s)
        if s in _OPEN:
            inner = self.expr()
            self.take(_OPEN[s])
            return inner
        if s == "|":
            inner = self.expr()
            self.take("|")
            return ("call", "abs", (inner,))
        if kind == "cmd":
            return self.command(s[1:])
        if kind == "word":
            return self.word(s)
        raise ParseError(f"unexpected {s!r}")

    def command(self, name: str) -> tuple:
        if name in ("frac", "dfrac", "tfrac"):
            num = self.braced()
            den = self.braced()
            return ("bin", "/", num, den)
        if name == "sqrt":
            t = self.peek()
            if t is not None and t[1] == "[":
                raise ParseError("only square roots \\sqrt{x} are supported")
            return ("call", "sqrt", (self.braced_or_atom(),))
        if name == "pi":
            return ("name", "pi")
        if name == "degree":
            raise ParseError("a degree sign is not allowed here")
        if name in ("dot", "ddot"):
            inner = self.braced_or_ident()
            return self.resolve_ident(Ident(inner.base, inner.sub, inner.sub_tree, 1 if name == "dot" else 2),
                                      allow_sub=True)
        if name in _WRAP_CMDS:
            word = self.group_text().replace(" ", "")
            if word in FUNCS:
                return self.function(FUNCS[word])
            return self.finish_ident(word)
        if name in FUNCS:
            return self.function(FUNCS[name])
        if name in GREEK:
            return self.finish_ident(name)
        raise ParseError(f"unsupported LaTeX command \\{name}")

    def braced(self) -> tuple:
        t = self.peek()
        if t is None or t[1] != "{":
            return self.atom()  # \frac12 style
        self.take("{")
        node = self.expr()
        self.take("}")
        return node

    def braced_or_atom(self) -> tuple:
        t = self.peek()
        return self.braced() if t is not None and t[1] == "{" else self.atom()

    def braced_or_ident(self) -> Ident:
        t = self.take()
        if t[1] == "{":
            inner = self.take()
            name = inner[1][1:] if inner[0] == "cmd" else inner[1]
            ident = self.read_sub(name)
            self.take("}")
        else:
            ident = self.read_sub(t[1][1:] if t[0] == "cmd" else t[1])
        nxt = self.peek()
        if not ident.sub and nxt is not None and nxt[1] == "_":
            ident = self.read_sub(ident.base)
        return ident

    def function(self, fname: str) -> tuple:
        power = None
        t = self.peek()
        if t is not None and t[1] == "^":  # \sin^2 x
            self.take()
            power = self.exponent()
        t = self.peek()
        nxt = self.peek(1)
        wrapped = t is not None and t[1] == "{" and nxt is not None and nxt[1] in ("(", "[")  # f{\left(a, b\right)}
        if wrapped:
            self.take("{")
            t = self.peek()
        if t is not None and t[1] in ("(", "[", "{"):
            self.take()
            args = [self.expr()]
            while (c := self.peek()) is not None and c[1] == ",":
                self.take()
                args.append(self.expr())
            self.take(_OPEN[t[1]])
            if wrapped:
                self.take("}")
        else:
            args = [self.power_free_atom()]
        if fname == "atan" and len(args) == 2:  # \\arctan(y, x): the two-argument arctangent
            fname = "atan2"
        want = _expr.FUNCTIONS[fname]
        if len(args) != want:
            raise ParseError(f"{fname} takes {want} argument(s), got {len(args)}")
        node = ("call", fname, tuple(args))
        return ("bin", "^", node, power) if power is not None else node

    def power_free_atom(self) -> tuple:
        """Argument of ``\\cos \\theta_1`` written without parentheses: a number times one name at most."""
        node = self.atom()
        t = self.peek()
        if node[0] == "num" and t is not None and (t[0] in ("word",) or (t[0] == "cmd" and t[1][1:] in GREEK)):
            node = ("bin", "*", node, self.atom())
        return node

    def read_sub(self, base: str) -> Ident:
        t = self.peek()
        if t is None or t[1] != "_":
            return Ident(base)
        self.take()
        start = self.i
        sub = self.group_text()
        tree = None
        try:
            sub_toks = self.toks[start:self.i]
            if sub_toks and sub_toks[0][1] == "{":
                sub_toks = sub_toks[1:-1]
            if sub_toks and not all(k == "num" for k, _ in sub_toks):
                p = _Parser.__new__(_Parser)
                p.text, p.toks, p.i, p.depth, p.resolve = sub, sub_toks, 0, self.depth, self.resolve
                tree = p.expr()
                if p.peek() is not None:
                    tree = None
        except ParseError:
            tree = None
        return Ident(base, sub.replace(" ", ""), tree)

    def finish_ident(self, base: str) -> tuple:
        return self.resolve_ident(self.read_sub(base), allow_sub=True)

    def word(self, word: str) -> tuple:
        if word in FUNCS and (self.peek() is None or self.peek()[1] != "_"):
            return self.function(FUNCS[word])
        if word == "pi":
            return ("name", "pi")
        m = re.match(r"([A-Za-z]+)(\d+)$", word)
        if m and (self.peek() is None or self.peek()[1] != "_"):
            ident = Ident(m.group(1), m.group(2))  # plain text C12, q1, L2
            word = m.group(1)
        else:
            ident = self.read_sub(word)
        try:
            return self.resolve(ident)
        except ParseError:
            if len(word) == 1:
                raise
        # "Lc" might be L·c: split letters, the last one keeps the subscript
        nodes = [self.resolve(Ident(ch)) for ch in word[:-1]]
        nodes.append(self.resolve(Ident(word[-1], ident.sub, ident.sub_tree)))
        out = nodes[0]
        for n in nodes[1:]:
            out = ("bin", "*", out, n)
        return out

    def resolve_ident(self, ident: Ident, allow_sub: bool) -> tuple:
        return self.resolve(ident)


def _strip_rhs(text: str) -> str:
    """``T = [...]`` → ``[...]``: keep what follows the last top-level ``=``."""
    level = 0
    cut = -1
    for k, ch in enumerate(text):
        if ch in "({[":
            level += 1
        elif ch in ")}]":
            level -= 1
        elif ch == "=" and level == 0:
            cut = k
    return text[cut + 1:] if cut >= 0 else text


_EQ_NUMBER = re.compile(r"(?:\\q?quad\s*\(\s*\d{1,6}[a-z]?\s*\)|\\tag\*?\{[^{}]{0,40}\})\s*$")


def strip_equation_number(text: str) -> str:
    """``… \\quad (11)`` or ``… \\tag{11}`` at the end: the report's equation number, not a factor 11."""
    return _EQ_NUMBER.sub("", text.strip().strip("$").strip())


def parse_math(text: str, resolve: Resolver, *, rhs: bool = True) -> tuple:
    """One scalar expression (LaTeX or plain) → an :mod:`denavit._expr` tree."""
    if not isinstance(text, str):
        text = str(text)
    text = strip_equation_number(text).strip()
    if rhs:
        text = _strip_rhs(text)
    if not text.strip():
        raise ParseError("empty expression")
    p = _Parser(text, resolve)
    node = p.expr()
    if p.peek() is not None:
        raise ParseError(f"unexpected {p.peek()[1]!r} after a complete expression in {text[:60]!r}")
    if tree_depth(node) > MAX_TREE_DEPTH:
        raise ParseError(f"expression too long: more than {MAX_TREE_DEPTH} operations in a chain "
                         "(split it, or group terms in parentheses)")
    return node


def tree_depth(node: tuple) -> int:
    """The depth of an expression tree, computed without recursion (so any tree can be measured)."""
    deepest, stack = 0, [(node, 1)]
    while stack:
        nd, d = stack.pop()
        deepest = max(deepest, d)
        kind = nd[0]
        if kind == "neg":
            stack.append((nd[1], d + 1))
        elif kind == "bin":
            stack += [(nd[2], d + 1), (nd[3], d + 1)]
        elif kind == "call":
            stack += [(a, d + 1) for a in nd[2]]
    return deepest


_BEGIN = re.compile(r"\\begin\{([bBpvV]?matrix|array)\}(?:\{[^{}]*\})?")


def split_matrix(text: str) -> list[list[str]] | None:
    """The cells of the (first) LaTeX matrix environment in ``text``, or None if there is none.

    Linear time: the first ``\\begin{…matrix}`` is found by one regex search (no backtracking across the
    text) and its ``\\end`` by a plain substring search; a ``\\begin`` without its ``\\end`` is an error.
    """
    if len(text) > MAX_CHARS:
        raise ParseError(f"expression longer than {MAX_CHARS} characters")
    text = _normalize(text)
    m = _BEGIN.search(text)
    if m is None:
        return None
    end = text.find("\\end{" + m.group(1) + "}", m.end())
    if end < 0:
        raise ParseError(f"\\begin{{{m.group(1)}}} without its \\end{{{m.group(1)}}}")
    body = text[m.end():end]
    rows = [r for r in re.split(r"\\\\(?:\[[^\]]*\])?", body) if r.strip() and not r.strip().startswith("\\hline")]
    return [[c.strip() for c in r.split("&")] for r in rows]


_ENV = re.compile(r"\\(begin|end)\{(?:[bBpvV]?matrix|array|smallmatrix)\*?\}")  # not split/aligned: an = there counts


def after_last_equals(text: str) -> str:
    """What follows the last ``=`` outside brackets and matrix environments (``J = [\\begin…] = \\begin…``)."""
    level, cut, k = 0, -1, 0
    while k < len(text):
        m = _ENV.match(text, k)
        if m:
            level += 1 if m.group(1) == "begin" else -1
            k = m.end()
            continue
        ch = text[k]
        if ch in "({[":
            level += 1
        elif ch in ")}]":
            level -= 1
        elif ch == "=" and level == 0:
            cut = k
        k += 1
    return text[cut + 1:] if cut >= 0 else text


def split_list(text: str) -> list[list[str]] | None:
    """``[a, b, c]`` / ``(a, b, c)`` (a column) or ``[a, b; c, d]`` / ``[[a, b], [c, d]]`` (rows), else None."""
    t = text.strip()
    for a, b in (("\\left[", "\\right]"), ("\\left(", "\\right)")):
        if t.startswith(a) and t.endswith(b):
            t = t[len(a) - 1:len(t) - len(b)] + b[-1]
    if len(t) < 2 or (t[0], t[-1]) not in (("[", "]"), ("(", ")")) or not encloses(t):
        return None
    from ._text import split_top

    body = t[1:-1]
    rows = split_top(body, (";", "\\\\"))
    if len(rows) > 1:
        return [[c.strip() for c in split_top(r, (",", "&"))] for r in rows if r.strip()]
    items = [c.strip() for c in split_top(body, (",",))]
    if len(items) < 2:
        return None
    if all(len(i) >= 2 and i[0] == "[" and i[-1] == "]" and encloses(i) for i in items):
        return [[c.strip() for c in split_top(i[1:-1], (",",))] for i in items]
    return [[c] for c in items]


def encloses(t: str) -> bool:
    """The first bracket of ``t`` closes at its last character."""
    level = 0
    for k, ch in enumerate(t):
        level += ch in "([{"
        level -= ch in ")]}"
        if level == 0:
            return k == len(t) - 1
    return False


def parse_matrix(text: str, resolve: Resolver) -> list[list[tuple]]:
    """A LaTeX matrix (or a single expression, as a 1×1 matrix) → rows of trees; errors name the entry.

    Only the part after the last ``=`` counts (a definition pasted before it is skipped); a bracketed list
    ``[a, b, c]`` is a column and ``[a, b; c, d]`` a matrix.  Rows of different lengths raise
    :class:`RaggedMatrix`.
    """
    if len(text) > MAX_CHARS:
        raise ParseError(f"expression longer than {MAX_CHARS} characters")
    text = after_last_equals(strip_equation_number(text))
    cells = split_matrix(text)
    if cells is None:
        cells = split_list(_normalize(text))
    if cells is None:
        return [[parse_math(text, resolve)]]
    if not cells:
        raise ParseError("empty matrix")
    width = max(len(r) for r in cells)
    if any(len(r) != width for r in cells):
        raise RaggedMatrix(f"rows of different lengths {[len(r) for r in cells]} in the matrix")
    out = []
    for i, row in enumerate(cells, start=1):
        out_row = []
        for j, cell in enumerate(row, start=1):
            try:
                out_row.append(parse_math(cell, resolve, rhs=False))
            except ParseError as exc:
                raise ParseError(f"entry ({i}, {j}) {cell[:40]!r}: {exc}") from None
        out.append(out_row)
    return out
