"""Jacobians of the end effector, batched: shape (..., 6, n), rows (v, ω).

Three numeric routes that share nothing but the model:

* :func:`geometric_jacobian` — from the joint axes of the world frames (Siciliano eq. 3.30);
* :func:`differentiation_jacobian` — by differentiating the product of DH matrices entry by entry,
  linear rows ∂p/∂q, angular rows from the skew matrix Ṙ Rᵀ (Spong eq. 4.30);
* :func:`denavit.numeric.propagation_jacobian` — Craig's outward velocity propagation (Craig eq. 5.45–5.47).

All use the end-effector origin (after ``tool``) as reference point. ``frame="base"`` gives J0 (world axes,
``base`` included), ``frame="tool"`` gives Je (end-effector axes); :func:`jacobian_tool_from_base` and
:func:`jacobian_base_from_tool` convert between them. :func:`analytic_jacobian` maps joint rates to
(ṗ, φ̇) with φ roll–pitch–yaw or ZYZ Euler angles, the unit quaternion or exponential coordinates.
"""

from __future__ import annotations

import warnings

import numpy as np

from .._threads import split_call
from .._validate import as_joint_array
from ..errors import ShapeError
from ..chain import chain_of
from ..model import Convention, DHRobot, Frame, JointType
from ._kinematics import joint_axes_batch, joint_values_per_row, link_transforms
from ._transforms import dh_transform, quaternion_from_rotation, rotation_log, rpy_from_rotation, zyz_from_rotation

__all__ = [
    "geometric_jacobian",
    "joint_axes",
    "differentiation_jacobian",
    "jacobian_tool_from_base",
    "jacobian_base_from_tool",
    "analytic_jacobian",
    "rpy_rate_matrix",
    "zyz_rate_matrix",
    "quaternion_rate_matrix",
    "exp_rate_matrix",
    "end_effector_twist",
    "REPRESENTATIONS",
]

REPRESENTATIONS = ("rpy", "zyz", "quaternion", "exp")
#: Below this |cos pitch| (RPY) or |sin θ| (ZYZ) the angle-rate map is treated as singular.
REPRESENTATION_SINGULAR_TOL = 1e-9


