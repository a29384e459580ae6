"""Robot files are lossless (issue 29, item 5): what denavit writes loads back bit-identical, without warnings.

Every catalogue arm and 200 random arms (random floats everywhere; base and tool within 1e-12 of the identity;
angles a hair away from whole degrees and from multiples of π; multi-turn limits such as ±400°) go through
``save_robot`` → ``load_robot`` in YAML and JSON.  The reloaded arm must equal the original (dataclass equality:
every float compared with ``==``, every expression text) and reading it must warn about nothing.  Truth is the
original object itself, not a number from the writer.
"""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest

import denavit
from denavit import Convention, DHLink, DHRobot, JointType, LinkInertia
from denavit.io import dump_robot, load_robot, save_robot

N_RANDOM = 200


def _reload(robot: DHRobot, path) -> tuple[DHRobot, list[str]]:
    save_robot(robot, path, overwrite=True)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        back = load_robot(path)
    return back.replace(source=robot.source), [str(w.message) for w in caught]


def _floats(robot: DHRobot) -> list[float]:
    """Every number the model holds, in a fixed order (for a bit-for-bit comparison with float.hex)."""
    out: list[float] = []
    for link in robot.links:
        out += [link.a, link.alpha, link.d, link.theta, *(link.q_limits or ())]
        if link.inertia is not None:
            li = link.inertia
            out += [li.mass, *li.com, *li.inertia, li.motor_inertia, li.viscous, li.coulomb]
    out += [x for row in robot.base for x in row] + [x for row in robot.tool for x in row] + list(robot.gravity)
    out += [v for _, v in robot.parameters] + [v for _, q in robot.poses for v in q]
    return out


def plain_model(robot: DHRobot) -> DHRobot:
    """The arm without the expression texts a file reader records (``deg(170)``, ``pi/2``): an arm built in
    Python has none, the same arm read from a file has them; the numbers are what must not change."""
    def link(l: DHLink) -> DHLink:
        inertia = None if l.inertia is None else LinkInertia(
            mass=l.inertia.mass, com=l.inertia.com, inertia=l.inertia.inertia, motor_inertia=l.inertia.motor_inertia,
            viscous=l.inertia.viscous, coulomb=l.inertia.coulomb)
        return DHLink(a=l.a, alpha=l.alpha, d=l.d, theta=l.theta, joint=l.joint, q_limits=l.q_limits, inertia=inertia)

    return robot.replace(links=tuple(link(l) for l in robot.links), symbols=())


def _assert_same(back: DHRobot, robot: DHRobot) -> None:
    """Bit for bit (float.hex of every number) and equal as models; an arm that came from a file keeps its
    expression texts too (full equality)."""
    assert [x.hex() for x in _floats(back)] == [x.hex() for x in _floats(robot)]
    assert plain_model(back) == plain_model(robot)
    if robot.symbols or any(l.symbols or (l.inertia is not None and l.inertia.symbols) for l in robot.links):
        assert back == robot


@pytest.mark.parametrize("name", denavit.catalogue_names())
def test_catalogue_arm_round_trips_bit_identical_without_warning(name, tmp_path):
    robot = load_robot(name)
    for suffix in ("yaml", "json"):
        back, warned = _reload(robot, tmp_path / f"arm.{suffix}")
        _assert_same(back, robot)
        assert warned == []


def _near(rng: np.random.Generator, exact: float) -> float:
    """``exact`` or a value a few ulps (or up to 1e-9°) away from it: what rounding and unit changes produce."""
    pick = rng.integers(4)
    if pick == 0:
        return exact
    if pick == 1:
        return float(np.nextafter(exact, math.inf if rng.random() < 0.5 else -math.inf))
    if pick == 2:
        return exact + float(rng.uniform(-1, 1)) * math.radians(1e-9)
    return exact * (1 + float(rng.uniform(-4, 4)) * 2.0**-52)


def _angle(rng: np.random.Generator) -> float:
    kind = rng.integers(4)
    if kind == 0:
        return _near(rng, math.radians(int(rng.integers(-360, 361))))
    if kind == 1:
        return _near(rng, int(rng.integers(-8, 9)) * math.pi / int(rng.choice([1, 2, 3, 4, 6, 8, 12])))
    if kind == 2:
        return float(rng.uniform(-math.pi, math.pi))
    return float(rng.normal() * 1e-13)


