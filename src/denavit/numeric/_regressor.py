"""The joint-torque regressor τ = Y(q, q̇, q̈) π and the energy regressors, from the library's own RNEA.

The inverse dynamics is linear in each body's inertial parameters written in the linear form — mass m, first
moment h = m c and rotational inertia J about a point fixed in the body (Khalil & Dombre 2002, §9.3; Atkeson,
An & Hollerbach 1986) — and in the joints' friction and motor inertia.  Y is read off
:func:`~denavit.numeric._dynamics_fast.rnea_kernel` itself: the kernel runs once with every parameter a
:class:`Linear` value (a linear combination of the unit parameters, whose coefficients are floats, (B,) arrays or
traced values), so each τ_j comes out as Σ_i Y_ji π_i.  No second copy of the dynamics is written here.

Parameters (π), per moving body k = 1 … n, in the frame of joint k (:func:`parameter_names`):
``M, MX, MY, MZ, XX, XY, YY, XZ, YZ, ZZ`` — m, m c and the inertia tensor about the frame's origin, in its axes
(the order of Pinocchio's ``Inertia.toDynamicParameters``).  Joint k's frame is the frame of its axis after its
motion: DH frame {r} (row r of the joint, 1-based) for modified DH, frame {r−1} turned (or slid) by q_k for
standard DH — Pinocchio's joint frame of :func:`denavit.peers.to_pinocchio`.  Then ``FV1 … FVn`` (viscous),
``FC1 … FCn`` (Coulomb), ``IA1 … IAn`` (motor inertia), each block present when asked for.
"""

from __future__ import annotations

import numpy as np

from .._threads import split_rows
from .._validate import as_joint_array
from ..model import DHRobot
from ._dynamics import gravity_vector
from ._dynamics_fast import body_frames, body_origins, frames, joint_columns, plan, rnea_kernel

__all__ = ["Linear", "BODY_PARAMETERS", "parameter_names", "inertial_parameters", "regressor", "regressor_rows",
           "kinetic_energy_regressor", "potential_energy_regressor", "linear_parameters"]

#: The 10 standard parameters of a body, in π's order (Khalil's names; Pinocchio's order).
BODY_PARAMETERS = ("M", "MX", "MY", "MZ", "XX", "XY", "YY", "XZ", "YZ", "ZZ")
_J_INDEX = ((4, 5, 7), (5, 6, 8), (7, 8, 9))  # J[i][j] ↔ position in BODY_PARAMETERS


class Linear:
    """Σ_i c_i π_i: a value linear in the parameters, ``terms`` {index: coefficient}.

    Coefficients are floats, numpy (B,) arrays or traced values; the kernels only add these and scale them by
    parameter-free values, so a product of two is an error (τ is linear in π).  ``__array_ufunc__ = None`` makes
    numpy hand ``array * Linear`` to :meth:`__rmul__` (a traced value does the same).
    """

    __slots__ = ("terms",)
    __array_ufunc__ = None

    def __init__(self, terms: dict) -> None:
        self.terms = terms

    def __add__(self, other):
        if isinstance(other, Linear):
            t = dict(self.terms)
            for i, c in other.terms.items():
                t[i] = t[i] + c if i in t else c
            return self.__class__(t)
        if isinstance(other, (int, float)) and other == 0:
            return self
        raise TypeError(f"a parameter-free value added to a Linear: {type(other).__name__} (not linear in π)")

    __radd__ = __add__

    def __neg__(self):
        return self.__class__({i: -c for i, c in self.terms.items()})

    def __sub__(self, other):
        return self + (-other)

    def __rsub__(self, other):
        return (-self) + other

    def __mul__(self, other):
        if isinstance(other, Linear):
            raise TypeError("a product of two Linear values is not linear in π")
        if isinstance(other, (int, float)) and other == 0:
            return 0.0
        return self.__class__({i: c * other for i, c in self.terms.items()})

    __rmul__ = __mul__


