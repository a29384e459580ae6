"""Kinematic calibration: the arm's DH table, base and tool fitted to measured end-effector poses or positions.

Residuals, per measured pose, in units of the stated noise (σ_p [m], σ_r [rad]):

    r_p = (p_model − p_meas) / σ_p,     r_φ = log(R_model R_measᵀ) / σ_r   (rotation vector, world axes),

minimised over the identifiable corrections x (see :mod:`._kinematic_observe`) by Levenberg–Marquardt (Marquardt
1963: (JᵀWJ + λ diag JᵀWJ) δ = −JᵀW r, λ divided by 10 on success and multiplied by 10 on failure) with a robust
loss by iteratively reweighted least squares (Huber: w = min(1, k/|r|); Cauchy: w = 1/(1 + (r/k)²); k in noise
units).  The rotation residual's Jacobian is J_l⁻¹(φ) δφ (the inverse left Jacobian of SO(3), Chirikjian 2011,
eq. 10.86), so the residual Jacobian is exact.  Standard deviations: Cov(x) = s² (JᵀWJ)⁻¹ at the solution, s²
= Σ w r² / (N − p) the residual variance factor (1 when the stated noise is right).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import ShapeError
from ..model import DHRobot
from ..numeric import rotation_log
from ._kinematic_model import PARALLEL_TOLERANCE, ErrorModel, error_model
from ._kinematic_observe import RANK_TOLERANCE, observability
from ._kinematic_register import REGISTERED_NOTE, registered_start
from ._kinematic_robot import calibrated_robot

__all__ = ["calibrate", "CalibrationResult", "ParameterEstimate", "ResidualStats", "WorstPose", "ROBUST_LOSSES",
           "MAX_ITERATIONS"]

#: Robust losses of the fit ("none": plain least squares).
ROBUST_LOSSES = ("huber", "cauchy", "none")
#: Levenberg–Marquardt iterations at most.
MAX_ITERATIONS = 100
#: Poses at most (memory: the Jacobian holds 6 · poses · unknowns numbers, about 100 MB for a 7-joint arm).
MAX_POSES = 50_000
_WORST = 5
_PASSES = 3


@dataclass(frozen=True)
class ParameterEstimate:
    """One unknown: nominal value, estimate, correction (estimate − nominal) and standard deviation [m or rad];
    held parameters (``identified`` False) keep their nominal value, ``sigma`` nan, and ``reason`` says why."""

    name: str
    unit: str
    nominal: float
    estimate: float
    correction: float
    sigma: float
    identified: bool
    reason: str = ""


@dataclass(frozen=True)
class ResidualStats:
    """Pose errors model − measurement: position error norms [m], rotation angles [rad] (None for positions)."""

    poses: int
    position_rms: float
    position_max: float
    rotation_rms: float | None = None
    rotation_max: float | None = None


@dataclass(frozen=True)
class WorstPose:
    """A measurement with a large residual after calibration: its label (file line, or 1-based index)."""

    label: int
    position_error: float
    rotation_error: float | None


@dataclass(frozen=True, eq=False)  # holds arrays: compared by identity
class CalibrationResult:
    """What :func:`calibrate` found.  ``robot`` is the calibrated arm (a :class:`~denavit.DHRobot`)."""

    robot: DHRobot
    nominal: DHRobot
    kind: str
    noise: tuple[float, float]
    parameters: tuple[ParameterEstimate, ...]
    rank: int
    condition_number: float
    before: ResidualStats
    after: ResidualStats
    holdout_before: ResidualStats | None
    holdout_after: ResidualStats | None
    worst: tuple[WorstPose, ...]
    iterations: int
    converged: bool
    variance_factor: float
    covariance: np.ndarray
    beta_rows: tuple[int, ...]
    notes: tuple[str, ...]

    @property
    def identified(self) -> tuple[str, ...]:
        return tuple(p.name for p in self.parameters if p.identified)

    @property
    def held(self) -> tuple[str, ...]:
        return tuple(p.name for p in self.parameters if not p.identified)

    def parameter(self, name: str) -> ParameterEstimate:
        """The estimate of one parameter by name (KeyError listing the names otherwise)."""
        for p in self.parameters:
            if p.name == name:
                return p
        raise KeyError(f"no parameter {name!r}; the parameters are {', '.join(p.name for p in self.parameters)}")


def _left_jacobian_inverse(phi: np.ndarray) -> np.ndarray:
    """J_l⁻¹(φ) = I − ½[φ]× + (1/θ² − (1 + cos θ)/(2 θ sin θ)) [φ]×², shape (m, 3, 3) (Chirikjian eq. 10.86)."""
    theta = np.linalg.norm(phi, axis=-1)
    K = np.zeros(phi.shape[:-1] + (3, 3))
    K[..., 0, 1], K[..., 0, 2], K[..., 1, 2] = -phi[..., 2], phi[..., 1], -phi[..., 0]
    K = K - np.swapaxes(K, -1, -2)
    small = theta < 1e-4
    t = np.where(small, 1.0, theta)
    c = np.where(small, 1.0 / 12.0 + theta**2 / 720.0, 1.0 / t**2 - (1.0 + np.cos(t)) / (2.0 * t * np.sin(t)))
    return np.eye(3) - 0.5 * K + c[..., None, None] * (K @ K)


class _Problem:
    """Weighted residuals and their Jacobian for the free corrections (the others held at zero)."""

    def __init__(self, model: ErrorModel, q, p_meas, R_meas, noise, free):
        self.model, self.q, self.p, self.R = model, q, p_meas, R_meas
        self.sp, self.sr = noise
        self.free = np.asarray(free, dtype=int)

    def full(self, x: np.ndarray) -> np.ndarray:
        out = np.zeros(len(self.model.parameters))
        out[self.free] = x
        return out

    def residuals(self, x_full: np.ndarray, jacobian: bool = True):
        """(r (N,), J (N, p_free) or None), N = 3 or 6 per pose."""
        if jacobian:
            T, Jid = self.model.pose_and_jacobian(self.q, x_full)
        else:
            T, Jid = self.model.pose(self.q, x_full), None
        rp = (T[:, :3, 3] - self.p) / self.sp  # (m, 3)
        if self.R is None:
            r = rp
            J = None if Jid is None else Jid[:, :3, self.free] / self.sp  # (m, 3, p)
        else:
            phi = rotation_log(T[:, :3, :3] @ np.swapaxes(self.R, -1, -2))  # (m, 3)
            r = np.concatenate([rp, phi / self.sr], axis=1)
            J = None
            if Jid is not None:
                Jr = _left_jacobian_inverse(phi) @ Jid[:, 3:, self.free] / self.sr
                J = np.concatenate([Jid[:, :3, self.free] / self.sp, Jr], axis=1)  # (m, 6, p)
        return r.ravel(), None if J is None else J.reshape(-1, J.shape[-1])


def _loss(r: np.ndarray, robust: str, k: float) -> tuple[float, np.ndarray]:
    """(robust cost Σ ρ(r), IRLS weights w(r)) of residuals in noise units."""
    a = np.abs(r)
    if robust == "huber":
        return float(np.sum(np.where(a <= k, 0.5 * r * r, k * a - 0.5 * k * k))), np.minimum(1.0, k / np.maximum(a, 1e-300))
    if robust == "cauchy":
        return float(np.sum(0.5 * k * k * np.log1p((r / k) ** 2))), 1.0 / (1.0 + (r / k) ** 2)
    return float(0.5 * r @ r), np.ones_like(r)


def _levenberg_marquardt(problem: _Problem, x: np.ndarray, robust: str, k: float, max_iterations: int):
    """Minimise the robust cost over the free corrections from ``x``; returns (x, r, J, w, iterations, converged)."""
    r, J = problem.residuals(problem.full(x))
    cost, w = _loss(r, robust, k)
    lam, converged, it = 1e-3, False, 0
    for it in range(1, max_iterations + 1):
        A = J.T @ (w[:, None] * J)
        g = J.T @ (w * r)
        D = np.maximum(np.diag(A), 1e-12 * max(np.diag(A).max(), 1e-300))
        while True:
            step = np.linalg.solve(A + lam * np.diag(D), -g)
            r_new, _ = problem.residuals(problem.full(x + step), jacobian=False)
            cost_new, _ = _loss(r_new, robust, k)
            if cost_new <= cost or lam > 1e12:
                break
            lam *= 10.0
        if cost_new > cost:  # no step lowers the cost: at the minimum to working precision
            converged = True
            break
        x, decrease = x + step, cost - cost_new
        r, J = problem.residuals(problem.full(x))
        cost, w = _loss(r, robust, k)
        lam = max(lam / 10.0, 1e-12)
        if decrease <= 1e-12 * max(cost, 1.0) and float(step @ A @ step) <= 1e-10 * max(cost, 1.0):
            converged = True
            break
    return x, r, J, w, it, converged


def _checked(robot: DHRobot, q, measured, kind: str, noise, robust: str, holdout: float):
    """(q (m, n), positions (m, 3), rotations (m, 3, 3) or None): the inputs checked (ShapeError otherwise)."""
    if kind not in ("pose", "position"):
        raise ShapeError(f"kind must be 'pose' or 'position', got {kind!r}")
    if robust not in ROBUST_LOSSES:
        raise ShapeError(f"robust must be one of {', '.join(ROBUST_LOSSES)}, got {robust!r}")
    if len(noise) != 2 or not all(np.isfinite(v) and v > 0 for v in noise):
        raise ShapeError(f"noise must be (position [m], rotation [rad]), both > 0, got {noise!r}")
    if not 0.0 <= holdout < 1.0:
        raise ShapeError(f"holdout must be a fraction in [0, 1), got {holdout!r}")
    q = np.asarray(q, dtype=float)
    if q.ndim != 2 or q.shape[1] != robot.dof or not 2 <= q.shape[0] <= MAX_POSES:
        raise ShapeError(f"q: expected shape (poses, {robot.dof}) with 2 to {MAX_POSES} poses, got {q.shape}")
    M = np.asarray(measured, dtype=float)
    m = q.shape[0]
    if M.shape == (m, 4, 4):
        p, R = M[:, :3, 3], M[:, :3, :3]
    elif kind == "position" and M.shape == (m, 3):
        p, R = M, None
    else:
        want = f"({m}, 4, 4)" + (f" or ({m}, 3)" if kind == "position" else "")
        raise ShapeError(f"measured: expected shape {want}, got {M.shape}")
    if not (np.all(np.isfinite(q)) and np.all(np.isfinite(M))):
        raise ShapeError("q and measured must be finite numbers (got nan or inf)")
    if R is not None:
        err = np.abs(R @ np.swapaxes(R, -1, -2) - np.eye(3)).max(axis=(1, 2))
        if err.max() > 1e-6:
            raise ShapeError(f"measured: pose {int(np.argmax(err)) + 1} has a rotation part that is not a rotation "
                             f"(|R Rᵀ − I| = {err.max():.2g})")
    return q, p, (R if kind == "pose" else None)


def _stats(model: ErrorModel, x_full, q, p, R) -> tuple[ResidualStats, np.ndarray, np.ndarray | None]:
    """Errors of the model with corrections ``x_full`` against the measurements, and the per-pose errors."""
    T = model.pose(q, x_full)
    ep = np.linalg.norm(T[:, :3, 3] - p, axis=1)
    if R is None:
        return ResidualStats(len(q), float(np.sqrt(np.mean(ep**2))), float(ep.max())), ep, None
    er = np.linalg.norm(rotation_log(T[:, :3, :3] @ np.swapaxes(R, -1, -2)), axis=1)
    return (ResidualStats(len(q), float(np.sqrt(np.mean(ep**2))), float(ep.max()), float(np.sqrt(np.mean(er**2))),
                          float(er.max())), ep, er)


def _held_from_start(model: ErrorModel, base: bool, tool: bool) -> dict[int, str]:
    held = {k: p.held for k, p in enumerate(model.parameters) if p.held}
    for k, p in enumerate(model.parameters):
        for place, on in (("base", base), ("tool", tool)):
            if p.row == -1 and p.name.startswith(place + "_") and not on:
                held[k] = f"not calibrated ({place}=False)"
    return held


def _preference(model: ErrorModel) -> list[int]:
    """Base, tool, then the rows from the base (see :mod:`._kinematic_observe`)."""
    params = model.parameters
    base = [k for k, p in enumerate(params) if p.name.startswith("base_")]
    tool = [k for k, p in enumerate(params) if p.name.startswith("tool_")]
    return base + tool + [k for k, p in enumerate(params) if p.row >= 0]


def _fit(model: ErrorModel, q, p, R, noise, places, loss, rank_tol: float, max_iterations: int):
    """Observability, then Levenberg-Marquardt on the identifiable corrections; repeated from the solution (at most
    :data:`_PASSES` times) until the identifiable set no longer changes: identifiability is judged where the
    Jacobian is evaluated, and the nominal arm can be a special point (a Puma's tool point on its wrist centre
    makes the wrist's parameters invisible to position data there, not at the real tool)."""
    names = tuple(prm.name for prm in model.parameters)
    x_full = np.zeros(len(names))
    every = np.arange(len(names))
    identified: tuple[int, ...] = ()
    for _ in range(_PASSES):
        r0, J0 = _Problem(model, q, p, R, noise, every).residuals(x_full)
        obs = observability(J0, _preference(model), names, _held_from_start(model, *places), rank_tol)
        if len(r0) <= obs.rank:
            raise ShapeError(f"too few measurements: {len(q)} poses give {len(r0)} equations for {obs.rank} "
                             f"identifiable parameters; measure more poses")
        if obs.identified == identified:
            break
        identified = obs.identified
        problem = _Problem(model, q, p, R, noise, identified)
        solution = _levenberg_marquardt(problem, x_full[list(identified)], *loss, max_iterations)
        x_full = problem.full(solution[0])
    return obs, problem, solution


def _split(m: int, holdout: float, seed: int) -> tuple[np.ndarray, np.ndarray]:
    n_out = int(round(holdout * m))
    order = np.random.default_rng(seed).permutation(m)
    return np.sort(order[n_out:]), np.sort(order[:n_out])


def calibrate(robot: DHRobot, q, measured, kind: str = "pose", *, noise: tuple[float, float] = (1e-4, 1e-4),
              base: bool = True, tool: bool = True, robust: str = "huber", robust_scale: float = 3.0,
              holdout: float = 0.0, seed: int = 0, labels=None, parallel_tolerance: float = PARALLEL_TOLERANCE,
              rank_tol: float = RANK_TOLERANCE, max_iterations: int = MAX_ITERATIONS) -> CalibrationResult:
    """Fit the arm's DH parameters, base and tool to measured end-effector poses (or positions).

    Parameters
    ----------
    robot : DHRobot
        The nominal arm (the starting point, and the values of held parameters).
    q : array_like, shape (m, n)
        Joint readings of the m measurements [rad, m].
    measured : array_like, shape (m, 4, 4), or (m, 3) with ``kind="position"``
        Measured end-effector poses (world frame) or positions [m].
    kind : {"pose", "position"}
        Which part of the measurement is fitted.
    noise : (float, float)
        Standard deviation of the measurement noise: position [m] per axis, orientation [rad] per axis; the
        residuals are divided by them.
    base, tool : bool
        Calibrate the base / tool transform (6 corrections each, in their own axes: x y z, then rotations rx ry
        rz applied in that order).
    robust : {"huber", "cauchy", "none"}
        Robust loss, with ``robust_scale`` its scale k in noise units.
    holdout : float
        Fraction of the measurements left out of the fit to validate the calibrated model; ``seed`` chooses them
        (a permutation by ``numpy.random.default_rng(seed)``, the last ``1 - holdout`` of it fitted).
    labels : array_like of int, optional
        A label per measurement (file lines) for the worst-pose report; 1-based indices otherwise.
    parallel_tolerance : float
        Consecutive joint axes within this angle of parallel get a Hayati β [rad].
    rank_tol : float
        Identifiability threshold (see :mod:`denavit.calibration._kinematic_observe`).
    max_iterations : int
        Levenberg–Marquardt iterations at most (per pass; ``converged`` says whether it stopped earlier).

    Returns
    -------
    CalibrationResult
        The calibrated robot, every parameter's estimate and σ (or why it is held), rank and condition number,
        residuals before and after (fitted and held-out measurements), the worst poses.

    Raises
    ------
    ShapeError
        Inputs of the wrong shape, not finite, too few measurements for the identifiable unknowns.
    """
    q, p, R = _checked(robot, q, measured, kind, noise, robust, holdout)
    labels = np.arange(1, len(q) + 1) if labels is None else np.asarray(labels, dtype=int)
    fit, out = _split(len(q), holdout, seed)
    start = registered_start(robot, q[fit], p[fit]) if base else robot
    model = error_model(start, parallel_tolerance)
    R_fit = None if R is None else R[fit]
    obs, problem, solution = _fit(model, q[fit], p[fit], R_fit, noise, (base, tool), (robust, robust_scale),
                                  rank_tol, max_iterations)
    x_full = problem.full(solution[0])
    params, s2, cov = _estimates(model, obs, solution, x_full)
    nominal = model if start is robot else error_model(robot, parallel_tolerance)
    before = _stats(nominal, np.zeros_like(x_full), q[fit], p[fit], R_fit)[0]
    after, worst = _fitted_report(model, x_full, q[fit], p[fit], R_fit, labels[fit], noise)
    held_out = [None, None]
    if len(out):
        R_out = None if R is None else R[out]
        held_out = [_stats(m_, x_, q[out], p[out], R_out)[0] for m_, x_ in ((nominal, 0 * x_full), (model, x_full))]
    note = f"kinematics calibrated from {len(fit)} measured {kind}s"
    iterations, converged = solution[4], solution[5]
    notes = _notes(q[fit], model, converged) + (() if start is robot else (REGISTERED_NOTE,))
    return CalibrationResult(
        calibrated_robot(start, model, x_full, note), robot, kind, tuple(float(v) for v in noise), params, obs.rank,
        obs.condition_number, before, after, held_out[0], held_out[1], worst, iterations, converged, s2, cov,
        tuple(r + 1 for r in model.beta_rows), notes)


def _estimates(model: ErrorModel, obs, solution, x_full: np.ndarray):
    """Every parameter's estimate and σ: Cov = s² (JᵀWJ)⁻¹, s² = Σ w r² / (N − rank) (see the module notes)."""
    _, r, J, w, _, _ = solution
    s2 = float(np.sum(w * r * r) / (len(r) - obs.rank))
    cov = s2 * np.linalg.pinv(J.T @ (w[:, None] * J))
    sigma = dict(zip(obs.identified, np.sqrt(np.maximum(np.diag(cov), 0.0))))
    params = tuple(ParameterEstimate(prm.name, prm.unit, prm.nominal, prm.nominal + x_full[k], x_full[k],
                                     float(sigma.get(k, np.nan)), k in sigma, obs.held.get(k, ""))
                   for k, prm in enumerate(model.parameters))
    return params, s2, cov


def _fitted_report(model: ErrorModel, x_full: np.ndarray, q, p, R, labels, noise):
    """Residuals after calibration on the fitted measurements, and the worst poses (largest error in noise units)."""
    after, ep, er = _stats(model, x_full, q, p, R)
    score = ep / noise[0] + (0.0 if er is None else er / noise[1])
    worst = tuple(WorstPose(int(labels[i]), float(ep[i]), None if er is None else float(er[i]))
                  for i in np.argsort(-score)[:_WORST])
    return after, worst


def _notes(q: np.ndarray, model: ErrorModel, converged: bool) -> tuple[str, ...]:
    notes = []
    span = q.max(axis=0) - q.min(axis=0)
    for k in np.flatnonzero(span <= 1e-9):
        notes.append(f"joint {k + 1} never moved (q{k + 1} = {q[0, k]:.6g} in every measurement): the parameters "
                     "that only its motion would separate are held")
    for r in model.beta_rows:
        notes.append(f"row {r + 1} joins nearly parallel joint axes: Hayati beta{r + 1} (rotation "
                     f"about the row's y axis) estimated, d{r + 1} held")
    if not converged:
        notes.append("Levenberg-Marquardt stopped at its iteration limit before converging")
    return tuple(notes)
