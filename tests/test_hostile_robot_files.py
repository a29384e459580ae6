"""Hostile robot files (issue 14): generated mutations of valid files, each run through ``denavit fk``.

A valid arm is drawn at random, then one mutation from a family is applied: deep nesting, huge numbers, wrong
types in every field, YAML aliases, duplicate keys, joint expressions that are not ``q + constant``,
non-physical inertia, garbage bytes.  Every case meets the contract of ``tests/_hostile.py`` (exit 2, one
stderr line naming the file, nothing on stdout, files unchanged, within the time bound) — or, for the
mutations that may leave a valid file, ends with exit 0.  Then the specific triggers of the issue, an alias
bomb in a memory-limited child, and the control: every catalogue arm written by ``convert`` loads again
with exit 0 and the same forward kinematics.
"""

from __future__ import annotations

import json
import math
import re
from pathlib import Path

import numpy as np
import pytest
import yaml
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from _hostile import assert_accepted_quietly, assert_refused, run_cli, run_cli_limited, corpus

import denavit
from denavit import forward_kinematics, load_robot

CASES = settings(max_examples=corpus(50), deadline=None, derandomize=True,
                 suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow])
MANY = settings(CASES, max_examples=corpus(80))

# --------------------------------------------------------------------------------------------------
# valid arms and how they are written


def rotation(draw) -> np.ndarray:
    """A random rotation (QR of a Gaussian matrix, sign-fixed to det +1)."""
    seed = draw(st.integers(0, 2**32 - 1))
    Q, R = np.linalg.qr(np.random.default_rng(seed).normal(size=(3, 3)))
    Q = Q * np.sign(np.diag(R))
    return Q if np.linalg.det(Q) > 0 else -Q


def tensor(moments, R) -> np.ndarray:
    return R @ np.diag(moments) @ R.T


@st.composite
def physical_inertia(draw) -> dict:
    """Inertial data of a real body: principal moments that satisfy the triangle inequality, in a rotated frame."""
    p1, p2 = draw(st.floats(0.01, 1.0)), draw(st.floats(0.01, 1.0))
    p3 = draw(st.floats(abs(p1 - p2), p1 + p2))
    I = tensor([p1, p2, p3], rotation(draw))
    six = [I[0, 0], I[1, 1], I[2, 2], I[0, 1], I[0, 2], I[1, 2]]
    return {"mass": draw(st.floats(0.1, 20.0)), "com": [draw(st.floats(-0.5, 0.5)) for _ in range(3)],
            "inertia": [float(x) for x in six]}


@st.composite
def valid_robots(draw) -> dict:
    n = draw(st.integers(1, 4))
    rows = []
    for k in range(n):
        prismatic = k > 0 and draw(st.booleans())
        row: dict = {"a": draw(st.sampled_from([0, 0.3, "0.25", 1])), "alpha": draw(st.sampled_from([0, "pi/2", "-pi/2", 1.2])),
                     "d": "q" if prismatic else draw(st.sampled_from([0, 0.1, "0.4"])),
                     "theta": draw(st.sampled_from([0, "pi/4"])) if prismatic else draw(st.sampled_from(["q", "q + pi/2", "q - 0.3"]))}
        if draw(st.booleans()):
            row["limits"] = [0, 0.5] if prismatic else draw(st.sampled_from([[-1, 1], ["-pi", "pi"], ["-170deg", "170deg"]]))
        if draw(st.booleans()):
            row["inertia"] = draw(physical_inertia())
        rows.append(row)
    data: dict = {"name": "arm", "convention": draw(st.sampled_from(["standard", "modified"])), "joints": rows}
    if draw(st.booleans()):
        data["gravity"] = [0, 0, -9.81]
    if draw(st.booleans()):
        data["base"] = {"xyz": [0, 0, 0.5], "rpy": [0, 0, "pi/2"]}
    return data


def _toml_value(v) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, (int, float)):
        return repr(v)
    if isinstance(v, str):
        return json.dumps(v)
    if isinstance(v, dict):
        return "{" + ", ".join(f"{json.dumps(str(k))} = {_toml_value(x)}" for k, x in v.items()) + "}"
    return "[" + ", ".join(_toml_value(x) for x in v) + "]"


