"""M(q), c(q, q̇) (and C), g(q) in hand form, computed on polynomials (the engine of :func:`lagrangian_dynamics`).

The formulas are those of :mod:`denavit.symbolic._dynamics` (Spong, Hutchinson & Vidyasagar 2006, sec. 7.3):
M = Σ m J_vᵀJ_v + J_ωᵀ I J_ω over the inertial pieces, entry M_jk (j ≤ k) worked in the axis frame of joint j;
g_j = −Σ m (z_j × (c − o_j))·g₀; C from the Christoffel symbols of M. The algebra is done in
:class:`~denavit.symbolic._rings.TrigRing` (sparse polynomials, normal form modulo s² + c² = 1), and the
angle variables are chosen as a person chooses them:

* consecutive revolute joints with parallel axes form a group whose link angles add up: the variables are
  q₂, q₂ + q₃, q₂ + q₃ + q₄ (C₂, C₂₃, C₂₃₄), not q₃ and q₄ separately;
* row j of M is written in the angles after joint j (it does not depend on q₁ … q_j: M₂₂ of a Puma shows C₃,
  not C₂C₂₃ + S₂S₂₃); g in the absolute angles (from the base); c in the angles after joint 1.

Each entry comes back as a sum of (parameter group) × (product of sines and cosines): see
:func:`hand_terms`.
"""

from __future__ import annotations

from functools import lru_cache
from typing import Callable

import numpy as np
import sympy as sp

from ..chain import chain_of
from ..model import DHRobot, JointType
from ._rings import TrigRing
from ._symbols import joint_symbols

__all__ = ["parallel_groups", "RingDynamics", "ring_dynamics", "PARAMETER_NAMES", "regressor_sym"]

Progress = Callable[[str, int, int], None]
PARALLEL_SAMPLES = 4  # random configurations that decide whether two consecutive joint axes are always parallel


def parallel_groups(robot: DHRobot) -> tuple[int, ...]:
    """For each joint (0-based) the first joint of its run of consecutive revolute joints with parallel axes."""
    from ..numeric import joint_axes, link_transforms

    rng = np.random.default_rng(0)
    Z = [joint_axes(robot, link_transforms(robot, rng.uniform(-np.pi, np.pi, robot.dof)))[0]
         for _ in range(PARALLEL_SAMPLES)]
    rev = [t is JointType.REVOLUTE for t in robot.joint_types]
    start = []
    for i in range(robot.dof):
        same = i > 0 and rev[i] and rev[i - 1] and all(np.linalg.norm(np.cross(z[i], z[i - 1])) < 1e-9 for z in Z)
        start.append(start[i - 1] if same else i)
    return tuple(start)


class _Frames:
    """Link matrices and relative transforms T_a_b in one ring (4×4 lists of ring elements), built lazily."""

    def __init__(self, rg: TrigRing, mats) -> None:
        self.rg, self.mats = rg, mats
        self.A: dict[int, list] = {}
        self.cache: dict[tuple[int, int], list] = {}

    def link(self, i: int) -> list:
        if i not in self.A:
            vals = [self.rg.element(e) for e in self.mats[i]]
            self.A[i] = [vals[4 * r:4 * r + 4] for r in range(4)]
        return self.A[i]

    def __call__(self, a: int, b: int) -> list:
        if (a, b) not in self.cache:
            R = self.rg.R
            if a == b:
                T = [[R.one if i == j else R.zero for j in range(4)] for i in range(4)]
            else:
                X, Y = self(a, b - 1), self.link(b - 1)
                T = [[self.rg.reduce(sum((X[i][m] * Y[m][j] for m in range(4)), R.zero)) for j in range(4)]
                     for i in range(4)]
            self.cache[a, b] = T
        return self.cache[a, b]


def _cross(a, b):
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]


def _dot(a, b, zero):
    return sum((x * y for x, y in zip(a, b)), zero)


