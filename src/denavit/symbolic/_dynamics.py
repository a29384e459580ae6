"""Symbolic equations of motion M(q) q̈ + C(q, q̇) q̇ + g(q) (+ τ_f) = τ, and their compact display.

The fast route (:func:`lagrangian_dynamics`) is the Lagrangian one written with Jacobians:
K = ½ q̇ᵀ M q̇ with M = Σ m J_vᵀ J_v + J_ωᵀ R I Rᵀ J_ω over the inertial pieces, P = −Σ m gᵀ p_c, so that
the Euler–Lagrange equations give g = ∂P/∂q = −Σ m J_vᵀ g and the velocity terms follow from the Christoffel
symbols of M (Spong, Hutchinson, Vidyasagar 2006, sec. 7.3, eqs. 7.50–7.58).  Each entry of M is collapsed
with the "trig" policy as it is formed, which keeps the result small and is what makes the Puma 560 quick.
The literal route with every step a report shows is :func:`denavit.symbolic.lagrange_steps`; the
Newton–Euler route is :func:`denavit.symbolic.newton_euler_dynamics`.

Frames: positions and axes are in the base DH frame {0}; gravity is ``robot.gravity`` turned into {0} axes
by the base rotation.  Bodies and pieces as in :mod:`denavit.numeric._dynamics` (a fixed row's inertia is
carried by the preceding moving link).
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from typing import Callable

import sympy as sp

from .. import _expr
from ..chain import chain_of
from ..errors import ModelError
from ..model import DHRobot, JointType, inertial_rows
from ._kinematics import link_matrices_sym
from ._dynamics_trig import collect_trig, fourier_form
from ._simplify import POLICIES, shorthand, simplify_expr
from ._symbols import joint_symbols, matrix_from_floats, parameter_symbols

__all__ = [
    "DynamicsTerms",
    "InertialPiece",
    "inertial_pieces",
    "lagrangian_dynamics",
    "christoffel_matrix",
    "terms_from_tau",
    "format_dynamics",
]

Progress = Callable[[str, int, int], None]
CSE_AUTO_CHARS = 3000  # format_dynamics pulls out common subexpressions above this total length


@dataclass(frozen=True)
class DynamicsTerms:
    """M(q), C(q, q̇), c = C q̇, g(q) and friction τ_f(q̇) as sympy matrices (column vectors for c, g, τ_f)."""

    M: sp.ImmutableMatrix
    C: sp.ImmutableMatrix | None
    c: sp.ImmutableMatrix
    g: sp.ImmutableMatrix
    friction: sp.ImmutableMatrix
    q: tuple[sp.Symbol, ...]
    qd: tuple[sp.Symbol, ...]
    qdd: tuple[sp.Symbol, ...]
    form: str = "expanded"
    """"hand": each entry a sum of parameter groups times sines and cosines (``simplify="trig"``)."""
    gravity: sp.Expr | None = None
    """|g₀| [m/s²] when ``g_unit`` is given."""
    g_unit: sp.ImmutableMatrix | None = None
    """g(q) per unit of gravitational acceleration (g = |g₀| · g_unit): presenters write g as a symbol."""

    def _repr_latex_(self) -> str:
        from ..display import dynamics_latex

        return dynamics_latex(self)

    @property
    def tau(self) -> sp.ImmutableMatrix:
        """τ = M q̈ + c + g + τ_f."""
        return sp.ImmutableMatrix(self.M * sp.Matrix(self.qdd) + self.c + self.g + self.friction)


@dataclass(frozen=True)
class InertialPiece:
    """One row's inertial data as sympy: ``row`` (DH row), ``body`` (joint index), mass, COM, inertia in {row}."""

    row: int
    body: int
    mass: sp.Expr
    com: sp.ImmutableMatrix
    inertia: sp.ImmutableMatrix


def _number(x: float) -> sp.Expr:
    return sp.Integer(0) if x == 0 else sp.nsimplify(sp.Rational(repr(float(x))), [sp.pi], rational=True)


def _values(robot: DHRobot, numeric: bool) -> tuple[dict[str, sp.Symbol], dict[sp.Symbol, sp.Expr]]:
    syms = parameter_symbols(robot)
    vals = {syms[k]: sp.Rational(repr(v)) for k, v in robot.parameters}
    return syms, (vals if numeric else {})


