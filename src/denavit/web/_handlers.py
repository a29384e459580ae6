"""The workbench's quick answers: request data in, plain JSON-able data out (no HTTP here).

Every function takes the decoded JSON body (untrusted: any shape) and either returns a dict or raises
:class:`RequestError` with one line naming what is wrong and, for a DH table, the cell (row and field).
The robot arrives as the robot-file mapping the page edits (``docs/robot-file.md``) and is read by
:func:`denavit.robot_from_dict` (the restricted expression grammar, never ``eval``); typed lists (q̇, a
wrench, a target pose) by :func:`denavit.io.parse_values`, the command line's reader.  Each answer is a
few small numeric calls (milliseconds); the long work is in :mod:`denavit.web._work`, run in a process.
"""

from __future__ import annotations

import json
import math
import re
import threading
import warnings
from collections import OrderedDict
from importlib import resources
from typing import Any

import numpy as np

from .. import (
    DenavitError,
    Frame,
    catalogue_names,
    coriolis_vector,
    dump_robot,
    forward_kinematics,
    geometric_jacobian,
    gravity_torques,
    joint_torques,
    manipulability,
    mass_matrix,
    robot_from_dict,
)
from ..io import CATALOGUE_ALIASES, load_data, parse_values, robot_to_dict

__all__ = [
    "MAX_MESSAGE",
    "ROBOT_CACHE",
    "RequestError",
    "catalogue",
    "catalogue_robot",
    "dynamics",
    "field_of",
    "json_matrix",
    "kinematics",
    "one_line",
    "q_of",
    "robot_file",
    "robot_info",
    "robot_of",
    "statics",
    "table",
    "values_of",
]

#: Longest error line sent back (long user text is cut in the middle).
MAX_MESSAGE = 300
#: Robots kept parsed, by the exact JSON of their file mapping (a slider move re-sends the same table).
ROBOT_CACHE = 64
_CELL = re.compile(r"row (\d+), field '([a-z_]+)")
_CONTROL = re.compile(r"[\x00-\x1f\x7f-\x9f\u202a-\u202e\u2066-\u2069]")


class RequestError(ValueError):
    """A request the workbench cannot answer: one line, an HTTP status and, for a table, the cell."""

    def __init__(self, message: str, status: int = 422, cell: dict[str, Any] | None = None) -> None:
        super().__init__(one_line(message))
        self.status = status
        self.cell = cell

    def to_json(self) -> dict[str, Any]:
        return {"error": str(self), "cell": self.cell}


