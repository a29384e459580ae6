"""The quantities a claim can name, and their true values from the library's numeric engine.

Each quantity is a function ``truth(robot, point, spec) -> ndarray`` where ``point`` holds the joint
values (``q``, and ``qd``/``wrench`` when needed).  The true values come from denavit's numeric engine;
the claimed values from the person's formula, read by :mod:`denavit.check._latex`: two independent routes.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Callable

import numpy as np

from .. import numeric as N
from ..errors import ParseError
from ..model import DHRobot, Frame

__all__ = ["Quantity", "QUANTITIES", "quantity", "Point"]


@dataclass(frozen=True)
class Point:
    """Where a claim is evaluated: joint values, rates, wrench (arrays) and the robot (parameter values)."""

    robot: DHRobot
    q: np.ndarray
    qd: np.ndarray | None = None
    wrench: np.ndarray | None = None


@dataclass(frozen=True)
class Quantity:
    name: str
    truth: Callable[[Point, dict[str, Any]], np.ndarray]
    needs: tuple[str, ...] = ()
    about: str = ""
    fk_like: bool = False  # a pose or part of one: convention and frame hints apply


def _frames(p: Point) -> np.ndarray:
    return N.link_transforms(p.robot, p.q)  # (N+1, 4, 4), world frames


def _index(spec: dict[str, Any], key: str, lo: int, hi: int, default: int | None = None) -> int:
    v = spec.get(key, default)
    if v is None:
        raise ParseError(f"'{key}' is required for this quantity (an integer from {lo} to {hi})")
    if isinstance(v, bool) or not isinstance(v, int) or not lo <= v <= hi:
        raise ParseError(f"'{key}' must be an integer from {lo} to {hi}, got {v!r}")
    return v


def _link(p: Point, spec: dict[str, Any]) -> np.ndarray:
    F = _frames(p)
    i = _index(spec, "index", 1, p.robot.n_rows)
    return np.linalg.solve(F[i - 1], F[i])


def _transform(p: Point, spec: dict[str, Any]) -> np.ndarray:
    F = _frames(p)
    n = p.robot.n_rows
    i = _index(spec, "from", 0, n, 0)
    j = _index(spec, "to", 0, n, n)
    return np.linalg.solve(F[i], F[j])


def _end_effector(p: Point, spec: dict[str, Any]) -> np.ndarray:
    return N.forward_kinematics(p.robot, p.q)


def _frame(spec: dict[str, Any]) -> Frame:
    try:
        return Frame(spec.get("frame", "base"))
    except ValueError:
        raise ParseError(f"'frame' must be base or tool, got {spec.get('frame')!r}") from None


def _jacobian(p: Point, spec: dict[str, Any]) -> np.ndarray:
    J = N.geometric_jacobian(p.robot, p.q, frame=_frame(spec))
    J = J[_rows(spec)]
    if "column" in spec:
        return J[:, _index(spec, "column", 1, p.robot.dof) - 1]
    return J


def _rows(spec: dict[str, Any]) -> list[int]:
    """The task rows a claim names: all, linear, angular, planar (vx, vy, ωz) or names such as ``vx,vy,wz``."""
    rows = spec.get("rows", "all")
    named = {"all": "vx,vy,vz,wx,wy,wz", "linear": "vx,vy,vz", "angular": "wx,wy,wz", "planar": "vx,vy,wz"}
    try:
        return N.select_rows(named.get(rows, rows) if isinstance(rows, str) else rows)
    except (ValueError, TypeError, AttributeError):
        raise ParseError(f"'rows' must be all, linear, angular, planar or row names such as vx,vy,wz; got "
                         f"{str(rows)[:40]!r}") from None


def _twist(p: Point, spec: dict[str, Any]) -> np.ndarray:
    return (N.geometric_jacobian(p.robot, p.q, frame=_frame(spec)) @ p.qd)[_rows(spec)]


def _torques(p: Point, spec: dict[str, Any]) -> np.ndarray:
    return N.geometric_jacobian(p.robot, p.q, frame=_frame(spec)).T @ p.wrench


def _dynamics(name: str) -> Callable[[Point, dict[str, Any]], np.ndarray]:
    def truth(p: Point, spec: dict[str, Any]) -> np.ndarray:
        fn = getattr(N, name, None)
        if fn is None:
            raise ParseError(f"this installation of denavit has no {name}() yet, so this claim cannot be checked")
        if not p.robot.has_dynamics:
            raise ParseError("the robot has no inertial data, so dynamics claims cannot be checked")
        rates = name in ("coriolis_vector", "coriolis_matrix")
        return np.asarray(fn(p.robot, p.q, p.qd) if rates else fn(p.robot, p.q), dtype=float)

    return truth


QUANTITIES: dict[str, Quantity] = {
    q.name: q
    for q in (
        Quantity("link_transform", _link, about="A_i = T_{i-1,i} of DH row 'index' (1-based)", fk_like=True),
        Quantity("transform", _transform, about="T_{from,to}: pose of DH frame 'to' in frame 'from' "
                 "(defaults 0 and the last row; base and tool not applied)", fk_like=True),
        Quantity("end_effector", _end_effector, about="world pose base · A_1 ⋯ A_N · tool", fk_like=True),
        Quantity("position", lambda p, s: _end_effector(p, s)[:3, 3], about="end-effector position (world)",
                 fk_like=True),
        Quantity("rotation", lambda p, s: _end_effector(p, s)[:3, :3], about="end-effector orientation (world)",
                 fk_like=True),
        Quantity("jacobian", _jacobian, about="geometric Jacobian J0 (frame: base) or Je (frame: tool), rows "
                 "(v, ω); optional 'column' (1-based) and 'rows' (linear/angular)"),
        Quantity("twist", _twist, ("qd",), about="end-effector twist (v, ω) = J q̇"),
        Quantity("torques", _torques, ("wrench",), about="joint torques τ = Jᵀ F balancing wrench (f, n)"),
        Quantity("mass_matrix", _dynamics("mass_matrix"), about="joint-space inertia matrix M(q)"),
        Quantity("gravity", _dynamics("gravity_torques"), about="gravity torques g(q)"),
        Quantity("coriolis", _dynamics("coriolis_vector"), ("qd",),
                 about="velocity torques c(q, q̇) = C(q, q̇) q̇ (Coriolis and centrifugal)"),
        Quantity("coriolis_matrix", _dynamics("coriolis_matrix"), ("qd",),
                 about="C(q, q̇) from the Christoffel symbols of M (a whole C with C q̇ = c is accepted too)"),
    )
}
_ALIASES = {"A": "link_transform", "T": "transform", "fk": "end_effector", "pose": "end_effector",
            "J": "jacobian", "J0": "jacobian", "Je": "jacobian", "tau": "torques", "M": "mass_matrix", "g": "gravity",
            "c": "coriolis", "C": "coriolis_matrix"}


def quantity(name: Any) -> tuple[Quantity, dict[str, Any]]:
    """The quantity named in a claim (plus spec defaults implied by an alias such as ``Je``)."""
    key = str(name)
    extra: dict[str, Any] = {"frame": "tool"} if key == "Je" else {}
    key = _ALIASES.get(key, key)
    if key not in QUANTITIES:
        raise ParseError(f"unknown quantity {name!r}; choose one of {', '.join(QUANTITIES)}")
    return QUANTITIES[key], extra
