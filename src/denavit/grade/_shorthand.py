"""Names a derivation defines for itself: ``c_2 = (x² + y² − a₁² − a₂²)/(2 a₁ a₂)`` (an IK intermediate, not the
cosine of θ₂), ``c_{124} = \\cos(\\theta_1 + \\theta_2 - \\theta_4)`` (the SCARA's shorthand with a minus sign: read as
``c_{12-4}`` in the claims that use it, the one just before the definition too: "… where c₁₂₄ = …").
"""

from __future__ import annotations

import re
from typing import Any

from ._context import Context, has_joint_names

__all__ = ["define_name", "rename_recent", "renamed", "SHORTHAND", "TARGET_NAMES", "trig_of_joint", "trig_named"]

SHORTHAND = re.compile(r"[cCsS]_?\{?\d{1,6}\}?")
#: Names of the target's entries in an IK formula (x, y, z, p_x, r_13, n_x …).
TARGET_NAMES = re.compile(r"(?<![A-Za-z\\])(?:[xyz](?![A-Za-z_])|[pP]_\{?[xyz]\}?|r_\{?\d\d\}?|[noa]_\{?[xyz]\}?)")
_TARGET_NAME = re.compile(r"\\(?:var)?phi|\\psi|[xyz]|[pP]_\{?[xyz]\}?|r_\{?\d\d\}?")
_TRIG = re.compile(r"^\s*\\?(cos|sin)\s*(?:\\left)?\s*\((.{1,120})\)\s*(?:\\right\))?\s*$")
_TERM = re.compile(r"([-+]?)\s*(?:\\(?:var)?theta|q)\s*_\s*\{?\s*(\d)\s*\}?")
#: How many lines a definition may follow the claim it explains ("… where c₁₂₄ = …").
RECENT_LINES = 3


def _signed(lhs: str, value: str) -> tuple[str, str] | None:
    """``c_{124} = \\cos(\\theta_1 + \\theta_2 - \\theta_4)`` → ("124", "12-4"): the shorthand's digits and the signed
    form the checker reads; None unless the digits match the joints in order and a sign is not +."""
    m = re.fullmatch(r"\s*([cCsS])_?\{?(\d{2,6})\}?\s*", lhs)
    t = _TRIG.match(value)
    if not m or not t or (m.group(1).lower() == "c") != (t.group(1) == "cos"):
        return None
    terms = _TERM.findall(t.group(2))
    if "".join(d for _, d in terms) != m.group(2) or len(_TERM.sub("", t.group(2)).strip(" +")) > 0:
        return None
    if all(sign in ("", "+") for sign, _ in terms) or terms[0][0] == "-":
        return None
    return m.group(2), "".join(("-" if sign == "-" else "") + d for sign, d in terms)


def renamed(text: str, renames: dict[str, str]) -> str:
    """``text`` with each shorthand ``c_{124}``, ``s_{124}`` (any case) written as its signed form ``c_{12-4}``."""
    for digits, signed in renames.items():
        text = re.sub(r"(?<![A-Za-z\\])([cCsS])_?\{?" + digits + r"\}?(?!\d)", lambda m: f"{m.group(1)}_{{{signed}}}",
                      text)
    return text


def define_name(ctx: Context, sym: Any, lhs: str, value: str, parts: tuple[str, ...], params: set[str]) -> bool:
    """Remember a name the derivation introduces (``D = …``; an IK intermediate ``c_2 = (x² + y² − …)/…`` in the
    target's names; a signed shorthand ``c_{124} = \\cos(θ1 + θ2 − θ4)``).  True for a signed shorthand (the claim
    just before may use it)."""
    signed = _signed(lhs, value)
    if signed is not None:
        ctx.renames[signed[0]] = signed[1]
        return True
    name = re.sub(r"\s+", "", lhs)
    square = re.fullmatch(r"([A-Za-z](?:_\{?\w{1,3}\}?)?)\^\{?2\}?", name)
    if square and not has_joint_names(value) and not _TARGET_NAME.fullmatch(square.group(1)):
        ctx.define(square.group(1), f"\\sqrt{{{value}}}")  # r^2 = x^2 + y^2: r is the distance, its root
        return False
    if _TARGET_NAME.fullmatch(name):  # φ = θ1 + θ2 + θ3, x = …: results; in IK formulas these are the target's
        return False
    intermediate = not has_joint_names(value) and TARGET_NAMES.search(value) is not None  # c_2 = (x² + y² …)/…
    if sym is not None and re.fullmatch(r"[A-Za-z]{1,3}", sym.base) and not sym.pre_sup and not sym.dots \
            and len(parts) == 2 and re.sub(r"[_{}]", "", name) not in params and "\\begin" not in value \
            and (not SHORTHAND.fullmatch(name) or intermediate):
        ctx.define(name, value)
    return False


def _renamed_claim(claim: dict[str, Any], renames: dict[str, str]) -> dict[str, Any]:
    value = claim.get("value")
    return {**claim, "value": renamed(value, renames)} if isinstance(value, str) else claim


def rename_recent(out: list, ctx: Context, line: int) -> None:
    """The claims of the last :data:`RECENT_LINES` lines before ``line`` with the signed shorthands applied."""
    for p in reversed(out):
        if p.line < line - RECENT_LINES:
            break
        if p.claim is None:
            continue
        new = _renamed_claim(p.claim, ctx.renames)
        if new.get("value") != p.claim.get("value"):
            p.claim["value"] = new["value"]  # in place: the claim dict is the Pending's own
            p.understood += f" (the shorthand as line {line} defines it)"
        p.alternatives = [(_renamed_claim(a, ctx.renames), w) for a, w in p.alternatives]
        p.equivalent = [(_renamed_claim(a, ctx.renames), w) for a, w in p.equivalent]


_JOINT = r"(?:\\(?:var)?theta|q)\s*_\s*(?:\{\s*(D)\s*\}|(D))"  # θ_2 or θ_{2}: a brace only in pairs


def _joint_arg(digit: str) -> str:
    """θ_j, q_j, (θ_j), \\left(θ_j\\right): a joint as a trig function's argument (a bracket only when it closes)."""
    one = _JOINT.replace("(D)", digit)
    return r"(?:(?:\\left\s*)?\(\s*" + one + r"\s*(?:\\right\s*)?\)|" + one + ")"


_TRIG_OF_JOINT = re.compile(r"^\s*\\?(cos|sin)\s*" + _joint_arg(r"(\d)") + r"\s*$")


def trig_of_joint(lhs: str) -> tuple[str, int] | None:
    """``\\cos\\theta_2``, ``cos(q_2)``, ``\\sin \\theta_{3}`` → ("cos", 2): the left side of an IK step that
    gives a joint's cosine or sine; None otherwise."""
    m = _TRIG_OF_JOINT.match(lhs)
    return (m.group(1), int(next(g for g in m.groups()[1:] if g))) if m else None


def trig_named(value: str, fn: str, joint: int) -> str:
    """``value`` with the joint's cosine (sine) written as the name ``c_j`` (``s_j``), its square too:
    ``atan2(±sqrt(1 - cos^2\\theta_2), \\cos\\theta_2)`` → ``atan2(±sqrt(1 - c_{2}^2), c_{2})``."""
    pattern = r"(?<![A-Za-z])\\?" + fn + r"\s*(\^\s*\{?\s*2\s*\}?)?\s*" + _joint_arg(str(joint))
    return re.sub(pattern, lambda m: f"{fn[0]}_{{{joint}}}" + ("^2" if m.group(1) else ""), value)
