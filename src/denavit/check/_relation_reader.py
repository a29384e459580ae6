"""The restricted reader of a relation's sides: matrix expressions of the arm's named vectors and matrices
(J, J_v, J_i, \\dot q, v, \\omega, F, \\tau, z_k, p_k, …) evaluated with numpy at one point (:mod:`._relations`).

Tokens come from :func:`._tokens.tokenize`; nothing reaches ``eval`` or sympy.
"""

from __future__ import annotations

import numpy as np

from .. import numeric as N
from ..errors import ParseError
from ..model import DHRobot

__all__ = ["RelationEnv", "RelationReader", "Undefined", "SizeMismatch", "MAX_RELATION_DEPTH"]

#: Deepest nesting of brackets and operators in a relation.
MAX_RELATION_DEPTH = 40
_OPEN = {"(": ")", "[": "]", "{": "}"}
_GREEK_NAMES = {"\\tau": "tau", "\\omega": "omega", "\\theta": "theta", "\\vartheta": "theta", "\\xi": "xi",
                "\\nu": "nu"}
_WRAP = {"\\mathbf", "\\boldsymbol", "\\bm", "\\vec", "\\mathrm", "\\mathit", "\\underline", "\\overline"}


class RelationEnv:
    """The values of the names at one point, for joint index ``i`` (1-based; None when no index is used)."""

    def __init__(self, robot: DHRobot, q: np.ndarray, qd: np.ndarray, F: np.ndarray, i: int | None) -> None:
        self.robot, self.i = robot, i
        self.frames = N.link_transforms(robot, q)
        self.J = N.geometric_jacobian(robot, q)
        self.p_e = N.forward_kinematics(robot, q)[:3, 3:4]
        self.qd, self.F = qd, F

    def index(self, tokens: list[tuple[str, str]]) -> int:
        """A subscript: a number, ``i``, ``i-1``, ``i+1``."""
        text = "".join(t for _, t in tokens).replace(" ", "")
        if text.isdigit() and len(text) <= 3:
            return int(text)
        if text in ("i", "i-1", "i+1", "i-2", "i+2"):
            if self.i is None:
                raise ParseError("internal: an index without a joint")
            return self.i + (int(text[1:]) if len(text) > 1 else 0)
        raise ParseError(f"subscript {text[:20]!r}: write a number, i, i-1 or i+1")

    def value(self, base: str, sub: list[tuple[str, str]] | None, dots: int) -> np.ndarray:
        n_rows = self.robot.n_rows
        if dots:
            if base in ("q", "theta") and not sub:
                return self.qd[:, None]
            if base in ("q", "theta"):
                k = self.index(sub)
                if not 1 <= k <= self.robot.dof:
                    raise Undefined(f"qd_{k}")
                return self.qd[k - 1:k, None]
            raise ParseError(f"only \\dot q (the joint rates) has a dot here, not {base!r}")
        if base == "tau" and sub:
            k = self.index(sub)
            if not 1 <= k <= self.robot.dof:
                raise Undefined(f"tau_{k}")
            return (self.J.T @ self.F)[k - 1:k, None]
        if base == "J":
            if not sub:
                return self.J
            key = "".join(t for _, t in sub).replace(" ", "")
            if key in ("v", "P", "L"):
                return self.J[:3]
            if key in ("\\omega", "w", "\\Omega", "A", "omega"):
                return self.J[3:]
            k = self.index(sub)
            if not 1 <= k <= self.robot.dof:
                raise Undefined(f"J_{k}")
            return self.J[:, k - 1:k]
        if base in ("z", "p", "o"):
            if not sub:
                if base == "z":
                    raise ParseError("z needs a subscript (z_{i-1}, z_0, …)")
                return self.p_e
            key = "".join(t for _, t in sub).replace(" ", "")
            if base in ("p", "o") and key in ("e", "n", "E", "ee", "N"):
                return self.p_e
            k = self.index(sub)
            if not 0 <= k <= n_rows:
                raise Undefined(f"{base}_{k}")
            return self.frames[k][:3, 2:3] if base == "z" else self.frames[k][:3, 3:4]
        if sub:
            raise ParseError(f"unknown name {base}_{{…}} in a relation")
        twist = self.J @ self.qd
        table = {"F": self.F[:, None], "W": self.F[:, None], "f": self.F[:3, None], "n": self.F[3:, None],
                 "tau": (self.J.T @ self.F)[:, None], "v": twist[:3, None], "omega": twist[3:, None],
                 "xi": twist[:, None], "nu": twist[:, None]}
        if base in table:
            return table[base]
        raise ParseError(f"unknown name {base!r} in a relation; known: J, J_v, J_\\omega, J_i, \\dot q, v, \\omega, "
                         "F, f, n, \\tau, z_k, p_k, p")


