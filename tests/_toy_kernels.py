"""Toy registered kernels for tests/test_codegen_groups.py (a module of their own, so that a second process
registers the very same kernels: their file is part of the group's cache key)."""

from __future__ import annotations

from denavit.codegen import KernelSpec, Tape, register_kernel

GROUP = "toys"


def trace_qq(robot, friction):
    """q·q, one number."""
    n = robot.dof
    tape = Tape()
    q = tape.inputs("q", n)
    s = q[0] * q[0]
    for x in q[1:]:
        s = s + x * x
    return KernelSpec("toy_qq", "q.q", (("q", n),), (1,), (s,), tape)


def trace_mix(robot, friction):
    """(q·w, q_0 sin w_0, w_1) for q of n entries and w of 2: inputs of different lengths."""
    n = robot.dof
    tape = Tape()
    q, w = tape.inputs("q", n), tape.inputs("w", 2)
    s = q[0] * w[0] + q[1] * w[1]
    return KernelSpec("toy_mix", "q[:2].w, q0 sin w0, w1", (("q", n), ("w", 2)), (3,), (s, q[0] * w[0].sin(), w[1]),
                      tape)


register_kernel("toy_qq", group=GROUP, inputs=lambda n: (("q", n),), shape=lambda n: (1,), doc="q.q",
                trace=trace_qq)
register_kernel("toy_mix", group=GROUP, inputs=lambda n: (("q", n), ("w", 2)), shape=lambda n: (3,),
                doc="q[:2].w, q0 sin w0, w1", trace=trace_mix)


def trace_needs_inertia(robot, friction):
    """Σ q_k, for arms with inertial data only (the tracer refuses the others, as a dynamics kernel would)."""
    from denavit.numeric import require_dynamics

    require_dynamics(robot)
    n = robot.dof
    tape = Tape()
    q = tape.inputs("q", n)
    s = q[0]
    for x in q[1:]:
        s = s + x
    return KernelSpec("toy_sum", "sum of q", (("q", n),), (1,), (s,), tape)


register_kernel("toy_sum", group=GROUP, inputs=lambda n: (("q", n),), shape=lambda n: (1,), doc="sum of q",
                trace=trace_needs_inertia)
