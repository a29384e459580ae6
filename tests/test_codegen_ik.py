"""Compiled analytic IK of the UR class (``denavit.compile(robot).analytic_ik``) against the plain solver.

The peer is :func:`denavit.analytic_ik` (numpy, batched; its closed forms are tested against FK, the general 6R
eigenvalue solver and peers in test_ik_*.py).  Oracles here: the same solution sets (order-insensitive, 1e-10), the
same labels and continuum texts, the same outside-limits sets, and FK(IK(T)) = T by the plain forward kinematics.
Singular poses (wrist singular, shoulder singular, elbow stretched or folded) are found from the joint axes alone
(no formula of the solver): the compiled path must hand them to the plain solver and agree with it.  That the
compiled kernel answers the regular poses itself is checked by counting the hand-overs.
"""

from __future__ import annotations

import contextlib
import os

import numpy as np
import pytest
from conftest import REDUCED
from hypothesis import example, given, settings
from hypothesis import strategies as st

import denavit
from denavit import Convention, DHLink, DHRobot
from denavit.numeric import joint_axes, link_transforms, transform_from_xyz_rpy

pytest.importorskip("numba")

from denavit.codegen import _solvers  # noqa: E402  (the hand-over to the plain solver is counted there)
from denavit.ik import ik_plan  # noqa: E402

N_POSES = 60 if REDUCED else 250


@pytest.fixture(scope="module", autouse=True)
def _kernel_cache(tmp_path_factory):
    """One kernel folder for the run, shared by pytest-xdist's workers (as test_codegen's): each arm compiles once."""
    base = tmp_path_factory.getbasetemp()
    if os.environ.get("PYTEST_XDIST_WORKER"):
        base = base.parent
    with pytest.MonkeyPatch.context() as mp:
        mp.setenv("DENAVIT_CACHE_DIR", str(base / "kernels"))
        yield


def _ur(name: str, d1: float, a2: float, a3: float, d4: float, d5: float, d6: float) -> DHRobot:
    """A UR arm from Universal Robots' published standard DH table (support article 45257, "Parameters for
    calculations of kinematics and dynamics"): alpha = (pi/2, 0, 0, pi/2, -pi/2, 0), joint range +-360 deg."""
    rows = [(0.0, np.pi / 2, d1), (a2, 0.0, 0.0), (a3, 0.0, 0.0), (0.0, np.pi / 2, d4), (0.0, -np.pi / 2, d5),
            (0.0, 0.0, d6)]
    return DHRobot(name=name, links=tuple(DHLink(a=a, alpha=al, d=d, q_limits=(-2 * np.pi, 2 * np.pi))
                                          for a, al, d in rows), convention=Convention.STANDARD)


ARMS = {"ur5": lambda: denavit.load_robot("ur5"),
        "ur10": lambda: _ur("ur10", 0.1273, -0.612, -0.5723, 0.163941, 0.1157, 0.0922),
        "ur3e": lambda: _ur("ur3e", 0.15185, -0.24355, -0.2132, 0.13105, 0.08535, 0.0921),
        "stanford": lambda: denavit.load_robot("stanford")}


@pytest.fixture(scope="module", params=sorted(ARMS))
def arm(request, _kernel_cache):
    robot = ARMS[request.param]()
    return robot, denavit.compile(robot, kernels=["fk", "fk_jacobian0"])


# --- comparison -------------------------------------------------------------------------------------------------


def _match(A: np.ndarray, B: np.ndarray, tol) -> list[int]:
    """Index in B of each row of A (one to one), within tol (a number, or one per row of A); fails if some row has
    no partner."""
    assert A.shape == B.shape, (A, B)
    tol = np.broadcast_to(tol, (len(A),))
    free = list(range(len(B)))
    out = []
    for row, t in zip(A, tol):
        d = [np.max(np.abs(row - B[k])) for k in free]
        assert d and min(d) < t, (row, B, t)
        out.append(free.pop(int(np.argmin(d))))
    return out


#: joint-space agreement asked of the two solvers at a well-conditioned solution
TOL = 1e-10