class RingDynamics:
    """The rings, frames and inertial data of one robot (see module notes)."""

    def __init__(self, robot: DHRobot, numeric: bool) -> None:
        from ._dynamics import gravity_base, inertial_pieces, joint_parameters
        from ._kinematics import link_matrices_sym

        self.robot, self.n = robot, robot.dof
        self.q = joint_symbols(self.n).q
        self.pieces = inertial_pieces(robot, numeric)
        self.armature = joint_parameters(robot, numeric)[0]
        self.g0 = gravity_base(robot)
        self.mats = [list(A) for A in link_matrices_sym(robot, numeric)]
        self.axis = list(chain_of(robot).axis_frame)
        self.revolute = [k for k, t in enumerate(robot.joint_types) if t is JointType.REVOLUTE]
        self.start = parallel_groups(robot)
        size = sp.sqrt(sum(x ** 2 for x in self.g0))
        self._exprs = [e for A in self.mats for e in A] + list(self.g0) + list(self.armature)
        self._exprs += [x / size for x in self.g0] if size != 0 else []  # the unit gravity vector's constants
        for p in self.pieces:
            self._exprs += [p.mass, *p.com, *p.inertia]
        self._rings: dict[int, tuple[TrigRing, _Frames]] = {}

    def ring(self, after: int) -> tuple[TrigRing, _Frames]:
        """The ring whose angles start after joint ``after`` (−1: absolute angles; j: joint j plain, later
        joints summed from max(group start, j + 1))."""
        if after not in self._rings:
            sums = []
            for i in self.revolute:
                if i < after:
                    continue
                lo = i if i == after else max(self.start[i], after + 1)
                sums.append(tuple(range(lo, i + 1)))
            rg = TrigRing(self._exprs, self.q, sums, tag=str(after + 1))
            self._rings[after] = (rg, _Frames(rg, self.mats))
        return self._rings[after]

    def _column(self, rg, T, p, ref: int, j: int):
        """(v in {ref} axes, ω in the piece's axes) of piece p for a unit rate of joint j."""
        a = self.axis[j]
        Tp = T(ref, p.row + 1)
        com = [rg.element(x) for x in p.com]
        c = [_dot(Tp[i][:3], com, rg.R.zero) + Tp[i][3] for i in range(3)]
        Ta = T(ref, a)
        z, o = [Ta[i][2] for i in range(3)], [Ta[i][3] for i in range(3)]
        if self.robot.joint_types[j] is JointType.PRISMATIC:
            return z, [rg.R.zero] * 3
        w_local = T(a, p.row + 1)[2][:3]
        return _cross(z, [c[i] - o[i] for i in range(3)]), w_local

    def mass_entry(self, j: int, k: int, after: int):
        """M_jk (j ≤ k) in the ring of angles after joint ``after`` (≤ j), worked in joint j's axis frame."""
        rg, T = self.ring(after)
        ref, zero = self.axis[j], rg.R.zero
        e = zero
        for p in self.pieces:
            if p.body < k:
                continue
            vj, wj = self._column(rg, T, p, ref, j)
            vk, wk = self._column(rg, T, p, ref, k)
            I = [[rg.element(p.inertia[r, s]) for s in range(3)] for r in range(3)]
            Iw = [_dot(I[r], wk, zero) for r in range(3)]
            e += rg.element(p.mass) * _dot(vj, vk, zero) + _dot(wj, Iw, zero)
        if j == k:
            e += rg.element(self.armature[j])
        return rg.reduce(e)

    def gravity(self, unit: bool = False):
        """g_j = −Σ m (z_j × (c − o_j))·g₀ in base axes, in the absolute angles (per unit of |g₀| if ``unit``)."""
        rg, T = self.ring(-1)
        size = sp.sqrt(sum(x ** 2 for x in self.g0))
        g0 = [rg.element(x / size if unit and size != 0 else x) for x in self.g0]
        out = []
        for j in range(self.n):
            e = rg.R.zero
            for p in self.pieces:
                if p.body >= j:
                    v, _ = self._column(rg, T, p, 0, j)
                    e -= rg.element(p.mass) * _dot(v, g0, rg.R.zero)
            out.append(rg.reduce(e))
        return rg, out

    def diff(self, rg: TrigRing, poly, i: int):
        if self.robot.joint_types[i] is JointType.REVOLUTE:
            return rg.diff_joint(poly, i)
        gen = rg.gen_of(self.q[i])
        return poly.diff(gen) if gen is not None else rg.R.zero


def _report(progress, stage, done, total):
    if progress is not None:
        progress(stage, done, total)


