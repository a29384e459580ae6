"""Base inertial parameters by grouping rules, in the DH symbols of the arm (Khalil & Kleinfinger 1987).

The parameters are those of :func:`denavit.numeric.regressor` (per body, about the origin of its joint frame, in
its axes).  Going from the tip to the base, joint j's own motion cannot tell apart what is invariant under it:

- revolute joint j (a rotation about z_j): the mass M_j, the first moment MZ_j along the axis and the part
  YY_j (1 − z zᵀ) of the inertia are a body that turns onto itself.  It is rigidly part of body j − 1, so it
  is moved there (XXR_j = XX_j − YY_j remains on body j) — Khalil & Kleinfinger 1987, eqs. (14)–(16); Khalil &
  Dombre 2002, §14.4.2, eq. 14.30;
- prismatic joint j (a translation along z_j): body j turns with body j − 1, so its rotational inertia
  (XX_j … ZZ_j) moves to body j − 1 (Khalil & Dombre 2002, eq. 14.32).

Moving a body (m, h, J) given in frame j into frame j − 1, with frame j at (R, p) there (the chain's constant
between the two joints, joint j at 0): h' = R h + m p, J' = R J Rᵀ + m(|p|² 1 − p pᵀ) + 2 (p·R h) 1 − R h pᵀ
− p (R h)ᵀ (parallel-axis theorem for first and second moments about a new origin).  What reaches body 0 (the
base) has no effect.  Then the first moving body turns about (or slides along) a fixed axis (Khalil & Dombre
2002, §14.4.3): revolute, only ZZR_1 acts on the torques — with the motor inertia, ZZR_1 = ZZ_1 + IA_1 — and
MX_1, MY_1 when gravity is not along the axis; prismatic, only the mass MR_1 (plus IA_1 when gravity is
perpendicular to the axis).

These are the general rules; special geometries (first axes parallel to gravity and to each other, …) can
leave more parameters without effect, which :func:`compare_base_parameters` shows against the numeric result.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import numpy as np
import sympy as sp

from ..chain import FLOATS, chain_of, walk
from ..model import DHRobot
from ..numeric import BODY_PARAMETERS, parameter_names

__all__ = ["SymbolicBaseParameters", "base_parameters_sym", "compare_base_parameters"]

_J = (("XX", "XY", "XZ"), ("XY", "YY", "YZ"), ("XZ", "YZ", "ZZ"))


@dataclass(frozen=True)
class SymbolicBaseParameters:
    """Grouping rules (data only; :func:`base_parameters_sym` makes it).

    Attributes
    ----------
    names : tuple of str
        The standard parameters (:func:`denavit.numeric.parameter_names`).
    kept : tuple of str
        The standard parameters that carry a base parameter, in π's order.
    base : tuple of sympy.Expr
        Per kept parameter its base parameter: the parameter plus what is grouped into it, linear in the
        standard parameters' symbols with coefficients in the DH symbols (``a2``, ``d3``, ``alpha4``, …).
    rules : tuple of (str, sympy.Expr)
        ``(name + "R", expression)`` for the kept parameters with something grouped into them.
    no_effect : tuple of str
        Parameters (after grouping) without effect on the torques, by the first-link rules.
    dh_values : tuple of (sympy.Symbol, float)
        The robot's values of the DH symbols.
    """

    names: tuple[str, ...]
    kept: tuple[str, ...]
    base: tuple
    rules: tuple
    no_effect: tuple[str, ...]
    dh_values: tuple


def _dh_symbols(robot: DHRobot):
    """The chain's constants C_0 … C_n with each non-zero length a, d a symbol named after its field and row
    (``a2``, ``d3``); the robot's own parameter names are kept where it has them.  Angles stay numbers (exact at
    multiples of π/2: the usual twists give cos, sin of 0 and ±1)."""
    links, params = [], dict(robot.parameters)
    for i, link in enumerate(robot.links):
        syms = dict(link.symbols)
        for field in ("a", "d"):
            v = float(getattr(link, field))
            if field in syms or v == 0.0:
                continue
            name = f"{field}{i + 1}"
            while name in params:
                name += "_"
            params[name] = v
            syms[field] = name
        links.append(link.replace(symbols=tuple(syms.items())) if hasattr(link, "replace") else
                     _with_symbols(link, tuple(syms.items())))
    labelled = robot.replace(links=tuple(links), parameters=tuple(params.items()))
    chain = chain_of(labelled)
    values = tuple((sp.Symbol(k, real=True), v) for k, v in params.items())
    return chain.constants_sym(False), values


def _with_symbols(link, symbols):
    import dataclasses

    return dataclasses.replace(link, symbols=symbols)


def _transfer(m, h, J, T):
    """(m, h, J) of a body in frame j → in frame j − 1, frame j at T = (R, p) there (module notes)."""
    R, p = T[:3, :3], T[:3, 3]
    Rh = R * h
    pRh = (p.T * Rh)[0, 0]
    J2 = R * J * R.T + m * ((p.T * p)[0, 0] * sp.eye(3) - p * p.T) + 2 * pRh * sp.eye(3) - Rh * p.T - p * Rh.T
    return m, Rh + m * p, J2


@dataclass(frozen=True)
class _Geometry:
    axes: tuple  # world axis directions at q = 0
    revolute: tuple
    r1: int  # first revolute joint (dof when none)
    r2: int  # first revolute joint after r1 not parallel to it (dof when none)
    along_u: frozenset  # prismatic joints in (r1, r2) sliding along u
    gravity: np.ndarray
    rotations: tuple  # joint frames' rotations at q = 0 (C_0 C_1 ⋯ C_k)


def _geometry(robot: DHRobot) -> _Geometry:
    """Joint 1 … r2 − 1 turn about one fixed direction u = axis r1, if at all (rotations about u keep it)."""
    chain = chain_of(robot)
    F = walk(chain, [0.0] * robot.dof, FLOATS, frames=True)
    axes = tuple(np.array(F[i][2]) for i in chain.axis_frame)
    n = robot.dof
    r1 = next((k for k in range(n) if chain.revolute[k]), n)
    r2 = n
    for k in range(r1 + 1, n):
        if chain.revolute[k] and np.linalg.norm(np.cross(axes[k], axes[r1])) > 1e-12:
            r2 = k
            break
    along = frozenset(k for k in range(r1 + 1, r2) if not chain.revolute[k]
                      and np.linalg.norm(np.cross(axes[k], axes[r1])) <= 1e-12)
    T, rotations = np.eye(4), []
    for C in chain.constants[:n]:
        T = T @ C
        rotations.append(T[:3, :3])
    return _Geometry(axes, chain.revolute, r1, r2, along, np.array(robot.gravity, dtype=float), tuple(rotations))


def _first_links(geo: _Geometry, expr: dict, P: dict, gone: set, motor_inertia: bool) -> list[str]:
    """The rules of the links before the first revolute joint r1 and up to the first revolute joint r2 not
    parallel to it (Khalil & Dombre 2002, §14.4.3): their bodies turn about one fixed direction u, if at all.

    Bodies before r1 only translate: MX, MY, MZ have no effect.  Bodies r1 … r2 − 1 that turn (revolute) turn
    about u: of their inertia only ZZ acts (XX, XY, XZ, YZ none), and ZZR_r1 = ZZ_r1 + IA_r1 (both act as
    ZZ q̈_r1 on joint r1 alone); so does ZZR_r2 = ZZ_r2 + IA_r2 when axis r2 is perpendicular to u.  A body
    sliding along u in that range: MZ has no effect, MX and MY join body j − 1 (the loop of
    :func:`base_parameters_sym`); one sliding along another direction: its first moment along u has no effect
    (:func:`_along_u_first_moment`).  With r1 the first joint: MX_1, MY_1 act only through gravity, so not when
    gravity is along u.  A prismatic first joint with gravity perpendicular to it: MR_1 = M_1 + IA_1.
    """
    axes, g, n = geo.axes, geo.gravity, len(geo.axes)
    small = 1e-12 * max(1.0, float(np.linalg.norm(g)))
    out: list[str] = [f"{c}{k + 1}" for k in range(geo.r1) for c in ("MX", "MY", "MZ")]
    out += [f"MZ{k + 1}" for k in sorted(geo.along_u)]
    if not geo.revolute[0] and motor_inertia and abs(axes[0] @ g) <= small:
        expr["M1"] = expr["M1"] + P["IA1"]
        gone.add("IA1")
    if geo.r1 == n:
        return out
    u = axes[geo.r1]
    out += [f"{c}{k + 1}" for k in range(geo.r1, geo.r2) if geo.revolute[k] for c in ("XX", "XY", "XZ", "YZ")]
    for k in range(geo.r1 + 1, geo.r2):
        if not geo.revolute[k] and k not in geo.along_u:
            _along_u_first_moment(k, geo.rotations[k].T @ u, expr, gone)
    for k in (geo.r1,) + ((geo.r2,) if geo.r2 < n and abs(axes[geo.r2] @ u) <= 1e-12 else ()):
        if motor_inertia:
            expr[f"ZZ{k + 1}"] = expr[f"ZZ{k + 1}"] + P[f"IA{k + 1}"]
            gone.add(f"IA{k + 1}")
    if geo.r1 == 0 and np.linalg.norm(np.cross(u, g)) <= small:
        out += ["MX1", "MY1"]
    return out


def _along_u_first_moment(k: int, uk, expr: dict, gone: set) -> None:
    """Body k slides (not along u) and turns about u only: its first moment along u (u_k in its frame) acts on
    no torque (ω̇ × h, ω × (ω × h) vanish and u·(h × a) = 0 for h ∥ u), so u_k · (MX, MY, MZ) has no effect: the
    last of MX, MY, MZ with u_k's component ≠ 0 is grouped into the others (MXR = MX − (u_x/u_z) MZ, …)."""
    b = f"{k + 1}"
    names = ("MX" + b, "MY" + b, "MZ" + b)
    i = max(j for j in range(3) if abs(uk[j]) > 1e-12)
    for j in range(i):
        if abs(uk[j]) > 1e-12:
            expr[names[j]] = expr[names[j]] - sp.Float(uk[j] / uk[i]) * expr[names[i]]
    gone.add(names[i])


