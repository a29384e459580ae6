"""Independent truth for the report fixtures in this folder: ``python tests/data/reports/_truth.py`` (exit 0 = all hold).

Every value is derived with SymPy in ``_truth_dh.py`` (our own DH matrices, Jacobians, propagation, Lagrange
equations; never denavit's code). Each fixture has one record per expected verdict, in the order of its
``expect`` comments: the result as written in the report, transcribed by hand into SymPy, and the truth. The
script checks that the fixture's ``expect`` comments equal the records' verdicts, that a result expected
``correct`` equals its truth and that one expected ``incorrect`` differs from it (every slip is real).
"""

from __future__ import annotations

import math
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

from _truth_dh import (
    HERE,
    Arm,
    R,
    c,
    force_moment,
    frame_velocity,
    ik_ok,
    link,
    np,
    pi,
    s,
    singular_set_ok,
    sp,
    t1,
    t2,
    t3,
    t4,
    t5,
    t6,
)

FIXTURES: dict = {}


def fixture(name):
    def register(fn):
        FIXTURES[name] = fn
        return fn
    return register


def M(*rows):
    return sp.Matrix(rows)


def col(*xs):
    return sp.Matrix(xs)


L1, L2, L3, L4, H1, d2, d3, d4, d6, a2, a3 = sp.symbols("L1 L2 L3 L4 H1 d2 d3 d4 d6 a2 a3", positive=True)
ai, ali, di, thi = sp.symbols("a_i alpha_i d_i theta_i", real=True)
NC = "not a claim"


# --- 01: planar 2R, Spong, pipe table, symbolic lengths ---------------------------------------------------------

@fixture("01_planar2r_spong.md")
def f01():
    arm = Arm("std", [(L1, 0, 0, t1), (L2, 0, 0, t2)], [("R", t1), ("R", t2)])
    T02, J = arm.T(0), arm.jacobian()
    c1, s1, c2, s2, c12, s12 = c(t1), s(t1), c(t2), s(t2), c(t1 + t2), s(t1 + t2)
    gen = M([c(thi), -s(thi) * c(ali), s(thi) * s(ali), ai * c(thi)],
            [s(thi), c(thi) * c(ali), -c(thi) * s(ali), ai * s(thi)], [0, s(ali), c(ali), di], [0, 0, 0, 1])
    case = {t1: pi / 3, t2: -pi / 2}

    def ik2(tg, q):
        return math.acos((tg["px"] ** 2 + tg["py"] ** 2 - 1 - 1) / 2)   # L1 = L2 = 1 below

    def ik1(tg, q):
        return math.atan2(tg["py"], tg["px"]) - math.atan2(math.sin(q["theta2"]), 1 + math.cos(q["theta2"]))

    arm1 = Arm("std", [(1, 0, 0, t1), (1, 0, 0, t2)], [("R", t1), ("R", t2)])
    return [
        R(NC, "A_i as a product of basic motions"),
        R("correct", "(1) general DH matrix", gen, link("std", ai, ali, di, thi)),
        R("correct", "(2) A_1", M([c1, -s1, 0, L1 * c1], [s1, c1, 0, L1 * s1], [0, 0, 1, 0], [0, 0, 0, 1]), arm.A(1)),
        R("incorrect", "(3) A_2: sign of (1,2)", M([c2, s2, 0, L2 * c2], [s2, c2, 0, L2 * s2], [0, 0, 1, 0],
                                                   [0, 0, 0, 1]), arm.A(2)),
        R(NC, "(4) T_0^2 = A_1 A_2"),
        R("correct", "(5) T_0^2", M([c12, -s12, 0, L1 * c1 + L2 * c12], [s12, c12, 0, L1 * s1 + L2 * s12],
                                    [0, 0, 1, 0], [0, 0, 0, 1]), T02),
        R("correct", "(6) p_x", L1 * c1 + L2 * c12, T02[0, 3]),
        R("correct", "(6) p_y", L1 * s1 + L2 * s12, T02[1, 3]),
        R("correct", "case 2 p_x", L1 / 2 + sp.sqrt(3) / 2 * L2, T02[0, 3].subs(case)),
        R("incorrect", "case 2 p_y: sign of the L2 term", sp.sqrt(3) / 2 * L1 + L2 / 2, T02[1, 3].subs(case)),
        R("incorrect", "(7) J: s/c swapped in (1,2)", M([-L1 * s1 - L2 * s12, -L2 * c12],
                                                        [L1 * c1 + L2 * c12, L2 * c12], [1, 1]),
          J.extract([0, 1, 5], [0, 1])),
        R("correct", "det J (position rows)", L1 * L2 * s2, J[:2, :].det()),
        R("correct", "singular when theta2 = 0 or pi", test=lambda: singular_set_ok(J[:2, :].det(), [s2])),
        R("correct", "(8) theta2 = acos(...), the branch theta2 > 0", test=lambda: ik_ok(arm1, 2, ik2, signs={t2: 1})),
        R("correct", "(9) theta1", test=lambda: ik_ok(arm1, 1, ik1)),
    ]


# --- 02: articulated RRR, Craig, tab-separated, tool row, propagation ------------------------------------------

