"""Claims about inverse kinematics: a formula for one joint (here), or the solutions for one target
(:mod:`._ik_solutions`).

``ik_formula``: ``q_1 = \\operatorname{atan2}(p_y, p_x)``, with optional ``where`` definitions evaluated in order
(``D: (p_x^2 + p_y^2 - L_1^2 - L_2^2)/(2 L_1 L_2)``), ± signs or σ_k = ±1 for branches, and the other joints
allowed on the right (a formula for q2 that uses q3).  The target names are the entries of the pose of the last DH
frame in {0}, ``T_0_N = B⁻¹ T E⁻¹`` (as in :func:`denavit.symbolic.ik_derivation`; ``pose: world`` for the
end-effector pose): ``r_{ij}``, ``p_x p_y p_z`` (also ``n_x … a_z`` for the columns, ``x y z`` and the heading
``\\phi = atan2(r_21, r_11)``).  The formula is correct when, at random reachable targets, every value it gives
(for every sign) is the joint's value in an IK solution that agrees with the joints it uses.  Solution sets come
from :func:`denavit.ik.analytic_ik` (inside and outside the limits); a value not in that set is still
accepted if Gauss–Newton with that joint held fixed reaches the target (so a gap in the solver cannot reject a
correct formula).

``ik_solutions``: a list of q for the target given by ``q`` (its pose) or ``T``.  Each must satisfy FK = T on the
rows the arm controls (to the decimals written, propagated through J), and every closed-form solution within the
limits must be listed (missing ones are named with their branch labels).
"""

from __future__ import annotations

import itertools
import re
from typing import Any

import numpy as np

from .. import _expr
from .. import numeric as N
from ..errors import ParseError
from ..ik import analytic_ik, characteristic_length, ik_structure
from ..model import DHRobot, JointType
from ._ik_targets import (MATCH_TOL, NUMERIC_STARTS, POSE_COLUMNS, controlled_rows, free_joints, joint_distance,
                          numeric_solutions, reaches, revolute_mask, target_env)
from ._latex import parse_math
from ._resolve import robot_resolver
from ._text import MAX_SIGN_COMBOS, expand_pm, split_relation
from ._tokens import MAX_CHARS
from ._vectorized import vec_eval

__all__ = ["check_ik_formula", "N_TARGETS", "MAX_WHERE"]

N_TARGETS = 6
#: Most definitions in an ik_formula's 'where'.
MAX_WHERE = 20
_TARGET = [f"r{i}{j}" for i in range(1, 4) for j in range(1, 4)] + ["px", "py", "pz"]


# --- ik_formula ------------------------------------------------------------------------------------------


