"""Closed-form inverse kinematics derived symbolically, step by step: kinematic decoupling and planar arms.

The derivation is built from the robot's own DH table (its named parameters stay symbols), not from a
template, so offsets such as the PUMA's a3 and d3, a wrist-to-flange distance d6, DH angle offsets, the
modified convention and a trailing fixed row all appear where they belong.  Two classes are covered:

``decoupled``  6 joints with a spherical wrist (Pieper 1968): joint 1 about z0 through the origin of {0},
               axis 2 perpendicular to axis 1, joint 3 revolute with axis 3 parallel to axis 2 (elbow arms:
               PUMA, report003) or prismatic across axis 2 (Stanford arm), wrist axes 4-6 through one point
               with ±90° twists between them.  Spong, Hutchinson & Vidyasagar (2006), Sec. 5.3-5.4;
               Craig (2005), Sec. 4.7 (PUMA 560); Siciliano et al. (2009), Sec. 2.12.
``planar``     2 or 3 revolute joints with parallel axes (planar 2R/3R): law of cosines, then the heading.
               Spong et al. (2006), Sec. 5.2 (the planar elbow); Craig (2005), Sec. 4.4 (Example 4.1).

Every formula that computes a quantity is an *assignment* step (``IKStep.assign``) whose right-hand side
uses only the target symbols, the sign symbols σ and quantities assigned before it, so the steps can be
evaluated in order (``IKDerivation.formulas``).
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np
import sympy as sp

from ..errors import UnsupportedRobotError
from ..model import DHRobot, JointType
from ._ik_decoupled import decoupled_derivation
from ._ik_shared import (at_zero, axis_frame_of, check_prefix, cosine_law_steps, inverse_transform, numeric_zero,
                         parameter_values, simplify_trig, target_steps, target_symbols)
from ._ik_types import IKDerivation, IKStep
from ._kinematics import link_transforms_sym
from ._symbols import joint_symbols

__all__ = ["ik_derivation"]


# ---------------------------------------------------------------------------------------------------------
# planar 2R / 3R


def _planar(robot: DHRobot) -> IKDerivation:
    n, N = robot.dof, robot.n_rows
    if n not in (2, 3) or any(t is not JointType.REVOLUTE for t in robot.joint_types):
        raise UnsupportedRobotError(f"{robot.name}: planar derivation covers 2 or 3 revolute joints")
    rng = np.random.default_rng(7)
    q = joint_symbols(n).q
    T = link_transforms_sym(robot, "trig")
    TN = T[N]
    if not numeric_zero(TN[2, 2] - 1, robot, q, rng):
        raise UnsupportedRobotError(f"{robot.name}: the joint axes are not all parallel to z0 in the same direction")
    target = target_symbols()
    R, p = target[:3, :3], target[:3, 3]
    steps = target_steps(robot, target, N)
    xw, yw = sp.symbols("x_w y_w", real=True)
    o = sp.Matrix([0, 0, 0, 1])
    if n == 3:
        F3 = axis_frame_of(robot, T, 3)
        cN = simplify_trig((inverse_transform(at_zero(inverse_transform(F3) * TN, q)) * o)[:3, 0])
        ref = F3 * o
        what = f"the point {sp.sstr(list(cN))} of frame {{{N}}} on axis 3 (the wrist of the planar arm)"
    else:
        cN = sp.zeros(3, 1)
        ref = TN * o
        what = f"the origin of frame {{{N}}}"
    w = simplify_trig(p + R * cN)
    steps.append(IKStep("Point placed by joints 1 and 2", sp.Matrix([xw, yw]), w[:2, 0],
                        f"Joints 1 and 2 place {what}.", assign=True))
    g = simplify_trig(at_zero(ref[:3, 0], q[:1]))
    steps.append(IKStep("Position of that point", sp.Matrix([xw, yw]), simplify_trig(ref[:2, 0]),
                        "Joint 1 turns about z0 through the origin: the point is Rz(q1) g(q2)."))
    more, sig2 = cosine_law_steps(xw**2 + yw**2, simplify_trig(sp.expand(g[0] ** 2 + g[1] ** 2)), q[1], robot, rng,
                             "Law of cosines", "The distance of the point from axis 1 depends on q2 only "
                             "(Spong eq. 5.8-5.10; Craig Example 4.1).")
    steps += more
    steps.append(IKStep("q1", q[0], sp.atan2(yw, xw) - sp.atan2(g[1], g[0]),
                        "Rz(q1) turns g(q2) onto (x_w, y_w) (Spong eq. 5.11).", assign=True))
    branches = [sig2]
    if n == 3:
        c = simplify_trig(sp.atan2(at_zero(TN[1, 0], q), at_zero(TN[0, 0], q)))
        phi = sp.Symbol("phi", real=True)
        if not numeric_zero(sp.sin(sum(q) + c) - TN[1, 0], robot, q, rng):
            raise UnsupportedRobotError(f"{robot.name}: the heading is not q1 + q2 + q3 + const")
        steps.append(IKStep("Heading", phi, sp.atan2(target[1, 0], target[0, 0]),
                            "All axes are parallel, so the heading of the last frame is the sum of the joint angles.",
                            assign=True))
        steps.append(IKStep("q3", q[2], phi - q[0] - q[1] - c, f"φ = {sp.sstr(q[0] + q[1] + q[2] + c)}.",
                            assign=True))
    return IKDerivation(robot, "planar", tuple(steps), target, tuple(branches), q,
                        tuple(parameter_values(robot).items()))


@lru_cache(maxsize=32)
def ik_derivation(robot: DHRobot) -> IKDerivation:
    """Derive the closed-form inverse kinematics of ``robot`` symbolically, step by step.

    Covered: 6-joint arms with an orthogonal spherical wrist whose first three joints form an elbow
    (R ⟂ R ∥ R, e.g. PUMA 560) or a Stanford-type R ⟂ R P arm, with any offsets (shoulder offset, a3, d3, d6),
    DH angle offsets, either DH convention, base and tool; planar 2R and 3R arms.  The steps follow
    Spong, Hutchinson & Vidyasagar (2006), ch. 5 and Craig (2005), ch. 4: wrist centre p_c = p + R c
    (p − d6 R z for the usual flange), q1 from atan2 with the shoulder offset (two branches), q3 from the
    law of cosines (two branches), q2, then M = R_0_3ᵀ R = R_3_6 and q4, q5, q6 by atan2 (two branches).

    Parameters
    ----------
    robot : DHRobot

    Returns
    -------
    IKDerivation
        Steps as data; evaluate ``formulas`` in order for each sign combination of ``branches``.

    Raises
    ------
    UnsupportedRobotError
        The arm is outside the covered classes (the numeric ``analytic_ik`` may still solve it).

    Examples
    --------
    >>> import denavit
    >>> from denavit.symbolic import ik_derivation
    >>> d = ik_derivation(denavit.load_robot("puma560"))
    >>> d.kind, [str(s) for s in d.branches]
    ('decoupled', ['sigma1', 'sigma3', 'sigma5'])
    """
    from ..ik import ik_structure

    try:
        kind = ik_structure(robot)
    except UnsupportedRobotError as exc:
        raise UnsupportedRobotError(f"{robot.name}: no closed form to derive ({exc})") from None
    check_prefix(robot)
    if kind == "pieper" and robot.dof == 6:
        return decoupled_derivation(robot)
    if kind == "planar" and all(t is JointType.REVOLUTE for t in robot.joint_types) and robot.dof in (2, 3):
        return _planar(robot)
    raise UnsupportedRobotError(
        f"{robot.name}: the symbolic derivation covers 6-joint arms with a spherical wrist (elbow or Stanford "
        f"type) and planar 2R/3R arms, not this '{kind}' structure; analytic_ik solves it numerically"
        + (" (general 6R eigenvalue method; its steps are in docs/ik.md)" if kind == "general" else ""))
