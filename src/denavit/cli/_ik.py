"""Subcommand ik: inverse kinematics, all closed-form solutions or a numerical solve."""

from __future__ import annotations

import argparse
import re

import numpy as np

from ..errors import DenavitError, ParseError, UnsupportedRobotError
from ._ik_path import add_path_arguments, cmd_ik_path
from . import _ik_sweep
from ._common import (add_common, bounded_int, check_values, emit, joint_values, load, matrix_text, numbers_text,
                      positive_float, require_finite)

#: ik: most random restarts and LM iterations per solve (numeric route), and the longest --lock joint number.
MAX_RESTARTS = 1000
MAX_ITERATIONS = 10_000


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("ik", help="inverse kinematics: every closed-form solution, or a numerical solve")
    add_common(p)
    target = p.add_mutually_exclusive_group()
    target.add_argument("--pose", metavar="X,Y,Z,ROLL,PITCH,YAW",
                        help="target position [m] and roll-pitch-yaw R = Rz(yaw) Ry(pitch) Rx(roll) [rad or --deg]")
    target.add_argument("--T", dest="T", metavar="T11,...,T44", help="target pose as 16 numbers, row by row")
    target.add_argument("--from-q", dest="from_q", metavar="Q", help="target = the pose of the arm at these joint values")
    add_path_arguments(target, p)
    p.add_argument("--method", choices=["auto", "analytic", "numeric"], default="auto",
                   help="closed form (all solutions), numerical LM, or auto: closed form when the arm has one")
    p.add_argument("--all", action="store_true",
                   help="numeric: search many seeds and list every distinct solution found; analytic: also list "
                        "the solutions outside the joint limits, marked per joint")
    p.add_argument("--seed", metavar="Q", help="numeric: starting configuration")
    p.add_argument("--mask", choices=["pose", "position"], default="pose", help="numeric: rows to match")
    p.add_argument("--tol", type=positive_float, default=1e-9, help="numeric: position [m] / orientation [rad] tolerance")
    p.add_argument("--restarts", type=bounded_int(0, MAX_RESTARTS), default=64,
                   help=f"numeric: random restarts (default 64, at most {MAX_RESTARTS})")
    p.add_argument("--max-iterations", type=bounded_int(1, MAX_ITERATIONS), default=100,
                   help=f"numeric: LM iterations per start (default 100, at most {MAX_ITERATIONS})")
    p.add_argument("--ignore-limits", action="store_true", help="accept --from-q outside the joint limits")
    p.add_argument("--lock", metavar="qN=V[,qM=W]", action="append",
                   help="analytic: hold these joints at these values and solve the others (redundant arms, e.g. "
                        "panda --lock q7=0.5); repeatable")
    _ik_sweep.add_arguments(p)  # --free (= --lock), --sweep, --samples
    p.add_argument("--derive", action="store_true",
                   help="print the symbolic derivation of the closed form (spherical-wrist 6-joint and planar 2R/3R "
                        "arms) instead of solving a target")
    p.add_argument("--latex", action="store_true", help="with --derive: LaTeX instead of plain text")
    p.set_defaults(handler=cmd_ik)


def _target(args, robot) -> np.ndarray:
    from .._validate import as_transform
    from ..io import parse_values
    from ..numeric import forward_kinematics, transform_from_xyz_rpy

    if args.pose is not None:
        v = check_values(parse_values(args.pose, 6, what="--pose"), "--pose")
        if args.deg:  # plain roll, pitch, yaw in degrees; a value with pi or deg says its own unit
            v[3:] = parse_values(args.pose, 6, what="--pose", deg=True)[3:]
        return transform_from_xyz_rpy(v[:3], v[3:])
    if args.T is not None:
        v = check_values(parse_values(args.T, 16, what="--T"), "--T").reshape(4, 4)
        if not np.allclose(v[3], [0, 0, 0, 1]):
            raise ParseError("--T: the last row must be 0, 0, 0, 1")
        return as_transform(v, "--T")
    T = forward_kinematics(robot, joint_values(args, robot, args.from_q, what="--from-q"))
    require_finite("--from-q", T)
    return T


def _fmt_q(robot, q, deg: bool) -> list[str]:
    from ..model import JointType

    vals = [np.degrees(v) if deg and t is JointType.REVOLUTE else v for v, t in zip(q, robot.joint_types)]
    return numbers_text(vals, sep="\n").split("\n")


