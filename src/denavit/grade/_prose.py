"""Results and givens stated in words: "singular when θ₂ = 0 or π", "Case 1: θ1 = 60°, d2 = 0.5 m, d3 = 0.3 m".

Only plain text outside ``$…$`` is read here (the mathematics is read as equations); Unicode subscripts and Greek
letters are taken as their LaTeX names.  Every pattern is linear in the line.
"""

from __future__ import annotations

import re

from ..model import DHRobot

__all__ = ["plain_prose", "prose_conditions", "prose_case", "prose_wrench", "prose_definitions"]

_SUBSCRIPTS = str.maketrans("₀₁₂₃₄₅₆₇₈₉", "0123456789")
_INLINE = re.compile(r"\$[^$]{0,2000}\$")
_JOINT = r"(?:θ|ϑ|theta|q|Q|(d))\s?_?\{?(\d)\}?"
_CONDITION = re.compile(_JOINT + r"\s?=\s?((?:[-+]?\s?(?:\d+(?:\.\d+)?|π|pi)(?:\s?(?:°|deg|π|pi|/\s?\d))*"
                        r"(?:\s?(?:,|or|and)\s?)?){1,6})")
_VALUE = re.compile(r"(?:θ|ϑ|theta|q|Q|d)\s?_?\{?(\d)\}?\s?=\s?(-?\d+(?:\.\d+)?)\s?(°|deg|rad|mm|cm|m)?")


def plain_prose(text: str) -> str:
    """The words of a prose line, its inline mathematics removed, subscripts as digits."""
    return _INLINE.sub(" ", text).translate(_SUBSCRIPTS)


def _latex_value(v: str) -> str:
    v = re.sub(r"\s?(?:or|and)\s?", ", ", v.strip().rstrip(",").strip())
    v = v.replace("π", "\\pi").replace("°", "^\\circ")
    return re.sub(r"(?<![a-z\\])pi", "\\\\pi", re.sub(r"\bdeg\b", "^\\\\circ", v)).strip(", ")


def prose_conditions(plain: str, robot: DHRobot) -> list[str]:
    """Singular values of one joint written in words: ``q_2 = 0, \\pi`` for "θ₂ = 0 or π"."""
    out = []
    for m in _CONDITION.finditer(plain):
        k = int(m.group(2))
        value = _latex_value(m.group(3))
        if m.group(1) and not (1 <= k <= robot.dof and robot.joint_types[k - 1].value == "prismatic"):
            continue  # d_k is a joint only when joint k slides
        if 1 <= k <= robot.dof and value:
            out.append(f"q_{k} = {value}")
    return out


def prose_case(plain: str, robot: DHRobot) -> str | None:
    """A case's joint values written in words (every joint once), as the checker's q reader takes them."""
    seen: dict[int, str] = {}
    for m in _VALUE.finditer(plain):
        k, num, unit = int(m.group(1)), m.group(2), m.group(3) or ""
        if not 1 <= k <= robot.dof or k in seen:
            return None
        scale = {"mm": "*0.001", "cm": "*0.01"}.get(unit, "")
        seen[k] = num + ("^\\circ" if unit in ("°", "deg") else "") + scale
    if len(seen) != robot.dof:
        return None
    return "(" + ", ".join(seen[k] for k in sorted(seen)) + ")"


_WRENCH = re.compile(r"\bF\s?=\s?\(([-+\d.,\s]{1,200})\)")


def prose_wrench(plain: str) -> str | None:
    """``F = (0, 10, -5) N`` in words: the wrench's numbers (3 or 6; 2 are a force in the plane, f_z = 0), as the
    checker reads them."""
    m = _WRENCH.search(plain)
    if m is None:
        return None
    items = [x.strip() for x in m.group(1).split(",") if x.strip()]
    if len(items) not in (2, 3, 6) or not all(re.fullmatch(r"[-+]?\d+(?:\.\d+)?", x) for x in items):
        return None
    return "[" + ", ".join(items + ["0"] * (len(items) == 2)) + "]"  # (f_x, f_y): a planar force


_DEFINITION = re.compile(r"\b([a-zA-Z]_[a-z0-9]{1,2})\s?=\s?([A-Za-z0-9_^*/+\- ().]{3,120}?)(?=,\s|;|\.\s|\.$|$|\sand\s|\sis\s)")


def prose_definitions(plain: str) -> list[tuple[str, str]]:
    """Names a text defines in words: "the wrist centre is x_c = p_x - d_6 r_13, y_c = …" (formulas, not numbers)."""
    out = []
    for m in _DEFINITION.finditer(plain):
        value = m.group(2).strip()
        if re.search(r"[A-Za-z]", value) and re.search(r"[-+*/]", value):
            out.append((m.group(1), value))
    return out
