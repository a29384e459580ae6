"""Singular configurations, symbolic: factor the Jacobian determinant and solve each factor.

The matrix analysed is the Jacobian, or the square sub-Jacobian of the rows a task uses (``rows="vx,vy,wz"``
for a planar arm). For a square 6×6 Jacobian the determinant does not change when the axes are rotated or
the reference point is moved (both are block-triangular maps with determinant 1, Siciliano et al. sec. 3.3),
so it is computed in the axes of a middle frame with the reference point on the last joint axis, where the
entries are shortest (Craig sec. 5.9 does the same with ³J). For a non-square m×k matrix the measure is the
Gram determinant det(JᵀJ) (m > k) or det(J Jᵀ) (m < k), a sum of squared k×k minors (Cauchy–Binet); their
common factor is what is factorized and solved. The algebra (frames, determinants, gcds, factorization) is done
on polynomials in sin qᵢ, cos qᵢ (:class:`~denavit.symbolic._rings.TrigRing`): a Panda's seven 6×6 minors take
seconds. Arms of fewer than six joints are analysed on their task rows (:func:`task_rows`).

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

from ..codegen import numeric_function
from ..chain import chain_of
from ..model import DHRobot, Frame, JointType
from ..numeric import (RANK_RTOL, TWIST_ROWS, geometric_jacobian, jacobian_rank, joint_axes, link_transforms,
                       select_rows)
from ._jacobians import geometric_jacobian_sym, reduce_trig
from ._rings import TrigRing
from ._symbols import joint_symbols, parameter_symbols

__all__ = ["SingularSolution", "SingularCondition", "SingularityAnalysis", "singularity_analysis", "task_rows"]

ZERO_TOL = 1e-9
TASK_ROW_SAMPLES = 5  # random configurations that decide the task rows of an arm with fewer than 6 joints


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


# --- the matrix, in a polynomial ring ------------------------------------------------------------------
#
# Every entry of J is a polynomial in s_i = sin q_i, c_i = cos q_i and the named parameters. Determinants,
# gcds and factorizations are done with sympy's sparse polynomial ring (sympy.polys.rings), which is two to
# three orders of magnitude faster than the same algebra on expression trees; constants that are not
# rational (√3/2, a float twist cos 0.7) are carried as extra generators and put back at the end, so
# nothing is expanded through trigonometric identities. Reduction modulo s_i² + c_i² − 1 (a Gröbner basis
# in lex order with s before c) gives the canonical form used for the zero test; factors are taken from
# the determinant as multiplied, where the product structure of the arm is still visible.


def _Ring(exprs: list[sp.Expr], q, robot: DHRobot) -> TrigRing:
    """The ring of the analysis: one angle per revolute joint, prismatic variables as generators."""
    return TrigRing(exprs, q, revolute=[k for k, t in enumerate(robot.joint_types) if t is JointType.REVOLUTE])


def _middle_frame(robot: DHRobot) -> int:
    """Index (0-based, into the chain's axis frames) of the frame whose axes J is expressed in."""
    return min(2, robot.dof - 1) if robot.dof <= 6 else robot.dof // 2


def _ring_frames(rg: TrigRing, A: list, k: int):
    """T_k_i for every frame i = 0 … N as 4×4 lists of ring elements, from the link matrices A (4×4 lists)
    (k: a DH frame index; frames before k through the inverses Rᵀ, −Rᵀp of the link matrices)."""
    R = rg.R

    def mul(X, Y):
        return [[rg.reduce(sum((X[i][l] * Y[l][j] for l in range(4)), R.zero)) for j in range(4)] for i in range(4)]

    def inv(X):
        Rt = [[X[j][i] for j in range(3)] for i in range(3)]
        p = [-sum((Rt[i][l] * X[l][3] for l in range(3)), R.zero) for i in range(3)]
        return [Rt[i] + [p[i]] for i in range(3)] + [[R.zero, R.zero, R.zero, R.one]]

    T = {k: [[R.one if i == j else R.zero for j in range(4)] for i in range(4)]}
    for i in range(k + 1, len(A) + 1):
        T[i] = mul(T[i - 1], A[i - 1])
    for i in range(k - 1, -1, -1):
        T[i] = mul(T[i + 1], inv(A[i]))
    return [T[i] for i in range(len(A) + 1)]


def _wrist_frame_jacobian(robot: DHRobot, simplify: str) -> tuple[sp.ImmutableMatrix, str, TrigRing, list]:
    """J in the axes of a middle frame (joint 3's axis frame; joint 4's for 7 joints), reference point on the
    last joint axis: (sympy matrix, note, ring, ring matrix as a list of rows)."""
    from ._kinematics import link_matrices_sym

    axis = chain_of(robot).axis_frame
    k, m = axis[_middle_frame(robot)], axis[-1]
    q = joint_symbols(robot.dof).q
    mats = link_matrices_sym(robot)
    rg = _Ring([e for A in mats for e in A], q, robot)
    vals = rg.elements()
    T = _ring_frames(rg, [[vals[16 * j + 4 * i:16 * j + 4 * i + 4] for i in range(4)] for j in range(len(mats))], k)
    p = [T[m][i][3] for i in range(3)]
    cols = []
    for a, jt in zip(axis, robot.joint_types):
        z, o = [T[a][i][2] for i in range(3)], [T[a][i][3] for i in range(3)]
        d = [p[i] - o[i] for i in range(3)]
        if jt is JointType.REVOLUTE:
            v = [z[1] * d[2] - z[2] * d[1], z[2] * d[0] - z[0] * d[2], z[0] * d[1] - z[1] * d[0]]
            cols.append([rg.reduce(x) for x in v] + z)
        else:
            cols.append(z + [rg.R.zero] * 3)
    J = [[cols[j][i] for j in range(robot.dof)] for i in range(6)]
    note = (f"J in the axes of frame {{{k}}} with reference point o_{m} (on the axis of joint {robot.dof}); "
            "its rank, and for 6 joints its determinant, equal those of J0 and Je")
    M = sp.ImmutableMatrix(6, robot.dof, [_display(rg.to_expr(x), simplify, q) for row in J for x in row])
    return M, note, rg, J


def _display(e: sp.Expr, simplify: str, q) -> sp.Expr:
    return reduce_trig(e, q) if simplify == "trig" else (sp.simplify(e) if simplify == "full" else e)


def _minors(rg: TrigRing, J: list, shape: tuple[int, int]) -> tuple[str, list]:
    """(name of the measure, ring minors whose common factor is solved): det J, or the k×k minors."""
    from sympy.polys.matrices import DomainMatrix

    m, k = shape
    dom = rg.R.to_domain()

    def det(rows, cols):
        return DomainMatrix([[J[i][j] for j in cols] for i in rows], (len(rows), len(cols)), dom).det()

    if m == k:
        return "det J", [_laplace_det(rg, J)]
    small = min(m, k)
    minors = [det(rows, cols)
              for rows in (itertools.combinations(range(m), small) if m > k else [tuple(range(m))])
              for cols in (itertools.combinations(range(k), small) if k > m else [tuple(range(k))])]
    name = ("common factor of the k×k minors (zeros of det(JᵀJ) = Σ minors²)" if m > k
            else "common factor of the k×k minors (zeros of det(J Jᵀ) = Σ minors²)").replace("k×k", f"{small}×{small}")
    return name, minors


def _laplace_det(rg: TrigRing, J: list):
    """det J by expansion along the last column of every leading-column minor, all minors kept (2ⁿ of them,
    no division): the same polynomial as fraction-free elimination — the arm's product structure kept for
    factoring — but a generic 6R's in seconds, where the exact divisions of large polynomials took minutes."""
    n = len(J)
    prev = {(): rg.R.one}
    reduce = False
    for k in range(n):
        cur = {}
        for rows in itertools.combinations(range(n), k + 1):
            acc = rg.R.zero
            for pos, r in enumerate(rows):
                sub = prev.get(rows[:pos] + rows[pos + 1:])
                if J[r][k] and sub:
                    acc = acc + J[r][k] * sub if (pos + k) % 2 == 0 else acc - J[r][k] * sub  # cofactor sign
            cur[rows] = acc
        if not reduce and max(len(p.terms()) for p in cur.values()) > FACTOR_AS_MULTIPLIED_TERMS:
            reduce = True  # a generic arm: no product structure to keep, and reduced minors stay ~10× smaller
        if reduce:
            cur = {rows: rg.reduce(p) if p else p for rows, p in cur.items()}
        prev = cur
    return prev[tuple(range(n))]


# --- factoring -------------------------------------------------------------------------------------


FACTOR_AS_MULTIPLIED_TERMS = 5000  # minors / determinants with more terms are reduced (s² + c² = 1) as formed
BIG_RATIONAL = 10 ** 6  # a factor with a coefficient whose numerator or denominator exceeds this is shown in floats


def _tidy(e: sp.Expr) -> tuple[sp.Expr, sp.Expr]:
    """(e / scale, scale): a factor of a float arm (cos 0.7, 17-digit decimals) written with floats of order
    one, its largest coefficient ±1; exact factors are returned as they are (scale 1)."""
    trans = {a: a.evalf(15) for a in e.atoms(sp.sin, sp.cos) if a.is_number and not a.is_algebraic}
    big = any(abs(r.p) > BIG_RATIONAL or r.q > BIG_RATIONAL for r in e.atoms(sp.Rational))
    if not trans and not big:
        return e, sp.Integer(1)
    x = sp.expand(e.xreplace(trans))
    coeffs = [abs(float(t.as_coeff_Mul()[0])) for t in sp.Add.make_args(x)]
    scale = sp.Float(max(coeffs), 15) if coeffs and max(coeffs) > 0 else sp.Integer(1)
    return sp.expand(sp.N(x / scale, 15)), scale


def _unit_floats(e: sp.Expr) -> sp.Expr:
    """1.0·x → x (a float coefficient within 1e-12 of ±1)."""
    return e.xreplace({f: sp.Integer(round(float(f))) for f in e.atoms(sp.Float) if abs(abs(float(f)) - 1) < 1e-12})


def _factors(rg: TrigRing, minors: list) -> tuple[sp.Expr, list[tuple[sp.Expr, int]]]:
    """Common factor of the ring minors, factorized: (constant part, [(factor in q, multiplicity)]).

    The gcd of the minors as multiplied is tried first (it keeps the arm's product structure); when it is
    a constant, the gcd of their canonical forms modulo s² + c² = 1."""
    q = rg.q
    g = minors[0]
    for p in minors[1:]:
        g = g.gcd(p)
    if len(minors) > 1 and not rg.to_expr(g).has(*q):
        red = [rg.reduce(p) for p in minors]
        g2 = red[0]
        for p in red[1:]:
            g2 = g2.gcd(p)
        g = g2 if rg.to_expr(g2).has(*q) else g
    if rg.const_relations:
        g = g.rem(rg.const_relations)
    if len(g.terms()) > FACTOR_AS_MULTIPLIED_TERMS:  # a generic arm: no product structure to keep
        g = rg.reduce(g)
    coeff, facs = g.factor_list()
    const, out = rg.R.domain.to_sympy(coeff), []
    for f, mult in facs:
        fr = rg.reduce(f)
        e = rg.to_expr(fr)
        if not e.has(*q):
            const *= e ** mult
            continue
        e, scale = _tidy(e)
        const *= scale ** mult
        e = reduce_trig(e, q)
        if scale != 1:
            e = _unit_floats(e)
        for i, (o, m) in enumerate(out):
            if sp.expand(e - o) == 0 or sp.expand(e + o) == 0:
                const *= (1 if sp.expand(e - o) == 0 else -1) ** mult
                out[i] = (o, m + mult)
                break
        else:
            out.append((e, mult))
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
        fn = numeric_function(f.subs(params), [qk], "math")
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
    fn = numeric_function(f.subs(params), list(q), "math")
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


def _common_point(z, o) -> np.ndarray | None:
    """The point the lines (o_i, z_i) all pass through, or None."""
    A = np.concatenate([np.eye(3) - np.outer(zz, zz) for zz in z])
    b = np.concatenate([(np.eye(3) - np.outer(zz, zz)) @ oo for zz, oo in zip(z, o)])
    c, *_ = np.linalg.lstsq(A, b, rcond=None)
    return c if np.linalg.norm(A @ c - b) < 1e-9 * (1 + np.abs(b).max()) else None


def _reference_point(robot: DHRobot, q: np.ndarray) -> tuple[np.ndarray, str]:
    """The wrist centre when the last three axes meet in a point; else the point where the last two axes
    meet (a UR-type wrist, Hawkins 2013); else the end-effector origin."""
    frames = link_transforms(robot, q)
    z, o = joint_axes(robot, frames)
    for k, name in ((3, "wrist centre"), (2, "point where the last two axes meet")):
        if robot.dof >= k and all(t is JointType.REVOLUTE for t in robot.joint_types[-k:]):
            c = _common_point(z[-k:], o[-k:])
            if c is not None and (k == 3 or np.linalg.norm(np.cross(z[-1], z[-2])) > 1e-7):
                return c, name
    return (frames[-1] @ robot.tool_matrix)[:3, 3], "end point"


def _parallel_revolute_pairs(robot: DHRobot, q: np.ndarray) -> set[tuple[int, int]]:
    """Pairs of revolute joints (0-based) whose axes are parallel (coaxial or not) at q."""
    z, _ = joint_axes(robot, link_transforms(robot, q))
    rev = [i for i, t in enumerate(robot.joint_types) if t is JointType.REVOLUTE]
    return {(i, j) for i, j in itertools.combinations(rev, 2) if np.linalg.norm(np.cross(z[i], z[j])) < 1e-7}


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
    if set(variables) <= last3 and samples and robot.dof >= 5:
        # a wrist without a centre (UR): two wrist axes turn parallel, and with them the arm's parallel axes
        generic_par = _parallel_revolute_pairs(robot, _random_q(robot, rng))
        new = None
        for x in samples:
            pairs = _parallel_revolute_pairs(robot, x) - generic_par
            new = pairs if new is None else new & pairs
        wrist_pairs = sorted(p for p in (new or ()) if p[0] in last3 and p[1] in last3)
        if wrist_pairs:
            i, j = wrist_pairs[0]
            group = sorted({k for p in (new or ()) for k in p} | {k for p in generic_par if i in p or j in p for k in p})
            also = f" (axes {', '.join(str(k + 1) for k in group)} all parallel)" if len(group) > 2 else ""
            return "wrist", f"wrist: the axes of joints {i + 1} and {j + 1} are parallel{also}"
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


def task_rows(robot: DHRobot, frame: Frame | str = Frame.BASE, seed: int = 0) -> tuple[str, ...]:
    """The task rows an arm of fewer than six joints is analysed on (all six for six or more joints).

    The rows of J that are not zero for every q (a planar arm in the xy plane has wx = wy = 0, and vz = 0
    unless it also moves along z); when there are as many of them as joints, those. Otherwise the position
    rows (vx, vy, vz) that are not always zero, then the angular rows, whichever has generic rank equal to
    the number of joints: a positioning arm is analysed on (x, y, z), a planar 2R on (x, y), a 3-axis wrist
    on (wx, wy, wz). Decided numerically on :data:`TASK_ROW_SAMPLES` random configurations.
    """
    if robot.dof >= 6:
        return TWIST_ROWS
    frame = Frame(frame)
    rng = np.random.default_rng(seed)
    Js = [geometric_jacobian(robot, _random_q(robot, rng), frame) for _ in range(TASK_ROW_SAMPLES)]
    scale = max(1.0, max(float(np.abs(J).max()) for J in Js))
    live = [i for i in range(6) if max(float(np.abs(J[i]).max()) for J in Js) > 1e-9 * scale]

    def rank(rows):
        return max(int(jacobian_rank(J[rows, :], RANK_RTOL)) for J in Js) if rows else 0

    candidates = [live] if len(live) == robot.dof else []
    candidates += [[i for i in live if i < 3], [i for i in live if i >= 3]]
    for rows in candidates:
        if len(rows) >= robot.dof and rank(rows) == robot.dof:
            return tuple(TWIST_ROWS[i] for i in rows)
    return tuple(TWIST_ROWS[i] for i in live) or TWIST_ROWS


@lru_cache(maxsize=32)
def singularity_analysis(robot: DHRobot, rows: str | None = "auto", frame: Frame | str = Frame.BASE,
                         simplify: str = "trig", progress: Callable[[str], None] | None = None
                         ) -> SingularityAnalysis:
    """Singular configurations of an arm: the factorized determinant and each factor solved and classified.

    Parameters
    ----------
    robot : DHRobot
    rows : str or None, optional
        Comma-separated task rows, e.g. ``"vx,vy,wz"``; ``None`` for all six; ``"auto"`` (default): all six
        for arms of six or more joints, the rows of :func:`task_rows` for fewer (a positioning arm on
        vx, vy, vz, a planar arm on vx, vy, wz).
    frame : Frame or {"base", "tool"}
        Axes of the Jacobian whose ``rows`` are taken (ignored for all six rows: the rank does not depend on it).
    simplify : {"none", "trig", "full"}
        Display form of the matrix entries and factors (the algebra is done on polynomials either way).
    progress : callable, optional
        Called with a short message at each stage (Jacobian, minors, factors, each condition).

    Returns
    -------
    SingularityAnalysis

    Notes
    -----
    With all six rows the Jacobian is taken in the axes of a middle frame with the reference point on the
    last joint axis (its determinant, or the minors of a 7-joint arm, equal those of J0: Siciliano et al.
    sec. 3.3); determinants and common factors are computed on polynomials in sin qᵢ, cos qᵢ (see the
    module notes). A 7-joint arm's 6×6 minors usually share no factor: its singular configurations are then
    where all seven vanish together, which is reported as such, not solved.

    Examples
    --------
    >>> import denavit, denavit.symbolic as S
    >>> a = S.singularity_analysis(denavit.load_robot("report004-1-planar2r"))
    >>> a.rows, [str(c.factor) for c in a.conditions], [s.values for s in a.conditions[0].solutions]
    (('vx', 'vy'), ['sin(q2)'], [(0.0,), (3.141592653589793,)])
    """
    frame = Frame(frame)
    q = joint_symbols(robot.dof).q
    if rows == "auto":
        auto = task_rows(robot, frame)
        rows = None if auto == TWIST_ROWS else ",".join(auto)
    idx = select_rows(rows)
    params = {parameter_symbols(robot)[k]: sp.Float(v) for k, v in robot.parameters}
    say = progress or (lambda msg: None)
    say("symbolic Jacobian")
    if rows is None:
        M, note, rg, J = _wrist_frame_jacobian(robot, simplify)
    else:
        M = sp.ImmutableMatrix(geometric_jacobian_sym(robot, frame, simplify).extract(idx, list(range(robot.dof))))
        note = f"rows {', '.join(TWIST_ROWS[i] for i in idx)} of J{'0' if frame is Frame.BASE else 'e'}"
        rg = _Ring(list(M), q, robot)
        vals = rg.elements()
        J = [vals[i * M.shape[1]:(i + 1) * M.shape[1]] for i in range(M.shape[0])]
    say(f"determinant / minors of the {M.shape[0]}x{M.shape[1]} matrix")
    name, minors = _minors(rg, J, M.shape)
    rng = np.random.default_rng(0)
    full = min(M.shape)
    if all(rg.reduce(m) == 0 for m in minors):
        rank, reason = _everywhere_reason(robot, idx, frame, rng)
        return SingularityAnalysis(robot.name, tuple(TWIST_ROWS[i] for i in idx), M, note, name, sp.Integer(0),
                                   (), (), True, rank, full, reason)
    say("factoring")
    const, facs = _factors(rg, minors)
    conds = []
    for k, (f, _) in enumerate(facs, start=1):
        say(f"solving and classifying factor {k}/{len(facs)}")
        variables = sorted(int(str(s)[1:]) - 1 for s in f.free_symbols if s in q)
        sols = _solutions(f, variables[0], robot, q, params) if len(variables) == 1 else []
        kind, text = _classify(f, variables, sols, robot, q, params, rng)
        conds.append(SingularCondition(f, tuple(f"q{k + 1}" for k in variables), tuple(sols), kind, text))
    det = sp.Mul(const, *[f ** m for f, m in facs])  # for m ≠ k: the common factor of the minors
    # a numeric factor is zero only when it is 0 (a generic float arm's content can be 1e-37); a factor in
    # the parameters is zero when it vanishes at their values (a2 = 0)
    everywhere = any(f == 0 or (f.free_symbols and abs(complex(sp.N(f.subs(params)))) < ZERO_TOL)
                     for f in sp.Mul.make_args(const))
    const_list = tuple(x for x in sp.Mul.make_args(const) if x not in (1, -1))
    reason = "a constant factor is zero at these parameter values" if everywhere else ""
    return SingularityAnalysis(robot.name, tuple(TWIST_ROWS[i] for i in idx), M, note, name, det, const_list,
                               tuple(conds), bool(everywhere), full - int(everywhere), full, reason)