@fixture("02_elbow_rrr_craig.md")
def f02():
    arm = Arm("mdh", [(0, 0, 0, t1), (0, pi / 2, 0, t2), (L2, 0, 0, t3), (L3, 0, 0, 0)],
              [("R", t1), ("R", t2), ("R", t3), None])
    C1, S1, C2, S2, C3, S3 = c(t1), s(t1), c(t2), s(t2), c(t3), s(t3)
    C23, S23 = c(t2 + t3), s(t2 + t3)
    w1, w2, w3 = sp.symbols("qd1:4", real=True)
    fx, fy, fz = sp.symbols("f_x f_y f_z", real=True)
    am1 = sp.Symbol("alpha_im1", real=True)
    gen = M([c(thi), -s(thi), 0, ai], [s(thi) * c(am1), c(thi) * c(am1), -s(am1), -s(am1) * di],
            [s(thi) * s(am1), c(thi) * s(am1), c(am1), c(am1) * di], [0, 0, 0, 1])
    om = [frame_velocity(arm, k)[0] for k in (1, 2, 3)]
    v3, v4 = frame_velocity(arm, 3)[1], frame_velocity(arm, 4)[1]
    f2, n2 = force_moment(arm, 2, [fx, fy, fz], [0, 0, 0])
    n3 = force_moment(arm, 3, [fx, fy, fz], [0, 0, 0])[1]
    J = arm.jacobian()
    detv = J[:3, :].det()
    return [
        R("correct", "general Craig matrix", gen, link("mdh", ai, am1, di, thi)),
        R("correct", "0T1", M([C1, -S1, 0, 0], [S1, C1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]), arm.A(1)),
        R("correct", "1T2", M([C2, -S2, 0, 0], [0, 0, -1, 0], [S2, C2, 0, 0], [0, 0, 0, 1]), arm.A(2)),
        R("incorrect", "2T3: rotation transposed", M([C3, S3, 0, L2], [-S3, C3, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]),
          arm.A(3)),
        R("correct", "3T4 (tool row)", M([1, 0, 0, L3], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]), arm.A(4)),
        R(NC, "0T4 as the product"),
        R("incorrect", "p_E: C_1 for C_2 in the x and y entries", col(C1 * (L2 * C1 + L3 * C23), S1 * (L2 * C1 + L3 * C23), L2 * S2 + L3 * S23),
          arm.T(0)[:3, 3]),
        R(NC, "propagation rule for omega"),
        R("correct", "1w1", col(0, 0, w1), om[0]),
        R("incorrect", "2w2: index 3 for 2", col(S3 * w1, C3 * w1, w2), om[1]),
        R("correct", "3w3", col(S23 * w1, C23 * w1, w2 + w3), om[2]),
        R("incorrect", "3v3: sign of the z entry", col(L2 * S3 * w2, L2 * C3 * w2, L2 * C2 * w1), v3),
        R("correct", "4v4", col(L2 * S3 * w2, (L2 * C3 + L3) * w2 + L3 * w3, -(L2 * C2 + L3 * C23) * w1), v4),
        R("correct", "4J", M([0, L2 * S3, 0], [0, L2 * C3 + L3, L3], [-L2 * C2 - L3 * C23, 0, 0], [S23, 0, 0],
                             [C23, 0, 0], [0, 1, 1]), arm.jacobian_in(4)),
        R("correct", "3n3", col(0, -L3 * fz, L3 * fy), n3),
        R("correct", "2f2", col(C3 * fx - S3 * fy, S3 * fx + C3 * fy, fz), f2),
        R("incorrect", "2n2: the L3 C3 term of the y entry missing",
          col(L3 * S3 * fz, -L2 * fz, L2 * S3 * fx + (L2 * C3 + L3) * fy), n2),
        R("correct", "tau = J^T F: the virtual-work identity, true by definition", test=lambda: True),
        R("correct", "det J_v", -L2 * L3 * S3 * (L2 * C2 + L3 * C23), detv),
        R("correct", "singular: s3 = 0 and L2 c2 + L3 c23 = 0",
          test=lambda: singular_set_ok(detv, [S3, L2 * C2 + L3 * C23])),
    ]


# --- 03: SCARA RRPR, Spong, space-separated table, numbers, degrees --------------------------------------------

@fixture("03_scara_spaces.md")
def f03():
    D3 = sp.Symbol("d3", real=True)
    r = sp.Rational
    arm = Arm("std", [(r(35, 100), 0, r(40, 100), t1), (r(30, 100), pi, 0, t2), (0, 0, D3, 0), (0, 0, r(10, 100), t4)],
              [("R", t1), ("R", t2), ("P", D3), ("R", t4)])
    c1, s1, c2, s2, c4, s4 = c(t1), s(t1), c(t2), s(t2), c(t4), s(t4)
    c12, s12, ca, sa = c(t1 + t2), s(t1 + t2), c(t1 + t2 - t4), s(t1 + t2 - t4)
    T04, J = arm.T(0), arm.jacobian()
    f = sp.Float
    case = {t1: pi / 6, t2: pi / 4, D3: r(12, 100), t4: pi / 2}
    ikd3 = lambda tg, q: 0.30 - tg["pz"]
    ik2 = lambda tg, q: math.acos((tg["px"] ** 2 + tg["py"] ** 2 - 0.2125) / 0.21)
    return [
        R("correct", "T01", M([c1, -s1, 0, f(0.35) * c1], [s1, c1, 0, f(0.35) * s1], [0, 0, 1, f(0.40)], [0, 0, 0, 1]),
          arm.A(1)),
        R("incorrect", "T12: the 180-degree twist ignored", M([c2, -s2, 0, f(0.30) * c2], [s2, c2, 0, f(0.30) * s2],
                                                                 [0, 0, 1, 0], [0, 0, 0, 1]),
          arm.A(2)),
        R("correct", "T23", M([1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, D3], [0, 0, 0, 1]), arm.A(3)),
        R("incorrect", "T34: the offset d4 = 0.10 left out", M([c4, -s4, 0, 0], [s4, c4, 0, 0], [0, 0, 1, 0],
                                                               [0, 0, 0, 1]), arm.A(4)),
        R(NC, "T04 as the product"),
        R("correct", "T04", M([ca, sa, 0, f(0.35) * c1 + f(0.30) * c12], [sa, -ca, 0, f(0.35) * s1 + f(0.30) * s12],
                              [0, 0, -1, f(0.30) - D3], [0, 0, 0, 1]), T04),
        R("correct", "p_x", f(0.35) * c1 + f(0.30) * c12, T04[0, 3]),
        R("correct", "p_y", f(0.35) * s1 + f(0.30) * s12, T04[1, 3]),
        R("incorrect", "p_z: d4 added instead of subtracted", f(0.50) - D3, T04[2, 3]),
        R("correct", "case 2 T04 (4 decimals)", M([0.9659, -0.2588, 0, 0.3808], [-0.2588, -0.9659, 0, 0.4648],
                                                  [0, 0, -1, 0.18], [0, 0, 0, 1]), T04.subs(case), tol=1e-4),
        R("correct", "J_v", M([-f(0.35) * s1 - f(0.30) * s12, -f(0.30) * s12, 0, 0],
                              [f(0.35) * c1 + f(0.30) * c12, f(0.30) * c12, 0, 0], [0, 0, -1, 0]), J[:3, :]),
        R("incorrect", "J_omega: sign of the roll column", M([0, 0, 0, 0], [0, 0, 0, 0], [1, 1, 0, 1]), J[3:, :]),
        R("correct", "J_11", -f(0.35) * s1 - f(0.30) * s12, J[0, 0]),
        R("correct", "singular when theta2 = 0 or 180 deg",
          test=lambda: singular_set_ok(J.extract([0, 1, 2, 5], [0, 1, 2, 3]).det(), [s2], joints=(t1, t2, D3, t4))),
        R("correct", "d3 = 0.30 - p_z", test=lambda: ik_ok(arm, 3, ikd3)),
        R("correct", "theta2 = +-acos(...)", test=lambda: ik_ok(arm, 2, ik2, signs={t2: 1})
          and ik_ok(arm, 2, lambda tg, q: -ik2(tg, q), signs={t2: -1})),
    ]


