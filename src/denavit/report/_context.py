"""What every section of a report needs: the robot, the numeric case read exactly, cached symbolic results."""

from __future__ import annotations

import math
from functools import cached_property
from typing import Any, Sequence

import numpy as np
import sympy as sp

from .. import _expr
from .. import symbolic as S
from ..chain import chain_of
from ..errors import ParseError
from ..model import DHRobot, JointType

__all__ = ["Context", "exact_values", "EXACT_TOL", "MAX_SYMBOLIC_CHARS"]

EXACT_TOL = 1e-12  # exact value vs the numeric engine
MAX_SYMBOLIC_CHARS = 30_000  # longer symbolic results are not printed (they help nobody)
MAX_FK_CHARS_FOR_JACOBIAN = 4_000  # beyond this the symbolic Jacobian takes long and reads badly


def _exact(value: Any, place: str, deg: bool = False) -> sp.Expr:
    """One value as an exact sympy number: text through the restricted parser, floats recognised."""
    if isinstance(value, str):
        try:
            tree = _expr.parse(value)
            if deg and not _has_unit(tree):
                tree = ("call", "deg", (tree,))
            out = _expr.to_sympy(tree, {})
        except ParseError as exc:
            raise ParseError(f"{place}: {exc}") from None
        if not out.is_number:
            raise ParseError(f"{place}: {value!r} is not a number")
        return out
    x = float(value)
    if not math.isfinite(x):
        raise ParseError(f"{place}: value must be finite, got {value!r}")
    if deg:
        x = math.radians(x)
    guess = sp.nsimplify(x, [sp.pi], tolerance=1e-13)
    if abs(float(guess) - x) <= 1e-14 * max(1.0, abs(x)):
        return guess
    return sp.Rational(repr(x))


def _has_unit(tree: _expr.Node) -> bool:
    if tree[0] == "name":
        return tree[1] == "pi"
    if tree[0] == "call":
        return tree[1] in ("deg", "rad") or any(_has_unit(a) for a in tree[2])
    if tree[0] == "neg":
        return _has_unit(tree[1])
    if tree[0] == "bin":
        return _has_unit(tree[2]) or _has_unit(tree[3])
    return False


def exact_values(values: Sequence[Any], n: int, what: str, deg_mask: Sequence[bool] | None = None) -> tuple:
    """A vector of exact sympy numbers (length ``n``) from strings or floats."""
    if isinstance(values, str):
        import re

        values = [p for p in re.split(r"[,;\s]+(?![^()]*\))", values.strip().strip("[]()")) if p]
    values = list(values)
    if len(values) != n:
        raise ParseError(f"{what}: expected {n} values, got {len(values)}")
    mask = list(deg_mask) if deg_mask is not None else [False] * n
    return tuple(_exact(v, f"{what}: value {i + 1}", mask[i]) for i, v in enumerate(values))


def default_q(robot: DHRobot) -> tuple:
    """π/6 for revolute joints (clipped into the limits), the middle of the stroke for prismatic ones."""
    out = []
    for link in robot.joints:
        lo, hi = link.q_limits if link.q_limits is not None else (-np.inf, np.inf)
        if link.joint is JointType.REVOLUTE:
            v = sp.pi / 6
            if not (lo <= float(v) <= hi):
                v = sp.nsimplify((lo + hi) / 2, [sp.pi], tolerance=1e-9)
        else:
            v = sp.Rational(repr(round((lo + hi) / 2, 4))) if math.isfinite(lo + hi) else sp.Rational(1, 10)
        out.append(v)
    return tuple(out)


