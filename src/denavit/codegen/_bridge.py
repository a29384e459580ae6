"""The one way a sympy expression of the library becomes a numeric function."""

from __future__ import annotations

__all__ = ["numeric_function"]


def numeric_function(expr, args, modules: str = "numpy"):
    """``f(*values)`` evaluating the sympy expression ``expr`` of the symbols ``args`` with ``modules``
    ("numpy" for arrays, "math" for scalars): :func:`sympy.lambdify`, behind one door.

    Only expressions the library built reach it: a string (which lambdify would parse as Python) is refused,
    so user text can never be turned into code here.  Straight-line kernels of whole arms are made by
    :func:`denavit.compile` instead.
    """
    import sympy as sp

    if not isinstance(expr, (sp.Basic, sp.MatrixBase)):
        raise TypeError(f"numeric_function takes a sympy expression, not {type(expr).__name__}")
    if isinstance(args, sp.Basic):
        args = [args]
    if not all(isinstance(a, sp.Symbol) for a in args):
        raise TypeError("numeric_function's arguments must be sympy symbols")
    return sp.lambdify(list(args), expr, modules)
