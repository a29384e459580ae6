"""Rigid-body dynamics of a DH arm, batched over leading axes: RNEA, CRBA, Christoffel C, gravity, FD.

Everything is computed in world axes from the frames of :func:`link_transforms` (base transform applied),
so gravity ``robot.gravity`` (world frame) is used as given.

Bodies and pieces
-----------------
Body k is the rigid body moved by joint k.  DH frame {r} of row r is attached to the body of the last
joint at or before row r (a fixed row is rigid with the row before it, in both conventions).  Each row
with a :class:`~denavit.model.LinkInertia` is a *piece* (mass, COM, inertia about the COM, in frame {r})
of its body; rows before the first joint belong to the fixed base and do not enter the dynamics; rows
without inertia are massless.  Motor (rotor) inertia adds to M's diagonal; friction is
τ_f = viscous·q̇ + coulomb·sign(q̇).

Spatial vectors are written in world axes with the world origin as reference point, ordered (v, ω)
for motions and (f, n) for forces, as in the rest of denavit.

References
----------
R. Featherstone, *Rigid Body Dynamics Algorithms*, Springer 2008, ch. 5 (RNEA) and 6 (CRBA).
J. J. Craig, *Introduction to Robotics*, 3rd ed., sec. 6.5 (iterative Newton–Euler).
M. W. Spong, S. Hutchinson, M. Vidyasagar, *Robot Modeling and Control*, 2006, sec. 7.3 (Christoffel symbols).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .._threads import split_call
from .._validate import as_joint_array
from ..errors import ModelError
from ..model import DHRobot, JointType, inertial_rows
from ._dynamics_fast import frames, joint_columns, ldl_solve, mass_matrix_kernel, plan, rnea_kernel, to_array
from ._jacobians import joint_axes
from ._kinematics import link_transforms

__all__ = [
    "rnea",
    "mass_matrix",
    "coriolis_matrix",
    "coriolis_vector",
    "gravity_torques",
    "friction_torques",
    "forward_dynamics",
    "kinetic_energy",
    "potential_energy",
    "mass_matrix_derivatives",
]


SINGULAR_TOL = 1e-12  # relative size of the smallest Cholesky pivot² below which M counts as singular


@dataclass(frozen=True)
class _Piece:
    row: int  # DH row whose frame holds the data
    body: int  # joint index (0-based) that moves it
    mass: float
    com: np.ndarray  # (3,) in frame {row}
    inertia: np.ndarray  # (3, 3) about the COM, frame {row} axes


def _pieces(robot: DHRobot) -> list[_Piece]:
    """Inertial pieces attached to moving bodies (see module notes)."""
    return [_Piece(r, body, li.mass, np.array(li.com, dtype=float), li.inertia_matrix)
            for r, body, li in inertial_rows(robot)]


def require_dynamics(robot: DHRobot) -> None:
    """Raise ModelError when the robot carries no inertial data on any moving row."""
    if not any(p.mass > 0 or np.any(p.inertia) for p in _pieces(robot)):
        raise ModelError(
            f"robot {robot.name!r} has no inertial data: add 'inertia: {{mass, com, inertia}}' to its joint rows"
        )


def friction_torques(robot: DHRobot, qd) -> np.ndarray:
    """Joint friction τ_f = viscous·q̇ + coulomb·sign(q̇), shape (..., n) [N m or N]."""
    qd = as_joint_array(qd, robot.dof, "qd")
    fv = np.array([link.inertia.viscous if link.inertia else 0.0 for link in robot.joints])
    fc = np.array([link.inertia.coulomb if link.inertia else 0.0 for link in robot.joints])
    return fv * qd + fc * np.sign(qd)


class _State:
    """World-frame kinematics shared by the algorithms: joint axes, pieces' COM and inertia."""

    def __init__(self, robot: DHRobot, q: np.ndarray) -> None:
        frames = link_transforms(robot, q)  # (..., N+1, 4, 4)
        self.z, self.o = joint_axes(robot, frames)  # (..., n, 3) each
        self.revolute = np.array([t is JointType.REVOLUTE for t in robot.joint_types])
        pieces = _pieces(robot)
        self.body = np.array([p.body for p in pieces], dtype=int)
        self.mass = np.array([p.mass for p in pieces])  # (P,)
        F = frames[..., [p.row + 1 for p in pieces], :, :]  # (..., P, 4, 4)
        R = F[..., :3, :3]
        com = np.array([p.com for p in pieces]).reshape(-1, 3)
        self.com = np.einsum("...pij,pj->...pi", R, com) + F[..., :3, 3]  # (..., P, 3) world
        Ilocal = np.array([p.inertia for p in pieces]).reshape(-1, 3, 3)
        self.inertia = R @ Ilocal @ np.swapaxes(R, -1, -2)  # (..., P, 3, 3) world axes, about COM

    def spatial_axes(self) -> np.ndarray:
        """Joint motion axes S_k = (o×z, z) (revolute) or (z, 0) (prismatic), shape (..., n, 6)."""
        rev = self.revolute[:, None]
        v = np.where(rev, np.cross(self.o, self.z), self.z)
        w = np.where(rev, self.z, 0.0)
        return np.concatenate([v, w], axis=-1)

    def composite_inertias(self, n: int) -> np.ndarray:
        """Spatial inertia about the world origin of bodies k…n together, shape (..., n, 6, 6)."""
        m = self.mass[:, None, None]
        c = self.com
        h = m[..., 0] * c  # (..., P, 3) first moments
        cc = np.einsum("...i,...j->...ij", c, c)
        J = self.inertia + m * (np.einsum("...i,...i->...", c, c)[..., None, None] * np.eye(3) - cc)
        Sh = _skew(h)
        top = np.concatenate([np.broadcast_to(m * np.eye(3), Sh.shape), -Sh], axis=-1)
        I = np.concatenate([top, np.concatenate([Sh, J], axis=-1)], axis=-2)  # (..., P, 6, 6)
        onehot = (self.body[:, None] == np.arange(n)[None, :]).astype(float)  # (P, n)
        per_body = np.einsum("pk,...pij->...kij", onehot, I)
        return np.flip(np.cumsum(np.flip(per_body, axis=-3), axis=-3), axis=-3)


