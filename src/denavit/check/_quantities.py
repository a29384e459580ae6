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

__all__ = ["Quantity", "QUANTITIES", "quantity", "Point", "frame_index", "axes_frame", "jacobian_in"]


@dataclass(frozen=True)
class Point:
    """Where a claim is evaluated: joint values, rates, wrench (arrays) and the robot (parameter values)."""

    robot: DHRobot
    q: np.ndarray
    qd: np.ndarray | None = None
    wrench: np.ndarray | None = None
    #: Values of the other symbols a claim uses at this point (a symbolic wrench's f_x, …), as (name, value) pairs.
    symbols: tuple[tuple[str, float], ...] = ()
    qdd: np.ndarray | None = None


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


def axes_frame(spec: dict[str, Any]) -> Frame | int:
    """The axes a Jacobian claim is written in: base (J0), tool (Je) or DH frame i (``frame: 3``: ⁱJ)."""
    f = spec.get("frame", "base")
    if isinstance(f, str) and f.strip().isdigit() and len(f.strip()) <= 3:
        f = int(f.strip())
    if isinstance(f, int) and not isinstance(f, bool):
        return f
    try:
        return Frame(f)
    except ValueError:
        raise ParseError(f"'frame' must be base, tool or the index of a DH frame (0 … N), got {str(f)[:40]!r}") from None


def jacobian_in(p: Point, spec: dict[str, Any]) -> np.ndarray:
    """J0, Je, or ⁱJ = blockdiag(R_0_iᵀ, R_0_iᵀ) J0 with R_0_i the world orientation of DH frame i (reference point
    the end-effector origin in every case)."""
    f = axes_frame(spec)
    if not isinstance(f, Frame) and not 0 <= f <= p.robot.n_rows:
        raise ParseError(f"'frame' {f} is not a DH frame of this robot (0 … {p.robot.n_rows})")
    return N.geometric_jacobian(p.robot, p.q, frame=f)


def _jacobian(p: Point, spec: dict[str, Any]) -> np.ndarray:
    J = jacobian_in(p, spec)
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
    return (jacobian_in(p, spec) @ p.qd)[_rows(spec)]


def _torques(p: Point, spec: dict[str, Any]) -> np.ndarray:
    return jacobian_in(p, spec).T @ p.wrench


def frame_index(p: Point, spec: dict[str, Any]) -> int:
    """'index' of a propagation frame: 0 … N (DH frames) or N+1 / "e" (the end effector, after the tool)."""
    n = p.robot.n_rows
    v = spec.get("index")
    if isinstance(v, str) and v.strip().lower() in ("e", "ee", "tool", "end_effector"):
        return n + 1
    return _index(spec, "index", 0, n + 1)


def _omega(p: Point, spec: dict[str, Any]) -> np.ndarray:
    return N.velocity_propagation(p.robot, p.q, p.qd).omega[frame_index(p, spec)]


def _velocity(p: Point, spec: dict[str, Any]) -> np.ndarray:
    return N.velocity_propagation(p.robot, p.q, p.qd).v[frame_index(p, spec)]


def _wrench_frame(spec: dict[str, Any]) -> Frame:
    try:
        return Frame(spec.get("frame", "tool"))
    except ValueError:
        raise ParseError(f"'frame' must be base or tool, got {spec.get('frame')!r}") from None


def _force(p: Point, spec: dict[str, Any]) -> np.ndarray:
    return N.force_propagation(p.robot, p.q, p.wrench, frame=_wrench_frame(spec)).f[frame_index(p, spec)]


def _moment(p: Point, spec: dict[str, Any]) -> np.ndarray:
    return N.force_propagation(p.robot, p.q, p.wrench, frame=_wrench_frame(spec)).n[frame_index(p, spec)]


def _com_row(p: Point, spec: dict[str, Any]) -> tuple[np.ndarray, np.ndarray]:
    """World pose (4×4) of the frame of DH row 'index' and that link's centre of mass in it."""
    if not p.robot.has_dynamics:
        raise ParseError("the robot has no inertial data, so centre-of-mass claims cannot be checked")
    i = _index(spec, "index", 1, p.robot.n_rows)
    link = p.robot.links[i - 1]
    if link.inertia is None:
        raise ParseError(f"DH row {i} has no inertial data (no centre of mass)")
    return _frames(p)[i], np.asarray(link.inertia.com, dtype=float)


