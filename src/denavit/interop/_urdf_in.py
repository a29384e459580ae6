"""URDF in, DH out: the serial chain between two links of a URDF as a DH table, with base, tool and inertias.

The method
----------
At q = 0 every moving joint k of the chain has an axis line L_k (a point p_k and the unit direction z_k of the
URDF axis, in the base link's frame).  Consecutive lines L_k, L_{k+1} have a common normal N_k: a unit
direction x_k perpendicular to both, from a foot f_k on L_k to a foot g_{k+1} on L_{k+1}, of length a_k ≥ 0,
and the twist α_k from z_k to z_{k+1} about x_k.  The cases (``ROW_CASES``):

- ``skew``: N_k is unique;
- ``intersecting``: a_k = 0, f_k = g_{k+1} the intersection, x_k = ±z_k × z_{k+1} / |z_k × z_{k+1}|, the
  sign that keeps x_k within 90° of x_{k-1} (so |θ_k| ≤ π/2; + when perpendicular);
- ``parallel`` / ``anti-parallel`` (distinct lines): x_k is unique, its foot is not; the normal is taken
  through the origin the URDF gives joint k+1 (so a pedestal's height stays in d_1, as textbooks write it);
- ``coincident`` / ``anti-coincident`` (one line): a_k = 0, α_k ∈ {0, π}; f_k = g_{k+1} is the origin of
  joint k+1 projected on the line, and x_k = x_{k-1} (θ_k = 0).

The DH z axes are the URDF joint axes with their sign (so q is the URDF's joint value; an opposite axis is
α = π, never a negated q), and the DH joint variable is the URDF's: the limits carry over unchanged.
With θ_k = ∠(x_{k-1}, x_k) about z_k and d_k = (f_k − g_k)·z_k, the two conventions share θ and d; standard
DH rows take (a_k, α_k), modified rows (a_{k-1}, α_{k-1}) (Craig 3rd ed. §3.4; Spong 2nd ed. §3.2).
The ends are free: frame {0} lies on L_1 at the point nearest the base link's origin, its x axis the base
link's x (or y) made perpendicular to z_1; frame {n} lies on L_n at the point nearest the tip link's origin,
its x axis the tip's x made perpendicular to z_n.  ``base`` and ``tool`` take the rest, so a chain whose first
axis is the base link's z through its origin gets an identity base.  Fixed joints fold into the geometry.
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
from ._urdf_read import UrdfJoint, UrdfModel, chain_path, read_urdf, subtree_joints

__all__ = ["UrdfImport", "import_urdf", "from_urdf", "urdf_chain_fk", "PARALLEL_TOL", "INTERSECT_TOL",
           "CHECK_SAMPLES", "CHECK_TOL", "FAR_FOOT", "ROW_CASES"]

#: Two axes count as parallel when the sine of their angle is below this.
PARALLEL_TOL = 1e-10
#: Two axes count as meeting (and parallel axes as one line) when their distance is below this, relative to
#: the chain's size (at least 1 m).
INTERSECT_TOL = 1e-10
#: Nearly parallel axes whose common normal meets the first axis farther than this (relative to the chain's size)
#: are taken as parallel: the DH model then approximates the URDF, and the self-check reports by how much.
FAR_FOOT = 1e3
#: Random configurations of the import's FK self-check.
CHECK_SAMPLES = 200
#: Self-check errors (relative to the chain's size, at least 1 m) beyond which the import warns.
CHECK_TOL = 1e-9
#: The geometry of consecutive axes that decides each row (the last row's is ``last``).
ROW_CASES = ("skew", "intersecting", "parallel", "anti-parallel", "coincident", "anti-coincident", "last")


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


def _unit_perp(v: np.ndarray, z: np.ndarray) -> np.ndarray | None:
    """``v`` made perpendicular to the unit ``z`` and unit, or None when ``v`` is (nearly) along ``z``."""
    w = v - (v @ z) * z
    n = float(np.linalg.norm(w))
    if n < 1e-3 * max(float(np.linalg.norm(v)), 1e-300):
        return None
    w = w / n
    w = w - (w @ z) * z
    return w / np.linalg.norm(w)


def _angle(u: np.ndarray, v: np.ndarray, axis: np.ndarray) -> float:
    """The angle from ``u`` to ``v`` about ``axis`` (all unit; u, v ⟂ axis)."""
    return math.atan2(float(np.cross(u, v) @ axis), float(u @ v))


def _snap(angle: float) -> float:
    """An angle in (−π, π], exact multiples of π/4 made exact (rounding noise of the rotations)."""
    k = round(angle / (math.pi / 4))
    if abs(angle - k * math.pi / 4) < 1e-13:
        angle = k * math.pi / 4
    angle = math.remainder(angle, 2 * math.pi)
    return math.pi if angle == -math.pi else (0.0 if angle == 0 else angle)


def _frame(origin: np.ndarray, x: np.ndarray, z: np.ndarray) -> np.ndarray:
    T = np.eye(4)
    T[:3, 0], T[:3, 1], T[:3, 2], T[:3, 3] = x, np.cross(z, x), z, origin
    return T


def _dh_geometry(P: np.ndarray, Z: np.ndarray, T_tip: np.ndarray, scale: float):
    """θ, d, a, α (a, α of the normal from axis k to k+1; last row 0), cases, frame {0}: see the module notes."""
    n = len(Z)
    tol = INTERSECT_TOL * scale
    g = P[0] - (P[0] @ Z[0]) * Z[0]  # foot of frame {0}: the point of L_1 nearest the base origin
    x_prev = _unit_perp(np.array([1.0, 0.0, 0.0]), Z[0])
    if x_prev is None:
        x_prev = _unit_perp(np.array([0.0, 1.0, 0.0]), Z[0])
    F0 = _frame(g, x_prev, Z[0])
    theta, d, a, alpha, cases, approximated = [], [], [], [], [], []
    for k in range(n):
        z = Z[k]
        if k == n - 1:
            f = g + ((T_tip[:3, 3] - g) @ z) * z  # the point of L_n nearest the tip origin
            x = _unit_perp(T_tip[:3, 0], z)
            x = x_prev if x is None else x
            ak, alk, g_next, case = 0.0, 0.0, f, "last"
        else:
            zn, w = Z[k + 1], P[k + 1] - P[k]
            c = np.cross(z, zn)
            s = float(np.linalg.norm(c))
            x = c / s if s > 0 else c
            t1 = float(np.cross(w, zn) @ x) / s if s > 0 else math.inf
            if s > PARALLEL_TOL and abs(t1) <= FAR_FOOT * scale:
                # foot on L_k: t = det[w, z_{k+1}, c] / |c|², written so that its error is ~ eps/s, not eps/s²
                # (nearly parallel axes): the foot on L_{k+1} then stays on it to rounding
                f = P[k] + t1 * z
                dist = float(w @ x)  # signed length of the common normal
                if abs(dist) < tol:
                    ak, case = 0.0, "intersecting"
                    if float(x @ x_prev) < -1e-9:  # the sign keeping θ_k within ±π/2 (+ on a tie)
                        x = -x
                else:
                    x, ak, case = (x if dist > 0 else -x), abs(dist), "skew"
                g_next = f + ak * x
            else:  # parallel, or so nearly that the common normal is far away: taken as parallel
                if s > PARALLEL_TOL:
                    approximated.append(k)
                f = P[k] + ((P[k + 1] - P[k]) @ z) * z  # the normal through the next joint's origin
                v = P[k + 1] - f
                v = v - (v @ z) * z  # from L_k to L_{k+1}, perpendicular to both
                ak = float(np.linalg.norm(v))
                same = float(z @ zn) > 0
                if ak <= tol:
                    x, ak, case = x_prev, 0.0, "coincident" if same else "anti-coincident"
                else:
                    x, case = v / ak, "parallel" if same else "anti-parallel"
                g_next = f + ak * x
            alk = math.atan2(float(np.cross(z, zn) @ x), float(z @ zn))
        theta.append(_snap(_angle(x_prev, x, z)))
        dk = float((f - g) @ z)
        d.append(0.0 if abs(dk) < 1e-14 * scale else dk)
        a.append(ak)
        alpha.append(_snap(alk))
        cases.append(case)
        g, x_prev = g_next, x
    return theta, d, a, alpha, cases, F0, approximated


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
    theta, d, a, alpha, cases, F0, approximated = _dh_geometry(P, Z, T, scale)
    robot = _robot(model, conv, moving, theta, d, a, alpha, F0, T)
    robot, notes = _with_inertia(robot, model, path, link_pose, link_body, base)
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
        links.append(DHLink(a=ak, alpha=alk, d=d[k], theta=theta[k], joint=kind, q_limits=limits))
    names = ", ".join(j.name for j in moving)
    robot = DHRobot(name=model.name, links=tuple(links), convention=conv, base=F0,
                    description=f"imported from URDF; rows are the joints {names}"[:2000])
    Fn = link_transforms(robot, np.zeros(n))[-1]
    tool = np.linalg.solve(Fn, T_tip)
    tool[3] = (0.0, 0.0, 0.0, 1.0)
    return robot.replace(tool=tool)


def _with_inertia(robot: DHRobot, model: UrdfModel, path: list[UrdfJoint], link_pose: dict, link_body: dict,
                  base: str) -> tuple[DHRobot, tuple[str, ...]]:
    """Each body's links (and rigid branches hanging from them, locked at 0) as one inertia in its DH frame."""
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
            li = LinkInertia(mass=m, com=tuple(c), inertia=(I[0, 0], I[1, 1], I[2, 2], I[0, 1], I[0, 2], I[1, 2]),
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