def write(data: dict, fmt: str) -> str:
    if fmt == "json":
        return json.dumps(data)
    if fmt == "toml":
        return "".join(f"{json.dumps(k)} = {_toml_value(v)}\n" for k, v in data.items())
    return yaml.safe_dump(data, sort_keys=False, default_flow_style=True, width=10_000)


def fk_argv(name: str, data: dict) -> list[str]:
    return ["fk", name, "-q", ",".join("0" for _ in data["joints"])]


def places(data: dict) -> list[tuple]:
    """Every place a value sits in a robot's data: (key, ...) paths."""
    out: list[tuple] = [("convention",), ("name",), ("joints",)]
    for i, row in enumerate(data["joints"]):
        out += [("joints", i, f) for f in row if f not in ("inertia", "limits")]
        if "limits" in row:
            out += [("joints", i, "limits"), ("joints", i, "limits", 0), ("joints", i, "limits", 1)]
        if "inertia" in row:
            out += [("joints", i, "inertia", "mass"), ("joints", i, "inertia", "com"), ("joints", i, "inertia", "com", 2),
                    ("joints", i, "inertia", "inertia"), ("joints", i, "inertia", "inertia", 0)]
    if "gravity" in data:
        out += [("gravity",), ("gravity", 2)]
    if "base" in data:
        out += [("base", "xyz", 1), ("base", "rpy", 2)]
    return out


def put(data: dict, path: tuple, value) -> dict:
    data = json.loads(json.dumps(data))  # a deep copy
    target = data
    for key in path[:-1]:
        target = target[key]
    target[path[-1]] = value
    return data


def refused(folder: Path, data_or_text, fmt: str, data: dict, mentions=()) -> None:
    name = f"robot.{fmt}"
    text = data_or_text if isinstance(data_or_text, (str, bytes)) else write(data_or_text, fmt)
    o = run_cli(fk_argv(name, data), folder, {name: text})
    assert_refused(o, mentions=[name, *mentions])


def refused_or_fine(folder: Path, text, fmt: str, data: dict) -> None:
    name = f"robot.{fmt}"
    o = run_cli(fk_argv(name, data), folder, {name: text})
    if o.code == 0:
        assert_accepted_quietly(o)
        assert "T_0_e" in o.out
    else:
        assert_refused(o)


# --------------------------------------------------------------------------------------------------
# the families


@CASES
@given(valid_robots(), st.sampled_from(["yaml", "json"]), st.booleans())
def test_valid_files_are_accepted(tmp_path, data, fmt, toml):
    """The control of every family: the unmutated arms load and compute (exit 0, nothing on stderr)."""
    fmt = "toml" if toml else fmt
    name = f"robot.{fmt}"
    o = run_cli(fk_argv(name, data), tmp_path, {name: write(data, fmt)})
    assert_accepted_quietly(o)
    assert o.err == "" and "T_0_e" in o.out


@CASES
@given(valid_robots(), st.sampled_from(["yaml", "json", "toml"]), st.integers(21, 1500), st.data())
def test_deep_nesting_is_refused(tmp_path, data, fmt, depth, draw):
    path = draw.draw(st.sampled_from(places(data)))
    text = write(put(data, path, "@DEEP@"), fmt).replace('"@DEEP@"', "[" * depth + "1" + "]" * depth)
    text = text.replace("'@DEEP@'", "[" * depth + "1" + "]" * depth).replace("@DEEP@", "[" * depth + "1" + "]" * depth)
    refused(tmp_path, text, fmt, data, mentions=["nested"])


huge_values = st.one_of(
    st.floats(1.01e6, 1e308).flatmap(lambda x: st.sampled_from([x, -x])),
    st.sampled_from(["10^60", "1e300*1e300", "exp(700)", "-1e7", "2^64", "1e308 + 1e308", "1/1e-300"]),
)


