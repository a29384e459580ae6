"""ik_path: branch-true IK along Cartesian paths (issue 30, item 3).

The truths come from other routes than the follower's own bookkeeping: FK of every returned q against the pose
interpolated independently here (linear position, Rodrigues on the relative rotation vector), the first-order step
bound recomputed from the geometric Jacobian, and paths built in joint space so that the place where they meet a
singular set or leave the workspace is known before the call.
"""

from __future__ import annotations

import numpy as np
import pytest

import denavit
from denavit.ik import pose_error, rotation_log

ATOL = 1e-8


def _pose_at(Ta, Tb, s):
    """The straight-line pose at parameter s ∈ [0, 1], written here independently of the library."""
    w = rotation_log(Tb[:3, :3] @ Ta[:3, :3].T) * s
    th = np.linalg.norm(w)
    K = np.array([[0, -w[2], w[1]], [w[2], 0, -w[0]], [-w[1], w[0], 0]]) / (th if th > 0 else 1.0)
    T = np.eye(4)
    T[:3, :3] = (np.eye(3) + np.sin(th) * K + (1 - np.cos(th)) * K @ K) @ Ta[:3, :3]
    T[:3, 3] = (1 - s) * Ta[:3, 3] + s * Tb[:3, 3]
    return T


def _check_trajectory(robot, poses, traj, free=None):
    """FK(q_k) reproduces the pose at s_k; every step is within 2·|J⁺Δx|_∞ (+ rounding) of the pose step."""
    n = robot.dof
    free = np.arange(n) if free is None else free
    for k, (s, q) in enumerate(zip(traj.s, traj.q)):
        i = min(int(np.floor(s)), len(poses) - 2)
        T = _pose_at(poses[i], poses[i + 1], s - i) if len(poses) > 1 else poses[0]
        e = pose_error(T, denavit.forward_kinematics(robot, q))
        assert np.max(np.abs(e)) < ATOL, (k, s, e)
        if k:
            i0 = min(int(np.floor(traj.s[k - 1])), len(poses) - 2)
            Ta = _pose_at(poses[i0], poses[i0 + 1], traj.s[k - 1] - i0)
            J = denavit.geometric_jacobian(robot, traj.q[k - 1])[:, free]
            pred = np.max(np.abs(np.linalg.lstsq(J, pose_error(T, Ta), rcond=None)[0]))
            d = q - traj.q[k - 1]
            d = np.angle(np.exp(1j * d))  # every joint of these arms is revolute: compared modulo 2π
            assert np.max(np.abs(d)) <= 2 * pred + 1e-9, (k, np.max(np.abs(d)), pred)


def _random_lines(robot, rng, count, length=0.15, angle=0.4):
    """Lines from FK(q) (q random within the limits, shrunk) to a pose displaced by `length` m and `angle` rad."""
    lim = robot.q_limits
    mid, half = lim.mean(axis=1), 0.5 * 0.5 * (lim[:, 1] - lim[:, 0])  # the middle half of each range
    for _ in range(count):
        q = rng.uniform(mid - half, mid + half)
        Ta = denavit.forward_kinematics(robot, q)
        d = rng.normal(size=3)
        w = rng.normal(size=3)
        Tb = _pose_at(np.eye(4), np.eye(4), 0.0)
        Tb[:3, 3] = Ta[:3, 3] + length * d / np.linalg.norm(d)
        Tb[:3, :3] = _pose_at(np.eye(4), _rot(angle * w / np.linalg.norm(w)), 1.0)[:3, :3] @ Ta[:3, :3]
        yield q, denavit.cartesian_line(Ta, Tb, step=0.02, angle_step=0.1)


def _rot(w):
    T = np.eye(4)
    th = np.linalg.norm(w)
    K = np.array([[0, -w[2], w[1]], [w[2], 0, -w[0]], [-w[1], w[0], 0]]) / th
    T[:3, :3] = np.eye(3) + np.sin(th) * K + (1 - np.cos(th)) * K @ K
    return T


