"""The dynamics-derivative kernels, traced: the numeric functions' own code run on duals of traced values.

:mod:`denavit.numeric._dyn_derivatives` runs the RNEA, CRBA and LDLᵀ kernels on dual numbers whose components
are floats or arrays; here the same kernels run on duals whose value and tangents are traced values
(:class:`denavit.numeric.Dual` over :class:`~denavit.codegen._trace.Sym`), so every derivative lands on the
same :class:`~denavit.codegen._trace.Tape` as the values it needs, constants folded and common subexpressions
shared (the LDLᵀ factor of M is recorded once and serves q̈ and all 3n tangent solves).

As in :func:`denavit.codegen._kernels.trace_kernels`, the dynamics are traced with joint 1 at q1 = 0 and gravity
turned by −q1 about joint 1's axis (the arm at q is the arm at q1 = 0 moved rigidly): ∂/∂q1 then comes only from
that rotation of gravity, exactly, and is 0 for a prismatic joint 1 or an axis along gravity.

References
----------
J. Carpentier, N. Mansard, "Analytical Derivatives of Rigid Body Dynamics Algorithms", RSS 2018 (∂q̈ = −M⁻¹ ∂τ).
"""

from __future__ import annotations

from ..chain import COMPONENTS, chain_of, walk
from ..model import DHRobot
from ..numeric import (SINGULAR_TOL, dual_sign, dynamics_plan, friction_coefficients, ldl_pivots_solve,
                       mass_matrix_kernel, require_dynamics, rnea_kernel, seed_duals, tangent_matrix)
from ._kernels import KernelSpec, first_joint_at_zero, gravity_seen_at_zero, register_kernel
from ._trace import Tape, sym_max, sym_min

__all__ = ["GROUP", "DERIVATIVE_KERNELS", "trace_rnea_derivatives", "trace_forward_dynamics_derivatives",
           "trace_gravity_derivatives"]


class _Setup:
    """What every dynamics-derivative kernel of an arm starts from."""

    def __init__(self, robot: DHRobot, friction: bool) -> None:
        require_dynamics(robot)  # ModelError for an arm without inertial data: no kernel for it
        self.chain = chain_of(robot)
        self.n = robot.dof
        self.pl = dynamics_plan(robot)
        self.g = [float(v) for v in robot.gravity]
        self.fv, self.fc = friction_coefficients(robot, friction)

    def inverse_dynamics(self, q, qd, qdd):
        """τ = ID(q, q̇, q̈) + τ_f in any algebra (traced values, or duals of them), with joint 1 at 0."""
        q0 = first_joint_at_zero(q)
        tau = rnea_kernel(self.pl, q0, qd, qdd, gravity_seen_at_zero(self.chain, q, self.g),
                          walk(self.chain, q0, COMPONENTS, frames=True))
        return [t + self.fv[k] * qd[k] + self.fc[k] * dual_sign(qd[k]) for k, t in enumerate(tau)]


def _blocks(D, n: int, count: int) -> tuple:
    """The n × (count·n) tangent matrix as ``count`` n × n blocks, C order: [block, output, input]."""
    return tuple(D[i][b * n + j] for b in range(count) for i in range(n) for j in range(n))


def trace_rnea_derivatives(robot: DHRobot, friction: bool = True) -> KernelSpec:
    """∂τ/∂q and ∂τ/∂q̇ of the RNEA (friction included when ``friction``), output (2, n, n)."""
    s = _Setup(robot, friction)
    n, m = s.n, 2 * s.n
    tape = Tape()
    q, qd, qdd = tape.inputs("q", n), tape.inputs("qd", n), tape.inputs("qdd", n)
    tau = s.inverse_dynamics(seed_duals(q, 0, m, traced=True), seed_duals(qd, n, m, traced=True), qdd)
    return KernelSpec("rnea_derivatives", "[dtau/dq, dtau/dqd] of tau = M qdd + c + g + tau_f",
                      (("q", n), ("qd", n), ("qdd", n)), (2, n, n), _blocks(tangent_matrix(tau, m), n, 2), tape)


