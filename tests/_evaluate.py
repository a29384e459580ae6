"""Evaluate sympy matrices at float points by walking each distinct sub-expression once (a test helper).

``sympy.lambdify`` prints every expression as a tree: a formula that repeats a sub-expression prints it every time
it occurs (the Panda's hand-form Coriolis vector is ~2 MB of text, and printing it costs ~30 CPU seconds), although
the expression is a DAG with ~27,000 distinct nodes.  :func:`numeric_function` evaluates that DAG in float64,
each distinct node once per call, with the operations ``lambdify(..., "numpy")`` would print (``*``, ``**``, sin,
cos, ...; sums by ``math.fsum``, correctly rounded, so no less accurate than lambdify's left-to-right ``+``);
anything it does not know raises ``TypeError`` rather than being guessed.
"""

from __future__ import annotations

import math
from typing import Callable, Sequence

import numpy as np
import sympy as sp

_FUNCTIONS = {sp.sin: math.sin, sp.cos: math.cos, sp.tan: math.tan, sp.exp: math.exp, sp.log: math.log,
              sp.atan2: math.atan2, sp.Abs: abs}


def _value(e: sp.Basic, env: dict) -> float:
    """e's value, its arguments already in env."""
    if e.is_Add:
        return math.fsum(env[a] for a in e.args)
    if e.is_Mul:
        out = 1.0
        for a in e.args:
            out *= env[a]
        return out
    if e.is_Pow:
        base, exp = env[e.args[0]], e.args[1]
        if exp.is_Integer:
            return base ** int(exp)
        return base ** env[exp]
    f = _FUNCTIONS.get(e.func)
    if f is None:
        raise TypeError(f"numeric_function: no rule for {e.func.__name__} in {str(e)[:80]}")
    return float(f(*(env[a] for a in e.args)))


def _order(exprs: Sequence[sp.Basic], symbols: set) -> list[sp.Basic]:
    """The distinct non-leaf nodes of exprs, each after its arguments (iterative post-order)."""
    done, out = set(), []
    for root in exprs:
        stack = [(root, False)]
        while stack:
            e, expanded = stack.pop()
            if e in done:
                continue
            if expanded or not e.args or e.is_number or e in symbols:
                done.add(e)
                out.append(e)
                continue
            stack.append((e, True))
            stack.extend((a, False) for a in e.args if a not in done)
    return out


def numeric_function(symbols: Sequence[sp.Symbol], matrices: Sequence[sp.MatrixBase]) -> Callable[..., list]:
    """``f(*values) -> [np.ndarray per matrix]``, as ``sympy.lambdify(symbols, matrices, "numpy")`` for float
    inputs; free symbols not in ``symbols`` raise ``KeyError`` (as lambdify's NameError)."""
    symbols = list(symbols)
    shapes = [M.shape for M in matrices]
    entries = [e for M in matrices for e in M]
    nodes = _order(entries, set(symbols))
    consts = {e: float(e) for e in nodes if e.is_number}
    given = set(symbols)
    work = [e for e in nodes if e not in consts and e not in given]

    def f(*values):
        if len(values) != len(symbols):
            raise TypeError(f"expected {len(symbols)} values, got {len(values)}")
        env = dict(consts)
        env.update((s, float(v)) for s, v in zip(symbols, values))
        for e in work:
            if e.is_Symbol:
                raise KeyError(f"numeric_function: no value for symbol {e}")
            env[e] = _value(e, env)
        out, k = [], 0
        for rows, cols in shapes:
            out.append(np.array([env[e] for e in entries[k:k + rows * cols]], dtype=float).reshape(rows, cols))
            k += rows * cols
        return out

    return f
