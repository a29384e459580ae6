"""denavit → URDF: the file loads in Pinocchio (and yourdfpy) and gives denavit's FK, RNEA and mass matrix; and
URDF → DH → URDF round trips keep the arm.  Catalogue arms and random arms (both conventions, prismatic joints, fixed rows with
inertia, base and tool).  URDF has no place for motor inertia or gravity: the comparisons use the arm without
motor inertia, and set Pinocchio's gravity to the arm's.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import denavit
from denavit.cli import main

from _random_urdf import chain_fk, random_chain, urdf_text, with_random_inertia, without_motor_inertia
from conftest import REDUCED, robots

EXAMPLES = 10 if REDUCED else 40


def _pin(robot):
    pin = pytest.importorskip("pinocchio")
    model = pin.buildModelFromXML(denavit.to_urdf(robot))
    model.gravity.linear = np.array(robot.gravity)  # URDF has no place for gravity: its reader sets it
    return pin, model, model.createData()


def _pin_q(pin, model, q):
    x = pin.neutral(model)
    for k, v in enumerate(q):
        j = model.joints[model.getJointId(f"q{k + 1}")]
        if j.nq == 2:  # continuous: (cos, sin)
            x[j.idx_q:j.idx_q + 2] = np.cos(v), np.sin(v)
        else:
            x[j.idx_q] = v
    return x


def _check_against_pinocchio(robot, rng, n=5):
    pin, model, data = _pin(robot)
    assert model.nv == robot.dof
    fid = model.getFrameId("tool")
    plain = without_motor_inertia(robot)
    for _ in range(n):
        q, qd, qdd = (rng.uniform(-np.pi, np.pi, robot.dof) for _ in range(3))
        x = _pin_q(pin, model, q)
        pin.framesForwardKinematics(model, data, x)
        np.testing.assert_allclose(data.oMf[fid].homogeneous, denavit.forward_kinematics(robot, q), atol=1e-12)
        if robot.has_dynamics:
            M = pin.crba(model, data, x)
            M = np.triu(M) + np.triu(M, 1).T
            np.testing.assert_allclose(M, denavit.mass_matrix(plain, q), atol=1e-11 * max(1, np.abs(M).max()))
            tau = pin.rnea(model, data, x, qd, qdd)
            np.testing.assert_allclose(tau, denavit.rnea(plain, q, qd, qdd, friction=False),
                                       atol=1e-10 * max(1, np.abs(tau).max()))


@pytest.mark.peer
@pytest.mark.parametrize("name", denavit.catalogue_names())
def test_catalogue_urdf_loads_in_pinocchio_with_same_fk_and_dynamics(name, rng):
    _check_against_pinocchio(denavit.load_robot(name), rng)


@pytest.mark.peer
@settings(max_examples=EXAMPLES, deadline=None)
@given(robot=robots(), seed=st.integers(0, 2**32 - 1))
def test_random_arm_urdf_matches_pinocchio(robot, seed):
    rng = np.random.default_rng(seed)
    _check_against_pinocchio(with_random_inertia(robot, rng), rng, n=3)


@pytest.mark.parametrize("name", denavit.catalogue_names())
@pytest.mark.parametrize("convention", ["standard", "modified"])
def test_catalogue_round_trip_through_urdf(name, convention, rng):
    """arm → URDF → DH: the same FK (1e-12) and, with inertia, the same RNEA and mass matrix."""
    robot = denavit.load_robot(name)
    back = denavit.from_urdf(denavit.to_urdf(robot), convention=convention)
    assert back.dof == robot.dof and back.joint_types == robot.joint_types
    np.testing.assert_array_equal(back.q_limits, robot.q_limits)
    q = rng.uniform(-np.pi, np.pi, (10, robot.dof))
    np.testing.assert_allclose(denavit.forward_kinematics(back, q), denavit.forward_kinematics(robot, q), atol=1e-12)
    if robot.has_dynamics:
        plain = without_motor_inertia(robot)
        back = back.replace(gravity=robot.gravity)  # URDF has no gravity; the import gives the usual -9.81 z
        qd, qdd = rng.uniform(-1, 1, (2, 10, robot.dof))
        np.testing.assert_allclose(denavit.mass_matrix(back, q), denavit.mass_matrix(plain, q), atol=1e-11)
        np.testing.assert_allclose(denavit.rnea(back, q, qd, qdd, friction=False),
                                   denavit.rnea(plain, q, qd, qdd, friction=False), atol=1e-10)


@settings(max_examples=EXAMPLES, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), convention=st.sampled_from(["standard", "modified"]))
def test_random_urdf_survives_urdf_dh_urdf(seed, convention):
    """A random URDF (every axis geometry, fixed joints mid-chain, prismatic joints) → DH → URDF → DH: the
    chain's FK and the dynamics stay the URDF's."""
    rng = np.random.default_rng(seed)
    links, joints = random_chain(rng)
    first = denavit.from_urdf(urdf_text(links, joints), convention=convention)
    again = denavit.from_urdf(denavit.to_urdf(first), convention=convention)
    q = rng.uniform(-np.pi, np.pi, (10, first.dof))
    expected = [chain_fk(joints, x) for x in q]
    np.testing.assert_allclose(denavit.forward_kinematics(again, q), expected, atol=1e-9)
    if first.has_dynamics:
        np.testing.assert_allclose(denavit.mass_matrix(again, q), denavit.mass_matrix(first, q), atol=1e-9)


def test_urdf_carries_names_limits_and_friction():
    robot = denavit.load_robot("puma560")
    text = denavit.to_urdf(robot)
    assert 'name="puma560"' in text or f'name="{robot.name}"' in text
    for k, link in enumerate(robot.joints, start=1):
        assert f'<joint name="q{k}"' in text
    back = denavit.interop.read_urdf(text)
    moving = [j for j in back.joints if j.moving]
    assert [j.limits for j in moving] == [link.q_limits for link in robot.joints]
    assert [j.damping for j in moving] == [link.inertia.viscous for link in robot.joints]
    assert [j.friction for j in moving] == [link.inertia.coulomb for link in robot.joints]


def test_cli_export_urdf(tmp_path, capsys):
    out = tmp_path / "arm.urdf"
    assert main(["export-urdf", "stanford", "-o", str(out)]) == 0
    assert "wrote" in capsys.readouterr().out
    robot = denavit.load_robot("stanford")
    back = denavit.from_urdf(out)
    q = np.linspace(-1, 1, robot.dof)
    np.testing.assert_allclose(denavit.forward_kinematics(back, q), denavit.forward_kinematics(robot, q), atol=1e-12)
    out.write_text("mine")
    assert main(["export-urdf", "stanford", "-o", str(out), "--no-clobber"]) == 2  # kept
    assert out.read_text() == "mine"
    assert main(["export-urdf", "stanford", "-o", str(out)]) == 0  # replaced, as savefig would
    assert denavit.from_urdf(out).dof == robot.dof
    assert main(["export-urdf", "stanford", "-o", str(tmp_path / "arm.png")]) == 2
    assert not (tmp_path / "arm.png").exists()


@pytest.mark.parametrize("name", ["a\nb <&> \"quoted\" 'x' -- end-", "ünïcödé ✓ \u202e", "x" * 2000])
def test_any_robot_name_gives_well_formed_files(name):
    """A robot's name is free text from a file: the URDF and MJCF written stay well-formed XML and carry it whole."""
    robot = denavit.load_robot("planar2r").replace(name=name)
    back = denavit.interop.read_urdf(denavit.to_urdf(robot))
    assert back.name == name
    import xml.etree.ElementTree as ET  # our own output: trusted

    mjcf = ET.fromstring(denavit.to_mjcf(robot))
    assert mjcf.tag == "mujoco" and mjcf.attrib["model"] == name