def joint_axes(robot: DHRobot, frames: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Axis direction z and a point o on it for every joint, in world axes, each (..., n, 3).

    Standard DH: joint i moves about/along z_{i-1} through o_{i-1}; modified DH: z_i through o_i
    (:attr:`denavit.chain.Chain.axis_frame`).
    """
    idx = list(chain_of(robot).axis_frame)
    sel = np.take(frames, idx, axis=-3)  # (..., n, 4, 4)
    return sel[..., :3, 2], sel[..., :3, 3]


def _frame_of(robot: DHRobot, frame: Frame | str | int) -> Frame | int:
    """The axes a Jacobian is asked in: :class:`Frame` (``"base"``, ``"tool"``) or a DH frame index 0 … N.

    Raises ``ValueError`` naming the choices for anything else (a bool, an index outside the arm, another word).
    """
    if isinstance(frame, (int, np.integer)) and not isinstance(frame, (bool, np.bool_)):
        if not 0 <= frame <= robot.n_rows:
            raise ValueError(f"frame {int(frame)} is not a DH frame of {robot.name!r}: choose base, tool or an index "
                             f"from 0 to {robot.n_rows}")
        return int(frame)
    try:
        return Frame(frame)
    except ValueError:
        raise ValueError(f"frame {str(frame)[:40]!r}: choose base, tool or a DH frame index from 0 to "
                         f"{robot.n_rows}") from None


def geometric_jacobian(robot: DHRobot, q, frame: Frame | str | int = Frame.BASE, *, threads=None) -> np.ndarray:
    """Geometric Jacobian of the end-effector origin, shape (..., 6, n), rows (v, ω).

    Column i is [z_i × (p_e − o_i); z_i] for a revolute joint and [z_i; 0] for a prismatic one
    (Siciliano et al. 2009, eq. 3.30), with z_i, o_i the joint axis and a point on it.

    Parameters
    ----------
    robot : DHRobot
    q : array_like, shape (..., n)
    frame : Frame, {"base", "tool"} or int
        ``base``: J0, velocities in world/base axes; ``tool``: Je, in end-effector axes; an integer i
        (0 … N, the DH frames): ⁱJ = diag(R_0_iᵀ, R_0_iᵀ) J0, the same velocities in the axes of DH frame {i}
        (R_0_i its orientation in the world, ``base`` applied; Craig 2005, eq. 5.101).  The reference point is
        the end-effector origin in every case.
    threads : int, optional
        Threads a batch's rows are split over (default every core; small batches run inline; the result is
        the unsplit one bit for bit: :mod:`denavit._threads`).

    Examples
    --------
    >>> import numpy as np, denavit
    >>> robot = denavit.load_robot("planar2r")
    >>> q = [0.3, 0.5]
    >>> R_0_1 = denavit.link_transforms(robot, q)[1, :3, :3]
    >>> J1 = geometric_jacobian(robot, q, frame=1)
    >>> bool(np.allclose(J1[:3], R_0_1.T @ geometric_jacobian(robot, q)[:3]))
    True
    """
    frame = _frame_of(robot, frame)
    q = as_joint_array(q, robot.dof)
    split = None if q.ndim == 1 and threads is None else split_call(  # one configuration: inline
        lambda x: geometric_jacobian(robot, x, frame, threads=1), (q,), threads)
    if split is not None:
        return split
    if not isinstance(frame, Frame):
        J0 = geometric_jacobian(robot, q, Frame.BASE, threads=1)
        return jacobian_tool_from_base(J0, link_transforms(robot, q, threads=1)[..., frame, :, :])
    if q.ndim > 1:
        return _geometric_jacobian_batch(robot, q, frame)
    frames = link_transforms(robot, q)  # (N+1, 4, 4)
    T_e = frames[..., -1, :, :] @ robot.tool_matrix  # (..., 4, 4)
    z, o = joint_axes(robot, frames)  # (..., n, 3)
    p_e = T_e[..., None, :3, 3]  # (..., 1, 3)
    revolute = np.array([t is JointType.REVOLUTE for t in robot.joint_types])
    v = np.where(revolute[:, None], np.cross(z, p_e - o), z)  # (..., n, 3)
    w = np.where(revolute[:, None], z, 0.0)
    J = np.concatenate([np.swapaxes(v, -1, -2), np.swapaxes(w, -1, -2)], axis=-2)  # (..., 6, n)
    if frame is Frame.TOOL:
        Rt = np.swapaxes(T_e[..., :3, :3], -1, -2)
        J = np.concatenate([Rt @ J[..., :3, :], Rt @ J[..., 3:, :]], axis=-2)
    return J


def _geometric_jacobian_batch(robot: DHRobot, q: np.ndarray, frame: Frame) -> np.ndarray:
    """The same columns as :func:`geometric_jacobian`, computed in the batch-contiguous layout (n, 3, B)."""
    z, o, xe, ye, ze, pe, batch = joint_axes_batch(robot, q)  # z, o: (n, 3, B)
    d = pe[None] - o  # (n, 3, B)
    revolute = np.array([t is JointType.REVOLUTE for t in robot.joint_types])[:, None, None]
    cross = np.stack([z[:, 1] * d[:, 2] - z[:, 2] * d[:, 1], z[:, 2] * d[:, 0] - z[:, 0] * d[:, 2],
                      z[:, 0] * d[:, 1] - z[:, 1] * d[:, 0]], axis=1)  # (n, 3, B)
    v = np.where(revolute, cross, z)
    w = np.where(revolute, z, 0.0)
    if frame is Frame.TOOL:  # rows of R_eᵀ are the end-effector axes
        axes = np.stack([xe, ye, ze])  # (3 axes, 3, B)
        v = np.einsum("kib,nib->nkb", axes, v)
        w = np.einsum("kib,nib->nkb", axes, w)
    J = np.concatenate([v, w], axis=1)  # (n, 6, B)
    return np.ascontiguousarray(np.moveaxis(J, (0, 1), (-1, -2))).reshape(batch + (6, robot.dof))


def _dh_derivative(convention: Convention, joint: JointType, theta, d, a: float, alpha: float) -> np.ndarray:
    """∂A/∂q of one DH matrix, entry by entry (the matrix of :func:`dh_transform` differentiated)."""
    theta, d = np.broadcast_arrays(np.asarray(theta, float), np.asarray(d, float))
    ct, st, ca, sa = np.cos(theta), np.sin(theta), np.cos(alpha), np.sin(alpha)
    dA = np.zeros(theta.shape + (4, 4))
    zero = np.zeros_like(ct)
    if joint is JointType.PRISMATIC:  # only the translation along z_{i-1} / z_i depends on d
        if convention is Convention.STANDARD:
            dA[..., 2, 3] = 1.0
        else:
            dA[..., 1, 3], dA[..., 2, 3] = -sa, ca
        return dA
    if convention is Convention.STANDARD:  # ∂/∂θ of Spong eq. 3.10
        dA[..., 0, :3] = np.stack([-st, -ct * ca, ct * sa], -1)
        dA[..., 0, 3] = -a * st
        dA[..., 1, :3] = np.stack([ct, -st * ca, st * sa], -1)
        dA[..., 1, 3] = a * ct
    else:  # ∂/∂θ of Craig eq. 3.6
        dA[..., 0, :3] = np.stack([-st, -ct, zero], -1)
        dA[..., 1, :3] = np.stack([ct * ca, -st * ca, zero], -1)
        dA[..., 2, :3] = np.stack([ct * sa, -st * sa, zero], -1)
    return dA


def differentiation_jacobian(robot: DHRobot, q, frame: Frame | str = Frame.BASE) -> np.ndarray:
    """Jacobian by differentiating the forward-kinematics product, shape (..., 6, n), rows (v, ω).

    For the joint of row k, ∂T/∂q_k = base A_1 ⋯ A_{k-1} (∂A_k/∂q_k) A_{k+1} ⋯ A_N tool; the linear rows
    are the translation column of that derivative and the angular rows the vector of the skew matrix
    (∂R/∂q_k) Rᵀ (Spong, Hutchinson & Vidyasagar 2006, sec. 4.2–4.6). Reference point: end-effector origin.

    Parameters
    ----------
    robot : DHRobot
    q : array_like, shape (..., n)
        Joint values [rad or m].
    frame : Frame or {"base", "tool"}
        Axes of the result: world/base (J0) or end effector (Je).
    """
    frame = Frame(frame)
    q = as_joint_array(q, robot.dof)
    batch = q.shape[:-1]
    rows = joint_values_per_row(robot, q)
    A = [np.broadcast_to(dh_transform(robot.convention, th, d, link.a, link.alpha), batch + (4, 4))
         for link, (th, d) in zip(robot.links, rows)]  # N × (..., 4, 4)
    prefix = [np.broadcast_to(robot.base_matrix, batch + (4, 4))]
    for Ak in A:
        prefix.append(prefix[-1] @ Ak)
    suffix = [np.broadcast_to(robot.tool_matrix, batch + (4, 4))]
    for Ak in reversed(A):
        suffix.append(Ak @ suffix[-1])
    suffix.reverse()  # suffix[k] = A_{k+1} ⋯ A_N tool (0-based rows)
    T = prefix[-1] @ robot.tool_matrix  # (..., 4, 4)
    Rt = np.swapaxes(T[..., :3, :3], -1, -2)
    cols = []
    for r in robot.joint_rows:
        link = robot.links[r]
        th, d = rows[r]
        dT = prefix[r] @ _dh_derivative(robot.convention, link.joint, th, d, link.a, link.alpha) @ suffix[r + 1]
        W = dT[..., :3, :3] @ Rt  # (..., 3, 3) skew(ω)
        w = 0.5 * np.stack([W[..., 2, 1] - W[..., 1, 2], W[..., 0, 2] - W[..., 2, 0], W[..., 1, 0] - W[..., 0, 1]], -1)
        cols.append(np.concatenate([dT[..., :3, 3], w], axis=-1))  # (..., 6)
    J = np.stack(cols, axis=-1)  # (..., 6, n)
    return jacobian_tool_from_base(J, T) if frame is Frame.TOOL else J


def _rotation(R_or_T) -> np.ndarray:
    M = np.asarray(R_or_T, dtype=float)
    if M.ndim < 2 or M.shape[-2:] not in ((3, 3), (4, 4)):
        raise ShapeError(f"expected a rotation (..., 3, 3) or transform (..., 4, 4), got shape {M.shape}")
    return M[..., :3, :3]


def _rotate_rows(J: np.ndarray, R: np.ndarray) -> np.ndarray:
    J = np.asarray(J, dtype=float)
    if J.ndim < 2 or J.shape[-2] != 6:
        raise ShapeError(f"J: expected shape (..., 6, n), got {J.shape}")
    return np.concatenate([R @ J[..., :3, :], R @ J[..., 3:, :]], axis=-2)


def jacobian_tool_from_base(J0, T_w_e) -> np.ndarray:
    """Je = diag(Rᵀ, Rᵀ) J0 with R the end-effector orientation in world axes (Siciliano eq. 3.112).

    ``T_w_e`` is the end-effector pose (..., 4, 4) or its rotation (..., 3, 3). Same reference point.  Given the
    world pose of another frame {i} instead, the result is ⁱJ, the Jacobian in {i}'s axes.
    """
    return _rotate_rows(J0, np.swapaxes(_rotation(T_w_e), -1, -2))


def jacobian_base_from_tool(Je, T_w_e) -> np.ndarray:
    """J0 = diag(R, R) Je, the inverse of :func:`jacobian_tool_from_base`."""
    return _rotate_rows(Je, _rotation(T_w_e))


def rpy_rate_matrix(rpy) -> np.ndarray:
    """E (..., 3, 3) with ω = E φ̇ for φ = (roll, pitch, yaw), R = Rz(yaw) Ry(pitch) Rx(roll), ω in world axes.

    ω = ẏ z + ṗ Rz(y) y + ṙ Rz(y) Ry(p) x (Siciliano eq. 3.64 for the RPY/ZYX case).
    """
    rpy = np.asarray(rpy, dtype=float)
    p, y = rpy[..., 1], rpy[..., 2]
    cp, sp, cy, sy = np.cos(p), np.sin(p), np.cos(y), np.sin(y)
    z = np.zeros_like(p)
    return np.stack([np.stack([cy * cp, -sy, z], -1),
                     np.stack([sy * cp, cy, z], -1),
                     np.stack([-sp, z, z + 1.0], -1)], axis=-2)


def zyz_rate_matrix(zyz) -> np.ndarray:
    """E (..., 3, 3) with ω = E φ̇ for ZYZ angles (φ, θ, ψ), R = Rz(φ) Ry(θ) Rz(ψ) (Siciliano eq. 3.64)."""
    zyz = np.asarray(zyz, dtype=float)
    ph, th = zyz[..., 0], zyz[..., 1]
    cf, sf, ct, st = np.cos(ph), np.sin(ph), np.cos(th), np.sin(th)
    z = np.zeros_like(ph)
    return np.stack([np.stack([z, -sf, cf * st], -1),
                     np.stack([z, cf, sf * st], -1),
                     np.stack([z + 1.0, z, ct], -1)], axis=-2)


def quaternion_rate_matrix(quat) -> np.ndarray:
    """G (..., 4, 3) with d/dt (w, x, y, z) = G ω, ω in world axes: q̇ = ½ (0, ω) ⊗ q (Siciliano eq. 3.94's
    counterpart for the world-axes ω; Sola 2017, "Quaternion kinematics for the error-state Kalman filter", eq. 199)."""
    quat = np.asarray(quat, dtype=float)
    w, x, y, z = quat[..., 0], quat[..., 1], quat[..., 2], quat[..., 3]
    return 0.5 * np.stack([np.stack([-x, -y, -z], -1), np.stack([w, z, -y], -1),
                           np.stack([-z, w, x], -1), np.stack([y, -x, w], -1)], axis=-2)


def exp_rate_matrix(r) -> np.ndarray:
    """J_l⁻¹ (..., 3, 3) with ṙ = J_l⁻¹(r) ω for the rotation vector r = θu (R = exp([r]×), ω in world axes).

    J_l⁻¹ = I − ½[r]× + (1 − (θ/2) cot(θ/2))/θ² [r]×² (the inverse left Jacobian of SO(3); Barfoot 2017, *State
    Estimation for Robotics*, eq. 7.77b), finite for θ ∈ [0, π] (the range of :func:`rotation_log`); the
    coefficient is its series 1/12 + θ²/720 below θ = 1e-4.
    """
    r = np.asarray(r, dtype=float)
    theta = np.linalg.norm(r, axis=-1)
    small = theta < 1e-4
    t = np.where(small, 1.0, theta)
    coef = np.where(small, 1.0 / 12.0 + theta**2 / 720.0, (1.0 - 0.5 * t / np.tan(0.5 * t)) / t**2)
    z = np.zeros_like(theta)
    K = np.stack([np.stack([z, -r[..., 2], r[..., 1]], -1), np.stack([r[..., 2], z, -r[..., 0]], -1),
                  np.stack([-r[..., 1], r[..., 0], z], -1)], axis=-2)
    return np.eye(3) - 0.5 * K + coef[..., None, None] * (K @ K)


def analytic_jacobian(robot: DHRobot, q, representation: str = "rpy") -> tuple[np.ndarray, np.ndarray]:
    """Analytic Jacobian Ja mapping q̇ to (ṗ, φ̇), and the orientation coordinates φ of the end effector.

    Ja = diag(I, E(φ)⁻¹) J0 (Siciliano eq. 3.66), from the geometric Jacobian's angular rows ω = J0[3:] q̇:

    * ``"rpy"``: roll–pitch–yaw (R = Rz Ry Rx), φ (..., 3), Ja (..., 6, n);
    * ``"zyz"``: ZYZ Euler angles, φ (..., 3), Ja (..., 6, n);
    * ``"quaternion"``: the unit quaternion (w, x, y, z), w ≥ 0 (:func:`quaternion_from_rotation`), φ (..., 4),
      Ja (..., 7, n) with rows (ẋ, ẏ, ż, ẇ, ẋ_q, ẏ_q, ż_q) = (J0[:3], G(φ) J0[3:]) (:func:`quaternion_rate_matrix`);
    * ``"exp"``: exponential coordinates (the rotation vector θu, θ ∈ [0, π], :func:`rotation_log`), φ (..., 3),
      Ja (..., 6, n) = (J0[:3], J_l⁻¹(φ) J0[3:]) (:func:`exp_rate_matrix`).

    φ is extracted as in :func:`denavit.numeric.rpy_from_rotation` / :func:`zyz_from_rotation`. At a representation
    singularity of rpy or zyz (cos pitch = 0, or sin θ = 0) the angle rows are not defined: a warning is issued and
    they are NaN; quaternion and exp rates are defined everywhere (the exp coordinates jump at θ = π).
    """
    if representation not in REPRESENTATIONS:
        raise ValueError(f"unknown representation {representation!r}; choose one of {', '.join(REPRESENTATIONS)}")
    frames = link_transforms(robot, q)
    R = (frames[..., -1, :, :] @ robot.tool_matrix)[..., :3, :3]
    J0 = geometric_jacobian(robot, q, Frame.BASE)
    if representation in ("quaternion", "exp"):
        phi = quaternion_from_rotation(R) if representation == "quaternion" else rotation_log(R)
        E_inv = quaternion_rate_matrix(phi) if representation == "quaternion" else exp_rate_matrix(phi)
        return np.concatenate([J0[..., :3, :], E_inv @ J0[..., 3:, :]], axis=-2), phi
    if representation == "rpy":
        phi = rpy_from_rotation(R)
        E = rpy_rate_matrix(phi)
        bad = np.abs(np.cos(phi[..., 1])) < REPRESENTATION_SINGULAR_TOL
    else:
        phi = zyz_from_rotation(R)
        E = zyz_rate_matrix(phi)
        bad = np.abs(np.sin(phi[..., 1])) < REPRESENTATION_SINGULAR_TOL
    if np.any(bad):
        warnings.warn(f"{representation} representation singularity: angle-rate rows set to NaN", stacklevel=2)
    E = np.where(bad[..., None, None], np.eye(3), E)
    rates = np.linalg.solve(E, J0[..., 3:, :])  # (..., 3, n)
    rates = np.where(bad[..., None, None], np.nan, rates)
    return np.concatenate([J0[..., :3, :], rates], axis=-2), phi


def end_effector_twist(robot: DHRobot, q, qd, frame: Frame | str = Frame.BASE) -> np.ndarray:
    """End-effector twist (v, ω) = J q̇, shape (..., 6), in base (J0) or tool (Je) axes.

    v is the velocity of the end-effector origin [m/s], ω the angular velocity [rad/s].
    """
    q = as_joint_array(q, robot.dof)
    qd = as_joint_array(qd, robot.dof, "qd")
    J = geometric_jacobian(robot, q, frame)
    return np.einsum("...ij,...j->...i", J, qd)
