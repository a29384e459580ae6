"""Craig's link-to-link propagation, numeric and batched: velocities outward, forces inward.

Every intermediate quantity is kept so it can be displayed step by step. Frames are labelled
``"0"``, ``"1"`` … ``"N"`` (one per DH row, fixed rows included) and ``"e"`` (end effector, after ``tool``);
each vector is expressed in the axes of its own frame, at that frame's origin.

Outward (Craig 3rd ed., eqs. 5.45–5.47, modified DH; joint i acts about/along ẑ_i):
    ω_i = R_{i-1,i}ᵀ ω_{i-1} + θ̇_i ẑ,    v_i = R_{i-1,i}ᵀ (v_{i-1} + ω_{i-1} × P_{i-1,i}) + ḋ_i ẑ.
For standard DH the joint acts about/along ẑ_{i-1}, before the row's transform:
    ω_i = R_{i-1,i}ᵀ (ω_{i-1} + θ̇_i ẑ),  v_i = R_{i-1,i}ᵀ (v_{i-1} + ḋ_i ẑ + (ω_{i-1} + θ̇_i ẑ) × P_{i-1,i}).
Inward statics (Craig eqs. 5.80–5.81, no gravity, no inertia):
    f_i = R_{i,i+1} f_{i+1},  n_i = R_{i,i+1} n_{i+1} + P_{i,i+1} × f_i,
and the joint torque is the component of n (revolute) or f (prismatic) along the joint axis, taken in the
frame whose z is that axis ({i} for modified, {i-1} for standard DH).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .._validate import as_joint_array
from ..model import Convention, DHRobot, Frame, JointType
from ._kinematics import joint_values_per_row
from ._transforms import dh_transform

__all__ = ["VelocityPropagation", "ForcePropagation", "velocity_propagation", "propagation_jacobian",
           "force_propagation", "frame_labels"]


@dataclass(frozen=True)
class VelocityPropagation:
    """Outward velocity propagation: ω and v of every frame origin, each in its own axes.

    Attributes
    ----------
    labels : tuple of str
        Frame names ``"0" … "N", "e"``.
    omega, v : ndarray, shape (..., N+2, 3)
        Angular velocity [rad/s] and origin velocity [m/s] of each frame, in that frame's axes.
    R_w_e : ndarray, shape (..., 3, 3)
        End-effector orientation in world axes (to express the final twist in base axes).
    """

    labels: tuple[str, ...]
    omega: np.ndarray
    v: np.ndarray
    R_w_e: np.ndarray

    def twist(self, frame: Frame | str = Frame.TOOL) -> np.ndarray:
        """End-effector twist (v, ω), shape (..., 6), in tool axes or in world/base axes."""
        tw = np.concatenate([self.v[..., -1, :], self.omega[..., -1, :]], axis=-1)
        if Frame(frame) is Frame.BASE:
            R = self.R_w_e
            tw = np.concatenate([np.einsum("...ij,...j->...i", R, tw[..., :3]),
                                 np.einsum("...ij,...j->...i", R, tw[..., 3:])], axis=-1)
        return tw


@dataclass(frozen=True)
class ForcePropagation:
    """Inward static force propagation.

    Attributes
    ----------
    labels : tuple of str
        Frame names ``"0" … "N", "e"``.
    f, n : ndarray, shape (..., N+2, 3)
        Force [N] and moment [N m] the outboard part of the arm receives across frame k, referred to the
        origin of {k}, in {k} axes (for "e": the wrench the end effector exerts on the environment).
    tau : ndarray, shape (..., n)
        Joint torques [N m] / forces [N] that balance it.
    """

    labels: tuple[str, ...]
    f: np.ndarray
    n: np.ndarray
    tau: np.ndarray


def frame_labels(robot: DHRobot) -> tuple[str, ...]:
    """``("0", "1", …, "N", "e")``."""
    return tuple(str(i) for i in range(robot.n_rows + 1)) + ("e",)


def _row_transforms(robot: DHRobot, q: np.ndarray) -> list[np.ndarray]:
    """A_1 … A_N then the tool transform, each (..., 4, 4)."""
    batch = q.shape[:-1]
    out = [np.broadcast_to(dh_transform(robot.convention, th, d, link.a, link.alpha), batch + (4, 4))
           for link, (th, d) in zip(robot.links, joint_values_per_row(robot, q))]
    out.append(np.broadcast_to(robot.tool_matrix, batch + (4, 4)))
    return out


def _mv(R: np.ndarray, x: np.ndarray) -> np.ndarray:
    return np.einsum("...ij,...j->...i", R, x)


def _mtv(R: np.ndarray, x: np.ndarray) -> np.ndarray:
    return np.einsum("...ji,...j->...i", R, x)


def velocity_propagation(robot: DHRobot, q, qd) -> VelocityPropagation:
    """Propagate ω and v from the fixed base {0} (at rest) out to the end effector (see module notes).

    Parameters
    ----------
    robot : DHRobot
    q, qd : array_like, shape (..., n)
        Joint values [rad or m] and rates [rad/s or m/s]; they broadcast against each other.
    """
    q = as_joint_array(q, robot.dof)
    qd = as_joint_array(qd, robot.dof, "qd")
    q, qd = np.broadcast_arrays(q, qd)
    batch = q.shape[:-1]
    z = np.array([0.0, 0.0, 1.0])
    w, v = np.zeros(batch + (3,)), np.zeros(batch + (3,))
    ws, vs = [w], [v]
    std = robot.convention is Convention.STANDARD
    A = _row_transforms(robot, q)
    k = 0
    for i, Ai in enumerate(A):
        link = robot.links[i] if i < robot.n_rows else None
        rate_w = rate_v = 0.0
        if link is not None and link.is_joint:
            rate = qd[..., k, None] * z  # (..., 3)
            rate_w, rate_v = (rate, 0.0) if link.joint is JointType.REVOLUTE else (0.0, rate)
            k += 1
        R, P = Ai[..., :3, :3], Ai[..., :3, 3]
        if std:  # the joint moves before the row's transform (axis z_{i-1})
            w_link = w + rate_w
            v, w = _mtv(R, v + rate_v + np.cross(w_link, P)), _mtv(R, w_link)
        else:  # Craig 5.45, 5.47: the joint moves after it (axis z_i)
            v, w = _mtv(R, v + np.cross(w, P)) + rate_v, _mtv(R, w) + rate_w
        ws.append(np.broadcast_to(w, batch + (3,)))
        vs.append(np.broadcast_to(v, batch + (3,)))
    R_w_e = robot.base_matrix[:3, :3]
    for Ai in A:
        R_w_e = R_w_e @ Ai[..., :3, :3]
    return VelocityPropagation(frame_labels(robot), np.stack(ws, -2), np.stack(vs, -2),
                               np.broadcast_to(R_w_e, batch + (3, 3)).copy())


def propagation_jacobian(robot: DHRobot, q, frame: Frame | str = Frame.TOOL) -> np.ndarray:
    """Jacobian (..., 6, n) from velocity propagation with unit joint rates; tool axes (Je) by default.

    Column k is the end-effector twist (v, ω) for q̇ = e_k (Craig sec. 5.7: the Jacobian "falls out" of
    the propagation written in the last frame). ``frame="base"`` rotates it to world axes (J0).
    """
    q = as_joint_array(q, robot.dof)
    eye = np.eye(robot.dof)
    prop = velocity_propagation(robot, q[..., None, :], eye)  # batch (..., n) over unit rates
    tw = prop.twist(frame)  # (..., n, 6)
    return np.swapaxes(tw, -1, -2)


def force_propagation(robot: DHRobot, q, wrench, frame: Frame | str = Frame.TOOL) -> ForcePropagation:
    """Joint torques balancing an end-effector wrench, by inward force propagation (see module notes).

    Parameters
    ----------
    robot : DHRobot
    q : array_like, shape (..., n)
    wrench : array_like, shape (..., 6) or (..., 3)
        (f, n) exerted by the end effector on the environment, at the end-effector origin [N, N m];
        three values mean a pure force.
    frame : Frame or {"base", "tool"}
        Axes the wrench is given in.
    """
    from ._statics import as_wrench

    q = as_joint_array(q, robot.dof)
    F = as_wrench(wrench)
    batch = np.broadcast_shapes(q.shape[:-1], F.shape[:-1])
    q, F = np.broadcast_to(q, batch + q.shape[-1:]), np.broadcast_to(F, batch + (6,))
    A = _row_transforms(robot, q)
    f, n = F[..., :3], F[..., 3:]
    if Frame(frame) is Frame.BASE:  # to tool axes
        R_w_e = robot.base_matrix[:3, :3]
        for Ai in A:
            R_w_e = R_w_e @ Ai[..., :3, :3]
        f, n = _mtv(R_w_e, f), _mtv(R_w_e, n)
    fs, ns = [f], [n]
    for Ai in reversed(A):  # frame {k+1} → {k}
        R, P = Ai[..., :3, :3], Ai[..., :3, 3]
        f = _mv(R, f)
        n = _mv(R, n) + np.cross(P, f)
        fs.append(f)
        ns.append(n)
    fs.reverse()
    ns.reverse()
    f_all, n_all = np.stack(fs, -2), np.stack(ns, -2)  # (..., N+2, 3)
    shift = 0 if robot.convention is Convention.STANDARD else 1
    taus = []
    for r, jt in zip(robot.joint_rows, robot.joint_types):
        src = n_all if jt is JointType.REVOLUTE else f_all
        taus.append(src[..., r + shift, 2])
    return ForcePropagation(frame_labels(robot), f_all, n_all, np.stack(taus, -1))