@lru_cache(maxsize=16)
def ring_dynamics(robot: DHRobot, numeric: bool = False, coriolis: bool = True, progress: Progress | None = None):
    """(M, C or None, c, g, |g₀|, g per unit |g₀|) as sympy in hand form (module notes, :func:`hand_terms`)."""
    D = RingDynamics(robot, numeric)
    n = D.n
    qd = joint_symbols(n).qd
    M = sp.zeros(n, n)
    total = n * (n + 1) // 2
    done = 0
    for j in range(n):
        rg, _ = D.ring(j)
        for k in range(j, n):
            _report(progress, "mass matrix", done, total)
            done += 1
            M[j, k] = M[k, j] = hand_terms(rg, D.mass_entry(j, k, j))
    # c and C from the Christoffel symbols of M, all in the ring of angles after joint 1
    rg0, _ = D.ring(0)
    M0 = {}
    done = 0
    for j in range(n):
        for k in range(j, n):
            _report(progress, "mass matrix in the angles after joint 1 (for c)", done, total)
            done += 1
            M0[j, k] = M0[k, j] = D.mass_entry(j, k, 0)
    dM = {(i, j, k): D.diff(rg0, M0[j, k], i) for i in range(n) for j in range(n) for k in range(j, n)}
    for (i, j, k), v in list(dM.items()):
        dM[i, k, j] = v
    half = rg0.R.domain.convert(sp.Rational(1, 2))
    gamma = {}
    for k in range(n):
        _report(progress, "Christoffel symbols", k, n)
        for i in range(n):
            for j in range(i, n):
                gamma[i, j, k] = rg0.reduce((dM[i, k, j] + dM[j, k, i] - dM[k, i, j]) * half)
    c = []
    for k in range(n):
        c.append(sp.Add(*[hand_terms(rg0, gamma[i, j, k] * (1 if i == j else 2)) * qd[i] * qd[j]
                          for i in range(n) for j in range(i, n) if gamma[i, j, k]]))
    C = None
    if coriolis:
        C = sp.ImmutableMatrix(n, n, [sp.Add(*[hand_terms(rg0, gamma[min(i, j), max(i, j), k]) * qd[i]
                                                for i in range(n) if gamma[min(i, j), max(i, j), k]])
                                      for k in range(n) for j in range(n)])
    rgg, gs = D.gravity()
    g = sp.ImmutableMatrix([hand_terms(rgg, x) for x in gs])
    size = sp.sqrt(sum(x ** 2 for x in D.g0))
    rgg, gs = D.gravity(unit=True)
    g_unit = sp.ImmutableMatrix([hand_terms(rgg, x) for x in gs]) if size != 0 else None
    return sp.ImmutableMatrix(M), C, sp.ImmutableMatrix(c), g, (size if size != 0 else None), g_unit


def _pair_angles(rg: TrigRing, terms: dict) -> dict:
    """Collapse pairs of terms into the sine or cosine of an angle difference, within a group of parallel axes:
    X (c_a c_b + s_a s_b) → X cos(φ_b − φ_a) (C₂C₂₃ + S₂S₂₃ → C₃), X (s_a c_b − c_a s_b) → X sin(φ_a − φ_b).

    ``terms`` maps (parameter exponents, trig exponents, extra atoms) to coefficients; extra atoms are the
    new sines and cosines (sympy)."""
    m = len(rg.sums)
    S, C = (lambda a: a), (lambda a: m + a)
    pairs = [(a, b) for a in range(m) for b in range(m) if a != b and rg.sums[a][0] == rg.sums[b][0]]
    if not pairs:
        return terms

    def moved(t, minus, plus):
        t = list(t)
        for i in minus:
            t[i] -= 1
        for i in plus:
            t[i] += 1
        return tuple(t)

    changed = True
    while changed:
        changed = False
        for (pm, tm, extra), coeff in list(terms.items()):
            if (pm, tm, extra) not in terms:
                continue
            for a, b in pairs:
                patterns = []
                if a < b and tm[C(a)] and tm[C(b)]:  # c_a c_b + s_a s_b
                    patterns.append(((C(a), C(b)), (S(a), S(b)), 1, sp.cos(rg.angles[b] - rg.angles[a])))
                if tm[S(a)] and tm[C(b)]:  # s_a c_b − c_a s_b
                    patterns.append(((S(a), C(b)), (C(a), S(b)), -1, sp.sin(rg.angles[a] - rg.angles[b])))
                for minus, plus, sign, atom in patterns:
                    partner = (pm, moved(tm, minus, plus), extra)
                    if terms.get(partner) == sign * coeff:
                        del terms[pm, tm, extra], terms[partner]
                        key = (pm, moved(tm, minus, ()), tuple(sorted(extra + (atom,), key=sp.default_sort_key)))
                        terms[key] = terms.get(key, 0) + coeff
                        if not terms[key]:
                            del terms[key]
                        changed = True
                        break
                if changed:
                    break
            if changed:
                break
    return terms


