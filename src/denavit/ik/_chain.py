"""The joint-screw form of a DH chain, as arrays, and the small subproblems the analytic IK is built from.

The arm, base, fixed rows and tool included, is ``T_w_e = C0 J1(q1) C1 J2(q2) ⋯ Jn(qn) Cn`` with constant
``C_k`` and J_k = Rz(q) or Tz(q) (the product-of-exponentials form in local coordinates, Lynch & Park 2017,
Sec. 4.1).  The constants and joint kinds are those of :mod:`denavit.chain` (the one place that splits DH rows
of either convention into constants and joint motions); :func:`chain_of` only stacks them into arrays for the
batched IK code.  The IK solvers work on this form only, so they treat both conventions, offsets and fixed rows alike
(no per-convention derivation to get wrong).  The subproblems are those of Paden (1986) and Kahan,
as collected in Murray, Li & Sastry (1994), Sec. 3.3.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..chain import chain_of as _chain_of
from ..model import DHRobot
from ..numeric import inverse_transform

__all__ = ["Chain", "damped_solve", "chain_of", "chain_fk", "chain_columns", "joint_motion", "reverse_chain", "solve_trig", "angle_about_z",
           "wrap_angle", "axis_lines"]


@dataclass(frozen=True, eq=False)
class Chain:
    """``T = C0 J1(q1) C1 ⋯ Jn(qn) Cn``: consts (n+1, 4, 4), prismatic (n,) bool."""

    consts: np.ndarray
    prismatic: np.ndarray

    @property
    def n(self) -> int:
        return len(self.prismatic)


def chain_of(robot: DHRobot) -> Chain:
    """The joint-screw form of a robot as arrays: :attr:`denavit.chain.Chain.constants` (base, fixed rows and
    tool folded in) stacked, and the joints' prismatic mask."""
    chain = _chain_of(robot)
    return Chain(np.array(chain.constants), np.array(chain.prismatic, dtype=bool))


def joint_motion(prismatic: bool, q: np.ndarray) -> np.ndarray:
    """Rz(q) or Tz(q), shape q.shape + (4, 4)."""
    q = np.asarray(q, dtype=float)
    J = np.zeros(q.shape + (4, 4))
    J[..., 3, 3] = 1.0
    J[..., 2, 2] = 1.0
    if prismatic:
        J[..., 0, 0] = J[..., 1, 1] = 1.0
        J[..., 2, 3] = q
    else:
        c, s = np.cos(q), np.sin(q)
        J[..., 0, 0], J[..., 0, 1], J[..., 1, 0], J[..., 1, 1] = c, -s, s, c
    return J


def chain_fk(chain: Chain, q: np.ndarray, upto: int | None = None, start: int = 0) -> np.ndarray:
    """``C_start J_{start+1} C_{start+1} ⋯ J_upto C_upto`` (joint indices 1-based), batched over q (..., m).

    ``q[..., k]`` is the value of joint ``start + k + 1``.  With ``upto=None`` the whole chain is used.
    """
    upto = chain.n if upto is None else upto
    q = np.asarray(q, dtype=float)
    T = np.broadcast_to(chain.consts[start], q.shape[:-1] + (4, 4))
    for k in range(start, upto):
        T = T @ joint_motion(bool(chain.prismatic[k]), q[..., k - start]) @ chain.consts[k + 1]
    return T


def chain_columns(chain: Chain, q: np.ndarray, upto: int) -> tuple[np.ndarray, ...]:
    """``C0 J1 C1 ⋯ J_upto C_upto`` as its columns x, y, z (rotation) and p (origin), each (3,) + q.shape[:-1].

    The same product as :func:`chain_fk`, computed column-wise with the batch contiguous (a joint rotation is
    ``x ← c x + s y``, ``y ← c y − s x``; a constant is a few axpy's): no (…, 4, 4) intermediates, which is
    what makes it several times faster than batched 4×4 products for the IK's short partial chains.
    """
    q = np.asarray(q, dtype=float)
    shape = q.shape[:-1]
    C0 = chain.consts[0]
    x, y, z, p = (np.broadcast_to(C0[:3, j].reshape((3,) + (1,) * len(shape)), (3,) + shape) for j in range(4))
    for k in range(upto):
        qk = q[..., k]
        if chain.prismatic[k]:
            p = p + qk * z
        else:
            c, s = np.cos(qk), np.sin(qk)
            x, y = c * x + s * y, c * y - s * x
        C = chain.consts[k + 1]
        cols = (x, y, z)
        x, y, z = (sum(cols[i] * C[i, j] for i in range(3) if C[i, j] != 0.0) for j in range(3))
        p = p + sum(cols[i] * C[i, 3] for i in range(3) if C[i, 3] != 0.0)
    return x, y, z, p


