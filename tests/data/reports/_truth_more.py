"""Truth records for fixtures 12–16 (registered into ``_truth.py``'s FIXTURES; run ``python _truth.py``).

The same method as ``_truth.py``: every truth derived with SymPy in ``_truth_dh.py`` (our own DH products,
geometric Jacobians, propagation by time derivative), never denavit's code; each record holds the result as the
report writes it, transcribed by hand.
"""

from __future__ import annotations

import math

from _truth_dh import (
    Arm,
    R,
    c,
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
NC = "not a claim"


def fixture(name):
    def register(fn):
        FIXTURES[name] = fn
        return fn
    return register


def M(*rows):
    return sp.Matrix(rows)


def col(*xs):
    return sp.Matrix(xs)


def det_matches(J: sp.Matrix, claimed, syms: list, n: int = 6, seed: int = 5) -> bool:
    """det J equals ``claimed`` at random numeric points (for a 6×6 J whose symbolic determinant is slow)."""
    rng = np.random.default_rng(seed)
    fJ, fc = sp.lambdify(syms, J, "numpy"), sp.lambdify(syms, claimed, "numpy")
    for _ in range(n):
        v = [float(x) for x in rng.uniform(0.3, 1.4, len(syms)) * rng.choice((-1, 1), len(syms))]
        a, b = np.linalg.det(np.asarray(fJ(*v), dtype=float)), float(fc(*v))
        if abs(a - b) > 1e-9 * max(1.0, abs(b)):
            return False
    return True


# --- 12: RPR arm with a gripper row, Craig's prescripts everywhere (^{0}_{1}T, {}^{0}_{3}R, {}^{3}_{0}R) ----------

@fixture("12_rpr_craig_prescripts.md")
def f12():
    L2, L3 = sp.symbols("L2 L3", positive=True)
    D2 = sp.Symbol("d2", real=True)
    arm = Arm("mdh", [(0, 0, 0, t1), (0, pi / 2, D2, 0), (0, 0, L2, t3), (L3, 0, 0, 0)],
              [("R", t1), ("P", D2), ("R", t3), None])
    c1, s1, c3, s3 = c(t1), s(t1), c(t3), s(t3)
    w1, w2, w3 = sp.symbols("qd1:4", real=True)
    ai, di, thi, am1 = sp.symbols("a_i d_i theta_i alpha_im1", real=True)
    gen = M([c(thi), -s(thi), 0, ai], [s(thi) * c(am1), c(thi) * c(am1), -s(am1), -s(am1) * di],
            [s(thi) * s(am1), c(thi) * s(am1), c(am1), c(am1) * di], [0, 0, 0, 1])
    T04, J = arm.T(0), arm.jacobian()
    R03 = arm.T(0, 3)[:3, :3]
    e = D2 + L2
    om3, v3 = frame_velocity(arm, 3)
    v4 = frame_velocity(arm, 4)[1]
    J4 = arm.jacobian_in(4)
    detv = J4[:3, :].det()
    # the IK formulas are checked at L2 = 0.3, L3 = 0.2 on the branch d2 > 0, cos(theta3) > 0
    armn = Arm("mdh", [(0, 0, 0, t1), (0, pi / 2, D2, 0), (0, 0, 0.3, t3), (0.2, 0, 0, 0)], arm.joints)
    ik3 = lambda tg, q: math.asin(tg["pz"] / 0.2)
    ik1 = lambda tg, q: math.atan2(tg["py"], tg["px"]) + math.atan2(q["d2"] + 0.3, 0.2 * math.cos(q["theta3"]))
    ik2 = lambda tg, q: math.hypot(tg["px"], tg["py"]) - 0.3
    branch = {D2: 1}
    return [
        R("correct", "general Craig matrix ^{i-1}_iT", gen, link("mdh", ai, am1, di, thi)),
        R("correct", "^0_1T", M([c1, -s1, 0, 0], [s1, c1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]), arm.A(1)),
        R("correct", "^1_2T", M([1, 0, 0, 0], [0, 0, -1, -D2], [0, 1, 0, 0], [0, 0, 0, 1]), arm.A(2)),
        R("incorrect", "^2_3T: L2 in the y row (it is along z)", M([c3, -s3, 0, 0], [s3, c3, 0, L2], [0, 0, 1, 0],
                                                                    [0, 0, 0, 1]), arm.A(3)),
        R("correct", "^3_4T (gripper row)", M([1, 0, 0, L3], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]), arm.A(4)),
        R("correct", "{}^0_3R", M([c1 * c3, -c1 * s3, s1], [s1 * c3, -s1 * s3, -c1], [s3, c3, 0]), R03),
        R("correct", "{}^3_0R = (0_3R)^T", M([c1 * c3, s1 * c3, s3], [-c1 * s3, -s1 * s3, c3], [s1, -c1, 0]), R03.T),
        R("incorrect", "^0_4T: sign of the L3 term of p_y",
          M([c1 * c3, -c1 * s3, s1, e * s1 + L3 * c1 * c3], [s1 * c3, -s1 * s3, -c1, -e * c1 - L3 * s1 * c3],
            [s3, c3, 0, L3 * s3], [0, 0, 0, 1]), T04),
        R("correct", "^0P_4ORG", col(e * s1 + L3 * c1 * c3, L3 * s1 * c3 - e * c1, L3 * s3), T04[:3, 3]),
        R("correct", "3w3", col(s3 * w1, c3 * w1, w3), om3),
        R("incorrect", "3v3: sign of the y entry", col(e * c3 * w1, e * s3 * w1, w2), v3),
        R("correct", "4v4", col(e * c3 * w1, L3 * w3 - e * s3 * w1, w2 - L3 * c3 * w1), v4),
        R("correct", "4J", M([e * c3, 0, 0], [-e * s3, 0, L3], [-L3 * c3, 1, 0], [s3, 0, 0], [c3, 0, 0], [0, 0, 1]), J4),
        R("correct", "det 4J_v", -L3 * e * c3, detv),
        R("correct", "singular: theta3 = +-90 deg or d2 = -L2", test=lambda: singular_set_ok(detv, [c3, e], joints=(t1, D2, t3))
          and singular_set_ok(J[:3, :].det(), [c3, e], joints=(t1, D2, t3))),
        R("correct", "theta3 = asin(p_z / L3) (cos theta3 > 0)", test=lambda: ik_ok(armn, 3, ik3, signs=branch)),
        R("correct", "theta1", test=lambda: ik_ok(armn, 1, ik1, signs=branch)),
        R("incorrect", "d2: the L3 c3 leg of the triangle forgotten", test=lambda: ik_ok(armn, 2, ik2, signs=branch)),
    ]


