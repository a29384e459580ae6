"""The kernels of one arm, traced: each quantity as straight-line code over the joint inputs.

Every kernel is the library's own algorithm run on traced values (:mod:`denavit.codegen._trace`):
the chain walker of :mod:`denavit.chain` for poses and joint axes, and the RNEA / CRBA / LDLᵀ kernels of
:mod:`denavit.numeric` for dynamics.  Nothing here re-derives kinematics or dynamics; it only says which
outputs each kernel has.
"""

from __future__ import annotations

import hashlib
import re
import sys
from dataclasses import dataclass
from pathlib import Path
from typing import Callable

from ..chain import COMPONENTS, FLOATS, chain_of, walk
from ..model import DHRobot
from ..errors import ModelError
from ..numeric import SINGULAR_TOL, require_dynamics, dynamics_plan, ldl_pivots_solve, mass_matrix_kernel, rnea_kernel
from ._trace import Tape, sym_max, sym_min, sym_sign

__all__ = ["KernelSpec", "trace_kernels", "KERNEL_NAMES", "DYNAMICS", "INTERNAL", "has_dynamics", "jacobian_columns",
           "end_effector", "register_kernel", "registered_kernels", "group_kernels", "trace_registered",
           "registered_digest", "RegisteredKernel", "BASE_GROUP", "first_joint_at_zero", "gravity_seen_at_zero"]

KERNEL_NAMES = ("fk", "position", "frames", "jacobian0", "jacobiane", "fk_jacobian0", "rnea", "mass_matrix",
                "gravity", "coriolis", "forward_dynamics")
DYNAMICS = frozenset({"rnea", "mass_matrix", "gravity", "coriolis", "forward_dynamics"})
#: Kernels no method calls directly: the IK solvers' (compiled with them, on their first use; not by ``warm()``, and
#: not in the module's batch group).
INTERNAL = frozenset({"fk_jacobian0"})
#: The group compiled by :func:`denavit.compile` itself; every other group is compiled (or loaded from the disk
#: cache) on its first call.
BASE_GROUP = "base"
_IDENTIFIER = re.compile(r"[a-z][a-z0-9_]{0,39}")


@dataclass(frozen=True)
class KernelSpec:
    """One traced kernel: ``inputs`` (name, length) in call order, ``shape`` of the output, ``outputs`` its
    entries in C order (traced values or constants), ``tape`` the recording they live on."""

    name: str
    doc: str
    inputs: tuple[tuple[str, int], ...]
    shape: tuple[int, ...]
    outputs: tuple
    tape: Tape


def _columns_to_matrix(x, y, z, p):
    """A pose as 16 entries of the 4×4 homogeneous matrix, row-major."""
    return [x[0], y[0], z[0], p[0], x[1], y[1], z[1], p[1], x[2], y[2], z[2], p[2], 0.0, 0.0, 0.0, 1.0]


def _with_tool(pose, T):
    """pose · T for a constant 4×4 T (nested lists), on column tuples."""
    x, y, z, p = pose

    def apply(col, w):  # R · col + w·p, with col the constant column
        out = []
        for r in range(3):
            s = w * p[r] if w else 0.0
            for v, c in zip((x, y, z), col):
                if c != 0.0:
                    s = s + c * v[r]
            out.append(s)
        return tuple(out)

    cols = [[T[r][j] for r in range(3)] for j in range(4)]
    return apply(cols[0], 0.0), apply(cols[1], 0.0), apply(cols[2], 0.0), apply(cols[3], 1.0)


def _cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def end_effector(chain, frames):
    """The end-effector pose (tool applied) as column tuples, from the walker's frames {0} … {N}."""
    return frames[-1] if chain.tool_identity else _with_tool(frames[-1], chain.tool.tolist())


def jacobian_columns(chain, frames, end, tool: bool = False):
    """The columns (v_k, w_k) of the geometric Jacobian, each a 3-tuple of components (traced values or floats).

    Column k is [z × (p_e − o); z] for a revolute joint and [z; 0] for a prismatic one (Siciliano et al. 2009,
    eq. 3.30), z and o the axis and origin of the frame carrying joint k (``frames`` from the walker, ``end`` the
    end-effector pose); ``tool=True``: components along the end-effector axes (the rows of R_eᵀ), i.e. Je.
    """
    xe, ye, ze, pe = end
    v_rows, w_rows = [], []
    for k in range(chain.dof):
        F = frames[chain.axis_frame[k]]
        z, o = F[2], F[3]
        if chain.revolute[k]:
            v, w = _cross(z, tuple(pe[i] - o[i] for i in range(3))), z
        else:
            v, w = z, (0.0, 0.0, 0.0)
        if tool:
            v = tuple(sum((a[i] * v[i] for i in range(3)), 0.0) for a in (xe, ye, ze))
            w = tuple(sum((a[i] * w[i] for i in range(3)), 0.0) for a in (xe, ye, ze))
        v_rows.append(v)
        w_rows.append(w)
    return v_rows, w_rows


