"""The RNEA and CRBA kernels behind :func:`denavit.rnea` and :func:`denavit.mass_matrix`.

One implementation serves both the single call and the batch: every 3-vector is a tuple of three
components, and a component is either a Python float (one configuration — plain float arithmetic, no
numpy call overhead) or a contiguous (B,) array (a batch — the batch-contiguous layout of
:mod:`denavit.numeric._kinematics`, no einsum over tiny axes, no 3×3 matrices per configuration).
The algebra is that of the module notes of :mod:`denavit.numeric._dynamics`: world axes, the world origin
as reference point for spatial quantities, gravity entered as a base acceleration −g.

References
----------
R. Featherstone, *Rigid Body Dynamics Algorithms*, Springer 2008, §5.3 (RNEA), §6.2 (CRBA).
J. J. Craig, *Introduction to Robotics*, 3rd ed., sec. 6.5 (iterative Newton–Euler, eqs. 6.45–6.53).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..chain import COMPONENTS, FLOATS, Chain, chain_of, walk
from ..model import DHRobot

__all__ = ["plan", "rnea_kernel", "mass_matrix_kernel", "ldl_pivots_solve", "ldl_solve", "joint_columns", "to_array",
           "frames"]

ZERO3 = (0.0, 0.0, 0.0)


@dataclass(frozen=True)
class _Piece:
    row: int
    mass: float
    com: tuple[float, float, float]  # frame {row}
    inertia: tuple[tuple[float, float, float], ...]  # 3×3 about the COM, frame {row} axes


@dataclass(frozen=True)
class _Plan:
    """Constants of a robot needed by the kernels (derived once per distinct robot value)."""

    chain: Chain  # rows, base, joint rule
    axis_frame: tuple[int, ...]  # per joint: index (0 = base, r + 1 = after row r) of the frame holding its axis
    revolute: tuple[bool, ...]
    pieces: tuple[tuple[_Piece, ...], ...]  # per body (joint)
    armature: tuple[float, ...]


def plan(robot: DHRobot) -> _Plan:
    """The kernel constants of ``robot`` (a pure function of the robot, kept with its chain)."""
    memo = chain_of(robot).memo
    pl = memo.get("dynamics_fast.plan")
    if pl is None:
        pl = memo["dynamics_fast.plan"] = _make_plan(robot)
    return pl


def _make_plan(robot: DHRobot) -> _Plan:
    body = -1
    pieces: list[list[_Piece]] = [[] for _ in range(robot.dof)]
    for r, link in enumerate(robot.links):
        body += link.is_joint
        li = link.inertia
        if li is not None and body >= 0:
            I = tuple(tuple(float(v) for v in row) for row in li.inertia_matrix)
            pieces[body].append(_Piece(r, float(li.mass), tuple(float(c) for c in li.com), I))
    chain = chain_of(robot)
    return _Plan(
        chain=chain,
        axis_frame=chain.axis_frame,
        revolute=chain.revolute,
        pieces=tuple(tuple(p) for p in pieces),
        armature=tuple(link.inertia.motor_inertia if link.inertia else 0.0 for link in robot.joints),
    )


# --- 3-vector algebra on component tuples (floats or (B,) arrays) -------------------------------------
def _add(a, b):
    return (a[0] + b[0], a[1] + b[1], a[2] + b[2])


def _sub(a, b):
    return (a[0] - b[0], a[1] - b[1], a[2] - b[2])


def _scale(s, a):
    return (s * a[0], s * a[1], s * a[2])


def _axpy(s, a, b):
    """s·a + b."""
    return (s * a[0] + b[0], s * a[1] + b[1], s * a[2] + b[2])


def _cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def _dot(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def _combine(coefs, vecs):
    """Σ c_i v_i over the non-zero constant coefficients c_i (at least one term, else zeros)."""
    out = None
    for c, v in zip(coefs, vecs):
        if c != 0.0:
            out = _scale(c, v) if out is None else _axpy(c, v, out)
    return ZERO3 if out is None else out


# --- chain --------------------------------------------------------------------------------------------
def joint_columns(q: np.ndarray):
    """Per-joint values: a list of floats for q of shape (n,), else contiguous (B,) arrays and the batch shape."""
    if q.ndim == 1:
        return q.tolist(), None
    batch = q.shape[:-1]
    size = int(np.prod(batch, dtype=int))
    return list(np.ascontiguousarray(q.reshape(size, q.shape[-1]).T)), batch


def frames(pl: _Plan, qcols) -> list[tuple]:
    """World frames {0} … {N} as (x, y, z, p) column tuples, walked by the chain (:mod:`denavit.chain`)."""
    return walk(pl.chain, qcols, FLOATS if isinstance(qcols[0], float) else COMPONENTS, frames=True)


def _piece_world(piece: _Piece, F):
    """World COM and the map v ↦ I_world v = R (I (Rᵀ v)) of a piece in frame F = (x, y, z, p)."""
    x, y, z, p = F
    c = _axpy(1.0, _combine(piece.com, (x, y, z)), p)
    I = piece.inertia

    def apply(v):
        u = (_dot(x, v), _dot(y, v), _dot(z, v))  # Rᵀ v
        Iu = [sum(I[i][j] * u[j] for j in range(3) if I[i][j] != 0.0) for i in range(3)]
        return _axpy(Iu[0], x, _axpy(Iu[1], y, _scale(Iu[2], z)))

    return c, apply


# --- RNEA -----------------------------------------------------------------------------------------------
def rnea_kernel(pl: _Plan, qc, qdc, qddc, g, F=None) -> list:
    """τ per joint (floats or (B,) arrays, motor inertia included, no friction) — Craig eqs. 6.45–6.53.

    ``F``: the frames of :func:`frames` when already computed for ``qc``.
    """
    F = frames(pl, qc) if F is None else F
    n = len(pl.revolute)
    axes = [(F[i][2], F[i][3]) for i in pl.axis_frame]
    w = wd = ZERO3
    acc = (-g[0], -g[1], -g[2])  # base accelerates at −g
    ref = axes[0][1]
    fs, ns = [], []
    for k in range(n):
        z, o = axes[k]
        r = _sub(o, ref)
        if w is not ZERO3:
            acc = _add(acc, _add(_cross(wd, r), _cross(w, _cross(w, r))))
        qz, qzz = _scale(qdc[k], z), _scale(qddc[k], z)
        if pl.revolute[k]:
            wd = _add(wd, _add(qzz, _cross(w, qz))) if w is not ZERO3 else _add(wd, qzz)
            w = _add(w, qz)
        else:
            acc = _add(acc, _axpy(2.0, _cross(w, qz), qzz))
        ref = o
        f_k, n_k = ZERO3, ZERO3
        for piece in pl.pieces[k]:
            c, inertia = _piece_world(piece, F[piece.row + 1])
            rc = _sub(c, o)
            ac = _add(acc, _add(_cross(wd, rc), _cross(w, _cross(w, rc))))
            f = _scale(piece.mass, ac)
            N = _add(inertia(wd), _cross(w, inertia(w)))
            f_k = _add(f_k, f)
            n_k = _add(n_k, _add(N, _cross(rc, f)))
        fs.append(f_k)
        ns.append(n_k)
    tau = [0.0] * n
    f = m = ZERO3
    for k in range(n - 1, -1, -1):
        z, o = axes[k]
        if k < n - 1:
            m = _add(m, _cross(_sub(axes[k + 1][1], o), f))  # moment moved from o_{k+1} to o_k
        f, m = _add(f, fs[k]), _add(m, ns[k])
        tau[k] = _dot(z, m if pl.revolute[k] else f) + pl.armature[k] * qddc[k]
    return tau


# --- CRBA -----------------------------------------------------------------------------------------------
def _piece_spatial(piece: _Piece, F):
    """Mass, first moment h = m c and rotational inertia about the world origin (xx, yy, zz, xy, xz, yz)."""
    x, y, z, p = F
    m = piece.mass
    c = _axpy(1.0, _combine(piece.com, (x, y, z)), p)
    I = piece.inertia
    cols = (x, y, z)
    A = [_combine((I[0][b], I[1][b], I[2][b]), cols) for b in range(3)]  # columns of R I
    J = [_dot((A[0][i], A[1][i], A[2][i]), (x[j], y[j], z[j])) for i, j in ((0, 0), (1, 1), (2, 2), (0, 1), (0, 2), (1, 2))]
    cc = _dot(c, c)
    if m != 0.0:
        J = [J[0] + m * (cc - c[0] * c[0]), J[1] + m * (cc - c[1] * c[1]), J[2] + m * (cc - c[2] * c[2]),
             J[3] - m * c[0] * c[1], J[4] - m * c[0] * c[2], J[5] - m * c[1] * c[2]]
    return m, _scale(m, c), J


def mass_matrix_kernel(pl: _Plan, qc, F=None) -> list[list]:
    """M as nested lists of entries: M_jk = S_jᵀ I^C_k S_k (Featherstone 2008, eq. 6.8) + motor inertia."""
    F = frames(pl, qc) if F is None else F
    n = len(pl.revolute)
    axes = [(F[i][2], F[i][3]) for i in pl.axis_frame]
    S = [(_cross(o, z), z) if rev else (z, None) for (z, o), rev in zip(axes, pl.revolute)]
    M = [[0.0] * n for _ in range(n)]
    mC, hC, JC = 0.0, ZERO3, [0.0] * 6
    for k in range(n - 1, -1, -1):
        for piece in pl.pieces[k]:
            m, h, J = _piece_spatial(piece, F[piece.row + 1])
            mC, hC, JC = mC + m, _add(hC, h), [a + b for a, b in zip(JC, J)]
        v, w = S[k]
        if w is None:  # prismatic: S = (z, 0)
            f, nn = _scale(mC, v), _cross(hC, v)
        else:  # f = m v − h × ω, n = h × v + J ω
            f = _sub(_scale(mC, v), _cross(hC, w))
            Jw = (JC[0] * w[0] + JC[3] * w[1] + JC[4] * w[2], JC[3] * w[0] + JC[1] * w[1] + JC[5] * w[2],
                  JC[4] * w[0] + JC[5] * w[1] + JC[2] * w[2])
            nn = _add(_cross(hC, v), Jw)
        for j in range(k + 1):
            vj, wj = S[j]
            M[j][k] = _dot(vj, f) + (_dot(wj, nn) if wj is not None else 0.0)
            M[k][j] = M[j][k]
        M[k][k] = M[k][k] + pl.armature[k]
    return M


def ldl_pivots_solve(M, b):
    """``(x, d)``: x = M⁻¹ b and the pivots d of M = L D Lᵀ, on entries (floats, (B,) arrays or traced values).

    Golub & Van Loan, *Matrix Computations*, 4th ed., alg. 4.1.2 (LDLᵀ), arithmetic only (no test, no
    pivoting): the caller decides from ``d`` whether M was singular.  Floats raise ZeroDivisionError on a
    zero pivot; arrays give inf/NaN there.
    """
    n = len(b)
    L = [[0.0] * n for _ in range(n)]
    d = [0.0] * n
    for j in range(n):
        Ld = [L[j][k] * d[k] for k in range(j)]
        d[j] = M[j][j] - sum(L[j][k] * Ld[k] for k in range(j))
        for i in range(j + 1, n):
            L[i][j] = (M[i][j] - sum(L[i][k] * Ld[k] for k in range(j))) / d[j]
    y = []
    for i in range(n):
        y.append(b[i] - sum(L[i][k] * y[k] for k in range(i)))
    x = [0.0] * n
    for i in range(n - 1, -1, -1):
        x[i] = y[i] / d[i] - sum(L[k][i] * x[k] for k in range(i + 1, n))
    return x, d


def ldl_solve(M, b, tol: float):
    """x = M⁻¹ b by M = L D Lᵀ (:func:`ldl_pivots_solve`); None where a pivot is ≤ tol · max pivot.

    The pivots d_j equal the squared diagonal of the Cholesky factor, so the singularity test is the one of
    the Cholesky route.
    """
    try:
        with np.errstate(divide="ignore", invalid="ignore"):
            x, d = ldl_pivots_solve(M, b)
    except ZeroDivisionError:
        return None
    if all(isinstance(v, float) for v in d):
        ok = min(d) > tol * max(d)
    else:
        D = np.array(np.broadcast_arrays(*d))
        ok = bool(np.all(D.min(axis=0) > tol * D.max(axis=0)))
    return x if ok else None


def to_array(values, batch, trailing: tuple[int, ...]) -> np.ndarray:
    """Nested lists of entries (floats or (B,) arrays) → array of shape batch + trailing."""
    if batch is None:
        return np.array(values, dtype=float)
    size = int(np.prod(batch, dtype=int))
    flat = np.empty(trailing + (size,))
    for idx in np.ndindex(*trailing):
        v = values
        for i in idx:
            v = v[i]
        flat[idx] = v
    return np.moveaxis(flat, -1, 0).reshape(batch + trailing)
