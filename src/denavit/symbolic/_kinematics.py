"""Symbolic forward kinematics: link transforms A_i and T_0_n as sympy ImmutableMatrix."""

from __future__ import annotations

from functools import lru_cache

import sympy as sp

from ..chain import Symbolic, chain_of, dh_matrix_sym, walk
from ..model import DHRobot
from ._simplify import simplify_matrix
from ._symbols import joint_symbols, matrix_from_floats

__all__ = ["dh_matrix_sym", "link_matrices_sym", "link_transforms_sym", "forward_kinematics_sym"]


@lru_cache(maxsize=32)
def link_matrices_sym(robot: DHRobot, numeric: bool = False) -> tuple[sp.ImmutableMatrix, ...]:
    """A_1 … A_N, one per DH row, in the robot's parameters (or their values with ``numeric``)."""
    chain = chain_of(robot)
    rows = Symbolic(chain, numeric)
    q = joint_symbols(robot.dof).q
    return tuple(rows.matrix(chain, i, q) for i in range(chain.n_rows))


@lru_cache(maxsize=32)
def link_transforms_sym(robot: DHRobot, simplify: str = "trig", numeric: bool = False) -> tuple[sp.ImmutableMatrix, ...]:
    """T_0_0 = I, T_0_1, …, T_0_N (DH frames relative to the base frame {0}; base not applied)."""
    chain = chain_of(robot)
    algebra = Symbolic(chain, numeric, lambda T: simplify_matrix(T, simplify))
    return tuple(walk(chain, joint_symbols(robot.dof).q, algebra, frames=True, base=False))


@lru_cache(maxsize=32)
def forward_kinematics_sym(robot: DHRobot, simplify: str = "trig", numeric: bool = False) -> sp.ImmutableMatrix:
    """End-effector pose base · A_1 ⋯ A_N · tool, simplified by the named policy."""
    T = link_transforms_sym(robot, simplify, numeric)[-1]
    chain = chain_of(robot)
    if not chain.base_identity or not chain.tool_identity:
        T = simplify_matrix(matrix_from_floats(chain.base) * T * matrix_from_floats(chain.tool), simplify)
    return T
