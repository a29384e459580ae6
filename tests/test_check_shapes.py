"""Claims checker: a bad claim gets its own verdict, wrong shapes are wrong results, student notation is read.

Truths are written from the textbook (the planar 3R arm: x = L1 c1 + L2 c12 + L3 c123, …) or computed here by
an independent product of DH matrices, never copied from denavit's output.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import denavit as dn
from denavit.check import check_claims

from conftest import REDUCED

P3 = "report000-planar3r"  # standard DH, rows (L_i, 0, 0, q_i); L1 = 1, L2 = 0.8, L3 = 0.6


def _dh(conv, th, d, a, al):
    ct, st_, ca, sa = math.cos(th), math.sin(th), math.cos(al), math.sin(al)
    if conv == "standard":
        return np.array([[ct, -st_ * ca, st_ * sa, a * ct], [st_, ct * ca, -ct * sa, a * st_], [0, sa, ca, d], [0, 0, 0, 1]])
    return np.array([[ct, -st_, 0, a], [st_ * ca, ct * ca, -sa, -sa * d], [st_ * sa, ct * sa, ca, ca * d], [0, 0, 0, 1]])


def dh_frames(robot, q):
    """World poses of DH frames 0 … N (base applied, tool not): an independent product of the DH matrices
    written above (revolute and prismatic joints)."""
    T, k, out = np.asarray(robot.base_matrix, dtype=float), 0, []
    out.append(T)
    for link in robot.links:
        th, d = link.theta, link.d
        if link.is_joint:
            if link.joint is dn.JointType.REVOLUTE:
                th += q[k]
            else:
                d += q[k]
            k += 1
        T = T @ _dh(robot.convention.value, th, d, link.a, link.alpha)
        out.append(T)
    return out


def _fk(robot, q):
    """An independent forward kinematics: :func:`dh_frames`' last frame, then the tool."""
    return dh_frames(robot, q)[-1] @ np.asarray(robot.tool_matrix, dtype=float)


def _planar3r_j(q, L=(1.0, 0.8, 0.6)):
    """Textbook planar 3R Jacobian rows (x, y, α)."""
    a = np.cumsum(q)
    s, c = np.sin(a), np.cos(a)
    return np.array([[-L[0] * s[0] - L[1] * s[1] - L[2] * s[2], -L[1] * s[1] - L[2] * s[2], -L[2] * s[2]],
                     [L[0] * c[0] + L[1] * c[1] + L[2] * c[2], L[1] * c[1] + L[2] * c[2], L[2] * c[2]],
                     [1.0, 1.0, 1.0]])


def _v(claims, name=P3, seed=0):
    return check_claims(dn.load_robot(name), claims, seed=seed).verdicts


def _q(q):
    return ", ".join(repr(float(x)) for x in q)


def test_one_bad_claim_never_aborts_the_file():
    q = np.array([0.3, -0.7, 1.1])
    J = _planar3r_j(q)
    x = 1.0 * math.cos(0.3) + 0.8 * math.cos(-0.4) + 0.6 * math.cos(0.7)
    claims = [
        {"id": "good", "quantity": "jacobian", "q": _q(q), "value": J.tolist()},
        {"id": "wrong", "quantity": "position", "q": _q(q), "entry": 1, "value": x + 0.5},
        {"id": "garbage", "quantity": "position", "q": _q(q), "value": r"\frac{1}{"},
        {"id": "no value", "quantity": "position"},
        {"id": "not a mapping"} and "text",
        {"id": "entry of twist", "quantity": "twist", "q": _q(q), "qd": "1, 2, 3", "entry": 6, "value": 7},
        {"id": "entry of J", "quantity": "J", "q": _q(q), "entry": [6, 2], "value": 7},
        {"id": "good x", "quantity": "position", "q": _q(q), "entry": 1, "value": x},
    ]
    v = {x.id: x for x in _v(claims)}
    assert len(v) == len(claims)
    assert v["good"].verdict == "correct", v["good"].message
    assert v["good x"].verdict == "correct"
    assert v["wrong"].verdict == "incorrect"
    assert v["entry of twist"].verdict == "incorrect" and v["entry of twist"].entries[0]["expected"] == pytest.approx(6)
    assert v["entry of J"].verdict == "incorrect" and v["entry of J"].entries[0]["expected"] == pytest.approx(1)
    for k in ("garbage", "no value", "claim 5"):
        assert v[k].verdict == "unreadable"


