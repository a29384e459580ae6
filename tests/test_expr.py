"""The restricted expression parser: values, exact sympy forms, and hostile input refused."""

import math

import pytest
import sympy as sp
from hypothesis import given, settings
from hypothesis import strategies as st

from denavit import ParseError
from denavit._expr import evaluate, names_in, parse, to_sympy, to_text


@pytest.mark.parametrize(
    "text, value",
    [
        ("pi/2", math.pi / 2),
        ("-sqrt(3)/2", -math.sqrt(3) / 2),
        ("2^3^2", 2.0 ** 9),
        ("2**-1", 0.5),
        ("-2^2", -4.0),
        ("90deg", math.pi / 2),
        ("(45 + 45)deg", math.pi / 2),
        ("deg(180)", math.pi),
        ("atan2(1, 1)", math.pi / 4),
        ("1.5e-3 * 2", 3e-3),
        ("3 - 2 - 1", 0.0),
        ("8 / 4 / 2", 1.0),
        ("\u2212\u03c0", -math.pi),
    ],
)
def test_parse_evaluate_known_values(text, value):
    assert evaluate(parse(text)) == pytest.approx(value, abs=1e-15)


def test_parameters_and_exact_sympy():
    L1 = sp.Symbol("L1", real=True)
    tree = parse("L1 + 0.4*cos(pi/6)")
    assert names_in(tree) == {"L1"}
    assert evaluate(tree, {"L1": 1.0}) == pytest.approx(1 + 0.4 * math.sqrt(3) / 2)
    expr = to_sympy(tree, {"L1": L1})
    assert sp.simplify(expr - (L1 + sp.Rational(1, 5) * sp.sqrt(3))) == 0


@pytest.mark.parametrize(
    "text, fragment",
    [
        ("__import__('os')", "character"),
        ("__import__(1)", "unknown function"),
        ("().__class__", "unexpected"),
        ("a.b", "character"),
        ("lambda x: x", "unexpected"),
        ("9**9**9", "exponent"),
        ("exp(1000)", "cannot evaluate"),
        ("(" * 200 + "1" + ")" * 200, "nested"),
        ("1+" * 400 + "1", "longer than"),
        ("open('f')", "character"),
        ("sin", "parentheses"),
        ("1 +", "end of expression"),
        ("1/0", "cannot evaluate"),
        ("unknown_name", "unknown symbol"),
        ("", "empty"),
        ("sqrt(1, 2)", "argument"),
    ],
)
def test_hostile_or_malformed_input_is_refused_with_a_reason(text, fragment):
    with pytest.raises(ParseError, match=fragment):
        evaluate(parse(text), {})


def test_huge_power_refused_in_sympy_too():
    with pytest.raises(ParseError, match="exponent"):
        to_sympy(parse("x^1000"), {"x": sp.Symbol("x")})


def test_nan_and_inf_refused():
    for v in (float("nan"), float("inf")):
        with pytest.raises(ParseError):
            parse(v)


# Round trip: canonical text parses back to the same tree (random trees).
_leaf = st.one_of(
    st.integers(0, 50).map(lambda i: ("num", str(i))),
    st.sampled_from([("name", "x"), ("name", "pi"), ("name", "L1")]),
)


def _extend(children):
    return st.one_of(
        st.tuples(st.just("neg"), children),
        st.tuples(st.just("bin"), st.sampled_from("+-*/"), children, children),
        st.tuples(st.just("call"), st.sampled_from(["sin", "cos", "sqrt"]), st.tuples(children)),
    )


@settings(max_examples=200, deadline=None)
@given(st.recursive(_leaf, _extend, max_leaves=12))
def test_text_round_trip_preserves_value(tree):
    env = {"x": 0.37, "L1": 1.3}
    text = to_text(tree)
    try:
        v1 = evaluate(tree, env)
    except ParseError:
        return
    assert evaluate(parse(text), env) == pytest.approx(v1, rel=1e-12, abs=1e-12)


@pytest.mark.slow
@settings(max_examples=60, deadline=None, derandomize=True)
@given(st.lists(st.integers(-9, 9), min_size=500, max_size=4000), st.sampled_from("+-*"))
def test_long_chains_fold_without_recursion(values, op):
    """A left-deep chain of thousands of terms (``1+1+…+1``): every walker finishes, with the exact result."""
    tree = ("num", str(values[0]))
    for v in values[1:]:
        tree = ("bin", op, tree, ("num", str(abs(v))) if op == "*" else ("num", str(v)))
    text = to_text(tree)
    assert names_in(tree) == set()
    if op == "*":
        return  # the product overflows or is zero; the point is that it is walked at all
    want = values[0] + sum(values[1:]) * (1 if op == "+" else -1)
    assert evaluate(tree) == want
    assert text.count(op) >= len(values) - 1
