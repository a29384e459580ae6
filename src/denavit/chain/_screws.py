"""The chain as arrays, ``C0 · J1(q1) · C1 ⋯ Jm(qm) · Cm``, and its batched walker on columns.

C_k are constant transforms and J_k = Rz(q) or Tz(q) (the product-of-exponentials form in local coordinates,
Lynch & Park 2017, Sec. 4.1).  :class:`Screws` holds the constants stacked and the prismatic mask: a robot's
comes from its :class:`~denavit.chain.Chain` (:func:`screws_of`: base, fixed rows and tool folded in), and
the IK derives others from it (the chain of T⁻¹ by :func:`reverse_screws`, chains with coaxial joints
merged).  :func:`screw_walk` is the one product over this form, on numpy arrays of any batch shape; a joint
rotation is ``x ← c x + s y``, ``y ← c y − s x`` on the columns and a constant is a few axpy's over its
non-zero entries, with no (…, 4, 4) intermediates.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property
from math import cos, sin

import numpy as np

from ._chain import chain_of

__all__ = ["Screws", "screws_of", "reverse_screws", "screw_walk", "screw_walk_floats", "screw_pose", "screw_axes", "reach_ball", "STRUCTURAL_ZERO"]

#: Constant entries at or below this are structural zeros and skipped (cos 90° = 6e-17 in a product).
STRUCTURAL_ZERO = 1e-15


@dataclass(frozen=True, eq=False)
class Screws:
    """``T = C0 J1(q1) C1 ⋯ Jm(qm) Cm``: ``consts`` (m+1, 4, 4), ``prismatic`` (m,) bool."""

    consts: np.ndarray
    prismatic: np.ndarray

    @property
    def n(self) -> int:
        """Number of joints m."""
        return len(self.prismatic)

    @cached_property
    def floats(self) -> tuple:
        """(start, consts, prismatic) in Python floats for :func:`screw_walk_floats`: C_0's rows [R | p] as three
        4-tuples, each C_k (k ≥ 1) as the 12 numbers (C00, C10, C20, C01, …, C23), the mask as bools."""
        C0 = self.consts[0]
        start = tuple(tuple(float(v) for v in C0[i, :4]) for i in range(3))
        consts = tuple(tuple(float(C[m, j]) for j in range(4) for m in range(3)) for C in self.consts[1:])
        return start, consts, tuple(bool(v) for v in self.prismatic)

    @cached_property
    def terms(self) -> tuple:
        """For each C_k, k ≥ 1, and each of its columns (x, y, z, p): the (row j, coefficient) pairs of its
        rotation part that are not structural zeros (column j of R·C_k is Σ_j R[:, j] C_k[j, col])."""
        return tuple(tuple(tuple((j, float(C[j, col])) for j in range(3) if abs(C[j, col]) > STRUCTURAL_ZERO)
                           for col in range(4)) for C in self.consts[1:])


def screws_of(robot) -> Screws:
    """The robot's chain as :class:`Screws` (:attr:`denavit.chain.Chain.constants` stacked), once per robot."""
    chain = chain_of(robot)
    hit = chain.memo.get("screws")
    if hit is None:
        hit = chain.memo["screws"] = Screws(np.array(chain.constants), np.array(chain.prismatic, dtype=bool))
    return hit


def reach_ball(screws: Screws, lo, hi) -> tuple[np.ndarray, float]:
    """Centre c (3,) and radius R of a ball holding the end-effector origin for every q with lo ≤ q ≤ hi.

    With T = C0 J1 C1 ⋯ Jn Cn, rotations keep lengths and a prismatic joint adds q_k along a unit axis, so
    |p − t(C0)| ≤ Σ_{k≥1} |t(C_k)| + Σ_prismatic max(|lo_k|, |hi_k|); R is inf when a prismatic joint is unbounded.
    """
    travel = np.maximum(np.abs(np.asarray(lo, float)), np.abs(np.asarray(hi, float)))[screws.prismatic]
    R = float(np.hypot.reduce(screws.consts[1:, :3, 3], axis=-1).sum() + travel.sum())
    return np.array(screws.consts[0, :3, 3], dtype=float), R


def reverse_screws(screws: Screws) -> Screws:
    """The chain of ``T⁻¹``: ``Cm⁻¹ Jm(−qm) ⋯ C0⁻¹``; its joint k is joint m+1−k with the sign flipped."""
    C = screws.consts[::-1]
    inv = np.zeros_like(C)
    Rt = np.swapaxes(C[:, :3, :3], -1, -2)
    inv[:, :3, :3] = Rt
    inv[:, :3, 3] = -np.einsum("kij,kj->ki", Rt, C[:, :3, 3])
    inv[:, 3, 3] = 1.0
    return Screws(inv, screws.prismatic[::-1].copy())


def _combine(cols, terms, acc=None):
    """acc + Σ c·cols[j] over terms (j, c); a ±1 coefficient costs no multiplication."""
    for j, c in terms:
        t = cols[j] if c == 1.0 else (-cols[j] if c == -1.0 else c * cols[j])
        acc = t if acc is None else acc + t
    return np.zeros_like(cols[0]) if acc is None else acc


