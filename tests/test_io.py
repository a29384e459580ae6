"""Robot files: every format, units, expressions, parameters, and clear errors naming file/row/field."""

import json
import math

import numpy as np
import pytest

import denavit
from denavit import JointType, ParseError, forward_kinematics, load_robot, robot_from_dict
from denavit.io import dump_robot, parse_values, robot_to_dict, save_robot

BASIC = """
name: demo
convention: modified
angle_unit: rad
parameters: {H1: 0.5, L1: 0.5, L2: L1 * 0.8}
joints:
  - {a: 0,  alpha: 0,    d: H1, theta: q, limits: [-pi, pi]}
  - {a: 0,  alpha: 0,    d: 0,  theta: q2}
  - {a: L1, alpha: pi/2, d: 0,  theta: q + pi/2}
  - {a: L2, alpha: 0,    d: q,  theta: 0, limits: [0, 0.3]}
tool: {a: 0, alpha: pi/2, d: 0, theta: 0}
base: {xyz: [0, 0, 0.1], rpy: [0, 0, 90deg]}
gravity: [0, 0, -9.81]
"""


def write(tmp_path, text, name="robot.yaml"):
    p = tmp_path / name
    p.write_text(text)
    return p


def test_basic_file_reads_everything(tmp_path):
    r = load_robot(write(tmp_path, BASIC))
    assert r.dof == 4 and r.n_rows == 5
    assert r.joint_types == (JointType.REVOLUTE, JointType.REVOLUTE, JointType.REVOLUTE, JointType.PRISMATIC)
    assert r.links[-1].joint is JointType.FIXED
    assert r.links[2].theta == pytest.approx(math.pi / 2)
    assert r.links[3].a == pytest.approx(0.4)
    assert r.links[3].q_limits == (0.0, 0.3)
    assert dict(r.links[0].symbols)["d"] == "H1"
    np.testing.assert_allclose(r.base_matrix[:3, 3], [0, 0, 0.1])
    np.testing.assert_allclose(r.base_matrix[:3, 0], [0, 1, 0], atol=1e-15)


def test_degree_file_equals_radian_file(tmp_path):
    deg = """
convention: standard
angle_unit: deg
joints:
  - {a: 1, alpha: 90, d: 0, theta: q + 30, limits: [-170, 170]}
  - {a: 1, alpha: -pi/2, d: 0, theta: q, limits: [-90deg, 90deg]}
"""
    rad = """
convention: standard
joints:
  - {a: 1, alpha: pi/2, d: 0, theta: q + pi/6, limits: [-170deg, 170deg]}
  - {a: 1, alpha: -pi/2, d: 0, theta: q, limits: [-pi/2, pi/2]}
"""
    a, b = load_robot(write(tmp_path, deg, "a.yaml")), load_robot(write(tmp_path, rad, "b.yaml"))
    q = np.array([0.3, -0.2])
    np.testing.assert_allclose(forward_kinematics(a, q), forward_kinematics(b, q), atol=1e-14)
    np.testing.assert_allclose(a.q_limits, b.q_limits, atol=1e-14)


def test_toml_and_json_equal_yaml(tmp_path):
    y = load_robot(write(tmp_path, BASIC))
    data = robot_to_dict(y)
    j = load_robot(write(tmp_path, json.dumps(data), "r.json"))
    toml_text = """
convention = "modified"
parameters = { H1 = 0.5, L1 = 0.5, L2 = "L1 * 0.8" }
joints = [
  { a = 0, alpha = 0, d = "H1", theta = "q", limits = ["-pi", "pi"] },
  { a = 0, alpha = 0, d = 0, theta = "q" },
  { a = "L1", alpha = "pi/2", d = 0, theta = "q + pi/2" },
  { a = "L2", alpha = 0, d = "q", theta = 0, limits = [0, 0.3] },
]
tool = { a = 0, alpha = "pi/2", d = 0, theta = 0 }
base = { xyz = [0, 0, 0.1], rpy = [0, 0, "90deg"] }
"""
    t = load_robot(write(tmp_path, toml_text, "r.toml"))
    q = np.array([0.1, 0.2, 0.3, 0.1])
    for other in (j, t):
        np.testing.assert_allclose(forward_kinematics(other, q), forward_kinematics(y, q), atol=1e-14)


