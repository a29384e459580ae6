"""A denavit arm as MJCF (MuJoCo): nested bodies, hinge/slide joints, limits, inertials, armature, visuals.

Bodies ``link1`` … ``linkN`` nest under the world body, each placed at the chain constant C_{k-1} (``pos`` and
``quat``) with its joint ``qk`` about/along z; the tool is the site ``tool`` at C_N.  Inertias are
``fullinertia`` at the centre of mass; motor inertia is the joint's ``armature`` (MuJoCo adds it to M's
diagonal, as denavit does); viscous friction is ``damping``, Coulomb friction ``frictionloss``.  Geoms are
visual only (no contacts, no mass: ``inertiafromgeom="false"``); a body without inertial data gets a tiny
mass (:data:`MJCF_MIN_MASS`), since MuJoCo refuses massless moving bodies, and principal moments below
:data:`MJCF_MIN_INERTIA` are raised to it (MuJoCo wants a positive definite tensor).
"""

from __future__ import annotations

import warnings
from xml.sax.saxutils import quoteattr

import numpy as np

from ..errors import DenavitWarning
from ..model import DHRobot
from ._export import GLYPH_FRACTION, export_plan, num, nums, quaternion_wxyz, xml_safe

__all__ = ["to_mjcf", "MJCF_MIN_MASS", "MJCF_MIN_INERTIA", "MJCF_BALANCE_MARGIN"]

#: Smallest principal moment of inertia written [kg m²]: MuJoCo refuses a tensor that is not positive definite
#: (point masses, thin rods), so smaller moments are raised to this (a change far below any arm's M).
MJCF_MIN_INERTIA = 1e-10
#: Mass [kg] (and inertia 1e-3 of it [kg m²] per axis) given to a body without inertial data: MuJoCo refuses a
#: moving body without mass.  Dynamics of such an arm in MuJoCo are then not denavit's (it has none).
MJCF_MIN_MASS = 1e-6
#: Relative margin by which the MJCF's principal moments meet A + B >= C: MuJoCo recomputes the moments from
#: ``fullinertia`` and refuses any shortfall, so an exactly balanced tensor (a flat plate) fails about half the time.
MJCF_BALANCE_MARGIN = 1e-9


def _pose(T: np.ndarray) -> str:
    return f'pos="{nums(T[:3, 3])}" quat="{nums(quaternion_wxyz(T[:3, :3]))}"'


def _mujoco_inertia(I: np.ndarray, body: str) -> np.ndarray:
    """``I`` as MuJoCo accepts it: principal moments at least :data:`MJCF_MIN_INERTIA`, and meeting the triangle
    inequality with a margin, A + B >= C (1 + :data:`MJCF_BALANCE_MARGIN`).

    MuJoCo (``user_objects.cc``) refuses A + B < C with no tolerance, on moments it computes itself from
    ``fullinertia``: a tensor balanced exactly in numpy's eigenvalues (a flat plate, C = A + B; a thin rod raised to
    the minimum moment) comes out a few ulps short there about half the time.  The two smaller moments are raised
    by (C (1 + margin) - A - B) / 2 each; a body truly off the inequality (a massless rotor's lone moment about
    its axis) draws a warning saying by how much (exact for the first body, which only turns about its axis).
    """
    w, V = np.linalg.eigh(I)  # ascending
    need = w[2] * (1 + MJCF_BALANCE_MARGIN)
    if w[0] >= MJCF_MIN_INERTIA and w[0] + w[1] >= need:
        return I
    w = np.maximum(w, MJCF_MIN_INERTIA)
    need = w[2] * (1 + MJCF_BALANCE_MARGIN)
    gap = need - w[0] - w[1]
    if gap > 0:
        w[0] += gap / 2
        w[1] += gap / 2
        if gap > 2 * MJCF_BALANCE_MARGIN * w[2]:  # more than the margin itself: the tensor broke the inequality
            warnings.warn(f"{body}: its principal moments break MuJoCo's A + B >= C; the two smaller ones are raised "
                          f"by {gap / 2:.3g} kg m² in the MJCF", DenavitWarning, stacklevel=3)
    return (V * w) @ V.T


def _rods(rods, radius: float) -> str:
    """Capsules along the link centre line segments (in the body's frame), visual only."""
    return "".join(f'<geom type="capsule" fromto="{nums(a)} {nums(b)}" size="{num(radius * 0.5)}" '
                   'rgba="0.55 0.55 0.55 1" contype="0" conaffinity="0" group="1"/>' for a, b in rods)


def to_mjcf(robot: DHRobot) -> str:
    """The arm as MJCF text for MuJoCo (see the module notes for names and what is written).

    Examples
    --------
    >>> import denavit
    >>> text = denavit.to_mjcf(denavit.load_robot("scara"))
    >>> text.count("<joint "), 'type="slide"' in text
    (4, True)
    """
    from ..viz import robot_scale

    bodies, tool, base_rods = export_plan(robot)
    r = GLYPH_FRACTION * robot_scale(robot)
    out = [f"<mujoco model={quoteattr(xml_safe(robot.name))}>",
           '  <compiler angle="radian" inertiafromgeom="false" autolimits="true"/>',
           f'  <option gravity="{nums(robot.gravity)}"/>',
           "  <worldbody>",
           f'    <geom type="box" size="{nums([2 * r, 2 * r, r / 2])}" rgba="0.55 0.55 0.55 1" contype="0" '
           f'conaffinity="0" group="1"/>{_rods(base_rods, r)}']
    indent = "    "
    for b in bodies:
        out.append(f'{indent}<body name="{b.name}" {_pose(b.placement)}>')
        indent += "  "
        if b.has_inertia and (b.mass > 0 or np.any(b.inertia)):
            I = _mujoco_inertia(b.inertia, b.name)
            mass = max(b.mass, MJCF_MIN_MASS)
            out.append(f'{indent}<inertial pos="{nums(b.com)}" mass="{num(mass)}" fullinertia="'
                       f'{nums([I[0, 0], I[1, 1], I[2, 2], I[0, 1], I[0, 2], I[1, 2]])}"/>')
        else:
            out.append(f'{indent}<inertial pos="0 0 0" mass="{num(MJCF_MIN_MASS)}" '
                       f'diaginertia="{nums([MJCF_MIN_MASS * 1e-3] * 3)}"/>')
        attrs = [f'name="{b.joint}"', f'type="{"slide" if b.prismatic else "hinge"}"', 'axis="0 0 1"']
        if b.limits is not None:
            attrs.append(f'range="{nums(b.limits)}"')
        for key, value in (("armature", b.motor_inertia), ("damping", b.viscous), ("frictionloss", b.coulomb)):
            if value:
                attrs.append(f'{key}="{num(value)}"')
        out.append(f"{indent}<joint {' '.join(attrs)}/>")
        glyph = (f'type="box" size="{nums([r, r, 1.5 * r])}"' if b.prismatic
                 else f'type="cylinder" size="{nums([r, 1.5 * r])}"')
        out.append(f'{indent}<geom {glyph} rgba="0.25 0.45 0.75 1" contype="0" conaffinity="0" group="1"/>'
                   f"{_rods(b.rods, r)}")
    out.append(f'{indent}<site name="tool" {_pose(tool)} size="{num(r / 2)}"/>')
    for _ in bodies:
        indent = indent[:-2]
        out.append(f"{indent}</body>")
    out += ["  </worldbody>", "</mujoco>"]
    return "\n".join(out) + "\n"
