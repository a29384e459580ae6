"""What URDF and MJCF exports share: the arm as bodies on joints, from the chain ``C0 · J1(q1) · C1 ⋯ Jn(qn) · Cn``.

Body k (k = 1 … n) is the link moved by joint k; its frame is joint k's axis frame after the motion (z = the
joint axis), placed at C_{k-1} in body k-1's frame (body 0 is the world/base link).  Every row with inertial
data moved by joint k becomes one piece of body k; the pieces are combined (parallel-axis theorem) into one
mass, centre of mass and inertia tensor in the body's frame.  The tool is a frame at C_n in body n.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass

import numpy as np

from ..chain import chain_of
from ..errors import ModelError
from ..model import DHRobot, inertial_rows

__all__ = ["Body", "export_plan", "combine_inertia", "quaternion_wxyz", "num", "nums", "xml_safe"]

#: Joint glyph radius of the visuals, as a fraction of the arm's size (as in the plots).
GLYPH_FRACTION = 0.035


@dataclass(frozen=True)
class Body:
    """Body k of an export: its placement in the parent body, joint and inertia (all in its own frame)."""

    name: str
    joint: str
    placement: np.ndarray  # (4, 4) the joint/axis frame in the parent body's frame (C_{k-1})
    prismatic: bool
    limits: tuple[float, float] | None
    mass: float
    com: np.ndarray  # (3,)
    inertia: np.ndarray  # (3, 3) about the COM, body axes
    has_inertia: bool
    motor_inertia: float
    viscous: float
    coulomb: float
    rods: tuple  # ((start, end), ...) the plots' link centre line carried by this body, in its frame [m]


def combine_inertia(pieces) -> tuple[float, np.ndarray, np.ndarray]:
    """Mass, centre of mass and inertia about it of rigid pieces ``(mass, com, inertia about own COM)`` given in
    one frame (the parallel-axis theorem)."""
    m = float(sum(p[0] for p in pieces))
    c = sum(p[0] * np.asarray(p[1]) for p in pieces) / m if m > 0 else np.zeros(3)
    I = np.zeros((3, 3))
    for mi, ci, Ii in pieces:
        r = np.asarray(ci) - c
        I += Ii + mi * ((r @ r) * np.eye(3) - np.outer(r, r))
    return m, np.asarray(c, dtype=float), 0.5 * (I + I.T)


def _rods(robot: DHRobot, chain) -> list[list[tuple[np.ndarray, np.ndarray]]]:
    """The plots' link centre line (``denavit.viz.arm_geometry`` skeleton at q = 0: o_{i-1}, knee k_i, o_i, …,
    the tool) cut into segments, each in the frame of the body that carries it; index 0 is the fixed base."""
    from ..viz import arm_geometry

    skel = arm_geometry(robot, np.zeros(robot.dof)).skeleton  # (2N+2, 3) world, q = 0
    body_after = np.cumsum([link.is_joint for link in robot.links]) - 1  # body carrying frame {i+1}
    L = [np.eye(4)]  # world pose of body k's frame at q = 0 (index 0: the base)
    for C in chain.constants[:-1]:
        L.append(L[-1] @ C)
    out: list[list] = [[] for _ in range(robot.dof + 1)]

    def add(body: int, a: np.ndarray, b: np.ndarray) -> None:
        if np.linalg.norm(b - a) > 1e-9:
            Li = np.linalg.inv(L[body + 1])
            out[body + 1].append((Li[:3, :3] @ a + Li[:3, 3], Li[:3, :3] @ b + Li[:3, 3]))

    for i in range(robot.n_rows):
        before = int(body_after[i - 1]) if i else -1
        first = before if not chain.standard else int(body_after[i])  # standard: along z_{i-1}, row i's axis
        add(first, skel[2 * i], skel[2 * i + 1])
        add(int(body_after[i]), skel[2 * i + 1], skel[2 * i + 2])
    add(robot.dof - 1, skel[-2], skel[-1])
    return out


def export_plan(robot: DHRobot) -> tuple[list[Body], np.ndarray, tuple]:
    """``(bodies, tool, base_rods)``: the bodies of the arm, base to tip, the tool frame C_n in the last body,
    and the centre-line segments of the fixed base (world frame)."""
    chain = chain_of(robot)
    C = chain.constants
    pieces: list[list] = [[] for _ in range(robot.dof)]
    for r, body, li in inertial_rows(robot):
        X = np.eye(4)  # DH frame {r+1} in the body's (axis) frame: the row constants in between
        for i in range(chain.axis_frame[body], r + 1):
            X = X @ chain.row_constant(i)
        R = X[:3, :3]
        pieces[body].append((li.mass, X[:3, :3] @ np.array(li.com) + X[:3, 3], R @ li.inertia_matrix @ R.T))
    rods = _rods(robot, chain)
    bodies = []
    for k, r in enumerate(chain.joint_rows):
        link = robot.links[r]
        li = link.inertia
        m, c, I = combine_inertia(pieces[k]) if pieces[k] else (0.0, np.zeros(3), np.zeros((3, 3)))
        bodies.append(Body(
            name=f"link{k + 1}", joint=f"q{k + 1}", placement=np.array(C[k]), prismatic=chain.prismatic[k],
            limits=link.q_limits, mass=m, com=c, inertia=I, has_inertia=bool(pieces[k]),
            motor_inertia=li.motor_inertia if li else 0.0, viscous=li.viscous if li else 0.0,
            coulomb=li.coulomb if li else 0.0, rods=tuple(rods[k + 1]),
        ))
    return bodies, np.array(C[-1]), tuple(rods[0])


def quaternion_wxyz(R: np.ndarray) -> np.ndarray:
    """Unit quaternion (w, x, y, z) of a rotation matrix (Shepperd's method: the largest pivot)."""
    t = np.trace(R)
    if t > 0:
        s = 2.0 * math.sqrt(1.0 + t)
        q = [0.25 * s, (R[2, 1] - R[1, 2]) / s, (R[0, 2] - R[2, 0]) / s, (R[1, 0] - R[0, 1]) / s]
    elif R[0, 0] >= R[1, 1] and R[0, 0] >= R[2, 2]:
        s = 2.0 * math.sqrt(1.0 + R[0, 0] - R[1, 1] - R[2, 2])
        q = [(R[2, 1] - R[1, 2]) / s, 0.25 * s, (R[0, 1] + R[1, 0]) / s, (R[0, 2] + R[2, 0]) / s]
    elif R[1, 1] >= R[2, 2]:
        s = 2.0 * math.sqrt(1.0 + R[1, 1] - R[0, 0] - R[2, 2])
        q = [(R[0, 2] - R[2, 0]) / s, (R[0, 1] + R[1, 0]) / s, 0.25 * s, (R[1, 2] + R[2, 1]) / s]
    else:
        s = 2.0 * math.sqrt(1.0 + R[2, 2] - R[0, 0] - R[1, 1])
        q = [(R[1, 0] - R[0, 1]) / s, (R[0, 2] + R[2, 0]) / s, (R[1, 2] + R[2, 1]) / s, 0.25 * s]
    q = np.array(q)
    return q / np.linalg.norm(q)


def num(x: float) -> str:
    """A number for an XML attribute: exact (``repr``), rounding noise below 1e-15 written as 0."""
    x = float(x)
    return "0" if abs(x) < 1e-15 else repr(x)


def nums(values) -> str:
    return " ".join(num(v) for v in values)


_NOT_XML = re.compile("[^\t\n\r\x20-\ud7ff\ue000-\ufffd\U00010000-\U0010ffff]")


def xml_safe(text: str, what: str = "the robot name") -> str:
    """Free text (a robot's name) for an XML 1.0 attribute, returned unchanged when XML can carry it; quoting is
    the caller's (``quoteattr`` writes newline, CR and tab as ``&#10;`` ``&#13;`` ``&#9;``, so they come back).

    Raises
    ------
    ModelError
        The text holds a character XML 1.0 cannot carry at all, not even as ``&#...;`` (a control character other
        than tab, newline and CR, such as ESC; a lone surrogate; U+FFFE, U+FFFF): refused rather than changed, so
        the file never names a different robot.
    """
    bad = _NOT_XML.search(str(text))
    if bad is not None:
        raise ModelError(f"{what} holds U+{ord(bad.group()):04X} at position {bad.start() + 1}, a character XML 1.0 "
                         "cannot carry; rename the robot ('name:' in its file) to export it")
    return str(text)