@pytest.mark.parametrize("name", denavit.catalogue_names())
def test_dump_and_reload_round_trip(tmp_path, name):
    robot = load_robot(name)
    path = tmp_path / f"{name}.yaml"
    save_robot(robot, path)
    again = load_robot(path)
    q = np.random.default_rng(0).uniform(-1, 1, (3, robot.dof))
    np.testing.assert_allclose(forward_kinematics(again, q), forward_kinematics(robot, q), atol=1e-12)
    assert again.parameters == robot.parameters
    assert [l.inertia is None for l in again.links] == [l.inertia is None for l in robot.links]
    assert dump_robot(robot, "json")


def test_parameters_override_and_keep_symbols():
    r = load_robot("report000-6r", L1=0.9)
    assert r.parameter_values["L1"] == 0.9
    T = forward_kinematics(r, np.zeros(6))
    base = forward_kinematics(load_robot("report000-6r"), np.zeros(6))
    assert T[0, 3] == pytest.approx(base[0, 3] + 0.4)
    with pytest.raises(ParseError, match="no parameter"):
        load_robot("report000-6r", L9=1)


def test_save_refuses_to_overwrite(tmp_path):
    p = write(tmp_path, "precious")
    with pytest.raises(ParseError, match="not overwriting"):
        save_robot(load_robot("planar2r"), p)
    assert p.read_text() == "precious"


BAD = [
    ("convention: standard\njoints: [{a: 0, theta: q\n", "malformed YAML at line"),
    ("convention: sideways\njoints: [{theta: q}]\n", "convention"),
    ("convention: standard\njoints: [{a: L9, theta: q}]\n", "row 1, field 'a': unknown symbol 'L9'"),
    ("convention: standard\njoints: [{a: 1, d: q, theta: q}]\n", "row 1, field 'theta'.*both"),
    ("convention: standard\njoints: [{a: q, theta: 0}]\n", "row 1, field 'a'"),
    ("convention: standard\njoints: [{theta: q}, {theta: q1}]\n", "row 2, field 'theta'.*q1 names joint 1"),
    ("convention: standard\njoints: [{theta: 2*q}]\n", "coefficient 1"),
    ("convention: standard\njoints: [{theta: q, limits: [1, -1]}]\n", "row 1, field 'limits'.*above"),
    ("convention: standard\njoints: [{theta: q, colour: red}]\n", "row 1.*unknown field 'colour'"),
    ("convention: standard\njoints: [{a: \"__import__('os')\", theta: q}]\n", "row 1, field 'a'.*character"),
    ("convention: standard\njoints: [{a: \"().__class__\", theta: q}]\n", "row 1, field 'a'"),
    ("convention: standard\njoints: [{a: \"lambda: 1\", theta: q}]\n", "row 1, field 'a'"),
    ("convention: standard\njoints: [{a: \"9**9**9\", theta: q}]\n", "row 1, field 'a'.*exponent"),
    ("convention: standard\njoints: [{a: .nan, theta: q}]\n", "row 1, field 'a'.*finite"),
    ("convention: standard\njoints: [{a: .inf, theta: q}]\n", "row 1, field 'a'.*finite"),
    ("convention: standard\njoints: [{a: 1, theta: 0}]\n", "at least one joint"),
    ("convention: standard\njoints: []\n", "non-empty"),
    ("- just a list\n", "mapping"),
    ("convention: standard\nparameters: {q: 1}\njoints: [{theta: q}]\n", "cannot be a parameter"),
    ("convention: standard\njoints: [{theta: q, inertia: {mass: -1}}]\n", "mass must be non-negative"),
    ("convention: standard\njoints: [{theta: q, inertia: {com: [1, 2]}}]\n", "com.*3 values"),
    ("convention: standard\ngravity: [0, 0]\njoints: [{theta: q}]\n", "gravity"),
]


@pytest.mark.parametrize("text, message", BAD)
def test_bad_files_name_the_place(tmp_path, text, message):
    p = write(tmp_path, text)
    with pytest.raises(ParseError, match=message) as info:
        load_robot(p)
    assert str(p) in str(info.value)
    assert "\n" not in str(info.value)


def test_unknown_robot_says_where_the_catalogue_is_listed():
    with pytest.raises(ParseError, match=r"the \d+ built-in names: denavit robots, or denavit.catalogue_names\(\)"):
        load_robot("no-such-robot")
    with pytest.raises(ParseError, match="did you mean scara or scara-rrrp"):
        load_robot("scarra")
    with pytest.raises(ParseError, match="no such robot file"):
        load_robot("missing.yaml")