def _field(li, key: str, value: float, syms, subs) -> sp.Expr:
    text = dict(li.symbols).get(key)
    if text is None:
        return _number(value)
    e = _expr.to_sympy(_expr.parse(text), syms)
    e = e.xreplace({f: sp.Rational(repr(float(f))) for f in e.atoms(sp.Float)})  # exact decimals: terms cancel
    return e.subs(subs) if subs else e


def inertial_pieces(robot: DHRobot, numeric: bool = False) -> list[InertialPiece]:
    """The inertial data of every moving row, with named parameters kept as symbols (``numeric`` substitutes)."""
    syms, subs = _values(robot, numeric)
    out = []
    for r, body, li in inertial_rows(robot):
        m = _field(li, "mass", li.mass, syms, subs)
        com = sp.ImmutableMatrix([_field(li, f"com{i}", li.com[i], syms, subs) for i in range(3)])
        xx, yy, zz, xy, xz, yz = (_field(li, f"inertia{i}", li.inertia[i], syms, subs) for i in range(6))
        out.append(InertialPiece(r, body, m, com, sp.ImmutableMatrix([[xx, xy, xz], [xy, yy, yz], [xz, yz, zz]])))
    if not out:
        raise ModelError(f"robot {robot.name!r} has no inertial data: add 'inertia:' to its joint rows")
    return out


def joint_parameters(robot: DHRobot, numeric: bool = False) -> tuple[list[sp.Expr], list[sp.Expr], list[sp.Expr]]:
    """Motor inertia, viscous and Coulomb coefficients of every joint, as sympy."""
    syms, subs = _values(robot, numeric)
    out: tuple[list, list, list] = ([], [], [])
    for link in robot.joints:
        li = link.inertia
        for lst, key in zip(out, ("motor_inertia", "viscous", "coulomb")):
            lst.append(_field(li, key, getattr(li, key), syms, subs) if li is not None else sp.Integer(0))
    return out


def gravity_base(robot: DHRobot) -> sp.ImmutableMatrix:
    """Gravity in base-frame {0} axes: R_baseᵀ g_world, exact where the numbers are simple."""
    R = matrix_from_floats(robot.base_matrix)[:3, :3]
    g = sp.Matrix([_number(x) for x in robot.gravity])
    return sp.ImmutableMatrix(R.T * g)


def joint_axes_sym(robot: DHRobot, T: tuple[sp.ImmutableMatrix, ...]) -> list[tuple[sp.Matrix, sp.Matrix]]:
    """(z, o) of each joint in {0}: standard z_{i-1}, o_{i-1}; modified z_i, o_i (the chain's axis frames)."""
    return [(T[f][:3, 2], T[f][:3, 3]) for f in chain_of(robot).axis_frame]


def friction_vector(robot: DHRobot, qd, numeric: bool = False) -> sp.ImmutableMatrix:
    _, fv, fc = joint_parameters(robot, numeric)
    return sp.ImmutableMatrix([fv[k] * qd[k] + fc[k] * sp.sign(qd[k]) for k in range(robot.dof)])


def make_simplifier(robot: DHRobot, policy: str) -> Callable[[sp.Expr], sp.Expr]:
    """The simplification used for dynamics terms.

    ``"trig"`` is the canonical Fourier form in the revolute joint angles
    (:func:`~denavit.symbolic._dynamics_trig.fourier_form`: c2·c23 + s2·s23 → cos q3); ``"none"`` leaves
    entries as formed; ``"full"`` is sympy's ``simplify`` (slow).
    """
    if policy not in POLICIES:
        raise ValueError(f"unknown simplification policy {policy!r}; choose one of {', '.join(POLICIES)}")
    q = joint_symbols(robot.dof).q
    revolute = tuple(t is JointType.REVOLUTE for t in robot.joint_types)
    if policy == "trig":
        return lambda e: fourier_form(e, q, revolute)
    return lambda e: simplify_expr(e, policy)


def _collector(robot: DHRobot, policy: str) -> Callable[[sp.Expr], sp.Expr]:
    """For sums and derivatives of entries already simplified: a cheap collection for "trig"."""
    return collect_trig if policy == "trig" else make_simplifier(robot, policy)


def _report(progress: Progress | None, stage: str, done: int, total: int) -> None:
    if progress is not None:
        progress(stage, done, total)


