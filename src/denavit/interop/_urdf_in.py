"""URDF in, DH out: the serial chain between two links of a URDF as a DH table, with base, tool and inertias.

The axis geometry that gives the DH rows is :mod:`denavit.interop._urdf_axes` (its notes state the method);
this module walks the chain, builds the robot, folds the inertias and checks the result against the URDF's FK.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass

import numpy as np

from ..errors import DenavitWarning, ModelError, ParseError
from ..model import MAX_JOINTS, Convention, DHLink, DHRobot, JointType, LinkInertia
from ..numeric import forward_kinematics, link_transforms
from ._export import combine_inertia
from ._urdf_axes import FAR_FOOT, dh_geometry
from ._urdf_read import UrdfJoint, UrdfModel, chain_path, read_urdf, subtree_joints

__all__ = ["UrdfImport", "import_urdf", "from_urdf", "urdf_chain_fk", "tidy", "CHECK_SAMPLES", "CHECK_TOL",
           "TIDY_DIGITS", "TIDY_ULPS"]

#: Random configurations of the import's FK self-check.
CHECK_SAMPLES = 200
#: Self-check errors (relative to the chain's size, at least 1 m) beyond which the import warns.
CHECK_TOL = 1e-9


@dataclass(frozen=True)
class UrdfImport:
    """The result of :func:`import_urdf`.

    Attributes
    ----------
    robot : DHRobot
    base_link, tip_link : str
        The URDF links the chain runs between.
    joint_names : tuple of str
        The URDF joints that became the DH rows, in order.
    cases : tuple of str
        Per row, the geometry of that joint's axis and the next one (see :data:`ROW_CASES`).
    position_error, rotation_error : float
        Worst FK difference between the DH model and the URDF chain over ``samples`` random configurations
        (largest entry difference of position [m] and of rotation matrix); a warning is raised beyond
        :data:`CHECK_TOL`.
    notes : tuple of str
        What else the import did (fixed joints folded, branches locked, ...).
    """

    robot: DHRobot
    base_link: str
    tip_link: str
    joint_names: tuple[str, ...]
    cases: tuple[str, ...]
    position_error: float
    rotation_error: float
    notes: tuple[str, ...]
    samples: int = CHECK_SAMPLES


#: Lengths, masses, centres of mass and inertias the import computes (sums, projections) carry rounding noise
#: (0.05 came out 0.050000000000000044, which a written robot file shows): a value within TIDY_ULPS units in the
#: last place of a decimal of TIDY_DIGITS significant digits is taken as that decimal, and one within TIDY_ULPS
#: units in the last place of the quantity's scale (the chain's size; a body's largest inertia) as 0.
TIDY_DIGITS = 12
TIDY_ULPS = 16


def tidy(x: float, scale: float = 0.0) -> float:
    """``x``, or the decimal of :data:`TIDY_DIGITS` significant digits within :data:`TIDY_ULPS` ulps of it, or 0
    when ``|x|`` is within TIDY_ULPS ulps of ``scale``."""
    x = float(x)
    if abs(x) <= TIDY_ULPS * np.spacing(float(scale)):
        return 0.0
    short = float(f"{x:.{TIDY_DIGITS}g}")
    return short if abs(short - x) <= TIDY_ULPS * np.spacing(abs(x)) else x


def urdf_chain_fk(path: list[UrdfJoint], q: np.ndarray) -> np.ndarray:
    """Pose of the chain's last link in its first link's frame at joint values ``q`` (one per moving joint)."""
    T = np.eye(4)
    k = 0
    for j in path:
        T = T @ j.origin
        if j.moving:
            M = np.eye(4)
            if j.kind == "prismatic":
                M[:3, 3] = j.axis * q[k]
            else:
                u, c, s = j.axis, math.cos(q[k]), math.sin(q[k])
                K = np.array([[0, -u[2], u[1]], [u[2], 0, -u[0]], [-u[1], u[0], 0]])
                M[:3, :3] = np.eye(3) + s * K + (1 - c) * (K @ K)  # Rodrigues
            T = T @ M
            k += 1
    return T


def import_urdf(source, base: str | None = None, tip: str | None = None, convention: str = "standard", *,
                xacro: bool = False, rng: np.random.Generator | None = None) -> UrdfImport:
    """Extract the DH model of the serial chain from link ``base`` to link ``tip`` of a URDF, with its report.

    Parameters
    ----------
    source : str or path
        A URDF file, or URDF text (a string starting with ``<``).  Parsed as untrusted XML (no DTD, no
        entities, size and depth bounded); meshes are never read.
    base, tip : str, optional
        Link names; default the URDF's root and its one leaf (a branching tree needs ``tip``).
    convention : {"standard", "modified"}
    xacro : bool
        Expand a xacro document first (needs the optional ``xacrodoc``).  Xacro evaluates Python expressions:
        only for files you trust; a ``*.xacro`` path without it is refused.
    rng : numpy.random.Generator, optional
        For the self-check's random configurations (default: a fixed seed, so reports repeat).

    Returns
    -------
    UrdfImport
        The robot, the URDF joint of each row, each row's axis geometry and the worst FK error of the self-check.

    Raises
    ------
    ParseError
        Bad XML or URDF (naming file, element and line), a chain without moving joints, a ``floating``,
        ``planar`` or ``mimic`` joint on the chain.
    """
    conv = Convention(convention) if convention in ("standard", "modified") else None
    if conv is None:
        raise ParseError(f"convention {str(convention)[:40]!r}: choose one of standard, modified")
    model = read_urdf(source, xacro=xacro)
    base, tip, path = chain_path(model, base, tip)
    moving = _moving_joints(model, path, base, tip)
    P, Z, T, link_pose, link_body = _chain_at_zero(path, base)
    scale = max(1.0, float(np.abs(P).max()), float(np.abs(T[:3, 3]).max()))
    theta, d, a, alpha, cases, F0, approximated = dh_geometry(P, Z, T, scale)
    robot = _robot(model, conv, moving, theta, d, a, alpha, F0, T)
    robot, notes = _with_inertia(robot, model, path, link_pose, link_body, base, scale)
    pos, rot = _self_check(robot, path, rng)
    if pos > CHECK_TOL * scale or rot > CHECK_TOL:
        warnings.warn(f"{model.where}: the DH model differs from the URDF chain by up to {pos:.2g} m and "
                      f"{rot:.2g} in rotation at random configurations (nearly parallel axes?)", DenavitWarning,
                      stacklevel=2)
    notes = _notes(path, moving, approximated) + notes
    return UrdfImport(robot, base, tip, tuple(j.name for j in moving), tuple(cases), pos, rot, notes)


def _moving_joints(model: UrdfModel, path: list[UrdfJoint], base: str, tip: str) -> list[UrdfJoint]:
    """The chain's moving joints; floating, planar and mimic joints on it refused."""
    for j in path:
        if j.kind in ("floating", "planar"):
            raise model.error(f"<joint name={j.name[:40]!r}> (line {j.line}): a {j.kind} joint has no DH row; "
                              "choose --base below it")
        if j.mimic and j.moving:
            raise model.error(f"<joint name={j.name[:40]!r}> (line {j.line}): a mimic joint (coupled to another "
                              "joint) has no independent DH row")
    moving = [j for j in path if j.moving]
    if not moving:
        raise model.error(f"no revolute, continuous or prismatic joint between links {base[:40]!r} and {tip[:40]!r}")
    if len(moving) > MAX_JOINTS:
        raise model.error(f"the chain has {len(moving)} moving joints (at most {MAX_JOINTS})")
    return moving


