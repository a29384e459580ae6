"""Redundant arms by one held joint: analytic_ik(free=) and free_joint_sweep, checked against a dense numeric search.

Truth comes from routes the code under test does not use: the held arm is built here from the DH rows (the held
joint's value added to its θ, the row made fixed) and searched by Levenberg–Marquardt from many random seeds;
every claimed solution is checked by forward kinematics of the full arm against the target and against the limits.
"""

from __future__ import annotations

import json
from dataclasses import replace

import numpy as np
import pytest

import denavit
from denavit import (
    analytic_ik,
    forward_kinematics,
    free_joint_sweep,
    geometric_jacobian,
    load_robot,
    solve_ik,
)
from denavit.cli import main
from denavit.errors import ModelError
from denavit.ik import default_free_joint
from denavit.model import JointType

SEEDS = 120  # LM starts per pose of the dense search (2-8 solutions within the limits; each found ~20-60 times)
SAME = 1e-6  # two joint vectors within this (max over joints, angles modulo 2π) are one solution


@pytest.fixture(scope="module")
def panda():
    return load_robot("panda")


def _range(robot):
    """(n, 2) the joint limits, one turn [−π, π] for a joint without them (Gen3's q1, q3, q5, q7)."""
    return np.where(np.isfinite(robot.q_limits), robot.q_limits, [-np.pi, np.pi])


def _poses(robot, n, seed):
    rng = np.random.default_rng(seed)
    q = rng.uniform(*_range(robot).T, (n, robot.dof))
    return q, forward_kinematics(robot, q)


def _held_arm(robot, k, v):
    """The arm with joint k turned into a fixed row at v (revolute: v added to the row's θ)."""
    rows = [i for i, link in enumerate(robot.links) if link.joint is not JointType.FIXED]
    link = robot.links[rows[k]]
    assert link.joint is JointType.REVOLUTE
    links = list(robot.links)
    links[rows[k]] = replace(link, theta=link.theta + v, joint=JointType.FIXED, q_limits=None)
    return replace(robot, links=tuple(links), poses=())


def _wrapped(d):
    return np.abs(d - 2 * np.pi * np.rint(d / (2 * np.pi)))


def _gap(a, b):
    """(A,) distance of each row of a to its nearest row of b (max over joints, angles modulo 2π)."""
    if len(b) == 0:
        return np.full(len(a), np.inf)
    return _wrapped(a[:, None, :] - b[None, :, :]).max(axis=-1).min(axis=-1)


def _missing(robot, k, numeric, analytic):
    """Rows of ``numeric`` (joint k held) that are no solution of ``analytic``: farther than SAME, or, next to a
    singularity of the held arm, farther than LM's accuracy there (its tolerance 1e-9 over the smallest singular
    value σ of the held arm's Jacobian, ×100) — a pose matched to 1e-9 fixes q only to ~1e-9/σ."""
    gap = _gap(numeric, analytic)
    J = np.delete(geometric_jacobian(robot, numeric), k, axis=-1)  # (m, 6, 6): the held arm's columns
    sigma = np.linalg.svd(J, compute_uv=False)[..., -1] if len(numeric) else np.zeros(0)
    return gap >= np.maximum(SAME, 100 * 1e-9 / np.maximum(sigma, 1e-300))


def _check_solutions(robot, T, q):
    """Every row of q reproduces T (full-arm FK, computed here) and lies within the limits."""
    q = np.asarray(q).reshape(-1, robot.dof)
    F = forward_kinematics(robot, q)
    assert np.abs(F - T).max(initial=0.0) < 1e-8
    lim = robot.q_limits
    assert np.all((q >= lim[:, 0] - 1e-9) & (q <= lim[:, 1] + 1e-9))


def _dense(robot, T, k, v, rng):
    """Every solution the numeric search finds with joint k held at v: (m, n) rows, joint k inserted."""
    held = _held_arm(robot, k, v)
    seeds = rng.uniform(*_range(held).T, (SEEDS, held.dof))
    res = solve_ik(held, np.broadcast_to(T, (SEEDS, 4, 4)), seeds, restarts=0, rng=rng)
    return np.insert(res.q[res.success], k, v, axis=1)