def lagrangian_dynamics(robot: DHRobot, simplify: str = "trig", numeric: bool = False,
                        progress: Progress | None = None, coriolis: bool = True) -> DynamicsTerms:
    """Equations of motion by the Lagrangian route in Jacobian form, with C from Christoffel symbols.

    Parameters
    ----------
    robot : DHRobot
        With inertial data; named parameters (``m1``, ``Lc1``, ``I1``…) stay symbols unless ``numeric``.
    simplify : {"none", "trig", "full"}
        ``"trig"`` (default): computed on polynomials in the sines and cosines of the link angles
        (:mod:`~denavit.symbolic._dynamics_ring`: angle sums C23 for parallel axes, each entry a sum of
        parameter groups times sines and cosines; Puma 560 in about a second, Panda in under a minute);
        ``"none"``/``"full"``: the entries as formed by sympy, or through ``simplify`` (slow).
    progress : callable(stage, done, total), optional
        Called as the work proceeds (for long derivations).
    coriolis : bool
        Also form the matrix C (c is always formed).

    Notes
    -----
    .. math::
        M = \\sum_p m_p J_{v,p}^T J_{v,p} + J_{\\omega,p}^T R_p I_p R_p^T J_{\\omega,p},\\quad
        g = -\\sum_p m_p J_{v,p}^T g_0,\\quad
        C_{kj} = \\sum_i \\tfrac12 (\\partial_i M_{kj} + \\partial_j M_{ki} - \\partial_k M_{ij}) \\dot q_i

    (Spong, Hutchinson, Vidyasagar 2006, eqs. 7.46, 7.57; motor inertia adds to M's diagonal, eq. 7.97.)
    """
    js = joint_symbols(robot.dof)
    q, qd, qdd = js.q, js.qd, js.qdd
    if simplify == "trig":  # the same formulas on polynomials, in hand form (C23 …): _dynamics_ring
        from ._dynamics_ring import ring_dynamics

        M, C, c, g, size, g_unit = ring_dynamics(robot, numeric, coriolis, progress)
        _report(progress, "done", 1, 1)
        return DynamicsTerms(M, C, c, g, friction_vector(robot, qd, numeric), q, qd, qdd, "hand", size, g_unit)
    n = robot.dof
    pieces = inertial_pieces(robot, numeric)
    armature, _, _ = joint_parameters(robot, numeric)
    chain = _Chain(robot, numeric)
    simp = make_simplifier(robot, simplify)
    M = sp.zeros(n, n)
    total = n * (n + 1) // 2
    done = 0
    for j in range(n):
        for k in range(j, n):
            _report(progress, "mass matrix", done, total)
            done += 1
            e = sum((_mass_entry(robot, chain, p, j, k) for p in pieces if p.body >= k), sp.Integer(0))
            M[j, k] = M[k, j] = simp(e + (armature[j] if j == k else 0))
    M = sp.ImmutableMatrix(M)
    g = _gravity_vector(robot, chain, pieces, simp)
    gamma = christoffel_symbols(M, q, _collector(robot, simplify), progress)
    C = _coriolis_from_gamma(gamma, qd) if coriolis else None
    c = _velocity_from_gamma(gamma, qd)
    _report(progress, "done", 1, 1)
    return DynamicsTerms(M, C, c, g, friction_vector(robot, qd, numeric), q, qd, qdd)


class _Chain:
    """Relative transforms T_a_b = A_{a+1} ⋯ A_b between DH frames, built once (rows and axis frames from
    :mod:`denavit.chain`)."""

    def __init__(self, robot: DHRobot, numeric: bool) -> None:
        self.A = link_matrices_sym(robot, numeric)
        self.cache: dict[tuple[int, int], sp.ImmutableMatrix] = {}
        self.axis_frame = list(chain_of(robot).axis_frame)

    def __call__(self, a: int, b: int) -> sp.ImmutableMatrix:
        if (a, b) not in self.cache:
            if b == a:
                T = sp.ImmutableMatrix(sp.eye(4))
            else:
                T = sp.ImmutableMatrix(self(a, b - 1) * self.A[b - 1])
            self.cache[a, b] = T
        return self.cache[a, b]


