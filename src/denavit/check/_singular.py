"""Claims of singular configurations: each claimed set must make J lose rank, and none may be missing.

A claim lists conditions: values of one joint (``q2 = 0, \\pi``; ``\\theta_5 = 0``; ``q_3 = k\\pi``) or equations
(``\\sin\\theta_2 = 0``; ``L_2 \\cos q_2 + L_3 \\cos(q_2 + q_3) = 0``), or says ``none`` / ``everywhere``.
The verdict is numeric, never a comparison of formulas (Siciliano et al. 2009, sec. 3.3; Spong et al. 2006,
sec. 4.9):

1. **each claimed set is singular**: points are sampled on it (a value with random other joints; a root of the
   equation found along one of its joints, by bracketing and Brent's method) and the Jacobian's smallest
   singular value relative to its largest must be below :data:`SINGULAR_RTOL` there;
2. **nothing is missing**: points sampled on the library's singular set
   (:func:`denavit.symbolic.singularity_analysis`), confirmed singular by the same rank test, must lie on one
   of the claimed sets.

A library point that the rank test does not confirm is ignored, so an error in the library cannot turn a correct
claim into an incorrect one.  For conditions written with rounded decimals (``q_3 = 1.6178``) the rank test
searches one unit of the last written decimal around the point.
"""

from __future__ import annotations

from functools import lru_cache
from typing import Any

import numpy as np

from .. import _expr
from .._constants import TWIST_ROWS
from ..codegen import numeric_function
from ..errors import ParseError
from ..model import DHRobot, Frame
from ._bounded import cpu_bounded
from ._conditions import Cond, read_conditions
from ._vectorized import vec_eval
from ._zero_sets import Arm, roots_along, scale_of, zero_set_points

__all__ = ["check_singularities", "SINGULAR_RTOL", "MAX_ANALYSIS_CPU_SECONDS"]

SINGULAR_RTOL = 1e-7
#: CPU seconds the library's symbolic singularity analysis may take for one set of rows of one arm (it runs in a
#: child process with this CPU limit, :func:`._bounded.cpu_bounded`; the Panda's 6 rows take ~4 s, but some row
#: subsets of 6- and 7-joint arms do not finish in minutes).  Past it, a claim is judged on its own conditions only (never "correct").
MAX_ANALYSIS_CPU_SECONDS = 10
#: Arms with at most this many joints are analysed in the process itself (always fast).
_SMALL_DOF = 3


def _rows(spec: dict[str, Any]) -> list[int]:
    rows = spec.get("rows")
    if rows is None or rows == "all":
        return list(range(6))
    if isinstance(rows, str):
        names = [r.strip() for r in rows.split(",")]
    elif isinstance(rows, list) and all(isinstance(r, str) for r in rows):
        names = [r.strip() for r in rows]
    else:
        names = []
    bad = [r for r in names if r not in TWIST_ROWS]
    if bad or not names or len(set(names)) != len(names):
        raise ParseError(f"'rows' must name rows from {', '.join(TWIST_ROWS)}, got {rows!r}")
    return [TWIST_ROWS.index(r) for r in names]


# --- judging ---------------------------------------------------------------------------------------------


def _variables(node: tuple) -> list[int]:
    return sorted(int(n[1:]) - 1 for n in _expr.names_in(node) if n.startswith("q") and n[1:].isdigit())


def _cond_points(c: Cond, arm: Arm) -> list[np.ndarray]:
    if c.var is not None:
        pts = []
        for v in c.values:
            for q in arm.random_q(2):
                q[c.var] = v
                pts.append(q)
        return pts
    fn = lambda Q: vec_eval(c.node, arm.env(Q))  # noqa: E731
    c.scale = scale_of(fn, arm)
    if c.scale == 0.0:  # identically zero: the whole configuration space
        return list(arm.random_q(4))
    variables = _variables(c.node)
    pts = zero_set_points(fn, variables, arm, c.scale)
    if not pts and len(variables) == 1:
        # no root inside the limits: judged where it is, as ``q3 = 0`` written as a value is (a condition the
        # library lists outside the limits, e.g. a prismatic joint at zero extension, is still a true one)
        j = variables[0]
        span = arm.hi[j] - arm.lo[j]
        lo, hi = (-np.pi, np.pi) if arm.rev[j] else (arm.lo[j] - span - abs(arm.lo[j]), arm.hi[j] + span + abs(arm.hi[j]))
        for r in roots_along(fn, arm.random_q()[0], j, lo, hi, c.scale)[:12]:
            for q in arm.random_q(2):
                q[j] = r
                pts.append(q)
    return pts


