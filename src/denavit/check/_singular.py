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

import re
from dataclasses import dataclass, field
from functools import lru_cache
from typing import Any

import numpy as np

from .. import _expr
from .. import numeric as N
from ..codegen import numeric_function
from ..errors import ParseError
from ..model import DHRobot, Frame, JointType
from ._bounded import cpu_bounded
from ._latex import parse_math
from ._resolve import robot_resolver
from ._text import expand_pm, split_relation, split_top
from ._tokens import MAX_CHARS
from ._vectorized import vec_eval

__all__ = ["check_singularities", "SINGULAR_RTOL", "MAX_KPI_DIVISOR", "MAX_VALUES", "MAX_CONDITIONS",
           "MAX_ANALYSIS_CPU_SECONDS"]

SINGULAR_RTOL = 1e-7
#: Largest n in ``q_j = k\pi/n`` (each of its 2n values is tested).
MAX_KPI_DIVISOR = 12
#: Most values of one joint in one claim (``q_2 = 0, \pi, …``), all conditions together.
MAX_VALUES = 64
#: Most conditions (values of a joint, or equations) in one claim.
MAX_CONDITIONS = 16
TWIST_ROWS = ("vx", "vy", "vz", "wx", "wy", "wz")
#: CPU seconds the library's symbolic singularity analysis may take for one set of rows of one arm (it runs in a
#: child process with this CPU limit, :func:`._bounded.cpu_bounded`; the Panda's 6 rows take ~4 s, but some row subsets of 6- and 7-joint arms do
#: not finish in minutes).  Past it, a claim is judged on its own conditions only (never "correct").
MAX_ANALYSIS_CPU_SECONDS = 10
#: Arms with at most this many joints are analysed in the process itself (always fast).
_SMALL_DOF = 3
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
    from ._values import _decimals as dec

    return dec(node)


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


class _Arm:
    """The robot, the rows of J taken and cheap numeric helpers (random q, rank ratio, limits)."""

    def __init__(self, robot: DHRobot, rows: list[int], frame: Frame, rng: np.random.Generator) -> None:
        self.robot, self.rows, self.frame, self.rng = robot, rows, frame, rng
        self.rev = np.array([t is JointType.REVOLUTE for t in robot.joint_types])
        lim = robot.q_limits
        self.lo = np.where(np.isfinite(lim[:, 0]), lim[:, 0], np.where(self.rev, -np.pi, -1.0))
        self.hi = np.where(np.isfinite(lim[:, 1]), lim[:, 1], np.where(self.rev, np.pi, 1.0))
        self.lo, self.hi = np.maximum(self.lo, -np.pi), np.minimum(self.hi, np.pi)
        self.params = dict(robot.parameters)

    def random_q(self, k: int = 1) -> np.ndarray:
        return self.rng.uniform(self.lo, self.hi, (k, self.robot.dof))

    def ratio(self, Q: np.ndarray) -> np.ndarray:
        """σ_min / σ_max of the selected rows of J at each row of Q (k, n) → (k,)."""
        J = N.geometric_jacobian(self.robot, Q, frame=self.frame)[..., self.rows, :]
        s = np.linalg.svd(J, compute_uv=False)
        return s[..., -1] / np.maximum(s[..., 0], 1e-300)

    def env(self, Q: np.ndarray) -> dict:
        out: dict = dict(self.params)
        out.update({f"q{k + 1}": Q[..., k] for k in range(self.robot.dof)})
        return out

    def same_angle(self, a, b, j: int, tol: float) -> bool:
        d = a - b
        if self.rev[j]:
            d = (d + np.pi) % (2 * np.pi) - np.pi
        return bool(abs(d) <= tol)


# --- reading ---------------------------------------------------------------------------------------------


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


def read_conditions(raw: Any, arm: _Arm) -> tuple[list[Cond], str | None]:
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


# --- sampling zero sets ---------------------------------------------------------------------------------