def _jacobian_column(robot: DHRobot, chain: _Chain, p: InertialPiece, ref: int, j: int):
    """(v, ω_local) of piece p for unit rate of joint j, v in the axes of frame {ref}, ω in the piece's axes."""
    a = chain.axis_frame[j]
    T_rp = chain(ref, p.row + 1)
    c = T_rp[:3, :3] * p.com + T_rp[:3, 3]  # COM in {ref}
    T_ra = chain(ref, a)
    z, o = T_ra[:3, 2], T_ra[:3, 3]
    if robot.joint_types[j] is JointType.PRISMATIC:
        return z, sp.zeros(3, 1)
    w_local = chain(a, p.row + 1)[2, :3].T  # ẑ of axis j in the piece's axes: R_a_pᵀ ẑ
    return z.cross(c - o), w_local


def _mass_entry(robot: DHRobot, chain: _Chain, p: InertialPiece, j: int, k: int) -> sp.Expr:
    """Piece p's part of M_jk (j ≤ k), worked in the axis frame of joint j, where M_jk needs no q_1…q_j."""
    ref = chain.axis_frame[j]
    vj, wj = _jacobian_column(robot, chain, p, ref, j)
    vk, wk = _jacobian_column(robot, chain, p, ref, k)
    return p.mass * vj.dot(vk) + (wj.T * p.inertia * wk)[0]


def _gravity_vector(robot: DHRobot, chain: _Chain, pieces, simp) -> sp.ImmutableMatrix:
    """g_j = −Σ m (z_j × (c − o_j))·g, each term in the axis frame of joint j (gravity turned into it)."""
    g0 = gravity_base(robot)
    out = []
    for j in range(robot.dof):
        ref = chain.axis_frame[j]
        g_ref = chain(0, ref)[:3, :3].T * g0
        e = sum((-p.mass * _jacobian_column(robot, chain, p, ref, j)[0].dot(g_ref) for p in pieces if p.body >= j),
                sp.Integer(0))
        out.append(simp(e))
    return sp.ImmutableMatrix(out)


def christoffel_symbols(M: sp.MatrixBase, q, simp: Callable[[sp.Expr], sp.Expr] = sp.expand,
                        progress: Progress | None = None) -> dict[tuple[int, int, int], sp.Expr]:
    """Γ_ijk = ½(∂M_kj/∂q_i + ∂M_ki/∂q_j − ∂M_ij/∂q_k) for i ≤ j (Γ_ijk = Γ_jik), Spong eq. 7.51."""
    n = len(q)
    dM = {}
    for i in range(n):
        for j in range(n):
            for k in range(j, n):
                dM[i, j, k] = dM[i, k, j] = sp.diff(M[j, k], q[i])
    gamma = {}
    for k in range(n):
        _report(progress, "Christoffel symbols", k, n)
        for i in range(n):
            for j in range(i, n):
                gamma[i, j, k] = simp((dM[i, k, j] + dM[j, k, i] - dM[k, i, j]) / 2)
    return gamma


def _gamma(gamma, i, j, k):
    return gamma[(i, j, k) if i <= j else (j, i, k)]


def christoffel_matrix(M: sp.MatrixBase, q, qd, simp: Callable[[sp.Expr], sp.Expr] = sp.expand,
                       progress: Progress | None = None) -> sp.ImmutableMatrix:
    """C(q, q̇) with C_kj = Σ_i Γ_ijk q̇_i (Spong eq. 7.52); Ṁ − 2C is skew-symmetric."""
    gamma = christoffel_symbols(M, q, simp, progress)
    return _coriolis_from_gamma(gamma, qd)


def _coriolis_from_gamma(gamma, qd) -> sp.ImmutableMatrix:
    n = len(qd)
    return sp.ImmutableMatrix(n, n, [sum((_gamma(gamma, i, j, k) * qd[i] for i in range(n)), sp.Integer(0))
                                     for k in range(n) for j in range(n)])


def _velocity_from_gamma(gamma, qd) -> sp.ImmutableMatrix:
    """c_k = Σ_{i≤j} (2 − δ_ij) Γ_ijk q̇_i q̇_j, each coefficient kept as simplified."""
    n = len(qd)
    return sp.ImmutableMatrix([
        sum(((1 if i == j else 2) * gamma[i, j, k] * qd[i] * qd[j] for i in range(n) for j in range(i, n)),
            sp.Integer(0))
        for k in range(n)])