def _inertia(rng: np.random.Generator) -> LinkInertia:
    """A physical tensor: principal moments obeying the triangle inequality, turned by a random rotation."""
    a, b = rng.uniform(0.01, 1.0, 2)
    principal = np.array([a, b, rng.uniform(abs(a - b), a + b) * 0.999 + 1e-3])
    Q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    I = Q @ np.diag(principal) @ Q.T
    return LinkInertia(mass=float(rng.uniform(0.1, 10)), com=tuple(float(x) for x in rng.normal(size=3) * 0.3),
                       inertia=(I[0, 0], I[1, 1], I[2, 2], I[0, 1], I[0, 2], I[1, 2]),
                       motor_inertia=float(rng.choice([0.0, rng.uniform(0, 1e-3)])),
                       viscous=float(rng.choice([0.0, rng.uniform(0, 1)])), coulomb=float(rng.choice([0.0, 0.1])))


def _near_identity(rng: np.random.Generator) -> np.ndarray:
    T = np.eye(4)
    if rng.random() < 0.7:
        T[:3] += rng.uniform(-1e-12, 1e-12, (3, 4)) * (rng.random((3, 4)) < 0.5)
    return T


def _limits(rng: np.random.Generator, joint: JointType) -> tuple[float, float] | None:
    if rng.random() < 0.2:
        return None
    if joint is JointType.PRISMATIC:
        lo = float(rng.uniform(-1, 0))
        return lo, lo + float(rng.uniform(0.01, 2))
    top = _near(rng, math.radians(float(rng.choice([170, 180, 360, 400, 540]))))
    if rng.random() < 0.2:
        top = float(rng.choice([9.42, 6.2832, 2 * math.pi + 1e-7]))  # ANYmal's ±9.42, UR's ±2π as -6.2832
    return -top, top


def random_arm(rng: np.random.Generator) -> DHRobot:
    """An arm with random floats everywhere (see the module notes)."""
    links = []
    for k in range(int(rng.integers(1, 8))):
        joint = JointType.PRISMATIC if rng.random() < 0.2 else JointType.FIXED if rng.random() < 0.1 else JointType.REVOLUTE
        if k == 0:
            joint = JointType.REVOLUTE
        links.append(DHLink(a=float(rng.choice([0.0, rng.normal()])), alpha=_angle(rng),
                            d=float(rng.choice([0.0, rng.normal(), rng.normal() * 1e-17])), theta=_angle(rng),
                            joint=joint, q_limits=_limits(rng, joint) if joint is not JointType.FIXED else None,
                            inertia=_inertia(rng) if rng.random() < 0.6 else None))
    robot = DHRobot(name="random", links=tuple(links), convention=Convention(rng.choice(["standard", "modified"])),
                    base=_near_identity(rng), tool=_near_identity(rng),
                    gravity=tuple(float(x) for x in rng.normal(size=3) * 5), description="random arm")
    lo, hi = robot.q_limits.T
    finite = np.isfinite(lo)
    q = np.where(finite, np.where(finite, lo, 0) + np.where(finite, hi - lo, 0) * rng.random(robot.dof),
                 rng.uniform(-10, 10, robot.dof))
    return robot.replace(poses=(("qz", tuple(np.clip(0.0, lo, hi))), ("qa", tuple(float(x) for x in q))))


def test_random_arms_round_trip_bit_identical_without_warning(tmp_path):
    rng = np.random.default_rng(29)
    for i in range(N_RANDOM):
        robot = random_arm(rng)
        back, warned = _reload(robot, tmp_path / ("arm.yaml" if i % 2 else "arm.json"))
        assert warned == [], dump_robot(robot)
        _assert_same(back, robot)
        if i % 4 == 0:  # the reloaded arm, expression texts and all, once more
            again, _ = _reload(back, tmp_path / "again.yaml")
            assert again == back


def test_tool_a_hair_off_identity_is_kept(tmp_path):
    """A tool 9e-9 m off the identity (issue 29) and a base 1e-12 rad turned are written and come back."""
    tool = np.eye(4)
    tool[0, 3] = 9e-9
    base = np.eye(4)
    base[0, 1], base[1, 0] = -1e-12, 1e-12
    robot = load_robot("planar2r").replace(tool=tool, base=base)
    back, _ = _reload(robot, tmp_path / "arm.yaml")
    assert back.tool[0][3] == 9e-9 and back.base[1][0] == 1e-12


