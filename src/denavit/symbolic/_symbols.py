"""Symbols of a robot: joint variables q1…qn (and rates), named parameters, DH rows as sympy."""

from __future__ import annotations

from functools import lru_cache

import sympy as sp

from ..chain import chain_of, joint_motion
from ..model import DHRobot

__all__ = ["JointSymbols", "joint_symbols", "parameter_symbols", "row_expressions", "matrix_from_floats", "exact_or_float"]


class JointSymbols:
    """q, qd, qdd as tuples of real symbols ``q1…qn``, ``qd1…``, ``qdd1…``."""

    def __init__(self, n: int) -> None:
        self.q = tuple(sp.symbols(f"q1:{n + 1}", real=True))
        self.qd = tuple(sp.symbols(f"qd1:{n + 1}", real=True))
        self.qdd = tuple(sp.symbols(f"qdd1:{n + 1}", real=True))

    def __iter__(self):
        return iter((self.q, self.qd, self.qdd))


@lru_cache(maxsize=64)
def joint_symbols(n: int) -> JointSymbols:
    return JointSymbols(n)


def parameter_symbols(robot: DHRobot) -> dict[str, sp.Symbol]:
    """One real symbol per named parameter of the robot."""
    return {name: sp.Symbol(name, real=True) for name, _ in robot.parameters}


_EXACT_TOL = 1e-12


def exact_or_float(x: float) -> sp.Expr:
    """x as a simple exact number when it is one (3/4, pi/6, √2/2, √3/2 …), else as a sympy Float.

    Only small denominators are tried, so a random float never turns into a huge rational.
    """
    x = float(x)
    for base in (sp.Integer(1), sp.pi, sp.sqrt(2), sp.sqrt(3)):
        b = float(base)
        for den in (1, 2, 3, 4, 5, 6, 8, 10, 12, 16, 20, 25, 100, 1000):
            num = round(x * den / b)
            if abs(num) <= 100_000 and abs(x - num * b / den) < _EXACT_TOL * max(1.0, abs(x)):
                return sp.Rational(num, den) * base
    return sp.Float(x)


def row_expressions(robot: DHRobot, numeric: bool = False) -> list[dict[str, sp.Expr]]:
    """Each row's (a, alpha, d, theta) as sympy, the joint variable included (qk added to θ or d).

    Parameters the robot file named stay symbols; with ``numeric=True`` they are replaced by their values
    (exact rationals).  The rows and the joint rule come from the chain (:mod:`denavit.chain`).
    """
    chain = chain_of(robot)
    q = joint_symbols(robot.dof).q
    rows = []
    for row, const in zip(chain.rows, chain.rows_sym(numeric)):
        r = dict(const)
        r["theta"], r["d"] = joint_motion(row, q, const["theta"], const["d"])
        rows.append(r)
    return rows


def matrix_from_floats(M) -> sp.ImmutableMatrix:
    """A 4×4 of floats as exact numbers where they are close to simple ones (0.5 → 1/2, 0.7071… → √2/2)."""
    return sp.ImmutableMatrix([[exact_or_float(x) for x in row] for row in M])