def _read_formula(robot: DHRobot, raw: dict[str, Any]):
    """(joint index, [(where nodes, rhs node) per ± choice], sign names, names used)."""
    where = raw.get("where") or {}
    if not isinstance(where, dict):
        raise ParseError("'where' must be a mapping of names to formulas, in evaluation order")
    if len(where) > MAX_WHERE:
        raise ParseError(f"'where' has {len(where)} definitions; at most {MAX_WHERE}")
    value = str(raw["value"]).strip().strip("$")
    if len(value) + sum(len(str(v)) for v in where.values()) > MAX_CHARS:
        raise ParseError(f"the formula and its 'where' are longer than {MAX_CHARS} characters")
    joint = raw.get("joint")
    if joint is not None and (isinstance(joint, bool) or not isinstance(joint, int) or not 1 <= joint <= robot.dof):
        raise ParseError(f"'joint' must be an integer from 1 to {robot.dof}, got {str(joint)[:40]!r}")
    inverse = None  # cos q_k = …: the formula gives cos q_k (both q_k = ±acos(…) are claimed)
    if "=" in value:
        lhs, rhs = split_relation(value)
        node, inverse = _joint_side(robot, lhs)
        if node is None:  # written the other way round: atan2(…) = q_1
            node, inverse = _joint_side(robot, rhs)
            lhs, rhs = rhs, lhs
        if node is None:
            raise ParseError(f"one side of {value[:60]!r} must be one joint variable (q_k or \\theta_k), or its "
                             "cos / sin / tan")
        value = rhs
        j = int(node[1][1:])
        if joint is not None and joint != j:
            raise ParseError(f"'joint: {joint}' disagrees with the formula's left side (joint {j})")
        joint = j
    if joint is None or isinstance(joint, bool) or not isinstance(joint, int) or not 1 <= joint <= robot.dof:
        raise ParseError(f"say which joint the formula gives: 'q_k = …' or 'joint: k' (1 to {robot.dof})")
    names = [re.sub(r"[^A-Za-z0-9]", "", str(k)) for k in where]  # x_c, x_{c}, \\delta → xc, delta
    if any(not n or n[0].isdigit() for n in names):
        raise ParseError(f"'where' names must start with a letter, got {list(where)}")
    signs = [f"sigma{k}" for k in range(1, 10)] + ["sigma"]
    resolve = robot_resolver(robot, extra=_TARGET + ["Px", "Py", "Pz", "phi", "x", "y", "z"]
                             + [f"{c}{a}" for c in POSE_COLUMNS for a in "xyz"] + names + signs)
    texts = [str(where[k]) for k in where] + [value]
    versions = []
    for version in expand_pm(texts):
        nodes = []
        for name, text in zip(names + ["value"], version):
            try:
                nodes.append(parse_math(text, resolve, rhs=False))
            except ParseError as exc:
                raise ParseError(f"{'where ' + name if name != 'value' else 'formula'}: {exc}") from None
        if inverse is None:
            versions.append((nodes[:-1], nodes[-1]))
        else:  # every angle with that cosine / sine / tangent
            x = nodes[-1]
            pi = ("name", "pi")
            alts = {"cos": [("call", "acos", (x,)), ("neg", ("call", "acos", (x,)))],
                    "sin": [("call", "asin", (x,)), ("bin", "-", pi, ("call", "asin", (x,)))],
                    "tan": [("call", "atan", (x,)), ("bin", "+", ("call", "atan", (x,)), pi)]}[inverse]
            versions += [(nodes[:-1], a) for a in alts]
    used: set[str] = set()
    for ws, v in versions:
        for nd in ws + [v]:
            used |= _expr.names_in(nd)
    used_signs = sorted(s for s in signs if s in used)
    if len(versions) * 2 ** len(used_signs) > MAX_SIGN_COMBOS:
        raise ParseError("too many sign combinations")
    return joint - 1, names, versions, used_signs, used


def _joint_side(robot: DHRobot, text: str) -> tuple[tuple | None, str | None]:
    """(``("name", "qk")``, None) for ``q_k``; (…, "cos") for ``\\cos q_k`` (also sin, tan); else (None, None)."""
    try:
        node = parse_math(text, robot_resolver(robot), rhs=False)
    except ParseError:
        return None, None
    fn = None
    if node[0] == "call" and node[1] in ("cos", "sin", "tan") and len(node[2]) == 1:
        fn, node = node[1], node[2][0]
    if node[0] == "name" and node[1].startswith("q") and node[1][1:].isdigit():
        return node, fn
    return None, None


def _formula_values(names, versions, used_signs, env: dict) -> np.ndarray:
    """All values of the formula over ± choices and σ = ±1 (NaN where undefined)."""
    out = []
    for ws, v in versions:
        for sg in itertools.product((1.0, -1.0), repeat=len(used_signs)):
            e = {**env, **dict(zip(used_signs, sg))}
            for name, node in zip(names, ws):
                e[name] = float(vec_eval(node, e))
            out.append(float(vec_eval(v, e)))
    return np.array(out)


