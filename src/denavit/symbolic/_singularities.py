"""Singular configurations, symbolic: factor the Jacobian determinant and solve each factor.

The matrix analysed is the Jacobian, or the square sub-Jacobian of the rows a task uses (``rows="vx,vy,wz"``
for a planar arm). For a square 6×6 Jacobian the determinant does not change when the axes are rotated or
the reference point is moved (both are block-triangular maps with determinant 1, Siciliano et al. sec. 3.3),
so it is computed in the axes of a middle frame with the reference point on the last joint axis, where the
entries are shortest (Craig sec. 5.9 does the same with ³J). For a non-square m×k matrix the measure is the
Gram determinant det(JᵀJ) (m > k) or det(J Jᵀ) (m < k), a sum of squared k×k minors (Cauchy–Binet); their
common factor is what is factorized and solved.

Each factor becomes a :class:`SingularCondition`: closed-form solutions when it involves one joint variable
(a cos q + b sin q + c = 0, or a polynomial in a prismatic d), the equation itself otherwise, plus a
classification checked numerically at points of its zero set (wrist: two wrist axes line up; shoulder: the
wrist centre / end point is at a critical distance from the first axis; elbow: one arm joint stretches or
folds the arm; prismatic at zero extension).
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass
from functools import lru_cache
from typing import Callable

import numpy as np
import sympy as sp

from ..chain import chain_of
from ..model import DHRobot, Frame, JointType
from ..numeric import (RANK_RTOL, TWIST_ROWS, geometric_jacobian, jacobian_rank, joint_axes, link_transforms,
                       select_rows)
from ._jacobians import geometric_jacobian_sym, reduce_trig, simplify_kinematic
from ._kinematics import link_transforms_sym
from ._symbols import joint_symbols, parameter_symbols

__all__ = ["SingularSolution", "SingularCondition", "SingularityAnalysis", "singularity_analysis"]

ZERO_TOL = 1e-9


@dataclass(frozen=True)
class SingularSolution:
    """Closed form ``variable = expression`` (None when only numeric roots were found) and its values
    at the robot's parameter values [rad in (−π, π] or m]; ``in_limits`` flags each value."""

    variable: str
    expression: sp.Expr | None
    values: tuple[float, ...]
    in_limits: tuple[bool, ...]


@dataclass(frozen=True)
class SingularCondition:
    """One factor of the determinant set to zero, its solutions (empty: kept as an equation) and its kind."""

    factor: sp.Expr
    variables: tuple[str, ...]
    solutions: tuple[SingularSolution, ...]
    kind: str
    explanation: str

    @property
    def equation(self) -> sp.Eq:
        return sp.Eq(self.factor, 0, evaluate=False)


@dataclass(frozen=True)
class SingularityAnalysis:
    """Result of :func:`singularity_analysis` (data only; presenters live in the CLI and reports)."""

    robot: str
    rows: tuple[str, ...]
    matrix: sp.ImmutableMatrix
    matrix_note: str
    measure: str
    determinant: sp.Expr
    constant_factors: tuple[sp.Expr, ...]
    conditions: tuple[SingularCondition, ...]
    everywhere: bool
    generic_rank: int
    full_rank: int
    reason: str

    def _repr_markdown_(self) -> str:
        from ..display import singularities_markdown

        return singularities_markdown(self)


# --- the matrix --------------------------------------------------------------------------------------


def _wrist_frame_jacobian(robot: DHRobot, simplify: str) -> tuple[sp.ImmutableMatrix, str]:
    """J in the axes of the frame of joint 3's axis, reference point on the last joint axis."""
    Ts = link_transforms_sym(robot, simplify)
    axis = chain_of(robot).axis_frame
    k, m = axis[min(2, robot.dof - 1)], axis[-1]
    Rk, p = Ts[k][:3, :3], Ts[m][:3, 3]
    cols = []
    for a, jt in zip(axis, robot.joint_types):
        z, o = Ts[a][:3, 2], Ts[a][:3, 3]
        cols.append(sp.Matrix.vstack(z.cross(p - o), z) if jt is JointType.REVOLUTE
                    else sp.Matrix.vstack(z, sp.zeros(3, 1)))
    J = sp.Matrix.hstack(*cols)
    J = sp.Matrix.vstack(Rk.T * J[:3, :], Rk.T * J[3:, :])
    note = (f"J in the axes of frame {{{k}}} with reference point o_{m} (on the axis of joint {robot.dof}); "
            "its rank, and for 6 joints its determinant, equal those of J0 and Je")
    return simplify_kinematic(J, simplify, joint_symbols(robot.dof).q), note


