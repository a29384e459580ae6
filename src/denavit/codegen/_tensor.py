"""``denavit.compile(robot, backend="torch" | "jax")``: the arm's kernels on the framework's tensors.

The kernels are the numba and numpy backends' own traced programs (:mod:`denavit.codegen._kernels`), written on
whole tensors by :func:`denavit.codegen._tensor_emit.tensor_module` and kept in the kernel cache like the other
backends' modules.  The object's methods check the inputs' shapes, then call the module's functions: results are
the framework's tensors on the inputs' device and dtype, differentiable by its autodiff and traceable by its JIT.
"""

from __future__ import annotations

import importlib
from pathlib import Path

from ..errors import MissingDependencyError, ModelError, ShapeError
from ..model import DHRobot, Frame
from ._cache import load_module, robot_key
from ._kernels import DYNAMICS, INTERNAL, KERNEL_NAMES, has_dynamics, trace_kernels
from ._tensor_emit import FRAMEWORKS, tensor_module

__all__ = ["TensorRobot", "compile_tensor", "framework_namespace", "FRAMEWORKS"]


def framework_namespace(framework: str):
    """The array namespace of ``framework`` (``torch``, or ``jax.numpy``); MissingDependencyError with the pip line
    when the framework is not installed (any other ImportError is raised as it is)."""
    packages = {"torch": ("torch", "torch"), "jax": ("jax.numpy", "jax")}
    if framework not in packages:
        raise ValueError(f"framework must be one of {', '.join(FRAMEWORKS)}, got {framework!r}")
    module, extra = packages[framework]
    try:
        return importlib.import_module(module)
    except ImportError as exc:
        if (exc.name or "").split(".")[0] not in ("torch", "jax", "jaxlib"):
            raise
        raise MissingDependencyError(f"backend={framework!r} needs {extra}: pip install 'denavit[{extra}]'") from None


