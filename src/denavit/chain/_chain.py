"""The arm written once: ``C0 · J1(q1) · C1 ⋯ Jn(qn) · Cn``.

A DH row is four elementary motions (DESIGN.md "Conventions"):

- standard (distal; Spong eq. 3.10):  A_i = Rz(θ_i) Tz(d_i) Tx(a_i) Rx(α_i);
- modified (proximal; Craig eq. 3.6): A_i = Rx(α_{i-1}) Tx(a_{i-1}) Rz(θ_i) Tz(d_i).

The joint variable q of a row is added to θ (revolute) or to d (prismatic).  Since Rz and Tz commute with
each other, a joint row splits into a joint motion J(q) = Rz(q) or Tz(q) and a constant D_i (the row at
q = 0): ``A_i = J(q) · D_i`` (standard) and ``A_i = D_i · J(q)`` (modified).  Collecting the constants between
joint motions, base in front and tool behind, gives ``T_w_e = C0 · J1(q1) · C1 ⋯ Jn(qn) · Cn``.

The same rule fixes the frame that carries joint k's axis (its z axis is the axis, its origin a point on it):
standard DH frame {r-1} (before the motion), modified DH frame {r} (after it), r the joint's row (1-based).
:attr:`Chain.axis_frame` holds that frame's index in the list of DH frames {0} … {N}.
"""

from __future__ import annotations

import math
import weakref
from dataclasses import dataclass

import numpy as np

from ..model import Convention, DHLink, DHRobot, JointType

__all__ = ["Row", "Chain", "chain_of", "joint_motion", "dh_transform", "cos_sin"]


def joint_motion(row: "Row", q, theta, d):
    """(θ, d) of a row with its joint value added: q + θ for a revolute row, q + d for a prismatic one.

    ``q`` holds one value per joint (floats, arrays or sympy expressions); ``theta``/``d`` are the row's
    constant parts in the same algebra.  The one place that says where a joint variable enters a row.
    """
    if row.joint < 0:
        return theta, d
    if row.prismatic:
        return theta, q[row.joint] + d
    return q[row.joint] + theta, d


@dataclass(frozen=True, slots=True)
class Row:
    """One DH row's numbers: its joint (index, or -1 for a fixed row) and the constant parts [m, rad]."""

    joint: int
    prismatic: bool
    theta: float
    d: float
    a: float
    alpha: float
    ca: float  # cos α (1 when α = 0)
    sa: float  # sin α (0 when α = 0)
    rot_x: bool  # α ≠ 0: the row turns about x


def cos_sin(angle: float) -> tuple[float, float]:
    """(cos, sin) of an angle, exact (0, ±1) at the multiples of π/2 that floats can write (α = ±π/2 rows).

    ``math.cos(math.pi / 2)`` is 6.1e-17, not 0: with exact values a ±π/2 twist folds away in the
    generated kernels (:mod:`denavit.codegen`) and leaves no 1e-17 residue in the numeric walkers.
    """
    k = round(angle / (math.pi / 2))
    if k != 0 and angle == k * (math.pi / 2):
        return ((1.0, 0.0), (0.0, 1.0), (-1.0, 0.0), (0.0, -1.0))[k % 4]
    return math.cos(angle), math.sin(angle)


def dh_transform(convention: Convention, theta, d, a, alpha) -> np.ndarray:
    """One DH link transform A_i, shape (..., 4, 4) broadcast over the inputs.

    Notes
    -----
    standard: :math:`A_i = R_z(\\theta_i) T_z(d_i) T_x(a_i) R_x(\\alpha_i)` (Spong 2nd ed. eq. 3.10);
    modified: :math:`A_i = R_x(\\alpha_{i-1}) T_x(a_{i-1}) R_z(\\theta_i) T_z(d_i)` (Craig 3rd ed. eq. 3.6).
    """
    theta, d, a, alpha = np.broadcast_arrays(*(np.asarray(x, dtype=float) for x in (theta, d, a, alpha)))
    ct, st, ca, sa = np.cos(theta), np.sin(theta), np.cos(alpha), np.sin(alpha)
    A = np.zeros(theta.shape + (4, 4))
    A[..., 3, 3] = 1.0
    if Convention(convention) is Convention.STANDARD:
        A[..., 0, :] = np.stack([ct, -st * ca, st * sa, a * ct], axis=-1)
        A[..., 1, :] = np.stack([st, ct * ca, -ct * sa, a * st], axis=-1)
        A[..., 2, 1], A[..., 2, 2], A[..., 2, 3] = sa, ca, d
    else:
        A[..., 0, :] = np.stack([ct, -st, np.zeros_like(ct), a], axis=-1)
        A[..., 1, :] = np.stack([st * ca, ct * ca, -sa, -sa * d], axis=-1)
        A[..., 2, :] = np.stack([st * sa, ct * sa, ca, ca * d], axis=-1)
    return A


def _elementary(kind: str, v: float) -> np.ndarray:
    M = np.eye(4)
    if kind == "rz" or kind == "rx":
        c, s = math.cos(v), math.sin(v)
        i, j = (0, 1) if kind == "rz" else (1, 2)
        M[i, i], M[i, j], M[j, i], M[j, j] = c, -s, s, c
    else:
        M[0 if kind == "tx" else 2, 3] = v
    return M


