"""The catalogue's names (old report names load as aliases) and its named poses (``poses:`` in robot files)."""

import json
import math

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

import denavit
from denavit.cli import main
from denavit.errors import ModelError, ParseError
from denavit.io import CATALOGUE_ALIASES, catalogue_names, dump_robot, load_robot, resolve_pose, robot_from_dict

OLD_NAMES = sorted(CATALOGUE_ALIASES)


def test_no_catalogue_name_is_a_seed_report_number():
    names = catalogue_names()
    assert not [n for n in names if n.startswith("report")]
    assert len(set(CATALOGUE_ALIASES.values())) == len(CATALOGUE_ALIASES) == 12
    assert set(CATALOGUE_ALIASES.values()) <= set(names)
    assert not set(CATALOGUE_ALIASES) & set(names)


@pytest.mark.parametrize("old", OLD_NAMES)
@settings(max_examples=10, deadline=None)
@given(data=st.data())
def test_old_name_loads_the_same_arm(old, data):
    a, b = load_robot(old), load_robot(CATALOGUE_ALIASES[old])
    assert a == b and a.source == f"catalogue:{CATALOGUE_ALIASES[old]}"
    lim = np.where(np.isfinite(a.q_limits), a.q_limits, np.sign(a.q_limits) * np.pi)
    q = np.array([data.draw(st.floats(lo, hi)) for lo, hi in lim])
    np.testing.assert_array_equal(denavit.forward_kinematics(a, q), denavit.forward_kinematics(b, q))


def test_robots_lists_new_names_and_notes_the_old(capsys):
    assert main(["robots", "--json"]) == 0
    listed = [r["name"] for r in json.loads(capsys.readouterr().out)["robots"]]
    assert listed == catalogue_names()
    assert not set(listed) & set(CATALOGUE_ALIASES)
    assert main(["robots"]) == 0
    out = capsys.readouterr().out
    for old, new in CATALOGUE_ALIASES.items():
        line = next(line for line in out.splitlines() if line.startswith(new + " "))
        assert f"old name {old}" in line


def test_catalogue_doc_names_every_arm_and_no_private_folder():
    from pathlib import Path

    doc = (Path(__file__).parents[1] / "docs" / "catalogue.md").read_text(encoding="utf-8")
    for name in catalogue_names():
        assert f"`{name}`" in doc, name
    for old in CATALOGUE_ALIASES:
        assert f"`{old}`" in doc, old
    assert "/work/" not in doc and "seeds/" not in doc


# --- named poses ----------------------------------------------------------------------------------

# the published named configurations (roboticstoolbox-python models/DH, read independently here)
RTB_POSES = {
    "puma560": ("Puma560", ["qz", "qr", "qs", "qn"]),
    "puma560-mdh": ("Puma560", ["qz", "qr", "qs", "qn"]),
    "ur5": ("UR5", ["qz", "qr"]),
    "panda": ("Panda", ["qr"]),
    "scara": ("Cobra600", ["qz", "qr"]),
    "planar2r": ("TwoLink", ["qz", "qr", "qn"]),  # RTB's q1, q2 would read as joint variables: left out
    "planar3r": ("Planar3", ["qz", "qr"]),
}


@pytest.mark.parametrize("name", catalogue_names())
def test_poses_are_within_limits_and_well_formed(name):
    robot = load_robot(name)
    lim = robot.q_limits
    for pose, q in robot.poses:
        assert pose.isidentifier() and len(q) == robot.dof
        assert np.all((np.array(q) >= lim[:, 0]) & (np.array(q) <= lim[:, 1])), (name, pose)
        np.testing.assert_array_equal(resolve_pose(robot, pose), q)
    hash(robot)


def test_well_known_arms_carry_poses():
    for name in ("puma560", "ur5", "panda", "stanford", "scara", "planar2r"):
        assert dict(load_robot(name).poses), name
    assert [k for k, _ in load_robot("puma560").poses] == ["qz", "qr", "qs", "qn"]