class Context:
    """Inputs of a report read once, plus symbolic results computed once and shared by the sections."""

    def __init__(self, robot: DHRobot, q, qd, wrench, simplify: str, q_given: bool, deg: bool) -> None:
        self.robot = robot
        self.q_exact = q
        self.qd_exact = qd
        self.wrench_exact = wrench
        self.q_given = q_given
        self.simplify = simplify
        self.deg = deg
        self.q = np.array([float(v) for v in q])
        self.qd = None if qd is None else np.array([float(v) for v in qd])
        self.wrench = None if wrench is None else np.array([float(v) for v in wrench])
        self.syms = S.joint_symbols(robot.dof)

    @classmethod
    def build(cls, robot: DHRobot, q, qd, wrench, *, simplify: str = "trig", deg: bool = False) -> "Context":
        if simplify not in S.POLICIES:
            raise ParseError(f"unknown simplification policy {simplify!r}; choose one of {', '.join(S.POLICIES)}")
        revolute = [t is JointType.REVOLUTE for t in robot.joint_types]
        mask = revolute if deg else None
        pose = None
        if isinstance(q, str):  # a named pose of the robot ("qr"): its values, made exact where they are simple
            from ..io import resolve_pose

            pose = resolve_pose(robot, q)
        if pose is not None:
            q_exact = tuple(sp.nsimplify(float(v), [sp.pi], tolerance=1e-12) for v in pose)
        else:
            q_exact = default_q(robot) if q is None else exact_values(q, robot.dof, "q", mask)
        qd_exact = None if qd is None else exact_values(qd, robot.dof, "qd", mask)
        w_exact = None if wrench is None else exact_values(wrench, 6, "wrench")
        return cls(robot, q_exact, qd_exact, w_exact, simplify, q is not None, deg)

    def inputs(self) -> dict[str, Any]:
        return {
            "robot": self.robot.name,
            "convention": self.robot.convention.value,
            "q": self.q.tolist(),
            "q_exact": [str(v) for v in self.q_exact],
            "q_given": self.q_given,
            "qd": None if self.qd is None else self.qd.tolist(),
            "wrench": None if self.wrench is None else self.wrench.tolist(),
            "simplify": self.simplify,
        }

    #: Cached results that do not depend on the numeric case (shared between the cases of one report).
    SHARED = ("param_subs", "symbolic_jacobian_ok", "base_exact", "tool_exact", "links_sym", "frames_sym", "fk_sym",
              "has_base_or_tool", "joint_frames_sym", "_J_sym", "_dT_sym")

    def share_symbolic(self, other: "Context") -> None:
        """Take ``other``'s case-independent results computed so far (same robot and simplification policy)."""
        if other is self or other.robot is not self.robot or other.simplify != self.simplify:
            return
        for key in self.SHARED:
            if key in other.__dict__ and key not in self.__dict__:
                self.__dict__[key] = other.__dict__[key]

    # --- symbols and substitutions ---------------------------------------------------------------
    @property
    def q_syms(self) -> tuple:
        return self.syms.q

    @cached_property
    def q_subs(self) -> dict:
        return dict(zip(self.syms.q, self.q_exact))

    @cached_property
    def param_subs(self) -> dict:
        syms = S.parameter_symbols(self.robot)
        return {syms[k]: sp.Rational(repr(v)) for k, v in self.robot.parameters}

    def at_case(self, M: Any) -> Any:
        """Substitute the robot's parameter values and the exact q of the numeric case, then tidy."""
        M = sp.ImmutableMatrix(M) if hasattr(M, "shape") else M
        out = M.xreplace(self.param_subs).xreplace(self.q_subs)
        if hasattr(out, "applyfunc"):
            return sp.ImmutableMatrix(out.applyfunc(_tidy_number))
        return _tidy_number(out)

    def short(self, M: Any) -> Any:
        """C_12 / S_3 shorthand for display."""
        if hasattr(M, "shape"):
            return S.shorthand_matrix(M, self.syms.q)
        return S.shorthand(M, self.syms.q)

    def too_long(self, M: Any) -> bool:
        return len(str(M)) > MAX_SYMBOLIC_CHARS

    @cached_property
    def symbolic_jacobian_ok(self) -> bool:
        """The symbolic Jacobian is derived when the pose formula is of a size a person can read."""
        return len(str(self.fk_sym)) <= MAX_FK_CHARS_FOR_JACOBIAN

    @cached_property
    def exact_ok(self) -> bool:
        """True when exact values are worth showing: revolute q are multiples of π/12 (their sines and
        cosines are short surds) and prismatic q are rationals."""
        for v, jt in zip(self.q_exact, self.robot.joint_types):
            if jt is JointType.REVOLUTE:
                r = sp.simplify(v / sp.pi)
                if not (r.is_Rational and (12 % r.q == 0)):
                    return False
            elif not v.is_Rational:
                return False
        return True

    @cached_property
    def frames_case(self) -> tuple:
        """World frames {0}..{N} at the numeric case, exact (base applied), computed from exact link matrices."""
        T = self.base_exact
        out = [T]
        for A in S.link_matrices_sym(self.robot, numeric=True):
            T = sp.ImmutableMatrix((T * self.at_case(A)).applyfunc(_tidy_number))
            out.append(T)
        return tuple(out)

    # --- symbolic results, computed once ---------------------------------------------------------
    @cached_property
    def base_exact(self) -> sp.ImmutableMatrix:
        return S.matrix_from_floats(self.robot.base_matrix)

    @cached_property
    def tool_exact(self) -> sp.ImmutableMatrix:
        return S.matrix_from_floats(self.robot.tool_matrix)

    @cached_property
    def links_sym(self) -> tuple:
        return S.link_matrices_sym(self.robot)

    @cached_property
    def frames_sym(self) -> tuple:
        """T_0_0 … T_0_N in the robot's parameters (base not applied)."""
        return S.link_transforms_sym(self.robot, self.simplify)

    @cached_property
    def fk_sym(self) -> sp.ImmutableMatrix:
        return S.forward_kinematics_sym(self.robot, self.simplify)

    @cached_property
    def has_base_or_tool(self) -> bool:
        return not (np.allclose(self.robot.base_matrix, np.eye(4)) and np.allclose(self.robot.tool_matrix, np.eye(4)))

    @cached_property
    def joint_frames_sym(self) -> list[tuple[sp.ImmutableMatrix, sp.ImmutableMatrix]]:
        """(z_i, p_i) of every joint axis in world axes: standard DH z_{i-1}, o_{i-1}; modified z_i, o_i."""
        out = []
        for f in chain_of(self.robot).axis_frame:
            F = self.base_exact * self.frames_sym[f]
            out.append((sp.ImmutableMatrix(F[:3, 2]), sp.ImmutableMatrix(F[:3, 3])))
        return out


def _tidy_number(e: Any) -> Any:
    """Exact numeric expressions in a readable form (√3/4 rather than sin(π/3)/2)."""
    if getattr(e, "is_number", False) and not e.is_Rational:
        return sp.radsimp(sp.expand(e))
    return e