def trace_kernels(robot: DHRobot, names=KERNEL_NAMES, friction: bool = True) -> dict[str, KernelSpec]:
    """Trace the kernels ``names`` of ``robot`` (dynamics ones only when it carries inertial data);
    ``friction``: rnea and forward_dynamics include the joints' viscous and Coulomb friction."""
    chain = chain_of(robot)
    n = chain.dof
    out: dict[str, KernelSpec] = {}

    def kinematics(name):
        tape = Tape()
        q = tape.inputs("q", n)
        frames = walk(chain, q, COMPONENTS, frames=True)
        return tape, q, frames, end_effector(chain, frames)

    if "fk" in names:
        tape, q, frames, end = kinematics("fk")
        out["fk"] = KernelSpec("fk", "T_w_e, the end-effector pose (tool applied)", (("q", n),), (4, 4),
                               tuple(_columns_to_matrix(*end)), tape)
    if "position" in names:  # the origin alone: the rotation's arithmetic not needed for it is dropped
        tape, q, frames, end = kinematics("position")
        out["position"] = KernelSpec("position", "p_w_e, the end-effector origin (tool applied)", (("q", n),),
                                     (3,), tuple(end[3]), tape)
    if "frames" in names:
        tape, q, frames, end = kinematics("frames")
        entries = [e for F in frames for e in _columns_to_matrix(*F)]
        out["frames"] = KernelSpec("frames", "world poses of the DH frames {0} ... {N} (no tool)",
                                   (("q", n),), (len(frames), 4, 4), tuple(entries), tape)
    for name in ("jacobian0", "jacobiane", "fk_jacobian0"):
        if name not in names:
            continue
        tape, q, frames, end = kinematics(name)
        v_rows, w_rows = jacobian_columns(chain, frames, end, tool=name == "jacobiane")
        entries = [v_rows[k][r] for r in range(3) for k in range(n)] + [w_rows[k][r] for r in range(3)
                                                                         for k in range(n)]
        if name == "fk_jacobian0":  # the pose and J0 in one pass (what each IK iteration needs)
            out[name] = KernelSpec(name, "T_w_e (16 entries, row-major) then J0 (6 x n, row-major)", (("q", n),),
                                   (16 + 6 * n,), tuple(_columns_to_matrix(*end)) + tuple(entries), tape)
            continue
        frame = "base (J0)" if name == "jacobian0" else "tool (Je)"
        out[name] = KernelSpec(name, f"geometric Jacobian, rows (v, w), in the {frame} frame", (("q", n),),
                               (6, n), tuple(entries), tape)
    if not DYNAMICS & set(names) or not has_dynamics(robot):
        return out

    pl = dynamics_plan(robot)
    g = [float(v) for v in robot.gravity]
    fv = [link.inertia.viscous if link.inertia and friction else 0.0 for link in robot.joints]
    fc = [link.inertia.coulomb if link.inertia and friction else 0.0 for link in robot.joints]

    def at(q0):  # the frames at q0 (joint 1 a constant: the walker on components)
        return walk(chain, q0, COMPONENTS, frames=True)

    def friction(qd):
        return [fv[k] * qd[k] + fc[k] * sym_sign(qd[k]) for k in range(n)]

    if "rnea" in names:
        tape = Tape()
        q, qd, qdd = tape.inputs("q", n), tape.inputs("qd", n), tape.inputs("qdd", n)
        q0 = first_joint_at_zero(q)
        tau = rnea_kernel(pl, q0, qd, qdd, gravity_seen_at_zero(chain, q, g), at(q0))
        tau = [t + f for t, f in zip(tau, friction(qd))]
        out["rnea"] = KernelSpec("rnea", "tau = M(q) qdd + C(q, qd) qd + g(q) + tau_f (friction)",
                                 (("q", n), ("qd", n), ("qdd", n)), (n,), tuple(tau), tape)
    if "gravity" in names:
        tape = Tape()
        q = tape.inputs("q", n)
        q0, zero = first_joint_at_zero(q), [0.0] * n
        out["gravity"] = KernelSpec("gravity", "g(q), the gravity torques", (("q", n),), (n,),
                                    tuple(rnea_kernel(pl, q0, zero, zero, gravity_seen_at_zero(chain, q, g), at(q0))),
                                    tape)
    if "coriolis" in names:
        tape = Tape()
        q, qd = tape.inputs("q", n), tape.inputs("qd", n)
        q0 = first_joint_at_zero(q)
        c = rnea_kernel(pl, q0, qd, [0.0] * n, [0.0, 0.0, 0.0], at(q0))
        out["coriolis"] = KernelSpec("coriolis", "c(q, qd) = C(q, qd) qd, the velocity torques",
                                     (("q", n), ("qd", n)), (n,), tuple(c), tape)
    if "mass_matrix" in names:
        tape = Tape()
        q = tape.inputs("q", n)
        q0 = first_joint_at_zero(q)
        M = mass_matrix_kernel(pl, q0, at(q0))
        out["mass_matrix"] = KernelSpec("mass_matrix", "M(q), the joint-space inertia matrix", (("q", n),),
                                        (n, n), tuple(e for row in M for e in row), tape)
    if "forward_dynamics" in names:
        tape = Tape()
        q, qd, tau = tape.inputs("q", n), tape.inputs("qd", n), tape.inputs("tau", n)
        q0 = first_joint_at_zero(q)
        frames = at(q0)
        bias = rnea_kernel(pl, q0, qd, [0.0] * n, gravity_seen_at_zero(chain, q, g), frames)
        M = mass_matrix_kernel(pl, q0, frames)
        rhs = [t - f - b for t, f, b in zip(tau, friction(qd), bias)]
        try:
            qdd, d = ldl_pivots_solve(M, rhs)
        except ZeroDivisionError:  # a pivot that is 0 for every q: M singular everywhere
            qdd, d = [0.0] * n, [-1.0]
        lo, hi = d[0], d[0]
        for v in d[1:]:
            lo, hi = sym_min(lo, v), sym_max(hi, v)
        ok = lo - SINGULAR_TOL * hi  # > 0 ⇔ M regular (the test of denavit.forward_dynamics)
        out["forward_dynamics"] = KernelSpec(
            "forward_dynamics", "qdd = M^-1 (tau - c - g - tau_f); last entry > 0 iff M is regular",
            (("q", n), ("qd", n), ("tau", n)), (n + 1,), tuple(qdd) + (ok,), tape)
    return out


