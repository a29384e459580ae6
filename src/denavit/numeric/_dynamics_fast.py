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
           "frames", "body_frames", "body_origins"]

ZERO3 = (0.0, 0.0, 0.0)


@dataclass(frozen=True)
class _Piece:
    row: int
    mass: float
    com: tuple[float, float, float]  # frame {row}
    inertia: tuple[tuple[float, float, float], ...]  # 3×3 about the COM, frame {row} axes


@dataclass(frozen=True)
class _Body:
    """Body k's inertial parameters in the linear form: mass m, first moment h = m c and rotational inertia J,
    both about O_k (the origin of joint k's frame, a point of its axis fixed in the body) in the axes of DH frame
    ``frame`` (frame {r + 1} after the joint's row r).  ``to_joint``: rotation from the joint frame's axes to
    those axes (vector components v_frame = to_joint · v_joint; the identity for modified DH)."""

    frame: int
    mass: float
    h: tuple[float, float, float]
    J: tuple[tuple[float, float, float], ...]
    to_joint: tuple[tuple[float, float, float], ...]


@dataclass(frozen=True)
class _Plan:
    """Constants of a robot needed by the kernels (derived once per distinct robot value)."""

    chain: Chain  # rows, base, joint rule
    axis_frame: tuple[int, ...]  # per joint: index (0 = base, r + 1 = after row r) of the frame holding its axis
    revolute: tuple[bool, ...]
    pieces: tuple[tuple[_Piece, ...], ...]  # per body (joint)
    armature: tuple[float, ...]
    bodies: tuple[_Body, ...]  # per joint: the pieces summed into the linear form (the RNEA's input)
    slide: tuple[bool, ...]  # per joint: O_k moves along the axis with q_k (a prismatic joint, standard DH)


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
        bodies=tuple(_make_body(chain, k, pieces[k]) for k in range(robot.dof)),
        slide=tuple(chain.standard and not rev for rev in chain.revolute),
    )


def _make_body(chain: Chain, k: int, pieces) -> _Body:
    """Body k's pieces summed about O_k in frame {r+1} axes (parallel-axis theorem; Khalil & Dombre 2002, §9.3).

    Joint frame = frame {r+1} · D_r⁻¹ (standard DH: A_r = J(q) D_r) or frame {r+1} itself (modified), so O_k sits at
    −R_Dᵀ p_D in frame {r+1} (standard) and the joint frame's axes are R_Dᵀ's columns there.
    """
    r = chain.joint_rows[k]
    D = chain.row_constant(r) if chain.standard else np.eye(4)
    origin = -D[:3, :3].T @ D[:3, 3]  # O_k in frame {r+1}
    m, h, J = 0.0, np.zeros(3), np.zeros((3, 3))
    for piece in pieces:
        X = np.eye(4)  # frame {row+1} seen from frame {r+1}: the fixed rows in between
        for i in range(r + 1, piece.row + 1):
            X = X @ chain.row_constant(i)
        c = X[:3, :3] @ np.array(piece.com) + X[:3, 3] - origin
        m += piece.mass
        h += piece.mass * c
        J += X[:3, :3] @ np.array(piece.inertia) @ X[:3, :3].T + piece.mass * (c @ c * np.eye(3) - np.outer(c, c))
    def tup(M):
        return tuple(tuple(float(v) for v in row) for row in M)
    return _Body(r + 1, float(m), tuple(float(v) for v in h), tup(J), tup(D[:3, :3].T))


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


# --- RNEA -----------------------------------------------------------------------------------------------
def _nonzero(v) -> bool:
    """False only for a float 0 (parameters are floats for the robot, opaque values in the regressor)."""
    return not (v.__class__ is float and v == 0.0)


def body_origins(pl: _Plan, F, qc) -> list:
    """World O_k per joint: the origin of joint k's frame, on its axis (the axis frame's origin, moved by q_k
    along the axis for a prismatic joint of a standard-DH arm)."""
    out = []
    for k, i in enumerate(pl.axis_frame):
        z, o = F[i][2], F[i][3]
        out.append(_axpy(qc[k], z, o) if pl.slide[k] else o)
    return out


