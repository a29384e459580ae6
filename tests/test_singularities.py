"""Singularities: numeric measures against their definitions, symbolic conditions against the rank of J."""

import math

import numpy as np
import pytest

from denavit import DHLink, DHRobot, JointType, load_robot
from denavit import numeric as N

from test_jacobians import make_robot

from conftest import REDUCED
ROW_NAMES = ("vx", "vy", "vz", "wx", "wy", "wz")


# --- numeric measures ------------------------------------------------------------------------------


def test_measures_against_definitions():
    rng = np.random.default_rng(40)
    for _ in range(100):
        m, n = int(rng.integers(1, 7)), int(rng.integers(1, 8))
        J = rng.normal(size=(m, n))
        s = np.sqrt(np.clip(np.linalg.eigvalsh(J @ J.T if m <= n else J.T @ J), 0, None))[::-1]
        np.testing.assert_allclose(N.singular_values(J), s, atol=1e-10)
        if m <= n:
            np.testing.assert_allclose(N.manipulability(J), np.sqrt(np.linalg.det(J @ J.T)), rtol=1e-8)
        else:
            assert N.manipulability(J) == 0.0
        np.testing.assert_allclose(N.condition_number(J), s[0] / s[-1], rtol=1e-8)
        assert N.jacobian_rank(J) == np.linalg.matrix_rank(J)


def test_rank_and_singularity_of_constructed_matrices():
    rng = np.random.default_rng(41)
    for r in range(0, 6):
        A, B = rng.normal(size=(6, r)), rng.normal(size=(r, 6))
        J = A @ B * 1e3  # rank r, large scale: the threshold is relative
        assert N.jacobian_rank(J) == r
        assert bool(N.is_singular(J)) == (r < 6)
    assert N.condition_number(np.diag([1.0, 0.0])) == np.inf


def test_ellipsoids_from_sampled_joint_velocities_and_forces():
    """Points J q̇ with |q̇| = 1 lie on the velocity ellipsoid; F on the force ellipsoid has |Jᵀ F| = 1."""
    rng = np.random.default_rng(42)
    robot = load_robot("puma560")
    q = rng.uniform(-1, 1, (4, 6))
    J = N.geometric_jacobian(robot, q)[..., :3, :]  # linear rows only (one unit)
    vel, frc = N.velocity_ellipsoid(J), N.force_ellipsoid(J)
    for k in range(4):
        qd = rng.normal(size=(50, 6))
        qd /= np.linalg.norm(qd, axis=1, keepdims=True)
        x = qd @ J[k].T  # (50, 3) inside or on the ellipsoid
        c = x @ vel.axes[k] / vel.radii[k]
        assert np.all(np.sum(c ** 2, axis=1) <= 1 + 1e-9)
        # the pre-image of a surface point: q̇ = J⁺ x has unit norm
        u = rng.normal(size=(50, 3))
        u /= np.linalg.norm(u, axis=1, keepdims=True)
        surf = (u * vel.radii[k]) @ vel.axes[k].T
        np.testing.assert_allclose(np.linalg.norm(surf @ np.linalg.pinv(J[k]).T, axis=1), 1.0, rtol=1e-8)
        F = (u * frc.radii[k]) @ frc.axes[k].T
        np.testing.assert_allclose(np.linalg.norm(F @ J[k], axis=1), 1.0, rtol=1e-8)
    np.testing.assert_allclose(vel.radii * frc.radii, 1.0, rtol=1e-12)


@pytest.mark.parametrize("shape", [(), (1,), (3, 2)])
def test_measures_batch_equals_loop(shape):
    rng = np.random.default_rng(43)
    robot = make_robot(rng, n_rows=6)
    J = N.geometric_jacobian(robot, rng.uniform(-np.pi, np.pi, shape + (robot.dof,)))
    flat = J.reshape((-1,) + J.shape[-2:])
    for fn in (N.manipulability, N.condition_number, N.smallest_singular_value, N.jacobian_rank):
        out = fn(J)
        assert out.shape == shape
        np.testing.assert_allclose(out, np.array([fn(j) for j in flat]).reshape(shape))


# --- symbolic conditions ---------------------------------------------------------------------------

