"""Excitation trajectories for dynamic identification: finite Fourier series that make the base regressor well
conditioned, inside the joints' position, velocity and acceleration limits.

Joint i follows (Swevers, Ganseman, Tükel, De Schutter & Van Brussel 1997, eq. 9)

.. math::

    q_i(t) = q_{i0} + \\sum_{l=1}^{H} \\frac{a_{il}}{\\omega_f l} \\sin(\\omega_f l t)
                                     - \\frac{b_{il}}{\\omega_f l} \\cos(\\omega_f l t),

so q̇_i = Σ a_il cos(ω_f l t) + b_il sin(ω_f l t) and q̈_i = Σ ω_f l (b_il cos(ω_f l t) − a_il sin(ω_f l t)),
exactly.  The series is periodic (period 1/f): it does NOT start or end at rest — q̇(0) = Σ_l a_il — but the end
of one period joins the start of the next smoothly, so the period can be repeated and averaged.

The coefficients minimise log cond(W_b), W_b the base regressor (:func:`denavit.numeric.base_regressor`) stacked
at evenly spaced instants, subject to the limits at a grid of instants: linear constraints on the coefficients,
solved by SLSQP (Kraft 1988) from a few seeded random feasible starts.  The gradient is exact in the series and
uses differences of the regressor in q and q̇ (q̈ enters Y linearly: a unit difference is exact).  Afterwards
each joint's oscillation is scaled down, if needed, so the limits hold at EVERY instant, not only at the grid:
between grid points h apart a function whose second derivative is at most M exceeds its grid values by at most
M h²/8, and M is bounded by the series' coefficients (Σ_l (ω_f l)^k |c_il|).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import ModelError, ShapeError
from ..model import DHRobot, JointType, sampling_ranges
from ..numeric import base_parameters, base_regressor
from ._excite_series import (
    CHECK_PER_HARMONIC,
    feasible_start,
    fourier_basis,
    fourier_series,
    limit_constraints,
    within_limits,
)

__all__ = ["DEFAULT_QDD_MAX", "DEFAULT_QD_MAX", "ExcitationTrajectory", "excitation_trajectory", "fourier_series"]

#: Velocity limits used when none are given [rad/s for revolute joints, m/s for prismatic ones].
DEFAULT_QD_MAX = {JointType.REVOLUTE: 1.0, JointType.PRISMATIC: 0.25}
#: Acceleration limits used when none are given [rad/s², m/s²].
DEFAULT_QDD_MAX = {JointType.REVOLUTE: 4.0, JointType.PRISMATIC: 1.0}
#: The position window of a joint without limits, about 0 [rad, m].
UNLIMITED_WINDOW = {JointType.REVOLUTE: np.pi, JointType.PRISMATIC: 0.5}
MAX_HARMONICS = 20
MAX_SAMPLES = 10**6  # output samples (three (k, n) arrays)
DEFAULT_RATE = 100.0  # output samples per second when samples= is not given [Hz]
MAX_STARTS = 20
MAX_ITERATIONS = 1000
FD_STEP = 1e-6  # step of the regressor's differences in q and q̇ [rad, rad/s]
GRID_PER_HARMONIC = 8  # constraint instants per period and harmonic (ω_H h = 2π/8 between them)
ACTIVE_TOL = 1e-3  # a limit counts as active when used to within this fraction
TINY = 1e-300
RANK_TOL = 1e-10  # relative singular-value threshold of the reported rank
FEASIBLE_TOL = 1e-3  # an SLSQP iterate counts as within the limits to this fraction of each


@dataclass(frozen=True, eq=False)  # holds arrays: compared by identity
class ExcitationTrajectory:
    """A designed excitation trajectory (data only; :func:`excitation_trajectory` makes it).

    Attributes
    ----------
    robot : str
    base_freq : float
        f [Hz]; ω_f = 2π f; the period 1/f.
    q0 : ndarray, shape (n,)
        Offsets [rad, m].
    a, b : ndarray, shape (n, H)
        Sine and cosine coefficients of q̇ [rad/s, m/s] (module equation).
    t : ndarray, shape (k,)
        Sample times [s]: t_j = j · duration / k (the end excluded: with one period it is t = 0 again).
    q, qd, qdd : ndarray, shape (k, n)
        The series and its exact derivatives at ``t``.
    cond_initial, cond : float
        cond(W_b) = σ_max/σ_min (SVD) at ``instants`` of the first start's random trajectory and of the result;
        inf when σ_min = 0.
    instants : ndarray, shape (m,)
        Where the regressor is stacked for the condition number.
    rank, n_base : int
        Rank of W_b at ``instants`` (singular values above RANK_TOL = 1e-10 of the largest) and the number of base
        parameters: rank < n_base says the trajectory leaves some base parameters unidentifiable.
    q_limits : ndarray, shape (n, 2)
        The position window used (the robot's limits shrunk by the margin).
    qd_max, qdd_max : ndarray, shape (n,)
        The velocity and acceleration limits used.
    usage : ndarray, shape (n, 3)
        Fraction of each limit used over all t (position: 1 − the closest approach to the window's edge over its
        width, so 1 means touching; velocity, acceleration: max |·| / limit).
    active : ndarray, shape (n, 3), bool
        usage ≥ 1 − ACTIVE_TOL.
    iterations, evaluations, starts : int
        SLSQP iterations and regressor stacks summed over the starts; the number of starts.
    message : str
        SLSQP's message of the chosen start.
    """

    robot: str
    base_freq: float
    q0: np.ndarray
    a: np.ndarray
    b: np.ndarray
    t: np.ndarray
    q: np.ndarray
    qd: np.ndarray
    qdd: np.ndarray
    cond_initial: float
    cond: float
    instants: np.ndarray
    rank: int
    n_base: int
    q_limits: np.ndarray
    qd_max: np.ndarray
    qdd_max: np.ndarray
    usage: np.ndarray
    active: np.ndarray
    iterations: int
    evaluations: int
    starts: int
    message: str

    @property
    def harmonics(self) -> int:
        return int(self.a.shape[1])

    @property
    def period(self) -> float:
        return 1.0 / self.base_freq


def _limits(robot: DHRobot, margin: float, q_limits, qd_max, qdd_max):
    """(window (n, 2), qd_max (n,), qdd_max (n,)) from the arguments, else the robot and the defaults."""
    n, types = robot.dof, robot.joint_types
    lim = robot.q_limits if q_limits is None else np.array(q_limits, dtype=float)
    if lim.shape != (n, 2):
        raise ShapeError(f"q_limits: expected shape ({n}, 2) for a {n}-joint robot, got {lim.shape}")
    if np.isnan(lim).any() or not np.all(lim[:, 0] <= lim[:, 1]):
        raise ValueError("q_limits: each row must be [low, high] with low <= high (no NaN)")
    lim = sampling_ranges(lim, [jt is JointType.REVOLUTE for jt in types], UNLIMITED_WINDOW[JointType.PRISMATIC])
    width = lim[:, 1] - lim[:, 0]
    window = np.column_stack([lim[:, 0] + margin * width, lim[:, 1] - margin * width])
    tight = np.flatnonzero(window[:, 1] - window[:, 0] <= 1e-9)
    if tight.size:
        raise ModelError(f"joint {tight[0] + 1}: its limits [{lim[tight[0], 0]:.6g}, {lim[tight[0], 1]:.6g}] "
                         f"leave no room to move (margin {margin:g} of the range each side)")
    rates = []
    for value, default, what in ((qd_max, DEFAULT_QD_MAX, "qd_max"), (qdd_max, DEFAULT_QDD_MAX, "qdd_max")):
        v = np.array([default[jt] for jt in types]) if value is None else np.array(value, dtype=float)
        v = np.full(n, float(v)) if v.ndim == 0 else v
        if v.shape != (n,):
            raise ShapeError(f"{what}: expected one value or {n}, got shape {v.shape}")
        if not np.all(np.isfinite(v) & (v > 0)):
            raise ValueError(f"{what}: every limit must be a finite number > 0, got {v.tolist()}")
        rates.append(v)
    return window, rates[0], rates[1]


class _Problem:
    """log cond(W_b(x)) and its gradient, W_b stacked at ``instants`` (the last few values kept by x)."""

    def __init__(self, robot, base, instants, H, w):
        self.robot, self.base, self.n, self.H = robot, base, robot.dof, H
        self.instants = instants
        self.P, self.V, self.A = fourier_basis(instants, H, w)
        names = [base.names[i] for i in base.independent]
        self.coulomb = np.array([name.startswith("FC") for name in names])  # sign(q̇): no derivative
        self.evaluations, self.seen = 0, {}

    def states(self, x):
        X = x.reshape(self.n, 2 * self.H + 1)
        return self.P @ X.T, self.V @ X.T, self.A @ X.T  # (m, n) each

    def log_cond(self, x) -> float:
        key = np.asarray(x, dtype=float).tobytes()
        if key not in self.seen:  # SLSQP's callback asks again for the point its line search accepted
            self.evaluations += 1
            W = base_regressor(self.robot, *self.states(x), self.base, threads=1).reshape(-1, len(self.coulomb))
            lam = np.linalg.eigvalsh(_gram(W))
            self.seen = {key: 0.5 * float(np.log(lam[-1] / max(lam[0], TINY * lam[-1], TINY))),
                         **dict(list(self.seen.items())[-3:])}
        return self.seen[key]

    def gradient(self, x) -> np.ndarray:
        """d log cond / dx.  cond² = λ_max/λ_min of WᵀW, dλ = 2 (W v)ᵀ dW v for its unit eigenvector v (Golub &
        Van Loan 4th ed. §8.1.2), chained through q, q̇, q̈ = P x, V x, A x."""
        n, m = self.n, self.P.shape[0]
        q, qd, qdd = self.states(x)
        Q, QD, QDD = (np.repeat(v[:, None, :], 1 + 3 * n, axis=1) for v in (q, qd, qdd))  # (m, 1 + 3n, n)
        eye = np.eye(n)
        Q[:, 1:1 + n] += FD_STEP * eye
        QD[:, 1 + n:1 + 2 * n] += FD_STEP * eye
        QDD[:, 1 + 2 * n:] += eye  # Y is linear in q̈: a unit step is exact
        Y = base_regressor(self.robot, Q, QD, QDD, self.base, threads=1)  # (m, 1 + 3n, n, r)
        self.evaluations += 1
        W = Y[:, 0].reshape(m * n, -1)
        lam, vec = np.linalg.eigh(_gram(W))
        lo, hi = vec[:, 0], vec[:, -1]
        G = (np.outer(W @ hi, hi) / lam[-1] - np.outer(W @ lo, lo) / max(lam[0], TINY * lam[-1], TINY))
        G = G.reshape(m, n, -1)
        dY = Y[:, 1:] - Y[:, :1]  # (m, 3n, n, r)
        dY[:, : 2 * n] /= FD_STEP
        dY[:, n:2 * n, :, self.coulomb] = 0.0
        g = np.einsum("mknr,mnr->mk", dY, G)  # (m, 3n)
        gX = self.P.T @ g[:, :n] + self.V.T @ g[:, n:2 * n] + self.A.T @ g[:, 2 * n:]  # (2H + 1, n)
        return gX.T.ravel()


def _gram(W: np.ndarray) -> np.ndarray:
    """WᵀW by einsum: a threaded BLAS product (and a threaded SVD) of these small matrices costs 10-100 times the
    CPU on a busy machine."""
    return np.einsum("ij,ik->jk", W, W)


def excitation_trajectory(robot: DHRobot, *, harmonics: int = 5, base_freq: float = 0.1, duration: float | None = None,
                          samples: int | None = None, margin: float = 0.05, q_limits=None, qd_max=None, qdd_max=None,
                          friction: bool = True, motor_inertia: bool = True, seed: int | None = 0, starts: int = 2,
                          max_iterations: int = 10, instants: int | None = None, center: bool = False,
                          progress=None) -> ExcitationTrajectory:
    """A finite-Fourier-series trajectory within the limits that minimises cond(W_b) (module notes).

    Parameters
    ----------
    robot : DHRobot
        Its inertial values are not used: W_b depends on the geometry only.
    harmonics : int
        H, 1 … 20.
    base_freq : float
        f [Hz] (period 1/f; the highest frequency is H f).
    duration : float, optional
        [s]; one period by default.  Longer durations repeat the period.
    samples : int, optional
        Output samples over ``duration``, end excluded (default 100 per second, at least 2).
    margin : float
        Each side of the robot's position limits is moved in by this fraction of the range (0 … 0.5).
    q_limits : array_like, shape (n, 2), optional
        Position limits instead of the robot's [rad, m]; a joint without limits gets ±π rad or ±0.5 m.
    qd_max, qdd_max : float or array_like (n,), optional
        Velocity [rad/s, m/s] and acceleration [rad/s², m/s²] limits (:data:`DEFAULT_QD_MAX`,
        :data:`DEFAULT_QDD_MAX` by default: robot files carry no such limits).
    friction, motor_inertia : bool
        Which base parameters are to be identified (as :func:`denavit.numeric.base_parameters`).
    seed : int, optional
        The random starts' seed (the same result for the same arguments).
    starts, max_iterations : int
        The budget: SLSQP from ``starts`` random feasible starts, at most ``max_iterations`` iterations each (each
        iteration stacks the regressor at ``instants`` × (1 + 3n) states once, plus its line search).
    instants : int, optional
        Instants where W_b is stacked (default max(50, ⌈3 r / n⌉), r base parameters, n joints).
    center : bool
        Hold each offset q_i0 at the middle of its position window (by default q_i0 starts there and is optimised
        with the other coefficients).
    progress : callable(str), optional
        Called at each start and each SLSQP iteration.

    Returns
    -------
    ExcitationTrajectory

    References
    ----------
    J. Swevers, C. Ganseman, D. B. Tükel, J. De Schutter, H. Van Brussel, "Optimal robot excitation and
    identification", IEEE Trans. Robotics and Automation 13(5), 1997, eq. 9 and §IV.
    """
    H, starts, max_iterations = (_whole(v, name, 1, hi) for v, name, hi in (
        (harmonics, "harmonics", MAX_HARMONICS), (starts, "starts", MAX_STARTS),
        (max_iterations, "max_iterations", MAX_ITERATIONS)))
    base_freq = _positive(base_freq, "base_freq")
    duration = 1.0 / base_freq if duration is None else _positive(duration, "duration")
    samples = _samples(samples, duration)
    margin = float(margin)
    if not 0 <= margin < 0.5:
        raise ValueError(f"margin must be in [0, 0.5), got {margin!r}")
    window, qd_lim, qdd_lim = _limits(robot, float(margin), q_limits, qd_max, qdd_max)
    base = base_parameters(robot, friction=friction, motor_inertia=motor_inertia)
    n, w = robot.dof, 2 * np.pi * base_freq
    period = 1.0 / base_freq
    span = min(duration, period)
    m = max(50, -(-3 * base.rank // n)) if instants is None else _whole(instants, "instants", 2, 10**5)
    at = np.linspace(0.0, span, m, endpoint=span < period)
    grid = np.linspace(0.0, span, int(np.ceil(GRID_PER_HARMONIC * H * span / period)) + 2)
    C, d = limit_constraints(grid, H, w, window, qd_lim, qdd_lim)
    problem = _Problem(robot, base, at, H, w)
    rng = np.random.default_rng(seed)
    best, first, iterations = None, None, 0
    for start in range(starts):
        x0 = feasible_start(rng, grid, H, w, window, qd_lim, qdd_lim)
        f0 = problem.log_cond(x0)
        first = x0 if first is None else first
        if progress is not None:
            progress(f"start {start + 1}/{starts}: cond {np.exp(f0):.4g}")
        nit, message, x = _solve(problem, x0, (C, d, window.mean(axis=1) if center else None), max_iterations,
                                 progress, f"start {start + 1}/{starts}")
        iterations += nit
        x = within_limits(x, span, H, w, window, qd_lim, qdd_lim)
        f = problem.log_cond(x)
        if best is None or f < best[0]:
            best = (f, x, message)
    return _result(robot, problem, best, first, (window, qd_lim, qdd_lim), base_freq, duration, samples, span,
                   iterations, starts)


def _solve(problem: _Problem, x0, constraints, max_iterations: int, progress, label: str):
    """SLSQP from x0 under C x + d ≥ 0 (and q_i0 = mid_i when ``mid`` is given); returns (iterations, message, x):
    x the iterate of least cond among those within the limits to FEASIBLE_TOL of each limit (SLSQP's iterates
    may step outside, and its last is not always its best)."""
    from scipy.optimize import minimize

    C, d, mid = constraints
    bounds = None
    if mid is not None:
        k = x0.size // mid.size
        bounds = [(mid[i // k], mid[i // k]) if i % k == 0 else (None, None) for i in range(x0.size)]
    best = [problem.log_cond(x0), x0]
    count = [0]

    def visit(xk):
        count[0] += 1
        f = problem.log_cond(xk)
        if f < best[0] and np.min(C @ xk + d) >= -FEASIBLE_TOL:
            best[:] = [f, xk.copy()]
        if progress is not None:
            progress(f"{label}, iteration {count[0]}: cond {np.exp(f):.4g}")

    res = minimize(problem.log_cond, x0, jac=problem.gradient, method="SLSQP", callback=visit, bounds=bounds,
                   constraints=[{"type": "ineq", "fun": lambda x: C @ x + d, "jac": lambda x: C}],
                   options={"maxiter": max_iterations, "ftol": 1e-6})
    return int(res.nit), str(res.message), best[1]


def _result(robot, problem, best, first, limits, base_freq, duration, samples, span, iterations, starts):
    window, qd_lim, qdd_lim = limits
    _, x, message = best
    n, H = robot.dof, problem.H
    X = x.reshape(n, 2 * H + 1)
    t = np.arange(samples) * (duration / samples)
    q, qd, qdd = fourier_series(X[:, 0], X[:, 1:H + 1], X[:, H + 1:], base_freq, t)
    fine = np.linspace(0.0, span, int(np.ceil(CHECK_PER_HARMONIC * H * span * base_freq)) + 2)
    fq, fqd, fqdd = fourier_series(X[:, 0], X[:, 1:H + 1], X[:, H + 1:], base_freq, fine)
    mid, half = window.mean(axis=1), (window[:, 1] - window[:, 0]) / 2
    usage = np.column_stack([np.abs(fq - mid).max(axis=0) / half, np.abs(fqd).max(axis=0) / qd_lim,
                             np.abs(fqdd).max(axis=0) / qdd_lim])
    (cond0, _), (cond, rank) = (_cond_rank(problem, v) for v in (first, x))
    return ExcitationTrajectory(robot.name, float(base_freq), X[:, 0].copy(), X[:, 1:H + 1].copy(),
                                X[:, H + 1:].copy(), t, q, qd, qdd, cond0, cond,
                                problem.instants, rank, problem.base.rank, window,
                                qd_lim, qdd_lim, usage, usage >= 1 - ACTIVE_TOL, iterations, problem.evaluations,
                                starts, message)


def _cond_rank(problem: _Problem, x) -> tuple[float, int]:
    """cond(W_b) = σ_max/σ_min by SVD (inf when σ_min = 0; the optimiser's Gram matrix squares it and floors it)
    and the rank: the σ > RANK_TOL σ_max."""
    W = base_regressor(problem.robot, *problem.states(x), problem.base, threads=1).reshape(-1, problem.base.rank)
    s = np.linalg.svd(W, compute_uv=False)
    return (float(s[0] / s[-1]) if s[-1] > 0 else float("inf")), int(np.sum(s > RANK_TOL * s[0]))


def _whole(value, name: str, lo: int, hi: int) -> int:
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or not lo <= value <= hi:
        raise ValueError(f"{name} must be a whole number in [{lo}, {hi}], got {value!r}")
    return int(value)


def _samples(samples, duration: float) -> int:
    if samples is not None:
        return _whole(samples, "samples", 2, MAX_SAMPLES)
    k = max(2, round(DEFAULT_RATE * duration))
    if k > MAX_SAMPLES:
        raise ValueError(f"duration {duration:g} s at {DEFAULT_RATE:g} samples/s is {k} samples (at most "
                         f"{MAX_SAMPLES}): give samples=")
    return k


def _positive(value, name: str) -> float:
    v = float(value)
    if not (np.isfinite(v) and v > 0):
        raise ValueError(f"{name} must be a finite number > 0, got {value!r}")
    return v
