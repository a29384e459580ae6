"""A URDF document as checked data: links with their inertials, joints with origin, axis and limits, the tree.

Every value is read with a strict number grammar (no ``nan``, ``inf``, ``1_0``), bounded like a robot file's
(:data:`denavit.model.MAX_MAGNITUDE` for lengths, masses and inertias, :data:`denavit.model.MAX_ANGLE` for
angles), and every error names the file, the element and its line.  Meshes are never opened.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, field
from typing import Iterator

import numpy as np

from ..errors import ParseError
from ..model import MAX_ANGLE, MAX_MAGNITUDE
from ..numeric import transform_from_xyz_rpy
from ._xacro import expand_xacro
from ._xml import Element, parse_xml, read_xml_source

__all__ = ["UrdfInertial", "UrdfLink", "UrdfJoint", "UrdfModel", "read_urdf", "chain_path", "default_tip", "MOVING",
           "MAX_URDF_LINKS", "MAX_NUMBER_CHARS"]

#: Joint types that move and can be a DH row; ``fixed`` folds into the geometry; ``floating`` and ``planar``
#: (6 and 3 degrees of freedom) have no DH row and are refused on the chain.
MOVING = ("revolute", "continuous", "prismatic")
JOINT_TYPES = MOVING + ("fixed", "floating", "planar")
#: Most links in one URDF.
MAX_URDF_LINKS = 1000

#: Longest robot name kept (a robot file's limit too); a longer <robot name> is cut.
MAX_NAME_CHARS = 2000
#: Longest number read from an attribute, in characters: a 45-digit decimal (an exporter printing many digits) is
#: a number; a megabyte of digits is refused before it is converted.
MAX_NUMBER_CHARS = 1000

_NUMBER = re.compile(r"[+-]?(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?\Z")


@dataclass(frozen=True)
class UrdfInertial:
    """A link's inertial: ``mass`` [kg], ``pose`` (4×4, inertial frame in the link frame), ``inertia`` (3×3 about
    the centre of mass, inertial-frame axes) [kg m²]."""

    mass: float
    pose: np.ndarray
    inertia: np.ndarray


@dataclass(frozen=True)
class UrdfLink:
    name: str
    inertial: UrdfInertial | None
    line: int


@dataclass(frozen=True)
class UrdfJoint:
    """A URDF joint: ``origin`` is the child link frame in the parent link frame at q = 0 (4×4); ``axis`` a unit
    3-vector in the child frame; ``limits`` (lower, upper) [rad or m] or None; ``damping``, ``friction`` from
    ``<dynamics>``."""

    name: str
    kind: str
    parent: str
    child: str
    origin: np.ndarray
    axis: np.ndarray
    limits: tuple[float, float] | None
    damping: float
    friction: float
    mimic: bool
    line: int

    @property
    def moving(self) -> bool:
        return self.kind in MOVING


@dataclass(frozen=True)
class UrdfModel:
    """A URDF's robot name, links by name, joints in document order, and the file name for messages."""

    name: str
    where: str
    links: dict[str, UrdfLink]
    joints: tuple[UrdfJoint, ...]
    parent_joint: dict[str, UrdfJoint] = field(default_factory=dict)  # child link -> its joint
    child_joints: dict[str, list[UrdfJoint]] = field(default_factory=dict)  # parent link -> joints

    def error(self, message: str) -> ParseError:
        return ParseError(message, where=self.where)


def _fail(where: str, el: Element, message: str) -> ParseError:
    return ParseError(f"{el.describe()}: {message}", where=where)


def _numbers(where: str, el: Element, attr: str, count: int, default: tuple[float, ...] | None, bound: float,
             what: str = "") -> tuple[float, ...]:
    text = el.attrib.get(attr)
    if text is None:
        if default is None:
            raise _fail(where, el, f"attribute {attr!r} is missing")
        return default
    parts = text.split()
    if len(parts) != count:
        raise _fail(where, el, f"{attr}={text[:60]!r}: expected {count} number{'s' if count > 1 else ''}")
    out = []
    for p in parts:
        if len(p) > MAX_NUMBER_CHARS:
            raise _fail(where, el, f"{attr}={text[:60]!r}...: a number longer than {MAX_NUMBER_CHARS} characters")
        if not _NUMBER.match(p):
            raise _fail(where, el, f"{attr}={text[:60]!r}: {p[:40]!r} is not a number")
        v = float(p)
        if not math.isfinite(v) or abs(v) > bound:
            raise _fail(where, el, f"{attr}={text[:60]!r}: {p[:40]} is out of range (at most {bound:g}{what} in "
                                   "magnitude)")
        out.append(v)
    return tuple(out)


