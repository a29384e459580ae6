"""The symbolic equations of motion as text, LaTeX or Markdown (:func:`format_dynamics`): entries in hand form
written entry by entry, recurring parameter groups and rate coefficients named, common subexpressions pulled out."""

from __future__ import annotations

import re

import sympy as sp

from ._dynamics_types import DynamicsTerms
from ._simplify import shorthand

__all__ = ["format_dynamics", "display_entry", "tex_label", "trim_zeros", "CSE_AUTO_CHARS", "GROUP_NAME_CHARS",
           "LONG_NODES"]

CSE_AUTO_CHARS = 3000  # format_dynamics pulls out common subexpressions above this total length


# ---------------------------------------------------------------------------------------------------
# presentation: text, LaTeX, Markdown, with common subexpressions pulled out


def display_entry(e: sp.Expr, q, digits: int | None, short: bool, collapse: bool = True) -> sp.Expr:
    if digits is not None:
        e = e.xreplace({r: sp.Float(r, digits) for r in e.atoms(sp.Rational) if r.q != 1 and r.q > 12})
    return shorthand(e, q, collapse=collapse) if short else e


_TRAILING = re.compile(r"(?<![\w.])(\d+\.\d*?[1-9])0+(?![\d])|(?<![\w.])(\d+)\.0+(?![\d.e])")


def trim_zeros(text: str) -> str:
    """0.00576000 → 0.00576, 2.00000 → 2 (plain-text output only)."""
    return _TRAILING.sub(lambda m: m.group(1) or m.group(2), text)


LONG_NODES = 200_000  # expression nodes above which format_dynamics prints terms in sympy's internal order


def _size(e: sp.Expr) -> int:
    """Number of nodes of an expression tree (cheap; printing pages of output to measure them is not)."""
    return sum(1 for _ in sp.preorder_traversal(e))


def _is_group(a: sp.Expr, rates) -> bool:
    return isinstance(a, sp.Add) and len(a.args) > 1 and not a.has(sp.sin, sp.cos, *rates)


def _group_key(a: sp.Add) -> tuple[sp.Expr, int]:
    """The group with a canonical sign (its first term, in sympy's order, positive) and that sign."""
    first = sp.Add.make_args(a)[0]
    return (a, 1) if not first.could_extract_minus_sign() else (-a, -1)


def _walk_groups(e: sp.Expr, rates, visit) -> sp.Expr:
    """Rebuild e with every parameter group (a sum of parameter terms, no sines, cosines or rates) passed
    through visit(group) -> replacement; sums containing sines or rates are walked into."""
    if isinstance(e, sp.Add):
        if _is_group(e, rates):
            return visit(e)
        return sp.Add(*[_walk_groups(t, rates, visit) for t in e.args])
    if isinstance(e, sp.Mul):
        return sp.Mul(*[_walk_groups(f, rates, visit) for f in e.args])
    return e


GROUP_NAME_CHARS = 40  # a parameter group longer than this, or occurring twice, is named P1, P2 … by format_dynamics


def _name_groups(exprs: list[sp.Expr], rates) -> tuple[list[tuple[sp.Symbol, sp.Expr]], list[sp.Expr]]:
    """Parameter groups that recur or are long get names P1, P2 … (in order of first use)."""
    count: dict[sp.Expr, int] = {}

    def tally(a):
        key, _ = _group_key(a)
        count[key] = count.get(key, 0) + 1
        return a

    for e in exprs:
        _walk_groups(e, rates, tally)
    names: dict[sp.Expr, sp.Symbol] = {}

    def name(a):
        key, sign = _group_key(a)
        if count[key] < 2 and len(str(key)) <= GROUP_NAME_CHARS:
            return a
        if key not in names:
            names[key] = sp.Symbol(f"P{len(names) + 1}", real=True)
        return sign * names[key]

    out = [_walk_groups(e, rates, name) for e in exprs]
    return [(v, k) for k, v in names.items()], out


