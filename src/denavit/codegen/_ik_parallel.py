"""Analytic IK on the compiled kernels: the UR-class closed form (axes 2, 3, 4 parallel, axes 5, 6 meeting) in numba.

The same formulas as the ``parallel`` plan of :mod:`denavit.ik` (Hawkins 2013 for the UR arms; Lynch & Park 2017,
Sec. 6.1.2): in the frame F1 = C0 Rz(q1) C1 the parallel joints turn about z, so the z coordinate of the point Q
where axes 5 and 6 meet is constant (Paden–Kahan subproblem 1 for q1); the z component of the last axis fixes q5
(the digit-keeping half-angle form of ``axis_angle_roots``), the rest of the orientation q6, and a planar 3R problem
is left for q2, q3 (law of cosines) and q4.  The eight candidates of one pose are each verified by the arm's
chain's FK, folded into the joint limits, merged when equal and labelled (shoulder, elbow, wrist: docs/ik.md).

Every case the plain solver treats specially is handed back to it (``status`` 1): a root next to a double root
(shoulder or elbow or wrist ratio near ±1), the point Q on or next to axis 1 or axis 2, axis 6 parallel or
nearly parallel to axes 2–4 (the wrist-singular continuum; NEAR_SINGULAR), a target beyond the bound where the
plain solver substitutes a reachable stand-in (``far``), a candidate that would need polishing, two solutions
closer than the merge radius.  The compiled path answers only where its answer is the plain solver's.  The kernel
is :mod:`._ik_nb_parallel` (compiled once per machine; the formulas are :mod:`denavit.ik.forms`', run as stages
over chunks of poses, every branch at once, :mod:`._ik_nb_parallel_stages`; the verification the FK of the arm's
chain, :mod:`._ik_nb_checks`); this module holds its constants.
"""

from __future__ import annotations

import numpy as np

from ..chain import chain_of
from ..ik import forms as ik_forms
from ..numeric import inverse_transform
from ._ik_finish import pack_constants

__all__ = ["PARALLEL_LAYOUT", "parallel_constants"]

#: Distance (relative to the reach) of the point Q from axis 1 or 2, or of the planar pair's point from axis 2, and
#: sine of the angle between axis 6 and axes 2-4, under which a pose goes to the plain solver: the angles found
#: there are ill-conditioned (rounding amplified by ~1/this), so the two solvers' answers could differ by more than
#: 1e-10, although the pose is not one the plain solver treats specially.
NEAR_SINGULAR = 1e-5
#: Largest estimated rounding error of a candidate, in units of the double-precision epsilon (2.2e-16), that the
#: compiled path answers.  Each step's error is its inputs' errors (plus one rounding) times its condition: 1/sin of
#: an arccos-type root's distance from its double root, 1/|xy| of a direction turned by atan2, reach/distance of a
#: point from an axis.  The differences measured between the compiled answer and the plain solver's (the same
#: formulas evaluated in another order) stay 20-1000 times below this estimate, and an ill-conditioned candidate
#: is ill-conditioned for both solvers alike: near a singular set two exact answers differ by about eps times the
#: Jacobian's condition number there (tests/test_codegen_ik.py holds the two to that).  Beyond 1e10 eps (an
#: estimated 2e-6 rad, near the merge radius) the plain solver decides.  At 1e6 eps, 1 random UR5 pose in 100 went
#: to the plain solver (2 ms each: 20 µs a pose on average); at 1e10, 1 in 1000 (those at a double root).
COND_MAX = 1e10

#: The constants of ``ik_parallel_packed``'s vector K, in order, with their sizes (186 numbers; "trig": the wrist's
#: ``forms.wrist_constants``, computed once per arm).
PARALLEL_LAYOUT = (("Q_e", 3), ("C0i", 16), ("consts", 112), ("a", 3), ("scalars", 11), ("lo", 6), ("hi", 6),
                   ("revolute", 6), ("theta", 6), ("tols", 8), ("far", 1), ("trig", 8))


def parallel_constants(robot, plan) -> np.ndarray:
    """K of ``ik_parallel_packed`` for ``robot`` and its 6R ``parallel`` plan (``plan.closed``: labels, theta and
    tolerances, from :func:`denavit.ik.ik_plan`): the plan's geometry, from the arm's chain constants.

    Q_e (the point of axes 5, 6 in the end-effector frame) is the plan's ``point_e``; h is the z of Q in F1 at
    q = 0; a the direction of axis 2 in the frame after joint 1; σ = ±1 as the parallel joints map z to σ z;
    (ρ_w, base_w, β_r, β_u) the constants of ``rᵀ Rz(q5) u = m_z`` (r = row z of C4, u = axis z of C5); and
    (2α, 2β, k0) those of the planar pair's law of cosines ``2α cos q3 + 2β sin q3 = |P_xy|² + k0``.
    """
    C = np.array(chain_of(robot).constants, dtype=float)  # (7, 4, 4)
    T0 = C[0]
    for k in range(1, 7):
        T0 = T0 @ C[k]
    Q_e = np.asarray(plan.point_e, dtype=float)
    h = (inverse_transform(C[0] @ C[1]) @ T0 @ np.append(Q_e, 1.0))[2]
    a, pc1 = C[1][:3, 2], C[1][:3, 3]
    sigma = float(np.sign((C[2] @ C[3])[2, 2]))
    r, u = C[4][2, :3], C[5][:3, 2]
    aw, bw = r[0] * u[0] + r[1] * u[1], r[1] * u[0] - r[0] * u[1]
    R2, p2, p3 = C[2][:3, :3], C[2][:3, 3], C[3][:3, 3]
    m = R2.T @ p2
    ap, bp, g = m[0] * p3[0] + m[1] * p3[1], m[1] * p3[0] - m[0] * p3[1], m[2] * p3[2]
    vz = p2[2] + R2[2, 2] * p3[2]
    scalars = [h + a @ pc1, sigma, np.hypot(aw, bw), np.arctan2(bw, aw), np.arctan2(np.hypot(r[0], r[1]), r[2]),
               np.arctan2(np.hypot(u[0], u[1]), u[2]), 2 * ap, 2 * bp, -(p2 @ p2) - p3 @ p3 + vz**2 - 2 * g,
               NEAR_SINGULAR, COND_MAX]
    lim = robot.q_limits
    k = dict(plan.closed, Q_e=Q_e, C0i=inverse_transform(C[0]), consts=C, a=a, scalars=scalars, lo=lim[:, 0],
             hi=lim[:, 1], revolute=[float(t.value == "revolute") for t in robot.joint_types],
             trig=ik_forms.wrist_constants(*scalars[2:6]))
    return pack_constants(k, PARALLEL_LAYOUT, "parallel")
