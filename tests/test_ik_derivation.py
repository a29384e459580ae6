"""Symbolic IK derivation: the derived formulas, lambdified and evaluated in order, must reproduce the target.

Independent routes: the numeric forward kinematics (FK(derived q) = T for every real branch) and the set of
closed-form solutions of ``analytic_ik`` (a different algorithm: resultant + subproblems on the joint-screw form).
Robots: the covered catalogue arms, the same arms with random parameter values, and random base/tool.
"""

from __future__ import annotations

import itertools
import json

import numpy as np
import pytest
import sympy as sp

from denavit import analytic_ik, forward_kinematics, load_robot
from denavit.cli import main
from denavit.errors import UnsupportedRobotError
from denavit.numeric import transform_from_xyz_rpy
from denavit.symbolic import IKDerivation, ik_derivation

from conftest import REDUCED, random_q_in_limits as _random_q

POSES = 6 if REDUCED else 12
ATOL = 1e-9
SIX = ["puma560", "puma560-mdh", "report003-6r", "report001-6r", "stanford"]
PLANAR = ["planar2r", "planar3r", "report004-1-planar2r", "report004-2-planar3r", "report000-planar3r"]


def _evaluate(d: IKDerivation, T_0N: np.ndarray, signs: dict) -> np.ndarray:
    """Run the derivation's assignments in order with lambdify, for a batch of poses T_0N (B, 4, 4)."""
    env = {s: T_0N[:, i, j] for (i, j), s in np.ndenumerate(np.array(d.target.tolist(), dtype=object))
           if isinstance(s, sp.Symbol)}
    env.update({s: float(v) for s, v in d.parameters})
    env.update({s: float(v) for s, v in signs.items()})
    for lhs, rhs in d.formulas:
        pairs = list(zip(lhs, rhs)) if isinstance(lhs, sp.MatrixBase) else [(lhs, rhs)]
        for sym, expr in pairs:
            args = sorted(expr.free_symbols, key=str)
            missing = [a for a in args if a not in env]
            assert not missing, f"{sym} uses {missing} before they are computed"
            with np.errstate(invalid="ignore"):
                val = sp.lambdify(args, expr, "numpy")(*(env[a] for a in args))
            env[sym] = np.broadcast_to(np.asarray(val, dtype=float), (len(T_0N),))
    return np.stack([env[qk] for qk in d.joints], axis=-1)


def _branches(d: IKDerivation, robot, T_world: np.ndarray) -> np.ndarray:
    """All sign combinations → (B, 2^k, n), NaN where a branch has no real value."""
    T_0N = np.linalg.inv(robot.base_matrix) @ T_world @ np.linalg.inv(robot.tool_matrix)
    out = [_evaluate(d, T_0N, dict(zip(d.branches, signs)))
           for signs in itertools.product((1.0, -1.0), repeat=len(d.branches))]
    return np.stack(out, axis=1)


def _wrap_dist(robot, a, b):
    rev = np.array([t.value == "revolute" for t in robot.joint_types])
    d = a - b
    return np.where(rev, np.abs((d + np.pi) % (2 * np.pi) - np.pi), np.abs(d)).max(axis=-1)


def _check_against_fk_and_analytic(robot, rng, position_only=False):
    d = ik_derivation(robot)
    q = _random_q(robot, rng, POSES)
    T = forward_kinematics(robot, q)
    cand = _branches(d, robot, T)  # (B, K, n)
    for b in range(len(T)):
        real = cand[b][np.all(np.isfinite(cand[b]), axis=-1)]
        assert len(real) > 0, f"{robot.name}: no real branch for a reachable pose"
        F = forward_kinematics(robot, real)
        if position_only:
            np.testing.assert_allclose(F[:, :3, 3], np.broadcast_to(T[b, :3, 3], (len(real), 3)), atol=ATOL)
        else:
            np.testing.assert_allclose(F, np.broadcast_to(T[b], F.shape), atol=ATOL)
        # the generating configuration is one of the derived branches
        assert _wrap_dist(robot, real, q[b]).min() < 1e-7
        # same set as analytic_ik (inside + outside the joint limits), compared modulo 2π
        distinct = [x for i, x in enumerate(real) if all(_wrap_dist(robot, x, y) > 1e-6 for y in real[:i])]
        both = analytic_ik(robot, T[b])
        ref = np.concatenate([both.solutions, both.outside_limits])
        assert len(distinct) == len(ref), (robot.name, len(distinct), len(ref))
        for x in distinct:
            assert _wrap_dist(robot, ref, x).min() < 1e-7


