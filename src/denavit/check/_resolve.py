"""What the names in a person's formulas mean for a given robot.

``\\theta_i``, ``\\vartheta_i``, ``q_i``, ``Q_i`` are joint variable i (``q{i}``); with a dot, its rate
(``qd{i}``), two dots its acceleration (``qdd{i}``).  ``C_{12}``, ``c_1``, ``S_{123}``, ``s12`` are the
cosine/sine of the sum of those joint variables; ``C_{\\theta_1}`` the cosine of the subscript.
``L_1`` is the parameter ``L1``; ``d_3`` is the parameter ``d3`` when the robot has one, else joint 3 when
that joint is prismatic.  A name the robot does not know is an error that lists the known ones.
"""

from __future__ import annotations

import re
from typing import Iterable

from ..errors import ParseError
from ..model import DHRobot, JointType
from ._tokens import Ident

__all__ = ["robot_resolver", "JOINT_BASES"]

JOINT_BASES = ("theta", "vartheta", "q", "Q")
_SHORT = {"C": "cos", "c": "cos", "S": "sin", "s": "sin"}


def _index(sub: str) -> int | None:
    """A subscript that is a (short, ASCII) whole number, as an int; None otherwise (``θ_{111…1}`` too)."""
    return int(sub) if sub.isascii() and sub.isdigit() and len(sub) <= 6 else None


def _joint_sum(digits: str, n: int) -> tuple | None:
    """``"123"`` → q1 + q2 + q3 (single digits when n < 10; ``"1,2"`` style separators allowed); ``"12-4"`` →
    q1 + q2 − q4 (the SCARA's c_{12-4}; a sign stands before one digit)."""
    terms = [("+", p) for p in re.split(r"[,\s]+", digits) if p] if "," in digits else [("+", d) for d in digits]
    if re.fullmatch(r"\d+(?:[-+]\d)+", digits) and n < 10:
        terms = [(sign or "+", d) for sign, d in re.findall(r"([-+]?)(\d)", digits)]
    if not terms or not all((k := _index(p)) is not None and 1 <= k <= n for _, p in terms):
        return None
    node: tuple = ("name", f"q{terms[0][1]}")
    for sign, p in terms[1:]:
        node = ("bin", sign, node, ("name", f"q{p}"))
    return node


def robot_resolver(robot: DHRobot, extra: Iterable[str] = ()):
    """A resolver (see :mod:`denavit.check._tokens`) for the names of ``robot``'s formulas."""
    params = {k for k, _ in robot.parameters}
    n = robot.dof
    extra = set(extra)
    prismatic = {k + 1 for k, t in enumerate(robot.joint_types) if t is JointType.PRISMATIC}

    def known() -> str:
        return ", ".join(sorted(params | extra) + [f"q1..q{n}", "C_12/S_3 shorthand"])

    def resolve(ident: Ident) -> tuple:
        plain = ident.plain
        if ident.dots == 0 and (plain in params or plain in extra):
            return ("name", plain)
        base, sub = ident.base, ident.sub
        if base == "heta":  # "\t" of "\theta" eaten by a text conversion
            base = "theta"
        prefix = {0: "q", 1: "qd", 2: "qdd"}[ident.dots]
        k = _index(sub)
        if base in JOINT_BASES and k is not None and 1 <= k <= n:
            return ("name", f"{prefix}{k}")
        if base in ("qd", "qdd", "dq", "ddq") and k is not None and 1 <= k <= n and ident.dots == 0:
            return ("name", f"{'qd' if base in ('qd', 'dq') else 'qdd'}{k}")
        if base == "d" and k is not None and k in prismatic:
            return ("name", f"{prefix}{k}")
        if base in _SHORT and ident.dots == 0:
            if ident.sub_tree is not None and sub and not re.fullmatch(r"[\d+-]+", sub):
                return ("call", _SHORT[base], (ident.sub_tree,))
            node = _joint_sum(sub, n)
            if node is not None:
                return ("call", _SHORT[base], (node,))
        sub = sub if len(sub) <= 40 else sub[:20] + "…"
        written = base + (f"_{{{sub}}}" if sub else "") if not ident.dots else f"\\dot{{{base}}}_{sub}"
        raise ParseError(f"unknown symbol {written!r}; known: {known()} (a name the derivation introduces is "
                         f"declared with where: {{name: formula}})")

    return resolve
