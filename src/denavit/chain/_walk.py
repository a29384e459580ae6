"""The one walker of the chain: base → row 1 → … → row N, in three algebras.

- :class:`Floats`: one configuration, poses as column tuples (x, y, z, p) of 3-tuples of Python floats
  (no numpy call per step: for one pose numpy's call overhead is most of the cost);
- :class:`Components`: one configuration or a batch, each column a 3-tuple of components (floats or (B,)
  arrays, mixed: constants stay floats), the layout of the dynamics kernels;
- :class:`Batch`: a batch of B configurations, columns as (3, B) arrays (every component contiguous);
- :class:`Symbolic`: sympy, poses as 4×4 ImmutableMatrix, each step ``simplify(T · A_i)``.

The numeric algebras apply a row as its four elementary motions (rotation/translation about z and x) on
the columns: the same product as 4×4 matrices at about a third of the arithmetic, zero terms skipped.
"""

from __future__ import annotations

from math import cos, sin
from typing import Callable

import numpy as np

from ..model import Convention
from ._chain import Chain, cos_sin, joint_motion

__all__ = ["walk", "Floats", "Components", "Batch", "Symbolic", "FLOATS", "COMPONENTS", "pack", "IDENTITY_COLUMNS"]

IDENTITY_COLUMNS = ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0), (0.0, 0.0, 0.0))


def walk(chain: Chain, q, algebra, *, frames=False, base: bool = True, first: int = 0,
         last: int | None = None):
    """Walk rows ``first`` … ``last - 1`` of the chain for joint values ``q`` (one per joint).

    Starts at the base pose (``base=True``, only when ``first == 0`` makes sense) or at the identity.
    Returns the last pose; with ``frames=True`` the list of poses: start, then after every row (with
    ``first=0`` these are the DH frames {0} … {N}); with ``frames`` a sequence of such frame indices,
    ``(poses at those indices, last pose)``.  The tool is not applied.
    """
    pose = algebra.start(chain, base)
    stop = chain.n_rows if last is None else last
    step, keep = algebra.row, algebra.keep
    if frames is False:
        for i in range(first, stop):
            pose = step(chain, pose, i, q)
        return pose
    if frames is True:
        out = [keep(pose) if keep else pose]
        for i in range(first, stop):
            pose = step(chain, pose, i, q)
            out.append(keep(pose) if keep else pose)
        return out
    wanted = set(frames)
    kept = {first: keep(pose) if keep else pose} if first in wanted else {}
    for i in range(first, stop):
        pose = step(chain, pose, i, q)
        if i + 1 in wanted:
            kept[i + 1] = keep(pose) if keep else pose
    return [kept[f] for f in frames], pose


class Floats:
    """One configuration: ``q`` a sequence of floats; a pose is (x, y, z, p), each a 3-tuple of floats."""

    @staticmethod
    def start(chain: Chain, base: bool):
        return chain.base_columns if base else IDENTITY_COLUMNS

    keep = None  # poses are never changed in place

    @staticmethod
    def row(chain: Chain, pose, i: int, q):
        row = chain.rows[i]
        theta, d = joint_motion(row, q, row.theta, row.d)
        x, y, z, p = pose
        c, s = cos(theta), sin(theta)
        if not chain.standard:  # Rx(α) Tx(a) first
            if row.rot_x:
                ca, sa = row.ca, row.sa
                y, z = ((ca * y[0] + sa * z[0], ca * y[1] + sa * z[1], ca * y[2] + sa * z[2]),
                        (ca * z[0] - sa * y[0], ca * z[1] - sa * y[1], ca * z[2] - sa * y[2]))
            if row.a != 0.0:
                a = row.a
                p = (p[0] + a * x[0], p[1] + a * x[1], p[2] + a * x[2])
        x, y = ((c * x[0] + s * y[0], c * x[1] + s * y[1], c * x[2] + s * y[2]),
                (c * y[0] - s * x[0], c * y[1] - s * x[1], c * y[2] - s * x[2]))
        if d != 0.0:
            p = (p[0] + d * z[0], p[1] + d * z[1], p[2] + d * z[2])
        if chain.standard:  # then Tx(a) Rx(α)
            if row.a != 0.0:
                a = row.a
                p = (p[0] + a * x[0], p[1] + a * x[1], p[2] + a * x[2])
            if row.rot_x:
                ca, sa = row.ca, row.sa
                y, z = ((ca * y[0] + sa * z[0], ca * y[1] + sa * z[1], ca * y[2] + sa * z[2]),
                        (ca * z[0] - sa * y[0], ca * z[1] - sa * y[1], ca * z[2] - sa * y[2]))
        return x, y, z, p