# --- 13: Stanford arm (RRP + spherical wrist), Spong, degrees, T01/T12 names, plain-text IK in a .txt -------------

@fixture("13_stanford_plain.txt")
def f13():
    d2, d6 = sp.symbols("d2 d6", positive=True)
    D3 = sp.Symbol("d3", real=True)
    rows = [(0, -pi / 2, 0, t1), (0, pi / 2, d2, t2), (0, 0, D3, 0), (0, -pi / 2, 0, t4), (0, pi / 2, 0, t5),
            (0, 0, d6, t6)]
    joints = [("R", t1), ("R", t2), ("P", D3), ("R", t4), ("R", t5), ("R", t6)]
    arm = Arm("std", rows, joints)
    c1, s1, c2, s2, c4, s4, c5, s5, c6, s6 = (f(t) for t in (t1, t2, t4, t5, t6) for f in (c, s))
    T06 = arm.T(0)
    # the IK formulas are checked at d2 = 0.15, d6 = 0.1 on the branch d3 > 0, sin(theta2) > 0
    num = {d2: 0.15, d6: 0.1}
    armn = Arm("std", [tuple(sp.sympify(x).subs(num) for x in r) for r in rows], joints)

    def centre(tg):
        return tg["px"] - 0.1 * tg["r13"], tg["py"] - 0.1 * tg["r23"], tg["pz"] - 0.1 * tg["r33"]

    def rho(tg):
        x, y, _ = centre(tg)
        return math.sqrt(x * x + y * y - 0.15 ** 2)

    ik1 = lambda tg, q: math.atan2(centre(tg)[1], centre(tg)[0]) - math.atan2(0.15, rho(tg))
    ik2 = lambda tg, q: math.atan2(rho(tg), centre(tg)[2])
    ikd3 = lambda tg, q: math.sqrt(sum(x * x for x in centre(tg)))
    branch = {t2: 1, D3: 1}
    q = [t1, t2, D3, t4, t5, t6, d2, d6]
    detJ = D3 ** 2 * s2 * s5

    def singular_ok():
        """det J = d3² s2 s5 (numerically), and that product is exactly the claimed conditions."""
        return det_matches(arm.jacobian(), detJ, q) and singular_set_ok(detJ, [D3 ** 2, s2, s5],
                                                                         joints=(t1, t2, D3, t4, t5, t6))
    return [
        R("correct", "T01", M([c1, 0, -s1, 0], [s1, 0, c1, 0], [0, -1, 0, 0], [0, 0, 0, 1]), arm.A(1)),
        R("correct", "T12", M([c2, 0, s2, 0], [s2, 0, -c2, 0], [0, 1, 0, d2], [0, 0, 0, 1]), arm.A(2)),
        R("correct", "T23", M([1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, D3], [0, 0, 0, 1]), arm.A(3)),
        R("incorrect", "T34: sign of (3,2)", M([c4, 0, -s4, 0], [s4, 0, c4, 0], [0, 1, 0, 0], [0, 0, 0, 1]), arm.A(4)),
        R("correct", "T45", M([c5, 0, s5, 0], [s5, 0, -c5, 0], [0, 1, 0, 0], [0, 0, 0, 1]), arm.A(5)),
        R("correct", "T56", M([c6, -s6, 0, 0], [s6, c6, 0, 0], [0, 0, 1, d6], [0, 0, 0, 1]), arm.A(6)),
        R("correct", "T03", M([c1 * c2, -s1, c1 * s2, c1 * s2 * D3 - s1 * d2], [s1 * c2, c1, s1 * s2, s1 * s2 * D3 + c1 * d2],
                              [-s2, 0, c2, c2 * D3], [0, 0, 0, 1]), arm.T(0, 3)),
        R("correct", "R36", M([c4 * c5 * c6 - s4 * s6, -c4 * c5 * s6 - s4 * c6, c4 * s5],
                              [s4 * c5 * c6 + c4 * s6, -s4 * c5 * s6 + c4 * c6, s4 * s5], [-s5 * c6, s5 * s6, c5]),
          arm.T(3, 6)[:3, :3]),
        R("correct", "p_x", c1 * s2 * D3 - s1 * d2 + d6 * (c1 * c2 * c4 * s5 + c1 * s2 * c5 - s1 * s4 * s5), T06[0, 3]),
        R("incorrect", "p_z: sign of the s2 c4 s5 term", c2 * D3 + d6 * (c2 * c5 + s2 * c4 * s5), T06[2, 3]),
        R("correct", "det J = d3^2 s2 s5", test=lambda: det_matches(arm.jacobian(), detJ, q)),
        R("correct", "singular: d3 = 0, theta2 = 0/180, theta5 = 0/180", test=singular_ok),
        R("correct", "theta1 (plain text)", test=lambda: ik_ok(armn, 1, ik1, signs=branch)),
        R("correct", "theta2 (plain text)", test=lambda: ik_ok(armn, 2, ik2, signs=branch)),
        R("incorrect", "d3 without the d2 offset (plain text)", test=lambda: ik_ok(armn, 3, ikd3, signs=branch)),
    ]