def _ratio_near(c: Cond, q: np.ndarray, arm: Arm) -> float:
    """σ_min/σ_max at q; for rounded decimals, the least value within one unit of the last decimal."""
    from scipy.optimize import minimize_scalar

    r = float(arm.ratio(q[None])[0])
    if r < SINGULAR_RTOL or c.decimals < 2:
        return r
    unit = 10.0 ** -c.decimals
    if c.var is not None:
        j, width = c.var, unit
    else:
        h = 1e-6
        grads = []
        for k in _variables(c.node):
            e = np.zeros_like(q)
            e[k] = h
            grads.append((abs(float(vec_eval(c.node, arm.env((q + e)[None]))[0]
                                    - vec_eval(c.node, arm.env((q - e)[None]))[0])) / (2 * h), k))
        g, j = max(grads)
        width = min(0.1, 2 * unit * max(1.0, c.scale) / max(g, 1e-9))

    def at(x: float) -> float:
        qq = q.copy()
        qq[j] = x
        return float(arm.ratio(qq[None])[0])

    xs = q[j] + np.linspace(-width, width, 41)
    Q = np.repeat(q[None], len(xs), 0)
    Q[:, j] = xs
    k = int(np.argmin(arm.ratio(Q)))
    res = minimize_scalar(at, bounds=(xs[max(k - 1, 0)], xs[min(k + 1, 40)]), method="bounded",
                          options={"xatol": 1e-15})
    return min(r, float(res.fun))


def _member(q: np.ndarray, conds: list[Cond], arm: Arm) -> bool:
    for c in conds:
        extra = 10.0 ** -c.decimals if c.decimals >= 2 else 0.0
        if c.var is not None:
            if any(arm.same_angle(q[c.var], v, c.var, extra + 1e-7) for v in c.values):
                return True
            continue
        if c.scale == 0.0:
            return True
        h = float(vec_eval(c.node, arm.env(q[None]))[0])
        if np.isfinite(h) and abs(h) <= 1e-7 * c.scale + extra * max(1.0, c.scale):
            return True
    return False


def _analyse(robot: DHRobot, rows: str | None, frame: Frame):
    from .. import symbolic as S

    return S.singularity_analysis(robot, rows=rows, frame=frame)


@lru_cache(maxsize=8)
def _analysis(robot: DHRobot, rows: str | None, frame: Frame):
    """The library's singularity analysis, once per robot, rows and frame (claims of one file share it); None when
    it needs more than MAX_ANALYSIS_CPU_SECONDS of CPU."""
    if robot.dof <= _SMALL_DOF:
        return _analyse(robot, rows, frame)
    return cpu_bounded(_analyse, (robot, rows, frame), MAX_ANALYSIS_CPU_SECONDS, warm=("denavit.symbolic",))


def _library(arm: Arm, spec: dict[str, Any]) -> tuple[list[tuple[str, np.ndarray]], bool, list[str] | None]:
    """Points of the library's singular set, each confirmed by the rank test: (description, q) pairs;
    whether J is singular everywhere; the library's conditions as text (None: the analysis ran out of time)."""
    import sympy as sp

    from .. import symbolic as S

    robot = arm.robot
    rows = None if arm.rows == list(range(6)) else ",".join(TWIST_ROWS[i] for i in arm.rows)
    a = _analysis(robot, rows, arm.frame)
    if a is None:
        if np.all(arm.ratio(arm.random_q(8)) < SINGULAR_RTOL):
            return [], True, ["every configuration (J never has full rank at random q)"]
        return [], False, None
    if a.everywhere or np.all(arm.ratio(arm.random_q(8)) < SINGULAR_RTOL):
        return [], True, [f"every configuration ({a.reason or 'J never has full rank'})"]
    qs = S.joint_symbols(robot.dof).q
    psub = {S.parameter_symbols(robot)[k]: v for k, v in robot.parameters}
    points, described = [], []
    for c in a.conditions:
        factor = f"{sp.sstr(c.factor)} = 0"
        vals = "; ".join(f"{s.variable} = " + ", ".join(f"{v:.6g}" for v in s.values) for s in c.solutions)
        described.append(f"{factor}" + (f" ({vals})" if vals else "") + f" [{c.kind}]")
        if c.solutions:
            for s in c.solutions:
                j = int(s.variable[1:]) - 1
                for v, inside in zip(s.values, s.in_limits):
                    for q in (arm.random_q(2) if inside else []):
                        q[j] = v
                        points.append((f"{s.variable} = {v:.6g} (from {factor})", q))
            continue
        fn0 = numeric_function(c.factor.xreplace(psub), list(qs))  # c.factor: the library's own sympy expression
        fn = lambda Q, f=fn0: np.broadcast_to(np.asarray(f(*Q.T), dtype=float), Q.shape[:1])  # noqa: E731
        for q in zero_set_points(fn, [int(v[1:]) - 1 for v in c.variables], arm, scale_of(fn, arm), 3):
            points.append((factor, q))
    confirmed = [(d, q) for d, q in points if arm.ratio(q[None])[0] < SINGULAR_RTOL]
    return confirmed, False, described


