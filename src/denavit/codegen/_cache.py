"""The kernel cache: its keys, and loading a generated module from it — verified, and rebuilt when corrupt.

A generated module ``_denavit_kernels_<backend>_<key>.py`` starts with a line naming its key and the SHA-256
of the rest; its bytecode ``.pyc`` is a checked-hash pyc (PEP 552: the source's hash is in the header).  Both
are read without following symlinks and checked before anything runs; numba's files about the module
(``__pycache__/<module>.<function>-<line>.py311.nbi/.nbc``, its index a pickle) are read only from the
trusted folder (:mod:`._cache_folder`).  An entry that fails a check or fails to load is deleted and built
again, with one warning line: a truncated file (a full disk, Ctrl-C) never breaks an arm for good.
"""

from __future__ import annotations

import builtins
import hashlib
import importlib.util
import marshal
import os
import stat
import sys
import tempfile
import threading
import types
import warnings
from pathlib import Path

from ..errors import DenavitWarning
from ..model import DHRobot
from . import _cache_folder as _folder
from ._lean import lean_kernels
from ._cache_folder import (
    CACHE_ENV,
    MODULE_PREFIX,
    cache_dir,
    choose_folder,
    ours,
    remove_entry,
)

__all__ = [
    "CACHE_ENV",
    "GENERATOR_VERSION",
    "active_cache_dir",
    "cache_dir",
    "cache_info",
    "clear_cache",
    "guard_cache",
    "load_module",
    "numba_available",
    "robot_key",
    "generator_sources",
]

_LOCK = threading.Lock()
_LOADED: dict[str, object] = {}  # module name → module, per process
_NOFOLLOW = getattr(os, "O_NOFOLLOW", 0) | getattr(os, "O_NONBLOCK", 0)  # a FIFO must not block the read


def numba_available() -> bool:
    """True when numba imports (the ``fast`` extra)."""
    return importlib.util.find_spec("numba") is not None


def active_cache_dir() -> Path:
    """The folder the kernels are kept in now: :func:`cache_dir` when only the current user can write it (and
    it can be written), else a private per-user one (see :mod:`denavit.codegen._cache_folder`)."""
    return choose_folder().folder


#: Part of every cache key, with a digest of the sources that shape the generated code: every module of the
#: generator (codegen/), the chain walker (chain/) and the numeric kernels the tracer runs (numeric/: the RNEA,
#: the dual numbers, the kinematic derivatives, the regressor, ...).  All of them, not a hand-kept list: a list
#: missed the modules new kernel groups trace through, and an upgrade that changed one would have read a stale
#: module.  A changed generator never reads a stale module.
GENERATOR_VERSION = "2"  # 2: verified modules (key and hash line, checked-hash .pyc)
_SOURCE_PACKAGES = ("codegen", "chain", "numeric", "ik")  # ik: the closed forms the IK kernels call
_DIGEST: list[str] = []


def generator_sources() -> list[str]:
    """The package files (paths relative to the package) whose text is part of every cache key."""
    root = Path(__file__).resolve().parent.parent
    return sorted(p.relative_to(root).as_posix() for pkg in _SOURCE_PACKAGES for p in (root / pkg).glob("*.py"))


def _generator_digest() -> str:
    if not _DIGEST:
        root = Path(__file__).resolve().parent.parent
        h = hashlib.sha256(GENERATOR_VERSION.encode())
        for rel in generator_sources():
            h.update(rel.encode() + b"\0" + (root / rel).read_bytes())
        _DIGEST.append(h.hexdigest()[:16])
    return _DIGEST[0]


def robot_key(robot: DHRobot, backend: str, friction: bool, kernels, salt: str = "") -> str:
    """A digest of everything the kernels depend on: the DH rows, base, tool, gravity, inertial data, the
    backend and options (exact float bits), and the generator's version; ``salt`` adds what else shapes them (a
    kernel group's name and the digest of the files tracing it).  Names and presentation are left out."""
    def h(x) -> str:
        return float(x).hex()

    parts = [_generator_digest(), backend, str(bool(friction)), ",".join(kernels), robot.convention.value]
    if salt:
        parts.append(salt)
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


class _Damaged(Exception):
    """A cache entry that is not what the cache wrote (the message says how)."""


