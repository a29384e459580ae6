"""Physical consistency: a full standard parameter set, realisable by rigid bodies, that reproduces identified
base parameters — and the arm that carries it.

A body's 10 parameters (m, h = m c, Ī about a point) are realisable by a mass distribution exactly when its
pseudo-inertia matrix is positive definite (Wensing, Kim & Slotine 2018):

    J = [[Σ, h], [hᵀ, m]] ≻ 0,   Σ = ½ tr(Ī) 1 − Ī  (the second moment ∫ x xᵀ dm),

which implies m > 0, an inertia about the centre of mass positive definite and its triangle inequalities
I1 + I2 > I3.  The set of such π is convex (a linear matrix inequality per body), so the fit is a convex
problem: :func:`physical_parameters` minimises

    (K π − π̂_b)ᵀ F (K π − π̂_b) + λ Σ_i ((π_i − π_nom,i) / s_i)²   subject to  J_k(π) ≻ 0,  FV, FC, IA > 0,

F the Fisher information of the identification (Cov⁻¹ on the identified directions, 0 on the others), π_nom the
robot's own (catalogue) parameters moved inside the realisable set, s_i their scales and λ = :data:`PRIOR_WEIGHT`:
the data decide every identified direction and the catalogue the rest.  It is solved by the log-barrier method
with Newton steps (Boyd & Vandenberghe 2004, §11.3; the barrier −log det J is that of the LMI formulation of
Wensing, Kim & Slotine 2018 and Sousa & Cortesão 2014) — small dense matrices only, no SDP solver.  (The
log-Cholesky parametrisation of Rucker & Wensing 2022 turns the same set into R¹⁰ per body; with Levenberg–
Marquardt it converged too slowly toward the boundary, where estimates from noisy data often lie.)  The
unconstrained estimate is *realisable* when the fit reproduces it: Mahalanobis distance
√((Kπ − π̂_b)ᵀ F (Kπ − π̂_b)) ≤ :data:`REALISABLE_TOL`.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np

from ..chain import chain_of
from ..model import DHRobot, LinkInertia
from ..numeric import dynamics_plan, inertial_parameters

__all__ = [
    "PRIOR_WEIGHT",
    "REALISABLE_TOL",
    "PhysicalEstimate",
    "physical_parameters",
    "pseudo_inertia",
    "robot_with_parameters",
]

#: Weight λ of the pull toward the robot's own parameters, against the data's χ² (one unit per σ²).
PRIOR_WEIGHT = 1e-4
#: The unconstrained estimate counts as realisable when the consistent fit is within this Mahalanobis distance.
REALISABLE_TOL = 0.1
#: Smallest eigenvalue of a body's normalised pseudo-inertia in the prior (and the start): a catalogue body on the
#: boundary (a massless link, a thin rod) is moved inside, so the prior never pulls toward the boundary.
PRIOR_FLOOR = 1e-2
#: Largest ratio of the data term's curvature to the prior's in the fit (in u = π / s): above it the data term is
#: scaled down to it (its minimiser is unchanged where the estimate is realisable; the distance reported is
#: always in the identification's own σ).
MAX_RATIO = 1e14
#: Barrier method: factor of t per round, duality-gap target (σ² units of the data term), Newton decrement
#: target and bound on the Newton steps.
MU = 20.0
GAP = 1e-4
NEWTON_TOL = 1e-7
MAX_NEWTON = 300


@dataclass(frozen=True)
class PhysicalEstimate:
    """A physically consistent full parameter set (:func:`physical_parameters`; data only).

    Attributes
    ----------
    names : tuple of str
        The standard parameters (:func:`denavit.numeric.parameter_names`), length p.
    parameters : ndarray, shape (p,)
        π, every body realisable (pseudo-inertia ≻ 0), friction and motor inertia ≥ 0.
    base_values : ndarray, shape (r,)
        K π: the base parameters it gives.
    deviation : ndarray, shape (r,)
        (K π − π̂_b) / σ per identifiable base parameter (NaN for the others).
    distance : float
        The Mahalanobis distance of K π from π̂_b (σ units, the identification's covariance).
    realisable : bool
        Whether the unconstrained estimate itself was realisable (distance ≤ :data:`REALISABLE_TOL`).
    robot : DHRobot
        The arm with these parameters (:func:`robot_with_parameters`).
    success : bool
        Whether the barrier method converged; ``message`` says how, ``evaluations`` counts its Newton steps.
    """

    names: tuple[str, ...]
    parameters: np.ndarray
    base_values: np.ndarray
    deviation: np.ndarray
    distance: float
    realisable: bool
    robot: DHRobot
    success: bool
    message: str
    evaluations: int


def pseudo_inertia(body: np.ndarray) -> np.ndarray:
    """J (..., 4, 4) of body parameters (..., 10) in π's order [M, MX, MY, MZ, XX, XY, YY, XZ, YZ, ZZ]."""
    m, h = body[..., 0], body[..., 1:4]
    I = _inertia_matrix(body[..., 4:])
    Sigma = 0.5 * np.trace(I, axis1=-2, axis2=-1)[..., None, None] * np.eye(3) - I
    top = np.concatenate([Sigma, h[..., None]], axis=-1)  # (..., 3, 4)
    bottom = np.concatenate([h, m[..., None]], axis=-1)[..., None, :]  # (..., 1, 4)
    return np.concatenate([top, bottom], axis=-2)


def _inertia_matrix(I6: np.ndarray) -> np.ndarray:
    """3×3 from (XX, XY, YY, XZ, YZ, ZZ)."""
    xx, xy, yy, xz, yz, zz = (I6[..., i] for i in range(6))
    return np.stack([np.stack([xx, xy, xz], -1), np.stack([xy, yy, yz], -1), np.stack([xz, yz, zz], -1)], -2)


def _body_from_pseudo(J: np.ndarray) -> np.ndarray:
    """Body parameters (B, 10) from pseudo-inertias (B, 4, 4) (linear; inverse of :func:`pseudo_inertia`)."""
    Sigma = J[:, :3, :3]
    I = np.trace(Sigma, axis1=1, axis2=2)[:, None, None] * np.eye(3) - Sigma
    return np.stack([J[:, 3, 3], J[:, 0, 3], J[:, 1, 3], J[:, 2, 3], I[:, 0, 0], I[:, 0, 1], I[:, 1, 1],
                     I[:, 0, 2], I[:, 1, 2], I[:, 2, 2]], axis=1)


def _scales(nominal: np.ndarray, n: int, friction: bool) -> tuple[np.ndarray, np.ndarray]:
    """Per standard parameter the scale s_i of the prior, and per body [m ℓ², m ℓ², m ℓ², m] (n, 4).

    m: the body's nominal mass, at least 10 % of the mean nominal mass (1 kg if none), ℓ = 0.1 m: s = m for M,
    m ℓ for MX…MZ, m ℓ² for XX…ZZ; max(|nominal|, 1) for FV, FC [N m s, N m]; max(|nominal|, m̄ ℓ²) for IA."""
    masses = nominal[0: 10 * n: 10]
    floor = 0.1 * masses.mean() if masses.max() > 0 else 1.0
    m = np.maximum(masses, floor)
    ell = 0.1
    body = m[:, None] * np.array([1, ell, ell, ell] + [ell ** 2] * 6)  # (n, 10)
    rest = np.abs(nominal[10 * n:])
    floors = np.full(rest.shape, max(floor, masses.mean()) * ell ** 2)
    if friction:
        floors[: 2 * n] = 1.0
    return np.concatenate([body.ravel(), np.maximum(rest, floors)]), np.column_stack([m * ell ** 2] * 3 + [m])


def physical_parameters(robot: DHRobot, identification, *, prior_weight: float = PRIOR_WEIGHT,
                        max_newton: int = MAX_NEWTON) -> PhysicalEstimate:
    """The physically consistent full parameter set closest to an identification (module notes).

    Parameters
    ----------
    robot : DHRobot
        The arm identified; its own inertial parameters are the prior π_nom.
    identification : Identification
        The result of :func:`denavit.identify` (its ``base``, ``solution`` and ``information`` are used).
    prior_weight : float
        λ of the pull toward π_nom (:data:`PRIOR_WEIGHT`).
    max_newton : int
        Bound on the Newton steps of the barrier method (``success`` is False when reached).
    """
    base, n = identification.base, robot.dof
    nominal = inertial_parameters(robot, friction=base.friction, motor_inertia=base.motor_inertia)  # (p,)
    scale, body_scale = _scales(nominal, n, base.friction)
    nominal = _inside(nominal, n, body_scale, PRIOR_FLOOR)  # a realisable prior
    w, Q = np.linalg.eigh(identification.information)
    R = np.sqrt(np.clip(w, 0.0, None))[:, None] * Q.T  # F = Rᵀ R
    K, xhat, lam = base.combination, identification.solution, np.sqrt(prior_weight)
    data = np.linalg.norm(R @ K * scale, 2) ** 2 / prior_weight  # data's curvature over the prior's (u = π / s)
    if data > MAX_RATIO:  # nearly noise-free data: the Newton system would be singular in float64
        R = R * np.sqrt(MAX_RATIO / data)
    M = np.vstack([R @ K, lam * np.diag(1.0 / scale)]) * scale  # residual M u − c in u = π / s
    c = np.concatenate([R @ xhat, lam * nominal / scale])
    u, steps, success = _barrier(M, c, nominal / scale, scale, n, max_newton)
    pi = u * scale
    d = K @ pi - xhat
    distance = float(np.sqrt(max(d @ identification.information @ d, 0.0)))
    deviation = (K @ pi - identification.estimate) / identification.std
    out = robot_with_parameters(robot, pi, friction=base.friction, motor_inertia=base.motor_inertia)
    message = f"{steps} Newton steps" + ("" if success else " (the bound was reached before convergence)")
    return PhysicalEstimate(base.names, pi, K @ pi, deviation, distance, distance <= REALISABLE_TOL, out,
                            success, message, steps)


def _inside(pi: np.ndarray, n: int, body_scale: np.ndarray, floor: float) -> np.ndarray:
    """π moved strictly inside the realisable set: every body's pseudo-inertia, normalised by its scale
    [m ℓ², m ℓ², m ℓ², m] on both sides, given eigenvalues ≥ ``floor`` (the nearest such matrix in the Frobenius
    norm); friction and motor inertia kept when positive, else set to ``floor`` / 100."""
    S = np.sqrt(body_scale)  # (n, 4)
    J = pseudo_inertia(pi[: 10 * n].reshape(n, 10)) / (S[:, :, None] * S[:, None, :])
    w, V = np.linalg.eigh(J)
    J = (V * np.maximum(w, floor)[:, None, :]) @ np.swapaxes(V, 1, 2) * (S[:, :, None] * S[:, None, :])
    rest = pi[10 * n:]
    return np.concatenate([_body_from_pseudo(J).ravel(), np.where(rest > 0, rest, 1e-2 * floor)])


def _barrier(M, c, u0, scale, n: int, max_newton: int):
    """min ‖M u − c‖² over realisable u = π / s by the log-barrier method (Boyd & Vandenberghe 2004, §11.3):
    Newton on t ‖M u − c‖² − Σ_k log det J_k(π) − Σ_j log π_j (friction, motor inertia), t × :data:`MU` per
    round until the duality gap m / t (m = 4 n + their count) is below :data:`GAP`.  Returns (u, steps, converged)."""
    A = pseudo_inertia(np.eye(10)) * scale[: 10 * n].reshape(n, 10, 1, 1)  # (n, 10, 4, 4): ∂J_k/∂u_i
    H_f = 2 * M.T @ M
    m_c = 4 * n + (u0.size - 10 * n)
    u, steps = u0.copy(), 0
    t = m_c / max(float(np.sum((M @ u - c) ** 2)), 1e-12)
    while True:
        while steps < max_newton:
            g, H = _barrier_terms(u, A, n)
            grad = t * 2 * M.T @ (M @ u - c) + g
            du = _newton_step(t * H_f + H, grad)
            steps += 1
            dec = -float(grad @ du)
            if dec / 2 <= NEWTON_TOL:
                break
            u = _line_search(u, du, grad, t, M, c, A, n)
        if m_c / t < GAP or steps >= max_newton:
            return u, steps, steps < max_newton
        t *= MU


def _newton_step(A: np.ndarray, grad: np.ndarray) -> np.ndarray:
    """−A⁻¹ grad, A symmetric positive (semi)definite, solved with Jacobi scaling D⁻¹ A D⁻¹ (the data and the
    barrier weigh the variables on very different scales), by Cholesky, or least squares where that fails."""
    d = np.sqrt(np.maximum(np.diag(A), 1e-300))
    As = A / np.outer(d, d)
    try:
        L = np.linalg.cholesky(As)
        y = np.linalg.solve(L.T, np.linalg.solve(L, grad / d))
    except np.linalg.LinAlgError:
        y = np.linalg.lstsq(As, grad / d, rcond=None)[0]
    return -y / d


def _barrier_terms(u, A, n: int):
    """Gradient and Hessian of −Σ_k log det J_k − Σ_j log u_j: −tr(J⁻¹ A_i), tr(J⁻¹ A_i J⁻¹ A_j)."""
    J = np.einsum("ki,kiab->kab", u[: 10 * n].reshape(n, 10), A)
    B = np.linalg.solve(J[:, None], A)  # (n, 10, 4, 4): J⁻¹ A_i
    g = np.concatenate([-np.trace(B, axis1=2, axis2=3).ravel(), -1.0 / u[10 * n:]])
    H = np.zeros((u.size, u.size))
    Hb = np.einsum("kiab,kjba->kij", B, B)
    for k in range(n):
        H[10 * k: 10 * k + 10, 10 * k: 10 * k + 10] = Hb[k]
    H[np.arange(10 * n, u.size), np.arange(10 * n, u.size)] = 1.0 / u[10 * n:] ** 2
    return g, H


def _phi(u, t, M, c, A, n: int) -> float:
    """The barrier objective, +inf outside the realisable set (a Cholesky factorisation fails there)."""
    J = np.einsum("ki,kiab->kab", u[: 10 * n].reshape(n, 10), A)
    rest = u[10 * n:]
    if np.any(rest <= 0):
        return np.inf
    try:
        L = np.linalg.cholesky(J)
    except np.linalg.LinAlgError:
        return np.inf
    logdet = 2 * np.sum(np.log(np.diagonal(L, axis1=1, axis2=2)))
    return float(t * np.sum((M @ u - c) ** 2) - logdet - np.sum(np.log(rest)))


def _line_search(u, du, grad, t, M, c, A, n: int):
    """Backtracking (α = 0.25, β = 0.5) that stays inside the realisable set."""
    phi0, slope, s = _phi(u, t, M, c, A, n), float(grad @ du), 1.0
    while s > 1e-12:
        if _phi(u + s * du, t, M, c, A, n) <= phi0 + 0.25 * s * slope:
            return u + s * du
        s *= 0.5
    return u


def robot_with_parameters(robot: DHRobot, parameters, *, friction: bool = True,
                          motor_inertia: bool = True) -> DHRobot:
    """``robot`` with the standard parameters π (:func:`denavit.numeric.parameter_names` order) as its inertia.

    Body k's m, h and J about O_k in joint k's frame become the joint row's :class:`~denavit.LinkInertia` in its
    DH frame {r+1}: h_f = E h, J_f = E J Eᵀ (E: the body's ``to_joint`` rotation), centre of mass
    c = O_k + h_f / m and inertia about it I_c = J_f − m (|c'|² 1 − c' c'ᵀ), c' = h_f / m (parallel axes, Khalil &
    Dombre 2002, eq. 9.4).  The fixed rows after a joint (part of its body) lose their own inertia: it is merged
    into the joint row's.  Friction and motor inertia not in π are written as 0 (the model identified had none).
    ``inertial_parameters(result) == parameters`` (up to rounding) is the round trip.
    """
    pi = np.asarray(parameters, dtype=float)
    n, chain, pl = robot.dof, chain_of(robot), dynamics_plan(robot)
    extra = pi[10 * n:]
    fv, fc = (extra[:n], extra[n: 2 * n]) if friction else (np.zeros(n), np.zeros(n))
    ia = extra[2 * n if friction else 0:][:n] if motor_inertia else np.zeros(n)
    links = list(robot.links)
    merged = {r for k, r in enumerate(chain.joint_rows) for r in _fixed_rows_after(robot, r)}
    for k, r in enumerate(chain.joint_rows):
        body = pi[10 * k: 10 * k + 10]
        m = float(body[0])
        E = np.array(pl.bodies[k].to_joint)  # v_frame = E v_joint
        D = chain.row_constant(r) if chain.standard else np.eye(4)
        origin = -D[:3, :3].T @ D[:3, 3]  # O_k in frame {r+1}
        h = E @ body[1:4]
        J = E @ _inertia_matrix(body[4:]) @ E.T
        c = h / m if m > 0 else np.zeros(3)
        Ic = J - m * (c @ c * np.eye(3) - np.outer(c, c))
        inertia = LinkInertia(mass=max(m, 0.0), com=tuple(origin + c), inertia=(Ic[0, 0], Ic[1, 1], Ic[2, 2],
                              Ic[0, 1], Ic[0, 2], Ic[1, 2]), motor_inertia=float(ia[k]), viscous=float(fv[k]),
                              coulomb=float(fc[k]))
        links[r] = dataclasses.replace(links[r], inertia=inertia)
    for r in merged:
        links[r] = dataclasses.replace(links[r], inertia=None)
    return robot.replace(links=tuple(links))


def _fixed_rows_after(robot: DHRobot, r: int) -> list[int]:
    """The fixed rows following joint row r up to the next joint row (they move with joint r's body)."""
    out = []
    for i in range(r + 1, len(robot.links)):
        if robot.links[i].is_joint:
            break
        out.append(i)
    return out
