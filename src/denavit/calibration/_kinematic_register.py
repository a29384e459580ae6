"""A first guess of the base when the measurements are taken in a frame far from the robot's (a laser tracker's).

The corrections of the error model are small motions from the nominal arm, and Levenberg–Marquardt started at
zero finds them only when they are small.  Measurements in an instrument's own frame can be metres and any
rotation away; the base is then first registered: the rigid motion (R, t) that best maps the nominal arm's
end-effector positions P_k onto the measured ones Q_k in least squares,

    min Σ ||R P_k + t − Q_k||²,   R = U diag(1, 1, det(U Vᵀ)) Vᵀ,  U S Vᵀ = Σ (Q_k − Q̄)(P_k − P̄)ᵀ,  t = Q̄ − R P̄

(Kabsch 1976; Umeyama 1991, eqs. 39–42, with the reflection excluded), and the nominal base becomes
(R, t) · base.  Only done when that motion is larger than a base error could plausibly be (:data:`REGISTER_ANGLE`,
:data:`REGISTER_DISTANCE`), so a nominal base that is nearly right stays the reference of the base corrections.
"""

from __future__ import annotations

import numpy as np

from ..model import DHRobot
from ..numeric import forward_kinematics

__all__ = ["registered_base", "registered_start", "rigid_fit", "REGISTER_ANGLE", "REGISTER_DISTANCE",
           "REGISTERED_NOTE"]

#: The base is registered first when the rigid fit turns the arm by more than this [rad] ...
REGISTER_ANGLE = np.radians(5.0)
#: ... or moves some measured point by more than this [m].
REGISTER_DISTANCE = 0.05


def rigid_fit(P: np.ndarray, Q: np.ndarray) -> np.ndarray | None:
    """The 4×4 rigid motion G minimising Σ ||G·P_k − Q_k||² over points P, Q of shape (m, 3), or None when the
    points P do not span a plane (3 non-collinear points are needed for a unique rotation)."""
    P_bar, Q_bar = P.mean(axis=0), Q.mean(axis=0)
    H = (Q - Q_bar).T @ (P - P_bar)  # (3, 3) = Σ (Q_k − Q̄)(P_k − P̄)ᵀ
    U, S, Vt = np.linalg.svd(H)
    if S[1] <= 1e-9 * max(S[0], 1e-300):
        return None
    D = np.diag([1.0, 1.0, np.sign(np.linalg.det(U @ Vt)) or 1.0])
    G = np.eye(4)
    G[:3, :3] = U @ D @ Vt
    G[:3, 3] = Q_bar - G[:3, :3] @ P_bar
    return G


def registered_base(model_positions: np.ndarray, measured_positions: np.ndarray,
                    base: np.ndarray) -> np.ndarray | None:
    """The registered base G · base when the rigid fit G of the nominal positions onto the measured ones is
    beyond :data:`REGISTER_ANGLE` or :data:`REGISTER_DISTANCE`; None when it is not (or the points are
    degenerate)."""
    G = rigid_fit(model_positions, measured_positions)
    if G is None:
        return None
    angle = np.arccos(np.clip((np.trace(G[:3, :3]) - 1.0) / 2.0, -1.0, 1.0))
    moved = np.linalg.norm(model_positions @ G[:3, :3].T + G[:3, 3] - model_positions, axis=1).max()
    if angle <= REGISTER_ANGLE and moved <= REGISTER_DISTANCE:
        return None
    out = G @ base
    out[3] = (0.0, 0.0, 0.0, 1.0)
    return out


REGISTERED_NOTE = ("the measurements are far from the nominal base frame: the base was first registered by a rigid "
                   "fit of the positions (Kabsch), and base_x ... base_rz are corrections of that registered base")


def registered_start(robot: DHRobot, q: np.ndarray, positions: np.ndarray) -> DHRobot:
    """``robot``, or ``robot`` with its base registered to the measured positions when they are far from it."""
    B = registered_base(forward_kinematics(robot, q)[:, :3, 3], positions, robot.base_matrix)
    if B is None:
        return robot
    return robot.replace(base=B, symbols=tuple((k, v) for k, v in robot.symbols if not k.startswith("base.")))