def _targets(robot: DHRobot, rng: np.random.Generator, count: int, numeric: bool = False):
    """(q_gen, T, analytic result) for random reachable, well-conditioned targets (``numeric``: the solutions by
    Gauss–Newton from many starts, for an arm of at most 3 joints without a closed form)."""
    length = characteristic_length(robot)
    length = 1.0 if length <= 1e-3 else length  # no fixed length at all (a polar RP arm): prismatic joints over ±1 m
    ranges = robot.sampling_ranges(length)  # ±L for a prismatic joint without limits
    turn = np.where([t is JointType.REVOLUTE for t in robot.joint_types], np.pi, np.inf)  # one turn (it repeats)
    lo, hi = np.maximum(ranges[:, 0], -turn), np.minimum(ranges[:, 1], turn)
    out = []
    for _ in range(count * 4):
        q = rng.uniform(lo, hi)
        T = N.forward_kinematics(robot, q)
        res = numeric_solutions(robot, T, q, rng.uniform(lo, hi, (NUMERIC_STARTS, robot.dof))) if numeric \
            else analytic_ik(robot, T)
        J = N.geometric_jacobian(robot, q)[controlled_rows(res)]
        s = np.linalg.svd(J, compute_uv=False)
        if s[-1] > 1e-3 * s[0]:
            out.append((q, T, res))
        if len(out) == count:
            break
    return out


def _solution_set(robot: DHRobot, res: Any) -> tuple[np.ndarray, list[str]]:
    sols = np.asarray(res.solutions, dtype=float).reshape(-1, robot.dof)
    outside = np.asarray(res.outside_limits, dtype=float).reshape(-1, robot.dof)
    return np.concatenate([sols, outside]), list(res.free) + [""] * len(outside)


def _decimals_of(nodes) -> int:
    from ._values import decimals

    return max((decimals(nd) for nd in nodes), default=0)


def _formula_hint(robot: DHRobot, j: int, v: float, s_j: float) -> str | None:
    rev = bool(revolute_mask(robot)[j])
    wrap = (lambda x: (x + np.pi) % (2 * np.pi) - np.pi) if rev else (lambda x: x)
    for other, text in ((-s_j, "the opposite sign (a sign slip)"),
                        (s_j + np.pi, "π away: atan instead of atan2, or both atan2 arguments with the wrong sign"),
                        (np.pi / 2 - s_j, "π/2 − q: the two atan2 arguments swapped"),
                        (s_j + np.pi / 2, "π/2 away: a DH angle offset missing or added"),
                        (s_j - np.pi / 2, "π/2 away: a DH angle offset missing or added")):
        if abs(wrap(v - other)) < 1e-6 and (rev or other is not s_j + np.pi):
            return f"it gives q{j + 1} = {v:.6g}, {text} (a solution has q{j + 1} = {s_j:.6g})"
    return None


_POSITION_NAMES = {"px", "py", "pz", "Px", "Py", "Pz", "x", "y", "z"}


def wrist_offset(robot: DHRobot) -> np.ndarray | None:
    """The point where the last three joint axes meet, in the last DH frame (None if they do not meet there).

    For an arm with a spherical wrist this is the wrist centre P of the kinematic decoupling; its position in
    {0} is ``T_0_N @ [offset, 1]`` for every target.
    """
    if robot.dof < 3:
        return None
    q = np.linspace(0.3, 1.1, robot.dof)
    F = N.link_transforms(robot, q)
    z, o = N.joint_axes(robot, F)
    z, o = z[-3:], o[-3:]
    A = sum(np.eye(3) - np.outer(d, d) for d in z)
    b = sum((np.eye(3) - np.outer(d, d)) @ c for d, c in zip(z, o))
    if np.linalg.matrix_rank(A, tol=1e-9) < 3:
        return None
    c = np.linalg.solve(A, b)
    if max(np.linalg.norm((np.eye(3) - np.outer(d, d)) @ (c - p)) for d, p in zip(z, o)) > 1e-9:
        return None
    T0N = np.linalg.solve(np.asarray(robot.base_matrix, dtype=float), F[-1])
    local = np.linalg.solve(T0N, np.append(np.linalg.solve(np.asarray(robot.base_matrix, dtype=float),
                                                           np.append(c, 1.0))[:3], 1.0))[:3]
    return None if np.linalg.norm(local) < 1e-12 else local


