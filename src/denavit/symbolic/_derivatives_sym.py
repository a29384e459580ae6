"""Symbolic derivatives: J̇, the kinematic Hessian ∂J/∂q, the acceleration bias J̇q̇, ∂τ/∂q, ∂τ/∂q̇ and ∂g/∂q.

The formulas a student or a paper writes, as sympy, in the joint symbols ``q1…qn``, ``qd1…qdn``, ``qdd1…qddn``
(:func:`denavit.symbolic.joint_symbols`) and the robot's named parameters.  Nothing here is a second
kinematics or dynamics: every result is a derivative of what the library already derives.

* Kinematics: the symbolic geometric Jacobian J(q) (:func:`denavit.symbolic.geometric_jacobian_sym`, base or
  tool axes) differentiated entry by entry,

  .. math::
      H_{r j k} = \\frac{\\partial J_{r j}}{\\partial q_k}, \\qquad
      \\dot J = \\sum_k \\frac{\\partial J}{\\partial q_k}\\,\\dot q_k
      \\ \\ (\\text{the chain rule of } :func:`denavit.symbolic.time_derivative`),

  with H laid out as the numeric :func:`denavit.kinematic_hessian`: ∂J[:, j]/∂q_k at ``H[:, j, k]``.
  The acceleration bias is J̇0 q̇ in base axes and R_w_eᵀ J̇0 q̇ in tool axes (the classical acceleration of
  the end-effector origin at q̈ = 0, as :func:`denavit.acceleration_bias`; not J̇e q̇).
* Dynamics: τ(q, q̇, q̈) = M(q) q̈ + c(q, q̇) + g(q) + τ_f(q̇) from :func:`denavit.symbolic.lagrangian_dynamics`
  (motor inertia inside M), differentiated:

  .. math::
      \\frac{\\partial \\tau}{\\partial q} = \\frac{\\partial (M \\ddot q + c + g)}{\\partial q}, \\qquad
      \\frac{\\partial \\tau}{\\partial \\dot q} = \\frac{\\partial c}{\\partial \\dot q} + \\mathrm{diag}(f_v),
      \\qquad \\frac{\\partial g}{\\partial q} = \\frac{\\partial^2 V}{\\partial q^2}\\ \\text{(symmetric)}.

  The Coulomb term f_c sign(q̇) has derivative 0 away from q̇ = 0 and 0 is taken at q̇ = 0, as the numeric
  :func:`denavit.rnea_derivatives` does (Carpentier & Mansard, RSS 2018).

Size bounds.  J̇ and H are sums of derivatives of J's entries and stay printable for every arm
the symbolic Jacobian takes.  The dynamics derivatives multiply the size of c (already quadratic in q̇ and, in
hand form, thousands of operations for a 6-joint arm) by up to n: :data:`DERIVATIVES_MAX_DOF` joints
are accepted whole; beyond it :func:`rnea_derivatives_sym` raises :class:`~denavit.errors.UnsupportedRobotError`
naming the bound, and :func:`rnea_derivative_entry_sym` gives one entry ∂τ_i/∂x_k at a time.

References
----------
J. Haviland, P. Corke, "Manipulator Differential Kinematics, Part I", IEEE RAM 2023, eq. 25–27 (∂J/∂q, J̇).
M. W. Spong, S. Hutchinson, M. Vidyasagar, *Robot Modeling and Control*, 2006, sec. 7.3 (τ = M q̈ + C q̇ + g).
J. Carpentier, N. Mansard, "Analytical Derivatives of Rigid Body Dynamics Algorithms", RSS 2018.
"""

from __future__ import annotations

from collections import defaultdict
from functools import lru_cache

import sympy as sp
from sympy.utilities.iterables import sift

from ..errors import UnsupportedRobotError
from ..model import DHRobot, Frame
from ._dynamics import lagrangian_dynamics
from ._dynamics_data import joint_parameters
from ._jacobians import geometric_jacobian_sym
from ._simplify import POLICIES, simplify_expr
from ._symbols import joint_symbols

__all__ = ["kinematic_hessian_sym", "jacobian_dot_sym", "acceleration_bias_sym", "hessian_slice_sym",
           "rnea_derivatives_sym", "gravity_derivatives_sym", "rnea_derivative_entry_sym", "DERIVATIVES_MAX_DOF", "GRAVITY"]