def test_free_is_locked(panda):
    q, T = _poses(panda, 1, 0)
    a = analytic_ik(panda, T[0], free={"q7": q[0, 6]})
    b = analytic_ik(panda, T[0], locked={"q7": q[0, 6]})
    assert np.array_equal(a.solutions, b.solutions) and a.method == b.method
    assert np.min(_gap(q[:1], a.solutions)) < 1e-9
    with pytest.raises(ModelError, match="not both"):
        analytic_ik(panda, T[0], locked={"q7": 0.1}, free={"q7": 0.1})


@pytest.mark.parametrize("joint, n", [(6, 6), (2, 2)])
def test_free_joint_solutions_are_complete(panda, joint, n):
    """Held q7 (closed form) at 6 random poses and q3 (general 6R route) at 2 (more under slow): the dense search finds no
    solution the analytic set lacks, and the generating configuration is in it."""
    rng = np.random.default_rng(10 + joint)
    q, T = _poses(panda, n, 20 + joint)
    found = 0
    for qi, Ti in zip(q, T):
        res = analytic_ik(panda, Ti, free={f"q{joint + 1}": qi[joint]})
        _check_solutions(panda, Ti, res.solutions)
        assert np.all(res.solutions[:, joint] == qi[joint])
        assert _gap(qi[None], res.solutions)[0] < 1e-8
        numeric = _dense(panda, Ti, joint, qi[joint], rng)
        _check_solutions(panda, Ti, numeric)
        assert not _missing(panda, joint, numeric, res.solutions).any(), "the dense search found one analytic_ik lacks"
        found += len(numeric)
    assert found > n  # the search did run


def test_default_free_joint_is_a_closed_form_choice(panda):
    assert default_free_joint(panda) == "q7"
    _, T = _poses(panda, 1, 3)
    assert not analytic_ik(panda, T[0], free={"q7": 0.0}).method.startswith("general")
    assert analytic_ik(panda, T[0], free={"q3": 0.0}).method.startswith("general")


def _sweep_checks(robot, T, q, sweep, rng, gaps=True):
    k = int(sweep.joint[1:]) - 1
    # the ends are bisected to sweep.tol: a generating value at a fold (the held arm singular there) may fall that
    # close outside (a Panda pose of the 1,000 run: σ_min 3.6e-6, the interval began 2.3e-7 above q7)
    assert any(a - sweep.tol <= q[k] <= b + sweep.tol for a, b in sweep.intervals), "the generating value is feasible"
    for b in sweep.branches:  # every listed solution: FK matches T, within the limits, held value as listed
        _check_solutions(robot, T, b.q)
        assert np.array_equal(b.q[:, k], b.values) and b.interval == (b.values[0], b.values[-1])
    ends = {v for b in sweep.branches for v in b.interval}
    for a, b in sweep.intervals:
        # the ends are confirmed by the branches' own solutions there (checked above); at a fold they sit within
        # rounding of where two solutions merge and vanish, where the one-value route (the target not moved by
        # X(v)) may fall on the other side, so it probes inside: near both ends and at random
        assert a in ends and b in ends
        inner = [t for t in (a + 0.01 * (b - a), b - 0.01 * (b - a)) if b - a > 100 * sweep.tol]
        for t in np.r_[inner, rng.uniform(a, b, 2)]:
            res = analytic_ik(robot, T, free={sweep.joint: t})
            assert res.count >= 1
            _check_solutions(robot, T, res.solutions)
    for t in [v + d for a, b in sweep.intervals for v, d in ((a, -1e-4), (b, 1e-4))]:  # just past each end: nothing
        if sweep.limits[0] <= t <= sweep.limits[1] and not any(a <= t <= b for a, b in sweep.intervals):
            assert analytic_ik(robot, T, free={sweep.joint: t}).count == 0, f"a solution at {sweep.joint} = {t}"
    for (a0, b0), (a1, b1) in zip(sweep.intervals[:-1], sweep.intervals[1:]):  # gaps: the dense search agrees
        if gaps and a1 - b0 > 1e-3:
            t = 0.5 * (b0 + a1)
            assert len(_dense(robot, T, k, t, rng)) == 0, f"a solution at {sweep.joint} = {t} in a gap"
    inside = [np.any([(a <= v <= b) for a, b in sweep.intervals]) for v in sweep.values]
    assert np.array_equal(np.array(inside), sweep.counts > 0)


