"""Claims of every IK solution for one target: each claimed q must reach it (FK, to the decimals written), and no
closed-form solution of :func:`denavit.ik.analytic_ik` within the limits may be missing.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from .. import _expr
from .. import numeric as N
from ..errors import ParseError
from ..ik import analytic_ik, characteristic_length
from ..model import DHRobot
from ._ik_targets import (MATCH_TOL, NUMERIC_STARTS, controlled_rows, free_joints, joint_distance,
                          numeric_solutions, pose_error, revolute_mask, rigid_target)
from ._latex import parse_math
from ._matrices import parse_matrix

__all__ = ["check_ik_solutions", "MAX_SOLUTIONS"]

#: Most solutions listed in an ik_solutions claim (a 6R arm has at most 16).
MAX_SOLUTIONS = 64


def _claimed_solutions(robot: DHRobot, raw: Any, deg: bool) -> list[tuple[np.ndarray, np.ndarray]]:
    """The claimed q vectors, each with the rounding unit of every entry (0 for exact entries)."""
    from ._values import decimals, no_names

    if isinstance(raw, str) and "\\begin" in raw:
        rows = parse_matrix(raw, no_names)
    else:
        items = raw if isinstance(raw, list) else [p for p in str(raw).split(";") if p.strip()]
        if len(items) > MAX_SOLUTIONS:
            raise ParseError(f"{len(items)} solutions listed; at most {MAX_SOLUTIONS}")
        rows = []
        for k, item in enumerate(items, start=1):
            cells = item if isinstance(item, list) else [c for c in str(item).strip().strip("[]()").split(",")]
            try:
                rows.append([_expr.parse(c) if isinstance(c, (int, float)) else parse_math(str(c), no_names, rhs=False)
                             for c in cells])
            except ParseError as exc:
                raise ParseError(f"solution {k}: {exc}") from None
    if len(rows) > MAX_SOLUTIONS:
        raise ParseError(f"{len(rows)} solutions listed; at most {MAX_SOLUTIONS}")
    out = []
    rev = revolute_mask(robot)
    for k, row in enumerate(rows, start=1):
        if len(row) != robot.dof:
            raise ParseError(f"solution {k}: expected {robot.dof} joint values, got {len(row)}")
        q = np.array([_expr.evaluate(c) for c in row])
        unit = np.array([10.0 ** -d if (d := decimals(c)) >= 2 or deg and r else 0.0  # 98.6°, 109°: rounded
                         for c, r in zip(row, rev)])
        if deg:
            q, unit = np.where(rev, np.radians(q), q), np.where(rev, np.radians(unit), unit)
        out.append((q, unit))
    if not out:
        raise ParseError("no solution listed (an unreachable target has none: write an empty list [])")
    return out


def _nearest_pose(T: np.ndarray) -> np.ndarray:
    """T with its rotation block replaced by the nearest rotation (SVD): a target written with 3-4 decimals is the
    pose it rounds, not a matrix analytic_ik refuses (rigid_target has already refused what is no pose at all)."""
    U, _, Vt = np.linalg.svd(T[:3, :3])
    out = np.array(T, dtype=float)
    out[:3, :3] = U @ Vt
    out[3] = (0.0, 0.0, 0.0, 1.0)
    return out


def _target_slack(cells) -> np.ndarray:
    """How far FK of a right answer may be from a target written rounded, per row of the pose error (position,
    then rotation vector): an entry with d ≥ 2 decimals is off by at most half of 10⁻ᵈ; the rotation vector of a
    rotation block off by u per entry is off by at most 3u/2 per component (taken as 2u), its position by u."""
    from ._values import decimals

    unit = np.array([[10.0 ** -d if (d := decimals(c)) >= 2 else 0.0 for c in r] for r in cells])
    return np.concatenate([unit[:3, 3], np.full(3, 2.0 * unit[:3, :3].max())])


def _covered(robot: DHRobot, sols: np.ndarray, frees, claimed, reach: list[bool], rows,
             slack: np.ndarray) -> list[bool]:
    """Which closed-form solutions the claimed q that reach the target stand for: those within a q's rounding.  For
    a target written rounded the q may also have moved by the joint motion the rounding allows (|J⁺| times the
    target's slack, doubled), and then a q stands only for its nearest solution, so that it never stands for two."""
    keeps = [[i for i in range(robot.dof) if i not in free_joints(f)] for f in frees]
    if not slack.any():
        return [any(r and np.all(joint_distance(robot, q, s)[keep] <= unit[keep] + MATCH_TOL)
                    for r, (q, unit) in zip(reach, claimed)) for s, keep in zip(sols, keeps)]
    moved = [np.abs(np.linalg.pinv(N.geometric_jacobian(robot, s)[rows])) @ slack[rows] for s in sols]
    covered = [False] * len(sols)
    for r, (q, unit) in zip(reach, claimed):
        if not r or not len(sols):
            continue
        gaps = [joint_distance(robot, q, s) for s in sols]
        k = int(np.argmin([np.max(g[keep], initial=0.0) for g, keep in zip(gaps, keeps)]))
        covered[k] = covered[k] or bool(np.all((gaps[k] - unit - 2.0 * moved[k])[keeps[k]] <= MATCH_TOL))
    return covered


def check_ik_solutions(robot: DHRobot, raw: dict[str, Any], cid: str, rng: np.random.Generator, deg: bool):
    """Each claimed q reaches the target; every closed-form solution within the limits is listed."""
    from ._engine import Verdict
    from ._values import claim_cells, joint_values, no_names

    slack = np.zeros(6)  # how far the target as written may be from the pose it rounds (p rows, then ω rows)
    if "q" in raw:
        T = N.forward_kinematics(robot, joint_values(raw["q"], robot, "q", deg))
    elif "T" in raw:
        cells = claim_cells(raw["T"], no_names)
        T = np.array([[_expr.evaluate(c) for c in r] for r in cells])
        slack = _target_slack(cells) if T.shape == (4, 4) else slack
    else:
        raise ParseError("an ik_solutions claim needs the target: 'q' (its pose is the target) or 'T' (4×4)")
    if T.shape != (4, 4):
        raise ParseError(f"'T' must be 4×4, got {T.shape}")
    rigid_target(T)  # a matrix that is no pose (bottom row 5 5 5 5) makes the claim unreadable, not judged
    claimed = [] if raw["value"] == [] else _claimed_solutions(robot, raw["value"], deg)
    numeric = False
    try:
        res = analytic_ik(robot, _nearest_pose(T))
    except Exception:  # no closed form: each solution is still checked by FK
        res = None
    if res is None and robot.dof <= 3 and claimed:  # a small arm places its tip: its solutions found numerically
        ranges = robot.sampling_ranges(max(characteristic_length(robot), 1.0))
        res = numeric_solutions(robot, T, claimed[0][0], rng.uniform(ranges[:, 0], ranges[:, 1],
                                                                      (NUMERIC_STARTS, robot.dof)))
        numeric = True
    if res is None and not claimed:
        raise ParseError("an empty list of solutions cannot be checked: this arm has no closed form to show that "
                         "the target is out of reach")
    rows = controlled_rows(res) if res is not None else list(range(6))
    entries, reach = [], []
    for k, (q, unit) in enumerate(claimed, start=1):
        e = pose_error(robot, q, T)[rows]
        allowed = 1e-9 + 2.0 * np.abs(N.geometric_jacobian(robot, q)[rows]) @ unit + slack[rows]
        ok = bool(np.all(np.abs(e) <= allowed))
        reach.append(ok)
        if not ok:
            entries.append({"entry": [k], "claimed": float(np.max(np.abs(e))), "expected": 0.0, "q": q.tolist(),
                            "note": "FK(q) does not reach the target"})
    missing = []
    if res is not None:
        sols = np.asarray(res.solutions).reshape(-1, robot.dof)
        for s, label, hit in zip(sols, res.branches, _covered(robot, sols, res.free, claimed, reach, rows, slack)):
            if not hit:
                shown = np.where(revolute_mask(robot), np.degrees(s), s) if deg else s
                missing.append(f"{label}: q = [" + ", ".join(f"{x:.6g}" for x in shown) + "]" + (" (degrees)" * deg))
    method = ("FK of each claimed solution on the rows the arm controls (to the decimals written of q and of the "
              "target, through J); "
              + ("completeness against the tip positions' solutions found by Gauss-Newton from "
                 f"{NUMERIC_STARTS} starts (no closed form)" if numeric else "completeness against analytic_ik"
                 if res is not None else "completeness not checked (no closed form)"))
    extra = {"missing": missing, "solutions": None if res is None else np.asarray(res.solutions).tolist()}
    if not entries and not missing:
        return Verdict(cid, "ik_solutions", "correct", f"correct: all {len(claimed)} solution(s) reach the target"
                       + (" and none is missing" if res is not None else ""), method=method, extra=extra)
    if not entries and raw.get("complete") is False:  # "θ = (…) (elbow down)": one branch claimed, not all
        return Verdict(cid, "ik_solutions", "correct", f"correct: the {len(claimed)} solution(s) given reach the "
                       f"target (the others: {'; '.join(missing[:8])})", method=method, extra=extra)
    parts = [f"solution {e['entry'][0]} does not reach the target (error {e['claimed']:.3g})" for e in entries]
    if raw.get("complete") is False:
        parts += [f"the solutions: {'; '.join(missing[:8])}"] if missing else []
    else:
        parts += [f"missing {m}" for m in missing]
    return Verdict(cid, "ik_solutions", "incorrect", "incorrect: " + "; ".join(parts[:8]), tuple(entries),
                   {"q": entries[0]["q"]} if entries else None, (), extra["solutions"], method, extra)
