"""A small, restricted expression language for robot files, command-line values and claims.

Robot files and pasted values are untrusted input: they are read here by a hand-written tokenizer and
recursive-descent parser into a tiny syntax tree, then evaluated to a float or built into a sympy
expression node by node.  Nothing ever reaches ``eval``, ``exec``, ``sympify`` or ``parse_expr``.

Grammar (``^`` and ``**`` are both power, right associative)::

    expr   := term (('+' | '-') term)*
    term   := unary (('*' | '/') unary)*
    unary  := ('+' | '-') unary | power
    power  := atom (('^' | '**') unary)?
    atom   := NUMBER ['deg'] | NAME ['deg'] | NAME '(' expr (',' expr)* ')' | '(' expr ')' ['deg']

Length, nesting depth and exponents are capped, so ``9**9**9`` or a deeply nested input is refused
quickly with a :class:`~denavit.errors.ParseError` instead of eating memory.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass
from typing import Any, Callable, Mapping

from .errors import ParseError

__all__ = ["Node", "parse", "evaluate", "to_sympy", "to_text", "names_in", "is_literal", "fold", "lookup", "tree_depth", "MAX_LENGTH",
           "MAX_DEPTH"]

MAX_LENGTH = 500
MAX_DEPTH = 30
MAX_EXPONENT = 64.0

# A node is a plain tuple so that it is hashable and cheap:
#   ("num", "0.5")  ("name", "L1")  ("neg", node)  ("bin", op, left, right)  ("call", fname, (args...))
Node = tuple

FUNCTIONS: dict[str, int] = {  # name -> number of arguments
    "sin": 1, "cos": 1, "tan": 1, "asin": 1, "acos": 1, "atan": 1, "atan2": 2,
    "sqrt": 1, "exp": 1, "log": 1, "abs": 1, "deg": 1, "rad": 1,
}
CONSTANTS = ("pi",)

_TOKEN = re.compile(
    r"\s*(?:(?P<num>(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?)|(?P<name>[A-Za-z_][A-Za-z_0-9]*)"
    r"|(?P<op>\*\*|[-+*/^(),]))"
)


@dataclass(frozen=True)
class _Tok:
    kind: str
    text: str
    pos: int


def _tokenize(text: str) -> list[_Tok]:
    toks: list[_Tok] = []
    pos = 0
    text = text.replace("\u2212", "-").replace("\u00d7", "*").replace("\u03c0", "pi").replace("°", "deg")
    while pos < len(text):
        if text[pos:].strip() == "":
            break
        m = _TOKEN.match(text, pos)
        if not m or m.end() == pos:
            bad = text[pos:].lstrip()[:1]
            raise ParseError(f"unexpected character {bad!r} at position {pos + 1} in {text!r}")
        kind = m.lastgroup or "op"
        toks.append(_Tok(kind, m.group(kind), m.start(kind)))
        pos = m.end()
    return toks


class _Parser:
    def __init__(self, text: str) -> None:
        self.text = text
        self.toks = _tokenize(text)
        self.i = 0
        self.depth = 0

    def peek(self) -> _Tok | None:
        return self.toks[self.i] if self.i < len(self.toks) else None

    def take(self, text: str | None = None) -> _Tok:
        tok = self.peek()
        if tok is None:
            raise ParseError(f"unexpected end of expression {self.text!r}")
        if text is not None and tok.text != text:
            raise ParseError(f"expected {text!r} but found {tok.text!r} in {self.text!r}")
        self.i += 1
        return tok

    def enter(self) -> None:
        self.depth += 1
        if self.depth > MAX_DEPTH:
            raise ParseError(f"expression nested too deeply (more than {MAX_DEPTH} levels)")

    def expr(self) -> Node:
        self.enter()
        node = self.term()
        while (tok := self.peek()) is not None and tok.text in "+-" and tok.kind == "op":
            self.take()
            node = ("bin", tok.text, node, self.term())
        self.depth -= 1
        return node

    def term(self) -> Node:
        node = self.unary()
        while (tok := self.peek()) is not None and tok.text in ("*", "/"):
            self.take()
            node = ("bin", tok.text, node, self.unary())
        return node

    def unary(self) -> Node:
        tok = self.peek()
        if tok is not None and tok.text in ("+", "-"):
            self.take()
            self.enter()
            inner = self.unary()
            self.depth -= 1
            return ("neg", inner) if tok.text == "-" else inner
        return self.power()

    def power(self) -> Node:
        base = self.atom()
        tok = self.peek()
        if tok is not None and tok.text in ("^", "**"):
            self.take()
            self.enter()
            exponent = self.unary()
            self.depth -= 1
            return ("bin", "^", base, exponent)
        return base

    def _deg_suffix(self, node: Node) -> Node:
        tok = self.peek()
        if tok is not None and tok.kind == "name" and tok.text == "deg":
            self.take()
            return ("call", "deg", (node,))
        return node

    def atom(self) -> Node:
        tok = self.take()
        if tok.kind == "num":
            return self._deg_suffix(("num", tok.text))
        if tok.text == "(":
            inner = self.expr()
            self.take(")")
            return self._deg_suffix(inner)
        if tok.kind == "name":
            nxt = self.peek()
            if nxt is not None and nxt.text == "(":
                if tok.text not in FUNCTIONS:
                    raise ParseError(
                        f"unknown function {tok.text!r}; allowed: {', '.join(sorted(FUNCTIONS))}"
                    )
                self.take("(")
                args = [self.expr()]
                while (t := self.peek()) is not None and t.text == ",":
                    self.take()
                    args.append(self.expr())
                self.take(")")
                if len(args) != FUNCTIONS[tok.text]:
                    raise ParseError(f"{tok.text}() takes {FUNCTIONS[tok.text]} argument(s), got {len(args)}")
                return ("call", tok.text, tuple(args))
            if tok.text in FUNCTIONS:
                raise ParseError(f"function {tok.text!r} needs parentheses, e.g. {tok.text}(x)")
            return self._deg_suffix(("name", tok.text))
        raise ParseError(f"unexpected {tok.text!r} at position {tok.pos + 1} in {self.text!r}")


def parse(text: Any) -> Node:
    """Parse ``text`` (a string or a plain number) into a syntax tree; raise ParseError if malformed."""
    if isinstance(text, bool):
        raise ParseError(f"expected a number or expression, got {text!r}")
    if isinstance(text, int) and text.bit_length() > 1100:  # beyond float range (and Python's 4,300-digit str limit)
        raise ParseError(f"integer of about {int(text.bit_length() * 0.30103)} digits is too large")
    if isinstance(text, (int, float)):
        if not math.isfinite(text):
            raise ParseError(f"value must be finite, got {text!r}")
        return ("num", repr(float(text)) if isinstance(text, float) else str(text))
    if not isinstance(text, str):
        raise ParseError(f"expected a number or expression, got {type(text).__name__}")
    if len(text) > MAX_LENGTH:
        raise ParseError(f"expression longer than {MAX_LENGTH} characters")
    if not text.strip():
        raise ParseError("empty expression")
    p = _Parser(text)
    node = p.expr()
    if p.peek() is not None:
        tok = p.toks[p.i]
        raise ParseError(f"unexpected {tok.text!r} at position {tok.pos + 1} in {text!r}")
    return node


def is_literal(node: Node) -> bool:
    """Whether a tree is a plain number, maybe negated (no unit, no ``pi``, no name)."""
    return node[0] == "num" or (node[0] == "neg" and node[1][0] == "num")


def names_in(node: Node) -> set[str]:
    """The free names used by a tree (constants such as ``pi`` excluded)."""
    out: set[str] = set()
    stack = [node]
    while stack:  # no recursion: a sum of thousands of terms is a tree thousands of levels deep
        n = stack.pop()
        kind = n[0]
        if kind == "name":
            if n[1] not in CONSTANTS:
                out.add(n[1])
        elif kind == "neg":
            stack.append(n[1])
        elif kind == "bin":
            stack += (n[2], n[3])
        elif kind == "call":
            stack += n[2]
    return out


def tree_depth(node: Node) -> int:
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


def fold(node: Node, number: Callable[[str], Any], name: Callable[[str], Any],
         ops: Mapping[str, Callable[..., Any]], funcs: Mapping[str, Callable[..., Any]]) -> Any:
    """Interpret a tree with one backend (floats, sympy, numpy arrays, text): the single tree walker.

    ``number(text)`` and ``name(identifier)`` give the leaves; ``ops`` holds ``"neg"`` and the binary
    operators ``+ - * / ^``; ``funcs`` the functions of :data:`FUNCTIONS`.  The walk uses an explicit
    stack, so a left-deep sum of thousands of terms (``1+1+…+1``) cannot exhaust Python's recursion limit;
    children are interpreted left to right.
    """
    values: list[Any] = []
    stack: list[tuple[Node, bool]] = [(node, False)]
    while stack:
        n, done = stack.pop()
        kind = n[0]
        if kind == "num":
            values.append(number(n[1]))
        elif kind == "name":
            values.append(name(n[1]))
        elif kind not in ("neg", "bin", "call"):
            raise ParseError(f"malformed expression node {kind!r}")
        elif not done:
            stack.append((n, True))
            children = (n[1],) if kind == "neg" else (n[2], n[3]) if kind == "bin" else tuple(n[2])
            stack.extend((c, False) for c in reversed(children))
        elif kind == "neg":
            values.append(ops["neg"](values.pop()))
        elif kind == "bin":
            b = values.pop()
            values[-1] = ops[n[1]](values[-1], b)
        else:
            k = len(n[2])
            args = values[len(values) - k:]
            del values[len(values) - k:]
            values.append(funcs[n[1]](*args))
    return values[0]


def lookup(env: Mapping[str, Any], pi: Any) -> Callable[[str], Any]:
    """The leaf function for names: ``pi``, else ``env``, else a ParseError listing what is known."""

    def name(n: str) -> Any:
        if n == "pi":
            return pi
        if n not in env:
            raise ParseError(f"unknown symbol {n!r} (known: {', '.join(['pi', *sorted(env)])})")
        return env[n]

    return name


def _float_power(a: float, b: float) -> float:
    if abs(b) > MAX_EXPONENT:
        raise ParseError(f"exponent {b:g} too large (at most {MAX_EXPONENT:g})")
    result = a ** b
    if isinstance(result, complex):
        raise ValueError("negative number to a fractional power")
    return float(result)


_FLOAT_OPS: dict[str, Callable[..., float]] = {
    "neg": lambda a: -a, "+": lambda a, b: a + b, "-": lambda a, b: a - b, "*": lambda a, b: a * b,
    "/": lambda a, b: a / b, "^": _float_power,
}
_FLOAT_FUNCS: dict[str, Callable[..., float]] = {
    "sin": math.sin, "cos": math.cos, "tan": math.tan, "asin": math.asin, "acos": math.acos,
    "atan": math.atan, "atan2": math.atan2, "sqrt": math.sqrt, "exp": math.exp, "log": math.log,
    "abs": abs, "deg": math.radians, "rad": lambda x: x,
}


def evaluate(node: Node, env: Mapping[str, float] | None = None) -> float:
    """Evaluate a tree to a finite float; names are looked up in ``env`` (plus ``pi``)."""
    env = env or {}
    try:
        value = float(fold(node, float, lambda n: float(lookup(env, math.pi)(n)), _FLOAT_OPS, _FLOAT_FUNCS))
    except (OverflowError, ZeroDivisionError, ValueError) as exc:
        if isinstance(exc, ParseError):
            raise
        raise ParseError(f"cannot evaluate {to_text(node)!r}: {exc}") from None
    if not math.isfinite(value):
        raise ParseError(f"value of {to_text(node)!r} is not finite")
    return value


def to_sympy(node: Node, symbols: Mapping[str, Any]) -> Any:
    """Build a sympy expression from a tree, node by node (no string parsing by sympy).

    ``symbols`` maps names to sympy objects.  Decimal numbers become exact rationals
    (``0.4`` -> ``2/5``) so that exact evaluation stays exact.
    """
    import sympy as sp

    def divide(a: Any, b: Any) -> Any:
        if b == 0:
            raise ParseError(f"division by zero in {to_text(node)!r}")
        return a / b

    def power(a: Any, b: Any) -> Any:
        if not b.is_number or abs(float(b)) > MAX_EXPONENT:
            raise ParseError(f"exponent in {to_text(node)!r} must be a number of size at most {MAX_EXPONENT:g}")
        return a ** b

    ops = {"neg": lambda a: -a, "+": lambda a, b: a + b, "-": lambda a, b: a - b, "*": lambda a, b: a * b,
           "/": divide, "^": power}
    funcs = {
        "sin": sp.sin, "cos": sp.cos, "tan": sp.tan, "asin": sp.asin, "acos": sp.acos,
        "atan": sp.atan, "atan2": sp.atan2, "sqrt": sp.sqrt, "exp": sp.exp, "log": sp.log,
        "abs": sp.Abs, "deg": lambda x: x * sp.pi / 180, "rad": lambda x: x,
    }
    number = lambda t: sp.Rational(t) if "e" not in t.lower() else sp.Float(t)  # noqa: E731
    return fold(node, number, lookup(symbols, sp.pi), ops, funcs)


_PREC = {"+": 1, "-": 1, "*": 2, "/": 2, "^": 4}
_ATOM = 9.0  # precedence of leaves and calls: never parenthesised
_NEG = 2.5   # a negation is parenthesised under * / ^ and as a base or exponent (context 3 and above)


class _AnyFunction(dict):
    def __missing__(self, fname: str) -> Callable[..., tuple[str, float]]:
        return lambda *args: (f"{fname}({', '.join(_wrap(a, 0) for a in args)})", _ATOM)


def _wrap(part: tuple[str, float], context: float) -> str:
    text, prec = part
    return f"({text})" if prec < context else text


def _text_bin(op: str) -> Callable[[tuple[str, float], tuple[str, float]], tuple[str, float]]:
    prec = _PREC[op]

    def join(a: tuple[str, float], b: tuple[str, float]) -> tuple[str, float]:
        if op == "^":
            return f"{_wrap(a, 5)}^{_wrap(b, 4)}", prec
        right = prec + 1 if op in "-/" else prec
        sep = op if op in "*/" else f" {op} "
        return f"{_wrap(a, prec)}{sep}{_wrap(b, right)}", prec

    return join


_TEXT_OPS = {"neg": lambda a: ("-" + _wrap(a, 3), _NEG), **{op: _text_bin(op) for op in _PREC}}


def to_text(node: Node, parent: int = 0) -> str:
    """Print a tree back as canonical text that :func:`parse` reads to the same tree (no recursion)."""
    part = fold(node, lambda t: (t, _ATOM), lambda n: (n, _ATOM), _TEXT_OPS, _AnyFunction())
    return _wrap(part, parent)
