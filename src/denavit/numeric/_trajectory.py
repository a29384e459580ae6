"""Trajectories: joint-space quintic and trapezoidal profiles, and a straight-line Cartesian path.

Shapes follow the package rule, batch axes first: endpoints ``(..., n)``, time samples ``(k,)``,
results ``(..., k, n)``.  Every result is a frozen :class:`JointTrajectory` (times, positions,
velocities, accelerations), so a caller never has to remember which array is which.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .._validate import as_joint_array
from ..errors import ShapeError
from ..model import DHRobot
from ._jacobians import geometric_jacobian
from ._kinematics import forward_kinematics

__all__ = [
    "JointTrajectory",
    "CartesianPath",
    "quintic_trajectory",
    "trapezoidal_trajectory",
    "cartesian_path",
]

DEFAULT_SAMPLES = 50
IK_TOL = 1e-9  # target error norm [m, rad] at which a waypoint counts as reached
IK_MAX_ITERATIONS = 100
IK_DAMPING = 1e-3  # λ of the damped least-squares step [m]


@dataclass(frozen=True)
class JointTrajectory:
    """Samples of a joint trajectory.

    Attributes
    ----------
    t : ndarray, shape (k,)
        Sample times [s].
    q, qd, qdd : ndarray, shape (..., k, n)
        Positions [rad or m], velocities [·/s] and accelerations [·/s²].
    """

    t: np.ndarray
    q: np.ndarray
    qd: np.ndarray
    qdd: np.ndarray

    @property
    def duration(self) -> float:
        return float(self.t[-1] - self.t[0])


@dataclass(frozen=True)
class CartesianPath:
    """A straight-line end-effector path followed through inverse kinematics.

    Attributes
    ----------
    t : ndarray, shape (k,)
        Sample times [s].
    q : ndarray, shape (k, n)
        Joint values at each waypoint (each solved from the previous one).
    targets : ndarray, shape (k, 4, 4)
        The commanded poses on the line (world frame).
    position_error, orientation_error : ndarray, shape (k,)
        Remaining error of FK(q) against the target [m] and [rad] (orientation 0 when not tracked).
    success : bool
        True when every waypoint met the tolerance.
    orientation_tracked : bool
        Whether orientation was interpolated and tracked (else position only).
    """

    t: np.ndarray
    q: np.ndarray
    targets: np.ndarray
    position_error: np.ndarray
    orientation_error: np.ndarray
    success: bool
    orientation_tracked: bool


def _times(t, duration: float | None) -> np.ndarray:
    if t is None:
        t = DEFAULT_SAMPLES
    if np.ndim(t) == 0:
        k = int(t)
        if k < 2:
            raise ShapeError(f"need at least 2 samples, got {k}")
        if duration is None or not np.isfinite(duration) or duration <= 0:
            raise ShapeError(f"duration must be a positive number of seconds, got {duration!r}")
        return np.linspace(0.0, float(duration), k)
    t = np.asarray(t, dtype=float)
    if t.ndim != 1 or t.size < 1 or not np.all(np.isfinite(t)):
        raise ShapeError(f"t: expected a 1-D array of finite sample times, got shape {t.shape}")
    return t


def quintic_trajectory(q0, q1, t=None, *, duration: float = 1.0, qd0=0.0, qd1=0.0, qdd0=0.0,
                       qdd1=0.0) -> JointTrajectory:
    """Joint-space quintic polynomial from ``q0`` to ``q1`` with given boundary rates.

    Each joint follows q(τ) = Σ_{j=0}^{5} c_j τ^j on τ ∈ [0, T], the unique quintic meeting
    position, velocity and acceleration at both ends.

    Parameters
    ----------
    q0, q1 : array_like, shape (..., n)
        Start and end joint values [rad or m].
    t : int or array_like, shape (k,), optional
        Number of evenly spaced samples on [0, duration] (default 50), or the sample times [s]
        (times outside [0, duration] extrapolate the polynomial).
    duration : float
        T [s].
    qd0, qd1, qdd0, qdd1 : array_like, broadcastable to (..., n)
        Boundary velocities and accelerations (default 0: rest to rest).

    Returns
    -------
    JointTrajectory
        ``q``, ``qd``, ``qdd`` of shape (..., k, n).

    Notes
    -----
    With h = q1 − q0 the coefficients are c0 = q0, c1 = q̇0, c2 = q̈0/2 and

    .. math::
        c_3 = \\frac{20h - (8\\dot q_1 + 12\\dot q_0)T - (3\\ddot q_0 - \\ddot q_1)T^2}{2T^3},\\quad
        c_4 = \\frac{-30h + (14\\dot q_1 + 16\\dot q_0)T + (3\\ddot q_0 - 2\\ddot q_1)T^2}{2T^4},\\quad
        c_5 = \\frac{12h - 6(\\dot q_1 + \\dot q_0)T - (\\ddot q_0 - \\ddot q_1)T^2}{2T^5}.

    References
    ----------
    B. Siciliano et al., *Robotics: Modelling, Planning and Control*, Springer 2009, §4.2.1 (eq. 4.5);
    L. Biagiotti & C. Melchiorri, *Trajectory Planning for Automatic Machines and Robots*, 2008, §2.1.7.
    """
    q0 = np.asarray(q0, dtype=float)
    n = q0.shape[-1] if q0.ndim else 1
    q0 = as_joint_array(q0, n, "q0")
    q1 = as_joint_array(q1, n, "q1")
    qd0, qd1, qdd0, qdd1 = (np.broadcast_to(np.asarray(v, dtype=float), np.broadcast_shapes(q0.shape, q1.shape))
                            for v in (qd0, qd1, qdd0, qdd1))
    if duration is None or not np.isfinite(duration) or duration <= 0:
        raise ShapeError(f"duration must be a positive number of seconds, got {duration!r}")
    T = float(duration)
    times = _times(t, T)
    h = q1 - q0  # (..., n)
    c = [q0 + 0 * h, qd0 + 0 * h, qdd0 / 2,
         (20 * h - (8 * qd1 + 12 * qd0) * T - (3 * qdd0 - qdd1) * T**2) / (2 * T**3),
         (-30 * h + (14 * qd1 + 16 * qd0) * T + (3 * qdd0 - 2 * qdd1) * T**2) / (2 * T**4),
         (12 * h - 6 * (qd1 + qd0) * T - (qdd0 - qdd1) * T**2) / (2 * T**5)]
    C = np.stack(c, axis=-2)  # (..., 6, n)
    tau = times[:, None]  # (k, 1)
    P = np.concatenate([tau**j for j in range(6)], axis=1)  # (k, 6): 1, τ, …, τ⁵
    dP = np.concatenate([np.zeros_like(tau)] + [j * tau ** (j - 1) for j in range(1, 6)], axis=1)
    ddP = np.concatenate([np.zeros_like(tau)] * 2 + [j * (j - 1) * tau ** (j - 2) for j in range(2, 6)], axis=1)
    return JointTrajectory(times, P @ C, dP @ C, ddP @ C)  # (k, 6) @ (..., 6, n) → (..., k, n)


def _trapezoid_duration(h: np.ndarray, qd_max: np.ndarray, qdd_max: np.ndarray) -> float:
    """Shortest common duration of rest-to-rest trapezoids under per-joint velocity/acceleration limits."""
    dist = np.abs(h)
    full = dist >= qd_max**2 / qdd_max  # the joint reaches cruise velocity
    t_j = np.where(full, dist / qd_max + qd_max / qdd_max, 2 * np.sqrt(dist / qdd_max))
    return float(np.max(t_j)) if t_j.size else 0.0


def _trapezoid_cruise(h, T: float, qd_max, qdd_max, cruise_ratio: float) -> np.ndarray:
    """Cruise speed |V| of each joint for duration T (from limits if given, else ratio·|h|/T)."""
    dist = np.abs(h)
    if qdd_max is None:
        return cruise_ratio * dist / T
    # slowest-acceleration trapezoid that still finishes in T: |h| = V (T − V/A)  →  V = (AT − √(A²T² − 4A|h|))/2
    A = np.broadcast_to(qdd_max, dist.shape)
    disc = np.maximum(A**2 * T**2 - 4 * A * dist, 0.0)
    return (A * T - np.sqrt(disc)) / 2


def trapezoidal_trajectory(q0, q1, t=None, *, duration: float | None = None, qd_max=None, qdd_max=None,
                           cruise_ratio: float = 1.5) -> JointTrajectory:
    """Joint-space trapezoidal velocity profile (linear segment with parabolic blends), rest to rest.

    All joints start and stop together.  Give either ``duration`` (each joint then cruises at
    ``cruise_ratio · |q1 − q0| / T``, ratio in (1, 2]) or the limits ``qd_max`` and ``qdd_max`` (the
    duration is then the shortest one all joints can meet, and each joint uses the smallest
    acceleration that still finishes in time, so no limit is exceeded).

    Parameters
    ----------
    q0, q1 : array_like, shape (n,)
        Start and end joint values [rad or m].
    t : int or array_like, shape (k,), optional
        Number of samples on [0, T] (default 50) or sample times [s] (clamped to [0, T]).
    duration : float, optional
        T [s].
    qd_max, qdd_max : array_like, broadcastable to (n,), optional
        Velocity and acceleration limits (both or neither; used when ``duration`` is None).
    cruise_ratio : float
        Cruise velocity as a multiple of the mean velocity when ``duration`` is given.

    Returns
    -------
    JointTrajectory
        q, qd, qdd of shape (k, n); qd is V on the cruise, qdd is ±V/t_b in the blends.

    Notes
    -----
    With blend time t_b = T − |h|/V and A = V/t_b:
    q = q0 + s·A t²/2 for t < t_b; q0 + s·V(t − t_b/2) on the cruise; q1 − s·A (T − t)²/2 at the end,
    where s = sign(h) (Spong, Hutchinson & Vidyasagar, *Robot Modeling and Control*, 2006, §5.5.2).
    """
    q0 = np.asarray(q0, dtype=float)
    n = q0.shape[-1] if q0.ndim else 1
    q0 = as_joint_array(q0, n, "q0")
    q1 = as_joint_array(q1, n, "q1")
    if q0.ndim != 1 or q1.ndim != 1:
        raise ShapeError(f"trapezoidal_trajectory takes one pair of (n,) endpoints, got {q0.shape} and {q1.shape}")
    h = q1 - q0
    if duration is None:
        if qd_max is None or qdd_max is None:
            raise ShapeError("give duration, or both qd_max and qdd_max")
        qd_max = np.broadcast_to(np.asarray(qd_max, dtype=float), h.shape)
        qdd_max = np.broadcast_to(np.asarray(qdd_max, dtype=float), h.shape)
        if np.any(~(qd_max > 0)) or np.any(~(qdd_max > 0)):
            raise ShapeError("qd_max and qdd_max must be positive")
        duration = _trapezoid_duration(h, qd_max, qdd_max)
        if duration == 0.0:
            duration = 1.0
    else:
        qdd_max = None
        if not 1.0 < cruise_ratio <= 2.0:
            raise ShapeError(f"cruise_ratio must be in (1, 2], got {cruise_ratio}")
    T = float(duration)
    times = np.clip(_times(t, T), 0.0, T)
    V = _trapezoid_cruise(h, T, qd_max, qdd_max, cruise_ratio)  # (n,)
    moving = np.abs(h) > 0
    Vs = np.where(moving, V, 1.0)
    tb = np.where(moving, T - np.abs(h) / Vs, T / 2)  # (n,)
    A = np.where(moving, Vs / np.where(tb > 0, tb, 1.0), 0.0)
    s = np.sign(h)
    tt = times[:, None]  # (k, 1)
    acc, dec = tt < tb, tt > T - tb
    q = np.where(acc, q0 + s * A * tt**2 / 2,
                 np.where(dec, q1 - s * A * (T - tt) ** 2 / 2, q0 + s * V * (tt - tb / 2)))
    qd = np.where(acc, s * A * tt, np.where(dec, s * A * (T - tt), s * V))
    qdd = np.where(acc, s * A, np.where(dec, -s * A, 0.0))
    return JointTrajectory(times, q, qd, qdd)


def _rotation_log(R: np.ndarray) -> np.ndarray:
    """Rotation vector ω θ of a rotation matrix (3,) (Rodrigues inverse, robust near 0 and π)."""
    c = np.clip((np.trace(R) - 1) / 2, -1.0, 1.0)
    angle = np.arccos(c)
    w = np.array([R[2, 1] - R[1, 2], R[0, 2] - R[2, 0], R[1, 0] - R[0, 1]])
    if angle < 1e-7:
        return w / 2
    if np.pi - angle < 1e-4:  # near π: axis from the diagonal of (R + I)/2 = a aᵀ
        B = (R + np.eye(3)) / 2
        k = int(np.argmax(np.diag(B)))
        axis = B[:, k] / np.sqrt(B[k, k])
        if w @ axis < 0:
            axis = -axis
        return axis * angle
    return w * angle / (2 * np.sin(angle))


def _rotation_exp(v: np.ndarray) -> np.ndarray:
    angle = float(np.linalg.norm(v))
    if angle < 1e-12:
        return np.eye(3)
    k = v / angle
    K = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
    return np.eye(3) + np.sin(angle) * K + (1 - np.cos(angle)) * K @ K  # Rodrigues


def _pose_error(T: np.ndarray, target: np.ndarray, orientation: bool) -> np.ndarray:
    e_p = target[:3, 3] - T[:3, 3]
    if not orientation:
        return e_p
    e_o = T[:3, :3] @ _rotation_log(T[:3, :3].T @ target[:3, :3])  # world axes
    return np.concatenate([e_p, e_o])


def _dls_solve(robot: DHRobot, target: np.ndarray, q: np.ndarray, orientation: bool) -> np.ndarray:
    """Damped least-squares IK from a warm start (Wampler 1986; Buss 2004, eq. 11)."""
    rows = slice(0, 6) if orientation else slice(0, 3)
    for _ in range(IK_MAX_ITERATIONS):
        e = _pose_error(forward_kinematics(robot, q), target, orientation)
        if np.linalg.norm(e) < IK_TOL:
            break
        J = geometric_jacobian(robot, q)[rows]  # (m, n)
        JJt = J @ J.T + IK_DAMPING**2 * np.eye(J.shape[0])
        q = q + J.T @ np.linalg.solve(JJt, e)
    return q


def cartesian_path(robot: DHRobot, q0, goal, t=None, *, duration: float = 1.0,
                   orientation: bool | None = None) -> CartesianPath:
    """Straight-line Cartesian motion from FK(q0) to ``goal``, followed by inverse kinematics.

    The end-effector origin moves on the segment p(s) = p0 + s (p1 − p0); the orientation turns
    about one fixed axis, R(s) = R0 exp(s log(R0ᵀ R1)) (geodesic, SLERP); s(t) is a rest-to-rest
    quintic in time.  Each waypoint is solved by damped least squares warm-started from the
    previous one, so the joint path is continuous.

    Parameters
    ----------
    robot : DHRobot
    q0 : array_like, shape (n,)
        Start configuration.
    goal : array_like, shape (n,) or (4, 4)
        End configuration, or end pose T_w_e.
    t : int or array_like, shape (k,), optional
        Number of samples (default 50) or sample times on [0, duration].
    duration : float
        [s].
    orientation : bool, optional
        Track orientation too.  Default: only when the arm has 6 or more joints (with fewer, the
        orientation along a straight line is generally not reachable and would pull the arm off it).

    Returns
    -------
    CartesianPath

    References
    ----------
    C. W. Wampler, "Manipulator inverse kinematic solutions based on vector formulations and damped
    least-squares methods", IEEE Trans. SMC 16(1), 1986; K. Shoemake, "Animating rotation with
    quaternion curves", SIGGRAPH 1985 (geodesic interpolation).
    """
    q0 = as_joint_array(q0, robot.dof, "q0")
    if q0.ndim != 1:
        raise ShapeError(f"q0: expected shape ({robot.dof},), got {q0.shape}")
    goal = np.asarray(goal, dtype=float)
    if goal.shape == (4, 4):
        T1 = goal
    else:
        T1 = forward_kinematics(robot, as_joint_array(goal, robot.dof, "goal"))
    if orientation is None:
        orientation = robot.dof >= 6
    T0 = forward_kinematics(robot, q0)
    s_traj = quintic_trajectory([0.0], [1.0], t, duration=duration)
    times, s = s_traj.t, s_traj.q[:, 0]
    w = _rotation_log(T0[:3, :3].T @ T1[:3, :3])
    targets = np.tile(np.eye(4), (len(s), 1, 1))
    targets[:, :3, 3] = T0[:3, 3] + s[:, None] * (T1[:3, 3] - T0[:3, 3])  # (k, 3)
    for i, si in enumerate(s):
        targets[i, :3, :3] = T0[:3, :3] @ _rotation_exp(si * w)
    qs = np.empty((len(s), robot.dof))
    q = q0.copy()
    for i in range(len(s)):
        q = _dls_solve(robot, targets[i], q, orientation)
        qs[i] = q
    T = forward_kinematics(robot, qs)  # (k, 4, 4)
    pos_err = np.linalg.norm(T[:, :3, 3] - targets[:, :3, 3], axis=-1)
    ori_err = np.array([np.linalg.norm(_rotation_log(Ti[:3, :3].T @ Gi[:3, :3])) for Ti, Gi in zip(T, targets)])
    if not orientation:
        ori_err = np.zeros_like(ori_err)
    ok = bool(np.all(pos_err < 1e-6) and np.all(ori_err < 1e-6))
    return CartesianPath(times, qs, targets, pos_err, ori_err, ok, bool(orientation))