def _run_random(name, count, seed):
    robot = denavit.load_robot(name)
    rng = np.random.default_rng(seed)
    done = stopped = 0
    free = np.arange(6)  # panda: q7 held (the default), the first six joints move
    for q, poses in _random_lines(robot, rng, count):
        res = denavit.ik_path(robot, poses, q)
        (traj,) = res.trajectories
        np.testing.assert_allclose(traj.q[0], q, atol=1e-7)  # the start continues q0 itself
        _check_trajectory(robot, poses, traj, free=free)
        if robot.dof == 7:
            assert np.all(traj.q[:, 6] == q[6]), "the held joint moved"
            if traj.status == "stopped":
                assert traj.reason.endswith(f"(q7 held at {q[6]:.6g})")
                stopped += 1
                continue
        if traj.status == "complete":
            done += 1
            assert traj.reached == len(poses) - 1 and traj.s[-1] == len(poses) - 1
        else:
            stopped += 1
            assert traj.reason.split(":")[0] in ("singularity", "joint limit", "workspace boundary")
            assert traj.stop_index == traj.reached + 1
            T = poses[traj.stop_index]
            if traj.reason.startswith("workspace boundary: no solution"):  # LM, limits ignored, fails too
                assert not denavit.solve_ik(robot, T, traj.q[-1], restarts=0, respect_limits=False,
                                            rng=np.random.default_rng(0)).success
            elif traj.reason.startswith("workspace boundary"):  # the branch's sheet ends: its label is gone
                assert traj.branch not in denavit.analytic_ik(robot, T).branches
    assert done >= count // 4, (done, stopped)  # (the Puma's mid-range q3 is a stretched elbow: many stop)


@pytest.mark.parametrize("name, count", [("puma560", 12), ("ur5", 12), ("panda", 6)])
def test_random_lines_are_continuous_and_reproduce_every_pose(name, count):
    _run_random(name, count, 1)


@pytest.mark.slow
@pytest.mark.parametrize("name, count", [("puma560", 200), ("ur5", 200), ("panda", 200)])
def test_many_random_lines_per_arm(name, count):
    _run_random(name, count, 2)


def test_joint_limit_is_named_at_the_pose_past_it():
    """Poses of a joint-space line on which q1 runs from 2.4 to 3.1 rad: the Puma's q1 limit (±160°) lies
    between samples 7 (2.75) and 8 (2.80), known from the limits, not from the follower."""
    robot = denavit.load_robot("puma560")
    qa = np.array([2.4, 0.4, -0.5, 0.3, 0.8, 0.2])
    qs = qa + np.linspace(0, 1, 15)[:, None] * (np.array([3.1, 0.4, -0.5, 0.3, 0.8, 0.2]) - qa)
    first_out = int(np.argmax(qs[:, 0] > robot.q_limits[0, 1]))
    (traj,) = denavit.ik_path(robot, denavit.forward_kinematics(robot, qs), qa).trajectories
    assert traj.stop_index == first_out == 8 and traj.reason.startswith("joint limit"), traj.reason
    np.testing.assert_allclose(traj.q, qs[:first_out], atol=1e-8)  # it followed the generating q until then


def _puma_wrist_line(count):
    """A line along which only q5 moves, from +0.3 to −0.3 (the tool point is the wrist centre, so the pose
    turns about axis 5 alone): it crosses the wrist singularity q5 = 0 at s = 1/2."""
    robot = denavit.load_robot("puma560")
    qa = np.array([0.1, 0.4, -0.5, 0.3, 0.3, 0.2])
    qb = qa.copy()
    qb[4] = -0.3
    Ta, Tb = denavit.forward_kinematics(robot, qa), denavit.forward_kinematics(robot, qb)
    np.testing.assert_allclose(Ta[:3, 3], Tb[:3, 3], atol=1e-12)  # premise: the position does not move
    s = np.linspace(0, 1, count)
    return robot, qa, np.array([_pose_at(Ta, Tb, x) for x in s])


