"""URDF in, DH out: random serial URDFs of every axis geometry, checked against an independent URDF FK and Pinocchio.

The URDFs are generated here (tests/_random_urdf.py) with the geometry of each pair of consecutive joint axes
crafted on purpose (skew, parallel, anti-parallel, coincident, anti-coincident, intersecting), fixed joints in
the chain, prismatic joints, and inertials in turned frames.  The oracles are the chain FK written in the test
with scipy, and Pinocchio's own URDF parser (``buildModelFromXML``) for FK, RNEA and the mass matrix.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import denavit
from denavit.interop import import_urdf

from _random_urdf import CASES, chain_fk, dof, random_chain, urdf_text
from conftest import REDUCED

ATOL = 1e-9
EXAMPLES = 15 if REDUCED else 60

seeds = st.integers(0, 2**32 - 1)
conventions = st.sampled_from(["standard", "modified"])


def _chain(seed: int, **kw):
    rng = np.random.default_rng(seed)
    links, joints = random_chain(rng, **kw)
    return rng, links, joints, urdf_text(links, joints)


@settings(max_examples=EXAMPLES, deadline=None)
@given(seed=seeds, convention=conventions)
def test_random_urdf_fk_equals_urdf_chain_fk(seed, convention):
    rng, links, joints, text = _chain(seed)
    result = import_urdf(text, convention=convention)
    robot = result.robot
    assert robot.dof == dof(joints)
    assert robot.convention.value == convention
    q = rng.uniform(-np.pi, np.pi, (20, robot.dof))
    T = denavit.forward_kinematics(robot, q)
    for s in range(len(q)):
        np.testing.assert_allclose(T[s], chain_fk(joints, q[s]), atol=ATOL)
    assert result.position_error < ATOL and result.rotation_error < ATOL


@settings(max_examples=EXAMPLES, deadline=None)
@given(seed=seeds)
def test_each_row_reports_the_crafted_axis_geometry(seed):
    rng, links, joints, text = _chain(seed)
    result = import_urdf(text)
    moving = [j for j in joints if j.kind != "fixed"]
    expected = [j.case for j in moving[1:]] + ["last"]
    assert list(result.cases) == expected
    assert result.joint_names == tuple(j.name for j in moving)


@settings(max_examples=EXAMPLES, deadline=None)
@given(seed=seeds, case=st.sampled_from(CASES), convention=conventions)
def test_every_special_case_alone(seed, case, convention):
    """Chains made of one geometry only (e.g. all coincident), which exercise the free choices in a row."""
    rng, links, joints, text = _chain(seed, cases=(case,))
    robot = import_urdf(text, convention=convention).robot
    q = rng.uniform(-np.pi, np.pi, (10, robot.dof))
    T = denavit.forward_kinematics(robot, q)
    for s in range(len(q)):
        np.testing.assert_allclose(T[s], chain_fk(joints, q[s]), atol=ATOL)
    for link in robot.joints:  # the free choices are made so that the row has no needless offsets
        assert abs(link.a) < 1e6 and abs(link.d) < 1e6
    if case in ("coincident", "anti-coincident", "intersecting"):
        assert all(link.a == 0 for link in robot.links)
    if case in ("coincident", "anti-coincident"):
        expect = 0.0 if case == "coincident" else np.pi
        rows = robot.links[:-1] if convention == "standard" else robot.links[1:]
        assert all(abs(abs(link.alpha) - expect) < 1e-12 for link in rows)


@settings(max_examples=EXAMPLES, deadline=None)
@given(seed=seeds)
def test_limits_and_joint_types_carried(seed):
    rng, links, joints, text = _chain(seed)
    robot = import_urdf(text).robot
    moving = [j for j in joints if j.kind != "fixed"]
    for link, j in zip(robot.joints, moving):
        assert link.joint.value == {"continuous": "revolute"}.get(j.kind, j.kind)
        assert link.q_limits == j.limits  # the DH variable is the URDF's: limits unchanged


@settings(max_examples=EXAMPLES // 2, deadline=None)
@given(seed=seeds, convention=conventions)
def test_written_robot_file_gives_the_same_arm(seed, convention, tmp_path_factory):
    rng, links, joints, text = _chain(seed)
    robot = import_urdf(text, convention=convention).robot
    path = tmp_path_factory.mktemp("urdf") / "arm.yaml"
    denavit.save_robot(robot, path)
    again = denavit.load_robot(path)
    q = rng.uniform(-np.pi, np.pi, (10, robot.dof))
    np.testing.assert_allclose(denavit.forward_kinematics(again, q), [chain_fk(joints, x) for x in q], atol=ATOL)
    if robot.has_dynamics:
        np.testing.assert_allclose(denavit.mass_matrix(again, q), denavit.mass_matrix(robot, q), atol=1e-9)


def test_first_axis_on_base_z_gives_identity_base_and_textbook_row():
    text = """<robot name="two"><link name="base"/><link name="l1"/><link name="l2"/><link name="tool"/>
      <joint name="j1" type="revolute"><parent link="base"/><child link="l1"/><origin xyz="0 0 0.4"/>
        <axis xyz="0 0 1"/><limit lower="-2" upper="2" effort="1" velocity="1"/></joint>
      <joint name="j2" type="revolute"><parent link="l1"/><child link="l2"/><origin xyz="0.25 0 0"/>
        <axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
      <joint name="t" type="fixed"><parent link="l2"/><child link="tool"/><origin xyz="0.2 0 0"/></joint></robot>"""
    result = import_urdf(text)
    robot = result.robot
    np.testing.assert_array_equal(robot.base_matrix, np.eye(4))
    # a planar 2R on a pedestal: d1 = 0.4, a1 = 0.25 (parallel axes), the tool 0.2 along x
    assert (robot.links[0].d, robot.links[0].a, robot.links[0].alpha) == pytest.approx((0.4, 0.25, 0.0))
    assert result.cases == ("parallel", "last")
    np.testing.assert_allclose(robot.tool_matrix[:3, 3], [0.2, 0, 0], atol=1e-15)
    assert any("fixed joint" in note for note in result.notes)


# --- Pinocchio as the oracle: FK, RNEA and mass matrix of the URDF itself ------------------------------------

def _pin_model(text: str):
    pin = pytest.importorskip("pinocchio")
    model = pin.buildModelFromXML(text)
    return model, model.createData()


@pytest.mark.peer
@settings(max_examples=EXAMPLES, deadline=None)
@given(seed=seeds, convention=conventions)
def test_random_urdf_matches_pinocchio(seed, convention):
    pin = pytest.importorskip("pinocchio")
    rng, links, joints, text = _chain(seed)
    robot = import_urdf(text, convention=convention).robot
    model, data = _pin_model(text)
    assert model.nv == robot.dof
    tip = model.getFrameId(links[-1].name)
    for _ in range(5):
        q, qd, qdd = (rng.uniform(-np.pi, np.pi, robot.dof) for _ in range(3))
        x = pin.neutral(model)
        for k, j in enumerate(model.joints[1:]):  # continuous joints as (cos, sin)
            x[j.idx_q:j.idx_q + j.nq] = (np.cos(q[k]), np.sin(q[k])) if j.nq == 2 else q[k]
        pin.framesForwardKinematics(model, data, x)
        np.testing.assert_allclose(denavit.forward_kinematics(robot, q), data.oMf[tip].homogeneous, atol=ATOL)
        if robot.has_dynamics:
            tau = pin.rnea(model, data, x, qd, qdd)
            np.testing.assert_allclose(denavit.rnea(robot, q, qd, qdd), tau, atol=1e-8 * max(1, np.abs(tau).max()))
            M = pin.crba(model, data, x)
            M = np.triu(M) + np.triu(M, 1).T
            np.testing.assert_allclose(denavit.mass_matrix(robot, q), M, atol=1e-9 * max(1, np.abs(M).max()))


# --- the command line ------------------------------------------------------------------------------------------

def test_cli_import_urdf_writes_the_arm_and_reports(tmp_path, capsys):
    import json

    from denavit.cli import main

    rng, links, joints, text = _chain(7, n=4)
    (tmp_path / "arm.urdf").write_text(text)
    out = tmp_path / "arm.yaml"
    assert main(["import-urdf", str(tmp_path / "arm.urdf"), "--convention", "modified", "-o", str(out), "--json"]) == 0
    report = json.loads(capsys.readouterr().out)
    robot = denavit.load_robot(out)
    assert robot.convention.value == "modified" and robot.dof == 4
    assert report["joints"] == [j.name for j in joints if j.kind != "fixed"]
    assert len(report["cases"]) == 4 and report["cases"][-1] == "last"
    assert report["self_check"]["position_error"] < ATOL
    q = rng.uniform(-np.pi, np.pi, (5, 4))
    np.testing.assert_allclose(denavit.forward_kinematics(robot, q), [chain_fk(joints, x) for x in q], atol=ATOL)
    assert main(["import-urdf", str(tmp_path / "arm.urdf")]) == 0  # no -o: the robot file on stdout
    shown = capsys.readouterr().out
    assert "FK self-check" in shown and "joints:" in shown


def test_default_tip_is_the_leaf_with_most_moving_joints():
    """Frames hanging off by fixed joints (a camera, a 'base' marker) do not compete for the tip."""
    text = """<robot name="t"><link name="w"/><link name="a"/><link name="b"/><link name="cam"/><link name="mark"/>
      <joint name="j1" type="continuous"><parent link="w"/><child link="a"/><axis xyz="0 0 1"/></joint>
      <joint name="j2" type="prismatic"><parent link="a"/><child link="b"/><origin xyz="0.1 0 0"/>
        <axis xyz="1 0 0"/><limit lower="0" upper="0.5" effort="1" velocity="1"/></joint>
      <joint name="fc" type="fixed"><parent link="a"/><child link="cam"/><origin xyz="0 0.1 0"/></joint>
      <joint name="fm" type="fixed"><parent link="w"/><child link="mark"/></joint></robot>"""
    result = import_urdf(text)
    assert (result.base_link, result.tip_link) == ("w", "b")
    assert [j.value for j in result.robot.joint_types] == ["revolute", "prismatic"]
    assert result.robot.joints[0].q_limits is None and result.robot.joints[1].q_limits == (0.0, 0.5)


SMALL_ARM = Path(__file__).resolve().parents[1] / "examples" / "urdf" / "small_arm.urdf"


def test_small_arm_fixture_by_hand():
    """examples/urdf/small_arm.urdf worked by hand: a pedestal 0.05 + 0.3 + 0.1 = 0.45 m high, the shoulder-lift
    axis (y) meeting the pan axis (z) there, the telescope (x) meeting both, the wrist roll on the telescope's
    line 0.5 m out, the flange 0.05 m beyond; the camera (fixed to the shoulder) rides on body 1."""
    result = import_urdf(SMALL_ARM)
    robot = result.robot
    assert (result.base_link, result.tip_link) == ("world", "flange")
    assert result.cases == ("intersecting", "intersecting", "coincident", "last")
    assert [t.value for t in robot.joint_types] == ["revolute", "revolute", "prismatic", "revolute"]
    assert robot.joints[2].q_limits == (0.0, 0.2) and robot.joints[3].q_limits is None
    for q, p in (([0, 0, 0, 0], [0.55, 0, 0.45]), ([np.pi / 2, 0, 0, 0], [0, 0.55, 0.45]),
                 ([0, 0, 0.2, 1.0], [0.75, 0, 0.45]), ([0, -np.pi / 2, 0, 0], [0, 0, 1.0])):
        np.testing.assert_allclose(denavit.forward_kinematics(robot, q)[:3, 3], p, atol=1e-12)
    assert robot.joints[0].inertia.mass == pytest.approx(2.2)  # shoulder 2.0 + camera 0.2
    assert robot.joints[0].inertia.viscous == 0.1 and robot.joints[0].inertia.coulomb == 0.05


@pytest.mark.peer
@pytest.mark.parametrize("convention", ["standard", "modified"])
def test_small_arm_fixture_matches_pinocchio(convention, rng):
    pin = pytest.importorskip("pinocchio")
    robot = import_urdf(SMALL_ARM, convention=convention).robot
    model = pin.buildModelFromUrdf(str(SMALL_ARM))
    data = model.createData()
    fid = model.getFrameId("flange")
    for _ in range(10):
        q, qd, qdd = (rng.uniform(-1, 1, 4) for _ in range(3))
        x = np.concatenate([q[:3], [np.cos(q[3]), np.sin(q[3])]])  # the continuous wrist as (cos, sin)
        pin.framesForwardKinematics(model, data, x)
        np.testing.assert_allclose(denavit.forward_kinematics(robot, q), data.oMf[fid].homogeneous, atol=1e-12)
        np.testing.assert_allclose(denavit.rnea(robot, q, qd, qdd, friction=False), pin.rnea(model, data, x, qd, qdd),
                                   atol=1e-12)


def _two_axes(eps: float) -> str:
    """Joint 2's z axis turned by eps about x and y: skew to joint 1's, nearly parallel for small eps."""
    return f"""<robot name="r"><link name="a"/><link name="b"/><link name="c"/><link name="d"/>
      <joint name="j1" type="revolute"><parent link="a"/><child link="b"/><axis xyz="0 0 1"/></joint>
      <joint name="j2" type="revolute"><parent link="b"/><child link="c"/><origin xyz="0.4 0.2 0.1"
        rpy="{eps!r} {eps!r} 0"/><axis xyz="0 0 1"/></joint>
      <joint name="j3" type="fixed"><parent link="c"/><child link="d"/><origin xyz="0.3 0 0"/></joint></robot>"""


@pytest.mark.parametrize("eps", [1e-2, 1e-3, 1e-4])
def test_nearly_parallel_skew_axes_stay_exact(eps):
    """The common normal of nearly parallel axes is far away (about 0.1/eps² m) but the model stays exact."""
    result = import_urdf(_two_axes(eps))
    assert result.cases == ("skew", "last")
    assert result.position_error < 1e-12 and result.rotation_error < 1e-12


@pytest.mark.parametrize("eps", [1e-5, 1e-7])
def test_almost_parallel_axes_taken_as_parallel_with_a_note_and_a_warning(eps):
    with pytest.warns(denavit.DenavitWarning, match="differs from the URDF chain"):
        result = import_urdf(_two_axes(eps))
    assert result.cases == ("parallel", "last")
    assert any("nearly parallel" in note for note in result.notes)
    assert 0 < result.position_error < 10 * eps and result.rotation_error < 10 * eps


@settings(max_examples=EXAMPLES, deadline=None)
@given(seed=seeds, exponent=st.integers(-3, 5))
def test_arms_of_any_size_import_exactly_or_are_refused_cleanly(seed, exponent):
    """Every length scaled by 10^exponent (millimetre arms to 100 km ones): the import is exact relative to the
    arm's size, or (beyond the magnitude bounds of denavit.model) a ParseError naming the file; nothing else."""
    import re
    import warnings

    rng, links, joints, text = _chain(seed)
    factor = 10.0 ** exponent
    text = re.sub(r'<origin xyz="([^"]*)"',
                  lambda m: '<origin xyz="' + " ".join(repr(float(v) * factor) for v in m.group(1).split()) + '"',
                  text)
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("error", denavit.DenavitWarning)  # a failed self-check would be an error here
            result = import_urdf(text)
    except denavit.ParseError as exc:
        # only arms whose lengths or (mass times length squared) inertias pass the 1e6 bounds may be refused
        assert exponent >= 3 and "<URDF text>" in str(exc)
        return
    size = max(1.0, factor)
    assert result.position_error < 1e-9 * size and result.rotation_error < 1e-9