def test_wrong_shapes_are_incorrect_with_the_reason():
    q = np.array([0.2, 0.5, -0.4, 0.9, -1.2, 0.3])
    robot = dn.load_robot("report001-6r")
    J = dn.geometric_jacobian(robot, q)
    claims = [
        {"id": "5 rows", "quantity": "jacobian", "q": _q(q), "value": J[:5].tolist()},
        {"id": "ragged", "quantity": "jacobian", "q": _q(q), "value": J[:5].tolist() + [J[5, :5].tolist()]},
        {"id": "ragged latex", "quantity": "position", "q": _q(q),
         "value": r"\begin{bmatrix} 1 & 2 \\ 3 \end{bmatrix}"},
    ]
    for v in _v(claims, "report001-6r"):
        assert v.verdict == "incorrect", (v.id, v.message)
        assert v.message.startswith("incorrect: shape"), v.message
    (v,) = _v([{"quantity": "torques", "q": "0.1, 0.2, 0.3", "wrench": "1, 2, 0, 0, 0, 0",
                "value": [[1, 2, 3], [4, 5, 6]]}])
    assert v.verdict == "incorrect" and "vector of 3" in v.message


def test_readings_of_partial_values():
    rng = np.random.default_rng(4)
    q = rng.uniform(-2, 2, 3)
    J = _planar3r_j(q)
    T = _fk(dn.load_robot(P3), q)
    v = _v([{"quantity": "jacobian", "q": _q(q), "value": J.tolist()},
            {"quantity": "jacobian", "q": _q(q), "value": J[:2].tolist()},
            {"quantity": "end_effector", "q": _q(q), "value": T[:3].tolist()},
            {"quantity": "jacobian", "rows": "vx,vy,wz", "q": _q(q), "value": J.tolist()}])
    assert [x.verdict for x in v] == ["correct"] * 4, [x.message for x in v]
    assert "ωz" in v[0].message and "[R | p]" in v[2].message
    bad = J.copy()
    bad[2, 1] = 0.0
    (w,) = _v([{"quantity": "jacobian", "q": _q(q), "value": bad.tolist()}])
    assert w.verdict == "incorrect" and "(3, 2)" in w.message and "ωz" in w.message
    Tb = T[:3].copy()
    Tb[0, 3] += 0.1
    (w,) = _v([{"quantity": "end_effector", "q": _q(q), "value": Tb.tolist()}])
    assert w.verdict == "incorrect" and "(1, 4)" in w.message


def test_planar_jacobian_symbolic_textbook_latex():
    value = (r"J = \begin{bmatrix} \dot x \\ \dot y \end{bmatrix} = \begin{bmatrix}"
             r"-L_1 S_1 - L_2 S_{12} - L_3 S_{123} & -L_2 S_{12} - L_3 S_{123} & -L_3 S_{123} \\"
             r"L_1 C_1 + L_2 C_{12} + L_3 C_{123} & L_2 C_{12} + L_3 C_{123} & L_3 C_{123} \\ 1 & 1 & 1 \end{bmatrix}")
    (v,) = _v([{"quantity": "jacobian", "value": value}])
    assert v.verdict == "correct", v.message
    (v,) = _v([{"quantity": "jacobian", "value": value.replace("-L_3 S_{123} \\\\", "L_3 S_{123} \\\\")}])
    assert v.verdict == "incorrect" and "(1, 3)" in v.message


@pytest.mark.parametrize("q_text", [
    r"(0.3, -0.7, 1.1)", r"\left(0.3, -0.7, 1.1\right)", "[0.3, -0.7, 1.1]",
])
def test_q_pasted_with_brackets(q_text):
    x = math.cos(0.3) + 0.8 * math.cos(-0.4) + 0.6 * math.cos(0.7)
    (v,) = _v([{"quantity": "position", "q": q_text, "entry": 1, "value": x}])
    assert v.verdict == "correct", v.message


@pytest.mark.parametrize("q_text", [
    r"(-60^\circ, 0^\circ, 90^\circ)", r"-60^{\circ}, 0^{\circ}, 90^{\circ}", "-60°, 0°, 90°",
    r"(-\pi/3, 0, \pi/2)", r"-\frac{\pi}{3}, 0^\circ, 90°",
])
def test_q_in_degrees_marks(q_text):
    q = np.radians([-60.0, 0.0, 90.0])
    x = math.cos(q[0]) + 0.8 * math.cos(q[0] + q[1]) + 0.6 * math.cos(q.sum())
    (v,) = _v([{"quantity": "position", "q": q_text, "entry": 1, "value": x}])
    assert v.verdict == "correct", v.message
    res = check_claims(dn.load_robot(P3), [{"quantity": "position", "q": q_text, "entry": 1, "value": x}], deg=True)
    if "pi" not in q_text:  # a degree mark is never converted twice when the file's unit is deg
        assert res.verdicts[0].verdict == "correct", res.verdicts[0].message


