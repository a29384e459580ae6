"""``denavit.compile(robot)``: the arm's generated kernels, loaded from a disk cache, behind one object."""

from __future__ import annotations

import hashlib
import random as _random
import importlib.machinery
import importlib.util
import py_compile
import os
import sys
import tempfile
import threading
from pathlib import Path

import numpy as np

from ..numeric import (IK_MAX_ITERATIONS, IK_RESTARTS, IK_TOL, AnalyticIKResult, IKResult, JointLimits,
                       analytic_ik, characteristic_length, ik_plan, row_mask, solve_ik)
from ..errors import MissingDependencyError, ModelError, ShapeError
from ..model import DHRobot, Frame
from ._emit import NUMBA, NUMPY, python_module
from ._ik_elbow import ELBOW_LAYOUT
from ._kernels import DYNAMICS, KERNEL_NAMES, has_dynamics as _has_dynamics, trace_kernels

__all__ = ["compile", "CompiledRobot", "cache_dir", "numba_available", "robot_key", "GENERATOR_VERSION"]

CACHE_ENV = "DENAVIT_CACHE_DIR"
_LOCK = threading.Lock()
_LOADED: dict[str, object] = {}  # module name → module, per process


def numba_available() -> bool:
    """True when numba imports (the ``fast`` extra)."""
    return importlib.util.find_spec("numba") is not None


def cache_dir() -> Path:
    """Where generated modules (and numba's compiled code) are kept: ``$DENAVIT_CACHE_DIR``, else
    ``$XDG_CACHE_HOME/denavit/kernels``, else ``~/.cache/denavit/kernels``."""
    env = os.environ.get(CACHE_ENV)
    if env:
        return Path(env)
    base = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    return Path(base) / "denavit" / "kernels"


def _writable(path: Path) -> Path:
    """``path`` when we can write there; otherwise a private temporary folder.

    The folder's files are imported as code, so a fallback is never a shared, guessable path another user
    could have prepared: it is made fresh by ``mkdtemp`` (mode 0700) once per process."""
    global _FALLBACK
    try:
        path.mkdir(parents=True, exist_ok=True)
        probe = path / f".probe-{os.getpid()}"
        probe.write_text("")
        probe.unlink()
        return path
    except OSError:
        if _FALLBACK is None:
            _FALLBACK = Path(tempfile.mkdtemp(prefix="denavit-kernels-"))
        return _FALLBACK


_FALLBACK: Path | None = None


#: Part of every cache key, with a digest of the sources that shape the generated code (the generator, the
#: chain walker, the dynamics kernels): a changed generator never reads a stale module.
GENERATOR_VERSION = "1"
_SOURCES = ("codegen/_emit.py", "codegen/_ik_lm.py", "codegen/_ik_elbow.py", "codegen/_llvm.py", "codegen/_kernels.py", "codegen/_trace.py",
            "chain/_chain.py", "chain/_walk.py", "numeric/_dynamics_fast.py")
_DIGEST: list[str] = []


def _generator_digest() -> str:
    if not _DIGEST:
        root = Path(__file__).resolve().parent.parent
        h = hashlib.sha256(GENERATOR_VERSION.encode())
        for rel in _SOURCES:
            h.update((root / rel).read_bytes())
        _DIGEST.append(h.hexdigest()[:16])
    return _DIGEST[0]


def robot_key(robot: DHRobot, backend: str, friction: bool, kernels) -> str:
    """A digest of everything the kernels depend on: the DH rows, base, tool, gravity, inertial data, the
    backend and options (exact float bits), and the generator's version.  Names and presentation are left out."""
    def h(x) -> str:
        return float(x).hex()

    parts = [_generator_digest(), backend, str(bool(friction)), ",".join(kernels), robot.convention.value]
    for link in robot.links:
        parts.append(" ".join([link.joint.value, h(link.a), h(link.alpha), h(link.d), h(link.theta)]))
        li = link.inertia
        if li is not None:
            parts.append(" ".join(h(v) for v in (li.mass, *li.com, *li.inertia, li.motor_inertia, li.viscous,
                                                 li.coulomb)))
    for M in (robot.base, robot.tool):
        parts.append(" ".join(h(v) for row in M for v in row))
    parts.append(" ".join(h(v) for v in robot.gravity))
    return hashlib.sha256("\n".join(parts).encode()).hexdigest()[:24]


