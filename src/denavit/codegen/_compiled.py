"""``denavit.compile(robot)``: the arm's generated kernels, loaded from a disk cache, behind one object."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from .._threads import resolve_threads, run_batch
from .._validate import checked_out
from ..errors import MissingDependencyError, ModelError, ShapeError
from ..model import DHRobot
from . import _fastcall
from ._cache import guard_cache, load_module, numba_available, robot_key
from ._emit import NUMBA, NUMPY, group_batch, python_module
from ._kernels import (BASE_GROUP, DYNAMICS, INTERNAL, KERNEL_NAMES, group_kernels, has_dynamics as _has_dynamics,
                       registered_digest, registered_kernels, trace_kernels, trace_registered)
from ._compiled_base import BaseMethods
from ._compiled_dyn import DynDerivativeMethods
from ._compiled_reg import RegressorMethods
from ._compiled_kin import KinDerivativeMethods
from ._solvers import IKMethods
from ._tensor import FRAMEWORKS, TensorRobot, compile_tensor

__all__ = ["compile", "CompiledRobot"]

def _as_batch(arrays, names):
    """Broadcast the inputs' batch axes (..., k_i) together; return the 2-D contiguous (B, k_i) arrays and the
    batch shape."""
    try:
        batch = np.broadcast_shapes(*[a.shape[:-1] for a in arrays])
    except ValueError:
        shapes = ", ".join(f"{nm} {a.shape}" for nm, a in zip(names, arrays))
        raise ShapeError(f"inputs do not broadcast together: {shapes}") from None
    flat = [np.ascontiguousarray(np.broadcast_to(a, batch + a.shape[-1:]).reshape(-1, a.shape[-1])) for a in arrays]
    return flat, batch


#: kernels whose single call a built-in function takes over (the method it stands in for), and their inputs' count
_BUILTIN_METHODS = {"fk": "fk", "position": "position", "jacobian0": "jacobian", "rnea": "rnea",
                    "mass_matrix": "mass_matrix", "gravity": "gravity", "coriolis": "coriolis",
                    "forward_dynamics": "forward_dynamics", "rnea_derivatives": "rnea_derivatives",
                    "forward_dynamics_derivatives": "forward_dynamics_derivatives",
                    "gravity_derivatives": "gravity_derivatives", "jacobian_dot0": "jacobian_dot",
                    "acceleration_bias0": "acceleration_bias", "kinematic_hessian0": "kinematic_hessian",
                    "regressor": "regressor"}
#: the built-in's result, when not one array of the kernel's shape: (its arrays' shapes of n, kernel's last entry
#: a flag that must be > 0)
_BUILTIN_RESULTS = {"forward_dynamics": (lambda n: ((n,),), True),
                    "rnea_derivatives": (lambda n: ((n, n),) * 2, False),
                    "forward_dynamics_derivatives": (lambda n: ((n, n),) * 3, True)}
#: base kernels whose built-in returns one array: their first call goes through it (see CompiledRobot._first)
_BASE_BUILTINS = frozenset({"fk", "position", "jacobian0", "rnea", "mass_matrix", "gravity", "coriolis",
                            "forward_dynamics"})
_ARITY = {"rnea": 3, "coriolis": 2, "forward_dynamics": 3}
_empty = np.empty


class CompiledRobot(BaseMethods, IKMethods, KinDerivativeMethods, DynDerivativeMethods, RegressorMethods):
    """The generated kernels of one arm.  Made by :func:`compile`; see there."""

    def __init__(self, robot: DHRobot, module, backend: str, names, friction: bool = True, only=None) -> None:
        self.robot = robot
        self.dof = n = robot.dof
        self.backend = backend
        self.friction = bool(friction)
        self.kernels = ()  #: the kernels loaded so far (the base ones; a group's when first called)
        self._m = module
        self._only = None if only is None else frozenset(only)  # compile(kernels=...): nothing else may load
        self._groups = {BASE_GROUP: (module, tuple(names))}
        self._shapes = {"fk": (4, 4), "position": (3,), "frames": (len(robot.links) + 1, 4, 4), "jacobian0": (6, n),
                        "jacobiane": (6, n), "fk_jacobian0": (16 + 6 * n,), "rnea": (n,), "gravity": (n,), "coriolis": (n,),
                        "mass_matrix": (n, n), "forward_dynamics": (n + 1,)}
        self._lengths: dict[str, tuple[int, ...]] = {}  # registered kernels: their inputs' lengths
        self._one, self._many = {}, {}
        self._vec, self._jshape, self._mshape, self._fshape = (n,), (6, n), (n, n), (n + 1,)
        self._ik_constants = None
        self._elbow = None
        self._keep: list = []  # what the built-in methods need alive (see _builtin)
        for name in names:
            self._bind(name, module)
        for name in self._shapes:  # bound kernels for the hot paths; a missing one raises the clear error
            if name not in self._one:
                setattr(self, f"_{name}_1", self._missing(name))

    def _bind(self, name: str, module) -> None:
        """Make kernel ``name`` of ``module`` callable: ``self._one``, ``self._many`` and ``self._<name>_1``."""
        reg = registered_kernels().get(name)
        if reg is not None:
            self._shapes[name] = tuple(reg.shape(self.dof))
            self._lengths[name] = tuple(k for _, k in reg.inputs(self.dof))
        one = getattr(module, f"{name}_1")
        self._one[name] = (one, self._shapes[name])
        self._many[name] = group_batch(module, name) or getattr(module, f"{name}_n")
        setattr(self, f"_{name}_1", self._first(name) if self.backend == NUMBA else one)
        if name not in self.kernels:
            self.kernels += (name,)

    def _load_group(self, group: str) -> None:
        """Compile the registered kernels of ``group`` for this arm, or load them from the disk cache (keyed by
        the arm, the backend, friction, the group's kernels and the digest of the files tracing them)."""
        names = group_kernels(group)
        robot, backend, friction = self.robot, self.backend, self.friction
        key = robot_key(robot, backend, friction, names, salt=f"group {group} {registered_digest(names)}")

        def make_source() -> str:
            specs = trace_registered(robot, names, friction)
            return python_module(specs, backend, f"Kernels of a {robot.dof}-joint arm, group {group}.")

        module = load_module(key, backend, make_source)
        self._groups[group] = (module, names)
        for name in names:  # absent from the module: its tracer refused this arm
            if hasattr(module, f"{name}_1") and (self._only is None or name in self._only):
                self._bind(name, module)

    @property
    def source(self) -> str:
        """The generated module's source text (kept in :func:`cache_dir`)."""
        return Path(self._m.__file__).read_text(encoding="utf-8")

    @property
    def path(self) -> Path:
        """Where the generated module lives."""
        return Path(self._m.__file__)

    def __repr__(self) -> str:
        return (f"<CompiledRobot {self.robot.name!r}: {self.dof} joints, {self.backend}, "
                f"kernels {', '.join(self.kernels)}>")

    def warm(self) -> dict[str, float]:
        """Run every kernel once, single and batch (this compiles it, or loads it from the disk cache);
        return the seconds each took (the first batch call compiles the batch forms of the whole group).  The IK
        solvers' own kernel (``fk_jacobian0``) is compiled with them, on their first use."""
        import time

        out = {}
        for name in self.kernels:
            if name in INTERNAL:  # the IK solvers' kernel: compiled with them
                continue
            _, shape = self._one[name]
            lengths = self._lengths.get(name) or (self.dof,) * {"rnea": 3, "forward_dynamics": 3, "coriolis": 2}.get(name, 1)
            t = time.perf_counter()
            try:  # the single call as the methods make it (a base kernel's built-in, if it has one)
                getattr(self, f"_{name}_1")(*[np.zeros(k) for k in lengths], _empty(shape))
            except ModelError:  # forward dynamics of an arm whose M is singular at q = 0: compiled all the same
                pass
            self._many[name](*[np.zeros((1, k)) for k in lengths], _empty((1,) + shape))
            out[name] = time.perf_counter() - t
        return out

    def _first(self, name: str):
        """The kernel's first call: compile (or load) it, then bind its machine-code entry point.

        A numba dispatcher spends a few hundred nanoseconds per call choosing the compiled version from the
        argument types; the hot paths already know them (float64, C-contiguous, fresh output), so they call
        the entry point of that version directly.  A base kernel with a built-in (:meth:`_builtin`) answers its
        first call through the built-in, and compiles its own one-configuration function only when a call the
        built-in hands back needs it (keywords, lists, ...): a cold ``compile`` + ``warm`` builds one program less
        per kernel."""
        dispatcher = self._one[name][0]

        def compiled(*args):
            dispatcher(*args)
            for sig, result in dispatcher.overloads.items():
                if all(getattr(t, "layout", "C") == "C" for t in sig):
                    setattr(self, f"_{name}_1", result.entry_point)
                    break

        def first(*args):
            compiled(*args)
            if name in _BUILTIN_METHODS:
                self._builtin(name, _BUILTIN_METHODS[name])

        if name not in _BASE_BUILTINS:
            return first

        def first_builtin(*args):
            setattr(self, f"_{name}_1", compiled)  # what the method runs when the built-in hands a call back
            builtin = self._builtin(name, _BUILTIN_METHODS[name])
            if builtin is None:
                compiled(*args)
                return
            *inputs, out = args
            if name == "forward_dynamics":  # q̈ only where M is regular (flag > 0); else the method raises
                out[:-1] = builtin(*inputs)
                out[-1] = 1.0
            else:
                out[...] = builtin(*inputs)

        return first_builtin

    def _builtin(self, name: str, method: str):
        """Put kernel ``name``'s CPython built-in (:mod:`denavit.codegen._fastcall`) on this object in place of
        ``method``: a call with exactly the kernel's float64 vectors runs in machine code from the call on (a
        tuple of fresh arrays where the method returns a tuple); every other call goes to the method itself.
        Nothing changes when the built-in cannot be made here (None is returned; else the built-in)."""
        reg = registered_kernels().get(name)
        module = self._groups[reg.group if reg else BASE_GROUP][0]
        try:
            together = self._builtin_specs(module)
            spec = next(s for s in together if s[0] == name)
            made = _fastcall.install(module, name, *spec[1:4], getattr(type(self), method).__get__(self),
                                     guard_cache, spec[4], together)
        except Exception:  # noqa: BLE001 — a numba or platform difference: the method stays, correct, slower
            made = None
        if made is None:
            return None
        setattr(self, method, made[0])
        self._keep.append(made[1])
        return made[0]

    def _builtin_specs(self, module) -> tuple:
        """``(name, input lengths, kernel shape, result blocks, flagged)`` of every kernel of ``module`` with a
        built-in, in one fixed order whichever is asked for first: their built-ins are made by one numba compile."""
        n, reg, specs = self.dof, registered_kernels(), []
        for k in _BUILTIN_METHODS:
            if not hasattr(module, f"{k}{_fastcall.ENTRY_SUFFIX}"):
                continue
            lengths = tuple(x for _, x in reg[k].inputs(n)) if k in reg else (n,) * _ARITY.get(k, 1)
            shape = tuple(reg[k].shape(n)) if k in reg else self._shapes[k]
            blocks, flagged = _BUILTIN_RESULTS.get(k, (lambda n, s=shape: (s,), False))
            specs.append((k, lengths, shape, blocks(n), flagged))
        return tuple(specs)

    def _missing(self, name: str):
        def kernel(*args):
            self._kernel(name)

        return kernel

    # --- plumbing ---------------------------------------------------------------------------------------
    def _kernel(self, name: str):
        hit = self._one.get(name)
        if hit is None:
            reg = registered_kernels().get(name)
            if reg is None or reg.group == BASE_GROUP or (self._only is not None and name not in self._only):
                if name in DYNAMICS and not _has_dynamics(self.robot):
                    raise ModelError(f"robot {self.robot.name!r} has no inertial data: compiled dynamics need "
                                     "'inertia: {mass, com, inertia}' on its joint rows")
                raise ModelError(f"kernel {name!r} was not compiled (compile(robot, kernels=...) left it out)")
            loaded = self._groups.get(reg.group)
            if loaded is None or name not in loaded[1]:  # first call of the group (or a kernel registered since)
                self._load_group(reg.group)
            hit = self._one.get(name)
            if hit is None:  # its tracer refused this arm: its own error says why
                reg.trace(self.robot, self.friction)
                raise ModelError(f"kernel {name!r} does not apply to robot {self.robot.name!r}")
        return hit

    def _call(self, name: str, inputs, labels, threads=None, out=None):
        """Any call: one configuration (every input (n,)) or a batch (inputs broadcast to (..., n)), the batch's
        rows split over ``threads`` threads (:mod:`denavit._threads`: None = every core) into one output: a fresh
        array, or ``out`` (checked: writeable C-contiguous float64 of the result's shape; returned)."""
        kernel, shape = self._kernel(name)
        n = self.dof
        lengths = self._lengths.get(name) or (n,) * len(labels)
        resolve_threads(threads)  # a bad value is refused on every path, even where it is not used
        arrays = []
        for x, label, k in zip(inputs, labels, lengths):
            a = np.asarray(x, dtype=np.float64)
            if a.ndim == 0 or a.shape[-1] != k:
                joints = f" for a {n}-joint robot" if k == n else ""
                raise ShapeError(f"{label}: expected shape (..., {k}){joints}, got {a.shape}")
            arrays.append(a)
        if all(a.ndim == 1 for a in arrays):
            result = _empty(shape) if out is None else checked_out(out, shape)
            getattr(self, f"_{name}_1")(*[np.array(a) if out is not None and np.may_share_memory(a, out)
                                          else np.ascontiguousarray(a) for a in arrays], result)
            return result
        flat, batch = _as_batch(arrays, labels)
        if out is None:
            result = _empty((flat[0].shape[0],) + shape)
        else:  # rows of a C-contiguous array: a view; an input overlapping it is copied first, as numpy's ufuncs do
            result = checked_out(out, batch + shape).reshape((flat[0].shape[0],) + shape)
            flat = [a.copy() if np.may_share_memory(a, out) else a for a in flat]
        if result.shape[0]:
            run_batch(self._many[name], flat, (result,), threads)  # the kernels release the GIL
        return result.reshape(batch + shape) if out is None else out


def compile(robot: DHRobot, *, backend: str | None = None, kernels=None,  # noqa: A001
            friction: bool = True) -> CompiledRobot | TensorRobot:
    """Generated kernels of ``robot``: FK, Jacobians and dynamics as straight-line code for this arm.

    Parameters
    ----------
    robot : DHRobot
    backend : {"numba", "numpy", "torch", "jax"}, optional
        ``numba`` (the ``fast`` extra: JIT-compiled machine code, cached on disk) is the default when
        numba is installed, else ``numpy`` (the same code run by numpy: vectorised over batches).  ``torch`` and
        ``jax`` (extras of those names) give a :class:`~denavit.codegen.TensorRobot`: the same programs on the
        framework's tensors, differentiable and jit-compatible, with the base methods below (no ``threads``,
        ``out`` or registered kernels; forward dynamics by the framework's linear solve).
    kernels : iterable of str, optional
        Which kernels to build now, and the only ones the object will have (built-in names, ``KERNEL_NAMES``, or
        registered ones).  Default: every built-in kernel the robot supports now, and every registered kernel
        (``register_kernel``) when first called (compiled then, or loaded from the disk cache, by group).
    friction : bool
        ``rnea`` and ``forward_dynamics`` include the joints' friction τ_f = viscous·q̇ + coulomb·sign(q̇), as the
        plain functions do by default (``friction=False`` there ⇔ ``compile(robot, friction=False)`` here).

    Returns
    -------
    CompiledRobot
        Methods ``fk(q, frames=False)``, ``jacobian(q, frame="base"|"tool")``, ``rnea(q, qd, qdd)``,
        ``mass_matrix(q)``, ``gravity(q)``, ``coriolis(q, qd)``, ``forward_dynamics(q, qd, tau)``, each
        taking ``(n,)`` or ``(..., n)`` and returning what the plain function returns.  Each takes
        ``threads=`` (default: every core): a batch's rows are split over that many threads (the kernels
        release the GIL; :mod:`denavit._threads` has the rules: small batches run inline, results are those of
        the unsplit call bit for bit).  All but ``forward_dynamics`` take ``out=``: the caller's writeable
        C-contiguous float64 array of the result's shape, written and returned (ShapeError if it is not one).

    Notes
    -----
    Each kernel is the library's own algorithm (chain walk, RNEA, CRBA, LDLᵀ) run once on traced symbols
    with the arm's constants folded in and common subexpressions shared (:mod:`denavit.codegen._trace`),
    then written out as straight-line code.  The first compile of an arm with numba takes seconds (LLVM);
    the code is cached in :func:`cache_dir`, so later processes load it in milliseconds.  Inputs are not
    checked for NaN (the plain functions do): the kernels are for hot loops.
    """
    if not isinstance(robot, DHRobot):
        raise TypeError(f"compile expects a DHRobot, got {type(robot).__name__}")
    if backend is None:
        backend = NUMBA if numba_available() else NUMPY
    if backend in FRAMEWORKS:
        return compile_tensor(robot, backend, kernels, friction)
    if backend not in (NUMBA, NUMPY):
        raise ValueError(f"backend must be 'numba', 'numpy', 'torch' or 'jax', got {backend!r}")
    if backend == NUMBA and not numba_available():
        raise MissingDependencyError("backend='numba' needs numba: pip install 'denavit[fast]'")
    reg = registered_kernels()
    wanted = KERNEL_NAMES + group_kernels(BASE_GROUP) if kernels is None else tuple(kernels)
    unknown = [k for k in wanted if k not in KERNEL_NAMES and k not in reg]
    if unknown:
        raise ValueError(f"unknown kernels {unknown}; choose from {', '.join(KERNEL_NAMES + tuple(reg))}")
    if not _has_dynamics(robot):
        wanted = tuple(k for k in wanted if k not in DYNAMICS)
    base = tuple(k for k in wanted if k in KERNEL_NAMES or reg[k].group == BASE_GROUP)
    added = tuple(k for k in base if k not in KERNEL_NAMES)
    key = robot_key(robot, backend, friction, base, salt=f"registered {registered_digest(added)}" if added else "")

    def make_source() -> str:
        specs = trace_kernels(robot, base, friction)
        specs.update(trace_registered(robot, added, friction))
        return python_module(specs, backend, f"Kernels of a {robot.dof}-joint arm.")  # no user text in code

    module = load_module(key, backend, make_source)
    fast = CompiledRobot(robot, module, backend, [k for k in base if k not in added or hasattr(module, f"{k}_1")], friction,
                         None if kernels is None else wanted)
    for group in dict.fromkeys(reg[k].group for k in wanted if k not in base):  # asked for by name: now
        fast._load_group(group)
    return fast
