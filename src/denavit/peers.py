"""The same DH robot built in the peer libraries Pinocchio and roboticstoolbox-python.

The Pinocchio model is the chain ``C0 · J1(q1) · C1 ⋯ Jn(qn) · Cn`` of :mod:`denavit.chain` (joint k placed
at C_{k-1}, the tool in C_n); each body sits in its DH link frame, reached from its joint's axis frame by the
row constants in between (standard: the joint's own row; modified: none).

Useful for comparing results, and for moving an arm described here into those libraries' tools (and, from
roboticstoolbox, back).  Names, limits, gravity, inertias and motor inertia travel with the arm.
Neither library is a dependency of denavit: install them with ``pip install "denavit[peers]"``.
"""

from __future__ import annotations

import warnings

import numpy as np

from .chain import chain_of
from .errors import DenavitWarning, MissingDependencyError, ModelError
from .model import Convention, DHLink, DHRobot, JointType, LinkInertia

__all__ = ["to_pinocchio", "to_roboticstoolbox", "from_roboticstoolbox", "expand_q"]


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

    One Pinocchio joint (RZ or PZ) per DH joint, named ``j<row>``; fixed rows fold into the placements; the end
    effector is the operational frame ``"ee"`` (tool included).  The model's name, gravity, position limits
    and motor inertia (``model.armature``, which Pinocchio's ``crba`` and ``rnea`` include, as denavit's do)
    are copied.
    """
    pin = _need("pinocchio")

    chain = chain_of(robot)
    C = chain.constants
    model = pin.Model()
    parent = 0
    for k, r in enumerate(chain.joint_rows):
        jmodel = pin.JointModelRZ() if chain.revolute[k] else pin.JointModelPZ()
        parent = model.addJoint(parent, jmodel, pin.SE3(C[k][:3, :3].copy(), C[k][:3, 3].copy()), f"j{r}")
        last = chain.joint_rows[k + 1] if k + 1 < chain.dof else robot.n_rows
        body_in_joint = np.eye(4)  # DH frame {row+1} seen from the axis frame
        for row in range(r, last):  # the joint's row and the fixed rows after it: pieces of one body
            if row >= chain.axis_frame[k]:
                body_in_joint = body_in_joint @ chain.row_constant(row)
            li = robot.links[row].inertia
            if li is not None:
                inertia = pin.Inertia(li.mass, np.array(li.com), li.inertia_matrix)
                X = pin.SE3(body_in_joint[:3, :3].copy(), body_in_joint[:3, 3].copy())
                model.appendBodyToJoint(parent, X.act(inertia), pin.SE3.Identity())
    ee = C[-1]
    fid = model.addFrame(pin.Frame("ee", parent, 0, pin.SE3(ee[:3, :3].copy(), ee[:3, 3].copy()), pin.FrameType.OP_FRAME))
    model.gravity.linear = np.array(robot.gravity)
    model.name = robot.name
    for k, link in enumerate(robot.joints):
        if link.q_limits is not None:
            model.lowerPositionLimit[k], model.upperPositionLimit[k] = link.q_limits
        if link.inertia is not None:
            model.armature[k] = link.inertia.motor_inertia
    return model, model.createData(), fid


def to_roboticstoolbox(robot: DHRobot):
    """A roboticstoolbox ``DHRobot`` with the name, limits, gravity, inertias, motor inertia and friction.

    Fixed rows become joints held at zero (see :func:`expand_q`).  Gear ratios are 1 (``G = 1``), so the
    toolbox's motor-side ``Jm``, ``B`` and ``Tc`` are denavit's joint-side motor inertia, viscous and Coulomb
    friction.
    """
    rtb = _need("roboticstoolbox")

    links = []
    mdh = robot.convention is Convention.MODIFIED
    for link in robot.links:
        kw: dict = {}
        if link.q_limits is not None:
            kw["qlim"] = list(link.q_limits)
        li = link.inertia
        if li is not None:
            kw.update(m=li.mass, r=list(li.com), I=li.inertia_matrix, Jm=li.motor_inertia, G=1.0, B=li.viscous,
                      Tc=[li.coulomb, -li.coulomb])
        if link.joint is JointType.PRISMATIC:
            cls = rtb.PrismaticMDH if mdh else rtb.PrismaticDH
            links.append(cls(theta=link.theta, a=link.a, alpha=link.alpha, offset=link.d, **kw))
        else:
            cls = rtb.RevoluteMDH if mdh else rtb.RevoluteDH
            links.append(cls(d=link.d, a=link.a, alpha=link.alpha, offset=link.theta, **kw))
    peer = rtb.DHRobot(links, name=robot.name, gravity=list(robot.gravity))
    peer.base = robot.base_matrix
    peer.tool = robot.tool_matrix
    return peer


def _inertia_from_peer(link, k: int) -> LinkInertia | None:
    """A toolbox link's dynamics, joint side (Jm G², B G², |G| Tc), or None when it has none."""
    G = float(link.G) if link.G is not None else 1.0
    I = np.asarray(link.I, dtype=float).reshape(3, 3)
    tc = np.asarray(link.Tc, dtype=float).ravel()
    tc_pos, tc_neg = (float(tc[0]), float(tc[-1])) if tc.size else (0.0, 0.0)
    coulomb = abs(G) * (tc_pos - tc_neg) / 2
    if abs(tc_pos + tc_neg) > 1e-12 * max(1.0, abs(tc_pos)):
        warnings.warn(f"joint {k + 1}: asymmetric Coulomb friction Tc = [{tc_pos:g}, {tc_neg:g}] read as the "
                      f"symmetric {coulomb:g} (denavit's model is symmetric)", DenavitWarning, stacklevel=3)
    values = dict(mass=float(link.m or 0.0), com=tuple(float(x) for x in np.ravel(link.r)),
                  inertia=(I[0, 0], I[1, 1], I[2, 2], I[0, 1], I[0, 2], I[1, 2]),
                  motor_inertia=float(link.Jm or 0.0) * G * G, viscous=float(link.B or 0.0) * G * G, coulomb=coulomb)
    if not any(np.any(v) for v in values.values()):
        return None
    return LinkInertia(**values)


