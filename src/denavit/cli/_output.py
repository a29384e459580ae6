"""The command line's output files: checked before the work, written beside the target and moved into place."""

from __future__ import annotations

import argparse
import contextlib
from typing import Sequence

from ..errors import ParseError

__all__ = ["add_force", "refuse_overwrite", "check_output", "output_file"]


def add_force(p: argparse.ArgumentParser) -> None:
    """--force: allow -o/--output to replace an existing file."""
    p.add_argument("--force", action="store_true", help="overwrite the output file if it exists")


def refuse_overwrite(args: argparse.Namespace, path: str | None) -> None:
    """ParseError if ``path`` exists and --force was not given (nothing the user has is replaced silently)."""
    import os

    if path and os.path.lexists(path) and not getattr(args, "force", False):
        raise ParseError(f"{path!r} exists; not overwriting it (choose another name or pass --force)")


def check_output(args: argparse.Namespace, path: str | None, suffixes: Sequence[str], what: str = "-o",
                 kind: str = "file type") -> None:
    """Refuse a bad output path *before* any work is done (ParseError → exit 2, one line naming the path).

    Checks, in order: the suffix is one of ``suffixes`` (lower-case, with the dot); the folder exists and is a
    folder; the name is not over the file system's limit; an existing path is a regular file (never a folder,
    FIFO or device, even with --force) and is only replaced with --force.
    """
    import os

    if path is None:
        return
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
        refuse_overwrite(args, path)


@contextlib.contextmanager
def output_file(path: str, what: str = "-o"):
    """Yield a temporary path beside ``path``; on success it replaces ``path`` atomically.

    Nothing the user has is touched until the whole output was written: a failure (full disk, an error while
    rendering) removes the temporary file and leaves ``path`` as it was. OS errors become one ParseError line
    naming the path (exit 2).
    """
    import os
    import tempfile

    folder = os.path.dirname(path) or "."
    suffix = os.path.splitext(path)[1]
    try:
        fd, tmp = tempfile.mkstemp(prefix=".denavit-", suffix=suffix, dir=folder)
        os.close(fd)
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(tmp, 0o666 & ~umask)  # as a plain open() would have made it (mkstemp gives 0600)
    except OSError as exc:
        raise ParseError(f"{what} {path!r}: cannot write there ({exc.strerror or exc})") from None
    try:
        yield tmp
        os.replace(tmp, path)
    except OSError as exc:
        raise ParseError(f"{what} {path!r}: writing failed ({exc.strerror or exc}); nothing was written") from None
    finally:
        if os.path.lexists(tmp):
            os.unlink(tmp)
