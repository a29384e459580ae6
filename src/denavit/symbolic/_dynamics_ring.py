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
:func:`~denavit.symbolic._hand_terms.hand_terms`.
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np
import sympy as sp

from ..chain import chain_of
from ..model import DHRobot, JointType
from ._dynamics_types import Progress, report_progress
from ._hand_terms import hand_terms
from ._rings import TrigRing
from ._symbols import joint_symbols

__all__ = ["parallel_groups", "RingDynamics", "ring_dynamics", "ring_cross", "ring_dot", "PARALLEL_SAMPLES"]

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


def ring_cross(a, b):
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]


def ring_dot(a, b, zero):
    return sum((x * y for x, y in zip(a, b)), zero)


class RingDynamics:
    """The rings, frames and inertial data of one robot (see module notes)."""

    def __init__(self, robot: DHRobot, numeric: bool) -> None:
        from ._dynamics_data import gravity_base, inertial_pieces, joint_parameters
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
        c = [ring_dot(Tp[i][:3], com, rg.R.zero) + Tp[i][3] for i in range(3)]
        Ta = T(ref, a)
        z, o = [Ta[i][2] for i in range(3)], [Ta[i][3] for i in range(3)]
        if self.robot.joint_types[j] is JointType.PRISMATIC:
            return z, [rg.R.zero] * 3
        w_local = T(a, p.row + 1)[2][:3]
        return ring_cross(z, [c[i] - o[i] for i in range(3)]), w_local

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
            Iw = [ring_dot(I[r], wk, zero) for r in range(3)]
            e += rg.element(p.mass) * ring_dot(vj, vk, zero) + ring_dot(wj, Iw, zero)
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
                    e -= rg.element(p.mass) * ring_dot(v, g0, rg.R.zero)
            out.append(rg.reduce(e))
        return rg, out

    def diff(self, rg: TrigRing, poly, i: int):
        if self.robot.joint_types[i] is JointType.REVOLUTE:
            return rg.diff_joint(poly, i)
        gen = rg.gen_of(self.q[i])
        return poly.diff(gen) if gen is not None else rg.R.zero



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
            report_progress(progress, "mass matrix", done, total)
            done += 1
            M[j, k] = M[k, j] = hand_terms(rg, D.mass_entry(j, k, j))
    # c and C from the Christoffel symbols of M, all in the ring of angles after joint 1
    rg0, _ = D.ring(0)
    M0 = {}
    done = 0
    for j in range(n):
        for k in range(j, n):
            report_progress(progress, "mass matrix in the angles after joint 1 (for c)", done, total)
            done += 1
            M0[j, k] = M0[k, j] = D.mass_entry(j, k, 0)
    dM = {(i, j, k): D.diff(rg0, M0[j, k], i) for i in range(n) for j in range(n) for k in range(j, n)}
    for (i, j, k), v in list(dM.items()):
        dM[i, k, j] = v
    half = rg0.R.domain.convert(sp.Rational(1, 2))
    gamma = {}
    for k in range(n):
        report_progress(progress, "Christoffel symbols", k, n)
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
