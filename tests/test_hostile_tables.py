"""Hostile pasted tables for ``denavit import-table`` (issue 14): specific triggers and a generated corpus.

A table that cannot be imported is bad input: exit 2, one line naming the file (and row/column where known),
nothing on stdout, no robot file written.  An imported table gives a robot file that denavit loads, whose
numbers are the table's numbers in SI units.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import denavit as dn
from denavit.tables import MAX_CELL_CHARS, MAX_LINE_CHARS, MAX_TABLE_ROWS
from _hostile import TIME_LIMIT, assert_refused, run_cli, corpus

HEAD = "| i | a | alpha | d | theta |\n|---|---|---|---|---|\n"


def _import(tmp_path, text: str | bytes, *extra: str):
    return run_cli(["import-table", "t.txt", "-o", "out.yaml", *extra], tmp_path, {"t.txt": text})


def _imported(o, tmp_path) -> dn.DHRobot:
    assert not o.hung and o.code == 0, o.describe()
    assert "Traceback" not in o.err and "internal error" not in o.err, o.describe()
    with warnings.catch_warnings():  # e.g. a table headed "alpha (rad)" over -90: the robot file's own warning
        warnings.simplefilter("ignore")
        return dn.load_robot(tmp_path / "out.yaml")


def _fk(a, alpha, d, theta, q):
    """Standard DH by hand: Rz(θ) Tz(d) Tx(a) Rx(α) per row (independent of denavit)."""
    T = np.eye(4)
    for ai, al, di, th in zip(a, alpha, d, np.asarray(theta) + q):
        c, s, ca, sa = np.cos(th), np.sin(th), np.cos(al), np.sin(al)
        T = T @ np.array([[c, -s * ca, s * sa, ai * c], [s, c * ca, -c * sa, ai * s], [0, sa, ca, di], [0, 0, 0, 1]])
    return T


# --- slow patterns, sizes ----------------------------------------------------------------------------------------

@pytest.mark.parametrize("text", [
    "| a" + " " * 100_000 + "x\n",
    "| a (" + "(" * 100_000 + " | alpha | d | theta |\n| 1 | 1 | 0 | 0 | q1 |\n",
    "| a [" + "[" * 100_000 + " | alpha | d | theta |\n| 1 | 1 | 0 | 0 | q1 |\n",
    "| a (" + "(" * 3_000 + " | alpha | d | theta |\n| 1 | 1 | 0 | 0 | q1 |\n",
    "| a [" + "[ " * 1_500 + " | alpha | d | theta |\n| 1 | 1 | 0 | 0 | q_1 |\n",
    "| a | alpha | d | theta |\n|" + " " * 3_900 + "x\n",
    "| a | alpha | d | theta |\n|" + " " * 100_000 + "x\n",
    "a & alpha & d & theta \\\\" + " " * 3_900 + "x\n1 & 0 & 0 & q_1 \\\\" + " " * 3_000 + "y\n",
    ("a & alpha & d & theta \\\\\n" + "1 & 0 & 0 & q_1 \\\\" + " " * 3_000 + "\\hline" + " " * 900 + "z\n") * 3,
    HEAD + "| 1 | " + "+".join(["1"] * 3000) + " | 0 | 0 | \\theta_1 |\n",
    HEAD + "| 1 | " + "1+" * 240 + "1 | 0 | 0 | \\theta_1 |\n",
    HEAD + "| 1 | 1 | 0 | 0 | \\theta_{" + "1" * 400 + "} |\n",
    HEAD + "| 1 | " + "9" * 400 + " | 0 | 0 | \\theta_1 |\n",
    HEAD + "| 1 | 1e999 | 0 | 0 | \\theta_1 |\n",
    HEAD + "| 1 | 1.2.3 | 0 | 0 | \\theta_1 |\n",
    HEAD + "| 1 | \\begin{bmatrix} | 0 | 0 | \\theta_1 |\n",
    HEAD + "| 1 | 1 | 0 | 0 | \\theta_1 |\n" * (MAX_TABLE_ROWS + 1),
    HEAD + "| 1 | " + "x" * (MAX_CELL_CHARS + 1) + " | 0 | 0 | \\theta_1 |\n",
    HEAD + "| 1 | 1 | 0 | 0 | " + "a" * (MAX_LINE_CHARS + 1) + " |\n",
    "no table here\n" * 10_000,
    b"\xff\xfe\x00| a | alpha |",
])
def test_hostile_table_is_refused_quickly(tmp_path, text):
    o = _import(tmp_path, text)
    assert o.seconds < 3, o.describe()
    assert_refused(o, mentions=["t.txt"])


# --- numbers and units -----------------------------------------------------------------------------------------

def test_powers_of_ten_are_numbers(tmp_path):
    """``1e3`` is a thousand (it was 1·e3 with a new parameter e3); here millimetres, so one metre."""
    o = _import(tmp_path, "| i | a (m) | alpha | d (mm) | theta |\n|---|---|---|---|---|\n"
                          "| 1 | 2.5e-1 | 0 | 1e3 | \\theta_1 |\n")
    robot = _imported(o, tmp_path)
    assert robot.parameters == ()
    q = np.array([0.7])
    np.testing.assert_allclose(dn.forward_kinematics(robot, q), _fk([0.25], [0], [1.0], [0], q), atol=1e-12)


@pytest.mark.parametrize("unit, factor", [("mm", 1e-3), ("cm", 1e-2), ("m", 1.0), ("millimetres", 1e-3)])
@pytest.mark.parametrize("brackets", ["({})", "[{}]"])
def test_length_units_in_the_header_are_converted_to_metres(tmp_path, unit, factor, brackets):
    u = brackets.format(unit)
    text = (f"| i | a_i {u} | \\alpha_i (deg) | d_i {u} | \\theta_i (deg) |\n|---|---|---|---|---|\n"
            "| 1 | 0 | 90 | 400 | \\theta_1 |\n| 2 | 250 | 0 | 0 | \\theta_2 - 90 |\n"
            "| 3 | 0 | 0 | d_3^* + 120 | 0 |\n")
    o = _import(tmp_path, text)
    robot = _imported(o, tmp_path)
    if factor != 1.0:
        assert f"converted from {'mm' if 'mm' in unit or 'milli' in unit else 'cm'} to metres" in o.out
    rng = np.random.default_rng(1)
    for _ in range(5):
        q = rng.uniform(-1, 1, 3)
        want = _fk(np.array([0, 250, 0]) * factor, np.radians([90, 0, 0]),
                   np.array([400, 0, 120]) * factor + np.array([0, 0, q[2]]), np.radians([0, -90, 0]),
                   np.array([q[0], q[1], 0]))
        np.testing.assert_allclose(dn.forward_kinematics(robot, q), want, atol=1e-12)


def test_a_parameter_in_a_millimetre_column_is_scaled(tmp_path):
    o = _import(tmp_path, "| i | a (mm) | alpha | d (mm) | theta |\n|---|---|---|---|---|\n"
                          "| 1 | $L_1 = 300$ | 0 | 0 | \\theta_1 |\n")
    robot = _imported(o, tmp_path)
    q = np.array([0.4])
    np.testing.assert_allclose(dn.forward_kinematics(robot, q), _fk([0.3], [0], [0], [0], q), atol=1e-12)


def test_millimetres_without_a_unit_give_a_warning_saying_what_to_write(tmp_path):
    o = _import(tmp_path, HEAD + "| 1 | 300 | 0 | 150 | \\theta_1 |\n| 2 | 250 | 0 | 0 | \\theta_2 |\n")
    robot = _imported(o, tmp_path)
    assert robot.links[0].a == 300  # read as written (metres), but said loudly
    warning = [line for line in o.err.splitlines() if "warning" in line]
    assert len(warning) == 1 and "millimetres" in warning[0] and "(mm)" in warning[0], o.err


def test_metres_do_not_warn(tmp_path):
    o = _import(tmp_path, HEAD + "| 1 | 0.3 | 0 | 0.15 | \\theta_1 |\n| 2 | 25 | 0 | 0 | \\theta_2 |\n")
    _imported(o, tmp_path)
    assert "millimetres" not in o.err


def test_joint_variable_inside_a_product_in_a_millimetre_column_is_refused(tmp_path):
    o = _import(tmp_path, "| i | a (mm) | alpha | d (mm) | theta |\n|---|---|---|---|---|\n"
                          "| 1 | 0 | 0 | 2 d_1^* | 0 |\n")
    assert_refused(o, mentions=["t.txt", "row 1", "metres"])


# --- the output file -------------------------------------------------------------------------------------------

GOOD = HEAD + "| 1 | 0.5 | 0 | 0 | \\theta_1 |\n"


@pytest.mark.parametrize("out, files, words", [
    ("out.png", {}, ["out.png", "unsupported"]),
    ("out", {}, ["out", "unsupported"]),
    ("missing/out.yaml", {}, ["missing"]),
    ("d.yaml", {"d.yaml/keep": "x"}, ["not a regular file"]),
    ("x" * 300 + ".yaml", {}, ["255"]),
])
def test_bad_output_path_is_refused_before_reading(tmp_path, out, files, words):
    o = run_cli(["import-table", "t.txt", "-o", out], tmp_path, {"t.txt": GOOD, **files})
    assert_refused(o, mentions=words)


def test_bad_output_path_is_refused_even_for_a_missing_table(tmp_path):
    o = run_cli(["import-table", "none.txt", "-o", "out.png"], tmp_path, {})
    assert_refused(o, mentions=["out.png"])


def test_output_equal_to_the_table_is_refused(tmp_path):
    o = run_cli(["import-table", "t.yaml", "-o", "t.yaml"], tmp_path, {"t.yaml": GOOD})
    assert_refused(o, mentions=["t.yaml", "input file"])
    assert (tmp_path / "t.yaml").read_text() == GOOD


def test_existing_output_refused_with_no_clobber(tmp_path):
    o = run_cli(["import-table", "t.txt", "-o", "out.yaml", "--no-clobber"], tmp_path,
                {"t.txt": GOOD, "out.yaml": "mine\n"})
    assert_refused(o, mentions=["out.yaml", "exists", "--no-clobber"])
    assert (tmp_path / "out.yaml").read_text() == "mine\n"


def test_existing_output_replaced_atomically(tmp_path):
    o = run_cli(["import-table", "t.txt", "-o", "out.yaml"], tmp_path, {"t.txt": GOOD, "out.yaml": "old"})
    robot = _imported(o, tmp_path)
    assert robot.links[0].a == 0.5
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out.yaml", "t.txt"]  # no temporary file left


# --- generated corpus ------------------------------------------------------------------------------------------

CELLS = st.one_of(
    st.sampled_from(["0", "1", "-1", "0.5", "90", "-90", "180", "1e3", "2.5E-2", "1e999", "9" * 50, "\\pi/2",
                     "$\\frac{\\pi}{2}$", "$-\\frac{\\pi}{2}$", "\\theta_1", "\\theta_2 + \\pi/2", "q_3", "d_2^*",
                     "$d_3$", "L_1", "$H_1 = 0.5$", "$H_1 = x$", "= =", "\\begin{bmatrix}", "\\frac{", "{{{{", "((((",
                     "[[[[", "\\\\", "&", "|", "$", "$$", "°", "90°", "θ_1", "α", "\\unknown", "1/0", "\\sqrt{-1}",
                     "sin(q1)", "abs(q1)", "\\theta_1 \\theta_2", "2\\theta_1", "q1^2", "\\dot\\theta_1", "",
                     " ", "\u0000", "1.2.3", "+".join(["1"] * 300)]),
    st.text(max_size=30),
)
UNITS = st.sampled_from(["", " (mm)", " [mm]", " (cm)", " (m)", " [m]", " (deg)", " (°)", " (rad)", " (z_{i-1})",
                         " (((", " [", " mm", " (in)"])
COLUMNS = ["a", "alpha", "d", "theta"]
NAMES = {"a": ["a", "a_i", "a_{i-1}", "$a_i$", "r", "length"], "alpha": ["alpha", "\\alpha_i", "α", "twist"],
         "d": ["d", "d_i", "$d_i$", "offset"], "theta": ["theta", "\\theta_i", "θ", "q", "Q"]}


GOOD_CELLS = {"a": ["0", "0.5", "-0.25", "1e-1", "L_1", "$L_{2}$", "$H_1 = 0.5$", "\\frac{1}{2}", "300"],
              "alpha": ["0", "90", "-90", "\\pi/2", "$-\\frac{\\pi}{2}$", "180", "\\pi"],
              "d": ["0", "0.4", "d_{k}^*", "$d_{k}$", "q_{k}", "H_1", "120"],
              "theta": ["\\theta_{k}", "\\theta_{k} + \\pi/2", "$\\theta_{k} - 90$", "q_{k}", "0", "θ{k}"]}


@st.composite
def pasted_table(draw) -> str:
    order = draw(st.permutations(COLUMNS))
    header = ["i"] + [draw(st.sampled_from(NAMES[c])) + draw(UNITS if draw(st.integers(0, 3)) == 0
                                                                else st.sampled_from(["", " (mm)", " (deg)"]))
                      for c in order]
    n_rows = draw(st.integers(0, 7))
    rows = [[str(k + 1)] + [draw(st.sampled_from(GOOD_CELLS[c])).replace("{k}", str(k + 1))
                            if draw(st.integers(0, 9)) else draw(CELLS) for c in order] for k in range(n_rows)]
    sep = draw(st.sampled_from(["md", "tab", "tex"]))
    if sep == "md":
        lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)] + ["| " + " | ".join(r) + " |" for r in rows]
    elif sep == "tab":
        lines = ["\t".join(header)] + ["\t".join(r) for r in rows]
    else:
        lines = [" & ".join(header) + " \\\\ \\hline"] + [" & ".join(r) + " \\\\" for r in rows]
    prose = draw(st.sampled_from(["", "Table 1: DH parameters\n", "x" * 5000 + "\n"]))
    return prose + "\n".join(lines) + draw(st.sampled_from(["", "\n", "\n\nmore text | with | bars | here\n"]))


@settings(max_examples=corpus(400), deadline=None, derandomize=True, database=None, suppress_health_check=list(HealthCheck))
@given(text=pasted_table())
def test_corpus_pasted_tables_are_imported_or_refused(tmp_path_factory, text):
    folder = tmp_path_factory.mktemp("t")
    o = _import(folder, text.encode("utf-8", "surrogatepass"))
    assert not o.hung and o.seconds < TIME_LIMIT, o.describe()
    if o.code == 2:
        assert_refused(o, mentions=["t.txt"])
    else:
        _imported(o, folder)  # exit 0 and a robot file denavit loads


@settings(max_examples=corpus(150), deadline=None, derandomize=True, database=None, suppress_health_check=list(HealthCheck))
@given(values=st.lists(st.tuples(st.integers(-900, 900), st.sampled_from([-90, 0, 90, 180]), st.integers(-900, 900),
                                 st.sampled_from([-90, 0, 90])), min_size=1, max_size=6),
       unit=st.sampled_from([("mm", 1e-3), ("cm", 1e-2), ("m", 1.0)]), sep=st.sampled_from(["|", "\t"]),
       q=st.lists(st.floats(-3, 3), min_size=6, max_size=6))
def test_corpus_numeric_tables_import_their_numbers_in_si(tmp_path_factory, values, unit, sep, q):
    """A table of numbers (lengths in mm/cm/m, angles in degrees) gives the robot of those numbers in SI units."""
    name, factor = unit
    header = ["i", f"a ({name})", "alpha (deg)", f"d ({name})", "theta (deg)"]
    rows = [[str(k + 1), str(a), str(al), str(d), f"\\theta_{{{k + 1}}} + {th}" if th else f"\\theta_{{{k + 1}}}"]
            for k, (a, al, d, th) in enumerate(values)]
    wrap = (lambda cells: "| " + " | ".join(cells) + " |") if sep == "|" else "\t".join
    text = "\n".join([wrap(header)] + ([wrap(["---"] * 5)] if sep == "|" else []) + [wrap(r) for r in rows]) + "\n"
    folder = tmp_path_factory.mktemp("n")
    robot = _imported(_import(folder, text), folder)
    a, al, d, th = (np.array(c, dtype=float) for c in zip(*values))
    qq = np.array(q[: len(values)])
    want = _fk(a * factor, np.radians(al), d * factor, np.radians(th), qq)
    np.testing.assert_allclose(dn.forward_kinematics(robot, qq), want, atol=1e-9)


def test_degrees_in_joint_offsets_are_recognised(tmp_path):
    """A newcomer's slip: degrees with no unit and no 90° twist; an offset of -90 cannot be radians."""
    o = _import(tmp_path, HEAD + "| 1 | 0.5 | 0 | 0 | \\theta_1 |\n| 2 | 0.4 | 0 | 0 | \\theta_2 - 90 |\n")
    robot = _imported(o, tmp_path)
    assert "angles read as degrees" in o.out
    q = np.array([0.3, -0.6])
    np.testing.assert_allclose(dn.forward_kinematics(robot, q),
                               _fk([0.5, 0.4], [0, 0], [0, 0], [0, -np.pi / 2], q), atol=1e-12)


def test_radian_offsets_stay_radians(tmp_path):
    o = _import(tmp_path, HEAD + "| 1 | 0.5 | 0 | 0 | \\theta_1 |\n| 2 | 0.4 | \\pi/2 | 0 | \\theta_2 - \\pi/2 |\n")
    robot = _imported(o, tmp_path)
    assert "degrees" not in o.out
    q = np.array([0.3, -0.6])
    np.testing.assert_allclose(dn.forward_kinematics(robot, q),
                               _fk([0.5, 0.4], [0, np.pi / 2], [0, 0], [0, -np.pi / 2], q), atol=1e-12)
