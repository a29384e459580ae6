"""Hostile claims files (issue 14): the specific triggers of the campaign, and a generated corpus.

A claims file that cannot be read as a whole (not YAML, not a list of claims, nesting or alias bombs, duplicate
keys, too many claims) is bad input: the contract of ``_hostile.assert_refused`` (exit 2, one line naming the file,
nothing on stdout, nothing written).  A readable file is judged claim by claim: a claim that cannot be read gets
its own "unreadable" verdict with the reason, the others are still judged, and the exit code is 0 — never a
traceback, an "internal error" or a hang.
"""

from __future__ import annotations

import json
import string

import numpy as np
import pytest
import yaml
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import denavit as dn
from denavit.check import MAX_CLAIMS

from _hostile import TIME_LIMIT, assert_refused, run_cli, run_cli_limited, corpus

ROBOT = "planar2r"
L1, L2 = dict(dn.load_robot(ROBOT).parameters)["L1"], dict(dn.load_robot(ROBOT).parameters)["L2"]


@pytest.fixture(scope="module", autouse=True)
def _warm(tmp_path_factory):
    """Import the checker's modules once, so the first generated case is not timed with the imports."""
    run_cli(["check", ROBOT, "c.yaml"], tmp_path_factory.mktemp("warm"),
            {"c.yaml": _file({"quantity": "position", "value": [1, 2, 3]},
                             {"quantity": "singularities", "rows": "vx,vy", "value": "none"})})


def _check(tmp_path, text: str | bytes, *extra: str):
    return run_cli(["check", ROBOT, "claims.yaml", "--json", *extra], tmp_path, {"claims.yaml": text})


def _verdicts(o) -> list[dict]:
    assert not o.hung and o.code == 0, o.describe()
    assert "Traceback" not in o.err and "internal error" not in o.err, o.describe()
    data = json.loads(o.out)
    assert sum(data["summary"].values()) == len(data["claims"])
    for c in data["claims"]:  # the per-claim safety net must never be what answered
        assert "checker failed" not in c["message"], c
    return data["claims"]


def _file(*claims: dict) -> str:
    return yaml.safe_dump({"robot": ROBOT, "claims": list(claims)}, sort_keys=False, width=10**9)


# --- specific triggers: one claim unreadable, with the reason, quickly ------------------------------------------

LONG_SUM = "+".join(["1"] * 3000)
LONG_PRODUCT = "*".join(["1"] * 3000)


