"""One-target Levenberg–Marquardt attempt in plain Python floats (the single-call fast path of ``solve_ik``).

For one target, numpy's fixed cost per call (~1–5 µs per ufunc on arrays of 3–36 numbers) dominates the
batched solver of :mod:`._numeric`: one iteration there is ~60 small array operations.  This module runs
the *first* attempt of that solver — from the seed, joint limits ignored during the iteration and the end
point folded by whole turns — as :func:`._lm.attempt` (the LM run ``denavit.compile`` jits) on lists of floats,
with the pose and Jacobian of the same joint-screw chain ``C0 J1(q1) C1 ⋯ Jn(qn) Cn`` of :mod:`denavit.chain`
as :class:`._kernel.Kernel`:

    revolute k: J_k = (z_k × (p_e − o_k), z_k),  prismatic k: J_k = (z_k, 0)

(Spong, Hutchinson & Vidyasagar 2006, eq. 4.52–4.53).

The caller (``solve_ik``) decides success by :func:`forward_kinematics`, as the batched path does, and
falls back to the batched path (random restarts, rescue, reasons) whenever this attempt does not end in a
solution within the limits, so the quality of the result is that of the batched solver.
"""

from __future__ import annotations

import numpy as np

from ..chain import chain_of, screw_walk_floats, screws_of
from ..model import DHRobot
from ..numeric import forward_kinematics
from ._lm import bind, pose_residual
from ._residual import IKResult

__all__ = ["SingleChain", "single_chain", "solve_single"]


class SingleChain:
    """One arm's pose and Jacobian in floats (build with :func:`single_chain`, cached per robot)."""

    def __init__(self, robot: DHRobot) -> None:
        self.screws = screws_of(robot)
        self.n = self.screws.n
        self.prismatic = self.screws.floats[2]
        self.attempt = bind(self.fk_jacobian0)[0]  # the LM run of denavit.compile's solver, on this chain

    def fk_jacobian0(self, q, P) -> None:
        """P[:16] = the pose at q (row-major), P[16:] = J0 (6, n) row-major: the layout of the compiled fused
        kernel ``fk_jacobian0`` that :func:`._lm.attempt` calls."""
        rows, axes = screw_walk_floats(self.screws, q)
        P[0:12] = rows[0] + rows[1] + rows[2]
        P[12:16] = 0.0, 0.0, 0.0, 1.0
        p0, p1, p2 = rows[0][3], rows[1][3], rows[2][3]
        n = self.n
        for k in range(n):
            z0, z1, z2, o0, o1, o2 = axes[k]
            if self.prismatic[k]:
                P[16 + k], P[16 + n + k], P[16 + 2 * n + k] = z0, z1, z2
                P[16 + 3 * n + k] = P[16 + 4 * n + k] = P[16 + 5 * n + k] = 0.0
            else:
                d0, d1, d2 = p0 - o0, p1 - o1, p2 - o2
                P[16 + k], P[16 + n + k], P[16 + 2 * n + k] = z1 * d2 - z2 * d1, z2 * d0 - z0 * d2, z0 * d1 - z1 * d0
                P[16 + 3 * n + k], P[16 + 4 * n + k], P[16 + 5 * n + k] = z0, z1, z2


def single_chain(robot: DHRobot) -> SingleChain:
    """The float chain of a robot (kept with its :func:`denavit.chain.chain_of`: found without hashing it)."""
    memo = chain_of(robot).memo
    single = memo.get("ik_single")
    if single is None:
        single = memo["ik_single"] = SingleChain(robot)
    return single


def solve_single(robot: DHRobot, q0: np.ndarray, T: np.ndarray, w: np.ndarray, w_mask: np.ndarray, limits,
                 max_iter: int, tol: float, L: float):
    """The first attempt of ``solve_ik`` for one target in floats; an ``IKResult`` when it ends in a solution
    within the limits (checked by :func:`forward_kinematics`, as the batched path does), else None."""
    n = len(q0)
    buf = ([0.0] * (16 + 6 * n), [0.0] * (16 + 6 * n), [0.0] * 6, [0.0] * 6, [0.0] * (n * n), [0.0] * n, [0.0] * n)
    q = q0.tolist()
    it, ok, _, _, _ = single_chain(robot).attempt(T.ravel().tolist(), q, limits.lo.tolist(), limits.hi.tolist(),
                                                  limits.revolute.tolist(), w.tolist(), L, tol, max_iter, False, buf)
    if not ok:
        return None
    q = limits.project(np.array(q))
    pe, re = fk_error(robot, q, T, w_mask)
    if not (pe <= tol and re <= tol and limits.inside(q)):
        return None
    return IKResult(q, True, pe, re, it, 0, "")


def fk_error(robot: DHRobot, q: np.ndarray, T: np.ndarray, mask: np.ndarray) -> tuple[float, float]:
    """Position and orientation error norms of ``forward_kinematics(robot, q)`` against T on the masked rows:
    ``pose_error`` of :mod:`._numeric` for one pose, in floats."""
    pe, re, _ = pose_residual(T.ravel().tolist(), forward_kinematics(robot, q).ravel().tolist(),
                              [1.0 if m else 0.0 for m in mask.tolist()], [0.0] * 6)
    return pe, re
