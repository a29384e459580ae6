"""The direct closed forms of analytic IK (elbow and Stanford Pieper arms) against the general resultant route.

The general route (``_plan(robot, closed_form=False)``: eigenvalues of the resultant's companion matrix, then
Gauss–Newton polish) shares no position code with the closed forms, so equal solution sets — counts, joint
values, branch labels, continuum names — on random, near-singular, singular and boundary poses are an
independent check of the fast path.  Singular poses are located with the Jacobian (det J = 0 by bisection),
not with the IK code.  Every solution is also re-checked here by FK.
"""

from __future__ import annotations

import re

import numpy as np
import pytest

from denavit import (DHLink, DHRobot, forward_kinematics, geometric_jacobian, link_transforms, load_robot,
                     solve_ik)
from denavit.numeric import transform_from_xyz_rpy
from denavit.ik._analytic import _plan, _solve
from denavit.ik._closed import wrist_angles
from denavit.ik._subproblems import rotation3

from conftest import REDUCED, random_q_in_limits as _random_q
N = 60 if REDUCED else 200
ARMS = {"puma560": "elbow", "puma560-mdh": "elbow", "report003-6r": "elbow", "report001-6r": "elbow",
        "stanford": "stanford"}
MATCH = 1e-6  # joint-space distance [rad, m] under which two solutions are the same (the de-duplication tol)


def _routes(robot, T):
    return _solve(robot, T, _plan(robot, True)), _solve(robot, T, _plan(robot, False))


def _dist(robot, a, b):
    rev = np.array([t.value == "revolute" for t in robot.joint_types])
    d = a - b
    return np.max(np.where(rev, np.abs((d + np.pi) % (2 * np.pi) - np.pi), np.abs(d)), axis=-1)


def _fk_gap(robot, q, T):
    F = forward_kinematics(robot, q)
    R = np.swapaxes(F[..., :3, :3], -1, -2) @ T[..., :3, :3]
    v = np.stack([R[..., 2, 1] - R[..., 1, 2], R[..., 0, 2] - R[..., 2, 0], R[..., 1, 0] - R[..., 0, 1]], -1)
    ang = np.arctan2(np.linalg.norm(v, axis=-1) / 2, (np.trace(R, axis1=-2, axis2=-1) - 1) / 2)
    return np.linalg.norm(F[..., :3, 3] - T[..., :3, 3], axis=-1), ang


def _sigma_min(robot, q):
    return np.linalg.svd(geometric_jacobian(robot, q), compute_uv=False)[..., -1]


def _compare(robot, fast, gen, T, regular, labels=True):
    """Every solution of the general route is one of the fast path; every fast solution reproduces T to 1e-10.

    "One of": within MATCH, or — near a singularity, where a joint-space neighbourhood of size ~ r/σ_min
    reproduces T to a residual r — within 10 r/σ_min of the general solution's own FK residual r (the general
    route keeps roots whose residual is below 1e-9, so its solutions there are less accurate; bound 0.1).
    At regular poses (``regular``: σ_min > 1e-2 at the generating q) the match is one-to-one with equal counts,
    continuum names and branch labels.  Returns the poses where the fast path has more solutions (the
    resultant's roots lose digits near singular poses and are dropped by the general route)."""
    L = sum(abs(l.a) + abs(l.d) for l in robot.links)
    for i in range(len(T)):
        A, B = fast.solutions[i][fast.valid[i]], gen.solutions[i][gen.valid[i]]
        if len(A):
            dp, dw = _fk_gap(robot, A, np.broadcast_to(T[i], A.shape[:1] + (4, 4)))
            assert dp.max() < 1e-10 * max(L, 1) and dw.max() < 1e-10, (i, dp, dw)
        if len(B) == 0:
            continue
        r = gen.position_error[i][gen.valid[i]] + L * gen.orientation_error[i][gen.valid[i]]
        tol = np.clip(10 * r / np.maximum(_sigma_min(robot, B), 1e-300), MATCH, 0.1)
        D = _dist(robot, B[:, None], A[None])  # (kB, kA)
        near = D.min(axis=1) < tol
        freeA = fast.free[i][fast.valid[i]]
        for j in np.flatnonzero(~near):  # at a continuum: a fast representative with the same fixed joints
            near[j] = any(f and _dist(robot, B[j] * _kept(f), A[m] * _kept(f)) < 1e-6 for m, f in enumerate(freeA))
        assert np.all(near), (i, D.min(axis=1), tol, freeA)
        if not regular[i]:
            continue
        partner = D.argmin(axis=1)
        assert len(set(partner)) == len(B) == len(A)  # one-to-one
        fb, fa = gen.free[i][gen.valid[i]], fast.free[i][fast.valid[i]][partner]
        assert list(fa) == list(fb), (i, fa, fb)
        if labels:
            assert list(fast.branches[i][fast.valid[i]][partner]) == list(gen.branches[i][gen.valid[i]])
    more = fast.valid.sum(-1) - gen.valid.sum(-1)
    assert np.all(fast.outside_limits[regular] == gen.outside_limits[regular])
    return np.flatnonzero(more > 0)


