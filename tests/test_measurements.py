"""The measurement CSV reader and writer (denavit.read_measurements / write_measurements).

Good files read to the values written by hand; every bad input is one ParseError line naming the file, the line
and the column; a written file reads back to the same numbers (hypothesis).
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import denavit
from denavit import ParseError, ShapeError, read_measurements, write_measurements

from conftest import REDUCED

PUMA = denavit.load_robot("puma560")
STANFORD = denavit.load_robot("stanford")  # joint 3 prismatic


def _write(tmp_path, text: str, name: str = "m.csv") -> str:
    path = tmp_path / name
    path.write_text(text, encoding="utf-8")
    return str(path)


HEADER6 = "q1,q2,q3,q4,q5,q6"


def test_read_poses_with_comments_blank_lines_and_extra_columns(tmp_path):
    text = ("# measured on the bench\n\n"
            f"t,{HEADER6},x,y,z,qw,qx,qy,qz,temperature\n"
            "0.0,0,0.1,0.2,0.3,0.4,0.5,1,2,3,1,0,0,0,21.5\n"
            "\n# a pause\n"
            "0.5, 1,1,1,1,1,1 ,0.5,0.25,0.125,0,0,0,1,22\n")
    m = read_measurements(_write(tmp_path, text), PUMA)
    np.testing.assert_array_equal(m.q, [[0, 0.1, 0.2, 0.3, 0.4, 0.5], [1] * 6])
    np.testing.assert_array_equal(m.t, [0.0, 0.5])
    np.testing.assert_array_equal(m.position, [[1, 2, 3], [0.5, 0.25, 0.125]])
    np.testing.assert_array_equal(m.quaternion, [[1, 0, 0, 0], [0, 0, 0, 1]])
    np.testing.assert_array_equal(m.lines, [4, 7])
    assert m.qd is None and m.qdd is None and m.tau is None
    assert len(m.notes) == 1 and "'temperature'" in m.notes[0]
    # quaternion (0,0,0,1) is a half turn about z
    np.testing.assert_allclose(m.poses[1], [[-1, 0, 0, 0.5], [0, -1, 0, 0.25], [0, 0, 1, 0.125], [0, 0, 0, 1]])


def test_read_units_degrees_and_millimetres_apply_by_joint_type(tmp_path):
    text = "q1,q2,q3,q4,q5,q6,x,y,z,tau1,tau2,tau3,tau4,tau5,tau6\n90,45,100,180,0,-90,1000,0,-5,1,2,3,4,5,6\n"
    m = read_measurements(_write(tmp_path, text), STANFORD, angle_unit="deg", length_unit="mm", torque_scale=1e-3)
    np.testing.assert_allclose(m.q, [[math.pi / 2, math.pi / 4, 0.1, math.pi, 0, -math.pi / 2]])  # q3 prismatic
    np.testing.assert_allclose(m.position, [[1.0, 0.0, -0.005]])
    np.testing.assert_allclose(m.tau, [[0.001, 0.002, 0.003, 0.004, 0.005, 0.006]])
    assert m.quaternion is None and m.poses is None


def test_read_rates_and_accelerations(tmp_path):
    cols = ",".join([f"q{k}" for k in range(1, 7)] + [f"qd{k}" for k in range(1, 7)] + [f"qdd{k}" for k in range(1, 7)])
    row = ",".join(str(v) for v in range(18))
    m = read_measurements(_write(tmp_path, f"{cols}\n{row}\n"), PUMA)
    np.testing.assert_array_equal(m.qd, [np.arange(6, 12)])
    np.testing.assert_array_equal(m.qdd, [np.arange(12, 18)])


def test_quaternion_slightly_off_is_normalised(tmp_path):
    text = f"{HEADER6},x,y,z,qw,qx,qy,qz\n0,0,0,0,0,0,0,0,0,1.0005,0,0,0\n"
    m = read_measurements(_write(tmp_path, text), PUMA)
    np.testing.assert_array_equal(m.quaternion, [[1, 0, 0, 0]])


BAD = [  # (file text, the line the message names, a fragment it must contain)
    ("q1,q2,q3,q4,q5\n1,2,3,4,5\n", 1, "column 'q6' missing"),
    (f"{HEADER6}\n1,2,abc,4,5,6\n", 2, "column 'q3': 'abc' is not a number"),
    (f"{HEADER6}\n1,2,3,4,5,nan\n", 2, "column 'q6': 'nan' is not a finite number"),
    (f"{HEADER6}\n1,2,3,4,5,-inf\n", 2, "column 'q6': '-inf' is not a finite number"),
    (f"{HEADER6}\n1,2,3,4,5,1e999\n", 2, "column 'q6': '1e999' is not a finite number"),
    (f"{HEADER6}\n1,2,3,4,5,\n", 2, "column 'q6': '' is not a number"),
    (f"{HEADER6}\n1,2,3,4,5,6\n1,2,3,4,5\n", 3, "5 fields; the header has 6"),
    (f"{HEADER6}\n1,2,3,4,5,6,7\n", 2, "7 fields; the header has 6"),
    (f"q1,q2,q3,q4,q5,q6,q2\n1,2,3,4,5,6,7\n", 1, "column 'q2' appears twice (columns 2 and 7)"),
    (f"{HEADER6},q7\n1,2,3,4,5,6,7\n", 1, "column 'q7': puma560 has 6 joints"),
    (f"{HEADER6},x,y\n1,2,3,4,5,6,7,8\n", 1, "column 'z' missing"),
    (f"{HEADER6},x,y,z,qw,qx\n1,2,3,4,5,6,7,8,9,1,0\n", 1, "column 'qy' missing"),
    (f"{HEADER6},qw,qx,qy,qz\n1,2,3,4,5,6,1,0,0,0\n", 1, "need the position columns"),
    (f"{HEADER6},tau1\n1,2,3,4,5,6,7\n", 1, "column 'tau2' missing"),
    (f"{HEADER6},x,y,z,qw,qx,qy,qz\n1,2,3,4,5,6,0,0,0,0.5,0,0,0\n", 2, "norm is 0.5"),
    (f"{HEADER6},,x\n1,2,3,4,5,6,7,8\n", 1, "column 7 has an empty name"),
    (f"{HEADER6}\n1,2,3,4,5,__import__('os')\n", 2, "is not a number"),
    (f"{HEADER6}\n1,2,3,4,5,\"6\x00\"\n", 2, "column 'q6': '6\\x00' is not a number"),
    (f"{HEADER6}\n1,2,3,4,5,6\n1,2,3,4,5,\"6\"x\n", 3, "not valid CSV"),
    ("# only a comment\n\n", 0, "no header line"),
    (f"{HEADER6}\n# no data\n", 1, "no data rows"),
]


@pytest.mark.parametrize("text, line, fragment", BAD, ids=[b[2][:30] for b in BAD])
def test_bad_input_is_one_line_naming_file_and_line(tmp_path, text, line, fragment):
    path = _write(tmp_path, text)
    with pytest.raises(ParseError) as info:
        read_measurements(path, PUMA)
    message = str(info.value)
    assert "\n" not in message
    assert message.startswith(f"{path}:{line}: " if line else f"{path}: "), message
    assert fragment in message, message


def test_not_utf8_names_the_line(tmp_path):
    path = tmp_path / "m.csv"
    path.write_bytes(f"{HEADER6}\n1,2,3,4,5,6\n1,2,\xff\xfe,4,5,6\n".encode("latin-1"))
    with pytest.raises(ParseError, match=r"m\.csv:3: not UTF-8"):
        read_measurements(str(path), PUMA)


def test_bounds_rows_and_bytes(tmp_path, monkeypatch):
    from denavit.calibration import _measurements as mod  # the bounds are module constants; shrink them here

    path = _write(tmp_path, f"{HEADER6}\n" + "1,2,3,4,5,6\n" * 4)
    monkeypatch.setattr(mod, "MAX_ROWS", 3)
    with pytest.raises(ParseError, match=r"m\.csv:5: more than 3 data rows"):
        read_measurements(path, PUMA)
    monkeypatch.setattr(mod, "MAX_FILE_BYTES", 20)
    with pytest.raises(ParseError, match=r"file too large \(\d+ bytes; at most 20\)"):
        read_measurements(path, PUMA)


def test_bad_units_refused(tmp_path):
    path = _write(tmp_path, f"{HEADER6}\n1,2,3,4,5,6\n")
    with pytest.raises(ParseError, match="angle_unit"):
        read_measurements(path, PUMA, angle_unit="grad")
    with pytest.raises(ParseError, match="torque_scale"):
        read_measurements(path, PUMA, torque_scale=float("nan"))


def test_write_refuses_bad_columns(tmp_path):
    with pytest.raises(ShapeError, match="different lengths"):
        write_measurements(tmp_path / "a.csv", {"q1": [1, 2], "q2": [1]})
    with pytest.raises(ShapeError, match="finite"):
        write_measurements(tmp_path / "a.csv", {"q1": [1, np.nan]})
    with pytest.raises(ShapeError, match="column name"):
        write_measurements(tmp_path / "a.csv", {"q,1": [1]})
    assert not list(tmp_path.iterdir())  # nothing written, no temporary left


finite = st.floats(-1e6, 1e6, allow_nan=False, allow_infinity=False, allow_subnormal=False)


@settings(max_examples=10 if REDUCED else 25)
@given(st.integers(1, 8).flatmap(lambda m: st.tuples(
    st.lists(st.lists(finite, min_size=6, max_size=6), min_size=m, max_size=m),
    st.lists(st.lists(finite, min_size=3, max_size=3), min_size=m, max_size=m),
    st.lists(st.lists(st.floats(0.1, 1.0), min_size=4, max_size=4), min_size=m, max_size=m))))
def test_write_then_read_round_trip(tmp_path_factory, data):
    q, xyz, quat = (np.array(v, dtype=float) for v in data)
    quat /= np.linalg.norm(quat, axis=1, keepdims=True)
    path = tmp_path_factory.mktemp("rt") / "m.csv"
    write_measurements(path, {"q": q, "x": xyz[:, 0], "y": xyz[:, 1], "z": xyz[:, 2], "qw": quat[:, 0],
                              "qx": quat[:, 1], "qy": quat[:, 2], "qz": quat[:, 3], "note": np.zeros(len(q))},
                       comment="simulated\nsecond line")
    m = read_measurements(path, PUMA)
    np.testing.assert_array_equal(m.q, q)  # repr's digits read back bit for bit
    np.testing.assert_array_equal(m.position, xyz)
    np.testing.assert_allclose(m.quaternion, quat, rtol=0, atol=1e-15)
    assert m.notes and "'note'" in m.notes[0]
    np.testing.assert_array_equal(m.lines, np.arange(len(q)) + 4)  # two comment lines and the header first


@settings(max_examples=15 if REDUCED else 60)
@given(st.lists(st.text(alphabet=st.sampled_from(list("q1234567xyzwtau,.-+e#\"' \t\r\x00\u2028nfi")), max_size=40),
                max_size=6),
       st.binary(max_size=20))
def test_any_text_is_read_or_refused_with_one_line(tmp_path_factory, lines, tail):
    """Random header and rows (and random bytes at the end): a Measurements or one ParseError line, nothing else."""
    path = tmp_path_factory.mktemp("hostile") / "m.csv"
    path.write_bytes(("\n".join([HEADER6 + ",x,y,z", *lines]) + "\n").encode("utf-8") + tail)
    try:
        m = read_measurements(path, PUMA)
    except ParseError as exc:
        assert "\n" not in str(exc) and str(exc).startswith(str(path))
    else:
        assert m.q.shape[1] == 6 and np.all(np.isfinite(m.q)) and np.all(np.isfinite(m.position))
