"""Dynamic identification: an arm's base inertial parameters from joint torques measured along a motion.

The inverse dynamics is linear in the base parameters π_b (:func:`denavit.base_parameters`):
τ(t_i) = Y_b(q_i, q̇_i, q̈_i) π_b + ε_i.  Stacking the N samples gives the overdetermined system
y = W π_b + ε, W = [Y_b(1); …; Y_b(N)] (N·n × r), solved by least squares (Gautier 1990; Khalil & Dombre 2002,
§14.6; Swevers, Ganseman, Tükel, De Schutter & Van Brussel 1997):

- OLS: π̂ = W⁺ y, one noise level σ² = ‖y − W π̂‖² / (N·n − r), Cov(π̂) = σ² (WᵀW)⁻¹;
- WLS (Gautier & Poignet 2001): σ_j² = ‖ρ_j‖² / (N − r_j) per joint j from the OLS residuals ρ_j (r_j: the base
  parameters reaching joint j), each row of joint j divided by σ_j, then OLS again: Cov(π̂) = (Wᵀ Σ⁻¹ W)⁻¹; σ_j
  re-estimated once from these residuals and the fit repeated (:data:`WLS_PASSES`).

Observability is that of the data, not only of the structure: W's columns are scaled to unit norm and the rank
is the number of singular values above :data:`RANK_TOL` × the largest.  A base parameter is *identifiable from
these data* when it is orthogonal to W's null space (then every least-squares solution gives it the same value);
the others — a joint that never moved, a motion that never separates two parameters — are named in
``unidentifiable`` and get no number (NaN), while the identifiable ones keep theirs.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np

from .._validate import as_joint_array
from ..model import DHRobot
from ..numeric import BaseParameters, base_parameters, base_regressor

__all__ = ["METHODS", "NULL_TOL", "RANK_TOL", "Identification", "identify"]

#: Relative singular-value threshold of the stacked, column-scaled base regressor: below it, a direction of π_b
#: is not seen by the data (the singular values come from the Gram matrix: float64 resolves them to ~1e-8).
RANK_TOL = 1e-6
#: Largest stacked regressor W (N · n · r doubles) identify builds: 2 GB (10⁶ samples of a 6-joint arm need 2.5).
MAX_REGRESSOR_BYTES = 2e9
#: Rows of W summed at once into the Gram matrices.
BLOCK = 4096
#: A base parameter is identifiable from the data when the norm of its components along W's null space (unit
#: basis) is below NULL_TOL.
NULL_TOL = 1e-6
METHODS = ("ols", "wls")
#: WLS fits: σ_j from the OLS residuals, then once more from the first WLS's (OLS misfits the joints of small
#: torques, whose σ_j it overestimates).
WLS_PASSES = 2


@dataclass(frozen=True)
class Identification:
    """The result of :func:`identify` (data only).

    Attributes
    ----------
    method : str
        ``"ols"`` or ``"wls"``.
    names : tuple of str
        Base parameter names (``base.base_names``), length r; ``rules`` their grouping (``base.rules``).
    estimate, std : ndarray, shape (r,)
        π̂_b and its standard deviations [kg, kg m, kg m², N m s, N m]; NaN for the unidentifiable ones.
    relative_std : ndarray, shape (r,)
        100 σ_i / |π̂_i| [%] (inf for an estimate of exactly 0, NaN when unidentifiable).
    covariance : ndarray, shape (r, r)
        Cov(π̂_b); rows and columns of the unidentifiable parameters are NaN.
    identifiable : ndarray of bool, shape (r,)
    unidentifiable : tuple of str
        Base parameters these data cannot determine (no number is given for them).
    noise : ndarray, shape (n,)
        Per-joint noise σ_j estimated from the residuals of the final fit [N m or N].
    residual_rms : ndarray, shape (n,)
        RMS of τ − Y_b π̂_b per joint, of the returned estimate ("after").
    nominal_residual_rms : ndarray, shape (n,)
        RMS of τ − Y_b π_b(robot) per joint: the arm's own parameters on the same (filtered) data ("before").
    condition_number : float
        σ_max / σ_min of the stacked base regressor W (unscaled, unweighted); inf when the data leave a direction
        of π_b unseen.
    rank, samples : int
        W's rank (column-scaled, :data:`RANK_TOL`) and the number of samples used.
    filter : str or None
        How q̇, q̈ were obtained from q (None when they were given).
    solution : ndarray, shape (r,)
        A least-squares solution for every base parameter (the minimum-norm one in unit-scaled columns): equal
        to ``estimate`` on the identifiable ones, one choice among many on the others — use ``estimate``.
    information : ndarray, shape (r, r)
        The Fisher information Wᵀ Σ⁻¹ W of the fit (its pseudo-inverse is Cov(π̂_b)); zero along the directions
        the data do not see.
    base : BaseParameters
        The structural base parameters (columns, grouping, the robot's own values).
    physical : PhysicalEstimate or None
        The physically consistent full parameter set (:func:`denavit.calibration.physical_parameters`).
    """

    method: str
    names: tuple[str, ...]
    rules: tuple[str, ...]
    estimate: np.ndarray
    std: np.ndarray
    relative_std: np.ndarray
    covariance: np.ndarray
    identifiable: np.ndarray
    unidentifiable: tuple[str, ...]
    noise: np.ndarray
    residual_rms: np.ndarray
    condition_number: float
    rank: int
    samples: int
    filter: str | None
    solution: np.ndarray
    information: np.ndarray
    base: BaseParameters
    physical: object | None = None
    nominal_residual_rms: np.ndarray | None = None


def identify(robot: DHRobot, q, qd=None, qdd=None, tau=None, *, t=None, method: str = "wls", friction: bool = True,
             motor_inertia: bool = True, filter: float | None = None, physical: bool = True,
             threads: int | None = None) -> Identification:
    """The base inertial parameters of ``robot`` from torques ``tau`` measured along the motion ``q``.

    Parameters
    ----------
    robot : DHRobot
        The arm: its kinematics is trusted, its inertia is only the prior of the physically consistent fit.
    q : array_like, shape (N, n)
        Joint positions [rad or m] at N samples.
    qd, qdd : array_like, shape (N, n), optional
        Joint rates and accelerations; when both are omitted they are estimated from ``q`` and ``t`` by the
        zero-phase filter of :func:`~denavit.calibration._identify_filter.differentiate` (Butterworth low-pass run
        forwards and backwards, then central differences) — and the SAME filter is applied to ``tau`` and to every
        column of the regressor (parallel filtering); the first and last samples are dropped.
    tau : array_like, shape (N, n)
        Measured joint torques [N m] (forces [N] for prismatic joints).
    t : array_like, shape (N,), optional
        Sample times [s] (constant rate), required when q̇, q̈ are estimated.  ``threads``: for the regressor.
    method : {"wls", "ols"}
        Weighted by the per-joint noise estimated from the residuals (default), or ordinary (module notes).
    friction, motor_inertia : bool
        Model viscous + Coulomb friction (FV, FC) and motor inertia (IA) as :func:`denavit.regressor` does.
    filter : float, optional
        Cut-off [Hz] of the filter (default min(10 Hz, f_s / 5)), with ``t`` and no q̇, q̈ only.
    physical : bool
        Also fit the physically consistent full parameter set (``physical`` of the result).

    Returns
    -------
    Identification
    """
    q, qd, qdd, tau, filtered = _inputs(robot, q, qd, qdd, tau, t, filter, method)
    base = base_parameters(robot, friction=friction, motor_inertia=motor_inertia)
    _check_size(q.shape[0], 8.0 * q.size * base.rank)
    W = base_regressor(robot, q, qd, qdd, base, threads=threads)  # (N, n, r)
    if filtered is not None:  # the same filter on τ and on every column of W; the ends dropped
        smooth, keep, filtered = filtered
        W, tau = smooth(W)[keep], smooth(tau)[keep]
    N, n = tau.shape
    W = W.reshape(N * n, base.rank)  # (N n, r)
    sol, residual, noise, cov, info = _fit(W, tau.reshape(N * n), N, n, method)
    result = _result(method, base, sol, cov, info, noise, residual, N, filtered)
    before = tau - (W @ base.values).reshape(N, n)  # the arm as given, on the same samples
    result = dataclasses.replace(result, nominal_residual_rms=np.sqrt(np.mean(before ** 2, axis=0)))
    if physical:
        from ._physical import physical_parameters

        result = dataclasses.replace(result, physical=physical_parameters(robot, result))
    return result


def _check_size(N: int, size: float) -> None:
    if size > MAX_REGRESSOR_BYTES:
        raise ValueError(f"{N} samples: their stacked regressor would take {size / 1e9:.3g} GB (at most "
                         f"{MAX_REGRESSOR_BYTES / 1e9:g} GB); decimate the data (every k-th sample)")


def _result(method, base, sol, cov, info, noise, residual, N: int, filtered) -> Identification:
    """The :class:`Identification` of a fit (NaN where unidentifiable, relative σ, the condition number)."""
    est, std, cov = _mask(sol.x, cov, sol.ident)
    with np.errstate(divide="ignore", invalid="ignore"):
        rel = 100.0 * std / np.abs(est)
    sv = sol.singular
    cond = float(sv[0] / sv[-1]) if sol.rank == base.rank and sv[-1] > 0 else float("inf")
    return Identification(method, base.base_names, base.rules, est, std, rel, cov, sol.ident,
                          tuple(nm for nm, ok in zip(base.base_names, sol.ident) if not ok), noise,
                          np.sqrt(np.mean(residual ** 2, axis=0)), cond, sol.rank, N, filtered, sol.x, info, base)


def _fit(W: np.ndarray, y: np.ndarray, N: int, n: int, method: str):
    """OLS, then (``wls``) the rows of joint j weighted by 1/σ_j of the previous fit's residuals, twice:
    (solution, residual (N, n), σ_j, Cov, information) — module notes."""
    sol = _least_squares(W, y, np.ones(N * n))
    if N * n <= sol.rank:
        raise ValueError(f"{N} sample{'s' * (N != 1)} of {n} torques fit the {sol.rank} parameters they determine "
                         "exactly: no degree of freedom is left to estimate the noise and σ (record more samples)")
    residual = (y - W @ sol.x).reshape(N, n)
    noise = _joint_noise(residual, W.reshape(N, n, -1), sol.ident)
    if method == "wls":
        for _ in range(WLS_PASSES):  # σ_j from the previous fit's residuals (OLS, then the first WLS)
            sol = _least_squares(W, y, np.tile(1.0 / noise, N))
            residual = (y - W @ sol.x).reshape(N, n)
            noise = _joint_noise(residual, W.reshape(N, n, -1), sol.ident)
        s2 = 1.0
    else:
        s2 = float(residual.ravel() @ residual.ravel()) / max(N * n - sol.rank, 1)
    return sol, residual, noise, sol.cov * s2, sol.info / s2


def _inputs(robot, q, qd, qdd, tau, t, cutoff, method: str):
    """Checked (N, n) arrays q, q̇, q̈, τ (q̇, q̈ from the filter when not given) and the filter as (smooth, kept
    samples, description), or None when not used."""
    if method not in METHODS:
        raise ValueError(f"method must be one of {', '.join(METHODS)}, got {method!r}")
    n = robot.dof
    q = as_joint_array(q, n, "q")
    if tau is None:
        raise ValueError("tau: the measured joint torques are required (shape (N, n))")
    tau = as_joint_array(tau, n, "tau")
    if q.ndim != 2 or tau.shape != q.shape:
        raise ValueError(f"q and tau: expected two arrays of shape (N, {n}), got {q.shape} and {tau.shape}")
    if (qd is None) != (qdd is None):
        raise ValueError("give both qd and qdd, or neither (then they are estimated from q and t)")
    if qd is None:
        if t is None:
            raise ValueError("qd and qdd not given: the sample times t are needed to estimate them from q")
        from ._identify_filter import differentiate

        q, qd, qdd, smooth, keep, text = differentiate(t, q, cutoff)
        return q, qd, qdd, tau, (smooth, keep, text)
    if cutoff is not None:
        raise ValueError("filter= applies only when qd and qdd are estimated from q and t (none was given)")
    qd, qdd = as_joint_array(qd, n, "qd"), as_joint_array(qdd, n, "qdd")
    if qd.shape != q.shape or qdd.shape != q.shape:
        raise ValueError(f"qd, qdd: expected shape {q.shape} like q, got {qd.shape} and {qdd.shape}")
    return q, qd, qdd, tau, None


@dataclass(frozen=True)
class _Solution:
    x: np.ndarray  # (r,) least-squares solution (minimum norm in the scaled columns)
    cov: np.ndarray  # (r, r) (AᵀA)⁺ of the weighted rows: Cov(x) for unit noise on them
    ident: np.ndarray  # (r,) bool: orthogonal to the null space
    rank: int
    info: np.ndarray  # (r, r) AᵀA on the seen directions (the information for unit noise on the weighted rows)
    singular: np.ndarray  # (r,) singular values of the unweighted, unscaled W, descending


def _least_squares(W: np.ndarray, y: np.ndarray, w: np.ndarray) -> _Solution:
    """Weighted least squares of y ≈ W x with row weights w, A = diag(w) W, through the normal equations of the
    column-scaled Ã = A D⁻¹ (D: column norms): Ãᵀ Ã = V Λ Vᵀ, k = #{√λ > RANK_TOL √λ_max},
    x = D⁻¹ V_k Λ_k⁻¹ V_kᵀ D⁻¹ Aᵀ y, (AᵀA)⁺ = D⁻¹ V_k Λ_k⁻¹ V_kᵀ D⁻¹ (Golub & Van Loan 4th ed. §5.3).

    The Gram matrices are summed over blocks of :data:`BLOCK` rows: r × r work, no LAPACK call on the tall
    matrix (a multi-threaded LAPACK on it costs 10–60× more CPU on a loaded machine).  Normal equations lose
    precision as cond(Ã)²: fine for cond(Ã) ≲ 10⁶ (:data:`RANK_TOL`)."""
    r = W.shape[1]
    G, Gw, b = np.zeros((r, r)), np.zeros((r, r)), np.zeros(r)
    for a in range(0, W.shape[0], BLOCK):
        Wa, wa = W[a: a + BLOCK], w[a: a + BLOCK, None]
        G += Wa.T @ Wa
        Aw = Wa * wa
        Gw += Aw.T @ Aw
        b += Aw.T @ (wa[:, 0] * y[a: a + BLOCK])
    singular = np.sqrt(np.clip(np.linalg.eigvalsh(G)[::-1], 0.0, None))
    D = np.sqrt(np.diag(Gw))
    D = np.where(D > 0, D, 1.0)
    lam, V = np.linalg.eigh(Gw / np.outer(D, D))
    lam, V = lam[::-1], V[:, ::-1]
    k = int(np.sum(np.sqrt(np.clip(lam, 0.0, None)) > RANK_TOL * np.sqrt(max(lam[0], 0.0)))) if lam[0] > 0 else 0
    Vk = V[:, :k] / D[:, None]  # (r, k)
    cov = (Vk / lam[:k]) @ Vk.T
    x = cov @ b
    Vi = V[:, :k] * D[:, None]
    ident = np.linalg.norm(V[:, k:], axis=1) < NULL_TOL if k < r else np.ones(r, bool)
    return _Solution(x, cov, ident, k, (Vi * lam[:k]) @ Vi.T, singular)


def _joint_noise(residual: np.ndarray, Wj: np.ndarray, ident: np.ndarray) -> np.ndarray:
    """σ_j = sqrt(‖ρ_j‖² / (N − r_j)) (Gautier & Poignet 2001), r_j the identifiable base parameters whose column
    reaches joint j's rows; a joint with no residual at all (nothing to fit) gets the smallest positive one."""
    N = residual.shape[0]
    reach = np.any(Wj != 0, axis=0) & ident  # (n, r)
    r_j = reach.sum(axis=1)
    s2 = np.sum(residual ** 2, axis=0) / np.maximum(N - r_j, 1)
    positive = s2[s2 > 0]
    floor = positive.min() if positive.size else 1.0
    return np.sqrt(np.where(s2 > 0, s2, floor))


def _mask(x: np.ndarray, cov: np.ndarray, ident: np.ndarray):
    """Estimate, σ and covariance with NaN for the unidentifiable parameters."""
    est = np.where(ident, x, np.nan)
    cov = np.where(np.outer(ident, ident), cov, np.nan)
    std = np.sqrt(np.clip(np.diag(cov), 0.0, None))
    return est, std, cov
