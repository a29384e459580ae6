"""Options and output shared by the Jacobian, velocity, statics and singularity commands: the frame, the
symbolic output format (pretty, LaTeX, Markdown, shorthand), and joint vectors as printed (rad or deg)."""

from __future__ import annotations

import numpy as np

from ._common import numbers_text

__all__ = ["add_frame", "add_sym_format", "sym_formatter", "q_out", "q_text"]


def add_frame(p, what: str = "axes of the result") -> None:
    p.add_argument("--frame", choices=["base", "tool"], default="base", help=f"{what}: base/world (J0) or tool (Je)")


def add_sym_format(p, simplify: bool = True) -> None:
    g = p.add_mutually_exclusive_group()
    g.add_argument("--latex", action="store_true", help="symbolic output as LaTeX")
    g.add_argument("--markdown", action="store_true", help="symbolic output as Markdown with $$ math $$ blocks")
    p.add_argument("--shorthand", action="store_true", help="write cos(q1+q2) as C12, sin(q3) as S3")
    if simplify:
        p.add_argument("--simplify", choices=["none", "trig", "full"], default="trig", help="simplification policy")


def sym_formatter(args, q):
    import sympy as sp

    from .. import symbolic as S

    show = (lambda M: S.shorthand(M, q) if not hasattr(M, "shape") else S.shorthand_matrix(M, q)) \
        if args.shorthand else (lambda M: M)
    if getattr(args, "markdown", False):
        return lambda M: "$$\n" + sp.latex(show(M)) + "\n$$"
    if getattr(args, "latex", False):
        return lambda M: sp.latex(show(M))
    from ..display import matrix_text

    return lambda M: matrix_text(show(M))  # wrapped to the terminal's width


def q_out(args, robot, q):
    from ..model import JointType

    if not args.deg:
        return q
    rev = np.array([t is JointType.REVOLUTE for t in robot.joint_types])
    return np.where(rev, np.degrees(q), q)


def q_text(args, robot, q) -> str:
    unit = "deg for revolute joints" if args.deg else "rad"
    return f"q = [{numbers_text(q_out(args, robot, q))}] ({unit})"
