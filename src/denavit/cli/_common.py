"""Shared pieces of the command line: the one-line-error parser, common arguments, output."""

from __future__ import annotations

import argparse
import contextlib
import json
import re
import sys
from typing import Any, Sequence

import numpy as np

from ..errors import ParseError

__all__ = ["OneLineParser", "add_common", "finite_float", "nonneg_int", "one_line", "positive_float", "add_force", "add_q", "emit", "load", "joint_values", "refuse_overwrite", "check_output", "output_file",
           "stage_printer", "to_json", "matrix_text"]


class OneLineParser(argparse.ArgumentParser):
    """argparse, but a usage error is one line on stderr and exit code 2.

    A value that starts with a minus sign is a value, not an option, when it is a number or a list or
    expression (``-q -0.5,1``, ``--qd -pi/2,0``); argparse alone only accepts a lone negative number.
    """

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        self._negative_number_matcher = re.compile(r"^-\.?\d|^-[^-].*[,*/()]")

    def error(self, message: str) -> None:  # type: ignore[override]
        print(f"{self.prog}: error: {one_line(message)} (see '{self.prog} --help')", file=sys.stderr)
        raise SystemExit(2)


MAX_MESSAGE = 300


def one_line(message: str, limit: int = MAX_MESSAGE) -> str:
    """An error message as one line of at most about ``limit`` characters (long user text is cut in the middle)."""
    text = " ".join(str(message).split())
    if len(text) > limit:
        text = text[: limit * 2 // 3] + " ... " + text[-(limit // 3):]
    return text


def nonneg_int(text: str) -> int:
    """argparse type: an integer >= 0 (random seeds, counts)."""
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a whole number >= 0, got {text!r}") from None
    if value < 0:
        raise argparse.ArgumentTypeError(f"expected a whole number >= 0, got {value}")
    return value


def finite_float(text: str) -> float:
    """argparse type: a finite number (no nan, inf or overflow such as 1e999)."""
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a number, got {text!r}") from None
    if not np.isfinite(value):
        raise argparse.ArgumentTypeError(f"expected a finite number, got {text!r}")
    return value


def positive_float(text: str) -> float:
    """argparse type: a finite number > 0 (tolerances, durations)."""
    value = finite_float(text)
    if value <= 0:
        raise argparse.ArgumentTypeError(f"expected a number > 0, got {text!r}")
    return value


def add_common(p: argparse.ArgumentParser, robot: bool = True) -> None:
    """ROBOT, --json and --deg."""
    if robot:
        p.add_argument("robot", metavar="ROBOT", help="built-in name or robot file")
    p.add_argument("--json", action="store_true", help="machine-readable JSON on stdout")
    p.add_argument("--deg", action="store_true", help="angles in and out in degrees (radians otherwise)")
    p.add_argument(
        "--param", action="append", default=[], metavar="NAME=VALUE", help="override a robot parameter (repeatable)"
    )


def add_q(p: argparse.ArgumentParser, required: bool = True) -> None:
    """-q/--q: a joint vector."""
    p.add_argument(
        "-q", "--q", dest="q", required=required, metavar="Q",
        help='joint values: comma-separated numbers or expressions, e.g. "0, pi/4, 90deg"',
    )
    p.add_argument("--ignore-limits", action="store_true", help="compute even if q is outside the joint limits")


def add_force(p: argparse.ArgumentParser) -> None:
    """--force: allow -o/--output to replace an existing file."""
    p.add_argument("--force", action="store_true", help="overwrite the output file if it exists")


def refuse_overwrite(args: argparse.Namespace, path: str | None) -> None:
    """ParseError if ``path`` exists and --force was not given (nothing the user has is replaced silently)."""
    import os

    if path and os.path.lexists(path) and not getattr(args, "force", False):
        raise ParseError(f"{path!r} exists; not overwriting it (choose another name or pass --force)")


def check_output(args: argparse.Namespace, path: str | None, suffixes: Sequence[str], what: str = "-o") -> None:
    """Refuse a bad output path *before* any work is done (ParseError → exit 2, one line naming the path).

    Checks, in order: the suffix is one of ``suffixes`` (lower-case, with the dot); the folder exists and is a
    folder; the name is not over the file system's limit; an existing path is a regular file (never a folder,
    FIFO or device, even with --force) and is only replaced with --force.
    """
    import os

    if not path:
        return
    name = os.path.basename(path)
    suffix = os.path.splitext(name)[1].lower()
    if suffixes and suffix not in suffixes:
        raise ParseError(f"{what} {path!r}: unsupported file type {suffix or '(none)'!r}; expected one of "
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


def stage_printer(args: argparse.Namespace, command: str):
    """A progress callback printing ``denavit COMMAND: <stage>`` on stderr, or None with --json (quiet)."""
    if getattr(args, "json", False):
        return None

    def show(stage: str) -> None:
        print(f"denavit {command}: {stage}", file=sys.stderr, flush=True)

    return show


def load(args: argparse.Namespace):
    """The robot named on the command line, with --param overrides."""
    from .. import _expr
    from ..io import load_robot

    overrides: dict[str, float] = {}
    for item in args.param:
        if "=" not in item:
            raise ParseError(f"--param {item!r}: expected NAME=VALUE")
        k, v = item.split("=", 1)
        try:
            overrides[k.strip()] = _expr.evaluate(_expr.parse(v))
        except ParseError as exc:
            raise ParseError(f"--param {k.strip()}: {exc}") from None
    return load_robot(args.robot, **overrides)


def joint_values(args: argparse.Namespace, robot, text: str | None, what: str = "q", check_limits: bool = True,
                 rates: bool = False) -> np.ndarray:
    """Parse a joint vector from the command line (degrees with --deg for revolute joints)."""
    from ..io import parse_values
    from ..model import JointType

    if text is None:
        raise ParseError(f"{what}: missing (give {robot.dof} values)")
    vals = parse_values(text, robot.dof, what=what)
    if args.deg:
        revolute = np.array([t is JointType.REVOLUTE for t in robot.joint_types])
        vals = np.where(revolute, np.radians(vals), vals)
    if check_limits and not rates and not getattr(args, "ignore_limits", False):
        lim = robot.q_limits
        for k in range(robot.dof):
            if not (lim[k, 0] - 1e-12 <= vals[k] <= lim[k, 1] + 1e-12):
                lo, hi, v = lim[k, 0], lim[k, 1], vals[k]
                unit = "m"
                if robot.joint_types[k] is JointType.REVOLUTE:
                    unit = "rad"
                    if args.deg:
                        lo, hi, v, unit = np.degrees(lo), np.degrees(hi), np.degrees(v), "deg"
                raise ParseError(
                    f"{what}: joint {k + 1} = {v:.6g} {unit} is outside its limits [{lo:.6g}, {hi:.6g}] "
                    f"(use --ignore-limits to compute anyway)"
                )
    return vals


def to_json(x: Any) -> Any:
    """Arrays → nested lists, sympy → strings, recursively; NaN and ±inf → ``null`` (strict JSON, RFC 8259)."""
    if isinstance(x, np.ndarray):
        return to_json(x.tolist()) if x.dtype.kind in "fcO" else x.tolist()
    if isinstance(x, (np.floating, np.integer)):
        x = x.item()
    if isinstance(x, float):
        return x if np.isfinite(x) else None
    if isinstance(x, dict):
        return {str(k): to_json(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [to_json(v) for v in x]
    if hasattr(x, "free_symbols"):  # sympy object
        if hasattr(x, "tolist"):
            return [[str(e) for e in row] for row in x.tolist()]
        return str(x)
    return x


def matrix_text(M: np.ndarray, digits: int = 6, indent: str = "  ") -> str:
    """A numeric matrix as aligned text."""
    M = np.atleast_2d(np.asarray(M, dtype=float))
    M = np.where(np.abs(M) < 0.5 * 10.0 ** (-digits), 0.0, M)
    cells = [[f"{v:.{digits}f}".rstrip("0").rstrip(".") if v != 0 else "0" for v in row] for row in M]
    width = max(len(c) for row in cells for c in row)
    return "\n".join(indent + "[ " + "  ".join(c.rjust(width) for c in row) + " ]" for row in cells)


def emit(args: argparse.Namespace, data: Any, text: str) -> None:
    if getattr(args, "json", False):
        json.dump(to_json(data), sys.stdout, indent=2, allow_nan=False)
        sys.stdout.write("\n")
    elif text:
        sys.stdout.write(text if text.endswith("\n") else text + "\n")
