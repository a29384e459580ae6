"""Analytic IK on the compiled kernels: the Stanford class (joints R R P with axes 1, 2 meeting, spherical wrist).

The same formulas as :class:`denavit.ik._closed.StanfordPosition` and ``wrist_angles`` (Spong, Hutchinson &
Vidyasagar 2006, Sec. 5.3.3; Paden–Kahan subproblems 1 and 2): turning about axes 1 and 2 keeps ``|W − O|`` (W the
wrist centre, O the point where axes 1 and 2 meet), a quadratic in the prismatic q3 whose discriminant is written as
``(|D| − |u⊥|)(|D| + |u⊥|)``; the height along axis 1 gives q2 (``α cos q2 + β sin q2 = γ``); q1 turns the point onto
W; the wrist angles follow from ``R_0_3ᵀ R R6ᵀ`` as for the elbow class.  The eight candidates of one pose are each
verified by the FK of the arm's chain, folded, merged (``ik_finish`` of :mod:`._ik_nb_finish`) and labelled
(shoulder, wrist: docs/ik.md).

Every case the plain solver treats specially goes back to it (``status`` 1): q3 next to its double root (the wrist
centre at its nearest to O), a q2 or wrist root next to a double root, the wrist centre on or next to axis 1 or
with its arm next to axis 2 (free or ill-conditioned joints; NEAR_SINGULAR of :mod:`._ik_parallel`), the wrist
axes 4 and 6 (nearly) aligned, a candidate whose estimated rounding error exceeds COND_MAX, a target beyond the
plain solver's bound (prismatic travel included: it then reports no solution, not even outside the limits), a
candidate needing polish, two solutions about to merge.  The kernel is :mod:`._ik_nb_stanford` (compiled once per
machine; the formulas are :mod:`denavit.ik.forms`'); this module holds its constants.
"""

from __future__ import annotations

import numpy as np

from ..chain import chain_of
from ..numeric import inverse_transform
from ._ik_parallel import COND_MAX, NEAR_SINGULAR
from ._ik_finish import pack_constants

__all__ = ["STANFORD_LAYOUT", "stanford_constants"]

#: The constants of ``ik_stanford_packed``'s vector K, in order, with their sizes (182 numbers).
STANFORD_LAYOUT = (("X_e", 3), ("C0i", 16), ("consts", 112), ("geom", 9), ("scalars", 9), ("lo", 6), ("hi", 6),
                   ("revolute", 6), ("theta", 6), ("tols", 8), ("far", 1))


def stanford_constants(robot, plan) -> np.ndarray:
    """K of ``ik_stanford_packed`` for ``robot`` and its Stanford-class Pieper plan (``plan.closed``: labels, theta
    and tolerances, from :func:`denavit.ik.ik_plan`), from the arm's chain constants and the plan's wrist centre.

    As StanfordPosition: P is the wrist centre in the frame of joint 3, O the point of axis 2 nearest to axis 1
    (where they meet), u the wrist centre at q3 = 0 seen from O in the frame of joint 2, z the direction of joint 3
    there, r the row z of C1's rotation, L the arm's size (the sum of |offsets| of its constants); (ρ_w, base_w,
    β_r, β_u) the constants of the wrist's z-row equation ``rᵀ Rz(q5) u = M_zz`` (r = row z of C4, u = axis z of C5).
    """
    C = np.array(chain_of(robot).constants, dtype=float)  # (7, 4, 4)
    F = C[0]
    for k in range(1, 7):
        F = F @ C[k]
    X_e = np.asarray(plan.point_e, dtype=float)
    P = (inverse_transform(C[0] @ C[1] @ C[2]) @ F @ np.append(X_e, 1.0))[:3]
    p1, a = C[1][:3, 3], C[1][:3, 2]
    s0 = -(p1[0] * a[0] + p1[1] * a[1]) / (a[0] ** 2 + a[1] ** 2)
    R2, p2 = C[2][:3, :3], C[2][:3, 3]
    u = p2 + R2 @ P - np.array([0.0, 0.0, s0])
    z = R2[:, 2]
    uz = float(u @ z)
    r4, u5 = C[4][2, :3], C[5][:3, 2]
    aw, bw = r4[0] * u5[0] + r4[1] * u5[1], r4[1] * u5[0] - r4[0] * u5[1]
    L = max(float(np.sum(np.abs(C[:, :3, 3]))), 1e-3)
    scalars = [uz, float(np.linalg.norm(u - uz * z)), L, np.hypot(aw, bw), np.arctan2(bw, aw),
               np.arctan2(np.hypot(r4[0], r4[1]), r4[2]), np.arctan2(np.hypot(u5[0], u5[1]), u5[2]), NEAR_SINGULAR,
               COND_MAX]
    lim = robot.q_limits
    k = dict(plan.closed, X_e=X_e, C0i=inverse_transform(C[0]), consts=C, geom=[*(p1 + s0 * a), *u, *z],
             scalars=scalars, lo=lim[:, 0], hi=lim[:, 1],
             revolute=[float(t.value == "revolute") for t in robot.joint_types])
    return pack_constants(k, STANFORD_LAYOUT, "Stanford")
