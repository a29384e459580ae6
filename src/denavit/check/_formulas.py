"""The correct formula of an incorrect claim, in LaTeX, from the symbolic engine (when it is cheap).

Moved unchanged from ``_engine.py``.
"""

from __future__ import annotations

import re

from functools import lru_cache
from typing import Any

from .. import _expr
from ..errors import DenavitError, ParseError
from ..model import DHRobot
from ._points import wrench_nodes

__all__ = ["expected_formula", "MAX_FORMULA_DOF_DYNAMICS", "MAX_FORMULA_DOF_STATICS", "MAX_FORMULA_DOF_JACOBIAN"]


def expected_formula(robot: DHRobot, name: str, spec: dict[str, Any]) -> str | None:
    """The correct formula in LaTeX (C_12/S_3 shorthand) from the symbolic engine, when it is cheap."""
    keys = tuple(spec.get(k) for k in ("index", "from", "to"))
    if not all(k is None or (isinstance(k, int) and not isinstance(k, bool)) for k in keys):
        return None
    if name in ("force", "moment"):
        return _expected_statics(robot, name, spec)
    if name == "jacobian":
        frame = spec.get("frame", "base")
        if spec.get("column") is not None or spec.get("rows", "all") != "all" or spec.get("entry") is not None \
                or not (frame in ("base", "tool")):
            return None  # a part of J, or J in frame i: the numbers and hints say what differs
        return _expected_jacobian(robot, str(frame), spec.get("_rows"))
    return _expected_formula(robot, name, *keys)


#: Most joints for which an incorrect M or g(q) claim is given the correct formula (symbolic Lagrangian dynamics).
MAX_FORMULA_DOF_DYNAMICS = 4
#: Most joints for which an incorrect ⁱfᵢ / ⁱnᵢ claim is given the correct formula (symbolic force propagation of a
#: 6-joint arm takes seconds).
MAX_FORMULA_DOF_STATICS = 4


def _expected_statics(robot: DHRobot, name: str, spec: dict[str, Any]) -> str | None:
    """ⁱfᵢ / ⁱnᵢ from the symbolic force propagation, with the claim's wrench (tool axes) put in."""
    import sympy as sp

    from .. import symbolic as S

    if robot.dof > MAX_FORMULA_DOF_STATICS or str(spec.get("frame", "tool")) != "tool" or "wrench" not in spec:
        return None
    try:
        nodes = wrench_nodes(spec["wrench"], robot)
        syms = {n: sp.Symbol(n[0] + "_" + n[1:]) for nd in nodes for n in _expr.names_in(nd)}
        params = {k: sp.Symbol(k) for k, _ in robot.parameters}
        values = [_expr.to_sympy(nd, {**params, **syms}) for nd in nodes]
        prop = _statics_sym(robot)
    except (ParseError, KeyError, ValueError, TypeError):
        return None
    steps = {st.label: st for st in prop.steps}
    step = steps.get(str(spec.get("index")))
    if step is None:
        return None
    M = (step.f if name == "force" else step.n).xreplace(dict(zip(S.wrench_symbols(), values)))
    M = sp.ImmutableMatrix(M.applyfunc(sp.expand))
    if len(str(M)) > 20_000:
        return None
    return _latex(S.shorthand_matrix(M, S.joint_symbols(robot.dof).q))


@lru_cache(maxsize=8)
def _statics_sym(robot: DHRobot):
    from .. import symbolic as S

    return S.force_propagation_sym(robot)


@lru_cache(maxsize=64)
def _expected_formula(robot: DHRobot, name: str, index: int | None, frm: int | None, to: int | None) -> str | None:
    import sympy as sp

    from .. import symbolic as S

    spec = {k: v for k, v in (("index", index), ("from", frm), ("to", to)) if v is not None}
    try:
        if name == "link_transform":
            M = S.simplify_matrix(S.link_matrices_sym(robot)[int(spec["index"]) - 1])
        elif name == "transform":
            F = S.link_transforms_sym(robot)
            i, j = int(spec.get("from", 0)), int(spec.get("to", robot.n_rows))
            M = S.simplify_matrix(_inverse(F[i]) * F[j])
        elif name in ("end_effector", "position", "rotation"):
            T = S.forward_kinematics_sym(robot)
            M = T if name == "end_effector" else T[:3, 3] if name == "position" else T[:3, :3]
        elif name in ("gravity", "mass_matrix"):
            if robot.dof > MAX_FORMULA_DOF_DYNAMICS or not robot.has_dynamics:
                return None
            terms = S.lagrangian_dynamics(robot, coriolis=False)
            if name == "mass_matrix":
                M = terms.M
            elif terms.g_unit is not None and "g" not in robot.parameter_values:
                M = sp.Symbol("g") * terms.g_unit  # the symbol g, not 981/100
            else:
                M = terms.g
        elif name in ("omega", "velocity"):
            steps = {st.label: st for st in S.velocity_propagation_sym(robot).steps}
            step = steps[str(spec["index"])]
            M = step.omega if name == "omega" else step.v
        else:
            return None
    except (KeyError, ValueError, IndexError, TypeError, DenavitError):
        return None
    if len(str(M)) > 20_000:
        return None
    M = S.shorthand_matrix(sp.ImmutableMatrix(M), S.joint_symbols(robot.dof).q)
    return _latex(M)


#: Most joints for which an incorrect J claim is given the correct formula (symbolic geometric Jacobian).
MAX_FORMULA_DOF_JACOBIAN = 4


@lru_cache(maxsize=16)
def _expected_jacobian(robot: DHRobot, frame: str, rows: tuple[int, ...] | None = None) -> str | None:
    """J0 or Je from the symbolic engine (arms of up to MAX_FORMULA_DOF_JACOBIAN joints: seconds at most); only
    ``rows`` (indices into (vx, vy, vz, ωx, ωy, ωz)) when the claim was read as those rows."""
    import sympy as sp

    from .. import symbolic as S

    if robot.dof > MAX_FORMULA_DOF_JACOBIAN:
        return None
    try:
        M = S.geometric_jacobian_sym(robot, frame=frame)
    except (ValueError, TypeError, DenavitError):
        return None
    if len(str(M)) > 20_000:
        return None
    M = S.shorthand_matrix(sp.ImmutableMatrix(M), S.joint_symbols(robot.dof).q)
    if rows:
        M = M.extract(list(rows), list(range(M.shape[1])))
    return _latex(M)


def _inverse(T):
    import sympy as sp

    R, p = T[:3, :3], T[:3, 3]
    return sp.ImmutableMatrix(sp.BlockMatrix([[R.T, -R.T * p], [sp.zeros(1, 3), sp.ones(1, 1)]]).as_explicit())


_COM_NAME = re.compile(r"(ell|[A-Za-z])c(\d{1,2})")


def _latex(M) -> str:
    """A result in LaTeX, a centre-of-mass distance as a report writes it: ``ellc1`` → ℓ_{c1}, ``Lc2`` → L_{c2}."""
    import sympy as sp

    names = {}
    for sym in M.free_symbols:
        m = _COM_NAME.fullmatch(sym.name)
        if m:
            names[sym] = ("\\ell" if m.group(1) == "ell" else m.group(1)) + f"_{{c{m.group(2)}}}"
    return sp.latex(M, mat_str="bmatrix", mat_delim="", symbol_names=names)