@pytest.mark.parametrize("claim, words", [
    ({"quantity": "position", "entry": 1, "value": LONG_SUM}, ["too long"]),
    ({"quantity": "position", "entry": 1, "value": LONG_PRODUCT}, ["too long"]),
    ({"quantity": "position", "entry": 1, "value": "L_1 C_1 " + "+ 0 " * 2000}, ["too long"]),
    ({"quantity": "position", "entry": 1, "value": "9" * 400}, ["digits"]),
    ({"quantity": "position", "entry": 1, "value": "9" * 5000}, ["digits"]),
    ({"quantity": "position", "entry": 1, "value": "\\theta_{" + "1" * 5000 + "}"}, ["digits"]),
    ({"quantity": "position", "entry": 1, "value": "\\theta_{" + "1 " * 3000 + "}"}, ["unknown symbol"]),
    ({"quantity": "position", "entry": 1, "value": "C_{" + "1" * 500 + "}"}, ["digits"]),
    ({"quantity": "position", "value": "\\begin{bmatrix} 1 & " * 900}, ["without its \\end"]),
    ({"quantity": "position", "value": "\\begin{pmatrix}" * 4000}, ["longer than"]),
    ({"quantity": "singularities", "rows": 5, "value": "q_2 = 0"}, ["'rows'"]),
    ({"quantity": "singularities", "rows": [1, 2], "value": "q_2 = 0"}, ["'rows'"]),
    ({"quantity": "singularities", "rows": {"a": 1}, "value": "q_2 = 0"}, ["'rows'"]),
    ({"quantity": "singularities", "value": "q_2 = k\\pi/99999999"}, ["divisor", "12"]),
    ({"quantity": "singularities", "value": "q_2 = k\\pi/" + "9" * 5000}, ["divisor"]),
    ({"quantity": "singularities", "value": "q_2 = " + ", ".join(["0"] * 500)}, ["too many values"]),
    ({"quantity": "singularities", "value": ["q_2 = 0"] * 40}, ["too many conditions"]),
    ({"quantity": "ik_formula", "joint": "x", "value": "atan2(p_y, p_x)"}, ["'joint'", "'x'"]),
    ({"quantity": "ik_formula", "joint": "x", "value": "q_1 = atan2(p_y, p_x)"}, ["'joint'"]),
    ({"quantity": "ik_formula", "joint": 10**30, "value": "atan2(p_y, p_x)"}, ["'joint'"]),
    ({"quantity": "ik_formula", "joint": [1], "value": "atan2(p_y, p_x)"}, ["'joint'"]),
    ({"quantity": "ik_formula", "where": {f"w{k}": "1" for k in range(50)}, "value": "q_1 = w1"}, ["'where'"]),
    ({"quantity": "position", "value": "1.2.3"}, ["malformed number"]),
    # the claim kinds of issue 13: bad keys and names are that claim's "unreadable", with the reason
    ({"quantity": "omega", "index": "x", "value": [0, 0, 0]}, ["'index'"]),
    ({"quantity": "omega", "index": 10**30, "value": [0, 0, 0]}, ["'index'"]),
    ({"quantity": "force", "index": 1, "value": [0, 0, 0]}, ["wrench"]),
    ({"quantity": "force", "index": 1, "wrench": "[f_x]", "value": [0, 0, 0]}, ["wrench", "got 1"]),
    ({"quantity": "force", "index": 1, "wrench": "f_q, 0, 0", "value": [0, 0, 0]}, ["wrench", "unknown symbol"]),
    ({"quantity": "moment", "index": 1, "wrench": "0," * 5000, "value": [0, 0, 0]}, ["wrench"]),
    ({"quantity": "force", "index": 1, "wrench": "f_x, 0, 0", "value": "[F_y, 0, 0]"}, ["unknown symbol"]),
    ({"quantity": "dh_matrix", "convention": "weird", "value": "1"}, ["'convention'"]),
    ({"quantity": "dh_matrix", "value": "\\input{/etc/passwd}"}, ["unsupported latex command"]),
    ({"quantity": "dh_matrix", "value": "\\begin{bmatrix} L_1 \\end{bmatrix}"}, ["unknown symbol"]),
    ({"quantity": "ik_formula", "point": "elbow", "value": "q_1 = atan2(p_y, p_x)"}, ["'point'"]),
    ({"quantity": "ik_formula", "point": "wrist", "value": "q_1 = atan2(p_y, p_x)"}, ["wrist"]),
    ({"quantity": "ik_formula", "value": "\\cos(q_1 + 1) = 0.5"}, ["joint variable"]),
    ({"quantity": "det_jacobian", "value": "1"}, ["square"]),
    ({"quantity": "det_jacobian", "rows": "vx", "value": "1"}, ["square"]),
    ({"quantity": "com_position", "index": 9, "value": [0, 0, 0]}, ["'index'"]),
    ({"quantity": "jacobian", "rows": "vx,vq", "value": [[1, 2]]}, ["'rows'"]),
    ({"quantity": "position", "q": "(" * 100 + "0, 0" + ")" * 100, "value": [1, 2, 0]}, ["q"]),
    ({"quantity": "position", "q": "0^{\\circ\\circ}, 0", "value": [1, 2, 0]}, ["q"]),
    ({"quantity": "position", "entry": 1, "where": "x", "value": "1"}, ["'where'"]),
    ({"quantity": "position", "entry": 1, "where": {"a": "a"}, "value": "a"}, ["where a", "unknown symbol"]),
    ({"quantity": "position", "entry": 1, "where": {"x" * 5000: "1"}, "value": "1"}, ["'where' name"]),
    ({"quantity": "position", "entry": 1, "where": {f"w{k}": "1" for k in range(50)}, "value": "1"}, ["'where'"]),
    ({"quantity": "position", "entry": 1, "where": {f"w{k}": (f"w{k - 1}*w{k - 1}" if k else "9") for k in range(20)},
      "value": "w19"}, ["not finite"]),
    ({"quantity": "position", "entry": 1, "where": {"q_1": "3"}, "value": "q_1"}, ["cannot redefine"]),
    ({"quantity": "position", "entry": 1, "where": {"L_1": "3"}, "value": "L_1"}, ["cannot redefine"]),
    ({"quantity": "det_jacobian", "rows": "vx,vy", "value": [["+".join(["q_1"] * 390)] * 6] * 6}, ["too large"]),
    ({"quantity": "relation", "value": "(" * 100 + "J" + ")" * 100 + " = J"}, ["nested too deeply"]),
    ({"quantity": "relation", "value": "J = " + "J + " * 6000 + "J"}, ["longer than"]),
    ({"quantity": "relation", "value": "\\tau = \\frac{1}{0} F"}, ["division by zero"]),
    ({"quantity": "relation", "value": "\\tau = 1e300 1e300 F"}, ["not finite"]),
    ({"quantity": "relation", "value": "\\input{/etc/passwd} = J"}, ["unsupported"]),
    ({"quantity": "relation", "value": "J_{" + "1" * 500 + "} = J"}, ["digits"]),
    ({"quantity": "relation", "joints": "x", "value": "J_i = J_i"}, ["'joints'"]),
])
def test_trigger_is_one_unreadable_claim(tmp_path, claim, words):
    good = {"id": "good", "quantity": "position", "value": ["L_1 C_1 + L_2 C_{12}", "L_1 S_1 + L_2 S_{12}", 0]}
    o = _check(tmp_path, _file(good, {"id": "bad", **claim}, good))
    assert o.seconds < 5, o.describe()
    first, bad, last = _verdicts(o)
    assert first["verdict"] == last["verdict"] == "correct"  # the others are still judged
    assert bad["verdict"] == "unreadable", bad
    for w in words:
        assert w.lower() in bad["message"].lower(), bad