def screw_walk(screws: Screws, q, upto: int | None = None, start: int = 0, axes: bool = False):
    """``C_start J_{start+1}(q) C_{start+1} ⋯ J_upto C_upto`` as its columns x, y, z, p, each (3,) + q.shape[:-1].

    ``q[..., k]`` is the value of joint ``start + k + 1`` (1-based joints); ``upto=None`` walks to the end.
    With ``axes=True`` also the lists of each joint's axis direction z_k and a point o_k on it (the columns z
    and p just before its motion), each (3,) + q.shape[:-1].
    """
    upto = screws.n if upto is None else upto
    q = np.asarray(q, dtype=float)
    shape = q.shape[:-1]
    qT = np.ascontiguousarray(np.moveaxis(q, -1, 0))  # one contiguous row per joint
    C = screws.consts[start]
    x, y, z, p = (np.broadcast_to(C[:3, j].reshape((3,) + (1,) * len(shape)), (3,) + shape) for j in range(4))
    zs, os = [], []
    for k in range(start, upto):
        if axes:
            zs.append(z)
            os.append(p)
        qk = qT[k - start]
        if screws.prismatic[k]:
            p = p + qk * z
        else:
            c, s = np.cos(qk), np.sin(qk)
            x, y = c * x + s * y, c * y - s * x
        cols = (x, y, z)
        tx, ty, tz, tp = screws.terms[k]
        x, y, z, p = _combine(cols, tx), _combine(cols, ty), _combine(cols, tz), _combine(cols, tp, p)
    return (x, y, z, p, zs, os) if axes else (x, y, z, p)


def screw_pose(screws: Screws, q, upto: int | None = None, start: int = 0) -> np.ndarray:
    """:func:`screw_walk` as homogeneous matrices, shape q.shape[:-1] + (4, 4)."""
    cols = screw_walk(screws, q, upto, start)
    shape = np.shape(q)[:-1]
    T = np.zeros(shape + (4, 4))
    for j, col in enumerate(cols):
        T[..., :3, j] = np.moveaxis(col, 0, -1)
    T[..., 3, 3] = 1.0
    return T


def screw_axes(screws: Screws, q) -> tuple[np.ndarray, np.ndarray]:
    """A point on and the direction of every joint axis at q, each q.shape[:-1] + (m, 3)."""
    *_, zs, os = screw_walk(screws, q, axes=True)
    shape = np.shape(q)[:-1]
    if not zs:
        return np.zeros(shape + (0, 3)), np.zeros(shape + (0, 3))
    return np.moveaxis(np.stack(os, axis=-1), 0, -1), np.moveaxis(np.stack(zs, axis=-1), 0, -1)


def screw_walk_floats(screws: Screws, q) -> tuple[tuple, list]:
    """:func:`screw_walk` for one configuration in Python floats (no numpy call per step: for one pose numpy's
    call overhead is most of the cost).

    Returns the pose as its three rows ((x_0, y_0, z_0, p_0), (x_1, …), (x_2, …)) and, per joint, its axis
    direction and a point on it as (z_0, z_1, z_2, o_0, o_1, o_2).  Joint k acts on columns x, y (revolute) or
    on p (prismatic), then the constant C_k multiplies from the right.
    """
    rows, consts, prismatic = screws.floats
    axes = []
    for k in range(len(prismatic)):
        (x0, y0, z0, p0), (x1, y1, z1, p1), (x2, y2, z2, p2) = rows
        axes.append((z0, z1, z2, p0, p1, p2))
        if prismatic[k]:
            qk = q[k]
            p0, p1, p2 = p0 + qk * z0, p1 + qk * z1, p2 + qk * z2
        else:
            c, s = cos(q[k]), sin(q[k])
            x0, y0 = c * x0 + s * y0, c * y0 - s * x0
            x1, y1 = c * x1 + s * y1, c * y1 - s * x1
            x2, y2 = c * x2 + s * y2, c * y2 - s * x2
        a0, a1, a2, b0, b1, b2, c0, c1, c2, d0, d1, d2 = consts[k]
        rows = ((x0 * a0 + y0 * a1 + z0 * a2, x0 * b0 + y0 * b1 + z0 * b2, x0 * c0 + y0 * c1 + z0 * c2,
                 p0 + x0 * d0 + y0 * d1 + z0 * d2),
                (x1 * a0 + y1 * a1 + z1 * a2, x1 * b0 + y1 * b1 + z1 * b2, x1 * c0 + y1 * c1 + z1 * c2,
                 p1 + x1 * d0 + y1 * d1 + z1 * d2),
                (x2 * a0 + y2 * a1 + z2 * a2, x2 * b0 + y2 * b1 + z2 * b2, x2 * c0 + y2 * c1 + z2 * c2,
                 p2 + x2 * d0 + y2 * d1 + z2 * d2))
    return rows, axes
