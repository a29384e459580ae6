"""The ``singularities`` subcommand: factored determinant (or minors), conditions, kinds, numeric measures."""

from __future__ import annotations

import argparse
import math

import numpy as np

from .._constants import TWIST_ROWS as ROWS
from ..errors import ParseError
from ._common import (MAX_SYMBOLIC_ANALYSIS_JOINTS, add_common, add_q, joint_values, load, matrix_text, number_text,
                      numbers_text, require_finite, require_symbolic_size, stage_printer)
from ._shared import add_frame, add_sym_format, q_out, q_text, sym_formatter

__all__ = ["register"]


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("singularities", help="singular configurations: factored determinant, conditions, kinds")
    add_common(p)
    add_q(p, required=False)
    p.add_argument("--rows", metavar="ROWS", help="task rows of the Jacobian, e.g. vx,vy,wz (default: all six)")
    add_frame(p, what="axes of the Jacobian whose rows are taken")
    add_sym_format(p, simplify=False)
    p.set_defaults(handler=cmd_singularities)


# --- singularities -------------------------------------------------------------------------------------


def _value_text(v: float, revolute: bool, deg: bool) -> str:
    if not revolute:
        return f"{number_text(v)} m"
    if deg:
        return f"{number_text(math.degrees(v))}°"
    return f"{number_text(v)} rad ({number_text(math.degrees(v))}°)"


def _condition_lines(cond, robot, args, fmt) -> list[str]:
    import sympy as sp

    from ..model import JointType

    eq = fmt(sp.Eq(cond.factor, 0, evaluate=False)) if (args.latex or args.markdown) else f"{cond.factor} = 0"
    if args.shorthand and not (args.latex or args.markdown):
        eq = f"{fmt(cond.factor)} = 0" if "\n" not in fmt(cond.factor) else eq
    lines = [f"- {eq}"]
    if cond.solutions:
        parts: dict[str, list[str]] = {}
        for s in cond.solutions:
            k = int(s.variable[1:]) - 1
            rev = robot.joint_types[k] is JointType.REVOLUTE
            vals = ", ".join(_value_text(v, rev, args.deg) + ("" if ok else " (outside limits)")
                             for v, ok in zip(s.values, s.in_limits))
            expr = f"{s.expression} = " if s.expression is not None and not s.expression.is_number else ""
            parts.setdefault(s.variable, []).append(expr + vals)
        lines.append(_prose("    → " + "; ".join(f"{var} = {', '.join(vals)}" for var, vals in parts.items()), args))
    else:
        lines.append("    (kept as an equation: no closed form in one variable)")
    lines.append(_prose(f"    kind: {cond.kind} — {cond.explanation}", args))
    return lines


def _prose(line: str, args) -> str:
    """A prose line fitted to the terminal (Markdown output is left to its renderer)."""
    from ..display import prose_text

    return line if args.markdown else prose_text(line)


def _measures(robot, args, rows_idx) -> tuple[dict, list[str]]:
    from .. import numeric as N

    q = joint_values(args, robot, args.q)
    J = N.geometric_jacobian(robot, q, args.frame)[rows_idx, :]
    require_finite("singularities", J)
    s = N.singular_values(J)
    lin = [i for i, r in enumerate(rows_idx) if r < 3] or list(range(len(rows_idx)))
    vel, frc = N.velocity_ellipsoid(J[lin]), N.force_ellipsoid(J[lin])
    which = ", ".join(ROWS[rows_idx[i]] for i in lin)
    data = {"q": q_out(args, robot, q), "J": J, "singular_values": s, "manipulability": float(N.manipulability(J)),
            "condition_number": float(N.condition_number(J)), "smallest_singular_value": float(s[-1]),
            "rank": int(N.jacobian_rank(J)), "singular": bool(N.is_singular(J)),
            "ellipsoid_rows": [ROWS[rows_idx[i]] for i in lin],
            "velocity_ellipsoid": {"axes": vel.axes, "radii": vel.radii},
            "force_ellipsoid": {"axes": frc.axes, "radii": frc.radii}}
    lines = ["", f"numeric measures at {q_text(args, robot, q)} (rows {', '.join(ROWS[i] for i in rows_idx)}):",
             f"  singular values: {numbers_text(s)}",
             f"  rank {data['rank']} of {min(J.shape)} (threshold 1e-9 · largest singular value)"
             + ("  → SINGULAR" if data["singular"] else ""),
             f"  manipulability (Yoshikawa) sqrt(det J J^T) = "
             f"{number_text(data['manipulability'], scale=float(np.prod(s[:-1])) if len(s) > 1 else 1.0)}",
             f"  condition number = {number_text(data['condition_number'])}, smallest singular value = "
             f"{number_text(s[-1], scale=s[0])}",
             f"  velocity ellipsoid (rows {which}, |qd| <= 1): radii {numbers_text(vel.radii)}",
             f"  force ellipsoid (rows {which}, |tau| <= 1): radii {numbers_text(frc.radii)}",
             "  axes (columns, same for both):", matrix_text(vel.axes, indent="    ")]
    return data, lines


