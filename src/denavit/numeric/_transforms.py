"""Homogeneous transforms and small rotation helpers, batched over leading axes (..., 4, 4)."""

from __future__ import annotations

import numpy as np

from ..chain import dh_transform  # the DH row matrix lives with the chain; re-exported here

__all__ = [
    "dh_transform",
    "inverse_transform",
    "skew",
    "adjoint",
    "rotx",
    "roty",
    "rotz",
    "transform_from_xyz_rpy",
    "rpy_from_rotation",
    "zyz_from_rotation",
    "rotation_from_rpy",
    "rotation_from_zyz",
    "rotation_log",
    "quaternion_from_rotation",
]


def inverse_transform(T: np.ndarray) -> np.ndarray:
    """Inverse of rigid transforms (..., 4, 4): [Rᵀ, −Rᵀp; 0, 1]."""
    T = np.asarray(T, dtype=float)
    out = np.zeros_like(T)
    Rt = np.swapaxes(T[..., :3, :3], -1, -2)
    out[..., :3, :3] = Rt
    out[..., :3, 3] = -np.einsum("...ij,...j->...i", Rt, T[..., :3, 3])
    out[..., 3, 3] = 1.0
    return out


def skew(v: np.ndarray) -> np.ndarray:
    """Skew-symmetric matrices (..., 3, 3) with skew(v) @ w = v × w."""
    v = np.asarray(v, dtype=float)
    z = np.zeros(v.shape[:-1])
    x, y, w = v[..., 0], v[..., 1], v[..., 2]
    return np.stack(
        [np.stack([z, -w, y], -1), np.stack([w, z, -x], -1), np.stack([-y, x, z], -1)], axis=-2
    )


def adjoint(T: np.ndarray) -> np.ndarray:
    """Adjoint (..., 6, 6) mapping twists (v, ω) in frame {b} to frame {a} for T = T_a_b."""
    T = np.asarray(T, dtype=float)
    R, p = T[..., :3, :3], T[..., :3, 3]
    out = np.zeros(T.shape[:-2] + (6, 6))
    out[..., :3, :3] = R
    out[..., 3:, 3:] = R
    out[..., :3, 3:] = skew(p) @ R
    return out


def _rot(axis: int, angle) -> np.ndarray:
    angle = np.asarray(angle, dtype=float)
    c, s = np.cos(angle), np.sin(angle)
    R = np.zeros(angle.shape + (3, 3))
    i, j = [(1, 2), (2, 0), (0, 1)][axis]
    R[..., axis, axis] = 1.0
    R[..., i, i], R[..., j, j] = c, c
    R[..., i, j], R[..., j, i] = -s, s
    return R


def rotx(angle) -> np.ndarray:
    """Rotation matrices (..., 3, 3) about x."""
    return _rot(0, angle)


def roty(angle) -> np.ndarray:
    """Rotation matrices (..., 3, 3) about y."""
    return _rot(1, angle)


def rotz(angle) -> np.ndarray:
    """Rotation matrices (..., 3, 3) about z."""
    return _rot(2, angle)


def rotation_from_rpy(rpy) -> np.ndarray:
    """R = Rz(yaw) Ry(pitch) Rx(roll) from rpy = (roll, pitch, yaw), shape (..., 3) → (..., 3, 3)."""
    rpy = np.asarray(rpy, dtype=float)
    return rotz(rpy[..., 2]) @ roty(rpy[..., 1]) @ rotx(rpy[..., 0])


def rotation_from_zyz(zyz) -> np.ndarray:
    """R = Rz(φ) Ry(θ) Rz(ψ) from (φ, θ, ψ), shape (..., 3) → (..., 3, 3)."""
    zyz = np.asarray(zyz, dtype=float)
    return rotz(zyz[..., 0]) @ roty(zyz[..., 1]) @ rotz(zyz[..., 2])


def transform_from_xyz_rpy(xyz, rpy) -> np.ndarray:
    """Homogeneous transform (..., 4, 4) from a translation and roll-pitch-yaw angles."""
    xyz = np.asarray(xyz, dtype=float)
    R = rotation_from_rpy(rpy)
    shape = np.broadcast_shapes(xyz.shape[:-1], R.shape[:-2])
    T = np.zeros(shape + (4, 4))
    T[..., :3, :3] = R
    T[..., :3, 3] = xyz
    T[..., 3, 3] = 1.0
    return T


def rpy_from_rotation(R: np.ndarray) -> np.ndarray:
    """Roll, pitch, yaw (..., 3) with R = Rz(yaw) Ry(pitch) Rx(roll); pitch in [−π/2, π/2].

    At pitch = ±π/2 (gimbal lock) roll is set to 0 and yaw carries the whole rotation.
    """
    R = np.asarray(R, dtype=float)
    pitch = np.arctan2(-R[..., 2, 0], np.hypot(R[..., 0, 0], R[..., 1, 0]))
    lock = np.hypot(R[..., 0, 0], R[..., 1, 0]) < 1e-10
    roll = np.where(lock, 0.0, np.arctan2(R[..., 2, 1], R[..., 2, 2]))
    yaw = np.where(lock, np.arctan2(-R[..., 0, 1], R[..., 1, 1]), np.arctan2(R[..., 1, 0], R[..., 0, 0]))
    return np.stack([roll, pitch, yaw], axis=-1)


