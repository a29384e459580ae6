"""The arm as the singularity checker samples it (random q within limits, the rank ratio of J's rows) and points on
zero sets {f(q) = 0}: roots along one joint by bracketing and Brent's method, double roots by a bounded minimum.
"""

from __future__ import annotations

import numpy as np

from .. import numeric as N
from ..model import DHRobot, Frame, JointType

__all__ = ["Arm", "roots_along", "scale_of", "zero_set_points"]


class Arm:
    """The robot, the rows of J taken and cheap numeric helpers (random q, rank ratio, limits)."""

    def __init__(self, robot: DHRobot, rows: list[int], frame: Frame, rng: np.random.Generator) -> None:
        self.robot, self.rows, self.frame, self.rng = robot, rows, frame, rng
        self.rev = np.array([t is JointType.REVOLUTE for t in robot.joint_types])
        ranges = robot.sampling_ranges(1.0)  # ±1 m for a prismatic joint without limits
        turn = np.where(self.rev, np.pi, np.inf)  # revolute joints within one turn (the rest repeats)
        self.lo, self.hi = np.maximum(ranges[:, 0], -turn), np.minimum(ranges[:, 1], turn)
        self.params = dict(robot.parameters)

    def random_q(self, k: int = 1) -> np.ndarray:
        return self.rng.uniform(self.lo, self.hi, (k, self.robot.dof))

    def ratio(self, Q: np.ndarray) -> np.ndarray:
        """σ_min / σ_max of the selected rows of J at each row of Q (k, n) → (k,)."""
        J = N.geometric_jacobian(self.robot, Q, frame=self.frame)[..., self.rows, :]
        s = np.linalg.svd(J, compute_uv=False)
        return s[..., -1] / np.maximum(s[..., 0], 1e-300)

    def env(self, Q: np.ndarray) -> dict:
        out: dict = dict(self.params)
        out.update({f"q{k + 1}": Q[..., k] for k in range(self.robot.dof)})
        return out

    def same_angle(self, a, b, j: int, tol: float) -> bool:
        d = a - b
        if self.rev[j]:
            d = (d + np.pi) % (2 * np.pi) - np.pi
        return bool(abs(d) <= tol)


def roots_along(fn, q: np.ndarray, j: int, lo: float, hi: float, scale: float) -> list[float]:
    """Roots of x ↦ fn(q with q_j = x) in [lo, hi]: sign changes refined by Brent, and double roots."""
    from scipy.optimize import brentq, minimize_scalar

    xs = np.linspace(lo, hi, 721)
    Q = np.repeat(q[None], len(xs), 0)
    Q[:, j] = xs
    h = fn(Q)

    def f(x: float) -> float:
        qq = q.copy()
        qq[j] = x
        return float(fn(qq[None])[0])

    out = []
    for k in range(len(xs) - 1):
        a, b = h[k], h[k + 1]
        if not (np.isfinite(a) and np.isfinite(b)):
            continue
        if a == 0:
            out.append(xs[k])
        elif a * b < 0:
            out.append(brentq(f, xs[k], xs[k + 1], xtol=1e-15, rtol=1e-15))
        elif 0 < k and abs(a) < 1e-2 * scale and abs(a) <= abs(h[k - 1]) and abs(a) <= abs(b):
            r = minimize_scalar(lambda x: abs(f(x)), bounds=(xs[k - 1], xs[k + 1]), method="bounded",
                                options={"xatol": 1e-14})
            if abs(r.fun) <= 1e-10 * scale:
                out.append(float(r.x))
    if np.isfinite(h[-1]) and h[-1] == 0:
        out.append(xs[-1])
    return out


def scale_of(fn, arm: Arm) -> float:
    vals = np.abs(fn(arm.random_q(32)))
    vals = vals[np.isfinite(vals)]
    return float(np.median(vals)) if vals.size else 0.0


def zero_set_points(fn, variables: list[int], arm: Arm, scale: float, count: int = 4) -> list[np.ndarray]:
    """Points on {fn = 0}: every root along a lone variable, or random roots along random variables."""
    pts: list[np.ndarray] = []
    if len(variables) == 1:
        j = variables[0]
        for r in roots_along(fn, arm.random_q()[0], j, arm.lo[j], arm.hi[j], scale)[:12]:
            for q in arm.random_q(2):
                q[j] = r
                pts.append(q)
        return pts
    for _ in range(6 * count):
        q = arm.random_q()[0]
        j = int(arm.rng.choice(variables))
        roots = roots_along(fn, q, j, arm.lo[j], arm.hi[j], scale)
        if roots:
            q[j] = roots[int(arm.rng.integers(len(roots)))]
            pts.append(q)
        if len(pts) >= count:
            break
    return pts