def roots_along(fn, q: np.ndarray, j: int, lo: float, hi: float, scale: float) -> list[float]:
    """Roots of x ↦ fn(q with q_j = x) in [lo, hi]: sign changes refined by Brent, and double roots."""
    from scipy.optimize import brentq, minimize_scalar

    xs = np.linspace(lo, hi, 721)
    Q = np.repeat(q[None], len(xs), 0)
    Q[:, j] = xs
    h = fn(Q)

    def f(x: float) -> float:
        qq = q.copy()
        qq[j] = x
        return float(fn(qq[None])[0])

    out = []
    for k in range(len(xs) - 1):
        a, b = h[k], h[k + 1]
        if not (np.isfinite(a) and np.isfinite(b)):
            continue
        if a == 0:
            out.append(xs[k])
        elif a * b < 0:
            out.append(brentq(f, xs[k], xs[k + 1], xtol=1e-15, rtol=1e-15))
        elif 0 < k and abs(a) < 1e-2 * scale and abs(a) <= abs(h[k - 1]) and abs(a) <= abs(b):
            r = minimize_scalar(lambda x: abs(f(x)), bounds=(xs[k - 1], xs[k + 1]), method="bounded",
                                options={"xatol": 1e-14})
            if abs(r.fun) <= 1e-10 * scale:
                out.append(float(r.x))
    if np.isfinite(h[-1]) and h[-1] == 0:
        out.append(xs[-1])
    return out


def _scale(fn, arm: _Arm) -> float:
    vals = np.abs(fn(arm.random_q(32)))
    vals = vals[np.isfinite(vals)]
    return float(np.median(vals)) if vals.size else 0.0


def zero_set_points(fn, variables: list[int], arm: _Arm, scale: float, count: int = 4) -> list[np.ndarray]:
    """Points on {fn = 0}: every root along a lone variable, or random roots along random variables."""
    pts: list[np.ndarray] = []
    if len(variables) == 1:
        j = variables[0]
        for r in roots_along(fn, arm.random_q()[0], j, arm.lo[j], arm.hi[j], scale)[:12]:
            for q in arm.random_q(2):
                q[j] = r
                pts.append(q)
        return pts
    for _ in range(6 * count):
        q = arm.random_q()[0]
        j = int(arm.rng.choice(variables))
        roots = roots_along(fn, q, j, arm.lo[j], arm.hi[j], scale)
        if roots:
            q[j] = roots[int(arm.rng.integers(len(roots)))]
            pts.append(q)
        if len(pts) >= count:
            break
    return pts


# --- judging ---------------------------------------------------------------------------------------------


def _variables(node: tuple) -> list[int]:
    return sorted(int(n[1:]) - 1 for n in _expr.names_in(node) if n.startswith("q") and n[1:].isdigit())


def _cond_points(c: Cond, arm: _Arm) -> list[np.ndarray]:
    if c.var is not None:
        pts = []
        for v in c.values:
            for q in arm.random_q(2):
                q[c.var] = v
                pts.append(q)
        return pts
    fn = lambda Q: vec_eval(c.node, arm.env(Q))  # noqa: E731
    c.scale = _scale(fn, arm)
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


def _ratio_near(c: Cond, q: np.ndarray, arm: _Arm) -> float:
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


def _member(q: np.ndarray, conds: list[Cond], arm: _Arm) -> bool:
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


def _library(arm: _Arm, spec: dict[str, Any]) -> tuple[list[tuple[str, np.ndarray]], bool, list[str] | None]:
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
        for q in zero_set_points(fn, [int(v[1:]) - 1 for v in c.variables], arm, _scale(fn, arm), 3):
            points.append((factor, q))
    confirmed = [(d, q) for d, q in points if arm.ratio(q[None])[0] < SINGULAR_RTOL]
    return confirmed, False, described


def _hint_for_value(c: Cond, q: np.ndarray, arm: _Arm) -> str | None:
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
    arm = _Arm(robot, _rows(raw), frame, rng)
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