def _measure(M: sp.MatrixBase, q) -> tuple[str, sp.Expr, list[sp.Expr]]:
    """(name, expression, list of the minors whose common factor is solved)."""
    m, k = M.shape
    if m == k:
        return "det J", M.det(method="berkowitz"), [M.det(method="berkowitz")]
    small = min(m, k)
    minors = []
    for rows in itertools.combinations(range(m), small) if m > k else [tuple(range(m))]:
        for cols in itertools.combinations(range(k), small) if k > m else [tuple(range(k))]:
            minors.append(reduce_trig(M.extract(list(rows), list(cols)).det(method="berkowitz"), q))
    name = ("common factor of the k×k minors (zeros of det(JᵀJ) = Σ minors²)" if m > k
            else "common factor of the k×k minors (zeros of det(J Jᵀ) = Σ minors²)").replace("k×k", f"{small}×{small}")
    return name, sp.Add(*[x ** 2 for x in minors]), minors


# --- factoring -------------------------------------------------------------------------------------


def _poly_vars(q):
    n = len(q)
    return sp.symbols(f"_c1:{n + 1}"), sp.symbols(f"_s1:{n + 1}")


def _to_poly(e: sp.Expr, q) -> sp.Expr:
    c, s = _poly_vars(q)
    x = sp.expand(sp.expand_trig(e))
    return x.xreplace({sp.cos(qi): ci for qi, ci in zip(q, c)}).xreplace({sp.sin(qi): si for qi, si in zip(q, s)})


def _from_poly(e: sp.Expr, q) -> sp.Expr:
    c, s = _poly_vars(q)
    return e.xreplace({ci: sp.cos(qi) for qi, ci in zip(q, c)}).xreplace({si: sp.sin(qi) for qi, si in zip(q, s)})


def _factors(exprs: list[sp.Expr], q) -> tuple[sp.Expr, list[tuple[sp.Expr, int]]]:
    """Common factor of the expressions, factorized: (constant part, [(factor in q, multiplicity)])."""
    polys = [_to_poly(e, q) for e in exprs]
    g = polys[0]
    for p in polys[1:]:
        g = sp.gcd(g, p)
    coeff, facs = sp.factor_list(g)
    const, out = (coeff if isinstance(coeff, sp.Basic) else sp.Integer(coeff)), []  # may be √3/4, not an integer
    for f, mult in facs:
        f = reduce_trig(_from_poly(f, q), q)
        if not f.has(*q):
            const *= f ** mult
            continue
        for i, (o, m) in enumerate(out):
            if sp.expand(f - o) == 0 or sp.expand(f + o) == 0:
                const *= (1 if sp.expand(f - o) == 0 else -1) ** mult
                out[i] = (o, m + mult)
                break
        else:
            out.append((f, mult))
    return const, out


# --- solving ---------------------------------------------------------------------------------------


def _wrap(x: float) -> float:
    return float(math.remainder(x, 2 * math.pi)) if abs(math.remainder(x, 2 * math.pi) + math.pi) > 1e-12 else math.pi


def _linear_trig(f: sp.Expr, qk: sp.Symbol):
    """(A, B, C) with f = A cos q + B sin q + C, or None."""
    c, s = sp.Dummy("c"), sp.Dummy("s")
    x = sp.expand(sp.expand_trig(f)).xreplace({sp.cos(qk): c, sp.sin(qk): s})
    if x.has(qk):
        return None
    try:
        P = sp.Poly(x, c, s)
    except sp.PolynomialError:
        return None
    if P.total_degree() > 1:
        return None
    return P.coeff_monomial(c), P.coeff_monomial(s), P.coeff_monomial(1)


def _solve_revolute(f: sp.Expr, qk: sp.Symbol) -> list[sp.Expr] | None:
    abc = _linear_trig(f, qk)
    if abc is None:
        return None
    A, B, C = abc
    if C == 0:
        if A == 0:
            return [sp.Integer(0), sp.pi]
        if B == 0:
            return [sp.pi / 2, -sp.pi / 2]
        base = sp.atan2(-A, B)  # A cos q + B sin q = 0  ⇔  tan q = −A/B
        return [base, base + sp.pi]
    r = sp.sqrt(A ** 2 + B ** 2)
    phi, delta = sp.atan2(B, A), sp.acos(-C / r)  # r cos(q − φ) = −C
    return [phi + delta, phi - delta]