def _tolerance(robot, Q: np.ndarray) -> np.ndarray:
    """TOL per solution, widened by the Jacobian's condition number there (position rows divided by the arm's
    length): a pose both solvers reproduce to unit roundoff fixes q only to about eps * sigma_max / sigma_min along
    the Jacobian's weakest direction, so near a singular set two exact answers differ that much (seed 340: sigma
    ratio 5.6e5, the two answers 1.07e-10 apart, each reproducing T to 1e-15)."""
    if len(Q) == 0:
        return np.zeros(0)
    L = max(1.0, sum(abs(l.a) + abs(l.d) for l in robot.links))
    J = denavit.geometric_jacobian(robot, Q)  # (k, 6, n)
    s = np.linalg.svd(J * np.array([1 / L] * 3 + [1.0] * 3)[:, None], compute_uv=False)  # (k, 6)
    return TOL + 16 * np.finfo(float).eps * s[:, 0] / np.maximum(s[:, -1], 1e-300)


def _same(robot, T, a, b):
    """a (compiled) and b (plain) give the same answer for T (to TOL, widened by the conditioning); every solution
    reproduces T by the plain FK."""
    assert (a.method, a.controlled) == (b.method, b.controlled)
    A = np.asarray(a.solutions)
    idx = _match(A, np.asarray(b.solutions), _tolerance(robot, A))
    assert [a.branches[k] for k in range(len(idx))] == [b.branches[j] for j in idx]
    assert [a.free[k] for k in range(len(idx))] == [b.free[j] for j in idx]
    np.testing.assert_allclose(a.position_error, np.asarray(b.position_error)[idx], atol=1e-12)
    np.testing.assert_allclose(a.orientation_error, np.asarray(b.orientation_error)[idx], atol=1e-12)
    O = np.asarray(a.outside_limits)
    _match(O, np.asarray(b.outside_limits), _tolerance(robot, O))
    if len(a.solutions):
        F = denavit.forward_kinematics(robot, np.asarray(a.solutions))
        L = max(1.0, sum(abs(l.a) + abs(l.d) for l in robot.links))
        assert np.all(np.abs(F[:, :3, 3] - T[:3, 3]).max(axis=-1) < 1e-9 * L)
        assert np.all(np.abs(F[:, :3, :3] - T[:3, :3]).max(axis=(-1, -2)) < 1e-9)


def _same_batch(robot, a, b):
    """Batched results a (compiled) and b (plain) in the same layout: the same slots filled (valid, NaN rows),
    labels, continuum texts and outside-limits counts; the filled rows equal to the conditioning-scaled tolerance
    of _tolerance."""
    np.testing.assert_array_equal(a.valid, b.valid)
    np.testing.assert_array_equal(np.isnan(a.solutions), np.isnan(b.solutions))
    np.testing.assert_array_equal(np.asarray(a.branches, dtype=object), np.asarray(b.branches, dtype=object))
    np.testing.assert_array_equal(np.asarray(a.free, dtype=object), np.asarray(b.free, dtype=object))
    np.testing.assert_array_equal(a.outside_limits, b.outside_limits)
    assert (a.method, a.controlled) == (b.method, b.controlled)
    A, Bs = a.solutions[a.valid], b.solutions[b.valid]  # (m, n), filled rows in the same order
    assert np.all(np.abs(A - Bs).max(axis=-1, initial=0.0) < _tolerance(robot, A))
    np.testing.assert_allclose(a.position_error[a.valid], b.position_error[b.valid], atol=1e-12)


@contextlib.contextmanager
def _handovers():
    """Calls of the plain solver made by the compiled analytic_ik (its status-1 path), counted in the list yielded."""
    calls = []

    def counted(robot, T, *args, **kwargs):
        calls.append(1)
        return denavit.analytic_ik(robot, T, *args, **kwargs)

    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(_solvers, "analytic_ik", counted)
        yield calls


# --- singular configurations, from the joint axes alone ------------------------------------------------------------


def _axes(robot, q):
    z, o = joint_axes(robot, link_transforms(robot, q))
    return z, o


def _meet(z, o, i, j):
    """The point nearest to axes i and j (their intersection when they meet)."""
    A = np.stack([z[i], -z[j]], axis=1)
    s = np.linalg.lstsq(A, o[j] - o[i], rcond=None)[0]
    return 0.5 * (o[i] + s[0] * z[i] + o[j] + s[1] * z[j])