@pytest.mark.parametrize("name", ["a\x01b", "\ud800lone", "esc\x1b[2J", "\uffff"])
def test_name_xml_cannot_carry_is_refused(name):
    """XML 1.0 has no form for these characters, not even &#1;: refused, never replaced by another name."""
    robot = denavit.load_robot("planar2r").replace(name=name)
    for write in (denavit.to_urdf, denavit.to_mjcf):
        with pytest.raises(denavit.ModelError, match="XML 1.0 cannot carry"):
            write(robot)


@pytest.mark.parametrize("name", denavit.catalogue_names())
def test_catalogue_urdf_valid_in_yourdfpy_with_same_fk(name, rng):
    """A second URDF reader (yourdfpy, its own parser and FK): the file validates and gives denavit's FK."""
    import io

    yourdfpy = pytest.importorskip("yourdfpy")
    robot = denavit.load_robot(name)
    urdf = yourdfpy.URDF.load(io.StringIO(denavit.to_urdf(robot)), load_meshes=False,
                              build_collision_scene_graph=False)
    assert urdf.validate()
    assert urdf.actuated_joint_names == [f"q{k + 1}" for k in range(robot.dof)]
    for q in rng.uniform(-1, 1, (3, robot.dof)):
        urdf.update_cfg(q)
        np.testing.assert_allclose(urdf.get_transform("tool", "base_link"), denavit.forward_kinematics(robot, q),
                                   atol=1e-12)