def _name_rate_coefficients(exprs: list[sp.Expr], rates) -> tuple[list[tuple[sp.Symbol, sp.Expr]], list[sp.Expr]]:
    """Coefficients of q̇ᵢq̇ⱼ that recur (up to a rational factor, e.g. 2Γ in one row and Γ in another) are named
    B1, B2 … and defined once."""
    def split(e):
        out = []
        for t in sp.Add.make_args(e):
            coeff, mono = t.as_independent(*rates, as_Add=False)
            out.append((coeff, mono))
        return out

    def key(coeff):  # expanded (canonical) when small; long ones compared as built (expanding them costs minutes)
        x = sp.expand(coeff) if _size(coeff) < 3000 else coeff
        lead = sp.Add.make_args(x)[0].as_coeff_Mul()[0]
        return (sp.expand(x / lead) if x is not coeff else x / lead), lead

    count: dict[sp.Expr, int] = {}
    for e in exprs:
        if e.has(*rates):
            for coeff, mono in split(e):
                if mono != 1 and isinstance(coeff, (sp.Add, sp.Mul)) and coeff.has(sp.sin, sp.cos):
                    k, _ = key(coeff)
                    count[k] = count.get(k, 0) + 1
    names: dict[sp.Expr, tuple[sp.Symbol, sp.Expr]] = {}
    out = []
    for e in exprs:
        if not e.has(*rates):
            out.append(e)
            continue
        terms = []
        for coeff, mono in split(e):
            if mono != 1 and isinstance(coeff, (sp.Add, sp.Mul)) and coeff.has(sp.sin, sp.cos):
                k, lead = key(coeff)
                if count[k] > 1:
                    if k not in names:  # defined as it first occurs; later ones are a multiple (2, −1, ½ …)
                        names[k] = (sp.Symbol(f"B{len(names) + 1}", real=True), coeff, lead)
                    sym, _, first = names[k]
                    terms.append(sp.nsimplify(lead / first) * sym * mono)
                    continue
            terms.append(coeff * mono)
        out.append(sp.Add(*terms))
    return [(sym, e) for sym, e, _ in names.values()], out


