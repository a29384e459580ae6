"""``relation`` claims: a textbook relation between the arm's vectors and matrices, such as ``\\tau = J^T F``,
``v = J_v \\dot q`` or the column rule ``J_i = [z_{i-1} \\times (p - p_{i-1}); z_{i-1}]``.

Both sides are read by a small restricted reader of matrix expressions (:mod:`denavit.check._relation_reader`;
nothing reaches ``eval`` or sympy) and evaluated with numpy at random joint values, rates and a random wrench; the
relation is correct when the sides are equal there.  Names (world axes, the numeric engine's values):

- ``J`` the geometric Jacobian J0 (6×n, rows v, ω); ``J_v``, ``J_\\omega`` (``J_w``) its rows; ``J_i`` its column i;
- ``\\dot q`` / ``\\dot\\theta`` the joint rates; ``v``, ``\\omega`` the end effector's velocity and angular velocity;
- ``F`` the wrench (6: f then n) the end effector exerts, ``f``, ``n`` its parts; ``\\tau`` the joint torques Jᵀ F;
- ``z_k``, ``p_k`` the z axis and origin of DH frame k (``k`` a number, ``i``, ``i-1`` or ``i+1``); ``p``, ``p_e``,
  ``p_n`` the end-effector position.

Operators: ``+ -``, a product written by juxtaposition or ``\\cdot`` (matrix product, or scalar times matrix),
``\\times`` (cross product of 3-vectors), ``^T`` / ``^{T}`` / ``^\\top``, ``^{-1}``, ``^{-T}``; ``\\begin{bmatrix}``
(cells ``&``, rows ``\\\\``) or ``[a; b]`` stack blocks.  A relation that names ``i`` is checked for every joint
(``joints: revolute`` / ``prismatic`` / ``all``; default: every revolute joint when the relation has a cross
product, else all).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ..errors import ParseError
from ..model import DHRobot, JointType
from ._relation_reader import RelationEnv, RelationReader, SizeMismatch, Undefined
from ._text import split_top
from ._tokens import MAX_CHARS, tokenize

__all__ = ["check_relation", "N_RELATION_POINTS"]

#: Random (q, q̇, F) at which a relation is evaluated.
N_RELATION_POINTS = 4


def _joints(robot: DHRobot, raw: Any, text: str) -> list[int | None]:
    which = str(raw.get("joints", "default"))
    if which not in ("default", "revolute", "prismatic", "all"):
        raise ParseError(f"'joints' must be revolute, prismatic or all; got {which[:40]!r}")
    uses_i = any(k == "word" and s == "i" for k, s in tokenize(text))
    if not uses_i:
        return [None]
    if which == "default":
        which = "revolute" if "\\times" in text or "×" in text else "all"
    types = robot.joint_types
    pick = [k + 1 for k, t in enumerate(types)
            if which == "all" or (t is JointType.REVOLUTE) == (which == "revolute")]
    if not pick:
        raise ParseError(f"the arm has no {which} joints for this relation")
    return pick


def check_relation(robot: DHRobot, raw: dict[str, Any], cid: str, rng: np.random.Generator, deg: bool):
    """The verdict on a claimed relation (see the module notes)."""
    from ._engine import Verdict

    text = str(raw["value"]).strip().strip("$").replace(";", " \\\\ ")  # [a; b]: rows
    if len(text) > MAX_CHARS:
        raise ParseError(f"relation longer than {MAX_CHARS} characters")
    sides = [s for s in split_top(text, ("=",))]
    if len(sides) < 2 or any(not s.strip() for s in sides):
        raise ParseError("a relation is 'left = right' (both sides written)")
    side_tokens = [tokenize(s) for s in sides]
    joints = _joints(robot, raw, text)
    lo, hi = robot.q_limits.T
    lo, hi = np.maximum(np.where(np.isfinite(lo), lo, -np.pi), -np.pi), np.minimum(np.where(np.isfinite(hi), hi, np.pi), np.pi)
    method = (f"both sides evaluated at {N_RELATION_POINTS} random (q, q̇, F)"
              + (f" for joint(s) {', '.join(map(str, joints))}" if joints != [None] else "") + " with the numeric engine")
    checked = 0
    for _ in range(N_RELATION_POINTS):
        q, qd, F = rng.uniform(lo, hi), rng.normal(size=robot.dof), rng.normal(size=6)
        for i in joints:
            env = RelationEnv(robot, q, qd, F, i)
            values = []
            try:
                with np.errstate(all="ignore"):
                    for toks in side_tokens:
                        reader = RelationReader(toks, env)
                        values.append(reader.expr())
                        if reader.peek() is not None:
                            raise ParseError(f"unexpected {reader.peek()[1][:20]!r} in the relation")
                if not all(np.all(np.isfinite(x)) for x in values):
                    raise ParseError("the relation's values are not finite (an overflow or a division by zero)")
            except Undefined:
                continue
            except SizeMismatch as exc:
                return Verdict(cid, "relation", "incorrect", f"incorrect: shape: {exc}", method=method)
            checked += 1
            first = values[0]
            for k, other in enumerate(values[1:], start=2):
                if first.shape != other.shape:
                    return Verdict(cid, "relation", "incorrect", f"incorrect: shape: side 1 is {first.shape[0]}×"
                                   f"{first.shape[1]}, side {k} is {other.shape[0]}×{other.shape[1]}", method=method)
                bad = np.abs(first - other) > 1e-9 * np.maximum(1.0, np.abs(first))
                if bad.any():
                    where = f" for joint {i}" if i is not None else ""
                    cex = {"q": q.tolist(), "qd": qd.tolist(), "wrench": F.tolist()}
                    if i is not None:
                        cex["joint"] = i
                    entries = tuple({"entry": [int(r) + 1, int(c) + 1], "claimed": float(other[r, c]),
                                     "expected": float(first[r, c])} for r, c in zip(*np.nonzero(bad)))
                    return Verdict(cid, "relation", "incorrect",
                                   f"incorrect: the sides differ{where} (side 1 and side {k}, "
                                   f"{len(entries)} entr{'y' if len(entries) == 1 else 'ies'})",
                                   entries[:12], cex, _relation_hints(robot, text), None, method)
    if checked == 0:
        raise ParseError("the relation names no frame or column of this arm (check the subscripts)")
    return Verdict(cid, "relation", "correct", "correct: the sides agree", method=method)


def _relation_hints(robot: DHRobot, text: str) -> tuple[str, ...]:
    from ..model import Convention

    if "i-1" in text.replace(" ", "") and robot.convention is Convention.MODIFIED:
        return ("in modified DH joint i moves about z_i through p_i (not z_{i-1}, p_{i-1})",)
    if "i-1" not in text.replace(" ", "") and "_i" in text and robot.convention is Convention.STANDARD:
        return ("in standard DH joint i moves about z_{i-1} through p_{i-1}",)
    return ()