def one_line(message: Any, limit: int = MAX_MESSAGE) -> str:
    """``message`` as one printable line of at most about ``limit`` characters."""
    text = " ".join(_CONTROL.sub(" ", str(message)).split())
    if len(text) > limit:
        text = text[: limit * 2 // 3] + " ... " + text[-(limit // 3):]
    return text


def _cell_of(exc: DenavitError) -> dict[str, Any] | None:
    """The table cell a robot-file error names (``row 2, field 'theta'``), or the top-level key."""
    where = str(getattr(exc, "where", "") or "")
    m = _CELL.search(where)
    if m:
        return {"row": int(m.group(1)), "field": m.group(2)}
    for key in ("parameters", "convention", "angle_unit", "joints", "tool", "base", "gravity", "poses"):
        if f": {key}" in where:
            return {"row": None, "field": key}
    return None


_robots: OrderedDict[str, tuple[Any, tuple[str, ...]]] = OrderedDict()
_robots_lock = threading.Lock()  # the IK answers run in worker threads


def robot_of(body: Any) -> Any:
    """The robot of a request (``body["robot"]``: the robot-file mapping), parsed once per distinct table."""
    return _robot_and_notes(body)[0]


def _robot_and_notes(body: Any) -> tuple[Any, tuple[str, ...]]:
    doc = body.get("robot") if isinstance(body, dict) else None
    if not isinstance(doc, dict):
        raise RequestError("'robot' must be the robot-file mapping {convention, joints, ...}", 422, {"row": None, "field": "joints"})
    key = json.dumps(doc, sort_keys=True)
    with _robots_lock:
        hit = _robots.get(key)
        if hit is not None:
            _robots.move_to_end(key)
            return hit
        return _parse(doc, key)


def _parse(doc: dict, key: str) -> tuple[Any, tuple[str, ...]]:
    """Read a table (under the cache's lock) and remember it with its warnings as notes."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            robot = robot_from_dict(doc, where="table")
        except DenavitError as exc:
            raise RequestError(str(exc), 422, _cell_of(exc)) from None
        except (TypeError, ValueError, OverflowError, RecursionError) as exc:  # odd JSON shapes the reader missed
            raise RequestError(f"table: {exc}", 422) from None
    notes = tuple(one_line(w.message) for w in caught if issubclass(w.category, UserWarning))
    _robots[key] = (robot, notes)
    while len(_robots) > ROBOT_CACHE:
        _robots.popitem(last=False)
    return robot, notes


def field_of(body: Any, key: str, default: Any = None) -> Any:
    return body.get(key, default) if isinstance(body, dict) else default


def q_of(body: Any, robot: Any, key: str = "q") -> np.ndarray:
    """Joint values ``body[key]`` of ``robot``."""
    return values_of(body, key, robot.dof)


def values_of(body: Any, key: str, n: int) -> np.ndarray:
    """``n`` values: a list of numbers (the sliders) or a text such as ``"0, pi/4, 90deg"`` (radians unless deg)."""
    raw = field_of(body, key)
    if raw is None:
        raise RequestError(f"'{key}' is missing: {n} values", 422)
    if not isinstance(raw, (str, list)) or (isinstance(raw, list) and not all(
            isinstance(v, (int, float, str)) and not isinstance(v, bool) for v in raw)):
        raise RequestError(f"'{key}' must be a list of {n} numbers or a text like \"0, pi/4\"", 422)
    what = key
    try:
        q = parse_values(raw, n, what=what)
    except DenavitError as exc:
        raise RequestError(str(exc), 422) from None
    if not np.all(np.isfinite(q)) or np.abs(q).max(initial=0) > 1e6:
        raise RequestError(f"{what}: values must be finite numbers of at most 1e6 in magnitude", 422)
    return q


def json_matrix(a: np.ndarray) -> list:
    a = np.where(np.abs(a) < 1e-15, 0.0, a)
    return [_finite(x) for x in a.tolist()] if a.ndim == 1 else [[_finite(x) for x in row] for row in a.tolist()]


def _finite(x: float) -> float | None:
    return x if math.isfinite(x) else None


def robot_info(body: Any) -> dict[str, Any]:
    """The parsed table: joint types row by row, sliders, the start configuration and the viewer page."""
    from ..viz import default_configuration, slider_limits, viewer_html

    robot, notes = _robot_and_notes(body)
    q0 = default_configuration(robot)
    return {
        "name": robot.name, "dof": robot.dof, "convention": robot.convention.value,
        "rows": [link.joint.value for link in robot.links],
        "joint_types": [t.value for t in robot.joint_types],
        "limits": json_matrix(slider_limits(robot)),
        "poses": {name: list(q) for name, q in robot.poses},
        "q0": json_matrix(q0), "notes": list(notes),
        "viewer": viewer_html(robot, q0, title=robot.name),
        "has_inertia": all(link.inertia is not None for link in robot.links if link.is_joint),
        "analytic_ik": _has_analytic_ik(robot),
    }


def _has_analytic_ik(robot: Any) -> bool:
    """Whether :func:`denavit.analytic_ik` has a closed form for the whole arm (no joint held)."""
    from ..ik import ik_structure

    try:
        ik_structure(robot)
    except DenavitError:
        return False
    return True


def kinematics(body: Any) -> dict[str, Any]:
    """T (world pose of the end effector), J0 and its measures at ``q`` (on the task ``rows``, all six by default:
    with fewer joints than rows J Jᵀ is singular and Yoshikawa's w = √det(J Jᵀ) is 0); ``seq`` is echoed."""
    from ..numeric import TWIST_ROWS, select_rows

    robot = robot_of(body)
    q = q_of(body, robot)
    T = forward_kinematics(robot, q)                    # (4, 4)
    J = geometric_jacobian(robot, q)                    # (6, n), rows (v, ω) in base axes
    rows = field_of(body, "rows")                         # task rows of the measures, e.g. ["vx", "vy"] (planar)
    try:
        idx = select_rows(rows if isinstance(rows, list) and all(isinstance(r, str) for r in rows) else None)
    except ValueError as exc:
        raise RequestError(f"rows: {exc}") from None
    Jt = J[idx]                                         # (m, n)
    sv = np.linalg.svd(Jt, compute_uv=False)
    out = {"q": json_matrix(q), "T": json_matrix(T), "J": json_matrix(J), "manipulability": float(manipulability(Jt)),
           "rows": [TWIST_ROWS[i] for i in idx], "singular_values": json_matrix(sv), "det": None,
           "seq": field_of(body, "seq")}
    if Jt.shape[0] == Jt.shape[1]:
        out["det"] = float(np.linalg.det(Jt))
    if not isinstance(out["seq"], (int, float)) or isinstance(out["seq"], bool):
        out["seq"] = None
    return out


def dynamics(body: Any) -> dict[str, Any]:
    """M(q), c(q, q̇) = C(q, q̇) q̇ and g(q) by the numeric engine (RNEA; Featherstone 2008, ch. 5)."""
    robot = robot_of(body)
    q = q_of(body, robot)
    qd = q_of(body, robot, "qd") if field_of(body, "qd") not in (None, "") else np.zeros(robot.dof)
    try:
        M, c, g = mass_matrix(robot, q), coriolis_vector(robot, q, qd), gravity_torques(robot, q)
    except DenavitError as exc:
        raise RequestError(str(exc), 422) from None
    return {"q": json_matrix(q), "qd": json_matrix(qd), "M": json_matrix(M), "c": json_matrix(c), "g": json_matrix(g)}


def statics(body: Any) -> dict[str, Any]:
    """τ = Jᵀ w for the end-effector wrench w = (f, n) [N, N·m] in base or tool axes (Craig eq. 5.105)."""
    robot = robot_of(body)
    q = q_of(body, robot)
    w = values_of(body, "wrench", 6)
    frame = field_of(body, "frame", "base")
    if frame not in ("base", "tool"):
        raise RequestError("'frame' must be base or tool")
    return {"q": json_matrix(q), "wrench": json_matrix(w), "frame": frame,
            "tau": json_matrix(joint_torques(robot, q, w, frame=Frame(frame)))}


def table(body: Any) -> dict[str, Any]:
    """A DH table pasted from a document (:func:`denavit.tables.import_table`) as a robot-file mapping."""
    from ..tables import import_table

    text = field_of(body, "text")
    if not isinstance(text, str) or not text.strip():
        raise RequestError("'text' must be the pasted table")
    conv = field_of(body, "convention")
    deg = field_of(body, "degrees")
    if conv not in (None, "standard", "modified") or deg not in (None, True, False):
        raise RequestError("'convention' must be standard, modified or null; 'degrees' true, false or null")
    try:
        result = import_table(text, name=str(field_of(body, "name", "pasted"))[:80], convention=conv, degrees=deg,
                              where="pasted table")
    except DenavitError as exc:
        raise RequestError(str(exc), 422) from None
    return {"robot": json.loads(json.dumps(result.data, default=str)), "notes": [one_line(n) for n in result.notes]}


def catalogue() -> dict[str, Any]:
    return {"names": catalogue_names()}


def catalogue_robot(body: Any) -> dict[str, Any]:
    """A built-in robot's file mapping, read from the package's own data (never a path from the request)."""
    name = field_of(body, "name")
    names = catalogue_names()
    if not isinstance(name, str) or (name not in names and name not in CATALOGUE_ALIASES):
        raise RequestError(f"unknown robot {one_line(name, 60)!r}; the {len(names)} built-in names are listed at /api/catalogue", 404)
    name = CATALOGUE_ALIASES.get(name, name)
    text = resources.files("denavit").joinpath("data", "robots", f"{name}.yaml").read_text(encoding="utf-8")
    data = load_data(text, ".yaml", f"catalogue:{name}")
    robot = robot_from_dict(data, where=name)
    return {"robot": robot_to_dict(robot)}


def robot_file(body: Any) -> dict[str, Any]:
    """The robot file of the table, as YAML or JSON text (:func:`denavit.dump_robot`)."""
    fmt = field_of(body, "format", "yaml")
    if fmt not in ("yaml", "json"):
        raise RequestError("'format' must be yaml or json")
    robot = robot_of(body)
    return {"text": dump_robot(robot, fmt), "filename": f"{re.sub(r'[^A-Za-z0-9_.-]+', '_', robot.name)[:60] or 'robot'}.{fmt}"}


_FILE_SUFFIXES = (".yaml", ".yml", ".json", ".toml", ".urdf")


def opened_file(body: Any) -> dict[str, Any]:
    """A robot file or URDF opened in the page (its text; the name only gives the format), as a robot-file mapping.

    A robot file is read safely (:func:`denavit.io.load_data`: bounded nesting, aliases, sizes) and kept as written,
    so its cells show as the author typed them; a URDF's chain becomes DH rows (:func:`denavit.from_urdf`, XML
    read with entities disabled).  The text is never taken for a path.
    """
    from .. import from_urdf

    text, name = field_of(body, "text"), field_of(body, "filename")
    if not isinstance(text, str) or not isinstance(name, str):
        raise RequestError("'text' and 'filename' must be the file's text and name")
    suffix = "." + name.rsplit(".", 1)[-1].lower() if "." in name else ""
    if suffix not in _FILE_SUFFIXES:
        raise RequestError(f"{one_line(name, 60)!r}: open a robot file ({', '.join(_FILE_SUFFIXES[:4])}) or a .urdf")
    where = one_line(name, 60)
    try:
        if suffix == ".urdf":
            if not text.lstrip().startswith("<"):
                raise RequestError(f"{where}: a URDF is XML text starting with '<'")
            return {"robot": robot_to_dict(from_urdf(text)), "notes": ["DH rows extracted from the URDF's chain"]}
        data = load_data(text, suffix, where)
        if not isinstance(data, dict):
            raise RequestError(f"{where}: a robot file is a mapping with 'convention' and 'joints'")
        data = json.loads(json.dumps(data, default=str))
        robot_from_dict(data, where=where)  # refused here, naming the file, row and field
    except DenavitError as exc:
        raise RequestError(str(exc), 422, _cell_of(exc)) from None
    return {"robot": data, "notes": []}
