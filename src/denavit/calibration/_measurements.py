"""Measurement files of calibration and identification: CSV with a header naming the columns.

Columns are found by their header name: ``q1 … qn`` (joint readings, required), ``t`` (seconds), ``qd1 … qdn``,
``qdd1 … qddn``, ``x y z`` (positions) or ``x y z qw qx qy qz`` (poses: position and unit quaternion, w first),
``tau1 … taun`` (torques N·m, forces N).  Other columns are ignored, with one note naming them.  Blank lines and
lines starting with ``#`` are skipped.  The file is untrusted: each field is read with ``float()`` (never
evaluated), and any bad input is refused with one :class:`~denavit.errors.ParseError` line naming the file, the
line and the column (``poses.csv:7: column 'q3': 'abc' is not a number``).  Size is bounded
(:data:`MAX_FILE_BYTES`, :data:`MAX_ROWS`).
"""

from __future__ import annotations

import csv
import io
import math
import os
import tempfile
from dataclasses import dataclass, field
from typing import Mapping

import numpy as np

from ..errors import ParseError, ShapeError
from ..model import DHRobot, JointType

__all__ = ["Measurements", "read_measurements", "write_measurements", "MAX_FILE_BYTES", "MAX_ROWS",
           "QUATERNION_TOLERANCE", "LENGTH_UNITS", "ANGLE_UNITS"]

#: Largest measurement file read [bytes].
MAX_FILE_BYTES = 200_000_000
#: Most data rows read.
MAX_ROWS = 10_000_000
#: A pose's quaternion is refused when its norm is off 1 by more than this (it is normalised otherwise).
QUATERNION_TOLERANCE = 1e-3
#: Length units of joint readings of prismatic joints and of positions, in metres.
LENGTH_UNITS = {"m": 1.0, "cm": 1e-2, "mm": 1e-3}
#: Angle units of joint readings of revolute joints (and their rates), in radians.
ANGLE_UNITS = {"rad": 1.0, "deg": math.pi / 180.0}

_POSITION = ("x", "y", "z")
_QUATERNION = ("qw", "qx", "qy", "qz")
_SHOWN = 40  # characters of a user's field shown in a message


@dataclass(frozen=True, eq=False)  # holds arrays: compared by identity
class Measurements:
    """The columns of a measurement file, in SI units and radians; ``None`` where a group is absent.

    Attributes
    ----------
    q : ndarray, shape (m, n)
        Joint readings [rad, m].
    t : ndarray, shape (m,) or None
        Time [s].
    qd, qdd : ndarray, shape (m, n) or None
        Joint rates [rad/s, m/s] and accelerations [rad/s², m/s²].
    position : ndarray, shape (m, 3) or None
        Measured end-effector position in the world frame [m].
    quaternion : ndarray, shape (m, 4) or None
        Measured end-effector orientation, unit quaternion (w, x, y, z) (normalised on reading).
    tau : ndarray, shape (m, n) or None
        Joint torques [N·m] or forces [N].
    lines : ndarray of int, shape (m,)
        The file line of each row (1-based), to name rows in reports.
    notes : tuple of str
        Remarks on the reading (ignored columns).
    source : str
        The file name.
    """

    q: np.ndarray
    t: np.ndarray | None = None
    qd: np.ndarray | None = None
    qdd: np.ndarray | None = None
    position: np.ndarray | None = None
    quaternion: np.ndarray | None = None
    tau: np.ndarray | None = None
    lines: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=int))
    notes: tuple[str, ...] = ()
    source: str = ""

    def __len__(self) -> int:
        return int(self.q.shape[0])

    @property
    def poses(self) -> np.ndarray | None:
        """The measured poses as homogeneous transforms, shape (m, 4, 4), or None without orientation."""
        if self.position is None or self.quaternion is None:
            return None
        T = np.zeros((len(self), 4, 4))
        T[:, :3, :3] = rotation_from_quaternion(self.quaternion)
        T[:, :3, 3] = self.position
        T[:, 3, 3] = 1.0
        return T