@MANY
@given(valid_robots(), st.sampled_from(["yaml", "json", "toml"]), st.one_of(huge_values, st.integers(101, 6000)), st.data())
def test_huge_numbers_are_refused(tmp_path, data, fmt, value, draw):
    """Values beyond the documented bounds (|x| <= 1e6 SI, angles <= 1000 rad) or with > 100 digits."""
    numeric = [p for p in places(data) if p[-1] not in ("limits", "com", "inertia", "gravity", "convention", "name", "joints")
               and not (p[0] == "joints" and len(p) == 3 and data["joints"][p[1]][p[2]] == "q")]
    path = draw.draw(st.sampled_from(numeric))
    if isinstance(value, int):  # an integer literal of that many digits, written into the text
        text = write(put(data, path, "@NUM@"), fmt)
        value_text = "9" * value
        text = text.replace('"@NUM@"', value_text).replace("'@NUM@'", value_text).replace("@NUM@", value_text)
        refused(tmp_path, text, fmt, data)
        return
    old = data
    for key in path:
        old = old[key]
    if isinstance(old, str) and "q" in old.split():  # keep the joint variable: theta: q + 1e7
        value = f"q + ({value})"
    refused(tmp_path, put(data, path, value), fmt, data)


wrong_values = st.sampled_from([None, True, [], {}, [1, 2], {"x": 1}, "", "1 +", "abc(", "$", "os.system('x')",
                                "__import__('os')", "q9", "L99", "1e", "(1", "[1]", "nan", "inf", "1..2", "sin", "q q"])


@MANY
@given(valid_robots(), st.sampled_from(["yaml", "json"]), wrong_values, st.data())
def test_wrong_types_in_every_field(tmp_path, data, fmt, value, draw):
    """Each field given a value of the wrong kind: refused naming the file (a few top-level ones may be fine)."""
    path = draw.draw(st.sampled_from(places(data)))
    text = write(put(data, path, value), fmt)
    if path[0] == "joints" and len(path) >= 3:
        refused(tmp_path, text, fmt, data)
    else:
        refused_or_fine(tmp_path, text, fmt, data)


@CASES
@given(valid_robots(), st.integers(9, 30), st.integers(5, 12), st.data())
def test_alias_bombs_are_refused(tmp_path, data, width, levels, draw):
    """Billion laughs: a few lines whose aliases expand to width**levels entries, placed in any field."""
    if width**levels < 10**6:
        levels = math.ceil(6 / math.log10(width))
    bomb = "[&a0 [" + ", ".join(["lol"] * width) + "]"
    for k in range(1, levels):
        bomb += f", &a{k} [" + ", ".join([f"*a{k - 1}"] * width) + "]"
    bomb += "]"
    path = draw.draw(st.sampled_from(places(data) + [("description",)]))
    text = write(put(data, path, "@BOMB@"), "yaml").replace("'@BOMB@'", bomb).replace("@BOMB@", bomb)
    refused(tmp_path, text, "yaml", data, mentions=["aliases"])


@CASES
@given(valid_robots(), st.data())
def test_alias_loops_refused_and_plain_aliases_fine(tmp_path, data, draw):
    rows = write({"joints": data["joints"]}, "yaml")[len("{joints: "):-2]
    loop = f"convention: standard\njoints: &j [{rows.strip()[1:-1]}, *j]\n"
    refused(tmp_path, loop, "yaml", data, mentions=["alias"])
    # a benign alias: the first row's values reused by name (an anchor on a scalar)
    fine = yaml.safe_dump(data, sort_keys=False).replace("name: arm", "name: &n arm", 1) + "description: *n\n"
    o = run_cli(fk_argv("robot.yaml", data), tmp_path, {"robot.yaml": fine})
    assert_accepted_quietly(o)


@CASES
@given(valid_robots(), st.sampled_from(["yaml", "json"]), st.sampled_from(["convention", "name", "a", "alpha", "d", "theta"]))
def test_duplicate_keys_are_refused(tmp_path, data, fmt, key):
    text = write(data, fmt)
    if fmt == "json":
        text = text.replace(f'"{key}": ', f'"{key}": 0, "{key}": ', 1)
    else:
        text = re.sub(rf"(?<=[{{ ]){key}: ", f"{key}: 0, {key}: ", text, count=1)
    refused(tmp_path, text, fmt, data, mentions=["twice", key])


