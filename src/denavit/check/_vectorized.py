"""Evaluate a restricted expression tree (:mod:`denavit._expr` nodes) on numpy arrays.

Used by the claim kinds that scan or sample a person's formula at many points (singular conditions, IK
formulas).  Domain errors give NaN instead of raising, so one bad point does not hide the others; names come
only from the given environment.  Nothing here parses text.
"""

from __future__ import annotations

from typing import Mapping

import numpy as np

from .. import _expr
from ..errors import ParseError

__all__ = ["vec_eval"]

_FUNCS = {
    "sin": np.sin, "cos": np.cos, "tan": np.tan, "asin": np.arcsin, "acos": np.arccos, "atan": np.arctan,
    "atan2": np.arctan2, "sqrt": np.sqrt, "exp": np.exp, "log": np.log, "abs": np.abs, "deg": np.radians,
    "rad": lambda x: x,
}


def vec_eval(node: tuple, env: Mapping[str, object]) -> np.ndarray:
    """The value of ``node`` with names from ``env`` (floats or broadcastable arrays); NaN where undefined."""
    with np.errstate(all="ignore"):
        out = np.asarray(_ev(node, env), dtype=float)
    return np.where(np.isfinite(out), out, np.nan)


def _ev(node: tuple, env: Mapping[str, object]):
    kind = node[0]
    if kind == "num":
        return float(node[1])
    if kind == "name":
        if node[1] == "pi":
            return np.pi
        if node[1] not in env:
            raise ParseError(f"unknown symbol {node[1]!r} (known: pi, {', '.join(sorted(env)) or 'none'})")
        return np.asarray(env[node[1]], dtype=float)
    if kind == "neg":
        return -_ev(node[1], env)
    if kind == "bin":
        a, b = _ev(node[2], env), _ev(node[3], env)
        op = node[1]
        if op == "+":
            return a + b
        if op == "-":
            return a - b
        if op == "*":
            return a * b
        if op == "/":
            return np.divide(a, b)
        if np.any(np.abs(b) > _expr.MAX_EXPONENT):
            raise ParseError(f"exponent too large (at most {_expr.MAX_EXPONENT:g})")
        return np.power(np.asarray(a, dtype=float), b)
    if kind == "call":
        return _FUNCS[node[1]](*(_ev(a, env) for a in node[2]))
    raise ParseError(f"malformed expression node {kind!r}")
