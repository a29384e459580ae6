"""The kinematic-derivative kernels, traced: J̇, the acceleration bias and ∂J/∂q in base and tool axes.

Each kernel is the chain walker (:func:`denavit.chain.walk`), the one definition of the Jacobian's columns
(:func:`jacobian_columns`) and the closed forms of :mod:`denavit.numeric` (``jacobian_dot_entries``,
``bias_entries``, ``hessian_entries``) run on traced values: the same code as :func:`denavit.jacobian_dot`,
:func:`denavit.acceleration_bias` and :func:`denavit.kinematic_hessian`, recorded once as straight-line code.

In tool axes nothing depends on joint 1 (a rigid motion of the whole arm about or along joint 1's fixed axis
leaves every quantity seen from the end effector unchanged; Lynch & Park 2017, §5.1.3: the body Jacobian's
column j depends on q_{j+1} … q_n only), so those kernels are traced at q1 = 0 and joint 1's sine and cosine fold
away.  The kernels form the group ``"kinematic_derivatives"``, compiled on first use.
"""

from __future__ import annotations

from ..chain import COMPONENTS, chain_of, walk
from ..model import DHRobot
from ..numeric import bias_entries, hessian_entries, jacobian_dot_entries
from ._kernels import KernelSpec, end_effector, jacobian_columns, register_kernel
from ._trace import Tape

__all__ = ["GROUP", "KIN_KERNELS", "trace_kin_kernel"]

GROUP = "kinematic_derivatives"
#: name → (doc, needs qd, tool axes)
KIN_KERNELS = {
    "jacobian_dot0": ("dJ0/dt, time derivative of the geometric Jacobian in base axes (6 x n)", True, False),
    "jacobian_dote": ("dJe/dt, time derivative of the geometric Jacobian in tool axes (6 x n)", True, True),
    "acceleration_bias0": ("dJ0/dt qd, classical acceleration bias of the end-effector origin, base axes", True, False),
    "acceleration_biase": ("R^T dJ0/dt qd, classical acceleration bias of the end-effector origin, tool axes", True,
                           True),
    "kinematic_hessian0": ("dJ0[:, j]/dq_k at [:, j, k], base axes (6 x n x n)", False, False),
    "kinematic_hessiane": ("dJe[:, j]/dq_k at [:, j, k], tool axes (6 x n x n)", False, True),
}


def _inputs(name: str, n: int) -> tuple:
    return (("q", n), ("qd", n)) if KIN_KERNELS[name][1] else (("q", n),)


def _shape(name: str, n: int) -> tuple:
    if name.startswith("kinematic_hessian"):
        return (6, n, n)
    return (6,) if name.startswith("acceleration_bias") else (6, n)


def trace_kin_kernel(name: str, robot: DHRobot) -> KernelSpec:
    """The kernel ``name`` (a key of :data:`KIN_KERNELS`) of ``robot``, traced."""
    doc, needs_qd, tool = KIN_KERNELS[name]
    chain = chain_of(robot)
    n = chain.dof
    tape = Tape()
    q = tape.inputs("q", n)
    qd = tape.inputs("qd", n) if needs_qd else None
    at = [0.0] + list(q[1:]) if tool else q  # tool axes: independent of q1 (module notes)
    frames = walk(chain, at, COMPONENTS, frames=True)
    v, w = jacobian_columns(chain, frames, end_effector(chain, frames), tool=tool)
    if name.startswith("jacobian_dot"):
        lin, ang = jacobian_dot_entries(v, w, qd, tool)
        out = [lin[j][r] for r in range(3) for j in range(n)] + [ang[j][r] for r in range(3) for j in range(n)]
    elif name.startswith("acceleration_bias"):
        out = list(bias_entries(v, w, qd))
    else:
        H = hessian_entries(v, w, tool)
        out = [H[j][k][r] for r in range(6) for j in range(n) for k in range(n)]
    return KernelSpec(name, doc, _inputs(name, n), _shape(name, n), tuple(out), tape)


def _register() -> None:
    for name in KIN_KERNELS:
        register_kernel(name, group=GROUP, inputs=lambda n, name=name: _inputs(name, n),
                        shape=lambda n, name=name: _shape(name, n), doc=KIN_KERNELS[name][0],
                        trace=lambda robot, friction, name=name: trace_kin_kernel(name, robot))


_register()
