"""Where a claim is evaluated: random or given q, q̇, q̈, a wrench (numbers or symbols), parameter sets, and
the names a derivation defines ('where').

Moved unchanged from ``_engine.py``.
"""

from __future__ import annotations

import re
from typing import Any

import numpy as np

from .. import _expr
from ..errors import ParseError
from ..io import with_parameters
from ..model import DHRobot
from ._latex import parse_math
from ._matrices import split_list
from ._quantities import Point
from ._resolve import robot_resolver
from ._text import split_top
from ._tokens import Ident
from ._values import joint_values

__all__ = ["sample_points", "evaluate_cells", "gravity_names", "where_nodes", "wrench_nodes", "N_POINTS",
           "N_PARAM_SETS", "MAX_NAME", "WRENCH_BASES"]

N_POINTS = 6
N_PARAM_SETS = 2
#: Longest name a claim's 'where' may define.
MAX_NAME = 40


def _sample_q(robot: DHRobot, rng: np.random.Generator) -> np.ndarray:
    lo, hi = robot.q_limits.T
    lo = np.where(np.isfinite(lo), lo, -np.pi)
    hi = np.where(np.isfinite(hi), hi, np.pi)
    return rng.uniform(np.maximum(lo, -np.pi), np.minimum(hi, np.pi))


def gravity_names(robot: DHRobot) -> list[str]:
    """``g`` (the magnitude of the robot's gravity) is a known name unless the robot has a parameter g."""
    return [] if "g" in robot.parameter_values else ["g"]


#: Bases of the names a symbolic wrench may use, with subscript x, y, z or 1 … 6 (``f_x``, ``F_y``, ``n_z``, ``F_1``).
WRENCH_BASES = ("f", "F", "n", "N", "m", "M")


def wrench_nodes(raw: Any, robot: DHRobot) -> list[tuple]:
    """A claim's 'wrench': 6 entries (f, n) or 3 (a pure force), numbers or symbols such as ``f_x``."""
    known = robot_resolver(robot)

    def resolve(ident):
        if ident.dots == 0 and ident.base in WRENCH_BASES and ident.sub in ("x", "y", "z", "1", "2", "3", "4", "5", "6"):
            return ("name", ident.base + ident.sub)
        return known(ident)

    if isinstance(raw, str):
        text = raw.strip().strip("$").strip()
        cells = split_list(text) if text[:1] in "([" else [[c] for c in split_top(text, (",", ";"))]
        items: list[Any] = [c for row in cells or [[text]] for c in row if str(c).strip()]
    elif isinstance(raw, list):
        items = raw
    else:
        items = [raw]
    if len(items) not in (3, 6):
        raise ParseError(f"wrench: expected 6 values (f, n) or 3 (a force), got {len(items)}")
    out = []
    for i, v in enumerate(items, start=1):
        try:
            out.append(_expr.parse(v) if isinstance(v, (int, float)) else parse_math(str(v), resolve, rhs=False))
        except ParseError as exc:
            raise ParseError(f"wrench: value {i} ({str(v)[:40]!r}): {exc}") from None
    zero = ("num", "0")
    return out + [zero] * (6 - len(out))


