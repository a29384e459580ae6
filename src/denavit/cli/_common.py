"""Shared pieces of the command line: the one-line-error parser, common arguments, output."""

from __future__ import annotations

import argparse
import difflib
import json
import re
import sys
import warnings
from typing import Any

import numpy as np

from ..errors import ParseError

__all__ = ["OneLineParser", "add_common", "finite_float", "nonneg_int", "one_line", "positive_float", "add_q", "emit", "load", "joint_values",
           "stage_printer", "to_json", "matrix_text", "number_text", "numbers_text", "bounded_int", "bounded_float",
           "check_values", "require_finite", "require_symbolic_size", "MAX_VALUE", "MAX_SYMBOLIC_JOINTS",
           "MAX_SYMBOLIC_ANALYSIS_JOINTS", "NOISE"]

#: Largest magnitude accepted for a value given on the command line (joint values, rates, wrenches, torques,
#: poses): beyond it products and squares in the algorithms can overflow to inf/nan. Documented in
#: docs/conventions.md, "Limits".
MAX_VALUE = 1e9
#: Joint counts above which the symbolic routes are refused: their expressions grow combinatorially (a general
#: 8-joint chain takes about 40 s through ``jacobian --symbolic``, 12 joints many minutes). ``fk`` and
#: ``jacobian`` symbolic: 8 joints; ``singularities`` (determinant or minors) and ``dynamics --symbolic``: 7
#: (Panda). Numeric routes take every arm a robot file allows.
MAX_SYMBOLIC_JOINTS = 8
MAX_SYMBOLIC_ANALYSIS_JOINTS = 7
#: Printed numbers smaller than this (relative to the largest of their group, or absolutely when all are small)
#: are rounding noise and are shown as 0.
NOISE = 1e-12


class OneLineParser(argparse.ArgumentParser):
    """argparse, but a usage error is one line on stderr and exit code 2.

    A value that starts with a minus sign is a value, not an option, when it is a number or a list or
    expression (``-q -0.5,1``, ``--qd -pi/2,0``); argparse alone only accepts a lone negative number.
    """

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        self._negative_number_matcher = re.compile(r"^-\.?\d|^-[^-].*[,*/()]")

    def _get_values(self, action, arg_strings):  # type: ignore[override]
        # ``--dpi=--``: argparse drops the lone '--' and would hand the option an empty list, unconverted
        if arg_strings == ["--"] and action.nargs in (None, "?") and action.option_strings:
            self.error(f"argument {'/'.join(action.option_strings)}: expected one argument")
        return super()._get_values(action, arg_strings)

    def error(self, message: str) -> None:  # type: ignore[override]
        print(f"{self.prog}: error: {one_line(message)} (see '{self.prog} --help')", file=sys.stderr)
        raise SystemExit(2)

    def _check_value(self, action, value):  # type: ignore[override]
        # a mistyped choice gets the nearest one; a long list (the 26 commands) is left to --help, not cut by
        # one_line in the middle of a name
        if action.choices is not None and value not in action.choices:
            names = [str(c) for c in action.choices]
            near = difflib.get_close_matches(str(value), names, n=1, cutoff=0.6)
            listed = ", ".join(names)
            said = ([f"did you mean {near[0]}?"] if near else []) + ([f"choose from {listed}"] if len(listed) <= 120
                                                                     else [])
            raise argparse.ArgumentError(action, f"invalid choice: {str(value)[:40]!r}"
                                         + (f" ({' '.join(said)})" if said else ""))
        super()._check_value(action, value)

    def parse_args(self, args=None, namespace=None):  # type: ignore[override]
        # an unknown option is reported by the subcommand it was given to, with the nearest option of that one
        # (argparse left it to the top parser: "denavit: error: unrecognized arguments: --frams")
        parsed, extras = self.parse_known_args(args, namespace)
        if extras:
            subs = [a for a in self._actions if isinstance(a, argparse._SubParsersAction)]
            name = getattr(parsed, subs[0].dest, None) if subs else None
            target = subs[0].choices.get(name, self) if name else self
            options = [o for o in target._option_string_actions if o.startswith("--")]
            near = [m for e in extras if e.startswith("-")
                    for m in difflib.get_close_matches(e.split("=")[0], options, n=1, cutoff=0.6)]
            target.error(f"unrecognized arguments: {' '.join(extras)}" + (f" (did you mean {near[0]}?)" if near else ""))
        return parsed


MAX_MESSAGE = 300


def one_line(message: str, limit: int = MAX_MESSAGE) -> str:
    """An error message as one line of at most about ``limit`` characters (long user text is cut in the middle)."""
    # imported here, not at the top: building the parser (and --help) needs no display code
    from ..display import terminal_text

    text = " ".join(terminal_text(str(message)).split())  # user text in a message is shown, not obeyed
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


