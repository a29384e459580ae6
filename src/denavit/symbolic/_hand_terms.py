"""Ring elements written as a person writes them: Σ (parameter group) × (sines and cosines), angle differences
within a group of parallel axes collapsed (C₂C₂₃ + S₂S₂₃ → C₃). The presentation step of
:mod:`~denavit.symbolic._dynamics_ring` and :mod:`~denavit.symbolic._regressor`."""

from __future__ import annotations

import sympy as sp

from ._rings import TrigRing

__all__ = ["hand_terms"]


def _pair_angles(rg: TrigRing, terms: dict) -> dict:
    """Collapse pairs of terms into the sine or cosine of an angle difference, within a group of parallel axes:
    X (c_a c_b + s_a s_b) → X cos(φ_b − φ_a) (C₂C₂₃ + S₂S₂₃ → C₃), X (s_a c_b − c_a s_b) → X sin(φ_a − φ_b).

    ``terms`` maps (parameter exponents, trig exponents, extra atoms) to coefficients; extra atoms are the
    new sines and cosines (sympy)."""
    m = len(rg.sums)
    S, C = (lambda a: a), (lambda a: m + a)
    pairs = [(a, b) for a in range(m) for b in range(m) if a != b and rg.sums[a][0] == rg.sums[b][0]]
    if not pairs:
        return terms

    def moved(t, minus, plus):
        t = list(t)
        for i in minus:
            t[i] -= 1
        for i in plus:
            t[i] += 1
        return tuple(t)

    changed = True
    while changed:
        changed = False
        for (pm, tm, extra), coeff in list(terms.items()):
            if (pm, tm, extra) not in terms:
                continue
            for a, b in pairs:
                patterns = []
                if a < b and tm[C(a)] and tm[C(b)]:  # c_a c_b + s_a s_b
                    patterns.append(((C(a), C(b)), (S(a), S(b)), 1, sp.cos(rg.angles[b] - rg.angles[a])))
                if tm[S(a)] and tm[C(b)]:  # s_a c_b − c_a s_b
                    patterns.append(((S(a), C(b)), (C(a), S(b)), -1, sp.sin(rg.angles[a] - rg.angles[b])))
                for minus, plus, sign, atom in patterns:
                    partner = (pm, moved(tm, minus, plus), extra)
                    if terms.get(partner) == sign * coeff:
                        del terms[pm, tm, extra], terms[partner]
                        key = (pm, moved(tm, minus, ()), tuple(sorted(extra + (atom,), key=sp.default_sort_key)))
                        terms[key] = terms.get(key, 0) + coeff
                        if not terms[key]:
                            del terms[key]
                        changed = True
                        break
                if changed:
                    break
            if changed:
                break
    return terms


def hand_terms(rg: TrigRing, poly) -> sp.Expr:
    """A ring element as Σ (parameter group) × (sines and cosines): angle differences within a group of
    parallel axes collapsed (:func:`_pair_angles`), terms collected on the trigonometric part (constant
    first), each group with its rational content and common parameter monomial taken out."""
    if not poly:
        return sp.Integer(0)
    ntrig = len(rg.trig_gens)
    k0 = len(rg.gens) - ntrig
    # constants: algebraic ones (√3) stay exact, transcendental ones (cos 0.7) become numbers
    syms = [s.xreplace(rg.back) for s in rg.R.symbols[:k0]]
    syms = [x.evalf(15) if x.is_number and not x.is_algebraic else x for x in syms]
    trig_atoms = [rg.trig_of(g) for g in rg.trig_gens]
    to_sympy = rg.R.domain.to_sympy
    terms = _pair_angles(rg, {(monom[:k0], monom[k0:], ()): to_sympy(coeff) for monom, coeff in poly.terms()})
    groups: dict[tuple, list] = {}
    for (pm, tm, extra), coeff in terms.items():
        groups.setdefault((tm, extra), []).append((pm, coeff))
    out = []
    for key in sorted(groups, key=lambda k: (sum(k[0]) + len(k[1]), k[0], [str(x) for x in k[1]])):
        items = groups[key]
        low = [min(m[i] for m, _ in items) for i in range(k0)]
        nums = [cf for _, cf in items]
        content = sp.gcd_list(nums) if len(nums) > 1 else nums[0]
        if len(nums) > 1 and (content.q > 4 or content.p > 1000) and not all(x.is_Integer for x in nums):
            content = sp.Integer(1)  # decimal data: 0.1465 a2 + 0.0791, not 8.0e-9 (18312500 a2 + 9887500)
        if len(nums) > 1 and all(x < 0 for x in nums):
            content = -content
        common = content * sp.Mul(*[x ** e for x, e in zip(syms, low) if e])
        rest = sp.Add(*[(x / content) * sp.Mul(*[v ** (e - l) for v, e, l in zip(syms, m, low) if e - l])
                        for (m, _), x in zip(items, nums)])
        tm, extra = key
        trig = sp.Mul(*[a ** e for a, e in zip(trig_atoms, tm) if e], *extra)
        out.append(sp.Mul(common, rest, trig))
    return sp.Add(*out)