# --- 04: spherical RRP, Spong, LaTeX tabular in a .tex file, prismatic joint, IK ------------------------------

@fixture("04_spherical_rrp.tex")
def f04():
    D3 = sp.Symbol("d3", real=True)
    arm = Arm("std", [(0, -pi / 2, H1, t1), (0, pi / 2, d2, t2), (0, 0, D3, 0)], [("R", t1), ("R", t2), ("P", D3)])
    c1, s1, c2, s2 = c(t1), s(t1), c(t2), s(t2)
    T03, J = arm.T(0), arm.jacobian()
    # the IK formulas are checked at H1 = 0.7, d2 = 0.25 (the report's symbols; any positive values would do)
    armn = Arm("std", [(0, -pi / 2, 0.7, t1), (0, pi / 2, 0.25, t2), (0, 0, D3, 0)], [("R", t1), ("R", t2), ("P", D3)])
    r = lambda tg: math.sqrt(tg["px"] ** 2 + tg["py"] ** 2 - 0.25 ** 2)
    ik1 = lambda tg, q: math.atan2(tg["py"], tg["px"]) - math.atan2(0.25, r(tg))
    ikd3 = lambda tg, q: math.hypot(r(tg), tg["pz"] - 0.7)
    ik2 = lambda tg, q: math.atan2(tg["pz"] - 0.7, r(tg))
    branch = {t2: 1, D3: 1}
    detv = J[:3, :].det()
    return [
        R("correct", "A_1", M([c1, 0, -s1, 0], [s1, 0, c1, 0], [0, -1, 0, H1], [0, 0, 0, 1]), arm.A(1)),
        R("incorrect", "A_2: c2 for s2 in (1,3)", M([c2, 0, c2, 0], [s2, 0, -c2, 0], [0, 1, 0, d2], [0, 0, 0, 1]),
          arm.A(2)),
        R("correct", "A_3", M([1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, D3], [0, 0, 0, 1]), arm.A(3)),
        R(NC, "T^0_3 = A_1 A_2 A_3"),
        R("correct", "T^0_3", M([c1 * c2, -s1, c1 * s2, c1 * s2 * D3 - s1 * d2],
                                [s1 * c2, c1, s1 * s2, s1 * s2 * D3 + c1 * d2], [-s2, 0, c2, H1 + D3 * c2],
                                [0, 0, 0, 1]), T03),
        R("correct", "p_x", -d2 * s1 + D3 * c1 * s2, T03[0, 3]),
        R("incorrect", "p_y: sign of the d3 term", d2 * c1 - D3 * s1 * s2, T03[1, 3]),
        R("correct", "p_z", H1 + D3 * c2, T03[2, 3]),
        R("incorrect", "J: sign of (3,2)", M([-d2 * c1 - D3 * s1 * s2, D3 * c1 * c2, c1 * s2],
                                             [-d2 * s1 + D3 * c1 * s2, D3 * s1 * c2, s1 * s2],
                                             [0, D3 * s2, c2], [0, -s1, 0], [0, c1, 0], [1, 0, 0]), J),
        R("correct", "det J_v", -D3 ** 2 * s2, detv),
        R("correct", "position singular: d3 = 0 or theta2 = 0, pi", test=lambda: singular_set_ok(detv, [D3 ** 2, s2], joints=(t1, t2, D3))),
        R("correct", "theta1 (branch d3 sin theta2 > 0)", test=lambda: ik_ok(armn, 1, ik1, signs=branch)),
        R("correct", "d3 (branch d3 > 0)", test=lambda: ik_ok(armn, 3, ikd3, signs=branch)),
        R("incorrect", "theta2: atan2 arguments swapped", test=lambda: ik_ok(armn, 2, ik2, signs=branch)),
    ]


# --- 05: cylindrical RPP, Craig, pipe table without outer pipes, a .txt, numeric case, statics -----------------