def zyz_from_rotation(R: np.ndarray) -> np.ndarray:
    """Euler angles (φ, θ, ψ) (..., 3) with R = Rz(φ) Ry(θ) Rz(ψ), θ in [0, π].

    At θ = 0 or π only φ ± ψ is defined; φ is set to 0.
    """
    R = np.asarray(R, dtype=float)
    s = np.hypot(R[..., 0, 2], R[..., 1, 2])
    theta = np.arctan2(s, R[..., 2, 2])
    lock = s < 1e-10
    phi = np.where(lock, 0.0, np.arctan2(R[..., 1, 2], R[..., 0, 2]))
    psi_free = np.arctan2(R[..., 1, 0], np.where(R[..., 2, 2] > 0, R[..., 0, 0], -R[..., 0, 0]))
    psi = np.where(lock, psi_free, np.arctan2(R[..., 2, 1], -R[..., 2, 0]))
    return np.stack([phi, theta, psi], axis=-1)


def rotation_log(R: np.ndarray) -> np.ndarray:
    """Rotation vector θ·u of rotation matrices (..., 3, 3) → (..., 3), θ in [0, π].

    Rodrigues inverted: sin θ [u]× = (R − Rᵀ)/2, cos θ = (tr R − 1)/2; near θ = π the axis is taken from the
    symmetric part, u uᵀ = (R + Rᵀ)/2 − cos θ I) / (1 − cos θ) (Murray, Li & Sastry 1994, Sec. 2.2).
    """
    R = np.asarray(R, dtype=float)
    tr = R[..., 0, 0] + R[..., 1, 1] + R[..., 2, 2]
    cos = np.clip((tr - 1.0) / 2.0, -1.0, 1.0)
    theta = np.arccos(cos)
    v = np.stack([R[..., 2, 1] - R[..., 1, 2], R[..., 0, 2] - R[..., 2, 0], R[..., 1, 0] - R[..., 0, 1]], -1)
    sin = np.sin(theta)
    with np.errstate(invalid="ignore", divide="ignore"):
        factor = np.where(theta < 1e-6, 0.5 + theta**2 / 12.0, theta / (2.0 * np.where(sin == 0, 1, sin)))
    out = v * factor[..., None]
    near_pi = cos < -0.9
    if np.any(near_pi):
        Rn, cn, vn, tn = R[near_pi], cos[near_pi], v[near_pi], theta[near_pi]
        S = 0.5 * (Rn + np.swapaxes(Rn, -1, -2)) - cn[:, None, None] * np.eye(3)
        S = S / (1.0 - cn)[:, None, None]  # u uᵀ
        k = np.argmax(np.diagonal(S, axis1=-2, axis2=-1), axis=-1)
        u = S[np.arange(len(k)), :, k]
        u = u / np.linalg.norm(u, axis=-1, keepdims=True)
        sign = np.where(np.einsum("...i,...i->...", u, vn) < 0, -1.0, 1.0)
        out[near_pi] = u * (sign * tn)[:, None]
    return out


def quaternion_from_rotation(R: np.ndarray) -> np.ndarray:
    """Unit quaternion (w, x, y, z), w ≥ 0, of rotation matrices (..., 3, 3) → (..., 4).

    Shepperd's method (Shepperd 1978): of 4w², 4x², 4y², 4z² (1 ± the diagonal entries) the largest is the
    pivot p, and the row of 4 p·(w, x, y, z) it gives is normalised; the sign is then chosen so that w ≥ 0.
    """
    R = np.asarray(R, dtype=float)
    r00, r01, r02 = R[..., 0, 0], R[..., 0, 1], R[..., 0, 2]
    r10, r11, r12 = R[..., 1, 0], R[..., 1, 1], R[..., 1, 2]
    r20, r21, r22 = R[..., 2, 0], R[..., 2, 1], R[..., 2, 2]
    rows = np.stack([  # row k: 4 q_k (w, x, y, z)
        np.stack([1 + r00 + r11 + r22, r21 - r12, r02 - r20, r10 - r01], -1),
        np.stack([r21 - r12, 1 + r00 - r11 - r22, r01 + r10, r02 + r20], -1),
        np.stack([r02 - r20, r01 + r10, 1 - r00 + r11 - r22, r12 + r21], -1),
        np.stack([r10 - r01, r02 + r20, r12 + r21, 1 - r00 - r11 + r22], -1)], -2)  # (..., 4, 4)
    k = np.argmax(np.diagonal(rows, axis1=-2, axis2=-1), axis=-1)
    quat = np.take_along_axis(rows, k[..., None, None], axis=-2)[..., 0, :]
    quat = quat / np.linalg.norm(quat, axis=-1, keepdims=True)
    return np.where(quat[..., :1] < 0, -quat, quat)
