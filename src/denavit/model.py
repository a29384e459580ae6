"""The robot model: a frozen, hashable description of a serial arm by its Denavit–Hartenberg table.

The model holds data only (no joint state, no algorithms).  Numbers are floats in SI units and
radians; where a value came from an expression of named parameters (``d: H1``), the expression text
is kept in ``DHLink.symbols`` so the symbolic engine can keep ``H1`` as a symbol.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from enum import Enum
from typing import Any

import numpy as np

from ._model_checks import (INERTIA_TOLERANCE, MAX_ANGLE, MAX_JOINTS, MAX_MAGNITUDE, MAX_POSES, POSE_LIMIT_TOL,
                            TRIANGLE_TOLERANCE, check_inertia_tensor, checked_poses, checked_transform, finite)
from .errors import ModelError

__all__ = [
    "Convention",
    "JointType",
    "Frame",
    "LinkInertia",
    "DHLink",
    "DHRobot",
    "sampling_ranges",
    "IDENTITY",
    "DH_FIELDS",
    "INERTIA_ORDER",
    "MAX_MAGNITUDE",
    "MAX_ANGLE",
    "MAX_JOINTS",
    "MAX_POSES",
    "POSE_LIMIT_TOL",
    "INERTIA_TOLERANCE",
    "TRIANGLE_TOLERANCE",
]

IDENTITY: tuple[tuple[float, ...], ...] = (
    (1.0, 0.0, 0.0, 0.0),
    (0.0, 1.0, 0.0, 0.0),
    (0.0, 0.0, 1.0, 0.0),
    (0.0, 0.0, 0.0, 1.0),
)
DH_FIELDS = ("a", "alpha", "d", "theta")
INERTIA_ORDER = ("Ixx", "Iyy", "Izz", "Ixy", "Ixz", "Iyz")


class Convention(str, Enum):
    """Which DH convention a table uses.

    ``STANDARD`` (distal; Spong, Siciliano):  A_i = Rz(θ_i) Tz(d_i) Tx(a_i) Rx(α_i).
    ``MODIFIED`` (proximal; Craig):            A_i = Rx(α_{i-1}) Tx(a_{i-1}) Rz(θ_i) Tz(d_i);
    in a modified row the ``a`` and ``alpha`` fields hold a_{i-1} and α_{i-1}.
    """

    STANDARD = "standard"
    MODIFIED = "modified"


class Frame(str, Enum):
    """Which axes a Jacobian, twist or wrench is expressed in.

    ``BASE``: the world/base axes (J0); ``TOOL``: the end-effector axes (Je).  Both use the
    end-effector origin as reference point and rows (v, ω).
    """

    BASE = "base"
    TOOL = "tool"


class JointType(str, Enum):
    """Revolute (variable in θ), prismatic (variable in d) or fixed (no variable)."""

    REVOLUTE = "revolute"
    PRISMATIC = "prismatic"
    FIXED = "fixed"


@dataclass(frozen=True, slots=True)
class LinkInertia:
    """Inertial data of one link, expressed in that link's DH frame {i}.

    Attributes
    ----------
    mass : float
        Mass [kg].
    com : tuple of 3 floats
        Centre of mass in frame {i} [m].
    inertia : tuple of 6 floats
        Inertia tensor about the centre of mass, axes of frame {i}, in the order
        (Ixx, Iyy, Izz, Ixy, Ixz, Iyz) [kg m²]; products are the tensor entries (I[0,1] = Ixy).
    motor_inertia : float
        Rotor inertia reflected to the joint side (G² Jm) [kg m²], added to M's diagonal.
    viscous, coulomb : float
        Joint friction: τ_f = viscous·q̇ + coulomb·sign(q̇).
    symbols : tuple of (field, expression) pairs
        Expression text of fields written with named parameters (``mass`` → ``"m1"``,
        ``com1`` → ``"Lc1"``, ``inertia2`` → ``"I1"``), for the symbolic engine.
    """

    mass: float = 0.0
    com: tuple[float, float, float] = (0.0, 0.0, 0.0)
    inertia: tuple[float, float, float, float, float, float] = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0)
    motor_inertia: float = 0.0
    viscous: float = 0.0
    coulomb: float = 0.0
    symbols: tuple[tuple[str, str], ...] = ()

    def __post_init__(self) -> None:
        if finite(self.mass, "mass", MAX_MAGNITUDE, " kg") < 0:
            raise ModelError(f"mass must be non-negative, got {self.mass!r}")
        if len(self.com) != 3:
            raise ModelError(f"com must have 3 values, got {len(self.com)}")
        if len(self.inertia) != 6:
            raise ModelError(f"inertia must have 6 values {INERTIA_ORDER}, got {len(self.inertia)}")
        object.__setattr__(self, "mass", float(self.mass))
        object.__setattr__(self, "com", tuple(finite(c, "com", MAX_MAGNITUDE, " m") for c in self.com))
        object.__setattr__(self, "inertia", tuple(finite(c, "inertia", MAX_MAGNITUDE, " kg m²") for c in self.inertia))
        for name in ("motor_inertia", "viscous", "coulomb"):
            if finite(getattr(self, name), name, MAX_MAGNITUDE) < 0:
                raise ModelError(f"{name} must be non-negative, got {getattr(self, name)!r}")
            object.__setattr__(self, name, float(getattr(self, name)))
        check_inertia_tensor(self.inertia_matrix, self.mass)

    @property
    def inertia_matrix(self) -> np.ndarray:
        """The 3×3 inertia tensor about the centre of mass, frame {i} axes (a fresh array)."""
        ixx, iyy, izz, ixy, ixz, iyz = self.inertia
        return np.array([[ixx, ixy, ixz], [ixy, iyy, iyz], [ixz, iyz, izz]], dtype=float)


@dataclass(frozen=True, slots=True)
class DHLink:
    """One row of a DH table.

    ``a``, ``alpha``, ``d``, ``theta`` are the constant parts [m, rad]; the joint variable q is
    added to ``theta`` (revolute) or ``d`` (prismatic), so a revolute row's ``theta`` is its offset.
    In a ``MODIFIED`` robot, ``a`` and ``alpha`` of row i are a_{i-1} and α_{i-1}.
    ``symbols`` keeps the expression text of fields written with parameters (``("d", "H1")``; the limits
    as ``limits0``/``limits1`` when they use parameters), so they can be re-evaluated for new values.
    """

    a: float = 0.0
    alpha: float = 0.0
    d: float = 0.0
    theta: float = 0.0
    joint: JointType = JointType.REVOLUTE
    q_limits: tuple[float, float] | None = None
    inertia: LinkInertia | None = None
    symbols: tuple[tuple[str, str], ...] = ()

    def __post_init__(self) -> None:
        for name in DH_FIELDS:
            angle = name in ("alpha", "theta")
            bound, unit = (MAX_ANGLE, " rad") if angle else (MAX_MAGNITUDE, " m")
            object.__setattr__(self, name, finite(getattr(self, name), name, bound, unit))
        if not isinstance(self.joint, JointType):
            try:
                object.__setattr__(self, "joint", JointType(self.joint))
            except ValueError:
                choices = ", ".join(j.value for j in JointType)
                raise ModelError(f"unknown joint type {self.joint!r}; choose one of {choices}") from None
        if self.q_limits is not None:
            if self.joint is JointType.FIXED:
                raise ModelError("a fixed row has no joint variable, so it cannot have limits")
            if len(self.q_limits) != 2:
                raise ModelError(f"limits must be [low, high], got {self.q_limits!r}")
            bound, unit = (MAX_ANGLE, " rad") if self.joint is JointType.REVOLUTE else (MAX_MAGNITUDE, " m")
            lo, hi = (finite(v, "limit", bound, unit) for v in self.q_limits)
            if lo > hi:
                raise ModelError(f"limits low > high: [{lo}, {hi}]")
            object.__setattr__(self, "q_limits", (lo, hi))
        for key, _ in self.symbols:
            if key not in DH_FIELDS and key not in ("limits0", "limits1"):
                raise ModelError(f"unknown DH field {key!r} in symbols")

    @property
    def is_joint(self) -> bool:
        """True for revolute and prismatic rows."""
        return self.joint is not JointType.FIXED

    def expression(self, field_name: str) -> str:
        """The expression text of a DH field (its number printed if none was given)."""
        return dict(self.symbols).get(field_name, repr(getattr(self, field_name)))


@dataclass(frozen=True)
class DHRobot:
    """A serial arm: DH rows from base to tip plus base/tool transforms and gravity.

    Frames: {0} is the base DH frame, {i} the frame attached by row i (fixed rows included).
    World pose of the end effector: ``T_w_e = base @ A_1 ⋯ A_N @ tool``.

    Attributes
    ----------
    name : str
    links : tuple of DHLink
        Rows base to tip; fixed rows (no variable) may stand anywhere.
    convention : Convention
    base, tool : 4×4 nested tuples
        Pose of {0} in the world frame; pose of the end effector in {N}.
    gravity : 3-tuple
        Gravity acceleration in the world frame [m/s²].
    parameters : tuple of (name, value)
        Named constants used by the ``symbols`` of links and inertias, with their values.
    poses : tuple of (name, q)
        Named configurations (``qz`` zero, ``qr`` ready, …), each ``q`` a tuple of ``dof`` joint values [rad, m]
        within the joint limits; at most :data:`MAX_POSES`.
    symbols : tuple of (key, expression)
        Expression text of gravity and base/tool entries written with parameters (``gravity2`` → ``"-g"``,
        ``base.xyz0``…``base.rpy2`` or ``base.m0``…``base.m15``, likewise ``tool``), so
        :func:`denavit.io.with_parameters` can re-evaluate them.
    """

    name: str
    links: tuple[DHLink, ...]
    convention: Convention = Convention.STANDARD
    base: tuple[tuple[float, ...], ...] = IDENTITY
    tool: tuple[tuple[float, ...], ...] = IDENTITY
    gravity: tuple[float, float, float] = (0.0, 0.0, -9.81)
    parameters: tuple[tuple[str, float], ...] = ()
    description: str = ""
    source: str = ""
    poses: tuple[tuple[str, tuple[float, ...]], ...] = ()
    symbols: tuple[tuple[str, str], ...] = ()
    #: The angle unit the robot's file was written in ("rad" or "deg"): how tables show angles to people.
    #: Presentation only: the model holds radians, and two robots differing only here are equal.
    angle_unit: str = field(default="rad", compare=False)
    _joint_rows: tuple[int, ...] = field(init=False, repr=False, compare=False, hash=False, default=())

    def __post_init__(self) -> None:
        if self.angle_unit not in ("rad", "deg"):
            raise ModelError(f"angle_unit must be 'rad' or 'deg', got {str(self.angle_unit)[:20]!r}")
        if not isinstance(self.convention, Convention):
            try:
                object.__setattr__(self, "convention", Convention(self.convention))
            except ValueError:
                raise ModelError(
                    f"unknown convention {self.convention!r}; choose one of standard, modified"
                ) from None
        links = tuple(self.links)
        if not links:
            raise ModelError("a robot needs at least one DH row")
        if not all(isinstance(link, DHLink) for link in links):
            raise ModelError("links must be DHLink values")
        object.__setattr__(self, "links", links)
        rows = tuple(i for i, link in enumerate(links) if link.is_joint)
        if not rows:
            raise ModelError("a robot needs at least one joint (a row with q)")
        if len(rows) > MAX_JOINTS:
            raise ModelError(f"too many joints ({len(rows)}; at most {MAX_JOINTS})")
        object.__setattr__(self, "_joint_rows", rows)
        object.__setattr__(self, "base", checked_transform(self.base, "base"))
        object.__setattr__(self, "tool", checked_transform(self.tool, "tool"))
        g = tuple(finite(x, "gravity", MAX_MAGNITUDE, " m/s²") for x in self.gravity)
        if len(g) != 3:
            raise ModelError(f"gravity must have 3 components, got {len(g)}")
        object.__setattr__(self, "gravity", g)
        object.__setattr__(self, "parameters", tuple((str(k), finite(v, f"parameter {k}")) for k, v in self.parameters))
        object.__setattr__(self, "poses", checked_poses(self.poses, self.q_limits))

    # --- trivial derived properties -------------------------------------------------------------
    @property
    def dof(self) -> int:
        """Number of joint variables."""
        return len(self._joint_rows)

    @property
    def n_rows(self) -> int:
        """Number of DH rows, fixed rows included."""
        return len(self.links)

    @property
    def joint_rows(self) -> tuple[int, ...]:
        """Row index (0-based) of each joint variable."""
        return self._joint_rows

    @property
    def joints(self) -> tuple[DHLink, ...]:
        """The rows that carry a joint variable, in order."""
        return tuple(self.links[i] for i in self._joint_rows)

    @property
    def joint_types(self) -> tuple[JointType, ...]:
        return tuple(link.joint for link in self.joints)

    @property
    def q_limits(self) -> np.ndarray:
        """Joint limits, shape (dof, 2); ±inf where a joint has none (a fresh array)."""
        out = np.empty((self.dof, 2))
        for k, link in enumerate(self.joints):
            out[k] = link.q_limits if link.q_limits is not None else (-np.inf, np.inf)
        return out

    def sampling_ranges(self, travel: float = 1.0) -> np.ndarray:
        """Where each joint is sampled or swept, shape (dof, 2): its limits, or for a joint without limits one
        turn [−π, π] (revolute) or [−travel, travel] [m] (prismatic: a length scale of the caller's, having no
        natural span).  See :func:`sampling_ranges`."""
        return sampling_ranges(self.q_limits, [t is JointType.REVOLUTE for t in self.joint_types], travel)

    @property
    def base_matrix(self) -> np.ndarray:
        return np.array(self.base, dtype=float)

    @property
    def tool_matrix(self) -> np.ndarray:
        return np.array(self.tool, dtype=float)

    @property
    def parameter_values(self) -> dict[str, float]:
        return dict(self.parameters)

    @property
    def has_dynamics(self) -> bool:
        """True when every joint row carries inertial data."""
        return all(link.inertia is not None for link in self.joints)

    def replace(self, **changes: Any) -> "DHRobot":
        """A copy with some fields changed (validated again).

        Named poses belong to the arm they were written for: when ``links`` change and ``poses`` is not given,
        the copy keeps only the poses that still fit its joints and limits (a pose given explicitly must fit).
        """
        if "links" in changes and "poses" not in changes and self.poses:
            probe = replace(self, poses=(), **changes)
            lim = probe.q_limits
            changes["poses"] = tuple(
                (name, q) for name, q in self.poses
                if len(q) == len(lim) and all(lo - POSE_LIMIT_TOL <= v <= hi + POSE_LIMIT_TOL
                                              for v, (lo, hi) in zip(q, lim))
            )
        return replace(self, **changes)

    # --- presentation (delegated to denavit.display) ---------------------------------------------
    def __str__(self) -> str:
        """The DH table as text (see :func:`denavit.dh_table`)."""
        from .display import dh_table

        return dh_table(self)

    def __repr__(self) -> str:
        from .display import robot_summary

        return robot_summary(self)

    def _repr_html_(self) -> str:
        from .display import robot_html

        return robot_html(self)

    def _repr_markdown_(self) -> str:
        from .display import dh_table

        return dh_table(self, fmt="markdown")


def inertial_rows(robot: DHRobot) -> list[tuple[int, int, LinkInertia]]:
    """``(row, body, inertia)`` for every row with inertial data that moves.

    ``body`` is the 0-based joint that carries the row: a fixed row's inertia belongs rigidly to the
    preceding moving link; rows before the first joint do not move and are left out.
    """
    out = []
    body = -1
    for row, link in enumerate(robot.links):
        body += link.is_joint
        if link.inertia is not None and body >= 0:
            out.append((row, body, link.inertia))
    return out


def sampling_ranges(limits, revolute, travel: float = 1.0) -> np.ndarray:
    """The one definition of where joints are sampled or swept: ``limits`` (n, 2) with an infinite end replaced
    by ∓π for a revolute joint (``revolute[k]``: one turn [−π, π] without limits) or by ∓``travel`` [m] for a
    prismatic one; where the other end is finite and lies beyond that, by that end ∓ 2π (∓ 2·travel) instead (a
    model's limits are finite or absent: one-sided limits come from callers' own arrays).  The middle,
    ``ranges.mean(axis=1)``, is the limits' middle, or 0 for a joint without limits."""
    lim = np.asarray(limits, dtype=float)
    span = np.where(np.asarray(revolute, dtype=bool), np.pi, float(travel))
    lo, hi = lim[:, 0], lim[:, 1]
    fin_lo, fin_hi = np.isfinite(lo), np.isfinite(hi)
    return np.stack([np.where(fin_lo, lo, np.where(fin_hi & (hi <= -span), hi - 2 * span, -span)),
                     np.where(fin_hi, hi, np.where(fin_lo & (lo >= span), lo + 2 * span, span))], axis=1)