def load_module(key: str, tag: str, make_source):
    """The generated module for ``key``: from the cache when its entry is intact, else written (atomically) from
    ``make_source()``.  A damaged entry is deleted and rebuilt, with one :class:`DenavitWarning`."""
    modname = f"{MODULE_PREFIX}{tag}_{key}"
    with _LOCK:
        mod = _LOADED.get(modname)
        if mod is not None:
            return mod
        choice = choose_folder()
        if choice.unsafe:
            warnings.warn(DenavitWarning(f"kernel cache {cache_dir()} not used: {choice.reason} (files there run as "
                                         f"your code); using {choice.folder}"), stacklevel=3)
        folder = choice.folder
        path, pyc = folder / f"{modname}.py", folder / f"{modname}.pyc"
        numba = tag == "numba"
        if numba:
            _numba_folder(folder)
        source = _entry(path, lambda data: _check_source(data, key), modname)
        if source is None:
            source = _stamped(key, make_source())
            _write(path, source)
            remove_entry(pyc)  # a leftover of another source (its .py deleted by hand): stale, not damage
        code = _entry(pyc, lambda data: _check_code(data, source, path), modname)
        if code is None:
            code = builtins.compile(source, str(path), "exec", dont_inherit=True)
            _write(pyc, _pyc(source, code))
        mod = _execute(modname, path, code)
        if numba:
            _guard_numba(mod)
            lean_kernels(mod)  # the kernels' compiles run LLVM's -O3 once (see _lean)
        _LOADED[modname] = mod
        return mod


def _entry(path: Path, check, modname: str):
    """``check(bytes)`` of the file at ``path``; None when it is absent, or damaged (then deleted, with a note;
    a damaged module takes its bytecode and numba's files with it)."""
    try:
        data = _read(path)
        return None if data is None else check(data)
    except _Damaged as exc:
        victims = [path]
        pycache = path.parent / "__pycache__"
        if path.suffix == ".py":
            victims.append(path.with_suffix(".pyc"))
            if pycache.is_dir() and not pycache.is_symlink():  # never into a folder elsewhere
                victims += sorted(pycache.glob(f"{modname}.*"))
        for victim in victims:
            remove_entry(victim)
        _note(f"{path} was damaged ({exc}): deleted, built again")
        return None


def _note(message: str) -> None:
    warnings.warn(DenavitWarning("kernel cache: " + " ".join(message.split())[:400]), stacklevel=4)


def _read(path: Path) -> bytes | None:
    """The bytes of the regular file at ``path``, owned by the current user; None when absent.  A symlink is not
    followed (it is damage, as a folder, a FIFO or another user's file is)."""
    try:
        fd = os.open(path, os.O_RDONLY | _NOFOLLOW)
    except FileNotFoundError:
        return None
    except OSError as exc:  # ELOOP: a symlink; ENXIO: a socket
        raise _Damaged(f"not a regular file: {exc.strerror}") from None
    st = os.fstat(fd)
    if not stat.S_ISREG(st.st_mode) or st.st_uid != _folder.current_uid():
        os.close(fd)
        raise _Damaged("not a regular file" if not stat.S_ISREG(st.st_mode) else
                       f"owned by another user (uid {st.st_uid})")
    with os.fdopen(fd, "rb") as fh:
        return fh.read()


def _header(key: str, body: bytes) -> bytes:
    return f"# denavit kernels {key} sha256 {hashlib.sha256(body).hexdigest()}\n".encode()


def _stamped(key: str, text: str) -> bytes:
    """The module's file: a first line naming the key and the SHA-256 of the rest, then the source."""
    body = text.encode("utf-8")
    return _header(key, body) + body


def _check_source(data: bytes, key: str) -> bytes:
    head, newline, body = data.partition(b"\n")
    if not newline or head + newline != _header(key, body):
        raise _Damaged("its content does not match the key and hash on its first line")
    return data


_PYC_FLAGS = (0b11).to_bytes(4, "little")  # PEP 552: hash-based, checked


def _pyc(source: bytes, code: types.CodeType) -> bytes:
    """A checked-hash pyc (PEP 552): magic, flags, the source's hash (``importlib.util.source_hash``), code."""
    return importlib.util.MAGIC_NUMBER + _PYC_FLAGS + importlib.util.source_hash(source) + marshal.dumps(code)


def _check_code(data: bytes, source: bytes, path: Path):
    """The code object of a pyc made by :func:`_pyc` from ``source``; None when it was made for the same source
    at another path (a moved folder: compiled again quietly, numba locates its files by that path)."""
    if data[:8] != importlib.util.MAGIC_NUMBER + _PYC_FLAGS or data[8:16] != importlib.util.source_hash(source):
        raise _Damaged("not the bytecode of its source")
    try:
        code = marshal.loads(data[16:])
    except (EOFError, ValueError, TypeError) as exc:
        raise _Damaged(f"unreadable bytecode: {exc}") from None
    if not isinstance(code, types.CodeType):
        raise _Damaged("not bytecode")
    return code if code.co_filename == str(path) else None


def _write(path: Path, data: bytes) -> None:
    """Write ``data`` to ``path`` atomically (a ``mkstemp`` file renamed over it; removed on any failure)."""
    fd, tmp = tempfile.mkstemp(dir=path.parent, suffix=".tmp")
    try:
        with os.fdopen(fd, "wb") as fh:
            fh.write(data)
        os.replace(tmp, path)
    except BaseException as exc:
        try:
            os.unlink(tmp)
        except OSError:
            pass
        if isinstance(exc, OSError):
            raise OSError(exc.errno, f"cannot write the kernel cache: {exc.strerror}", str(path)) from None
        raise


