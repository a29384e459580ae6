"""A restricted reader for mathematics written by people: LaTeX or plain text, into :mod:`denavit._expr` trees.

Claims files and pasted tables are untrusted.  This module reads them with a hand-written tokenizer and a
recursive-descent parser; nothing reaches ``eval``, ``exec``, ``sympify`` or ``parse_expr``.  Its output
is the same tiny tree as :mod:`denavit._expr` (``("num", "0.5")``, ``("name", "q1")``, ``("bin", "+", a, b)``
...), so evaluation and conversion to sympy reuse that module.

Accepted: numbers, decimals and powers of ten (``1e3``, ``2.5E-4``), ``+ - * / ^``, ``\\cdot``, ``\\times``, implicit multiplication
(``2 L_1 \\cos\\theta_1``), parentheses ``( ) [ ] { } \\left( \\right)``, ``\\frac{a}{b}``, ``\\sqrt{x}``,
``\\sin \\cos \\tan \\arctan \\operatorname{atan2}``, ``\\sin^2 x``, ``\\pi``, Greek letters, subscripts
(``\\theta_1``, ``L_{1}``, ``a_{i-1}``), dots (``\\dot\\theta_1``), shorthand ``C_1``, ``S_{12}``, ``c_{123}``,
``C_{\\theta_1}`` (the tokens: :mod:`._tokens`; matrices ``\\begin{bmatrix} … \\end{bmatrix}`` and lists of
cells: :mod:`._matrices`).
Names are resolved by a caller-supplied function, which decides what ``L_1`` or ``\\theta_2`` means.
Input length and nesting are capped.
"""

from __future__ import annotations

import re

from .. import _expr
from ..errors import ParseError
from ._text import after_last_equals, strip_equation_number
from ._tokens import FUNCS, GREEK, MAX_DEPTH, MAX_TREE_DEPTH, WRAP_CMDS, Ident, Resolver, tokenize

__all__ = ["parse_math"]

_OPEN = {"(": ")", "[": "]", "{": "}", "\\{": "\\}"}


_OPENS = {")": "(", "]": "[", "\\right)": "\\left(", "\\right]": "\\left["}


class _Parser:
    def __init__(self, text: str, resolve: Resolver) -> None:
        self.text = text
        self.toks = tokenize(text)
        self.i = 0
        self.depth = 0
        self.resolve = resolve

    # --- helpers ---------------------------------------------------------------------------------
    def peek(self, k: int = 0) -> tuple[str, str] | None:
        j = self.i + k
        return self.toks[j] if j < len(self.toks) else None

    def take(self, text: str | None = None) -> tuple[str, str]:
        tok = self.peek()
        unclosed = f": a {_OPENS[text]!r} opened before it is not closed (the brackets do not balance)" \
            if text in _OPENS else ""
        if tok is None:
            raise ParseError(f"unexpected end of expression{f' (expected {text!r})' if text else ''}{unclosed}")
        if text is not None and tok[1] != text:
            raise ParseError(f"expected {text!r} but found {tok[1]!r}{unclosed}")
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
        if s == "|":  # a_2 |s_3|: an absolute value starts a factor, unless this bar closes the one we are in
            return not getattr(self, "in_bars", 0)
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
            self.in_bars = getattr(self, "in_bars", 0) + 1
            try:
                inner = self.expr()
            finally:
                self.in_bars -= 1
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
        if name in WRAP_CMDS:
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
            if fname in _INVERSE and _is_minus_one(power):  # \cos^{-1} x is arccos x, as textbooks write it
                fname, power = _INVERSE[fname], None
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
            joined = self.joined_name(word, ident)
            if joined is not None:
                return joined
            if len(word) == 1:
                raise
        # "Lc" might be L·c: split letters, the last one keeps the subscript
        nodes = [self.resolve(Ident(ch)) for ch in word[:-1]]
        nodes.append(self.resolve(Ident(word[-1], ident.sub, ident.sub_tree)))
        out = nodes[0]
        for n in nodes[1:]:
            out = ("bin", "*", out, n)
        return out

    def joined_name(self, word: str, ident: Ident) -> tuple | None:
        """``L c_2`` read as ``Lc_2`` when ``L`` alone is unknown and the two words make a known name (a space a
        PDF-to-text conversion put inside the name); None, with nothing consumed, when they do not."""
        nxt = self.peek()
        if ident.sub or ident.dots or nxt is None or nxt[0] != "word" or not nxt[1].isalpha():
            return None
        start = self.i
        self.take()
        try:
            node = self.resolve(self.read_sub(word + nxt[1]))
        except ParseError:
            node = None
        if node is None or node[0] != "name":
            self.i = start
            return None
        return node

    def resolve_ident(self, ident: Ident, allow_sub: bool) -> tuple:
        return self.resolve(ident)


_INVERSE = {"sin": "asin", "cos": "acos", "tan": "atan"}


def _is_minus_one(node: tuple) -> bool:
    """The exponent ``-1`` (``^{-1}``): read on a function as its inverse (``\\sin^{-1}`` = arcsin), never 1/sin."""
    if _expr.names_in(node):
        return False
    try:
        return _expr.evaluate(node) == -1.0
    except Exception:  # noqa: BLE001 - any exponent that does not evaluate is simply not -1
        return False


def parse_math(text: str, resolve: Resolver, *, rhs: bool = True) -> tuple:
    """One scalar expression (LaTeX or plain) → an :mod:`denavit._expr` tree."""
    if not isinstance(text, str):
        text = str(text)
    text = strip_equation_number(text).strip()
    if rhs:
        text = after_last_equals(text)
    if not text.strip():
        raise ParseError("empty expression")
    p = _Parser(text, resolve)
    node = p.expr()
    if p.peek() is not None:
        extra = text.count(")") - text.count("(")
        why = f" (the brackets do not balance: {extra} more ')' than '(')" if p.peek()[1] == ")" and extra > 0 else ""
        raise ParseError(f"unexpected {p.peek()[1]!r} after a complete expression in {text[:60]!r}{why}")
    if _expr.tree_depth(node) > MAX_TREE_DEPTH:
        raise ParseError(f"expression too long: more than {MAX_TREE_DEPTH} operations in a chain "
                         "(split it, or group terms in parentheses)")
    return node