@fixture("05_cylindrical_rpp.txt")
def f05():
    D2, D3 = sp.symbols("d2 d3", real=True)
    r, f = sp.Rational, sp.Float
    arm = Arm("mdh", [(0, 0, r(1, 4), t1), (0, 0, D2, 0), (0, -pi / 2, D3, 0), (0, 0, r(1, 10), 0)],
              [("R", t1), ("P", D2), ("P", D3), None])
    c1, s1 = c(t1), s(t1)
    T04, J = arm.T(0), arm.jacobian()
    fx, fy, fz = sp.symbols("f_x f_y f_z", real=True)
    qd = sp.Matrix(sp.symbols("qd1:4", real=True))
    case = {t1: pi / 3, D2: r(1, 2), D3: r(3, 10)}
    e = D3 + f(0.1)
    Jv = M([-e * c1, 0, -s1], [-e * s1, 0, c1], [0, 1, 0])
    n1, n2, n3 = (force_moment(arm, k, [fx, fy, fz], [0, 0, 0])[1] for k in (1, 2, 3))
    f2 = force_moment(arm, 2, [fx, fy, fz], [0, 0, 0])[0]
    detv = J[:3, :].det()
    return [
        R("correct", "0_1T", M([c1, -s1, 0, 0], [s1, c1, 0, 0], [0, 0, 1, f(0.25)], [0, 0, 0, 1]), arm.A(1)),
        R("correct", "1_2T", M([1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, D2], [0, 0, 0, 1]), arm.A(2)),
        R("incorrect", "2_3T: d3 in the z row", M([1, 0, 0, 0], [0, 0, 1, 0], [0, -1, 0, D3], [0, 0, 0, 1]), arm.A(3)),
        R("correct", "3_4T (tool row)", M([1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, f(0.1)], [0, 0, 0, 1]), arm.A(4)),
        R("correct", "0_4T", M([c1, 0, -s1, -e * s1], [s1, 0, c1, e * c1], [0, -1, 0, D2 + f(0.25)], [0, 0, 0, 1]), T04),
        R("incorrect", "case 1: p_x without the tool offset",
          M([0.5, 0, -0.866, -0.260], [0.866, 0, 0.5, 0.200], [0, -1, 0, 0.750], [0, 0, 0, 1]), T04.subs(case),
          tol=1e-3),
        R("correct", "linear velocity = J_v qdot", Jv * qd, J[:3, :] * qd),
        R("correct", "0J", sp.Matrix.vstack(Jv, M([0, 0, 0], [0, 0, 0], [1, 0, 0])), J),
        R("correct", "det J_v", e, detv),
        R("incorrect", "singular only when d3 = 0 (the tool offset forgotten)",
          test=lambda: singular_set_ok(detv, [D3], joints=(t1, D2, D3))),
        R("correct", "3n3", col(-f(0.1) * fy, f(0.1) * fx, 0), n3),
        R("correct", "2f2", col(fx, fz, -fy), f2),
        R("incorrect", "2n2: sign of the z entry", col(-e * fy, 0, e * fx), n2),
        R("correct", "1n1", col(-D2 * fz - e * fy, D2 * fx, -e * fx), n1),
        R("correct", "tau at case 1 (F in base axes)", col(-3.464, -5, 5),
          (J.T * col(0, 10, -5, 0, 0, 0)).subs(case), tol=1e-3),
    ]


# --- 06: two arms in two sections, each with its own table ------------------------------------------------------

@fixture("06_two_arms.md")
def f06():
    a1, a2 = sp.symbols("a1 a2", positive=True)
    D2 = sp.Symbol("d2", real=True)
    arm = Arm("mdh", [(0, 0, 0, t1), (a1, 0, 0, t2), (a2, 0, 0, 0)], [("R", t1), ("R", t2), None])
    c1, s1, c2, s2, c12, s12 = c(t1), s(t1), c(t2), s(t2), c(t1 + t2), s(t1 + t2)
    w1, w2 = sp.symbols("qd1:3", real=True)
    fx, fy = sp.symbols("f_x f_y", real=True)
    J3 = arm.jacobian_in(3)
    tau = J3.T * col(fx, fy, 0, 0, 0, 0)          # the wrench in frame 3 (tool) axes
    rp = Arm("std", [(0, pi / 2, sp.Rational(3, 10), t1), (0, 0, D2, 0)], [("R", t1), ("P", D2)])
    Jrp = rp.jacobian()
    f = sp.Float
    return [
        R("correct", "0T3", M([c12, -s12, 0, a1 * c1 + a2 * c12], [s12, c12, 0, a1 * s1 + a2 * s12], [0, 0, 1, 0],
                              [0, 0, 0, 1]), arm.T(0)),
        R("incorrect", "2v2: entries swapped", col(a1 * c2 * w1, a1 * s2 * w1, 0), frame_velocity(arm, 2)[1]),
        R("correct", "3v3", col(a1 * s2 * w1, a1 * c2 * w1 + a2 * (w1 + w2), 0), frame_velocity(arm, 3)[1]),
        R("incorrect", "3J: c2 for s2 in (1,1)", M([a1 * c2, 0], [a1 * c2 + a2, a2], [0, 0], [0, 0], [0, 0], [1, 1]), J3),
        R("correct", "1n1", col(0, 0, a1 * s2 * fx + (a1 * c2 + a2) * fy), force_moment(arm, 1, [fx, fy, 0], [0, 0, 0])[1]),
        R("correct", "tau_1", a1 * s2 * fx + (a1 * c2 + a2) * fy, tau[0]),
        R("incorrect", "tau_2: f_x for f_y", a2 * fx, tau[1]),
        R("correct", "det 3J_v", a1 * a2 * s2, J3[:2, :].det()),
        R("correct", "singular theta2 = 0, pi", test=lambda: singular_set_ok(J3[:2, :].det(), [s2])),
        R("correct", "general Spong matrix T_{i-1}^i",
          M([c(thi), -s(thi) * c(ali), s(thi) * s(ali), ai * c(thi)], [s(thi), c(thi) * c(ali), -c(thi) * s(ali), ai * s(thi)],
            [0, s(ali), c(ali), di], [0, 0, 0, 1]), link("std", ai, ali, di, thi)),
        R("correct", "T_0^1", M([c1, 0, s1, 0], [s1, 0, -c1, 0], [0, 1, 0, f(0.3)], [0, 0, 0, 1]), rp.A(1)),
        R("correct", "T_1^2", M([1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, D2], [0, 0, 0, 1]), rp.A(2)),
        R("incorrect", "T_0^2: sign of (2,4)", M([c1, 0, s1, D2 * s1], [s1, 0, -c1, D2 * c1], [0, 1, 0, f(0.3)],
                                                 [0, 0, 0, 1]), rp.T(0)),
        R("correct", "J (vx, vy, wz)", M([D2 * c1, s1], [D2 * s1, -c1], [1, 0]), Jrp.extract([0, 1, 5], [0, 1])),
        R("correct", "det J_v", -D2, Jrp[:2, :].det()),
        R("correct", "singular when d2 = 0", test=lambda: singular_set_ok(Jrp[:2, :].det(), [D2], joints=(t1, D2))),
    ]


