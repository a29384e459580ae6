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