def _com_position(p: Point, spec: dict[str, Any]) -> np.ndarray:
    F, c = _com_row(p, spec)
    return F[:3, :3] @ c + F[:3, 3]


def _com_velocity(p: Point, spec: dict[str, Any]) -> np.ndarray:
    F, c = _com_row(p, spec)
    i = _index(spec, "index", 1, p.robot.n_rows)
    prop = N.velocity_propagation(p.robot, p.q, p.qd)  # frame i's ω and origin velocity, in its own axes
    return F[:3, :3] @ (prop.v[i] + np.cross(prop.omega[i], c))  # ṗ_c = R (v_i + ω_i × c), world axes


def _joint_axis(p: Point, spec: dict[str, Any]) -> np.ndarray:
    z, _ = N.joint_axes(p.robot, _frames(p))
    return z[_index(spec, "index", 1, p.robot.dof) - 1]


def _origin(p: Point, spec: dict[str, Any]) -> np.ndarray:
    return _frames(p)[_index(spec, "index", 0, p.robot.n_rows)][:3, 3]


def _energy(which: str) -> Callable[[Point, dict[str, Any]], np.ndarray]:
    def truth(p: Point, spec: dict[str, Any]) -> np.ndarray:
        if not p.robot.has_dynamics:
            raise ParseError("the robot has no inertial data, so energy claims cannot be checked")
        K = N.kinetic_energy(p.robot, p.q, p.qd) if which != "potential" else 0.0
        V = N.potential_energy(p.robot, p.q) if which != "kinetic" else 0.0
        return np.asarray(K - V if which == "lagrangian" else K + V, dtype=float)

    return truth


def _equations_of_motion(p: Point, spec: dict[str, Any]) -> np.ndarray:
    if not p.robot.has_dynamics:
        raise ParseError("the robot has no inertial data, so equations of motion cannot be checked")
    return np.asarray(N.rnea(p.robot, p.q, p.qd, p.qdd), dtype=float)


def _det(p: Point, spec: dict[str, Any]) -> np.ndarray:
    J = jacobian_in(p, spec)
    if "rows" not in spec and p.robot.dof != 6:
        raise ParseError(f"det J needs a square Jacobian: give 'rows' ({p.robot.dof} of vx,vy,vz,wx,wy,wz)")
    J = J[_rows(spec)]
    if J.shape[0] != J.shape[1]:
        raise ParseError(f"det J needs a square Jacobian: 'rows' gives {J.shape[0]} rows for {J.shape[1]} joints")
    return np.asarray(np.linalg.det(J))


def _manipulability(p: Point, spec: dict[str, Any]) -> np.ndarray:
    """Yoshikawa's w = √det(J Jᵀ) of the rows named (all six by default); |det J| for a square block."""
    J = jacobian_in(p, spec)[_rows(spec)]
    return np.asarray(np.sqrt(max(float(np.linalg.det(J @ J.T)), 0.0)))


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


