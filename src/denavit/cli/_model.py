"""Subcommands on the model and forward kinematics: robots, show, fk, convert."""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

from ..errors import ParseError
from ._common import add_common, add_q, joint_values, load, matrix_text, numbers_text
from ._output import add_no_clobber, check_output, output_file

#: File types ``convert -o`` writes.
CONVERT_SUFFIXES = (".yaml", ".yml", ".json")


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("robots", help="list the built-in robots")
    p.add_argument("--json", action="store_true", help="machine-readable JSON on stdout")
    p.add_argument("--deg", action="store_true", help="accepted like every command's --deg (the list has no angles)")
    p.set_defaults(handler=cmd_robots)

    p = sub.add_parser("show", help="DH table, parameters and limits of a robot")
    add_common(p)
    p.set_defaults(handler=cmd_show)

    p = sub.add_parser("fk", help="forward kinematics: pose of the end effector (and every frame)")
    add_common(p)
    add_q(p, required=False)
    p.add_argument("--frames", action="store_true", help="also every DH frame T_0_i")
    p.add_argument("--symbolic", action="store_true", help="the symbolic link transforms A_i and T_0_n")
    p.add_argument("--latex", action="store_true", help="symbolic output as LaTeX")
    p.add_argument("--markdown", action="store_true", help="symbolic output as Markdown with $$ math $$ blocks")
    p.add_argument("--shorthand", action="store_true", help="write cos(q1+q2) as C12, sin(q3) as S3")
    p.add_argument("--simplify", choices=["none", "trig", "full"], default="trig", help="simplification policy")
    p.set_defaults(handler=cmd_fk)

    p = sub.add_parser("convert", help="write the same arm in the other DH convention")
    add_common(p, angles=False)
    p.add_argument("--to", required=True, choices=["standard", "modified"], help="target convention")
    p.add_argument("-o", "--output", metavar="FILE", help="robot file to write (.yaml or .json); stdout if absent")
    add_no_clobber(p)
    p.set_defaults(handler=cmd_convert)


def cmd_robots(args: argparse.Namespace):
    from ..io import catalogue_names, load_robot

    rows = []
    for name in catalogue_names():
        r = load_robot(name)
        types = "".join("R" if t.value == "revolute" else "P" for t in r.joint_types)
        rows.append({"name": name, "dof": r.dof, "joints": types, "convention": r.convention.value,
                     "dynamics": r.has_dynamics, "description": r.description})
    width = max(len(r["name"]) for r in rows)
    lines = [f"{'name'.ljust(width)}  dof  joints   convention  dyn  description"]
    for r in rows:
        lines.append(
            f"{r['name'].ljust(width)}  {r['dof']:>3}  {r['joints']:<7}  {r['convention']:<10}  "
            f"{'yes' if r['dynamics'] else ' - '}  {r['description']}"
        )
    return {"robots": rows}, "\n".join(lines)


def cmd_show(args: argparse.Namespace):
    """The DH table as ``print(robot)`` shows it (``denavit.dh_table``), and the model as JSON."""
    from ..display import dh_table
    from ..model import JointType

    robot = load(args)
    text = dh_table(robot, deg=True if args.deg else None)
    text += f"\ninertial data: {'yes' if robot.has_dynamics else 'no'}"
    angle = (lambda x: float(np.degrees(x))) if args.deg else float  # noqa: E731  (--deg: angles in degrees)
    data_rows = [{"a": link.a, "alpha": angle(link.alpha), "d": link.d, "theta": angle(link.theta),
                  "joint": link.joint.value, "expressions": dict(link.symbols),
                  "limits": None if not link.q_limits else
                  [angle(v) if link.joint is JointType.REVOLUTE else v for v in link.q_limits]}
                 for link in robot.links]
    poses = {name: [angle(v) if t is JointType.REVOLUTE else v for v, t in zip(q, robot.joint_types)]
             for name, q in robot.poses}
    data = {"robot": robot.name, "convention": robot.convention.value, "dof": robot.dof,
            "angle_unit": "deg" if args.deg else "rad", "rows": data_rows, "poses": poses,
            "parameters": dict(robot.parameters), "base": robot.base_matrix, "tool": robot.tool_matrix,
            "gravity": list(robot.gravity), "dynamics": robot.has_dynamics}
    return data, text