def test_parse_values():
    np.testing.assert_allclose(parse_values("0, pi/4, 90deg, -sqrt(2)/2"), [0, math.pi / 4, math.pi / 2, -math.sqrt(2) / 2])
    np.testing.assert_allclose(parse_values("[1 2 3]"), [1, 2, 3])
    np.testing.assert_allclose(parse_values("atan2(1, 1), 2"), [math.pi / 4, 2])
    np.testing.assert_allclose(parse_values("90, pi/2", deg=True), [math.pi / 2, math.pi / 2])
    with pytest.raises(ParseError, match="expected 3 values, got 2"):
        parse_values("1, 2", 3)
    with pytest.raises(ParseError, match="value 2"):
        parse_values("1, os.system", 2)


def test_robot_from_dict_directly():
    r = robot_from_dict({"convention": "standard", "joints": [{"a": 1, "theta": "q"}, {"a": 1, "theta": "q"}]})
    np.testing.assert_allclose(forward_kinematics(r, [0, 0])[:3, 3], [2, 0, 0])


# --------------------------------------------------------------------------------------------------
# issue 14: property tests of the hardened reader (library level, fast)

from hypothesis import HealthCheck, given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402

from denavit import LinkInertia, ModelError  # noqa: E402
from denavit._safeload import MAX_NESTING, load_data  # noqa: E402

FAST = settings(max_examples=250, deadline=None, derandomize=True, suppress_health_check=[HealthCheck.too_slow])

_scalars = st.one_of(st.integers(-10**6, 10**6), st.floats(-1e6, 1e6), st.text(st.characters(codec="utf-8",
                     exclude_categories=("Cs", "Cc")), max_size=12), st.booleans(), st.none())
_plain_data = st.recursive(_scalars, lambda c: st.one_of(st.lists(c, max_size=4),
                           st.dictionaries(st.text("abcxyz_", min_size=1, max_size=5), c, max_size=4)), max_leaves=25)


@FAST
@given(_plain_data)
def test_safe_loader_reads_plain_data_like_the_standard_parsers(data):
    """Within the limits the safe loader returns what json/yaml return (an independent parser as reference)."""
    import yaml

    assert load_data(json.dumps(data), ".json", "f.json") == json.loads(json.dumps(data))
    text = yaml.safe_dump(data)
    assert load_data(text, ".yaml", "f.yaml") == yaml.safe_load(text)


@FAST
@given(st.dictionaries(st.text("abcdef", min_size=1, max_size=3), st.integers(), min_size=1, max_size=5), st.data())
def test_safe_loader_refuses_a_repeated_key(mapping, draw):
    key = draw.draw(st.sampled_from(sorted(mapping)))
    body = ", ".join(f'"{k}": {v}' for k, v in mapping.items())
    for text, suffix in ((f"{{{body}, \"{key}\": 1}}", ".json"), ("{" + body.replace('"', "") + f", {key}: 1}}", ".yaml")):
        with pytest.raises(ParseError, match=f"'{key}' given twice"):
            load_data(text, suffix, "f")


@FAST
@given(st.integers(MAX_NESTING + 1, 3000), st.sampled_from([".json", ".yaml", ".toml"]))
def test_safe_loader_refuses_deep_nesting_quickly(depth, suffix):
    text = ("x = " if suffix == ".toml" else "") + "[" * depth + "]" * depth
    with pytest.raises(ParseError, match="nested"):
        load_data(text, suffix, "f")


def _rotation(seed: int) -> np.ndarray:
    Q, R = np.linalg.qr(np.random.default_rng(seed).normal(size=(3, 3)))
    Q = Q * np.sign(np.diag(R))
    return Q if np.linalg.det(Q) > 0 else -Q


def _six(I):
    return (I[0, 0], I[1, 1], I[2, 2], I[0, 1], I[0, 2], I[1, 2])