class Undefined(Exception):
    """A frame or column outside the arm for this joint (z_{i-1} for i = 0): the relation says nothing there."""


class RelationReader:
    def __init__(self, tokens: list[tuple[str, str]], env: RelationEnv) -> None:
        self.t, self.k, self.env, self.depth = tokens, 0, env, 0

    def peek(self, j: int = 0):
        return self.t[self.k + j] if self.k + j < len(self.t) else None

    def take(self, text: str | None = None):
        tok = self.peek()
        if tok is None or (text is not None and tok[1] != text):
            raise ParseError(f"expected {text or 'more'} in the relation, found {tok[1] if tok else 'the end'!r}")
        self.k += 1
        return tok

    def enter(self):
        self.depth += 1
        if self.depth > MAX_RELATION_DEPTH:
            raise ParseError(f"relation nested too deeply (more than {MAX_RELATION_DEPTH} levels)")

    def expr(self, stop: tuple[str, ...] = ()) -> np.ndarray:
        self.enter()
        out = self.term(stop)
        while (tok := self.peek()) is not None and tok[1] in ("+", "-") and tok[1] not in stop:
            self.take()
            rhs = self.term(stop)
            out = _add(out, rhs if tok[1] == "+" else -rhs)
        self.depth -= 1
        return out

    def term(self, stop) -> np.ndarray:
        out = self.unary(stop)
        while (tok := self.peek()) is not None and tok[1] not in stop:
            if tok[1] == "\\times":
                self.take()
                out = _cross(out, self.unary(stop))
            elif tok[1] in ("\\cdot", "*"):
                self.take()
                out = _product(out, self.unary(stop))
            elif tok[0] in ("word", "num", "cmd") and tok[1] not in ("\\end",) or tok[1] in ("(", "["):
                out = _product(out, self.unary(stop))
            else:
                break
        return out

    def unary(self, stop) -> np.ndarray:
        tok = self.peek()
        if tok is not None and tok[1] == "-":
            self.take()
            return -self.unary(stop)
        if tok is not None and tok[1] == "+":
            self.take()
            return self.unary(stop)
        return self.postfix()

    def postfix(self) -> np.ndarray:
        out = self.atom()
        while (tok := self.peek()) is not None and tok[1] == "^":
            self.take()
            sup = self.group()
            key = "".join(t for _, t in sup).replace(" ", "")
            if key in ("T", "\\top", "\\intercal"):
                out = out.T
            elif key in ("-1",):
                out = _inverse(out)
            elif key in ("-T", "-\\top"):
                out = _inverse(out).T
            elif key.isdigit() and len(key) == 1 and out.size == 1:
                out = out ** int(key)
            else:
                raise ParseError(f"unsupported power ^{key[:20]} in a relation (T, -1, -T)")
        return out

    def group(self) -> list[tuple[str, str]]:
        """The tokens of ``{…}`` or one token."""
        tok = self.take()
        if tok[1] != "{":
            return [tok]
        out, level = [], 1
        while True:
            t = self.take()
            level += t[1] == "{"
            level -= t[1] == "}"
            if level == 0:
                return out
            out.append(t)

    def atom(self) -> np.ndarray:
        self.enter()
        try:
            kind, s = self.take()
            if kind == "num":
                return np.array([[float(s)]])
            if s == "{" and (nxt := self.peek()) is not None and nxt[1] == "}":  # {}^0 J: a frame marker
                self.take()
                self.take("^")
                frame = "".join(t for _, t in self.group()).replace(" ", "")
                if frame != "0":
                    raise ParseError(f"{{}}^{frame[:10]}: relations are written in base axes ({{}}^0) only")
                return self.atom()
            if s in ("(", "{"):
                inner = self.expr((_OPEN[s],))
                self.take(_OPEN[s])
                return inner
            if s == "[":
                return self.stack("]")
            if s == "\\begin":
                env = "".join(t for _, t in self.group())
                if not env.endswith("matrix"):
                    raise ParseError(f"\\begin{{{env[:20]}}} is not a matrix environment")
                out = self.stack("\\end")
                self.group()
                return out
            if s == "\\frac":
                num, den = self.braced(), self.braced()
                return _product(num, np.array([[1.0 / _scalar(den)]]))
            if s == "\\dot":
                base = self.name_of(self.take_name_token())
                return self.finish(base, dots=1)
            if s in _WRAP:
                inner = self.group()
                if len(inner) != 1:
                    raise ParseError("\\mathbf{…} holds one name in a relation")
                return self.finish(self.name_of(inner[0]))
            if kind in ("word", "cmd"):
                return self.finish(self.name_of((kind, s)))
            raise ParseError(f"unexpected {s!r} in a relation")
        finally:
            self.depth -= 1

    def braced(self) -> np.ndarray:
        self.take("{")
        out = self.expr(("}",))
        self.take("}")
        return out

    def take_name_token(self):
        tok = self.take()
        if tok[1] == "{":
            inner = self.take()
            if inner[1] in _WRAP:
                inner = self.group()[0]
            self.take("}")
            return inner
        if tok[1] in _WRAP:
            return self.group()[0]
        return tok

    def name_of(self, tok) -> str:
        kind, s = tok
        if kind == "cmd":
            if s in _GREEK_NAMES:
                return _GREEK_NAMES[s]
            raise ParseError(f"unsupported command {s[:20]} in a relation")
        if kind != "word" or len(s) > 3:
            raise ParseError(f"unexpected {s[:20]!r} in a relation")
        return s

    def finish(self, base: str, dots: int = 0) -> np.ndarray:
        sub = None
        if (tok := self.peek()) is not None and tok[1] == "_":
            self.take()
            sub = self.group()
        return np.atleast_2d(np.asarray(self.env.value(base, sub, dots), dtype=float))

    def stack(self, end: str) -> np.ndarray:
        """Rows (``\\\\`` or ``;``) of cells (``&`` or ``,``) up to ``end``: blocks stacked."""
        rows, cells = [], []
        while True:
            tok = self.peek()
            if tok is None:
                raise ParseError(f"a matrix without its {end!r}")
            if tok[1] == end:
                self.take()
                break
            cells.append(self.expr(("&", ",", ";", "\\\\", end)))
            tok = self.peek()
            if tok is not None and tok[1] in ("&", ","):
                self.take()
                continue
            if tok is not None and tok[1] in (";", "\\\\"):
                self.take()
            rows.append(cells)
            cells = []
        if cells:
            rows.append(cells)
        rows = [r for r in rows if r]
        if any(b.size > 1 for r in rows for b in r):  # a 0 among blocks is a zero block: [z; 0], [R 0; 0 R]
            zero = lambda b: b.size == 1 and b.reshape(-1)[0] == 0  # noqa: E731
            heights = [max((b.shape[0] for b in r if not zero(b)), default=3) for r in rows]
            widths = {}
            for r in rows:
                for c, b in enumerate(r):
                    if not zero(b):
                        widths[c] = max(widths.get(c, 0), b.shape[1])
            rows = [[np.zeros((heights[k], widths.get(c, 1))) if zero(b) else b for c, b in enumerate(r)]
                    for k, r in enumerate(rows)]
        try:
            return np.vstack([np.hstack(r) for r in rows])
        except ValueError:
            raise SizeMismatch("blocks of a stacked matrix do not fit together") from None