def rotation_from_quaternion(quat: np.ndarray) -> np.ndarray:
    """Rotation matrices of unit quaternions (w, x, y, z), shape (..., 4) → (..., 3, 3) (Siciliano (2.34))."""
    w, x, y, z = np.moveaxis(np.asarray(quat, dtype=float), -1, 0)
    R = np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y),
                  2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x),
                  2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)], axis=-1)
    return R.reshape(w.shape + (3, 3))


def _short(text: str) -> str:
    return repr(text if len(text) <= _SHOWN else text[:_SHOWN] + "...")


def _open_checked(path: str):
    """The file opened as text, after the size check (a non-regular file is read at most MAX_FILE_BYTES + 1)."""
    st = os.stat(path)
    if st.st_size > MAX_FILE_BYTES:
        raise ParseError(f"file too large ({st.st_size} bytes; at most {MAX_FILE_BYTES})", where=path)
    with open(path, "rb") as fh:
        raw = fh.read(MAX_FILE_BYTES + 1)
    if len(raw) > MAX_FILE_BYTES:
        raise ParseError(f"file too large (more than {MAX_FILE_BYTES} bytes)", where=path)
    try:
        return raw.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        line = raw[: exc.start].count(b"\n") + 1
        raise ParseError("not UTF-8 text (a CSV file is expected)", where=f"{path}:{line}") from None


def _records(text: str, path: str):
    """(line number, fields) of each non-blank, non-comment line, fields stripped."""
    reader = csv.reader(io.StringIO(text, newline=""), strict=True)  # line_num counts the file's lines
    try:
        for fields in reader:
            stripped = [f.strip() for f in fields]
            if not any(stripped) or stripped[0].startswith("#"):
                continue
            yield reader.line_num, stripped
    except csv.Error as exc:
        raise ParseError(f"not valid CSV ({exc})", where=f"{path}:{reader.line_num}") from None


def _columns(header: list[str], robot: DHRobot, where: str, joints: bool = True) -> tuple[dict[str, int], list[str]]:
    """Column index of each known name, and the ignored names; refuses duplicates and incomplete groups."""
    n = robot.dof
    known = {"t", *_POSITION, *_QUATERNION}
    for stem in ("q", "qd", "qdd", "tau"):
        known.update(f"{stem}{k}" for k in range(1, n + 1))
    index: dict[str, int] = {}
    ignored: list[str] = []
    for k, name in enumerate(header):
        if not name:
            raise ParseError(f"column {k + 1} has an empty name in the header", where=where)
        if name in index or name in ignored:
            first = header.index(name) + 1
            raise ParseError(f"column {_short(name)} appears twice (columns {first} and {k + 1})", where=where)
        for stem in ("qdd", "qd", "q", "tau"):  # a joint beyond the arm's: most likely the wrong robot
            rest = name[len(stem):]
            if name.startswith(stem) and rest.isdigit() and not 1 <= int(rest) <= n and name not in known:
                raise ParseError(f"column {_short(name)}: {robot.name} has {n} joint{'s' * (n != 1)} "
                                 f"(columns {stem}1 ... {stem}{n})", where=where)
        (index.__setitem__(name, k) if name in known else ignored.append(name))
    groups = [tuple(f"q{k}" for k in range(1, n + 1))]
    groups += [tuple(f"{s}{k}" for k in range(1, n + 1)) for s in ("qd", "qdd", "tau")]
    groups += [_POSITION, _QUATERNION]
    for group in groups:
        missing = [c for c in group if c not in index]
        if missing and ((group is groups[0] and joints) or len(missing) < len(group)):
            raise ParseError(f"column {missing[0]!r} missing (the group {' '.join(group)} needs every column)",
                             where=where)
    if _QUATERNION[0] in index and _POSITION[0] not in index:
        raise ParseError("columns qw qx qy qz need the position columns x y z too", where=where)
    return index, ignored