FLOATS = Floats()


class Components:
    """Floats or a batch, one code: ``q`` one value per joint, each a float or a contiguous (B,) array; a
    pose is (x, y, z, p), each a 3-tuple of components that are floats or (B,) arrays.

    A component stays a float until a joint motion reaches it (the base's columns, the z column through
    turns about z), which spares the dynamics kernels that consume these frames work on constants.
    """

    @staticmethod
    def start(chain: Chain, base: bool):
        return chain.base_columns if base else IDENTITY_COLUMNS

    keep = None  # components are never changed in place

    @staticmethod
    def row(chain: Chain, pose, i: int, q):
        row = chain.rows[i]
        theta, d = joint_motion(row, q, row.theta, row.d)
        x, y, z, p = pose
        if isinstance(theta, float):  # a fixed row: exact at multiples of π/2
            c, s = cos_sin(theta)
        else:
            c, s = np.cos(theta), np.sin(theta)
        if not chain.standard:  # Rx(α) Tx(a) first
            if row.rot_x:
                y, z = _axpy(row.ca, y, _scale(row.sa, z)), _axpy(row.ca, z, _scale(-row.sa, y))
            if row.a != 0.0:
                p = _axpy(row.a, x, p)
        x, y = _axpy(c, x, _scale(s, y)), _axpy(c, y, _scale(-s, x))
        if not isinstance(d, float) or d != 0.0:
            p = _axpy(d, z, p)
        if chain.standard:  # then Tx(a) Rx(α)
            if row.a != 0.0:
                p = _axpy(row.a, x, p)
            if row.rot_x:
                y, z = _axpy(row.ca, y, _scale(row.sa, z)), _axpy(row.ca, z, _scale(-row.sa, y))
        return x, y, z, p


def _scale(s, a):
    return (s * a[0], s * a[1], s * a[2])


def _axpy(s, a, b):
    """s·a + b on component 3-tuples."""
    return (s * a[0] + b[0], s * a[1] + b[1], s * a[2] + b[2])


COMPONENTS = Components()


class Batch:
    """B configurations: ``q`` indexable by joint, each entry a contiguous (B,) array (e.g. q of shape
    (n, B)); a pose is (x, y, z, p), each a (3, B) array.

    The origin is moved in place (at large batches the cost is memory traffic, not arithmetic), so a kept
    pose gets its own copy of p.
    """

    def __init__(self, size: int) -> None:
        self.size = size

    @staticmethod
    def keep(pose):
        x, y, z, p = pose
        return x, y, z, p.copy()

    def start(self, chain: Chain, base: bool):
        cols = chain.base_columns if base else IDENTITY_COLUMNS
        return tuple(np.repeat(np.array(col)[:, None], self.size, axis=1) for col in cols)  # 4 × (3, B)

    @staticmethod
    def row(chain: Chain, pose, i: int, q):
        row = chain.rows[i]
        theta, d = joint_motion(row, q, row.theta, row.d)
        x, y, z, p = pose
        c, s = np.cos(theta), np.sin(theta)
        if not chain.standard:
            if row.rot_x:
                y, z = _turn(row.ca, row.sa, y, z)
            if row.a != 0.0:
                p += row.a * x
        x, y = _turn(c, s, x, y)
        if isinstance(d, np.ndarray) or d != 0.0:
            p += d * z
        if chain.standard:
            if row.a != 0.0:
                p += row.a * x
            if row.rot_x:
                y, z = _turn(row.ca, row.sa, y, z)
        return x, y, z, p