# --- 14: spherical RRP without offset, Spong, results inline in prose ---------------------------------------------

@fixture("14_spherical_inline.md")
def f14():
    d1 = sp.Symbol("d1", positive=True)
    D3 = sp.Symbol("d3", real=True)
    arm = Arm("std", [(0, -pi / 2, d1, t1), (0, pi / 2, 0, t2), (0, 0, D3, 0)], [("R", t1), ("R", t2), ("P", D3)])
    c1, s1, c2, s2 = c(t1), s(t1), c(t2), s(t2)
    T03, J = arm.T(0), arm.jacobian()
    w1, w2, w3 = sp.symbols("qd1:4", real=True)
    fx, fy, fz = sp.symbols("f_x f_y f_z", real=True)
    v = J * col(w1, w2, w3)
    detv = J[:3, :].det()
    case = {t1: pi / 2, t2: pi / 2, D3: sp.Rational(1, 2)}
    # the IK formulas are checked at d1 = 0.6 on the branch d3 sin(theta2) > 0
    armn = Arm("std", [(0, -pi / 2, 0.6, t1), (0, pi / 2, 0, t2), (0, 0, D3, 0)], arm.joints)
    branch = {t2: 1, D3: 1}
    ik1 = lambda tg, q: math.atan2(tg["py"], tg["px"])
    ikd3 = lambda tg, q: math.sqrt(tg["px"] ** 2 + tg["py"] ** 2 + (tg["pz"] - 0.6) ** 2)
    ik2 = lambda tg, q: math.atan2(tg["pz"] - 0.6, math.hypot(tg["px"], tg["py"]))
    return [
        R("correct", "p_x", D3 * c1 * s2, T03[0, 3]),
        R("incorrect", "p_y: sign", -D3 * s1 * s2, T03[1, 3]),
        R("correct", "p_z = d1 + d3 c2", d1 + D3 * c2, T03[2, 3]),
        R("correct", "R_3^0 (inline matrix)", M([c1 * c2, -s1, c1 * s2], [s1 * c2, c1, s1 * s2], [-s2, 0, c2]), T03[:3, :3]),
        R("correct", "zdot", c2 * w3 - D3 * s2 * w2, v[2]),
        R("correct", "omega_z", w1, v[5]),
        R("correct", "J_11", -D3 * s1 * s2, J[0, 0]),
        R("correct", "J_21", D3 * c1 * s2, J[1, 0]),
        R("incorrect", "J_13: c2 for s2", c1 * c2, J[0, 2]),
        R("correct", "det J_v", -D3 ** 2 * s2, detv),
        R("correct", "singular: d3 = 0 or theta2 = 0, pi", test=lambda: singular_set_ok(detv, [D3 ** 2, s2], joints=(t1, t2, D3))),
        R("correct", "theta1 = atan2(p_y, p_x)", test=lambda: ik_ok(armn, 1, ik1, signs=branch)),
        R("correct", "d3", test=lambda: ik_ok(armn, 3, ikd3, signs=branch)),
        R("incorrect", "theta2: atan2 arguments swapped", test=lambda: ik_ok(armn, 2, ik2, signs=branch)),
        R("correct", "case: p_x = 0", 0, T03[0, 3].subs(case)),
        R("correct", "case: p_y = 0.5", sp.Rational(1, 2), T03[1, 3].subs(case)),
        R("correct", "case: p_z = d1", d1, T03[2, 3].subs(case)),
        R("correct", "tau_1 for a tip force in base axes", D3 * s2 * (c1 * fy - s1 * fx),
          (J.T * col(fx, fy, fz, 0, 0, 0))[0]),
    ]


