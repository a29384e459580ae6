"""collapse_angle_sums is sympy's TR10i found by lookup: the same expression, on random sums of products of
sines and cosines (angle sums expanded, symbolic, rational, radical and float coefficients), on the entries of
random DH arms, and on the shapes it hands to TR10i. The reference is sympy's own TR10i."""

from __future__ import annotations

import numpy as np
import sympy as sp
from conftest import REDUCED, robots
from hypothesis import given, settings
from hypothesis import strategies as st
from sympy.simplify.fu import TR10i

from denavit.symbolic import forward_kinematics_sym
from denavit.symbolic._angle_sums import collapse_angle_sums

Q = sp.symbols("q1:5", real=True)
A, D = sp.symbols("a d", real=True)
COEFFS = [1, -1, 2, sp.Rational(-1, 2), A, -D, A * D, sp.sqrt(2), sp.sqrt(3), 3, sp.Float(0.25)]


@st.composite
def angles(draw) -> sp.Expr:
    """q_i, or a sum of two or three of them, sometimes plus π/2."""
    qs = draw(st.lists(st.sampled_from(Q), min_size=1, max_size=3, unique=True))
    return sum(qs) + draw(st.sampled_from([0, 0, 0, sp.pi / 2]))


@st.composite
def trig_sums(draw) -> sp.Expr:
    """An expanded sum of products: coefficient · (expanded sine or cosine of an angle sum) · a few factors."""
    e = sp.S.Zero
    for _ in range(draw(st.integers(1, 4))):
        t = draw(st.sampled_from(COEFFS))
        for _ in range(draw(st.integers(1, 3))):
            f = draw(st.sampled_from([sp.cos, sp.sin]))(draw(angles()))
            t *= sp.expand_trig(f) if draw(st.booleans()) else f
        e += t
    return sp.expand(e)


def _same_value(e: sp.Expr, r: sp.Expr) -> bool:
    vals = {s: v for s, v in zip(sorted(e.free_symbols, key=str), np.linspace(0.3, 1.9, len(e.free_symbols)))}
    return abs(complex(e.evalf(subs=vals)) - complex(r.evalf(subs=vals))) < 1e-9


@settings(max_examples=30 if REDUCED else 80)
@given(trig_sums())
def test_same_as_tr10i_on_random_sums(e):
    r = collapse_angle_sums(e)
    assert r == TR10i(e)
    assert _same_value(e, r)


@settings(max_examples=3 if REDUCED else 8)
@given(robots(n_rows=3, base_tool=False))
def test_same_as_tr10i_on_random_arms(robot):
    """Entries of a random 3-row arm's pose (floats, both conventions, prismatic and fixed rows), expanded."""
    T = forward_kinematics_sym(robot, "none")
    for e in T[:3, :]:
        e = sp.expand(e)
        assert collapse_angle_sums(e) == TR10i(e)


def test_collapses_the_textbook_pairs():
    q1, q2, q3 = Q[:3]
    c, s = sp.cos, sp.sin
    e = sp.expand(A * c(q1) * c(q2) * c(q3) - A * s(q1) * s(q2) * c(q3) - A * c(q1) * s(q2) * s(q3)
                  - A * s(q1) * c(q2) * s(q3) + D * s(q2) * c(q3) + D * c(q2) * s(q3))
    assert collapse_angle_sums(e) == A * c(q1 + q2 + q3) + D * s(q2 + q3)


def test_other_shapes_go_to_tr10i():
    """Shapes outside the lookup's reasoning (a sum inside a product, a reciprocal cosine) still give TR10i's
    answer; a lone product is returned unchanged."""
    q1, q2 = Q[:2]
    c, s = sp.cos, sp.sin
    inner = (c(q1) * c(q2) - s(q1) * s(q2)) * (A + s(q1))
    for e in (inner, c(q2) / c(q1) - s(q1) * s(q2) / c(q1) ** 2, A * c(q1) * s(q2)):
        assert collapse_angle_sums(e) == TR10i(e)
