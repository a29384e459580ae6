"""The claims checker: the restricted reader, verdicts on correct and broken claims, the CLI.

Correct claims are produced independently of the checker (sympy's LaTeX printer applied to the symbolic
engine's matrices, rewritten in several equivalent forms); broken ones are made from them by one slip.
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
import sympy as sp
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import denavit as dn
from denavit import _expr
from denavit import symbolic as S
from denavit.check import check_claims, parse_math, robot_resolver
from denavit.cli import main

from conftest import REDUCED
ARMS = ["report000-6r", "report001-6r", "report004-4-rrp", "scara", "planar3r"]


def _val(text, robot, env=None):
    node = parse_math(text, robot_resolver(robot))
    return _expr.evaluate(node, {**robot.parameter_values, **(env or {})})


# --- the reader ------------------------------------------------------------------------------------


def test_reader_equivalent_forms_evaluate_alike():
    robot = dn.load_robot("report000-6r")
    env = {"q1": 0.3, "q2": -1.1, "q3": 0.7}
    want = math.cos(0.3 - 1.1)
    for text in [r"C_{12}", r"c_{12}", "C12", r"\cos(\theta_1 + \theta_2)", r"\cos\left(q_{1}+q_{2}\right)",
                 r"c_1 c_2 - s_1 s_2", "c1*c2 - s1*s2", r"\cos\theta_1\cos\theta_2-\sin\theta_1\sin\theta_2",
                 r"C_{\theta_1 + \theta_2}", r"\cos{\left(q_{1} + q_{2} \right)}", "cos(θ1 + θ2)"]:
        assert _val(text, robot, env) == pytest.approx(want, abs=1e-14), text
    assert _val(r"\frac{\sqrt{3}}{2}", robot) == pytest.approx(math.sqrt(3) / 2)
    assert _val(r"2 L_1 \cdot 3", robot) == pytest.approx(3.0)
    assert _val(r"\sin^2\theta_3 + \cos^{2}(\theta_3)", robot, env) == pytest.approx(1.0)
    assert _val(r"-\frac{\sqrt{3}\cdot(0.5 - 0.1\sqrt{3})}{2}", robot) == pytest.approx(-math.sqrt(3) * (0.5 - 0.1 * math.sqrt(3)) / 2)
    assert _val("H_1 + L_{2}", robot) == pytest.approx(0.9)
    assert _val(r"{}^{0}T_{1} = 0.5", robot) == 0.5


@pytest.mark.parametrize("text,match", [
    ("__import__('os').system('x')", "unknown symbol|unexpected"),
    (r"\input{/etc/passwd}", "unsupported LaTeX command"),
    ("Z_9", "unknown symbol"),
    ("(" * 100 + "1" + ")" * 100, "nested too deeply"),
    ("1+" * 12000 + "1", "longer than"),
    ("x^{1000}", "unknown symbol|exponent"),
    (r"\frac{1}{", "end of expression"),
])
def test_reader_refuses_bad_text(text, match):
    with pytest.raises(dn.ParseError, match=match):
        _val(text, dn.load_robot("planar2r"))


def test_reader_caps_exponents():
    with pytest.raises(dn.ParseError, match="exponent"):
        _val("2^{1000}", dn.load_robot("planar2r"))


# --- claims from the symbolic engine ---------------------------------------------------------------


def _tex(M, robot, style: str) -> str:
    q = S.joint_symbols(robot.dof).q
    if style == "shorthand":
        M = S.shorthand_matrix(M, q)
    elif style == "expanded":
        M = M.applyfunc(lambda e: sp.expand(sp.expand_trig(e)))
    elif style == "theta":
        M = M.xreplace({s: sp.Symbol(f"theta_{k + 1}") for k, s in enumerate(q)})
    elif style == "decimal":  # numbers only (at a fixed q): 8 decimals
        M = M.applyfunc(lambda e: sp.Float(float(e), 12) if e.is_number else e)
        return sp.latex(M.applyfunc(lambda e: sp.Symbol(f"{float(e):.8f}") if e.is_number else e),
                        mat_str="bmatrix", mat_delim="")
    return sp.latex(M, mat_str="bmatrix", mat_delim="")


def _check(robot, claims, seed=0):
    return check_claims(robot, claims, seed=seed).verdicts


@pytest.mark.parametrize("name", ARMS)
def test_check_correct_symbolic_claims_in_varied_forms_are_accepted(name):
    robot = dn.load_robot(name)
    A = S.link_matrices_sym(robot)
    T = S.link_transforms_sym(robot)
    claims = []
    for k, style in enumerate(["plain", "shorthand", "expanded", "theta"]):
        i = k % robot.n_rows + 1
        claims.append({"id": f"A{i}-{style}", "quantity": "link_transform", "index": i, "value": _tex(A[i - 1], robot, style)})
        claims.append({"id": f"T-{style}", "quantity": "transform", "value": _tex(T[-1], robot, style)})
    claims.append({"quantity": "position", "value": _tex(S.forward_kinematics_sym(robot)[:3, 3], robot, "shorthand")})
    for v in _check(robot, claims):
        assert v.verdict == "correct", (v.id, v.message)


@pytest.mark.parametrize("name", ["report000-6r", "report004-4-rrp", "report001-6r"])
def test_check_jacobian_claims_from_an_independent_symbolic_route(name):
    """J0 columns by differentiating the symbolic position (linear rows) are accepted by the checker."""
    robot = dn.load_robot(name)
    q = S.joint_symbols(robot.dof).q
    p = S.forward_kinematics_sym(robot)[:3, 3]
    Jv = p.jacobian(sp.Matrix(q))
    claims = [{"quantity": "jacobian", "rows": "linear", "value": _tex(sp.ImmutableMatrix(Jv), robot, "shorthand")},
              {"quantity": "jacobian", "rows": "linear", "column": 2, "value": _tex(sp.ImmutableMatrix(Jv[:, 1]), robot, "plain")}]
    for v in _check(robot, claims):
        assert v.verdict == "correct", v.message


def _case(robot, rng):
    lo, hi = np.maximum(robot.q_limits[:, 0], -np.pi), np.minimum(robot.q_limits[:, 1], np.pi)
    return rng.uniform(lo, hi)


@settings(max_examples=12 if REDUCED else 30, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(name=st.sampled_from(ARMS), style=st.sampled_from(["plain", "shorthand", "expanded", "theta", "decimal"]),
       seed=st.integers(0, 2**31 - 1), which=st.sampled_from(["A", "T", "position"]))
def test_check_never_calls_a_correct_claim_incorrect(name, style, seed, which):
    """Property: a claim equal to the truth (any rewriting, at random q, or as a formula) is never rejected."""
    robot = dn.load_robot(name)
    rng = np.random.default_rng(seed)
    q = _case(robot, rng)
    subs = dict(zip(S.joint_symbols(robot.dof).q, [sp.Float(v, 30) for v in q]))
    i = int(rng.integers(1, robot.n_rows + 1))
    M = {"A": lambda: S.link_matrices_sym(robot)[i - 1], "T": lambda: S.link_transforms_sym(robot)[-1],
         "position": lambda: S.forward_kinematics_sym(robot)[:3, 3]}[which]()
    claim = {"quantity": {"A": "link_transform", "T": "transform", "position": "position"}[which]}
    if which == "A":
        claim["index"] = i
    if style == "decimal":
        params = {sp.Symbol(k, real=True): sp.Float(v, 30) for k, v in robot.parameters}
        M = sp.ImmutableMatrix(M.xreplace(params).xreplace(subs).evalf(30))
        claim["q"] = ", ".join(repr(float(v)) for v in q)
    claim["value"] = _tex(sp.ImmutableMatrix(M), robot, style)
    (v,) = _check(robot, [claim], seed=seed)
    assert v.verdict == "correct", (claim, v.message)


# --- broken claims ---------------------------------------------------------------------------------


def _numeric_claim(robot, q, M, quantity, **spec):
    return {"quantity": quantity, "q": ", ".join(repr(float(x)) for x in q),
            "value": [[f"{x:.10f}" for x in row] for row in np.atleast_2d(M)] if np.ndim(M) == 2
            else [f"{x:.10f}" for x in M], **spec}


@pytest.mark.parametrize("name", ["report000-6r", "report001-6r", "puma560"])
def test_check_broken_claims_are_rejected_with_the_right_entries(name):
    robot = dn.load_robot(name)
    rng = np.random.default_rng(11)
    q = _case(robot, rng)
    T = dn.forward_kinematics(robot, q)
    F = dn.link_transforms(robot, q)
    # sign flip of one entry
    bad = T.copy()
    bad[0, 3] = -bad[0, 3]
    (v,) = _check(robot, [_numeric_claim(robot, q, bad, "end_effector")])
    assert v.verdict == "incorrect" and [e["entry"] for e in v.entries] == [[1, 4]]
    assert any("sign" in h for h in v.hints)
    # two entries swapped
    bad = T.copy()
    bad[[0, 1], 3] = bad[[1, 0], 3]
    (v,) = _check(robot, [_numeric_claim(robot, q, bad, "end_effector")])
    assert {tuple(e["entry"]) for e in v.entries} == {(1, 4), (2, 4)} and any("swapped" in h for h in v.hints)
    # transposed rotation
    bad = T.copy()
    bad[:3, :3] = T[:3, :3].T
    (v,) = _check(robot, [_numeric_claim(robot, q, bad, "end_effector")])
    assert v.verdict == "incorrect" and any("transposed" in h for h in v.hints)
    # a link transform computed with the other convention's formula
    other = robot.replace(convention="modified" if robot.convention.value == "standard" else "standard")
    i = 3
    Fo = dn.link_transforms(other, q)
    A_other = np.linalg.solve(Fo[i - 1], Fo[i])
    A_true = np.linalg.solve(F[i - 1], F[i])
    assert not np.allclose(A_other, A_true)
    (v,) = _check(robot, [_numeric_claim(robot, q, A_other, "link_transform", index=i)])
    assert v.verdict == "incorrect" and any("convention" in h for h in v.hints)


def test_check_wrong_parameter_value_is_found():
    robot = dn.load_robot("report000-6r")
    q = np.array([0.3, -0.2, 0.9, -1.0, 0.4, 0.1])
    wrong = dn.with_parameters(robot, L2=0.55)
    (v,) = _check(robot, [_numeric_claim(robot, q, dn.forward_kinematics(wrong, q)[:3, 3], "position")])
    assert v.verdict == "incorrect"
    assert any("L2 = 0.55" in h for h in v.hints), v.hints


def test_check_symbolic_sign_slip_gives_a_counterexample():
    robot = dn.load_robot("planar2r")
    claims = [{"id": "x", "quantity": "position", "value": [r"L_1 c_1 + L_2 c_{12}", r"L_1 s_1 - L_2 s_{12}", "0"]}]
    (v,) = _check(robot, claims)
    assert v.verdict == "incorrect" and [e["entry"] for e in v.entries] == [[2]]
    q = np.array(v.counterexample["q"])
    truth = dn.forward_kinematics(robot, q)[1, 3]
    claimed = math.sin(q[0]) - math.sin(q[0] + q[1])
    assert abs(claimed - truth) > 1e-6


def test_check_jacobian_frame_and_twist_and_torques():
    robot = dn.load_robot("report004-4-rrp")
    q = np.array([0.4, -0.7, 0.2])
    Je = dn.geometric_jacobian(robot, q, frame="tool")
    J0 = dn.geometric_jacobian(robot, q)
    qd = np.array([1.0, -2.0, 0.5])
    w = np.array([1, 2, 3, 0.1, 0.2, 0.3])
    claims = [_numeric_claim(robot, q, Je, "jacobian"),
              _numeric_claim(robot, q, Je, "jacobian", frame="tool"),
              {**_numeric_claim(robot, q, J0 @ qd, "twist"), "qd": "1, -2, 0.5"},
              {**_numeric_claim(robot, q, J0.T @ w, "torques"), "wrench": "1, 2, 3, 0.1, 0.2, 0.3"}]
    v = _check(robot, claims)
    assert v[0].verdict == "incorrect" and any("tool axes" in h for h in v[0].hints)
    assert [x.verdict for x in v[1:]] == ["correct"] * 3


def test_check_unreadable_claims_say_why():
    robot = dn.load_robot("planar2r")
    v = _check(robot, [{"quantity": "position", "value": r"\begin{bmatrix} x \\ 1 \end{bmatrix}"},
                       {"quantity": "nonsense", "value": "1"},
                       {"quantity": "position"},
                       {"quantity": "link_transform", "index": 9, "value": "1"}])
    assert [x.verdict for x in v] == ["unreadable"] * 4
    assert "unknown symbol" in v[0].message and "choose one of" in v[1].message
    assert "no 'value'" in v[2].message and "index" in v[3].message


# --- command line ----------------------------------------------------------------------------------


def test_cli_check_json_and_errors(tmp_path, capsys):
    f = tmp_path / "claims.yaml"
    f.write_text("robot: planar2r\nclaims:\n"
                 "  - {id: p, quantity: position, value: ['L_1 \\cos\\theta_1 + L_2 C_{12}', 'L_1 S_1 + L_2 S_{12}', 0]}\n"
                 "  - {id: bad, quantity: position, value: ['L_1 C_1', 'L_1 S_1', 0]}\n")
    assert main(["check", "planar2r", str(f), "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["summary"] == {"correct": 1, "incorrect": 1, "unreadable": 0}
    assert data["claims"][1]["entries"][0]["entry"] == [1]
    assert main(["check", "planar2r", str(f)]) == 0
    assert "[INCORRECT] bad" in capsys.readouterr().out
    f.write_text("claims: [ {quantity: position\n")
    assert main(["check", "planar2r", str(f)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "malformed YAML" in err
    assert main(["check", "planar2r", str(tmp_path / "none.yaml")]) == 2


# --- singular configurations -----------------------------------------------------------------------------


def _sing(robot, value, rows=None, seed=0):
    claim = {"quantity": "singularities", "value": value}
    if rows:
        claim["rows"] = rows
    (v,) = _check(robot, [claim], seed=seed)
    return v


def _svd_ratio(robot, q, rows):
    idx = [["vx", "vy", "vz", "wx", "wy", "wz"].index(r) for r in rows.split(",")] if rows else list(range(6))
    s = np.linalg.svd(dn.geometric_jacobian(robot, np.asarray(q))[idx], compute_uv=False)
    return s[-1] / s[0]


@pytest.mark.parametrize("value", ["q2 = 0, pi", r"\sin\theta_2 = 0", r"q_2 = 0 \text{ or } q_2 = \pi", "s_2 = 0",
                                   r"\theta_2 = k\pi", ["q2 = 0", "q2 = -pi"], r"\cos^2 q_2 = 1", "q2 = 0.0000, 3.1416"])
def test_check_singularities_planar_2r_textbook_forms_accepted(value):
    """Planar 2R (Spong eq. 4.91): det of the position Jacobian is L1 L2 sin q2: singular iff q2 = 0 or π."""
    assert _sing(dn.load_robot("planar2r"), value, "vx,vy").verdict == "correct"


def test_check_singularities_broken_claims_named_with_counterexamples():
    robot = dn.load_robot("planar2r")
    v = _sing(robot, "q2 = 0", "vx,vy")
    assert v.verdict == "incorrect" and v.extra["missing"] == ["q2 = 3.14159 (from sin(q2) = 0)"]
    v = _sing(robot, r"q_2 = \pi/2", "vx,vy")
    assert v.verdict == "incorrect" and v.entries[0]["entry"] == [1] and "not singular" in v.message
    assert _svd_ratio(robot, v.entries[0]["q"], "vx,vy") > 0.1  # the counterexample really has full rank
    assert any("π/2 away" in h for h in v.hints)
    v = _sing(robot, r"\sin(2 q_2) = 0", "vx,vy")  # a superset: q2 = ±π/2 is not singular
    assert v.verdict == "incorrect" and abs(abs(v.entries[0]["q"][1]) - np.pi / 2) < 1e-9
    assert _sing(robot, "none", "vx,vy").verdict == "incorrect"
    assert _sing(robot, "none").verdict == "correct"  # with all six rows a 2R arm never loses rank 2


def test_check_singularities_puma_and_stanford():
    puma = dn.load_robot("puma560")
    ok = [r"a_3 \sin\theta_3 + d_4 \cos\theta_3 = 0", "s_5 = 0", r"a_2 C_2 + a_3 C_{23} - d_4 S_{23} = 0"]
    assert _sing(puma, ok).verdict == "correct"
    assert _sing(puma, ["q3 = -1.5238, 1.6178", r"\theta_5 = 0, \pi", ok[2]]).verdict == "correct"
    v = _sing(puma, ok[1:])
    assert v.verdict == "incorrect" and any("q3" in m for m in v.extra["missing"])
    v = _sing(puma, ok[:2])
    assert v.verdict == "incorrect" and any("a2*cos(q2)" in m for m in v.extra["missing"])
    assert _sing(dn.load_robot("stanford"), "sin(q2) = 0; sin(q5) = 0; q3 = 0").verdict == "correct"


@pytest.mark.slow
def test_check_singularities_everywhere_and_unreadable():
    robot = dn.load_robot("report000-6r")  # joints 1 and 2 coaxial: J0 never has rank 6
    assert _sing(robot, "everywhere").verdict == "correct"
    v = _sing(robot, "q3 = 0")
    assert v.verdict == "incorrect" and "every configuration" in v.extra["missing"][0]
    assert _sing(dn.load_robot("planar2r"), "everywhere", "vx,vy").verdict == "incorrect"
    assert _sing(dn.load_robot("planar2r"), "L_1 = 0", "vx,vy").verdict == "unreadable"
    assert _sing(dn.load_robot("planar2r"), "q2 = 0", "vx,foo").verdict == "unreadable"


def _library_forms(robot, rows, rng):
    """A correct claim written from the symbolic analysis in a random form per condition."""
    a = S.singularity_analysis(robot, rows=rows)
    q = S.joint_symbols(robot.dof).q
    out = []
    for c in a.conditions:
        form = rng.integers(4) if c.solutions else 3
        if form == 0:
            for s in c.solutions:  # revolute values shifted by a random multiple of 2π
                turn = 2 * np.pi * (robot.joint_types[int(s.variable[1:]) - 1].value == "revolute")
                out.append(f"{s.variable} = " + ", ".join(repr(float(v + turn * int(rng.integers(-1, 2))))
                                                          for v in s.values))
        elif form == 1:
            out += [f"{s.variable} = " + ", ".join(f"{v:.6f}" for v in s.values) for s in c.solutions]
        elif form == 2:
            out.append(sp.latex(S.shorthand(c.factor, q)) + " = 0")
        else:
            k = sp.Rational(int(rng.integers(1, 9)), int(rng.integers(1, 5))) * (-1) ** int(rng.integers(2))
            out.append(sp.latex(sp.expand(k * c.factor)) + " = 0")
    return out or ["none"]


@settings(max_examples=8 if REDUCED else 20, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(case=st.sampled_from([("planar2r", "vx,vy"), ("report000-planar3r", "vx,vy,wz"), ("puma560", None),
                             ("stanford", None), ("scara", "vx,vy,vz,wz"), ("planar3r", "vx,vy")]),
       seed=st.integers(0, 2**31 - 1))
@pytest.mark.slow
def test_check_never_rejects_correct_singularity_claims(case, seed):
    name, rows = case
    robot = dn.load_robot(name)
    value = _library_forms(robot, rows, np.random.default_rng(seed))
    v = _sing(robot, value, rows, seed=seed)
    assert v.verdict == "correct", (value, v.message)


# --- inverse kinematics ----------------------------------------------------------------------------------


def _derivation_claims(robot):
    """Every joint formula of the symbolic derivation as a claim whose 'where' holds the steps before it."""
    d = S.ik_derivation(robot)
    where, out = {}, []
    for lhs, rhs in d.formulas:
        for sym, e in (list(zip(lhs, rhs)) if isinstance(lhs, sp.MatrixBase) else [(lhs, rhs)]):
            if sym in d.joints:
                out.append({"quantity": "ik_formula", "where": dict(where), "value": f"{sp.latex(sym)} = {sp.latex(e)}"})
            where[sp.latex(sym)] = sp.latex(e)
    return out


@pytest.mark.parametrize("name", ["planar2r", "report000-planar3r", "puma560", "stanford"])
def test_check_ik_formulas_of_the_derivation_are_accepted(name):
    robot = dn.load_robot(name)
    for v in _check(robot, _derivation_claims(robot)):
        assert v.verdict == "correct", v.message


def test_check_ik_formulas_hand_written_forms_and_slips():
    robot = dn.load_robot("planar2r")
    D = {"D": "(p_x^2 + p_y^2 - L_1^2 - L_2^2)/(2 L_1 L_2)"}
    ok = [{"value": r"q_2 = \operatorname{atan2}(\pm\sqrt{1 - D^2}, D)", "where": D},
          {"value": r"\theta_2 = \arccos D", "where": D},
          {"value": r"θ1 = atan2(y, x) - atan2(L_2 \sin\theta_2, L_1 + L_2 \cos\theta_2)"},
          {"joint": 1, "value": r"\operatorname{atan2}(p_y, p_x) - \operatorname{atan2}(L_2 s_2, L_1 + L_2 c_2)"}]
    bad = [{"value": r"q_1 = atan2(p_y, p_x) + atan2(L_2 s_2, L_1 + L_2 c_2)"},
           {"value": r"q_1 = \arctan(p_y / p_x) - atan2(L_2 s_2, L_1 + L_2 c_2)"},
           {"value": r"q_2 = \arccos D", "where": {"D": "(p_x^2 + p_y^2 - L_1^2 + L_2^2)/(2 L_1 L_2)"}}]
    v = _check(robot, [{"quantity": "ik_formula", **c} for c in ok + bad])
    assert [x.verdict for x in v] == ["correct"] * 4 + ["incorrect"] * 3, [x.message for x in v]
    assert "one branch" in v[1].message
    assert any("atan instead of atan2" in h for h in v[5].hints)
    e = v[4].entries[0]  # the claimed q1 with the q2 it was computed from really misses the target
    T = dn.forward_kinematics(robot, np.array(v[4].counterexample["q"]))
    F = dn.forward_kinematics(robot, np.array([e["claimed"], e["given"]["q2"]]))
    assert np.linalg.norm(F[:3, 3] - T[:3, 3]) > 1e-3
    u = _check(robot, [{"quantity": "ik_formula", "value": "q_1 = q_1"}, {"quantity": "ik_formula", "value": "atan2(1, 2)"}])
    assert [x.verdict for x in u] == ["unreadable"] * 2


@pytest.mark.parametrize("name", ["puma560", "planar2r", "scara"])
def test_check_ik_solutions_complete_and_missing(name):
    robot = dn.load_robot(name)
    rng = np.random.default_rng(4)
    q = _case(robot, rng)
    res = dn.analytic_ik(robot, dn.forward_kinematics(robot, q))
    sols = [[f"{x:.6f}" for x in s] for s in res.solutions]
    qtext = ", ".join(repr(float(x)) for x in q)
    (v,) = _check(robot, [{"quantity": "ik_solutions", "q": qtext, "value": sols}])
    assert v.verdict == "correct", v.message
    if len(sols) > 1:
        (v,) = _check(robot, [{"quantity": "ik_solutions", "q": qtext, "value": sols[1:]}])
        assert v.verdict == "incorrect" and v.extra["missing"][0].startswith(res.branches[0])
    wrong = [list(map(float, s)) for s in sols]
    wrong[0][0] += 0.1
    (v,) = _check(robot, [{"quantity": "ik_solutions", "q": qtext, "value": wrong}])
    assert v.verdict == "incorrect" and v.entries[0]["entry"] == [1] and "does not reach" in v.message


# --- dynamics: c and C -----------------------------------------------------------------------------------


@pytest.mark.parametrize("name", ["planar2r", "report000-planar3r"])
def test_check_coriolis_claims_from_the_symbolic_engine(name):
    """c and C from the symbolic Lagrangian (Christoffel symbols) are accepted against the numeric engine's CRBA-
    derivative route; any factorization with C q̇ = c is accepted as a C; a sign slip in c is named."""
    if not hasattr(S, "lagrangian_dynamics"):
        pytest.skip("denavit.symbolic.lagrangian_dynamics is not in this checkout yet")
    robot = dn.load_robot(name)
    t = S.lagrangian_dynamics(robot)
    tex = lambda M: sp.latex(S.shorthand_matrix(M, t.q), mat_str="bmatrix", mat_delim="")  # noqa: E731
    other = sp.ImmutableMatrix(t.C + sp.Matrix(robot.dof, robot.dof, lambda i, j: 0)).as_mutable()
    other[0, 0] += t.qd[1]  # break C, then repair C q̇ = c through column 2
    other[0, 1] -= t.qd[0]
    bad_c = t.c.as_mutable()
    bad_c[1] = -bad_c[1]
    claims = [{"quantity": "c", "value": tex(t.c)}, {"quantity": "C", "value": tex(t.C)},
              {"quantity": "C", "entry": [1, 2], "value": sp.latex(t.C[0, 1])},
              {"quantity": "coriolis_matrix", "value": tex(sp.ImmutableMatrix(other))},
              {"quantity": "M", "entry": [1, 1], "value": sp.latex(t.M[0, 0])},
              {"quantity": "c", "value": tex(sp.ImmutableMatrix(bad_c))}]
    v = _check(robot, claims)
    assert [x.verdict for x in v] == ["correct"] * 5 + ["incorrect"], [x.message for x in v]
    assert "factorization" in v[3].message and [e["entry"] for e in v[5].entries] == [[2]]


def test_christoffel_symbols_of_the_planar_elbow_are_spongs():
    """Spong, Hutchinson, Vidyasagar (2006) Sec. 7.4, the planar elbow with ℓ_c2 = L2 and I2 = 0 (the catalogue's
    point masses at the link ends): c_121 = c_211 = c_221 = h, c_112 = −h, the rest 0, h = −m2 L1 L2 sin q2."""
    robot = dn.load_robot("planar2r")
    h = "-m_2 L_1 L_2 \\sin q_2"
    truth = {(1, 2, 1): h, (2, 1, 1): h, (2, 2, 1): h, (1, 1, 2): f"-({h})", (1, 1, 1): "0", (1, 2, 2): "0",
             (2, 1, 2): "0", (2, 2, 2): "0"}
    claims = [{"quantity": "christoffel", "entry": list(k), "value": v} for k, v in truth.items()]
    assert [v.verdict for v in check_claims(robot, claims).verdicts] == ["correct"] * 8
    wrong = [{"quantity": "christoffel", "entry": [2, 2, 1], "value": "0"}]
    assert check_claims(robot, wrong).verdicts[0].verdict == "incorrect"


def test_christoffel_symbols_equal_finite_differences_of_m():
    """c_ijk = ½(∂M_kj/∂q_i + ∂M_ki/∂q_j − ∂M_ij/∂q_k) with ∂M by central differences of the CRBA's M (a second
    route), on the Puma 560 and the Panda at random q; and C q̇ = Σ c_ijk q̇_i q̇_j is the RNEA's velocity term."""
    from denavit.check import QUANTITIES
    from denavit.check._quantities import Point

    rng = np.random.default_rng(3)
    for name in ("puma560", "panda"):
        robot = dn.load_robot(name)
        n = robot.dof
        q, qd = rng.uniform(-1.5, 1.5, n), rng.uniform(-1, 1, n)
        G = QUANTITIES["christoffel"].truth(Point(robot, q), {})
        eps = 1e-6
        dM = np.stack([(dn.mass_matrix(robot, q + eps * e) - dn.mass_matrix(robot, q - eps * e)) / (2 * eps)
                       for e in np.eye(n)])  # [i, j, k] = ∂M_jk/∂q_i
        fd = np.array([[[0.5 * (dM[i, k, j] + dM[j, k, i] - dM[k, i, j]) for k in range(n)] for j in range(n)]
                       for i in range(n)])
        assert np.allclose(G, fd, atol=1e-6)
        c = np.einsum("ijk,i,j->k", G, qd, qd)
        assert np.allclose(c, dn.coriolis_vector(robot, q, qd), atol=1e-9)
