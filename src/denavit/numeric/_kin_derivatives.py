"""Kinematic derivatives of the geometric Jacobian: J̇, the acceleration bias J̇q̇ and the kinematic Hessian ∂J/∂q.

All three are closed forms in the columns of the geometric Jacobian itself, with no second column definition:
column j of J0 (reference point: the end-effector origin, rows (v, ω)) is (v_j, w_j) with w_j = z_j for a
revolute joint and 0 for a prismatic one.  A motion of joint k turns (revolute) or slides (prismatic) everything
after it, so (Haviland & Corke 2023, "Manipulator Differential Kinematics, Part I", eq. 25–27; Lynch & Park 2017,
§5.1 for the Lie-bracket form):

.. math::

    \\frac{\\partial v_j}{\\partial q_k} = w_{\\min(j,k)} \\times v_{\\max(j,k)}, \\qquad
    \\frac{\\partial w_j}{\\partial q_k} = w_k \\times w_j \\ (k < j), \\ 0 \\ (k \\ge j)

(the linear block is symmetric in j, k: it is ∂²p/∂q_j∂q_k).  In the end-effector axes (Je = diag(Rᵀ, Rᵀ) J0,
∂R/∂q_k = [w_k]× R) the terms of the joints before j cancel, and with the same formulas applied to the columns
of Je (a rotation commutes with the cross product):

.. math::

    \\frac{\\partial \\hat J_j}{\\partial q_k} = (\\hat w_j \\times \\hat v_k - \\hat w_k \\times \\hat v_j,\\;
    \\hat w_j \\times \\hat w_k) \\ (k > j), \\qquad 0 \\ (k \\le j).

J̇ = Σ_k (∂J/∂q_k) q̇_k is summed in O(n) per column with the running sums Ω_j = Σ_{k≤j} w_k q̇_k,
V_j = Σ_{k>j} v_k q̇_k and W_j = Σ_{k>j} w_k q̇_k: J̇0_j = (Ω_j × v_j + w_j × V_j, Ω_j × w_j),
J̇e_j = (ŵ_j × V̂_j − Ŵ_j × v̂_j, −Ŵ_j × ŵ_j).

The component functions (:func:`hessian_entries`, :func:`jacobian_dot_entries`, :func:`bias_entries`) use only
``+ - *`` on components that are floats, numpy arrays or traced values, so the compiled kernels
(:mod:`denavit.codegen`) run this same code on the tape.
"""

from __future__ import annotations

import numpy as np

from .._threads import resolve_threads, split_rows
from .._validate import as_joint_array
from ..errors import ShapeError
from ..model import DHRobot, Frame
from ._jacobians import geometric_jacobian

__all__ = ["jacobian_dot", "acceleration_bias", "kinematic_hessian", "hessian_entries", "jacobian_dot_entries",
           "bias_entries", "kin_frame"]

_ZERO3 = (0.0, 0.0, 0.0)


def _cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def _axpy(s, a, b):
    """s·a + b on 3-component tuples."""
    return (s * a[0] + b[0], s * a[1] + b[1], s * a[2] + b[2])


def _sub(a, b):
    return (a[0] - b[0], a[1] - b[1], a[2] - b[2])


def _running_sums(v, w, qd):
    """Ω_j = Σ_{k≤j} w_k q̇_k, V_j = Σ_{k>j} v_k q̇_k, W_j = Σ_{k>j} w_k q̇_k (3-tuples, one per column)."""
    n = len(v)
    omega, acc = [], _ZERO3
    for j in range(n):
        acc = _axpy(qd[j], w[j], acc)
        omega.append(acc)
    V, W = [_ZERO3] * n, [_ZERO3] * n
    accv, accw = _ZERO3, _ZERO3
    for j in range(n - 1, 0, -1):
        accv, accw = _axpy(qd[j], v[j], accv), _axpy(qd[j], w[j], accw)
        V[j - 1], W[j - 1] = accv, accw
    return omega, V, W


def jacobian_dot_entries(v, w, qd, tool: bool):
    """Columns (linear, angular) of J̇ from the columns (v_j, w_j) of J0 (``tool=False``) or Je (``tool=True``).

    Returns two lists of n 3-tuples.  See the module notes for the formulas.
    """
    omega, V, W = _running_sums(v, w, qd)
    lin, ang = [], []
    for j in range(len(v)):
        if tool:  # (ŵ_j × V̂_j − Ŵ_j × v̂_j, −Ŵ_j × ŵ_j) = (…, ŵ_j × Ŵ_j)
            lin.append(_sub(_cross(w[j], V[j]), _cross(W[j], v[j])))
            ang.append(_cross(w[j], W[j]))
        else:  # (Ω_j × v_j + w_j × V_j, Ω_j × w_j)
            a, b = _cross(omega[j], v[j]), _cross(w[j], V[j])
            lin.append((a[0] + b[0], a[1] + b[1], a[2] + b[2]))
            ang.append(_cross(omega[j], w[j]))
    return lin, ang


