"""Singularity analysis, each factor: solved in closed form (one joint variable) or numerically, and classified
(wrist, shoulder, elbow, prismatic at zero extension) at points of its zero set (see :mod:`._singularities`)."""

from __future__ import annotations

import itertools
import math

import numpy as np
import sympy as sp

from ..codegen import numeric_function
from ..model import DHRobot, JointType
from ..numeric import joint_axes, link_transforms
from ._singular_types import SingularSolution

__all__ = ["ZERO_TOL", "factor_solutions", "classify_factor", "random_q", "aligned_pairs"]

ZERO_TOL = 1e-9


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


def factor_solutions(f: sp.Expr, var: int, robot: DHRobot, q, params: dict) -> list[SingularSolution]:
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


def random_q(robot: DHRobot, rng: np.random.Generator) -> np.ndarray:
    """A random configuration within the limits (:meth:`DHRobot.sampling_ranges`: ±1 m for a prismatic joint
    without limits, as the singularity checker's), revolute joints within one turn."""
    ranges = robot.sampling_ranges(1.0)
    turn = np.where([t is JointType.REVOLUTE for t in robot.joint_types], math.pi, np.inf)
    return rng.uniform(np.maximum(ranges[:, 0], -turn), np.minimum(ranges[:, 1], turn))


def _zero_set_samples(f, variables: list[int], sols, robot, q, params, rng, count: int = 3) -> list[np.ndarray]:
    out: list[np.ndarray] = []
    if sols:
        for sol in sols:
            for v in sol.values:
                for _ in range(count):
                    x = random_q(robot, rng)
                    x[variables[0]] = v
                    out.append(x)
        return out
    fn = numeric_function(f.subs(params), list(q), "math")
    k = variables[-1]
    for _ in range(20 * count):
        x = random_q(robot, rng)

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


def aligned_pairs(robot: DHRobot, q: np.ndarray) -> list[tuple[int, int, str]]:
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


def classify_factor(f, variables, sols, robot, q, params, rng) -> tuple[str, str]:
    names = [f"q{k + 1}" for k in variables]
    samples = _zero_set_samples(f, variables, sols, robot, q, params, rng)
    generic = {(i, j) for i, j, _ in aligned_pairs(robot, random_q(robot, rng))}
    aligned = None
    for x in samples:
        pairs = {(i, j, kind) for i, j, kind in aligned_pairs(robot, x) if (i, j) not in generic}
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
        generic_par = _parallel_revolute_pairs(robot, random_q(robot, rng))
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