def test_sweep_intervals_confirmed(panda):
    rng = np.random.default_rng(5)
    q, T = _poses(panda, 2, 6)
    for qi, Ti in zip(q, T):
        sweep = free_joint_sweep(panda, Ti, "q7", samples=48, tol=1e-5)
        assert sweep.tol == 1e-5 and np.isin(np.linspace(*panda.q_limits[6], 48), sweep.values).all()
        _sweep_checks(panda, Ti, qi, sweep, rng)
        # the batch route (targets moved by X(v)) against the one-value route at a few samples
        for i in rng.choice(48, 4, replace=False):
            res = analytic_ik(panda, Ti, free={"q7": sweep.values[i]})
            assert res.count == sweep.counts[i]


@pytest.mark.slow
def test_sweep_intervals_confirmed_many(panda):
    rng = np.random.default_rng(7)
    q, T = _poses(panda, 2, 8)
    for j, (qi, Ti) in enumerate(zip(q, T)):
        _sweep_checks(panda, Ti, qi, free_joint_sweep(panda, Ti, "q1" if j == 1 else "q7", samples=48), rng)


@pytest.mark.slow
def test_free_joint_solutions_are_complete_many(panda):
    rng = np.random.default_rng(11)
    q, T = _poses(panda, 16, 12)
    for j, (qi, Ti) in enumerate(zip(q, T)):
        k = (4, 5, 6, 3, 0)[j % 5]
        res = analytic_ik(panda, Ti, free={f"q{k + 1}": qi[k]})
        _check_solutions(panda, Ti, res.solutions)
        assert not _missing(panda, k, _dense(panda, Ti, k, qi[k], rng), res.solutions).any()


def test_sweep_refuses_bad_input(panda):
    T = forward_kinematics(panda, panda.q_limits.mean(axis=1))
    for kwargs, match in [({"joint": "q8"}, "not a joint"), ({"joint": "x"}, "not a joint"),
                          ({"samples": 1}, "samples"), ({"tol": -1.0}, "tol")]:
        with pytest.raises(ModelError, match=match):
            free_joint_sweep(panda, T, **kwargs)
    with pytest.raises(ModelError, match="one target"):
        free_joint_sweep(panda, np.stack([T, T]), "q7")


def _run(capsys, *argv):
    code = main(list(argv))
    out = capsys.readouterr()
    return code, out.out, out.err


def test_cli_free_and_sweep(capsys, panda):
    qs = "0.2,-0.3,0.1,-2.0,0.3,1.6,0.5"
    code, out, err = _run(capsys, "ik", "panda", "--from-q", qs, "--free", "q7=0.5", "--json")
    assert code == 0, err
    data = json.loads(out)
    assert data["locked"] == {"q7": 0.5}
    assert np.min(_gap(np.array([[0.2, -0.3, 0.1, -2.0, 0.3, 1.6, 0.5]]), np.array(data["solutions"]))) < 1e-9
    code, out, err = _run(capsys, "ik", "panda", "--from-q", qs, "--free", "q7", "--sweep", "--samples", "32", "--json")
    assert code == 0, err
    data = json.loads(out)
    assert data["joint"] == "q7" and data["samples"] == 32
    assert any(a <= 0.5 <= b for a, b in data["intervals"])
    T = np.array(data["T"])
    for b in data["branches"]:
        _check_solutions(panda, T, np.array(b["solutions"]))
    code, out, err = _run(capsys, "ik", "panda", "--from-q", qs, "--sweep", "--samples", "32")
    assert code == 0, err
    assert "q7 swept over" in out and "feasible q7" in out and "branch(es)" in out
    assert f"32 samples + {data['evaluated'] - 32} added: next to branch ends, from the cross-wise q5 search, from the limit margin" in out


@pytest.mark.parametrize("argv, match", [
    (["--free", "q9", "--sweep"], "not a joint"), (["--samples", "5"], "goes with --sweep"),
    (["--free", "q7", "--free", "q6", "--sweep"], "one --free"), (["--sweep", "--lock", "q7=0"], "--sweep goes"),
    (["--free", "q7=0", "--method", "numeric"], "analytic"), (["--free", "q7=abc"], "q7"),
    (["--sweep", "--samples", "1"], "")])
def test_cli_refuses_bad_input(capsys, argv, match):
    code, _, err = _run(capsys, "ik", "panda", "--from-q", "0,0,0,-1,0,1,0", *argv)
    assert code == 2 and err.count("\n") == 1 and "Traceback" not in err
    assert match in err


def test_public_names():
    assert denavit.free_joint_sweep is free_joint_sweep and "free_joint_sweep" in denavit.__all__