def _to_unit(robot, q, deg: bool) -> np.ndarray:
    from ..model import JointType

    rev = np.array([t is JointType.REVOLUTE for t in robot.joint_types])
    return np.where(rev, np.degrees(q), q) if deg else np.asarray(q)


def _locks(args, robot) -> dict[str, float] | None:
    """``--lock q7=0.5,q3=-1`` → {"q7": 0.5, "q3": -1.0} (values through the restricted reader; --deg for
    revolute joints)."""
    from ..io import parse_values
    from ..model import JointType

    items = (args.lock or []) + (args.free or [])  # --free is --lock under issue 30's name
    if not items:
        return None
    out = {}
    for item in ",".join(items).split(","):  # linear: split and strip, no backtracking regex
        name, eq, value = item.partition("=")
        name, value = name.strip(), value.strip()
        digits = name[1:]
        if not (eq and value and name[:1] == "q" and digits.isascii() and digits.isdigit()):
            raise ParseError(f"--lock: {item.strip()[:40]!r} is not qN=VALUE")
        if len(digits) > 4 or not 1 <= int(digits) <= robot.dof:
            raise ParseError(f"--lock: {name[:12]!r} is not a joint of {robot.name} (q1 … q{robot.dof})")
        k = int(digits)
        rev = robot.joint_types[k - 1] is JointType.REVOLUTE
        v = check_values(parse_values(value, 1, what=f"--lock q{k}", deg=args.deg and rev), f"--lock q{k}")
        out[f"q{k}"] = float(v[0])
    return out


def _analytic(args, robot, T):
    from ..ik import analytic_ik

    locked = _locks(args, robot)
    try:
        res = analytic_ik(robot, T, locked=locked)
    except UnsupportedRobotError as e:
        raise UnsupportedRobotError(_lock_hint(str(e), robot)) from None
    sols = res.solutions
    require_finite("ik", sols)
    data = {"method": "analytic", "structure": res.method, "controlled": res.controlled,
            "locked": {k: _to_unit(robot, np.where(np.arange(robot.dof) == int(k[1:]) - 1, v, 0.0), args.deg)[int(k[1:]) - 1]
                       for k, v in (locked or {}).items()},
            "solutions": _to_unit(robot, sols, args.deg), "success": res.count > 0,
            "branches": list(res.branches), "free": list(res.free),
            "residuals": [{"position": float(p), "orientation": float(o)}
                          for p, o in zip(res.position_error, res.orientation_error)],
            "outside_limits": _to_unit(robot, res.outside_limits, args.deg)}
    how = ("general 6R eigenvalue method (Raghavan-Roth / Manocha-Canny)" if res.method == "general"
           else f"closed form ({res.method}")
    lines = [f"{how}; the arm controls: {res.controlled}): {res.count} solution(s)" if res.method != "general"
             else f"{how}, every real solution; the arm controls: {res.controlled}: {res.count} solution(s)"]
    for k, (q, b, f) in enumerate(zip(sols, res.branches, res.free), start=1):
        lines.append(f"  {k}: q = [{', '.join(_fmt_q(robot, q, args.deg))}]" + (f"   {b}" if b else ""))
        if f:
            lines.append(f"     continuum: {f}")
    outside = np.asarray(res.outside_limits, dtype=float).reshape(-1, robot.dof)
    if len(outside) and args.all:
        lim = robot.q_limits
        lines.append(f"  outside the joint limits ({len(outside)}):")
        for k, q in enumerate(outside, start=res.count + 1):
            off = [f"q{j + 1}" for j in range(robot.dof) if not lim[j, 0] - 1e-9 <= q[j] <= lim[j, 1] + 1e-9]
            lines.append(f"  {k}: q = [{', '.join(_fmt_q(robot, q, args.deg))}]   outside limits: "
                         + (", ".join(off) or "(at a limit)"))
    elif len(outside):
        lines.append(f"  ({len(outside)} more outside the joint limits; --all lists them)")
    return data, lines