def trace_gravity_derivatives(robot: DHRobot, friction: bool = True) -> KernelSpec:
    """∂g/∂q of the gravity torques, output (n, n)."""
    s = _Setup(robot, False)
    n = s.n
    tape = Tape()
    q = tape.inputs("q", n)
    zero = [0.0] * n
    g = s.inverse_dynamics(seed_duals(q, 0, n, traced=True), zero, zero)
    return KernelSpec("gravity_derivatives", "dg/dq of the gravity torques g(q)", (("q", n),), (n, n),
                      _blocks(tangent_matrix(g, n), n, 1), tape)


def trace_forward_dynamics_derivatives(robot: DHRobot, friction: bool = True) -> KernelSpec:
    """∂q̈/∂q, ∂q̈/∂q̇, ∂q̈/∂τ = M⁻¹ of forward dynamics, 3 n² entries, then a last entry > 0 iff M is regular.

    q̈ = FD(q, q̇, τ) first (the trace of the ``forward_dynamics`` kernel), then the RNEA on duals at that q̈ and
    the LDLᵀ solve of M with the tangents of τ − ID as right-hand sides (Carpentier & Mansard 2018).
    """
    s = _Setup(robot, friction)
    n, m = s.n, 3 * s.n
    tape = Tape()
    q, qd, tau = tape.inputs("q", n), tape.inputs("qd", n), tape.inputs("tau", n)
    q0 = first_joint_at_zero(q)
    M = mass_matrix_kernel(s.pl, q0, walk(s.chain, q0, COMPONENTS, frames=True))
    bias = s.inverse_dynamics(q, qd, [0.0] * n)  # c + g + τ_f
    try:
        qdd, d = ldl_pivots_solve(M, [t - b for t, b in zip(tau, bias)])
    except ZeroDivisionError:  # a pivot that is 0 for every q: M singular everywhere
        return KernelSpec("forward_dynamics_derivatives", "singular everywhere", (("q", n), ("qd", n), ("tau", n)),
                          (3 * n * n + 1,), (0.0,) * (3 * n * n) + (-1.0,), tape)
    ident = s.inverse_dynamics(seed_duals(q, 0, m, traced=True), seed_duals(qd, n, m, traced=True), qdd)
    residual = [t - i for t, i in zip(seed_duals(tau, 2 * n, m, traced=True), ident)]
    x, _ = ldl_pivots_solve(M, residual)
    lo = hi = d[0]
    for v in d[1:]:
        lo, hi = sym_min(lo, v), sym_max(hi, v)
    ok = lo - SINGULAR_TOL * hi  # > 0 ⇔ M regular (the test of denavit.forward_dynamics)
    return KernelSpec("forward_dynamics_derivatives",
                      "[dqdd/dq, dqdd/dqd, dqdd/dtau = M^-1] (3 n x n, C order); last entry > 0 iff M is regular",
                      (("q", n), ("qd", n), ("tau", n)), (3 * n * n + 1,),
                      _blocks(tangent_matrix(x, m), n, 3) + (ok,), tape)


GROUP = "dynamics_derivatives"

#: name → (tracing function, input labels of n, output shape of n, one-line doc)
DERIVATIVE_KERNELS = {
    "rnea_derivatives": (trace_rnea_derivatives, lambda n: (("q", n), ("qd", n), ("qdd", n)), lambda n: (2, n, n),
                         "[dtau/dq, dtau/dqd] of tau = M qdd + c + g + tau_f, each n x n [output, input]"),
    "forward_dynamics_derivatives": (trace_forward_dynamics_derivatives, lambda n: (("q", n), ("qd", n), ("tau", n)),
                                     lambda n: (3 * n * n + 1,),
                                     "[dqdd/dq, dqdd/dqd, M^-1] (3 n x n, C order), then an entry > 0 iff M is regular"),
    "gravity_derivatives": (trace_gravity_derivatives, lambda n: (("q", n),), lambda n: (n, n),
                            "dg/dq of the gravity torques, n x n [output, input]"),
}

for _name, (_trace_fn, _inputs, _shape, _doc) in DERIVATIVE_KERNELS.items():
    register_kernel(_name, group=GROUP, inputs=_inputs, shape=_shape, doc=_doc, trace=_trace_fn)