def _origin(where: str, el: Element | None) -> np.ndarray:
    if el is None:
        return np.eye(4)
    xyz = _numbers(where, el, "xyz", 3, (0.0, 0.0, 0.0), MAX_MAGNITUDE, " m")
    rpy = _numbers(where, el, "rpy", 3, (0.0, 0.0, 0.0), MAX_ANGLE, " rad")
    return transform_from_xyz_rpy(xyz, rpy)


def _name(where: str, el: Element) -> str:
    name = el.attrib.get("name")
    if not name:
        raise _fail(where, el, "attribute 'name' is missing")
    if len(name) > 200:
        raise _fail(where, el, "name longer than 200 characters")
    return name


def _inertial(where: str, el: Element) -> UrdfInertial:
    mass_el = el.find("mass")
    if mass_el is None:
        raise _fail(where, el, "<mass> is missing")
    (mass,) = _numbers(where, mass_el, "value", 1, None, MAX_MAGNITUDE, " kg")
    if mass < 0:
        raise _fail(where, mass_el, f"mass {mass:g} is negative")
    in_el = el.find("inertia")
    I = np.zeros((3, 3))
    if in_el is not None:
        names = ("ixx", "iyy", "izz", "ixy", "ixz", "iyz")
        # all six are required (the URDF specification; urdfdom drops a tensor that lacks one)
        ixx, iyy, izz, ixy, ixz, iyz = (_numbers(where, in_el, k, 1, None, MAX_MAGNITUDE, " kg m²")[0] for k in names)
        I = np.array([[ixx, ixy, ixz], [ixy, iyy, iyz], [ixz, iyz, izz]])
    return UrdfInertial(mass, _origin(where, el.find("origin")), I)


def _joint(where: str, el: Element, links: dict[str, UrdfLink]) -> UrdfJoint:
    name = _name(where, el)
    kind = el.attrib.get("type", "")
    if kind not in JOINT_TYPES:
        raise _fail(where, el, f"type {kind[:40]!r} is not a URDF joint type; expected one of {', '.join(JOINT_TYPES)}")
    ends = []
    for end in ("parent", "child"):
        e = el.find(end)
        if e is None or not e.attrib.get("link"):
            raise _fail(where, el, f"<{end} link=...> is missing")
        if e.attrib["link"] not in links:
            raise _fail(where, e, f"link {e.attrib['link'][:60]!r} is not defined")
        ends.append(e.attrib["link"])
    axis = np.array([1.0, 0.0, 0.0])
    axis_el = el.find("axis")
    if axis_el is not None:
        axis = np.array(_numbers(where, axis_el, "xyz", 3, (1.0, 0.0, 0.0), MAX_MAGNITUDE))
    norm = float(np.linalg.norm(axis))
    if kind in MOVING and not norm > 1e-9:
        raise _fail(where, axis_el or el, "the joint axis is the zero vector")
    limits = None
    lim_el = el.find("limit")
    if lim_el is not None and kind in ("revolute", "prismatic") and ("lower" in lim_el.attrib or "upper" in lim_el.attrib):
        bound, unit = (MAX_ANGLE, " rad") if kind == "revolute" else (MAX_MAGNITUDE, " m")
        (lo,) = _numbers(where, lim_el, "lower", 1, (0.0,), bound, unit)
        (hi,) = _numbers(where, lim_el, "upper", 1, (0.0,), bound, unit)
        if lo > hi:
            raise _fail(where, lim_el, f"lower {lo:g} > upper {hi:g}")
        limits = (lo, hi)
    damping = friction = 0.0
    dyn = el.find("dynamics")
    if dyn is not None:
        (damping,) = _numbers(where, dyn, "damping", 1, (0.0,), MAX_MAGNITUDE)
        (friction,) = _numbers(where, dyn, "friction", 1, (0.0,), MAX_MAGNITUDE)
        if damping < 0 or friction < 0:
            raise _fail(where, dyn, "damping and friction must be non-negative")
    return UrdfJoint(name, kind, ends[0], ends[1], _origin(where, el.find("origin")),
                     axis / norm if norm > 0 else axis, limits, damping, friction, el.find("mimic") is not None, el.line)