def _turn(c, s, u, v):
    """(c u + s v, c v − s u): the two columns a rotation by (c, s) about the third axis changes."""
    nu = c * u
    nu += s * v
    nv = c * v
    nv -= s * u
    return nu, nv


class Symbolic:
    """sympy: ``q`` a sequence of joint symbols; a pose is a 4×4 ImmutableMatrix.

    Each step is ``simplify(T · A_i)`` with A_i the DH matrix of row i in the robot's parameter symbols
    (values put in with ``numeric``); ``simplify`` maps a matrix to a matrix (identity when None).
    """

    def __init__(self, chain: Chain, numeric: bool = False,
                 simplify: Callable | None = None) -> None:
        from ._symbolic import dh_matrix_sym

        self.rows = chain.rows_sym(numeric)
        self.dh = dh_matrix_sym
        self.simplify = simplify

    keep = None

    def start(self, chain: Chain, base: bool):
        import sympy as sp

        if base and not chain.base_identity:
            from ..symbolic import matrix_from_floats

            return matrix_from_floats(chain.base)
        return sp.ImmutableMatrix(sp.eye(4))

    def matrix(self, chain: Chain, i: int, q):
        """A_i(q): row i's DH matrix with its joint symbol put in."""
        r = self.rows[i]
        theta, d = joint_motion(chain.rows[i], q, r["theta"], r["d"])
        return self.dh(chain.convention, r["a"], r["alpha"], d, theta)

    def split(self, chain: Chain, i: int, q):
        """(head, tail) with A_i = head · tail and the joint's motion in the head, tail constant:
        standard Rz(θ) Tz(d) · Tx(a) Rx(α); modified the whole row · I.  The head ends in the frame where
        the joint's axis is z: standard {i-1} moved by the joint, modified {i}."""
        r = self.rows[i]
        theta, d = joint_motion(chain.rows[i], q, r["theta"], r["d"])
        if chain.standard:
            return (self.dh(chain.convention, 0, 0, d, theta),
                    self.dh(Convention.MODIFIED, r["a"], r["alpha"], 0, 0))  # Tx(a) Rx(α) = Rx(α) Tx(a)
        import sympy as sp

        return self.dh(chain.convention, r["a"], r["alpha"], d, theta), sp.ImmutableMatrix(sp.eye(4))

    def row(self, chain: Chain, pose, i: int, q):
        T = pose * self.matrix(chain, i, q)
        return self.simplify(T) if self.simplify is not None else T


def pack(poses, batch: tuple[int, ...] | None, contiguous: bool = True):
    """Poses (column tuples) → array (F, 4, 4) (``batch`` None: float poses) or batch + (F, 4, 4).

    A batch is filled as (F, 4, 4, B) with contiguous writes; ``contiguous=False`` returns the transposed view
    of that (one pass less; what a single end-effector pose needs), else a C-ordered copy.
    """
    F = len(poses)
    if batch is None:
        out = np.zeros((F, 4, 4))
        out[:, :3, :] = np.array(poses).transpose(0, 2, 1)  # (F, 4 columns, 3) → rows × columns
        out[:, 3, 3] = 1.0
        return out
    size = poses[0][0].shape[-1]
    T = np.zeros((F, 4, 4, size))  # filled with contiguous writes, then one transposing copy
    for f, cols in enumerate(poses):
        for j in range(4):
            T[f, :3, j] = cols[j]
    T[:, 3, 3] = 1.0
    T = T.transpose(3, 0, 1, 2)  # (B, F, 4, 4)
    return (np.ascontiguousarray(T) if contiguous else T).reshape(batch + (F, 4, 4))