not_linear = st.one_of(
    st.sampled_from(["q*q", "abs(q)", "sqrt(q^2)", "-q", "q + q", "exp(log(q))", "cos(q)", "atan2(q, 1)", "q^1",
                     "(q)*1", "q*q^0", "q - q + q", "0*q + q", "q/1", "-(-q)*1"]),
    st.floats(0.01, 10).filter(lambda c: abs(c - 1) > 1e-9).flatmap(lambda c: st.sampled_from([
        f"{c!r}*q", f"q*{c!r}", f"q + sin({c!r}*q)", f"q/{c!r}", f"(q + {c!r})*{c!r}", f"{c!r} - q", f"q + {c!r}*q",
        f"q^{c!r}", f"q + {c!r}*sin(2*pi*q)"])),
)


@MANY
@given(valid_robots(), not_linear, st.data())
def test_joint_expressions_other_than_q_plus_constant_are_refused(tmp_path, data, expr, draw):
    k = draw.draw(st.integers(0, len(data["joints"]) - 1))
    row = data["joints"][k]
    field = "d" if row["d"] == "q" else "theta"
    refused(tmp_path, put(data, ("joints", k, field), expr), "yaml", data, mentions=[f"row {k + 1}", field])


@CASES
@given(valid_robots(), st.floats(-5, 5), st.sampled_from(["q + {c}", "{c} + q", "q - ({c})", "({c}) + q + 0"]))
def test_q_plus_constant_is_accepted_with_its_offset(tmp_path, data, c, form):
    """The twin of the refusals: q plus a q-free term gives that term as the offset (checked by math.)"""
    data = put(data, ("joints", 0, "theta"), form.format(c=repr(c)))
    data = put(data, ("joints", 0, "d"), 0)
    data["joints"][0].pop("limits", None)
    path = tmp_path / "robot.yaml"
    path.write_text(write(data, "yaml"))
    robot = load_robot(path)
    want = -c if "q - " in form else c
    assert robot.links[0].theta == pytest.approx(want, abs=1e-12)


@st.composite
def bad_inertia(draw) -> tuple[dict, str]:
    R = rotation(draw)
    kind = draw(st.sampled_from(["negative mass", "negative moment", "triangle", "asymmetric", "short matrix"]))
    p1, p2 = draw(st.floats(0.01, 1.0)), draw(st.floats(0.01, 1.0))
    mass = draw(st.floats(0.1, 10))
    if kind == "negative mass":
        return {"mass": -mass, "inertia": [p1, p1, p1, 0, 0, 0]}, "mass"
    if kind == "negative moment":
        I = tensor([-draw(st.floats(0.01, 1.0)), p1, p2], R)
        return {"mass": mass, "inertia": [float(x) for x in (I[0, 0], I[1, 1], I[2, 2], I[0, 1], I[0, 2], I[1, 2])]}, "negative"
    if kind == "triangle":
        I = tensor([p1, p2, (p1 + p2) * draw(st.floats(1.2, 10))], R)
        return {"mass": mass, "inertia": [float(x) for x in (I[0, 0], I[1, 1], I[2, 2], I[0, 1], I[0, 2], I[1, 2])]}, "triangle"
    if kind == "asymmetric":
        I = tensor([p1, p2, (p1 + p2) / 2 + abs(p1 - p2) / 2], R)
        i, j = draw(st.sampled_from([(0, 1), (0, 2), (1, 2), (1, 0), (2, 0), (2, 1)]))
        I[i, j] += draw(st.floats(1e-3, 1.0)) * draw(st.sampled_from([1, -1]))
        return {"mass": mass, "inertia": I.tolist()}, "symmetric"
    rows = draw(st.sampled_from([[[1], [2], [3]], [[1, 0, 0], [0, 1, 0]], [[1, 0], [0, 1], [0, 0]], [[1, 0, 0], [0, 1, 0], [0, 0]]]))
    return {"mass": mass, "inertia": rows}, "3 rows of 3"


@MANY
@given(valid_robots(), bad_inertia(), st.sampled_from(["yaml", "json"]), st.data())
def test_non_physical_inertia_is_refused(tmp_path, data, case, fmt, draw):
    inertia, reason = case
    k = draw.draw(st.integers(0, len(data["joints"]) - 1))
    refused(tmp_path, put(data, ("joints", k, "inertia"), inertia), fmt, data, mentions=[f"row {k + 1}", "inertia", reason])


@MANY
@given(st.one_of(st.binary(max_size=3000), st.text(max_size=2000).map(lambda t: t.encode("utf-8", "surrogatepass"))),
       st.sampled_from(["yaml", "json", "toml"]))