def _numeric_values(exprs: list[sp.Expr], params: dict, revolute: bool) -> list[float]:
    vals = []
    for e in exprs:
        v = complex(sp.N(e.subs(params)))
        if abs(v.imag) > 1e-9:
            continue
        x = _wrap(v.real) if revolute else v.real
        if all(abs(x - y) > 1e-9 for y in vals):
            vals.append(x)
    return sorted(vals)


def _scan_roots(fn, lo: float, hi: float, samples: int = 721) -> list[float]:
    from scipy.optimize import brentq

    xs = np.linspace(lo, hi, samples)
    ys = np.array([fn(x) for x in xs], dtype=float)
    roots = [float(x) for x, y in zip(xs, ys) if abs(y) < 1e-14]
    for a, b, ya, yb in zip(xs[:-1], xs[1:], ys[:-1], ys[1:]):
        if ya * yb < 0:
            roots.append(float(brentq(fn, a, b, xtol=1e-14)))
    return sorted(set(round(r, 12) for r in roots))


def _in_limits(v: float, lo: float, hi: float, revolute: bool) -> bool:
    shifts = (-2 * math.pi, 0.0, 2 * math.pi) if revolute else (0.0,)
    return any(lo - 1e-12 <= v + k <= hi + 1e-12 for k in shifts)


def _solutions(f: sp.Expr, var: int, robot: DHRobot, q, params: dict) -> list[SingularSolution]:
    qk = q[var]
    lo, hi = robot.q_limits[var]
    revolute = robot.joint_types[var] is JointType.REVOLUTE
    if revolute:
        closed = _solve_revolute(f, qk)
        if closed is not None:
            exprs = [sp.simplify(e) for e in closed]
            vals = _numeric_values(exprs, params, True)
            # one expression per distinct numeric value, in the order of the values
            chosen = []
            for v in vals:
                for e in exprs:
                    ev = complex(sp.N(e.subs(params)))
                    if abs(ev.imag) < 1e-9 and abs(_wrap(ev.real) - v) < 1e-9:
                        chosen.append(e)
                        break
            return [SingularSolution(str(qk), e, (v,), (_in_limits(v, lo, hi, True),)) for e, v in zip(chosen, vals)]
        fn = sp.lambdify(qk, f.subs(params), "math")
        vals = [_wrap(v) for v in _scan_roots(fn, -math.pi, math.pi)]
        vals = sorted({round(v, 12) for v in vals})
        return [SingularSolution(str(qk), None, (v,), (_in_limits(v, lo, hi, True),)) for v in vals]
    exprs = [e for e in sp.solve(f, qk) if e.is_real is not False]
    out = []
    for e in exprs:
        vals = _numeric_values([e], params, False)
        if vals:
            out.append(SingularSolution(str(qk), e, tuple(vals), tuple(_in_limits(v, lo, hi, False) for v in vals)))
    return out


def _random_q(robot: DHRobot, rng: np.random.Generator) -> np.ndarray:
    lim = robot.q_limits
    lo = np.where(np.isfinite(lim[:, 0]), lim[:, 0], -math.pi)
    hi = np.where(np.isfinite(lim[:, 1]), lim[:, 1], math.pi)
    lo, hi = np.maximum(lo, -math.pi), np.minimum(hi, math.pi)
    return rng.uniform(lo, hi)


def _zero_set_samples(f, variables: list[int], sols, robot, q, params, rng, count: int = 3) -> list[np.ndarray]:
    out: list[np.ndarray] = []
    if sols:
        for sol in sols:
            for v in sol.values:
                for _ in range(count):
                    x = _random_q(robot, rng)
                    x[variables[0]] = v
                    out.append(x)
        return out
    fn = sp.lambdify(q, f.subs(params), "math")
    k = variables[-1]
    for _ in range(20 * count):
        x = _random_q(robot, rng)

        def g(t, x=x):
            y = x.copy()
            y[k] = t
            return fn(*y)

        roots = _scan_roots(g, -math.pi, math.pi, 181)
        if roots:
            x[k] = roots[0]
            out.append(x)
        if len(out) >= count:
            break
    return out


