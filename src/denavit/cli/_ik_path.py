"""``denavit ik ROBOT --path poses.csv | --line A B``: branch-true IK along a path (:func:`denavit.ik_path`)."""

from __future__ import annotations

import argparse

import numpy as np

from ..errors import DenavitError, ParseError
from ._common import check_values, emit, joint_values, numbers_text, positive_float

__all__ = ["MAX_LINE_POSES", "add_path_arguments", "cmd_ik_path"]

#: Most poses a --line may be cut into (--step small against the line's length is refused).
MAX_LINE_POSES = 100_000


def add_path_arguments(target: argparse._MutuallyExclusiveGroup, p: argparse.ArgumentParser) -> None:
    """--path / --line (in the target group) and the options that go with them."""
    target.add_argument("--path", metavar="POSES.csv",
                        help="follow these poses (CSV columns x y z qw qx qy qz; m, unit quaternion w first) on "
                             "one branch each")
    target.add_argument("--line", nargs=2, metavar="X,Y,Z,ROLL,PITCH,YAW",
                        help="follow the Cartesian straight line between two poses (position linear, orientation "
                             "slerp), cut at --step")
    p.add_argument("--step", type=positive_float, default=0.01, help="--line: position step [m] (default 0.01)")
    p.add_argument("--q0", metavar="Q", help="--path/--line: continue this configuration's branch (default: one "
                                             "trajectory per solution of the first pose)")
    p.add_argument("--max-step", dest="max_step", type=positive_float,
                   help="--path/--line: largest joint step [rad (deg with --deg), m]; poses are inserted to "
                        "respect it")
    p.add_argument("--hold", metavar="qN", help="--path/--line, redundant arms: the joint held at --q0's value "
                                                "(default the last)")
    p.add_argument("--redundancy", choices=["hold", "nearest"], default="hold",
                   help="--path/--line, redundant arms: hold one joint (closed form for the rest), or nearest: the "
                        "numeric solver from the previous q at every pose")


def _line_pose(args, text: str):
    from ..io import parse_values
    from ..numeric import transform_from_xyz_rpy

    v = check_values(parse_values(text, 6, what="--line"), "--line")
    if args.deg:
        v[3:] = parse_values(text, 6, what="--line", deg=True)[3:]
    return transform_from_xyz_rpy(v[:3], v[3:])


def _poses(args, robot) -> np.ndarray:
    from ..calibration import read_measurements
    from ..ik import cartesian_line

    if args.path is not None:
        poses = read_measurements(args.path, robot, require_joints=False).poses
        if poses is None:
            raise ParseError(f"{args.path}: --path needs the columns x y z qw qx qy qz")
        return poses
    Ta, Tb = (_line_pose(args, t) for t in args.line)
    length = float(np.linalg.norm(Tb[:3, 3] - Ta[:3, 3]))
    if length / args.step > MAX_LINE_POSES:
        raise ParseError(f"--step {args.step:g}: the line ({length:.4g} m) would have more than {MAX_LINE_POSES} "
                         "poses; use a larger step")
    return cartesian_line(Ta, Tb, step=args.step)


class _NotFollowed(DenavitError):
    """No trajectory reached the last pose: exit code 1 after the result is printed."""


def cmd_ik_path(args: argparse.Namespace, robot):
    from ..ik import ik_path
    from ..model import JointType

    poses = _poses(args, robot)
    q0 = None if args.q0 is None else joint_values(args, robot, args.q0, what="--q0")
    if args.hold is not None and q0 is None:
        raise ParseError("--hold needs --q0 (the held joint keeps its value)")
    max_step = np.radians(args.max_step) if args.deg and args.max_step is not None else args.max_step
    res = ik_path(robot, poses, q0, hold=args.hold, max_step=max_step, redundancy=args.redundancy)
    rev = np.array([t is JointType.REVOLUTE for t in robot.joint_types])
    unit = lambda q: np.where(rev, np.degrees(q), q) if args.deg else q
    trajs = [{"branch": t.branch, "status": t.status, "reached": t.reached, "stop_index": t.stop_index,
              "reason": t.reason, "s": t.s, "q": unit(t.q)} for t in res.trajectories]
    data = {"robot": robot.name, "angle_unit": "deg" if args.deg else "rad", "poses": len(poses),
            "held": res.held, "trajectories": trajs, "success": bool(res.complete)}
    lines = [f"{robot.name}: inverse kinematics along {len(poses)} poses: {len(res.complete)} of "
             f"{len(res.trajectories)} trajector{'y' if len(res.trajectories) == 1 else 'ies'} complete"
             + (f" ({res.held} held)" if res.held else "")]
    for k, t in enumerate(res.trajectories, start=1):
        head = f"  {k}: {t.branch or 'trajectory'}: {t.status}, {len(t.q)} samples, reached pose {t.reached}"
        lines.append(head + (f"; stops before pose {t.stop_index}: {t.reason}" if t.stop_index is not None else ""))
        lines += [f"     s = {s:.4g}: q = [{numbers_text(unit(q))}]" for s, q in zip(t.s, t.q)]
    text = "\n".join(lines)
    if not res.complete:
        emit(args, data, text)
        raise _NotFollowed("no trajectory reaches the last pose (reasons above)")
    return data, text
