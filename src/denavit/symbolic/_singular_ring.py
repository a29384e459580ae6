"""Singularity analysis, the algebra: the Jacobian in a middle frame as polynomials in sin qᵢ, cos qᵢ, its
determinant or minors, and their common factor factorized (see :mod:`._singularities` for the method)."""

from __future__ import annotations

import itertools

import sympy as sp

from ..chain import chain_of
from ..model import DHRobot, JointType
from ._jacobians import reduce_trig
from ._rings import TrigRing
from ._symbols import joint_symbols

__all__ = ["FACTOR_AS_MULTIPLIED_TERMS", "BIG_RATIONAL", "analysis_ring", "wrist_frame_jacobian", "measure_minors",
           "laplace_det", "common_factors"]

# --- the matrix, in a polynomial ring ------------------------------------------------------------------
#
# Every entry of J is a polynomial in s_i = sin q_i, c_i = cos q_i and the named parameters. Determinants,
# gcds and factorizations are done with sympy's sparse polynomial ring (sympy.polys.rings), which is two to
# three orders of magnitude faster than the same algebra on expression trees; constants that are not
# rational (√3/2, a float twist cos 0.7) are carried as extra generators and put back at the end, so
# nothing is expanded through trigonometric identities. Reduction modulo s_i² + c_i² − 1 (a Gröbner basis
# in lex order with s before c) gives the canonical form used for the zero test; factors are taken from
# the determinant as multiplied, where the product structure of the arm is still visible.


def analysis_ring(exprs: list[sp.Expr], q, robot: DHRobot) -> TrigRing:
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


def wrist_frame_jacobian(robot: DHRobot, simplify: str) -> tuple[sp.ImmutableMatrix, str, TrigRing, list]:
    """J in the axes of a middle frame (joint 3's axis frame; joint 4's for 7 joints), reference point on the
    last joint axis: (sympy matrix, note, ring, ring matrix as a list of rows)."""
    from ._kinematics import link_matrices_sym

    axis = chain_of(robot).axis_frame
    k, m = axis[_middle_frame(robot)], axis[-1]
    q = joint_symbols(robot.dof).q
    mats = link_matrices_sym(robot)
    rg = analysis_ring([e for A in mats for e in A], q, robot)
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


def measure_minors(rg: TrigRing, J: list, shape: tuple[int, int]) -> tuple[str, list]:
    """(name of the measure, ring minors whose common factor is solved): det J, or the k×k minors."""
    from sympy.polys.matrices import DomainMatrix

    m, k = shape
    dom = rg.R.to_domain()

    def det(rows, cols):
        return DomainMatrix([[J[i][j] for j in cols] for i in rows], (len(rows), len(cols)), dom).det()

    if m == k:
        return "det J", [laplace_det(rg, J)]
    small = min(m, k)
    minors = [det(rows, cols)
              for rows in (itertools.combinations(range(m), small) if m > k else [tuple(range(m))])
              for cols in (itertools.combinations(range(k), small) if k > m else [tuple(range(k))])]
    name = ("common factor of the k×k minors (zeros of det(JᵀJ) = Σ minors²)" if m > k
            else "common factor of the k×k minors (zeros of det(J Jᵀ) = Σ minors²)").replace("k×k", f"{small}×{small}")
    return name, minors


def laplace_det(rg: TrigRing, J: list):
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


def common_factors(rg: TrigRing, minors: list) -> tuple[sp.Expr, list[tuple[sp.Expr, int]]]:
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
