"""The rough edges a new user hits (issue 31): output that fits the terminal, messages that say what to do."""

from __future__ import annotations

import re

import pytest

from denavit.cli import main


def run(capsys, *argv):
    code = main(list(argv))
    out, err = capsys.readouterr()
    return code, out, err


# --- symbolic matrices fit the terminal -------------------------------------------------------------------------

def test_symbolic_t06_of_the_puma_fits_a_100_column_terminal_entry_by_entry(capsys, monkeypatch):
    monkeypatch.setenv("COLUMNS", "100")
    code, out, _ = run(capsys, "fk", "puma560", "--symbolic", "--shorthand")
    assert code == 0
    assert max(len(line) for line in out.splitlines()) <= 100
    t06 = out[out.index("T_0_6 ="):]
    entries = dict(re.findall(r"^\((\d, \d)\) = (.*)$", t06, re.M))
    assert len(entries) == 16
    assert [entries[f"4, {j}"] for j in range(1, 5)] == ["0", "0", "0", "1"]
    # Craig (3.14) / Paul's Puma: p_x = C1 (a2 C2 + a3 C23 - d4 S23) - d3 S1, expanded
    px = set(entries["1, 4"].replace(" ", "").replace("+", " +").replace("-", " -").split())
    assert px == {"C₁⋅C₂⋅a₂", "+C₁⋅C₂₃⋅a₃", "-C₁⋅S₂₃⋅d₄", "+S₁⋅d₃"} or px == {"C₁⋅C₂⋅a₂", "+C₁⋅C₂₃⋅a₃",
                                                                             "-C₁⋅S₂₃⋅d₄", "-S₁⋅d₃"}


def test_a_symbolic_matrix_that_fits_stays_a_matrix(capsys, monkeypatch):
    monkeypatch.setenv("COLUMNS", "400")
    code, out, _ = run(capsys, "fk", "puma560", "--symbolic", "--shorthand")
    assert code == 0 and "entry by entry" not in out and out.count("⎡") == 7  # A_1..A_6 and T_0_6


def test_symbolic_jacobian_fits_the_terminal(capsys, monkeypatch):
    monkeypatch.setenv("COLUMNS", "80")
    code, out, _ = run(capsys, "jacobian", "puma560", "--shorthand")
    assert code == 0 and "entry by entry" in out
    matrix = out[out.index("entry by entry"):].splitlines()[1:]
    assert len(matrix) >= 36 and max(len(line) for line in matrix) <= 80
    assert sum(line.startswith("(") for line in matrix) == 36


def test_a_long_entry_is_broken_at_its_plus_and_minus_and_reads_back_the_same():
    import sympy as sp

    from denavit.display import matrix_text

    x = sp.symbols("x1:40")
    M = sp.Matrix([[sum(x[i] * x[i + 1] for i in range(30)) - 7 * x[0] * sp.cos(x[2] + x[3]), 1]])
    text = matrix_text(M, width=40)
    lines = text.splitlines()[1:]
    assert max(len(line) for line in lines) <= 40
    assert lines[0] == "(1, 1) =" and lines[-1] == "(1, 2) = 1"
    body = [line.strip() for line in lines[1:-1]]
    assert all(b.startswith(("+", "-")) for b in body[1:])  # every break is before a sign
    one_line = sp.pretty(M[0, 0], use_unicode=True, wrap_line=False)
    assert "⋅" in one_line and " ".join(body) == one_line


# --- inverse kinematics says why ---------------------------------------------------------------------------------

def _beyond(text):
    m = re.search(r"out of reach: the target is ([\d.e+-]+) m beyond the arm's reach bound \(it is ([\d.e+-]+) m "
                  r"from the chain's base point; no configuration reaches farther than ([\d.e+-]+) m from it\)", text)
    assert m, text
    return tuple(float(g) for g in m.groups())


def test_out_of_reach_ik_says_how_far_beyond_the_reach_the_target_is(capsys):
    import denavit

    robot = denavit.load_robot("planar2r")
    reach = sum(link.a for link in robot.links)  # a 2R arm reaches a1 + a2 from its base, stretched out (q2 = 0)
    code, out, err = run(capsys, "ik", "planar2r", "--pose", "5,0,0,0,0,0")
    assert code == 1 and len(err.strip().splitlines()) == 1
    beyond, dist, bound = _beyond(out)
    assert (beyond, dist, bound) == pytest.approx((5 - reach, 5, reach))
    assert _beyond(err) == (beyond, dist, bound)


def test_out_of_reach_puma_target_names_the_bound_and_reachable_ones_do_not(capsys, rng):
    import numpy as np

    import denavit

    robot = denavit.load_robot("puma560")
    code, out, _ = run(capsys, "ik", "puma560", "--pose", "3,0,0,0,0,0")
    beyond, dist, bound = _beyond(out)
    assert code == 1 and beyond == pytest.approx(dist - bound, abs=1e-3) and beyond > 0
    # the bound is a bound: no configuration within the limits reaches past it (sampled), nor past 3 m
    lo, hi = robot.q_limits.T
    p = denavit.forward_kinematics(robot, rng.uniform(lo, hi, (20_000, 6)))[:, :3, 3]
    assert np.max(np.linalg.norm(p - p.mean(axis=0), axis=1)) < 2 * bound and np.max(np.linalg.norm(p, axis=1)) < 3
    code, out, err = run(capsys, "ik", "puma560", "--from-q", "0.1, 0.2, -0.3, 0.4, 0.5, 0.6")
    assert code == 0 and "out of reach" not in out + err
    code, out, err = run(capsys, "ik", "planar2r", "--pose", "0,0,0,0,0,0", "--method", "numeric")
    assert "out of reach" not in out + err  # inside the reach (a folded arm reaches its base): no such claim


def test_redundant_arm_analytic_refusal_names_lock(capsys):
    code, out, err = run(capsys, "ik", "panda", "--pose", "0.3,0,0.5,0,0,0", "--method", "analytic")
    assert code == 1 and out == "" and len(err.strip().splitlines()) == 1
    assert "--lock" in err and "--lock q7=0" in err and "redundant" in err
    # and the advice works: with q7 held, the closed forms answer (the README's command)
    code, out, _ = run(capsys, "ik", "panda", "--from-q", "0.1, 0.2, 0.3, -1.4, 0.5, 1.6, 0.7", "--lock", "q7=0.7")
    assert code == 0 and "q7 locked" in out


# --- names: did you mean, any letter case; the symbols known -----------------------------------------------------

def test_unknown_robot_name_gets_did_you_mean_and_a_whole_short_line(capsys):
    code, out, err = run(capsys, "fk", "puma650", "-q", "0")
    assert code == 2 and out == "" and len(err.strip().splitlines()) == 1
    assert "did you mean puma560" in err and " ... " not in err  # no list cut in the middle of a name
    assert "denavit robots" in err
    code, _, err = run(capsys, "fk", "qwertyuiop", "-q", "0")
    assert code == 2 and "did you mean" not in err and " ... " not in err


@pytest.mark.parametrize(("typed", "name"), [("UR5", "ur5"), ("Puma560", "puma560"), ("PANDA", "panda"),
                                             ("Report000-6R", "coaxial-6r")])
def test_catalogue_lookup_ignores_letter_case(typed, name):
    import denavit

    assert denavit.load_robot(typed) == denavit.load_robot(name)


def test_unknown_symbol_in_joint_values_lists_only_what_is_known(capsys):
    code, _, err = run(capsys, "fk", "puma560", "-q", "0, 0, 0, 0, 0, O")
    assert code == 2 and "unknown symbol 'O' (known: pi)" in err and "none" not in err