def _symbolic_fk(robot, args) -> tuple[dict, list[str]]:
    from .. import symbolic as S
    import sympy as sp

    from ._common import require_symbolic_size

    require_symbolic_size(robot, "fk --symbolic")
    q = S.joint_symbols(robot.dof).q
    if args.markdown:
        fmt = lambda M: "$$\n" + sp.latex(M) + "\n$$"  # noqa: E731
    elif args.latex:
        fmt = sp.latex
    else:
        from ..display import matrix_text as fmt  # wrapped to the terminal's width
    show = (lambda M: S.shorthand_matrix(M, q)) if args.shorthand else (lambda M: M)
    lines = []
    As = S.link_matrices_sym(robot)
    data: dict = {"A": [], "T_symbolic": None}
    for i, A in enumerate(As, start=1):
        A = S.simplify_matrix(A, args.simplify)
        lines += [f"A_{i} = T_{i - 1}_{i} =", fmt(show(A)), ""]
        data["A"].append(A)
    T = S.forward_kinematics_sym(robot, args.simplify)
    lines += [f"T_0_{len(As)}" + (" (with base and tool)" if not (np.allclose(robot.base_matrix, np.eye(4))
                                                                 and np.allclose(robot.tool_matrix, np.eye(4))) else "")
              + " =", fmt(show(T))]
    data["T_symbolic"] = T
    data["T_latex"] = sp.latex(T)
    return data, lines


def cmd_fk(args: argparse.Namespace):
    from ..numeric import forward_kinematics, link_transforms, rpy_from_rotation, zyz_from_rotation
    from ._shared import q_out, q_text

    robot = load(args)
    data: dict = {"robot": robot.name, "convention": robot.convention.value}
    lines: list[str] = []
    if args.symbolic:
        sdata, slines = _symbolic_fk(robot, args)
        data.update(sdata)
        lines += slines
    elif args.q is None:
        raise ParseError("give joint values with -q (or --symbolic for the formulas)")
    if args.q is not None:
        q = joint_values(args, robot, args.q)
        T = forward_kinematics(robot, q)
        rpy = rpy_from_rotation(T[:3, :3])
        zyz = zyz_from_rotation(T[:3, :3])
        unit = "deg" if args.deg else "rad"
        conv = np.degrees if args.deg else (lambda x: x)
        data.update({"q": q_out(args, robot, q), "angle_unit": unit, "T": T, "position": T[:3, 3],
                     "rpy": conv(rpy), "zyz": conv(zyz)})
        if lines:
            lines.append("")
        lines += [f"{robot.name}: end-effector pose at {q_text(args, robot, q)}", "T_0_e =", matrix_text(T),
                  f"position [m]: {numbers_text(T[:3, 3])}",
                  f"RPY (roll, pitch, yaw) [{unit}]: {numbers_text(conv(rpy))}",
                  f"ZYZ (phi, theta, psi) [{unit}]: {numbers_text(conv(zyz))}"]
        if args.frames:
            frames = link_transforms(robot, q)
            data["frames"] = frames
            for i, F in enumerate(frames):
                lines += ["", f"T_0_{i} =", matrix_text(F)]
    return data, "\n".join(lines)


def cmd_convert(args: argparse.Namespace):
    from .._convert import convert_convention
    from ..io import dump_robot, robot_to_dict

    check_output(args, args.output, CONVERT_SUFFIXES)  # before any work: x.png is refused, not filled with YAML
    robot = load(args)
    out = convert_convention(robot, args.to)
    if args.output:
        path = Path(args.output)
        with output_file(args.output) as tmp:
            Path(tmp).write_text(dump_robot(out, "json" if path.suffix.lower() == ".json" else "yaml"), encoding="utf-8")
        same = " (it was already in that convention: rows unchanged)" if out.convention is robot.convention else ""
        text = f"wrote {path} ({out.convention.value} DH, {out.n_rows} row{'s' * (out.n_rows != 1)}){same}"
    else:
        text = dump_robot(out)
    return {"robot": robot.name, "from": robot.convention.value, "to": out.convention.value,
            "output": args.output, "robot_file": robot_to_dict(out)}, text