# --- 15: planar 3R with numbers, three "Case k" blocks: T, J, velocities and torques at each --------------------

@fixture("15_planar3r_cases.md")
def f15():
    r = sp.Rational
    arm = Arm("std", [(r(1, 2), 0, 0, t1), (r(2, 5), 0, 0, t2), (r(1, 5), 0, 0, t3)], [("R", t1), ("R", t2), ("R", t3)])
    J = arm.jacobian()
    Jp = J.extract([0, 1, 5], [0, 1, 2])
    T03 = arm.T(0)
    q1 = {t1: pi / 6, t2: pi / 4, t3: -pi / 3}
    q2 = {t1: pi / 2, t2: -pi / 2, t3: pi / 4}
    q3 = {t1: 0, t2: 0, t3: pi / 6}
    tol = 1e-4
    h = 0.7071

    def at(expr, case):
        return expr.subs(case)
    return [
        R("correct", "det J = 0.2 sin(theta2)", r(1, 5) * s(t2), Jp.det()),
        R("correct", "case 1 T03", M([0.9659, -0.2588, 0, 0.7297], [0.2588, 0.9659, 0, 0.6881], [0, 0, 1, 0], [0, 0, 0, 1]),
          at(T03, q1), tol=tol),
        R("correct", "case 1 J", M([-0.6881, -0.4381, -0.0518], [0.7297, 0.2967, 0.1932], [1, 1, 1]), at(Jp, q1), tol=tol),
        R("correct", "case 1 twist", col(-0.2720, 0.3635, 0.6), at(Jp * col(0.5, -0.2, 0.3), q1), tol=tol),
        R("correct", "case 1 tau", col(-13.0945, -4.4343, -2.3637), at(J.T * col(0, -20, 0, 0, 0, 1.5), q1), tol=tol),
        R("correct", "case 2 T03", M([h, -h, 0, 0.5414], [h, h, 0, 0.6414], [0, 0, 1, 0], [0, 0, 0, 1]), at(T03, q2), tol=tol),
        R("correct", "case 2 J", M([-0.6414, -0.1414, -0.1414], [0.5414, 0.5414, 0.1414], [1, 1, 1]), at(Jp, q2), tol=tol),
        R("incorrect", "case 2 det J: the sign of sin(-90 deg)", 0.2, at(Jp.det(), q2), tol=tol),
        R("incorrect", "case 2 twist: omega_z", col(-0.6414, 0.7414, 0.5), at(Jp * col(1.0, 0.5, -0.5), q2), tol=tol),
        R("correct", "case 2 tau", col(-6.4142, -1.4142, -1.4142), at(J.T * col(10, 0, 0, 0, 0, 0), q2), tol=tol),
        R("correct", "case 3 T03", M([0.8660, -0.5, 0, 1.0732], [0.5, 0.8660, 0, 0.1], [0, 0, 1, 0], [0, 0, 0, 1]),
          at(T03, q3), tol=tol),
        R("correct", "case 3 det J = 0", 0, at(Jp.det(), q3)),
        R("incorrect", "case 3 tau_3", col(10.7321, 5.7321, 1.0), at(J.T * col(0, 10, 0, 0, 0, 0), q3), tol=tol),
    ]


