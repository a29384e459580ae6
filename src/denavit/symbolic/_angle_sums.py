"""Fu's TR10i (products of sines and cosines → sine or cosine of an angle sum) with its pairs found by lookup.

TR10i (Fu, Zhong and Zeng, "Automated and readable simplification of trigonometric expressions",
Math. Comput. Model. 44 (2006) 1169; sympy ``sympy.simplify.fu.TR10i``) rewrites a sum pairwise::

    k·R·(cos a cos b ∓ sin a sin b) → k·R·cos(a ± b),    k·R·(cos a sin b ± sin a cos b) → k·R·sin(b ± a),
    k·R·(cos a + sin a) → √2·k·R·sin(a + π/4)          (and the √3 : 1 ratios, with π/3 and π/6).

sympy's ``do`` walks the terms in ``ordered`` order and, for each term i, tries every later term j with
``trig_split`` (a factorisation of both terms) until one pairs: O(n²) factorisations a pass, most of them
failing. That is most of the CPU of a 6-joint arm's symbolic force propagation.

Here the same walk is kept (same order, same first partner j, the pair rewritten by sympy's own
``trig_split``, so the output is the same expression), but the candidates j are found by hashing: a pair
that ``trig_split`` accepts has terms whose non-numeric factors differ only by one or two trigonometric
factors swapped for their co-functions (f g ↔ f' g' with cos' = sin, sin' = cos, or f ↔ f'), so each term
is keyed by its non-numeric factors and its partners' keys are computed from its own. Only candidates are
handed to ``trig_split``. Inputs outside the shape this reasoning covers (a sine or cosine inside another
function, a power or a sum, negative or fractional powers of a sine or cosine) go to sympy's TR10i itself.
"""

from __future__ import annotations

from collections import defaultdict
from itertools import combinations

import sympy as sp
from sympy.core.sorting import ordered
from sympy.simplify.fu import TR10i, process_common_addends, trig_split

__all__ = ["collapse_angle_sums"]

_TRIG = (sp.cos, sp.sin)


def collapse_angle_sums(e: sp.Expr) -> sp.Expr:
    """The same expression as ``sympy.simplify.fu.TR10i(e)``, found faster on sums of products of sines,
    cosines and trig-free factors (denavit's kinematic entries); other shapes are handed to TR10i."""
    if not isinstance(e, sp.Expr) or not e.has(*_TRIG):
        return TR10i(e)
    terms = sp.Add.make_args(e)
    keys = [_key(t) for t in terms]
    if any(k is None for k in keys):
        return TR10i(e)
    if not e.is_Add:
        return e  # one product: TR10i rewrites sums only, and there is none below (checked by _key)
    return _top(e)


def _key(t: sp.Expr) -> frozenset | None:
    """The non-numeric factors of a term as a set of (base, exponent); None if TR10i could change a part of
    the term (a sine or cosine inside a sum, a power or another function) or the lookup would not cover it."""
    out = []
    for f in sp.Mul.make_args(t):
        b, x = f.as_base_exp()
        if isinstance(b, _TRIG):  # cos(1) too: trig_split pairs it like cos(q1)
            if not (x.is_Integer and x > 0) or b.args[0].has(*_TRIG):
                return None
        elif f.has(*_TRIG):
            return None
        elif f.is_number:
            continue
        out.append((b, x))
    return frozenset(out)


def _partner_keys(key: frozenset, co: dict) -> list[frozenset]:
    """Keys of the terms that could pair with a term of key ``key``: one trig factor f → f', or two f g → f' g'
    (remembered in ``co`` for the call, with the co-function of each sine and cosine)."""
    out = co.get(key)
    if out is not None:
        return out
    powers = dict(key)
    trig = [b for b in powers if isinstance(b, _TRIG)]
    out = co[key] = []
    for swap in [(f,) for f in trig] + list(combinations(trig, 2)):
        p = dict(powers)
        for f in swap:
            g = co.get(f)
            if g is None:
                g = co[f] = (sp.sin if isinstance(f, sp.cos) else sp.cos)(f.args[0])
            p[f] -= 1
            if not p[f]:
                del p[f]
            p[g] = p.get(g, 0) + 1
        out.append(frozenset(p.items()))
    return out


