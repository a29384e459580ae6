"""Robot files (YAML, TOML, JSON) and the built-in catalogue: loading, parameters, value lists.

The safe parsing of the text lives in :mod:`denavit._safeload`, the reading of the data in
:mod:`denavit._read`, the writing in :mod:`denavit._write`; this module is their public face.

Robot files are untrusted: every value goes through :mod:`denavit._expr` (a restricted grammar), never
``eval``.  Errors are :class:`~denavit.errors.ParseError` naming the file, the row and the field.
Degrees are converted to radians in these modules (and on the command line) and nowhere else.
"""

from __future__ import annotations

import math
from functools import lru_cache
from importlib import resources
from pathlib import Path
from typing import Any, Mapping

import numpy as np

from . import _expr
from ._safeload import MAX_TEXT_BYTES, load_data
from ._read import names_unit, robot_from_dict, transform_from_texts
from ._write import dump_robot, expression_text, robot_to_dict, save_robot, value_text
from .errors import ModelError, ParseError
from .model import DH_FIELDS, DHLink, DHRobot, LinkInertia

__all__ = [
    "load_data",
    "split_values",
    "load_robot",
    "robot_from_dict",
    "robot_to_dict",
    "dump_robot",
    "save_robot",
    "catalogue_names",
    "CATALOGUE_ALIASES",
    "with_parameters",
    "parse_values",
    "value_text",
    "expression_text",
    "resolve_pose",
]

#: Largest robot file read (bytes); a 32-joint arm with inertial data is about 10 kB.
MAX_FILE_BYTES = MAX_TEXT_BYTES
#: Most values in one list given on the command line or to :func:`parse_values`, and its length in characters.
MAX_VALUES = 10_000
MAX_VALUES_TEXT = 200_000


# --------------------------------------------------------------------------------------------------
# catalogue


def _catalogue_dir():
    return resources.files("denavit") / "data" / "robots"


# old catalogue names (after the student report each arm came from) -> current names; still loadable
CATALOGUE_ALIASES = {
    "report000-6r": "coaxial-6r", "report000-planar3r": "planar3r-lagrange", "report001-6r": "offset-6r",
    "report003-6r": "elbow-6r-deg", "report004-1-planar2r": "planar2r-mdh", "report004-2-planar3r": "planar3r-mdh",
    "report004-3-articulated-rrr": "articulated-rrr", "report004-4-rrp": "spherical-rrp",
    "report004-5-rpp-cylindrical": "cylindrical-rpp", "report004-6-wrist3r": "spherical-wrist",
    "report004-7-scara-rrrp": "scara-rrrp", "report004-8-prrr": "lift-prrr",
}


def catalogue_names() -> list[str]:
    """Names of the built-in robots, sorted (old names in :data:`CATALOGUE_ALIASES` also load)."""
    return sorted(p.name[:-5] for p in _catalogue_dir().iterdir() if p.name.endswith(".yaml"))


def catalogue_name(name: str) -> str:
    """The built-in robot ``name`` stands for: itself, an old name (:data:`CATALOGUE_ALIASES`), or either in
    other letter case (``"UR5"`` is ``ur5``).  Unknown: a ParseError with the closest names (difflib) and how to
    list them all."""
    import difflib

    known = {n.lower(): n for n in catalogue_names()} | {a.lower(): n for a, n in CATALOGUE_ALIASES.items()}
    if name.lower() in known:
        return known[name.lower()]
    close = difflib.get_close_matches(name.lower(), [n for n in known if n in known.values()], n=3, cutoff=0.6)
    hint = f"; did you mean {' or '.join(close)}?" if close else ""
    raise ParseError(f"unknown robot {name!r}: not a file and not a built-in name{hint} (the {len(catalogue_names())} "
                     "built-in names: denavit robots, or denavit.catalogue_names())")


def load_robot(source: str | Path, **parameters: float) -> DHRobot:
    """Load a robot from a file path or a built-in name (see :func:`catalogue_names`).

    Parameters
    ----------
    source : str or Path
        A ``.yaml``/``.yml``/``.toml``/``.json`` robot file, or a catalogue name such as ``"puma560"``.
    **parameters : float
        Override values of the robot's named parameters (``L1=0.7``).
    """
    path = Path(source)
    if path.suffix.lower() in (".yaml", ".yml", ".toml", ".json") or path.exists():
        if not path.is_file():
            raise ParseError(f"no such robot file: {str(path)!r}")
        size = path.stat().st_size
        if size > MAX_FILE_BYTES:
            raise ParseError(f"file too large ({size} bytes; at most {MAX_FILE_BYTES})", where=str(path))
        with path.open("rb") as fh:  # bounded read: the size on disk may lie (special files)
            raw = fh.read(MAX_FILE_BYTES + 1)
        if len(raw) > MAX_FILE_BYTES:
            raise ParseError(f"file too large (more than {MAX_FILE_BYTES} bytes)", where=str(path))
        data = _load_text(raw.decode("utf-8", errors="replace"), path.suffix.lower(), str(path))
        robot = robot_from_dict(_override(data, parameters, str(path)), where=str(path))
    else:
        name = catalogue_name(str(source))
        res = _catalogue_dir() / f"{name}.yaml"
        data = _load_text(res.read_text(encoding="utf-8"), ".yaml", f"catalogue:{name}")
        robot = robot_from_dict(_override(data, parameters, name), where=name)
        robot = robot.replace(source=f"catalogue:{name}")
    return robot


