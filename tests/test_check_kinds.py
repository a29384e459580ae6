"""Claim kinds of the link-by-link routes, energies, det J, the general DH matrix, IK derivations, the symbol g.

Every correct claim is computed here by another route than the one the checker uses: velocities by
differentiating the symbolic frame poses (ⁱωᵢ from Rᵀ Ṙ, ⁱvᵢ = Rᵀ ṗ; the checker propagates link by link),
forces by moving the tip wrench straight to frame i (the checker recurses inward), energies from the textbook
formulas of a planar 3R arm, the DH matrices from Craig's and Spong's books.  Perturbed claims must be caught
with their wrong entries named.
"""

from __future__ import annotations

import numpy as np
import pytest
import sympy as sp
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import denavit as dn
from denavit import symbolic as S
from denavit.check import check_claims

from conftest import REDUCED
from test_check_shapes import dh_frames as _poses  # the test's own DH product

ARMS = ["planar3r", "report000-planar3r", "scara", "stanford", "report000-6r", "puma560", "report004-4-rrp"]
_ARMS_SLOW_6R = [pytest.param(a, marks=pytest.mark.slow) if a == "puma560" else a for a in ARMS]


def _tex(M) -> str:
    return sp.latex(sp.ImmutableMatrix(M), mat_str="bmatrix", mat_delim="")


def _rates(n):
    return sp.Matrix([sp.Symbol(f"qd{k + 1}") for k in range(n)])


def _frame_poses(robot):
    F = S.link_transforms_sym(robot)
    inv0 = F[0].inv()
    return [sp.ImmutableMatrix(inv0 * f) for f in F]  # pose of frame i in {0}


def _derivative(M, q, qd):
    return sum((M.diff(qk) * qdk for qk, qdk in zip(q, qd)), sp.zeros(*M.shape))


def _velocities(robot, i):
    """ⁱωᵢ and ⁱvᵢ by differentiation: skew(ω) = Rᵀ Ṙ, v = Rᵀ ṗ (frame {0} at rest)."""
    q = S.joint_symbols(robot.dof).q
    qd = _rates(robot.dof)
    T = _frame_poses(robot)[i]
    R, p = T[:3, :3], T[:3, 3]
    W = R.T * _derivative(R, q, qd)
    w = sp.Matrix([W[2, 1], W[0, 2], W[1, 0]])
    v = R.T * _derivative(p, q, qd)
    return w, v


def _nonzero_row(vec) -> int:
    """A row of a symbolic vector that is not identically zero (tested at random values of its symbols)."""
    rng = np.random.default_rng(0)
    for r in range(len(vec)):
        e = sp.sympify(vec[r])
        if abs(float(e.subs({s: rng.uniform(0.3, 1.2) for s in e.free_symbols}))) > 1e-6:
            return r
    raise AssertionError("all rows vanish")


def _v(robot, claims, seed=0):
    return check_claims(robot, claims, seed=seed).verdicts


@pytest.mark.parametrize("name", _ARMS_SLOW_6R)
def test_velocity_propagation_vectors_against_differentiation(name):
    robot = dn.load_robot(name)
    claims = []
    last = min(3, robot.n_rows)
    for i in sorted({1, 2, last}):
        w, v = _velocities(robot, i)
        claims += [{"id": f"w{i}", "quantity": "omega", "index": i, "value": _tex(w)},
                   {"id": f"v{i}", "quantity": "velocity", "index": i, "value": _tex(v)}]
    for verdict in _v(robot, claims):
        assert verdict.verdict == "correct", (verdict.id, verdict.message)
    w, v = _velocities(robot, last)
    bad = sp.Matrix(v)
    k = _nonzero_row(bad)
    bad[k] = -bad[k]
    (verdict,) = _v(robot, [{"quantity": "velocity", "index": last, "value": _tex(bad)}])
    assert verdict.verdict == "incorrect" and f"({k + 1})" in verdict.message


def _tip_statics(robot, i, wrench):
    """ⁱfᵢ, ⁱnᵢ directly from the tip wrench (tool axes): f = R_{i,e} f_e, n = R_{i,e} n_e + (p_e − p_i) × f."""
    poses = _frame_poses(robot)
    T_e = poses[-1] * sp.Matrix(robot.tool_matrix)
    Ti = poses[i]
    R_ie = Ti[:3, :3].T * T_e[:3, :3]
    f = R_ie * wrench[:3, 0]
    r = Ti[:3, :3].T * (T_e[:3, 3] - Ti[:3, 3])
    n = R_ie * wrench[3:, 0] + r.cross(f)
    return f, n


@pytest.mark.parametrize("name", ["planar3r", "report000-planar3r", "scara", "report004-4-rrp",
                                  pytest.param("report000-6r", marks=pytest.mark.slow)])
