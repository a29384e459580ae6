"""The chain's constants as sympy (imported on use: this module imports sympy).

Parameter symbols and exact numbers follow :mod:`denavit.symbolic`: a field the robot file wrote with named
parameters (``d: H1``) becomes that expression of real symbols; any other value the simplest exact number
it equals (``pi/2``, ``3/4``), else a Float.  With ``numeric`` the parameters' values are put in as exact
rationals.
"""

from __future__ import annotations

import sympy as sp

from .. import _expr
from ..model import Convention, DHLink

__all__ = ["dh_matrix_sym", "row_constants_sym", "constants_sym"]


def dh_matrix_sym(convention: Convention, a, alpha, d, theta) -> sp.ImmutableMatrix:
    """The DH link transform of one row, symbolic.

    standard (Spong eq. 3.10): Rz(θ) Tz(d) Tx(a) Rx(α); modified (Craig eq. 3.6): Rx(α) Tx(a) Rz(θ) Tz(d).
    """
    ct, st, ca, sa = sp.cos(theta), sp.sin(theta), sp.cos(alpha), sp.sin(alpha)
    if Convention(convention) is Convention.STANDARD:
        rows = [[ct, -st * ca, st * sa, a * ct], [st, ct * ca, -ct * sa, a * st], [0, sa, ca, d], [0, 0, 0, 1]]
    else:
        rows = [[ct, -st, 0, a], [st * ca, ct * ca, -sa, -sa * d], [st * sa, ct * sa, ca, ca * d], [0, 0, 0, 1]]
    return sp.ImmutableMatrix(rows)


def _field(link: DHLink, field: str, syms: dict[str, sp.Symbol]) -> sp.Expr:
    from ..symbolic import exact_or_float  # (denavit.symbolic imports this module: names taken on use)

    text = dict(link.symbols).get(field)
    if text is None:
        return exact_or_float(getattr(link, field))
    return _expr.to_sympy(_expr.parse(text), syms)


def row_constants_sym(chain, numeric: bool) -> tuple[dict, ...]:
    """Each row's constant (a, alpha, d, theta) as sympy (see module notes)."""
    from ..symbolic import parameter_symbols

    syms = parameter_symbols(chain)  # uses only .parameters
    values = {syms[k]: sp.Rational(repr(v)) for k, v in chain.parameters}
    out = []
    for link in chain.links:
        row = {f: _field(link, f, syms) for f in ("a", "alpha", "d", "theta")}
        if numeric:
            row = {f: e.subs(values) for f, e in row.items()}
        out.append(row)
    return tuple(out)


def constants_sym(chain, numeric: bool) -> tuple[sp.ImmutableMatrix, ...]:
    """C_0 … C_n with exact entries (the numeric :attr:`Chain.constants` in sympy)."""
    from ..symbolic import matrix_from_floats

    out, C = [], sp.Matrix(matrix_from_floats(chain.base))
    for row, r in zip(chain.rows, chain.rows_sym(numeric)):
        D = dh_matrix_sym(chain.convention, r["a"], r["alpha"], r["d"], r["theta"])
        if row.joint < 0:
            C = C * D
        elif chain.standard:
            out.append(C)
            C = sp.Matrix(D)
        else:
            out.append(C * D)
            C = sp.eye(4)
    out.append(C * matrix_from_floats(chain.tool))
    return tuple(sp.ImmutableMatrix(sp.Matrix(M).applyfunc(sp.expand)) for M in out)
