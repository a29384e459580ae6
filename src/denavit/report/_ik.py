"""The report's inverse-kinematics section: the closed-form derivation, then the solutions, each checked.

Order (as a course report writes it; Spong, Hutchinson & Vidyasagar 2006, ch. 5; Craig 2005, ch. 4):

1. the target, the end-effector pose of the numeric case;
2. when :func:`denavit.symbolic.ik_derivation` covers the arm, every step of the derivation from the DH table
   (wrist centre, q1, q3 by the law of cosines, q2, R_3_6, q4..q6; or the planar law of cosines), then those
   formulas evaluated at the target for every sign combination σ = ±1;
3. all closed-form solutions of :func:`denavit.ik.analytic_ik` with their branch labels;
4. otherwise the numeric solution of :func:`denavit.ik.solve_ik` and its residual.

Every solution shown is checked here by forward kinematics (an independent route), and the derived
formulas are matched against the analytic solver's set (two different algorithms).
"""

from __future__ import annotations

import itertools
from typing import Any

import numpy as np
import sympy as sp

from .. import numeric as N
from ..codegen import numeric_function
from ..model import JointType
from . import _capabilities
from ._context import Context
from ._derivation import Equation, Numbers, Section, Table, Text

__all__ = ["section_ik", "derived_branches", "MAX_STEP_CHARS", "unique_labels", "residual_text"]

MAX_STEP_CHARS = 6_000  # a derivation step longer than this (LaTeX) is named, not printed
MATCH_TOL = 1e-7  # rad or m: a derived branch equals an analytic solution
_REL = {"=": "=", "≡": "\\equiv", ":=": ":="}


def _names(e: Any) -> dict:
    """Craig's frame names for symbols such as T_0_6 or R_3_6 → {}^{0}T_{6}."""
    out = {}
    for s in getattr(e, "free_symbols", ()):
        parts = str(s).split("_")
        if len(parts) == 3 and parts[0] in ("T", "R") and parts[1].isdigit() and parts[2].isdigit():
            out[s] = f"{{}}^{{{parts[1]}}}{parts[0]}_{{{parts[2]}}}"
    return out


def _tex(e: Any) -> str:
    if isinstance(e, str):
        return e
    e = sp.ImmutableMatrix(e) if isinstance(e, sp.MatrixBase) else e
    return sp.latex(e, mat_str="bmatrix", mat_delim="", symbol_names=_names(e))


def _wrap(x: np.ndarray, revolute: np.ndarray) -> np.ndarray:
    return np.where(revolute, (x + np.pi) % (2 * np.pi) - np.pi, x)