class SizeMismatch(Exception):
    """Sizes that do not fit (a product, a sum, a stack): the relation is wrong as written."""


def _scalar(x: np.ndarray) -> float:
    if x.size != 1:
        raise SizeMismatch("a fraction of a matrix")
    value = float(x.reshape(-1)[0])
    if value == 0:
        raise ParseError("division by zero in the relation")
    return value


def _add(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    if a.shape != b.shape:
        raise SizeMismatch(f"a {a.shape[0]}×{a.shape[1]} plus a {b.shape[0]}×{b.shape[1]}")
    return a + b


def _product(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    if a.size == 1 or b.size == 1:
        return a * b
    if a.shape[1] != b.shape[0]:
        raise SizeMismatch(f"a {a.shape[0]}×{a.shape[1]} times a {b.shape[0]}×{b.shape[1]}")
    return a @ b


def _cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    if a.shape != (3, 1) or b.shape != (3, 1):
        raise SizeMismatch("× needs two 3-vectors")
    return np.cross(a[:, 0], b[:, 0])[:, None]


def _inverse(a: np.ndarray) -> np.ndarray:
    if a.shape[0] != a.shape[1]:
        raise SizeMismatch(f"the inverse of a {a.shape[0]}×{a.shape[1]} matrix")
    if abs(np.linalg.det(a)) < 1e-12 * max(1.0, np.abs(a).max()) ** a.shape[0]:
        raise Undefined("singular")
    return np.linalg.inv(a)