def bias_entries(v, w, qd):
    """Σ_j q̇_j J̇0_j: the classical acceleration bias (p̈, ω̇) at q̈ = 0, in the axes the columns are given in.

    With the columns of J0 it is J̇0 q̇ (base axes); with those of Je it is Rᵀ J̇0 q̇, the same acceleration in the
    end-effector axes (the formula is that of J̇0 and a rotation commutes with the cross product).
    """
    lin, ang = jacobian_dot_entries(v, w, qd, tool=False)
    a, b = _ZERO3, _ZERO3
    for j in range(len(v)):
        a, b = _axpy(qd[j], lin[j], a), _axpy(qd[j], ang[j], b)
    return a + b


def hessian_entries(v, w, tool: bool):
    """H[j][k] = ∂J_j/∂q_k as a 6-tuple (linear, angular), from the columns of J0 or (``tool=True``) Je."""
    n = len(v)
    H = [[_ZERO3 + _ZERO3] * n for _ in range(n)]
    for j in range(n):
        for k in range(n):
            if tool:
                if k > j:
                    H[j][k] = _sub(_cross(w[j], v[k]), _cross(w[k], v[j])) + _cross(w[j], w[k])
            elif k <= j:  # linear part symmetric: filled for (j, k) and (k, j) at once
                lin = _cross(w[k], v[j])
                H[j][k] = lin + (_cross(w[k], w[j]) if k < j else _ZERO3)
                if k < j:
                    H[k][j] = lin + _ZERO3
    return H


def kin_frame(frame) -> Frame:
    """``frame`` as :class:`Frame` (base or tool); anything else a ValueError naming the choices."""
    try:
        return Frame(frame)
    except ValueError:
        raise ValueError(f"frame {str(frame)[:40]!r}: choose base or tool") from None


def _columns(J: np.ndarray):
    """The columns of J (..., 6, n) as components: floats for one configuration, (B,) arrays for a batch."""
    n = J.shape[-1]
    if J.ndim == 2:
        rows = J.tolist()
    else:
        rows = np.ascontiguousarray(np.moveaxis(J.reshape(-1, 6, n), 0, -1))  # (6, n, B)
    v = [(rows[0][j], rows[1][j], rows[2][j]) for j in range(n)]
    w = [(rows[3][j], rows[4][j], rows[5][j]) for j in range(n)]
    return v, w


def _assemble(entries, shape: tuple[int, ...], batch: tuple[int, ...]) -> np.ndarray:
    """Entries in C order (floats or (B,) arrays) → array ``batch + shape``."""
    if not batch:
        return np.array(entries, dtype=float).reshape(shape)
    size = int(np.prod(batch, dtype=int))
    out = np.empty((len(entries), size))
    for i, e in enumerate(entries):
        out[i] = e
    return np.ascontiguousarray(out.T).reshape(batch + shape)


def _inputs(robot: DHRobot, q, qd):
    q = as_joint_array(q, robot.dof)
    qd = as_joint_array(qd, robot.dof, "qd")
    try:
        return np.broadcast_arrays(q, qd)
    except ValueError:
        raise ShapeError(f"q {q.shape} and qd {qd.shape} do not broadcast together") from None


def _evaluate(robot: DHRobot, frame: Frame, q: np.ndarray, qd, shape: tuple[int, ...], entries, threads):
    """``entries(v, w, qd)`` → the C-ordered entries of one output of ``shape``, evaluated at q (..., n) (and qd):
    one configuration in floats, a batch as (B,) components, its rows split over ``threads``
    (:func:`denavit._threads.split_rows`)."""
    resolve_threads(threads)  # a bad value is refused for one configuration too
    n = robot.dof
    batch = q.shape[:-1]
    if not batch:
        v, w = _columns(geometric_jacobian(robot, q, frame))
        return _assemble(entries(v, w, None if qd is None else qd.tolist()), shape, ())
    Q = q.reshape(-1, n)
    QD = None if qd is None else qd.reshape(-1, n)
    out = np.empty((Q.shape[0],) + shape)

    def work(s: int, e: int) -> None:
        if e > s:
            v, w = _columns(geometric_jacobian(robot, Q[s:e], frame))
            out[s:e] = _assemble(entries(v, w, None if QD is None else list(QD[s:e].T)), shape, (e - s,))

    split_rows(Q.shape[0], work, threads)
    return out.reshape(batch + shape)