def test_garbage_bytes_are_refused(tmp_path, blob, fmt):
    data = {"joints": [{}]}
    refused(tmp_path, blob, fmt, data)


@CASES
@given(valid_robots(), st.sampled_from(["yaml", "json", "toml"]), st.binary(min_size=1, max_size=40), st.data())
def test_garbage_spliced_into_a_valid_file(tmp_path, data, fmt, blob, draw):
    text = write(data, fmt).encode()
    at = draw.draw(st.integers(0, len(text)))
    refused_or_fine(tmp_path, text[:at] + blob + text[at:], fmt, data)


# --------------------------------------------------------------------------------------------------
# the specific triggers of the issue

GOOD = "convention: standard\njoints:\n  - {a: 1, alpha: 0, d: 0, theta: q}\n  - {a: 1, alpha: 0, d: 0, theta: q}\n"


@pytest.mark.parametrize("fmt, text", [
    ("yaml", "convention: standard\njoints: " + "[" * 1000 + "]" * 1000 + "\n"),
    ("yaml", "convention: standard\njoints:\n" + "".join("  " * k + "- \n" for k in range(1, 300))),
    ("json", '{"convention": "standard", "joints": ' + "[" * 1000 + "]" * 1000 + "}"),
    ("json", '{"a": ' * 1000 + "1" + "}" * 1000),
    ("toml", 'convention = "standard"\njoints = ' + "[" * 1000 + "]" * 1000 + "\n"),
    ("toml", "x = " + "{a = " * 1000 + "1" + "}" * 1000 + "\n"),
])
def test_nesting_1000_deep(tmp_path, fmt, text):
    o = run_cli(["fk", f"r.{fmt}", "-q", "0"], tmp_path, {f"r.{fmt}": text})
    assert_refused(o, mentions=[f"r.{fmt}", "nested"])


def test_billion_laughs_in_a_memory_limited_child(tmp_path):
    lines = ["a0: &a0 [" + ", ".join(["lol"] * 10) + "]"]
    lines += [f"a{k}: &a{k} [" + ", ".join([f"*a{k - 1}"] * 10) + "]" for k in range(1, 10)]
    text = "\n".join(lines) + "\nconvention: standard\nname: *a9\njoints: [{theta: q}]\n"
    o = run_cli_limited(["show", "bomb.yaml"], tmp_path, {"bomb.yaml": text}, memory_limit=1024**3)
    assert_refused(o, mentions=["bomb.yaml", "aliases"])
    assert o.seconds < 5


@pytest.mark.parametrize("fmt, text, fragment", [
    ("yaml", "convention: standard\njoints:\n  - {a: " + "1" * 5000 + ", theta: q}\n", "digits"),
    ("yaml", "convention: standard\njoints:\n  - {a: " + "1" * 400 + ", theta: q}\n", "digits"),
    ("yaml", "convention: standard\njoints:\n  - {a: '" + "1" * 400 + "', theta: q}\n", "row 1, field 'a'"),
    ("json", '{"convention": "standard", "joints": [{"theta": "q", "a": ' + "1" * 5000 + "}]}", "digits"),
    ("toml", 'convention = "standard"\njoints = [{theta = "q", a = ' + "1" * 5000 + "}]\n", "digits"),
    ("json", '{"convention": "standard", "name": "\\ud800", "joints": [{"theta": "q"}]}', "surrogate"),
    ("json", '{"convention": "standard", "joints": [{"theta": "q", "a": "\\udfff"}]}', "surrogate"),
    ("yaml", "convention: standard\njoints:\n  - {a: 1e308, theta: q}\n", "out of range"),
    ("yaml", "convention: standard\njoints:\n  - {theta: q, limits: [-1e308, 1e308]}\n", "field 'limits'"),
    ("yaml", "convention: standard\ngravity: [0, 0, -1e300]\njoints:\n  - {theta: q}\n", "gravity"),
    ("yaml", "convention: standard\njoints:\n  - {theta: q, inertia: {mass: 1, inertia: [[1],[2],[3]]}}\n", "inertia"),
    ("yaml", "convention: standard\njoints:\n  - {theta: q, inertia: {mass: 1e300}}\n", "mass"),
    ("yaml", "convention: standard\njoints:\n  - {theta: q}\n" + "  - {theta: q}\n" * 32, "too many joints"),
    ("yaml", "convention: standard\nparameters: {" + ", ".join(f"p{k}: 1" for k in range(257)) + "}\njoints: [{theta: q}]\n",
     "too many parameters"),
    ("yaml", "convention: standard\njoints:\n  - {alpha: 1001, theta: q}\n", "field 'alpha'"),
    ("yaml", "convention: standard\nname: [1, 2]\njoints:\n  - {theta: q}\n", "name"),
])
def test_specific_triggers(tmp_path, fmt, text, fragment):
    name = f"r.{fmt}"
    o = run_cli(["show", name], tmp_path, {name: text})
    assert_refused(o, mentions=[name, fragment])