def terms_from_tau(tau: sp.MatrixBase, q, qd, qdd, friction: sp.MatrixBase,
                   simp: Callable[[sp.Expr], sp.Expr] = sp.expand, coriolis: bool = True) -> DynamicsTerms:
    """Split τ(q, q̇, q̈) (friction excluded) into M = ∂τ/∂q̈, g = τ|_{q̇=q̈=0}, c = τ − M q̈ − g."""
    n = len(q)
    zero = {**{s: 0 for s in qd}, **{s: 0 for s in qdd}}
    tau = [sp.expand(t) for t in tau]
    M = sp.ImmutableMatrix(n, n, [simp(tau[k].diff(qdd[j])) for k in range(n) for j in range(n)])
    g = sp.ImmutableMatrix([simp(tau[k].subs(zero)) for k in range(n)])
    c = sp.ImmutableMatrix([simp(tau[k].subs({s: 0 for s in qdd}) - g[k]) for k in range(n)])
    C = christoffel_matrix(M, q, qd, simp) if coriolis else None
    return DynamicsTerms(M, C, c, g, sp.ImmutableMatrix(friction), tuple(q), tuple(qd), tuple(qdd))


# ---------------------------------------------------------------------------------------------------
# presentation: text, LaTeX, Markdown, with common subexpressions pulled out


def _display(e: sp.Expr, q, digits: int | None, short: bool, collapse: bool = True) -> sp.Expr:
    if digits is not None:
        e = e.xreplace({r: sp.Float(r, digits) for r in e.atoms(sp.Rational) if r.q != 1 and r.q > 12})
    return shorthand(e, q, collapse=collapse) if short else e


_TRAILING = re.compile(r"(?<![\w.])(\d+\.\d*?[1-9])0+(?![\d])|(?<![\w.])(\d+)\.0+(?![\d.e])")


def _trim(text: str) -> str:
    """0.00576000 → 0.00576, 2.00000 → 2 (plain-text output only)."""
    return _TRAILING.sub(lambda m: m.group(1) or m.group(2), text)


LONG_NODES = 200_000  # expression nodes above which format_dynamics prints terms in sympy's internal order


def _size(e: sp.Expr) -> int:
    """Number of nodes of an expression tree (cheap; printing pages of output to measure them is not)."""
    return sum(1 for _ in sp.preorder_traversal(e))


def _is_group(a: sp.Expr, rates) -> bool:
    return isinstance(a, sp.Add) and len(a.args) > 1 and not a.has(sp.sin, sp.cos, *rates)


def _group_key(a: sp.Add) -> tuple[sp.Expr, int]:
    """The group with a canonical sign (its first term, in sympy's order, positive) and that sign."""
    first = sp.Add.make_args(a)[0]
    return (a, 1) if not first.could_extract_minus_sign() else (-a, -1)


def _walk_groups(e: sp.Expr, rates, visit) -> sp.Expr:
    """Rebuild e with every parameter group (a sum of parameter terms, no sines, cosines or rates) passed
    through visit(group) -> replacement; sums containing sines or rates are walked into."""
    if isinstance(e, sp.Add):
        if _is_group(e, rates):
            return visit(e)
        return sp.Add(*[_walk_groups(t, rates, visit) for t in e.args])
    if isinstance(e, sp.Mul):
        return sp.Mul(*[_walk_groups(f, rates, visit) for f in e.args])
    return e


GROUP_NAME_CHARS = 40  # a parameter group longer than this, or occurring twice, is named P1, P2 … by format_dynamics


def _name_groups(exprs: list[sp.Expr], rates) -> tuple[list[tuple[sp.Symbol, sp.Expr]], list[sp.Expr]]:
    """Parameter groups that recur or are long get names P1, P2 … (in order of first use)."""
    count: dict[sp.Expr, int] = {}

    def tally(a):
        key, _ = _group_key(a)
        count[key] = count.get(key, 0) + 1
        return a

    for e in exprs:
        _walk_groups(e, rates, tally)
    names: dict[sp.Expr, sp.Symbol] = {}

    def name(a):
        key, sign = _group_key(a)
        if count[key] < 2 and len(str(key)) <= GROUP_NAME_CHARS:
            return a
        if key not in names:
            names[key] = sp.Symbol(f"P{len(names) + 1}", real=True)
        return sign * names[key]

    out = [_walk_groups(e, rates, name) for e in exprs]
    return [(v, k) for k, v in names.items()], out