def test_powers_of_ten_are_numbers_not_a_name(tmp_path):
    """``1e3`` is one thousand (it was 1·e3 with an unknown symbol e3)."""
    o = _check(tmp_path, _file({"quantity": "position", "q": "0, 0", "value": [f"{(L1 + L2) * 1e3:.6g}e-3", "0", "0"]}))
    (v,) = _verdicts(o)
    assert v["verdict"] == "correct", v


# --- issue 13: one entry of a twist or a Jacobian, incorrect ------------------------------------------------------

def _fd_jacobian_linear(q: np.ndarray) -> np.ndarray:
    """∂p/∂q by central differences of the textbook planar 2R position (an independent route)."""
    def p(q):
        return np.array([L1 * np.cos(q[0]) + L2 * np.cos(q[0] + q[1]), L1 * np.sin(q[0]) + L2 * np.sin(q[0] + q[1])])
    h = 1e-6
    return np.column_stack([(p(q + h * e) - p(q - h * e)) / (2 * h) for e in np.eye(2)])


@pytest.mark.parametrize("claim", [
    {"quantity": "twist", "entry": 1, "qd": "1, 0.5", "value": "5"},
    {"quantity": "twist", "entry": 2, "value": "\\dot\\theta_1 + 7"},
    {"quantity": "jacobian", "entry": [1, 1], "value": "5"},
    {"quantity": "jacobian", "entry": [2, 2], "value": "L_2 S_{12}"},
    {"quantity": "jacobian", "column": 1, "entry": 1, "value": "3"},
])
def test_incorrect_entry_of_twist_or_jacobian_is_judged(tmp_path, claim):
    (v,) = _verdicts(_check(tmp_path, _file(claim)))
    assert v["verdict"] == "incorrect", v
    (e,) = v["entries"]
    q = np.array(v["counterexample"]["q"])
    J = _fd_jacobian_linear(q)
    if claim["quantity"] == "jacobian":
        i, j = (claim["entry"] if isinstance(claim["entry"], list) else [claim["entry"], claim["column"]])
        assert e["expected"] == pytest.approx(J[i - 1, j - 1], abs=1e-6)
    elif "qd" in claim:
        qd = np.array([1.0, 0.5])
        assert e["expected"] == pytest.approx((J @ qd)[claim["entry"] - 1], abs=1e-6)


