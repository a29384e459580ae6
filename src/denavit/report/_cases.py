"""Several numeric cases in one report: the inputs read into cases, and one section per case merged into one.

A section is built once per case (the symbolic results are shared, so only the numeric work is repeated).
The steps every case has in common at the start (the derivation: formulas, the route's rule) are written
once; then each case follows under its heading ("Case 2: q = (…)") with its own numbers and checks.
"""

from __future__ import annotations

from typing import Any, Sequence

import numpy as np

from ..errors import ParseError
from ._derivation import MAX_CASES, Equation, Heading, Numbers, Section, Text

__all__ = ["CASE_TOPICS", "case_list", "merge_cases", "case_label"]

#: Sections written once per numeric case (the others do not depend on q; figures show the first case).
CASE_TOPICS = ("case", "jacobian", "velocity", "statics", "singularities", "ik", "dynamics")

_KEYS = ("q", "qd", "wrench")


def case_list(q: Any, qd: Any, wrench: Any, cases: Sequence[Any] | None) -> list[dict[str, Any]]:
    """The numeric cases of a report as mappings with keys q, qd, wrench (None where not given)."""
    if cases is None:
        return [{"q": q, "qd": qd, "wrench": wrench}]
    if q is not None or qd is not None or wrench is not None:
        raise ParseError("give either q/qd/wrench or cases, not both")
    if isinstance(cases, (str, bytes, dict)) or not hasattr(cases, "__len__"):
        raise ParseError("cases: expected a list of mappings with 'q' (and 'qd', 'wrench')")
    if not 1 <= len(cases) <= MAX_CASES:
        raise ParseError(f"cases: {len(cases)} given; a report takes 1 to {MAX_CASES} numeric cases")
    out = []
    for k, c in enumerate(cases, start=1):
        if not isinstance(c, dict):
            raise ParseError(f"case {k}: expected a mapping with 'q' (and 'qd', 'wrench')")
        unknown = [str(key)[:40] for key in c if key not in _KEYS]
        if unknown:
            raise ParseError(f"case {k}: unknown key {unknown[0]!r}; a case has q, qd, wrench")
        out.append({key: c.get(key) for key in _KEYS})
    return out


def case_label(k: int, ctx: Any, rates: bool = True, wrench: bool = True) -> str:
    """``Case k: $q = (…)$``, with the rates and the wrench when the case has them (and they are asked for)."""
    from ._sections import latex

    text = f"Case {k}: $q = ({', '.join(latex(v) for v in ctx.q_exact)})$"
    if rates and ctx.qd_exact is not None:
        text += f", $\\dot q = ({', '.join(latex(v) for v in ctx.qd_exact)})$"
    if wrench and ctx.wrench_exact is not None:
        text += f", $F = ({', '.join(latex(v) for v in ctx.wrench_exact)})$"
    return text


def _same(a: Any, b: Any) -> bool:
    """Two steps say the same thing (numbers compared entry by entry, formulas structurally)."""
    if type(a) is not type(b):
        return False
    if isinstance(a, Numbers):
        va, vb = np.asarray(a.values), np.asarray(b.values)
        return ((a.lhs, a.note, a.digits) == (b.lhs, b.note, b.digits) and va.shape == vb.shape
                and bool(np.array_equal(va, vb)))
    if isinstance(a, Equation):
        if (a.lhs, a.relation, a.note, a.shorthand) != (b.lhs, b.relation, b.note, b.shorthand):
            return False
        if isinstance(a.expr, str) or isinstance(b.expr, str):
            return a.expr == b.expr
        return bool(a.expr == b.expr)  # structural equality of two sympy objects
    return a == b


def _is_formula(step: Any) -> bool:
    """An equation in symbols (q, q̇, parameters …), or one given as LaTeX text (the IK derivation's)."""
    return isinstance(step, Equation) and (isinstance(step.expr, str) or bool(getattr(step.expr, "free_symbols", ())))


def _drop_repeated_formulas(tail: Sequence[Any], first_tail: Sequence[Any]) -> list:
    """A later case's steps without the formulas (in q, q̇, …) that case 1 already shows at the same place, nor
    the sentence introducing them; one line says so.  Numbers and checks stay."""
    same = [k < len(first_tail) and _same(st, first_tail[k]) for k, st in enumerate(tail)]
    drop = [same[k] and _is_formula(st) for k, st in enumerate(tail)]
    for k in range(len(tail) - 2, -1, -1):  # shared sentences that only introduce dropped formulas go too
        if same[k] and isinstance(tail[k], Text) and drop[k + 1]:
            drop[k] = True
    out: list = []
    for k, st in enumerate(tail):
        if not drop[k]:
            out.append(st)
        elif not out or out[-1] != _AS_CASE_1:
            out.append(_AS_CASE_1)
    return out


_AS_CASE_1 = Text("The formulas are those written for case 1; at this case:")


def merge_cases(sections: list[Section], ctxs: list[Any]) -> Section:
    """One section from the same section built at each case: the common opening once, then each case."""
    first = sections[0]
    n = min(len(s.steps) for s in sections)
    common = 0
    while common < n and all(_same(first.steps[common], s.steps[common]) for s in sections[1:]):
        common += 1
    if common == n and all(len(s.steps) == n and s.status == first.status for s in sections):
        return first  # nothing depends on the case (a skipped section, say)
    steps: list = list(first.steps[:common])
    rates = len({c.qd_exact for c in ctxs}) > 1  # the rates and the wrench are named when they vary by case
    wrench = len({c.wrench_exact for c in ctxs}) > 1
    for k, (s, ctx) in enumerate(zip(sections, ctxs), start=1):
        steps.append(Heading(case_label(k, ctx, rates, wrench)))
        if s.status != "done":
            word = "Not available" if s.status == "unavailable" else "Skipped"
            steps.append(Text(f"{word} for this case: {s.reason}."))
        steps += s.steps[common:] if k == 1 else _drop_repeated_formulas(s.steps[common:], first.steps[common:])
    done = [s for s in sections if s.status == "done"]
    if done:
        return Section(first.key, first.title, tuple(steps))
    return Section(first.key, first.title, tuple(steps), status=first.status, reason=first.reason)