# --- KUKA LBR iiwa (S-R-S) -------------------------------------------------------------------------------------

@pytest.mark.parametrize("name, joint, n", [("iiwa7", 6, 3), ("iiwa14", 2, 3)])
def test_iiwa_free_joint_solutions_are_complete(name, joint, n):
    robot = load_robot(name)
    rng = np.random.default_rng(30 + joint)
    q, T = _poses(robot, n, 40 + joint)
    for qi, Ti in zip(q, T):
        res = analytic_ik(robot, Ti, free={f"q{joint + 1}": qi[joint]})
        _check_solutions(robot, Ti, res.solutions)
        assert _gap(qi[None], res.solutions)[0] < 1e-8
        numeric = _dense(robot, Ti, joint, qi[joint], rng)
        assert len(numeric) and not _missing(robot, joint, numeric, res.solutions).any()


@pytest.mark.slow
def test_iiwa_sweep_intervals_confirmed():
    rng = np.random.default_rng(9)
    for name, joint in (("iiwa7", "q7"),):
        robot = load_robot(name)
        q, T = _poses(robot, 1, 50)
        _sweep_checks(robot, T[0], q[0], free_joint_sweep(robot, T[0], joint, samples=48), rng)


NARROW = [  # iiwa7 poses whose generating q7 lay in no interval the sweep reported before its cross and margin searches
    # the elbow 0.0127 rad from straight: the whole self-motion spans two q7 pieces about 0.04 wide, between two of 32
    # samples (the 1,000-pose run of scripts/ik_free_check.py found 16 such iiwa7 poses at 64 samples)
    ([0.07015093314455312, 1.886897918781949, -2.111599365668808, -0.01271212090831742, -1.116614641778755,
      -0.32116941950986466, 2.0018212303223164], 32),
    # q2 and q6 0.012 and 0.0033 rad from their limits: the limits leave a piece 0.005 wide between two of 64 samples
    ([0.6672306455572419, -2.0825017281070695, 1.6931930925144574, -1.9307710028114171, -1.8541471749700604,
      2.091070322499808, -2.773923471129255], 64),
]


@pytest.mark.slow  # about 3 CPU-s each
@pytest.mark.parametrize("q, samples", NARROW)
def test_iiwa_sweep_finds_a_piece_narrower_than_its_step(q, samples):
    """The piece holding the generating q7 lies strictly between two evenly spaced samples; the sweep reports it
    (cross-wise search over q5, limit margin of the branches without limits), and analytic_ik(free=) confirms
    solutions inside it, the generating configuration among them."""
    robot = load_robot("iiwa7")
    q = np.array(q)
    T = forward_kinematics(robot, q)
    sweep = free_joint_sweep(robot, T, "q7", samples=samples)
    assert sweep.cross == "q5"
    even = np.linspace(*robot.q_limits[6], samples)
    piece = [(a, b) for a, b in sweep.intervals if a - sweep.tol <= q[6] <= b + sweep.tol]
    assert len(piece) == 1
    a, b = piece[0]
    assert not ((even >= a) & (even <= b)).any() and b - a < 0.5 * (even[1] - even[0])  # between two samples
    for t in (a + 0.01 * (b - a), 0.5 * (a + b), b - 0.01 * (b - a)):
        res = analytic_ik(robot, T, free={"q7": t})
        assert res.count >= 1
        _check_solutions(robot, T, res.solutions)
    assert _gap(q[None], analytic_ik(robot, T, free={"q7": q[6]}).solutions)[0] < 1e-8
    for br in sweep.branches:
        _check_solutions(robot, T, br.q)


# --- Kinova Gen3 7-DOF (offset shoulder and elbow, spherical wrist: not S-R-S) ------------------------------------

@pytest.mark.parametrize("joint, n", [(2, 2), (0, 1), (5, 1)])
def test_gen3_free_joint_solutions_are_complete(joint, n):
    """q3 (the default) and q1 held: a Pieper arm, closed form; q6 held: the general 6R route."""
    robot = load_robot("gen3")
    rng = np.random.default_rng(70 + joint)
    q, T = _poses(robot, n, 80 + joint)
    for qi, Ti in zip(q, T):
        res = analytic_ik(robot, Ti, free={f"q{joint + 1}": qi[joint]})
        assert res.method.startswith("general" if joint == 5 else "pieper")
        _check_solutions(robot, Ti, res.solutions)
        assert _gap(qi[None], res.solutions)[0] < 1e-8
        numeric = _dense(robot, Ti, joint, qi[joint], rng)
        assert len(numeric) and not _missing(robot, joint, numeric, res.solutions).any()