@pytest.mark.parametrize("count, where", [(11, 5), (12, 6)])
def test_puma_wrist_singularity_is_named_where_it_is_crossed(count, where):
    robot, qa, poses = _puma_wrist_line(count)  # 11 poses: pose 5 is singular; 12: the crossing lies in 5–6
    (traj,) = denavit.ik_path(robot, poses, qa).trajectories
    assert traj.status == "stopped" and traj.stop_index == where
    assert traj.reason.startswith("singularity")
    _check_trajectory(robot, poses, traj)
    assert np.all(traj.q[:, 4] > 0)  # the branch (wrist noflip) kept to the end


@pytest.mark.parametrize("name, q", [("ur5", [0.3, -1.2, 1.4, -0.6, 1.1, 0.4]),
                                     ("puma560", [0.1, 0.4, -0.5, 0.3, 0.8, 0.2])])
def test_line_beyond_reach_stops_at_the_workspace_boundary(name, q):
    robot = denavit.load_robot(name)
    q = np.array(q)
    Ta = denavit.forward_kinematics(robot, q)
    Tb = Ta.copy()
    Tb[:3, 3] += 1.5 * Ta[:3, 3] / np.linalg.norm(Ta[:3, 3])  # straight out, far past the reach
    poses = denavit.cartesian_line(Ta, Tb, step=0.05)
    (traj,) = denavit.ik_path(robot, poses, q).trajectories
    assert traj.status == "stopped" and traj.reason.startswith("workspace boundary"), traj.reason
    i = traj.stop_index
    # independent check of the index: the numeric solver reaches the last pose reached, and no pose from i on
    assert denavit.solve_ik(robot, poses[i - 1], traj.q[-1], restarts=0).success
    assert traj.branch not in denavit.analytic_ik(robot, poses[i]).branches
    assert not denavit.analytic_ik(robot, poses[-1]).count
    _check_trajectory(robot, poses, traj)


def test_without_q0_one_trajectory_per_solution_of_the_first_pose():
    robot = denavit.load_robot("ur5")
    q = np.array([0.3, -1.2, 1.4, -0.6, 1.1, 0.4])
    Ta = denavit.forward_kinematics(robot, q)
    Tb = Ta.copy()
    Tb[:3, 3] += [0.05, -0.05, 0.05]
    poses = denavit.cartesian_line(Ta, Tb, step=0.02)
    res = denavit.ik_path(robot, poses)
    first = denavit.analytic_ik(robot, Ta)
    assert len(res.trajectories) == first.count
    assert sorted(t.branch for t in res.trajectories) == sorted(first.branches)
    for traj in res.trajectories:
        _check_trajectory(robot, poses, traj)


def test_max_step_inserts_poses():
    robot = denavit.load_robot("puma560")
    q = np.array([0.1, 0.4, -0.5, 0.3, 0.8, 0.2])
    Ta = denavit.forward_kinematics(robot, q)
    Tb = Ta.copy()
    Tb[:3, 3] += [0.0, 0.15, -0.05]
    poses = denavit.cartesian_line(Ta, Tb, step=0.05)
    (traj,) = denavit.ik_path(robot, poses, q, max_step=0.02).trajectories
    assert traj.status == "complete"
    assert len(traj.q) > len(poses)  # poses were inserted
    d = np.abs(np.diff(traj.q, axis=0))
    assert d.max() <= 0.02
    _check_trajectory(robot, poses, traj)


def test_panda_holds_the_chosen_joint():
    robot = denavit.load_robot("panda")
    q = np.array([0.1, -0.3, 0.2, -2.0, 0.1, 1.5, 0.7])
    Ta = denavit.forward_kinematics(robot, q)
    Tb = Ta.copy()
    Tb[:3, 3] += [0.05, 0.05, -0.05]
    poses = denavit.cartesian_line(Ta, Tb, step=0.02)
    res = denavit.ik_path(robot, poses, q)
    (traj,) = res.trajectories
    assert res.held == "q7" and traj.status == "complete", traj.reason
    assert np.all(traj.q[:, 6] == 0.7)
    _check_trajectory(robot, poses, traj, free=np.arange(6))