def bounded_int(lo: int, hi: int):
    """argparse type: a whole number in [lo, hi] (one line and exit 2 otherwise)."""
    def parse(text: str) -> int:
        t = text.strip()
        if not (t.lstrip("+-").isdigit() and len(t) <= 20):
            raise argparse.ArgumentTypeError(f"expected a whole number in [{lo}, {hi}], got {text[:40]!r}")
        value = int(t)
        if not lo <= value <= hi:
            raise argparse.ArgumentTypeError(f"expected a whole number in [{lo}, {hi}], got {value}")
        return value
    return parse


def bounded_float(lo: float, hi: float, *, open_low: bool = False):
    """argparse type: a finite number in [lo, hi] (or (lo, hi] with ``open_low``)."""
    span = f"{'(' if open_low else '['}{lo:g}, {hi:g}]"

    def parse(text: str) -> float:
        value = finite_float(text)
        if not (value > lo if open_low else value >= lo) or value > hi:
            raise argparse.ArgumentTypeError(f"expected a number in {span}, got {text[:40]!r}")
        return value
    return parse


def check_values(values: np.ndarray, what: str, limit: float = MAX_VALUE) -> np.ndarray:
    """ParseError unless every value is finite with magnitude <= ``limit`` (:data:`MAX_VALUE`)."""
    values = np.asarray(values, dtype=float)
    bad = ~(np.abs(values) <= limit)
    if bad.any():
        k = int(np.argmax(bad))
        raise ParseError(f"{what}: value {k + 1} ({values.flat[k]:.6g}) is beyond the magnitude limit {limit:g}")
    return values


def require_finite(what: str, *arrays) -> None:
    """ParseError if a result computed from accepted inputs is not finite (inputs too large for float64)."""
    for a in arrays:
        if a is not None and not np.all(np.isfinite(np.asarray(a, dtype=float))):
            raise ParseError(f"{what}: the result is not finite (inf or nan): the robot's or the given values are "
                             "too large to compute with")


def require_symbolic_size(robot, what: str, limit: int = MAX_SYMBOLIC_JOINTS) -> None:
    """ParseError for a symbolic route on an arm with more than ``limit`` joints (:data:`MAX_SYMBOLIC_JOINTS`)."""
    if robot.dof > limit:
        raise ParseError(f"{what}: {robot.name} has {robot.dof} joints; this symbolic result is limited to "
                         f"{limit} joints (its expressions grow too fast to finish); use the numeric route with -q")


def add_common(p: argparse.ArgumentParser, robot: bool = True, angles: bool = True) -> None:
    """ROBOT, --json and --deg (``angles=False``: a command without angles says --deg has no effect there)."""
    if robot:
        p.add_argument("robot", metavar="ROBOT", help="built-in name or robot file")
    p.add_argument("--json", action="store_true", help="machine-readable JSON on stdout")
    p.add_argument("--deg", action="store_true", help="angles in and out in degrees (radians otherwise)" if angles else
                   "no effect here: this command reads and writes no angles (taken so that every command takes it)")
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
    robot = load_robot(args.robot, **overrides)
    args.shown_names = [*getattr(args, "shown_names", []), robot.name]  # emit keeps each on one line
    return robot


def joint_values(args: argparse.Namespace, robot, text: str | None, what: str = "q", check_limits: bool = True,
                 rates: bool = False) -> np.ndarray:
    """Parse a joint vector from the command line (degrees with --deg for revolute joints)."""
    from ..io import parse_values, resolve_pose
    from ..model import JointType

    if text is None:
        raise ParseError(f"{what}: missing (give {robot.dof} values)")
    pose = None if rates else resolve_pose(robot, text)
    if pose is not None:  # a named configuration of the arm (qz, qr, ...): radians/metres as stored
        vals = pose
    else:
        try:
            vals = check_values(parse_values(text, robot.dof, what=what), what)
            if args.deg:  # plain numbers of revolute joints in degrees; a value with pi or deg says its unit
                revolute = np.array([t is JointType.REVOLUTE for t in robot.joint_types])
                vals = np.where(revolute, parse_values(text, robot.dof, what=what, deg=True), vals)
        except ParseError:
            name = text.strip()
            if not rates and name.isidentifier() and len(name) <= 40 and robot.poses:  # else: the value's error
                known = ", ".join(p for p, _ in robot.poses)
                raise ParseError(f"{what}: {name!r} is neither {robot.dof} joint value{'s' * (robot.dof != 1)} nor "
                                 f"a named pose of {robot.name} (its poses: {known})") from None
            raise
    if check_limits and not rates and not getattr(args, "ignore_limits", False):
        lim = robot.q_limits
        for k in range(robot.dof):
            if not (lim[k, 0] - 1e-12 <= vals[k] <= lim[k, 1] + 1e-12):
                lo, hi, v = lim[k, 0], lim[k, 1], vals[k]
                unit, hint = "m", "use --ignore-limits to compute anyway"
                if robot.joint_types[k] is JointType.REVOLUTE:
                    unit = "rad"
                    if args.deg:
                        lo, hi, v, unit = np.degrees(lo), np.degrees(hi), np.degrees(v), "deg"
                    elif pose is None and lo <= np.radians(v) <= hi:  # degrees typed without --deg, most likely
                        hint = f"{v:.6g} deg would be inside: add --deg for degrees, or --ignore-limits to compute anyway"
                raise ParseError(
                    f"{what}: joint {k + 1} = {v:.6g} {unit} is outside its limits [{lo:.6g}, {hi:.6g}] ({hint})"
                )
    if not args.deg and pose is None and not rates:
        _warn_full_turns(robot, vals, what)
    return vals


