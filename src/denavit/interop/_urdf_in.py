"""URDF in, DH out: the serial chain between two links of a URDF as a DH table, with base, tool and inertias.

The axis geometry that gives the DH rows is :mod:`denavit.interop._urdf_axes` (its notes state the method); this
module walks the chain, builds the robot (URDF rounding taken out: ``._urdf_snap``), folds the inertias and
checks the result against the URDF's FK."""

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
from ._urdf_read import UrdfJoint, UrdfModel, chain_path, default_tip, read_urdf, subtree_joints
from ._urdf_snap import snap_angle, snap_pose

__all__ = ["UrdfImport", "import_urdf", "from_urdf", "urdf_chain_fk", "tidy", "nearest_physical_inertia",
           "INERTIA_CHOICES", "URDF_GRAVITY", "CHECK_SAMPLES", "CHECK_TOL", "TIDY_DIGITS", "TIDY_ULPS"]

#: What :func:`import_urdf` does with the links' inertial data (``inertia=``; ``--fix-inertia``, ``--no-inertia``).
INERTIA_CHOICES = ("check", "fix", "none")
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
                xacro: bool = False, rng: np.random.Generator | None = None, inertia: str = "check") -> UrdfImport:
    """Extract the DH model of the serial chain from link ``base`` to link ``tip`` of a URDF, with its report.

    Parameters
    ----------
    source : str or path
        A URDF file, or URDF text (a string starting with ``<``).  Parsed as untrusted XML (no DTD, no
        entities, size and depth bounded); meshes are never read.
    base, tip : str, optional
        Link names; default the URDF's root and :func:`~denavit.interop.default_tip`'s choice, said in the notes.
    convention : {"standard", "modified"}
    xacro : bool
        Expand a xacro document first (needs the optional ``xacrodoc``).  Xacro evaluates Python expressions:
        only for files you trust; a ``*.xacro`` path without it is refused.
    rng : numpy.random.Generator, optional
        For the self-check's random configurations (default: a fixed seed, so reports repeat).
    inertia : {"check", "fix", "none"}
        What to do with the links' inertial data.  ``"check"``: used when every link's tensor is one a rigid body
        can have; a link's tensor that breaks the triangle inequality (xArm6's link 3, 13.5 % off; Pinocchio
        and pybullet load it) draws a warning naming the ``<link>`` and its line, and the arm is imported
        without inertial data (its kinematics are not refused).  ``"fix"``: each such tensor is replaced by the
        nearest physical one (:func:`nearest_physical_inertia`), stated in the notes.  ``"none"``: no inertial
        data at all (kinematics only).

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
    if convention not in ("standard", "modified"):
        raise ParseError(f"convention {str(convention)[:40]!r}: choose one of standard, modified")
    if inertia not in INERTIA_CHOICES:
        raise ParseError(f"inertia {str(inertia)[:40]!r}: choose one of {', '.join(INERTIA_CHOICES)}")
    model, conv, given = read_urdf(source, xacro=xacro), Convention(convention), tip
    base, tip, path = chain_path(model, base, tip)
    why = "" if given is not None else default_tip(model, base)[1]  # the choice, said in the notes
    moving = _moving_joints(model, path, base, tip)
    P, Z, T, link_pose, link_body = _chain_at_zero(path, base)
    scale = max(1.0, float(np.abs(P).max()), float(np.abs(T[:3, 3]).max()))
    theta, d, a, alpha, cases, F0, approximated = dh_geometry(P, Z, T, scale)
    robot = _robot(model, conv, moving, theta, d, a, alpha, F0, T)
    robot, gravity_notes = _gravity_in_base(robot, model, base)
    model, inertia_notes = _physical_inertials(model, inertia)
    robot, notes = _with_inertia(robot, model, path, link_pose, link_body, base, scale)
    pos, rot = _self_check(robot, path, rng)
    if pos > CHECK_TOL * scale or rot > CHECK_TOL:
        warnings.warn(f"{model.where}: the DH model differs from the URDF chain by up to {pos:.2g} m and "
                      f"{rot:.2g} in rotation at random configurations (nearly parallel axes?)", DenavitWarning,
                      stacklevel=2)
    chosen = (f"end link {tip} (chosen: {why}; --tip chooses another)",) * bool(why)
    notes = chosen + _notes(path, moving, approximated) + gravity_notes + inertia_notes + notes
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
        links.append(DHLink(a=tidy(ak), alpha=snap_angle(alk), d=tidy(d[k]), theta=snap_angle(theta[k]), joint=kind,
                            q_limits=limits))
    names = ", ".join(j.name for j in moving)
    robot = DHRobot(name=model.name, links=tuple(links), convention=conv, base=snap_pose(F0),
                    description=f"imported from URDF; rows are the joints {names}"[:2000])
    Fn = link_transforms(robot, np.zeros(n))[-1]
    tool = np.linalg.solve(Fn, T_tip)
    tool[3] = (0.0, 0.0, 0.0, 1.0)
    return robot.replace(tool=snap_pose(tool))


#: Gravity of a URDF, in its root link's frame [m/s²] (URDF has no gravity element; ROS and simulators use -z).
URDF_GRAVITY = (0.0, 0.0, -9.81)


def _gravity_in_base(robot: DHRobot, model: UrdfModel, base: str) -> tuple[DHRobot, tuple[str, ...]]:
    """The robot's gravity in the ``base`` link's frame: g_base = R_root_baseᵀ g_root, with R_root_base the base
    link's orientation in the URDF's root frame when the joints above it are at 0 (their ``origin`` rotations
    composed).  A base that is the root, or sits in it unturned, keeps (0, 0, -9.81)."""
    R = np.eye(3)
    link, seen = base, 0
    while link in model.parent_joint and seen <= len(model.links):  # up to the root (a cycle was refused earlier)
        j = model.parent_joint[link]
        R = j.origin[:3, :3] @ R
        link, seen = j.parent, seen + 1
    g = R.T @ np.array(URDF_GRAVITY)
    if np.array_equal(R, np.eye(3)):
        return robot, ()
    g = np.where(np.abs(g) < 1e-15 * 9.81, 0.0, g)  # rounding noise of the rotation
    note = (f"gravity {URDF_GRAVITY[2]:g} m/s² along z of the root link {link[:40]!r} turned into the base link "
            f"{base[:40]!r} (joints above it at 0): ({', '.join(f'{v:.6g}' for v in g)}) m/s²")
    return robot.replace(gravity=tuple(float(v) for v in g)), (note,)


def nearest_physical_inertia(I: np.ndarray) -> np.ndarray:
    """The inertia tensor nearest to ``I`` (Frobenius norm) that a rigid body can have: principal moments
    non-negative and meeting the triangle inequality A + B >= C, principal axes kept.

    The moments (ascending w0 <= w1 <= w2) are clipped at 0, then, if w0 + w1 < w2, moved onto the plane
    w0 + w1 = w2 along its normal (1, 1, -1): each by δ = (w2 - w0 - w1) / 3 — the Euclidean projection onto that
    half-space, and for a tensor with fixed axes the nearest matrix (von Neumann's trace inequality).

    >>> np.linalg.eigvalsh(nearest_physical_inertia(np.diag([1.0, 1.0, 3.0]))).round(6).tolist()
    [1.333333, 1.333333, 2.666667]
    """
    w, V = np.linalg.eigh(np.asarray(I, dtype=float))  # ascending
    w = np.maximum(w, 0.0)
    delta = (w[2] - w[0] - w[1]) / 3
    if delta > 0:
        w = w + np.array([delta, delta, -delta])
    return (V * w) @ V.T


def _physical_inertials(model: UrdfModel, how: str) -> tuple[UrdfModel, tuple[str, ...]]:
    """The model with each link's inertial checked (see :func:`import_urdf`, ``inertia=``) and notes on what was
    done; ``"none"`` drops every inertial."""
    from dataclasses import replace

    if how == "none":
        return replace(model, links={k: replace(v, inertial=None) for k, v in model.links.items()}), (
            "inertial data left out (--no-inertia): kinematics only",)
    bad = []
    for link in model.links.values():
        el = link.inertial
        if el is None:
            continue
        I = el.inertia
        try:
            LinkInertia(mass=el.mass, inertia=(I[0, 0], I[1, 1], I[2, 2], I[0, 1], I[0, 2], I[1, 2]))
        except ModelError as exc:
            bad.append((link, str(exc).removeprefix("inertia: ")))
    if not bad:
        return model, ()
    where = "; ".join(f"<link name={link.name[:40]!r}> (line {link.line}): {why}" for link, why in bad[:3])
    more = f" and {len(bad) - 3} more links" if len(bad) > 3 else ""
    if how == "check":
        warnings.warn(f"{model.where}: {where}{more}; the arm is imported without inertial data (kinematics only): "
                      "--fix-inertia uses the nearest physical tensor, --no-inertia leaves inertia out quietly",
                      DenavitWarning, stacklevel=3)
        return replace(model, links={k: replace(v, inertial=None) for k, v in model.links.items()}), (
            f"inertial data left out: {len(bad)} link{'s' * (len(bad) > 1)} with a tensor no rigid body has",)
    links = dict(model.links)
    notes = []
    for link, _ in bad:
        before = np.linalg.eigvalsh(link.inertial.inertia)
        fixed = nearest_physical_inertia(link.inertial.inertia)
        links[link.name] = replace(link, inertial=replace(link.inertial, inertia=fixed))
        notes.append(f"<link name={link.name[:40]!r}> (line {link.line}): inertia replaced by the nearest physical "
                     f"tensor (principal moments {', '.join(f'{w:.4g}' for w in before)} -> "
                     f"{', '.join(f'{w:.4g}' for w in np.linalg.eigvalsh(fixed))} kg m², axes kept)")
    return replace(model, links=links), tuple(notes)


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
              xacro: bool = False, inertia: str = "check") -> DHRobot:
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
    return import_urdf(source, base, tip, convention, xacro=xacro, inertia=inertia).robot