def _parse_rows(records, header: list[str], index: Mapping[str, int], path: str) -> tuple[np.ndarray, np.ndarray]:
    """The known columns of every data row as floats (m, len(index)) and their line numbers."""
    cols = list(index.values())
    names = [header[c] for c in cols]
    width = len(header)
    rows: list[list[float]] = []
    lines: list[int] = []
    for line, fields in records:
        if len(fields) != width:
            raise ParseError(f"{len(fields)} fields; the header has {width}", where=f"{path}:{line}")
        if len(rows) >= MAX_ROWS:
            raise ParseError(f"more than {MAX_ROWS} data rows", where=f"{path}:{line}")
        row = []
        for name, c in zip(names, cols):
            text = fields[c]
            try:
                value = float(text)
            except ValueError:
                raise ParseError(f"column {name!r}: {_short(text)} is not a number",
                                 where=f"{path}:{line}") from None
            if not math.isfinite(value):
                raise ParseError(f"column {name!r}: {_short(text)} is not a finite number",
                                 where=f"{path}:{line}")
            row.append(value)
        rows.append(row)
        lines.append(line)
    return np.array(rows, dtype=float).reshape(len(rows), len(cols)), np.array(lines, dtype=int)


def read_measurements(path: str | os.PathLike, robot: DHRobot, *, angle_unit: str = "rad", length_unit: str = "m",
                      torque_scale: float = 1.0, require_joints: bool = True) -> Measurements:
    """Read a measurement CSV file for ``robot`` (see the module notes for the columns).

    Parameters
    ----------
    path : str or path-like
        The CSV file.
    robot : DHRobot
        The arm the readings are of: its joint count names the columns, its joint types the units.
    angle_unit : {"rad", "deg"}
        Unit of revolute joint readings, rates and accelerations in the file (quaternions have none).
    length_unit : {"m", "cm", "mm"}
        Unit of prismatic joint readings (and rates) and of the positions x y z.
    torque_scale : float
        Factor from the file's torque unit to N·m / N (e.g. 1e-3 for N·mm).
    require_joints : bool
        False for files of poses alone (``denavit ik --path``): without q columns, ``q`` has shape (m, 0).

    Returns
    -------
    Measurements
        SI units and radians; the quaternions normalised.

    Raises
    ------
    ParseError
        One line ``FILE:LINE: ...`` for a missing or duplicate column, a field that is not a finite number, a
        row with the wrong number of fields, a quaternion whose norm is off 1 by more than
        :data:`QUATERNION_TOLERANCE`, a file beyond :data:`MAX_FILE_BYTES` or :data:`MAX_ROWS`.
    """
    path = os.fspath(path)
    if angle_unit not in ANGLE_UNITS or length_unit not in LENGTH_UNITS:
        raise ParseError(f"angle_unit must be one of {', '.join(ANGLE_UNITS)} and length_unit one of "
                         f"{', '.join(LENGTH_UNITS)}; got {angle_unit!r}, {length_unit!r}")
    if not (math.isfinite(torque_scale) and torque_scale > 0):
        raise ParseError(f"torque_scale must be a finite number > 0, got {torque_scale!r}")
    records = _records(_open_checked(path), path)
    try:
        line, header = next(records)
    except StopIteration:
        raise ParseError("no header line (expected column names such as q1, q2, ..., x, y, z)", where=path) from None
    index, ignored = _columns(header, robot, f"{path}:{line}", require_joints)
    values, lines = _parse_rows(records, header, index, path)
    if not len(lines):
        raise ParseError("no data rows after the header", where=f"{path}:{line}")
    col = {name: values[:, k] for k, name in enumerate(index)}
    return _assemble(col, robot, lines, ignored, path, ANGLE_UNITS[angle_unit], LENGTH_UNITS[length_unit],
                     float(torque_scale))