def read_urdf(source, *, xacro: bool = False) -> UrdfModel:
    """The checked links, joints and tree of a URDF file or text (ParseError naming file, element and line).

    A xacro file (``*.xacro``) is a program: its ``${...}`` expressions are evaluated by Python.  It is expanded
    (by the optional ``xacrodoc``) only with ``xacro=True``, for files one trusts; the document is checked as
    untrusted XML first (no DTD, size and depth bounds) and the expanded URDF again.
    """
    where, data = read_xml_source(source)
    is_path = not (isinstance(source, str) and source.lstrip().startswith("<"))
    if is_path and str(source).lower().endswith(".xacro") and not xacro:
        raise ParseError("a xacro file is a program (Python evaluates its ${...} expressions); expand it only "
                         "if you trust it: --xacro (xacro=True)", where=where)
    root = parse_xml(data, where)
    if xacro:
        import os

        data = expand_xacro(data, where, os.path.dirname(os.path.abspath(str(source))) if is_path else None)
        where = f"{where} (expanded)"
        root = parse_xml(data, where)
    if root.tag != "robot":
        raise ParseError(f"the root element is <{root.tag[:40]}>, not <robot> (not a URDF)", where=where)
    links: dict[str, UrdfLink] = {}
    for el in root.iter("link"):
        name = _name(where, el)
        if name in links:
            raise _fail(where, el, "a link of this name is already defined")
        if len(links) >= MAX_URDF_LINKS:
            raise _fail(where, el, f"more than {MAX_URDF_LINKS} links")
        inertial = el.find("inertial")
        links[name] = UrdfLink(name, _inertial(where, inertial) if inertial is not None else None, el.line)
    if not links:
        raise ParseError("the URDF defines no <link>", where=where)
    joints: list[UrdfJoint] = []
    names: set[str] = set()
    parent_joint: dict[str, UrdfJoint] = {}
    child_joints: dict[str, list[UrdfJoint]] = {}
    for el in root.iter("joint"):
        j = _joint(where, el, links)
        if j.name in names:
            raise _fail(where, el, "a joint of this name is already defined")
        if j.child in parent_joint:
            raise _fail(where, el, f"link {j.child[:60]!r} is already the child of joint "
                                   f"{parent_joint[j.child].name[:60]!r} (a URDF is a tree)")
        names.add(j.name)
        joints.append(j)
        parent_joint[j.child] = j
        child_joints.setdefault(j.parent, []).append(j)
    model = UrdfModel(str(root.attrib.get("name", ""))[:MAX_NAME_CHARS] or "urdf", where, links, tuple(joints), parent_joint,
                      child_joints)
    _check_tree(model)
    return model


def _check_tree(model: UrdfModel) -> None:
    """A cycle in the joint tree (a link that is its own ancestor) is refused, naming a joint on it."""
    done: set[str] = set()
    for start in model.links:
        seen: list[str] = []
        link = start
        while link in model.parent_joint and link not in done:
            if link in seen:
                j = model.parent_joint[link]
                raise model.error(f"<joint name={j.name[:40]!r}> (line {j.line}): the joints form a cycle through "
                                  f"link {link[:60]!r} (a URDF is a tree)")
            seen.append(link)
            link = model.parent_joint[link].parent
        done.update(seen)


def _roots(model: UrdfModel) -> list[str]:
    return [name for name in model.links if name not in model.parent_joint]


def _leaves_below(model: UrdfModel, link: str) -> Iterator[str]:
    stack = [link]
    while stack:
        here = stack.pop()
        kids = model.child_joints.get(here, [])
        if not kids:
            yield here
        stack.extend(j.child for j in reversed(kids))


def _moving_depth(model: UrdfModel, link: str, base: str) -> int:
    count = 0
    while link != base:
        j = model.parent_joint[link]
        count += j.moving
        link = j.parent
    return count


#: End links preferred, in this order, among frames fixed to the chain's last link (ROS-Industrial's tool0 is
#: the flange frame; ee_link its older name); without one, the chain's last link itself is the end.
PREFERRED_TIPS = ("tool0", "flange", "tcp", "ee_link")


def _ancestors(model: UrdfModel, link: str, base: str) -> list[str]:
    """Links from ``base`` down to ``link``, both included."""
    up = [link]
    while link != base:
        link = model.parent_joint[link].parent
        up.append(link)
    return up[::-1]


