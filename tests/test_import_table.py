"""import-table: DH tables as documents write them → robots whose FK equals the intended arm's."""

from __future__ import annotations

import math

import numpy as np
import pytest

import denavit as dn
from denavit.cli import main
from denavit.tables import import_table

from conftest import SEED_REPORTS as SEEDS  # ../shared/seeds: outside the repository; absent → skip
SEED_ARMS = {"000": "report000-6r", "001": "report001-6r", "003": "report003-6r"}


def _same_fk(a: dn.DHRobot, b: dn.DHRobot, rng, n=20):
    q = rng.uniform(-np.pi, np.pi, (n, a.dof))
    np.testing.assert_allclose(dn.forward_kinematics(a, q), dn.forward_kinematics(b, q), atol=1e-12)


@pytest.mark.parametrize("prefix", sorted(SEED_ARMS))
def test_import_table_seed_reports_give_the_catalogue_arms(prefix):
    files = sorted(SEEDS.glob(f"{prefix}_*.txt"))
    if not files:
        pytest.skip("seed reports not present")
    result = import_table(files[0].read_text(encoding="utf-8"), name=prefix)
    cat = dn.load_robot(SEED_ARMS[prefix])
    imported = dn.with_parameters(result.robot, **cat.parameter_values)  # the table may not give values
    assert imported.convention is cat.convention
    assert imported.n_rows == cat.n_rows and imported.dof == cat.dof
    _same_fk(imported, cat, np.random.default_rng(int(prefix)))


def test_import_table_seed_000_reads_parameter_values_and_the_fixed_row():
    files = sorted(SEEDS.glob("000_*.txt"))
    if not files:
        pytest.skip("seed reports not present")
    r = import_table(files[0].read_text(encoding="utf-8")).robot
    assert r.parameter_values == {"H1": 0.5, "L1": 0.5, "L2": 0.4, "L3": 0.3, "L4": 0.3}
    assert [link.joint.value for link in r.links][-1] == "fixed"
    _same_fk(r, dn.load_robot("report000-6r"), np.random.default_rng(0))


def _fmt_angle(x: float, style: str) -> str:
    for k in (1, 2, 3, 4, 6):
        for num in (-2, -1, 1, 2):
            if abs(x - num * math.pi / k) < 1e-12:
                if style == "frac":
                    top = ("-" if num < 0 else "") + (f"{abs(num)}\\pi" if abs(num) != 1 else "\\pi")
                    return f"$\\frac{{{top}}}{{{k}}}$" if k != 1 else f"${top}$"
                return ("-" if num < 0 else "") + (f"{abs(num)}*pi" if abs(num) != 1 else "pi") + (f"/{k}" if k != 1 else "")
    return f"{x!r}"


def _random_table(rng, conv: str, deg: bool, sep: str):
    """A random arm and a table text for it (shuffled columns, LaTeX or plain cells)."""
    n = int(rng.integers(2, 6))
    rows, links = [], []
    for i in range(1, n + 1):
        alpha = float(rng.choice([0, math.pi / 2, -math.pi / 2, math.pi, math.pi / 3]))
        a = float(np.round(rng.uniform(-1, 1), 3)) if rng.random() < 0.6 else 0.0
        d = float(np.round(rng.uniform(-1, 1), 3)) if rng.random() < 0.5 else 0.0
        prismatic = rng.random() < 0.25
        offset = float(rng.choice([0, math.pi / 2, -math.pi / 2])) if not prismatic else float(rng.choice([0, math.pi / 2]))
        links.append(dn.DHLink(a=a, alpha=alpha, d=d, theta=offset, joint="prismatic" if prismatic else "revolute"))
        ang = (lambda x: f"{math.degrees(x):g}") if deg else (lambda x: _fmt_angle(x, str(rng.choice(["frac", "plain"]))))
        if prismatic:
            theta_cell = ang(offset)
            d_cell = f"$d_{i}^*$" if d == 0 else f"$d_{i} + {d}$".replace("+ -", "- ")
            if d != 0:
                d_cell = f"$q_{i} + {d}$".replace("+ -", "- ")
        else:
            off = ang(offset)
            theta_cell = f"$\\theta_{i}$" if offset == 0 else f"$\\theta_{i} + {off.strip('$')}$".replace("+ -", "- ")
            d_cell = f"{d}"
        rows.append({"a": f"{a}", "alpha": ang(alpha), "d": d_cell, "theta": theta_cell})
    robot = dn.DHRobot("random", tuple(links), convention=conv)
    sub = "_{i-1}" if conv == "modified" else "_i"
    unit = " (deg)" if deg and rng.random() < 0.5 else ""
    heads = {"a": f"$a{sub}$", "alpha": f"$\\alpha{sub}${unit}", "d": "$d_i$", "theta": f"$\\theta_i${unit}"}
    order = list(rng.permutation(["a", "alpha", "d", "theta"]))
    lines = []
    if sep == "|":
        lines.append("| i | " + " | ".join(heads[k] for k in order) + " |")
        lines.append("|---" * 5 + "|")
        lines += ["| " + str(i) + " | " + " | ".join(r[k] for k in order) + " |" for i, r in enumerate(rows, 1)]
    else:
        lines.append("i\t" + "\t".join(heads[k] for k in order))
        lines += [str(i) + "\t" + "\t".join(r[k] for k in order) for i, r in enumerate(rows, 1)]
    return robot, "Some text before the table.\n\n" + "\n".join(lines) + "\n\nText after.\n"