def test_a_claim_the_checker_fails_on_is_unreadable_and_the_rest_is_judged(tmp_path, monkeypatch):
    """A failure inside the checker (here forced: the truth of `gravity` raises) is that claim's verdict only."""
    import dataclasses

    from denavit.check import _quantities

    def broken(p, spec):
        raise IndexError("forced failure")

    monkeypatch.setitem(_quantities.QUANTITIES, "gravity",
                        dataclasses.replace(_quantities.QUANTITIES["gravity"], truth=broken))
    good = {"quantity": "position", "value": ["L_1 C_1 + L_2 C_{12}", "L_1 S_1 + L_2 S_{12}", 0]}
    o = run_cli(["check", ROBOT, "claims.yaml", "--json"], tmp_path,
                {"claims.yaml": _file(good, {"quantity": "g", "value": [0, 0]}, good)})
    assert o.code == 0 and "Traceback" not in o.err, o.describe()
    a, b, c = json.loads(o.out)["claims"]
    assert a["verdict"] == c["verdict"] == "correct"
    assert b["verdict"] == "unreadable" and "IndexError" in b["message"] and "forced failure" in b["message"]


# --- the file itself is bad input: exit 2, one line naming the file ----------------------------------------------

ALIAS_BOMB = ("a: &a [x,x,x,x,x,x,x,x,x]\nb: &b [*a,*a,*a,*a,*a,*a,*a,*a,*a]\nc: &c [*b,*b,*b,*b,*b,*b,*b,*b,*b]\n"
              "d: &d [*c,*c,*c,*c,*c,*c,*c,*c,*c]\ne: &e [*d,*d,*d,*d,*d,*d,*d,*d,*d]\n"
              "f: &f [*e,*e,*e,*e,*e,*e,*e,*e,*e]\ng: &g [*f,*f,*f,*f,*f,*f,*f,*f,*f]\n"
              "h: &h [*g,*g,*g,*g,*g,*g,*g,*g,*g]\nclaims:\n- quantity: position\n  id: *h\n  value: [1, 2, 3]\n")
BAD_FILES = {
    "not yaml": ("claims: [\n  - {", ["malformed yaml"]),
    "not a mapping": ("42\n", ["claims"]),
    "empty": ("", ["claims"]),
    "claims not a list": ("claims: 3\n", ["list"]),
    "claim not a mapping": ("claims:\n- 3\n", ["claim 1"]),
    "bad angle_unit": ("angle_unit: grad\nclaims: []\n", ["angle_unit"]),
    "angle_unit list": ("angle_unit: [deg]\nclaims: []\n", ["angle_unit"]),
    "deep nesting": ("claims: " + "[" * 1000 + "]" * 1000 + "\n", ["nest"]),
    "deep mappings": ("claims:\n- " + "{a: " * 300 + "1" + "}" * 300 + "\n", ["nest"]),
    "alias bomb": (ALIAS_BOMB, ["aliases"]),
    "block nesting": ("claims:\n" + "".join("  " * k + "- \n" for k in range(60)) + "  " * 60 + "- 1\n", ["nest"]),
    "many entries": ("claims:\n- quantity: position\n  value: [" + ", ".join(["1"] * 60_000) + "]\n", ["entries"]),
    "recursive alias": ("claims: &a\n- *a\n", ["recursive"]),
    "duplicate key": ("claims:\n- quantity: position\n  value: [1, 2, 3]\n  value: [1, 2, 4]\n", ["'value'", "twice"]),
    "duplicate top key": ("claims: []\nclaims: []\n", ["twice"]),
    "huge int": ("claims:\n- quantity: position\n  entry: 1\n  value: " + "9" * 5000 + "\n", ["digits"]),
    "huge int 400": ("claims:\n- quantity: position\n  entry: " + "9" * 400 + "\n  value: 1\n", ["digits"]),
    "not utf-8": (b"claims:\n- quantity: \xff\xfe\n  value: 1\n", ["utf-8"]),
    "too many claims": (yaml.safe_dump({"claims": [{"quantity": "position", "value": [1, 2, 3]}] * (MAX_CLAIMS + 1)}),
                        [str(MAX_CLAIMS + 1)]),
    # the 20-claim cap on costly kinds is gone (issue 13: 500 claims of any kind); its bounds are these two
    "too many sign choices": (yaml.safe_dump({"claims": [{"quantity": "ik_formula", "value": "q_1 = atan2(y, x)"
                                                          + " \\pm 0" * 6}] * 17}), ["1088", "sign choices"]),
    "too many singular row sets": (yaml.safe_dump({"claims": [{"quantity": "singularities", "rows": r, "value": "none"}
                                                              for r in ("vx,vy", "vx,wz", "vy,wz", "vx,vz")]}),
                                   ["4 different rows/frame"]),
}