def _shoulder(robot, q):
    """Signed distance of the wrist point Q (axes 5, 6) from the plane of axis 1 and the direction of axis 2:
    zero where the two shoulder solutions meet."""
    z, o = _axes(robot, q)
    n = np.cross(z[0], z[1])
    return (_meet(z, o, 4, 5) - o[0]) @ n / max(np.linalg.norm(n), 1e-300)


def _elbow(robot, q):
    """Zero where the parallel axes 2, 3, 4 lie in one plane (elbow stretched or folded)."""
    z, o = _axes(robot, q)
    return np.cross(o[2] - o[1], o[3] - o[1]) @ z[1]


def _wrist_coplanar(robot, q):
    """Triple product of axes 4, 5, 6: zero where they lie in one plane (axes 4 and 6 aligned among those)."""
    z, _ = _axes(robot, q)
    return np.cross(z[3], z[4]) @ z[5]


def _stanford_reach(robot, q):
    """(W - O) . z3, W the wrist centre (axes 4, 5), O the point of axes 1 and 2: zero where |W - O| is least
    along the prismatic joint 3 (its two roots meet)."""
    z, o = _axes(robot, q)
    return (_meet(z, o, 3, 4) - _meet(z, o, 0, 1)) @ z[2]


def _stanford_height(robot, q):
    """(W - O) . (z1 x z2): zero where the wrist centre lies in the plane of axes 1 and 2 (the two q2 meet)."""
    z, o = _axes(robot, q)
    n = np.cross(z[0], z[1])
    return (_meet(z, o, 3, 4) - _meet(z, o, 0, 1)) @ n / max(np.linalg.norm(n), 1e-300)


UR_SINGULAR = ((_shoulder, 1), (_elbow, 2), (_wrist_coplanar, 4))  # for UR arms axes 4, 5, 6 coplanar = axis 6 ∥ 4
STANFORD_SINGULAR = ((_stanford_reach, 2), (_stanford_height, 1), (_wrist_coplanar, 4))


def _root(fun, robot, q, k, rng):
    """q with joint k moved onto a sign change of fun (bisection to 1e-15), or None when there is none."""
    grid = q[k] + np.linspace(-np.pi, np.pi, 25)
    vals = []
    for x in grid:
        qq = q.copy()
        qq[k] = x
        vals.append(fun(robot, qq))
    flips = [i for i in range(24) if np.sign(vals[i]) != np.sign(vals[i + 1])]
    if not flips:
        return None
    i = flips[int(rng.integers(len(flips)))]
    lo, hi, flo = grid[i], grid[i + 1], vals[i]
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        qq = q.copy()
        qq[k] = mid
        fm = fun(robot, qq)
        if np.sign(fm) == np.sign(flo):
            lo, flo = mid, fm
        else:
            hi = mid
    qq = q.copy()
    qq[k] = 0.5 * (lo + hi)
    return qq