def _hint_for_value(c: Cond, q: np.ndarray, arm: Arm) -> str | None:
    for v in c.values:
        for shift, why in ((np.pi / 2, "π/2 away"), (-np.pi / 2, "π/2 away"), (np.pi, "π away")):
            qq = q.copy()
            qq[c.var] = v + shift
            if arm.rev[c.var] and arm.ratio(qq[None])[0] < SINGULAR_RTOL:
                return (f"q{c.var + 1} = {v + shift:.6g} ({why}) is singular: sine and cosine mixed up, or a DH "
                        "angle offset?")
    return None


def check_singularities(robot: DHRobot, raw: dict[str, Any], cid: str, rng: np.random.Generator, deg: bool):
    """The verdict on a claim of singular configurations (see the module notes)."""
    from ._engine import Verdict

    frame = Frame(raw.get("frame", "base")) if raw.get("frame", "base") in ("base", "tool") else None
    if frame is None:
        raise ParseError(f"'frame' must be base or tool, got {raw.get('frame')!r}")
    arm = Arm(robot, _rows(raw), frame, rng)
    conds, special = read_conditions(raw["value"], arm)
    if deg:
        for c in conds:
            if c.var is not None and arm.rev[c.var]:
                c.values = [float(np.radians(v)) for v in c.values]
    bad, entries, hints = [], [], []
    for k, c in enumerate(conds, start=1):
        pts = _cond_points(c, arm)
        if not pts:
            bad.append(f"condition {k} ({c.text!r}) holds at no configuration within the joint limits")
            entries.append({"entry": [k], "claimed": float("nan"), "expected": 0.0, "condition": c.text})
            continue
        for q in pts:
            r = _ratio_near(c, q, arm)
            if r >= SINGULAR_RTOL:
                bad.append(f"condition {k} ({c.text!r}) is not singular: σ_min/σ_max = {r:.3g} at q = "
                           + "[" + ", ".join(f"{x:.6g}" for x in q) + "]")
                entries.append({"entry": [k], "claimed": r, "expected": 0.0, "condition": c.text, "q": q.tolist()})
                if c.var is not None and (h := _hint_for_value(c, q, arm)):
                    hints.append(h)
                break
    lib_points, everywhere, described = _library(arm, raw)
    missing: list[tuple[str, np.ndarray]] = []
    if special == "everywhere":
        Q = arm.random_q(8)
        r = arm.ratio(Q)
        if not np.all(r < SINGULAR_RTOL):
            k = int(np.argmax(r))
            bad.append(f"J has full rank at q = [{', '.join(f'{x:.6g}' for x in Q[k])}] (σ_min/σ_max = {r[k]:.3g})")
            entries.append({"entry": [1], "claimed": float(r[k]), "expected": 0.0, "q": Q[k].tolist()})
    elif everywhere:
        missing.append((described[0], arm.random_q()[0]))
    else:
        seen = set()
        for d, q in lib_points:
            if d not in seen and not _member(q, conds, arm):
                seen.add(d)
                missing.append((d, q))
    method = (f"rank of J ({','.join(TWIST_ROWS[i] for i in arm.rows)} rows, {arm.frame.value} axes) at points on "
              "each claimed set and on the library's singular set (singularity_analysis)")
    if described is None:  # the library's set is unknown: only the claimed conditions are judged
        method = method.split(" and on ")[0]
        why = (f"the library's singular set of this Jacobian ({len(arm.rows)} rows, {robot.dof} joints) was not "
               f"computed within {MAX_ANALYSIS_CPU_SECONDS} s of CPU, so whether a singular configuration is missing "
               "was not checked")
        if bad:
            return Verdict(cid, "singularities", "incorrect", "incorrect: " + "; ".join(bad[:8]) + f" ({why})",
                           tuple(entries), {"q": entries[0]["q"]} if "q" in entries[0] else None, tuple(hints[:3]),
                           None, method, {"missing": [], "library": None})
        said = ("J has full rank at random configurations" if special == "none" else
                f"each of the {len(conds)} claimed condition(s) makes J lose rank")
        return Verdict(cid, "singularities", "ambiguous", f"ambiguous: {said}, but {why}", method=method,
                       extra={"missing": [], "library": None})
    extra = {"missing": [d for d, _ in missing], "library": described}
    if not bad and not missing:
        return Verdict(cid, "singularities", "correct",
                       f"correct: {'J is singular everywhere' if special == 'everywhere' else 'no singularity' if special == 'none' else f'each of the {len(conds)} claimed condition(s) makes J lose rank'}"
                       " and none of the library's singular configurations is missing",
                       expected=described, method=method, extra=extra)
    parts = bad + [f"missing: {d}" for d, _ in missing]
    cex_q = entries[0]["q"] if entries and "q" in entries[0] else missing[0][1].tolist() if missing else None
    return Verdict(cid, "singularities", "incorrect", "incorrect: " + "; ".join(parts[:8]), tuple(entries),
                   {"q": cex_q} if cex_q is not None else None, tuple(hints[:3]), described, method, extra)