def test_file_size_cap(tmp_path):
    text = GOOD + "#" + "x" * 300_000 + "\n"
    o = run_cli(["show", "big.yaml"], tmp_path, {"big.yaml": text})
    assert_refused(o, mentions=["big.yaml", "too large"])


@pytest.mark.parametrize("q", ["1,,2", "[1,2", "1 2,", "(1, 2", "1, 2)", "[1, 2)", ",1,2", "1,2,", "((1), 2"])
def test_malformed_value_lists(tmp_path, q):
    o = run_cli(["fk", "r.yaml", "-q", q], tmp_path, {"r.yaml": GOOD})
    assert_refused(o, mentions=["q"])


@pytest.mark.parametrize("q, want", [("0, pi/4", [0, math.pi / 4]), ("[0 0.5]", [0, 0.5]), ("(-\\pi/3, 0)", [-math.pi / 3, 0]),
                                     ("0.1 0.2", [0.1, 0.2]), ("90deg, 0", [math.pi / 2, 0]), ("atan2(1, 1) 0", [math.pi / 4, 0])])
def test_accepted_value_lists(tmp_path, q, want):
    o = run_cli(["fk", "r.yaml", "-q", q, "--json"], tmp_path, {"r.yaml": GOOD})
    assert_accepted_quietly(o)
    np.testing.assert_allclose(json.loads(o.out)["q"], want, atol=1e-15)


def test_parse_values_is_linear_and_capped():
    import time

    from denavit import ParseError
    from denavit.io import MAX_VALUES, parse_values

    text = ", ".join(["(1)"] * MAX_VALUES)
    t0 = time.process_time()
    assert parse_values(text).sum() == MAX_VALUES
    assert time.process_time() - t0 < 3.0  # CPU seconds
    with pytest.raises(ParseError, match="more than"):
        parse_values(", ".join(["1"] * 20_000))
    with pytest.raises(ParseError, match="longer than"):
        parse_values(" " * 300_000 + "1")


def test_long_sum_in_a_claimless_expression_does_not_recurse():
    from denavit import _expr

    tree = ("num", "1")
    for _ in range(5000):
        tree = ("bin", "+", tree, ("bin", "*", ("num", "1"), ("name", "x")))
    assert _expr.evaluate(tree, {"x": 2.0}) == 10_001
    assert _expr.names_in(tree) == {"x"}
    assert _expr.to_text(tree).count("+") == 5000


# --------------------------------------------------------------------------------------------------
# --param, degrees, output polish

PARAM = """convention: standard
parameters: {L: 1.0, g: 9.81, m: 2.0, L2: L*2}
joints:
  - {a: L, alpha: 0, d: 0, theta: q, limits: [-L, L], inertia: {mass: m, com: [-L/2, 0, 0], inertia: [0, m*L^2/12, m*L^2/12, 0, 0, 0]}}
  - {a: L2, alpha: 0, d: 0, theta: q}
base: {xyz: [0, 0, L], rpy: [0, 0, 0]}
gravity: [0, 0, -g]
"""


