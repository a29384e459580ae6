"""One equation's claim: the :class:`Pending` it becomes and the claim built from its reading and the context.

Moved from ``_claims.py`` (code unchanged: the walker's ``claim``/``_wrench`` methods as functions of the context).
"""

from __future__ import annotations

import itertools
import re
from dataclasses import dataclass, field
from typing import Any

from .._constants import TWIST_ROWS
from ._arms import Arm
from ._context import Context, has_joint_names, vector_entries
from ._names import Reading
from ._reading import det_rows, used_where
from ._lhs import read_symbol
from ._shorthand import renamed, trig_named, trig_of_joint
from ._split import Equation
from ._values import WRENCH_NAMES, expand_product, matrices, numeric_value, scale_matrix, wrench_symbols

__all__ = ["Pending", "build_claim", "det_pending", "ik_formula_pending", "manipulability_pending", "singular_pending",
           "MANIPULABILITY"]


@dataclass
class Pending:
    """One equation on its way to a verdict."""

    line: int
    end_line: int
    latex: str
    arm: Arm | None
    claim: dict[str, Any] | None = None
    understood: str = ""
    alternatives: list[tuple[dict[str, Any], str]] = field(default_factory=list)
    equivalent: list[tuple[dict[str, Any], str]] = field(default_factory=list)
    sure: bool = True
    verdict: str = ""
    message: str = ""
    quantity: str = ""
    numeric_without_case: bool = False
    numeric_without_wrench: bool = False  # numbers for τ, ⁱfᵢ, ⁱnᵢ with no wrench stated: judged at random ones
    numeric_without_rates: bool = False  # numbers for a velocity with no joint rates stated: judged at random ones
    not_a_claim_if_unreadable: bool = False


def build_claim(ctx: Context, eq: Equation, arm: Arm, reading: Reading, value: str) -> Pending:
    """The claim an equation makes under ``reading`` (with the case, rates, wrench and names ``ctx`` carries), and
    the other readings of its left-hand side."""
    value = renamed(value, ctx.renames) if ctx.renames else value
    if reading.spec.get("quantity") == "heading":
        return _heading(ctx, eq, arm, reading, value)
    if "\\begin" in value and matrices(value) is None:
        value = scale_matrix(value) or value
    if "\\begin" in value:
        mats = matrices(value)
        expanded = expand_product(value) if mats is not None and len(mats) == 2 else None
        if mats is None or len(mats) > 2 or (len(mats) == 2 and expanded is None):
            return Pending(eq.line, eq.end_line, eq.text, arm, None, reading.understood, verdict="not a claim",
                           message="not judged: a matrix expression (products, sums with other results), not "
                           "one value; the result after it is judged", quantity=str(reading.spec.get("quantity")))
        if expanded is not None:
            value = expanded
            if reading.spec["quantity"] == "end_effector":  # "T = [J^T] [f]": an OCR'd τ
                reading = Reading({"quantity": "torques"}, "τ (written T)", sure=False, needs=("q", "wrench"))
    qty = str(reading.spec.get("quantity"))
    if "wrench" in reading.needs:  # F = [F_x, F_y, M_z]: the wrench's names as the checker's f_x, f_y, n_z
        value = _CAPITAL_WRENCH.sub(lambda m: f"{'n' if m.group(1) in 'Mm' else m.group(1).lower()}_{{{m.group(2)}}}",
                                    value)  # a moment m_z / M_z is the checker's n_z
    vec = vector_entries(value)
    spec = dict(reading.spec)
    if qty in ("torques", "equations_of_motion") and "entry" in spec and vec and len(vec) == arm.robot.dof:
        spec.pop("entry")  # "τ_2 = [2 entries]": the subscript is a label
        reading = Reading(spec, "the joint torques τ (the subscript read as a label)", sure=False,
                          needs=reading.needs)
    claim: dict[str, Any] = {**spec, "value": value}
    numeric = numeric_value(value)
    p = Pending(eq.line, eq.end_line, eq.text, arm, claim, reading.understood, sure=reading.sure,
                quantity=qty)
    p.alternatives = [({**alt, "value": value}, words) for alt, words in reading.alternatives]
    if not has_joint_names(value) and ctx.q:
        claim["q"] = ctx.q  # a value without joint variables, after a case: that case's value
    elif numeric:
        p.numeric_without_case = True
    if "qd" in reading.needs and numeric and ctx.qd:
        claim["qd"] = ctx.qd
    elif "qd" in reading.needs and numeric:
        p.numeric_without_rates = True
    if "wrench" in reading.needs:
        _wrench(ctx, p, claim, value, numeric)
    if qty == "jacobian" and "frame" not in claim and ctx.jacobian_frame is not None:
        claim["frame"] = ctx.jacobian_frame
        p.understood += f" (in the axes of frame {ctx.jacobian_frame}, as the ⁱJ before it)"
        p.alternatives.append(({**claim, "frame": "base"}, "J0, in base axes"))
    elif qty == "jacobian" and "frame" not in claim:
        p.alternatives += [({**claim, "frame": f}, f"ⁱJ in the axes of frame {f}")
                           for f in range(1, arm.robot.n_rows + 1)] + [({**claim, "frame": "tool"}, "Je")]
    if qty == "jacobian" and isinstance(claim.get("frame"), int):
        ctx.jacobian_frame = claim["frame"]
    used = used_where(ctx.where, value)
    if used:
        claim["where"] = used
    if vec is not None and len(vec) == 2 and qty in ("position", "com_position", "com_velocity", "origin"):
        flat = {**claim, "value": "[" + ", ".join(vec + ["0"]) + "]"}
        p.equivalent.append((flat, "the (x, y) of a planar arm, z = 0"))
    for alt, _ in p.alternatives + p.equivalent:
        for key in ("q", "qd", "wrench", "where"):
            if key in claim and key not in alt:
                alt[key] = claim[key]
    return p

