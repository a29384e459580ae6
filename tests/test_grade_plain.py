"""A report typed as plain text (a word processor's export): unicode names (θ1, φ, τ1, cos²), numbered headings
("4. Inverse kinematics"), `det J = …`, `cos θ2 = …`, a matrix over several lines `J = [ a, b ; ⏎ c, d ]`, a wrench
`F = [fx, fy, mz]`.

The arm is the planar 3R (Spong et al. Sec. 3.3): every formula the report calls right is first checked here with the
arm's own forward kinematics written by hand (x = L1 c1 + L2 c12 + L3 c123, …) at random configurations.
"""

from __future__ import annotations

import numpy as np
import pytest

from denavit.grade import grade_text

REPORT = """Homework 2 - Planar 3R manipulator

1. DH parameters

Link  a_i  alpha_i  d_i  theta_i
1     L1   0        0    θ1
2     L2   0        0    θ2
3     L3   0        0    θ3

2. Forward kinematics

x = L1 cos θ1 + L2 cos(θ1 + θ2) + L3 cos(θ1 + θ2 + θ3)
y = L1 sin θ1 + L2 sin(θ1 + θ2) + L3 sin(θ1 + θ2 + θ3)
φ = θ1 + θ2 + θ3

3. Jacobian

J = [ -L1 s1 - L2 s12 - L3 s123, -L2 s12 - L3 s123, -L3 s123 ;
       L1 c1 + L2 c12 + L3 c123,  L2 c12 + L3 c123,  L3 c123 ;
       1, 1, 1 ]

det J = L1 L2 sin θ2

The arm is singular when θ2 = 0 or θ2 = π.

4. Inverse kinematics

xw = x - L3 cos φ
yw = y - L3 sin φ
cos θ2 = (xw^2 + yw^2 - L1^2 - L2^2) / (2 L1 L2)
θ2 = atan2(±sqrt(1 - cos²θ2), cos θ2)
θ1 = atan2(yw, xw) - atan2(L2 sin θ2, L1 + L2 cos θ2)
θ3 = φ - θ1 - θ2

5. Statics

τ = J^T F, with F = [fx, fy, mz]^T:
τ1 = (-L1 s1 - L2 s12 - L3 s123) fx + (L1 c1 + L2 c12 + L3 c123) fy + mz
"""
L = (0.7, 0.5, 0.3)


def _fk(q):
    a = np.cumsum(q)
    return np.array([np.dot(L, np.cos(a)), np.dot(L, np.sin(a)), a[-1]])


def test_the_formulas_called_right_are_right():
    for q in np.random.default_rng(4).uniform(-np.pi, np.pi, (30, 3)):
        x, y, phi = _fk(q)
        eps = 1e-6
        J = np.array([(_fk(q + eps * e) - _fk(q - eps * e)) / (2 * eps) for e in np.eye(3)]).T
        s, c = np.sin(np.cumsum(q)), np.cos(np.cumsum(q))
        mine = np.array([[-L[0] * s[0] - L[1] * s[1] - L[2] * s[2], -L[1] * s[1] - L[2] * s[2], -L[2] * s[2]],
                         [L[0] * c[0] + L[1] * c[1] + L[2] * c[2], L[1] * c[1] + L[2] * c[2], L[2] * c[2]],
                         [1, 1, 1]])
        assert np.allclose(J, mine, atol=1e-8) and np.isclose(np.linalg.det(mine), L[0] * L[1] * np.sin(q[1]))
        xw, yw = x - L[2] * np.cos(phi), y - L[2] * np.sin(phi)
        c2 = (xw ** 2 + yw ** 2 - L[0] ** 2 - L[1] ** 2) / (2 * L[0] * L[1])
        assert np.isclose(c2, np.cos(q[1]))
        for t2 in (np.arctan2(sg * np.sqrt(max(1 - c2 * c2, 0)), c2) for sg in (1, -1)):
            t1 = np.arctan2(yw, xw) - np.arctan2(L[1] * np.sin(t2), L[0] + L[1] * np.cos(t2))
            assert np.allclose(_fk(np.array([t1, t2, phi - t1 - t2])), [x, y, phi], atol=1e-6)


def _verdicts(text: str) -> list[tuple[int, str, str]]:
    return [(c.line, c.quantity, c.verdict) for c in grade_text(text, "txt").claims if c.verdict != "not a claim"]


def test_a_plain_text_report_is_read_and_judged():
    got = _verdicts(REPORT)
    assert all(v == "correct" for _, _, v in got), got
    kinds = [q for _, q, _ in got]
    assert kinds.count("ik_formula") == 4 and {"jacobian", "det_jacobian", "singularities", "torques",
                                                "heading"} <= set(kinds)
    assert [line for line, q, _ in got if q == "jacobian"] == [18]  # the three lines of J are one matrix


@pytest.mark.parametrize("right, slip, quantity", [
    ("det J = L1 L2 sin θ2", "det J = L1 L2 cos θ2", "det_jacobian"),
    ("θ1 = atan2(yw, xw) - atan2(L2", "θ1 = atan2(yw, xw) + atan2(L2", "ik_formula"),
    ("+ (L1 c1 + L2 c12 + L3 c123) fy + mz", "+ (L1 c1 + L2 c12 + L3 c123) fy - mz", "torques"),
    ("1, 1, 1 ]", "1, 1, 0 ]", "jacobian"),
    ("φ = θ1 + θ2 + θ3", "φ = θ1 + θ2 - θ3", "heading"),
])
def test_a_slip_in_a_plain_text_report_is_incorrect(right, slip, quantity):
    assert right in REPORT
    got = [v for _, q, v in _verdicts(REPORT.replace(right, slip)) if q == quantity]
    assert "incorrect" in got, got