# --- 16: articulated arm with a shoulder offset a1, Spong, align + \tag{} in a .tex, tool-frame Jacobian ---------

@fixture("16_offset_elbow_align.tex")
def f16():
    a1, a2, a3, d1 = sp.symbols("a1 a2 a3 d1", positive=True)
    arm = Arm("std", [(a1, pi / 2, d1, t1), (a2, 0, 0, t2), (a3, 0, 0, t3)], [("R", t1), ("R", t2), ("R", t3)])
    c1, s1, c2, s2, c3, s3 = c(t1), s(t1), c(t2), s(t2), c(t3), s(t3)
    c23, s23 = c(t2 + t3), s(t2 + t3)
    T03, J = arm.T(0), arm.jacobian()
    w = a1 + a2 * c2 + a3 * c23
    detv = J[:3, :].det()
    # the IK formulas are checked at a1 = 0.3, a2 = 0.7, a3 = 0.4, d1 = 0.5: there a1 + a2 c2 + a3 c23 > 0 for
    # every |theta2|, |theta3| < 1.3 that ik_ok draws, so atan2(p_y, p_x) is theta1 on the whole sample
    armn = Arm("std", [(0.3, pi / 2, 0.5, t1), (0.7, 0, 0, t2), (0.4, 0, 0, t3)], arm.joints)

    def rs(tg):
        return math.hypot(tg["px"], tg["py"]) - 0.3, tg["pz"] - 0.5

    def ik3(tg, q):
        r, z = rs(tg)
        return math.acos((r * r + z * z - 0.49 - 0.16) / (2 * 0.7 * 0.4))

    def ik2(sign):
        def fn(tg, q):
            r, z = rs(tg)
            t = q["theta3"]
            return math.atan2(z, r) + sign * math.atan2(0.4 * math.sin(t), 0.7 + 0.4 * math.cos(t))
        return fn
    branch = {t3: 1}
    return [
        R("correct", "(1) A_1", M([c1, 0, s1, a1 * c1], [s1, 0, -c1, a1 * s1], [0, 1, 0, d1], [0, 0, 0, 1]), arm.A(1)),
        R("correct", "(2) A_2", M([c2, -s2, 0, a2 * c2], [s2, c2, 0, a2 * s2], [0, 0, 1, 0], [0, 0, 0, 1]), arm.A(2)),
        R("incorrect", "(3) A_3: s3 and c3 swapped in the last column",
          M([c3, -s3, 0, a3 * s3], [s3, c3, 0, a3 * c3], [0, 0, 1, 0], [0, 0, 0, 1]), arm.A(3)),
        R("correct", "(4) p_x", c1 * w, T03[0, 3]),
        R("correct", "(5) p_y", s1 * w, T03[1, 3]),
        R("incorrect", "(6) p_z: s3 for s23", d1 + a2 * s2 + a3 * s3, T03[2, 3]),
        R("correct", "z_0 (the axis of joint 1: J_omega's first column)", sp.Matrix([0, 0, 1]), J[3:, 0]),
        R("correct", "z_1 (the axis of joint 2)", sp.Matrix([s1, -c1, 0]), J[3:, 1]),
        R("correct", "(7) J_v", M([-s1 * w, -c1 * (a2 * s2 + a3 * s23), -a3 * c1 * s23],
                                  [c1 * w, -s1 * (a2 * s2 + a3 * s23), -a3 * s1 * s23], [0, a2 * c2 + a3 * c23, a3 * c23]),
          J[:3, :]),
        R("correct", "(8) J_omega", M([0, s1, s1], [0, -c1, -c1], [1, 0, 0]), J[3:, :]),
        R("correct", "(9) J_e = {}^eJ (tool = frame 3 axes)",
          M([0, a2 * s3, 0], [0, a2 * c3 + a3, a3], [-w, 0, 0], [s23, 0, 0], [c23, 0, 0], [0, 1, 1]), arm.jacobian_in(3)),
        R("correct", "(10) det J_v factored", -a2 * a3 * s3 * w, detv),
        R("correct", "singular: theta3 = 0 or pi, or a1 + a2 c2 + a3 c23 = 0",
          test=lambda: singular_set_ok(detv, [s3, w], joints=(t1, t2, t3))),
        R("correct", "(11) theta1 = atan2(p_y, p_x)", test=lambda: ik_ok(armn, 1, lambda tg, q: math.atan2(tg["py"], tg["px"]))),
        R(NC, "D = (r^2 + s^2 - a2^2 - a3^2) / (2 a2 a3)"),
        R("correct", "(12) theta3 = acos(D) (theta3 > 0)", test=lambda: ik_ok(armn, 3, ik3, signs=branch)),
        R("incorrect", "(13) theta2: sign of the second atan2", test=lambda: ik_ok(armn, 2, ik2(+1), signs=branch)
          or not ik_ok(armn, 2, ik2(-1), signs=branch)),
    ]


