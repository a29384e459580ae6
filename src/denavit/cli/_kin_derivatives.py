"""``denavit jacobian ... --dot --qd QD`` and ``--hessian``: J̇, J̇q̇ and ∂J/∂q at one configuration, and with
``--symbolic`` as formulas.

Parses, calls :func:`denavit.jacobian_dot` / :func:`denavit.kinematic_hessian` (numeric) or
:func:`denavit.symbolic.jacobian_dot_sym` / :func:`denavit.symbolic.kinematic_hessian_sym` (symbolic), formats
(text or the JSON keys ``Jdot``, ``Jdot_qd``, ``H``; ``Jdot_symbolic``, ``Jdot_qd_symbolic``, ``H_symbolic`` with
their ``*_latex``).  Numeric results are in SI units with radians (rad/s, m/s), whatever ``--deg`` says about
the inputs.
"""

from __future__ import annotations

import argparse

import numpy as np

from .._constants import TWIST_ROWS as ROWS
from ..errors import ParseError
from ._common import joint_values, matrix_text, numbers_text, require_finite, require_symbolic_size
from ._shared import q_out, q_text, sym_formatter

__all__ = ["add_kin_derivative_args", "wants_kin_derivatives", "cmd_kin_derivatives", "analytic_numeric",
           "check_analytic_symbolic"]

REFERENCE = "end-effector origin (after the tool transform)"


def add_kin_derivative_args(p: argparse.ArgumentParser) -> None:
    """--dot, --qd and --hessian on the ``jacobian`` subcommand."""
    p.add_argument("--dot", action="store_true", help="the time derivative dJ/dt and dJ/dt qd at -q and --qd, or "
                   "with --symbolic as formulas in q and qd (--frame base or tool)")
    p.add_argument("--qd", metavar="QD", help="joint rates for --dot [rad/s or m/s; deg/s with --deg]")
    p.add_argument("--hessian", action="store_true", help="the kinematic Hessian dJ/dq at -q (or with --symbolic as "
                   "formulas): per joint k the 6 x n matrix dJ/dq_k (--frame base or tool)")


def wants_kin_derivatives(args: argparse.Namespace) -> bool:
    """True when the call asks for J̇ or ∂J/∂q; a --qd without --dot is refused."""
    if args.qd is not None and not args.dot:
        raise ParseError("--qd goes with --dot (the joint rates of dJ/dt)")
    return bool(args.dot or args.hessian)


def _check(args: argparse.Namespace) -> None:
    flags = "/".join(f for f, on in (("--dot", args.dot), ("--hessian", args.hessian)) if on)
    if args.q is None and not args.symbolic:
        raise ParseError(f"{flags}: give -q (and --qd for --dot) for numbers, or --symbolic for the formulas")
    if args.q is None and args.qd is not None:
        raise ParseError("--qd goes with -q (the formulas are written in the rates qd1 ... qdn)")
    if args.q is not None and args.dot and args.qd is None:
        raise ParseError("--dot needs --qd, the joint rates")
    if args.frame not in ("base", "tool"):
        raise ParseError(f"{flags} --frame {args.frame}: choose base or tool")
    for name, bad in (("--analytic", args.analytic), ("--steps", args.steps),
                      ("--method " + args.method, args.method != "geometric")):
        if bad:
            raise ParseError(f"{flags} does not go with {name} (derivatives of the geometric Jacobian)")


#: rows of the analytic Jacobian after (x, y, z), per representation; angles in degrees with --deg
COORDINATES = {"rpy": ("roll", "pitch", "yaw"), "zyz": ("phi", "theta", "psi"), "quaternion": ("qw", "qx", "qy", "qz"),
               "exp": ("rx", "ry", "rz")}


def check_analytic_symbolic(args: argparse.Namespace) -> None:
    """The symbolic analytic Jacobian exists for rpy and zyz only."""
    if args.analytic in ("quaternion", "exp"):
        raise ParseError(f"--analytic {args.analytic} is numeric: give -q (without --symbolic); formulas exist for rpy "
                         "and zyz")


def analytic_numeric(args: argparse.Namespace, robot, q, lines: list[str]) -> dict:
    """``jacobian -q Q --analytic REP``: Ja and the coordinates at q; the text lines appended to ``lines``, the
    JSON entries returned.  Euler angles are in degrees with --deg; quaternion and rotation vector as computed."""
    from .. import numeric as N

    Ja, phi = N.analytic_jacobian(robot, q, args.analytic)
    require_finite("jacobian", phi)  # rate rows are NaN at a representation singularity (warned)
    names = ("x", "y", "z") + COORDINATES[args.analytic]
    euler = args.analytic in ("rpy", "zyz")
    conv = np.degrees(phi) if args.deg and euler else phi
    unit = "" if args.analytic == "quaternion" else f" ({'deg' if args.deg and euler else 'rad'})"
    what = "angles" if euler else "quaternion (w, x, y, z)" if args.analytic == "quaternion" else "rotation vector"
    lines += ["" if lines else "", f"{robot.name}: analytic Jacobian ({args.analytic}) at {q_text(args, robot, q)}",
              f"rows (xdot, ydot, zdot, {', '.join(n + 'dot' for n in names[3:])}) in base/world axes",
              f"{what}: {', '.join(f'{n} = {t}' for n, t in zip(names[3:], numbers_text(conv).split(', ')))}{unit}",
              _labelled(Ja, names)]
    return {"Ja": Ja, "representation": args.analytic, "angles": conv, "analytic_rows": list(names)}