def reverse_chain(chain: Chain) -> Chain:
    """The chain of ``T⁻¹``: ``Cn⁻¹ Jn(−qn) ⋯ C0⁻¹``; its joint k is joint n+1−k with the sign flipped."""
    return Chain(inverse_transform(chain.consts[::-1]), chain.prismatic[::-1].copy())


def axis_lines(chain: Chain, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Point on and direction of every joint axis in world coordinates at q, each (..., n, 3)."""
    q = np.asarray(q, dtype=float)
    T = np.broadcast_to(chain.consts[0], q.shape[:-1] + (4, 4))
    pts, dirs = [], []
    for k in range(chain.n):
        pts.append(T[..., :3, 3])
        dirs.append(T[..., :3, 2])
        T = T @ joint_motion(bool(chain.prismatic[k]), q[..., k]) @ chain.consts[k + 1]
    return np.stack(pts, axis=-2), np.stack(dirs, axis=-2)


def wrap_angle(x: np.ndarray) -> np.ndarray:
    """Angles wrapped into (−π, π]."""
    return np.pi - np.mod(np.pi - np.asarray(x, dtype=float), 2 * np.pi)


def solve_trig(a, b, c, tol: float = 1e-9) -> np.ndarray:
    """All θ with ``a cos θ + b sin θ = c`` (Paden–Kahan subproblem 1 in scalar form), shape (..., 2).

    θ = atan2(b, a) ± arccos(c / √(a² + b²)); NaN where there is no solution (|c| > ρ) or the equation does
    not depend on θ (ρ ≈ 0).  A ratio within ``tol`` beyond ±1 is taken as the tangent (double) root.
    """
    a, b, c = np.broadcast_arrays(*(np.asarray(x, dtype=float) for x in (a, b, c)))
    rho = np.hypot(a, b)
    with np.errstate(invalid="ignore", divide="ignore"):
        ratio = c / rho
    ok = (rho > 1e-12) & (np.abs(ratio) <= 1 + tol)
    base = np.arctan2(b, a)
    delta = np.arccos(np.clip(np.where(ok, ratio, 0.0), -1.0, 1.0))
    out = np.stack([base + delta, base - delta], axis=-1)
    return np.where(ok[..., None], out, np.nan)


def angle_about_z(u: np.ndarray, v: np.ndarray) -> np.ndarray:
    """θ with Rz(θ) u ≈ v in the xy-plane (Paden–Kahan subproblem 2 about z), shape (...)."""
    return np.arctan2(v[..., 1], v[..., 0]) - np.arctan2(u[..., 1], u[..., 0])


def damped_solve(A: np.ndarray, b: np.ndarray) -> np.ndarray:
    """``np.linalg.solve(A, b)`` for a batch of damped normal matrices A = JᵀJ + λI (..., n, n), b (..., n, k).

    The damping can vanish against JᵀJ (a target 1e6 m away makes JᵀJ ~1e12 and λ lost to rounding on an arm
    whose J lacks rank): such an A is exactly singular in floating point and LAPACK raises; those systems get
    the least-squares step of their pseudo-inverse instead (no bare LinAlgError from the IK functions)."""
    try:
        return np.linalg.solve(A, b)
    except np.linalg.LinAlgError:
        return np.linalg.pinv(np.nan_to_num(A, nan=0.0, posinf=0.0, neginf=0.0)) @ b