def hand_terms(rg: TrigRing, poly) -> sp.Expr:
    """A ring element as Σ (parameter group) × (sines and cosines): angle differences within a group of
    parallel axes collapsed (:func:`_pair_angles`), terms collected on the trigonometric part (constant
    first), each group with its rational content and common parameter monomial taken out."""
    if not poly:
        return sp.Integer(0)
    ntrig = len(rg.trig_gens)
    k0 = len(rg.gens) - ntrig
    # constants: algebraic ones (√3) stay exact, transcendental ones (cos 0.7) become numbers
    syms = [s.xreplace(rg.back) for s in rg.R.symbols[:k0]]
    syms = [x.evalf(15) if x.is_number and not x.is_algebraic else x for x in syms]
    trig_atoms = [rg.trig_of(g) for g in rg.trig_gens]
    to_sympy = rg.R.domain.to_sympy
    terms = _pair_angles(rg, {(monom[:k0], monom[k0:], ()): to_sympy(coeff) for monom, coeff in poly.terms()})
    groups: dict[tuple, list] = {}
    for (pm, tm, extra), coeff in terms.items():
        groups.setdefault((tm, extra), []).append((pm, coeff))
    out = []
    for key in sorted(groups, key=lambda k: (sum(k[0]) + len(k[1]), k[0], [str(x) for x in k[1]])):
        items = groups[key]
        low = [min(m[i] for m, _ in items) for i in range(k0)]
        nums = [cf for _, cf in items]
        content = sp.gcd_list(nums) if len(nums) > 1 else nums[0]
        if len(nums) > 1 and (content.q > 4 or content.p > 1000) and not all(x.is_Integer for x in nums):
            content = sp.Integer(1)  # decimal data: 0.1465 a2 + 0.0791, not 8.0e-9 (18312500 a2 + 9887500)
        if len(nums) > 1 and all(x < 0 for x in nums):
            content = -content
        common = content * sp.Mul(*[x ** e for x, e in zip(syms, low) if e])
        rest = sp.Add(*[(x / content) * sp.Mul(*[v ** (e - l) for v, e, l in zip(syms, m, low) if e - l])
                        for (m, _), x in zip(items, nums)])
        tm, extra = key
        trig = sp.Mul(*[a ** e for a, e in zip(trig_atoms, tm) if e], *extra)
        out.append(sp.Mul(common, rest, trig))
    return sp.Add(*out)


# --- the regressor: τ = Y(q, q̇, q̈) π, linear in the standard inertial parameters ---------------------------

PARAMETER_NAMES = ("m", "hx", "hy", "hz", "Jxx", "Jyy", "Jzz", "Jxy", "Jxz", "Jyz")
"""Standard inertial parameters of a piece (Khalil & Dombre 2002, sec. 9.3): mass, first moment h = m c and
inertia J about the origin of its DH frame, J = I_c + m(|c|² 1 − c cᵀ) (parallel axis theorem), in frame {row}."""


def _linear_entry(D: RingDynamics, rg: TrigRing, T, j: int, k: int, pis: list):
    """M_jk (j ≤ k) linear in each piece's (m, h, J): m v0_j·v0_k + v0_j·(z_k × R h) + v0_k·(z_j × R h) + w_jᵀ J w_k,
    v0 = z × (o_p − o) (the frame origin of the piece instead of its COM)."""
    ref, zero = D.axis[j], rg.R.zero
    e = zero
    for p, pi in zip(D.pieces, pis):
        if p.body < k:
            continue
        m, h, J = pi[0], pi[1:4], [[pi[4], pi[7], pi[8]], [pi[7], pi[5], pi[9]], [pi[8], pi[9], pi[6]]]
        Tp = T(ref, p.row + 1)
        op = [Tp[i][3] for i in range(3)]
        Rh = [_dot(Tp[i][:3], h, zero) for i in range(3)]
        cols = []
        for jj in (j, k):
            Ta = T(ref, D.axis[jj])
            z, o = [Ta[i][2] for i in range(3)], [Ta[i][3] for i in range(3)]
            if D.robot.joint_types[jj] is JointType.PRISMATIC:
                cols.append((z, z, [zero] * 3, True))
            else:
                cols.append((_cross(z, [op[i] - o[i] for i in range(3)]), z, T(D.axis[jj], p.row + 1)[2][:3], False))
        (v0j, zj, wj, pj), (v0k, zk, wk, pk) = cols
        e += m * _dot(v0j, v0k, zero)
        if not pk:
            e += _dot(v0j, _cross(zk, Rh), zero)
        if not pj:
            e += _dot(v0k, _cross(zj, Rh), zero)
        e += _dot(wj, [_dot(J[r], wk, zero) for r in range(3)], zero)
    return rg.reduce(e)