def _numeric(args, robot, T):
    from ..ik import solve_ik

    rng = np.random.default_rng()
    seed = None
    if args.seed is not None:
        seed = joint_values(args, robot, args.seed, what="--seed", check_limits=False)  # degrees: revolute only
    if args.all:
        n = 256
        seeds = rng.uniform(*_seed_ranges(robot).T, (n, robot.dof))
        res = solve_ik(robot, np.broadcast_to(T, (n, 4, 4)), seeds, mask=args.mask, tol=args.tol, restarts=0, rng=rng,
                       max_iterations=args.max_iterations)
        require_finite("ik", res.q[res.success])
        sols = _distinct(robot, res.q[res.success])
        data = {"method": "numeric", "solutions": _to_unit(robot, np.array(sols).reshape(-1, robot.dof), args.deg),
                "success": bool(sols), "seeds": n, "residuals": None}
        lines = [f"numeric search from {n} random seeds: {len(sols)} distinct solution(s)"]
        lines += [f"  {k}: q = [{', '.join(_fmt_q(robot, q, args.deg))}]" for k, q in enumerate(sols, start=1)]
        return data, lines
    res = solve_ik(robot, T, seed, mask=args.mask, tol=args.tol, restarts=args.restarts, rng=rng,
                   max_iterations=args.max_iterations)
    require_finite("ik", res.q if res.success else None)
    data = {"method": "numeric", "solutions": _to_unit(robot, res.q[None], args.deg) if res.success else [],
            "q": _to_unit(robot, res.q, args.deg), "success": res.success,
            "residuals": [{"position": res.position_error, "orientation": res.orientation_error}],
            "iterations": res.iterations, "restarts": res.restarts, "reason": res.reason}
    head = "converged" if res.success else f"failed ({res.reason})"
    lines = [f"numeric (Levenberg-Marquardt): {head} after {res.iterations} iterations, {res.restarts} restarts",
             f"  q = [{', '.join(_fmt_q(robot, res.q, args.deg))}]",
             f"  residual: position {res.position_error:.3g} m, orientation {res.orientation_error:.3g} rad"]
    return data, lines


def _seed_ranges(robot) -> np.ndarray:
    """(n, 2) ranges for random seeds: the limits, one turn of a revolute joint when they are wider or absent,
    and prismatic ranges within ±MAX_VALUE (limits like ±1e308 would overflow the sampler)."""
    from ..model import JointType
    from ._common import MAX_VALUE

    lim = robot.q_limits.copy()
    for k, kind in enumerate(robot.joint_types):
        lo, hi = lim[k]
        if kind is JointType.REVOLUTE:
            lo, hi = np.clip([lo, hi], -MAX_VALUE, MAX_VALUE)
            if hi - lo > 2 * np.pi:
                lo, hi = ((-np.pi, np.pi) if lo <= -np.pi and hi >= np.pi
                          else (lo, lo + 2 * np.pi) if lo > -np.pi else (hi - 2 * np.pi, hi))
        else:
            lo = lo if np.isfinite(lo) else -np.pi
            hi = hi if np.isfinite(hi) else np.pi
            lo, hi = np.clip([lo, hi], -MAX_VALUE, MAX_VALUE)
        lim[k] = lo, hi
    return lim


def _distinct(robot, qs, tol: float = 1e-6) -> list[np.ndarray]:
    from ..model import JointType

    rev = np.array([t is JointType.REVOLUTE for t in robot.joint_types])
    out: list[np.ndarray] = []
    for q in qs:
        if all(np.max(np.where(rev, np.abs((q - p + np.pi) % (2 * np.pi) - np.pi), np.abs(q - p))) > tol for p in out):
            out.append(q)
    return out


def _derive(args, robot):
    from ..symbolic import ik_derivation

    d = ik_derivation(robot)
    steps = [{"title": s.title, "text": s.text, "lhs": str(s.lhs) if s.lhs is not None else None,
              "rhs": str(s.rhs) if s.rhs is not None else None, "assign": s.assign,
              "latex": f"{_latex(s.lhs)} {s.relation} {_latex(s.rhs)}" if s.lhs is not None else None}
             for s in d.steps]
    data = {"robot": robot.name, "kind": d.kind, "branches": [str(b) for b in d.branches], "steps": steps,
            "text": d.to_text(), "latex": d.to_latex(), "markdown": d.to_markdown()}
    return data, (d.to_latex() if args.latex else d.to_text())


def _latex(e) -> str:
    import sympy as sp

    return sp.latex(e)