def test_force_propagation_vectors_with_a_symbolic_tip_wrench(name):
    robot = dn.load_robot(name)
    fx, fy, fz, nz = sp.symbols("f_x f_y f_z n_z")
    wrench = sp.Matrix([fx, fy, fz, 0, 0, nz])
    text = "[f_x, f_y, f_z, 0, 0, n_z]"
    claims = []
    for i in sorted({0, 1, robot.n_rows - 1}):
        f, n = _tip_statics(robot, i, wrench)
        claims += [{"id": f"f{i}", "quantity": "force", "index": i, "wrench": text, "value": _tex(f)},
                   {"id": f"n{i}", "quantity": "moment", "index": i, "wrench": text, "value": _tex(n)}]
    for verdict in _v(robot, claims):
        assert verdict.verdict == "correct", (verdict.id, verdict.message)
    f, n = _tip_statics(robot, 1, wrench)
    k = _nonzero_row(n)
    dropped = sp.Matrix(n)
    terms = sp.Add.make_args(sp.expand(n[k]))
    dropped[k] = sp.Add(*terms[1:]) if len(terms) > 1 else 0  # one term dropped
    (verdict,) = _v(robot, [{"quantity": "moment", "index": 1, "wrench": text, "value": _tex(dropped)}])
    assert verdict.verdict == "incorrect" and f"({k + 1})" in verdict.message, verdict.message


@pytest.mark.parametrize("name", ["planar3r", "scara", "report004-4-rrp"])
def test_torques_as_formulas_of_a_symbolic_wrench(name):
    """τ = Jᵀ F with J from differentiating the position and the rotation (not the checker's J)."""
    robot = dn.load_robot(name)
    q = S.joint_symbols(robot.dof).q
    T = _frame_poses(robot)[-1] * sp.Matrix(robot.tool_matrix)
    Jv = T[:3, 3].jacobian(sp.Matrix(q))
    cols = []
    for k, qk in enumerate(q):
        W = T[:3, :3].diff(qk) * T[:3, :3].T
        cols.append([W[2, 1], W[0, 2], W[1, 0]])
    J = Jv.col_join(sp.Matrix(cols).T)
    F = sp.Matrix(sp.symbols("F_x F_y F_z M_x M_y M_z"))
    tau = J.T * F
    claims = [{"quantity": "torques", "wrench": "F_x, F_y, F_z, M_x, M_y, M_z", "value": _tex(tau)}]
    bad = sp.Matrix(tau)
    bad[0] = bad[0] + sp.Symbol("F_x") * 0.25
    claims.append({"quantity": "tau", "wrench": "F_x, F_y, F_z, M_x, M_y, M_z", "value": _tex(bad)})
    good, wrong = _v(robot, claims)
    assert good.verdict == "correct", good.message
    assert wrong.verdict == "incorrect" and "(1)" in wrong.message


# --- planar 3R from the textbook: COM, energies, gravity with the symbol g ----------------------------

P3 = "report000-planar3r"  # links L_i, COM at Lc_i from joint i, masses m_i, I_i about the COM, gravity −g ŷ
_XC = [r"Lc_1 c_1", r"L_1 c_1 + Lc_2 c_{12}", r"L_1 c_1 + L_2 c_{12} + Lc_3 c_{123}"]
_YC = [r"Lc_1 s_1", r"L_1 s_1 + Lc_2 s_{12}", r"L_1 s_1 + L_2 s_{12} + Lc_3 s_{123}"]
_W = [r"\dot\theta_1", r"(\dot\theta_1 + \dot\theta_2)", r"(\dot\theta_1 + \dot\theta_2 + \dot\theta_3)"]
_VX = [r"-Lc_1 s_1 \dot\theta_1", r"-L_1 s_1 \dot\theta_1 - Lc_2 s_{12} (\dot\theta_1 + \dot\theta_2)",
       r"-L_1 s_1 \dot\theta_1 - L_2 s_{12} (\dot\theta_1 + \dot\theta_2) - Lc_3 s_{123} " + _W[2]]
_VY = [r"Lc_1 c_1 \dot\theta_1", r"L_1 c_1 \dot\theta_1 + Lc_2 c_{12} (\dot\theta_1 + \dot\theta_2)",
       r"L_1 c_1 \dot\theta_1 + L_2 c_{12} (\dot\theta_1 + \dot\theta_2) + Lc_3 c_{123} " + _W[2]]
_K_TERMS = [rf"\frac{{1}}{{2}} m_{i + 1} (({_VX[i]})^2 + ({_VY[i]})^2)" for i in range(3)] + [
    rf"\frac{{1}}{{2}} I_{i + 1} {_W[i]}^2" for i in range(3)]
_K = " + ".join(_K_TERMS)
_V = " + ".join(rf"m_{i + 1} g ({_YC[i]})" for i in range(3))