def _christoffel(p: Point, spec: dict[str, Any]) -> np.ndarray:
    """Spong's Christoffel symbols c_ijk = ½(∂M_kj/∂q_i + ∂M_ki/∂q_j − ∂M_ij/∂q_k), shape (n, n, n), [i, j, k]
    (Spong, Hutchinson, Vidyasagar 2006, eq. 7.51: C_kj = Σ_i c_ijk q̇_i), from ∂M/∂q of the CRBA."""
    if not p.robot.has_dynamics:
        raise ParseError("the robot has no inertial data, so dynamics claims cannot be checked")
    dM = N.mass_matrix_derivatives(p.robot, p.q)  # [i, j, k] = ∂M_jk/∂q_i
    return 0.5 * (np.einsum("ikj->ijk", dM) + np.einsum("jki->ijk", dM) - np.einsum("kij->ijk", dM))


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
        Quantity("jacobian", _jacobian, about="geometric Jacobian J0 (frame: base), Je (frame: tool) or ⁱJ in the axes "
                 "of DH frame i (frame: i), rows (v, ω); optional 'column' (1-based) and 'rows' (linear/angular)"),
        Quantity("twist", _twist, ("qd",), about="end-effector twist (v, ω) = J q̇"),
        Quantity("torques", _torques, ("wrench",), about="joint torques τ = Jᵀ F balancing wrench (f, n)"),
        Quantity("mass_matrix", _dynamics("mass_matrix"), about="joint-space inertia matrix M(q)"),
        Quantity("gravity", _dynamics("gravity_torques"), about="gravity torques g(q)"),
        Quantity("coriolis", _dynamics("coriolis_vector"), ("qd",),
                 about="velocity torques c(q, q̇) = C(q, q̇) q̇ (Coriolis and centrifugal)"),
        Quantity("coriolis_matrix", _dynamics("coriolis_matrix"), ("qd",),
                 about="C(q, q̇) from the Christoffel symbols of M (a whole C with C q̇ = c is accepted too)"),
        Quantity("christoffel", _christoffel, about="Spong's Christoffel symbol c_ijk = ½(∂M_kj/∂q_i + ∂M_ki/∂q_j − "
                 "∂M_ij/∂q_k), 'entry': [i, j, k] (C_kj = Σ_i c_ijk q̇_i)"),
        Quantity("omega", _omega, ("qd",), about="ⁱωᵢ: angular velocity of frame 'index' in its own axes "
                 "(velocity propagation; index 0 … N, or e)"),
        Quantity("velocity", _velocity, ("qd",), about="ⁱvᵢ: velocity of the origin of frame 'index' in its own axes"),
        Quantity("force", _force, ("wrench",), about="ⁱfᵢ: force across frame 'index' in its own axes (force "
                 "propagation of the tip wrench; 'frame' tool (default) or base for the wrench's axes)"),
        Quantity("moment", _moment, ("wrench",), about="ⁱnᵢ: moment across frame 'index' about its origin, in its axes"),
        Quantity("joint_axis", _joint_axis, about="z of joint 'index' (1 … n) in world axes: the z_{i-1} (standard DH) "
                 "or z_i (modified) of J_i = [z × (p − p_i); z]"),
        Quantity("origin", _origin, about="world position of the origin of DH frame 'index' (0 … N): the p_i of J_i"),
        Quantity("com_position", _com_position, about="world position of the centre of mass of link 'index' (DH row)"),
        Quantity("com_velocity", _com_velocity, ("qd",), about="world velocity of the centre of mass of link 'index'"),
        Quantity("kinetic_energy", _energy("kinetic"), ("qd",), about="K = ½ q̇ᵀ M(q) q̇"),
        Quantity("potential_energy", _energy("potential"), about="V = −Σ m gᵀ p_c (zero at the base origin)"),
        Quantity("lagrangian", _energy("lagrangian"), ("qd",), about="L = K − V"),
        Quantity("equations_of_motion", _equations_of_motion, ("qd", "qdd"), about="τ = M(q) q̈ + C(q, q̇) q̇ + g(q) "
                 "(+ the robot's friction): the Lagrange or Newton–Euler equations of motion"),
        Quantity("manipulability", _manipulability, about="Yoshikawa's w = √det(J Jᵀ) of the rows named ('rows'; all "
                 "six by default): |det J| for a square block"),
        Quantity("det_jacobian", _det, about="det J (square: 6 joints, or 'rows' naming as many rows as joints); "
                 "a list of factors is read as their product"),
    )
}
_ALIASES = {"eom": "equations_of_motion", "dynamics": "equations_of_motion", "z": "joint_axis", "axis": "joint_axis", "p": "origin", "frame_origin": "origin", "w": "omega", "angular_velocity": "omega", "v": "velocity", "linear_velocity": "velocity", "f": "force",
            "n": "moment", "com": "com_position", "p_c": "com_position", "v_c": "com_velocity", "K": "kinetic_energy",
            "V": "potential_energy", "U": "potential_energy", "L": "lagrangian", "det": "det_jacobian",
            "detJ": "det_jacobian", "A": "link_transform", "T": "transform", "fk": "end_effector", "pose": "end_effector",
            "J": "jacobian", "J0": "jacobian", "Je": "jacobian", "tau": "torques", "M": "mass_matrix", "g": "gravity",
            "c": "coriolis", "C": "coriolis_matrix", "Gamma": "christoffel"}


def quantity(name: Any) -> tuple[Quantity, dict[str, Any]]:
    """The quantity named in a claim (plus spec defaults implied by an alias such as ``Je``)."""
    key = str(name)
    extra: dict[str, Any] = {"frame": "tool"} if key == "Je" else {}
    key = _ALIASES.get(key, key)
    if key not in QUANTITIES:
        raise ParseError(f"unknown quantity {name!r}; choose one of {', '.join(QUANTITIES)}")
    return QUANTITIES[key], extra