@lru_cache(maxsize=16)
def base_parameters_sym(robot: DHRobot, *, friction: bool = True, motor_inertia: bool = True) -> SymbolicBaseParameters:
    """The base parameters of ``robot`` by the grouping rules of the module notes, in its DH symbols.

    Examples
    --------
    >>> import denavit
    >>> from denavit.symbolic import base_parameters_sym
    >>> b = base_parameters_sym(denavit.load_robot("planar2r"), friction=False, motor_inertia=False)
    >>> b.kept
    ('MX1', 'MY1', 'ZZ1', 'MX2', 'MY2', 'ZZ2')
    """
    names = parameter_names(robot, friction=friction, motor_inertia=motor_inertia)
    P = {name: sp.Symbol(name, real=True) for name in names}
    expr = dict(P)
    C, values = _dh_symbols(robot)
    n = robot.dof
    gone: set = set()
    revolute = chain_of(robot).revolute
    geo = _geometry(robot)
    for k in range(n - 1, -1, -1):
        b = f"{k + 1}"
        Jk = sp.Matrix(3, 3, lambda i, j: expr[_J[i][j] + b])
        if revolute[k]:
            yy = expr["YY" + b]
            virtual = (expr["M" + b], sp.Matrix([0, 0, expr["MZ" + b]]), sp.diag(yy, yy, 0))
            expr["XX" + b] = expr["XX" + b] - yy
            gone |= {"M" + b, "MZ" + b, "YY" + b}
        else:
            virtual = (sp.Integer(0), sp.zeros(3, 1), Jk)
            gone |= {_J[i][j] + b for i in range(3) for j in range(3)}
            if k in geo.along_u:  # slides along u inside the parallel range: MX, MY ride on body k − 1
                virtual = (sp.Integer(0), sp.Matrix([expr["MX" + b], expr["MY" + b], 0]), Jk)
                gone |= {"MX" + b, "MY" + b}
        if k == 0:
            break  # into the base: no effect
        m, h, J = _transfer(*virtual, sp.Matrix(C[k]))
        a = f"{k}"
        expr["M" + a] = expr["M" + a] + m
        for i, c in enumerate(("MX", "MY", "MZ")):
            expr[c + a] = expr[c + a] + h[i]
        for i, j in ((0, 0), (0, 1), (1, 1), (0, 2), (1, 2), (2, 2)):
            expr[_J[i][j] + a] = expr[_J[i][j] + a] + J[i, j]
    no_effect = _first_links(geo, expr, P, gone, motor_inertia)
    kept = tuple(name for name in names if name not in gone and name not in no_effect)
    base = tuple(_tidy(expr[name]) for name in kept)
    rules = tuple((name + "R", e) for name, e in zip(kept, base) if e != P[name])
    return SymbolicBaseParameters(names, kept, base, rules, tuple(no_effect), values)