def _warn_full_turns(robot, vals: np.ndarray, what: str) -> None:
    """One warning when a revolute value typed in radians is beyond a full turn: degrees without ``--deg``?"""
    from .._read import DEGREE_HINT
    from ..errors import DenavitWarning
    from ..model import JointType

    big = [k for k, t in enumerate(robot.joint_types) if t is JointType.REVOLUTE and abs(vals[k]) > DEGREE_HINT]
    if big:
        k = big[0]
        more = f" (and {len(big) - 1} more)" if len(big) > 1 else ""
        warnings.warn(DenavitWarning(f"{what}: joint {k + 1} = {vals[k]:.6g} rad is more than a full turn{more}; "
                                     "if the values are degrees, add --deg"), stacklevel=3)


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


def number_text(x: float, digits: int = 6, scale: float = 0.0) -> str:
    """One number for text output: ``digits`` significant digits, rounding noise shown as ``0``.

    ``x`` is noise when ``|x| <= NOISE * max(1, |scale|)`` (``scale``: the largest magnitude of the group the
    number is printed with), so ``-2.16e-18`` next to ``0.5`` prints ``0``; ``-0`` prints ``0``.

    >>> number_text(-2.16e-18), number_text(0.1 + 0.2), number_text(float("inf"))
    ('0', '0.3', 'inf')
    """
    x = float(x)
    if np.isfinite(x) and abs(x) <= NOISE * max(1.0, abs(scale)):
        return "0"
    return f"{x:.{digits}g}"


def numbers_text(values, digits: int = 6, sep: str = ", ") -> str:
    """Numbers joined by ``sep`` through :func:`number_text`, noise judged against the largest of them."""
    v = np.ravel(np.asarray(values, dtype=float))
    finite = v[np.isfinite(v)]
    scale = float(np.abs(finite).max()) if finite.size else 0.0
    return sep.join(number_text(x, digits, scale) for x in v)


def matrix_text(M: np.ndarray, digits: int = 6, indent: str = "  ") -> str:
    """A numeric matrix as aligned text (fixed decimals; very large entries in exponent form)."""
    M = np.atleast_2d(np.asarray(M, dtype=float))
    M = np.where(np.abs(M) < 0.5 * 10.0 ** (-digits), 0.0, M)

    def cell(v: float) -> str:
        if v == 0:
            return "0"
        if not np.isfinite(v) or abs(v) >= 1e9:
            return f"{v:.{digits}g}"
        return f"{v:.{digits}f}".rstrip("0").rstrip(".")

    cells = [[cell(v) for v in row] for row in M]
    width = max(len(c) for row in cells for c in row)
    return "\n".join(indent + "[ " + "  ".join(c.rjust(width) for c in row) + " ]" for row in cells)


_LINE_BREAKS = "\n\r\x0b\x0c\x1c\x1d\x1e\x85\u2028\u2029"
_LINE_BREAK_ESCAPES = {ord(c): c.encode("unicode_escape").decode("ascii") for c in _LINE_BREAKS}


def emit(args: argparse.Namespace, data: Any, text: str) -> None:
    from ..display import terminal_text

    if getattr(args, "json", False):
        json.dump(to_json(data), sys.stdout, indent=2, allow_nan=False)
        sys.stdout.write("\n")
    elif text:
        for name in getattr(args, "shown_names", []):
            if any(ch in name for ch in _LINE_BREAKS):  # a robot name never breaks the output's lines
                text = text.replace(name, name.translate(_LINE_BREAK_ESCAPES))
        text = terminal_text(text)  # a name's ESC or U+202E is shown as \x1b, \u202e: the terminal never obeys it
        sys.stdout.write(text if text.endswith("\n") else text + "\n")