#: Joints up to which :func:`rnea_derivatives_sym` and :func:`gravity_derivatives_sym` form the whole matrices
#: (Puma 560: ∂τ/∂q about 6 s and 30 k operations, measured 2026-12; a 7-joint arm is several times that).
DERIVATIVES_MAX_DOF = 6


def _collect(e: sp.Expr) -> sp.Expr:
    """A sum collected on its sine/cosine factors, each exact coefficient factored (L2 (qd1 + qd2)² cos(q1 + q2))."""
    groups: dict = defaultdict(list)
    for t in sp.Add.make_args(sp.expand(e)):
        trig, rest = sift(sp.Mul.make_args(t), lambda f: isinstance(f, (sp.cos, sp.sin)), binary=True)
        groups[sp.Mul(*trig)].append(sp.Mul(*rest))
    coefficients = [sp.Add(*v) for v in groups.values()]  # factoring float coefficients is slow and gains little
    return sp.Add(*[(sp.factor_terms(c) if c.has(sp.Float) else sp.factor(c)) * k
                    for c, k in zip(coefficients, groups)])


def _simplifier(policy: str):
    """Entries here are derivatives of expressions already simplified, so "trig" is a collection on their
    sine/cosine factors (:func:`_collect`), not a new simplification."""
    if policy not in POLICIES:
        raise ValueError(f"unknown simplification policy {policy!r}; choose one of {', '.join(POLICIES)}")
    if policy == "trig":
        return _collect
    return lambda e: simplify_expr(e, policy)


@lru_cache(maxsize=32)
def kinematic_hessian_sym(robot: DHRobot, frame: Frame | str = Frame.BASE, simplify: str = "trig",
                          numeric: bool = False) -> sp.ImmutableDenseNDimArray:
    """Kinematic Hessian H = ∂J/∂q as a sympy array of shape (6, n, n): ∂J[:, j]/∂q_k at ``H[:, j, k]``.

    Parameters
    ----------
    robot : DHRobot
    frame : {"base", "tool"}
        Of J0 (world/base axes) or Je (tool axes); reference point the end-effector origin, rows (v, ω).
    simplify : {"none", "trig", "full"}
    numeric : bool
        Named parameters replaced by their values.

    Notes
    -----
    H_rjk = ∂J_rj/∂q_k of :func:`denavit.symbolic.geometric_jacobian_sym` (the numeric
    :func:`denavit.kinematic_hessian` has the same layout).  For J0 the linear block H[:3] is symmetric in j, k
    (∂²p/∂q_j∂q_k); for Je, H[:, j, k] = 0 for k ≤ j.  :func:`hessian_slice_sym` gives the 6×n matrix ∂J/∂q_k.
    """
    frame = Frame(frame)
    J = geometric_jacobian_sym(robot, frame, simplify, numeric)
    q = joint_symbols(robot.dof).q
    simp = _simplifier(simplify)
    n = robot.dof
    cells = [simp(J[r, j].diff(q[k])) for r in range(6) for j in range(n) for k in range(n)]
    return sp.ImmutableDenseNDimArray(cells, (6, n, n))


def hessian_slice_sym(H: sp.NDimArray, k: int) -> sp.ImmutableMatrix:
    """The 6×n matrix ∂J/∂q_k (k from 0) out of a Hessian array of shape (6, n, n)."""
    rows, n, _ = H.shape
    return sp.ImmutableMatrix(rows, n, [H[r, j, k] for r in range(rows) for j in range(n)])


@lru_cache(maxsize=32)
def jacobian_dot_sym(robot: DHRobot, frame: Frame | str = Frame.BASE, simplify: str = "trig",
                     numeric: bool = False) -> sp.ImmutableMatrix:
    """J̇ = Σ_k (∂J/∂q_k) q̇_k, a 6×n sympy matrix in q1…qn, qd1…qdn (rows (v, ω)).

    Parameters as :func:`kinematic_hessian_sym`; ``frame="tool"`` gives d/dt Je (as :func:`denavit.jacobian_dot`).

    Examples
    --------
    >>> import denavit, denavit.symbolic as S
    >>> S.jacobian_dot_sym(denavit.load_robot("planar2r"))[:2, :]
    Matrix([
    [-L1*qd1*cos(q1) - L2*(qd1 + qd2)*cos(q1 + q2), -L2*(qd1 + qd2)*cos(q1 + q2)],
    [-L1*qd1*sin(q1) - L2*(qd1 + qd2)*sin(q1 + q2), -L2*(qd1 + qd2)*sin(q1 + q2)]])
    """
    H = kinematic_hessian_sym(robot, frame, simplify, numeric)
    qd = joint_symbols(robot.dof).qd
    simp = _simplifier(simplify)
    n = robot.dof
    return sp.ImmutableMatrix(6, n, [simp(sum((H[r, j, k] * qd[k] for k in range(n)), sp.Integer(0)))
                                     for r in range(6) for j in range(n)])