@pytest.mark.parametrize("name", sorted(BAD_FILES))
def test_bad_claims_file_is_refused(tmp_path, name):
    text, words = BAD_FILES[name]
    assert_refused(_check(tmp_path, text), mentions=["claims.yaml", *words])


def test_alias_bomb_within_a_memory_bound(tmp_path):
    o = run_cli_limited(["check", ROBOT, "claims.yaml"], tmp_path, {"claims.yaml": ALIAS_BOMB},
                        memory_limit=1024**3)
    assert_refused(o, mentions=["claims.yaml", "aliases"])


def test_many_incorrect_claims_in_bounded_time(tmp_path):
    """100 incorrect claims (the cap): each judged, hints only for the first few; seconds, not minutes."""
    claims = [{"quantity": "jacobian", "value": [[1, 2], [3, 4], [0, 0], [0, 0], [0, 0], [1, 2]]}] * 100
    o = _check(tmp_path, _file(*claims))
    vs = _verdicts(o)
    assert [v["verdict"] for v in vs] == ["incorrect"] * 100
    assert o.seconds < TIME_LIMIT
    assert any("first 8 incorrect" in n for n in json.loads(o.out)["notes"])


@pytest.mark.slow
def test_a_file_of_the_most_claims_is_judged_in_bounded_time(tmp_path):
    """MAX_CLAIMS (500) claims of every plain kind, right and wrong, each judged, well inside a minute."""
    kinds = [{"quantity": "position", "value": ["L_1 C_1 + L_2 C_{12}", "L_1 S_1 + L_2 S_{12}", 0]},
             {"quantity": "jacobian", "value": [[1, 2], [3, 4], [0, 0], [0, 0], [0, 0], [1, 2]]},
             {"quantity": "omega", "index": 2, "value": [0, 0, "\\dot\\theta_1 + \\dot\\theta_2"]},
             {"quantity": "torques", "wrench": "F_x, F_y, 0", "value": ["F_x", "F_y"]},
             {"quantity": "K", "value": "\\dot q_1^2"}]
    o = _check(tmp_path, _file(*[kinds[k % len(kinds)] for k in range(MAX_CLAIMS)]))
    vs = _verdicts(o)
    assert len(vs) == MAX_CLAIMS
    assert [v["verdict"] for v in vs[:5]] == ["correct", "incorrect", "correct", "incorrect", "incorrect"]
    assert o.seconds < 60, o.describe()


def test_repeated_singularity_claims_share_the_analysis(tmp_path):
    claims = [{"quantity": "singularities", "rows": "vx,vy", "value": "\\sin\\theta_2 = 0"}] * 20  # the cap
    o = _check(tmp_path, _file(*claims))
    assert [v["verdict"] for v in _verdicts(o)] == ["correct"] * 20
    assert o.seconds < TIME_LIMIT


# --- generated corpus ---------------------------------------------------------------------------------------------