@pytest.mark.slow
def test_gen3_sweep_of_a_joint_without_limits_confirmed(capsys):
    """q3 turns without end: swept over [−π, π], the intervals confirmed as for the Panda; the CLI's --sweep."""
    robot = load_robot("gen3")
    assert default_free_joint(robot) == "q3"
    q, T = _poses(robot, 1, 90)
    sweep = free_joint_sweep(robot, T[0], samples=24)
    assert sweep.joint == "q3" and sweep.limits == (-np.pi, np.pi)
    _sweep_checks(robot, T[0], q[0], sweep, np.random.default_rng(91))
    qs = ",".join(f"{v:.17g}" for v in q[0])
    code, out, err = _run(capsys, "ik", "gen3", "--from-q", qs, "--sweep", "--samples", "16", "--json")
    assert code == 0, err
    data = json.loads(out)
    assert data["joint"] == "q3" and any(a <= q[0, 2] <= b for a, b in data["intervals"])


def test_gen3_cli_free(capsys):
    qs = "0.1,0.5,-1,1.2,0.4,0.7,2"
    code, out, err = _run(capsys, "ik", "gen3", "--from-q", qs, "--free", "q3=-1", "--json")
    assert code == 0, err
    sol = np.array(json.loads(out)["solutions"])
    assert np.min(_gap(np.array([[0.1, 0.5, -1, 1.2, 0.4, 0.7, 2]]), sol)) < 1e-9


def _urdf_fk(path, q, drop_offsets):
    """FK of a URDF chain base_link → tool0 written here: each joint's origin (xyz, rpy), then Rot(axis, q)."""
    import xml.etree.ElementTree as ET

    from scipy.spatial.transform import Rotation

    text = path.read_text(encoding="utf-8")
    assert "<!DOCTYPE" not in text and "<!ENTITY" not in text  # a plain file: no entities to expand
    joints = {j.find("parent").get("link"): j for j in ET.fromstring(text).iter("joint")
              if j.find("child").get("link") != "base"}  # base_link → base: a side branch (ROS's "base" frame)
    T, k, link = np.eye(4), 0, "base_link"
    while link != "tool0":
        j = joints[link]
        o = j.find("origin")
        xyz = np.array(o.get("xyz").split(), float)
        if drop_offsets:
            xyz[0] = 0.0
        A = np.eye(4)
        A[:3, :3], A[:3, 3] = Rotation.from_euler("xyz", np.array(o.get("rpy").split(), float)).as_matrix(), xyz
        T = T @ A
        if j.get("type") == "revolute":
            R = np.eye(4)
            R[:3, :3] = Rotation.from_rotvec(np.array(j.find("axis").get("xyz").split(), float) * q[k]).as_matrix()
            T, k = T @ R, k + 1
        link = j.find("child").get("link")
    return T


def test_iiwa14_matches_the_ros_industrial_urdf():
    from pathlib import Path

    rtbdata = pytest.importorskip("rtbdata")
    path = Path(rtbdata.__file__).parent / "xacro/kuka_description/kuka_lbr_iiwa/urdf/lbr_iiwa_14_r820.urdf"
    if not path.is_file():
        pytest.skip("rtbdata ships no lbr_iiwa_14_r820.urdf")
    robot = load_robot("iiwa14")
    q, F = _poses(robot, 20, 60)
    exact = np.array([_urdf_fk(path, qi, True) for qi in q])
    assert np.abs(F - exact).max() < 1e-12
    shifted = np.array([_urdf_fk(path, qi, False) for qi in q])
    assert np.abs(F[:, :3, :3] - shifted[:, :3, :3]).max() < 1e-12
    assert np.linalg.norm(F[:, :3, 3] - shifted[:, :3, 3], axis=-1).max() < 0.9e-3  # two ±0.436 mm offsets
    import xml.etree.ElementTree as ET

    lim = [(float(j.find("limit").get("lower")), float(j.find("limit").get("upper")))
           for j in ET.fromstring(path.read_text(encoding="utf-8")).iter("joint") if j.get("type") == "revolute"]
    assert np.abs(np.array(lim) - robot.q_limits).max() < 1e-3
