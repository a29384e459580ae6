"""The target of a report's inverse kinematics, stated in words, and the joint values that answer it.

"The tool must reach $x = 1.2$, $y = 0.9$ with orientation $\\phi = 60^\\circ$" sets a target; joint values
given after it ("$\\theta_1 = -19.4^\\circ$, $\\theta_2 = 108.9^\\circ$, …") are a claimed solution, judged by
the checker's ``ik_solutions`` (FK of the values reaches the target, to the decimals written; the other solutions
are named, not required).  The target is the pose whose position is (x, y, z) and whose rotation is a turn φ
about the base's z axis: a planar arm's heading, as the textbooks state it.
"""

from __future__ import annotations

import math
import re
from typing import Any

from ._context import Context, is_numeric, vector_entries
from ._lhs import read_symbol
from ._names import joint_of
from ._shorthand import TARGET_NAMES
from ._values import cells, matrices

__all__ = ["IK_HEADING", "prose_target", "is_target_part", "solution_claim", "target_words", "matrix_target", "case_solution",
           "slide_formula"]

_WORDS = re.compile(r"\b(?:reach(?:es|ed)?|target|desired|goal|move[sd]? to|placed? at|must be at)\b", re.I)
_POSE_WORDS = re.compile(r"\b(?:given|following|this)\s+(?:end[- ]effector\s+|tool\s+)?(?:pose|transform(?:ation)?)\b",
                         re.I)
#: A heading about inverse kinematics: coordinates its prose states are the target, without words of a target.
IK_HEADING = re.compile(r"inverse\s+kinematics|\bIK\b|inverse\s+position", re.I)
#: Lines a target matrix may follow the words that announce it.
TARGET_REACH = 6
_NUMBER = r"(-?\s?\d+(?:\.\d+)?)\s*(\^\s*\{?\\circ\}?|°)?"
_COORD = re.compile(r"\$\s*(x|y|z|p_\{?[xyz]\}?|\\phi|\\varphi|\\psi)\s*=\s*" + _NUMBER + r"\s*\$")


def prose_target(text: str, dof: int, ik_section: bool = False) -> str | None:
    """The target pose (a 4×4 matrix as text for the checker) a paragraph states, or None: it needs words of a
    target (or a heading about inverse kinematics: ``ik_section``) and at least as many numbers (x, y, z, φ) as the
    arm has joints."""
    if not (_WORDS.search(text) or ik_section):
        return None
    found: dict[str, float] = {}
    for m in _COORD.finditer(text):
        key = re.sub(r"[^a-z]", "", m.group(1).replace("p_", "")) or m.group(1)
        key = "phi" if key in ("phi", "varphi", "psi") else key[-1]
        value = float(m.group(2).replace(" ", ""))
        found[key] = math.radians(value) if m.group(3) or key == "phi" and abs(value) > 2 * math.pi else value
    if len(found) < dof or not {"x", "y"} <= set(found):
        return None
    c, s = math.cos(found.get("phi", 0.0)), math.sin(found.get("phi", 0.0))
    rows = [[c, -s, 0.0, found["x"]], [s, c, 0.0, found["y"]], [0.0, 0.0, 1.0, found.get("z", 0.0)], [0, 0, 0, 1]]
    return "[" + "; ".join(", ".join(repr(float(v)) for v in r) for r in rows) + "]"


def target_words(text: str) -> bool:
    """Words that announce a target: "the desired pose", "must reach", "the given end-effector pose"."""
    return bool(_WORDS.search(text) or _POSE_WORDS.search(text))


def matrix_target(ctx: Context, parts: tuple[str, ...], line: int) -> str | None:
    """``T = [4×4 of numbers]`` within :data:`TARGET_REACH` lines after words of a target: the target (the matrix
    as written, for the checker), else None.  A pose's name on the left (``T``, ``T_6^0``, ``{}^0T_6``,
    ``T_{d}``), numbers only (fractions, √, π), the bottom row 0 0 0 1."""
    if not ctx.target_words_line or not 0 <= line - ctx.target_words_line <= TARGET_REACH or len(parts) != 2:
        return None
    sym = read_symbol(parts[0])
    mats = matrices(parts[1])
    if sym is None or sym.base not in ("T", "H") or sym.dots or mats is None or len(mats) != 1:
        return None
    rows = cells(mats[0])
    if len(rows) != 4 or any(len(r) != 4 for r in rows) or not all(is_numeric(c) for r in rows for c in r):
        return None
    if [c.replace(" ", "") for c in rows[3]] not in (["0", "0", "0", "1"], ["0", "0", "0", "1.0"]):
        return None
    return mats[0]


def case_solution(ctx: Context, value: str) -> dict[str, Any] | None:
    """A whole q (``q = (…)``) after a target: the ``ik_solutions`` claim of that one solution, else None."""
    entries = vector_entries(value)
    if ctx.target is None or not entries:
        return None
    return solution_claim(ctx, {k: f"q_{k} = {e}" for k, e in enumerate(entries, start=1)})


def is_target_part(ctx: Context, line: int, lhs: str) -> bool:
    """``x = 1.2`` on the line that stated the target: a given, not the end effector's x claimed."""
    return ctx.target is not None and ctx.target_line == line and _COORD.fullmatch(f"$ {lhs} = 0 $") is not None


def solution_claim(ctx: Context, partial: dict[int, str]) -> dict[str, Any]:
    """The ``ik_solutions`` claim of joint values given after a target: one solution, the others not required."""
    deg = any(re.search(r"\\circ|°", v) for v in partial.values())
    values = [re.sub(r"\^\s*\{?\\circ\}?|°", "", partial[k].split("=", 1)[1]).strip() for k in sorted(partial)]
    return {"quantity": "ik_solutions", "T": ctx.target, "value": [values], "complete": False, "deg": deg}


def slide_formula(sym: Any, robot: Any, value: str) -> bool:
    """``d_3 = d_1 - d_4 - z``: a prismatic joint's IK formula (the target's names, no inverse function needed)."""
    k = joint_of(sym, robot) if sym is not None else None
    return k is not None and robot.joint_types[k - 1].value == "prismatic" and TARGET_NAMES.search(value) is not None
