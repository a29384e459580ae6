"""Inverse kinematics: every closed-form solution (analytic) and Levenberg–Marquardt (numeric).

- :func:`analytic_ik` — all solutions of a pose for arms with a closed form (Pieper: three intersecting or
  parallel axes), the general 6R by an eigenvalue problem; :func:`ik_structure` / :func:`ik_plan` say which.
- :func:`free_joint_sweep` — a redundant arm's solutions as functions of one held joint, with the feasible
  intervals of that joint (:func:`analytic_ik` with ``free=`` / ``locked=`` at one value).
- :func:`solve_ik` — one solution near a seed, by damped least squares on the pose error, with restarts (one
  target's LM run is :mod:`lm`, in numba's subset of Python: ``denavit.compile`` jits the same code).

The solvers work on the arm as the chain ``C0 · J1(q1) · C1 ⋯ Jn(qn) · Cn`` (:mod:`denavit.chain`) and use the
numeric engine (:mod:`denavit.numeric`) for forward kinematics and Jacobians; nothing there imports this package.
"""

from . import _forms as forms  # the closed forms in numba's subset of Python (denavit.codegen jits them)
from . import _lm as lm  # Levenberg–Marquardt in numba's subset of Python (solve_ik runs it, compile jits it)
from ._analytic import AnalyticIKResult, analytic_ik, ik_plan, ik_structure
from ._line import cartesian_line
from ._path import PathResult, PathTrajectory, ik_path
from ._numeric import MAX_ITERATIONS, RESTARTS, TOL, solve_ik
from ._sweep import SAMPLES, SWEEP_TOL, FreeJointSweep, SweepBranch, default_free_joint, free_joint_sweep
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
    "free_joint_sweep",
    "default_free_joint",
    "FreeJointSweep",
    "SweepBranch",
    "SAMPLES",
    "SWEEP_TOL",
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
