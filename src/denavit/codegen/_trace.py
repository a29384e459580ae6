"""A symbolic tracer: run the library's own numeric algorithms on symbols and record straight-line code.

The numeric kernels of denavit (the chain walker :mod:`denavit.chain`, the RNEA and CRBA of
:mod:`denavit.numeric`) are written on components that are Python floats or arrays, with plain ``+ - *``.
Run them on :class:`Sym` values instead and every operation is recorded on a :class:`Tape`: an expression
graph in static single assignment form, where

- **constants fold** — an operation on two floats is just done (the robot's numbers are floats), and the
  identities x + 0, x · 1, x · 0, x · (−1), −(−x), x − x are applied as the operation is recorded, so a zero or
  ±π/2 twist costs nothing;
- **common subexpressions are shared** — each operation is hash-consed (the same operation on the same
  operands returns the node already recorded; ``a·b`` and ``b·a`` are one node), which is common-subexpression
  elimination done as the graph is built (the "value numbering" of compilers: Aho, Lam, Sethi & Ullman,
  *Compilers*, 2nd ed., §6.1.2);
- **sin/cos of q + k·π/2** become ±cos/±sin of q.

A kernel is then the list of nodes its outputs depend on (dead code dropped), in recording order, which is
already an evaluation order.  This is a small computer-algebra system for one purpose: sympy's general
expressions and ``cse`` take minutes on a 7-joint RNEA; this takes milliseconds and gives the same
straight-line program.

>>> tape = Tape()
>>> q = tape.inputs("q", 2)
>>> e = q[0] * 2.0 + 0.0 * q[1] + q[0] * 2.0
>>> [tape.ops[i] for i in tape.program([e])]
[('input', 'q', 0), ('mul', 0, 2.0), ('add', 2, 2)]
"""

from __future__ import annotations

import math
from numbers import Real

__all__ = ["Sym", "Tape", "sym_sin", "sym_cos", "sym_sign", "sym_min", "sym_max"]

_HALF_PI = math.pi / 2


class Sym:
    """One recorded value (a node of a :class:`Tape`).  Arithmetic with floats and other nodes records."""

    __slots__ = ("tape", "i")
    __array_priority__ = 100  # numpy scalars defer to our reflected operators

    def __init__(self, tape: "Tape", i: int) -> None:
        self.tape, self.i = tape, i

    # another kind of number (a dual of denavit.numeric holding traced values) does the operation itself
    def __add__(self, other):
        if not isinstance(other, _OPERANDS) and not isinstance(other, Real):
            return NotImplemented
        return self.tape.add(self, other)

    __radd__ = __add__

    def __sub__(self, other):
        if not isinstance(other, _OPERANDS) and not isinstance(other, Real):
            return NotImplemented
        return self.tape.sub(self, other)

    def __rsub__(self, other):
        return self.tape.sub(other, self)

    def __mul__(self, other):
        if not isinstance(other, _OPERANDS) and not isinstance(other, Real):
            return NotImplemented
        return self.tape.mul(self, other)

    __rmul__ = __mul__

    def __truediv__(self, other):
        if not isinstance(other, _OPERANDS) and not isinstance(other, Real):
            return NotImplemented
        return self.tape.div(self, other)

    def __rtruediv__(self, other):
        return self.tape.div(other, self)

    def __neg__(self):
        return self.tape.neg(self)

    def __pos__(self):
        return self

    # numpy's ufuncs on objects call these (np.cos(x) → x.cos())
    def sin(self):
        return self.tape.unary("sin", self)

    def cos(self):
        return self.tape.unary("cos", self)

    # what the dual numbers of denavit.numeric call on a value that is neither a float nor an array
    def sign(self):
        return self.tape.unary("sign", self)

    def min(self, other):
        return self.tape.binary("min", self, other)

    def max(self, other):
        return self.tape.binary("max", self, other)

    def __repr__(self) -> str:
        return f"Sym({self.tape.describe(self.i)})"

    def __bool__(self):
        raise TypeError("a traced value has no truth value: the algorithm branches on data, not on the arm")


_OPERANDS = (Sym, int, float)


def sym_sin(x):
    return math.sin(x) if isinstance(x, (int, float)) else x.sin()


def sym_cos(x):
    return math.cos(x) if isinstance(x, (int, float)) else x.cos()


def sym_sign(x):
    if isinstance(x, (int, float)):
        return float((x > 0) - (x < 0))
    return x.tape.unary("sign", x)


def sym_min(a, b):
    if isinstance(a, (int, float)) and isinstance(b, (int, float)):
        return float(min(a, b))
    tape = (a if isinstance(a, Sym) else b).tape
    return tape.binary("min", a, b)


def sym_max(a, b):
    if isinstance(a, (int, float)) and isinstance(b, (int, float)):
        return float(max(a, b))
    tape = (a if isinstance(a, Sym) else b).tape
    return tape.binary("max", a, b)


def _key(x):
    """Hash key of an operand: a node index, or the constant's exact bits (0.0 and −0.0 stay apart)."""
    return x.i if isinstance(x, Sym) else ("c", float(x).hex())