def parameter_names(robot: DHRobot, *, friction: bool = True, motor_inertia: bool = True) -> tuple[str, ...]:
    """Names of π's entries: ``M1, MX1, …, ZZ1, M2, …`` then ``FV1…``, ``FC1…`` (friction), ``IA1…``."""
    n = robot.dof
    names = [f"{p}{k + 1}" for k in range(n) for p in BODY_PARAMETERS]
    if friction:
        names += [f"FV{k + 1}" for k in range(n)] + [f"FC{k + 1}" for k in range(n)]
    if motor_inertia:
        names += [f"IA{k + 1}" for k in range(n)]
    return tuple(names)


def inertial_parameters(robot: DHRobot, *, friction: bool = True, motor_inertia: bool = True) -> np.ndarray:
    """π of the robot, shape (p,), in the order of :func:`parameter_names`, so that ``regressor(...) @ π`` is
    :func:`denavit.rnea`.

    Body k's pieces (its joint row and the fixed rows after it) are summed about the joint frame's origin by the
    parallel-axis theorem, J = Σ R I_c Rᵀ + m(|c|² 1 − c cᵀ) (Khalil & Dombre 2002, eq. 9.4), in its axes.
    """
    pl = plan(robot)
    out = []
    for b in pl.bodies:
        E = np.array(b.to_joint)  # v_frame = E v_joint
        h = E.T @ np.array(b.h)
        J = E.T @ np.array(b.J) @ E
        out += [b.mass, *h, J[0, 0], J[0, 1], J[1, 1], J[0, 2], J[1, 2], J[2, 2]]
    joints = robot.joints
    if friction:
        out += [link.inertia.viscous if link.inertia else 0.0 for link in joints]
        out += [link.inertia.coulomb if link.inertia else 0.0 for link in joints]
    if motor_inertia:
        out += [link.inertia.motor_inertia if link.inertia else 0.0 for link in joints]
    return np.array(out, dtype=float)


def linear_parameters(pl, unit, motor_inertia: bool = True) -> tuple:
    """Per body the (frame, m, h, J, armature) of :func:`~denavit.numeric._dynamics_fast.body_frames` with every
    parameter π_i the value ``unit(i)``, h and J turned from the joint frame's axes into the frame's.

    ``unit(i)`` is the i-th unit vector of the parameter space: a row of the identity (one configuration: τ_j
    then is row j of Y), a :class:`Linear` keyed by body with rows of the 10 × 10 identity as coefficients (a
    batch: :func:`_block_unit`), or a :class:`Linear` with float coefficients that traced values multiply (the
    compiled kernel).
    """
    out = []
    n = len(pl.bodies)
    for k, (frame, *_rest) in enumerate(body_frames(pl)):
        e = [unit(10 * k + i) for i in range(10)]
        E = pl.bodies[k].to_joint
        Jj = [[e[_J_INDEX[i][j]] for j in range(3)] for i in range(3)]
        h = tuple(_mix(E[i], e[1:4]) for i in range(3))  # E h
        EJ = [[_mix(E[i], [Jj[a][j] for a in range(3)]) for j in range(3)] for i in range(3)]
        J = tuple(tuple(_mix(E[j], EJ[i]) for j in range(3)) for i in range(3))  # E J Eᵀ
        ia = unit(10 * n + k) if motor_inertia else 0.0
        out.append((frame, e[0], h, J, ia))
    return tuple(out)


def _mix(coefs, values):
    """Σ c_i v_i over the non-zero float coefficients c_i (0.0 when none)."""
    out = 0.0
    for c, v in zip(coefs, values):
        if c != 0.0:
            out = v * c if isinstance(out, float) else out + v * c
    return out


