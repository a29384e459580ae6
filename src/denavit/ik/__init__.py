"""Inverse kinematics: every closed-form solution (analytic) and Levenberg–Marquardt (numeric).

- :func:`analytic_ik` — all solutions of a pose for arms with a closed form (Pieper: three intersecting or
  parallel axes), the general 6R by an eigenvalue problem; :func:`ik_structure` / :func:`ik_plan` say which.
- :func:`solve_ik` — one solution near a seed, by damped least squares on the pose error, with restarts.

The solvers work on the arm as the chain ``C0 · J1(q1) · C1 ⋯ Jn(qn) · Cn`` (:mod:`denavit.chain`) and use the
numeric engine (:mod:`denavit.numeric`) for forward kinematics and Jacobians; nothing there imports this package.
"""

from ._analytic import AnalyticIKResult, analytic_ik, ik_plan, ik_structure
from ._path import PathResult, PathTrajectory, cartesian_line, ik_path
from ._numeric import MAX_ITERATIONS, RESTARTS, TOL, solve_ik
from ._residual import IKResult, JointLimits, characteristic_length, pose_error, rotation_log, row_mask

__all__ = [
    "AnalyticIKResult",
    "ik_path",
    "cartesian_line",
    "PathResult",
    "PathTrajectory",
    "analytic_ik",
    "ik_structure",
    "ik_plan",
    "IKResult",
    "solve_ik",
    "JointLimits",
    "characteristic_length",
    "row_mask",
    "pose_error",
    "rotation_log",
    "TOL",
    "MAX_ITERATIONS",
    "RESTARTS",
]