def _skew(v: np.ndarray) -> np.ndarray:
    S = np.zeros(v.shape + (3,))
    S[..., 0, 1], S[..., 0, 2], S[..., 1, 2] = -v[..., 2], v[..., 1], -v[..., 0]
    S[..., 1, 0], S[..., 2, 0], S[..., 2, 1] = v[..., 2], -v[..., 1], v[..., 0]
    return S


def _crm(s: np.ndarray) -> np.ndarray:
    """Motion cross-product matrix of s = (v, ω): crm(s) m = s ×_m m, shape (..., 6, 6)."""
    Sv, Sw = _skew(s[..., :3]), _skew(s[..., 3:])
    Z = np.zeros_like(Sw)
    return np.concatenate([np.concatenate([Sw, Sv], -1), np.concatenate([Z, Sw], -1)], -2)


def gravity_vector(robot: DHRobot, gravity) -> np.ndarray:
    """Gravity [m/s²] in the world frame: ``gravity`` (3 finite numbers) or, when None, ``robot.gravity``."""
    g = np.asarray(robot.gravity if gravity is None else gravity, dtype=float)
    if g.shape != (3,):
        raise ModelError(f"gravity must have 3 components [m/s²], got shape {g.shape}")
    if not np.all(np.isfinite(g)):
        raise ModelError(f"gravity must be finite [m/s²], got {g.tolist()}")
    return g


def rnea(robot: DHRobot, q, qd, qdd, *, gravity=None, friction: bool = True, threads=None) -> np.ndarray:
    """Inverse dynamics τ = M(q) q̈ + C(q, q̇) q̇ + g(q) (+ τ_f) by the recursive Newton–Euler algorithm.

    Parameters
    ----------
    robot : DHRobot
        With inertial data (rows without it are massless).
    q, qd, qdd : array_like, shape (..., n)
        Joint positions [rad, m], rates [rad/s, m/s], accelerations [rad/s², m/s²]; broadcast together.
    gravity : array_like, shape (3,), optional
        Gravity in the world frame [m/s²]; default ``robot.gravity``.  Pass zeros to drop it.  NaN or ±inf
        raises ModelError (it would turn every torque into NaN).
    friction : bool
        Add τ_f = viscous·q̇ + coulomb·sign(q̇).
    threads : int, optional
        Threads a batch's rows are split over (default every core; small batches run inline; the result is
        the unsplit one bit for bit: :mod:`denavit._threads`).

    Returns
    -------
    tau : ndarray, shape (..., n)
        Joint torques [N m] / forces [N].

    Notes
    -----
    Outward recursion in world axes for body k with axis z_k through o_k (Craig 3rd ed. eqs. 6.45–6.53,
    Featherstone 2008 §5.3), with the base accelerating at −g to include gravity:

    .. math::
        \\omega_k = \\omega_{k-1} + \\dot q_k z_k,\\quad
        \\dot\\omega_k = \\dot\\omega_{k-1} + \\ddot q_k z_k + \\omega_{k-1}\\times\\dot q_k z_k
        \\quad\\text{(revolute)},\\qquad
        a_{o_k} = a_{o_k\\in k-1} + \\ddot q_k z_k + 2\\,\\omega_{k-1}\\times\\dot q_k z_k \\quad\\text{(prismatic)}.

    Each piece then needs F = m a_c and N = I ω̇ + ω × I ω; the inward recursion sums them and projects
    the moment about o_k (revolute) or the force (prismatic) on z_k.  The motor inertia adds I_m q̈.
    """
    n = robot.dof
    q, qd, qdd = np.broadcast_arrays(
        as_joint_array(q, n), as_joint_array(qd, n, "qd"), as_joint_array(qdd, n, "qdd")
    )
    g = gravity_vector(robot, gravity)
    split = None if q.ndim == 1 and threads is None else split_call(  # one configuration: inline
        lambda *x: rnea(robot, *x, gravity=g, friction=friction, threads=1), (q, qd, qdd), threads)
    if split is not None:
        return split
    (qc, batch), (qdc, _), (qddc, _) = joint_columns(q), joint_columns(qd), joint_columns(qdd)
    tau = to_array(rnea_kernel(plan(robot), qc, qdc, qddc, g.tolist()), batch, (n,))
    if friction:
        tau = tau + friction_torques(robot, qd)
    return tau