def derived_branches(derivation: Any, T_0N: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Evaluate the derivation's assignments in order at one pose, for every sign combination.

    Returns ``(signs, q)``: signs (K, b) of ±1 and q (K, n), NaN where a branch has no real value.
    The formulas are the library's own sympy expressions, made numeric by :func:`denavit.codegen.numeric_function` (never user text).
    """
    combos = np.array(list(itertools.product((1.0, -1.0), repeat=len(derivation.branches))), dtype=float)
    K = len(combos)
    targets = np.array(derivation.target.tolist(), dtype=object)
    env: dict = {s: np.full(K, T_0N[i, j]) for (i, j), s in np.ndenumerate(targets) if isinstance(s, sp.Symbol)}
    env.update({s: float(v) for s, v in derivation.parameters})
    env.update({s: combos[:, k] for k, s in enumerate(derivation.branches)})
    for lhs, rhs in derivation.formulas:
        pairs = list(zip(lhs, rhs)) if isinstance(lhs, sp.MatrixBase) else [(lhs, rhs)]
        for sym, expr in pairs:
            args = sorted(expr.free_symbols, key=str)
            with np.errstate(invalid="ignore", divide="ignore"):
                val = numeric_function(expr, args)(*(env[a] for a in args))
            val = np.asarray(val, dtype=complex if np.iscomplexobj(val) else float)
            if np.iscomplexobj(val):
                val = np.where(np.abs(val.imag) < 1e-12, val.real, np.nan)
            env[sym] = np.broadcast_to(val.astype(float), (K,))
    return combos, np.stack([env[qk] for qk in derivation.joints], axis=-1)


def _derivation_steps(ctx: Context, T_world: np.ndarray) -> tuple[list, Any]:
    """The symbolic derivation (when covered) and its formulas evaluated at the target."""
    found = _capabilities.capability("denavit.symbolic", "ik_derivation")
    if found is None:
        return [Text("The symbolic IK derivation is not available in this installation.")], None
    from ..errors import UnsupportedRobotError

    try:
        d = found[1](ctx.robot)
    except UnsupportedRobotError:
        return [Text("The step-by-step symbolic derivation covers 6-joint arms with a spherical wrist (elbow or "
                     "Stanford type) and planar 2R/3R arms, so the derivation is not printed for this arm; the "
                     "solver's solutions follow.")], None
    kind = ("kinematic decoupling at the wrist centre (Pieper 1968; Spong et al. 2006, sec. 5.3-5.4; "
            "Craig 2005, sec. 4.7)" if d.kind == "decoupled"
            else "the planar law of cosines (Spong et al. 2006, sec. 5.2; Craig 2005, example 4.1)")
    steps: list = [Text(f"Closed-form derivation from this DH table by {kind}. Named parameters stay symbols; "
                        "each sign σ = ±1 picks one branch.")]
    for k, s in enumerate(d.steps, start=1):
        steps.append(Text(f"Step {k}, {s.title}. {s.text}".rstrip()))
        if s.lhs is None:
            continue
        rhs = _tex(s.rhs)
        if len(rhs) > MAX_STEP_CHARS:
            steps.append(Text("(This expression is too long to print usefully.)"))
            continue
        steps.append(Equation(_tex(s.lhs), rhs, relation=_REL.get(s.relation, s.relation)))
    T_0N = np.linalg.solve(ctx.robot.base_matrix, T_world) @ np.linalg.inv(ctx.robot.tool_matrix)
    signs, cand = derived_branches(d, T_0N)
    return steps, (d, signs, cand)


def _branch_rows(ctx: Context, derived: Any, solutions: list[np.ndarray], T_world: np.ndarray,
                 controlled: str, outside: np.ndarray) -> list:
    """Table: each sign combination, its q from the formulas, FK residual, which analytic solution it is."""
    d, signs, cand = derived
    robot = ctx.robot
    rev = np.array([t is JointType.REVOLUTE for t in robot.joint_types])
    rows = []
    for sg, qv in zip(signs, cand):
        label = "(" + ", ".join(f"{'+' if v > 0 else '−'}1" for v in sg) + ")"
        if not np.all(np.isfinite(qv)):
            rows.append((label, "no real value (out of reach on this branch)", "-", "-"))
            continue
        err = _residual(robot, qv, T_world, controlled)
        match = [k for k, s in enumerate(solutions, start=1)
                 if np.max(np.abs(_wrap(qv - s, rev))) < MATCH_TOL]
        if not match and any(np.max(np.abs(_wrap(qv - s, rev))) < MATCH_TOL for s in outside):
            rows.append((label, _qtext(qv), residual_text(err), "outside the joint limits"))
            continue
        rows.append((label, _qtext(qv), residual_text(err), ", ".join(map(str, match)) if match else "none"))
    return rows


def _residual(robot, q: np.ndarray, T: np.ndarray, controlled: str) -> float:
    """FK residual on the rows the arm controls: position error [m] and/or rotation angle of R_t Rᵀ [rad]."""
    F = N.forward_kinematics(robot, q)
    pos = float(np.linalg.norm(F[:3, 3] - T[:3, 3]))
    E = T[:3, :3] @ F[:3, :3].T
    rot = float(np.arctan2(np.linalg.norm([E[2, 1] - E[1, 2], E[0, 2] - E[2, 0], E[1, 0] - E[0, 1]]) / 2,
                           (np.trace(E) - 1) / 2))
    if controlled == "position":
        return pos
    if controlled == "orientation":
        return rot
    if controlled == "position+heading":
        return max(pos, abs(float(np.arctan2(E[1, 0] - E[0, 1], E[0, 0] + E[1, 1]))))
    return max(pos, rot)


_GENERAL_STEPS = [Text(
    "This arm has no spherical wrist and no three parallel axes, so it has no closed form; all its solutions "
    "(at most 16) are found exactly by the Raghavan-Roth elimination solved as an eigenvalue problem "
    "(Raghavan & Roth 1993; Manocha & Canny 1994). Step 1: the arm and the target close a loop of six joint "
    "rotations; looking only at the line of the last joint axis removes q6. Step 2: from a point p and the "
    "direction l of that line, seen through joints 3-5 on one side and through joints 1-2 and the target on the "
    "other, the 14 quantities p, l, p.p, p.l, p x l, (p.p) l - 2 (p.l) p are formed; each side is linear in "
    "products of sines and cosines of its joints. Step 3: the 8 products of q1 and q2 are eliminated, leaving 6 "
    "equations in q3, q4, q5; with half-angle tangents they become a 12 x 12 matrix quadratic in tan(q3/2). "
    "Step 4: its determinant vanishes at the real roots of a degree-24 polynomial (8 roots are spurious, +-i), "
    "found as the eigenvalues of a 24 x 24 matrix. Step 5: q4, q5 follow from the null vector at each root, q1, q2 "
    "from the eliminated products, q6 from the loop; every candidate is checked by forward kinematics. Which joint "
    "plays q3 is chosen per arm (12 ways to run the loop).")]


def _qtext(q: np.ndarray) -> str:
    """A joint vector as plain text, 4 decimals, trailing zeros dropped (a table cell that may wrap)."""
    from ._render import number_text

    return "(" + ", ".join(number_text(float(v)).replace("-", "−") for v in q) + ")"


def residual_text(err: float) -> str:
    """A residual as plain text (``4.9e-16``), so that no renderer typesets it as a subtraction."""
    return f"{err:.1e}"


def unique_labels(labels: list[str]) -> list[str]:
    """Branch labels made unique: a label given to several solutions gets " (1 of 2)", " (2 of 2)", …

    An empty or ``"-"`` label (no branch names, as for the general 6R method) is left as it is: the row number
    names the solution.  Distinct solutions can share a label where its geometric tests do not separate them (e.g. coaxial joints,
    or two solutions on one side of every test); the table must still name each one once.

    >>> unique_labels(["elbow up", "elbow down", "elbow up"])
    ['elbow up (1 of 2)', 'elbow down', 'elbow up (2 of 2)']
    """
    count = {b: labels.count(b) for b in labels}
    seen: dict[str, int] = {}
    out = []
    for b in labels:
        seen[b] = seen.get(b, 0) + 1
        out.append(f"{b} ({seen[b]} of {count[b]})" if count[b] > 1 and b not in ("", "-") else b)
    return out


def _analytic(ctx: Context, T_world: np.ndarray, steps: list) -> tuple[list, list, list, str, np.ndarray]:
    """(solutions within the limits, branch labels, continuum notes, rows controlled, solutions outside)."""
    found = _capabilities.capability("denavit.ik", "analytic_ik")
    none = np.zeros((0, ctx.robot.dof))
    if found is None:
        return [], [], [], "pose", none
    try:
        res = found[1](ctx.robot, T_world)
    except Exception as exc:  # UnsupportedRobotError: no closed form for this structure
        steps.append(Text(f"No closed-form solver for this arm ({exc}); a numeric solution follows."))
        return [], [], [], "pose", none
    sols = [np.asarray(s, dtype=float) for s in np.atleast_2d(res.solutions) if np.all(np.isfinite(s))]
    out_lim = np.asarray(res.outside_limits, dtype=float).reshape(-1, ctx.robot.dof)
    if out_lim.size:
        steps.append(Text(f"{len(out_lim)} further solution(s) lie outside the joint limits and are left out."))
    controlled = str(getattr(res, "controlled", "pose"))
    if controlled != "pose":
        steps.append(Text(f"This arm controls the {controlled} of the end effector, not the whole pose: residuals "
                          "below are on those rows, and the other rows differ between branches."))
    return sols, list(res.branches)[:len(sols)], list(res.free)[:len(sols)], controlled, out_lim


def section_ik(ctx: Context) -> Section:
    """Inverse kinematics of the pose reached at the numeric case: derivation, branches, checks."""
    robot = ctx.robot
    T_world = N.forward_kinematics(robot, ctx.q)
    steps: list = [Text("Target: the end-effector pose of the numeric case (so at least one solution is known: "
                        "the q of the case)."), Numbers("T_{\\text{target}}", T_world)]
    structure = _capabilities.capability("denavit.ik", "ik_structure")
    kind = ""
    if structure is not None:
        try:
            kind = structure[1](robot)
            steps.append(Text(f"Structure recognised from the DH table: {kind}."))
        except Exception as exc:  # UnsupportedRobotError: no closed form at all
            steps.append(Text(f"No closed form: {exc}."))
            return _numeric(ctx, T_world, steps, False)
    deriv_steps, derived = (_GENERAL_STEPS, None) if kind == "general" else _derivation_steps(ctx, T_world)
    steps += deriv_steps
    solutions, branches, free, controlled, outside = _analytic(ctx, T_world, steps)
    if derived is not None:
        signs = "(" + ", ".join(f"${sp.latex(b)}$" for b in derived[0].branches) + ")"
        steps.append(Text("The derived formulas evaluated at the target, for every sign combination; the residual "
                          "is the position [m] / rotation [rad] error by forward kinematics, and the last column names "
                          "the analytic solver's solution (below) that the branch reproduces:"))
        steps.append(Table((signs, "$q$ [rad, m]", "residual", "solution"),
                           tuple(_branch_rows(ctx, derived, solutions, T_world, controlled, outside)), math=False))
    if solutions:
        rows = []
        labels = unique_labels([b or "-" for b in branches])
        for k, (s, b, f) in enumerate(zip(solutions, labels, free), start=1):
            err = _residual(robot, s, T_world, controlled)
            rows.append((str(k), b + (f" (a continuum: {f})" if f else ""), _qtext(s), residual_text(err)))
        how = ("the general 6R eigenvalue method" if kind == "general"
               else f"closed form, {kind} structure" if kind else "closed form")
        steps.append(Text(f"All {len(solutions)} solution(s) within the joint limits from analytic_ik ({how}), "
                          "each checked by forward kinematics:"))
        steps.append(Table(("$k$", "branch", "$q_{sol}$ [rad, m]", "residual"), tuple(rows), math=False))
        return Section("ik", "Inverse kinematics", tuple(steps))
    return _numeric(ctx, T_world, steps, derived is not None)


def _numeric(ctx: Context, T_world: np.ndarray, steps: list, have_derivation: bool) -> Section:
    found = _capabilities.capability("denavit.ik", "solve_ik")
    if found is None:
        status = "done" if have_derivation else "unavailable"
        return Section("ik", "Inverse kinematics", tuple(steps), status=status,
                       reason="" if have_derivation else "inverse kinematics is not available in this installation")
    res = found[1](ctx.robot, T_world, rng=np.random.default_rng(0))
    q = np.asarray(res.q, dtype=float).reshape(-1)
    err = float(np.max(np.abs(N.forward_kinematics(ctx.robot, q) - T_world)))
    steps.append(Text("Numeric solution by damped least squares / Levenberg-Marquardt from random starts "
                      "(solve_ik; one of possibly several solutions):"))
    steps.append(Numbers("q_{sol}", q))
    steps.append(Text(f"Success: {bool(res.success)}; position error {float(res.position_error):.1e} m, "
                      f"orientation error {float(res.orientation_error):.1e} rad; residual by forward kinematics "
                      f"$\\max|T(q_{{sol}}) - T_{{\\text{{target}}}}|$ = {err:.1e}."))
    return Section("ik", "Inverse kinematics", tuple(steps))