def _singular_set(robot, rng, count: int, funs, wrist: bool = False) -> np.ndarray:
    """Configurations on the singular sets where each of ``funs`` ((function, joint moved)) vanishes (and, for UR
    arms, the wrist singularity q5 = 0, pi), each also moved off by 1e-9 .. 1e-2 (where the solver's thresholds
    lie), and rounded to one decimal; returns them and how many lie on a singular set."""
    lim = np.clip(robot.q_limits, -np.pi, np.pi)
    out = []
    for m in range(count):
        q = rng.uniform(lim[:, 0], lim[:, 1])
        fun, k = funs[m % len(funs)]
        found = _root(fun, robot, q, k, rng)
        if found is not None:
            out.append(found)
    if wrist:
        for m in range(count // 2):
            q = rng.uniform(lim[:, 0], lim[:, 1])
            q[4] = np.pi * (m % 2)
            out.append(q)
    base = np.array(out).reshape(-1, robot.dof)
    moved = [base + 10.0 ** -e * rng.choice([-1.0, 1.0], base.shape) for e in (9, 6, 4, 2)]
    return np.concatenate([base, *moved, np.round(base, 1)]), len(base)


#: the singular sets of each catalogue arm (functions, joint moved) and whether to add q5 = 0, pi (UR wrist)
SINGULAR = {"ur5": (UR_SINGULAR, True), "ur10": (UR_SINGULAR, True), "ur3e": (UR_SINGULAR, True),
            "stanford": (STANFORD_SINGULAR, False)}


def _check_arm(robot, fast, rng, n_poses, n_singular, funs, wrist=False, handed_over=0.05):
    lim = np.clip(robot.q_limits, -2 * np.pi, 2 * np.pi)
    Q = rng.uniform(lim[:, 0], lim[:, 1], (n_poses, robot.dof))
    with _handovers() as calls:
        for q in Q:
            T = denavit.forward_kinematics(robot, q)
            res = fast.analytic_ik(T)
            _same(robot, T, res, denavit.analytic_ik(robot, T))
            assert res.count >= 1  # q itself is a solution, inside the limits
        assert len(calls) <= handed_over * n_poses  # the compiled kernel answers the regular poses itself
        singular, exact = _singular_set(robot, rng, n_singular, funs, wrist)
        for q in singular:
            T = denavit.forward_kinematics(robot, q)
            _same(robot, T, fast.analytic_ik(T), denavit.analytic_ik(robot, T))
        assert exact == 0 or len(calls) > 0  # those on a singularity reach the plain solver


# --- tests --------------------------------------------------------------------------------------------------------


@pytest.mark.slow
def test_catalogue_arms_compiled_equals_plain(arm):
    """UR5, UR10, UR3e, Stanford: every solution, label and outside-limits solution of the plain solver, random and
    singular poses; batches and unreachable poses too."""
    robot, fast = arm
    plan = ik_plan(robot)
    assert plan.closed is not None and (plan.kind == "parallel" or plan.route == "closed form (stanford)")
    rng = np.random.default_rng(sum(robot.name.encode()))
    _check_arm(robot, fast, rng, N_POSES, 6 if REDUCED else 16, *SINGULAR[robot.name])
    for dist in (2.0, 5.0, 9.0, 1e20, 1e300):  # far and farther (the Stanford arm reaches anything, its slider
        far = np.eye(4)  # out of its limits: the plain solver reports nothing beyond its bound)
        far[:3, 3] = dist * np.array([1.0, 1 / 3, -1 / 7])
        _same(robot, far, fast.analytic_ik(far), denavit.analytic_ik(robot, far))
    batch = denavit.forward_kinematics(robot, rng.uniform(robot.q_limits[:, 0], robot.q_limits[:, 1], (4, 6)))
    _same_batch(robot, fast.analytic_ik(batch), denavit.analytic_ik(robot, batch))


def _random_ur_class(seed: int) -> DHRobot:
    """A random 6R arm with axes 2, 3, 4 parallel and axes 5, 6 meeting (either convention): random lengths,
    offsets, twists of the non-parallel axes, joint offsets, limits, base and tool."""
    rng = np.random.default_rng(seed)
    conv = Convention.MODIFIED if rng.random() < 0.5 else Convention.STANDARD

    def twist():
        return float(rng.choice([-1.0, 1.0]) * rng.uniform(0.3, np.pi - 0.3))

    def length():
        return float(rng.choice([0.0, rng.uniform(-0.8, 0.8)]))

    if conv is Convention.STANDARD:  # row i: z_{i-1} -> z_i; axes 2-4 are z1-z3, axes 5, 6 z4, z5
        rows = [(length(), twist()), (rng.uniform(0.2, 0.8), 0.0), (rng.uniform(0.2, 0.8), 0.0), (length(), twist()),
                (0.0, twist()), (length(), twist())]
    else:  # row i carries a_{i-1}, alpha_{i-1}: z_{i-1} -> z_i; axes 2-4 are z2-z4, axes 5, 6 z5, z6
        rows = [(length(), twist()), (length(), twist()), (rng.uniform(0.2, 0.8), 0.0), (rng.uniform(0.2, 0.8), 0.0),
                (length(), twist()), (0.0, twist())]
    links = []
    for k, (a, alpha) in enumerate(rows):
        lo = float(rng.choice([-2 * np.pi, rng.uniform(-np.pi, 0.0)]))
        # row 5's d kept off 0: with it 0 (and a4 = 0) axes 4, 5, 6 would meet, a spherical wrist (the pieper plan)
        d = float(rng.choice([-1.0, 1.0]) * rng.uniform(0.05, 0.5)) if k == 4 else length()
        links.append(DHLink(a=a, alpha=alpha, d=d, theta=float(rng.uniform(-np.pi, np.pi)),
                            q_limits=(lo, lo + float(rng.uniform(np.pi, 4 * np.pi)))))
    base, tool = np.eye(4), np.eye(4)
    if rng.random() < 0.7:
        base = transform_from_xyz_rpy(rng.uniform(-1, 1, 3), rng.uniform(-np.pi, np.pi, 3))
        tool = transform_from_xyz_rpy(rng.uniform(-0.3, 0.3, 3), rng.uniform(-np.pi, np.pi, 3))
    return DHRobot(name="random-ur", links=tuple(links), convention=conv, base=base, tool=tool)


@pytest.mark.slow
@settings(max_examples=2 if REDUCED else 5)
@given(seed=st.integers(0, 2**32 - 1))
@example(seed=340)  # a pose 3e-6 from a singular set: two exact answers 1.07e-10 apart (see _tolerance)
@example(seed=391)  # a singular pose with q3 = 0 at a limit of −2π: the folding's knife edge (FOLD_EDGE)
def test_random_ur_class_arms_compiled_equals_plain(seed, _kernel_cache):
    """Random UR-class arms (both conventions, offsets, limits, base and tool) x random and singular poses."""
    robot = _random_ur_class(seed)
    plan = ik_plan(robot)
    assert plan.kind == "parallel" and plan.closed is not None
    fast = denavit.compile(robot, kernels=["fk", "fk_jacobian0"])
    # (a random arm may be ill-conditioned over much of its workspace, its wrist centre near axis 1 say: more
    # poses go to the plain solver)
    _check_arm(robot, fast, np.random.default_rng(seed), N_POSES // 2, 6 if REDUCED else 12, UR_SINGULAR,
               handed_over=0.6)


@pytest.mark.slow
@pytest.mark.parametrize("seed", range(3) if REDUCED else range(10))
def test_random_ur_class_batches_equal_plain(seed, _kernel_cache):
    """Random UR-class arms, batches through the staged kernel (its candidates, checks and folds run over chunks of
    poses, every branch at once; codegen/_ik_nb_parallel_stages.py): 45 poses (two chunks and part of a third),
    random ones mixed with singular and rounded ones and one out of reach, in the plain solver's batched layout
    (the same slots, labels, continuum texts and outside-limits counts); every filled row reproduces its target by
    the plain FK."""
    robot = _random_ur_class(1000 + seed)
    fast = denavit.compile(robot, kernels=["fk", "fk_jacobian0"])
    assert fast._analytic_solver()[1][1] == "parallel"  # the UR-class kernel answers
    rng = np.random.default_rng(seed)
    lim = np.clip(robot.q_limits, -2 * np.pi, 2 * np.pi)
    Q = rng.uniform(lim[:, 0], lim[:, 1], (45, robot.dof))
    singular, _ = _singular_set(robot, rng, 3, UR_SINGULAR, wrist=True)
    pick = rng.choice(45, 15, replace=False)
    Q[pick] = singular[rng.choice(len(singular), 15)]
    T = denavit.forward_kinematics(robot, Q)
    T[17, :3, 3] = 50.0 * (1.0 + sum(abs(l.a) + abs(l.d) for l in robot.links))  # beyond every reachable point
    a, b = fast.analytic_ik(T), denavit.analytic_ik(robot, T)
    _same_batch(robot, a, b)
    L = max(1.0, sum(abs(l.a) + abs(l.d) for l in robot.links))
    for k in range(len(T)):
        S = a.solutions[k][a.valid[k]]
        assert k != 17 or len(S) == 0
        if len(S):
            F = denavit.forward_kinematics(robot, S)
            assert np.all(np.abs(F[:, :3, 3] - T[k, :3, 3]).max(axis=-1) < 1e-9 * L)
            assert np.all(np.abs(F[:, :3, :3] - T[k, :3, :3]).max(axis=(-1, -2)) < 1e-9)


@pytest.mark.parametrize("name", ["ur5", "puma560"])  # the UR-class and the elbow kernel
def test_compiled_solutions_come_in_the_plain_order(name, _kernel_cache):
    """One pose at a time, the compiled kernel's solutions (sorted in machine code) come in the plain solver's
    order, row by row, with its labels: random poses and rounded ones (joints on round values, where solutions
    share joint values and the order is decided by a later joint)."""
    robot = denavit.load_robot(name)
    fast = denavit.compile(robot, kernels=["fk", "fk_jacobian0"])
    rng = np.random.default_rng(12)
    lim = np.clip(robot.q_limits, -np.pi, np.pi)
    Q = rng.uniform(lim[:, 0], lim[:, 1], (60, robot.dof))
    Q[::3] = np.round(Q[::3], 1)
    Q[1::6, 0] = 0.0
    found = 0
    for q in Q:
        T = denavit.forward_kinematics(robot, q)
        a, b = fast.analytic_ik(T), denavit.analytic_ik(robot, T)
        A, B = np.asarray(a.solutions), np.asarray(b.solutions)
        assert A.shape == B.shape
        assert np.all(np.abs(A - B).max(axis=-1, initial=0.0) < _tolerance(robot, A))
        assert list(a.branches) == list(b.branches)
        found += len(A)
    assert found >= 2 * len(Q)  # mostly several solutions a pose (a rounded q may leave the limits)


def random_wrist_draws(seed: int):
    """The first draws of a random arm with a spherical wrist: (rng, convention, twist(), length(), t4, t5) —
    half of the wrists with equal outer twists, so that axes 4 and 6 can align."""
    rng = np.random.default_rng(seed)
    conv = Convention.MODIFIED if rng.random() < 0.5 else Convention.STANDARD

    def twist():
        return float(rng.choice([-1.0, 1.0]) * rng.uniform(0.3, np.pi - 0.3))

    def length():
        return float(rng.choice([0.0, rng.uniform(-0.6, 0.6)]))

    t4 = twist()
    t5 = -t4 if rng.random() < 0.5 else twist()
    return rng, conv, twist, length, t4, t5


def random_revolute(rng, a: float, alpha: float, d: float) -> DHLink:
    """A revolute row with a random joint offset and random limits (a full turn and more, or the whole circle)."""
    lo = float(rng.choice([-2 * np.pi, rng.uniform(-np.pi, 0.0)]))
    return DHLink(a=a, alpha=alpha, d=d, theta=float(rng.uniform(-np.pi, np.pi)),
                  q_limits=(lo, lo + float(rng.uniform(np.pi, 4 * np.pi))))


def random_base_tool(rng) -> tuple[np.ndarray, np.ndarray]:
    """Identity base and tool, or (seven times in ten) random ones."""
    base, tool = np.eye(4), np.eye(4)
    if rng.random() < 0.7:
        base = transform_from_xyz_rpy(rng.uniform(-1, 1, 3), rng.uniform(-np.pi, np.pi, 3))
        tool = transform_from_xyz_rpy(rng.uniform(-0.3, 0.3, 3), rng.uniform(-np.pi, np.pi, 3))
    return base, tool


def _random_stanford_class(seed: int) -> DHRobot:
    """A random R R P arm with axes 1, 2 meeting and a spherical wrist (either convention): random offsets, twists
    (half of the wrists with equal outer twists, so that axes 4 and 6 can align), limits, base and tool."""
    rng, conv, twist, length, t4, t5 = random_wrist_draws(seed)
    if conv is Convention.STANDARD:  # (a, alpha, d) of z_{i-1} -> z_i; axes 1, 2 = z0, z1; wrist z3, z4, z5 at o4
        rows = [(0.0, twist(), length()), (length(), twist(), length()), (length(), twist(), 0.0),
                (0.0, t4, length()), (0.0, t5, 0.0), (length(), twist(), length())]
    else:  # (a_{i-1}, alpha_{i-1}, d_i); axes 1, 2 = z1, z2; wrist z4, z5, z6 at o4 = o5
        rows = [(length(), twist(), length()), (0.0, twist(), length()), (length(), twist(), 0.0),
                (length(), twist(), length()), (0.0, t4, 0.0), (0.0, t5, length())]
    links = []
    for k, (a, alpha, d) in enumerate(rows):
        if k == 2:  # the prismatic joint: its travel
            lo = float(rng.uniform(-0.5, 0.5))
            links.append(DHLink(a=a, alpha=alpha, d=d, theta=float(rng.uniform(-np.pi, np.pi)), joint="prismatic",
                                q_limits=(lo, lo + float(rng.uniform(0.3, 1.5)))))
            continue
        links.append(random_revolute(rng, a, alpha, d))
    base, tool = random_base_tool(rng)
    return DHRobot(name="random-stanford", links=tuple(links), convention=conv, base=base, tool=tool)


@pytest.mark.slow
@settings(max_examples=2 if REDUCED else 5)
@given(seed=st.integers(0, 2**32 - 1))
@example(seed=273)  # a pose on the singular set q2 = 0 whose shoulder label sits on its knife edge (LABEL_EDGE)
def test_random_stanford_class_arms_compiled_equals_plain(seed, _kernel_cache):
    """Random Stanford-class arms (both conventions, offsets, limits, base and tool) x random and singular poses."""
    robot = _random_stanford_class(seed)
    plan = ik_plan(robot)
    assert plan.route == "closed form (stanford)" and plan.closed is not None
    fast = denavit.compile(robot, kernels=["fk", "fk_jacobian0"])
    _check_arm(robot, fast, np.random.default_rng(seed), N_POSES // 2, 6 if REDUCED else 12, STANFORD_SINGULAR,
               handed_over=0.6)


def test_kernel_cache_entries_go_when_a_source_they_inline_changes(tmp_path):
    """numba stamps a cached kernel by its own file only, and the kernels inline denavit.ik.forms: fresh_cache drops
    their index files where the stamped digest of their sources is another (here a stale stamp written by hand),
    keeps them where it is the same, and leaves other functions' entries alone."""
    from types import SimpleNamespace

    from denavit.codegen import _ik_jit

    assert {p.name for p in _ik_jit.kernel_sources()} >= {"_forms.py", "_ik_nb_elbow.py", "_ik_nb_finish.py"}
    fake = SimpleNamespace(_cache=SimpleNamespace(_cache_path=str(tmp_path)))
    for name in ("_ik_nb_elbow.ik_elbow-46.py311.nbi", "_ik_nb_finish.ik_finish-58.py311.nbi", "other.f-1.py311.nbi"):
        (tmp_path / name).write_text("index")
    (tmp_path / _ik_jit.STAMP).write_text("stale")
    _ik_jit.fresh_cache(fake, force=True)
    assert sorted(p.name for p in tmp_path.glob("*.nbi")) == ["other.f-1.py311.nbi"]
    digest = (tmp_path / _ik_jit.STAMP).read_text()
    assert len(digest) == 64 and digest != "stale"
    (tmp_path / "_ik_nb_elbow.ik_elbow-46.py311.nbi").write_text("index")  # compiled again from the same sources
    _ik_jit.fresh_cache(fake, force=True)
    assert (tmp_path / "_ik_nb_elbow.ik_elbow-46.py311.nbi").exists()


def test_compiled_result_reads_copies_and_pickles_as_the_plain_one(_kernel_cache):
    """The compiled one-pose result (its arrays made from the kernel's output when first read) holds what the plain
    solver's holds, field by field, and stays so when copied, replaced or pickled; a list, a Fortran-ordered or
    a read-only target gives the same answer, a bad one the plain function's error."""
    import copy
    import dataclasses
    import pickle

    robot = denavit.load_robot("ur5")
    fast = denavit.compile(robot, kernels=["fk", "fk_jacobian0"])
    T = denavit.forward_kinematics(robot, np.array([0.3, -1.1, 1.4, 0.2, 0.9, -0.4]))
    a, b = fast.analytic_ik(T), denavit.analytic_ik(robot, T)
    assert isinstance(a, denavit.AnalyticIKResult) and a.count == b.count == 8
    assert a.solutions is a.solutions and repr(a).startswith("AnalyticIKResult(solutions=array(")
    _same(robot, T, a, b)
    for c in (pickle.loads(pickle.dumps(fast.analytic_ik(T))), copy.copy(fast.analytic_ik(T)),
              dataclasses.replace(fast.analytic_ik(T), method="parallel")):
        _same(robot, T, c, b)
    assert type(pickle.loads(pickle.dumps(a))) is denavit.AnalyticIKResult
    frozen = T.copy()
    frozen.flags.writeable = False
    for other in (T.tolist(), np.asfortranarray(T), frozen):
        _same(robot, T, fast.analytic_ik(other), b)
    bad = T.copy()
    bad[0, 1] += 0.5
    with pytest.raises(denavit.errors.ShapeError, match="orthonormal"):
        fast.analytic_ik(bad)
    bad[0, 1] = np.nan
    with pytest.raises(denavit.errors.ShapeError, match="non-finite"):
        fast.analytic_ik(bad)


def test_compiled_batch_keeps_the_plain_layout(arm):
    """A batch through the compiled kernel's loop comes back in the plain solver's batched layout (slot = rank among
    the verified candidates, NaN rows for duplicates and solutions outside the limits), with singular and rounded
    poses (handed to the plain solver as one sub-batch) among random ones, in a (2, 15) batch."""
    robot, fast = arm
    rng = np.random.default_rng(5)
    lim = np.clip(robot.q_limits, -np.pi, np.pi)
    Q = rng.uniform(lim[:, 0], lim[:, 1], (30, robot.dof))
    singular, _ = _singular_set(robot, rng, 2, *SINGULAR[robot.name])
    Q[:10] = singular[rng.choice(len(singular), 10, replace=False)]
    T = denavit.forward_kinematics(robot, Q).reshape(2, 15, 4, 4)
    with _handovers() as calls:
        a = fast.analytic_ik(T)
    assert len(calls) <= 1  # at most one plain sub-batch
    b = denavit.analytic_ik(robot, T)
    assert a.solutions.shape == b.solutions.shape and a.solutions.shape[:2] == (2, 15)
    _same_batch(robot, a, b)
    assert np.all(a.count.reshape(-1)[10:] >= 1)  # the random poses: q itself is a solution, inside the limits


@pytest.mark.parametrize("name", ["ur5", "puma560"])  # the UR-class and the elbow kernel
def test_batch_over_blocks_equals_pose_by_pose(name, _kernel_cache):
    """The batch entry (the kernel run over blocks of BLOCK poses, codegen/_ik_nb_batch.py) against the one-pose
    path, pose by pose, on a batch spanning two blocks and part of a third: random poses, wrist-singular and rounded
    ones (handed to the plain solver as one sub-batch), one out of reach; each pose's filled slots hold the one-pose
    call's solutions (to the conditioning-scaled tolerance: a handed-over pose is solved batched there, alone
    here) with its labels and outside-limits count; a non-orthonormal target in the last block refuses the batch."""
    from denavit.codegen._ik_nb_batch import BLOCK

    robot = denavit.load_robot(name)
    fast = denavit.compile(robot, kernels=["fk", "fk_jacobian0"])
    rng = np.random.default_rng(11)
    lim = np.clip(robot.q_limits, -np.pi, np.pi)
    Q = rng.uniform(lim[:, 0], lim[:, 1], (2 * BLOCK + 12, robot.dof))
    Q[5::9, 4] = 0.0  # wrist singular: axes 4 and 6 aligned (a continuum: the plain solver answers)
    Q[7::9] = np.round(Q[7::9], 1)
    T = denavit.forward_kinematics(robot, Q)
    T[BLOCK + 3, :3, 3] = (9.0, 0.0, 0.0)  # out of reach: no solution
    with _handovers() as calls:
        a = fast.analytic_ik(T)
    assert len(calls) == 1
    assert a.count[BLOCK + 3] == 0 and np.all(np.delete(a.count, BLOCK + 3) >= 1)  # q itself, inside the limits
    for b in range(len(T)):
        one = fast.analytic_ik(T[b])
        S = np.asarray(one.solutions)
        idx = _match(S, a.solutions[b][a.valid[b]], _tolerance(robot, S))
        assert list(one.branches) == [a.branches[b][a.valid[b]][j] for j in idx]
        assert len(one.outside_limits) == a.outside_limits[b]
    bad = T.copy()
    bad[2 * BLOCK + 1, 0, 1] += 0.5
    with pytest.raises(denavit.errors.ShapeError, match="orthonormal"):
        fast.analytic_ik(bad)