# --- 07: planar 3R Lagrangian dynamics, catalogue arm (robot=planar3r-lagrange), no table -----------------------

@fixture("07_planar3r_lagrange.md")
def f07():
    from _truth_dh import planar_lagrange
    L = sp.symbols("L1:4", positive=True)
    Lc = sp.symbols("Lc1:4", positive=True)
    m = sp.symbols("m1:4", positive=True)
    II = sp.symbols("I1:4", positive=True)
    g = sp.Symbol("g", positive=True)
    pcs, vcs, _, V, Mq, G = planar_lagrange(3, L, Lc, m, II, g)
    c1, s1, c2, c3 = c(t1), s(t1), c(t2), c(t3)
    c12, s12, c23, c123, s123 = c(t1 + t2), s(t1 + t2), c(t2 + t3), c(t1 + t2 + t3), s(t1 + t2 + t3)
    w1, w2, w3 = sp.symbols("qd1:4", real=True)
    L1_, L2_, L3_ = L
    Lc1, Lc2, Lc3 = Lc
    m1, m2, m3 = m
    I1, I2, I3 = II
    # the catalogue's values (the report states them in step 4)
    num = {L1_: 1, L2_: 0.8, L3_: 0.6, Lc1: 0.5, Lc2: 0.4, Lc3: 0.3, m1: 2, m2: 1.5, m3: 1, I1: 1 / 6, I2: 0.08,
           I3: 0.03, g: 9.81}
    case = {t1: 0, t2: pi / 2, t3: -pi / 2}
    return [
        R("correct", "p_c1", col(Lc1 * c1, Lc1 * s1, 0), pcs[0]),
        R("incorrect", "p_c2: cos(theta2) for cos(theta1 + theta2)", col(L1_ * c1 + Lc2 * c2, L1_ * s1 + Lc2 * s12, 0), pcs[1]),
        R("correct", "pdot_c3", col(-L1_ * s1 * w1 - L2_ * s12 * (w1 + w2) - Lc3 * s123 * (w1 + w2 + w3),
                                    L1_ * c1 * w1 + L2_ * c12 * (w1 + w2) + Lc3 * c123 * (w1 + w2 + w3), 0), vcs[2]),
        R("correct", "V", g * (m1 * Lc1 * s1 + m2 * (L1_ * s1 + Lc2 * s12) + m3 * (L1_ * s1 + L2_ * s12 + Lc3 * s123)), V),
        R(NC, "Lagrange's equation"),
        R("correct", "M11", I1 + I2 + I3 + m1 * Lc1 ** 2 + m2 * (L1_ ** 2 + Lc2 ** 2 + 2 * L1_ * Lc2 * c2)
          + m3 * (L1_ ** 2 + L2_ ** 2 + Lc3 ** 2 + 2 * L1_ * L2_ * c2 + 2 * L1_ * Lc3 * c23 + 2 * L2_ * Lc3 * c3), Mq[0, 0]),
        R("correct", "M12", I2 + I3 + m2 * (Lc2 ** 2 + L1_ * Lc2 * c2)
          + m3 * (L2_ ** 2 + Lc3 ** 2 + L1_ * L2_ * c2 + L1_ * Lc3 * c23 + 2 * L2_ * Lc3 * c3), Mq[0, 1]),
        R("incorrect", "M22: the factor 2 of 2 L2 Lc3 c3 missing",
          I2 + I3 + m2 * Lc2 ** 2 + m3 * (L2_ ** 2 + Lc3 ** 2 + L2_ * Lc3 * c3), Mq[1, 1]),
        R("correct", "M23", I3 + m3 * (Lc3 ** 2 + L2_ * Lc3 * c3), Mq[1, 2]),
        R("correct", "M33", I3 + m3 * Lc3 ** 2, Mq[2, 2]),
        R("incorrect", "g(theta): sign of the m3 Lc3 c123 term of g_2",
          g * col((m1 * Lc1 + m2 * L1_ + m3 * L1_) * c1 + (m2 * Lc2 + m3 * L2_) * c12 + m3 * Lc3 * c123,
                  (m2 * Lc2 + m3 * L2_) * c12 - m3 * Lc3 * c123, m3 * Lc3 * c123), G),
        R("correct", "M(q) at the case", M([4.8467, 1.38, 0.42], [1.38, 1.08, 0.12], [0.42, 0.12, 0.12]),
          Mq.subs(num).subs(case), tol=1e-4),
        R("correct", "g(q) at the case", col(37.278, 2.943, 2.943), G.subs(num).subs(case), tol=1e-3),
    ]


