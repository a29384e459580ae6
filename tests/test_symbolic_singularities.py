"""Singularities of the catalogue arms (6 and 7 joints, UR-type wrists, arms of fewer than 6 joints), checked
against the numeric Jacobian: its rank on each reported condition and just off it, its minors, and the
geometry (axes lining up, distance from axis 1) that each label claims."""

import json

import numpy as np
import pytest

from denavit import catalogue_names, load_robot
from denavit import numeric as N

from test_singularities import CASES, ROW_NAMES, _ratio, _zero_set_point

CATALOGUE = catalogue_names()


def _J(robot, q, rows):
    return N.geometric_jacobian(robot, q)[[ROW_NAMES.index(r) for r in rows], :]


def _points(robot, cond, rng, count=3):
    """Configurations on the condition's zero set (from its solutions, else by bisection) and the joint moved."""
    import sympy as sp

    from denavit.symbolic import joint_symbols, parameter_symbols

    idx = [int(v[1:]) - 1 for v in cond.variables]
    out = []
    if cond.solutions:
        for sol in cond.solutions:
            k = int(sol.variable[1:]) - 1
            for v in sol.values:
                for _ in range(count):
                    q = rng.uniform(-np.pi, np.pi, robot.dof)
                    q[k] = v
                    out.append((q, k))
        return out
    params = {parameter_symbols(robot)[k]: v for k, v in robot.parameters}
    f = sp.lambdify(joint_symbols(robot.dof).q, cond.factor.subs(params), "math")
    return [(_zero_set_point(robot, lambda y: f(*y), idx, rng), idx[-1]) for _ in range(count)]


@pytest.mark.slow
@pytest.mark.parametrize("name", [n for n in CATALOGUE if n != "panda"])
def test_every_catalogue_arm_loses_rank_exactly_on_its_conditions(name):
    from denavit.symbolic import singularity_analysis

    robot = load_robot(name)
    res = singularity_analysis(robot)  # rows chosen by the library for arms of fewer than 6 joints
    rng = np.random.default_rng(70)
    if res.everywhere:
        for q in rng.uniform(-np.pi, np.pi, (10, robot.dof)):
            assert N.jacobian_rank(_J(robot, q, res.rows)) == res.generic_rank < res.full_rank
        return
    if not res.conditions and robot.dof > len(res.rows):
        # a redundant arm whose maximal minors share no factor (gen3: offset shoulder and elbow): its rank drops only
        # where all of them vanish (codimension 2), so there is no single condition; full rank at random q
        assert res.determinant == 1, name
        for q in rng.uniform(-np.pi, np.pi, (10, robot.dof)):
            assert N.jacobian_rank(_J(robot, q, res.rows)) == res.full_rank
        return
    assert res.conditions, name
    for cond in res.conditions:
        for q, k in _points(robot, cond, rng):
            assert _ratio(_J(robot, q, res.rows)) < 1e-9, (name, cond.factor, q)
            near = q.copy()
            near[k] += 1e-3
            assert not N.is_singular(_J(robot, near, res.rows)), (name, cond.factor, near)
    # and away from every condition the analysed rows have full rank
    for q in rng.uniform(-np.pi, np.pi, (10, robot.dof)):
        assert N.jacobian_rank(_J(robot, q, res.rows)) == res.full_rank


@pytest.mark.parametrize("name, rows", [c for c in CASES if c[1] is not None])
def test_rows_picked_for_short_arms_are_the_ones_report_004_uses(name, rows):
    """Report 004 chose the task rows of its eight small arms by hand; the library picks the same ones."""
    from denavit.symbolic import singularity_analysis
    from denavit.symbolic._singularities import task_rows

    robot = load_robot(name)
    assert ",".join(task_rows(robot)) == rows
    assert ",".join(singularity_analysis(robot).rows) == rows