@pytest.mark.slow
def test_planar3r_centres_of_mass_and_energies_from_the_textbook():
    robot = dn.load_robot(P3)
    claims = [{"id": f"pc{i + 1}", "quantity": "com_position", "index": i + 1, "value": f"[{_XC[i]}, {_YC[i]}, 0]"}
              for i in range(3)]
    claims += [{"id": f"vc{i + 1}", "quantity": "com_velocity", "index": i + 1, "value": f"[{_VX[i]}, {_VY[i]}, 0]"}
               for i in range(3)]
    claims += [{"id": "K", "quantity": "kinetic_energy", "value": "K = " + _K},
               {"id": "V", "quantity": "potential_energy", "value": "V = " + _V},
               {"id": "L", "quantity": "lagrangian", "value": f"L = {_K} - ({_V})"},
               {"id": "V at q", "quantity": "V", "q": r"(30^\circ, -45^\circ, 60^\circ)",
                "value": _V.replace(" s_{123}", r" \sin(\theta_1+\theta_2+\theta_3)").replace(" s_{12}", r" \sin(\theta_1+\theta_2)")
                .replace(" s_1", r" \sin\theta_1")}]
    for verdict in _v(robot, claims):
        assert verdict.verdict == "correct", (verdict.id, verdict.message)
    wrong = [{"id": "K without I3", "quantity": "K", "value": " + ".join(_K_TERMS[:-1])},
             {"id": "V sign", "quantity": "V", "value": "-(" + _V + ")"},
             {"id": "L = K + V", "quantity": "L", "value": f"{_K} + {_V}"},
             {"id": "vc3 with L3", "quantity": "com_velocity", "index": 3,
              "value": f"[{_VX[2].replace('Lc_3', 'L_3')}, {_VY[2]}, 0]"}]
    for verdict in _v(robot, wrong):
        assert verdict.verdict == "incorrect", (verdict.id, verdict.message)
    assert "(1)" in _v(robot, wrong[3:])[0].message


def test_gravity_symbol_g_in_gravity_torques():
    """g(q) = ∂V/∂q with V written with the symbol g; the checker varies g, so 9.81 written for g is still fine
    but a wrong factor is not."""
    robot = dn.load_robot(P3)
    q = sp.symbols("q1:4")
    m, L, Lc, g = sp.symbols("m1:4"), sp.symbols("L1:4"), sp.symbols("Lc1:4"), sp.Symbol("g")
    a = [q[0], q[0] + q[1], q[0] + q[1] + q[2]]
    y = [Lc[0] * sp.sin(a[0]), L[0] * sp.sin(a[0]) + Lc[1] * sp.sin(a[1]),
         L[0] * sp.sin(a[0]) + L[1] * sp.sin(a[1]) + Lc[2] * sp.sin(a[2])]
    V = sum(mi * g * yi for mi, yi in zip(m, y))
    tau = sp.Matrix([V.diff(qk) for qk in q])
    (ok,) = _v(robot, [{"quantity": "gravity", "value": _tex(tau)}])
    assert ok.verdict == "correct", ok.message
    (ok2,) = _v(robot, [{"quantity": "g", "value": _tex(tau.subs(g, sp.Rational(981, 100)))}])
    assert ok2.verdict == "correct", ok2.message
    (bad,) = _v(robot, [{"quantity": "g", "value": _tex(tau.subs(g, 2 * g))}])
    assert bad.verdict == "incorrect"


def test_det_jacobian_and_its_factors():
    robot = dn.load_robot(P3)  # rows (x, y, α) of a planar 3R arm: det J = L1 L2 sin θ2 (L1 = 1, L2 = 0.8)
    good = [{"quantity": "det_jacobian", "rows": "vx,vy,wz", "value": r"L_1 L_2 \sin\theta_2"},
            {"quantity": "det", "rows": "planar", "value": ["L_1", "L_2", r"\sin\theta_2"]},
            {"quantity": "detJ", "rows": "vx,vy,wz", "value": r"\det J = L_1 L_2 s_2", "q": "0.4, 1.1, -2"},
            {"quantity": "detJ", "rows": "vx,vy,wz", "value": r"0.8 \sin(1.1)", "q": "0.4, 1.1, -2"}]
    for verdict in _v(robot, good):
        assert verdict.verdict == "correct", verdict.message
    for value in [r"-L_1 L_2 \sin\theta_2", r"L_1 L_2 \cos\theta_2", ["L_1", r"\sin\theta_2"]]:
        (verdict,) = _v(robot, [{"quantity": "det_jacobian", "rows": "vx,vy,wz", "value": value}])
        assert verdict.verdict == "incorrect", value
    (verdict,) = _v(robot, [{"quantity": "det_jacobian", "value": "1"}])
    assert verdict.verdict == "unreadable" and "square" in verdict.message


_CRAIG = (r"\begin{bmatrix} c\theta_i & -s\theta_i & 0 & a_{i-1} \\ s\theta_i c\alpha_{i-1} & c\theta_i c\alpha_{i-1}"
          r" & -s\alpha_{i-1} & -s\alpha_{i-1} d_i \\ s\theta_i s\alpha_{i-1} & c\theta_i s\alpha_{i-1} & c\alpha_{i-1}"
          r" & c\alpha_{i-1} d_i \\ 0 & 0 & 0 & 1 \end{bmatrix}")
