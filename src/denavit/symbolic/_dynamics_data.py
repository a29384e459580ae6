"""The robot's inertial data, joint parameters and gravity as sympy (named parameters kept as symbols unless
``numeric``): what every symbolic dynamics route starts from. Bodies and pieces as in
:mod:`denavit.numeric._dynamics` (a fixed row's inertia is carried by the preceding moving link)."""

from __future__ import annotations

import sympy as sp

from .. import _expr
from ..chain import chain_of
from ..errors import ModelError
from ..model import DHRobot, inertial_rows
from ._dynamics_types import InertialPiece
from ._symbols import matrix_from_floats, parameter_symbols

__all__ = ["inertial_pieces", "joint_parameters", "gravity_base", "joint_axes_sym", "friction_vector"]


def _number(x: float) -> sp.Expr:
    return sp.Integer(0) if x == 0 else sp.nsimplify(sp.Rational(repr(float(x))), [sp.pi], rational=True)


def _values(robot: DHRobot, numeric: bool) -> tuple[dict[str, sp.Symbol], dict[sp.Symbol, sp.Expr]]:
    syms = parameter_symbols(robot)
    vals = {syms[k]: sp.Rational(repr(v)) for k, v in robot.parameters}
    return syms, (vals if numeric else {})


def _field(li, key: str, value: float, syms, subs) -> sp.Expr:
    text = dict(li.symbols).get(key)
    if text is None:
        return _number(value)
    e = _expr.to_sympy(_expr.parse(text), syms)
    e = e.xreplace({f: sp.Rational(repr(float(f))) for f in e.atoms(sp.Float)})  # exact decimals: terms cancel
    return e.subs(subs) if subs else e


def inertial_pieces(robot: DHRobot, numeric: bool = False) -> list[InertialPiece]:
    """The inertial data of every moving row, with named parameters kept as symbols (``numeric`` substitutes)."""
    syms, subs = _values(robot, numeric)
    out = []
    for r, body, li in inertial_rows(robot):
        m = _field(li, "mass", li.mass, syms, subs)
        com = sp.ImmutableMatrix([_field(li, f"com{i}", li.com[i], syms, subs) for i in range(3)])
        xx, yy, zz, xy, xz, yz = (_field(li, f"inertia{i}", li.inertia[i], syms, subs) for i in range(6))
        out.append(InertialPiece(r, body, m, com, sp.ImmutableMatrix([[xx, xy, xz], [xy, yy, yz], [xz, yz, zz]])))
    if not out:
        raise ModelError(f"robot {robot.name!r} has no inertial data: add 'inertia:' to its joint rows")
    return out


def joint_parameters(robot: DHRobot, numeric: bool = False) -> tuple[list[sp.Expr], list[sp.Expr], list[sp.Expr]]:
    """Motor inertia, viscous and Coulomb coefficients of every joint, as sympy."""
    syms, subs = _values(robot, numeric)
    out: tuple[list, list, list] = ([], [], [])
    for link in robot.joints:
        li = link.inertia
        for lst, key in zip(out, ("motor_inertia", "viscous", "coulomb")):
            lst.append(_field(li, key, getattr(li, key), syms, subs) if li is not None else sp.Integer(0))
    return out


def gravity_base(robot: DHRobot) -> sp.ImmutableMatrix:
    """Gravity in base-frame {0} axes: R_baseᵀ g_world, exact where the numbers are simple."""
    R = matrix_from_floats(robot.base_matrix)[:3, :3]
    g = sp.Matrix([_number(x) for x in robot.gravity])
    return sp.ImmutableMatrix(R.T * g)


def joint_axes_sym(robot: DHRobot, T: tuple[sp.ImmutableMatrix, ...]) -> list[tuple[sp.Matrix, sp.Matrix]]:
    """(z, o) of each joint in {0}: standard z_{i-1}, o_{i-1}; modified z_i, o_i (the chain's axis frames)."""
    return [(T[f][:3, 2], T[f][:3, 3]) for f in chain_of(robot).axis_frame]


def friction_vector(robot: DHRobot, qd, numeric: bool = False) -> sp.ImmutableMatrix:
    _, fv, fc = joint_parameters(robot, numeric)
    return sp.ImmutableMatrix([fv[k] * qd[k] + fc[k] * sp.sign(qd[k]) for k in range(robot.dof)])
