"""Where generated kernels live: the disk cache, its keys, and loading a generated module."""

from __future__ import annotations

import hashlib
import importlib.machinery
import importlib.util
import os
import py_compile
import sys
import tempfile
import threading
from pathlib import Path

from ..model import DHRobot

__all__ = ["cache_dir", "numba_available", "robot_key", "load_module", "GENERATOR_VERSION", "CACHE_ENV"]

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
_SOURCES = ("codegen/_emit.py", "codegen/_ik_lm.py", "codegen/_ik_elbow.py", "codegen/_ik_finish.py", "codegen/_ik_parallel.py", "codegen/_ik_stanford.py", "codegen/_llvm.py", "codegen/_kernels.py", "codegen/_trace.py",
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


def load_module(key: str, tag: str, make_source):
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