def _load(key: str, tag: str, make_source):
    """Import the generated module for ``key`` from the cache, writing it first (atomically) when absent."""
    modname = f"_denavit_kernels_{tag}_{key}"
    with _LOCK:
        mod = _LOADED.get(modname)
        if mod is not None:
            return mod
        folder = _writable(cache_dir())
        path = folder / f"{modname}.py"
        if not path.exists():
            fd, tmp = tempfile.mkstemp(dir=folder, suffix=".tmp")
            with os.fdopen(fd, "w") as fh:
                fh.write(make_source())
            os.replace(tmp, path)
        # the bytecode is kept beside the source by us (PYTHONDONTWRITEBYTECODE would otherwise make every
        # process parse the module again: ~0.3 s for a 7-joint arm); numba's own cache keys on the source file
        pyc = folder / f"{modname}.pyc"
        if not pyc.exists():
            fd, tmp = tempfile.mkstemp(dir=folder, suffix=".tmp")
            os.close(fd)
            py_compile.compile(str(path), cfile=tmp, dfile=str(path), doraise=True,
                               invalidation_mode=py_compile.PycInvalidationMode.UNCHECKED_HASH)
            os.replace(tmp, pyc)
        loader = importlib.machinery.SourcelessFileLoader(modname, str(pyc))
        spec = importlib.util.spec_from_loader(modname, loader, origin=str(path))
        mod = importlib.util.module_from_spec(spec)
        mod.__file__ = str(path)
        sys.modules[modname] = mod
        try:
            spec.loader.exec_module(mod)
        except BaseException:
            sys.modules.pop(modname, None)
            raise
        _LOADED[modname] = mod
        return mod


def _as_batch(arrays, n: int, names):
    """Broadcast the inputs to (..., n); return the 2-D contiguous (B, n) views and the batch shape."""
    try:
        arrays = np.broadcast_arrays(*arrays)
    except ValueError:
        shapes = ", ".join(f"{nm} {a.shape}" for nm, a in zip(names, arrays))
        raise ShapeError(f"inputs do not broadcast together: {shapes}") from None
    batch = arrays[0].shape[:-1]
    flat = [np.ascontiguousarray(a.reshape(-1, n)) for a in arrays]
    return flat, batch


_ndarray, _F64, _empty, _SHAPE44, _SHAPE3, _STRIDE = np.ndarray, np.dtype(np.float64), np.empty, (4, 4), (3,), (8,)
_NO_SEEDS = np.zeros((0, 1))


