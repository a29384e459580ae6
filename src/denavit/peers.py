"""The same DH robot built in the peer libraries Pinocchio and roboticstoolbox-python.

The Pinocchio model is the chain ``C0 · J1(q1) · C1 ⋯ Jn(qn) · Cn`` of :mod:`denavit.chain` (joint k placed
at C_{k-1}, the tool in C_n); each body sits in its DH link frame, reached from its joint's axis frame by the
row constants in between (standard: the joint's own row; modified: none).

Useful for comparing results, and for moving an arm described here into those libraries' tools.
Neither library is a dependency of denavit: install them with ``pip install "denavit[peers]"``.
"""

from __future__ import annotations

import numpy as np

from .chain import chain_of
from .errors import MissingDependencyError
from .model import Convention, DHRobot, JointType

__all__ = ["to_pinocchio", "to_roboticstoolbox", "expand_q"]


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

    chain = chain_of(robot)
    C = chain.constants
    model = pin.Model()
    parent = 0
    for k, r in enumerate(chain.joint_rows):
        jmodel = pin.JointModelRZ() if chain.revolute[k] else pin.JointModelPZ()
        parent = model.addJoint(parent, jmodel, pin.SE3(C[k][:3, :3].copy(), C[k][:3, 3].copy()), f"j{r}")
        li = robot.links[r].inertia
        if li is not None:
            body_in_joint = np.eye(4)  # DH frame {r+1} seen from the axis frame
            for i in range(chain.axis_frame[k], r + 1):
                body_in_joint = body_in_joint @ chain.row_constant(i)
            inertia = pin.Inertia(li.mass, np.array(li.com), li.inertia_matrix)
            X = pin.SE3(body_in_joint[:3, :3].copy(), body_in_joint[:3, 3].copy())
            model.appendBodyToJoint(parent, X.act(inertia), pin.SE3.Identity())
    ee = C[-1]
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
