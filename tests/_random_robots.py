"""Random DH robots for property tests (both conventions, prismatic joints, offsets, fixed rows)."""

from __future__ import annotations

import numpy as np

from denavit import Convention, DHLink, DHRobot, JointType
from denavit.numeric import transform_from_xyz_rpy


def random_robot(rng: np.random.Generator, convention: str | None = None, n_rows: int | None = None,
                 fixed_rows: bool = True, base_tool: bool = True) -> DHRobot:
    """A random serial arm; about one row in five prismatic and one in eight fixed."""
    conv = Convention(convention or rng.choice(["standard", "modified"]))
    n_rows = n_rows or int(rng.integers(1, 8))
    links = []
    for _ in range(n_rows):
        kind = rng.random()
        joint = JointType.PRISMATIC if kind < 0.2 else JointType.FIXED if (fixed_rows and kind > 0.88) else JointType.REVOLUTE
        alpha = float(rng.choice([0.0, np.pi / 2, -np.pi / 2, rng.uniform(-np.pi, np.pi)]))
        links.append(DHLink(
            a=float(rng.choice([0.0, rng.uniform(-1, 1)])), alpha=alpha,
            d=float(rng.choice([0.0, rng.uniform(-1, 1)])), theta=float(rng.uniform(-np.pi, np.pi)), joint=joint,
        ))
    if all(link.joint is JointType.FIXED for link in links):
        links[0] = DHLink(a=links[0].a, alpha=links[0].alpha, d=links[0].d, joint=JointType.REVOLUTE)
    base = tool = np.eye(4)
    if base_tool and rng.random() < 0.5:
        base = transform_from_xyz_rpy(rng.uniform(-1, 1, 3), rng.uniform(-np.pi, np.pi, 3))
        tool = transform_from_xyz_rpy(rng.uniform(-1, 1, 3), rng.uniform(-np.pi, np.pi, 3))
    return DHRobot(name="random", links=tuple(links), convention=conv, base=base, tool=tool)


def random_q(rng: np.random.Generator, robot: DHRobot, shape: tuple[int, ...] = ()) -> np.ndarray:
    return rng.uniform(-np.pi, np.pi, shape + (robot.dof,))