def default_tip(model: UrdfModel, base: str) -> tuple[str, str]:
    """The end link below ``base`` when none is given, and the sentence saying why ("" for a lone leaf).

    The leaf reached through the most moving joints; leaves hanging off by fixed joints (sensor and tool frames)
    do not compete.  When several tie, the link where they branch (their last common link) is the end, if each
    branch has fewer moving joints below it than the chain above it (a gripper's fingers below the hand, not
    two arms on a torso): that link (the Panda's hand, not its fingers), or a leaf fixed to it with a usual end-frame
    name (:data:`PREFERRED_TIPS`: the UR's ``tool0`` over ``ee_link``).  Otherwise ``--tip`` is needed and the
    error lists the leaves.
    """
    leaves = list(_leaves_below(model, base))
    if len(leaves) == 1:
        return leaves[0], ""
    depth = {leaf: _moving_depth(model, leaf, base) for leaf in leaves}
    best = max(depth.values())
    top = [leaf for leaf in leaves if depth[leaf] == best]
    if len(top) == 1:
        return top[0], f"the leaf with the most moving joints ({best}; other leaves: {_names(set(leaves) - set(top))})"
    lines = [_ancestors(model, leaf, base) for leaf in top]
    k = 0  # lines[*][k] is the last link common to every tied leaf's line
    while all(len(li) > k + 1 for li in lines) and len({li[k + 1] for li in lines}) == 1:
        k += 1
    fork = lines[0][k]
    above = _moving_depth(model, fork, base)
    if above == 0 or best - above >= above:
        raise model.error(f"the tree branches below link {base[:60]!r} into {len(top)} chains of {best} moving "
                          f"joints; choose the end link with --tip (leaves: {_names(top)})")
    fixed = sorted(leaf for leaf in leaves if fork in _ancestors(model, leaf, base) and leaf != fork
                   and _moving_depth(model, leaf, fork) == 0)
    tip = next((name for name in PREFERRED_TIPS if name in fixed), fork)
    if tip == fork:
        return tip, (f"the {above}-joint chain branches there into {_names(top)}"
                     + (f"; fixed to it: {_names(fixed)}" if fixed else ""))
    return tip, (f"{_names(fixed)} {'are' if len(fixed) > 1 else 'is'} fixed to {fork}, the end of the {above}-joint "
                 f"chain; {tip} is the usual name of the end frame")


def _names(names) -> str:
    names = sorted(names)
    return ", ".join(x[:40] for x in names[:12]) + (" ..." if len(names) > 12 else "")


def chain_path(model: UrdfModel, base: str | None = None, tip: str | None = None) -> tuple[str, str, list[UrdfJoint]]:
    """``(base, tip, joints)``: the joints from link ``base`` to link ``tip``, base first.

    ``base`` defaults to the tree's root; ``tip`` to :func:`default_tip`'s choice.
    """
    for what, name in (("base", base), ("tip", tip)):
        if name is not None and name not in model.links:
            known = ", ".join(list(model.links)[:12]) + (" ..." if len(model.links) > 12 else "")
            raise model.error(f"--{what} {name[:60]!r}: no such link (links: {known})")
    if base is None:
        roots = _roots(model)
        if len(roots) != 1:
            raise model.error(f"{len(roots)} links have no parent joint ({', '.join(r[:40] for r in roots[:6])}); "
                              "a URDF is one tree")
        base = roots[0]
    if tip is None:
        tip = default_tip(model, base)[0]
    if tip == base:
        why = ("choose --tip below --base" if model.child_joints.get(base) else
               f"no link hangs below {base[:60]!r}; choose a --base nearer the root" if base in model.parent_joint
               else "the URDF has no joints")
        raise model.error(f"the chain from link {base[:60]!r} to link {tip[:60]!r} is empty: {why}")
    path: list[UrdfJoint] = []
    link = tip
    while link != base:
        if link not in model.parent_joint:
            raise model.error(f"link {tip[:60]!r} is not below link {base[:60]!r}; choose --base and --tip on one "
                              "branch")
        j = model.parent_joint[link]
        path.append(j)
        link = j.parent
    path.reverse()
    return base, tip, path


def subtree_joints(model: UrdfModel, link: str, skip: UrdfJoint | None) -> Iterator[tuple[UrdfJoint, np.ndarray]]:
    """Joints below ``link`` except the branch of ``skip``, each with its child frame in ``link``'s frame at q = 0."""
    stack = [(j, j.origin) for j in model.child_joints.get(link, []) if j is not skip]
    while stack:
        j, T = stack.pop()
        yield j, T
        stack.extend((k, T @ k.origin) for k in model.child_joints.get(j.child, []))