def test_six_joint_arms_keep_all_six_rows():
    from denavit.symbolic._singularities import task_rows

    for name in ("puma560", "ur5", "stanford", "panda"):
        assert task_rows(load_robot(name)) == tuple(ROW_NAMES)


@pytest.mark.slow
def test_panda_minors_of_the_middle_frame_jacobian_equal_those_of_j0():
    """The 6x7 matrix analysed (axes of frame {4}, reference point on axis 7) has the seven 6x6 minors of J0
    (rotation and change of reference point are block-triangular with determinant 1)."""
    import sympy as sp

    from denavit.symbolic import joint_symbols, parameter_symbols, singularity_analysis

    robot = load_robot("panda")
    res = singularity_analysis(robot)
    assert res.matrix.shape == (6, 7) and not res.everywhere
    syms = list(joint_symbols(7).q) + list(parameter_symbols(robot).values())
    f = sp.lambdify(syms, res.matrix, "numpy")
    rng = np.random.default_rng(71)
    for q in rng.uniform(-np.pi, np.pi, (5, 7)):
        M = np.array(f(*q, *robot.parameter_values.values()), dtype=float)
        J = N.geometric_jacobian(robot, q)
        for drop in range(7):
            cols = [j for j in range(7) if j != drop]
            np.testing.assert_allclose(np.linalg.det(M[:, cols]), np.linalg.det(J[:, cols]), atol=1e-12, rtol=1e-9)
    # no common factor reported: then no factor's zero set is singular, and a random configuration is regular
    if not res.conditions:
        assert res.determinant == 1
        assert all(N.jacobian_rank(N.geometric_jacobian(robot, q)) == 6 for q in rng.uniform(-2, 2, (10, 7)))


def test_ur5_wrist_shoulder_and_elbow_are_labelled_by_their_geometry():
    from denavit.symbolic import singularity_analysis

    robot = load_robot("ur5")
    res = singularity_analysis(robot)
    kinds = {c.kind: c for c in res.conditions}
    assert set(kinds) == {"wrist", "elbow", "shoulder"}
    assert kinds["wrist"].variables == ("q5",) and kinds["elbow"].variables == ("q3",)
    rng = np.random.default_rng(72)
    for q, _ in _points(robot, kinds["wrist"], rng):  # wrist: axes 4 and 6 turn parallel
        z, _o = N.joint_axes(robot, N.link_transforms(robot, q))
        assert np.linalg.norm(np.cross(z[3], z[5])) < 1e-9
    for q, _ in _points(robot, kinds["shoulder"], rng):
        # shoulder: the point where axes 5 and 6 meet is at its least distance from axis 1, for every joint
        def rho2(x):
            z, o = N.joint_axes(robot, N.link_transforms(robot, x))
            A = np.concatenate([np.eye(3) - np.outer(v, v) for v in z[4:6]])
            b = np.concatenate([(np.eye(3) - np.outer(v, v)) @ p for v, p in zip(z[4:6], o[4:6])])
            c = np.linalg.lstsq(A, b, rcond=None)[0]
            d = c - o[0]
            return d @ d - (d @ z[0]) ** 2

        h = 1e-6
        grad = [(rho2(q + h * e) - rho2(q - h * e)) / (2 * h) for e in np.eye(6)]
        assert np.abs(grad).max() < 1e-6