@pytest.mark.parametrize("name", sorted(RTB_POSES))
def test_poses_match_roboticstoolbox(name):
    pytest.importorskip("roboticstoolbox")
    import roboticstoolbox.models.DH as rtb_models

    cls, names = RTB_POSES[name]
    peer = getattr(rtb_models, cls)()
    poses = dict(load_robot(name).poses)
    assert sorted(poses) == sorted(names)
    for k in names:
        np.testing.assert_allclose(poses[k], getattr(peer, k), atol=1e-12, err_msg=f"{name}.{k}")


def test_puma_poses_are_the_postures_they_name():
    # independent of the numbers: qr points the arm straight up, qs stretches it horizontally (Corke 2017, 7.2)
    robot = load_robot("puma560")
    poses = dict(robot.poses)
    frames = denavit.numeric.link_transforms(robot, np.array(poses["qr"]))
    wrist, shoulder = frames[4][:3, 3], frames[1][:3, 3]
    assert abs(wrist[0] - shoulder[0]) < 0.05 and wrist[2] - shoulder[2] > 0.8  # upright
    frames = denavit.numeric.link_transforms(robot, np.array(poses["qs"]))
    wrist, shoulder = frames[4][:3, 3], frames[1][:3, 3]
    assert abs(wrist[2] - shoulder[2]) < 0.05 and wrist[0] - shoulder[0] > 0.8  # horizontal


def _file(**extra):
    data = {"convention": "standard", "angle_unit": "deg",
            "joints": [{"a": 1, "alpha": 0, "d": 0, "theta": "q", "limits": [-90, 90]},
                       {"a": 0, "alpha": 0, "d": "q", "theta": 0, "limits": [0, 0.5]}]}
    data.update(extra)
    return data


@settings(max_examples=40, deadline=None)
@given(deg=st.floats(-90, 90), d=st.floats(0, 0.5))
def test_pose_values_follow_the_angle_unit_and_round_trip(deg, d):
    robot = robot_from_dict(_file(poses={"home": [repr(deg), repr(d)], "up": ["pi/4", 0.1]}))
    poses = dict(robot.poses)
    assert poses["home"][0] == pytest.approx(math.radians(deg), abs=1e-15) and poses["home"][1] == d
    assert poses["up"] == pytest.approx((math.pi / 4, 0.1))  # pi says its unit; the prismatic value is in m
    back = robot_from_dict(__import__("yaml").safe_load(dump_robot(robot)))
    np.testing.assert_allclose(np.array([q for _, q in back.poses]), np.array([q for _, q in robot.poses]),
                               atol=1e-12)


@pytest.mark.parametrize("poses, words", [
    ({"qr": [0]}, ["poses.qr", "2 values"]),
    ({"qr": [0, 0, 0]}, ["poses.qr", "2 values"]),
    ({"qr": "0 0"}, ["poses.qr"]),
    ([[0, 0]], ["poses", "mapping"]),
    ({"qr": [100, 0]}, ["pose qr", "joint 1", "limits"]),
    ({"qr": [0, 0.7]}, ["pose qr", "joint 2", "limits"]),
    ({"qr": ["__import__('os')", 0]}, ["poses.qr"]),
    ({"qr": ["L9", 0]}, ["poses.qr", "L9"]),
    ({"bad name": [0, 0]}, ["bad name", "identifier"]),
])
def test_bad_poses_are_refused_naming_the_place(poses, words):
    with pytest.raises(ParseError) as info:
        robot_from_dict(_file(poses=poses), where="arm.yaml")
    text = str(info.value)
    assert "arm.yaml" in text
    for w in words:
        assert w in text, (w, text)


def test_model_checks_poses_given_in_python():
    robot = load_robot("planar2r")
    assert robot.replace(poses={"a": (0.1, 0.2)}).poses == (("a", (0.1, 0.2)),)
    for poses in ({"a": (0.1,)}, {"a": (9.0, 0.0)}, {"a": (float("nan"), 0.0)}, {"a": 3}):
        with pytest.raises(ModelError):
            robot.replace(poses=poses)
    with pytest.raises(ModelError):
        robot.replace(poses=[("a", (0, 0)), ("a", (0, 0))])
    assert resolve_pose(robot, "nope") is None