class CompiledRobot:
    """The generated kernels of one arm.  Made by :func:`compile`; see there."""

    def __init__(self, robot: DHRobot, module, backend: str, names) -> None:
        self.robot = robot
        self.dof = n = robot.dof
        self.backend = backend
        self.kernels = tuple(names)
        self._m = module
        self._shapes = {"fk": (4, 4), "position": (3,), "frames": (len(robot.links) + 1, 4, 4), "jacobian0": (6, n),
                        "jacobiane": (6, n), "fk_jacobian0": (16 + 6 * n,), "rnea": (n,), "gravity": (n,), "coriolis": (n,),
                        "mass_matrix": (n, n), "forward_dynamics": (n + 1,)}
        self._one = {name: (getattr(module, f"{name}_1"), self._shapes[name]) for name in names}
        self._vec, self._jshape, self._mshape, self._fshape = (n,), (6, n), (n, n), (n + 1,)
        self._ik_constants = None
        self._elbow = None
        for name in self._shapes:  # bound kernels for the hot paths; a missing one raises the clear error
            if name not in self._one:
                setattr(self, f"_{name}_1", self._missing(name))
            else:
                setattr(self, f"_{name}_1", self._first(name) if backend == NUMBA else self._one[name][0])

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
        return the seconds each took."""
        import time

        out = {}
        for name in self.kernels:
            kernel, shape = self._one[name]
            k = {"rnea": 3, "forward_dynamics": 3, "coriolis": 2}.get(name, 1)
            t = time.perf_counter()
            kernel(*[np.zeros(self.dof)] * k, _empty(shape))
            getattr(self._m, f"{name}_n")(*[np.zeros((1, self.dof))] * k, _empty((1,) + shape))
            out[name] = time.perf_counter() - t
        return out

    def _first(self, name: str):
        """The kernel's first call: compile (or load) it, then bind its machine-code entry point.

        A numba dispatcher spends a few hundred nanoseconds per call choosing the compiled version from the
        argument types; the hot paths already know them (float64, C-contiguous, fresh output), so they call
        the entry point of that version directly."""
        dispatcher = self._one[name][0]

        def first(*args):
            dispatcher(*args)
            for sig, result in dispatcher.overloads.items():
                if all(getattr(t, "layout", "C") == "C" for t in sig):
                    setattr(self, f"_{name}_1", result.entry_point)
                    break

        return first

    def _missing(self, name: str):
        def kernel(*args):
            self._kernel(name)

        return kernel

    # --- plumbing ---------------------------------------------------------------------------------------
    def _kernel(self, name: str):
        hit = self._one.get(name)
        if hit is None:
            if name in DYNAMICS and not _has_dynamics(self.robot):
                raise ModelError(f"robot {self.robot.name!r} has no inertial data: compiled dynamics need "
                                 "'inertia: {mass, com, inertia}' on its joint rows")
            raise ModelError(f"kernel {name!r} was not compiled (compile(robot, kernels=...) left it out)")
        return hit

    def _call(self, name: str, inputs, labels):
        """Any call: one configuration (every input (n,)) or a batch (inputs broadcast to (..., n))."""
        kernel, shape = self._kernel(name)
        n = self.dof
        arrays = []
        for x, label in zip(inputs, labels):
            a = np.asarray(x, dtype=np.float64)
            if a.ndim == 0 or a.shape[-1] != n:
                raise ShapeError(f"{label}: expected shape (..., {n}) for a {n}-joint robot, got {a.shape}")
            arrays.append(a)
        if all(a.ndim == 1 for a in arrays):
            out = _empty(shape)
            getattr(self, f"_{name}_1")(*[np.ascontiguousarray(a) for a in arrays], out)
            return out
        flat, batch = _as_batch(arrays, n, labels)
        out = _empty((flat[0].shape[0],) + shape)
        if out.shape[0]:
            getattr(self._m, f"{name}_n")(*flat, out)
        return out.reshape(batch + shape)

    # --- kinematics ---------------------------------------------------------------------------------------
    # Each method first tries the hot path: float64 ndarrays of shape (n,) go straight to the kernel with a
    # fresh output; anything else (lists, other dtypes, batches, wrong shapes) takes :meth:`_call`.
    def fk(self, q, frames: bool = False) -> np.ndarray:
        """End-effector pose T_w_e, shape (..., 4, 4) (as :func:`denavit.forward_kinematics`); with
        ``frames=True`` the world poses of the DH frames {0} … {N}, shape (..., N+1, 4, 4) (as
        :func:`denavit.link_transforms`, tool not applied)."""
        if not frames and q.__class__ is _ndarray and q.dtype is _F64 and q.shape == self._vec and q.strides == _STRIDE:
            out = _empty(_SHAPE44)
            self._fk_1(q, out)
            return out
        return self._call("frames" if frames else "fk", (q,), ("q",))

    def position(self, q) -> np.ndarray:
        """End-effector origin p_w_e, shape (..., 3): ``fk(q)[..., :3, 3]`` from a kernel that computes only
        what the origin needs (for workspace sampling)."""
        if q.__class__ is _ndarray and q.dtype is _F64 and q.shape == self._vec and q.strides == _STRIDE:
            out = _empty(_SHAPE3)
            self._position_1(q, out)
            return out
        return self._call("position", (q,), ("q",))

    def jacobian(self, q, frame: Frame | str = "base") -> np.ndarray:
        """Geometric Jacobian, shape (..., 6, n), rows (v, ω): ``base`` J0 or ``tool`` Je (as
        :func:`denavit.geometric_jacobian`)."""
        if frame == "base" or frame is Frame.BASE:
            if q.__class__ is _ndarray and q.dtype is _F64 and q.shape == self._vec and q.strides == _STRIDE:
                out = _empty(self._jshape)
                self._jacobian0_1(q, out)
                return out
            return self._call("jacobian0", (q,), ("q",))
        if frame == "tool" or Frame(frame) is Frame.TOOL:
            if q.__class__ is _ndarray and q.dtype is _F64 and q.shape == self._vec and q.strides == _STRIDE:
                out = _empty(self._jshape)
                self._jacobiane_1(q, out)
                return out
            return self._call("jacobiane", (q,), ("q",))
        raise ValueError(f"frame must be 'base' or 'tool', got {frame!r}")  # pragma: no cover (Frame raises)

    # --- dynamics -------------------------------------------------------------------------------------------
    def rnea(self, q, qd, qdd) -> np.ndarray:
        """Inverse dynamics τ = M q̈ + C q̇ + g + τ_f, shape (..., n) (as :func:`denavit.rnea` with the robot's
        gravity and friction)."""
        if (q.__class__ is _ndarray and qd.__class__ is _ndarray and qdd.__class__ is _ndarray
                and q.dtype is _F64 and qd.dtype is _F64 and qdd.dtype is _F64
                and q.shape == self._vec and qd.shape == self._vec and qdd.shape == self._vec
                and q.strides == qd.strides == qdd.strides == _STRIDE):
            out = _empty(self._vec)
            self._rnea_1(q, qd, qdd, out)
            return out
        return self._call("rnea", (q, qd, qdd), ("q", "qd", "qdd"))

    def mass_matrix(self, q) -> np.ndarray:
        """M(q), shape (..., n, n) (as :func:`denavit.mass_matrix`)."""
        if q.__class__ is _ndarray and q.dtype is _F64 and q.shape == self._vec and q.strides == _STRIDE:
            out = _empty(self._mshape)
            self._mass_matrix_1(q, out)
            return out
        return self._call("mass_matrix", (q,), ("q",))

    def gravity(self, q) -> np.ndarray:
        """g(q), shape (..., n) (as :func:`denavit.gravity_torques` with the robot's gravity)."""
        if q.__class__ is _ndarray and q.dtype is _F64 and q.shape == self._vec and q.strides == _STRIDE:
            out = _empty(self._vec)
            self._gravity_1(q, out)
            return out
        return self._call("gravity", (q,), ("q",))

    def coriolis(self, q, qd) -> np.ndarray:
        """c(q, q̇) = C(q, q̇) q̇, shape (..., n) (as :func:`denavit.coriolis_vector`)."""
        return self._call("coriolis", (q, qd), ("q", "qd"))

    def forward_dynamics(self, q, qd, tau) -> np.ndarray:
        """q̈ = M⁻¹ (τ − c − g − τ_f), shape (..., n) (as :func:`denavit.forward_dynamics`); ModelError where
        M is singular."""
        if (q.__class__ is _ndarray and qd.__class__ is _ndarray and tau.__class__ is _ndarray
                and q.dtype is _F64 and qd.dtype is _F64 and tau.dtype is _F64
                and q.shape == self._vec and qd.shape == self._vec and tau.shape == self._vec
                and q.strides == qd.strides == tau.strides == _STRIDE):
            r = _empty(self._fshape)
            self._forward_dynamics_1(q, qd, tau, r)
        else:
            r = self._call("forward_dynamics", (q, qd, tau), ("q", "qd", "tau"))
        if r.ndim == 1:
            if not r[-1] > 0.0:
                self._singular()
        elif not (r[..., -1] > 0.0).all():
            self._singular()
        return r[..., :-1]

    # --- inverse kinematics ------------------------------------------------------------------------------------
    def solve_ik(self, T, q0=None, *, mask="pose", tol: float | None = None, max_iterations: int | None = None,
                 restarts: int | None = None, respect_limits: bool = True, rng: np.random.Generator | None = None):
        """Numeric IK by Levenberg–Marquardt on the compiled FK and Jacobian: as :func:`denavit.solve_ik`
        (same arguments, same :class:`~denavit.IKResult`), each iteration in machine code.

        Targets the compiled search does not solve are handed to :func:`denavit.solve_ik` with the same
        arguments (its closed-form and bank rescues, and its diagnosis of *why* a target fails), so the
        answers are never worse than the plain function's.  The numpy backend always uses the plain function.
        """
        tol = IK_TOL if tol is None else float(tol)
        max_iterations = IK_MAX_ITERATIONS if max_iterations is None else int(max_iterations)
        restarts = IK_RESTARTS if restarts is None else int(restarts)
        plain = dict(mask=mask, tol=tol, max_iterations=max_iterations, restarts=restarts,
                     respect_limits=respect_limits, rng=rng)
        if self.backend != NUMBA or not {"fk", "fk_jacobian0"} <= set(self.kernels):
            return solve_ik(self.robot, T, q0, **plain)
        c = self._ik_constants
        if c is None or c[0] != (mask if isinstance(mask, str) else tuple(mask), respect_limits):
            L = characteristic_length(self.robot)
            w = np.where(row_mask(mask), 1.0, 0.0) * np.array([1.0, 1.0, 1.0, L, L, L])
            lim = JointLimits(self.robot, not respect_limits)
            slo, shi = lim.sample_bounds(L)
            mid = np.where(np.isfinite(lim.lo) & np.isfinite(lim.hi), 0.5 * (np.nan_to_num(lim.lo) + np.nan_to_num(lim.hi)),
                           0.0)
            c = self._ik_constants = ((mask if isinstance(mask, str) else tuple(mask), respect_limits), w, L, lim,
                                      slo, shi, lim.revolute.astype(np.bool_), mid)
        _, w, L, lim, slo, shi, revolute, mid = c
        n = self.dof
        Ta = np.asarray(T, dtype=np.float64)
        if Ta.ndim < 2 or Ta.shape[-2:] != (4, 4):
            raise ShapeError(f"T: expected shape (..., 4, 4), got {Ta.shape}")
        batch = Ta.shape[:-2]
        Tf = np.ascontiguousarray(Ta.reshape(-1, 4, 4))
        B = Tf.shape[0]
        if q0 is None:
            Q0 = np.ascontiguousarray(np.broadcast_to(mid, (B, n)))
        elif B == 1 and q0.__class__ is _ndarray and q0.dtype is _F64 and q0.shape == self._vec:
            Q0 = np.ascontiguousarray(q0).reshape(1, n)
        else:
            try:
                Q0 = np.broadcast_to(np.asarray(q0, dtype=np.float64), batch + (n,)).reshape(B, n)
            except (ValueError, TypeError):
                raise ShapeError(f"q0: expected shape (..., {n}) matching the targets {batch}, got "
                                 f"{np.shape(q0)}") from None
            Q0 = np.ascontiguousarray(Q0)
        err = self._m.ik_check(Tf, Q0)  # NaN, inf and orthonormality in one pass
        if err < 0.0:
            raise ShapeError("q0 has non-finite values (NaN or inf)")
        if err > 1e-6:
            raise ShapeError("T has non-finite values" if err == np.inf else
                             f"T: rotation part is not orthonormal (error {err:.2g})")
        seed = _random.getrandbits(31) if rng is None else int(rng.bit_generator.random_raw() & 0x7FFFFFFF)
        q_out = np.empty((B, n))
        info = np.empty((B, 5))
        self._m.ik_lm(Tf, Q0, lim.lo, lim.hi, slo, shi, revolute, w, L, tol, max_iterations, restarts, seed,
                      q_out, info)
        if batch == () and info[0, 0] > 0.0:  # one target, solved: the lean path
            return IKResult(q_out[0], True, float(info[0, 1]), float(info[0, 2]), int(info[0, 3]), int(info[0, 4]),
                            "")
        success = info[:, 0] > 0.0
        reason = np.full(B, "", dtype=object)
        iters, used = info[:, 3].astype(int), info[:, 4].astype(int)
        pe, re = info[:, 1].copy(), info[:, 2].copy()
        if not success.all():  # the plain solver: rescues, and the reason of each failure
            fail = np.flatnonzero(~success)
            again = solve_ik(self.robot, Tf[fail], Q0[fail], **plain)
            q_out[fail] = again.q
            success[fail] = again.success
            pe[fail], re[fail] = again.position_error, again.orientation_error
            iters[fail] += again.iterations
            used[fail] += again.restarts
            reason[fail] = again.reason
        if batch == ():
            return IKResult(q_out[0], bool(success[0]), float(pe[0]), float(re[0]), int(iters[0]), int(used[0]),
                            str(reason[0]))
        return IKResult(q_out.reshape(batch + (n,)), success.reshape(batch), pe.reshape(batch), re.reshape(batch),
                        iters.reshape(batch), used.reshape(batch), reason.reshape(batch))

    def analytic_ik(self, T) -> AnalyticIKResult:
        """Every closed-form solution of one pose: as :func:`denavit.analytic_ik` (same result), in machine code
        for arms of the elbow + spherical-wrist class (Puma 560 and most industrial 6R arms).

        Poses the plain solver treats specially (a joint left free, a double root, a candidate that needs
        polishing, solutions about to merge) are answered by :func:`denavit.analytic_ik`, and so are batches
        (its batched path is already the fast one) and arms of other classes.
        """
        c = self._elbow
        if c is None:
            plan = ik_plan(self.robot)  # UnsupportedRobotError for arms with no closed form, as the plain function
            if self.backend != NUMBA or plan.closed is None or not {"fk", "fk_jacobian0"} <= set(self.kernels):
                c = self._elbow = False
            else:
                k = dict(plan.closed)
                lim = self.robot.q_limits
                k.update(lo=lim[:, 0], hi=lim[:, 1],
                         revolute=[float(t.value == "revolute") for t in self.robot.joint_types])
                K = np.concatenate([np.asarray(k[name], dtype=np.float64).ravel() for name, _ in ELBOW_LAYOUT])
                assert K.size == sum(size for _, size in ELBOW_LAYOUT)
                c = self._elbow = [K, k["labels"], plan.kind, self._m.ik_check, self._m.ik_elbow_packed, True]
        Ta = np.asarray(T, dtype=np.float64)
        if c is False or Ta.shape != (4, 4):
            return analytic_ik(self.robot, T)
        K, labels, kind, check, solve, first = c
        Tf = np.ascontiguousarray(Ta).reshape(1, 4, 4)
        err = check(Tf, _NO_SEEDS)
        if err > 1e-6:
            raise ShapeError("T has non-finite values" if err == np.inf else
                             f"T: rotation part is not orthonormal (error {err:.2g})")
        f = np.empty((1, 8, 14))  # solutions (6), residuals (2), outside-limits solutions (6)
        i = np.empty((1, 11), dtype=np.int64)  # label codes (8), then kept, outside, status
        solve(Tf, K, f, i)
        if first:  # numba compiled (or loaded) them on this first call: call their machine code from now on
            c[3] = next(iter(self._m.ik_check.overloads.values())).entry_point
            c[4] = next(iter(self._m.ik_elbow_packed.overloads.values())).entry_point
            c[5] = False
        if i[0, 10]:
            return analytic_ik(self.robot, T)
        k, j = int(i[0, 8]), int(i[0, 9])
        return AnalyticIKResult(f[0, :k, :6], tuple(labels[i[0, :k]]), ("",) * k, f[0, :k, 6], f[0, :k, 7],
                                f[0, :j, 8:], kind, "pose", np.ones(k, dtype=bool))

    def _singular(self):
        raise ModelError(f"robot {self.robot.name!r}: the mass matrix is singular at this configuration "
                         "(a joint whose subtree has no inertia about its axis)")


def compile(robot: DHRobot, *, backend: str | None = None, kernels=None,  # noqa: A001
            friction: bool = True) -> CompiledRobot:
    """Generated kernels of ``robot``: FK, Jacobians and dynamics as straight-line code for this arm.

    Parameters
    ----------
    robot : DHRobot
    backend : {"numba", "numpy"}, optional
        ``numba`` (the ``fast`` extra: JIT-compiled machine code, cached on disk) is the default when
        numba is installed, else ``numpy`` (the same code run by numpy: vectorised over batches).
    kernels : iterable of str, optional
        Which kernels to build (default all of ``KERNEL_NAMES`` the robot supports).
    friction : bool
        ``rnea`` and ``forward_dynamics`` include the joints' friction τ_f = viscous·q̇ + coulomb·sign(q̇), as the
        plain functions do by default (``friction=False`` there ⇔ ``compile(robot, friction=False)`` here).

    Returns
    -------
    CompiledRobot
        Methods ``fk(q, frames=False)``, ``jacobian(q, frame="base"|"tool")``, ``rnea(q, qd, qdd)``,
        ``mass_matrix(q)``, ``gravity(q)``, ``coriolis(q, qd)``, ``forward_dynamics(q, qd, tau)``, each
        taking ``(n,)`` or ``(..., n)`` and returning what the plain function returns.

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
    if backend not in (NUMBA, NUMPY):
        raise ValueError(f"backend must be 'numba' or 'numpy', got {backend!r}")
    if backend == NUMBA and not numba_available():
        raise MissingDependencyError("backend='numba' needs numba: pip install 'denavit[fast]'")
    wanted = KERNEL_NAMES if kernels is None else tuple(kernels)
    unknown = [k for k in wanted if k not in KERNEL_NAMES]
    if unknown:
        raise ValueError(f"unknown kernels {unknown}; choose from {', '.join(KERNEL_NAMES)}")
    if not _has_dynamics(robot):
        wanted = tuple(k for k in wanted if k not in DYNAMICS)
    key = robot_key(robot, backend, friction, wanted)

    def make_source() -> str:
        specs = trace_kernels(robot, wanted, friction)
        return python_module(specs, backend, f"Kernels of a {robot.dof}-joint arm.")  # no user text in code

    module = _load(key, backend, make_source)
    fast = CompiledRobot(robot, module, backend, wanted)
    fast.friction = bool(friction)
    return fast