@pytest.mark.parametrize("name", SIX + PLANAR)
def test_derived_branches_reproduce_target_and_match_analytic_ik(name):
    robot = load_robot(name)
    _check_against_fk_and_analytic(robot, np.random.default_rng(abs(hash(name)) % 2**32),
                                   position_only=robot.dof == 2)


@pytest.mark.parametrize("name", ["puma560", "puma560-mdh", "stanford", "report001-6r", "planar3r"])
@pytest.mark.slow
def test_random_parameters_base_and_tool(name):
    """Random link lengths/offsets (named parameters re-drawn) and a random base and tool."""
    rng = np.random.default_rng(11)
    base = load_robot(name)
    for _ in range(2):
        values = {k: float(np.sign(v) * rng.uniform(0.05, 0.8)) if v else 0.0 for k, v in base.parameter_values.items()}
        robot = load_robot(name, **values)
        if robot.dof == 6:
            B = transform_from_xyz_rpy(rng.uniform(-1, 1, 3), rng.uniform(-np.pi, np.pi, 3))
            E = transform_from_xyz_rpy(rng.uniform(-0.2, 0.2, 3), rng.uniform(-np.pi, np.pi, 3))
            robot = robot.replace(base=B, tool=E)
        _check_against_fk_and_analytic(robot, rng)


def test_puma_formulas_are_the_textbook_ones():
    """PUMA 560 (standard DH): the law of cosines is Craig's a3 c3 − d4 s3 = K (Craig eq. 4.69, with his d3 as
    our shoulder offset); q5 is the ZYZ angle from the third column (Spong eq. 2.28)."""
    d = ik_derivation(load_robot("puma560"))
    a2, a3, d1, d3, d4 = sp.symbols("a2 a3 d1 d3 d4", real=True)
    r, s, K = sp.symbols("r s K", real=True)
    formulas = dict((str(k), v) for k, v in d.formulas if not isinstance(k, sp.MatrixBase))
    expected_K = (r**2 + (s - d1) ** 2 - a2**2 - a3**2 - d4**2) / (2 * a2)
    assert sp.simplify(formulas["K"] - expected_K) == 0
    shown = [st for st in d.steps if st.title.startswith("Law of cosines")][0]
    q3 = d.joints[2]
    assert sp.simplify(shown.rhs - (a2**2 + a3**2 + d4**2 + 2 * a2 * (a3 * sp.cos(q3) - d4 * sp.sin(q3)))) == 0
    assert sp.simplify(formulas["r"].subs(d.branches[0], 1) ** 2 - (sp.Symbol("x_c", real=True) ** 2 + sp.Symbol("y_c", real=True) ** 2
                                             - d3**2)) == 0


def test_wrist_centre_is_p_minus_d6_R_z():
    """report003: p_c = p − d6 R z (Spong eq. 5.12) with d6 kept as a symbol."""
    d = ik_derivation(load_robot("report003-6r"))
    lhs, rhs = d.formulas[0]
    R, p = d.target[:3, :3], d.target[:3, 3]
    d6 = sp.Symbol("d6", real=True)
    assert sp.simplify(sp.Matrix(rhs) - (p - d6 * R[:, 2])) == sp.zeros(3, 1)


@pytest.mark.parametrize("name", ["ur5", "panda", "scara", "articulated-rrr", "spherical-wrist"])
def test_uncovered_arms_raise(name):
    with pytest.raises(UnsupportedRobotError, match=name):
        ik_derivation(load_robot(name))


def test_renderers_contain_every_step():
    d = ik_derivation(load_robot("puma560"))
    text, tex, md = d.to_text(), d.to_latex(), d.to_markdown()
    for st in d.steps:
        assert st.title in text and st.title in md
    assert tex.count("\\begin{align*}") == sum(st.lhs is not None for st in d.steps)
    assert "\\operatorname{atan}_{2}" in tex and "$$" in md and "sigma5" in text


def test_cli_derive_text_latex_json(capsys):
    assert main(["ik", "puma560", "--derive"]) == 0
    out = capsys.readouterr().out
    assert "Law of cosines" in out and "q6 =" in out
    assert main(["ik", "stanford", "--derive", "--latex"]) == 0
    assert "\\begin{align*}" in capsys.readouterr().out
    assert main(["ik", "planar3r", "--derive", "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["kind"] == "planar" and all(isinstance(data[k], str) for k in ("text", "latex", "markdown"))
    assert [s["title"] for s in data["steps"]][-1] == "q3"


def test_cli_derive_unsupported_and_missing_target(capsys):
    assert main(["ik", "ur5", "--derive"]) == 1
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "ur5" in err
    assert main(["ik", "puma560"]) == 2
    assert "--pose" in capsys.readouterr().err