def _aligned_pairs(robot: DHRobot, q: np.ndarray) -> list[tuple[int, int, str]]:
    """Pairs of joints (0-based) whose axes are coaxial (revolute) or parallel (prismatic / mixed) at q."""
    z, o = joint_axes(robot, link_transforms(robot, q))
    scale = 1.0 + np.abs(o).max()
    out = []
    for i, j in itertools.combinations(range(robot.dof), 2):
        if np.linalg.norm(np.cross(z[i], z[j])) > 1e-7:
            continue
        both_rev = robot.joint_types[i] is JointType.REVOLUTE and robot.joint_types[j] is JointType.REVOLUTE
        if both_rev and np.linalg.norm(np.cross(o[j] - o[i], z[i])) < 1e-7 * scale:
            out.append((i, j, "coaxial"))
        elif not both_rev:
            out.append((i, j, "parallel"))
    return out


def _reference_point(robot: DHRobot, q: np.ndarray) -> tuple[np.ndarray, str]:
    """The wrist centre when the last three axes meet in a point, else the end-effector origin."""
    frames = link_transforms(robot, q)
    if robot.dof >= 3 and all(t is JointType.REVOLUTE for t in robot.joint_types[-3:]):
        z, o = joint_axes(robot, frames)
        A = np.concatenate([np.eye(3) - np.outer(zz, zz) for zz in z[-3:]])
        b = np.concatenate([(np.eye(3) - np.outer(zz, zz)) @ oo for zz, oo in zip(z[-3:], o[-3:])])
        c, *_ = np.linalg.lstsq(A, b, rcond=None)
        if np.linalg.norm(A @ c - b) < 1e-9 * (1 + np.abs(b).max()):
            return c, "wrist centre"
    return (frames[-1] @ robot.tool_matrix)[:3, 3], "end point"


def _rho2(robot: DHRobot, q: np.ndarray) -> float:
    z, o = joint_axes(robot, link_transforms(robot, q))
    p, _ = _reference_point(robot, q)
    d = p - o[0]
    return float(d @ d - (d @ z[0]) ** 2)


def _is_shoulder(robot: DHRobot, samples: list[np.ndarray]) -> bool:
    if robot.joint_types[0] is not JointType.REVOLUTE or not samples:
        return False
    h = 1e-6
    for x in samples:
        grad = [(_rho2(robot, x + h * e) - _rho2(robot, x - h * e)) / (2 * h) for e in np.eye(robot.dof)]
        scale = 1.0 + math.sqrt(max(_rho2(robot, x), 0.0))
        if np.abs(grad).max() > 1e-5 * scale:
            return False
    return True


def _classify(f, variables, sols, robot, q, params, rng) -> tuple[str, str]:
    names = [f"q{k + 1}" for k in variables]
    samples = _zero_set_samples(f, variables, sols, robot, q, params, rng)
    generic = {(i, j) for i, j, _ in _aligned_pairs(robot, _random_q(robot, rng))}
    aligned = None
    for x in samples:
        pairs = {(i, j, kind) for i, j, kind in _aligned_pairs(robot, x) if (i, j) not in generic}
        aligned = pairs if aligned is None else aligned & pairs
    aligned = sorted(aligned or ())
    last3 = set(range(robot.dof - 3, robot.dof))
    types = robot.joint_types
    if len(variables) == 1 and types[variables[0]] is JointType.PRISMATIC and sols and \
            all(abs(v) < ZERO_TOL for s in sols for v in s.values):
        return "prismatic at zero extension", f"joint {variables[0] + 1} (prismatic) at zero extension"
    in_wrist = [(i, j, kind) for i, j, kind in aligned if i in last3 and j in last3]
    if set(variables) <= last3 and in_wrist and samples and _reference_point(robot, samples[0])[1] == "wrist centre":
        i, j, kind = in_wrist[0]
        return "wrist", f"wrist: the axes of joints {i + 1} and {j + 1} are {kind}"
    first = [(i, j, kind) for i, j, kind in aligned if i == 0]
    if first:
        _, j, kind = first[0]
        return "shoulder", f"shoulder: the axes of joints 1 and {j + 1} are {kind}"
    if len(variables) == 1 and variables[0] != 0 and types[variables[0]] is JointType.REVOLUTE:
        return "elbow", f"elbow/boundary: joint {variables[0] + 1} stretches the arm out or folds it back"
    if len(variables) > 1 and 0 not in variables and _is_shoulder(robot, samples):
        _, what = _reference_point(robot, samples[0])
        return "shoulder", f"shoulder: the {what} is at its least distance from the axis of joint 1 (on it if no offset)"
    if aligned:
        i, j, kind = aligned[0]
        return "other", f"the axes of joints {i + 1} and {j + 1} are {kind}"
    return "other", f"condition on {', '.join(names)}"