def mass_matrix(robot: DHRobot, q, *, threads=None) -> np.ndarray:
    """Joint-space inertia matrix M(q), shape (..., n, n), by the composite-rigid-body algorithm.

    Notes
    -----
    With S_k the spatial axis of joint k and I^C_k the spatial inertia of bodies k…n (world axes,
    world origin), :math:`M_{jk} = S_j^T I^C_k S_k` for j ≤ k (Featherstone 2008, eq. 6.8), plus the
    motor inertia on the diagonal.  ``threads``: as :func:`rnea`.
    """
    q = as_joint_array(q, robot.dof)
    split = None if q.ndim == 1 and threads is None else split_call(  # one configuration: inline
        lambda x: mass_matrix(robot, x, threads=1), (q,), threads)
    if split is not None:
        return split
    qc, batch = joint_columns(q)
    return to_array(mass_matrix_kernel(plan(robot), qc), batch, (robot.dof, robot.dof))


def mass_matrix_derivatives(robot: DHRobot, q) -> np.ndarray:
    """∂M/∂q_i for every joint i, shape (..., n, n, n) with index order [i, j, k] = ∂M_jk/∂q_i.

    Notes
    -----
    A body-fixed motion vector s changes with joint i as ∂s/∂q_i = S_i ×_m s, a body-fixed spatial
    inertia as ∂I/∂q_i = S_i ×_f I − I (S_i ×_m) (Featherstone 2008 §2.9, §2.13).  S_j is fixed in
    body j−1 (moved by joints i < j), I^C_k collects bodies ≥ k (moved by i ≤ k, and only its part
    I^C_i by i > k).  Differentiating M_jk = S_jᵀ I^C_k S_k gives the result exactly.
    """
    q = as_joint_array(q, robot.dof)
    n = robot.dof
    st = _State(robot, q)
    S = st.spatial_axes()  # (..., n, 6)
    IC = st.composite_inertias(n)  # (..., n, 6, 6)
    X = _crm(S)  # (..., n, 6, 6) crm(S_i)
    Xf = -np.swapaxes(X, -1, -2)  # crf(S_i)
    lower = np.tril(np.ones((n, n)), -1).T  # [i, j] = 1 where i < j
    dS = np.einsum("...iab,...jb->...ija", X, S) * lower[..., None]  # (..., i, j, 6)
    idx = np.maximum.outer(np.arange(n), np.arange(n))  # [i, k] -> max(i, k)
    ICm = IC[..., idx, :, :]  # (..., i, k, 6, 6)
    dIC = Xf[..., :, None, :, :] @ ICm - ICm @ X[..., :, None, :, :]
    F = np.einsum("...kab,...kb->...ka", IC, S)  # (..., k, 6)
    t1 = np.einsum("...ija,...ka->...ijk", dS, F)
    t2 = np.einsum("...ja,...ikab,...kb->...ijk", S, dIC, S)
    t3 = np.einsum("...ja,...kab,...ikb->...ijk", S, IC, dS)
    dM = t1 + t2 + t3
    upper = np.triu(np.ones((n, n), dtype=bool))
    return np.where(upper, dM, np.swapaxes(dM, -1, -2))


