"""Which folder holds the kernel cache, and whether it can be trusted: its files are imported as code.

A folder is used only when the caller could be the only one to have written it (the rule of OpenSSH's
``StrictModes`` and of CPython's ``__pycache__`` in a private tree): a real folder owned by the current user,
not writable by group or others, inside folders that only the user or root can change (or sticky ones, such
as ``/tmp``).  Otherwise — or when it cannot be written — a per-user private folder in the temporary folder
(mode 0700, reused across processes), and when even that one is not safe, a fresh ``mkdtemp`` folder removed
when the process ends.  Folders are made with mode 0700; writability is probed with ``mkstemp``
(``O_CREAT | O_EXCL``: a planted symlink is never followed).
"""

from __future__ import annotations

import atexit
import os
import shutil
import stat
import tempfile
import time
from pathlib import Path
from typing import NamedTuple

__all__ = ["CACHE_ENV", "MODULE_PREFIX", "cache_dir", "choose_folder", "current_uid", "ours", "remove_entry", "tidy"]

CACHE_ENV = "DENAVIT_CACHE_DIR"
#: Every file the cache holds starts with this (the generated modules and numba's files about them).
MODULE_PREFIX = "_denavit_kernels_"
#: Leftovers of a killed process (a temporary file, a probe) older than this are removed.
STALE_SECONDS = 3600.0
_PRIVATE: list[Path] = []  # this process's mkdtemp fallback, when one was needed


def cache_dir() -> Path:
    """Where generated modules (and numba's compiled code) are meant to be kept: ``$DENAVIT_CACHE_DIR``, else
    ``$XDG_CACHE_HOME/denavit/kernels``, else ``~/.cache/denavit/kernels``.  The folder actually used is
    :func:`active_cache_dir` (this one when it is safe and writable)."""
    env = os.environ.get(CACHE_ENV)
    if env:
        return Path(env)
    base = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    return Path(base) / "denavit" / "kernels"


def current_uid() -> int:
    """The user the cache must belong to (a function, so that tests can play another user).  Windows has no
    uids (``st_uid`` is 0, access is by ACL, profile folders are private): 0 there, and modes are not judged."""
    return os.geteuid() if _POSIX else 0


_POSIX = hasattr(os, "geteuid")


class Choice(NamedTuple):
    folder: Path  #: the folder used
    reason: str  #: why the configured folder was not used ("" when it was)
    unsafe: bool  #: True when the reason is that another user could have written it


def _untrusted(folder: Path, private: bool = False) -> str:
    """Why ``folder`` (an absolute path, not followed if a symlink) could hold another user's files, or ""."""
    st = os.lstat(folder)
    if not stat.S_ISDIR(st.st_mode):
        return "not a folder (a symlink or a file)"
    if not _POSIX:
        return ""
    if st.st_uid != current_uid():
        return f"owned by another user (uid {st.st_uid})"
    if st.st_mode & (0o077 if private else 0o022):
        return f"open to other users (mode {stat.S_IMODE(st.st_mode):o})"
    for parent in folder.parents:
        st = os.stat(parent)
        if st.st_uid not in (current_uid(), 0):
            return f"inside {parent}, owned by another user (uid {st.st_uid})"
        if st.st_mode & 0o022 and not st.st_mode & stat.S_ISVTX:
            return f"inside {parent}, which other users can change (mode {stat.S_IMODE(st.st_mode):o})"
    pycache = folder / "__pycache__"  # numba's files (a symlink or a file there is the loader's to remove)
    if os.path.lexists(pycache):
        st = os.lstat(pycache)
        if stat.S_ISDIR(st.st_mode) and (st.st_uid != current_uid() or st.st_mode & 0o022):
            return f"its {pycache.name} is open to other users"
    return ""


def _make_dirs(path: Path) -> None:
    """Make ``path`` and its missing parents, each with mode 0700."""
    for p in [*reversed(path.parents), path]:
        if not os.path.isdir(p):
            try:
                os.mkdir(p, 0o700)
            except FileExistsError:
                pass


def _probe(folder: Path) -> None:
    """Raise OSError unless a file can be made in ``folder`` (``mkstemp``: O_EXCL, a symlink is never followed)."""
    fd, name = tempfile.mkstemp(dir=folder, prefix=".probe-", suffix=".tmp")
    os.close(fd)
    os.unlink(name)


def choose_folder() -> Choice:
    """The folder to use now (made if absent), and why the configured one was not used."""
    wanted = cache_dir()
    try:
        _make_dirs(wanted)
        real = Path(os.path.realpath(wanted))
        reason = _untrusted(real)
        if not reason:
            _probe(real)
            tidy(real)
            return Choice(real, "", False)
        unsafe = True
    except OSError as exc:
        reason, unsafe = f"not writable ({exc.strerror or exc})", False
    return Choice(_fallback(), reason, unsafe)


def _fallback() -> Path:
    """``$TMPDIR/denavit-kernels-<uid>`` (0700, reused) when it is safe; else a fresh private folder."""
    shared = Path(tempfile.gettempdir()) / f"denavit-kernels-{current_uid()}"
    try:
        try:
            os.mkdir(shared, 0o700)
        except FileExistsError:
            pass
        if not _untrusted(shared, private=True):
            _probe(shared)
            tidy(shared)
            return shared
    except OSError:
        pass
    if not _PRIVATE:
        _sweep_private()
        folder = Path(tempfile.mkdtemp(prefix=f"denavit-kernels-{current_uid()}-{os.getpid()}-"))
        _PRIVATE.append(folder)
        atexit.register(shutil.rmtree, folder, True)
    return _PRIVATE[0]


def _sweep_private() -> None:
    """Remove the fresh private folders of this user's processes that ended without their exit handler."""
    prefix = f"denavit-kernels-{current_uid()}-"
    try:
        entries = list(os.scandir(tempfile.gettempdir()))
    except OSError:
        return
    for entry in entries:
        if not entry.name.startswith(prefix):
            continue
        pid = entry.name[len(prefix):].split("-")[0]
        try:
            st = entry.stat(follow_symlinks=False)
            if not pid.isdigit() or not stat.S_ISDIR(st.st_mode) or st.st_uid != current_uid():
                continue
            os.kill(int(pid), 0)
        except ProcessLookupError:
            shutil.rmtree(entry.path, ignore_errors=True)
        except OSError:
            continue


def ours(name: str) -> bool:
    """True for names the cache itself makes: generated modules, numba's files about them, temporary files."""
    return name.startswith((MODULE_PREFIX, ".probe-")) or (name.startswith("tmp") and name.endswith(".tmp"))


def tidy(folder: Path) -> None:
    """Remove temporary files left by killed processes (older than an hour) from ``folder`` and numba's part."""
    now = time.time()
    for where in (folder, folder / "__pycache__"):
        try:
            entries = list(os.scandir(where))
        except OSError:
            continue
        for entry in entries:
            name = entry.name
            leftover = name.startswith(".probe-") or (name.startswith("tmp") and name.endswith(".tmp")) or (
                name.startswith(MODULE_PREFIX) and ".tmp." in name)  # numba's own temporary files
            try:
                if leftover and now - entry.stat(follow_symlinks=False).st_mtime > STALE_SECONDS:
                    remove_entry(Path(entry.path))
            except OSError:
                continue


def remove_entry(path: Path) -> None:
    """Delete a file, a symlink (not its target) or a folder at ``path``; absent is fine."""
    try:
        st = os.lstat(path)
    except FileNotFoundError:
        return
    if stat.S_ISDIR(st.st_mode):
        shutil.rmtree(path)
    else:
        os.unlink(path)