def _chain_at_zero(path: list[UrdfJoint], base: str):
    """At q = 0, in the base link's frame: axis points P (n, 3) and unit directions Z (n, 3), the tip pose T,
    and every chain link's pose and body (the 0-based moving joint carrying it; -1 for the fixed base)."""
    T = np.eye(4)
    P, Z, link_pose, link_body = [], [], {base: np.eye(4)}, {base: -1}
    for j in path:
        T = T @ j.origin
        if j.moving:
            P.append(T[:3, 3].copy())
            Z.append(T[:3, :3] @ j.axis)
        link_pose[j.child], link_body[j.child] = T.copy(), len(P) - 1
    P, Z = np.array(P), np.array(Z)
    Z /= np.linalg.norm(Z, axis=1, keepdims=True)
    return P, Z, T, link_pose, link_body


def _notes(path: list[UrdfJoint], moving: list[UrdfJoint], approximated: list[int]) -> tuple[str, ...]:
    notes = []
    folded = sum(1 for j in path if not j.moving)
    if folded:
        notes.append(f"{folded} fixed joint{'s' if folded > 1 else ''} folded into the geometry")
    if approximated:
        rows = ", ".join(f"{k + 1} ({moving[k].name})" for k in approximated)
        notes.append(f"rows {rows}: nearly parallel axes (common normal farther than {FAR_FOOT:g} × the arm's "
                     "size) taken as parallel; the self-check shows the error")
    if any(j.kind == "continuous" for j in moving):
        notes.append("continuous joints have no limits")
    empty = [j.name for j in moving if j.limits is not None and j.limits[0] == j.limits[1]]
    if empty:
        notes.append(f"limits with lower = upper read as no limits: {', '.join(empty)}")
    return tuple(notes)