def coriolis_matrix(robot: DHRobot, q, qd) -> np.ndarray:
    """Coriolis/centrifugal matrix C(q, q̇) from the Christoffel symbols of M, shape (..., n, n).

    Notes
    -----
    :math:`C_{kj} = \\sum_i \\Gamma_{ijk}\\dot q_i`, :math:`\\Gamma_{ijk} = \\tfrac12(\\partial_i M_{kj}
    + \\partial_j M_{ki} - \\partial_k M_{ij})` (Spong, Hutchinson, Vidyasagar 2006, eq. 7.51), so
    C q̇ is the velocity term of the RNEA and Ṁ − 2C is skew-symmetric.
    """
    n = robot.dof
    q, qd = np.broadcast_arrays(as_joint_array(q, n), as_joint_array(qd, n, "qd"))
    dM = mass_matrix_derivatives(robot, q)
    return 0.5 * (
        np.einsum("...ikj,...i->...kj", dM, qd)
        + np.einsum("...jki,...i->...kj", dM, qd)
        - np.einsum("...kij,...i->...kj", dM, qd)
    )


def coriolis_vector(robot: DHRobot, q, qd, *, threads=None) -> np.ndarray:
    """The velocity term c(q, q̇) = C(q, q̇) q̇, shape (..., n), by the RNEA with q̈ = 0, g = 0 (``threads``: as
    :func:`rnea`)."""
    zero = np.zeros(np.shape(qd)[-1:])
    return rnea(robot, q, qd, zero, gravity=np.zeros(3), friction=False, threads=threads)


def gravity_torques(robot: DHRobot, q, *, gravity=None, threads=None) -> np.ndarray:
    """Gravity term g(q) = ∂V/∂q, shape (..., n) [N m or N] (RNEA at rest; ``threads``: as :func:`rnea`)."""
    q = as_joint_array(q, robot.dof)
    zero = np.zeros(robot.dof)
    return rnea(robot, q, zero, zero, gravity=gravity, friction=False, threads=threads)


def forward_dynamics(robot: DHRobot, q, qd, tau, *, gravity=None, friction: bool = True,
                     threads=None) -> np.ndarray:
    """Joint accelerations q̈ = M⁻¹ (τ − C q̇ − g − τ_f), shape (..., n).

    The bias C q̇ + g comes from the RNEA at q̈ = 0, M from the CRBA on the same frames, and the system is
    solved by an LDLᵀ factorisation, whose pivots also decide that M is singular (``ModelError``).

    Parameters
    ----------
    q, qd, tau : array_like, shape (..., n)
        Positions, rates and applied joint torques/forces [N m, N]; broadcast together.
    threads : int, optional
        Threads a batch's rows are split over (default every core; small batches run inline; the result is
        the unsplit one bit for bit: :mod:`denavit._threads`).
    """
    n = robot.dof
    q, qd, tau = np.broadcast_arrays(
        as_joint_array(q, n), as_joint_array(qd, n, "qd"), as_joint_array(tau, n, "tau")
    )
    g = gravity_vector(robot, gravity)
    split = None if q.ndim == 1 and threads is None else split_call(  # one configuration: inline
        lambda *x: forward_dynamics(robot, *x, gravity=g, friction=friction, threads=1), (q, qd, tau), threads)
    if split is not None:
        return split
    if friction:
        tau = tau - friction_torques(robot, qd)
    pl, g = plan(robot), g.tolist()
    (qc, batch), (qdc, _), (tc, _) = joint_columns(q), joint_columns(qd), joint_columns(tau)
    F = frames(pl, qc)
    bias = rnea_kernel(pl, qc, qdc, [0.0] * n, g, F)
    qdd = ldl_solve(mass_matrix_kernel(pl, qc, F), [t - b for t, b in zip(tc, bias)], SINGULAR_TOL)
    if qdd is None:
        _raise_singular(robot)
    return to_array(qdd, batch, (n,))


def _raise_singular(robot: DHRobot) -> None:
    """Raise ModelError: M is singular (a joint whose subtree has no inertia about its axis)."""
    raise ModelError(
        f"robot {robot.name!r}: the mass matrix is singular here, so q̈ is undefined (a joint moves no "
        "mass or inertia, e.g. point masses on its axis); give the links inertia tensors or motor inertia"
    )


def kinetic_energy(robot: DHRobot, q, qd) -> np.ndarray:
    """K = ½ q̇ᵀ M(q) q̇ (motor inertia included), shape (...) [J]."""
    n = robot.dof
    q, qd = np.broadcast_arrays(as_joint_array(q, n), as_joint_array(qd, n, "qd"))
    return 0.5 * np.einsum("...i,...ij,...j->...", qd, mass_matrix(robot, q), qd)


def potential_energy(robot: DHRobot, q, *, gravity=None) -> np.ndarray:
    """Gravitational potential V = −Σ m gᵀ c (COMs in the world frame), shape (...) [J]."""
    q = as_joint_array(q, robot.dof)
    st = _State(robot, q)
    g = gravity_vector(robot, gravity)
    return -np.einsum("p,...pi,i->...", st.mass, st.com, g)