def _kept(free):
    """0/1 mask of the joints a continuum leaves fixed: ``qk free`` frees joint k and the wrist that follows it,
    ``qa ± qb fixed`` frees the two joints (only their sum or difference is fixed)."""
    keep = np.ones(6)
    for part in free.split("; "):
        m = re.match(r"q(\d) free", part)
        if m:
            keep[[int(m.group(1)) - 1, 3, 4, 5]] = 0
        m = re.match(r"q(\d) [+-] q(\d) fixed", part)
        if m:
            keep[[int(m.group(1)) - 1, int(m.group(2)) - 1]] = 0
    return keep


def _numeric_subset(robot, T, fast_solutions, seeds=200, seed=0):
    """Every distinct solution a many-seed numeric search finds (within the limits) is among the fast ones, to
    the accuracy its own residual r allows at the local σ_min (10 r/σ_min, at least 1e-6, at most 0.1).
    Returns how many seeds converged."""
    rng = np.random.default_rng(seed)
    num = solve_ik(robot, np.broadcast_to(T, (seeds, 4, 4)), _random_q(robot, rng, seeds), restarts=0, rng=rng,
                   max_iterations=300)
    found = num.q[num.success]
    if len(found) == 0:  # LM may not reach 1e-9 at all right at a singularity: no evidence either way
        return 0
    L = sum(abs(l.a) + abs(l.d) for l in robot.links)
    r = num.position_error[num.success] + L * num.orientation_error[num.success]
    tol = np.clip(10 * r / np.maximum(_sigma_min(robot, found), 1e-300), MATCH, 0.1)
    assert np.all(np.min(_dist(robot, found[:, None], fast_solutions[None]), axis=1) < tol)
    return len(found)


@pytest.mark.parametrize("name", sorted(ARMS))
def test_catalogue_arm_takes_the_closed_form(name):
    plan = _plan(load_robot(name), True)
    assert plan.kind == "pieper" and plan.route == f"closed form ({ARMS[name]})"
    assert _plan(load_robot(name), False).route == "resultant"