def first_joint_at_zero(q) -> list:
    """q with joint 1 at 0: the dynamics kernels' configuration.

    Joint 1 moves everything after it rigidly (a rotation about, or a translation along, a fixed line), and
    kinetic energy does not change under a rigid motion of the whole moving system: M(q), and with it the
    velocity terms c(q, q̇) built from M and its derivatives, do not depend on q1 (Featherstone 2008, Sec. 6.1;
    Khalil & Dombre 2002, Sec. 9.4).  Tracing them at q1 = 0 folds joint 1's sine and cosine out of every frame.
    """
    return [0.0] + list(q[1:])


def gravity_seen_at_zero(chain, q, g) -> list:
    """Gravity as the arm at q1 = 0 feels it: Rᵀ g, with R the rotation of joint 1 by q1 about its axis u.

    The arm at q is the arm at q1 = 0 moved rigidly by joint 1; in gravity g it needs the torques the unmoved
    arm needs in gravity Rᵀ g.  Rodrigues: Rᵀ g = g∥ + g⊥ cos q1 − (u × g) sin q1, with g∥ = u (u·g); for a
    prismatic joint 1, or an axis along gravity (g⊥ = 0: most arms), Rᵀ g = g, a constant.
    """
    if not chain.revolute[0]:
        return list(g)
    u = walk(chain, [0.0] * chain.dof, FLOATS, frames=True)[chain.axis_frame[0]][2]  # fixed: before joint 1
    ug = sum(a * b for a, b in zip(u, g))
    par = [a * ug for a in u]
    perp = [gi - pi for gi, pi in zip(g, par)]
    ucg = _cross(u, g)
    scale = 1e-15 * max(1.0, max(abs(v) for v in g))  # rounding of u's components: an axis along g
    if max(abs(v) for v in perp) <= scale and max(abs(v) for v in ucg) <= scale:
        return list(g)
    c, s = q[0].cos(), q[0].sin()
    return [par[i] + perp[i] * c - ucg[i] * s for i in range(3)]


def has_dynamics(robot: DHRobot) -> bool:
    """The rule of :func:`denavit.numeric.require_dynamics` (inertial data on some moving row)."""
    try:
        require_dynamics(robot)
    except ModelError:
        return False
    return True


# --- registered kernels: compiled by group, on first use ---------------------------------------------------------
@dataclass(frozen=True)
class RegisteredKernel:
    """A kernel another module adds (see :func:`register_kernel`)."""

    name: str
    group: str
    inputs: Callable[[int], tuple]
    shape: Callable[[int], tuple]
    doc: str
    trace: Callable
    source: str  #: the file defining ``trace`` (its bytes are part of the group's cache key)