@pytest.mark.parametrize("text", [
    r"L_1 \cos\theta_1(t) + L_2 \cos(\theta_1(t) + \theta_2(t)) + L_3\cos(\theta 1 + \theta 2 + \theta 3)",
    r"x = L_1 C_1 + L_2 C_{12} + L_3 C_{123}",
    r"p_x = L_1 \cos(\theta_1) + L_2 \cos(\theta_1+\theta_2) + L_3 \cos(\theta_1+\theta_2+\theta_3)",
])
def test_student_notation_for_joint_variables(text):
    (v,) = _v([{"quantity": "position", "entry": 1, "value": text}])
    assert v.verdict == "correct", v.message


def test_two_argument_arctan_and_value_lists_in_text():
    (v,) = _v([{"quantity": "position", "q": "0.3, 0.2, -0.1", "entry": 1,
                "value": r"\cos(\arctan(0.5, -1)) - \cos(\operatorname{atan2}(0.5, -1)) + "
                         r"L_1 c_1 + L_2 c_{12} + L_3 c_{123}"}])
    assert v.verdict == "correct", v.message
    x = lambda q: math.cos(q[0]) + 0.8 * math.cos(q[0] + q[1]) + 0.6 * math.cos(sum(q))  # noqa: E731
    y = lambda q: math.sin(q[0]) + 0.8 * math.sin(q[0] + q[1]) + 0.6 * math.sin(sum(q))  # noqa: E731
    q = (0.3, 0.2, -0.1)
    (v,) = _v([{"quantity": "position", "q": _q(q), "value": f"p = [{x(q)!r}, {y(q)!r}, 0]"}])
    assert v.verdict == "correct", v.message