def sample_points(robot: DHRobot, spec: dict[str, Any], names: set[str], needs, rng, deg: bool, *,
            wrench: list[tuple] | None = None, symbols: list[str] = ()) -> list[Point]:
    """Evaluation points: the claim's q (or random ones), its q̇/wrench (or random), robot parameter sets."""
    params = [k for k, _ in robot.parameters]
    robots = [robot]
    varied = names & (set(params) | {"g"})
    if varied:
        for _ in range(N_PARAM_SETS):
            r = with_parameters(robot, **{k: v * rng.uniform(0.6, 1.4) if v else rng.uniform(0.1, 1.0)
                                          for k, v in robot.parameters if k in names})
            if "g" in names and "g" not in params:  # the symbol g: the same direction, another magnitude
                r = r.replace(gravity=tuple(float(x) * rng.uniform(0.6, 1.4) for x in r.gravity))
            robots.append(r)
    fixed_q = joint_values(spec["q"], robot, "q", deg) if "q" in spec else None
    fixed_qd = joint_values(spec["qd"], robot, "qd", deg) if "qd" in spec else None
    fixed_qdd = joint_values(spec["qdd"], robot, "qdd", deg) if "qdd" in spec else None
    uses_qdd = any(n.startswith("qdd") and n[3:].isdigit() for n in names)
    if "wrench" in needs and wrench is None:
        raise ParseError("this claim needs 'wrench' (6 numbers or symbols f, n; or 3 for a force)")
    uses_q = any(n.startswith("q") and n[1:].isdigit() for n in names)
    uses_qd = any(n.startswith("qd") and n[2:].isdigit() for n in names)
    # a quantity of the rates claimed without 'qd' and without rates (ⁱvᵢ = 0, a constant): it must hold at any
    # rates, so it is checked at random ones
    const_qd = "qd" in needs and fixed_qd is None and not uses_qd
    const_qd = const_qd or ("qdd" in needs and fixed_qdd is None and not uses_qdd)
    n_q = N_POINTS if ((uses_q and fixed_q is None) or (uses_qd and fixed_qd is None) or symbols or const_qd
                       or (uses_qdd and fixed_qdd is None)) else 1
    pts = []
    for r in robots:
        for _ in range(n_q):
            q = fixed_q if fixed_q is not None else _sample_q(robot, rng)
            qd = fixed_qd if fixed_qd is not None else rng.normal(size=robot.dof)
            qdd = fixed_qdd if fixed_qdd is not None else rng.normal(size=robot.dof)
            sym = tuple((s, float(rng.normal())) for s in symbols)
            w = None
            if wrench is not None:
                env = {**r.parameter_values, **dict(sym)}
                w = np.array([_expr.evaluate(nd, env) for nd in wrench], dtype=float)
            pts.append(Point(r, q, qd, w, sym, qdd))
    return pts


def _env(p: Point) -> dict[str, float]:
    env = dict(p.robot.parameters)
    if "g" not in env:
        env["g"] = float(np.linalg.norm(p.robot.gravity))
    env.update(p.symbols)
    for k in range(p.robot.dof):
        env[f"q{k + 1}"] = float(p.q[k])
        if p.qd is not None:
            env[f"qd{k + 1}"] = float(p.qd[k])
        if p.qdd is not None:
            env[f"qdd{k + 1}"] = float(p.qdd[k])
    return env


def where_nodes(raw: Any, robot: DHRobot, extra: list[str]) -> list[tuple[str, tuple]]:
    """A claim's 'where': names a derivation introduces (``k: a_2``, ``x_c: p_x - d_6 a_x``…), each a formula in
    the robot's names and the names defined before it, in order."""
    from ._ik_claims import MAX_WHERE

    if raw is None:
        return []
    if not isinstance(raw, dict):
        raise ParseError("'where' must be a mapping of names to formulas, in evaluation order")
    if len(raw) > MAX_WHERE:
        raise ParseError(f"'where' has {len(raw)} definitions; at most {MAX_WHERE}")
    out: list[tuple[str, tuple]] = []
    for key, text in raw.items():
        name = re.sub(r"[^A-Za-z0-9]", "", str(key)[:10 * MAX_NAME])
        if len(name) > MAX_NAME:
            raise ParseError(f"'where' name longer than {MAX_NAME} characters")
        if not name or name[0].isdigit():
            raise ParseError(f"'where' names must start with a letter, got {str(key)[:40]!r}")
        m = re.fullmatch(r"([A-Za-z]+?)(\d*)", name)
        try:  # a name that already means something (q1, L1, C12, pi, g) cannot be redefined
            meaning = robot_resolver(robot, extra=extra)(Ident(m.group(1), m.group(2))) if m else None
        except ParseError:
            meaning = None
        if meaning is not None or name in ("pi", "e"):
            raise ParseError(f"'where' cannot redefine {name!r}: it already means {_expr.to_text(meaning) if meaning else name}")
        try:
            node = (_expr.parse(text) if isinstance(text, (int, float)) and not isinstance(text, bool)
                    else parse_math(str(text), robot_resolver(robot, extra=extra + [n for n, _ in out]), rhs=False))
        except ParseError as exc:
            raise ParseError(f"where {name}: {exc}") from None
        out.append((name, node))
    return out


def evaluate_cells(cells: list[list[tuple]], p: Point, where: list[tuple[str, tuple]] = ()) -> np.ndarray:
    env = _env(p)
    for name, node in where:
        env[name] = _expr.evaluate(node, env)
    return np.array([[_expr.evaluate(c, env) for c in row] for row in cells], dtype=float)
