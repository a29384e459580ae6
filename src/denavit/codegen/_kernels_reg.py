"""The regressor kernel, traced: the plain regressor's own code (the RNEA kernel on unit parameters) on the tape.

:func:`denavit.numeric.regressor_rows` runs :func:`~denavit.numeric.rnea_kernel` with every inertial parameter a
:class:`~denavit.numeric.Linear` — here one whose coefficients are traced values — so each entry Y_ji is the
coefficient of π_i in τ_j, recorded on one :class:`~denavit.codegen._trace.Tape` with the kinematics shared.
As in :func:`denavit.codegen._kernels.trace_kernels`, the arm is traced at q1 = 0 with gravity turned by −q1
about joint 1's axis (the regressor of the arm moved rigidly by joint 1 is that of the unmoved arm in the turned
gravity: τ(q) = τ(q with q1 = 0; Rᵀ g) for every π, so column by column).
"""

from __future__ import annotations

from ..chain import COMPONENTS, chain_of, walk
from ..model import DHRobot
from ..numeric import Linear, dynamics_plan, parameter_names, regressor_rows
from ._kernels import KernelSpec, first_joint_at_zero, gravity_seen_at_zero, register_kernel
from ._trace import Tape, sym_sign

__all__ = ["trace_regressor", "GROUP"]

GROUP = "regressor"


def trace_regressor(robot: DHRobot, friction: bool = True) -> KernelSpec:
    """Y(q, q̇, q̈), output (n, 13 n): the columns of :func:`denavit.numeric.regressor` with its defaults (friction
    and motor-inertia columns always: they hold q̇, sign q̇ and q̈, whatever the robot's friction values and the
    compiled object's ``friction`` setting, which ``τ = Y π`` leaves to π)."""
    chain = chain_of(robot)
    n = robot.dof
    pl = dynamics_plan(robot)
    tape = Tape()
    q, qd, qdd = tape.inputs("q", n), tape.inputs("qd", n), tape.inputs("qdd", n)
    q0 = first_joint_at_zero(q)
    g = gravity_seen_at_zero(chain, q, [float(v) for v in robot.gravity])
    rows = regressor_rows(pl, q0, qd, qdd, g, lambda i: Linear({i: 1.0}), True,
                          walk(chain, q0, COMPONENTS, frames=True))
    p = len(parameter_names(robot))
    out = []
    for j, tau in enumerate(rows):
        row = [0.0] * p
        if isinstance(tau, Linear):
            for i, c in tau.terms.items():
                row[i if i < 10 * n else p - n + (i - 10 * n)] = c  # motor inertia: the last n columns
        row[10 * n + j], row[11 * n + j] = qd[j], sym_sign(qd[j])
        out.extend(row)
    return KernelSpec("regressor", "Y(q, qd, qdd) with tau = Y pi (pi: denavit.inertial_parameters)",
                      (("q", n), ("qd", n), ("qdd", n)), (n, p), tuple(out), tape)


register_kernel("regressor", group=GROUP, inputs=lambda n: (("q", n), ("qd", n), ("qdd", n)),
                shape=lambda n: (n, 13 * n), doc="Y(q, qd, qdd) with tau = Y pi (pi: denavit.inertial_parameters)",
                trace=trace_regressor)
