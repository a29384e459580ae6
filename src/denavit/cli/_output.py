"""The command line's output files: checked before the work, written beside the target and moved into place.

``-o FILE`` replaces FILE, as matplotlib's ``savefig``, pandoc and compilers do, but only once the whole work
succeeded: every output is written to a temporary file in the target's folder, flushed to disk (``fsync``) and
then moved over the target with ``os.replace`` (atomic on POSIX and Windows within one file system).  A failure
before that point (a bad input found late, a full disk, Ctrl-C) removes the temporary files and leaves every
existing file as it was.  Refused, before any work, with one line: an empty path, a folder, FIFO, device or
symlink, a file that is one of the command's inputs (same path after resolving symlinks, or same inode), and,
with ``--no-clobber``, any existing file.
"""

from __future__ import annotations

import argparse
import contextlib
import os
from collections.abc import Sequence

from ..errors import ParseError

__all__ = ["INPUT_ARGUMENTS", "add_no_clobber", "check_output", "output_file", "output_files"]

#: Arguments that name an input file of some command (ROBOT, import-urdf's URDF, import-table's FILE, check's
#: CLAIMS_FILE): an output naming the same file is refused, so an input is never overwritten.
INPUT_ARGUMENTS = ("robot", "urdf", "file", "claims")


def add_no_clobber(p: argparse.ArgumentParser) -> None:
    """``--no-clobber``: refuse an existing output file (by default -o replaces it).

    ``--force`` (which, before -o replaced files, allowed the replacing) is still accepted and does nothing, so
    scripts written for the old behaviour keep working; it is no longer shown in --help.
    """
    p.add_argument("--no-clobber", action="store_true",
                   help="refuse to replace an existing output file (by default it is replaced once the work "
                        "succeeded)")
    p.add_argument("--force", action="store_true", help=argparse.SUPPRESS)


def _input_of(args: argparse.Namespace, path: str) -> str | None:
    """The input argument naming the same file as the existing ``path`` (same inode or same real path), if any."""
    out = os.stat(path)
    for name in INPUT_ARGUMENTS:
        src = getattr(args, name, None)
        if not isinstance(src, str) or not src or not os.path.exists(src):
            continue
        st = os.stat(src)
        if (st.st_dev, st.st_ino) == (out.st_dev, out.st_ino) or os.path.realpath(src) == os.path.realpath(path):
            return src
    return None


def check_output(args: argparse.Namespace, path: str | None, suffixes: Sequence[str], what: str = "-o",
                 kind: str = "file type") -> None:
    """Refuse a bad output path *before* any work is done (ParseError → exit 2, one line naming the path).

    Checks, in order: the path is not empty; the suffix is one of ``suffixes`` (lower-case, with the dot); the
    folder exists and is a folder; the name is not over the file system's limit; an existing path is a regular
    file (never a folder, FIFO, device or symlink), is none of the command's input files
    (:data:`INPUT_ARGUMENTS`), and is only refused for existing with ``--no-clobber``.
    """
    if path is None:
        return
    if not path.strip():
        raise ParseError(f"{what} {path!r}: empty path; name the file to write")
    name = os.path.basename(path)
    suffix = os.path.splitext(name)[1].lower()
    if suffixes and suffix not in suffixes:
        raise ParseError(f"{what} {path!r}: unsupported {kind} {suffix or '(none)'!r}; expected one of "
                         + ", ".join(suffixes))
    folder = os.path.dirname(path) or "."
    if not os.path.isdir(folder):
        raise ParseError(f"{what} {path!r}: folder {folder!r} does not exist")
    if len(name.encode("utf-8", "surrogateescape")) > 255:
        raise ParseError(f"{what} {path!r}: file name longer than 255 bytes")
    if os.path.lexists(path):
        if not os.path.isfile(path) or os.path.islink(path):
            raise ParseError(f"{what} {path!r}: exists and is not a regular file; not writing there")
        src = _input_of(args, path)
        if src is not None:
            raise ParseError(f"{what} {path!r} is the input file {src!r}; an input is never overwritten "
                             "(choose another output name)")
        if getattr(args, "no_clobber", False):
            raise ParseError(f"{what} {path!r} exists; not replacing it (--no-clobber)")


