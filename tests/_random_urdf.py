"""Random serial URDFs for the interop tests, with every geometry of consecutive joint axes crafted on purpose.

Each moving joint is placed relative to the previous joint's axis line (carried through any fixed joints in
between) so that the two axes are, as asked: ``skew`` (random), ``parallel``, ``anti-parallel``,
``coincident``, ``anti-coincident`` or ``intersecting``.  The chain's FK here is computed independently of
denavit (scipy rotations, the joint data as generated), as one oracle; Pinocchio is the other.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.spatial.transform import Rotation

CASES = ("skew", "parallel", "anti-parallel", "coincident", "anti-coincident", "intersecting")


@dataclass
class GenJoint:
    name: str
    kind: str  # revolute | prismatic | fixed
    xyz: np.ndarray
    rpy: np.ndarray
    axis: np.ndarray
    limits: tuple[float, float] | None
    case: str  # the intended geometry with the previous moving axis ("" for the first and fixed joints)


@dataclass
class GenLink:
    name: str
    inertial: tuple | None  # (mass, xyz, rpy, (ixx, iyy, izz, ixy, ixz, iyz))


def _origin(xyz, rpy) -> np.ndarray:
    T = np.eye(4)
    T[:3, :3] = Rotation.from_euler("xyz", rpy).as_matrix()  # extrinsic x, y, z = Rz Ry Rx (URDF rpy)
    T[:3, 3] = xyz
    return T


def _unit(rng) -> np.ndarray:
    v = rng.normal(size=3)
    return v / np.linalg.norm(v)


def _inertial(rng):
    m = float(rng.uniform(0.2, 5.0))
    a, b, c = rng.uniform(0.05, 0.6, 3)
    I = (m * (b * b + c * c) / 12, m * (a * a + c * c) / 12, m * (a * a + b * b) / 12)
    R = Rotation.from_euler("xyz", rng.uniform(-np.pi, np.pi, 3)).as_matrix()
    J = R @ np.diag(I) @ R.T  # a box's tensor in turned axes
    return (m, rng.uniform(-0.3, 0.3, 3), rng.uniform(-np.pi, np.pi, 3),
            tuple(float(x) for x in (J[0, 0], J[1, 1], J[2, 2], J[0, 1], J[0, 2], J[1, 2])))


def _skew(prev, point, direction) -> bool:
    """True when the line (point, direction) is clearly skew to ``prev`` (neither parallel nor meeting)."""
    p, u = prev
    c = np.cross(u, direction / np.linalg.norm(direction))
    s = float(np.linalg.norm(c))
    return s > 1e-3 and abs(float((point - p) @ c)) / s > 1e-3


def random_chain(rng: np.random.Generator, n: int | None = None, cases=CASES, fixed: float = 0.25,
                 prismatic: float = 0.2, inertia: bool = True,
                 continuous: bool = True) -> tuple[list[GenLink], list[GenJoint]]:
    """Links and joints of a random serial URDF (link i+1 child of joint i); some revolute joints without
    limits are ``continuous``."""
    n = n or int(rng.integers(1, 8))
    joints: list[GenJoint] = []
    prev = None  # previous moving axis in the current link's frame: (point, direction)
    k = 0
    while k < n:
        if rng.random() < fixed:
            xyz, rpy = rng.uniform(-0.5, 0.5, 3), rng.uniform(-np.pi, np.pi, 3)
            joints.append(GenJoint(f"fixed{len(joints)}", "fixed", xyz, rpy, np.array([1.0, 0, 0]), None, ""))
            if prev is not None:
                Ti = np.linalg.inv(_origin(xyz, rpy))
                prev = (Ti[:3, :3] @ prev[0] + Ti[:3, 3], Ti[:3, :3] @ prev[1])
            continue
        rpy = rng.uniform(-np.pi, np.pi, 3)
        if rng.random() < 0.3:  # the URDF habit: quarter turns
            rpy = rng.integers(-2, 3, 3) * np.pi / 2
        R = Rotation.from_euler("xyz", rpy).as_matrix()
        xyz = rng.uniform(-0.8, 0.8, 3)
        case = "" if prev is None else str(rng.choice(cases))
        if case in ("", "skew"):
            axis = np.eye(3)[rng.integers(3)] * rng.choice([-1, 1]) if rng.random() < 0.5 else _unit(rng)
            if case == "skew" and not _skew(prev, xyz, R @ axis):
                continue  # quarter turns can make it parallel or meeting by chance: draw again
        else:
            p, u = prev
            if case in ("parallel", "anti-parallel", "coincident", "anti-coincident"):
                direction = u if case in ("parallel", "coincident") else -u
                if case.endswith("coincident"):
                    xyz = p + rng.uniform(-0.5, 0.5) * u
                else:  # a point off the line
                    off = np.cross(u, _unit(rng))
                    xyz = p + rng.uniform(-0.5, 0.5) * u + rng.uniform(0.1, 0.8) * off / np.linalg.norm(off)
            else:  # intersecting: the new axis passes through a point of the old one
                c = p + rng.uniform(-0.5, 0.5) * u
                direction = c - xyz
                direction /= np.linalg.norm(direction)
            axis = R.T @ direction
        kind = "prismatic" if rng.random() < prismatic else "revolute"
        limits = None
        if kind == "prismatic":
            limits = (float(rng.uniform(-1, 0)), float(rng.uniform(0, 1)))
        elif rng.random() < 0.7:
            limits = (float(rng.uniform(-3, 0)), float(rng.uniform(0, 3)))
        elif continuous and rng.random() < 0.5:
            kind = "continuous"
        joints.append(GenJoint(f"joint{k + 1}", kind, xyz, rpy, axis, limits, case))
        prev = (np.zeros(3), axis / np.linalg.norm(axis))
        k += 1
    if rng.random() < 0.5:  # a tool flange
        joints.append(GenJoint("flange", "fixed", rng.uniform(-0.3, 0.3, 3), rng.uniform(-np.pi, np.pi, 3),
                               np.array([1.0, 0, 0]), None, ""))
    links = [GenLink(f"link{i}", _inertial(rng) if inertia and rng.random() < 0.9 else None)
             for i in range(len(joints) + 1)]
    return links, joints


def _v(values) -> str:
    return " ".join(repr(float(x)) for x in values)


def urdf_text(links: list[GenLink], joints: list[GenJoint], name: str = "random") -> str:
    out = [f'<?xml version="1.0"?>\n<robot name="{name}">']
    for link in links:
        if link.inertial is None:
            out.append(f'  <link name="{link.name}"/>')
            continue
        m, xyz, rpy, I = link.inertial
        out.append(f'  <link name="{link.name}"><inertial><origin xyz="{_v(xyz)}" rpy="{_v(rpy)}"/>'
                   f'<mass value="{m!r}"/><inertia ixx="{I[0]!r}" iyy="{I[1]!r}" izz="{I[2]!r}" ixy="{I[3]!r}" '
                   f'ixz="{I[4]!r}" iyz="{I[5]!r}"/></inertial></link>')
    for i, j in enumerate(joints):
        limit = (f'<limit lower="{j.limits[0]!r}" upper="{j.limits[1]!r}" effort="10" velocity="1"/>'
                 if j.limits else ('<limit effort="10" velocity="1"/>' if j.kind in ("revolute", "prismatic") else ""))
        out.append(f'  <joint name="{j.name}" type="{j.kind}"><parent link="{links[i].name}"/>'
                   f'<child link="{links[i + 1].name}"/><origin xyz="{_v(j.xyz)}" rpy="{_v(j.rpy)}"/>'
                   f'<axis xyz="{_v(j.axis)}"/>{limit}</joint>')
    out.append("</robot>\n")
    return "\n".join(out)


def chain_fk(joints: list[GenJoint], q) -> np.ndarray:
    """Pose of the last link in the first link's frame: the URDF rule, written here with scipy."""
    T = np.eye(4)
    k = 0
    for j in joints:
        T = T @ _origin(j.xyz, j.rpy)
        if j.kind != "fixed":
            u = j.axis / np.linalg.norm(j.axis)
            M = np.eye(4)
            if j.kind == "prismatic":
                M[:3, 3] = u * q[k]
            else:
                M[:3, :3] = Rotation.from_rotvec(u * q[k]).as_matrix()
            T = T @ M
            k += 1
    return T