def _override(data: dict[str, Any], values: Mapping[str, float], where: str) -> dict[str, Any]:
    """The file's data with some parameters given new values, so every field is evaluated with them.

    Fields, limits, inertia, gravity, base, tool and parameters defined from the overridden ones all
    follow, because the whole file is read again with the new values.
    """
    if not values:
        return data
    params = data.get("parameters")
    known = [str(k) for k in params] if isinstance(params, dict) else []
    for k in values:
        if k not in known:
            raise ParseError(f"no parameter {k!r}; parameters: {', '.join(known) or 'none'}", where=where)
    new = dict(params)  # type: ignore[arg-type]
    for k, v in values.items():
        new[k] = _param_value(k, v)
    return {**data, "parameters": new}


def _param_value(name: str, value: Any) -> float:
    try:
        v = float(value)
    except (TypeError, ValueError, OverflowError):
        raise ParseError(f"parameter {name}: expected a number, got {value!r:.40}") from None
    if not math.isfinite(v):
        raise ParseError(f"parameter {name}: value must be finite, got {v}")
    return v


def _load_text(text: str, suffix: str, where: str) -> dict[str, Any]:
    data = load_data(text, suffix, where)
    if not isinstance(data, dict):
        raise ParseError("a robot file must be a mapping with at least 'convention' and 'joints'", where=where)
    return data


def resolve_pose(robot: DHRobot, text: str) -> np.ndarray | None:
    """The joint values of the named pose ``text`` of ``robot`` (``"qr"``), or None when it names none.

    >>> resolve_pose(load_robot("puma560"), "qz")
    array([0., 0., 0., 0., 0., 0.])
    """
    poses = dict(robot.poses)
    key = text.strip() if isinstance(text, str) else None
    return np.array(poses[key], dtype=float) if key in poses else None


# --------------------------------------------------------------------------------------------------
# parameters, values


def with_parameters(robot: DHRobot, **values: float) -> DHRobot:
    """The same robot with some named parameters given new values, every field that uses them re-evaluated.

    DH values, joint limits, inertial data, gravity, base and tool written with parameters all follow.
    Parameters defined in the file from other parameters keep their values here (``load_robot(path, L1=…)``
    re-reads the file, so they follow too).

    Raises
    ------
    ParseError
        An unknown parameter name (the message lists the robot's parameters), a value that is not a finite
        number, or a new value that puts a field out of range.
    """
    if not all(type(v) in (float, int) for v in values.values()):  # anything else: checked below, not remembered
        return _with_parameters(robot, values)
    # the key tells apart what == does not: the robot's angle unit (compare=False), -0.0 and 0.0, 1 and 1.0
    return _with_parameters_remembered(robot, robot.angle_unit,
                                       tuple((k, type(v), repr(v), v) for k, v in values.items()))


@lru_cache(maxsize=1024)
def _with_parameters_remembered(robot: DHRobot, unit: str, values: tuple) -> DHRobot:
    """:func:`with_parameters` for plain numbers, remembered: a pure function of a frozen robot and the values (the
    claim checker's "a wrong parameter value" hint builds the same robots on the same grid for every incorrect
    claim of an arm)."""
    return _with_parameters(robot, {k: v for k, _, _, v in values})


def _with_parameters(robot: DHRobot, values: dict) -> DHRobot:
    params = robot.parameter_values
    for k, v in values.items():
        if k not in params:
            raise ParseError(f"robot {robot.name!r} has no parameter {k!r}; parameters: {', '.join(params) or 'none'}")
        params[k] = _param_value(k, v)
    ev = lambda text: _expr.evaluate(_expr.parse(text), params)  # noqa: E731
    try:
        links = []
        for row, link in enumerate(robot.links, start=1):
            try:
                links.append(_link_with(link, ev))
            except ModelError as exc:
                raise ParseError(f"row {row}: {exc}") from None
        changes: dict[str, Any] = {"links": tuple(links), "parameters": tuple(params.items())}
        sym = dict(robot.symbols)
        if "gravity0" in sym:
            changes["gravity"] = tuple(ev(sym[f"gravity{i}"]) for i in range(3))
        for place in ("base", "tool"):
            T = transform_from_texts(sym, place, params)
            if T is not None:
                changes[place] = T
        return robot.replace(**changes)
    except ModelError as exc:
        raise ParseError(str(exc)) from None