# --- 08: spherical wrist, Craig, tab table with units, rotations, IK in r_ij ------------------------------------

@fixture("08_spherical_wrist.md")
def f08():
    arm = Arm("mdh", [(0, 0, 0, t1), (0, -pi / 2, 0, t2), (0, pi / 2, 0, t3)], [("R", t1), ("R", t2), ("R", t3)])
    c1, s1, c2, s2, c3, s3 = c(t1), s(t1), c(t2), s(t2), c(t3), s(t3)
    w1, w2, w3 = sp.symbols("qd1:4", real=True)
    R03 = arm.T(0)[:3, :3]
    J, J3 = arm.jacobian(), arm.jacobian_in(3)
    h = sp.sqrt(3) / 2
    half = sp.Rational(1, 2)
    Z = sp.zeros(3, 3)
    ik2 = lambda tg, q: math.atan2(math.hypot(tg["r31"], tg["r32"]), tg["r33"])
    ik1 = lambda tg, q: math.atan2(tg["r23"], tg["r13"])
    ik3 = lambda tg, q: math.atan2(tg["r32"], tg["r31"])
    up = {t2: 1}
    return [
        R("correct", "1T2", M([c2, -s2, 0, 0], [0, 0, 1, 0], [-s2, -c2, 0, 0], [0, 0, 0, 1]), arm.A(2)),
        R("incorrect", "2T3: sign of (2,3)", M([c3, -s3, 0, 0], [0, 0, 1, 0], [s3, c3, 0, 0], [0, 0, 0, 1]), arm.A(3)),
        R("correct", "0R3", M([c1 * c2 * c3 - s1 * s3, -c1 * c2 * s3 - s1 * c3, c1 * s2],
                              [s1 * c2 * c3 + c1 * s3, -s1 * c2 * s3 + c1 * c3, s1 * s2], [-s2 * c3, s2 * s3, c2]), R03),
        R("incorrect", "0R3 at (90, 60, 0) deg: transposed", M([0, half, -h], [-1, 0, 0], [0, h, half]),
          R03.subs({t1: pi / 2, t2: pi / 3, t3: 0})),
        R("incorrect", "2w2: sign of the y entry", col(-s2 * w1, c2 * w1, w2), frame_velocity(arm, 2)[0]),
        R("correct", "3w3", col(-s2 * c3 * w1 + s3 * w2, s2 * s3 * w1 + c3 * w2, c2 * w1 + w3), frame_velocity(arm, 3)[0]),
        R("correct", "3J", sp.Matrix.vstack(Z, M([-s2 * c3, s3, 0], [s2 * s3, c3, 0], [c2, 0, 1])), J3),
        R("correct", "0J", sp.Matrix.vstack(Z, M([0, -s1, c1 * s2], [0, c1, s1 * s2], [1, 0, c2])), J),
        R("correct", "det J_w", -s2, J[3:, :].det()),
        R("correct", "singular when theta2 = 0 or pi", test=lambda: singular_set_ok(J[3:, :].det(), [s2])),
        R("correct", "theta2 (sin theta2 > 0)", test=lambda: ik_ok(arm, 2, ik2, signs=up)),
        R("correct", "theta1 (sin theta2 > 0)", test=lambda: ik_ok(arm, 1, ik1, signs=up)),
        R("incorrect", "theta3: sign of r31", test=lambda: ik_ok(arm, 3, ik3, signs=up)),
    ]


# --- 09: PRRR lift, Craig, lengths defined in the table, degrees, tool row, q_i notation --------------------------

@fixture("09_lift_prrr.md")
def f09():
    D1, f = sp.Symbol("d1", real=True), sp.Float
    l2, l3, l4 = f(0.4), f(0.3), f(0.15)
    arm = Arm("mdh", [(0, 0, D1, 0), (0, 0, 0, t2), (l2, 0, 0, t3), (l3, 0, 0, t4), (l4, 0, 0, pi / 2)],
              [("P", D1), ("R", t2), ("R", t3), ("R", t4), None])
    c2, s2, c23, s23, c234, s234 = c(t2), s(t2), c(t2 + t3), s(t2 + t3), c(t2 + t3 + t4), s(t2 + t3 + t4)
    T05, J = arm.T(0), arm.jacobian()
    x, y = l2 * c2 + l3 * c23 + l4 * c234, l2 * s2 + l3 * s23 + l4 * s234
    Jsq = J.extract([0, 1, 2, 5], [0, 1, 2, 3])

    def ik3(tg, q):
        phi = math.atan2(tg["r21"], tg["r11"])
        return math.acos(((tg["px"] - 0.15 * math.sin(phi)) ** 2 + (tg["py"] + 0.15 * math.cos(phi)) ** 2 - 0.25)
                         / 0.24)
    return [
        R("correct", "0T1", M([1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, D1], [0, 0, 0, 1]), arm.A(1)),
        R("correct", "1T2", M([c2, -s2, 0, 0], [s2, c2, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]), arm.A(2)),
        R("incorrect", "4T5: rotation transposed", M([0, 1, 0, l4], [-1, 0, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]), arm.A(5)),
        R(NC, "0T5 as the product"),
        R("correct", "0T5", M([-s234, -c234, 0, x], [c234, -s234, 0, y], [0, 0, 1, D1], [0, 0, 0, 1]), T05),
        R("incorrect", "case 2: a wrong p_y", M([-0.7071, -0.7071, 0, 0.7423], [0.7071, -0.7071, 0, 0.3284],
                                                [0, 0, 1, 0.2], [0, 0, 0, 1]),
          T05.subs({D1: 0.2, t2: pi / 6, t3: -pi / 4, t4: pi / 3}), tol=1e-4),
        R("correct", "case 3: p_E", col(0.55, 0.3, 0.5), T05[:3, 3].subs({D1: 0.5, t2: 0, t3: pi / 2, t4: -pi / 2})),
        R("incorrect", "J: the L4 s234 term of (1,3) missing",
          M([0, -l2 * s2 - l3 * s23 - l4 * s234, -l3 * s23, -l4 * s234], [0, x, l3 * c23 + l4 * c234, l4 * c234],
            [1, 0, 0, 0], [0, 0, 0, 0], [0, 0, 0, 0], [0, 1, 1, 1]), J),
        R("correct", "det J (rows vx, vy, vz, wz)", f(0.12) * s(t3), Jsq.det()),
        R("correct", "singular q3 = 0 or pi", test=lambda: singular_set_ok(Jsq.det(), [s(t3)], joints=(D1, t2, t3, t4))),
        R("correct", "q1 = p_z", test=lambda: ik_ok(arm, 1, lambda tg, q: tg["pz"])),
        R("correct", "q3 = acos(...) (branch q3 > 0)", test=lambda: ik_ok(arm, 3, ik3, signs={t3: 1})),
    ]


