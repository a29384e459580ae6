"""M(q), c(q, q̇), g(q) in recursive form: short formulas in named intermediate quantities, as a textbook prints them.

For an arm whose expanded entries run to pages (the Panda: no two consecutive axes parallel, M₁₁ alone is
pages), the equations of motion are written the way Craig (2005, ch. 6) and Featherstone (2008, ch. 6) write
them: as recursions over the links, each step one short formula per vector component, in

* **body frames** B_j: attached to body j, z along joint j's axis, origin on it (the DH frame where the joint's
  axis is z, moved by the joint); T(B_{j−1}, B_j) = K_j · Rz(q_j) (or · Tz(q_j)), K_j constant;
* **body parameters** of body j in B_j (all inertial rows it carries): mass ``mb_j``, first moment
  ``hb_j = Σ m c`` and inertia ``Jb_j`` about the origin of B_j (parallel axis theorem);
* **composite bodies** (bodies j … n, backward): ``mc_j``, ``hc_j``, ``Jc_j`` in B_j, about its origin:
  mc_j = mb_j + mc_{j+1}, hc_j = hb_j + R hc_{j+1} + mc_{j+1} t,
  Jc_j = Jb_j + R Jc_{j+1} Rᵀ − mc_{j+1} [t]×² − [t]×[h']× − [h']×[t]× (h' = R hc_{j+1}; (R, t) = T(B_j, B_{j+1}));
* **M** by the composite-rigid-body algorithm: M_jj = Jc_j,zz (revolute) or mc_j (prismatic) plus the motor
  inertia; for j < k the momentum of composite body k for a unit rate of joint k — linear ``pk_j`` and angular
  about the origin of B_j ``Lk_j`` — carried from B_k down to B_j (p ← R p, L ← R L + t × R p), M_jk its z
  component (angular for a revolute joint j, linear for a prismatic one);
* **c** by the Newton–Euler recursion with q̈ = 0 and no gravity: ω_j ``w_j``, ω̇_j ``wd_j``, the acceleration of
  the origin of B_j ``a_j`` (outward); the force ``F_j`` and moment ``N_j`` (about the origin) that body j needs,
  then the force ``f_j`` and moment ``n_j`` that joint j transmits (inward); c_j = n_j,z (or f_j,z);
* **g** from the composite bodies: the direction of gravity in B_j ``e_j`` (e_j = Rᵀ e_{j−1}),
  g_j = −g ẑ·(hc_j × e_j) (revolute) or −g mc_j e_j,z (prismatic), g = |g₀| a symbol.

Each quantity is a vector of components ``x, y, z`` (``w3x``) or a symmetric matrix (``Jc3xx``, ``Jc3xy`` …);
components that are zero are left out and used as zero, components equal to another quantity (± a name) are
not defined again. Evaluated in order, the formulas give M, c, g (the tests do exactly that against the numeric
CRBA, Christoffel c and gravity).
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass
from functools import lru_cache

import sympy as sp

from ..chain import Symbolic, chain_of
from ..model import DHRobot, JointType
from ._symbols import joint_symbols, parameter_symbols

__all__ = ["RecursiveDynamics", "recursive_dynamics", "format_recursive", "dynamics_form", "SECTIONS",
           "HAND_FORM_MAX_DOF"]

HAND_FORM_MAX_DOF = 6  # dynamics_form("auto"): the hand form up to this many joints (and right-angle twists)

SECTIONS = {
    "body": "body parameters in body frames B_j (mass mb, first moment hb, inertia Jb about the origin of B_j)",
    "composite": "composite bodies j..n (mc, hc, Jc in B_j, about its origin), from the last body inward",
    "M": "M: momentum of composite body k for a unit rate of joint k (linear pk_j, angular Lk_j about the "
         "origin of B_j, in B_j axes), carried inward; M[j,k] its z component",
    "c": "c: Newton-Euler with qdd = 0 and no gravity: w (omega), wd (omega dot), a (acceleration of the origin) "
         "outward; F, N (force, moment about the origin needed by body j); f, n (transmitted by joint j) inward",
    "g": "g: e_j = direction of gravity in B_j axes; g[j] = -g z.(hc_j x e_j)",
    "friction": "friction: tau_f = viscous qd + Coulomb sign(qd)",
}


@dataclass(frozen=True)
class RecursiveDynamics:
    """The recursive form of :func:`recursive_dynamics` (data only: presenters format it).

    ``definitions``: (symbol, formula, section) in evaluation order; ``M``, ``c``, ``g``: sympy matrices whose
    entries are formulas in those symbols (g with the symbol ``gravity_symbol``, |g₀| = ``gravity``).
    """

    robot: str
    definitions: tuple[tuple[sp.Symbol, sp.Expr, str], ...]
    M: sp.ImmutableMatrix
    c: sp.ImmutableMatrix
    g: sp.ImmutableMatrix
    q: tuple[sp.Symbol, ...]
    qd: tuple[sp.Symbol, ...]
    gravity: sp.Expr | None
    gravity_symbol: sp.Symbol
    friction: sp.ImmutableMatrix

    def at(self, values: dict) -> tuple:
        """(M, c, g) as float arrays: the formulas evaluated in order at ``values`` (symbol → number: q, q̇ and
        the named parameters; the gravity symbol is |g₀| unless given)."""
        import numpy as np

        env = {self.gravity_symbol: float(self.gravity or 0), **{k: sp.Float(v, 30) for k, v in values.items()}}
        for s, formula, _ in self.definitions:
            env[s] = formula.xreplace(env).evalf(30)
        out = [np.array(m.xreplace(env).evalf(30).tolist(), dtype=float) for m in (self.M, self.c, self.g)]
        return out[0], out[1].ravel(), out[2].ravel()


def _cross(a, b):
    return sp.Matrix([a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]])


def _skew(v):
    return sp.Matrix([[0, -v[2], v[1]], [v[2], 0, -v[0]], [-v[1], v[0], 0]])


_AXES = "xyz"
_PAIRS = ((0, 0), (1, 1), (2, 2), (0, 1), (0, 2), (1, 2))


class _Book:
    """Named quantities: formulas that are 0 are dropped, ± one name (or a number) is substituted, others named."""

    def __init__(self, taken: set[str]) -> None:
        self.taken = set(taken)
        self.defs: list[tuple[sp.Symbol, sp.Expr, str]] = []

    def name(self, text: str) -> sp.Symbol:
        while text in self.taken:
            text += "_"
        self.taken.add(text)
        return sp.Symbol(text, real=True)

    def scalar(self, text: str, e: sp.Expr, section: str, keep: bool = False) -> sp.Expr:
        e = sp.expand(e)
        if not keep and (e.is_number or (len(e.free_symbols) == 1 and (e.is_Symbol or (-e).is_Symbol))):
            return e
        s = self.name(text)
        self.defs.append((s, e, section))
        return s

    def vector(self, text: str, v, section: str, keep: bool = False) -> sp.Matrix:
        return sp.Matrix([self.scalar(f"{text}{_AXES[i]}", v[i], section, keep and v[i] != 0) for i in range(3)])

    def symmetric(self, text: str, J, section: str, keep: bool = False) -> sp.Matrix:
        out = sp.zeros(3, 3)
        for i, j in _PAIRS:
            out[i, j] = out[j, i] = self.scalar(f"{text}{_AXES[i]}{_AXES[j]}", J[i, j], section, keep and J[i, j] != 0)
        return out


def _frames(robot: DHRobot, numeric: bool):
    """(K_j, motion_j) for every joint, and for every inertial row (row, body, T(B_body, {row+1}))."""
    chain = chain_of(robot)
    algebra = Symbolic(chain, numeric)
    zero = [sp.Integer(0)] * robot.dof
    K = sp.eye(4)
    joints, frame_of_row = [], {}
    body = -1
    for i in range(chain.n_rows):
        if i in chain.joint_rows:
            head, tail = algebra.split(chain, i, zero)
            body += 1
            joints.append(sp.ImmutableMatrix(sp.expand(K * head)))
            K = sp.Matrix(tail)
        else:
            K = sp.expand(K * algebra.matrix(chain, i, zero))
        frame_of_row[i] = (body, sp.ImmutableMatrix(K))
    return joints, frame_of_row


@lru_cache(maxsize=16)
def recursive_dynamics(robot: DHRobot, numeric: bool = False) -> RecursiveDynamics:
    """M(q), c(q, q̇), g(q) as recursions in named quantities (see the module notes).

    Parameters
    ----------
    robot : DHRobot
        With inertial data; named parameters stay symbols unless ``numeric``.

    Returns
    -------
    RecursiveDynamics
        Formulas in order; fast for any arm (Panda in about a second), whatever its twists.

    Examples
    --------
    >>> import denavit
    >>> from denavit.symbolic import recursive_dynamics
    >>> rd = recursive_dynamics(denavit.load_robot("planar2r"))
    >>> rd.M[0, 1]
    Jb2zz + L1*hb2x*cos(q2)
    >>> [(str(name), str(formula)) for name, formula, _ in rd.definitions if str(name) == "hb2x"]
    [('hb2x', 'L2*m2')]
    """
    from ._dynamics_data import friction_vector, gravity_base, inertial_pieces, joint_parameters

    n = robot.dof
    js = joint_symbols(n)
    q, qd = js.q, js.qd
    prismatic = [t is JointType.PRISMATIC for t in robot.joint_types]
    pieces = inertial_pieces(robot, numeric)
    armature = joint_parameters(robot, numeric)[0]
    joints, frame_of_row = _frames(robot, numeric)
    G = sp.Symbol("g", positive=True)
    taken = {str(s) for s in parameter_symbols(robot).values()} | {"g"} | {str(s) for s in (*q, *qd)}
    book = _Book(taken)
    z = sp.Matrix([0, 0, 1])

    def motion(j):
        if prismatic[j]:
            return sp.Matrix([[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, q[j]], [0, 0, 0, 1]])
        c, s = sp.cos(q[j]), sp.sin(q[j])
        return sp.Matrix([[c, -s, 0, 0], [s, c, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]])

    T = [sp.Matrix(joints[j]) * motion(j) for j in range(n)]  # T(B_{j-1}, B_j), B_{-1} = {0}
    R = [sp.Matrix(Tj[:3, :3]).applyfunc(sp.expand) for Tj in T]
    t = [sp.Matrix(Tj[:3, 3]).applyfunc(sp.expand) for Tj in T]

    # body parameters in B_j
    mb, hb, Jb = [], [], []
    for j in range(n):
        m, h, J = sp.Integer(0), sp.zeros(3, 1), sp.zeros(3, 3)
        for p in pieces:
            if p.body != j:
                continue
            _, K = frame_of_row[p.row]
            Rk, tk = sp.Matrix(K[:3, :3]), sp.Matrix(K[:3, 3])
            cb = Rk * sp.Matrix(p.com) + tk
            m += p.mass
            h += p.mass * cb
            J += Rk * sp.Matrix(p.inertia) * Rk.T + p.mass * ((cb.T * cb)[0] * sp.eye(3) - cb * cb.T)
        mb.append(book.scalar(f"mb{j + 1}", m, "body", keep=True) if m != 0 else sp.Integer(0))
        hb.append(book.vector(f"hb{j + 1}", h, "body", keep=True))
        Jb.append(book.symmetric(f"Jb{j + 1}", J, "body", keep=True))

    # composite bodies, inward
    mc, hc, Jc = [None] * n, [None] * n, [None] * n
    for j in reversed(range(n)):
        m, h, J = mb[j], sp.Matrix(hb[j]), sp.Matrix(Jb[j])
        if j + 1 < n:
            Rn, tn = R[j + 1], t[j + 1]
            hp = Rn * hc[j + 1]
            m = m + mc[j + 1]
            h = h + hp + mc[j + 1] * tn
            J = (J + Rn * Jc[j + 1] * Rn.T - mc[j + 1] * _skew(tn) * _skew(tn)
                 - _skew(tn) * _skew(hp) - _skew(hp) * _skew(tn))
            mc[j] = book.scalar(f"mc{j + 1}", m, "composite") if j + 1 < n else m
        else:
            mc[j] = m
        hc[j] = book.vector(f"hc{j + 1}", h, "composite") if j + 1 < n else h
        Jc[j] = book.symmetric(f"Jc{j + 1}", J, "composite") if j + 1 < n else J

    # M: composite-rigid-body algorithm
    M = sp.zeros(n, n)
    for k in range(n):
        if prismatic[k]:
            p, L = mc[k] * z, _cross(hc[k], z)
        else:
            p, L = _cross(z, hc[k]), Jc[k] * z
        M[k, k] = (p[2] if prismatic[k] else L[2]) + armature[k]
        for j in reversed(range(k)):
            Rn, tn = R[j + 1], t[j + 1]
            p = Rn * p
            L = Rn * L + _cross(tn, p)
            if j > 0:
                p = book.vector(f"p{k + 1}_{j + 1}", p, "M")
                L = book.vector(f"L{k + 1}_{j + 1}", L, "M")
            M[j, k] = M[k, j] = sp.expand(p[2] if prismatic[j] else L[2])

    # c: Newton-Euler, q̈ = 0, no gravity
    w, wd, a = sp.zeros(3, 1), sp.zeros(3, 1), sp.zeros(3, 1)
    Fs, Ns = [], []
    for j in range(n):
        Rt, tj = R[j].T, t[j]
        a = Rt * (a + _cross(wd, tj) + _cross(w, _cross(w, tj)))
        wr = Rt * w
        if prismatic[j]:
            w, wd = wr, Rt * wd
            a = a + 2 * _cross(w, qd[j] * z)
        else:
            w, wd = wr + qd[j] * z, Rt * wd + _cross(wr, qd[j] * z)
        w = book.vector(f"w{j + 1}", w, "c")
        wd = book.vector(f"wd{j + 1}", wd, "c")
        a = book.vector(f"a{j + 1}", a, "c")
        F = mb[j] * a + _cross(wd, hb[j]) + _cross(w, _cross(w, hb[j]))
        Nm = Jb[j] * wd + _cross(w, Jb[j] * w) + _cross(hb[j], a)
        Fs.append(book.vector(f"F{j + 1}", F, "c"))
        Ns.append(book.vector(f"N{j + 1}", Nm, "c"))
    c = [sp.Integer(0)] * n
    f, nn = sp.zeros(3, 1), sp.zeros(3, 1)
    for j in reversed(range(n)):
        if j + 1 < n:
            Rn, tn = R[j + 1], t[j + 1]
            fr = Rn * f
            f, nn = Fs[j] + fr, Ns[j] + Rn * nn + _cross(tn, fr)
        else:
            f, nn = Fs[j], Ns[j]
        if j > 0:
            f = book.vector(f"f{j + 1}", f, "c")
            nn = book.vector(f"n{j + 1}", nn, "c")
        c[j] = sp.expand(f[2] if prismatic[j] else nn[2])

    # g: composite bodies and the direction of gravity
    g0 = gravity_base(robot)
    size = sp.sqrt(sum(x ** 2 for x in g0))
    e = sp.Matrix(g0) / size if size != 0 else sp.zeros(3, 1)
    g = [sp.Integer(0)] * n
    for j in range(n):
        e = book.vector(f"e{j + 1}", R[j].T * e, "g")
        g[j] = sp.expand(-G * (mc[j] * e[2] if prismatic[j] else _cross(hc[j], e)[2]))
    used = set().union(*(x.free_symbols for x in (*M, *c, *g)))
    defs = []
    for s, formula, section in reversed(book.defs):  # only what M, c, g use (F1x of a first body is not)
        if s in used:
            defs.append((s, formula, section))
            used |= formula.free_symbols
    return RecursiveDynamics(robot.name, tuple(reversed(defs)), sp.ImmutableMatrix(M), sp.ImmutableMatrix(c),
                             sp.ImmutableMatrix(g), q, qd, size if size != 0 else None, G,
                             friction_vector(robot, qd, numeric))


def dynamics_form(robot: DHRobot, form: str = "auto") -> str:
    """"hand" or "recursive": ``form`` itself, or for "auto" the hand form (entry by entry,
    :func:`~denavit.symbolic.lagrangian_dynamics`) when its entries stay short — at most
    :data:`HAND_FORM_MAX_DOF` joints and every twist a multiple of 90° (Puma 560: 9 k characters) — and the
    recursive form otherwise (the Panda's expanded entries are about 1 MB, a generic-twist arm's longer)."""
    if form not in ("auto", "hand", "recursive"):
        raise ValueError(f"unknown form {form!r}; choose one of auto, hand, recursive")
    if form != "auto":
        return form
    right = all(abs(math.remainder(link.alpha, math.pi / 2)) < 1e-12 for link in robot.links)
    return "hand" if robot.dof <= HAND_FORM_MAX_DOF and right else "recursive"


def format_recursive(rd: RecursiveDynamics, style: str = "text", digits: int | None = 6) -> str:
    """The recursive form as text (``name = formula`` lines under section comments), LaTeX or Markdown.

    Sines and cosines are written S3, C3 (LaTeX S_{3}); fractions with denominators above 12 as decimals of
    ``digits`` significant digits; M by its upper triangle.
    """
    from ._dynamics_format import display_entry, tex_label, trim_zeros

    if style not in ("text", "latex", "markdown"):
        raise ValueError(f"unknown style {style!r}; choose one of text, latex, markdown")
    n = len(rd.q)
    def show(e):
        if digits is not None:  # float constants (cos 0.7 of a generic twist) to the same digits as fractions
            e = e.xreplace({x: sp.Float(x, digits) for x in e.atoms(sp.Float)})
        return display_entry(e, rd.q, digits, True, collapse=False)

    blocks: list[tuple[str, list[tuple[str, sp.Expr]]]] = []
    for key in list(SECTIONS)[:-1]:
        rows = [(str(s), show(e)) for s, e, sec in rd.definitions if sec == key]
        if key == "M":
            rows += [(f"M[{i + 1},{j + 1}]", show(rd.M[i, j])) for i in range(n) for j in range(i, n)]
        elif key == "c":
            rows += [(f"c[{i + 1}]", show(rd.c[i])) for i in range(n)]
        elif key == "g":
            rows += [(f"g[{i + 1}]", show(rd.g[i])) for i in range(n)]
        blocks.append((key, rows))
    blocks.append(("friction", [(f"friction[{i + 1}]", show(rd.friction[i])) for i in range(n)]))
    head = f"M(q) q'' + c(q, q') + g(q) + tau_f(q') = tau   ({n} joints, recursive form)"
    notes = ["body frame B_j: attached to body j, z along joint j's axis; vectors in B_j axes",
             "M is symmetric: M[k,j] = M[j,k]", "Ci = cos(qi), Si = sin(qi)"]
    if rd.gravity is not None:
        notes.insert(0, f"g = {trim_zeros(sp.sstr(sp.Float(rd.gravity, 6)))} m/s^2 (gravitational acceleration)")
    if style == "text":
        lines = [head] + [f"  {x}" for x in notes]
        for key, rows in blocks:
            lines += ["", f"# {SECTIONS[key]}"] + [f"{k} = {trim_zeros(sp.sstr(e))}" for k, e in rows]
        return "\n".join(lines)
    names = {s: _tex_name(str(s)) for _, rows in blocks for _, e in rows for s in e.free_symbols}
    names.update({s: f"\\dot{{q}}_{{{k + 1}}}" for k, s in enumerate(rd.qd)})
    label = lambda k: tex_label(k) if "[" in k else _tex_name(k)  # noqa: E731
    tex = [(key, [(label(k), sp.latex(e, symbol_names=names)) for k, e in rows]) for key, rows in blocks]
    if style == "latex":
        rows = [f"{k} &= {v}" for _, block in tex for k, v in block] + ["M_{kj} &= M_{jk} \\quad (j < k)"]
        return "\\begin{aligned}\n" + " \\\\\n".join(rows) + "\n\\end{aligned}"
    out = [f"**{head}**", ""]
    for key, block in tex:
        out += [f"*{SECTIONS[key]}*", ""] + [f"$${k} = {v}$$" for k, v in block]
    return "\n\n".join(out)


_TEX = {"mb": "m^{b}", "hb": "h^{b}", "Jb": "J^{b}", "mc": "m^{c}", "hc": "h^{c}", "Jc": "J^{c}",
        "wd": "\\dot\\omega", "w": "\\omega"}
_NAME = re.compile(r"(mb|hb|Jb|mc|hc|Jc|wd|w|p|L|a|F|N|f|n|e)(\d+)(?:_(\d+))?([xyz]{0,2})")


def _tex_name(name: str) -> str:
    """w3x → \\omega_{3x}, Jc3xy → J^{c}_{3xy}, p5_3x → p^{5}_{3x} (other names: sympy's own)."""
    m = _NAME.fullmatch(name)
    if m is None:
        return sp.latex(sp.Symbol(name))
    base, idx, sub, comp = m.groups()
    head = _TEX.get(base, base)
    if sub is not None:
        return f"{head}^{{{idx}}}_{{{sub}{comp}}}"
    return f"{head}_{{{idx}{comp}}}"