def check_ik_formula(robot: DHRobot, raw: dict[str, Any], cid: str, rng: np.random.Generator, deg: bool):
    """The verdict on a formula for one joint of the inverse kinematics (see the module notes).

    ``p_x p_y p_z`` mean the origin of the last DH frame (the flange) unless the claim says ``point: wrist``
    (the wrist centre).  A formula that is wrong with the flange but right with the wrist centre, written without
    ``point``, gets the verdict "ambiguous" saying so: a question, not "incorrect".
    """
    from ._engine import Verdict

    point = str(raw.get("point", "flange"))
    if point not in ("flange", "wrist"):
        raise ParseError(f"'point' must be flange (the last DH frame's origin, default) or wrist (the wrist "
                         f"centre), got {point[:40]!r}")
    offset = wrist_offset(robot)
    if point == "wrist" and offset is None:
        raise ParseError("'point: wrist': the last three joint axes of this arm do not meet in one point")
    state = rng.bit_generator.state
    verdict = _check_ik_formula(robot, raw, cid, rng, offset if point == "wrist" else None)
    if verdict.verdict != "incorrect" or "point" in raw or offset is None:
        return verdict
    *_, used = _read_formula(robot, raw)
    declared = {re.sub(r"[^A-Za-z0-9]", "", str(k)) for k in (raw.get("where") or {})}
    if not (used & _POSITION_NAMES) - declared:
        return verdict
    again = np.random.default_rng()
    again.bit_generator.state = state
    alt = _check_ik_formula(robot, raw, cid, again, offset)
    if alt.verdict != "correct":
        return verdict
    return Verdict(cid, "ik_formula", "ambiguous",
                   "ambiguous: which point is P? With P = (p_x, p_y, p_z) the origin of the last DH frame (the "
                   "default meaning) the formula is wrong; with P the wrist centre (where the last three axes meet) "
                   "it is correct. Add 'point: wrist' to the claim if that is what you meant.",
                   (), None, (), None, alt.method,
                   {**verdict.extra, "readings": {"flange": verdict.message, "wrist": alt.message},
                    "flange_entries": list(verdict.entries)})