class TensorRobot:
    """The generated kernels of one arm on PyTorch or JAX tensors.  Made by :func:`denavit.compile`; see there.

    Every method takes tensors (or anything the framework's ``as_tensor`` / ``asarray`` takes; integers become
    the default float type) of shape ``(n,)`` or ``(..., n)``, broadcasts the inputs' leading axes together, and
    returns the framework's tensors with the batch axes first, on the inputs' device and dtype.
    """

    def __init__(self, robot: DHRobot, module, framework: str, names, friction: bool = True) -> None:
        self.robot = robot
        self.dof = robot.dof
        self.backend = framework
        self.friction = bool(friction)
        self.kernels = tuple(names) + (("forward_dynamics",) if hasattr(module, "forward_dynamics") else ())
        self.module = module  #: the generated module: one function per kernel, on tensors
        self._xp = framework_namespace(framework)

    @property
    def source(self) -> str:
        """The generated module's source text (kept in :func:`cache_dir`)."""
        return Path(self.module.__file__).read_text(encoding="utf-8")

    @property
    def path(self) -> Path:
        """Where the generated module lives."""
        return Path(self.module.__file__)

    def __repr__(self) -> str:
        return (f"<TensorRobot {self.robot.name!r}: {self.dof} joints, {self.backend}, "
                f"kernels {', '.join(self.kernels)}>")

    # --- plumbing -------------------------------------------------------------------------------------------
    def _tensor(self, x, label: str):
        """``x`` as a floating tensor of shape (..., n); ShapeError naming ``label`` otherwise."""
        xp = self._xp
        if self.backend == "torch":
            t = x if isinstance(x, xp.Tensor) else xp.as_tensor(x)
            if not t.is_floating_point():
                t = t.to(xp.get_default_dtype())
        else:
            t = xp.asarray(x)
            if not xp.issubdtype(t.dtype, xp.floating):
                t = t.astype(xp.result_type(float))
        n = self.dof
        if t.ndim == 0 or t.shape[-1] != n:
            raise ShapeError(f"{label}: expected shape (..., {n}) for a {n}-joint robot, got {tuple(t.shape)}")
        return t

    def _call(self, name: str, inputs, labels):
        """Kernel ``name`` of the module on the checked inputs (their batch axes broadcast together)."""
        kernel = getattr(self.module, name, None)
        if kernel is None:
            self._missing(name)
        tensors = [self._tensor(x, label) for x, label in zip(inputs, labels)]
        if len(tensors) > 1:
            shapes = [tuple(t.shape[:-1]) for t in tensors]
            try:
                self._xp.broadcast_shapes(*shapes)
            except (RuntimeError, ValueError):
                text = ", ".join(f"{label} {tuple(t.shape)}" for label, t in zip(labels, tensors))
                raise ShapeError(f"inputs do not broadcast together: {text}") from None
        return kernel(*tensors)

    def _missing(self, name: str):
        if name in DYNAMICS and not has_dynamics(self.robot):
            raise ModelError(f"robot {self.robot.name!r} has no inertial data: compiled dynamics need "
                             "'inertia: {mass, com, inertia}' on its joint rows")
        raise ModelError(f"kernel {name!r} was not compiled (compile(robot, kernels=...) left it out)")

    # --- kinematics -----------------------------------------------------------------------------------------
    def fk(self, q, frames: bool = False):
        """End-effector pose T_w_e, shape (..., 4, 4) (as :func:`denavit.forward_kinematics`); ``frames=True``: the
        world poses of the DH frames {0} … {N}, shape (..., N+1, 4, 4) (as :func:`denavit.link_transforms`)."""
        return self._call("frames" if frames else "fk", (q,), ("q",))

    def position(self, q):
        """End-effector origin p_w_e, shape (..., 3), from a kernel computing only what the origin needs."""
        return self._call("position", (q,), ("q",))

    def jacobian(self, q, frame: Frame | str = "base"):
        """Geometric Jacobian, shape (..., 6, n), rows (v, ω): ``base`` J0 or ``tool`` Je (as
        :func:`denavit.geometric_jacobian`)."""
        try:
            base = Frame(frame) is Frame.BASE
        except ValueError:
            raise ValueError(f"frame must be 'base' or 'tool', got {frame!r}") from None
        return self._call("jacobian0" if base else "jacobiane", (q,), ("q",))

    # --- dynamics -------------------------------------------------------------------------------------------
    def rnea(self, q, qd, qdd):
        """Inverse dynamics τ = M q̈ + C q̇ + g + τ_f, shape (..., n) (as :func:`denavit.rnea` with the robot's
        gravity and the object's friction)."""
        return self._call("rnea", (q, qd, qdd), ("q", "qd", "qdd"))

    def mass_matrix(self, q):
        """M(q), shape (..., n, n) (as :func:`denavit.mass_matrix`)."""
        return self._call("mass_matrix", (q,), ("q",))

    def gravity(self, q):
        """g(q), shape (..., n) (as :func:`denavit.gravity_torques` with the robot's gravity)."""
        return self._call("gravity", (q,), ("q",))

    def coriolis(self, q, qd):
        """c(q, q̇) = C(q, q̇) q̇, shape (..., n) (as :func:`denavit.coriolis_vector`)."""
        return self._call("coriolis", (q, qd), ("q", "qd"))

    def forward_dynamics(self, q, qd, tau):
        """q̈ = M⁻¹ (τ − c − g − τ_f), shape (..., n), by the framework's linear solve of M (``torch.linalg.solve``,
        ``jax.numpy.linalg.solve``: differentiable).  M is not checked for regularity (that would stop a JIT): a
        singular M gives what the solve gives (torch raises, JAX returns non-finite values)."""
        if not hasattr(self.module, "forward_dynamics"):
            self._missing("forward_dynamics")
        return self._call("forward_dynamics", (q, qd, tau), ("q", "qd", "tau"))


def compile_tensor(robot: DHRobot, framework: str, kernels=None, friction: bool = True) -> TensorRobot:
    """The kernels ``kernels`` (default: every built-in one the arm supports) of ``robot`` for ``framework``
    (``"torch"`` or ``"jax"``), generated or loaded from the kernel cache; see :func:`denavit.compile`."""
    framework_namespace(framework)  # the missing framework is reported before any work
    wanted = tuple(k for k in KERNEL_NAMES if k not in INTERNAL) if kernels is None else tuple(kernels)
    unknown = [k for k in wanted if k not in KERNEL_NAMES]
    if unknown:
        raise ValueError(f"unknown kernels {unknown} for backend {framework!r}; choose from {', '.join(KERNEL_NAMES)}")
    if not has_dynamics(robot):
        wanted = tuple(k for k in wanted if k not in DYNAMICS)
    if "forward_dynamics" in wanted:  # by the framework's solve: M and the bias (rnea at q̈ = 0) are what it needs
        wanted = tuple(k for k in wanted if k != "forward_dynamics") + tuple(
            k for k in ("rnea", "mass_matrix") if k not in wanted)
    key = robot_key(robot, framework, friction, wanted)

    def make_source() -> str:
        return tensor_module(trace_kernels(robot, wanted, friction), framework,
                             f"Kernels of a {robot.dof}-joint arm.", standalone=False)  # no user text in code

    return TensorRobot(robot, load_module(key, framework, make_source), framework, wanted, friction)