@lru_cache(maxsize=32)
def acceleration_bias_sym(robot: DHRobot, frame: Frame | str = Frame.BASE, simplify: str = "trig",
                          numeric: bool = False) -> sp.ImmutableMatrix:
    """The classical acceleration bias (p̈, ω̇) at q̈ = 0 of the end-effector origin, a 6×1 sympy matrix.

    ``frame="base"``: J̇0 q̇; ``"tool"``: R_w_eᵀ J̇0 q̇, the same acceleration in tool axes (as
    :func:`denavit.acceleration_bias`; *not* J̇e q̇, the derivative of the body-axes twist).  The tool form is
    written with the tool-axes Jacobian, so no rotation matrix multiplies the result: with (v_e, ω_e) = Je q̇ and
    v_e = R_w_eᵀ v, d/dt v_e = R_w_eᵀ v̇ − ω_e × v_e (and ω_e × ω_e = 0), hence

    .. math::
        R_{we}^T \\dot J_0 \\dot q = \\dot J_e \\dot q + (\\omega_e \\times v_e,\\ 0).
    """
    frame = Frame(frame)
    qd = sp.Matrix(joint_symbols(robot.dof).qd)
    a = jacobian_dot_sym(robot, frame, simplify, numeric) * qd
    if frame is Frame.TOOL:
        twist = geometric_jacobian_sym(robot, frame, simplify, numeric) * qd  # (v_e, ω_e) in tool axes
        a = a + sp.Matrix.vstack(twist[3:, :].cross(twist[:3, :]), sp.zeros(3, 1))
    simp = _simplifier(simplify)
    return sp.ImmutableMatrix([simp(e) for e in a])


def _require_size(robot: DHRobot, what: str) -> None:
    if robot.dof > DERIVATIVES_MAX_DOF:
        raise UnsupportedRobotError(
            f"{what}: {robot.name} has {robot.dof} joints; the whole symbolic matrices are formed up to "
            f"{DERIVATIVES_MAX_DOF} joints (DERIVATIVES_MAX_DOF); use rnea_derivative_entry_sym for one entry, "
            "or the numeric rnea_derivatives")


#: the symbol of |g₀| with ``gravity_symbol=True`` (the one :func:`denavit.symbolic.format_dynamics` prints)
GRAVITY = sp.Symbol("g", positive=True)


@lru_cache(maxsize=16)
def _torque_parts(robot: DHRobot, simplify: str, numeric: bool, gravity_symbol: bool = False):
    """(τ without friction = M q̈ + c + g, g, viscous coefficients) from the symbolic equations of motion; with
    ``gravity_symbol`` g = GRAVITY · g_unit (unless the robot names a parameter g)."""
    t = lagrangian_dynamics(robot, simplify, numeric, coriolis=False)
    g = t.g
    if gravity_symbol and t.g_unit is not None and "g" not in robot.parameter_values:
        g = sp.ImmutableMatrix([GRAVITY * e for e in t.g_unit])
    tau = t.M * sp.Matrix(t.qdd) + t.c + g
    _, viscous, _ = joint_parameters(robot, numeric)
    return sp.ImmutableMatrix(tau), g, tuple(viscous)