ARM = """name: arm
convention: standard
joints:
  - {a: 1, alpha: 0, d: 0, theta: q, limits: [-pi, pi]}
  - {a: 0.5, alpha: 0, d: 0, theta: q, limits: [-pi, pi]}
"""
CORRECT = [  # a planar 2R with a1 = 1, a2 = 0.5 and no parameters (standard DH), derived by hand
    {"quantity": "position", "value": ["C_1 + 0.5 C_{12}", "S_1 + 0.5 (s_1 c_2 + c_1 s_2)", 0]},
    {"quantity": "position", "value": ["\\cos\\theta_1 + \\frac{1}{2}\\cos(\\theta_1+\\theta_2)",
                                       "\\sin\\theta_1 + 0.5\\sin(\\theta_1+\\theta_2)", "0"]},
    {"quantity": "jacobian", "column": 2, "value": "\\begin{bmatrix} -0.5 S_{12} \\\\ 0.5 C_{12} \\\\ 0 \\\\ 0 "
                                                     "\\\\ 0 \\\\ 1 \\end{bmatrix}"},
    {"quantity": "link_transform", "index": 2, "value": [["C_2", "-S_2", 0, "0.5 C_2"], ["S_2", "C_2", 0, "S_2/2"],
                                                         [0, 0, 1, 0], [0, 0, 0, 1]]},
    {"quantity": "twist", "entry": 6, "value": "\\dot\\theta_1 + \\dot\\theta_2"},
    {"quantity": "singularities", "rows": "vx,vy", "value": "q_2 = 0, \\pi"},
    {"quantity": "omega", "index": 2, "value": [0, 0, "\\dot\\theta_1 + \\dot\\theta_2"]},
    {"quantity": "velocity", "index": 1, "value": ["0", "\\dot\\theta_1", "0"]},
    {"quantity": "force", "index": 1, "wrench": "[f_x, f_y, 0]", "value": ["c_2 f_x - s_2 f_y", "s_2 f_x + c_2 f_y", 0]},
    {"quantity": "moment", "index": 1, "wrench": "[f_x, f_y, 0]", "value": [0, 0, "0.5 f_y"]},
    {"quantity": "torques", "wrench": "F_x, F_y, 0, 0, 0, 0",
     "value": ["-(S_1 + 0.5 S_{12}) F_x + (C_1 + 0.5 C_{12}) F_y", "-0.5 S_{12} F_x + 0.5 C_{12} F_y"]},
    {"quantity": "det_jacobian", "rows": "vx,vy", "value": "\\frac{1}{2} \\sin\\theta_2"},
    {"quantity": "dh_matrix", "value": "\\begin{bmatrix} c\\theta & -s\\theta c\\alpha & s\\theta s\\alpha & a c\\theta \\\\ "
                                       "s\\theta & c\\theta c\\alpha & -c\\theta s\\alpha & a s\\theta \\\\ "
                                       "0 & s\\alpha & c\\alpha & d \\\\ 0 & 0 & 0 & 1 \\end{bmatrix}"},
    {"quantity": "jacobian", "q": "(90^\\circ, -90°)", "value": "[-1, 0; 0.5, 0.5; 1, 1]"},
]


def _check_arm(tmp_path, text: str | bytes):
    return run_cli(["check", "arm.yaml", "claims.yaml", "--json"], tmp_path, {"arm.yaml": ARM, "claims.yaml": text})


def test_corpus_seeds_are_correct_claims(tmp_path):
    """The claims the corpus mutates are right (hand-derived): each is judged correct, all in one file."""
    vs = _verdicts(_check_arm(tmp_path, _file(*CORRECT)))
    assert [v["verdict"] for v in vs] == ["correct"] * len(CORRECT), vs