def _execute(modname: str, path: Path, code: types.CodeType) -> types.ModuleType:
    """Run the verified code object as module ``modname`` (what importlib's loaders do with a pyc); it stays in
    ``sys.modules``, where numba's cached functions find their module again."""
    mod = types.ModuleType(modname)
    mod.__file__ = str(path)
    sys.modules[modname] = mod
    try:
        exec(code, mod.__dict__)  # noqa: S102  # safe: the cache's own generated code, checked against its key and hash above
    except BaseException:
        sys.modules.pop(modname, None)
        raise
    return mod


def _numba_folder(folder: Path) -> None:
    """numba keeps its files about the module in ``folder/__pycache__``: a real folder (0700), else numba would
    look elsewhere; a symlink or file there is damage."""
    pycache = folder / "__pycache__"
    if os.path.lexists(pycache) and not stat.S_ISDIR(os.lstat(pycache).st_mode):
        remove_entry(pycache)
        _note(f"{pycache} was not a folder: deleted")
    if not os.path.lexists(pycache):
        os.mkdir(pycache, 0o700)


class _GuardedCache:
    """numba's disk cache of one jitted function, where a file that fails to load is a miss: the function's files
    are deleted (one note) and numba compiles it again and saves it afresh.  A failed save (a full disk) is a
    note too: the compiled function works, it is just not kept.  Everything else is numba's ``FunctionCache``."""

    def __init__(self, inner) -> None:
        self._inner = inner

    def __getattr__(self, name):
        return getattr(self._inner, name)

    def load_overload(self, sig, target_context):
        try:
            return self._inner.load_overload(sig, target_context)
        except Exception as exc:  # noqa: BLE001 — whatever a truncated or garbage pickle, or a folder, raises
            base = getattr(getattr(self._inner, "_impl", None), "filename_base", None)
            folder = Path(self._inner.cache_path)
            victims = sorted(folder.glob(f"{base}.*")) if base else []
            for victim in victims:
                remove_entry(victim)
            _note(f"numba's files {folder / (base or '?')}.* could not be loaded ({type(exc).__name__}: {exc}): "
                  "deleted, compiled again")
            return None

    def save_overload(self, sig, data):
        try:
            self._inner.save_overload(sig, data)
        except Exception as exc:  # noqa: BLE001 — a full disk, a read-only folder: the kernel still works
            _note(f"could not save a compiled kernel in {self._inner.cache_path} ({exc}); it works, uncached")


def _guard_numba(mod: types.ModuleType) -> None:
    """Put a :class:`_GuardedCache` in front of the disk cache of every jitted function of ``mod``."""
    from numba.core.dispatcher import Dispatcher

    for value in vars(mod).values():
        if isinstance(value, Dispatcher) and hasattr(getattr(value, "_cache", None), "load_overload"):
            value._cache = _GuardedCache(value._cache)


def guard_cache(compiled) -> None:
    """Put a :class:`_GuardedCache` in front of the disk cache of one numba object made later (a ``CFunc``)."""
    if hasattr(getattr(compiled, "_cache", None), "load_overload"):
        compiled._cache = _GuardedCache(compiled._cache)


def _own_entries(folder: Path) -> list[os.DirEntry]:
    """The cache's own entries in ``folder`` and its ``__pycache__`` (other files are never listed)."""
    found = []
    for where in (folder, folder / "__pycache__"):
        try:
            found += [e for e in os.scandir(where) if ours(e.name)]
        except OSError:
            continue
    return found


def _usage(folder: Path) -> tuple[int, int]:
    """(files, bytes) of the cache's own entries in ``folder`` and its ``__pycache__``."""
    files = size = 0
    for entry in _own_entries(folder):
        try:
            st = entry.stat(follow_symlinks=False)
        except OSError:
            continue
        files += 1
        size += st.st_size if stat.S_ISREG(st.st_mode) else 0
    return files, size


def cache_info() -> dict:
    """The folder in use, the one configured (and why it is not used, if so), and the cache's files and bytes."""
    choice = choose_folder()
    files, size = _usage(choice.folder)
    return {"folder": str(choice.folder), "configured": str(cache_dir()), "reason": choice.reason,
            "files": files, "bytes": size}


def clear_cache() -> dict:
    """Delete every cached kernel from the folder in use: generated modules, their bytecode, numba's files about
    them, leftovers.  Other files in the folder are left alone.  Returns :func:`cache_info` of what was removed."""
    with _LOCK:
        info = cache_info()
        for entry in _own_entries(Path(info["folder"])):
            remove_entry(Path(entry.path))
        _LOADED.clear()
    return info