def dof(joints: list[GenJoint]) -> int:
    return sum(j.kind != "fixed" for j in joints)


def with_random_inertia(robot, rng: np.random.Generator, motor: bool = True):
    """``robot`` with random inertial data on every row (fixed rows too), motor inertia and no friction."""
    from denavit import DHLink, LinkInertia

    links = []
    for link in robot.links:
        m, _, _, I = _inertial(rng)
        li = LinkInertia(mass=m, com=tuple(rng.uniform(-0.3, 0.3, 3)), inertia=I,
                         motor_inertia=float(rng.uniform(0, 0.05)) if motor and link.is_joint else 0.0)
        links.append(DHLink(a=link.a, alpha=link.alpha, d=link.d, theta=link.theta, joint=link.joint,
                            q_limits=link.q_limits, inertia=li))
    return robot.replace(links=tuple(links))


def without_motor_inertia(robot):
    """``robot`` with every row's motor inertia set to 0 (URDF has no place for it)."""
    from dataclasses import replace

    from denavit import DHLink

    links = [link if link.inertia is None else DHLink(
        a=link.a, alpha=link.alpha, d=link.d, theta=link.theta, joint=link.joint, q_limits=link.q_limits,
        inertia=replace(link.inertia, motor_inertia=0.0)) for link in robot.links]
    return robot.replace(links=tuple(links))