def _assemble(col: Mapping[str, np.ndarray], robot: DHRobot, lines: np.ndarray, ignored: list[str], path: str,
              angle: float, length: float, torque: float) -> Measurements:
    n = robot.dof
    unit = np.array([angle if t is JointType.REVOLUTE else length for t in robot.joint_types])

    def group(stem: str, scale) -> np.ndarray | None:
        if f"{stem}1" not in col:
            return None
        return np.stack([col[f"{stem}{k}"] for k in range(1, n + 1)], axis=-1) * scale  # (m, n)

    position = quat = None
    if "x" in col:
        position = np.stack([col[c] for c in _POSITION], axis=-1) * length  # (m, 3)
    if "qw" in col:
        quat = np.stack([col[c] for c in _QUATERNION], axis=-1)  # (m, 4)
        norm = np.linalg.norm(quat, axis=-1)
        bad = np.flatnonzero(np.abs(norm - 1.0) > QUATERNION_TOLERANCE)
        if bad.size:
            k = int(bad[0])
            raise ParseError(f"columns qw qx qy qz: the quaternion's norm is {norm[k]:.6g}; a unit quaternion is "
                             f"expected (within {QUATERNION_TOLERANCE:g})", where=f"{path}:{lines[k]}")
        quat = quat / norm[:, None]
    notes = ()
    if ignored:
        shown = ", ".join(_short(c) for c in ignored[:10]) + (f" and {len(ignored) - 10} more" if len(ignored) > 10
                                                                else "")
        notes = (f"{path}: ignored column{'s' * (len(ignored) > 1)} {shown}",)
    q = group("q", unit)
    return Measurements(q=np.zeros((len(lines), 0)) if q is None else q, t=col.get("t"), qd=group("qd", unit), qdd=group("qdd", unit),
                        position=position, quaternion=quat, tau=group("tau", torque), lines=lines, notes=notes,
                        source=path)


def _column_items(columns: Mapping[str, object]) -> list[tuple[str, np.ndarray]]:
    """(name, 1-D float array) pairs; a 2-D array under ``name`` gives columns name1, name2, ..."""
    items: list[tuple[str, np.ndarray]] = []
    for name, values in columns.items():
        a = np.asarray(values, dtype=float)
        if a.ndim == 2:
            items += [(f"{name}{k + 1}", a[:, k]) for k in range(a.shape[1])]
        elif a.ndim == 1:
            items.append((str(name), a))
        else:
            raise ShapeError(f"column {name!r}: expected a 1-D array (or 2-D for numbered columns), got shape {a.shape}")
    names = [n for n, _ in items]
    for n in names:
        if not n or n != n.strip() or any(c in n for c in ',"\n\r#') or names.count(n) > 1:
            raise ShapeError(f"column name {n!r}: expected a unique, non-empty name without , \" # or line breaks")
    lengths = {a.shape[0] for _, a in items}
    if len(lengths) != 1:
        raise ShapeError(f"columns of different lengths: expected one length, got {sorted(lengths)}")
    for n, a in items:
        if not np.all(np.isfinite(a)):
            raise ShapeError(f"column {n!r}: expected finite numbers, got nan or inf")
    return items


def write_measurements(path: str | os.PathLike, columns: Mapping[str, object], *, comment: str = "") -> None:
    """Write a measurement CSV file atomically (a temporary file beside ``path``, then ``os.replace``).

    Parameters
    ----------
    path : str or path-like
        The file to write (replaced if it exists).
    columns : mapping of name to array
        Each a 1-D array of the same length, in the order given; a 2-D array of shape (m, k) under ``name``
        writes columns ``name1 … namek`` (so ``{"q": q}`` writes q1 … qn).  Numbers are written with ``repr``
        (shortest digits that read back exactly).
    comment : str
        Written first as ``#`` lines (skipped by the reader).
    """
    path = os.fspath(path)
    items = _column_items(columns)
    folder = os.path.dirname(path) or "."
    fd, tmp = tempfile.mkstemp(prefix=".denavit-", suffix=".csv", dir=folder)
    try:
        with os.fdopen(fd, "w", encoding="utf-8", newline="") as fh:
            for line in comment.splitlines():
                fh.write(f"# {line}\n")
            fh.write(",".join(n for n, _ in items) + "\n")
            table = np.stack([a for _, a in items], axis=-1)  # (m, columns)
            for row in table.tolist():
                fh.write(",".join(map(repr, row)) + "\n")
            fh.flush()
            os.fsync(fh.fileno())
        os.chmod(tmp, 0o666 & ~_umask())
        os.replace(tmp, path)
    finally:
        if os.path.lexists(tmp):
            os.unlink(tmp)


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask
