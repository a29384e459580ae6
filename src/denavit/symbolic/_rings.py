"""Kinematic expressions as polynomials in a sparse ring: the fast algebra behind singularities and dynamics.

Every entry of a link matrix, a Jacobian, M(q) or g(q) is a polynomial in sines and cosines of joint angles,
the prismatic joint variables and the named parameters. :class:`TrigRing` writes such expressions in
``QQ[parameters, constants, prismatic q, s_1, c_1, …]`` (``sympy.polys.rings``: sparse dict polynomials,
two to three orders of magnitude faster than expression trees for products, sums and determinants).

* The angle variables may be *sums* of joint angles: with φ₂ = q₂, φ₃ = q₂ + q₃ (two parallel axes) the
  rotation of link 3 comes out as cos φ₃, i.e. C₂₃, the way it is written by hand; cos q₃ is rewritten as
  cos(φ₃ − φ₂) = c₃c₂ + s₃s₂ when it enters.
* Reduction modulo sᵢ² + cᵢ² − 1 (a Gröbner basis in lex order, s before c) gives the unique normal form:
  equal functions give equal polynomials, zero is zero.
* Constants that are not rational (√3/2 from a 60° twist, a float twist cos 0.7) are carried as extra
  generators, never expanded through trigonometric identities; algebraic ones keep their minimal
  polynomial among the relations (r² − 3 = 0), floats stay generic. They are put back by :meth:`to_expr`.
"""

from __future__ import annotations

from typing import Iterable, Sequence

import sympy as sp

__all__ = ["TrigRing", "FLOAT_PAIR_TOL"]

FLOAT_PAIR_TOL = 1e-12  # two floats x, y with |x² + y² − 1| below this are taken as cos and sin of one angle


class TrigRing:
    """QQ[parameters, constants, prismatic q, s_1, c_1, …] for expressions in joint variables ``q``.

    Parameters
    ----------
    exprs : expressions whose parameters and constants the ring must hold (e.g. all link-matrix entries)
    q : the joint symbols q1…qn
    sums : one tuple of 0-based joint indices per angle variable (φ = Σ q over it); default one per revolute
        joint given in ``revolute`` (φᵢ = qᵢ)
    revolute : indices of the revolute joints (default all)
    """

    def __init__(self, exprs: Iterable[sp.Expr], q: Sequence[sp.Symbol], sums: Sequence[tuple[int, ...]] | None = None,
                 revolute: Sequence[int] | None = None, tag: str = "") -> None:
        from sympy.polys.domains import QQ
        from sympy.polys.rings import ring

        self.q = tuple(q)
        revolute = tuple(range(len(q))) if revolute is None else tuple(revolute)
        self.sums = [tuple(s) for s in (sums if sums is not None else [(i,) for i in revolute])]
        m = len(self.sums)
        self.s = sp.symbols(f"_s{tag}_0:{m}")
        self.c = sp.symbols(f"_c{tag}_0:{m}")
        self.angles = [sp.Add(*[self.q[i] for i in s]) for s in self.sums]
        self._subs = self._joint_trig()
        exprs = list(exprs)
        self._floats = self._float_map(exprs)
        consts: set[sp.Expr] = set()
        params: set[sp.Symbol] = set()
        for e in exprs:
            x = self._trig_vars(e, strict=False)
            consts |= {a for a in x.atoms(sp.Float, sp.Pow, sp.sin, sp.cos, sp.NumberSymbol, sp.exp)
                       if a.is_number and not a.is_Rational}
            params |= {a for a in x.free_symbols if a not in self.s and a not in self.c}
        params -= set(self._pair_dummy.values())
        consts = {a for a in consts if not any(a != b and a.has(b) for b in consts)}  # outermost only
        self.konst = {a: sp.Dummy(f"k{i}") for i, a in enumerate(sorted(consts, key=sp.default_sort_key))}
        self.konst.update(self._pair_dummy)  # cos α, sin α of a float twist: one generator each, ± its sign
        self.back = {v: k for k, v in self.konst.items()}
        gens = sorted(params, key=str) + list(self.konst.values()) + list(self.s) + list(self.c)
        self.R, *self.gens = ring(gens, QQ)
        self.const_relations = [self.R(sp.minimal_polynomial(a, d)) for a, d in self.konst.items()
                                if not a.has(sp.Float) and a.is_algebraic]
        self.const_relations += [self.R(self.konst[x] ** 2 + self.konst[y] ** 2 - 1) for x, y in self._pairs
                                 if x in self.konst and y in self.konst]
        # cos r and sin r of one constant angle (a twist of 0.7 rad written exactly as 7/10): r² + s² = 1
        self.const_relations += [self.R(self.konst[a] ** 2 + self.konst[sp.sin(a.args[0])] ** 2 - 1)
                                 for a in self.konst if isinstance(a, sp.cos) and sp.sin(a.args[0]) in self.konst]
        self.relations = self.const_relations + [self.R(si ** 2 + ci ** 2 - 1) for si, ci in zip(self.s, self.c)]
        self._exprs = exprs
        self.trig_gens = self.gens[len(self.gens) - 2 * m:]

    # --- conversion --------------------------------------------------------------------------------

    def _joint_trig(self) -> dict[sp.Expr, sp.Expr]:
        """cos qᵢ, sin qᵢ in the angle variables: φ_a alone, or φ_a − φ_b when sums[a] = sums[b] + (i,)."""
        out: dict[sp.Expr, sp.Expr] = {}
        index = {s: a for a, s in enumerate(self.sums)}
        for a, s in enumerate(self.sums):
            i = s[-1]
            if sp.cos(self.q[i]) in out:
                continue
            if len(s) == 1:
                out[sp.cos(self.q[i])], out[sp.sin(self.q[i])] = self.c[a], self.s[a]
            elif s[:-1] in index:
                b = index[s[:-1]]
                out[sp.cos(self.q[i])] = self.c[a] * self.c[b] + self.s[a] * self.s[b]
                out[sp.sin(self.q[i])] = self.s[a] * self.c[b] - self.c[a] * self.s[b]
        return out

    def _float_map(self, exprs) -> dict[sp.Float, sp.Expr]:
        """Floats (a generic twist's cos 0.7 = 0.7648…): pairs x, y with x² + y² = 1 (to 1e-12) become the
        cosine and sine of one constant angle, generators with the relation x² + y² − 1 (so RᵀR = I holds
        exactly and terms cancel); other floats become exact rationals of their decimal text."""
        floats = sorted({abs(f) for e in exprs for f in sp.sympify(e).atoms(sp.Float)}, key=float)  # safe: the engine's own expressions (ints → Integer), never text
        paired: dict[sp.Float, sp.Float] = {}
        for i, x in enumerate(floats):
            for y in floats[i:]:
                if x not in paired and y not in paired and abs(float(x) ** 2 + float(y) ** 2 - 1) < FLOAT_PAIR_TOL:
                    paired[x], paired[y] = y, x
        self._pairs = list({tuple(sorted((x, y), key=float)) for x, y in paired.items()})
        # a paired float and its negative are one generator with a sign (−sin α is −k, not a second constant
        # unrelated to k: that left a generic-twist 6R's determinant without cancellations for minutes)
        self._pair_dummy = {a: sp.Dummy(f"f{i}") for i, a in enumerate(sorted(paired, key=float))}
        out: dict[sp.Float, sp.Expr] = {}
        for e in exprs:
            for f in sp.sympify(e).atoms(sp.Float):  # safe: the engine's own expressions, never text
                a = abs(f)
                val = self._pair_dummy[a] if a in paired else sp.Rational(repr(float(a)))
                out[f] = val if f >= 0 else -val
        return out

    def _trig_vars(self, e: sp.Expr, strict: bool = True) -> sp.Expr:
        x = sp.expand(sp.expand_trig(sp.sympify(e)))  # safe: the engine's own expressions, never text
        if self._floats:
            x = sp.expand(x.xreplace({f: self._floats.get(f, f) for f in x.atoms(sp.Float)}))
        x = x.xreplace(self._subs)
        left = [f for f in x.atoms(sp.sin, sp.cos) if f.has(*self.q)]
        if left and not strict:  # scanning for parameters and constants only
            return x.xreplace({f: sp.Integer(1) for f in left})
        if left:
            raise ValueError(f"internal: {left[0]} has no angle variable in this ring")  # pragma: no cover
        return sp.expand(x)

    def elements(self) -> list:
        """The expressions given at construction, as ring elements."""
        return [self.element(e) for e in self._exprs]

    def element(self, e: sp.Expr):
        """One more expression (its parameters and constants must already be in the ring)."""
        return self.R(self._trig_vars(e).xreplace(self.konst))

    def reduce(self, p):
        """Normal form modulo sᵢ² + cᵢ² = 1 (and the constants' minimal polynomials)."""
        return p.rem(self.relations)

    def to_expr(self, p, trig: bool = True) -> sp.Expr:
        """The ring element as a sympy expression (constants put back; s, c as sin φ, cos φ when ``trig``)."""
        e = p.as_expr().xreplace(self.back)
        if not trig:
            return e
        return e.xreplace({ci: sp.cos(a) for ci, a in zip(self.c, self.angles)}).xreplace(
            {si: sp.sin(a) for si, a in zip(self.s, self.angles)})

    def trig_of(self, gen) -> sp.Expr:
        """sin φ / cos φ of a trigonometric generator (a ring generator)."""
        k = self.gens.index(gen)
        sym = self.R.symbols[k]
        if sym in self.s:
            return sp.sin(self.angles[self.s.index(sym)])
        return sp.cos(self.angles[self.c.index(sym)])

    # --- calculus ------------------------------------------------------------------------------------

    def diff_joint(self, p, i: int):
        """∂p/∂qᵢ (revolute joint i): Σ over the angle variables containing qᵢ of cₐ ∂/∂sₐ − sₐ ∂/∂cₐ."""
        out = self.R.zero
        for a, s in enumerate(self.sums):
            if i in s:
                sa, ca = self.gens[len(self.gens) - 2 * len(self.sums) + a], self.gens[len(self.gens) - len(self.sums) + a]
                out += ca * p.diff(sa) - sa * p.diff(ca)
        return out

    def gen_of(self, sym: sp.Symbol):
        """The ring generator of a parameter or prismatic joint symbol (None if absent)."""
        try:
            return self.gens[self.R.symbols.index(sym)]
        except ValueError:
            return None