class Tape:
    """The recorded program: ``ops[i]`` is ``(op, a, b)`` with operands node indices (int) or constants (float).

    ``op`` is one of ``input`` (a = input name, b = index), ``add``, ``sub``, ``mul``, ``div``, ``neg``,
    ``sin``, ``cos``, ``sign``, ``min``, ``max`` (unary ops have b = None).
    """

    def __init__(self) -> None:
        self.ops: list[tuple] = []
        self._seen: dict[tuple, int] = {}
        self.input_names: list[tuple[str, int]] = []

    # --- recording --------------------------------------------------------------------------------------
    def _node(self, op: str, a, b=None) -> Sym:
        if op in ("add", "mul", "min", "max") and isinstance(a, Sym) and isinstance(b, Sym) and a.i > b.i:
            a, b = b, a  # commutative: one node for a·b and b·a
        elif op in ("add", "mul") and not isinstance(a, Sym):
            a, b = b, a  # constant second
        key = (op, _key(a), None if b is None else _key(b))
        i = self._seen.get(key)
        if i is None:
            i = self._seen[key] = len(self.ops)
            self.ops.append((op, a.i if isinstance(a, Sym) else float(a),
                             None if b is None else (b.i if isinstance(b, Sym) else float(b))))
        return Sym(self, i)

    def inputs(self, name: str, n: int) -> list[Sym]:
        """``n`` input values ``name[0]`` … ``name[n-1]`` (a joint vector, say)."""
        out = []
        for k in range(n):
            self.input_names.append((name, k))
            i = len(self.ops)
            self.ops.append(("input", name, k))
            out.append(Sym(self, i))
        return out

    def _op_of(self, x):
        return self.ops[x.i][0] if isinstance(x, Sym) else None

    def add(self, a, b):
        if not isinstance(a, Sym):
            a, b = b, a
        if not isinstance(b, Sym):
            b = float(b)
            if b == 0.0:
                return a
            return self._node("add", a, b)
        if self._op_of(b) == "neg":
            return self.sub(a, Sym(self, self.ops[b.i][1]))
        if self._op_of(a) == "neg":
            return self.sub(b, Sym(self, self.ops[a.i][1]))
        return self._node("add", a, b)

    def sub(self, a, b):
        if not isinstance(b, Sym):
            b = float(b)
            return a if b == 0.0 else self.add(a, -b)
        if not isinstance(a, Sym):
            a = float(a)
            if a == 0.0:
                return self.neg(b)
            return self._node("sub", a, b)
        if a.i == b.i:
            return 0.0
        if self._op_of(b) == "neg":
            return self.add(a, Sym(self, self.ops[b.i][1]))
        return self._node("sub", a, b)

    def mul(self, a, b):
        if not isinstance(a, Sym):
            a, b = b, a
        if not isinstance(b, Sym):
            b = float(b)
            if b == 0.0:
                return 0.0
            if b == 1.0:
                return a
            if b == -1.0:
                return self.neg(a)
            if self._op_of(a) == "neg":
                return self.mul(Sym(self, self.ops[a.i][1]), -b)
            return self._node("mul", a, b)
        na, nb = self._op_of(a) == "neg", self._op_of(b) == "neg"
        if na or nb:
            a2 = Sym(self, self.ops[a.i][1]) if na else a
            b2 = Sym(self, self.ops[b.i][1]) if nb else b
            prod = self._node("mul", a2, b2)
            return prod if na and nb else self.neg(prod)
        return self._node("mul", a, b)

    def div(self, a, b):
        if not isinstance(b, Sym):
            return self.mul(a, 1.0 / float(b))
        if not isinstance(a, Sym) and float(a) == 0.0:
            return 0.0
        return self._node("div", a, b)

    def neg(self, a):
        if not isinstance(a, Sym):
            return -float(a)
        if self._op_of(a) == "neg":
            return Sym(self, self.ops[a.i][1])
        return self._node("neg", a)

    def unary(self, op: str, a):
        if op in ("sin", "cos") and self._op_of(a) == "add":
            _, x, c = self.ops[a.i]
            if isinstance(c, float):  # sin/cos(x + k·π/2) → ±sin/±cos(x)
                k = round(c / _HALF_PI)
                if k != 0 and c == k * _HALF_PI:
                    xs = Sym(self, x)
                    k %= 4
                    base = self.unary("sin" if (op == "sin") == (k % 2 == 0) else "cos", xs)
                    negate = k in (2, 3) if op == "sin" else k in (1, 2)
                    return self.neg(base) if negate else base
        if op == "neg":
            return self.neg(a)
        return self._node(op, a)

    def binary(self, op: str, a, b):
        return self._node(op, a, b)

    # --- reading ----------------------------------------------------------------------------------------
    def program(self, outputs) -> list[int]:
        """Indices of the nodes the ``outputs`` (Sym or floats) depend on, in evaluation order."""
        need = set()
        stack = [o.i for o in outputs if isinstance(o, Sym)]
        while stack:
            i = stack.pop()
            if i in need:
                continue
            need.add(i)
            op, a, b = self.ops[i]
            if op == "input":
                continue
            if isinstance(a, int):
                stack.append(a)
            if isinstance(b, int):
                stack.append(b)
        return sorted(need)

    def describe(self, i: int) -> str:
        op, a, b = self.ops[i]
        if op == "input":
            return f"{a}[{b}]"
        return f"{op}({a}, {b})" if b is not None else f"{op}({a})"