SAMPLE_TEXT = st.sampled_from([
    "", " ", "1", "-0", "1e3", "1e999", "9" * 60, "\\pi", "\\frac{1}{0}", "\\sqrt{-1}", "x", "L_3", "\\theta_9",
    "\\theta_{0}", "C_{19}", "\\begin{bmatrix}", "\\end{bmatrix}", "\\begin{bmatrix} 1 & 2 \\\\ 3 \\end{bmatrix}",
    "(" * 60 + "1" + ")" * 60, "(" * 30, "}" * 10, "\\frac{", "^{", "_", "&", "\\\\", "\\unknown", "q_1 = ",
    "= = =", "k\\pi/7", "k\\pi/0", "\\pm\\pm\\pm\\pm\\pm\\pm\\pm", "none", "everywhere", "atan2(1)", "\\sin",
    "2^{100}", "10^{400}", "\\exp(1000)", "\\ln 0", "|q_1|", "\\dot", "\\ddot{q}_1", "'", "\u0000", "\ud800",
    LONG_SUM, "+".join(["q_1"] * 500), "\\sqrt{" * 50,
])
ANY_VALUE = st.recursive(
    st.one_of(st.none(), st.booleans(), st.integers(-10**50, 10**50), st.floats(allow_nan=True),
              SAMPLE_TEXT, st.text(string.printable + "θπ±√·×−²", max_size=40)),
    lambda inner: st.one_of(st.lists(inner, max_size=5), st.dictionaries(st.sampled_from(["a", "value", "q"]),
                                                                         inner, max_size=3)),
    max_leaves=12,
)
KEYS = ["quantity", "value", "entry", "index", "column", "rows", "frame", "q", "qd", "wrench", "joint", "where",
        "pose", "T", "from", "to", "deg", "id", "point", "convention", "qdd", "joints"]
QUANTITY_NAMES = ["position", "rotation", "end_effector", "transform", "link_transform", "jacobian", "J0", "Je",
                  "twist", "torques", "mass_matrix", "gravity", "coriolis", "C", "singularities", "ik_formula",
                  "ik_solutions", "bogus", "", "__class__", "omega", "velocity", "force", "moment", "com_position",
                  "com_velocity", "K", "V", "L", "det_jacobian", "dh_matrix", "eom", "z", "p", "relation"]


@st.composite
def mutated_claim(draw) -> dict:
    claim = dict(draw(st.sampled_from(CORRECT)))
    for _ in range(draw(st.integers(0, 3))):
        key = draw(st.sampled_from(KEYS))
        if key == "quantity":
            claim[key] = draw(st.sampled_from(QUANTITY_NAMES))
        elif draw(st.booleans()):
            claim[key] = draw(ANY_VALUE)
        else:
            claim.pop(key, None)
    if claim.get("quantity") in ("singularities", "ik_formula", "ik_solutions") and draw(st.booleans()):
        claim["quantity"] = "position"  # keep the costly kinds a minority: the corpus must stay fast
    return claim


def _judged_or_refused(o, n_claims: int | None) -> None:
    assert not o.hung, o.describe()
    if o.code == 2:
        assert_refused(o, mentions=["claims.yaml"])
        return
    claims = _verdicts(o)
    if n_claims is not None:
        assert len(claims) == n_claims


CORPUS = settings(max_examples=corpus(600), deadline=None, derandomize=True, database=None,
                  suppress_health_check=list(HealthCheck))


@CORPUS
@given(claims=st.lists(mutated_claim(), min_size=1, max_size=3), as_text=st.booleans())
def test_corpus_mutated_claims_are_judged_or_refused(tmp_path_factory, claims, as_text):
    folder = tmp_path_factory.mktemp("c")
    try:
        text = yaml.safe_dump({"claims": claims}, allow_unicode=True, width=10**9)
    except (yaml.YAMLError, UnicodeEncodeError):
        return
    if as_text:  # the text report: every verdict printed, no traceback
        o = run_cli(["check", "arm.yaml", "claims.yaml"], folder, {"arm.yaml": ARM, "claims.yaml": text})
        assert not o.hung, o.describe()
        if o.code == 2:
            assert_refused(o, mentions=["claims.yaml"])
        else:
            assert o.code == 0 and "Traceback" not in o.err and "internal error" not in o.err, o.describe()
            assert o.out.startswith("arm: ") and o.out.count("\n[") == len(claims), o.describe()
            assert "checker failed" not in o.out, o.describe()
        return
    _judged_or_refused(_check_arm(folder, text), len(claims))


GARBAGE = st.one_of(
    st.binary(max_size=200),
    st.text(max_size=200),
    st.builds(lambda n, s: s * n, st.integers(1, 2000), st.sampled_from(["[", "{", "- ", "&a ", "*a ", "!!python/"
                                                                          "object:os.system ", "\t", ":"])),
    st.builds(lambda c, g: "claims:\n- quantity: position\n  value: " + g + "\n" + c, st.text(max_size=50),
              st.text(max_size=50)),
)


