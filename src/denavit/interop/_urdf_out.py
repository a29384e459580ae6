"""A denavit arm as URDF: links, joints, limits, inertials, damping/friction and simple visuals.

Links ``base_link``, ``link1`` … ``linkN`` and ``tool``; joints ``q1`` … ``qN`` (``revolute`` with limits,
``continuous`` without, ``prismatic``) about/along their z axis, placed at the chain constants C_0 … C_{N-1};
the fixed joint ``tool_joint`` at C_N.  URDF has no place for motor (rotor) inertia: it is left out (MJCF
keeps it as ``armature``).  A prismatic joint without limits gets ±:data:`denavit.model.MAX_MAGNITUDE`
(URDF requires limits); effort and velocity limits are unknown and written as 0.
"""

from __future__ import annotations

from xml.sax.saxutils import quoteattr

import numpy as np

from .. import _text
from ..model import MAX_MAGNITUDE, DHRobot
from ..numeric import rpy_from_rotation
from ._export import GLYPH_FRACTION, export_plan, num, nums, xml_safe

__all__ = ["to_urdf"]


def _origin(T: np.ndarray) -> str:
    return f'<origin xyz="{nums(T[:3, 3])}" rpy="{nums(rpy_from_rotation(T[:3, :3]))}"/>'


def _rod(a: np.ndarray, b: np.ndarray, radius: float) -> str:
    """A cylinder visual from ``a`` to ``b`` (a segment of the link centre line, in the link's frame)."""
    v = b - a
    length = float(np.linalg.norm(v))
    z = v / length
    axis = np.cross([0.0, 0.0, 1.0], z)  # turn z onto the segment: about z × u by the angle between them
    s, c = float(np.linalg.norm(axis)), float(z[2])
    if s < 1e-12:
        R = np.eye(3) if c > 0 else np.diag([1.0, -1.0, -1.0])
    else:
        k = axis / s
        K = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
        R = np.eye(3) + s * K + (1 - c) * K @ K
    T = np.eye(4)
    T[:3, :3], T[:3, 3] = R, (a + b) / 2
    return (f'<visual>{_origin(T)}<geometry><cylinder radius="{num(radius * 0.5)}" length="{num(length)}"/>'
            f'</geometry><material name="link"/></visual>')


def _rods(rods, radius: float) -> str:
    return "".join(_rod(a, b, radius) for a, b in rods)


def to_urdf(robot: DHRobot) -> str:
    """The arm as URDF text (see the module notes for names and what is written).

    Loads in Pinocchio, yourdfpy and ROS tools; FK, RNEA and mass matrix of the URDF equal denavit's (motor
    inertia aside, which URDF cannot hold).

    Examples
    --------
    >>> import denavit
    >>> text = denavit.to_urdf(denavit.load_robot("planar2r"))
    >>> text.count("<joint "), 'type="revolute"' in text or 'type="continuous"' in text
    (3, True)
    """
    from ..viz import robot_scale

    bodies, tool, base_rods = export_plan(robot)
    r = GLYPH_FRACTION * robot_scale(robot)
    name = xml_safe(robot.name)
    out = ['<?xml version="1.0"?>', f"<!-- {_text.xml_comment(name)}: written by denavit -->",
           f"<robot name={quoteattr(name)}>",
           '  <material name="link"><color rgba="0.55 0.55 0.55 1"/></material>',
           '  <material name="joint"><color rgba="0.25 0.45 0.75 1"/></material>',
           f'  <link name="base_link"><visual><geometry><box size="{nums([4 * r, 4 * r, r])}"/></geometry>'
           f'<material name="link"/></visual>{_rods(base_rods, r)}</link>']
    parent = "base_link"
    for b in bodies:
        glyph = (f'<box size="{nums([2 * r, 2 * r, 3 * r])}"/>' if b.prismatic
                 else f'<cylinder radius="{num(r)}" length="{num(3 * r)}"/>')
        inertial = ""
        if b.has_inertia:
            I = b.inertia
            inertial = (f'<inertial><origin xyz="{nums(b.com)}" rpy="0 0 0"/><mass value="{num(b.mass)}"/>'
                        f'<inertia ixx="{num(I[0, 0])}" iyy="{num(I[1, 1])}" izz="{num(I[2, 2])}" '
                        f'ixy="{num(I[0, 1])}" ixz="{num(I[0, 2])}" iyz="{num(I[1, 2])}"/></inertial>')
        out.append(f'  <link name="{b.name}">{inertial}<visual><geometry>{glyph}</geometry>'
                   f'<material name="joint"/></visual>{_rods(b.rods, r)}</link>')
        if b.prismatic:
            kind = "prismatic"
            lo, hi = b.limits if b.limits is not None else (-MAX_MAGNITUDE, MAX_MAGNITUDE)
        else:
            kind = "revolute" if b.limits is not None else "continuous"
            lo, hi = b.limits if b.limits is not None else (0.0, 0.0)
        limit = f'<limit lower="{num(lo)}" upper="{num(hi)}" effort="0" velocity="0"/>' if kind != "continuous" else ""
        dynamics = (f'<dynamics damping="{num(b.viscous)}" friction="{num(b.coulomb)}"/>'
                    if b.viscous or b.coulomb else "")
        out.append(f'  <joint name="{b.joint}" type="{kind}"><parent link="{parent}"/><child link="{b.name}"/>'
                   f'{_origin(b.placement)}<axis xyz="0 0 1"/>{limit}{dynamics}</joint>')
        parent = b.name
    out.append('  <link name="tool"/>')
    out.append(f'  <joint name="tool_joint" type="fixed"><parent link="{parent}"/><child link="tool"/>'
               f"{_origin(tool)}</joint>")
    out.append("</robot>")
    return "\n".join(out) + "\n"