def _tidy(e):
    """Collected by parameter symbol, each coefficient simplified; float terms below 1e-12 (the rounding left where
    cos²θ + sin²θ of a numeric offset cancels) dropped."""
    e = sp.expand(e)
    params = sorted((s for s in e.free_symbols if s.name.rstrip("0123456789") in BODY_PARAMETERS + ("FV", "FC", "IA")),
                    key=lambda s: s.name)
    out = sp.Integer(0)
    for monomial, c in (sp.Poly(e, *params).as_dict() if params else {}).items():
        terms = [t for t in sp.Add.make_args(sp.expand(c)) if not _negligible(t)]
        if not terms:
            continue
        c = sp.Add(*terms)
        c = c if c.has(sp.Float) else sp.factor(c)
        out += c * sp.Mul(*[s ** k for s, k in zip(params, monomial)])
    return out


def _negligible(term) -> bool:
    number, _ = term.as_coeff_Mul()
    return isinstance(number, sp.Float) and abs(float(number)) < 1e-12


def compare_base_parameters(robot: DHRobot, sym: SymbolicBaseParameters, base) -> tuple[bool, bool]:
    """``(same_span, same_values)`` of the symbolic and the numeric (:func:`denavit.numeric.base_parameters`)
    base parameters: the rows of K (π_b = K π) span the same space, and where both keep the same parameters the
    robot's base-parameter values agree (to 1e-9 relative)."""
    subs = dict(sym.dh_values)
    index = {sp.Symbol(name, real=True): i for i, name in enumerate(sym.names)}
    K = np.zeros((len(sym.base), len(index)))
    for row, e in enumerate(sym.base):
        for term in sp.Add.make_args(e):  # each term: (coefficient in the DH symbols) × one parameter
            (param,) = [s for s in term.free_symbols if s in index]
            K[row, index[param]] += float((term / param).subs(subs))
    Kn = np.asarray(base.combination)
    rank = np.linalg.matrix_rank
    tol = 1e-9 * max(1.0, np.abs(Kn).max())
    same_span = (K.shape[0] == base.rank == rank(K, tol) == rank(np.vstack([K, Kn]), tol))
    kept_numeric = tuple(base.names[i] for i in base.independent)
    if not same_span or kept_numeric != sym.kept:
        return same_span, False
    from ..numeric import inertial_parameters

    values = K @ inertial_parameters(robot, friction=base.friction, motor_inertia=base.motor_inertia)
    return True, bool(np.allclose(values, base.values, rtol=1e-9, atol=1e-9 * max(1.0, np.abs(values).max())))
