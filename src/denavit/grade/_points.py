"""What a report calls its points: the coordinates it names P_x, P_y, P_z.

Inverse kinematics by kinematic decoupling (Spong et al. 2006, Sec. 5.3) solves the arm for the wrist centre and
many reports call the wrist centre's coordinates P_x, P_y, P_z: ``T_4^0(1:3,4) = [⋯] = [P_x; P_y; P_z]``.  The
checker reads p_x, p_y, p_z as the origin of the last DH frame unless an ``ik_formula`` claim says ``point:
wrist``; after a report has named the wrist centre so, its IK formulas in P are read with the wrist centre (and
judged correct or incorrect, not ambiguous).
"""

from __future__ import annotations

import re
from typing import Any

import numpy as np

from .. import numeric as N
from ..check import wrist_offset
from ._context import vector_entries

__all__ = ["names_wrist_centre"]

_P = re.compile(r"\s*P\s*_\s*\{?\s*([xyz])\s*\}?\s*", re.IGNORECASE)


def _is_wrist_centre(robot: Any, frame: int) -> bool:
    """Is the origin of DH frame ``frame`` the wrist centre (where the last three joint axes meet) at every q?"""
    offset = wrist_offset(robot)
    if offset is None or not 0 <= frame <= robot.n_rows:
        return False
    q = np.random.default_rng(0).uniform(-np.pi, np.pi, (3, robot.dof))
    F = N.link_transforms(robot, q)  # (3, N+1, 4, 4), world frames
    centre = F[:, -1, :3, :3] @ offset + F[:, -1, :3, 3]
    return bool(np.allclose(F[:, frame, :3, 3], centre, atol=1e-9))


def names_wrist_centre(parts: tuple[str, ...], spec: dict[str, Any], robot: Any) -> bool:
    """True when an equation's last part names the entries of its value P_x, P_y, P_z and that value is the wrist
    centre (the origin of a DH frame that sits there): ``T_4^0(1:3,4) = [⋯] = [P_x; P_y; P_z]``."""
    if len(parts) < 3 or spec.get("quantity") != "origin" or not isinstance(spec.get("index"), int):
        return False
    entries = vector_entries(parts[-1])
    if not entries or len(entries) != 3:
        return False
    axes = [m.group(1).lower() if (m := _P.fullmatch(e)) else "" for e in entries]
    return axes == ["x", "y", "z"] and _is_wrist_centre(robot, spec["index"])