def body_frames(pl: _Plan) -> tuple:
    """Per body: (frame index, m, h, J, armature) of the robot, the parameters :func:`rnea_kernel` uses."""
    return tuple((b.frame, b.mass, b.h, b.J, a) for b, a in zip(pl.bodies, pl.armature))


def _body_wrench(body, R, w, wd, acc):
    """Force and moment about O_k of one body from its linear-form parameters (Khalil & Dombre 2002, eq. 9.44):

    f = m a_O + ω̇ × h + ω × (ω × h),   n_O = J ω̇ + ω × (J ω) + h × a_O,

    with h turned into world axes by R = (x, y, z) of the body's frame, and the J terms evaluated in the body's
    own axes: R (J ω̇_b + ω_b × (J ω_b)) with ω_b = Rᵀ ω, ω̇_b = Rᵀ ω̇ (R (a × b) = R a × R b) — three turns of
    axes, where R J Rᵀ applied to ω̇ and to ω takes four (a quarter of the ∂RNEA kernel's operations went there).
    """
    _, m, h, J, _ = body
    x, y, z = R
    f = _scale(m, acc) if _nonzero(m) else ZERO3
    n = ZERO3
    if any(_nonzero(c) for c in h):
        hw = _combine_any(h, (x, y, z))
        f = _add(f, _add(_cross(wd, hw), _cross(w, _cross(w, hw)))) if w is not ZERO3 else _add(f, _cross(wd, hw))
        n = _cross(hw, acc)

    def J_times(u):  # J u in the body's axes (terms with a float-zero J_ij skipped)
        return tuple(_sum_any([J[i][j] * u[j] for j in range(3) if _nonzero(J[i][j])]) for i in range(3))

    if any(_nonzero(c) for row in J for c in row) and (wd is not ZERO3 or w is not ZERO3):
        n_b = J_times((_dot(x, wd), _dot(y, wd), _dot(z, wd)))
        if w is not ZERO3:
            w_b = (_dot(x, w), _dot(y, w), _dot(z, w))
            n_b = _add(n_b, _cross(w_b, J_times(w_b)))
        n = _add(n, _combine_any(n_b, (x, y, z)))
    return f, n


def _sum_any(terms):
    if not terms:
        return 0.0
    out = terms[0]
    for t in terms[1:]:
        out = out + t
    return out


def _combine_any(coefs, vecs):
    """Σ c_i v_i with c_i floats or opaque values (terms with a float-zero c_i skipped)."""
    out = None
    for c, v in zip(coefs, vecs):
        if _nonzero(c):
            out = _scale(c, v) if out is None else _axpy(c, v, out)
    return ZERO3 if out is None else out


def rnea_kernel(pl: _Plan, qc, qdc, qddc, g, F=None, params=None) -> list:
    """τ per joint (floats or (B,) arrays, motor inertia included, no friction) — Craig eqs. 6.45–6.53, with each
    body's wrench from its parameters in the linear form (:func:`_body_wrench`), about O_k.

    ``F``: the frames of :func:`frames` when already computed for ``qc``.  ``params``: per body
    (frame, m, h, J, armature) in place of the robot's (:func:`body_frames`); τ is linear in them, which the
    regressor uses (:mod:`denavit.numeric._regressor`).
    """
    F = frames(pl, qc) if F is None else F
    params = body_frames(pl) if params is None else params
    n = len(pl.revolute)
    axes = [F[i][2] for i in pl.axis_frame]
    origins = body_origins(pl, F, qc)
    w = wd = ZERO3
    acc = (-g[0], -g[1], -g[2])  # base accelerates at −g
    ref = origins[0]
    fs, ns = [], []
    for k in range(n):
        z, o = axes[k], origins[k]
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
        f_k, n_k = _body_wrench(params[k], F[params[k][0]][:3], w, wd, acc)
        fs.append(f_k)
        ns.append(n_k)
    tau = [0.0] * n
    f = m = ZERO3
    for k in range(n - 1, -1, -1):
        z, o = axes[k], origins[k]
        if k < n - 1:
            m = _add(m, _cross(_sub(origins[k + 1], o), f))  # moment moved from O_{k+1} to O_k
        f, m = _add(f, fs[k]), _add(m, ns[k])
        tau[k] = _dot(z, m if pl.revolute[k] else f)
        if _nonzero(params[k][4]):
            tau[k] = tau[k] + params[k][4] * qddc[k]
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
