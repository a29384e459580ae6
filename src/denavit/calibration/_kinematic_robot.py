"""The calibrated arm as a robot file: corrected DH rows, Hayati β rows as fixed rows, corrected base and tool.

The robot model has no β field, so a row with an estimated β is written with two fixed rows that make exactly the
rotation Ry(β) = Rz(π/2) Rx(β) Rz(−π/2):

- standard row r, Rz(θ) Tz(d) Tx(a) Rx(α) Ry(β): the row as it is, then the fixed rows {θ: π/2, α: β} and
  {θ: −π/2};
- modified row r, Rx(α) Tx(a) Ry(β) Rz(θ) Tz(d): the fixed rows {α: α_r, a: a_r, θ: π/2} and {α: β, θ: −π/2}, then
  the row with a = α = 0.

Every DH frame of the nominal arm keeps its place on its link, so the inertial data (given in those frames), the
joint limits, the names and the named poses carry over unchanged; the added fixed rows carry none.  A corrected
field loses the parameter expression it was written with (``a: a2`` becomes the number); fields that were not
corrected keep theirs.
"""

from __future__ import annotations

import math

import numpy as np

from ..model import Convention, DHLink, DHRobot, JointType
from ._kinematic_model import ErrorModel

__all__ = ["calibrated_robot", "correction_matrix"]


def correction_matrix(model: ErrorModel, x: np.ndarray, place: str) -> np.ndarray:
    """Δ = Tx Ty Tz Rx Ry Rz of the base or tool corrections in ``x`` (4, 4)."""
    M = np.eye(4)
    for k, p in enumerate(model.parameters):
        if p.row == -1 and p.name.startswith(place + "_"):
            v = float(x[k])
            E = np.eye(4)
            axis = "xyz".index(p.field[-1])
            if p.field.startswith("r"):
                i, j = ((1, 2), (2, 0), (0, 1))[axis]
                E[i, i], E[i, j], E[j, i], E[j, j] = math.cos(v), -math.sin(v), math.sin(v), math.cos(v)
            else:
                E[axis, 3] = v
            M = M @ E
    return M


def _row_values(model: ErrorModel, x: np.ndarray, r: int) -> tuple[dict[str, float], set[str]]:
    """Corrected DH fields of row r (and β), and the names of the fields that changed."""
    values, changed = {}, set()
    for k, p in enumerate(model.parameters):
        if p.row == r:
            values[p.field] = p.nominal + float(x[k])
            if x[k] != 0.0:
                changed.add(p.field)
    return values, changed


def _link(link: DHLink, values: dict[str, float], changed: set[str], drop: tuple[str, ...] = ()) -> DHLink:
    symbols = tuple((k, v) for k, v in link.symbols if k not in changed and k not in drop)
    fields = {f: (0.0 if f in drop else values[f]) for f in ("a", "alpha", "d", "theta")}
    return DHLink(**fields, joint=link.joint, q_limits=link.q_limits, inertia=link.inertia, symbols=symbols)


def _rows(robot: DHRobot, model: ErrorModel, x: np.ndarray) -> list[DHLink]:
    standard = robot.convention is Convention.STANDARD
    out: list[DHLink] = []
    for r, link in enumerate(robot.links):
        values, changed = _row_values(model, x, r)
        beta = values.get("beta", 0.0)
        if beta == 0.0:
            out.append(_link(link, values, changed))
            continue
        turn = DHLink(alpha=beta, theta=math.pi / 2, joint=JointType.FIXED)  # Rz(π/2) Rx(β)
        back = DHLink(theta=-math.pi / 2, joint=JointType.FIXED)  # Rz(−π/2)
        if standard:
            out += [_link(link, values, changed), turn, back]
        else:
            front = DHLink(a=values["a"], alpha=values["alpha"], theta=math.pi / 2, joint=JointType.FIXED)
            back = DHLink(alpha=beta, theta=-math.pi / 2, joint=JointType.FIXED)
            out += [front, back, _link(link, values, changed, drop=("a", "alpha"))]
    return out


def calibrated_robot(robot: DHRobot, model: ErrorModel, x: np.ndarray, note: str = "") -> DHRobot:
    """``robot`` with the corrections ``x`` (one per ``model.parameters``) applied (see the module notes)."""
    x = np.asarray(x, dtype=float)
    changes: dict = {"links": tuple(_rows(robot, model, x))}
    symbols = dict(robot.symbols)
    for place in ("base", "tool"):
        delta = correction_matrix(model, x, place)
        if not np.array_equal(delta, np.eye(4)):
            M = getattr(robot, f"{place}_matrix") @ delta
            M[3] = (0.0, 0.0, 0.0, 1.0)
            changes[place] = tuple(tuple(float(v) for v in row) for row in M)
            symbols = {k: v for k, v in symbols.items() if not k.startswith(place + ".")}
    changes["symbols"] = tuple(symbols.items())
    if note:
        changes["description"] = f"{robot.description}; {note}" if robot.description else note
    return robot.replace(**changes)