_SPONG = (r"A_i = \begin{bmatrix} \cos\theta_i & -\sin\theta_i\cos\alpha_i & \sin\theta_i\sin\alpha_i & a_i\cos\theta_i \\"
          r" \sin\theta_i & \cos\theta_i\cos\alpha_i & -\cos\theta_i\sin\alpha_i & a_i\sin\theta_i \\"
          r" 0 & \sin\alpha_i & \cos\alpha_i & d_i \\ 0 & 0 & 0 & 1 \end{bmatrix}")


def test_general_dh_matrix_both_conventions_and_slips():
    std, mdh = dn.load_robot("puma560"), dn.load_robot("report000-6r")
    assert _v(std, [{"quantity": "dh_matrix", "value": _SPONG}])[0].verdict == "correct"
    assert _v(mdh, [{"quantity": "dh_matrix", "value": _CRAIG}])[0].verdict == "correct"
    assert _v(std, [{"quantity": "dh_matrix", "convention": "modified", "value": _CRAIG}])[0].verdict == "correct"
    (v,) = _v(std, [{"quantity": "dh_matrix", "value": _CRAIG}])
    assert v.verdict == "incorrect" and "modified" in v.hints[0]
    (v,) = _v(std, [{"quantity": "dh_matrix", "value": _SPONG.replace(r"-\cos\theta_i\sin\alpha_i", r"\cos\theta_i\sin\alpha_i")}])
    assert v.verdict == "incorrect" and "(2, 3)" in v.message