@lru_cache(maxsize=8)
def regressor_sym(robot: DHRobot):
    """The regressor Y(q, q̇, q̈) with τ = Y π (friction excluded), and π as symbols.

    Returns ``(Y, pi)``: ``Y`` an n × (10 · pieces + n) sympy matrix in hand form, ``pi`` the symbols: for
    every inertial piece k (order of :func:`~denavit.symbolic._dynamics.inertial_pieces`) its
    :data:`PARAMETER_NAMES` suffixed ``_k``, then the motor inertias ``Ia_1 … Ia_n``. The dynamics is linear in
    these (Khalil & Dombre 2002, sec. 9.3), which is what identification needs; the robot's own inertial values
    are not used, only its kinematics (and which rows carry inertia).

    Examples
    --------
    >>> import denavit
    >>> from denavit.symbolic import regressor_sym
    >>> Y, pi = regressor_sym(denavit.load_robot("planar2r"))
    >>> Y.shape, pi[:4]
    ((2, 22), (m_1, hx_1, hy_1, hz_1))
    """
    D = RingDynamics(robot, False)
    n = D.n
    js = joint_symbols(n)
    pis = [[sp.Symbol(f"{name}_{k + 1}", real=True) for name in PARAMETER_NAMES] for k in range(len(D.pieces))]
    arm = [sp.Symbol(f"Ia_{k + 1}", real=True) for k in range(n)]
    D._exprs += [s for pi in pis for s in pi] + arm
    rg, T = D.ring(0)
    rpis = [[rg.element(s) for s in pi] for pi in pis]
    M = {}
    for j in range(n):
        for k in range(j, n):
            M[j, k] = M[k, j] = _linear_entry(D, rg, T, j, k, rpis) + (rg.element(arm[j]) if j == k else rg.R.zero)
    dM = {(i, j, k): D.diff(rg, M[j, k], i) for i in range(n) for j in range(n) for k in range(n)}
    half = rg.R.domain.convert(sp.Rational(1, 2))
    g0 = [rg.element(x) for x in D.g0]
    allpi = [s for pi in pis for s in pi] + arm
    gens = [rg.gen_of(s) for s in allpi]
    Y = sp.zeros(n, len(allpi))
    for j in range(n):
        tau = {}  # per q̇/q̈ monomial: its polynomial coefficient
        for k in range(n):
            tau[js.qdd[k]] = M[j, k]
        for a in range(n):
            for b in range(a, n):
                G = (dM[a, j, b] + dM[b, j, a] - dM[j, a, b]) * half
                tau[js.qd[a] * js.qd[b]] = G * (1 if a == b else 2)
        grav = rg.R.zero
        for p, pi in zip(D.pieces, rpis):
            if p.body >= j:
                Tp = T(0, p.row + 1)
                op = [Tp[i][3] for i in range(3)]
                Rh = [_dot(Tp[i][:3], pi[1:4], rg.R.zero) for i in range(3)]
                if robot.joint_types[j] is JointType.PRISMATIC:
                    Ta = T(0, D.axis[j])
                    v = [Ta[i][2] * pi[0] for i in range(3)]
                else:
                    Ta = T(0, D.axis[j])
                    z, o = [Ta[i][2] for i in range(3)], [Ta[i][3] for i in range(3)]
                    v = _cross(z, [pi[0] * (op[i] - o[i]) + Rh[i] for i in range(3)])
                grav -= _dot(v, g0, rg.R.zero)
        tau[sp.Integer(1)] = grav
        for col, gen in enumerate(gens):
            Y[j, col] = sp.Add(*[hand_terms(rg, rg.reduce(poly.diff(gen))) * mono for mono, poly in tau.items() if poly])
    return sp.ImmutableMatrix(Y), tuple(allpi)