def test_angle_a_hair_off_a_whole_degree_is_not_rounded(tmp_path):
    off = math.radians(30) + math.radians(1e-10)
    robot = DHRobot(name="r", links=(DHLink(a=1.0, alpha=off, joint=JointType.REVOLUTE),))
    text = dump_robot(robot)
    assert "30deg" not in text and "pi/6" not in text
    back, _ = _reload(robot, tmp_path / "arm.yaml")
    assert back.links[0].alpha == off


def test_exact_forms_are_written_only_when_exact():
    """pi/2 and 90deg are written for the exact values (they read nicer), never for a neighbour."""
    exact = DHRobot(name="r", links=(DHLink(alpha=math.pi / 2, theta=math.radians(170), joint=JointType.REVOLUTE),))
    text = dump_robot(exact)
    assert "alpha: pi/2" in text and "q + 170deg" in text
    nudged = exact.replace(links=(DHLink(alpha=np.nextafter(math.pi / 2, 0), joint=JointType.REVOLUTE),))
    assert "pi/2" not in dump_robot(nudged)


def test_multi_turn_limits_say_their_unit():
    """A ±9.42 rad limit is written rad(9.42): the file reads back without the 'degrees?' warning."""
    robot = DHRobot(name="r", links=(DHLink(joint=JointType.REVOLUTE, q_limits=(-9.42, 9.42)),))
    assert "limits: [rad(-9.42), rad(9.42)]" in dump_robot(robot)


def test_urdf_import_with_rounded_angles_writes_the_arm_it_checked(tmp_path):
    """An URDF with rpy="1.5708 0 0" (rounded π/2): the written YAML loads back to the very arm whose FK self-check
    import-urdf reported, so the file passes the same self-check."""
    from denavit.interop import import_urdf

    urdf = tmp_path / "arm.urdf"
    urdf.write_text("""<robot name="rounded">
  <link name="base"/><link name="l1"/><link name="l2"/><link name="l3"/>
  <joint name="j1" type="revolute"><parent link="base"/><child link="l1"/><origin xyz="0 0 0.333" rpy="0 0 0"/>
    <axis xyz="0 0 1"/><limit lower="-2.8973" upper="2.8973" effort="1" velocity="1"/></joint>
  <joint name="j2" type="revolute"><parent link="l1"/><child link="l2"/><origin xyz="0 0 0" rpy="-1.5708 0 0"/>
    <axis xyz="0 0 1"/><limit lower="-1.7628" upper="1.7628" effort="1" velocity="1"/></joint>
  <joint name="j3" type="revolute"><parent link="l2"/><child link="l3"/><origin xyz="0.0825 -0.316 0" rpy="1.5708 0 0"/>
    <axis xyz="0 0 1"/><limit lower="-6.2832" upper="6.2832" effort="1" velocity="1"/></joint>
</robot>""")
    result = import_urdf(str(urdf))
    back, warned = _reload(result.robot, tmp_path / "arm.yaml")
    _assert_same(back, result.robot)
    assert warned == []


@pytest.mark.parametrize("limits, unit", [("[-400, 400]", "deg"), ("[-rad(9.42), rad(9.42)]", "rad"),
                                          ("[-6.2832deg * 180 / pi, 6.2832deg * 180 / pi]", "rad")])
def test_genuine_multi_turn_limits_written_by_denavit_read_back_quietly(limits, unit, tmp_path):
    """IRB140's ±400°, ANYmal's ±9.42 rad, UR's ±2π as 6.2832: read once, written by denavit, read again
    without the "more than a full turn" warning (issue 29), to the same limits."""
    src = tmp_path / "src.yaml"
    src.write_text(f"name: arm\nconvention: standard\nangle_unit: {unit}\njoints:\n"
                   f"  - {{a: 0.07, alpha: 0, d: 0.35, theta: q, limits: {limits}}}\n")
    robot = load_robot(src)
    back, warned = _reload(robot, tmp_path / "arm.yaml")
    assert warned == [] and back.links[0].q_limits == robot.links[0].q_limits
    assert abs(robot.links[0].q_limits[1]) > 2 * math.pi