def _labelled(M, labels=ROWS) -> str:
    body = matrix_text(M).split("\n")
    width = max(len(lab) for lab in labels)
    return "\n".join(f"{lab:>{width}} {row}" for lab, row in zip(labels, body))


def _symbolic(args: argparse.Namespace, robot, axes: str) -> tuple[dict, list[str]]:
    """J̇, J̇q̇ and ∂J/∂q_k as formulas in q1 ... qn (and qd1 ... qdn), in the chosen output format."""
    import sympy as sp

    from .. import symbolic as S

    require_symbolic_size(robot, "jacobian --dot/--hessian --symbolic")
    js = S.joint_symbols(robot.dof)
    fmt = sym_formatter(args, js.q)
    name = "J0" if args.frame == "base" else "Je"
    data: dict = {}
    lines = [f"{robot.name}: symbolic kinematic derivatives of {name} (geometric Jacobian)",
             f"rows (vx, vy, vz, wx, wy, wz); reference point: {REFERENCE}; joint rates qd1 ... qd{robot.dof}"]
    if args.dot:
        Jd = S.jacobian_dot_sym(robot, args.frame, args.simplify)
        Jd_qd = (S.acceleration_bias_sym(robot, "base", args.simplify) if args.frame == "base" else  # = dJ0/dt qd
                 S.simplify_matrix(Jd * sp.Matrix(js.qd), args.simplify))
        lines += ["", f"dJ/dt = sum_k dJ/dq_k qd_k in {axes}:", f"d{name}/dt =", fmt(Jd), f"d{name}/dt qd =", fmt(Jd_qd)]
        if args.frame == "base":
            lines.append("(the classical acceleration of the end-effector origin at qdd = 0)")
        data.update({"Jdot_symbolic": Jd, "Jdot_latex": sp.latex(Jd), "Jdot_qd_symbolic": Jd_qd,
                     "Jdot_qd_latex": sp.latex(Jd_qd)})
    if args.hessian:
        H = S.kinematic_hessian_sym(robot, args.frame, args.simplify)
        slices = [S.hessian_slice_sym(H, k) for k in range(robot.dof)]
        lines += ["", f"kinematic Hessian H[:, j, k] = dJ[:, j]/dq_k in {axes.split(' (')[0]}:"]
        for k, Hk in enumerate(slices):
            lines += [f"dJ/dq{k + 1} =", fmt(Hk)]
        data.update({"H_symbolic": H.tolist(), "H_latex": [sp.latex(Hk) for Hk in slices]})
    return data, lines


def cmd_kin_derivatives(args: argparse.Namespace, robot):
    """(data, text) for ``jacobian --dot`` / ``--hessian`` (with ``--symbolic``: the formulas, then the numbers
    when -q is given too)."""
    _check(args)
    axes = "base/world axes (d/dt J0)" if args.frame == "base" else "tool axes (d/dt Je)"
    data: dict = {"robot": robot.name, "frame": args.frame, "reference_point": REFERENCE, "rows": list(ROWS)}
    lines: list[str] = []
    if args.q is not None:  # a bad -q or --qd fails now, not after the symbolic work
        joint_values(args, robot, args.q)
        if args.dot:
            joint_values(args, robot, args.qd, what="qd", rates=True)
    if args.symbolic:
        sdata, lines = _symbolic(args, robot, axes)
        data.update(sdata)
    if args.q is not None:
        ndata, nlines = _numeric(args, robot, axes)
        data.update(ndata)
        lines += ([""] if lines else []) + nlines
    return data, "\n".join(lines)


def _numeric(args: argparse.Namespace, robot, axes: str) -> tuple[dict, list[str]]:
    from .. import numeric as N

    q = joint_values(args, robot, args.q)
    data: dict = {"q": q_out(args, robot, q)}
    lines = [f"{robot.name}: kinematic derivatives at {q_text(args, robot, q)}",
             f"rows (vx, vy, vz, wx, wy, wz); reference point: {REFERENCE}; SI units, radians"]
    if args.dot:
        qd = joint_values(args, robot, args.qd, what="qd", rates=True)
        Jd = N.jacobian_dot(robot, q, qd, args.frame)
        Jd_qd = Jd @ qd
        require_finite("jacobian --dot", Jd)
        data.update({"qd": q_out(args, robot, qd), "Jdot": Jd, "Jdot_qd": Jd_qd})
        lines += ["", f"dJ/dt in {axes}, qd = [{numbers_text(qd)}] (rad/s or m/s):", _labelled(Jd),
                  f"dJ/dt qd = [{numbers_text(Jd_qd)}]"]
        if args.frame == "base":
            lines.append("(the classical acceleration of the end-effector origin at qdd = 0)")
    if args.hessian:
        H = N.kinematic_hessian(robot, q, args.frame)
        require_finite("jacobian --hessian", H)
        data["H"] = H
        lines += ["", f"kinematic Hessian H[:, j, k] = dJ[:, j]/dq_k in {axes.split(' (')[0]}:"]
        for k in range(robot.dof):
            lines += [f"dJ/dq{k + 1} =", _labelled(H[:, :, k])]
    return data, lines
