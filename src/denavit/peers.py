"""The same DH robot built in the peer libraries Pinocchio and roboticstoolbox-python.

Chain algebra used (q enters through a pure z rotation/translation J(q) that commutes with Tz/Rz):
standard rows  A_i = J(q_i) C_i   with C_i = Rz(θ_i) Tz(d_i) Tx(a_i) Rx(α_i);
modified rows  A_i = C_i J(q_i)   with C_i = Rx(α_{i-1}) Tx(a_{i-1}) Rz(θ_i) Tz(d_i).

Useful for comparing results, and for moving an arm described here into those libraries' tools.
Neither library is a dependency of denavit: install them with ``pip install "denavit[peers]"``.
"""

from __future__ import annotations

import numpy as np

from .errors import MissingDependencyError
from .model import Convention, DHRobot, JointType
from .numeric import dh_transform

__all__ = ["to_pinocchio", "to_roboticstoolbox", "expand_q"]


def _constant(robot, link):
    return dh_transform(robot.convention, link.theta, link.d, link.a, link.alpha)


def _need(module: str):
    import importlib

    try:
        return importlib.import_module(module)
    except ImportError as exc:
        if exc.name and exc.name.split(".")[0] != module.split(".")[0]:
            raise
        raise MissingDependencyError(f"{module} is not installed: pip install 'denavit[peers]'") from None


def to_pinocchio(robot: DHRobot):
    """``(model, data, ee_frame_id)``: a Pinocchio model with the same kinematics and inertias.

    One Pinocchio joint (RZ or PZ) per DH joint; fixed rows fold into the placements; the end
    effector is the operational frame ``"ee"`` (tool included); gravity is copied.
    """
    pin = _need("pinocchio")

    model = pin.Model()
    parent = 0
    pending = robot.base_matrix
    std = robot.convention is Convention.STANDARD
    for k, link in enumerate(robot.links):
        C = _constant(robot, link)
        if not link.is_joint:
            pending = pending @ C
            continue
        if not std:
            pending = pending @ C
        jmodel = pin.JointModelRZ() if link.joint is JointType.REVOLUTE else pin.JointModelPZ()
        parent = model.addJoint(parent, jmodel, pin.SE3(pending[:3, :3].copy(), pending[:3, 3].copy()), f"j{k}")
        body_in_joint = C if std else np.eye(4)
        if link.inertia is not None:
            li = link.inertia
            inertia = pin.Inertia(li.mass, np.array(li.com), li.inertia_matrix)
            X = pin.SE3(body_in_joint[:3, :3].copy(), body_in_joint[:3, 3].copy())
            model.appendBodyToJoint(parent, X.act(inertia), pin.SE3.Identity())
        pending = C if std else np.eye(4)
    ee = pending @ robot.tool_matrix
    fid = model.addFrame(pin.Frame("ee", parent, 0, pin.SE3(ee[:3, :3].copy(), ee[:3, 3].copy()), pin.FrameType.OP_FRAME))
    model.gravity.linear = np.array(robot.gravity)
    return model, model.createData(), fid


def to_roboticstoolbox(robot: DHRobot):
    """A roboticstoolbox ``DHRobot`` (kinematics); fixed rows become joints held at zero (see expand_q)."""
    rtb = _need("roboticstoolbox")

    links = []
    mdh = robot.convention is Convention.MODIFIED
    for link in robot.links:
        if link.joint is JointType.PRISMATIC:
            cls = rtb.PrismaticMDH if mdh else rtb.PrismaticDH
            links.append(cls(theta=link.theta, a=link.a, alpha=link.alpha, offset=link.d))
        else:
            cls = rtb.RevoluteMDH if mdh else rtb.RevoluteDH
            links.append(cls(d=link.d, a=link.a, alpha=link.alpha, offset=link.theta))
    peer = rtb.DHRobot(links)
    peer.base = robot.base_matrix
    peer.tool = robot.tool_matrix
    return peer


def expand_q(robot: DHRobot, q: np.ndarray) -> np.ndarray:
    """Joint values for :func:`to_roboticstoolbox`'s robot: zeros inserted at fixed rows."""
    q = np.asarray(q, dtype=float)
    full = np.zeros(q.shape[:-1] + (robot.n_rows,))
    full[..., list(robot.joint_rows)] = q
    return full