def rnea_derivative_entry_sym(robot: DHRobot, i: int, wrt: str, k: int, simplify: str = "trig",
                              numeric: bool = False, friction: bool = True, gravity_symbol: bool = False) -> sp.Expr:
    """One entry ∂τ_i/∂q_k (``wrt="q"``) or ∂τ_i/∂q̇_k (``wrt="qd"``), indices from 0; any number of joints.

    Costs the symbolic equations of motion of the arm (:func:`denavit.symbolic.lagrangian_dynamics`) once and one
    derivative; meant for arms beyond :data:`DERIVATIVES_MAX_DOF`, where the whole matrices are not formed.
    """
    n = robot.dof
    if wrt not in ("q", "qd"):
        raise ValueError(f"wrt must be 'q' or 'qd', got {wrt!r}")
    if not (0 <= i < n and 0 <= k < n):
        raise ValueError(f"entry ({i}, {k}) out of range for {robot.name}'s {n} joints (indices 0 ... {n - 1})")
    tau, _, viscous = _torque_parts(robot, simplify, numeric, gravity_symbol)
    js = joint_symbols(n)
    x = (js.q if wrt == "q" else js.qd)[k]
    e = tau[i].diff(x)
    if wrt == "qd" and friction and i == k:
        e = e + viscous[k]
    return _simplifier(simplify)(e)


@lru_cache(maxsize=16)
def rnea_derivatives_sym(robot: DHRobot, simplify: str = "trig", numeric: bool = False,
                         friction: bool = True, gravity_symbol: bool = False) -> tuple[sp.ImmutableMatrix, sp.ImmutableMatrix]:
    """``(dtau_dq, dtau_dqd)``: ∂τ/∂q and ∂τ/∂q̇ as n×n sympy matrices, [output, input] (rows τ_i, columns q_k).

    Parameters
    ----------
    robot : DHRobot
        With inertial data; named parameters stay symbols unless ``numeric``.
    simplify : {"none", "trig", "full"}
        As :func:`denavit.symbolic.lagrangian_dynamics`; "trig": each entry collected on its sines and cosines.
    friction : bool
        Add diag(viscous) to ∂τ/∂q̇ (the Coulomb term contributes 0, module notes).
    gravity_symbol : bool
        Write |g₀| as the symbol ``g`` (:data:`GRAVITY`; as ``format_dynamics(..., gravity_symbol=True)``), not
        as its value; substitute it before evaluating.

    Returns
    -------
    dtau_dq : ImmutableMatrix, n×n, in q, q̇, q̈
    dtau_dqd : ImmutableMatrix, n×n, in q, q̇ (∂τ/∂q̈ = M: ``lagrangian_dynamics(robot).M``)

    Raises
    ------
    UnsupportedRobotError
        More than :data:`DERIVATIVES_MAX_DOF` joints (use :func:`rnea_derivative_entry_sym`).

    Examples
    --------
    >>> import denavit, denavit.symbolic as S
    >>> dq, dqd = S.rnea_derivatives_sym(denavit.load_robot("planar2r"))
    >>> dqd[1, 0]
    2*L1*L2*m2*qd1*sin(q2)
    """
    _require_size(robot, "rnea_derivatives_sym")
    n = robot.dof
    tau, _, viscous = _torque_parts(robot, simplify, numeric, gravity_symbol)
    js = joint_symbols(n)
    simp = _simplifier(simplify)
    dq = sp.ImmutableMatrix(n, n, [simp(tau[i].diff(js.q[k])) for i in range(n) for k in range(n)])
    fv = [viscous[k] if friction else 0 for k in range(n)]
    dqd = sp.ImmutableMatrix(n, n, [simp(tau[i].diff(js.qd[k]) + (fv[k] if i == k else 0))
                                    for i in range(n) for k in range(n)])
    return dq, dqd


@lru_cache(maxsize=16)
def gravity_derivatives_sym(robot: DHRobot, simplify: str = "trig", numeric: bool = False,
                            gravity_symbol: bool = False) -> sp.ImmutableMatrix:
    """∂g/∂q, an n×n symmetric sympy matrix in q (the Hessian of the potential energy), [output, input].

    g(q) from :func:`denavit.symbolic.lagrangian_dynamics` (``robot.gravity``), differentiated entry by entry;
    ``gravity_symbol`` as :func:`rnea_derivatives_sym`.
    Raises :class:`~denavit.errors.UnsupportedRobotError` beyond :data:`DERIVATIVES_MAX_DOF` joints.
    """
    _require_size(robot, "gravity_derivatives_sym")
    n = robot.dof
    _, g, _ = _torque_parts(robot, simplify, numeric, gravity_symbol)
    q = joint_symbols(n).q
    simp = _simplifier(simplify)
    return sp.ImmutableMatrix(n, n, [simp(g[i].diff(q[k])) for i in range(n) for k in range(n)])
