"""Reading a claim of singular configurations: conditions on one joint's values (``q_2 = 0, \\pi``, ``q_3 = k\\pi``) or
equations (``\\sin\\theta_2 = 0``), or the special claims ``none`` / ``everywhere`` (:mod:`._singular` judges them).
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from .. import _expr
from ..errors import ParseError
from ._latex import parse_math
from ._resolve import robot_resolver
from ._text import expand_pm, split_relation, split_top
from ._tokens import MAX_CHARS
from ._zero_sets import Arm

__all__ = ["Cond", "read_conditions", "MAX_KPI_DIVISOR", "MAX_VALUES", "MAX_CONDITIONS"]

#: Largest n in ``q_j = k\pi/n`` (each of its 2n values is tested).
MAX_KPI_DIVISOR = 12
#: Most values of one joint in one claim (``q_2 = 0, \pi, …``), all conditions together.
MAX_VALUES = 64
#: Most conditions (values of a joint, or equations) in one claim.
MAX_CONDITIONS = 16
_NONE = {"none", "never", "nowhere", "no singularities", "\\emptyset", "∅", "{}"}
_ALL = {"all", "always", "everywhere", "every configuration", "all q", "any q"}
_SEPS = (";", "\n", " or ", "\\lor", "\\vee", "\\text{or}", "\\text{ or }", "\\quad", "\\qquad")
_KPI = re.compile(r"^\s*(?:[kn]|\d*[kn])\s*(?:\\pi|π|pi)\s*(?:/\s*(\d+))?\s*$")


@dataclass
class Cond:
    """One claimed condition: ``values`` of joint ``var`` (0-based), or the zero set of ``node``."""

    text: str
    var: int | None = None
    values: list[float] = field(default_factory=list)
    node: tuple | None = None
    decimals: int = 0
    scale: float = 1.0


def _decimals(node: tuple) -> int:
    from ._values import decimals as dec

    return dec(node)


def _pieces(raw: Any) -> list[str]:
    items = [str(x) for x in raw] if isinstance(raw, list) else [str(raw)]
    if len(items) > MAX_CONDITIONS or sum(len(x) for x in items) > MAX_CHARS:
        raise ParseError(f"too many conditions, or longer than {MAX_CHARS} characters in all (at most "
                         f"{MAX_CONDITIONS} conditions)")
    out = []
    for item in items:
        for part in split_top(item.strip().strip("$"), _SEPS):
            segs = split_top(part, (",",))
            if sum("=" in s for s in segs) <= 1:
                out.append(part)
                continue
            for s in segs:  # "q2 = 0, q5 = 0": one condition per '='; values without '=' continue the last
                if "=" in s or not out:
                    out.append(s)
                else:
                    out[-1] += "," + s
    return [p.strip() for p in out if p.strip()]


def _values(rhs: str, resolve, env: dict, rev: bool) -> tuple[list[float], int] | None:
    """``0, \\pi, \\pm\\pi/2`` or ``k\\pi`` → numbers (None if a value depends on the joints)."""
    vals, dec = [], 0
    items = split_top(rhs, (",",))
    if len(items) > MAX_VALUES:
        raise ParseError(f"too many values in {rhs[:40]!r} ({len(items)}; at most {MAX_VALUES})")
    for item in items:
        m = _KPI.match(item)
        if m and rev:
            digits = m.group(1) or "1"
            d = int(digits) if len(digits) <= 6 else MAX_KPI_DIVISOR + 1
            if not 1 <= d <= MAX_KPI_DIVISOR:
                raise ParseError(f"k\\pi/{digits[:12]}: the divisor must be from 1 to {MAX_KPI_DIVISOR} "
                                 "(list the values instead)")
            vals += [k * np.pi / d for k in range(-d + 1, d + 1)]
            continue
        for (version,) in expand_pm([item]):
            node = parse_math(version, resolve, rhs=False)
            if any(n.startswith("q") for n in _expr.names_in(node)):
                return None
            vals.append(_expr.evaluate(node, env))
            dec = max(dec, _decimals(node))
    return vals, dec


def read_conditions(raw: Any, arm: Arm) -> tuple[list[Cond], str | None]:
    """The claimed conditions, or a special claim (``"none"`` / ``"everywhere"``)."""
    resolve = robot_resolver(arm.robot)
    pieces = _pieces(raw)
    if len(pieces) == 1 and pieces[0].lower().strip(". ") in _NONE | _ALL:
        return [], "none" if pieces[0].lower().strip(". ") in _NONE else "everywhere"
    if not pieces:
        raise ParseError("no singular condition given (write 'none' if there is none)")
    if len(pieces) > MAX_CONDITIONS:
        raise ParseError(f"too many conditions in one claim ({len(pieces)}; at most {MAX_CONDITIONS})")
    conds = []
    for text in pieces:
        lhs, rhs = split_relation(text)
        left = parse_math(lhs, resolve, rhs=False)
        if left[0] == "name" and left[1].startswith("q") and left[1][1:].isdigit():
            j = int(left[1][1:]) - 1
            got = _values(rhs, resolve, arm.params, bool(arm.rev[j]))
            if got is not None:
                conds.append(Cond(text, var=j, values=got[0], decimals=got[1]))
                continue
        for (version,) in expand_pm([rhs]):
            node = ("bin", "-", left, parse_math(version, resolve, rhs=False))
            if not any(n.startswith("q") for n in _expr.names_in(node)):
                raise ParseError(f"condition {text!r} names no joint variable")
            conds.append(Cond(text, node=node, decimals=_decimals(node)))
    if len(conds) > MAX_CONDITIONS or sum(len(c.values) for c in conds) > MAX_VALUES:
        raise ParseError(f"too many conditions or values in one claim (at most {MAX_CONDITIONS} conditions and "
                         f"{MAX_VALUES} joint values)")
    return conds, None