ARM = """convention: standard
angle_unit: deg
joints:
  - {a: 1, alpha: 0, d: 0, theta: q, limits: [-90, 90]}
  - {a: 0, alpha: 0, d: q, theta: 0, limits: [0, 0.5]}
"""


@pytest.mark.parametrize("poses, words", [
    ("poses: {qr: [0]}", ["arm.yaml", "poses.qr"]),
    ("poses: {qr: [120, 0]}", ["arm.yaml", "pose qr", "limits"]),
    ("poses: {qr: [\"__import__('os').system('x')\", 0]}", ["arm.yaml", "poses.qr"]),
    ("poses: [1, 2]", ["arm.yaml", "poses"]),
    ("poses: {qr: [1e400, 0]}", ["arm.yaml"]),
])
def test_cli_refuses_bad_poses_in_one_line(tmp_path, poses, words):
    from _hostile import assert_refused, run_cli

    assert_refused(run_cli(["show", "arm.yaml"], tmp_path, {"arm.yaml": ARM + poses + "\n"}), mentions=words)


def test_replace_links_keeps_only_the_poses_that_still_fit():
    """A catalogue arm with narrower limits keeps the poses inside them and drops the others; poses given
    explicitly must fit (a pose outside the limits is refused)."""
    from denavit.errors import ModelError

    base = load_robot("planar2r")
    assert base.poses
    links = list(base.links)
    links[1] = links[1].__class__(a=links[1].a, alpha=0.0, d=0.0, theta=0.0, q_limits=(0.0, 0.1))
    narrow = base.replace(links=tuple(links))
    lim = narrow.q_limits
    kept = dict(narrow.poses)
    for name, q in base.poses:
        inside = all(lo - 1e-9 <= v <= hi + 1e-9 for v, (lo, hi) in zip(q, lim))
        assert (name in kept) == inside, name
    with pytest.raises(ModelError, match="outside its limits"):
        base.replace(links=tuple(links), poses=(("bad", (0.0, 1.0)),))


@pytest.mark.parametrize("name", ["puma560", "panda", "ur5"])
def test_cli_q_accepts_a_named_pose(capsys, name):
    """``-q qr`` on the command line means the arm's named pose; FK equals the library at the stored values."""
    robot = load_robot(name)
    for pose, q in robot.poses:
        assert main(["fk", name, "-q", pose, "--json"]) == 0
        data = json.loads(capsys.readouterr().out)
        np.testing.assert_allclose(data["T"], denavit.forward_kinematics(robot, np.array(q)), atol=1e-12)
        # --deg changes how numbers are read and shown, not what a pose name means
        assert main(["fk", name, "-q", pose, "--deg", "--json"]) == 0
        data = json.loads(capsys.readouterr().out)
        np.testing.assert_allclose(data["T"], denavit.forward_kinematics(robot, np.array(q)), atol=1e-12)


def test_cli_unknown_pose_name_lists_the_poses(capsys):
    code = main(["fk", "puma560", "-q", "qx"])
    out, err = capsys.readouterr()
    assert code == 2 and out == ""
    lines = err.strip().splitlines()
    assert len(lines) == 1 and "'qx'" in lines[0] and "qz, qr, qs, qn" in lines[0]


def test_cli_report_at_a_named_pose(capsys, tmp_path):
    robot = load_robot("puma560")
    path = tmp_path / "r.md"
    assert main(["report", "puma560", "-q", "qn", "--topics", "fk", "-o", str(path)]) == 0
    capsys.readouterr()
    from denavit.io import parse_values

    text = path.read_text()
    shown = text.split("q = (", 1)[1].split(")", 1)[0]  # the configuration the report states it used
    np.testing.assert_allclose(parse_values(shown, robot.dof), dict(robot.poses)["qn"], atol=1e-12)


@pytest.mark.parametrize("bad", ["q1", "q12", "pi", "deg", "q"])
def test_pose_names_that_read_as_joint_values_are_refused(bad):
    """``-q q1`` must never mean a pose: names of joint variables and constants are refused as pose names."""
    base = load_robot("planar2r")
    with pytest.raises(ModelError, match="taken"):
        base.replace(poses=((bad, (0.0, 0.0)),))