def _check_ik_formula(robot: DHRobot, raw: dict[str, Any], cid: str, rng: np.random.Generator,
                      wrist: np.ndarray | None):
    from ._engine import Verdict

    j, names, versions, used_signs, used = _read_formula(robot, raw)
    deps = sorted(int(n[1:]) - 1 for n in used if n[:1] == "q" and n[1:].isdigit() and n not in names)
    if j in deps:
        raise ParseError(f"the formula for q{j + 1} uses q{j + 1} itself")
    pose = str(raw.get("pose", "dh"))
    if pose not in ("dh", "world"):
        raise ParseError(f"'pose' must be dh (T_0_N, default) or world (end-effector pose), got {pose!r}")
    numeric = False
    try:
        ik_structure(robot)
    except Exception as exc:
        if robot.dof > 3:
            raise ParseError(f"IK formulas cannot be checked for this arm: {exc}") from None
        numeric = True  # a small arm without a closed form (the polar RP arm): its solutions found numerically
    tol = MATCH_TOL + (10.0 * 10.0 ** -d if (d := _decimals_of([v for _, v in versions])) >= 2 else 0.0)
    params = dict(robot.parameters)
    bad, hints, cover, checked = [], [], [], 0
    for t, (qg, T, res) in enumerate(_targets(robot, rng, N_TARGETS, numeric)):
        if len(bad) >= 3:
            break
        S, free = _solution_set(robot, res)
        usable = [k for k in range(len(S)) if not (free_joints(free[k]) & set(deps + [j]))]
        if not usable:
            continue
        checked += 1
        env0 = {**params, **target_env(robot, T, pose)}
        if wrist is not None:  # P is the wrist centre: T_0_N applied to its fixed place in the last frame
            T0N = np.linalg.solve(robot.base_matrix, T) @ np.linalg.inv(robot.tool_matrix)
            P = T0N[:3, :3] @ wrist + T0N[:3, 3]
            if pose == "world":
                P = (np.asarray(robot.base_matrix) @ np.append(P, 1.0))[:3]
            params_ = {k for k, _ in robot.parameters}
            env0.update({k: P[i] for i, ax in enumerate("xyz") for k in (f"p{ax}", f"P{ax}", ax) if k not in params_})
        rows = controlled_rows(res)
        hit = set()
        for s in ([S[k] for k in usable] if deps else [S[usable[0]]]):
            env = {**env0, **{f"q{i + 1}": s[i] for i in deps}}
            vals = _formula_values(names, versions, used_signs, env)
            if not np.isfinite(vals).any():
                bad.append({"entry": [t + 1], "claimed": float("nan"), "expected": float(s[j]), "q": qg.tolist(),
                            "note": "undefined (a square root of a negative number, a division by zero, …)"})
                break
            same = [k for k in usable if all(joint_distance(robot, S[k], s)[i] < tol for i in deps)]
            for v in vals[np.isfinite(vals)]:
                match = [k for k in same if abs(joint_distance(robot, [S[k][j]], [v])[0] if revolute_mask(robot)[j] else S[k][j] - v) < tol]
                if match:
                    hit |= set(match)
                    continue
                q0 = s.copy()
                q0[j] = v
                if reaches(robot, q0, T, deps + [j], rows) is not None:
                    continue
                near = min(same, key=lambda k: abs(((S[k][j] - v + np.pi) % (2 * np.pi)) - np.pi))
                bad.append({"entry": [t + 1], "claimed": float(v), "expected": float(S[near][j]), "q": qg.tolist(),
                            "given": {f"q{i + 1}": float(s[i]) for i in deps}})
                if (h := _formula_hint(robot, j, float(v), float(S[near][j]))) is not None:
                    hints.append(h)
        distinct = {round(float(S[k][j]), 6) for k in usable}
        cover.append((len({round(float(S[k][j]), 6) for k in hit}), len(distinct)))
    if checked == 0:
        raise ParseError(f"q{j + 1} is not determined by the pose at the targets tried (a continuum of solutions)")
    method = (f"evaluated at {checked} random reachable target(s) (pose: {pose}); values compared with the "
              + (f"solution set found by Gauss-Newton on the tip's position from {NUMERIC_STARTS} starts (no closed "
                 "form for this arm)" if numeric else "closed-form solution set (analytic_ik)")
              + ", gaps re-checked by Gauss-Newton with the joint held")
    extra = {"joint": j + 1, "coverage": cover}
    if not bad:
        a, b = min(cover)
        note = "" if all(x == y for x, y in cover) else f"; it gives {a} of the {b} values of q{j + 1} (one branch)"
        return Verdict(cid, "ik_formula", "correct", f"correct: every value it gives is q{j + 1} of an IK solution{note}",
                       method=method, extra=extra)
    first = bad[0]
    msg = (f"incorrect: at target {first['entry'][0]} the formula is {first['note']}" if "note" in first else
           f"incorrect: at target {first['entry'][0]} it gives q{j + 1} = {first['claimed']:.6g}, which is not q{j + 1} "
           f"of any IK solution (nearest: {first['expected']:.6g})")
    return Verdict(cid, "ik_formula", "incorrect", msg, tuple(bad[:12]), {"q": first["q"]},
                   tuple(dict.fromkeys(hints))[:1], None, method, extra)
