"""Better seeds for the numerical IK: a per-robot bank of configurations, and the closed form as a fallback.

Random restarts alone leave two kinds of reachable targets unsolved (measured on 2000 FK targets per
catalogue arm, see docs/ik.md):

* targets whose in-limit solutions have a small basin, e.g. Panda poses whose folded-back free solutions
  all lie outside the tight limits of joints 4 and 6: the first restarts are therefore taken from a bank of
  configurations sampled once per robot within the limits, nearest in pose space first (the
  "nearest precomputed configuration" seed of IK libraries such as TRAC-IK's and bio_ik's memetic seeding);
* targets next to a singularity (wrist centre on the shoulder axis, stretched elbow), where LM creeps along a
  curved valley at a linear rate: when the arm has a closed form (:func:`~denavit.analytic_ik`), its
  solutions are the seeds — the one nearest the caller's seed first — and LM only polishes them.

Success is still decided by the caller with an independent forward-kinematics pass.
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np

from ..model import DHRobot
from ..numeric import forward_kinematics
from ._analytic import analytic_ik, ik_structure
from ._residual import pose_error

__all__ = ["SeedBank", "seed_bank", "closed_form_seeds"]

BANK_SIZE = 4096
BANK_SEEDS = 8  # restarts of a target taken from the bank before random ones


class SeedBank:
    """Configurations ``q`` (M, n) within the limits and their end-effector poses as features (M, 12)."""

    def __init__(self, robot: DHRobot, lo: np.ndarray, hi: np.ndarray, revolute: np.ndarray, L: float) -> None:
        rng = np.random.default_rng(20240611)  # fixed: the bank is a constant of the robot
        lo = np.where(np.isfinite(lo), lo, np.where(revolute, -np.pi, -L))
        hi = np.where(np.isfinite(hi), hi, np.where(revolute, np.pi, L))
        self.q = rng.uniform(lo, hi, size=(BANK_SIZE, len(lo)))
        self.L = L
        self.p, self.R = _features(forward_kinematics(robot, self.q), L)

    def nearest(self, T: np.ndarray, mask: np.ndarray, k: int = BANK_SEEDS) -> np.ndarray:
        """Indices (b, k) of the k bank poses nearest to the targets T (b, 4, 4), nearest first.

        Distance² = Σ_masked (Δp/L)² + ½‖ΔR‖²_F (≈ θ² for a small rotation angle θ) when any rotation row is
        matched."""
        p, R = _features(T, self.L)
        d = ((p * mask[:3]) ** 2).sum(-1)[:, None] - 2 * (p * mask[:3]) @ (self.p * mask[:3]).T
        d += ((self.p * mask[:3]) ** 2).sum(-1)[None]
        if mask[3:].any():
            d += 3.0 - R @ self.R.T  # ½‖R_a − R_b‖² = 3 − tr(R_aᵀ R_b)
        k = min(k, len(self.q))
        idx = np.argpartition(d, k - 1, axis=1)[:, :k]
        order = np.argsort(np.take_along_axis(d, idx, 1), axis=1)
        return np.take_along_axis(idx, order, 1)


def _features(T: np.ndarray, L: float) -> tuple[np.ndarray, np.ndarray]:
    return T[..., :3, 3] / L, T[..., :3, :3].reshape(T.shape[:-2] + (9,))


@lru_cache(maxsize=32)
def _bank(robot: DHRobot, lo: tuple, hi: tuple, L: float) -> SeedBank:
    from ..model import JointType

    revolute = np.array([t is JointType.REVOLUTE for t in robot.joint_types])
    return SeedBank(robot, np.array(lo), np.array(hi), revolute, L)


def seed_bank(robot: DHRobot, lo: np.ndarray, hi: np.ndarray, L: float) -> SeedBank:
    """The (cached) bank of ``robot`` for the limits [lo, hi]."""
    return _bank(robot, tuple(map(float, lo)), tuple(map(float, hi)), float(L))


@lru_cache(maxsize=64)
def _has_closed_form(robot: DHRobot) -> bool:
    from ..errors import UnsupportedRobotError

    try:
        ik_structure(robot)
    except UnsupportedRobotError:
        return False
    return True


def closed_form_seeds(robot: DHRobot, T: np.ndarray, q_ref: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Closed-form solutions of the targets T (b, 4, 4), ordered by distance to q_ref (b, n).

    Returns q (b, K, n) (NaN where a target has fewer solutions) and valid (b, K); K = 0 when the arm has no
    closed form.  Angles are compared modulo 2π for the ordering."""
    b, n = q_ref.shape
    if b == 0 or not _has_closed_form(robot):
        return np.zeros((b, 0, n)), np.zeros((b, 0), dtype=bool)

    res = analytic_ik(robot, T)
    q, valid = res.solutions, res.valid
    d = np.angle(np.exp(1j * (np.nan_to_num(q) - q_ref[:, None])))  # wrapped difference, fine for ordering
    dist = np.where(valid, np.abs(d).max(axis=-1), np.inf)
    order = np.argsort(dist, axis=1)
    return np.take_along_axis(q, order[..., None], 1), np.take_along_axis(valid, order, 1)


RESCUE_BANK_SEEDS = 128  # bank seeds per target in the rescue pass


def rescue(robot: DHRobot, T: np.ndarray, q_ref: np.ndarray, mask: np.ndarray, limits, L: float, polish):
    """Second chance for the targets (b, 4, 4) the random restarts left unsolved.

    Seeds, in order: the closed-form solutions nearest ``q_ref`` first, then the ``RESCUE_BANK_SEEDS``
    nearest bank configurations; all of them are polished at once by ``polish(q0 (m, n), T (m, 4, 4))`` (LM
    without restarts) and, per target, the first seed whose polished end point passes the FK test is taken.
    Returns q (b, n) (rows not solved keep NaN) and the number of seeds used per target (b,)."""
    b, n = q_ref.shape
    qc, valid = closed_form_seeds(robot, T, q_ref)
    bank = seed_bank(robot, limits.lo, limits.hi, L)
    qb = bank.q[bank.nearest(T, mask, RESCUE_BANK_SEEDS)]  # (b, k, n)
    seeds = np.concatenate([qc, qb, qb], axis=1)  # bank seeds twice: iterated free (then folded), and clipped
    use = np.concatenate([valid, np.ones(qb.shape[:2] * np.array([1, 2]), dtype=bool)], axis=1)
    clipped = np.arange(seeds.shape[1]) >= qc.shape[1] + qb.shape[1]
    tgt, slot = np.nonzero(use)
    q = limits.project(polish(limits.project(seeds[tgt, slot]), T[tgt], clipped[slot]))
    e = pose_error(T[tgt], forward_kinematics(robot, q))
    tol = polish.tol
    ok = (np.linalg.norm(e[:, :3] * mask[:3], axis=-1) <= tol) & (np.linalg.norm(e[:, 3:] * mask[3:], axis=-1) <= tol)
    ok &= limits.inside(q)
    out = np.full((b, n), np.nan)
    hit = np.flatnonzero(ok)[::-1]  # written last-to-first, so the first good seed of a target wins
    out[tgt[hit]] = q[hit]
    return out, use.sum(axis=1)