@settings(max_examples=10 if REDUCED else 40, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(conv=st.sampled_from(["standard", "modified"]), entry=st.tuples(st.integers(0, 2), st.integers(0, 3)),
       slip=st.sampled_from(["none", "sign", "swap_trig"]))
def test_general_dh_matrix_property(conv, entry, slip):
    text = _SPONG if conv == "standard" else _CRAIG
    from denavit.check import split_matrix

    cells = split_matrix(text)
    i, j = entry
    cell = cells[i][j]
    robot = dn.load_robot("puma560" if conv == "standard" else "report000-6r")
    if slip == "sign" and cell.strip() != "0":
        cells[i][j] = f"-({cell})"
    elif slip == "swap_trig" and ("cos" in cell or "sin" in cell):
        cells[i][j] = cell.replace("cos", "TMP").replace("sin", "cos").replace("TMP", "sin")
    else:
        slip = "none"
    value = r"\begin{bmatrix}" + r" \\ ".join(" & ".join(r) for r in cells) + r"\end{bmatrix}"
    (v,) = _v(robot, [{"quantity": "dh_matrix", "value": value}])
    if slip == "none":
        assert v.verdict == "correct", v.message
    else:
        assert v.verdict == "incorrect" and f"({i + 1}, {j + 1})" in v.message, v.message


# --- IK derivation equations with named intermediate quantities ------------------------------------------


def test_ik_derivation_with_the_wrist_centre():
    """Report 003's arm (spherical wrist, d6 past the wrist centre): q1 = atan2(P_y, P_x) with P the wrist centre."""
    robot = dn.load_robot("elbow-6r-deg")
    claims = [{"id": "undeclared", "quantity": "ik_formula", "value": r"\arctan(P_y, P_x) = q_1"},
              {"id": "declared", "quantity": "ik_formula", "point": "wrist", "value": r"\arctan(P_y, P_x) = q_1"},
              {"id": "where", "quantity": "ik_formula", "where": {"x_c": "p_x - d_6 a_x", "y_c": "p_y - d_6 a_y"},
               "value": r"q_1 = \operatorname{atan2}(y_c, x_c)"},
              {"id": "cos", "quantity": "ik_formula", "point": "wrist",
               "value": r"\sin(\theta_3) = -\frac{P_x^2 + P_y^2 + (P_z - d_1)^2 - a_2^2 - d_4^2}{2 a_2 d_4}"},
              {"id": "swapped", "quantity": "ik_formula", "point": "wrist", "value": r"\arctan(P_x, P_y) = q_1"},
              {"id": "bad where", "quantity": "ik_formula", "where": {"x_c": "p_x", "y_c": "p_y"},
               "value": r"q_1 = \operatorname{atan2}(x_c, y_c)"}]
    v = {x.id: x for x in _v(robot, claims)}
    assert v["undeclared"].verdict == "ambiguous" and "wrist" in v["undeclared"].message
    for k in ("declared", "where", "cos"):
        assert v[k].verdict == "correct", (k, v[k].message)
    for k in ("swapped", "bad where"):
        assert v[k].verdict == "incorrect", (k, v[k].message)
    res = check_claims(robot, claims)
    assert res.to_json()["summary"]["ambiguous"] == 1


def test_ik_formula_without_a_wrist_offset_is_never_ambiguous():
    robot = dn.load_robot("planar2r")
    (v,) = _v(robot, [{"quantity": "ik_formula", "value": r"\operatorname{atan2}(p_x, p_y) = \theta_1"}])
    assert v.verdict == "incorrect"


def test_example_propagation_file_from_craig(tmp_path, capsys):
    """examples/claims/report004-propagation.yaml (Craig's examples 5.3 and 5.7): all right but the marked slip."""
    import json
    from pathlib import Path

    from denavit.cli import main

    path = Path(__file__).resolve().parents[1] / "examples" / "claims" / "report004-propagation.yaml"
    assert main(["check", "planar2r-mdh", str(path), "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    verdicts = {c["id"]: c for c in data["claims"]}
    slip = verdicts.pop("a slip (the sign of s2 in 1f1)")
    assert all(c["verdict"] == "correct" for c in verdicts.values()), verdicts
    assert slip["verdict"] == "incorrect" and slip["entries"][0]["entry"] == [1]
    assert set(slip["counterexample"]["symbols"]) == {"fx", "fy"}


def test_text_output_of_new_kinds_does_not_fail():
    from denavit.check import verdicts_text

    res = check_claims(dn.load_robot("puma560"), [{"quantity": "dh_matrix", "value": _CRAIG},
                                                  {"quantity": "force", "index": 1, "wrench": "F_x, 0, 0",
                                                   "value": "[F_x, 0, 0]"}])
    text = verdicts_text(res)
    assert "counterexample: a = " in text and "Fx = " in text


# --- property: numeric claims at random q from an independent numeric route ------------------------------


@settings(max_examples=10 if REDUCED else 40, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(name=st.sampled_from(ARMS), seed=st.integers(0, 2**31 - 1), kind=st.sampled_from(["omega", "velocity",
       "force", "moment"]), broken=st.booleans())
def test_propagation_claims_at_random_q_never_rejected_and_slips_named(name, seed, kind, broken):
    robot = dn.load_robot(name)
    rng = np.random.default_rng(seed)
    q, qd = rng.uniform(-2, 2, robot.dof), rng.normal(size=robot.dof)
    F = rng.normal(size=6)
    i = int(rng.integers(0, robot.n_rows + 1))
    P = _poses(robot, q)
    B = np.linalg.inv(P[0])  # frame {0} at rest: everything relative to it
    if kind in ("omega", "velocity"):
        h = 1e-5
        Pp, Pm = _poses(robot, q + h * qd), _poses(robot, q - h * qd)
        R, Rd = (B @ P[i])[:3, :3], ((B @ Pp[i]) - (B @ Pm[i]))[:3, :3] / (2 * h)
        pd = ((B @ Pp[i]) - (B @ Pm[i]))[:3, 3] / (2 * h)
        W = R.T @ Rd
        value = np.array([W[2, 1], W[0, 2], W[1, 0]]) if kind == "omega" else R.T @ pd
    else:
        Te = P[-1] @ np.asarray(robot.tool_matrix, dtype=float)
        R_ie = P[i][:3, :3].T @ Te[:3, :3]
        f = R_ie @ F[:3]
        value = f if kind == "force" else R_ie @ F[3:] + np.cross(P[i][:3, :3].T @ (Te[:3, 3] - P[i][:3, 3]), f)
    value = np.round(value, 6) + 0.0
    j = int(rng.integers(0, 3))
    if broken:
        value[j] += 0.01
    claim = {"quantity": kind, "index": i, "q": ", ".join(repr(float(x)) for x in q),
             "value": [f"{x:.6f}" for x in value]}
    claim["qd" if kind in ("omega", "velocity") else "wrench"] = ", ".join(
        repr(float(x)) for x in (qd if kind in ("omega", "velocity") else F))
    (v,) = _v(robot, [claim])
    if broken:
        assert v.verdict == "incorrect" and f"({j + 1})" in v.message, v.message
    else:
        assert v.verdict == "correct", v.message


def test_potential_energy_up_to_a_constant_and_rotation_blocks():
    robot = dn.load_robot(P3)
    (v,) = _v(robot, [{"quantity": "V", "value": _V + " + 3 m_1 g"}])
    assert v.verdict == "correct" and "constant" in v.message
    (v,) = _v(robot, [{"quantity": "V", "value": _V + r" + m_1 g \cos\theta_1"}])
    assert v.verdict == "incorrect"
    q = np.array([0.3, -0.2, 0.9])
    R = _poses(robot, q)[3][:3, :3]
    (v,) = _v(robot, [{"quantity": "T", "q": "0.3, -0.2, 0.9", "value": R.tolist()}])
    assert v.verdict == "correct" and "rotation block" in v.message


def test_propagation_slips_are_named():
    """ⁱvᵢ written in base axes, or the vector of the neighbouring frame: incorrect, with the slip as a hint."""
    robot = dn.load_robot(P3)
    v2_base = _VX[1].replace("Lc_2", "L_2"), _VY[1].replace("Lc_2", "L_2")  # ṗ of frame 2's origin, world axes
    v = _v(robot, [{"quantity": "velocity", "index": 2, "value": f"[{v2_base[0]}, {v2_base[1]}, 0]"},
                   {"quantity": "omega", "index": 2, "value": r"[0, 0, \dot\theta_1]"}])
    assert v[0].verdict == "incorrect" and any("base axes" in h for h in v[0].hints), v[0].hints
    assert v[1].verdict == "incorrect" and any("frame {1}" in h for h in v[1].hints), v[1].hints


def test_jacobian_ingredients_axes_and_origins():
    """z and p of J_i = [z_{i-1} × (p − p_{i-1}); z_{i-1}] from the test's own DH product (puma560, standard DH)."""
    robot = dn.load_robot("puma560")
    q = np.array([0.3, -0.8, 1.1, 0.4, -0.6, 0.2])
    P = _poses(robot, q)
    claims = [{"quantity": "z", "index": k + 1, "q": ", ".join(repr(float(x)) for x in q), "value": P[k][:3, 2].tolist()}
              for k in range(6)]
    claims += [{"quantity": "p", "index": k, "q": ", ".join(repr(float(x)) for x in q), "value": P[k][:3, 3].tolist()}
               for k in range(7)]
    assert [v.verdict for v in _v(robot, claims)] == ["correct"] * 13
    bad = dict(claims[2], value=P[3][:3, 2].tolist())  # z_3 given for joint 3 (standard DH: it is z_2)
    (v,) = _v(robot, [bad])
    assert v.verdict == "incorrect"


_CRAIG_EOM = [  # Craig, Introduction to Robotics, eq. 6.60: point masses at the distal ends, gravity −g ŷ0
    r"\tau_1 = m_2 L_2^2 (\ddot\theta_1 + \ddot\theta_2) + m_2 L_1 L_2 c_2 (2 \ddot\theta_1 + \ddot\theta_2)"
    r" + (m_1 + m_2) L_1^2 \ddot\theta_1 - m_2 L_1 L_2 s_2 \dot\theta_2^2 - 2 m_2 L_1 L_2 s_2 \dot\theta_1"
    r" \dot\theta_2 + m_2 L_2 g c_{12} + (m_1 + m_2) L_1 g c_1",
    r"\tau_2 = m_2 L_1 L_2 c_2 \ddot\theta_1 + m_2 L_1 L_2 s_2 \dot\theta_1^2 + m_2 L_2 g c_{12}"
    r" + m_2 L_2^2 (\ddot\theta_1 + \ddot\theta_2)",
]


def test_equations_of_motion_of_craigs_two_link_arm():
    robot = dn.load_robot("planar2r")
    (v,) = _v(robot, [{"quantity": "equations_of_motion", "value": _CRAIG_EOM}])
    assert v.verdict == "correct", v.message
    (v,) = _v(robot, [{"quantity": "eom", "q": "0.3, -0.4", "qd": "0, 0", "qdd": "0, 0", "value": [
        "(m_1 + m_2) L_1 g \\cos(0.3) + m_2 L_2 g \\cos(-0.1)", "m_2 L_2 g \\cos(-0.1)"]}])
    assert v.verdict == "correct", v.message
    slip = [_CRAIG_EOM[0], _CRAIG_EOM[1].replace(r"+ m_2 L_1 L_2 s_2 \dot\theta_1^2", r"- m_2 L_1 L_2 s_2 \dot\theta_1^2")]
    (v,) = _v(robot, [{"quantity": "eom", "value": slip}])
    assert v.verdict == "incorrect" and "(2)" in v.message


@pytest.mark.slow
def test_equations_of_motion_of_the_planar_3r_by_lagrange():
    """Report 000's planar 3R: d/dt ∂L/∂q̇ − ∂L/∂q by sympy from the textbook L = K − V (COM at Lc_i, I_i)."""
    robot = dn.load_robot(P3)
    t = sp.Symbol("t")
    th = [sp.Function(f"th{k}")(t) for k in range(1, 4)]
    m, L, Lc, I, g = sp.symbols("m1:4"), sp.symbols("L1:4"), sp.symbols("Lc1:4"), sp.symbols("I1:4"), sp.Symbol("g")
    a = [th[0], th[0] + th[1], th[0] + th[1] + th[2]]
    x = [Lc[0] * sp.cos(a[0]), L[0] * sp.cos(a[0]) + Lc[1] * sp.cos(a[1]),
         L[0] * sp.cos(a[0]) + L[1] * sp.cos(a[1]) + Lc[2] * sp.cos(a[2])]
    y = [Lc[0] * sp.sin(a[0]), L[0] * sp.sin(a[0]) + Lc[1] * sp.sin(a[1]),
         L[0] * sp.sin(a[0]) + L[1] * sp.sin(a[1]) + Lc[2] * sp.sin(a[2])]
    K = sum(m[i] * (x[i].diff(t) ** 2 + y[i].diff(t) ** 2) / 2 + I[i] * a[i].diff(t) ** 2 / 2 for i in range(3))
    V = sum(m[i] * g * y[i] for i in range(3))
    Lag = K - V
    eqs = [(Lag.diff(th[k].diff(t)).diff(t) - Lag.diff(th[k])) for k in range(3)]
    q, qd, qdd = sp.symbols("q1:4"), sp.symbols("qd1:4"), sp.symbols("qdd1:4")
    subs = {}
    for k in range(3):
        subs[th[k].diff(t, 2)] = qdd[k]
    eqs = [e.subs(subs) for e in eqs]
    eqs = [e.subs({th[k].diff(t): qd[k] for k in range(3)}) for e in eqs]
    eqs = [e.subs({th[k]: q[k] for k in range(3)}) for e in eqs]
    value = [sp.latex(e) for e in eqs]
    (v,) = _v(robot, [{"quantity": "eom", "value": value}])
    assert v.verdict == "correct", v.message
    value[2] = sp.latex(eqs[2] - I[2] * qdd[0])
    (v,) = _v(robot, [{"quantity": "eom", "value": value}])
    assert v.verdict == "incorrect" and "(3)" in v.message


def test_energy_slips_are_named():
    robot = dn.load_robot(P3)
    no_rot = " + ".join(_K_TERMS[:3])
    v = _v(robot, [{"quantity": "K", "value": no_rot}, {"quantity": "K", "value": f"2 ({_K})"},
                   {"quantity": "L", "value": f"{_K} + {_V}"}])
    assert [x.verdict for x in v] == ["incorrect"] * 3
    assert any("rotational" in h for h in v[0].hints), v[0].hints
    assert any("½ is missing" in h for h in v[1].hints), v[1].hints
    assert any("K + V" in h for h in v[2].hints), v[2].hints


ARM_WITH_G = """name: two-link-g
convention: standard
parameters: {L1: 0.7, L2: 0.5, m1: 1.5, m2: 0.8, g: 9.81}
joints:
  - {a: L1, alpha: 0, d: 0, theta: q, inertia: {mass: m1, com: [0, 0, 0], inertia: [0, 0, 0, 0, 0, 0]}}
  - {a: L2, alpha: 0, d: 0, theta: q, inertia: {mass: m2, com: [0, 0, 0], inertia: [0, 0, 0, 0, 0, 0]}}
gravity: [0, -g, 0]
"""


def test_gravity_as_a_parameter_g_of_the_robot_file(tmp_path):
    """gravity: [0, -g, 0] with a parameter g: a claim in g is checked at other values of g too (Craig eq. 6.60's
    gravity terms, point masses at the link ends)."""
    path = tmp_path / "arm.yaml"
    path.write_text(ARM_WITH_G)
    robot = dn.load_robot(str(path))
    assert robot.has_dynamics, "the test arm must carry masses"
    good = [r"(m_1 + m_2) L_1 g c_1 + m_2 L_2 g c_{12}", r"m_2 L_2 g c_{12}"]
    (v,) = _v(robot, [{"quantity": "gravity", "value": good}])
    assert v.verdict == "correct", v.message
    (v,) = _v(robot, [{"quantity": "gravity", "value": [t.replace("g", "2 g") for t in good]}])
    assert v.verdict == "incorrect"
    (v,) = _v(robot, [{"quantity": "gravity", "value": [good[0], "m_2 L_2 9.81 c_{12} + 0 g"]}])
    assert v.verdict == "incorrect" and any("parameter" in h for h in v.hints), v.hints


def test_det_written_as_the_determinant_of_a_matrix():
    """Report 004's layout: det J = |J_v| written as a vmatrix of ³J's rows (x, y) (textbook planar 3R, tool axes)."""
    robot = dn.load_robot(P3)
    a = [r"L_1 s_{23} + L_2 s_3", r"L_2 s_3", "0", r"L_1 c_{23} + L_2 c_3 + L_3", r"L_2 c_3 + L_3", "L_3", "1", "1", "1"]
    vm = (r"\begin{vmatrix} " + " & ".join(a[0:3]) + r" \\ " + " & ".join(a[3:6]) + r" \\ " + " & ".join(a[6:9])
          + r" \end{vmatrix}")
    v = _v(robot, [{"quantity": "det", "rows": "planar", "frame": "tool", "value": vm},
                   {"quantity": "det", "rows": "planar", "value": vm},  # det is the same in base axes (a rotation)
                   {"quantity": "det", "rows": "planar", "value": vm.replace("L_2 s_3 &", "-L_2 s_3 &", 1)}])
    assert [x.verdict for x in v] == ["correct", "correct", "incorrect"], [x.message for x in v]


@pytest.mark.parametrize("name", ["planar2r-mdh", pytest.param("report000-planar3r", marks=pytest.mark.slow),
                                  pytest.param("scara", marks=pytest.mark.slow)])
def test_the_correct_formula_given_for_a_wrong_propagation_claim_is_itself_correct(name):
    robot = dn.load_robot(name)
    wrong = [{"quantity": "velocity", "index": 2, "value": r"[\dot\theta_1, 0, 0]"},
             {"quantity": "omega", "index": robot.n_rows, "value": r"[0, \dot\theta_2, 0]"},
             {"quantity": "moment", "index": 1, "wrench": "[f_x, f_y, 0, 0, 0, n_z]", "value": "[0, 0, f_x]"},
             {"quantity": "force", "index": 0, "wrench": "[F_1, 0, F_3]", "value": "[F_3, 0, 0]"}]
    for claim, v in zip(wrong, _v(robot, wrong)):
        assert v.verdict == "incorrect", v.message
        formula = v.extra.get("expected_latex")
        assert formula, (claim, "no correct formula given")
        (again,) = _v(robot, [{**claim, "value": formula}])
        assert again.verdict == "correct", (claim, formula, again.message)


# --- relations: textbook identities of the Jacobian and statics ------------------------------------------

_STD_COLUMN = r"J_i = \begin{bmatrix} z_{i-1} \times (p - p_{i-1}) \\ z_{i-1} \end{bmatrix}"  # Siciliano eq. 3.30
_MDH_COLUMN = r"J_i = \begin{bmatrix} z_{i} \times (p_e - p_{i}) \\ z_{i} \end{bmatrix}"  # Craig's frames: axis z_i


@pytest.mark.parametrize("name", ["puma560", "stanford", "report000-6r", "report004-4-rrp", "scara"])
def test_relations_of_the_textbook(name):
    robot = dn.load_robot(name)
    std = robot.convention is dn.Convention.STANDARD
    right, wrong = (_STD_COLUMN, _MDH_COLUMN) if std else (_MDH_COLUMN, _STD_COLUMN)
    prism = (r"J_i = [z_{i-1}; 0]" if std else r"J_i = [z_{i}; 0]")
    claims = [{"id": "column rule", "quantity": "relation", "value": right},
              {"id": "statics", "quantity": "relation", "value": r"\boldsymbol\tau = \mathbf{J}^T \mathbf{F}"},
              {"id": "twist", "quantity": "relation", "value": r"\begin{bmatrix} v \\ \omega \end{bmatrix} = J \dot q"},
              {"id": "rows", "quantity": "relation", "value": r"\omega = J_\omega \dot\theta"},
              {"id": "wrong frames", "quantity": "relation", "value": wrong},
              {"id": "no transpose", "quantity": "relation", "value": r"\tau = J F"},
              {"id": "v from all of J", "quantity": "relation", "value": r"v = J \dot q"}]
    if any(t is dn.JointType.PRISMATIC for t in robot.joint_types):
        claims.append({"id": "prismatic rule", "quantity": "relation", "joints": "prismatic", "value": prism})
    v = {x.id: x for x in _v(robot, claims)}
    for k in ("column rule", "statics", "twist", "rows", "prismatic rule"):
        if k in v:
            assert v[k].verdict == "correct", (k, v[k].message)
    assert v["wrong frames"].verdict == "incorrect", v["wrong frames"].message
    assert v["no transpose"].verdict == "incorrect"
    assert v["v from all of J"].verdict == "incorrect" and "shape" in v["v from all of J"].message


def test_relation_readers_refuse_what_they_cannot_read():
    robot = dn.load_robot("puma560")
    bad = [r"\tau", r"\tau = K F", r"J_x = 1", r"{}^3 J = J", "(" * 60 + "J" + ")" * 60 + " = J", r"\tau = J^{2} F"]
    for verdict in _v(robot, [{"quantity": "relation", "value": b} for b in bad]):
        assert verdict.verdict == "unreadable", verdict.message
    (v,) = _v(robot, [{"quantity": "relation", "joints": "prismatic", "value": "J_i = [z_{i-1}; 0]"}])
    assert v.verdict == "unreadable" and "no prismatic" in v.message


def test_example_ik_file_of_report_003(capsys):
    """examples/claims/report003-ik.yaml (Spong's decoupling): all correct but the undeclared P, which is ambiguous."""
    import json
    from pathlib import Path

    from denavit.cli import main

    path = Path(__file__).resolve().parents[1] / "examples" / "claims" / "report003-ik.yaml"
    assert main(["check", "elbow-6r-deg", str(path), "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    verdicts = {c["id"]: c["verdict"] for c in data["claims"]}
    assert verdicts.pop("q1 written as in the report (P undeclared)") == "ambiguous"
    assert set(verdicts.values()) == {"correct"}, verdicts


@pytest.mark.slow
@pytest.mark.parametrize("quantity", ["gravity", "M"])
def test_the_correct_dynamics_formula_given_is_itself_correct_and_keeps_g(quantity):
    robot = dn.load_robot(P3)
    (v,) = _v(robot, [{"quantity": quantity, "value": [["m_1 g c_1"] * (3 if quantity == "M" else 1)] * 3}])
    assert v.verdict == "incorrect"
    formula = v.extra.get("expected_latex")
    assert formula and ("981" not in formula) and (quantity == "M" or "g" in formula), formula
    (again,) = _v(robot, [{"quantity": quantity, "value": formula}])
    assert again.verdict == "correct", (formula, again.message)
