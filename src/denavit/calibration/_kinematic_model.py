"""The error model of kinematic calibration: the arm as a product of elementary motions with unknowns.

World pose of the end effector, every factor an elementary motion (rotation or translation along one axis of the
current frame):

    T_w_e(q, x) = B · Δ_B · A_1 ⋯ A_N · T · Δ_T,
    Δ = Tx(x) Ty(y) Tz(z) Rx(rx) Ry(ry) Rz(rz)                     (base / tool corrections, own axes),
    standard row:  A_i = Rz(θ_i) Tz(d_i) Tx(a_i) Rx(α_i) [Ry(β_i)]      (Spong (3.10); Hayati & Mirmirani 1985),
    modified row:  A_i = Rx(α_i) Tx(a_i) [Ry(β_i)] Rz(θ_i) Tz(d_i)      (Craig (3.6); the same β about y),

B and T the nominal base and tool, the joint value added to θ (revolute) or d (prismatic), and each parameter the
nominal value plus its correction.  The extra rotation β about the row's y axis is added to rows whose consecutive
joint axes are nearly parallel (the classical DH singularity of calibration: there a small tilt of the next axis
would move the common normal, and d, by kilometres); such a row's d is then held (while the axes are parallel it
moves the arm exactly as the d of the other row on them: the next row's in the standard convention, the previous
row's in the modified one).

Identification Jacobian (no finite differences): a parameter of an elementary motion about (along) the unit axis
e of the frame F it acts in moves the end effector by the twist (Veitschegger & Wu 1986; Mooring, Roth & Driels,
*Fundamentals of Manipulator Calibration*, 1991, ch. 4)

    rotation:     δp = (R_F e) × (p_e − o_F),   δφ = R_F e,
    translation:  δp = R_F e,                   δφ = 0,

δφ the small rotation of the end effector in world axes.  Rows (δp, δφ), as the library's Jacobians.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..model import Convention, DHRobot, JointType

__all__ = ["Op", "Parameter", "ErrorModel", "error_model", "PARALLEL_TOLERANCE", "CORRECTION_AXES"]

#: Consecutive joint axes at most this far from parallel (or antiparallel) [rad] get the Hayati β of their row.
PARALLEL_TOLERANCE = np.radians(1.0)
#: Base and tool corrections: (suffix, kind, axis), applied in this order in the frame's own axes.
CORRECTION_AXES = (("x", "t", 0), ("y", "t", 1), ("z", "t", 2), ("rx", "r", 0), ("ry", "r", 1), ("rz", "r", 2))

_X, _Y, _Z = 0, 1, 2


@dataclass(frozen=True, eq=False)  # holds arrays: compared by identity
class Op:
    """One elementary motion: rotation ("r") or translation ("t") along ``axis`` (0, 1, 2 = x, y, z) of the current
    frame by ``value`` + (joint value of ``joint`` when ≥ 0) + (correction ``param`` when ≥ 0); or, with
    ``matrix`` set, a constant 4×4 transform (nominal base and tool)."""

    kind: str
    axis: int = 0
    value: float = 0.0
    joint: int = -1
    param: int = -1
    matrix: np.ndarray | None = None


@dataclass(frozen=True)
class Parameter:
    """One unknown: its name (``a2``, ``alpha3``, ``theta1_offset``, ``beta2``, ``base_x``, ``tool_rz``), where it
    lives (``row`` 0-based, or -1 for base/tool), the DH field (``a``, ``alpha``, ``d``, ``theta``, ``beta``) or
    the correction axis, its nominal value and unit, and why it is held from the start (empty when free)."""

    name: str
    row: int
    field: str
    nominal: float
    unit: str
    held: str = ""


@dataclass(frozen=True, eq=False)  # holds arrays: compared by identity
class ErrorModel:
    """The arm's elementary motions and unknowns (see the module notes)."""

    ops: tuple[Op, ...]
    parameters: tuple[Parameter, ...]
    beta_rows: tuple[int, ...]
    dof: int

    def pose(self, q: np.ndarray, x: np.ndarray) -> np.ndarray:
        """End-effector world poses T_w_e, shape (m, 4, 4), for joint values q (m, n) and corrections x (p,)."""
        return self._walk(q, x, None)[0]

    def pose_and_jacobian(self, q: np.ndarray, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(T_w_e (m, 4, 4), identification Jacobian (m, 6, p)): rows (δp, δφ) per unit correction."""
        T, J = self._walk(q, x, len(self.parameters))
        return T, J

    def _walk(self, q: np.ndarray, x: np.ndarray, n_params: int | None):
        q = np.atleast_2d(np.asarray(q, dtype=float))  # (m, n)
        m = q.shape[0]
        F = np.broadcast_to(np.eye(4), (m, 4, 4)).copy()  # current frame, world pose (m, 4, 4)
        acts: list[tuple[int, str, np.ndarray, np.ndarray]] = []  # (param, kind, world axis (m,3), origin (m,3))
        for op in self.ops:
            if op.matrix is not None:
                F = F @ op.matrix
                continue
            v = np.full(m, op.value)
            if op.joint >= 0:
                v = v + q[:, op.joint]
            if op.param >= 0:
                v = v + x[op.param]
            F = F @ _elementary(op.kind, op.axis, v)
            if n_params is not None and op.param >= 0:  # the axis is the same before and after its own motion
                acts.append((op.param, op.kind, F[:, :3, op.axis].copy(), F[:, :3, 3].copy()))
        if n_params is None:
            return F, None
        J = np.zeros((m, 6, n_params))
        p_e = F[:, :3, 3]  # (m, 3)
        for k, kind, axis, origin in acts:
            if kind == "t":
                J[:, :3, k] = axis
            else:
                J[:, :3, k] = np.cross(axis, p_e - origin)
                J[:, 3:, k] = axis
        return F, J


def _elementary(kind: str, axis: int, v: np.ndarray) -> np.ndarray:
    """Batch of elementary transforms Rot(axis, v) or Trans(axis, v), shape (m, 4, 4)."""
    E = np.broadcast_to(np.eye(4), v.shape + (4, 4)).copy()
    if kind == "t":
        E[:, axis, 3] = v
        return E
    i, j = {_X: (1, 2), _Y: (2, 0), _Z: (0, 1)}[axis]
    c, s = np.cos(v), np.sin(v)
    E[:, i, i], E[:, i, j], E[:, j, i], E[:, j, j] = c, -s, s, c
    return E


def _parallel_rows(robot: DHRobot, tol: float) -> tuple[int, ...]:
    """Rows (0-based) that join two consecutive joint axes nearly parallel: they get a Hayati β.

    Standard row r relates axis z_{r-1} (its own joint) to z_r (row r+1's joint); modified row r relates z_{r-1}
    (row r-1's joint) to z_r (its own).  Parallel when |sin α_r| < sin(tol) (tol = 0: never).
    """
    links = robot.links
    standard = robot.convention is Convention.STANDARD
    rows = []
    for r, link in enumerate(links):
        pair = (r, r + 1) if standard else (r - 1, r)
        if pair[0] < 0 or pair[1] >= len(links) or not (links[pair[0]].is_joint and links[pair[1]].is_joint):
            continue
        if abs(np.sin(link.alpha)) < np.sin(tol):
            rows.append(r)
    return tuple(rows)


def _row_ops(robot: DHRobot, r: int, joint: int, beta: bool, params: list[Parameter]) -> list[Op]:
    """The elementary motions of row r (0-based) with a new unknown for each field (and β)."""
    link = robot.links[r]
    n = r + 1
    offset = {JointType.REVOLUTE: "theta", JointType.PRISMATIC: "d"}.get(link.joint)

    def op(field: str, kind: str, axis: int, value: float) -> Op:
        name = f"{field}{n}" + ("_offset" if field == offset else "")
        held = ("parallel axes: moves the arm as the d of the other row on these axes does (Hayati beta estimated "
                "instead)") if beta and field == "d" else ""
        unit = "m" if kind == "t" else "rad"
        params.append(Parameter(name, r, field, value, unit, held))
        moving = joint if field == offset else -1
        return Op(kind, axis, value, moving, len(params) - 1)

    theta = lambda: op("theta", "r", _Z, link.theta)  # noqa: E731
    d = lambda: op("d", "t", _Z, link.d)  # noqa: E731
    a = lambda: op("a", "t", _X, link.a)  # noqa: E731
    alpha = lambda: op("alpha", "r", _X, link.alpha)  # noqa: E731
    b = lambda: [op("beta", "r", _Y, 0.0)] if beta else []  # noqa: E731
    if robot.convention is Convention.STANDARD:
        return [theta(), d(), a(), alpha(), *b()]
    return [alpha(), a(), *b(), theta(), d()]


def _correction_ops(place: str, params: list[Parameter]) -> list[Op]:
    ops = []
    for suffix, kind, axis in CORRECTION_AXES:
        params.append(Parameter(f"{place}_{suffix}", -1, suffix, 0.0, "m" if kind == "t" else "rad"))
        ops.append(Op(kind, axis, 0.0, -1, len(params) - 1))
    return ops


def error_model(robot: DHRobot, parallel_tolerance: float = PARALLEL_TOLERANCE) -> ErrorModel:
    """The calibration error model of ``robot`` (every DH field of every row, base and tool corrections, and a
    Hayati β for each row joining nearly parallel joint axes), all corrections zero at the nominal arm."""
    params: list[Parameter] = []
    beta_rows = _parallel_rows(robot, parallel_tolerance)
    ops: list[Op] = [Op("m", matrix=robot.base_matrix)]
    ops += _correction_ops("base", params)
    joint = 0
    for r, link in enumerate(robot.links):
        ops += _row_ops(robot, r, joint if link.is_joint else -1, r in beta_rows, params)
        joint += link.is_joint
    ops.append(Op("m", matrix=robot.tool_matrix))
    ops += _correction_ops("tool", params)
    return ErrorModel(tuple(ops), tuple(params), beta_rows, robot.dof)
