"""ⁱJ: a Jacobian written in the axes of an intermediate DH frame (``frame: 3``), ⁱJ = blockdiag(R_0_iᵀ, R_0_iᵀ) J0.

The truths here are built by the test: J0 by central differences of an independent forward kinematics (the DH
matrices written in test_check_shapes), R_0_i from the same product, and, for formulas, a planar 3R arm's ⁱJ
written from the textbook (the Jacobian of the tip in frame i's axes: rotate J0 by −(q1 + … + qi))."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import denavit as dn
from denavit.check import check_claims

from conftest import REDUCED
from test_check_shapes import _fk, dh_frames as _frames  # the test's own DH product

ARMS = ["planar3r", "scara", "report000-6r", "puma560-mdh"]


def _J0(robot, q, h=1e-6):
    """J0 (v, ω; world axes; the tip origin) by central differences of the test's forward kinematics."""
    R = _fk(robot, q)[:3, :3]
    cols = []
    for i in range(robot.dof):
        e = np.zeros(robot.dof)
        e[i] = h
        D = (_fk(robot, q + e) - _fk(robot, q - e)) / (2 * h)
        W = D[:3, :3] @ R.T
        cols.append(np.concatenate([D[:3, 3], [W[2, 1], W[0, 2], W[1, 0]]]))
    return np.array(cols).T


def _iJ(robot, q, i):
    R = _frames(robot, q)[i][:3, :3]
    J = _J0(robot, q)
    return np.vstack([R.T @ J[:3], R.T @ J[3:]])


def _q(robot, rng):
    lo, hi = robot.q_limits.T
    return rng.uniform(np.maximum(lo, -np.pi), np.minimum(hi, np.pi))


def _claim(robot, q, J, **extra):
    return {"quantity": "jacobian", "q": [float(x) for x in q], "value": [[f"{x:.9f}" for x in row] for row in J],
            **extra}


@pytest.mark.parametrize("name", ARMS)
def test_jacobian_in_every_intermediate_frame(name):
    robot = dn.load_robot(name)
    rng = np.random.default_rng(len(name))
    q = _q(robot, rng)
    claims = []
    for i in range(robot.n_rows + 1):
        claims.append(_claim(robot, q, _iJ(robot, q, i), frame=i, id=f"J{i}"))
    res = check_claims(robot, claims)
    assert [v.verdict for v in res.verdicts] == ["correct"] * len(claims), [v.message for v in res.verdicts]
    # frame 0 without a base is J0 itself; the last frame without a tool is Je
    J = _iJ(robot, q, 2)
    J[1, 0] += 0.01
    bad = check_claims(robot, [_claim(robot, q, J, frame="2")]).verdicts[0]
    assert bad.verdict == "incorrect" and [e["entry"] for e in bad.entries] == [[2, 1]], bad.message


def test_a_base_axes_jacobian_claimed_for_frame_3_is_named():
    robot = dn.load_robot("report000-6r")
    q = np.array([0.3, 0.7, -0.4, 0.9, -1.1, 0.2])
    v = check_claims(robot, [_claim(robot, q, _J0(robot, q), frame=3)]).verdicts[0]
    assert v.verdict == "incorrect"
    assert any("expressed in base axes (J0), not frame {3}'s axes" in h for h in v.hints), v.hints


def test_planar_3r_frame_jacobians_as_formulas():
    """³J of a planar 3R arm from the textbook: the tip's Jacobian rotated by −(q1 + q2 + q3) about z."""
    robot = dn.load_robot("planar3r")
    # in frame 1's axes (angle q1 removed): rows vx, vy, ωz
    j1 = [["-L2*sin(q2) - L3*sin(q2 + q3)", "-L2*sin(q2) - L3*sin(q2 + q3)", "-L3*sin(q2 + q3)"],
          ["L1 + L2*cos(q2) + L3*cos(q2 + q3)", "L2*cos(q2) + L3*cos(q2 + q3)", "L3*cos(q2 + q3)"],
          ["1", "1", "1"]]
    j3 = [["L1*sin(q2 + q3) + L2*sin(q3)", "L2*sin(q3)", "0"],
          ["L1*cos(q2 + q3) + L2*cos(q3) + L3", "L2*cos(q3) + L3", "L3"],
          ["1", "1", "1"]]
    claims = [{"quantity": "jacobian", "frame": 1, "rows": "planar", "value": j1},
              {"quantity": "jacobian", "frame": 3, "rows": "planar", "value": j3},
              {"quantity": "jacobian", "frame": 3, "rows": "planar",
               "value": [j3[0], [j3[1][0], "L2*cos(q3)", "L3"], j3[2]]}]  # a dropped term in entry (2, 2)
    res = check_claims(robot, claims)
    assert [v.verdict for v in res.verdicts] == ["correct", "correct", "incorrect"], [v.message for v in res.verdicts]
    assert [e["entry"] for e in res.verdicts[2].entries] == [[2, 2]]


def test_bad_frames_are_unreadable_with_a_reason():
    robot = dn.load_robot("planar3r")
    res = check_claims(robot, [{"quantity": "jacobian", "frame": 9, "q": [0, 0, 0], "value": [[0, 0, 0]] * 6},
                               {"quantity": "jacobian", "frame": "elbow", "q": [0, 0, 0], "value": [[0, 0, 0]] * 6}])
    assert [v.verdict for v in res.verdicts] == ["unreadable", "unreadable"]
    assert "not a DH frame of this robot (0 … 3)" in res.verdicts[0].message
    assert "base, tool or the index of a DH frame" in res.verdicts[1].message


@settings(max_examples=3 if REDUCED else 25, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(seed=st.integers(0, 2**31 - 1), data=st.data())
def test_frame_jacobians_never_rejected_and_perturbations_named(seed, data):
    robot = dn.load_robot(data.draw(st.sampled_from(["scara", "report000-6r", "stanford"])))
    rng = np.random.default_rng(seed)
    q = _q(robot, rng)
    i = data.draw(st.integers(0, robot.n_rows))
    J = _iJ(robot, q, i)
    assert check_claims(robot, [_claim(robot, q, J, frame=i)]).verdicts[0].verdict == "correct"
    r, c = data.draw(st.integers(0, 5)), data.draw(st.integers(0, robot.dof - 1))
    J[r, c] += data.draw(st.sampled_from([0.05, -0.3, 1.0]))
    v = check_claims(robot, [_claim(robot, q, J, frame=i)]).verdicts[0]
    assert v.verdict == "incorrect" and [e["entry"] for e in v.entries] == [[r + 1, c + 1]], v.message