def _temp_beside(path: str) -> str:
    """A new empty file in ``path``'s folder, with the permissions ``path`` has (or a plain ``open`` would give)."""
    import stat
    import tempfile

    folder = os.path.dirname(path) or "."
    fd, tmp = tempfile.mkstemp(prefix=".denavit-", suffix=os.path.splitext(path)[1], dir=folder)
    os.close(fd)
    try:
        mode = stat.S_IMODE(os.stat(path).st_mode)  # a replaced file keeps its permissions
    except OSError:
        umask = os.umask(0)
        os.umask(umask)
        mode = 0o666 & ~umask  # as a plain open() would have made it (mkstemp gives 0600)
    os.chmod(tmp, mode)
    return tmp


def _sync(path: str, folder: bool = False) -> None:
    """Flush a file (or a folder's entries, where the platform allows it) to the disk."""
    flags = os.O_RDONLY | (getattr(os, "O_DIRECTORY", 0) if folder else 0)
    try:
        fd = os.open(path, flags)
    except OSError:
        if folder:  # Windows opens no folder: its rename is already durable enough
            return
        raise
    try:
        os.fsync(fd)
    except OSError:
        if not folder:
            raise
    finally:
        os.close(fd)


def _failed(what: str, paths: Sequence[str], tmps: Sequence[str], exc: OSError, stage: str,
            kept: str = "nothing was replaced") -> ParseError:
    """One line naming the output(s) the OS error is about (never the hidden temporary name)."""
    named = [p for p, t in zip(paths, tmps) if exc.filename in (p, t) or exc.filename2 in (p, t)]
    named = named or list(paths)
    where = " and ".join(repr(p) for p in named[:3]) + (" ..." if len(named) > 3 else "")
    return ParseError(f"{what} {where}: {stage} failed ({exc.strerror or exc}); {kept}")


@contextlib.contextmanager
def output_files(paths: Sequence[str], what: str = "-o"):
    """Yield temporary paths beside ``paths``; when the block succeeds they replace ``paths``.

    Each temporary file is flushed to the disk before any is moved into place (``os.replace``), so the outputs
    change together and only after all were written: an exception in the block (a bad input found late, a
    full disk) removes the temporary files and leaves every existing file as it was. OS errors become one
    ParseError line naming the output (exit 2).
    """
    paths = [str(p) for p in paths]
    tmps: list[str] = []
    try:
        try:
            for path in paths:
                tmps.append(_temp_beside(path))
        except OSError as exc:
            raise _failed(what, paths[len(tmps):len(tmps) + 1], [""], exc, "creating a file there") from None
        try:
            yield list(tmps)
            for tmp in tmps:
                _sync(tmp)
        except OSError as exc:
            raise _failed(what, paths, tmps, exc, "writing") from None
        done: list[str] = []
        try:
            for k, (tmp, path) in enumerate(zip(tmps, paths)):
                os.replace(tmp, path)
                tmps[k] = ""
                done.append(path)
        except OSError as exc:
            kept = "replaced before it: " + ", ".join(map(repr, done)) if done else "nothing was replaced"
            raise _failed(what, paths, tmps, exc, "moving the written file into place", kept) from None
        for folder in {os.path.dirname(p) or "." for p in paths}:
            _sync(folder, folder=True)
    finally:
        for tmp in tmps:
            if tmp and os.path.lexists(tmp):
                os.unlink(tmp)


@contextlib.contextmanager
def output_file(path: str, what: str = "-o"):
    """Yield a temporary path beside ``path``; when the block succeeds it replaces ``path`` atomically.

    :func:`output_files` for one file.
    """
    with output_files([path], what) as (tmp,):
        yield tmp