def _block_unit(batch: bool):
    """unit(i) for a batch (or the potential energy): a :class:`Linear` keyed by body, whose coefficient is row
    i mod 10 of the 10 × 10 identity ((10,) arrays, or (10, 1) against (B,) kinematics): one numpy operation per
    body that a value depends on, each over that body's 10 parameters."""
    eye = np.eye(10)
    rows = [eye[i][:, None] for i in range(10)] if batch else list(eye)
    return lambda i: Linear({i // 10: rows[i % 10]})


def _block_rows(value, n: int, batch: bool):
    """Row j of Y's inertial block (10n,) or (B, 10n) from τ_j of :func:`regressor_rows` on :func:`_block_unit`."""
    if not isinstance(value, Linear):
        return None
    out = {}
    for k, c in value.terms.items():
        out[k] = np.transpose(c) if batch else c
    return out


def regressor_rows(pl, qc, qdc, qddc, g, unit, motor_inertia: bool = True, F=None) -> list:
    """τ_j of :func:`~denavit.numeric._dynamics_fast.rnea_kernel` run on the unit parameters ``unit(i)`` (see
    :func:`linear_parameters`): per joint, row j of Y's inertial (and motor-inertia) block as a :class:`Linear`
    (or the float 0 when no parameter reaches joint j).  ``F``: the frames at ``qc`` when already walked."""
    F = frames(pl, qc) if F is None else F
    return rnea_kernel(pl, qc, qdc, qddc, g, F, linear_parameters(pl, unit, motor_inertia))


#: Rows of a batch evaluated together by the plain regressor (the kernel's arrays are (p, rows)).
_BLOCK = 1024


def regressor(robot: DHRobot, q, qd, qdd, *, friction: bool = True, motor_inertia: bool = True, gravity=None,
              threads=None) -> np.ndarray:
    """The joint-torque regressor Y(q, q̇, q̈), shape (..., n, p): τ = Y π with π from :func:`inertial_parameters`.

    Parameters
    ----------
    q, qd, qdd : array_like, shape (..., n)
        Joint positions [rad or m], rates and accelerations; broadcast together.
    friction, motor_inertia : bool
        Include the columns of viscous and Coulomb friction (τ_f = FV q̇ + FC sign q̇) and of motor inertia
        (IA q̈); ``regressor(...) @ inertial_parameters(...)`` equals ``denavit.rnea`` with the same terms.
    gravity : array_like (3,), optional
        World gravity [m/s²]; the robot's by default.
    threads : int, optional
        Threads the batch is split over (``None``: every core; :mod:`denavit._threads`).

    Notes
    -----
    Column i of Y is the RNEA (Craig 3rd ed. eqs. 6.45–6.53) of the arm whose only non-zero parameter is
    π_i = 1: :func:`~denavit.numeric._dynamics_fast.rnea_kernel` runs once with the parameters the rows of the
    identity, so its τ_j is row j of Y.  Parameter order and frames: module notes; Pinocchio's
    ``computeJointTorqueRegressor`` has the same inertial columns.
    """
    n = robot.dof
    q, qd, qdd = np.broadcast_arrays(as_joint_array(q, n), as_joint_array(qd, n, "qd"),
                                      as_joint_array(qdd, n, "qdd"))
    g = gravity_vector(robot, gravity).tolist()
    p = len(parameter_names(robot, friction=friction, motor_inertia=motor_inertia))
    pl = plan(robot)
    if q.ndim == 1:
        eye = np.eye(10 * n)  # one configuration: dense unit rows, (10 n,) arrays (half the time of blocks)
        rows = regressor_rows(pl, q.tolist(), qd.tolist(), qdd.tolist(), g, eye.__getitem__, False)
        Y = np.zeros((n, p))
        for j, row in enumerate(rows):
            Y[j, : 10 * n] = row
        return _finish(Y, qd, qdd, n, friction, motor_inertia)
    batch = q.shape[:-1]
    flat = [x.reshape(-1, n) for x in (q, qd, qdd)]
    out = np.zeros((flat[0].shape[0], n, p))
    split_rows(out.shape[0], lambda s, e: _fill(out, pl, flat, g, s, e, friction, motor_inertia), threads,
               min_rows=256)
    return out.reshape(batch + (n, p))


def _fill(out, pl, flat, g, s: int, e: int, friction: bool, motor_inertia: bool) -> None:
    """Rows s:e of a batch's Y, in blocks of :data:`_BLOCK` rows (the kernel's arrays are (10, rows))."""
    n = out.shape[1]
    unit = _block_unit(True)
    for a in range(s, e, _BLOCK):
        b = min(e, a + _BLOCK)
        rows = regressor_rows(pl, *[joint_columns(x[a:b])[0] for x in flat], g, unit, False)
        for j, row in enumerate(rows):
            for k, c in (_block_rows(row, n, True) or {}).items():
                out[a:b, j, 10 * k: 10 * k + 10] = c
        out[a:b] = _finish(out[a:b], flat[1][a:b], flat[2][a:b], n, friction, motor_inertia)


def _finish(out, qd, qdd, n: int, friction: bool, motor_inertia: bool) -> np.ndarray:
    """Y (..., n, p) with its inertial block filled: the friction and motor-inertia columns written in."""
    idx = np.arange(n)
    col = 10 * n
    if friction:
        out[..., idx, col + idx] = qd
        out[..., idx, col + n + idx] = np.sign(qd)
        col += 2 * n
    if motor_inertia:
        out[..., idx, col + idx] = qdd
    return out


def kinetic_energy_regressor(robot: DHRobot, q, qd, *, friction: bool = True, motor_inertia: bool = True,
                             threads=None) -> np.ndarray:
    """y_K(q, q̇), shape (..., p): K = ½ q̇ᵀ M(q) q̇ = y_K π (friction columns zero).

    M q̇ is the RNEA at velocity 0, acceleration q̇ and no gravity, so y_K = ½ q̇ᵀ Y(q, 0, q̇; g = 0)
    (Gautier & Khalil 1988, the energy model); the columns are those of :func:`regressor`.
    """
    n = robot.dof
    q, qd = np.broadcast_arrays(as_joint_array(q, n), as_joint_array(qd, n, "qd"))
    Y = regressor(robot, q, np.zeros_like(qd), qd, friction=friction, motor_inertia=motor_inertia,
                  gravity=np.zeros(3), threads=threads)
    return 0.5 * np.einsum("...j,...jp->...p", qd, Y)


def potential_energy_regressor(robot: DHRobot, q, *, friction: bool = True, motor_inertia: bool = True,
                               gravity=None) -> np.ndarray:
    """y_U(q), shape (..., p): U = −Σ_k gᵀ (m_k O_k + R_k h_k) = y_U π, the potential energy of
    :func:`denavit.potential_energy` (O_k, R_k: origin and axes of joint k's frame in the world)."""
    n = robot.dof
    q = as_joint_array(q, n)
    g = gravity_vector(robot, gravity)
    p = len(parameter_names(robot, friction=friction, motor_inertia=motor_inertia))
    pl = plan(robot)
    qc, batch = joint_columns(q)
    F = frames(pl, qc)
    origins = body_origins(pl, F, qc)
    total = 0.0
    for k, (frame, m, h, _J, _ia) in enumerate(linear_parameters(pl, _block_unit(batch is not None), False)):
        axes = F[frame][:3]
        total = total + m * sum(-g[i] * origins[k][i] for i in range(3))
        for i in range(3):
            total = total + h[i] * sum(-g[a] * axes[i][a] for a in range(3))
    out = np.zeros((1 if batch is None else int(np.prod(batch, dtype=int)), p))
    for k, c in _block_rows(total, n, batch is not None).items():
        out[:, 10 * k: 10 * k + 10] = c
    return out[0] if batch is None else out.reshape(batch + (p,))