def cmd_singularities(args: argparse.Namespace):
    import sympy as sp

    from .. import symbolic as S
    from ..numeric import select_rows

    robot = load(args)
    try:
        rows_idx = select_rows(args.rows)
    except ValueError as exc:
        raise ParseError(f"--rows: {exc}") from None
    rows = "auto" if args.rows is None else ",".join(ROWS[i] for i in rows_idx)
    if args.q is not None:
        joint_values(args, robot, args.q)  # a bad -q fails now, not after minutes of symbolic work
    require_symbolic_size(robot, "singularities", MAX_SYMBOLIC_ANALYSIS_JOINTS)
    res = S.singularity_analysis(robot, rows, args.frame, progress=stage_printer(args, "singularities"))
    rows_idx = [ROWS.index(r) for r in res.rows]  # the task rows analysed (an arm of < 6 joints: its own)
    fmt = sym_formatter(args, S.joint_symbols(robot.dof).q)
    det_text = fmt(res.determinant)
    lines = [f"{robot.name}: singularities", _prose(f"matrix: {res.matrix_note}", args),
             _prose(f"measure: {res.measure}", args)]
    if args.markdown:
        lines = [f"## {robot.name}: singularities", "", f"matrix: {res.matrix_note}", "", f"measure: {res.measure}", ""]
    lines += ["matrix =", fmt(res.matrix), f"{res.measure} =", det_text]
    if res.constant_factors:
        lines.append("constant factors (assumed non-zero): " + ", ".join(str(c) for c in res.constant_factors))
    if res.everywhere:
        lines += ["", f"SINGULAR EVERYWHERE: rank {res.generic_rank} of {res.full_rank} for every q ({res.reason})"]
    elif res.conditions:
        lines += ["", "singular when:"]
        for cond in res.conditions:
            lines += _condition_lines(cond, robot, args, fmt)
    elif "minors" in res.measure:
        # Non-square J: a common factor of all minors is sufficient for a rank loss, not necessary. Without
        # one, singular configurations (if any) are where all minors vanish together: not solved here.
        lines += ["", _prose("no common factor of the minors: any singular configuration lies where ALL the minors "
                             "vanish together, which is not solved symbolically here (redundant arms, e.g. 7 joints, "
                             "do have such configurations); check a configuration with -q (rank, smallest singular "
                             "value), or pick a square sub-Jacobian with --rows", args)]
    else:
        lines += ["", "no singular configuration: the determinant never vanishes"]
    data = {"robot": robot.name, "rows": list(res.rows), "frame": args.frame, "matrix_note": res.matrix_note,
            "measure": res.measure, "matrix": res.matrix, "determinant": str(res.determinant),
            "determinant_latex": sp.latex(res.determinant), "constant_factors": [str(c) for c in res.constant_factors],
            "everywhere": res.everywhere, "generic_rank": res.generic_rank, "full_rank": res.full_rank,
            "reason": res.reason, "angle_unit": "deg" if args.deg else "rad",
            # False when J is not square and its minors share no factor: the singular set is not solved then
            "conditions_complete": not ("minors" in res.measure and not res.conditions and not res.everywhere),
            "conditions": [{"equation": f"{c.factor} = 0", "latex": sp.latex(c.factor) + " = 0",
                            "variables": list(c.variables), "kind": c.kind, "explanation": c.explanation,
                            "solutions": [{"variable": s.variable,
                                           "expression": None if s.expression is None else str(s.expression),
                                           "values": [math.degrees(v) if args.deg and _is_rev(robot, s.variable) else v
                                                      for v in s.values],
                                           "in_limits": list(s.in_limits)} for s in c.solutions]}
                           for c in res.conditions]}
    if args.q is not None:
        mdata, mlines = _measures(robot, args, rows_idx)
        data["measures"] = mdata
        lines += mlines
    return data, "\n".join(lines)


def _is_rev(robot, var: str) -> bool:
    from ..model import JointType

    return robot.joint_types[int(var[1:]) - 1] is JointType.REVOLUTE
