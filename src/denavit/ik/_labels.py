"""Branch labels of closed-form IK solutions (shoulder left/right, elbow up/down, wrist flip/noflip; definitions in
docs/ik.md), each a boolean test of q, combined by a lookup table.
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np

from ..chain import chain_of, screw_walk, screws_of
from ..model import DHRobot
from ._structure import Plan

__all__ = ["SHOULDER", "ELBOW", "WRIST", "branch_labels", "label_table", "joint_thetas"]

SHOULDER, ELBOW, WRIST = ("shoulder right", "shoulder left"), ("elbow up", "elbow down"), ("wrist noflip", "wrist flip")


def branch_labels(robot: DHRobot, plan: Plan, q: np.ndarray, T: np.ndarray) -> np.ndarray:
    """Branch labels (B, K); definitions in docs/ik.md.

    Each part of a label is a boolean test of q; the label is looked up from the combined bits (no string
    arithmetic per solution)."""
    B, K, n = q.shape
    chain = screws_of(robot)
    qq = np.nan_to_num(q)
    rev = ~chain.prismatic
    theta = joint_thetas(robot)
    parts = []  # (test (B, K) bool, label where True, label where False)
    if plan.kind.startswith(("pieper", "parallel", "position")) and plan.point_e is not None or plan.kind == "position":
        pe = plan.point_e if plan.point_e is not None else np.zeros(3)
        X = (T[:, :3, :3] @ pe + T[:, :3, 3]).T[:, :, None]  # (3, B, 1)
        x1, _, _, S = screw_walk(chain, qq[..., :1], upto=1)  # frame after joint 1 (shoulder), (3, B, K)
        if rev[0]:  # measured from axis 1 (not from S, which a shoulder offset a1 moves along x1)
            O1 = chain.consts[0][:3, 3][:, None, None]  # a point of axis 1
            parts.append((np.sum(x1 * (X - O1), axis=0) >= 0, *SHOULDER))
        if n >= 3 and rev[1] and rev[2]:
            # in the plane normal to axis 2 the two elbows are mirror images across the line from the shoulder S
            # to the point W the joints 2-3 place (the wrist centre; UR: a point of axis 4, parallel to axis 2):
            # the side of that line, with n = a2 × (W − S) oriented towards axis 1, tells them apart
            a2 = screw_walk(chain, qq[..., :1], upto=1)[2]  # axis 2, (3, B, K)
            E = screw_walk(chain, qq[..., :2], upto=2)[3]  # a point of axis 3
            W = screw_walk(chain, qq[..., :3], upto=3)[3] if plan.kind.startswith("parallel") and n >= 4 else X
            up = chain.consts[0][:3, 2][:, None, None]
            nrm = np.cross(a2, W - S, axis=0)
            towards = np.where(np.sum(up * nrm, axis=0) >= 0, 1.0, -1.0)
            parts.append((np.sum((E - S) * nrm, axis=0) * towards >= 0, *ELBOW))
        if n == 6 and rev[4] and plan.kind.startswith(("pieper", "parallel")):
            parts.append((np.sin(qq[..., 4] + theta[4]) >= 0, *WRIST))
    elif plan.kind == "planar":
        r = np.flatnonzero(rev)
        parts.append((np.sin(qq[..., r[1]] + theta[r[1]]) >= 0, "elbow up", "elbow down"))
    elif plan.kind == "wrist":
        parts.append((np.sin(qq[..., 1] + theta[1]) >= 0, "wrist noflip", "wrist flip"))
    code = np.zeros((B, K), dtype=np.intp)
    for i, (test, _, _) in enumerate(parts):
        code |= np.where(test, 0, 1 << i)
    return label_table(tuple(p[1:] for p in parts))[code]


@lru_cache(maxsize=64)
def label_table(names: tuple) -> np.ndarray:
    """Label of every bit code: bit i set picks the second name of part i."""
    return np.array([", ".join(p[(c >> i) & 1] for i, p in enumerate(names)) for c in range(1 << len(names))],
                    dtype=object)


def joint_thetas(robot: DHRobot) -> np.ndarray:
    memo = chain_of(robot).memo
    if "ik_thetas" not in memo:
        memo["ik_thetas"] = np.array([l.theta for l in robot.joints])  # read-only use
    return memo["ik_thetas"]