def test_small_arm_file_shows_the_urdf_decimals(tmp_path):
    """The flange 0.05 m beyond the wrist and the wrist's centre of mass 0.03 m behind the flange (0.02 from the
    wrist link's origin, by hand) came out 0.050000000000000044 and -0.030000000000000027 in the written file."""
    robot = import_urdf(SMALL_ARM).robot
    assert robot.links[3].d == 0.05 and robot.links[3].inertia.com == (0.0, 0.0, -0.03)
    assert robot.links[2].inertia.com == (0.0, 0.0, -0.1)
    denavit.save_robot(robot, tmp_path / "arm.yaml")
    text = (tmp_path / "arm.yaml").read_text()
    assert "0000000" not in text and "9999999" not in text


@settings(max_examples=200 if REDUCED else 1000, deadline=None)
@given(st.integers(-10**9, 10**9), st.integers(0, 12), st.integers(-8, 8),
       st.floats(-1e6, 1e6, allow_nan=False, allow_subnormal=False))
def test_tidy_snaps_noise_only(mantissa, exponent, ulps, x):
    from denavit.interop._urdf_in import TIDY_ULPS, tidy

    decimal = mantissa / 10**exponent  # a short decimal (at most 10 significant digits)
    assert tidy(decimal + ulps * np.spacing(abs(decimal))) == decimal
    assert tidy(ulps * np.spacing(1.0), 1.0) == 0.0  # noise around zero, at the scale of the quantity
    assert abs(tidy(x) - x) <= TIDY_ULPS * np.spacing(abs(x))  # any value moves by a few ulps at most
    assert abs(tidy(x, 1.0) - x) <= TIDY_ULPS * np.spacing(max(abs(x), 1.0))


def test_cli_import_urdf_deg_prints_the_table_in_degrees_and_writes_radians(tmp_path, capsys):
    from denavit.cli import main

    src = Path(__file__).resolve().parents[1] / "examples" / "urdf" / "small_arm.urdf"
    out = tmp_path / "arm.yaml"
    assert main(["import-urdf", str(src), "--deg", "-o", str(out)]) == 0
    shown = capsys.readouterr().out
    assert "angles in degrees" in shown and "-90°" in shown
    again = tmp_path / "plain.yaml"
    assert main(["import-urdf", str(src), "-o", str(again)]) == 0
    capsys.readouterr()
    assert out.read_text() == again.read_text()  # the file does not depend on --deg (radians)
    assert "angle_unit: rad" in out.read_text()