# --- the analysis ------------------------------------------------------------------------------------


def _everywhere_reason(robot: DHRobot, rows: list[int], frame: Frame, rng) -> tuple[int, str]:
    ranks, common = [], None
    for _ in range(5):
        x = _random_q(robot, rng)
        ranks.append(int(jacobian_rank(geometric_jacobian(robot, x, frame)[rows, :], RANK_RTOL)))
        pairs = set(_aligned_pairs(robot, x))
        common = pairs if common is None else common & pairs
    text = [f"joints {i + 1} and {j + 1} are {kind} for every q" for i, j, kind in sorted(common or ())]
    return max(ranks), "; ".join(text) or "the columns are dependent for every q"


@lru_cache(maxsize=32)
def singularity_analysis(robot: DHRobot, rows: str | None = None, frame: Frame | str = Frame.BASE,
                         simplify: str = "trig", progress: Callable[[str], None] | None = None
                         ) -> SingularityAnalysis:
    """Singular configurations of an arm: the factorized determinant and each factor solved and classified.

    Parameters
    ----------
    robot : DHRobot
    rows : str, optional
        Comma-separated task rows, e.g. ``"vx,vy,wz"`` (all six when omitted).
    frame : Frame or {"base", "tool"}
        Axes of the Jacobian whose ``rows`` are taken (ignored without ``rows``: the rank does not depend on it).
    simplify : {"none", "trig", "full"}
    progress : callable, optional
        Called with a short message at each stage (Jacobian, minors, factors, each condition); a 6- or
        7-joint arm takes seconds to minutes.

    Returns
    -------
    SingularityAnalysis

    Examples
    --------
    >>> import denavit, denavit.symbolic as S
    >>> a = S.singularity_analysis(denavit.load_robot("report004-1-planar2r"), rows="vx,vy")
    >>> [str(c.factor) for c in a.conditions], [s.values for s in a.conditions[0].solutions]
    (['sin(q2)'], [(0.0,), (3.141592653589793,)])
    """
    frame = Frame(frame)
    q = joint_symbols(robot.dof).q
    idx = select_rows(rows)
    params = {parameter_symbols(robot)[k]: sp.Float(v) for k, v in robot.parameters}
    say = progress or (lambda msg: None)
    say("symbolic Jacobian")
    if rows is None:
        M, note = _wrist_frame_jacobian(robot, simplify)
    else:
        M = sp.ImmutableMatrix(geometric_jacobian_sym(robot, frame, simplify).extract(idx, list(range(robot.dof))))
        note = f"rows {', '.join(TWIST_ROWS[i] for i in idx)} of J{'0' if frame is Frame.BASE else 'e'}"
    say(f"determinant / minors of the {M.shape[0]}x{M.shape[1]} matrix")
    name, measure, minors = _measure(M, q)
    rng = np.random.default_rng(0)
    full = min(M.shape)
    if all(reduce_trig(m, q) == 0 for m in minors):
        rank, reason = _everywhere_reason(robot, idx, frame, rng)
        return SingularityAnalysis(robot.name, tuple(TWIST_ROWS[i] for i in idx), M, note, name, sp.Integer(0),
                                   (), (), True, rank, full, reason)
    say("factoring")
    const, facs = _factors(minors, q)
    conds = []
    for k, (f, _) in enumerate(facs, start=1):
        say(f"solving and classifying factor {k}/{len(facs)}")
        variables = sorted(int(str(s)[1:]) - 1 for s in f.free_symbols if s in q)
        sols = _solutions(f, variables[0], robot, q, params) if len(variables) == 1 else []
        kind, text = _classify(f, variables, sols, robot, q, params, rng)
        conds.append(SingularCondition(f, tuple(f"q{k + 1}" for k in variables), tuple(sols), kind, text))
    det = sp.Mul(const, *[f ** m for f, m in facs])  # for m ≠ k: the common factor of the minors
    everywhere = abs(complex(sp.N(const.subs(params)))) < ZERO_TOL
    const_list = tuple(sp.Mul.make_args(const)) if const != 1 else ()
    reason = "a constant factor is zero at these parameter values" if everywhere else ""
    return SingularityAnalysis(robot.name, tuple(TWIST_ROWS[i] for i in idx), M, note, name, det, const_list,
                               tuple(conds), bool(everywhere), full - int(everywhere), full, reason)