CASES = [  # (robot, rows): the eight arms of seed report 004 with the task rows it uses, Puma 560, Stanford
    ("report004-1-planar2r", "vx,vy"),
    ("report004-2-planar3r", "vx,vy,wz"),
    ("report004-3-articulated-rrr", "vx,vy,vz"),
    ("report004-4-rrp", "vx,vy,vz"),
    ("report004-5-rpp-cylindrical", "vx,vy,vz"),
    ("report004-6-wrist3r", "wx,wy,wz"),
    ("report004-7-scara-rrrp", "vx,vy,vz,wz"),
    ("report004-8-prrr", "vx,vy,vz,wz"),
    ("puma560", None),
    ("stanford", None),
]


def _J(robot, q, rows):
    idx = [ROW_NAMES.index(r) for r in rows.split(",")] if rows else list(range(6))
    return N.geometric_jacobian(robot, q)[idx, :]


def _ratio(J):
    s = np.linalg.svd(J, compute_uv=False)
    return s[-1] / s[0] if J.shape[0] <= J.shape[1] else s[min(J.shape) - 1] / s[0]


def _zero_set_point(robot, f, variables, rng):
    """A configuration on {f = 0}: random joints, then bisection on the last variable (independent of the code)."""
    from scipy.optimize import brentq

    k = variables[-1]
    for _ in range(200):
        q = rng.uniform(-np.pi, np.pi, robot.dof)
        lim = robot.q_limits
        for j, t in enumerate(robot.joint_types):
            if t is JointType.PRISMATIC:
                q[j] = rng.uniform(max(lim[j, 0], -1), min(lim[j, 1], 1))

        def g(t, q=q):
            y = q.copy()
            y[k] = t
            return f(y)

        xs = np.linspace(-np.pi, np.pi, 181)
        ys = [g(x) for x in xs]
        for a, b, ya, yb in zip(xs[:-1], xs[1:], ys[:-1], ys[1:]):
            if ya * yb < 0:
                q[k] = brentq(g, a, b, xtol=1e-15)
                return q
    raise AssertionError("no point found on the zero set")


@pytest.mark.parametrize("name, rows", CASES)
def test_reported_conditions_lose_rank_and_nearby_points_do_not(name, rows):
    import sympy as sp

    from denavit.symbolic import joint_symbols, parameter_symbols, singularity_analysis

    robot = load_robot(name)
    result = singularity_analysis(robot, rows)
    assert not result.everywhere and result.conditions
    qs = joint_symbols(robot.dof).q
    params = {parameter_symbols(robot)[k]: v for k, v in robot.parameters}
    rng = np.random.default_rng(44)
    for cond in result.conditions:
        idx = [int(v[1:]) - 1 for v in cond.variables]
        points = []
        if cond.solutions:
            for sol in cond.solutions:
                k = int(sol.variable[1:]) - 1
                for v in sol.values:
                    for _ in range(3):
                        q = rng.uniform(-np.pi, np.pi, robot.dof)
                        q[k] = v
                        points.append((q, k))
        else:
            f = sp.lambdify(qs, cond.factor.subs(params), "math")
            for _ in range(3):
                points.append((_zero_set_point(robot, lambda y: f(*y), idx, rng), idx[-1]))
        for q, k in points:
            assert _ratio(_J(robot, q, rows)) < 1e-10, (cond.factor, q)  # rank lost (round-off level)
            near = q.copy()
            near[k] += 1e-3
            assert _ratio(_J(robot, near, rows)) > 1e-8, (cond.factor, near)  # full rank 1e-3 away
            assert not N.is_singular(_J(robot, near, rows))


@pytest.mark.parametrize("name, rows", CASES)
def test_determinant_equals_numeric_determinant(name, rows):
    """For square J the reported det (computed in a wrist frame when no rows are given) equals det(J0)."""
    import sympy as sp

    from denavit.symbolic import joint_symbols, parameter_symbols, singularity_analysis

    robot = load_robot(name)
    result = singularity_analysis(robot, rows)
    syms = list(joint_symbols(robot.dof).q) + list(parameter_symbols(robot).values())
    f = sp.lambdify(syms, result.determinant, "math")
    rng = np.random.default_rng(45)
    for _ in range(5):
        q = rng.uniform(-np.pi, np.pi, robot.dof)
        J = _J(robot, q, rows)
        expected = np.linalg.det(J) if J.shape[0] == J.shape[1] else np.linalg.det(J.T @ J)
        got = f(*q, *robot.parameter_values.values())
        if J.shape[0] == J.shape[1]:
            np.testing.assert_allclose(got, expected, atol=1e-12, rtol=1e-9)
        else:  # Gram determinant: only the zero set is frame-independent
            assert (abs(got) < 1e-12) == (abs(expected) < 1e-12)


