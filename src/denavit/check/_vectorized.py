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


def _power(a, b):
    if np.any(np.abs(b) > _expr.MAX_EXPONENT):
        raise ParseError(f"exponent too large (at most {_expr.MAX_EXPONENT:g})")
    return np.power(np.asarray(a, dtype=float), b)


_OPS = {"neg": np.negative, "+": np.add, "-": np.subtract, "*": np.multiply, "/": np.divide, "^": _power}


def vec_eval(node: tuple, env: Mapping[str, object]) -> np.ndarray:
    """The value of ``node`` with names from ``env`` (floats or broadcastable arrays); NaN where undefined."""
    with np.errstate(all="ignore"):
        find = _expr.lookup(env, np.pi)
        name = lambda n: np.asarray(find(n), dtype=float)  # noqa: E731
        out = np.asarray(_expr.fold(node, float, name, _OPS, _FUNCS), dtype=float)
    return np.where(np.isfinite(out), out, np.nan)
