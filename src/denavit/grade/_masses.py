"""A report's own arm given the masses its dynamics section writes: the textbook lumped model of a planar arm.

A DH table has no masses, yet the classic exercise (Spong, Hutchinson & Vidyasagar, *Robot Modeling and Control*,
Sec. 7.4: the two-link planar arm; Craig, *Introduction to Robotics*, Sec. 6.x) writes the equations of motion in
symbols: link i has mass ``m_i``, its centre of mass at ``\\ell_{ci}`` (``l_{c1}``, ``Lc_1``, ``r_{c1}``) from
joint i along the link, and the moment of inertia ``I_i`` about the axis through that centre normal to the plane.
When a section's equations name a mass and a centre-of-mass distance for every link of an arm that moves in the
base's xy plane (all joints revolute), the arm is read with exactly that model, its symbols as parameters
(generic values for numbers), gravity along −y (the plane vertical, y up: P = m g y, as both books draw it).
Without an ``I_i`` a link's inertia about its centre is zero (a point mass).
"""

from __future__ import annotations

import functools
import re
from typing import Any

from ..check import parse_math
from ..errors import ParseError
from ..io import robot_from_dict
from ..model import JointType

__all__ = ["massed_arm_data", "names_written", "check_buildable", "moves_in_xy", "turns_about_z", "MASS_NOTE"]

#: Said of an arm read this way (in the arm's notes).
MASS_NOTE = ("masses {m}, centres of mass at {c} along the links, inertias {i} from the report's symbols (the "
             "lumped model of a planar arm; gravity along −y, the plane vertical)")

_COM = re.compile(r"(?:ell|l|L|r)c(\d)")
_MASS = re.compile(r"m(\d)")
_INERTIA = re.compile(r"I(?:zz)?(\d)|I(\d)zz")
#: Generic values of the symbols (distinct, not round): masses, centre-of-mass fractions of the link, inertias.
_GENERIC = {"mass": (1.37, 0.83, 0.61, 0.47), "com": (0.43, 0.57, 0.39, 0.52), "inertia": (0.113, 0.071, 0.037, 0.029)}


def names_written(maths: list[str]) -> set[str]:
    """The plain names (``m1``, ``ellc1``, ``I2``) the equations ``maths`` use, as the claims' reader spells them."""
    seen: set[str] = set()

    def capture(ident: Any) -> tuple:
        seen.add(ident.plain)
        return ("name", ident.plain)

    for text in maths:
        for side in text.split("=")[1:] if "=" in text else [text]:
            try:
                parse_math(side[:4000], capture)
            except ParseError:
                continue
    return seen


def _per_link(pattern: re.Pattern, names: set[str], n: int) -> dict[int, str]:
    """Link number → the name written for it; a link the report never names gets the same name with its number
    (``m_2`` written, ``m1`` made for link 1: an entry that needs it is then a formula in it too)."""
    out: dict[int, str] = {}
    for name in sorted(names):
        m = pattern.fullmatch(name)
        k = m and int(next(g for g in m.groups() if g))
        if k and 1 <= k <= n:
            out.setdefault(k, name)
    if out:
        first, name = min(out.items())
        for k in range(1, n + 1):
            out.setdefault(k, re.sub(rf"(?<=\D){first}(?=\D|$)", str(k), name, count=1))
    return dict(sorted(out.items()))


def massed_arm_data(data: dict, robot: Any, names: set[str], moves_in_xy: bool) -> tuple[dict, str] | None:
    """The table's robot dict with the lumped masses the names give, and the note saying so; None when the names
    do not give a mass and a centre of mass for every link, or the arm is not a planar all-revolute one."""
    n = robot.dof
    if robot.has_dynamics or not moves_in_xy or any(t is not JointType.REVOLUTE for t in robot.joint_types):
        return None
    if robot.n_rows != n:  # a fixed tool row: its place in the lumped model is not the textbook's
        return None
    mass, com, inertia = (_per_link(p, names, n) for p in (_MASS, _COM, _INERTIA))
    if len(mass) < n or len(com) < n:
        return None
    values = dict(data["parameters"])
    joints = []
    for k, joint in enumerate(data["joints"], start=1):
        a = joint.get("a", 0)
        along = com[k] if data.get("convention", "standard") == "modified" else f"{com[k]} - ({a})"
        izz = inertia.get(k, 0)
        joints.append({**joint, "inertia": {"mass": mass[k], "com": [along, 0, 0], "inertia": [0, izz, izz, 0, 0, 0]}})
        length = robot.parameter_values.get(str(a), a) if isinstance(a, str) else a
        values[mass[k]] = _GENERIC["mass"][(k - 1) % 4]
        values[com[k]] = _GENERIC["com"][(k - 1) % 4] * (float(length) or 1.0)
        if k in inertia:
            values[inertia[k]] = _GENERIC["inertia"][(k - 1) % 4]
    out = {**data, "joints": joints, "parameters": values, "gravity": [0, -9.81, 0]}
    note = MASS_NOTE.format(m=", ".join(mass.values()), c=", ".join(com.values()),
                            i=", ".join(inertia.values()) or "none (point masses)")
    return out, note


def check_buildable(data: dict, where: str) -> Any:
    """The robot of ``data`` (a bad model is a table problem: None)."""
    try:
        return robot_from_dict(data, where=where)
    except Exception:  # noqa: BLE001 - a model the table cannot carry: no masses, the table arm stays
        return None


@functools.lru_cache(maxsize=64)
def turns_about_z(robot: Any) -> bool:
    """Every joint turns the tip about the base's z axis only, or slides it (J's ωx, ωy rows zero at random q: a
    planar arm, a SCARA): its heading φ is defined."""
    import numpy as np

    from .. import numeric as N

    J = N.geometric_jacobian(robot, np.random.default_rng(0).uniform(-1.0, 1.0, (3, robot.dof)))
    return bool(np.abs(J[:, 3:5, :]).max() < 1e-9 * max(1.0, np.abs(J).max()))


def moves_in_xy(robot: Any) -> bool:
    """Every joint moves the tip in the base's xy plane only (J's vz, ωx, ωy rows zero at random q)."""
    import numpy as np

    from .. import numeric as N

    rng = np.random.default_rng(0)
    J = N.geometric_jacobian(robot, rng.uniform(-1.0, 1.0, (3, robot.dof)))
    return bool(np.abs(J[:, 2:5, :]).max() < 1e-9 * max(1.0, np.abs(J).max()))