def _link_with(link: DHLink, ev: Any) -> DHLink:
    """A DH row with the fields written with parameters evaluated again by ``ev``."""
    sym = dict(link.symbols)
    new: dict[str, Any] = {k: ev(t) for k, t in sym.items() if k in DH_FIELDS}
    if "limits0" in sym:
        new["q_limits"] = (ev(sym["limits0"]), ev(sym["limits1"]))
    inertia = link.inertia
    if inertia is not None and inertia.symbols:
        s = dict(inertia.symbols)
        inertia = LinkInertia(
            mass=ev(s["mass"]) if "mass" in s else inertia.mass,
            com=tuple(ev(s[f"com{i}"]) if f"com{i}" in s else inertia.com[i] for i in range(3)),  # type: ignore[arg-type]
            inertia=tuple(ev(s[f"inertia{i}"]) if f"inertia{i}" in s else inertia.inertia[i] for i in range(6)),  # type: ignore[arg-type]
            **{k: ev(s[k]) if k in s else getattr(inertia, k) for k in ("motor_inertia", "viscous", "coulomb")},
            symbols=inertia.symbols,
        )
    return DHLink(**{**_link_kwargs(link), **new, "inertia": inertia})


def _link_kwargs(link: DHLink) -> dict[str, Any]:
    return {
        "a": link.a, "alpha": link.alpha, "d": link.d, "theta": link.theta, "joint": link.joint,
        "q_limits": link.q_limits, "inertia": link.inertia, "symbols": link.symbols,
    }


def parse_values(text: str | list[Any], n: int | None = None, *, what: str = "q", deg: bool = False,
                 env: Mapping[str, float] | None = None) -> np.ndarray:
    r"""Parse ``"0, pi/4, 90deg"`` (comma or space separated expressions) into floats.

    Values are separated by commas (or semicolons) when there are any outside brackets, else by spaces;
    the whole list may be wrapped in ``[...]`` or ``(...)``; ``\pi`` is read as ``pi``.  An empty value
    (``"1,,2"``, ``"1 2,"``), unbalanced brackets (``"[1,2"``), more than :data:`MAX_VALUES` values or
    more than :data:`MAX_VALUES_TEXT` characters are refused.  The text is read in one linear pass.
    ``deg=True`` reads plain numbers as degrees (``pi`` or ``deg`` in a value still say their unit).
    Raises ParseError naming the value when something is wrong.

    >>> parse_values("[0 0.5]").tolist(), parse_values("(-\\pi/2, 90deg)").round(4).tolist()
    ([0.0, 0.5], [-1.5708, 1.5708])
    """
    if isinstance(text, str):
        parts = split_values(text, what)
    else:
        parts = list(text)
        if len(parts) > MAX_VALUES:
            raise ParseError(f"{what}: more than {MAX_VALUES} values")
    if n is not None and len(parts) != n:
        raise ParseError(f"{what}: expected {n} values, got {len(parts)}")
    out = []
    for i, p in enumerate(parts, start=1):
        try:
            tree = _expr.parse(p)
            if deg and not names_unit(tree):
                tree = ("call", "deg", (tree,))
            out.append(_expr.evaluate(tree, env or {}))
        except ParseError as exc:
            raise ParseError(f"{what}: value {i} ({str(p)[:40]!r}): {exc}") from None
    return np.array(out, dtype=float)


_CLOSE = {"(": ")", "[": "]"}


def split_values(text: str, what: str = "values") -> list[str]:
    """The values of a list text as written (see :func:`parse_values`), checked for balanced brackets and empty
    values; commas (or semicolons) separate when there are any outside brackets, else spaces.

    >>> split_values("[0, pi/4; (pi/2)]"), split_values("0 -pi/3")
    (['0', 'pi/4', '(pi/2)'], ['0', '-pi/3'])
    """
    if len(text) > MAX_VALUES_TEXT:
        raise ParseError(f"{what}: longer than {MAX_VALUES_TEXT} characters")
    t = text.strip().replace("\\pi", "pi")
    opened: list[int] = []
    outer_close = -1
    for i, ch in enumerate(t):
        if ch in "([":
            opened.append(i)
        elif ch in ")]":
            if not opened or _CLOSE[t[opened[-1]]] != ch:
                raise ParseError(f"{what}: unbalanced brackets: {ch!r} at position {i + 1} closes nothing")
            if opened.pop() == 0:
                outer_close = i
    if opened:
        raise ParseError(f"{what}: unbalanced brackets: {t[opened[-1]]!r} at position {opened[-1] + 1} is never closed")
    if t and outer_close == len(t) - 1:
        t = t[1:-1].strip()
    depth = 0
    commas = False
    for ch in t:
        depth += (ch in "([") - (ch in ")]")
        if depth == 0 and ch in ",;":
            commas = True
            break
    parts: list[str] = []
    start = depth = 0
    for i, ch in enumerate(t):
        depth += (ch in "([") - (ch in ")]")
        if depth == 0 and (ch in ",;" if commas else ch.isspace()):
            parts.append(t[start:i].strip())
            start = i + 1
            if len(parts) > MAX_VALUES:
                raise ParseError(f"{what}: more than {MAX_VALUES} values")
    parts.append(t[start:].strip())
    if not commas:
        return [p for p in parts if p]
    for k, p in enumerate(parts, start=1):
        if not p:
            raise ParseError(f"{what}: value {k} is empty (two separators in a row, or one at an end): {text[:60]!r}")
    return parts
