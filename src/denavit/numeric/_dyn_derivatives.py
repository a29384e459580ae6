"""Derivatives of the dynamics: ∂τ/∂q, ∂τ/∂q̇ of the RNEA, ∂q̈/∂(q, q̇, τ) of forward dynamics, ∂g/∂q.

Analytical, not finite differences: the library's own RNEA, CRBA and LDLᵀ kernels
(:mod:`denavit.numeric._dynamics_fast`, walking the chain of :mod:`denavit.chain`) run on dual numbers
(:mod:`denavit.numeric._dual`) seeded with the unit tangents of q and q̇, which carries the exact
derivatives of every intermediate quantity through the same arithmetic (forward mode).  The compiled
kernels of :mod:`denavit.codegen` trace this same code.

Forward dynamics is differentiated without going through the solve (Carpentier & Mansard 2018, Sec. III-B):
with q̈ = FD(q, q̇, τ), the identity ID(q, q̇, q̈) = τ differentiated at fixed q̈ gives

.. math::
    \\frac{\\partial \\ddot q}{\\partial x} = M^{-1}(q)\\,\\frac{\\partial\\,(\\tau - \\mathrm{ID}(q, \\dot q, \\ddot q))}
    {\\partial x}\\Big|_{\\ddot q = \\mathrm{FD}(q, \\dot q, \\tau)},\\qquad
    \\frac{\\partial \\ddot q}{\\partial q} = -M^{-1}\\frac{\\partial \\tau}{\\partial q},\\quad
    \\frac{\\partial \\ddot q}{\\partial \\dot q} = -M^{-1}\\frac{\\partial \\tau}{\\partial \\dot q},\\quad
    \\frac{\\partial \\ddot q}{\\partial \\tau} = M^{-1},

one LDLᵀ solve with 3n right-hand sides (the tangents of τ − ID).  Friction τ_f = viscous·q̇ + coulomb·sign(q̇)
contributes diag(viscous) to ∂τ/∂q̇ (the Coulomb term has derivative 0 away from q̇ = 0, and 0 is taken at
q̇ = 0, the one-sided limits' common part); motor inertia enters through M (∂τ/∂q̈ = M).

References
----------
J. Carpentier, N. Mansard, "Analytical Derivatives of Rigid Body Dynamics Algorithms", Robotics: Science and
Systems (RSS) 2018, doi:10.15607/RSS.2018.XIV.038.
A. Griewank, A. Walther, *Evaluating Derivatives*, 2nd ed., SIAM 2008, ch. 3 (forward mode).
R. Featherstone, *Rigid Body Dynamics Algorithms*, Springer 2008, §5.3 (RNEA), §6.2 (CRBA).
"""

from __future__ import annotations

import numpy as np

from .._threads import resolve_threads, split_rows
from .._validate import as_joint_array
from ..errors import ShapeError
from ..model import DHRobot
from ._dual import dual_sign, seed_duals, tangent_matrix
from ._dynamics import forward_dynamics, gravity_vector
from ._dynamics_fast import frames, joint_columns, ldl_pivots_solve, mass_matrix_kernel, plan, rnea_kernel, to_array

__all__ = ["rnea_derivatives", "forward_dynamics_derivatives", "gravity_derivatives", "friction_coefficients"]


def friction_coefficients(robot: DHRobot, friction: bool = True) -> tuple[list[float], list[float]]:
    """Per joint (viscous, Coulomb) coefficients, zeros without inertial data or with ``friction=False``."""
    fv = [link.inertia.viscous if link.inertia and friction else 0.0 for link in robot.joints]
    fc = [link.inertia.coulomb if link.inertia and friction else 0.0 for link in robot.joints]
    return fv, fc


def _inputs(robot: DHRobot, arrays, names):
    arrays = [as_joint_array(a, robot.dof, nm) for a, nm in zip(arrays, names)]
    try:
        return np.broadcast_arrays(*arrays)
    except ValueError:
        shapes = ", ".join(f"{nm} {a.shape}" for nm, a in zip(names, arrays))
        raise ShapeError(f"inputs do not broadcast together: {shapes}") from None


def _batched(arrays, shape: tuple[int, ...], compute, threads):
    """``compute(*arrays)`` → output of ``shape`` per configuration: one configuration directly, a batch (..., n)
    flattened and its rows split over ``threads`` (:func:`denavit._threads.split_rows`)."""
    resolve_threads(threads)  # a bad value is refused for one configuration too
    batch = arrays[0].shape[:-1]
    if not batch:
        return compute(*arrays)
    flat = [a.reshape(-1, a.shape[-1]) for a in arrays]
    out = np.empty((flat[0].shape[0],) + shape)

    def work(s: int, e: int) -> None:
        if e > s:
            out[s:e] = compute(*[f[s:e] for f in flat])

    split_rows(out.shape[0], work, threads)
    return out.reshape(batch + shape)


def _id_tangents(robot, qc, qdc, qddc, g, friction: bool, m: int):
    """ID(q, q̇, q̈) + τ_f on duals: q seeded along directions 0…n−1, q̇ along n…2n−1 (of m)."""
    n = robot.dof
    qx, qdx = seed_duals(qc, 0, m), seed_duals(qdc, n, m)
    tau = rnea_kernel(plan(robot), qx, qdx, qddc, g)
    fv, fc = friction_coefficients(robot, friction)
    return [t + fv[k] * qdx[k] + fc[k] * dual_sign(qdx[k]) for k, t in enumerate(tau)]