def jacobian_dot(robot: DHRobot, q, qd, frame: Frame | str = Frame.BASE, *, threads: int | None = None) -> np.ndarray:
    """Time derivative J̇ of the geometric Jacobian, shape (..., 6, n), rows (v, ω).

    ``frame="base"``: d/dt J0 (end-effector origin, world/base axes; Pinocchio's ``LOCAL_WORLD_ALIGNED``);
    ``"tool"``: d/dt Je (end-effector axes; ``LOCAL``), = diag(Rᵀ, Rᵀ)(J̇0 − [ω]× J0) with ω the end effector's
    angular velocity.  Closed form in the Jacobian's columns (module notes; Haviland & Corke 2023, Part I).

    Parameters
    ----------
    robot : DHRobot
    q, qd : array_like, shape (..., n)
        Joint positions [rad or m] and rates [rad/s or m/s]; their batch shapes broadcast.
    frame : {"base", "tool"}
    threads : int, optional
        Threads that share a batch (None: all cores).

    Examples
    --------
    >>> import numpy as np, denavit
    >>> robot = denavit.load_robot("planar2r")
    >>> Jd = jacobian_dot(robot, [0.3, 0.5], [1.0, -2.0])
    >>> Jd.shape
    (6, 2)
    """
    frame = kin_frame(frame)
    q, qd = _inputs(robot, q, qd)
    n, tool = robot.dof, frame is Frame.TOOL

    def entries(v, w, qd):
        lin, ang = jacobian_dot_entries(v, w, qd, tool)
        return [lin[j][r] for r in range(3) for j in range(n)] + [ang[j][r] for r in range(3) for j in range(n)]

    return _evaluate(robot, frame, q, qd, (6, n), entries, threads)


def acceleration_bias(robot: DHRobot, q, qd, frame: Frame | str = Frame.BASE, *,
                      threads: int | None = None) -> np.ndarray:
    """The classical acceleration bias of the end-effector origin, shape (..., 6): (p̈, ω̇) at q̈ = 0.

    (p̈, ω̇) = J0 q̈ + J̇0 q̇ in base axes, so the bias is J̇0 q̇ (``frame="base"``).  ``frame="tool"`` gives the
    same acceleration in the end-effector axes, Rᵀ J̇0 q̇ (Pinocchio's classical acceleration in ``LOCAL``); note
    that this is *not* J̇e q̇ = Rᵀ J̇0 q̇ − (Rᵀ(ω × v), 0), the derivative of the body-axes twist.

    Parameters
    ----------
    robot : DHRobot
    q, qd : array_like, shape (..., n)
    frame : {"base", "tool"}
    threads : int, optional
        Threads that share a batch (None: all cores).
    """
    frame = kin_frame(frame)
    q, qd = _inputs(robot, q, qd)
    return _evaluate(robot, frame, q, qd, (6,), lambda v, w, qd: list(bias_entries(v, w, qd)), threads)


def kinematic_hessian(robot: DHRobot, q, frame: Frame | str = Frame.BASE, *, threads: int | None = None) -> np.ndarray:
    """Kinematic Hessian H = ∂J/∂q, shape (..., 6, n, n), with ∂J[:, j]/∂q_k at ``H[..., :, j, k]``.

    ``frame="base"``: of J0 (the linear block H[:3] is symmetric in j, k: ∂²p/∂q_j∂q_k); ``"tool"``: of Je
    (zero for k ≤ j: a column of Je depends only on the joints after it).  J̇ = Σ_k H[..., :, :, k] q̇_k.
    Closed form (module notes; Haviland & Corke 2023, Part I, eq. 25–27).

    Parameters
    ----------
    robot : DHRobot
    q : array_like, shape (..., n)
    frame : {"base", "tool"}
    threads : int, optional
        Threads that share a batch (None: all cores).
    """
    frame = kin_frame(frame)
    q = as_joint_array(q, robot.dof)
    n, tool = robot.dof, frame is Frame.TOOL

    def entries(v, w, _):
        H = hessian_entries(v, w, tool)
        return [H[j][k][r] for r in range(6) for j in range(n) for k in range(n)]

    return _evaluate(robot, frame, q, None, (6, n, n), entries, threads)
