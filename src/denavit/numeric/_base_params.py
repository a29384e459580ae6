"""Base (identifiable) inertial parameters, numerically: the independent columns of the stacked regressor.

Some of the standard parameters π never reach the joint torques (a body's mass on the first joint's axis) and
others only in fixed combinations (the mass of body j and the first moments of body j − 1): the columns of
Y(q, q̇, q̈) are linearly dependent for every motion.  Stacking Y at many random states into W, the base
parameters are the combinations π_b = K π with W π = W_b π_b, W_b the r independent columns of W (Gautier 1990;
Khalil & Dombre 2002, §14.5).
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from ..errors import ModelError
from ..model import DHRobot
from ._regressor import inertial_parameters, parameter_names, regressor

__all__ = ["BaseParameters", "base_parameters", "base_regressor", "BASE_TOL"]

#: Rank tolerance of :func:`base_parameters`: a column counts as independent of the ones before it when its
#: distance to their span exceeds BASE_TOL × its norm (after scaling every column of W to unit norm).
BASE_TOL = 1e-8
#: The smallest tolerance accepted: below it the rounding of float64 columns would count as independent.
MIN_TOL = 1e-15


@dataclass(frozen=True)
class BaseParameters:
    """The base parameters of an arm (data only; :func:`base_parameters` makes it).

    Attributes
    ----------
    names : tuple of str
        The standard parameters π (:func:`~denavit.numeric.parameter_names`), length p.
    independent : tuple of int
        Indices into ``names`` of the r parameters kept: Y_b = Y[..., independent].
    combination : ndarray, shape (r, p)
        K with π_b = K π: row i is 1 at ``independent[i]`` plus the dependent parameters grouped into it.
    values : ndarray, shape (r,)
        π_b of the robot (K times its π).
    base_names : tuple of str
        Names of π_b: the kept parameter's name, with ``R`` appended when others are grouped into it (Khalil's
        notation, e.g. ``XX2R = XX2 - YY2``).
    rules : tuple of str
        One line per grouped base parameter: ``XX2R = XX2 - 1*YY2`` (coefficients to 10 significant digits).
    unidentifiable : tuple of str
        Parameters that reach no torque at all (their column of Y is zero).
    rank, samples : int
        r, and the number of random states stacked.
    tol : float
        The rank tolerance used (see :data:`BASE_TOL`).
    """

    names: tuple[str, ...]
    independent: tuple[int, ...]
    combination: np.ndarray
    values: np.ndarray
    base_names: tuple[str, ...]
    rules: tuple[str, ...]
    unidentifiable: tuple[str, ...]
    rank: int
    samples: int
    tol: float
    friction: bool
    motor_inertia: bool


def _states(robot: DHRobot, samples: int, rng: np.random.Generator):
    """Random (q, q̇, q̈): angles in (−π, π], prismatic values within limits (or ±1 m), rates and accelerations
    in (−2, 2)."""
    n = robot.dof
    q = rng.uniform(-np.pi, np.pi, (samples, n))
    for k, link in enumerate(robot.joints):
        if link.joint.value == "prismatic":
            lo, hi = link.q_limits if link.q_limits is not None else (-1.0, 1.0)
            q[:, k] = rng.uniform(max(lo, -1e3), min(hi, 1e3), samples)
    return q, rng.uniform(-2, 2, (samples, n)), rng.uniform(-2, 2, (samples, n))


def base_parameters(robot: DHRobot, *, friction: bool = True, motor_inertia: bool = True, tol: float = BASE_TOL,
                    samples: int | None = None, rng: np.random.Generator | None = None) -> BaseParameters:
    """The base parameters of ``robot``, found from its regressor at random states.

    Parameters
    ----------
    friction, motor_inertia : bool
        Include the friction and motor-inertia parameters (as :func:`~denavit.numeric.regressor`).
    tol : float
        Rank tolerance, relative (:data:`BASE_TOL` = 1e-8): W's columns are scaled to unit norm; the rank r is the
        number of |R_ii| > tol·|R_11| of W's QR factorisation with column pivoting (Golub & Van Loan 4th ed.
        §5.4.2), and the parameters kept are the first r columns, in π's order, each farther than tol from the
        span of the ones before it (QR without pivoting; Gautier 1990), so the kept ones are those of the bodies
        nearer the base, XX before YY, M before MX — Khalil's choice.
    samples : int, optional
        Random states stacked (default max(50, 3p / n)).
    rng : numpy.random.Generator, optional
        Source of the states (default ``np.random.default_rng(0)``: the same result every run).

    Returns
    -------
    BaseParameters
        With W π = W_b π_b for every state, π_b = K π, K = [I  β] up to the columns' order, β = W_b⁺ W_d
        (least squares; entries below 1e-10 × the largest set to 0).

    Raises
    ------
    ModelError
        When the independent columns found by the two QR factorisations disagree in number (a W too
        ill-conditioned to decide: raise ``samples`` or ``tol``).
    """
    if rng is None:  # the default draw is a pure function of the arguments: computed once per robot
        return _base_parameters_cached(robot, friction, motor_inertia, float(tol), samples)
    return _base_parameters(robot, friction, motor_inertia, float(tol), samples, rng)


@lru_cache(maxsize=32)
def _base_parameters_cached(robot, friction, motor_inertia, tol, samples) -> BaseParameters:
    return _base_parameters(robot, friction, motor_inertia, tol, samples, np.random.default_rng(0))


def _base_parameters(robot, friction, motor_inertia, tol, samples, rng) -> BaseParameters:
    if not (MIN_TOL <= tol < 1):
        raise ValueError(f"tol must be in [{MIN_TOL:g}, 1), got {tol!r} (below, float64 rounding counts as rank)")
    names = parameter_names(robot, friction=friction, motor_inertia=motor_inertia)
    p, n = len(names), robot.dof
    samples = int(samples) if samples is not None else max(50, -(-3 * p // n))
    if samples * n < p:
        raise ValueError(f"samples={samples}: at least {-(-p // n)} states are needed for {p} parameters")
    q, qd, qdd = _states(robot, samples, rng)
    W = regressor(robot, q, qd, qdd, friction=friction, motor_inertia=motor_inertia).reshape(samples * n, p)
    norms = np.linalg.norm(W, axis=0)
    zero = norms <= tol * max(norms.max(), 1e-300)
    Wn = W / np.where(zero, 1.0, norms)
    Wn[:, zero] = 0.0
    rank = _pivoted_rank(Wn, tol)
    R = np.linalg.qr(Wn, mode="r")
    kept = [i for i in range(p) if not zero[i] and abs(R[i, i]) > tol]
    if len(kept) != rank:
        raise ModelError(f"robot {robot.name!r}: the regressor's rank is {rank} by pivoted QR but {len(kept)} "
                         f"columns are independent in order; raise samples= or tol= (tol={tol:g})")
    dep = [i for i in range(p) if i not in kept]
    K = np.zeros((rank, p))
    K[np.arange(rank), kept] = 1.0
    if dep:
        beta = np.linalg.lstsq(W[:, kept], W[:, dep], rcond=None)[0]  # (r, p − r)
        beta[np.abs(beta) < 1e-10 * max(1.0, np.abs(beta).max())] = 0.0
        K[:, dep] = beta
    values = K @ inertial_parameters(robot, friction=friction, motor_inertia=motor_inertia)
    K.flags.writeable = values.flags.writeable = False  # a cached result, shared
    base_names, rules = _rules(names, kept, K)
    return BaseParameters(names, tuple(kept), K, values, base_names, rules,
                          tuple(names[i] for i in range(p) if zero[i]), rank, samples, float(tol), friction,
                          motor_inertia)


def _pivoted_rank(W: np.ndarray, tol: float) -> int:
    from scipy.linalg import qr

    R = qr(W, mode="r", pivoting=True)[0]
    d = np.abs(np.diag(R))
    return int(np.sum(d > tol * d[0])) if d.size and d[0] > 0 else 0


def _rules(names, kept, K) -> tuple[tuple[str, ...], tuple[str, ...]]:
    base_names, rules = [], []
    for row, i in enumerate(kept):
        others = [(j, K[row, j]) for j in np.flatnonzero(K[row]) if j != i]
        if not others:
            base_names.append(names[i])
            continue
        name = names[i] + "R"
        terms = " ".join(f"{'-' if c < 0 else '+'} {_coefficient(c)}{names[j]}" for j, c in others)
        base_names.append(name)
        rules.append(f"{name} = {names[i]} {terms}")
    return tuple(base_names), tuple(rules)


def _coefficient(c: float) -> str:
    text = f"{abs(c):.10g}"
    return "" if text == "1" else text + "*"


def base_regressor(robot: DHRobot, q, qd, qdd, base: BaseParameters | None = None, *, gravity=None,
                   threads=None) -> np.ndarray:
    """Y_b(q, q̇, q̈) = Y[..., base.independent], shape (..., n, r): τ = Y_b π_b (``base.values`` for the robot)."""
    base = base_parameters(robot) if base is None else base
    Y = regressor(robot, q, qd, qdd, friction=base.friction, motor_inertia=base.motor_inertia, gravity=gravity,
                  threads=threads)
    return Y[..., list(base.independent)]