def _heading(ctx: Context, eq: Equation, arm: Arm, reading: Reading, value: str) -> Pending:
    """``φ = θ1 + θ2 + θ3`` on an arm moving in the xy plane: the end effector's rotation is a turn φ about z (tool
    z up), or φ with the tool's z down (a SCARA: [c s 0; s −c 0; 0 0 −1]); a guess (never incorrect) when the arm
    has a base or tool transform."""
    c, s = f"\\cos({value})", f"\\sin({value})"
    up = f"\\begin{{bmatrix}} {c} & -{s} & 0 \\\\ {s} & {c} & 0 \\\\ 0 & 0 & 1 \\end{{bmatrix}}"
    down = f"\\begin{{bmatrix}} {c} & {s} & 0 \\\\ {s} & -{c} & 0 \\\\ 0 & 0 & -1 \\end{{bmatrix}}"
    claim: dict[str, Any] = {"quantity": "rotation", "value": up}
    if not has_joint_names(value) and ctx.q:
        claim["q"] = ctx.q
    p = Pending(eq.line, eq.end_line, eq.text, arm, claim, reading.understood, sure=reading.sure, quantity="heading")
    p.equivalent = [({**claim, "value": down}, "the heading with the tool's z axis down")]
    return p


_CAPITAL_WRENCH = re.compile(r"(?<![A-Za-z\\])([FfNnMm])\s*_?\s*\{?\s*([xyz])\s*\}?(?![A-Za-z])")


def _wrench(ctx: Context, p: Pending, claim: dict[str, Any], value: str, numeric: bool) -> None:
    """The wrench a τ, ⁱfᵢ or ⁱnᵢ claim is about: the stated numbers, or the symbols the section names."""
    if numeric and ctx.wrench and claim["quantity"] == "torques":
        claim["wrench"] = ctx.wrench
    else:
        names = wrench_symbols(value, *ctx.wrench_texts)
        if names:
            claim["wrench"] = "[" + ", ".join(n if n in names else "0" for n in WRENCH_NAMES) + "]"
        elif numeric and ctx.wrench:
            claim["wrench"] = ctx.wrench
        else:
            claim["wrench"] = "[" + ", ".join(WRENCH_NAMES) + "]"
            p.numeric_without_wrench = numeric
    if claim["quantity"] == "torques":
        first, second = ("tool", "base") if ctx.propagation else ("base", "tool")
        if ctx.wrench_frame:
            first, second = ctx.wrench_frame, ("tool" if ctx.wrench_frame == "base" else "base")
        claim["frame"] = first
        p.alternatives.append(({**claim, "frame": second}, f"τ for the wrench in {second} axes"))


