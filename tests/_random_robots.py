"""Random DH robots for property tests (both conventions, prismatic joints, offsets, fixed rows), and random
physical inertial data for them."""

from __future__ import annotations

import numpy as np

from denavit import Convention, DHLink, DHRobot, JointType, LinkInertia
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


def random_inertia(rng: np.random.Generator, motor: bool = True, friction: bool = True) -> LinkInertia:
    """A physically valid rigid body: principal moments of a random mass distribution (second moments s along the
    principal axes, so the triangle inequality holds), turned by a random rotation; motor inertia and viscous and
    Coulomb friction drawn when asked."""
    mass = rng.uniform(0.5, 3.0)
    s = rng.uniform(0.01, 0.1, 3)
    Q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    I = Q @ np.diag([s[1] + s[2], s[0] + s[2], s[0] + s[1]]) * mass @ Q.T
    return LinkInertia(mass=mass, com=tuple(rng.uniform(-0.3, 0.3, 3)),
                       inertia=(I[0, 0], I[1, 1], I[2, 2], I[0, 1], I[0, 2], I[1, 2]),
                       motor_inertia=rng.uniform(0, 0.5) if motor else 0.0,
                       viscous=rng.uniform(0, 1) if friction else 0.0, coulomb=rng.uniform(0, 1) if friction else 0.0)