def test_singularities_cli_measures_the_planar_rows_of_a_planar_arm(capsys):
    """Without --rows a planar 3R is analysed on (vx, vy, wz): full rank there, manipulability √det(J Jᵀ) > 0."""
    from denavit.cli import main

    q = np.array([0.3, 0.5, 0.2])
    assert main(["singularities", "planar3r", "-q", "0.3, 0.5, 0.2", "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["rows"] == ["vx", "vy", "wz"]
    J = N.geometric_jacobian(load_robot("planar3r"), q)[[0, 1, 5], :]
    assert data["measures"]["rank"] == 3 and not data["measures"]["singular"]
    np.testing.assert_allclose(data["measures"]["manipulability"], abs(np.linalg.det(J)), rtol=1e-12)
    assert data["measures"]["manipulability"] > 0.1
    assert [c["kind"] for c in data["conditions"]] == ["elbow"]


def test_report_measures_a_short_arm_on_its_task_rows():
    from denavit.report import derive
    from denavit.report._derivation import Numbers

    robot = load_robot("planar3r")
    q = np.array([0.3, 0.5, 0.2])
    sec = derive(robot, q=list(q), topics=["singularities"]).section("singularities")
    w = [s for s in sec.steps if isinstance(s, Numbers) and s.lhs == "w(q)"][0]
    J = N.geometric_jacobian(robot, q)[[0, 1, 5], :]
    np.testing.assert_allclose(float(np.ravel(w.values)[0]), abs(np.linalg.det(J)), rtol=1e-10)
    assert float(np.ravel(w.values)[0]) > 0.1


def _puma_with_twist(row, alpha=0.7):
    import dataclasses

    robot = load_robot("puma560")
    links = list(robot.links)
    links[row] = dataclasses.replace(links[row], alpha=alpha,
                                     symbols=tuple(s for s in links[row].symbols if s[0] != "alpha"))
    return robot.replace(links=tuple(links))


@pytest.mark.slow
@pytest.mark.parametrize("row", [0, 1])
def test_generic_twist_conditions_lose_rank(row):
    """A Puma with a 0.7 rad twist (cos 0.7 and sin 0.7 carried as a pair, never expanded) keeps its wrist and
    elbow conditions; every reported condition is singular and 1e-3 away is not."""
    from denavit.symbolic import singularity_analysis

    robot = _puma_with_twist(row)
    res = singularity_analysis(robot)
    assert not res.everywhere and {"wrist", "elbow"} <= {c.kind for c in res.conditions}
    rng = np.random.default_rng(73)
    for cond in res.conditions:
        for q, k in _points(robot, cond, rng, count=2):
            assert _ratio(_J(robot, q, res.rows)) < 1e-9, (cond.factor, q)
            near = q.copy()
            near[k] += 1e-3
            assert not N.is_singular(_J(robot, near, res.rows))


def test_determinant_by_expansion_equals_fraction_free_elimination():
    """The 6×6 determinant the analysis factors (expansion with all minors kept) is sympy's fraction-free
    determinant of the same polynomial matrix (Puma 560 with a generic 0.7 rad twist on row 2)."""
    from sympy.polys.matrices import DomainMatrix

    from denavit.symbolic._singular_ring import laplace_det, wrist_frame_jacobian

    _, _, rg, J = wrist_frame_jacobian(_puma_with_twist(1), "none")
    bareiss = DomainMatrix([list(row) for row in J], (6, 6), rg.R.to_domain()).det()
    assert rg.reduce(laplace_det(rg, J) - bareiss) == 0 and bareiss != 0


def test_a_float_twist_and_its_negative_are_one_generator():
    """cos 0.7, sin 0.7 and −sin 0.7 (a rotation's entries) are two ring generators with c² + s² = 1, not three
    unrelated constants (the generic 6R's determinant did not finish in ten minutes with them)."""
    import sympy as sp

    from denavit.symbolic._rings import TrigRing

    c, s = sp.cos(sp.Float(0.7)), sp.sin(sp.Float(0.7))
    q1 = sp.Symbol("q1", real=True)
    rg = TrigRing([c, -s, s, c * sp.cos(q1)], (q1,))
    consts = [g for g in rg.R.symbols if not str(g).startswith(("_s", "_c"))]
    assert len(consts) == 2
    assert rg.reduce(rg.element(c) ** 2 + rg.element(-s) ** 2 - 1) == 0
    assert rg.reduce(rg.element(-s) + rg.element(s)) == 0
    assert abs(float(rg.to_expr(rg.element(-s))) + np.sin(0.7)) < 1e-15