# --- 17: two-link planar arm, Spong's d_ij/φ_k, masses from the report's symbols (no robot given) ---------------

@fixture("17_two_link_dynamics.tex")
def f17():
    from _truth_dh import planar_lagrange
    l1, l2 = sp.symbols("l1 l2", positive=True)
    lc = sp.symbols("lc1 lc2", positive=True)
    m1, m2 = m = sp.symbols("m1 m2", positive=True)
    i1, i2 = II = sp.symbols("I1 I2", positive=True)
    g = sp.Symbol("g", positive=True)
    _, _, K, V, Mq, G = planar_lagrange(2, (l1, l2), lc, m, II, g)
    qd = sp.symbols("qd1 qd2", real=True)
    qdd = sp.symbols("qdd1 qdd2", real=True)
    q = (t1, t2)

    def tau(i):  # Lagrange: d/dt ∂K/∂q̇ − ∂K/∂q + ∂V/∂q, the time derivative by the chain rule
        p = sp.diff(K, qd[i])
        ddt = sum(sp.diff(p, q[j]) * qd[j] + sp.diff(p, qd[j]) * qdd[j] for j in range(2))
        return sp.expand(ddt - sp.diff(K, q[i]) + sp.diff(V, q[i]))
    lc1, lc2 = lc
    c2_, s2_, c1_, c12 = c(t2), s(t2), c(t1), c(t1 + t2)
    d11 = m1 * lc1 ** 2 + m2 * (l1 ** 2 + lc2 ** 2 + 2 * l1 * lc2 * c2_) + i1 + i2
    d12 = m2 * (lc2 ** 2 + l1 * lc2 * c2_) + i2
    d22 = m2 * lc2 ** 2 + i2
    phi1 = (m1 * lc1 + m2 * l1) * g * c1_ + m2 * lc2 * g * c12
    h = -m2 * l1 * lc2 * s2_
    return [
        R("correct", "K", m1 * lc1 ** 2 * qd[0] ** 2 / 2 + m2 * (l1 ** 2 * qd[0] ** 2 + lc2 ** 2 * (qd[0] + qd[1]) ** 2
                                                                 + 2 * l1 * lc2 * c2_ * qd[0] * (qd[0] + qd[1])) / 2
          + i1 * qd[0] ** 2 / 2 + i2 * (qd[0] + qd[1]) ** 2 / 2, K),
        R("correct", "P", m1 * g * lc1 * s(t1) + m2 * g * (l1 * s(t1) + lc2 * s(t1 + t2)), V),
        R("correct", "d11", d11, Mq[0, 0]),
        R("incorrect", "d12: 2 l1 lc2 c2 for l1 lc2 c2", m2 * (lc2 ** 2 + 2 * l1 * lc2 * c2_) + i2, Mq[0, 1]),
        R("correct", "d22", d22, Mq[1, 1]),
        R("correct", "phi1", phi1, G[0]),
        R("incorrect", "phi2: l2 for lc2", m2 * l2 * g * c12, G[1]),
        R("correct", "tau1 (with the report's phi1)", d11 * qdd[0] + d12 * qdd[1] + 2 * h * qd[0] * qd[1]
          + h * qd[1] ** 2 + phi1, tau(0)),
        R("correct", "tau2", d12 * qdd[0] + d22 * qdd[1] - h * qd[0] ** 2 + m2 * lc2 * g * c12, tau(1)),
    ]