@settings(max_examples=corpus(250), deadline=None, derandomize=True, database=None, suppress_health_check=list(HealthCheck))
@given(data=GARBAGE)
def test_corpus_garbage_files_are_judged_or_refused(tmp_path_factory, data):
    folder = tmp_path_factory.mktemp("g")
    text = data if isinstance(data, bytes) else data.encode("utf-8", "surrogatepass")
    _judged_or_refused(_check_arm(folder, text), None)


@settings(max_examples=corpus(100), deadline=None, derandomize=True, database=None, suppress_health_check=list(HealthCheck))
@given(q=st.lists(st.floats(-3, 3), min_size=2, max_size=2), style=st.sampled_from(range(4)),
       spaces=st.sampled_from(["", " ", "  ", "\\,"]))
def test_a_correct_claim_is_never_rejected(tmp_path_factory, q, style, spaces):
    """The position of a planar 2R, hand-derived, written four ways, at a random q: always correct."""
    x = L1 * np.cos(q[0]) + L2 * np.cos(q[0] + q[1])
    y = L1 * np.sin(q[0]) + L2 * np.sin(q[0] + q[1])
    s = spaces
    value = [
        [f"L_1{s}C_1 + L_2{s}C_{{12}}", f"L_1{s}S_1 + L_2{s}S_{{12}}", "0"],
        [repr(float(x)), repr(float(y)), "0"],
        f"\\begin{{bmatrix}} {x:.12e} \\\\ {y:.12e} \\\\ 0 \\end{{bmatrix}}",
        [f"L_1 c_1 + L_2{s}(c_1 c_2 - s_1 s_2)", f"L_1 s_1 + L_2{s}(s_1 c_2 + c_1 s_2)", "0"],
    ][style]
    claim = {"quantity": "position", "value": value}
    if style in (1, 2):
        claim["q"] = [float(v) for v in q]
    o = _check(tmp_path_factory.mktemp("ok"), _file(claim))
    (v,) = _verdicts(o)
    assert v["verdict"] == "correct", v


def test_claims_path_that_is_not_a_file_is_refused(tmp_path):
    import os

    os.mkfifo(tmp_path / "fifo.yaml")
    o = run_cli(["check", ROBOT, "fifo.yaml"], tmp_path, {})
    assert_refused(o, mentions=["fifo.yaml", "not a regular file"])
    (tmp_path / "dir.yaml").mkdir()
    assert_refused(run_cli(["check", ROBOT, "dir.yaml"], tmp_path, {}), mentions=["dir.yaml"])
    assert_refused(run_cli(["check", ROBOT, "missing.yaml"], tmp_path, {}), mentions=["missing.yaml"])


N_BIG = 60_000


@pytest.mark.parametrize("claim", [
    {"quantity": "singularities", "value": "q_1 = 0, q_2 = 0" + ", 0" * N_BIG},
    {"quantity": "singularities", "value": "q_1 = 0 or " * N_BIG},
    {"quantity": "singularities", "value": "q_1 = 0;" * N_BIG},
    {"quantity": "ik_formula", "value": "q_1 = " + "\\pm 1 " * N_BIG},
    {"quantity": "ik_solutions", "q": "0.3, 0.9", "value": "0.3, 0.9;" * N_BIG},
    {"quantity": "position", "q": "0," * N_BIG, "value": [1, 2, 0]},
    {"quantity": "position", "value": ["1"] * N_BIG},
    {"quantity": "position", "value": "\\begin{bmatrix}" + "1 \\\\ " * N_BIG + "\\end{bmatrix}"},
    {"quantity": "position", "value": "{" * N_BIG},
])
def test_a_claim_near_the_file_size_limit_is_refused_quickly(tmp_path, claim):
    o = _check(tmp_path, _file(claim))
    assert o.seconds < 3, o.describe()
    if o.code == 2:  # a file of more YAML entries than the limit
        assert_refused(o, mentions=["claims.yaml", "entries"])
    else:
        (v,) = _verdicts(o)
        assert v["verdict"] == "unreadable", v