@FAST
@given(st.floats(1e-3, 10), st.floats(1e-3, 10), st.floats(0, 1), st.integers(0, 2**32 - 1), st.floats(0.01, 100))
def test_inertia_of_a_real_body_is_accepted_in_any_frame(p1, p2, t, seed, mass):
    """Principal moments within the triangle inequality, rotated arbitrarily: accepted, tensor kept."""
    p3 = abs(p1 - p2) + t * (p1 + p2 - abs(p1 - p2))
    R = _rotation(seed)
    I = R @ np.diag([p1, p2, p3]) @ R.T
    li = LinkInertia(mass=mass, inertia=_six(I))
    np.testing.assert_allclose(np.linalg.eigvalsh(li.inertia_matrix), sorted([p1, p2, p3]), rtol=1e-9, atol=1e-12)


@FAST
@given(st.floats(1e-3, 10), st.floats(1e-3, 10), st.floats(1.2, 50), st.integers(0, 2**32 - 1), st.booleans())
def test_inertia_no_body_has_is_refused_in_any_frame(p1, p2, factor, seed, negative):
    """A negative principal moment, or I3 > (I1 + I2) by more than the documented 10 %: ModelError."""
    moments = [-p1, p2, p2] if negative else [p1, p2, (p1 + p2) * factor]
    R = _rotation(seed)
    with pytest.raises(ModelError, match="negative" if negative else "triangle"):
        LinkInertia(mass=1.0, inertia=_six(R @ np.diag(moments) @ R.T))


@FAST
@given(st.lists(st.floats(-1e3, 1e3).map(lambda x: round(x, 6)), min_size=1, max_size=12),
       st.sampled_from([", ", ",", "; ", " ", "  "]), st.sampled_from(["{}", "[{}]", "({})", "  {}  "]))
def test_parse_values_reads_every_accepted_form(values, sep, wrap):
    text = wrap.format(sep.join(repr(v) for v in values))
    np.testing.assert_array_equal(parse_values(text), values)
    assert parse_values(text, len(values)).shape == (len(values),)


@FAST
@given(st.lists(st.integers(-99, 99).map(str), min_size=2, max_size=8), st.data())
def test_parse_values_refuses_empty_values_and_unbalanced_brackets(values, draw):
    k = draw.draw(st.integers(0, len(values)))
    broken = draw.draw(st.sampled_from([
        ", ".join(values[:k] + [""] + values[k:]),          # 1,,2 or ,1,2 or 1,2,
        "[" + ", ".join(values),                               # [1,2
        ", ".join(values) + ")",                               # 1,2)
        " ".join(values) + ",",                                # 1 2,
        "(" + ", ".join(values) + "]",                         # (1,2]
    ]))
    with pytest.raises(ParseError):
        parse_values(broken)


_OFFSETS = {  # form -> the offset it means, computed by Python's math (an independent route)
    "q + {c}": lambda c, d: c, "{c} + q": lambda c, d: c, "q - {c}": lambda c, d: -c,
    "{c} - {d} + q": lambda c, d: c - d, "q + {c}*{d}": lambda c, d: c * d,
    "(q) + sin({c})": lambda c, d: math.sin(c), "q + ({c} - {d})": lambda c, d: c - d,
}


@FAST
@given(st.floats(-3, 3), st.floats(-3, 3), st.sampled_from(sorted(_OFFSETS)))
def test_q_plus_any_constant_gives_that_constant(c, d, form):
    """The offset read from ``q + f`` equals f."""
    text = form.format(c=f"({c!r})", d=f"({d!r})")
    r = robot_from_dict({"convention": "standard", "joints": [{"theta": text}]})
    assert r.links[0].theta == pytest.approx(_OFFSETS[form](c, d), abs=1e-12)


@pytest.mark.parametrize("name", denavit.catalogue_names())
def test_convert_keeps_inertia_expressions_that_still_hold(name):
    """After a convention change every kept expression still evaluates to the stored value."""
    from denavit._convert import convert_convention
    from denavit import _expr

    robot = load_robot(name)
    for target in ("standard", "modified"):
        out = convert_convention(robot, target)
        for link in out.links:
            if link.inertia is None:
                continue
            li = link.inertia
            values = {"mass": li.mass, "motor_inertia": li.motor_inertia, "viscous": li.viscous,
                      "coulomb": li.coulomb, **{f"com{i}": c for i, c in enumerate(li.com)},
                      **{f"inertia{i}": c for i, c in enumerate(li.inertia)}}
            for key, text in li.symbols:
                assert _expr.evaluate(_expr.parse(text), robot.parameter_values) == pytest.approx(values[key], abs=1e-12)