_REGISTRY: dict[str, RegisteredKernel] = {}


def register_kernel(name: str, *, group: str, inputs, shape, doc: str, trace) -> RegisteredKernel:
    """Add a kernel to every compiled arm: ``CompiledRobot._call(name, ...)`` and ``export_sources(kernels=...)``.

    Parameters
    ----------
    name : str
        Lower-case identifier (it becomes function names ``<name>_1`` / ``<name>_n`` and C ``<prefix>_<name>``).
    group : str
        Kernels of one group are compiled together, into one module cached on disk (keyed by robot, backend,
        friction and group), on the first call of any of them; ``"base"`` ones by :func:`denavit.compile` itself.
    inputs : callable
        ``n -> ((label, length), ...)``, e.g. ``lambda n: (("q", n), ("qd", n))``.
    shape : callable
        ``n -> shape`` of one configuration's output.
    doc : str
        One line: what the output is.
    trace : callable
        ``(robot, friction) -> KernelSpec`` (traced on a :class:`~denavit.codegen.Tape`, as :func:`trace_kernels`
        does); it raises :class:`~denavit.errors.ModelError` for an arm it does not apply to.
    """
    for what, value in (("name", name), ("group", group)):
        if not isinstance(value, str) or not _IDENTIFIER.fullmatch(value):
            raise ValueError(f"register_kernel: {what} {value!r} must be a lower-case identifier (at most 40)")
    if name in KERNEL_NAMES:
        raise ValueError(f"register_kernel: {name!r} is a built-in kernel")
    if not _one_line(doc):
        raise ValueError("register_kernel: doc is one line without quotes, backslashes or '*/'")
    old = _REGISTRY.get(name)
    module = sys.modules.get(getattr(trace, "__module__", ""), None)
    source = getattr(module, "__file__", None) or ""
    if old is not None and (old.source, old.group) != (source, group):
        raise ValueError(f"register_kernel: {name!r} is already registered by {old.source or old.trace!r}")
    entry = RegisteredKernel(name, group, inputs, shape, doc, trace, source)
    _REGISTRY[name] = entry
    return entry


def _one_line(doc: str) -> bool:
    """True for text that can sit in a generated docstring or C comment as is."""
    return isinstance(doc, str) and not any(c in doc for c in ('"', "\\", "\n", "\r")) and "*/" not in doc


def registered_kernels() -> dict[str, RegisteredKernel]:
    """Every registered kernel by name, in registration order."""
    return dict(_REGISTRY)


def group_kernels(group: str) -> tuple[str, ...]:
    """The names of the registered kernels of ``group``, in registration order."""
    return tuple(name for name, e in _REGISTRY.items() if e.group == group)


def trace_registered(robot: DHRobot, names, friction: bool = True) -> dict[str, KernelSpec]:
    """The registered kernels ``names`` of ``robot``, traced; one that does not apply to this arm (its trace raises
    :class:`~denavit.errors.ModelError`) is left out."""
    n = robot.dof
    out = {}
    for name in names:
        e = _REGISTRY[name]
        try:
            spec = e.trace(robot, friction)
        except ModelError:
            continue
        want = (name, tuple(tuple(x) for x in e.inputs(n)), tuple(e.shape(n)))
        got = (spec.name, tuple(tuple(x) for x in spec.inputs), tuple(spec.shape))
        if not all(_IDENTIFIER.fullmatch(label) for label, _ in spec.inputs) or not _one_line(spec.doc):
            raise RuntimeError(f"kernel {name!r}: input labels must be identifiers and doc one plain line")
        if want != got:  # a bug of the registering module, not of the user's input
            raise RuntimeError(f"kernel {name!r}: traced (name, inputs, shape) {got} != registered {want}")
        count = 1
        for s in spec.shape:
            count *= s
        if len(spec.outputs) != count:
            raise RuntimeError(f"kernel {name!r}: {len(spec.outputs)} outputs for shape {spec.shape}")
        out[name] = spec
    return out


_DIGESTS: dict[str, str] = {}


def registered_digest(names) -> str:
    """A digest of the files defining the kernels ``names`` (part of their cache key: an edited tracer never
    reads a module generated by its former self)."""
    h = hashlib.sha256()
    for name in names:
        e = _REGISTRY[name]
        d = _DIGESTS.get(e.source)
        if d is None:
            data = Path(e.source).read_bytes() if e.source else repr(e.trace.__code__.co_code).encode()
            d = _DIGESTS[e.source] = hashlib.sha256(data).hexdigest()
        h.update(f"{name} {e.group} {d}\n".encode())
    return h.hexdigest()[:16]
