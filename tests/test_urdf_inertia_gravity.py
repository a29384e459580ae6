"""URDF import: a link's unphysical inertia and a tilted --base link (issue 29, item 5).

* A link whose tensor breaks the triangle inequality (xArm6's link 3 is 13.5 % off; Pinocchio and pybullet load
  it) no longer refuses the kinematics: a warning names the ``<link>`` and its line and the arm comes without
  inertial data; ``--fix-inertia`` uses the nearest physical tensor (stated), ``--no-inertia`` leaves inertia out.
* With ``--base`` on a link turned in the URDF's root frame, gravity is turned into that link's frame (it was
  (0, 0, -9.81) of the tilted link).  The truth is the same arm imported from the root: both must give the same
  gravity torques at every configuration.
"""

from __future__ import annotations

import numpy as np
import pytest

import denavit
from denavit import DenavitWarning
from denavit.interop import import_urdf, nearest_physical_inertia
from denavit.numeric import gravity_torques

from _hostile import run_cli

BAD_TENSOR = """<robot name="tri">
  <link name="base"/>
  <link name="l1"><inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.023" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="l2"><inertial><mass value="1"/><inertia ixx="0.01" iyy="0.02" izz="0.02" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <joint name="j1" type="revolute"><parent link="base"/><child link="l1"/><origin xyz="0 0 0.3"/>
    <axis xyz="0 0 1"/><limit lower="-2" upper="2" effort="1" velocity="1"/></joint>
  <joint name="j2" type="revolute"><parent link="l1"/><child link="l2"/><origin xyz="0.2 0 0" rpy="1.5707963267948966 0 0"/>
    <axis xyz="0 0 1"/><limit lower="-2" upper="2" effort="1" velocity="1"/></joint>
</robot>
"""


def _inertias(robot):
    return [link.inertia for link in robot.links]


def test_unphysical_link_warns_with_link_and_line_and_keeps_the_kinematics():
    with pytest.warns(DenavitWarning, match=r"<link name='l1'> \(line 3\).*triangle inequality"):
        result = import_urdf(BAD_TENSOR)
    assert _inertias(result.robot) == [None, None]
    bare = import_urdf(BAD_TENSOR, inertia="none").robot
    assert bare == result.robot  # the same kinematics, no inertia
    assert any("--no-inertia" in n for n in import_urdf(BAD_TENSOR, inertia="none").notes)


def test_fix_inertia_uses_the_nearest_physical_tensor():
    """l1's moments (0.01, 0.01, 0.023) break A + B >= C by 0.003: the projection onto A + B = C moves each by
    0.001 (worked by hand: (0.011, 0.011, 0.022)); l2 is physical and kept as written."""
    result = import_urdf(BAD_TENSOR, inertia="fix")
    note = next(n for n in result.notes if "l1" in n)
    assert "line 3" in note and "nearest physical" in note
    li1, li2 = _inertias(result.robot)
    np.testing.assert_allclose(sorted(np.linalg.eigvalsh(li1.inertia_matrix)), [0.011, 0.011, 0.022], atol=1e-12)
    np.testing.assert_allclose(sorted(np.linalg.eigvalsh(li2.inertia_matrix)), [0.01, 0.02, 0.02], atol=1e-9)


def test_nearest_physical_inertia_by_hand_and_minimal():
    np.testing.assert_allclose(nearest_physical_inertia(np.diag([1.0, 1.0, 3.0])), np.diag([4, 4, 8]) / 3)
    I = np.diag([2.0, 3.0, 4.0])
    assert np.array_equal(nearest_physical_inertia(I), I)  # physical already: unchanged
    rng = np.random.default_rng(3)
    bad = np.diag([0.1, 0.2, 1.0])
    best = np.linalg.norm(nearest_physical_inertia(bad) - bad)
    for _ in range(500):  # no physical diagonal tensor is nearer
        w = np.sort(rng.uniform(0, 1.2, 3))
        if w[0] + w[1] >= w[2]:
            assert np.linalg.norm(np.diag(w) - bad) >= best - 1e-12


def test_cli_flags(tmp_path):
    o = run_cli(["import-urdf", "arm.urdf", "-o", "arm.yaml"], tmp_path, {"arm.urdf": BAD_TENSOR})
    assert o.code == 0 and len(o.err.strip().splitlines()) == 1 and "<link name='l1'> (line 3)" in o.err
    assert denavit.load_robot(tmp_path / "arm.yaml").links[0].inertia is None
    o = run_cli(["import-urdf", "arm.urdf", "--fix-inertia", "-o", "fixed.yaml"], tmp_path)
    assert o.code == 0 and o.err == "" and "nearest physical" in o.out
    assert denavit.load_robot(tmp_path / "fixed.yaml").links[0].inertia is not None
    o = run_cli(["import-urdf", "arm.urdf", "--no-inertia", "--fix-inertia"], tmp_path)
    assert o.code == 2


TILTED = """<robot name="tilt">
  <link name="world"/>
  <link name="mount"/>
  <link name="l1"><inertial><origin xyz="0.1 0.02 0"/><mass value="2"/>
    <inertia ixx="0.01" iyy="0.02" izz="0.02" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="l2"><inertial><origin xyz="0.15 0 0.03"/><mass value="1"/>
    <inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <joint name="m" type="fixed"><parent link="world"/><child link="mount"/><origin xyz="0 0 1" rpy="0.7 -0.4 0.2"/></joint>
  <joint name="j1" type="revolute"><parent link="mount"/><child link="l1"/><origin xyz="0 0 0.3"/>
    <axis xyz="0 0 1"/><limit lower="-2" upper="2" effort="1" velocity="1"/></joint>
  <joint name="j2" type="revolute"><parent link="l1"/><child link="l2"/><origin xyz="0.2 0 0" rpy="1.5707963267948966 0 0"/>
    <axis xyz="0 0 1"/><limit lower="-2" upper="2" effort="1" velocity="1"/></joint>
</robot>
"""


def test_base_on_a_tilted_link_turns_gravity_into_its_frame():
    from_root = import_urdf(TILTED).robot
    result = import_urdf(TILTED, base="mount")
    assert from_root.gravity == (0.0, 0.0, -9.81)
    assert np.isclose(np.linalg.norm(result.robot.gravity), 9.81)
    assert not np.allclose(result.robot.gravity, (0, 0, -9.81))
    assert any("gravity" in n and "'mount'" in n for n in result.notes)
    q = np.random.default_rng(7).uniform(-2, 2, (20, 2))
    np.testing.assert_allclose(gravity_torques(result.robot, q), gravity_torques(from_root, q), atol=1e-9)