def _name_rate_coefficients(exprs: list[sp.Expr], rates) -> tuple[list[tuple[sp.Symbol, sp.Expr]], list[sp.Expr]]:
    """Coefficients of q̇ᵢq̇ⱼ that recur (up to a rational factor, e.g. 2Γ in one row and Γ in another) are named
    B1, B2 … and defined once."""
    def split(e):
        out = []
        for t in sp.Add.make_args(e):
            coeff, mono = t.as_independent(*rates, as_Add=False)
            out.append((coeff, mono))
        return out

    def key(coeff):  # expanded (canonical) when small; long ones compared as built (expanding them costs minutes)
        x = sp.expand(coeff) if _size(coeff) < 3000 else coeff
        lead = sp.Add.make_args(x)[0].as_coeff_Mul()[0]
        return (sp.expand(x / lead) if x is not coeff else x / lead), lead

    count: dict[sp.Expr, int] = {}
    for e in exprs:
        if e.has(*rates):
            for coeff, mono in split(e):
                if mono != 1 and isinstance(coeff, (sp.Add, sp.Mul)) and coeff.has(sp.sin, sp.cos):
                    k, _ = key(coeff)
                    count[k] = count.get(k, 0) + 1
    names: dict[sp.Expr, tuple[sp.Symbol, sp.Expr]] = {}
    out = []
    for e in exprs:
        if not e.has(*rates):
            out.append(e)
            continue
        terms = []
        for coeff, mono in split(e):
            if mono != 1 and isinstance(coeff, (sp.Add, sp.Mul)) and coeff.has(sp.sin, sp.cos):
                k, lead = key(coeff)
                if count[k] > 1:
                    if k not in names:  # defined as it first occurs; later ones are a multiple (2, −1, ½ …)
                        names[k] = (sp.Symbol(f"B{len(names) + 1}", real=True), coeff, lead)
                    sym, _, first = names[k]
                    terms.append(sp.nsimplify(lead / first) * sym * mono)
                    continue
            terms.append(coeff * mono)
        out.append(sp.Add(*terms))
    return [(sym, e) for sym, e, _ in names.values()], out