def ik_formula_pending(ctx: Context, eq: Equation, arm: Arm, lhs: str, value: str) -> Pending:
    """``q_1 = atan2(p_y, p_x)``: an inverse-kinematics formula, with the names the derivation defined that it uses
    and the wrist centre as P when the report named it so (:func:`._points.names_wrist_centre`)."""
    step = trig_of_joint(lhs)
    if step is not None:  # "cos θ2 = …": the formulas for θ2 after it may use cos θ2 as that value
        ctx.trig_steps[step] = value
    joint = read_symbol(lhs)
    k = int(joint.sub.strip("{} ")) if joint is not None and joint.sub.strip("{} ").isdigit() else None
    for (fn, j), given in (ctx.trig_steps.items() if step is None else ()):
        if j == k and trig_named(value, fn, j) != value:
            value = trig_named(value, fn, j)
            ctx.define(f"{fn[0]}_{{{j}}}", given)
    claim: dict[str, Any] = {"quantity": "ik_formula", "value": f"{lhs} = {value}"}
    used = used_where(ctx.where, value)
    if used:
        claim["where"] = used
    if ctx.p_wrist:
        claim["point"] = "wrist"
    return Pending(eq.line, eq.end_line, eq.text, arm, claim, f"{lhs}: an inverse-kinematics formula",
                   quantity="ik_formula")


def det_pending(eq: Equation, arm: Arm, value: str, sym: Any) -> Pending:
    """A det J claim: its rows from the name or the arm (det_rows), every square block of rows another form."""
    claim: dict[str, Any] = {"quantity": "det_jacobian", "value": value}
    if sym is not None and sym.pre_sup.strip().isdigit():
        claim["frame"] = int(sym.pre_sup.strip())
    rows = det_rows(sym, arm.robot)
    p = Pending(eq.line, eq.end_line, eq.text, arm, claim, "det J, the Jacobian's determinant",
                quantity="det_jacobian")
    subsets = [",".join(c) for c in itertools.combinations(TWIST_ROWS, arm.robot.dof)] if arm.robot.dof <= 6 else []
    p.equivalent = [({**claim, "rows": r}, f"det J of the rows {r}") for r in subsets]
    if rows:
        claim["rows"] = rows
    return p


#: Yoshikawa's measure written out: ``\\sqrt{\\det(J_v J_v^T)}`` (the J named decides the rows).
MANIPULABILITY = re.compile(r"\\sqrt\s*\{?\s*\\det\s*\\?(?:left)?\(?\s*(J(?:_\{?\\?\w+\}?)?)")


def manipulability_pending(eq: Equation, arm: Arm, value: str, written: str) -> Pending:
    """``w = \\sqrt{\\det(J_v J_v^T)} = …``: the measure of the rows the J's name says (or the arm's default, as
    for det J); the usual other blocks of rows (position, planar, angular, all) other forms."""
    from ._lhs import read_symbol

    claim: dict[str, Any] = {"quantity": "manipulability", "value": value}
    rows = det_rows(read_symbol(written), arm.robot)
    if rows:
        claim["rows"] = rows
    p = Pending(eq.line, eq.end_line, eq.text, arm, claim, "the manipulability w = √det(J Jᵀ)",
                quantity="manipulability")
    blocks = ("vx,vy,vz", "vx,vy,wz", "vx,vy", "wx,wy,wz", "vx,vy,vz,wx,wy,wz")
    p.equivalent = [({**claim, "rows": r}, f"w of the rows {r}") for r in blocks
                    if r != rows and r.count(",") + 1 >= arm.robot.dof]
    return p


def singular_pending(sing: list[tuple[Equation, str]], arm: Arm | None) -> Pending:
    """The singular conditions collected in a row (each equation and its condition), as one claim (moved from the
    walker's ``flush``, code unchanged)."""
    eqs = [e for e, _ in sing]
    claim = {"quantity": "singularities", "value": [c for _, c in sing]}
    first = Equation(eqs[0].line, max(e.end_line for e in eqs), "; ".join(c for _, c in sing), (), "=")
    p = Pending(first.line, first.end_line, first.text, arm, claim,
                "the singular configurations", quantity="singularities")
    p.equivalent = [({**claim, "rows": r}, f"the singular configurations of the rows {r}")
                    for r in ("vx,vy,vz", "vx,vy,wz", "vx,vy", "wx,wy,wz")]
    return p
