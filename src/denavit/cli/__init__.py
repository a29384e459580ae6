"""The ``denavit`` command line: parse → load the robot → one library call → format.

Each group of subcommands lives in its own module with a ``register(subparsers)`` function; the
handler it sets returns ``(json_data, text)``.  Every command takes ``--json``.  Errors print one
line on stderr: exit code 2 for bad input, 1 for failures.
"""

from __future__ import annotations

import argparse
import importlib
import os
import signal
import sys
import warnings
from typing import Sequence

import numpy as np

from ..errors import DenavitError, MissingDependencyError, ModelError, ParseError, ShapeError, Terminated
from ._common import OneLineParser, emit, one_line

__all__ = ["main", "build_parser"]

# Modules that add subcommands, in the order they appear in --help.
COMMAND_MODULES = ("_model", "_report", "_viz", "_scale", "_ik", "_jacobian", "_singularities", "_dynamics", "_regressor", "_interop", "_codegen", "_calibrate", "_excite", "_identify", "_serve")


def build_parser() -> argparse.ArgumentParser:
    parser = OneLineParser(
        prog="denavit",
        description="Serial robot arms from their DH table: kinematics, Jacobians, IK, dynamics, pictures, reports.",
        epilog="ROBOT is a built-in name (see 'denavit robots') or a robot file (.yaml/.toml/.json).",
    )
    parser.add_argument("--version", action="version", version=f"denavit {_version()}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=OneLineParser)
    for name in COMMAND_MODULES:
        importlib.import_module(f"{__name__}.{name}").register(sub)
    return parser


_PARSER: list[argparse.ArgumentParser] = []


def _parser() -> argparse.ArgumentParser:
    """The parser, built once per process: building it (every subcommand's options, argparse's gettext look-ups)
    costs ~15 ms, more than most commands; parsing leaves it unchanged, so a process that calls :func:`main`
    many times (the workbench, a notebook, the test suite) reuses it."""
    if not _PARSER:
        _PARSER.append(build_parser())
    return _PARSER[0]


def _version() -> str:
    from .. import __version__

    return __version__


def main(argv: Sequence[str] | None = None) -> int:
    """Run the command line; returns the exit code."""
    parser = _parser()
    try:
        args = parser.parse_args(argv)
    except SystemExit as exc:  # argparse: --help (0) or a usage error (2), already printed
        return int(exc.code or 0)
    if not getattr(args, "command", None):
        parser.print_help()
        return 0
    shown: list[str] = []
    try:
        with warnings.catch_warnings(record=True) as caught, np.errstate(all="ignore"):
            warnings.simplefilter("always")
            try:
                data, text = args.handler(args)
            finally:
                shown = _warning_lines(args.command, caught)
            emit(args, data, text)
        for line in shown:
            print(line, file=sys.stderr)
        return 0
    except (ParseError, ShapeError, ModelError) as exc:
        return _fail(args.command, one_line(exc), 2)
    except MissingDependencyError as exc:
        return _fail(args.command, one_line(exc), 1)
    except DenavitError as exc:
        return _fail(args.command, one_line(exc), 1)
    except Terminated:  # SIGTERM during a local cluster, caught outside the block that exits 143 itself
        return 128 + signal.SIGTERM
    except KeyboardInterrupt:
        print("denavit: interrupted", file=sys.stderr)
        return 130
    except BrokenPipeError:
        return 0
    except MemoryError:
        return _fail(args.command, "out of memory (the input asks for more work than this machine can hold)", 1)
    except OSError as exc:  # a file the user named: unreadable, a directory, a name too long, a full disk ...
        where = f"{exc.filename!r}" if exc.filename is not None else ""
        if where and exc.filename2 is not None:  # a rename or link: both names
            where += f" -> {exc.filename2!r}"
        what = (f"{where}: " if where else "") + f"{exc.strerror or exc}"
        return _fail(args.command, one_line(what), 2)
    except Exception as exc:  # a bug of ours: one line, the traceback only on request
        if os.environ.get("DENAVIT_DEBUG"):
            raise
        print(f"denavit {args.command}: internal error: {type(exc).__name__}: {one_line(exc)} "
              "(set DENAVIT_DEBUG=1 for the traceback, and please report it)", file=sys.stderr)
        return 1


def _fail(command: str, message: str, code: int) -> int:
    """The one error line; warnings collected during the failed run are not shown (one line per error)."""
    print(f"denavit {command}: error: {message}", file=sys.stderr)
    return code


def _warning_lines(command: str, caught) -> list[str]:
    """Library warnings as one line each, ``denavit CMD: warning: message`` (duplicates once).

    Shown: :class:`denavit.errors.DenavitWarning` (when defined) and UserWarnings raised from denavit's own code;
    numpy/scipy RuntimeWarnings and third-party noise are dropped (results are checked for finiteness instead).
    """
    from .. import errors

    ours = getattr(errors, "DenavitWarning", None)
    lines: list[str] = []
    for w in caught:
        mine = ours is not None and issubclass(w.category, ours)
        if not mine and issubclass(w.category, UserWarning) and not issubclass(w.category, RuntimeWarning):
            mine = f"{os.sep}denavit{os.sep}" in str(w.filename)
        line = f"denavit {command}: warning: {one_line(w.message)}"
        if mine and line not in lines:
            lines.append(line)
    return lines
