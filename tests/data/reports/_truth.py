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

from _truth_dh import (HERE, Arm, R, force_moment, frame_velocity, ik_ok, link, pi, qd_symbols,  # noqa: E402
                       same, singular_set_ok, sp, t1, t2, t3, t4, t5, t6)
from _truth_dh import c, s  # noqa: E402

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
        R("correct", "case 2 p_y", sp.sqrt(3) / 2 * L1 - L2 / 2, T02[1, 3].subs(case)),
        R("incorrect", "(7) J: s/c swapped in (1,2)", M([-L1 * s1 - L2 * s12, -L2 * c12],
                                                        [L1 * c1 + L2 * c12, L2 * c12], [1, 1]),
          J.extract([0, 1, 5], [0, 1])),
        R("correct", "det J (position rows)", L1 * L2 * s2, J[:2, :].det()),
        R("correct", "singular when theta2 = 0 or pi", test=lambda: singular_set_ok(J[:2, :].det(), [s2])),
        R("correct", "(8) theta2 = acos(...), the branch theta2 > 0", test=lambda: ik_ok(arm1, 2, ik2, signs={t2: 1})),
        R("correct", "(9) theta1", test=lambda: ik_ok(arm1, 1, ik1)),
    ]


# --- the check ----------------------------------------------------------------------------------------------

def main() -> int:
    from _truth_dh import expects
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
        for r in records:
            ok = r.holds()
            if r.verdict == "correct" and ok is not True:
                failures.append(f"{name}: {r.label}: expected correct but the truth differs")
            if r.verdict == "incorrect" and ok is not False:
                failures.append(f"{name}: {r.label}: expected incorrect but it equals the truth")
        print(f"{name}: {len(records)} verdicts, {sum(r.verdict == 'incorrect' for r in records)} slips, "
              f"{sum(r.holds() is not None for r in records)} checked against the truth")
    for f in failures:
        print("FAIL", f)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