def _pair(a: sp.Expr, b: sp.Expr, rv: sp.Expr) -> sp.Expr:
    """sympy's TR10i ``do`` on a two-term sum ``rv = a + b`` (``a``, ``b`` in ``ordered`` order)."""
    split = trig_split(a, b, two=True)
    if not split:
        return rv
    gcd, n1, n2, a, b, same = split
    gcd = n1 * gcd
    if same:  # coscos, sinsin
        return gcd * sp.cos(a - b) if n1 == n2 else gcd * sp.cos(a + b)
    return gcd * sp.sin(a + b) if n1 == n2 else gcd * sp.sin(b - a)


def _do(rv: sp.Expr, co: dict) -> sp.Expr:
    """TR10i's greedy pass: for each term in ``ordered`` order, the first later free term it pairs with;
    repeated while anything paired. Candidates come from the key lookup instead of all later terms, and a sum
    in which no term has a candidate is returned as it is (TR10i would try every pair and return it too)."""
    if not rv.is_Add:
        return rv
    keys = {a: _key(a) for a in rv.args}
    index = defaultdict(list)
    for a, k in keys.items():
        index[k].append(a)
    if None not in index and not any(p in index for k in index for p in _partner_keys(k, co)):
        return rv
    args = list(ordered(rv.args))
    if len(args) == 2:
        return _pair(args[0], args[1], rv)
    pos = {a: i for i, a in enumerate(args)}
    hit = False
    for i, a in enumerate(list(args)):
        if args[i] is None:
            continue
        if keys[a] is None:  # not covered by the lookup: every later term, as sympy does
            cands = range(i + 1, len(args))
        else:
            near = [b for k in _partner_keys(keys[a], co) + [None] for b in index.get(k, ())]
            cands = sorted({pos[b] for b in near if pos[b] > i})
        for j in cands:
            if args[j] is None:
                continue
            was = args[i] + args[j]
            new = _do(was, co)
            if new != was:
                args[i], args[j], hit = new, None, True
                break
    if hit:
        rv = sp.Add(*[f for f in args if f])
        if rv.is_Add:
            rv = _do(rv, co)
    return rv


def _top(rv: sp.Expr) -> sp.Expr:
    """TR10i's rule on one sum: pairs within groups of equal |coefficient| and free symbols, then the
    √3 : 1 radical pairs, then the greedy pass over all terms (sympy ``fu.TR10i.f``, step for step)."""
    co: dict = {}
    # groups keyed by frozenset(free symbols): the same groups, in the same order, as sympy's ordered tuple
    rv = process_common_addends(rv, lambda x: _do(x, co), lambda x: frozenset(x.free_symbols))
    root3 = sp.sqrt(3)
    while rv.is_Add:
        byrad = defaultdict(list)
        for a in rv.args:
            rad = next((f for f in a.args if f.is_Pow and f.exp is sp.S.Half and f.base.is_Integer), None) \
                if a.is_Mul else None
            byrad[rad if rad is not None else sp.S.One].append(a)
        args = []
        for a in byrad:
            for b in [root3 * a, 1 / root3]:  # sympy's list, the second item as written there
                if b in byrad:
                    _radical_pairs(byrad[a], byrad[b], args, co)
        if args:
            rv = sp.Add(*(args + [sp.Add(*[f for f in v if f]) for v in byrad.values()]))
        else:
            rv = _do(rv, co)
            break
    return rv


def _radical_pairs(la: list, lb: list, out: list, co: dict) -> None:
    """Pair terms of ``la`` with terms of ``lb`` (TR10i's √3 : 1 step), consuming both in place."""
    for i in range(len(la)):
        if la[i] is None:
            continue
        for j in range(len(lb)):
            if lb[j] is None:
                continue
            was = sp.Add(la[i] + lb[j])
            new = _do(was, co)
            if new != was:
                out.append(new)
                la[i] = lb[j] = None
                break