class Chain:
    """The constants of one robot's kinematic chain (built once per robot by :func:`chain_of`).

    Attributes
    ----------
    convention : Convention
    standard : bool
    rows : tuple of Row
        Every DH row, base to tip, fixed rows included.
    dof, n_rows : int
    joint_rows : tuple of int
        Row index (0-based) of each joint.
    revolute, prismatic : tuple of bool
        Per joint.
    axis_frame : tuple of int
        Per joint, the index in {0} … {N} of the DH frame whose z axis is the joint axis.
    base, tool : ndarray (4, 4), read-only
    base_identity, tool_identity : bool
    links, parameters
        The robot's rows and named parameters (for the symbolic constants).
    memo : dict
        Other constants derived from the same robot by other modules, by name (e.g. the dynamics kernels'
        plan): they live as long as the robot, found without hashing it.
    """

    __slots__ = ("convention", "standard", "rows", "dof", "n_rows", "joint_rows", "revolute", "prismatic",
                 "axis_frame", "base", "tool", "base_identity", "tool_identity", "base_columns", "links",
                 "parameters", "memo", "_constants", "_sym")

    def __init__(self, robot: DHRobot) -> None:
        self.convention = robot.convention
        self.standard = robot.convention is Convention.STANDARD
        rows, k = [], 0
        for link in robot.links:
            joint = k if link.is_joint else -1
            k += link.is_joint
            ca, sa = cos_sin(float(link.alpha))
            rows.append(Row(joint, link.joint is JointType.PRISMATIC, float(link.theta), float(link.d),
                            float(link.a), float(link.alpha), ca, sa, link.alpha != 0.0))
        self.rows = tuple(rows)
        self.dof, self.n_rows = k, len(rows)
        self.joint_rows = tuple(robot.joint_rows)
        self.revolute = tuple(t is JointType.REVOLUTE for t in robot.joint_types)
        self.prismatic = tuple(not r for r in self.revolute)
        self.axis_frame = tuple(r if self.standard else r + 1 for r in self.joint_rows)
        self.base, self.tool = robot.base_matrix, robot.tool_matrix
        self.base.flags.writeable = self.tool.flags.writeable = False
        self.base_identity = bool(np.array_equal(self.base, np.eye(4)))
        self.tool_identity = bool(np.array_equal(self.tool, np.eye(4)))
        B = robot.base
        self.base_columns = tuple(tuple(float(B[i][j]) for i in range(3)) for j in range(4))  # x, y, z, p
        self.links: tuple[DHLink, ...] = robot.links
        self.parameters = robot.parameters
        self.memo: dict = {}
        self._constants = None
        self._sym: dict = {}

    # --- C0 · J1 · C1 ⋯ Jn · Cn ---------------------------------------------------------------------------
    def row_constant(self, i: int) -> np.ndarray:
        """D_i: row i's transform at joint value 0, shape (4, 4)."""
        row = self.rows[i]
        return dh_transform(self.convention, row.theta, row.d, row.a, row.alpha)

    @property
    def constants(self) -> tuple[np.ndarray, ...]:
        """C_0 … C_n (n = dof), each (4, 4) read-only, base in C_0 and tool in C_n."""
        if self._constants is None:
            out, C = [], self.base.copy()
            for i, row in enumerate(self.rows):
                D = self.row_constant(i)
                if row.joint < 0:
                    C = C @ D
                elif self.standard:  # A = J(q) · D
                    out.append(C)
                    C = D
                else:  # A = D · J(q)
                    out.append(C @ D)
                    C = np.eye(4)
            out.append(C @ self.tool)
            for M in out:
                M.flags.writeable = False
            self._constants = tuple(out)
        return self._constants

    def joint_matrix(self, k: int, q: float) -> np.ndarray:
        """J_k(q): Rz(q) for a revolute joint, Tz(q) for a prismatic one, shape (4, 4)."""
        return _elementary("tz" if self.prismatic[k] else "rz", q)

    # --- symbolic constants (sympy imported only here, on use) -------------------------------------------
    def rows_sym(self, numeric: bool = False) -> tuple[dict, ...]:
        """Each row's constant parts {a, alpha, d, theta} as sympy: parameter symbols where the file named
        them, exact numbers where the value is simple (``numeric`` puts the parameters' values in)."""
        key = ("rows", numeric)
        if key not in self._sym:
            from ._symbolic import row_constants_sym

            self._sym[key] = row_constants_sym(self, numeric)
        return self._sym[key]

    def constants_sym(self, numeric: bool = False) -> tuple:
        """C_0 … C_n as sympy ImmutableMatrix (exact entries, parameter symbols kept unless ``numeric``)."""
        key = ("C", numeric)
        if key not in self._sym:
            from ._symbolic import constants_sym

            self._sym[key] = constants_sym(self, numeric)
        return self._sym[key]


_CACHE: dict[int, tuple[weakref.ref, Chain]] = {}


def chain_of(robot: DHRobot) -> Chain:
    """The chain of ``robot``, built once per robot object.

    Looked up by object identity (hashing a robot costs microseconds: it hashes every row), and dropped
    when the robot is; an equal robot built anew gets its own, equal chain.
    """
    key = id(robot)
    hit = _CACHE.get(key)
    if hit is not None and hit[0]() is robot:
        return hit[1]
    chain = Chain(robot)

    def drop(ref: weakref.ref, key: int = key) -> None:
        entry = _CACHE.get(key)
        if entry is not None and entry[0] is ref:
            del _CACHE[key]

    try:
        _CACHE[key] = (weakref.ref(robot, drop), chain)
    except TypeError:  # an object that cannot be weakly referenced: not cached
        pass
    return chain