@pytest.mark.parametrize("name", sorted(ARMS))
def test_random_poses_same_solutions_as_general_route(name):
    robot = load_robot(name)
    rng = np.random.default_rng(101)
    q = _random_q(robot, rng, N)
    T = forward_kinematics(robot, q)
    fast, gen = _routes(robot, T)
    more = _compare(robot, fast, gen, T, _sigma_min(robot, q) > 1e-2)
    assert len(more) <= max(N // 50, 1), more  # the general route drops roots only at rare near-singular poses
    for i in more[:2]:
        assert _numeric_subset(robot, T[i], fast.solutions[i][fast.valid[i]]) > 0
    # and the generating configuration is found by the fast path, at every pose
    d = np.min(np.where(fast.valid, _dist(robot, fast.solutions, q[:, None]), np.inf), axis=1)
    assert np.all(d < 1e-8)


def _det(robot, q):
    return np.linalg.det(geometric_jacobian(robot, q))


def _singular_configs(robot, rng, k, count):
    """Configurations with det J = 0 reached by moving joint k (sign change over a scan, then bisection)."""
    lim = robot.q_limits[k]
    lo, hi = (lim if np.all(np.isfinite(lim)) else (-np.pi, np.pi))
    grid = np.linspace(lo, hi, 97)
    out = []
    while len(out) < count:
        q = _random_q(robot, rng, 1)[0]
        Q = np.repeat(q[None], len(grid), 0)
        Q[:, k] = grid
        f = _det(robot, Q)
        for j in np.flatnonzero(np.sign(f[:-1]) != np.sign(f[1:]))[:2]:
            a, b, fa = grid[j], grid[j + 1], f[j]
            for _ in range(60):
                m = 0.5 * (a + b)
                qm = q.copy()
                qm[k] = m
                fm = _det(robot, qm)
                a, b, fa = (a, m, fa) if np.sign(fm) != np.sign(fa) else (m, b, fm)
            qs = q.copy()
            qs[k] = 0.5 * (a + b)
            out.append(qs)
    return np.array(out[:count])


@pytest.mark.parametrize("name", sorted(ARMS))
def test_singular_and_near_singular_poses_same_solutions(name):
    """Arm singularities (elbow stretched, wrist centre over the shoulder; Stanford: reach along axis 1), found
    by bisection on det J, and poses 1e-7, 1e-5, 1e-3 away; wrist singularities q5 = −θ5 and nearby."""
    robot = load_robot(name)
    rng = np.random.default_rng(7)
    k = 1 if robot.joint_types[2].value == "prismatic" else 2
    qs = _singular_configs(robot, rng, k, 4 if REDUCED else 8)
    for d in (0.0, 1e-7, 1e-5, 1e-3):
        Q = qs + d * np.eye(6)[k]
        T = forward_kinematics(robot, Q)
        fast, gen = _routes(robot, T)
        more = _compare(robot, fast, gen, T, _sigma_min(robot, Q) > 1e-2, labels=False)  # labels: signs of ~0
        assert np.all(fast.count >= 1)
        for i in more[:1]:
            _numeric_subset(robot, T[i], fast.solutions[i][fast.valid[i]])
    th5 = robot.joints[4].theta
    qw = _random_q(robot, rng, 6)
    for d in (1e-7, 1e-4):
        Q = np.column_stack([qw[:, :4], np.full(6, -th5 + d), qw[:, 5]])
        T = forward_kinematics(robot, Q)
        _compare(robot, *_routes(robot, T), T, _sigma_min(robot, Q) > 1e-2, labels=False)


@pytest.mark.parametrize("name", sorted(ARMS))
def test_wrist_singular_poses_same_arm_solutions(name):
    """q5 = −θ5 exactly (axes 4 and 6 aligned): only q4 ± q6 is determined, and whether a candidate is flagged
    as the continuum depends on the last bit of M_zz, so the routes may pick different representatives.  The
    arm parts (q1, q2, q3) must agree as sets, every returned solution must reproduce T, and the generating
    configuration's arm part must be among them."""
    robot = load_robot(name)
    rng = np.random.default_rng(12)
    qw = _random_q(robot, rng, 12)
    qw[:, 4] = -robot.joints[4].theta
    T = forward_kinematics(robot, qw)
    fast, gen = _routes(robot, T)
    for i in range(len(T)):
        A = fast.solutions[i][fast.valid[i]]
        dp, dw = _fk_gap(robot, A, np.broadcast_to(T[i], A.shape[:1] + (4, 4)))
        assert dp.max() < 1e-9 and dw.max() < 1e-9
    arm = np.array([1, 1, 1, 0, 0, 0])  # compare q1, q2, q3 only
    for i in range(len(T)):
        A, B = fast.solutions[i][fast.valid[i]] * arm, gen.solutions[i][gen.valid[i]] * arm
        DA = _dist(robot, A[:, None], B[None])
        assert DA.min(axis=1).max() < 1e-4 and DA.min(axis=0).max() < 1e-4
        assert _dist(robot, A, qw[i] * arm).min() < 1e-6


def _shoulder_singular_report003(q1, q3, q4, q5, q6):
    """report003-6r with the wrist centre (origin of frame 4) on axis 1: q2 by bisection on its x coordinate."""
    robot = load_robot("report003-6r")

    def x(q2):
        F = link_transforms(robot, [0.0, q2, q3, 0, 0, 0])
        return F[4, 0, 3]

    a, b = -np.pi / 2, np.pi / 2
    grid = np.linspace(a, b, 61)
    vals = np.array([x(g) for g in grid])
    j = np.flatnonzero(np.sign(vals[:-1]) != np.sign(vals[1:]))[0]
    a, b = grid[j], grid[j + 1]
    for _ in range(80):
        m = 0.5 * (a + b)
        a, b = (a, m) if np.sign(x(m)) != np.sign(x(a)) else (m, b)
    return np.array([q1, 0.5 * (a + b), q3, q4, q5, q6])


def test_shoulder_singular_pose_goes_the_general_way_in_a_mixed_batch():
    """Wrist centre on axis 1: q1 is free; that pose is handed to the resultant route (which names the
    continuum), the others of the same batch stay on the closed form — and batch == loop."""
    robot = load_robot("report003-6r")
    rng = np.random.default_rng(3)
    qs = _shoulder_singular_report003(0.4, 0.7, 0.3, 0.9, -0.2)
    assert np.hypot(*link_transforms(robot, qs)[4, :2, 3]) < 1e-12
    Q = np.vstack([_random_q(robot, rng, 3), qs[None], _random_q(robot, rng, 2)])
    T = forward_kinematics(robot, Q)
    fast, gen = _routes(robot, T)
    _compare(robot, fast, gen, T, _sigma_min(robot, Q) > 1e-2)
    free = fast.free[3][fast.valid[3]]
    assert len(free) == 4 and all(f == "q1 free (wrist centre on axis 1; q4, q5, q6 follow)" for f in free)  # 2 elbows × 2 wrists
    np.testing.assert_allclose(fast.solutions[3][fast.valid[3], 0], 0.0, atol=0)  # the representative q1 = 0
    for i in range(len(T)):
        one = _solve(robot, T[i], _plan(robot, True))
        got = fast.solutions[i][fast.valid[i]]
        assert len(got) == one.count
        for s in one.solutions:
            assert np.min(_dist(robot, got, s)) < 1e-12


def _wrist(rng, convention):
    """Spherical wrist rows 4-6 with random twists (any angles, not only ±90°)."""
    if convention == "standard":
        return [DHLink(a=0.0, alpha=rng.uniform(0.3, 2.8), d=rng.uniform(0.2, 0.6), theta=rng.uniform(-3, 3)),
                DHLink(a=0.0, alpha=rng.uniform(0.3, 2.8), d=0.0, theta=rng.uniform(-3, 3)),
                DHLink(a=rng.uniform(-.2, .2), alpha=rng.uniform(-3, 3), d=rng.uniform(-.2, .2))]
    return [DHLink(a=rng.uniform(-.5, .5), alpha=rng.uniform(-3, 3), d=rng.uniform(0.2, 0.6)),
            DHLink(a=0.0, alpha=rng.uniform(0.3, 2.8), d=0.0, theta=rng.uniform(-3, 3)),
            DHLink(a=0.0, alpha=rng.uniform(0.3, 2.8), d=0.0, theta=rng.uniform(-3, 3))]


def _random_arm(rng, convention, kind):
    """Random elbow-type (R R∥R, any shoulder offsets) or Stanford-type (R R P, axes 1, 2 meeting) arm with a
    spherical wrist, random base and tool."""
    u = rng.uniform
    std = convention == "standard"
    if kind == "elbow":  # axes 2 ∥ 3: the twist between them is 0 or π (row 2 standard, row 3 modified)
        par = float(rng.choice([0.0, np.pi]))
        links = [DHLink(a=u(-.3, .3), alpha=u(0.3, 2.8) * rng.choice([-1, 1]), d=u(-.5, .5), theta=u(-3, 3)),
                 DHLink(a=u(.2, .6) if std else u(-.3, .3), alpha=par if std else u(0.3, 2.8), d=u(-.3, .3),
                        theta=u(-3, 3)),
                 DHLink(a=u(-.3, .3) if std else u(.2, .6), alpha=u(-3, 3) if std else par, d=u(-.3, .3),
                        theta=u(-3, 3))]
    else:  # axes 1 and 2 meet: no common normal length between them (a1 standard, a in row 2 modified)
        links = [DHLink(a=0.0 if std else u(-.3, .3), alpha=u(0.3, 2.8), d=u(-.5, .5), theta=u(-3, 3)),
                 DHLink(a=u(-.3, .3) if std else 0.0, alpha=u(0.3, 2.8), d=u(-.3, .3), theta=u(-3, 3)),
                 DHLink(a=u(-.3, .3), alpha=u(-3, 3), d=u(-.2, .2), theta=u(-3, 3), joint="prismatic",
                        q_limits=(0.1, 1.2))]
    tool = transform_from_xyz_rpy(u(-.2, .2, 3), u(-3, 3, 3))
    base = transform_from_xyz_rpy(u(-.2, .2, 3), u(-3, 3, 3))
    return DHRobot(f"random-{kind}", tuple(links + _wrist(rng, convention)), convention=convention, base=base,
                   tool=tool)


@pytest.mark.parametrize("kind", ["elbow", "stanford"])
@pytest.mark.parametrize("convention", ["standard", "modified"])
def test_random_arms_same_solutions_as_general_route(kind, convention):
    rng = np.random.default_rng({"elbow": 31, "stanford": 32}[kind] + (convention == "modified"))
    for _ in range(3 if REDUCED else 8):
        robot = _random_arm(rng, convention, kind)
        assert _plan(robot, True).route == f"closed form ({kind})"
        q = _random_q(robot, rng, 40)
        T = forward_kinematics(robot, q)
        fast, gen = _routes(robot, T)
        more = _compare(robot, fast, gen, T, _sigma_min(robot, q) > 1e-2)
        assert len(more) <= 2, more
        d = np.min(np.where(fast.valid, _dist(robot, fast.solutions, q[:, None]), np.inf), axis=1)
        assert np.all(d < 1e-8)
        assert fast.valid.shape[-1] <= 8 and np.all(fast.count <= 8)


def test_random_elbow_arm_near_singular_poses():
    rng = np.random.default_rng(44)
    for convention in ("standard", "modified"):
        robot = _random_arm(rng, convention, "elbow")
        qs = _singular_configs(robot, rng, 2, 3)
        for d in (0.0, 1e-7, 1e-4):
            T = forward_kinematics(robot, qs + d * np.eye(6)[2])
            fast, gen = _routes(robot, T)
            _compare(robot, fast, gen, T, np.zeros(len(T), bool), labels=False)
            assert np.all(fast.count >= 1)


def test_wrist_angles_equal_rotation3_and_reproduce_M():
    rng = np.random.default_rng(8)
    for _ in range(5):
        Ra = transform_from_xyz_rpy([0, 0, 0], rng.uniform(-3, 3, 3))[:3, :3]
        Rb = transform_from_xyz_rpy([0, 0, 0], rng.uniform(-3, 3, 3))[:3, :3]
        t = rng.uniform(-3, 3, (50, 3))
        Rz = lambda a: np.stack([np.stack([np.cos(a), -np.sin(a), 0 * a], -1),  # noqa: E731
                                 np.stack([np.sin(a), np.cos(a), 0 * a], -1),
                                 np.stack([0 * a, 0 * a, 1 + 0 * a], -1)], -2)
        M = Rz(t[:, 0]) @ Ra @ Rz(t[:, 1]) @ Rb @ Rz(t[:, 2])
        q, sing, sign = wrist_angles(M, Ra, Rb)
        q0, sing0, sign0 = rotation3(M, Ra, Rb)
        d = np.abs(q - q0)  # the same angles, modulo 2π (wrist_angles takes qa with one atan2: within (−π, π])
        np.testing.assert_array_equal(np.isnan(q), np.isnan(q0))
        assert np.all(np.abs(d - 2 * np.pi * np.round(d / (2 * np.pi)))[np.isfinite(d)] < 1e-12)
        np.testing.assert_array_equal(sing, sing0)
        np.testing.assert_array_equal(sign, sign0)
        ok = np.isfinite(q).all(-1)
        assert ok[:, 0].all()  # M is reachable: at least one root
        R = Rz(q[..., 0]) @ Ra @ Rz(q[..., 1]) @ Rb @ Rz(q[..., 2])
        np.testing.assert_allclose(R[ok], np.broadcast_to(M[:, None], R.shape)[ok], atol=1e-12)


def test_mirrored_arm_uses_the_closed_form_of_its_reversed_chain():
    """Spherical joint at the base (axes 1-3 meeting) and an elbow at the tip (axes 4 ∥ 5): the plan solves the
    reversed chain, whose joints 1-3 are an elbow, by the direct closed form."""
    rng = np.random.default_rng(77)
    u = rng.uniform
    for _ in range(3):
        links = [DHLink(a=0.0, alpha=0.0, d=u(.2, .5), theta=u(-3, 3)),
                 DHLink(a=0.0, alpha=u(0.3, 2.8), d=0.0, theta=u(-3, 3)),
                 DHLink(a=0.0, alpha=u(0.3, 2.8), d=0.0, theta=u(-3, 3)),
                 DHLink(a=u(-.3, .3), alpha=u(0.3, 2.8), d=u(.2, .4), theta=u(-3, 3)),
                 DHLink(a=u(.2, .5), alpha=float(rng.choice([0.0, np.pi])), d=u(-.2, .2), theta=u(-3, 3)),
                 DHLink(a=u(.1, .4), alpha=u(0.3, 2.8), d=u(-.2, .2), theta=u(-3, 3))]
        robot = DHRobot("mirrored-elbow", tuple(links), convention="modified",
                        tool=transform_from_xyz_rpy(u(-.2, .2, 3), u(-3, 3, 3)))
        plan = _plan(robot, True)
        assert plan.kind.startswith("pieper (mirrored") and plan.route == "closed form (elbow)"
        q = rng.uniform(-np.pi, np.pi, (40, 6))
        T = forward_kinematics(robot, q)
        fast, gen = _routes(robot, T)
        more = _compare(robot, fast, gen, T, _sigma_min(robot, q) > 1e-2)
        assert len(more) <= 2
        d = np.min(np.where(fast.valid, _dist(robot, fast.solutions, q[:, None]), np.inf), axis=1)
        assert np.all(d < 1e-8)