def _lock_hint(message: str, robot) -> str:
    """A redundant arm's refusal, with the way to its closed forms the CLI offers: hold the extra joints with
    --lock (docs/ik.md, "Redundant arms"), e.g. the Panda's q7."""
    m = re.search(r"are redundant \(its Jacobian has rank (\d+) everywhere\)", message)
    if m is None:
        return message
    rank = int(m.group(1))
    extra = robot.dof - rank
    held = " ".join(f"q{k}=0" for k in range(robot.dof - extra + 1, robot.dof + 1))
    numeric = "--method numeric" + (" with a --mask" if rank < 6 else "")
    # written whole (the library's message and this advice together ran past one_line's limit and were cut in
    # the middle of the advice: "use the numerical ... w mask)")
    return (f"{robot.name}: this {robot.dof}-joint arm is redundant (its Jacobian has rank {rank} everywhere), so "
            f"a target is reached along a continuum: hold {extra} joint{'s' * (extra > 1)} with --lock (e.g. "
            f"--lock {held}) for every closed-form solution of the others, or use {numeric} for one solution")


def beyond_reach(robot, T) -> tuple[float, float, float] | None:
    """How far the target's origin lies beyond the arm's reach, or None when it is within it.

    The bound (:func:`denavit.chain.reach_ball`): with T = C0 J1(q1) C1 ⋯ Jn(qn) Cn, rotations keep lengths, so
    the end-effector origin p stays within R = Σ_k |t(C_k)| (+ the prismatic travel) of c = t(C0) for every q.
    Returns (|p − c| − R, |p − c|, R) when |p − c| > R.
    """
    from ..chain import reach_ball, screws_of

    lim = robot.q_limits
    centre, R = reach_ball(screws_of(robot), lim[:, 0], lim[:, 1])
    dist = float(np.linalg.norm(np.asarray(T, dtype=float)[:3, 3] - centre))
    return (dist - R, dist, R) if np.isfinite(R) and dist > R else None


def cmd_ik(args: argparse.Namespace):
    robot = load(args)
    if args.derive:
        return _derive(args, robot)
    if args.path is not None or args.line is not None:
        return cmd_ik_path(args, robot)
    if args.pose is None and args.T is None and args.from_q is None:
        raise ParseError("give a target: --pose, --T or --from-q, a path: --path or --line (or --derive for the "
                         "symbolic derivation)")
    if args.latex:
        raise ParseError("--latex goes with --derive")
    T = _target(args, robot)
    method = args.method
    _ik_sweep.check(args)
    if args.sweep:
        data, lines = _ik_sweep.cmd_sweep(args, robot, T)
        data = {"robot": robot.name, "angle_unit": "deg" if args.deg else "rad", "T": T, **data}
        return data, "\n".join([f"{robot.name}: inverse kinematics of", "T =", matrix_text(T), ""] + lines)
    if args.free:
        method = "analytic"
    if args.lock and method == "numeric":
        raise ParseError("--lock goes with the analytic solver (--method analytic or auto)")
    if args.lock:
        method = "analytic"
    if method == "auto":
        from ..ik import ik_structure

        try:
            ik_structure(robot)
            method = "analytic"
        except UnsupportedRobotError:
            method = "numeric"
    data, lines = (_analytic if method == "analytic" else _numeric)(args, robot, T)
    data = {"robot": robot.name, "angle_unit": "deg" if args.deg else "rad", "T": T, **data}
    text = "\n".join([f"{robot.name}: inverse kinematics of", "T =", matrix_text(T), ""] + lines)
    if not data["success"] and (far := beyond_reach(robot, T)) is not None:
        data["reason"] = (f"out of reach: the target is {far[0]:.4g} m beyond the arm's reach bound (it is "
                          f"{far[1]:.4g} m from the chain's base point; no configuration reaches farther than "
                          f"{far[2]:.4g} m from it)")
        text += "\n" + data["reason"]
    if not data["success"]:
        emit(args, data, text)  # the result is printed, then the exit code says "no solution"
        raise _NoSolution("no solution" + (f" ({data.get('reason')})" if data.get("reason") else ""))
    return data, text


class _NoSolution(DenavitError):
    """No inverse-kinematics solution: exit code 1 after the (empty) result is printed."""


__all__ = ["register", "cmd_ik"]