def _robot(model: UrdfModel, conv: Convention, moving: list[UrdfJoint], theta, d, a, alpha, F0, T_tip) -> DHRobot:
    try:
        return _robot_rows(model, conv, moving, theta, d, a, alpha, F0, T_tip)
    except ModelError as exc:
        raise model.error(f"the chain gives no valid DH model: {exc}") from None


def _robot_rows(model: UrdfModel, conv: Convention, moving: list[UrdfJoint], theta, d, a, alpha, F0,
                T_tip) -> DHRobot:
    n = len(moving)
    links = []
    for k, j in enumerate(moving):
        ak, alk = (a[k], alpha[k]) if conv is Convention.STANDARD else ((a[k - 1], alpha[k - 1]) if k else (0.0, 0.0))
        kind = JointType.PRISMATIC if j.kind == "prismatic" else JointType.REVOLUTE
        limits = j.limits if j.limits is None or j.limits[0] < j.limits[1] else None  # [0, 0]: no range given
        links.append(DHLink(a=tidy(ak), alpha=alk, d=tidy(d[k]), theta=theta[k], joint=kind, q_limits=limits))
    names = ", ".join(j.name for j in moving)
    robot = DHRobot(name=model.name, links=tuple(links), convention=conv, base=F0,
                    description=f"imported from URDF; rows are the joints {names}"[:2000])
    Fn = link_transforms(robot, np.zeros(n))[-1]
    tool = np.linalg.solve(Fn, T_tip)
    tool[3] = (0.0, 0.0, 0.0, 1.0)
    return robot.replace(tool=tool)