def from_roboticstoolbox(peer) -> DHRobot:
    """A denavit robot from a roboticstoolbox ``DHRobot``: rows, convention, limits, base, tool, gravity, name,
    inertias and joint-side motor inertia and friction (the toolbox's motor-side values times the gear ratio).

    Raises ModelError for a ``flip``-ped joint (a joint turning against its z axis has no DH row).
    """
    links = []
    for k, link in enumerate(peer.links):
        if getattr(link, "flip", False):
            raise ModelError(f"joint {k + 1} of {peer.name!r} is flipped (turns about -z); it has no DH row")
        qlim = getattr(link, "qlim", None)
        limits = tuple(float(x) for x in np.ravel(qlim)) if qlim is not None else None
        common = dict(a=float(link.a), alpha=float(link.alpha), q_limits=limits, inertia=_inertia_from_peer(link, k))
        if link.isprismatic:
            links.append(DHLink(d=float(link.offset), theta=float(link.theta), joint=JointType.PRISMATIC, **common))
        else:
            links.append(DHLink(d=float(link.d), theta=float(link.offset), joint=JointType.REVOLUTE, **common))
    return DHRobot(name=str(peer.name or "roboticstoolbox"), links=tuple(links),
                   convention=Convention.MODIFIED if peer.mdh else Convention.STANDARD,
                   base=np.asarray(peer.base.A, dtype=float), tool=np.asarray(peer.tool.A, dtype=float),
                   gravity=tuple(float(g) for g in np.ravel(peer.gravity)))


def expand_q(robot: DHRobot, q: np.ndarray) -> np.ndarray:
    """Joint values for :func:`to_roboticstoolbox`'s robot: zeros inserted at fixed rows."""
    q = np.asarray(q, dtype=float)
    full = np.zeros(q.shape[:-1] + (robot.n_rows,))
    full[..., list(robot.joint_rows)] = q
    return full
