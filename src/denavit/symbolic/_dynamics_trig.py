"""A canonical, fast trigonometric form for dynamics terms: a Fourier polynomial in the joint angles.

Entries of M, C and g are polynomials in cos q_i, sin q_i.  Products are turned into sums
(cos A cos B = ½[cos(A−B) + cos(A+B)], …), so every entry becomes

    Σ_k a_k cos(k·q) + b_k sin(k·q),   k an integer vector, first non-zero entry positive,

with coefficients in the parameters.  This is a canonical form (equal expressions print equally), it
collapses c2·c23 + s2·s23 into cos q3 exactly as one does by hand, and it costs a polynomial expansion
instead of a pattern search (sympy's TR10i), which is what keeps the Puma 560 within seconds.
"""

from __future__ import annotations

from collections import defaultdict

import sympy as sp

__all__ = ["fourier_form"]

Freq = tuple[int, ...]


def _normalize(k: Freq) -> tuple[Freq, int]:
    """(k', s) with cos(k·q) = cos(k'·q) and sin(k·q) = s·sin(k'·q), k' first non-zero entry positive."""
    for x in k:
        if x:
            return (k, 1) if x > 0 else (tuple(-y for y in k), -1)
    return k, 1


def _mul(series: dict, factor_cos: bool, i: int, n: int) -> dict:
    """Multiply a series {(k, 'c'|'s'): coeff} by cos q_i (factor_cos) or sin q_i."""
    out: dict = defaultdict(lambda: sp.Integer(0))
    e = tuple(1 if j == i else 0 for j in range(n))
    for (k, kind), a in series.items():
        plus = tuple(x + y for x, y in zip(k, e))
        minus = tuple(x - y for x, y in zip(k, e))
        half = a / 2
        for freq, sign_term in ((plus, 1), (minus, -1)):
            kk, s = _normalize(freq)
            if factor_cos:  # cos A cos B = ½cos(A−B) + ½cos(A+B); sin A cos B = ½sin(A+B) + ½sin(A−B)
                out[kk, kind] += half * (s if kind == "s" else 1)
            elif kind == "c":  # cos A sin B = ½sin(A+B) − ½sin(A−B)
                out[kk, "s"] += half * sign_term * s
            else:  # sin A sin B = ½cos(A−B) − ½cos(A+B)
                out[kk, "c"] += -half * sign_term
    return out


def fourier_form(expr: sp.Expr, q: tuple[sp.Symbol, ...], revolute: tuple[bool, ...] | None = None) -> sp.Expr:
    """``expr`` as a Fourier polynomial in the revolute joint angles (see module notes).

    Prismatic joint variables and parameters stay in the coefficients.
    """
    angles = [s for s, r in zip(q, revolute or (True,) * len(q)) if r]
    if not angles or not expr.has(*angles):
        return sp.factor_terms(sp.expand(expr))
    e = sp.expand(sp.expand_trig(expr))
    C = sp.symbols(f"_c0:{len(angles)}")
    S = sp.symbols(f"_s0:{len(angles)}")
    repl = {}
    for f in e.atoms(sp.cos, sp.sin):
        if f.args[0] in angles:
            i = angles.index(f.args[0])
            repl[f] = C[i] if isinstance(f, sp.cos) else S[i]
        elif f.has(*angles):
            return sp.factor_terms(e)  # an argument we cannot split (e.g. q1*q2): leave it
    e = e.xreplace(repl)
    if e.has(*angles):
        return sp.factor_terms(e.xreplace({v: k for k, v in repl.items()}))
    n = len(angles)
    total: dict = defaultdict(lambda: sp.Integer(0))
    for monom, coeff in sp.Poly(e, *C, *S).terms():
        series: dict = {((0,) * n, "c"): sp.Integer(1)}
        for i in range(n):
            for _ in range(monom[i]):
                series = _mul(series, True, i, n)
            for _ in range(monom[n + i]):
                series = _mul(series, False, i, n)
        for key, a in series.items():
            total[key] += coeff * a
    terms = []
    for (k, kind), a in sorted(total.items(), key=lambda kv: (sum(map(abs, kv[0][0])), kv[0][0], kv[0][1])):
        a = sp.factor_terms(sp.expand(a))
        if a == 0:
            continue
        arg = sum((ki * s for ki, s in zip(k, angles)), sp.Integer(0))
        if kind == "s" and arg == 0:
            continue
        terms.append(a * (sp.cos(arg) if kind == "c" else sp.sin(arg)))
    return sp.Add(*terms)


def collect_trig(expr: sp.Expr) -> sp.Expr:
    """Collect a sum of Fourier-form terms on its sine/cosine factors (cheap; no product-to-sum needed).

    Used for derivatives and sums of entries already in :func:`fourier_form`, whose terms carry at most
    one sine or cosine each.
    """
    groups: dict = defaultdict(list)
    for t in sp.Add.make_args(sp.expand(expr)):
        trig, rest = [], []
        for f in sp.Mul.make_args(t):
            (trig if isinstance(f, (sp.cos, sp.sin)) else rest).append(f)
        groups[sp.Mul(*trig)].append(sp.Mul(*rest))
    return sp.Add(*[sp.factor_terms(sp.Add(*v)) * k for k, v in groups.items()])