def _with_inertia(robot: DHRobot, model: UrdfModel, path: list[UrdfJoint], link_pose: dict, link_body: dict,
                  base: str, scale: float) -> tuple[DHRobot, tuple[str, ...]]:
    """Each body's links (and rigid branches hanging from them, locked at 0) as one inertia in its DH frame
    (``scale``: the chain's size [m], for :func:`tidy`)."""
    n = robot.dof
    notes: list[str] = []
    frames = link_transforms(robot, np.zeros(n))  # (n+1, 4, 4) frames {0} … {n} at q = 0, base link axes
    pieces: list[list] = [[] for _ in range(n)]
    locked = 0
    on_path = {j.child for j in path}
    next_on_path = {j.parent: j for j in path}

    def add(link_name: str, T_link: np.ndarray, body: int) -> None:
        inertial = model.links[link_name].inertial
        if inertial is None or body < 0:
            return
        F = frames[body + 1]
        Tp = np.linalg.solve(F, T_link @ inertial.pose)  # inertial frame in DH frame {body+1}
        R = Tp[:3, :3]
        pieces[body].append((inertial.mass, Tp[:3, 3], R @ inertial.inertia @ R.T))

    for name in [base] + [j.child for j in path]:
        body = link_body[name]
        add(name, link_pose[name], body)
        for j, T_rel in subtree_joints(model, name, next_on_path.get(name)):
            if j.child in on_path:
                continue
            locked += j.moving
            add(j.child, link_pose[name] @ T_rel, body)
    if locked and any(pieces):
        notes.append(f"{locked} joint{'s' if locked > 1 else ''} off the chain locked at 0 (their links' inertia "
                      "rides on the chain)")
    if not any(pieces) and not any(j.damping or j.friction for j in path):
        return robot, tuple(notes)
    links = list(robot.links)
    moving = [j for j in path if j.moving]
    for k in range(n):
        m, c, I = combine_inertia(pieces[k]) if pieces[k] else (0.0, np.zeros(3), np.zeros((3, 3)))
        try:
            i6 = (I[0, 0], I[1, 1], I[2, 2], I[0, 1], I[0, 2], I[1, 2])
            li = LinkInertia(mass=tidy(m), com=tuple(tidy(v, scale) for v in c),
                             inertia=tuple(tidy(v, float(np.abs(I).max())) for v in i6),
                             viscous=moving[k].damping, coulomb=moving[k].friction)
        except ModelError as exc:
            raise model.error(f"the links moved by joint {moving[k].name[:40]!r}: {exc}") from None
        links[k] = DHLink(a=links[k].a, alpha=links[k].alpha, d=links[k].d, theta=links[k].theta,
                          joint=links[k].joint, q_limits=links[k].q_limits, inertia=li)
    return robot.replace(links=tuple(links)), tuple(notes)


def _self_check(robot: DHRobot, path: list[UrdfJoint], rng: np.random.Generator | None) -> tuple[float, float]:
    rng = np.random.default_rng(20261202) if rng is None else rng
    prismatic = np.array([t is JointType.PRISMATIC for t in robot.joint_types])
    q = rng.uniform(-math.pi, math.pi, (CHECK_SAMPLES, robot.dof))
    q[:, prismatic] /= math.pi  # ±1 m
    T_dh = forward_kinematics(robot, q)  # (S, 4, 4)
    pos = rot = 0.0
    for s in range(CHECK_SAMPLES):
        T_u = urdf_chain_fk(path, q[s])
        pos = max(pos, float(np.abs(T_dh[s, :3, 3] - T_u[:3, 3]).max()))
        rot = max(rot, float(np.abs(T_dh[s, :3, :3] - T_u[:3, :3]).max()))
    return pos, rot


def from_urdf(source, base: str | None = None, tip: str | None = None, convention: str = "standard", *,
              xacro: bool = False) -> DHRobot:
    """The DH model of a URDF's serial chain from link ``base`` to link ``tip`` (see :func:`import_urdf`).

    Examples
    --------
    >>> import denavit
    >>> urdf = '''<robot name="r1"><link name="a"/><link name="b"/>
    ...   <joint name="j" type="revolute"><parent link="a"/><child link="b"/>
    ...     <origin xyz="0 0 0.5"/><axis xyz="0 0 1"/><limit lower="-1" upper="1"/></joint></robot>'''
    >>> robot = denavit.from_urdf(urdf)
    >>> robot.links[0].d, robot.links[0].q_limits
    (0.5, (-1.0, 1.0))
    """
    return import_urdf(source, base, tip, convention, xacro=xacro).robot
