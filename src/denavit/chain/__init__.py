"""The arm as one chain ``C0 · J1(q1) · C1 ⋯ Jn(qn) · Cn`` and its walkers.

The only code that knows DH conventions, where a joint variable enters its row, fixed rows, base and tool,
and which frame carries each joint's axis.  The numeric and symbolic engines ask it.  Two forms of the same
product: :func:`walk` goes row by row (each DH row as its elementary motions: floats, numpy batches, traced
values or sympy), :func:`screw_walk` goes over the stacked constants C_k (numpy batches; the IK also walks
chains derived from the arm's, reversed or with joints merged).

>>> import denavit
>>> from denavit.chain import chain_of, walk, FLOATS
>>> chain = chain_of(denavit.load_robot("planar2r"))
>>> chain.axis_frame, chain.revolute
((0, 1), (True, True))
>>> x, y, z, p = walk(chain, [0.0, 0.0], FLOATS)
"""

from ._chain import Chain, Row, chain_of, cos_sin, dh_transform, joint_motion
from ._screws import (STRUCTURAL_ZERO, Screws, reach_ball, reverse_screws, screw_axes, screw_pose, screw_walk, screw_walk_floats,
                      screws_of)
from ._walk import COMPONENTS, FLOATS, IDENTITY_COLUMNS, Batch, Components, Floats, Symbolic, pack, walk



def __getattr__(name: str):
    if name == "dh_matrix_sym":  # sympy is imported on first use, not with the package
        from ._symbolic import dh_matrix_sym

        return dh_matrix_sym
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


__all__ = [
    "Chain",
    "Row",
    "chain_of",
    "joint_motion",
    "dh_transform",
    "cos_sin",
    "dh_matrix_sym",
    "walk",
    "Floats",
    "Components",
    "COMPONENTS",
    "Batch",
    "Symbolic",
    "FLOATS",
    "IDENTITY_COLUMNS",
    "pack",
    "Screws",
    "screws_of",
    "reverse_screws",
    "screw_walk",
    "screw_walk_floats",
    "screw_pose",
    "screw_axes",
    "reach_ball",
    "STRUCTURAL_ZERO",
]