def test_planar_2r_condition_is_sin_q2_at_0_and_180_degrees():
    """Hand derivation (Craig Example 5.3): det [[L1 s2, 0], [L1 c2 + L2, L2]] = L1 L2 s2."""
    import sympy as sp

    from denavit.symbolic import singularity_analysis

    result = singularity_analysis(load_robot("report004-1-planar2r"), "vx,vy")
    L1, L2, q2 = sp.symbols("L1 L2 q2", real=True)
    assert sp.simplify(result.determinant - L1 * L2 * sp.sin(q2)) == 0
    (cond,) = result.conditions
    assert cond.variables == ("q2",) and cond.kind == "elbow"
    np.testing.assert_allclose(sorted(v for s in cond.solutions for v in s.values), [0.0, np.pi], atol=1e-12)


def test_puma560_has_wrist_elbow_and_shoulder_singularities():
    from denavit.symbolic import singularity_analysis

    result = singularity_analysis(load_robot("puma560"))
    kinds = {c.kind: c for c in result.conditions}
    assert set(kinds) == {"wrist", "elbow", "shoulder"}
    assert kinds["wrist"].variables == ("q5",)
    np.testing.assert_allclose(sorted(v for s in kinds["wrist"].solutions for v in s.values), [0.0, np.pi])
    assert kinds["elbow"].variables == ("q3",)
    # elbow: a3 sin q3 + d4 cos q3 = 0, i.e. tan q3 = −d4/a3 with the catalogue values
    a3, d4 = 0.0203, 0.4318
    expected = sorted([math.atan2(-d4, a3), math.atan2(-d4, a3) + math.pi])
    np.testing.assert_allclose(sorted(v for s in kinds["elbow"].solutions for v in s.values), expected, atol=1e-12)
    assert kinds["shoulder"].variables == ("q2", "q3") and not kinds["shoulder"].solutions  # kept as an equation


@pytest.mark.slow
def test_coaxial_joints_make_the_arm_singular_everywhere():
    from denavit.symbolic import singularity_analysis

    robot = load_robot("report000-6r")
    result = singularity_analysis(robot)
    assert result.everywhere and result.generic_rank == 5 and result.full_rank == 6
    assert "joints 1 and 2 are coaxial" in result.reason
    rng = np.random.default_rng(46)
    for q in rng.uniform(-np.pi, np.pi, (20, 6)):
        assert N.jacobian_rank(N.geometric_jacobian(robot, q)) == 5


def test_prismatic_at_zero_extension():
    from denavit.symbolic import singularity_analysis

    robot = DHRobot("rp", (DHLink(alpha=np.pi / 2), DHLink(joint=JointType.PRISMATIC)))  # polar arm in a plane
    result = singularity_analysis(robot, "vx,vy")
    kinds = [c.kind for c in result.conditions]
    assert "prismatic at zero extension" in kinds


def test_unknown_rows_are_rejected():
    from denavit.symbolic import singularity_analysis

    with pytest.raises(ValueError, match="choose from vx, vy, vz, wx, wy, wz"):
        singularity_analysis(load_robot("planar2r"), "vx,vq")


def test_irrational_constant_factor_is_kept_not_truncated():
    """A wrist with 60° twists: det of the angular rows is sin α1 sin α2 sin q2 = (3/4) sin q2 (by hand).
    The constant 3/4 was once truncated to the integer 0, which declared such arms (jaco2-6dof) singular
    everywhere."""
    import sympy as sp

    from denavit import Convention, DHLink, DHRobot
    from denavit.symbolic import joint_symbols, singularity_analysis

    robot = DHRobot(name="wrist60", links=(DHLink(alpha=np.pi / 3), DHLink(alpha=np.pi / 3), DHLink()),
                    convention=Convention.STANDARD)
    result = singularity_analysis(robot, "wx,wy,wz")
    assert not result.everywhere
    assert sp.simplify(sp.Mul(*result.constant_factors) - sp.Rational(3, 4)) == 0
    q2 = joint_symbols(3).q[1]
    assert [c.factor for c in result.conditions] == [sp.sin(q2)]