# --- 10: 6R elbow arm with a spherical wrist, Spong in degrees (array table), decoupled IK, an ambiguous P ------

@fixture("10_elbow6r_ik.md")
def f10():
    d1, a2_, d4_, d6_ = sp.symbols("d1 a2 d4 d6", positive=True)
    rows = [(0, pi / 2, d1, t1), (a2_, 0, 0, t2), (0, pi / 2, 0, t3), (0, -pi / 2, d4_, t4), (0, pi / 2, 0, t5),
            (0, 0, d6_, t6)]
    arm = Arm("std", rows, [("R", t) for t in (t1, t2, t3, t4, t5, t6)])
    C1, S1, C2, S2, C4, S4, C5, S5, C6, S6 = (f(t) for t in (t1, t2, t4, t5, t6) for f in (c, s))
    C23, S23 = c(t2 + t3), s(t2 + t3)
    # the IK formulas are checked at d1 = 0.4, a2 = 0.5, d4 = 0.45, d6 = 0.1 (any positive lengths would do)
    num = {d1: 0.4, a2_: 0.5, d4_: 0.45, d6_: 0.1}
    armn = Arm("std", [tuple(sp.sympify(x).subs(num) for x in r) for r in rows], arm.joints)
    wrist = armn.T(0, 4)[:3, 3]

    def centre(tg):
        return (tg["px"] - 0.1 * tg["r13"], tg["py"] - 0.1 * tg["r23"], tg["pz"] - 0.1 * tg["r33"])

    def ik3(tg, q):
        x, y, z = centre(tg)
        return math.asin((x * x + y * y + (z - 0.4) ** 2 - 0.25 - 0.2025) / (2 * 0.5 * 0.45))

    def ik2(sign):
        def fn(tg, q):
            x, y, z = centre(tg)
            return math.atan2(z - 0.4, math.hypot(x, y)) + sign * math.atan2(
                0.45 * math.cos(q["theta3"]), 0.5 + 0.45 * math.sin(q["theta3"]))
        return fn

    def ik1_centre(tg, q):
        x, y, _ = centre(tg)
        return math.atan2(y, x)

    branch = {t2: 1, t3: 1}
    atan_p = lambda tg, q: math.atan2(tg["py"], tg["px"])

    def wrist_only_incomplete():
        """J (6x6, numeric) is singular at an elbow-stretched pose with sin θ5 ≠ 0: the claimed set misses it."""
        J = sp.lambdify(armn.q, armn.jacobian(), "numpy")
        sv = np.linalg.svd(np.asarray(J(0.3, 0.5, math.pi / 2, 0.7, 0.9, -0.4), dtype=float), compute_uv=False)
        sw = np.linalg.svd(np.asarray(J(0.3, 0.5, 0.8, 0.7, 0.0, -0.4), dtype=float), compute_uv=False)
        return not (sv[-1] / sv[0] < 1e-9 and sw[-1] / sw[0] < 1e-9)

    return [
        R("incorrect", "0T3: S_2 C_1 for S_1 C_2 in (2,4)", M([C1 * C23, S1, C1 * S23, a2_ * C1 * C2],
                                                                [S1 * C23, -C1, S1 * S23, a2_ * S2 * C1],
                              [S23, 0, -C23, d1 + a2_ * S2], [0, 0, 0, 1]), arm.T(0, 3)),
        R("correct", "3R6", M([C4 * C5 * C6 - S4 * S6, -C4 * C5 * S6 - S4 * C6, C4 * S5],
                              [S4 * C5 * C6 + C4 * S6, -S4 * C5 * S6 + C4 * C6, S4 * S5], [-S5 * C6, S5 * S6, C5]),
          arm.T(3, 6)[:3, :3]),
        R("ambiguous", "theta1 = atan2(p_y, p_x): wrong for the flange, right for the wrist centre",
          test=lambda: not ik_ok(armn, 1, atan_p, signs=branch) and ik_ok(armn, 1, atan_p, signs=branch, point=wrist)),
        R(NC, "x_c, y_c, z_c definitions"),
        R(NC, "3R6 = (0R3)^T R"),
        R("correct", "theta1 = atan2(y_c, x_c)", test=lambda: ik_ok(armn, 1, ik1_centre, signs=branch)),
        R("correct", "sin theta3 = D", test=lambda: ik_ok(armn, 3, ik3, signs=branch)),
        R("correct", "theta3 = asin(D)", test=lambda: ik_ok(armn, 3, ik3, signs=branch)),
        R("correct", "theta2 (+)", test=lambda: ik_ok(armn, 2, ik2(+1), signs=branch)),
        R("incorrect", "theta2 (-): sign of the second atan2", test=lambda: ik_ok(armn, 2, ik2(-1), signs=branch)),
        R("incorrect", "singular only when theta5 = 0 or pi (the elbow cos θ3 = 0 missing)",
          test=wrist_only_incomplete),
    ]


