"""Symbolic forward kinematics: link transforms A_i and T_0_n as sympy ImmutableMatrix."""

from __future__ import annotations

from functools import lru_cache

import sympy as sp

from ..model import Convention, DHRobot
from ._simplify import simplify_matrix
from ._symbols import matrix_from_floats, row_expressions

__all__ = ["dh_matrix_sym", "link_matrices_sym", "link_transforms_sym", "forward_kinematics_sym"]


def dh_matrix_sym(convention: Convention, a, alpha, d, theta) -> sp.ImmutableMatrix:
    """The DH link transform of one row, symbolic.

    standard (Spong eq. 3.10): Rz(θ) Tz(d) Tx(a) Rx(α); modified (Craig eq. 3.6): Rx(α) Tx(a) Rz(θ) Tz(d).
    """
    ct, st, ca, sa = sp.cos(theta), sp.sin(theta), sp.cos(alpha), sp.sin(alpha)
    if Convention(convention) is Convention.STANDARD:
        rows = [[ct, -st * ca, st * sa, a * ct], [st, ct * ca, -ct * sa, a * st], [0, sa, ca, d], [0, 0, 0, 1]]
    else:
        rows = [[ct, -st, 0, a], [st * ca, ct * ca, -sa, -sa * d], [st * sa, ct * sa, ca, ca * d], [0, 0, 0, 1]]
    return sp.ImmutableMatrix(rows)


@lru_cache(maxsize=32)
def link_matrices_sym(robot: DHRobot, numeric: bool = False) -> tuple[sp.ImmutableMatrix, ...]:
    """A_1 … A_N, one per DH row, in the robot's parameters (or their values with ``numeric``)."""
    return tuple(
        dh_matrix_sym(robot.convention, r["a"], r["alpha"], r["d"], r["theta"])
        for r in row_expressions(robot, numeric=numeric)
    )


@lru_cache(maxsize=32)
def link_transforms_sym(robot: DHRobot, simplify: str = "trig", numeric: bool = False) -> tuple[sp.ImmutableMatrix, ...]:
    """T_0_0 = I, T_0_1, …, T_0_N (DH frames relative to the base frame {0}; base not applied)."""
    T = sp.ImmutableMatrix(sp.eye(4))
    out = [T]
    for A in link_matrices_sym(robot, numeric):
        T = simplify_matrix(T * A, simplify)
        out.append(T)
    return tuple(out)


@lru_cache(maxsize=32)
def forward_kinematics_sym(robot: DHRobot, simplify: str = "trig", numeric: bool = False) -> sp.ImmutableMatrix:
    """End-effector pose base · A_1 ⋯ A_N · tool, simplified by the named policy."""
    T = link_transforms_sym(robot, simplify, numeric)[-1]
    base, tool = robot.base_matrix, robot.tool_matrix
    import numpy as np

    if not np.allclose(base, np.eye(4), atol=0) or not np.allclose(tool, np.eye(4), atol=0):
        T = simplify_matrix(matrix_from_floats(base) * T * matrix_from_floats(tool), simplify)
    return T