def test_panda_nearest_moves_every_joint_and_stays_continuous():
    """redundancy="nearest": LM from the previous q at every pose, all seven joints free."""
    robot = denavit.load_robot("panda")
    rng = np.random.default_rng(3)
    moved = 0
    for q, poses in _random_lines(robot, rng, 4):
        (traj,) = denavit.ik_path(robot, poses, q, redundancy="nearest").trajectories
        assert traj.status == "complete" or traj.reason.split(":")[0] in (
            "singularity", "joint limit", "workspace boundary", "no convergence"), traj.reason
        _check_trajectory(robot, poses, traj)
        moved += np.ptp(traj.q[:, 6]) > 1e-6
    assert moved  # the self-motion is used (q7 not held)


def test_bad_input_is_refused_with_one_line():
    robot = denavit.load_robot("puma560")
    with pytest.raises(ValueError, match="poses"):
        denavit.ik_path(robot, np.zeros((3, 3)))
    with pytest.raises(ValueError, match="max_step"):
        denavit.ik_path(robot, np.eye(4)[None], max_step=-1.0)
    with pytest.raises(ValueError, match="hold"):
        denavit.ik_path(robot, np.eye(4)[None], hold="q9")
    with pytest.raises(ValueError, match="redundancy"):
        denavit.ik_path(robot, np.eye(4)[None], redundancy="free")
    with pytest.raises(ValueError, match="step"):
        denavit.cartesian_line(np.eye(4), np.eye(4), step=0.0)


def test_cli_line_and_path_file(tmp_path, capsys):
    import json

    from denavit.cli import main

    q0 = "0.3,-1.2,1.4,-0.6,1.1,0.4"
    assert main(["ik", "ur5", "--line", "0.4,0.1,0.3,0,3.1,0", "0.4,0.2,0.3,0,3.1,0", "--step", "0.05", "--q0", q0,
                 "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    (traj,) = out["trajectories"]
    assert traj["status"] == "complete" and len(traj["q"]) == 3
    robot = denavit.load_robot("ur5")
    T = denavit.forward_kinematics(robot, np.array(traj["q"][-1]))
    np.testing.assert_allclose(T[:3, 3], [0.4, 0.2, 0.3], atol=1e-8)
    # the same poses from a CSV file (quaternion of roll 0, pitch 3.1, yaw 0: w = cos 1.55, y = sin 1.55), then a
    # pose far out of reach: exit code 1, the stop named
    w, y = np.cos(1.55), np.sin(1.55)
    f = tmp_path / "poses.csv"
    f.write_text(f"x,y,z,qw,qx,qy,qz\n0.4,0.1,0.3,{w},0,{y},0\n0.4,0.2,0.3,{w},0,{y},0\n3,3,3,1,0,0,0\n")
    assert main(["ik", "ur5", "--path", str(f), "--q0", q0]) == 1
    text = capsys.readouterr().out
    assert "stops before pose 2: workspace boundary" in text
    f.write_text("x,y,z\n1,2,3\n")
    assert main(["ik", "ur5", "--path", str(f)]) == 2
    assert "--path needs the columns x y z qw qx qy qz" in capsys.readouterr().err


def test_cli_max_step_and_degrees(capsys):
    import json

    from denavit.cli import main

    args = ["ik", "puma560", "--line", "0.4,0.1,0.6,0,90,0", "0.45,0.2,0.6,0,90,0", "--step", "0.05", "--deg"]
    assert main(args + ["--max-step", "1", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    robot = denavit.load_robot("puma560")
    for traj in out["trajectories"]:
        q = np.radians(np.array(traj["q"]))  # --deg: every Puma joint is revolute
        assert np.abs(np.diff(q, axis=0)).max() <= np.radians(1) + 1e-12
        T = denavit.forward_kinematics(robot, q[-1])
        np.testing.assert_allclose(T[:3, 3], [0.45, 0.2, 0.6], atol=1e-8)
        np.testing.assert_allclose(T[:3, 2], [1, 0, 0], atol=1e-8)  # pitch 90°: the tool z axis along +x
    assert main(args + ["--hold", "q6"]) == 2
    assert "--hold needs --q0" in capsys.readouterr().err