# --- 11: two catalogue arms by section (arms=1:planar2r,2:scara-rrrp), no tables ---------------------------------

@fixture("11_catalogue_sections.md")
def f11():
    from _truth_dh import planar_lagrange
    m1, m2, g = sp.symbols("m1 m2 g", positive=True)
    _, _, _, _, Mq, G = planar_lagrange(2, (L1, L2), (L1, L2), (m1, m2), (0, 0), g)   # point masses at the ends
    two = Arm("std", [(1, 0, 0, t1), (1, 0, 0, t2)], [("R", t1), ("R", t2)])
    ik2 = lambda tg, q: math.acos((tg["px"] ** 2 + tg["py"] ** 2 - 2) / 2)
    ik1 = lambda tg, q: (math.atan(tg["py"] / tg["px"])
                         - math.atan(math.sin(q["theta2"]) / (1 + math.cos(q["theta2"]))))
    D4, f = sp.Symbol("d4", real=True), sp.Float
    sc = Arm("mdh", [(0, 0, 0, t1), (f(0.35), 0, 0, t2), (f(0.3), 0, 0, t3), (0, pi, D4, 0)],
             [("R", t1), ("R", t2), ("R", t3), ("P", D4)])
    C1, S1, C3, S3 = c(t1), s(t1), c(t3), s(t3)
    C12, S12, C23, S23, C123, S123 = c(t1 + t2), s(t1 + t2), c(t2 + t3), s(t2 + t3), c(t1 + t2 + t3), s(t1 + t2 + t3)
    w1, w2, w3, w4 = sp.symbols("qd1:5", real=True)
    om4, v4 = frame_velocity(sc, 4)
    J = sc.jacobian()
    Jsq = J.extract([0, 1, 2, 5], [0, 1, 2, 3])
    return [
        R("correct", "q2 = acos((x^2 + y^2 - 2)/2) (branch q2 > 0)", test=lambda: ik_ok(two, 2, ik2, signs={t2: 1})),
        R("incorrect", "q1 with the one-argument arctangent (wrong by pi when x < 0)",
          test=lambda: ik_ok(two, 1, ik1, n=40)),
        R("correct", "M(q)", M([(m1 + m2) * L1 ** 2 + m2 * L2 ** 2 + 2 * m2 * L1 * L2 * c(t2), m2 * L2 ** 2 + m2 * L1 * L2 * c(t2)],
                               [m2 * L2 ** 2 + m2 * L1 * L2 * c(t2), m2 * L2 ** 2]), Mq),
        R("incorrect", "g(q): cos q1 for cos(q1 + q2) in g_2",
          col((m1 + m2) * g * L1 * c(t1) + m2 * g * L2 * c(t1 + t2), m2 * g * L2 * c(t1)), G),
        R("correct", "3T4", M([1, 0, 0, 0], [0, -1, 0, 0], [0, 0, -1, -D4], [0, 0, 0, 1]), sc.A(4)),
        R("correct", "0T4", M([C123, S123, 0, f(0.35) * C1 + f(0.3) * C12], [S123, -C123, 0, f(0.35) * S1 + f(0.3) * S12],
                              [0, 0, -1, -D4], [0, 0, 0, 1]), sc.T(0)),
        R("correct", "4w4", col(0, 0, -(w1 + w2 + w3)), om4),
        R("incorrect", "4v4: z entry -d4dot (the slide moves along +z4)",
          col(f(0.35) * S23 * w1 + f(0.3) * S3 * (w1 + w2), -f(0.35) * C23 * w1 - f(0.3) * C3 * (w1 + w2), -w4), v4),
        R("correct", "J_v", M([-f(0.35) * S1 - f(0.3) * S12, -f(0.3) * S12, 0, 0], [f(0.35) * C1 + f(0.3) * C12, f(0.3) * C12, 0, 0],
                              [0, 0, 0, -1]), J[:3, :]),
        R("correct", "det of rows vx, vy, vz, wz", f(0.105) * s(t2), Jsq.det()),
        R("correct", "singular theta2 = 0 or pi", test=lambda: singular_set_ok(Jsq.det(), [s(t2)], joints=(t1, t2, t3, D4))),
    ]


# --- the check ----------------------------------------------------------------------------------------------

def main() -> int:
    from _truth_dh import expects
    from _truth_more import FIXTURES as MORE  # fixtures 12-16
    FIXTURES.update(MORE)
    failures = []
    names = sorted(p.name for p in HERE.iterdir()
                   if p.suffix in (".md", ".tex", ".txt") and not p.name.startswith(("_", "README")))
    for name in names:
        if name not in FIXTURES:
            failures.append(f"{name}: no truth records")
            continue
        records = FIXTURES[name]()
        want, got = expects(HERE / name), [r.verdict for r in records]
        if want != got:
            failures.append(f"{name}: expect comments {want} != records {got}")
        held = [r.holds() for r in records]
        for r, ok in zip(records, held):
            if r.verdict == "correct" and ok is not True:
                failures.append(f"{name}: {r.label}: expected correct but the truth differs")
            if r.verdict == "incorrect" and ok is not False:
                failures.append(f"{name}: {r.label}: expected incorrect but it equals the truth")
            if r.verdict == "ambiguous" and ok is False:
                failures.append(f"{name}: {r.label}: expected ambiguous but its test fails")
        print(f"{name}: {len(records)} verdicts, {sum(r.verdict == 'incorrect' for r in records)} slips, "
              f"{sum(ok is not None for ok in held)} checked against the truth")
    for f in failures:
        print("FAIL", f)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
