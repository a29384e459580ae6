"""What an arm's joint axes are, for the IK plans: the structural tests (axes through one point, parallel),
merging coaxial joints, and the :class:`Plan` a structure is solved by (built in :mod:`._plans`).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Callable

import numpy as np

from ..chain import Screws, screw_axes

__all__ = ["GEOM_TOL", "Plan", "arm_scale", "sample_configs", "common_point", "axes_meet", "axes_parallel",
           "merge_coaxial", "free_text", "rot_z_angle"]

GEOM_TOL = 1e-9  # relative tolerance of the structural tests (axes parallel / through one point)


@dataclass
class Plan:
    """How an arm is solved: kind, the rows verified, and the batched candidate generator."""

    kind: str
    projector: np.ndarray  # (6, 6) rows of the pose residual the arm controls (world axes)
    solve: Callable  # (B, 4, 4) -> candidates (B, K, n), free (B, K) object array of str
    point_e: np.ndarray | None = None  # wrist / reference point in the end-effector frame, for labels
    notes: list[str] = field(default_factory=list)
    route: str = ""  # how joints 1-3 of a Pieper arm are found: "closed form (elbow|stanford)" or "resultant"
    closed: dict | None = None  # the constants of a direct (unmirrored, unmerged) elbow Pieper arm: the compiled
    # solver of denavit.codegen reads them (see elbow_constants); for a direct unmerged 6R parallel arm an empty
    # dict, which analytic_ik's plan cache fills with labels and tolerances (codegen._ik_parallel adds the geometry)


def arm_scale(chain: Screws) -> float:
    return max(float(np.sum(np.abs(chain.consts[:, :3, 3]))), 1e-3)


def sample_configs(chain: Screws, rng) -> list[np.ndarray]:
    return [np.zeros(chain.n), rng.uniform(-np.pi, np.pi, chain.n), rng.uniform(-np.pi, np.pi, chain.n)]


def common_point(pts: np.ndarray, dirs: np.ndarray) -> tuple[np.ndarray, float]:
    """Least-squares point nearest to lines (pts, dirs (k, 3)) and its largest distance to them."""
    A = np.zeros((3, 3))
    b = np.zeros(3)
    for p, d in zip(pts, dirs):
        M = np.eye(3) - np.outer(d, d)
        A += M
        b += M @ p
    x = np.linalg.lstsq(A, b, rcond=None)[0]
    dist = max(np.linalg.norm((np.eye(3) - np.outer(d, d)) @ (x - p)) for p, d in zip(pts, dirs))
    return x, dist


def axes_meet(chain: Screws, idx, rng) -> bool:
    """Do the axes ``idx`` pass through one point (and no two of them coincide) in every test pose?"""
    L = arm_scale(chain)
    for q in sample_configs(chain, rng):
        pts, dirs = screw_axes(chain, q)
        for a, b in zip(idx[:-1], idx[1:]):
            if np.linalg.norm(np.cross(dirs[a], dirs[b])) < 1e-6:
                return False
        if common_point(pts[list(idx)], dirs[list(idx)])[1] > GEOM_TOL * L:
            return False
    return True


def axes_parallel(chain: Screws, idx, rng) -> bool:
    for q in sample_configs(chain, rng):
        _, dirs = screw_axes(chain, q)
        if any(np.linalg.norm(np.cross(dirs[idx[0]], dirs[k])) > GEOM_TOL for k in idx[1:]):
            return False
    return True


def merge_coaxial(chain: Screws):
    """Merge consecutive coaxial revolute joints; returns (chain, expand(q_reduced) -> q, [(group name, text)] of
    the merged groups, representative joint of each reduced joint, name of each reduced joint)."""
    consts, pris = list(chain.consts), list(chain.prismatic)
    groups: list[list[tuple[int, float]]] = [[(0, 1.0)]]
    k = 0
    while k < len(pris) - 1:
        C = consts[k + 1]
        if (not pris[k] and not pris[k + 1] and abs(abs(C[2, 2]) - 1) < 1e-12
                and np.hypot(C[0, 3], C[1, 3]) < 1e-12):
            sign = float(np.sign(C[2, 2]))  # J(q_k) C J(q_k+1) = J(q_k ± q_k+1) C
            orig = groups[-1][-1][0] + 1
            groups[-1].append((orig, sign))
            consts[k + 1] = C @ consts[k + 2]
            del consts[k + 2], pris[k + 1]
            continue
        groups.append([(groups[-1][-1][0] + 1, 1.0)])
        k += 1
    n = chain.n
    free, gnames = [], []
    for g in groups:
        if len(g) > 1:
            terms = f"q{g[0][0] + 1}" + "".join(f" {'+' if s > 0 else '-'} q{i + 1}" for i, s in g[1:])
            free.append((f"({terms})", f"{terms} fixed (coaxial joints)"))
            gnames.append(f"({terms})")  # what the reduced joint stands for, in the free texts of the solvers
        else:
            gnames.append(f"q{g[0][0] + 1}")

    def expand(qr: np.ndarray) -> np.ndarray:
        out = np.zeros(qr.shape[:-1] + (n,))
        for j, g in enumerate(groups):
            out[..., g[0][0]] = qr[..., j]  # representative: the first joint takes the whole sum
        return out

    reps = [g[0][0] for g in groups]
    return Screws(np.array(consts), np.array(pris)), expand, free, reps, gnames


def free_text(mask: np.ndarray, text: str, out: np.ndarray) -> np.ndarray:
    if not text or not np.any(mask):
        return out
    add = np.where(out == "", text, out + "; " + text)
    return np.where(mask, add, out)


def rot_z_angle(R: np.ndarray) -> np.ndarray:
    return np.arctan2(R[..., 1, 0], R[..., 0, 0])