def rnea_derivatives(robot: DHRobot, q, qd, qdd, *, friction: bool = True, gravity=None, threads=None):
    """``(dtau_dq, dtau_dqd)``: ∂τ/∂q and ∂τ/∂q̇ of :func:`denavit.rnea`, each shape (..., n, n), [output, input].

    Parameters
    ----------
    robot : DHRobot
    q, qd, qdd : array_like, shape (..., n)
        Joint positions [rad, m], rates and accelerations; broadcast together (as :func:`denavit.rnea`).
    friction : bool
        Include τ_f = viscous·q̇ + coulomb·sign(q̇): adds diag(viscous) to ∂τ/∂q̇.
    gravity : array_like, shape (3,), optional
        World gravity [m/s²]; default ``robot.gravity``.
    threads : int, optional
        Split a batch over this many threads (default: every core; :mod:`denavit._threads`).

    Notes
    -----
    τ = M(q) q̈ + C(q, q̇) q̇ + g(q) + τ_f(q̇) by the RNEA run on dual numbers (module notes); motor inertia is
    in M, and ∂τ/∂q̈ = M (:func:`denavit.mass_matrix`).  Checked against Pinocchio's
    ``computeRNEADerivatives`` (Carpentier & Mansard, RSS 2018).
    """
    q, qd, qdd = _inputs(robot, (q, qd, qdd), ("q", "qd", "qdd"))
    g = gravity_vector(robot, gravity).tolist()
    n = robot.dof

    def compute(q, qd, qdd):
        (qc, batch), (qdc, _), (qddc, _) = joint_columns(q), joint_columns(qd), joint_columns(qdd)
        tau = _id_tangents(robot, qc, qdc, qddc, g, friction, 2 * n)
        return to_array(tangent_matrix(tau, 2 * n), batch, (n, 2 * n))

    D = _batched((q, qd, qdd), (n, 2 * n), compute, threads)
    return D[..., :n].copy(), D[..., n:].copy()


def forward_dynamics_derivatives(robot: DHRobot, q, qd, tau, *, friction: bool = True, gravity=None, threads=None):
    """``(dqdd_dq, dqdd_dqd, dqdd_dtau)`` of :func:`denavit.forward_dynamics`, each shape (..., n, n); dqdd_dtau = M⁻¹.

    Parameters
    ----------
    q, qd, tau : array_like, shape (..., n)
        Positions, rates and applied joint torques/forces [N m, N]; broadcast together.
    friction, gravity, threads
        As :func:`rnea_derivatives`.

    Raises
    ------
    ModelError
        Where M is singular (as :func:`denavit.forward_dynamics`).

    Notes
    -----
    ∂q̈/∂x = M⁻¹ ∂(τ − ID(q, q̇, q̈))/∂x at q̈ = FD(q, q̇, τ) (Carpentier & Mansard, RSS 2018; module notes): the
    RNEA on duals at the forward-dynamics q̈, then one LDLᵀ solve of M with the 3n tangents as right-hand sides.
    """
    q, qd, tau = _inputs(robot, (q, qd, tau), ("q", "qd", "tau"))
    n, m = robot.dof, 3 * robot.dof
    gravity = gravity_vector(robot, gravity)
    g, pl = gravity.tolist(), plan(robot)

    def compute(q, qd, tau):
        qdd = forward_dynamics(robot, q, qd, tau, gravity=gravity, friction=friction)  # raises where M is singular
        (qc, batch), (qdc, _), (qddc, _), (tc, _) = (joint_columns(a) for a in (q, qd, qdd, tau))
        ident = _id_tangents(robot, qc, qdc, qddc, g, friction, m)
        residual = [t - i for t, i in zip(seed_duals(tc, 2 * n, m), ident)]  # τ − ID, tangents along (q, q̇, τ)
        x, _ = ldl_pivots_solve(mass_matrix_kernel(pl, qc, frames(pl, qc)), residual)
        return to_array(tangent_matrix(x, m), batch, (n, m))

    D = _batched((q, qd, tau), (n, m), compute, threads)
    return D[..., :n].copy(), D[..., n:2 * n].copy(), D[..., 2 * n:].copy()


def gravity_derivatives(robot: DHRobot, q, *, gravity=None, threads=None) -> np.ndarray:
    """∂g/∂q of the gravity torques :func:`denavit.gravity_torques`, shape (..., n, n), [output, input].

    Parameters
    ----------
    q : array_like, shape (..., n)
    gravity, threads
        As :func:`rnea_derivatives`.

    Notes
    -----
    g(q) = ∂V/∂q is the RNEA at rest; run on duals it gives ∂g/∂q = ∂²V/∂q², which is symmetric.
    """
    q = as_joint_array(q, robot.dof)
    g = gravity_vector(robot, gravity).tolist()
    n = robot.dof
    zero = [0.0] * n

    def compute(q):
        qc, batch = joint_columns(q)
        tau = rnea_kernel(plan(robot), seed_duals(qc, 0, n), zero, zero, g)
        return to_array(tangent_matrix(tau, n), batch, (n, n))

    return _batched((q,), (n, n), compute, threads)