@settings(max_examples=10 if REDUCED else 40, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(q=st.lists(st.floats(-3, 3), min_size=3, max_size=3), style=st.sampled_from(["list", "brackets", "latex"]),
       rows=st.sampled_from(["all", "xy", "xya"]), flip=st.booleans(), at=st.tuples(st.integers(0, 2), st.integers(0, 2)))
def test_planar_jacobian_correct_accepted_perturbed_named(q, style, rows, flip, at):
    J = _planar3r_j(np.array(q))
    full = dn.geometric_jacobian(dn.load_robot(P3), q)  # only its shape/rows are used to pick the 6-row form
    if rows == "all":
        M = np.zeros((6, 3))
        M[[0, 1, 5]] = J
        assert full.shape == M.shape
    else:
        M = J[:2] if rows == "xy" else J
    i, j = at
    i = min(i, M.shape[0] - 1)
    if flip:
        if abs(M[i, j]) < 1e-6:
            M = M.copy()
            M[i, j] = 0.5  # a wrong value where the truth is 0
        else:
            M = M.copy()
            M[i, j] = -M[i, j]
    value = (M.tolist() if style == "list" else "[" + "; ".join(", ".join(repr(float(x)) for x in r) for r in M) + "]"
             if style == "brackets" else r"\begin{bmatrix}" + r" \\ ".join(" & ".join(repr(float(x)) for x in r) for r in M)
             + r"\end{bmatrix}")
    (v,) = _v([{"quantity": "jacobian", "q": _q(q), "value": value}])
    if flip:
        assert v.verdict == "incorrect", v.message
        assert f"({i + 1}, {j + 1})" in v.message
    else:
        assert v.verdict == "correct", v.message


def test_seed_report_layouts_are_read():
    """The layouts of the seed reports (values from the textbook DH matrix, not from the reports): equation numbers
    ``\\quad (2)``, ``\\theta_i(t)`` with ``*``, ``T_0^1 = …``, a Bmatrix τ = Jᵀ F with F_1 … F_3."""
    a1 = (r"T_0^1 = \begin{bmatrix} \cos \theta_1 & -\sin \theta_1 & 0 & L_1 \cos \theta_1 \\ \sin \theta_1 & "
          r"\cos \theta_1 & 0 & L_1 \sin \theta_1 \\ 0 & 0 & 1 & 0 \\ 0 & 0 & 0 & 1 \end{bmatrix} \quad (2)")
    px = (r"p_x = L_1 * \cos(\theta_1(t)) + L_2 * \cos(\theta_1(t) + \theta_2(t)) + L_3 * \cos(\theta_1(t) + "
          r"\theta_2(t) + \theta_3(t)) \quad (11)")
    tau = (r"\begin{Bmatrix} \tau_1 \\ \tau_2 \\ \tau_3 \end{Bmatrix} = J^T \begin{Bmatrix} F_1 \\ F_2 \\ F_3 "
           r"\end{Bmatrix} = \begin{Bmatrix} -(L_1 S_1 + L_2 S_{12} + L_3 S_{123}) F_1 + (L_1 C_1 + L_2 C_{12} + "
           r"L_3 C_{123}) F_2 \\ -(L_2 S_{12} + L_3 S_{123}) F_1 + (L_2 C_{12} + L_3 C_{123}) F_2 \\ -L_3 S_{123} F_1 "
           r"+ L_3 C_{123} F_2 \end{Bmatrix} \tag{13}")
    v = _v([{"quantity": "A", "index": 1, "value": a1}, {"quantity": "position", "entry": 1, "value": px},
            {"quantity": "tau", "wrench": "F_1, F_2, F_3", "value": tau}])
    assert [x.verdict for x in v] == ["correct"] * 3, [x.message for x in v]
    (w,) = _v([{"quantity": "position", "entry": 1, "value": px.replace(r"\quad (11)", "(11)")}])
    assert w.verdict == "incorrect"  # without \quad, "(11)" is a factor: never silently dropped


def test_where_declares_the_names_a_derivation_introduces():
    x2 = "L_1 c_1 + L_2 c_{12}"  # the elbow's x, from the textbook
    v = _v([{"quantity": "position", "entry": 1, "where": {"x_2": x2}, "value": r"x_2 + L_3 c_{123}"},
            {"quantity": "position", "entry": 1, "where": {"k": "L_3", "x_2": x2}, "value": r"x_2 + k\cos(q_1+q_2+q_3)"},
            {"quantity": "position", "entry": 1, "where": {"x_2": x2}, "value": r"x_2 - L_3 c_{123}"},
            {"quantity": "position", "entry": 1, "value": r"x_2 + L_3 c_{123}"},
            {"quantity": "position", "entry": 1, "where": {"k": "L_2"}, "value": r"L_1 c_1 + k c_{12} + k c_{123}"}])
    assert [x.verdict for x in v] == ["correct", "correct", "incorrect", "unreadable", "incorrect"], [x.message for x in v]
    assert "where" in v[3].message


@pytest.mark.parametrize("q_text", [
    r"\theta_1 = -60^\circ, \theta_2 = 0^\circ, \theta_3 = 90^\circ",
    r"q_3 = \pi/2, q_1 = -\pi/3, q_2 = 0",
    "θ1 = -60°; θ2 = 0°; θ3 = 90°",
])
def test_q_written_as_assignments(q_text):
    q = np.radians([-60.0, 0.0, 90.0])
    x = math.cos(q[0]) + 0.8 * math.cos(q[0] + q[1]) + 0.6 * math.cos(q.sum())
    (v,) = _v([{"quantity": "position", "q": q_text, "entry": 1, "value": x}])
    assert v.verdict == "correct", v.message
    (v,) = _v([{"quantity": "position", "q": q_text.replace("_2", "_1").replace("θ2", "θ1"), "entry": 1, "value": x}])
    assert v.verdict == "unreadable"  # a joint given twice is not guessed


def test_transposed_jacobians_and_unit_headers():
    rng = np.random.default_rng(9)
    q = rng.uniform(-2, 2, 3)
    J = _planar3r_j(q)  # rows (x, y, α): square
    M = np.zeros((6, 3))
    M[[0, 1, 5]] = J
    tex = lambda A: r"\begin{bmatrix}" + r" \\ ".join(" & ".join(repr(float(x)) for x in r) for r in A) + r"\end{bmatrix}"  # noqa: E731
    v = _v([{"quantity": "J", "q": _q(q), "value": M.T.tolist()},
            {"quantity": "J", "q": _q(q), "rows": "planar", "value": r"\begin{split} & J^T \\ & = " + tex(J.T) + r"\end{split}"},
            {"quantity": "J", "q": _q(q), "rows": "planar", "transpose": True, "value": J.T.tolist()},
            {"quantity": "J", "q": _q(q), "rows": "planar", "value": "J = " + tex(J.T)}])
    assert [x.verdict for x in v] == ["correct", "correct", "correct", "incorrect"], [x.message for x in v]
    assert "transpose" in v[0].message and "transposed" in " ".join(v[3].hints)
    x = math.cos(0.5) + 0.8 * math.cos(0.5 + math.pi / 4) + 0.6 * math.cos(0.5 + math.pi / 4 - math.pi / 2)
    (w,) = _v([{"quantity": "position", "entry": 1, "value": x,
                "q": r"(\theta_1, \theta_2, \theta_3)[deg] = (" + f"{math.degrees(0.5)!r}, 45, -90)"}])
    assert w.verdict == "correct", w.message


@pytest.mark.parametrize("lc2, th2, wrong", [
    ("Lc_2", r"\theta_2", False), ("L c_2", r"\theta 2", False), ("L c_{2}", r"\theta_{2}", False),
    ("L c_2", r"\theta 2", True),
])
def test_names_split_by_a_text_conversion_are_joined(lc2, th2, wrong):
    """``L c_2`` is Lc₂ when L alone names nothing; the potential energy of the planar 3R arm from the textbook
    (gravity along −y: P = g Σ mᵢ y_cᵢ), so a wrong mass in it is still caught."""
    m3 = "m_2" if wrong else "m_3"
    text = (rf"P = Lc_1 g m_1 \sin(\theta_1) + g m_2 (L_1 \sin(\theta_1) + {lc2} \sin({th2} + \theta_1))"
            rf" + g {m3} (L_1 \sin\theta_1 + L_2 \sin({th2} + \theta_1) + Lc_3 \sin({th2} + \theta_3 + \theta_1))")
    (v,) = _v([{"quantity": "potential_energy", "q": "0.3, -0.4, 0.9", "value": text.split("=", 1)[1]}])
    assert v.verdict == ("incorrect" if wrong else "correct"), v.message


@pytest.mark.parametrize("dot", [r"\dot{\theta}_1", r"\dot{\theta}1", r"\dot{\theta 1}", r"\dot{\theta} 1"])
def test_a_lost_subscript_of_a_joint_rate_is_read(dot):
    """v_c1 = Lc₁ θ̇₁ (−sin θ₁, cos θ₁, 0) (the textbook's planar arm), with the rate's subscript written as
    conversions leave it."""
    value = rf"\begin{{bmatrix}} -Lc_1 \sin(\theta_1) {dot} \\ Lc_1 \cos(\theta_1) {dot} \\ 0 \end{{bmatrix}}"
    (v,) = _v([{"quantity": "com_velocity", "index": 1, "q": "0.3, -0.4, 0.9", "qd": "0.7, 0.1, -0.2",
                "value": value}])
    assert v.verdict == "correct", v.message


@pytest.mark.parametrize("drop", [0, 1, 5])
def test_a_vector_with_one_entry_left_out_says_which(drop):
    """A column of the planar 3R arm's J0 (textbook: column 1 = (−y, x, 0, 0, 0, 1)) with one entry dropped: the
    verdict stays incorrect (shape) and names the entry; a wrong entry besides the gap names none."""
    q = (0.3, -0.4, 0.9)
    x = math.cos(q[0]) + 0.8 * math.cos(q[0] + q[1]) + 0.6 * math.cos(sum(q))
    y = math.sin(q[0]) + 0.8 * math.sin(q[0] + q[1]) + 0.6 * math.sin(sum(q))
    col = [repr(-y), repr(x), "0", "0", "0", "1"]
    short = col[:drop] + col[drop + 1:]
    (v,) = _v([{"quantity": "jacobian", "column": 1, "q": _q(q), "value": "[" + ", ".join(short) + "]"}])
    assert v.verdict == "incorrect" and "shape" in v.message
    zeros = [str(i + 1) for i, c in enumerate(col) if c == "0"]
    said = f"entry {drop + 1} left out" if col[drop] != "0" else f"the equal entries {', '.join(zeros)} left out"
    assert said in v.message, v.message
    wrong = [repr(-y + 0.5)] + short[1:] if drop else [short[0], repr(x + 0.5)] + short[2:]
    (w,) = _v([{"quantity": "jacobian", "column": 1, "q": _q(q), "value": "[" + ", ".join(wrong) + "]"}])
    assert w.verdict == "incorrect" and "left out" not in w.message