@pytest.mark.parametrize("seed", range(12))
def test_import_table_random_tables_round_trip(seed):
    rng = np.random.default_rng(seed)
    conv = ["standard", "modified"][seed % 2]
    deg = seed % 3 == 0
    robot, text = _random_table(rng, conv, deg, "|" if seed % 4 < 2 else "\t")
    result = import_table(text)
    assert result.robot.convention.value == conv
    assert result.robot.joint_types == robot.joint_types
    _same_fk(result.robot, robot, rng)


def test_import_table_latex_tabular_and_convention_override():
    text = r"""
\begin{tabular}{ccccc}
i & $\theta_i$ & $d_i$ & $a_i$ & $\alpha_i$ \\ \hline
1 & $\theta_1$ & $0.4$ & $0$ & $\pi/2$ \\
2 & $\theta_2 - \frac{\pi}{2}$ & 0 & $L_2 = 0.3$ & 0 \\
\end{tabular}"""
    r = import_table(text).robot
    assert r.convention.value == "standard" and r.parameter_values == {"L2": 0.3}
    assert r.links[1].theta == pytest.approx(-math.pi / 2)
    r2 = import_table(text, convention="modified").robot
    assert r2.convention.value == "modified"


def test_import_table_errors_name_the_place():
    with pytest.raises(dn.ParseError, match="no DH table found"):
        import_table("nothing here\njust text")
    bad = "i\ta\talpha\td\ttheta\n1\t0\t$\\frac{\\pi}{$\t0\t$\\theta_1$\n"
    with pytest.raises(dn.ParseError, match="row 1, column 'alpha'"):
        import_table(bad, where="t.txt")
    with pytest.raises(dn.ParseError, match="row 1"):
        import_table("i\ta\talpha\td\ttheta\n1\t$\\theta_1$\t0\t0\t$\\theta_1$\n")


def test_cli_import_table_writes_refuses_overwrite_and_json(tmp_path, capsys):
    src = tmp_path / "table.md"
    src.write_text("| $\\theta_i$ | $d_i$ | $a_i$ | $\\alpha_i$ |\n|---|---|---|---|\n| $\\theta_1$ | 0 | 1 | 0 |\n"
                   "| $\\theta_2$ | 0 | 0.5 | 0 |\n")
    out = tmp_path / "arm.yaml"
    assert main(["import-table", str(src), "-o", str(out)]) == 0
    r = dn.load_robot(out)
    np.testing.assert_allclose(dn.forward_kinematics(r, [0, 0])[:3, 3], [1.5, 0, 0], atol=1e-12)
    capsys.readouterr()
    assert main(["import-table", str(src), "-o", str(out), "--no-clobber"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "exists" in err and "--no-clobber" in err
    assert main(["import-table", str(src), "-o", str(out)]) == 0  # replaced
    assert main(["import-table", str(src), "-o", str(out), "--force"]) == 0  # the old flag: accepted, no effect
    capsys.readouterr()
    assert main(["import-table", str(src), "--json"]) == 0
    import json

    data = json.loads(capsys.readouterr().out)
    assert data["convention"] == "standard" and len(data["robot_file"]["joints"]) == 2
    assert main(["import-table", str(tmp_path / "missing.txt")]) == 2


def test_import_table_space_separated_tables(capsys):
    """A header whose every word names a column (``i a alpha d theta``) makes a space-separated table: the same
    arm as the tab-separated one; a cell holding a space there is refused naming the line; prose is no header."""
    rows = [("1", "0", "pi/2", "0.3", "q1"), ("2", "0.4", "0", "0", "q2 + pi/6"), ("3", "0.2", "-pi/2", "0.1", "q3")]
    tabbed = "i\ta\talpha\td\ttheta\n" + "\n".join("\t".join(r) for r in rows)
    spaced = "i  a alpha   d theta\n" + "\n".join(" ".join(c.replace(" ", "") for c in r) for r in rows)
    a, b = import_table(tabbed).robot, import_table(spaced).robot
    assert a.dof == b.dof == 3
    _same_fk(a, b, np.random.default_rng(5))
    with pytest.raises(dn.errors.ParseError, match=r"line 3: 7 cells .* cannot hold a space"):
        import_table("i a alpha d theta\n" + "\n".join(" ".join(r) for r in rows))
    with pytest.raises(dn.errors.ParseError, match="no DH table found"):
        import_table("The a alpha d theta values are in the table below, which is missing.\n")