@settings(max_examples=corpus(40), deadline=None, derandomize=True, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(st.floats(0.1, 3.0), st.floats(0.5, 20.0), st.floats(0.5, 5.0))
def test_param_reevaluates_every_field(tmp_path, L, g, m):
    """--param L=… equals the file with the value written in (an independent route through the loader)."""
    (tmp_path / "p.yaml").write_text(PARAM)
    (tmp_path / "w.yaml").write_text(PARAM.replace("{L: 1.0, g: 9.81, m: 2.0,", f"{{L: {L!r}, g: {g!r}, m: {m!r},"))
    a = load_robot(tmp_path / "p.yaml", L=L, g=g, m=m)
    b = load_robot(tmp_path / "w.yaml")
    for r in (a, denavit.with_parameters(load_robot(tmp_path / "p.yaml"), L=L, g=g, m=m)):
        assert r.q_limits[0].tolist() == pytest.approx([-L, L])
        assert r.gravity == pytest.approx((0, 0, -g))
        assert r.base_matrix[2, 3] == pytest.approx(L)
        assert r.links[0].inertia.mass == pytest.approx(m)
        assert r.links[0].inertia.inertia[1] == pytest.approx(m * L**2 / 12)
    assert a.links[1].a == pytest.approx(2 * L)
    assert a.replace(name=b.name, source=b.source) == b
    q = np.random.default_rng(0).uniform(-0.5, 0.5, (4, 2)) * min(L, 1)
    np.testing.assert_allclose(forward_kinematics(a, q), forward_kinematics(b, q), atol=1e-12)


def test_unknown_param_lists_the_valid_names(tmp_path):
    o = run_cli(["fk", "p.yaml", "-q", "0,0", "--param", "L9=1"], tmp_path, {"p.yaml": PARAM})
    assert_refused(o, mentions=["L9", "L, g, m, L2"])
    o = run_cli(["fk", "p.yaml", "-q", "0,0", "--param", "L=1e300"], tmp_path, {"p.yaml": PARAM})
    assert_refused(o, mentions=["out of range"])


@pytest.mark.parametrize("field, value", [("alpha", "90"), ("alpha", "-180"), ("theta", "q + 90"), ("limits", "[-170, 170]")])
def test_degrees_without_angle_unit_warn_with_the_fix(tmp_path, field, value):
    row = {"alpha": "0", "theta": "q", "limits": "[-1, 1]"}
    row[field] = value
    text = "convention: standard\njoints:\n  - {a: 1, alpha: %s, theta: %s, limits: %s}\n" % (row["alpha"], row["theta"], row["limits"])
    o = run_cli(["fk", "r.yaml", "-q", "0", "--ignore-limits"], tmp_path, {"r.yaml": text})
    assert_accepted_quietly(o)
    lines = o.err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("denavit fk: warning: r.yaml: row 1")
    number = re.search(r"-?\d+", value.replace("q + ", "")).group()
    assert "angle_unit: deg" in lines[0] and f"{number}deg" in lines[0]
    with pytest.warns(denavit.errors.DenavitWarning, match="angle_unit: deg"):
        load_robot(tmp_path / "r.yaml")
    # the same numbers in a degree file, or angles that name their unit, draw no warning
    for quiet in ("angle_unit: deg\n" + text, text.replace(value, value.replace("90", "pi/2").replace("180", "pi")
                                                            .replace("170", "170deg"))):
        o = run_cli(["fk", "r.yaml", "-q", "0", "--ignore-limits"], tmp_path, {"r.yaml": quiet})
        assert_accepted_quietly(o)
        assert o.err == ""


def test_show_is_readable(tmp_path):
    text = ("convention: standard\nangle_unit: deg\njoints:\n  - {a: 1, alpha: -90, theta: q, limits: [-170, 170]}\n"
            "  - {a: 1, alpha: 0, theta: q - 30}\n")
    o = run_cli(["show", "r.yaml"], tmp_path, {"r.yaml": text})
    assert_accepted_quietly(o)
    assert "deg(" not in o.out and "+ 0" not in o.out
    row1 = next(line for line in o.out.splitlines() if line.startswith("1 "))
    row2 = next(line for line in o.out.splitlines() if line.startswith("2 "))
    # columns of the DH table (denavit.dh_table): j, joint, a, α, d, θ, limits
    assert row1.split()[3] == "-90°" and row1.split()[5] == "q1" and "[-170°, 170°]" in row1
    assert "q2 - 30°" in row2


def test_robots_accepts_deg(tmp_path):
    o = run_cli(["robots", "--deg"], tmp_path)
    assert_accepted_quietly(o)
    assert "puma560" in o.out


def test_convert_refuses_unsupported_suffix_before_work(tmp_path):
    o = run_cli(["convert", "puma560", "--to", "modified", "-o", "x.png"], tmp_path)
    assert_refused(o, mentions=["x.png", ".png"])
    assert not (tmp_path / "x.png").exists()
    with pytest.raises(denavit.ParseError, match="unsupported"):
        denavit.save_robot(load_robot("puma560"), tmp_path / "x.png")


@pytest.mark.parametrize("name", denavit.catalogue_names())
@pytest.mark.parametrize("target", ["standard", "modified"])
def test_catalogue_converted_files_are_clean_and_round_trip(tmp_path, name, target):
    """Control: every catalogue arm written by convert loads with exit 0 and the same FK, and reads well."""
    o = run_cli(["convert", name, "--to", target, "-o", "c.yaml"], tmp_path)
    assert_accepted_quietly(o)
    text = (tmp_path / "c.yaml").read_text()
    back = run_cli(["show", "c.yaml"], tmp_path)
    assert_accepted_quietly(back)
    assert back.err == ""
    a, b = load_robot(name), load_robot(tmp_path / "c.yaml")
    q = np.random.default_rng(7).uniform(-1, 1, (8, a.dof))
    np.testing.assert_allclose(forward_kinematics(b, q), forward_kinematics(a, q), atol=1e-12)
    assert not re.search(r"\de-(1[3-9]|[2-9]\d)\b", text), "rounding noise written"
    assert not re.search(r"'-?[\d.]+'|\"-?[\d.]+\"", text), "a number written quoted"
    assert max(len(line) for line in text.splitlines() if not line.startswith("description:")) <= 130
    for row in yaml.safe_load(text)["joints"]:
        for v in (row["alpha"], row["theta"]):
            if isinstance(v, float):  # an exact multiple of pi/12 is written as such, not as a decimal
                assert all(abs(v * k / math.pi - round(v * k / math.pi)) > 1e-9 for k in (1, 2, 3, 4, 6, 8, 12))
    assert b.has_dynamics == a.has_dynamics
    if a.has_dynamics:
        from denavit import mass_matrix
        np.testing.assert_allclose(mass_matrix(b, q), mass_matrix(a, q), atol=1e-9)


def test_parameter_inertia_is_checked_with_its_values(tmp_path):
    """Inertia written with parameters is checked once the values are in: from the file and after --param."""
    text = ("convention: standard\nparameters: {Ia: 1, Ib: 1, Ic: 1.5}\n"
            "joints:\n  - {a: 1, theta: q, inertia: {mass: 1, inertia: [Ia, Ib, Ic, 0, 0, 0]}}\n")
    o = run_cli(["fk", "r.yaml", "-q", "0"], tmp_path, {"r.yaml": text})
    assert_accepted_quietly(o)
    o = run_cli(["fk", "r.yaml", "-q", "0", "--param", "Ic=5"], tmp_path, {"r.yaml": text})
    assert_refused(o, mentions=["r.yaml", "row 1", "inertia", "triangle"])
    o = run_cli(["fk", "r.yaml", "-q", "0", "--param", "Ia=-1"], tmp_path, {"r.yaml": text})
    assert_refused(o, mentions=["r.yaml", "row 1", "negative"])
    with pytest.raises(denavit.ParseError, match="triangle"):
        denavit.with_parameters(load_robot(tmp_path / "r.yaml"), Ic=5)


@pytest.mark.parametrize("suffix", [".json", ".yml"])
def test_convert_writes_json_and_yml_that_load_back(tmp_path, suffix):
    o = run_cli(["convert", "puma560", "--to", "modified", "-o", f"c{suffix}"], tmp_path)
    assert_accepted_quietly(o)
    a, b = load_robot("puma560"), load_robot(tmp_path / f"c{suffix}")
    q = np.random.default_rng(3).uniform(-1, 1, (5, 6))
    np.testing.assert_allclose(forward_kinematics(b, q), forward_kinematics(a, q), atol=1e-12)
    again = run_cli(["convert", "puma560", "--to", "modified", "-o", f"c{suffix}", "--no-clobber"], tmp_path)
    assert_refused(again, mentions=[f"c{suffix}", "--no-clobber"])
