"""Pieces shared by the symbolic IK derivations (:mod:`._ik`, :mod:`._ik_decoupled`): the target symbols,
transform helpers, the robot's parameter values, a numeric identity test, the first steps and the law of cosines."""

from __future__ import annotations

import numpy as np
import sympy as sp

from ..codegen import numeric_function
from ..chain import chain_of
from ..errors import UnsupportedRobotError
from ..model import Convention, DHRobot
from ._ik_types import IKStep
from ._simplify import simplify_expr, simplify_matrix
from ._symbols import matrix_from_floats, parameter_symbols, row_expressions

__all__ = ["target_symbols", "matrix_product", "inverse_transform", "simplify_trig", "at_zero", "parameter_values",
           "numeric_zero", "axis_frame_of", "check_prefix", "target_steps", "cosine_law_steps"]


def target_symbols() -> sp.ImmutableMatrix:
    r = sp.symbols("r11 r12 r13 r21 r22 r23 r31 r32 r33", real=True)
    p = sp.symbols("p_x p_y p_z", real=True)
    return sp.ImmutableMatrix([[r[0], r[1], r[2], p[0]], [r[3], r[4], r[5], p[1]], [r[6], r[7], r[8], p[2]],
                               [0, 0, 0, 1]])


def matrix_product(ms) -> sp.Matrix:
    out = sp.eye(4)
    for m in ms:
        out = out * m
    return out


def inverse_transform(T: sp.MatrixBase) -> sp.Matrix:
    R, p = T[:3, :3], T[:3, 3]
    out = sp.eye(4)
    out[:3, :3] = R.T
    out[:3, 3] = -R.T * p
    return out


def simplify_trig(M):
    if isinstance(M, sp.MatrixBase):
        return simplify_matrix(M, "trig")
    return simplify_expr(M, "trig")


def at_zero(M, qs):
    return M.subs({s: 0 for s in qs})


def parameter_values(robot: DHRobot) -> dict:
    syms = parameter_symbols(robot)
    return {syms[k]: v for k, v in robot.parameter_values.items()}


def numeric_zero(expr, robot: DHRobot, qs, rng: np.random.Generator, tol: float = 1e-9) -> bool:
    """Is ``expr`` zero for the robot's parameter values at random joint values (a cheap identity test)?"""
    f = numeric_function(sp.sympify(expr).subs(parameter_values(robot)), list(qs))  # safe: expr is built by this module, never user text
    for _ in range(4):
        if np.max(np.abs(np.asarray(f(*rng.uniform(-3, 3, len(qs))), dtype=complex))) > tol:
            return False
    return True


def axis_frame_of(robot: DHRobot, T, k: int):
    """The frame whose z axis is joint k (1-based), by the chain's rule (:attr:`denavit.chain.Chain.axis_frame`)."""
    return T[chain_of(robot).axis_frame[k - 1]]


def check_prefix(robot: DHRobot) -> None:
    first = robot.links[0]
    if not first.is_joint:
        raise UnsupportedRobotError(f"{robot.name}: the derivation needs joint 1 in the first DH row")
    if robot.convention is Convention.MODIFIED:
        rows = row_expressions(robot)
        if rows[0]["a"] != 0 or rows[0]["alpha"] != 0:
            raise UnsupportedRobotError(f"{robot.name}: the derivation needs joint 1 about z0 through the origin "
                                        "of {0} (a0 = alpha0 = 0 in the first modified-DH row)")


def target_steps(robot: DHRobot, target, n_rows: int) -> list[IKStep]:
    steps = []
    B, E = robot.base_matrix, robot.tool_matrix
    name = sp.Symbol(f"T_0_{n_rows}")
    if not (np.allclose(B, np.eye(4), atol=0) and np.allclose(E, np.eye(4), atol=0)):
        Tw = sp.MatrixSymbol("T_we", 4, 4)
        rhs = sp.MatMul(matrix_from_floats(np.linalg.inv(B)), Tw, matrix_from_floats(np.linalg.inv(E)), evaluate=False)
        steps.append(IKStep("Base and tool removed", name, rhs,
                            "The DH chain sees the target with the base transform B and the tool E taken off: "
                            f"T_0_{n_rows} = B⁻¹ T_w_e E⁻¹."))
    steps.append(IKStep("Target", name, target,
                        f"Entries of the pose of DH frame {{{n_rows}}} to be reached (r_ij: rotation R, p: position)."))
    return steps


def cosine_law_steps(lhs_sq, expr_q, q, robot, rng, title, text):
    """Steps solving ``lhs_sq = K0 + K1 cos q + K2 sin q`` for q (two roots, sign σ)."""
    K0 = sp.expand((expr_q.subs(q, 0) + expr_q.subs(q, sp.pi)) / 2)
    K1 = sp.expand((expr_q.subs(q, 0) - expr_q.subs(q, sp.pi)) / 2)
    K2 = sp.expand(expr_q.subs(q, sp.pi / 2) - K0)
    if not numeric_zero(expr_q - (K0 + K1 * sp.cos(q) + K2 * sp.sin(q)), robot, [q], rng):
        raise UnsupportedRobotError(f"{robot.name}: the reach does not depend on {q} as A + B cos + C sin")
    if K1 == 0 and K2 == 0:
        raise UnsupportedRobotError(f"{robot.name}: the reach does not depend on {q}")
    f = sp.gcd(K1, K2) if (K1 != 0 and K2 != 0) else (K1 if K2 == 0 else K2)
    f = sp.factor_terms(f)
    if float(f.subs(parameter_values(robot))) < 0:
        f = -f  # divide by a positive number only: atan2 must keep its quadrants
    k1, k2 = sp.simplify(K1 / f), sp.simplify(K2 / f)
    Ksym, sig = sp.Symbol("K", real=True), sp.Symbol(f"sigma{str(q)[1:]}", real=True)
    c = sp.cos(q)
    s = sp.sin(q)
    return [
        IKStep(title, lhs_sq, K0 + K1 * c + K2 * s, text),
        IKStep("The constant K of the law of cosines", Ksym, sp.factor_terms((lhs_sq - K0) / f),
               f"Dividing by {sp.sstr(f)}: {sp.sstr(k1 * c + k2 * s)} = K.", assign=True),
        IKStep(f"{q} (two roots)", q,
               sp.atan2(k2, k1) + sig * sp.atan2(sp.sqrt(k1**2 + k2**2 - Ksym**2), Ksym),
               f"a cos {q} + b sin {q} = K ⇔ cos({q} − atan2(b, a)) = K/√(a² + b²); "
               f"{sig} = ±1 gives the two roots (no real root when K² > a² + b²: out of reach).",
               assign=True),
    ], sig
