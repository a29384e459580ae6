"""Symbolic Jacobians (sympy ImmutableMatrix 6×n, rows (v, ω), reference point: end-effector origin).

Three routes, as in the numeric engine:

* ``"geometric"`` — columns [z_i × (p_e − o_i); z_i] (revolute) or [z_i; 0] (prismatic) from the
  symbolic frames T_0_i (Siciliano et al. 2009, eq. 3.30);
* ``"differentiation"`` — linear rows ∂p/∂q of the symbolic forward kinematics, angular rows the vector
  of (∂R/∂q_i) Rᵀ (Spong et al. 2006, eq. 4.30);
* ``"propagation"`` — read off Craig's outward velocity propagation, natively in tool axes (Craig eq. 5.64).

``frame="base"`` gives J0 (world axes, ``base`` applied), ``frame="tool"`` gives Je = diag(Rᵀ, Rᵀ) J0.
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np
import sympy as sp

from ..chain import chain_of
from ..model import DHRobot, Frame, JointType
from ._angle_sums import collapse_angle_sums
from ._kinematics import forward_kinematics_sym, link_transforms_sym
from ._propagation import velocity_propagation_sym
from ._simplify import simplify_expr, simplify_matrix
from ._symbols import joint_symbols, matrix_from_floats

__all__ = ["jacobian_sym", "geometric_jacobian_sym", "differentiation_jacobian_sym", "propagation_jacobian_sym",
           "jacobian_tool_from_base_sym", "jacobian_base_from_tool_sym", "end_effector_pose_sym", "METHODS",
           "describe_jacobian", "reduce_trig", "simplify_kinematic", "analytic_jacobian_sym",
           "angle_rate_matrix_sym", "angle_symbols"]

METHODS = ("geometric", "differentiation", "propagation")


def reduce_trig(e: sp.Expr, q: tuple[sp.Symbol, ...]) -> sp.Expr:
    """Canonical form of a polynomial in sin q_i, cos q_i modulo sin² + cos² = 1, recombined into angle sums.

    Sines and cosines of sums are expanded, each (sin q_i, cos q_i) pair becomes a polynomial variable pair
    (s_i, c_i), the polynomial is reduced by the Gröbner basis {s_i² + c_i² − 1} (lex, s before c, so the
    remainder is unique and zero exactly when the expression is identically zero), and the result is
    collapsed back with Fu's TR10i (c1 c2 − s1 s2 → cos(q1 + q2); its pairs found by lookup,
    :func:`collapse_angle_sums`, the same result). Much faster than a general
    ``simplify`` on products of kinematic matrices.
    """
    if e.is_number or not e.has(sp.sin, sp.cos):
        return sp.factor_terms(sp.expand(e))
    n = len(q)
    c, s = sp.symbols(f"_c1:{n + 1}"), sp.symbols(f"_s1:{n + 1}")
    x = sp.expand(sp.expand_trig(e))
    x = x.xreplace({**{sp.cos(qi): ci for qi, ci in zip(q, c)}, **{sp.sin(qi): si for qi, si in zip(q, s)}})
    free = x.free_symbols
    used = [k for k in range(n) if c[k] in free or s[k] in free]
    if not used or any(a.has(*q) for a in x.atoms(sp.sin, sp.cos)):  # nothing to reduce, or sin(2 q1)-like atoms
        return simplify_expr(e, "trig")
    if x.has(sp.Float):  # float coefficients: sympy's division, whose rounding the outputs were made with
        basis = [s[k] ** 2 + c[k] ** 2 - 1 for k in used]
        _, r = sp.reduced(x, basis, *[s[k] for k in used], *[c[k] for k in used], order="lex")
    else:
        r = _remainder(x, [s[k] for k in used], [c[k] for k in used])
    r = r.xreplace({**{ci: sp.cos(qi) for qi, ci in zip(q, c)}, **{si: sp.sin(qi) for qi, si in zip(q, s)}})
    return sp.factor_terms(collapse_angle_sums(sp.expand(r)))


def _remainder(x: sp.Expr, s: list[sp.Symbol], c: list[sp.Symbol]) -> sp.Expr:
    """x modulo {s_i² + c_i² − 1}, lex with s before c: s_i^(2m+r) → s_i^r (1 − c_i²)^m in every term.

    The leading terms s_i² are pairwise coprime, so the basis is a Gröbner basis (Cox, Little and O'Shea,
    *Ideals, Varieties, and Algorithms*, ch. 2 §9, Prop. 4) and this remainder is the unique one that
    ``sympy.reduced`` computes by division, at the cost of one pass over the terms."""
    k = len(s)
    P = sp.Poly(x, *s, *c)
    dom = P.domain
    out: dict = {}
    for monom, coeff in P.as_dict(native=True).items():
        items = [(tuple(e % 2 for e in monom[:k]) + monom[k:], coeff)]
        for i in range(k):
            m = monom[i] // 2
            if m:
                binom = [dom.convert((-1) ** j * sp.binomial(m, j)) for j in range(m + 1)]  # (1 − c_i²)^m
                items = [(mo[:k + i] + (mo[k + i] + 2 * j,) + mo[k + i + 1:], co * b)
                         for mo, co in items for j, b in enumerate(binom)]
        for mo, co in items:
            out[mo] = out.get(mo, dom.zero) + co
    return sp.Poly.from_dict({m: v for m, v in out.items() if v}, *s, *c, domain=dom).as_expr()


def simplify_kinematic(M: sp.MatrixBase, policy: str, q: tuple[sp.Symbol, ...]) -> sp.ImmutableMatrix:
    """Entry-wise simplification: ``"trig"`` uses :func:`reduce_trig`; ``"none"``/``"full"`` as the policies."""
    if policy != "trig":
        return simplify_matrix(M, policy)
    return sp.ImmutableMatrix(M.shape[0], M.shape[1], [reduce_trig(e, q) for e in M])


def _vee(W: sp.MatrixBase) -> list[sp.Expr]:
    return [(W[2, 1] - W[1, 2]) / 2, (W[0, 2] - W[2, 0]) / 2, (W[1, 0] - W[0, 1]) / 2]


def _rotate(J: sp.MatrixBase, R: sp.MatrixBase) -> sp.Matrix:
    return sp.Matrix.vstack(R * J[:3, :], R * J[3:, :])


@lru_cache(maxsize=32)
def end_effector_pose_sym(robot: DHRobot, simplify: str = "trig", numeric: bool = False) -> sp.ImmutableMatrix:
    """T_w_e = base · T_0_N · tool (the same as :func:`forward_kinematics_sym`)."""
    return forward_kinematics_sym(robot, simplify, numeric)


def jacobian_tool_from_base_sym(J0: sp.MatrixBase, R_w_e: sp.MatrixBase, simplify: str = "trig") -> sp.ImmutableMatrix:
    """Je = diag(Rᵀ, Rᵀ) J0 (same reference point)."""
    return simplify_kinematic(_rotate(J0, R_w_e[:3, :3].T), simplify, _qs(J0, R_w_e))


def jacobian_base_from_tool_sym(Je: sp.MatrixBase, R_w_e: sp.MatrixBase, simplify: str = "trig") -> sp.ImmutableMatrix:
    """J0 = diag(R, R) Je (same reference point)."""
    return simplify_kinematic(_rotate(Je, R_w_e[:3, :3]), simplify, _qs(Je, R_w_e))


def _qs(*Ms: sp.MatrixBase) -> tuple[sp.Symbol, ...]:
    names = {s.name for M in Ms for s in M.free_symbols}
    n = max((int(x[1:]) for x in names if x[:1] == "q" and x[1:].isdigit()), default=0)
    return joint_symbols(n).q if n else ()


def _base_rotation(robot: DHRobot) -> sp.ImmutableMatrix | None:
    base = robot.base_matrix
    return None if np.allclose(base[:3, :3], np.eye(3), atol=0) else matrix_from_floats(base)[:3, :3]


@lru_cache(maxsize=32)
def geometric_jacobian_sym(robot: DHRobot, frame: Frame | str = Frame.BASE, simplify: str = "trig",
                           numeric: bool = False) -> sp.ImmutableMatrix:
    """Geometric Jacobian from the symbolic frames (see module notes)."""
    frame = Frame(frame)
    Ts = link_transforms_sym(robot, simplify, numeric)  # T_0_0 … T_0_N without base
    T_e = Ts[-1] * matrix_from_floats(robot.tool_matrix)
    p_e = T_e[:3, 3]
    cols = []
    for f, jt in zip(chain_of(robot).axis_frame, robot.joint_types):
        T = Ts[f]
        z, o = T[:3, 2], T[:3, 3]
        if jt is JointType.REVOLUTE:
            cols.append(sp.Matrix.vstack(z.cross(p_e - o), z))
        else:
            cols.append(sp.Matrix.vstack(z, sp.zeros(3, 1)))
    J = sp.Matrix.hstack(*cols)  # in {0} axes
    Rb = _base_rotation(robot)
    if frame is Frame.TOOL:
        J = _rotate(J, T_e[:3, :3].T)  # base rotation cancels: (R_b R_0e)ᵀ R_b = R_0eᵀ
    elif Rb is not None:
        J = _rotate(J, Rb)
    return simplify_kinematic(J, simplify, joint_symbols(robot.dof).q)


@lru_cache(maxsize=32)
def differentiation_jacobian_sym(robot: DHRobot, frame: Frame | str = Frame.BASE, simplify: str = "trig",
                                 numeric: bool = False) -> sp.ImmutableMatrix:
    """Jacobian by differentiating the symbolic forward kinematics (see module notes)."""
    T = end_effector_pose_sym(robot, simplify, numeric)
    q = joint_symbols(robot.dof).q
    R, p = T[:3, :3], T[:3, 3]
    tool = Frame(frame) is Frame.TOOL
    cols = []
    for qk in q:
        dR = R.diff(qk)
        # skew(ω) = Ṙ Rᵀ (base axes) or Rᵀ Ṙ (tool axes); only the three entries (2,1), (0,2), (1,0) are needed
        pairs = ((2, 1), (0, 2), (1, 0))
        if tool:
            w = [sum(R[m, i] * dR[m, j] for m in range(3)) for i, j in pairs]
            v = list(R.T * p.diff(qk))
        else:
            w = [sum(dR[i, m] * R[j, m] for m in range(3)) for i, j in pairs]
            v = list(p.diff(qk))
        cols.append(sp.Matrix(v + w))
    return simplify_kinematic(sp.Matrix.hstack(*cols), simplify, q)


@lru_cache(maxsize=32)
def propagation_jacobian_sym(robot: DHRobot, frame: Frame | str = Frame.TOOL, simplify: str = "trig",
                             numeric: bool = False) -> sp.ImmutableMatrix:
    """Jacobian read off the outward velocity propagation; native in tool axes (Je)."""
    Je = velocity_propagation_sym(robot, simplify, numeric).Je
    if Frame(frame) is Frame.TOOL:
        return Je
    T = end_effector_pose_sym(robot, simplify, numeric)
    return simplify_kinematic(_rotate(Je, T[:3, :3]), simplify, joint_symbols(robot.dof).q)


def jacobian_sym(robot: DHRobot, method: str = "geometric", frame: Frame | str = Frame.BASE,
                 simplify: str = "trig", numeric: bool = False) -> sp.ImmutableMatrix:
    """Symbolic Jacobian (6×n, rows (v, ω)) by a named route, in base (J0) or tool (Je) axes.

    Parameters
    ----------
    robot : DHRobot
    method : {"geometric", "differentiation", "propagation"}
    frame : Frame or {"base", "tool"}
    simplify : {"none", "trig", "full"}
        Simplification policy (see :mod:`denavit.symbolic._simplify`).
    numeric : bool
        Replace named parameters by their values.

    Examples
    --------
    >>> import denavit, denavit.symbolic as S
    >>> S.jacobian_sym(denavit.load_robot("report004-1-planar2r"))[:2, :]
    Matrix([
    [-(L1*sin(q1) + L2*sin(q1 + q2)), -L2*sin(q1 + q2)],
    [   L1*cos(q1) + L2*cos(q1 + q2),  L2*cos(q1 + q2)]])
    """
    routes = {"geometric": geometric_jacobian_sym, "differentiation": differentiation_jacobian_sym,
              "propagation": propagation_jacobian_sym}
    if method not in routes:
        raise ValueError(f"unknown Jacobian method {method!r}; choose one of {', '.join(METHODS)}")
    return routes[method](robot, Frame(frame), simplify, numeric)


def describe_jacobian(frame: Frame | str) -> str:
    """One line stating axes, reference point and row order."""
    if Frame(frame) is Frame.BASE:
        return "J0: rows (vx, vy, vz, wx, wy, wz) in base/world axes; v is the velocity of the end-effector origin"
    return "Je: rows (vx, vy, vz, wx, wy, wz) in end-effector (tool) axes; v is the velocity of the end-effector origin"


def angle_symbols(representation: str) -> tuple[sp.Symbol, sp.Symbol, sp.Symbol]:
    """The orientation angles as real symbols: (roll, pitch, yaw) or (phi, theta, psi)."""
    names = {"rpy": "roll pitch yaw", "zyz": "phi theta psi"}
    if representation not in names:
        raise ValueError(f"unknown representation {representation!r}; choose one of rpy, zyz")
    return tuple(sp.symbols(names[representation], real=True))  # type: ignore[return-value]


def angle_rate_matrix_sym(representation: str) -> sp.ImmutableMatrix:
    """E(φ) with ω = E(φ) φ̇ (world axes), Siciliano et al. (2009) eq. 3.64.

    rpy: R = Rz(yaw) Ry(pitch) Rx(roll); zyz: R = Rz(φ) Ry(θ) Rz(ψ).
    """
    a, b, c = angle_symbols(representation)
    if representation == "rpy":  # ω = ẏ z + ṗ Rz(y) y + ṙ Rz(y) Ry(p) x
        p, y = b, c
        return sp.ImmutableMatrix([[sp.cos(y) * sp.cos(p), -sp.sin(y), 0],
                                   [sp.sin(y) * sp.cos(p), sp.cos(y), 0],
                                   [-sp.sin(p), 0, 1]])
    ph, th = a, b
    return sp.ImmutableMatrix([[0, -sp.sin(ph), sp.cos(ph) * sp.sin(th)],
                               [0, sp.cos(ph), sp.sin(ph) * sp.sin(th)],
                               [1, 0, sp.cos(th)]])


def analytic_jacobian_sym(robot: DHRobot, representation: str = "rpy", simplify: str = "trig",
                          numeric: bool = False) -> sp.ImmutableMatrix:
    """Analytic Jacobian Ja = diag(I, E(φ)⁻¹) J0 mapping q̇ to (ṗ, φ̇), Siciliano et al. (2009) eq. 3.66.

    The result is written in the joint symbols q and the angle symbols of :func:`angle_symbols`
    (the current orientation angles of the end effector); it is undefined where det E = 0
    (cos pitch = 0 for rpy, sin θ = 0 for zyz).
    """
    J0 = jacobian_sym(robot, "geometric", Frame.BASE, simplify, numeric)
    E_inv = angle_rate_matrix_sym(representation).inv()
    E_inv = sp.ImmutableMatrix(3, 3, [sp.trigsimp(e) for e in E_inv])
    angular = E_inv * J0[3:, :]
    rows = [J0[i, j] for i in range(3) for j in range(J0.shape[1])]
    rows += [simplify_expr(e, simplify) for e in angular]
    return sp.ImmutableMatrix(6, J0.shape[1], rows)