def format_dynamics(terms: DynamicsTerms, style: str = "text", cse: bool | None = None, short: bool = True,
                    digits: int | None = 6, include: tuple[str, ...] = ("M", "c", "g", "friction"),
                    gravity_symbol: bool = False) -> str:
    """The equations of motion as text, LaTeX or Markdown.

    M is written by its upper triangle (M[j,k], j ≤ k; it is symmetric, as the header says).
    Entries in hand form (``lagrangian_dynamics(simplify="trig")``) are written entry by entry, each a sum
    of parameter groups times sines and cosines; when the entries are long (over ``CSE_AUTO_CHARS``
    characters in all, and ``cse`` is not False) a group that recurs or is longer than ``GROUP_NAME_CHARS``
    is named P1, P2 … (π₁, π₂ … in LaTeX) and defined first. With ``gravity_symbol`` gravity is the symbol
    g (its value in the header; g = |g₀| · g_unit). Other forms: ``cse`` pulls repeated subexpressions out as
    x0, x1, … (``sympy.cse``; ``None``: only when the entries are long). ``short`` writes cos(q1 + q2) as C12
    (LaTeX C_{12}; the Coriolis matrix's entries are \\mathcal{C}_{12}); ``digits``: fractions with
    denominators above 12 are printed as decimals of that many significant digits (trailing zeros dropped
    in text).
    """
    if style not in ("text", "latex", "markdown"):
        raise ValueError(f"unknown style {style!r}; choose one of text, latex, markdown")
    n = len(terms.q)
    hand = terms.form == "hand"
    blocks = {"M": terms.M, "C": terms.C, "c": terms.c, "g": terms.g, "friction": terms.friction}
    notes = []
    G = sp.Symbol("g", positive=True)
    taken = {str(s) for m in (terms.M, terms.g) for s in m.free_symbols}
    if gravity_symbol and terms.g_unit is not None and "g" not in taken and "g" in include:
        blocks["g"] = sp.ImmutableMatrix([G * e for e in terms.g_unit])
        notes.append(f"g = {trim_zeros(sp.sstr(sp.Float(terms.gravity, 6)))} m/s^2 (gravitational acceleration)")
    entries: list[tuple[str, sp.Expr]] = []
    for name in include:
        mat = blocks[name]
        if mat is None:
            continue
        for i in range(mat.shape[0]):
            for j in range(i if name == "M" else 0, mat.shape[1]):  # M is symmetric: its upper triangle
                label = f"{name}[{i + 1},{j + 1}]" if mat.shape[1] > 1 else f"{name}[{i + 1}]"
                entries.append((label, mat[i, j]))
    exprs = [e for _, e in entries]
    repl: list[tuple[sp.Symbol, sp.Expr]] = []
    nodes = sum(_size(e) for e in exprs)
    long = nodes > CSE_AUTO_CHARS or sum(len(str(e)) for e in exprs) > CSE_AUTO_CHARS  # printing only short ones
    grouped = hand and cse is not False and long
    if grouped:
        rates, exprs = _name_rate_coefficients(exprs, terms.qd) if nodes <= LONG_NODES else ([], exprs)
        repl, named = _name_groups([e for _, e in rates] + exprs, terms.qd)
        repl += [(s, e) for (s, _), e in zip(rates, named[:len(rates)])]
        exprs = named[len(rates):]
    show = lambda e: display_entry(e, terms.q, digits, short, collapse=not hand)  # noqa: E731
    repl, exprs = [(s, show(e)) for s, e in repl], [show(e) for e in exprs]
    if not hand:
        if cse is None:
            cse = long
        if cse:
            repl, exprs = sp.cse(exprs, symbols=sp.numbered_symbols("x"), optimizations="basic")
    pairs = [(str(s), e) for s, e in repl] + [(label, e) for (label, _), e in zip(entries, exprs)]
    head = f"M(q) q'' + c(q, q') + g(q) + tau_f(q') = tau   ({n} joints)"
    if "M" in include and n > 1:
        notes.append("M is symmetric: M[k,j] = M[j,k]")
    if short:
        notes.append("Ci = cos(qi), Sij = sin(qi + qj), …")
    order = "none" if nodes > LONG_NODES else None  # sorting the terms of pages of output costs minutes
    if style == "text":
        return "\n".join([head] + [f"  {x}" for x in notes] + [""] +
                         [f"{k} = {trim_zeros(sp.sstr(e, order=order))}" for k, e in pairs])
    names = _latex_names([e for _, e in pairs])
    tex = [(tex_label(k), sp.latex(e, symbol_names=names, order=order)) for k, e in pairs]
    if "M" in include and n > 1:  # the upper triangle is written
        tex.append(("M_{kj}", "M_{jk} \\quad (j < k)"))
    if style == "latex":
        rows = " \\\\\n".join(f"{k} &= {v}" for k, v in tex)
        return "\\begin{aligned}\n" + rows + "\n\\end{aligned}"
    lines = [f"**{head}**", ""] + [f"$${k} = {v}$$" for k, v in tex]
    return "\n\n".join(lines)


def _latex_names(exprs: list[sp.Expr]) -> dict[sp.Symbol, str]:
    """Parameter groups P1 as \\pi_{1}, rate coefficients B1 as \\beta_{1}."""
    greek = {"P": "pi", "B": "beta"}
    return {s: f"\\{greek[s.name[0]]}_{{{s.name[1:]}}}" for e in exprs for s in e.free_symbols
            if s.name[:1] in greek and s.name[1:].isdigit()}


def tex_label(label: str) -> str:
    if "[" not in label:
        if label[:1] in "PB" and label[1:].isdigit():
            return f"\\{'pi' if label[0] == 'P' else 'beta'}_{{{label[1:]}}}"
        return label.replace("x", "x_{", 1) + "}" if label.startswith("x") else label
    name, idx = label[:-1].split("[")
    if name == "friction":  # one subscript: \tau_{f}_{1} is a LaTeX error
        return f"\\tau_{{f,{idx.replace(',', '')}}}"
    if name == "C":  # C_{12} is the shorthand of cos(q1 + q2)
        return f"\\mathcal{{C}}_{{{idx.replace(',', '')}}}"
    return f"{name}_{{{idx.replace(',', '')}}}"
