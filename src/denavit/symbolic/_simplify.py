"""Simplification policies and the compact C/S shorthand display.

Policies are named and explicit: ``"none"`` (as multiplied), ``"trig"`` (expand, then collapse products
of sines and cosines into sines and cosines of angle sums, Fu et al.'s TR10i, which is what a person
writes by hand: cos(q2 + q3), not cos q2 cos q3 − sin q2 sin q3), and ``"full"`` (sympy's ``simplify``).
"""

from __future__ import annotations

from functools import lru_cache
from typing import Callable

import sympy as sp

from ._angle_sums import collapse_angle_sums

__all__ = ["simplify_expr", "simplify_matrix", "shorthand", "POLICIES"]

POLICIES = ("none", "trig", "full")


def _trig(e: sp.Expr) -> sp.Expr:
    if e.is_number or not e.has(sp.sin, sp.cos):
        return sp.factor_terms(sp.expand(e))
    e = sp.expand(e)
    if e.has(sp.Float) and len(sp.Add.make_args(e)) > 24:
        return e  # generic float geometry: pairing dozens of float terms costs minutes and gains little
    e = collapse_angle_sums(e)  # TR10i: c1 c2 − s1 s2 → cos(q1 + q2), repeatedly
    return sp.factor_terms(e)


def simplify_expr(e: sp.Expr, policy: str = "trig") -> sp.Expr:
    """Simplify one expression by a named policy (see module docstring)."""
    if policy == "none":
        return e
    if policy == "trig":
        return _trig(e)
    if policy == "full":
        return sp.simplify(e)
    raise ValueError(f"unknown simplification policy {policy!r}; choose one of {', '.join(POLICIES)}")


def simplify_matrix(M: sp.MatrixBase, policy: str = "trig") -> sp.ImmutableMatrix:
    """Apply :func:`simplify_expr` to every entry."""
    return sp.ImmutableMatrix(M.shape[0], M.shape[1], [simplify_expr(e, policy) for e in M])


def _digits(arg: sp.Expr, qs: dict[sp.Symbol, int]) -> str | None:
    terms = sp.Add.make_args(arg)
    idx = []
    for t in terms:
        if t in qs:
            idx.append(qs[t])
        else:
            return None
    idx.sort()
    return "".join(str(i) for i in idx) if max(idx) < 10 else "_".join(str(i) for i in idx)


def _joint_variables(q) -> tuple[sp.Symbol, ...]:
    """The joint variables q1…qn from a JointSymbols object, a tuple/list of symbols or one symbol."""
    q = getattr(q, "q", q)  # JointSymbols → its q (iterating it would give the (q, qd, qdd) tuples)
    if isinstance(q, sp.Symbol):
        return (q,)
    try:
        qs = tuple(q)
    except TypeError:
        raise TypeError(f"joint variables must be symbols or a JointSymbols object, not {type(q).__name__}") from None
    bad = [s for s in qs if not isinstance(s, sp.Symbol)]
    if bad:
        raise TypeError(f"joint variables must be sympy symbols, got {bad[0]!r}")
    return qs


def shorthand(e: sp.Expr, q, style: str = "C", collapse: bool = True) -> sp.Expr:
    """Replace cos(q1 + q2) by the symbol C12, sin(q3) by S3 (``style="c"`` gives c12, s3).

    ``q`` is the joint variables: a :class:`JointSymbols` object (``joint_symbols(n)``) or a sequence of
    symbols. Products that are angle sums (cos q2 cos q3 − sin q2 sin q3) are collapsed first (Fu's TR10i),
    so the result reads C23, not C2*C3 - S2*S3 (``collapse=False``: atoms replaced only, for entries already
    written in angle sums). For display only: the result uses plain symbols and is not
    meant to be computed with.

    Examples
    --------
    >>> import sympy as sp
    >>> from denavit.symbolic import joint_symbols
    >>> q1, q2 = joint_symbols(2).q
    >>> shorthand(sp.cos(q1) * sp.cos(q2) - sp.sin(q1) * sp.sin(q2) + sp.sin(q2), joint_symbols(2))
    C12 + S2
    """
    qs = _joint_variables(q)
    try:
        hash(e)
    except TypeError:  # not a sympy expression: the same work, not remembered
        return _shorthand.__wrapped__(e, qs, style, collapse)
    return _shorthand(e, qs, style, collapse)


@lru_cache(maxsize=4096)
def _shorthand(e: sp.Expr, q: tuple[sp.Symbol, ...], style: str, collapse: bool) -> sp.Expr:
    """:func:`shorthand` of a hashable ``e``, remembered: a pure function of its arguments, and its TR10i pass
    costs seconds on a 6-joint arm's force propagation, which every report of that arm shows again."""
    qs = {s: i + 1 for i, s in enumerate(q)}
    if collapse and isinstance(e, sp.Basic) and e.has(sp.sin, sp.cos):
        terms = sp.Add.make_args(sp.expand(e))
        if any(isinstance(t, sp.Mul) and len(t.atoms(sp.sin, sp.cos)) > 1 for t in terms) and not (
            e.has(sp.Float) and len(terms) > 24  # same bound as the "trig" policy: float geometry stays as is
        ):
            e = collapse_angle_sums(sp.expand(e))
    cname, sname = ("C", "S") if style == "C" else ("c", "s")
    repl: dict[sp.Expr, sp.Expr] = {}
    for f in e.atoms(sp.cos, sp.sin):
        digits = _digits(f.args[0], qs)
        if digits is not None:
            repl[f] = sp.Symbol(f"{cname if isinstance(f, sp.cos) else sname}{digits}", real=True)
    return e.xreplace(repl)


def shorthand_matrix(M: sp.MatrixBase, q, style: str = "C") -> sp.ImmutableMatrix:
    """:func:`shorthand` applied to every entry of ``M`` (``q``: JointSymbols or a sequence of symbols)."""
    qs = _joint_variables(q)
    return sp.ImmutableMatrix(M.shape[0], M.shape[1], [shorthand(e, qs, style) for e in M])


Simplifier = Callable[[sp.Expr], sp.Expr]