def format_dynamics(terms: DynamicsTerms, style: str = "text", cse: bool | None = None, short: bool = True,
                    digits: int | None = 6, include: tuple[str, ...] = ("M", "c", "g", "friction"),
                    gravity_symbol: bool = False) -> str:
    """The equations of motion as text, LaTeX or Markdown.

    M is written by its upper triangle (M[j,k], j ≤ k; it is symmetric, as the header says).
    Entries in hand form (``lagrangian_dynamics(simplify="trig")``) are written entry by entry, each a sum
    of parameter groups times sines and cosines; when the entries are long (over ``CSE_AUTO_CHARS``
    characters in all, and ``cse`` is not False) a group that recurs or is longer than ``GROUP_NAME_CHARS``
    is named P1, P2 … (π₁, π₂ … in LaTeX) and defined first. With ``gravity_symbol`` gravity is the symbol
    g (its value in the header; g = |g₀| · g_unit). Other forms: ``cse`` pulls repeated subexpressions out as
    x0, x1, … (``sympy.cse``; ``None``: only when the entries are long). ``short`` writes cos(q1 + q2) as C12
    (LaTeX C_{12}; the Coriolis matrix's entries are \\mathcal{C}_{12}); ``digits``: fractions with
    denominators above 12 are printed as decimals of that many significant digits (trailing zeros dropped
    in text).
    """
    if style not in ("text", "latex", "markdown"):
        raise ValueError(f"unknown style {style!r}; choose one of text, latex, markdown")
    n = len(terms.q)
    hand = terms.form == "hand"
    blocks = {"M": terms.M, "C": terms.C, "c": terms.c, "g": terms.g, "friction": terms.friction}
    notes = []
    G = sp.Symbol("g", positive=True)
    taken = {str(s) for m in (terms.M, terms.g) for s in m.free_symbols}
    if gravity_symbol and terms.g_unit is not None and "g" not in taken and "g" in include:
        blocks["g"] = sp.ImmutableMatrix([G * e for e in terms.g_unit])
        notes.append(f"g = {_trim(sp.sstr(sp.Float(terms.gravity, 6)))} m/s^2 (gravitational acceleration)")
    entries: list[tuple[str, sp.Expr]] = []
    for name in include:
        mat = blocks[name]
        if mat is None:
            continue
        for i in range(mat.shape[0]):
            for j in range(i if name == "M" else 0, mat.shape[1]):  # M is symmetric: its upper triangle
                label = f"{name}[{i + 1},{j + 1}]" if mat.shape[1] > 1 else f"{name}[{i + 1}]"
                entries.append((label, mat[i, j]))
    exprs = [e for _, e in entries]
    repl: list[tuple[sp.Symbol, sp.Expr]] = []
    nodes = sum(_size(e) for e in exprs)
    long = nodes > CSE_AUTO_CHARS or sum(len(str(e)) for e in exprs) > CSE_AUTO_CHARS  # printing only short ones
    grouped = hand and cse is not False and long
    if grouped:
        rates, exprs = _name_rate_coefficients(exprs, terms.qd) if nodes <= LONG_NODES else ([], exprs)
        repl, named = _name_groups([e for _, e in rates] + exprs, terms.qd)
        repl += [(s, e) for (s, _), e in zip(rates, named[:len(rates)])]
        exprs = named[len(rates):]
    show = lambda e: _display(e, terms.q, digits, short, collapse=not hand)  # noqa: E731
    repl, exprs = [(s, show(e)) for s, e in repl], [show(e) for e in exprs]
    if not hand:
        if cse is None:
            cse = long
        if cse:
            repl, exprs = sp.cse(exprs, symbols=sp.numbered_symbols("x"), optimizations="basic")
    pairs = [(str(s), e) for s, e in repl] + [(label, e) for (label, _), e in zip(entries, exprs)]
    head = f"M(q) q'' + c(q, q') + g(q) + tau_f(q') = tau   ({n} joints)"
    if "M" in include and n > 1:
        notes.append("M is symmetric: M[k,j] = M[j,k]")
    if short:
        notes.append("Ci = cos(qi), Sij = sin(qi + qj), …")
    order = "none" if nodes > LONG_NODES else None  # sorting the terms of pages of output costs minutes
    if style == "text":
        return "\n".join([head] + [f"  {x}" for x in notes] + [""] +
                         [f"{k} = {_trim(sp.sstr(e, order=order))}" for k, e in pairs])
    names = _latex_names([e for _, e in pairs])
    tex = [(_tex_label(k), sp.latex(e, symbol_names=names, order=order)) for k, e in pairs]
    if "M" in include and n > 1:  # the upper triangle is written
        tex.append(("M_{kj}", "M_{jk} \\quad (j < k)"))
    if style == "latex":
        rows = " \\\\\n".join(f"{k} &= {v}" for k, v in tex)
        return "\\begin{aligned}\n" + rows + "\n\\end{aligned}"
    lines = [f"**{head}**", ""] + [f"$${k} = {v}$$" for k, v in tex]
    return "\n\n".join(lines)


def _latex_names(exprs: list[sp.Expr]) -> dict[sp.Symbol, str]:
    """Parameter groups P1 as \\pi_{1}, rate coefficients B1 as \\beta_{1}."""
    greek = {"P": "pi", "B": "beta"}
    return {s: f"\\{greek[s.name[0]]}_{{{s.name[1:]}}}" for e in exprs for s in e.free_symbols
            if s.name[:1] in greek and s.name[1:].isdigit()}


def _tex_label(label: str) -> str:
    if "[" not in label:
        if label[:1] in "PB" and label[1:].isdigit():
            return f"\\{'pi' if label[0] == 'P' else 'beta'}_{{{label[1:]}}}"
        return label.replace("x", "x_{", 1) + "}" if label.startswith("x") else label
    name, idx = label[:-1].split("[")
    if name == "friction":  # one subscript: \tau_{f}_{1} is a LaTeX error
        return f"\\tau_{{f,{idx.replace(',', '')}}}"
    if name == "C":  # C_{12} is the shorthand of cos(q1 + q2)
        return f"\\mathcal{{C}}_{{{idx.replace(',', '')}}}"
    return f"{name}_{{{idx.replace(',', '')}}}"
