"""Robots built in Python (denavit.revolute/prismatic/fixed/robot) against the catalogue files.

The rows below are typed from the published DH tables (the sources named in each catalogue file), not read
from the loaded robots, so a builder that placed a value in the wrong field would show at random q.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import denavit
from denavit import ModelError, ParseError, fixed, prismatic, revolute, robot
from denavit.numeric import transform_from_xyz_rpy

from _random_robots import random_robot

PI = np.pi
D = np.radians


def puma560():
    lim = [(-160, 160), (-45, 225), (-225, 45), (-110, 170), (-100, 100), (-266, 266)]
    lim = [(D(lo), D(hi)) for lo, hi in lim]
    return robot([
        revolute(alpha=PI / 2, d="d1", limits=lim[0]),
        revolute(a="a2", limits=lim[1]),
        revolute(a="a3", alpha=-PI / 2, d="d3", limits=lim[2]),
        revolute(alpha="pi/2", d="d4", limits=lim[3]),
        revolute(alpha="-pi/2", limits=lim[4]),
        revolute(limits=lim[5]),
    ], name="puma560", parameters={"d1": 0.67183, "a2": 0.4318, "a3": 0.0203, "d3": 0.15005, "d4": 0.4318})


def ur5():
    p = {"d1": 0.089159, "a2": -0.425, "a3": -0.39225, "d4": 0.10915, "d5": 0.09465, "d6": 0.0823}
    lim = ("-2*pi", "2*pi")
    return robot([
        revolute(alpha="pi/2", d="d1", limits=lim), revolute(a="a2", limits=lim), revolute(a="a3", limits=lim),
        revolute(alpha="pi/2", d="d4", limits=lim), revolute(alpha="-pi/2", d="d5", limits=lim),
        revolute(d="d6", limits=lim),
    ], name="ur5", parameters=p)


def panda():
    p = {"d1": 0.333, "d3": 0.316, "a4": 0.0825, "d5": 0.384, "a7": 0.088, "d_flange": 0.107}
    return robot([
        revolute(d="d1", limits=(-2.8973, 2.8973)),
        revolute(alpha=-PI / 2, limits=(-1.7628, 1.7628)),
        revolute(alpha=PI / 2, d="d3", limits=(-2.8973, 2.8973)),
        revolute(a="a4", alpha=PI / 2, limits=(-3.0718, -0.0698)),
        revolute(a="-a4", alpha=-PI / 2, d="d5", limits=(-2.8973, 2.8973)),
        revolute(alpha=PI / 2, limits=(-0.0175, 3.7525)),
        revolute(a="a7", alpha=PI / 2, limits=(-2.8973, 2.8973)),
    ], name="panda", convention="modified", parameters=p, tool=fixed(d="d_flange"))


def stanford():
    return robot([
        revolute(alpha=-90, d="d1", limits=(-170, 170)),
        revolute(alpha=90, d="d2", limits=(-170, 170)),
        prismatic(a="a3", theta=-90, limits=(0.3048, 1.27)),
        revolute(alpha=-90, limits=(-170, 170)),
        revolute(alpha=90, limits=(-90, 90)),
        revolute(limits=(-170, 170)),
    ], name="stanford", angle_unit="deg", parameters={"d1": 0.412, "d2": 0.154, "a3": 0.0203})


BUILT = {"puma560": puma560, "ur5": ur5, "panda": panda, "stanford": stanford}


def _random_q(rng, robot_, shape=()):
    lim = np.clip(robot_.q_limits, -PI, PI)
    return lim[:, 0] + rng.random(shape + (robot_.dof,)) * (lim[:, 1] - lim[:, 0])


@pytest.mark.parametrize("name", sorted(BUILT))
def test_built_catalogue_arm_has_the_catalogue_forward_kinematics(name):
    built, loaded = BUILT[name](), denavit.load_robot(name)
    assert built.dof == loaded.dof and built.n_rows == loaded.n_rows
    assert built.convention is loaded.convention and built.joint_types == loaded.joint_types
    np.testing.assert_allclose(built.q_limits, loaded.q_limits, atol=1e-12)
    assert built.parameter_values == loaded.parameter_values
    q = _random_q(np.random.default_rng(0), loaded, (64,))
    np.testing.assert_allclose(denavit.forward_kinematics(built, q), denavit.forward_kinematics(loaded, q), atol=1e-12)
    np.testing.assert_allclose(denavit.geometric_jacobian(built, q), denavit.geometric_jacobian(loaded, q), atol=1e-12)


def test_built_parameters_stay_symbols_and_can_be_changed():
    arm = puma560()
    assert dict(arm.links[0].symbols)["d"] == "d1"
    longer = denavit.with_parameters(arm, a2=0.5)
    ref = denavit.with_parameters(denavit.load_robot("puma560"), a2=0.5)
    q = _random_q(np.random.default_rng(1), arm, (8,))
    np.testing.assert_allclose(denavit.forward_kinematics(longer, q), denavit.forward_kinematics(ref, q), atol=1e-12)


@settings(max_examples=40, deadline=None)
@given(seed=st.integers(0, 2**32 - 1))
def test_rebuilding_a_random_robot_from_its_rows_gives_the_same_kinematics(seed):
    rng = np.random.default_rng(seed)
    original = random_robot(rng)
    rows = []
    for link in original.links:
        if link.joint.value == "revolute":
            rows.append(revolute(a=link.a, alpha=link.alpha, d=link.d, offset=link.theta))
        elif link.joint.value == "prismatic":
            rows.append(prismatic(a=link.a, alpha=link.alpha, theta=link.theta, offset=link.d))
        else:
            rows.append(fixed(a=link.a, alpha=link.alpha, d=link.d, theta=link.theta))
    built = robot(rows, convention=original.convention.value, base=original.base_matrix, tool=original.tool_matrix)
    q = rng.uniform(-PI, PI, (5, original.dof))
    np.testing.assert_allclose(denavit.forward_kinematics(built, q), denavit.forward_kinematics(original, q),
                               atol=1e-12)
    relinked = robot(original.links, convention=original.convention.value,  # DHLink rows are accepted too
                     base=original.base_matrix, tool=original.tool_matrix)
    np.testing.assert_allclose(denavit.link_transforms(relinked, q), denavit.link_transforms(original, q), atol=1e-12)


def test_base_tool_gravity_inertia_and_poses_reach_the_model():
    base = transform_from_xyz_rpy([0.1, 0.2, 0.3], [0.0, 0.0, PI / 2])
    inertia = denavit.LinkInertia(mass=2.0, com=(0.25, 0.0, 0.0), inertia=(0.01, 0.02, 0.03, 0.0, 0.0, 0.0))
    arm = robot([revolute(a=0.5, inertia=inertia),
                 revolute(a=0.4, inertia={"mass": 1.5, "com": [0.2, 0, 0], "inertia": [0.01, 0.01, 0.01, 0, 0, 0]})],
                name="two", base=base, tool={"xyz": [0, 0, 0.1]}, gravity=(0, -9.81, 0),
                poses={"qz": [0, 0], "qr": ["pi/2", 0]})
    np.testing.assert_allclose(arm.base_matrix, base, atol=1e-15)
    np.testing.assert_allclose(arm.tool_matrix[:3, 3], [0, 0, 0.1])
    assert arm.gravity == (0.0, -9.81, 0.0) and arm.has_dynamics
    got = arm.links[0].inertia
    assert (got.mass, got.com, got.inertia) == (inertia.mass, inertia.com, inertia.inertia)
    assert arm.links[1].inertia.mass == 1.5
    assert dict(arm.poses)["qr"] == pytest.approx((PI / 2, 0.0))
    # the same arm from a robot file's data
    same = denavit.robot_from_dict({
        "name": "two", "convention": "standard", "gravity": [0, -9.81, 0],
        "joints": [{"a": 0.5, "theta": "q", "inertia": {"mass": 2.0, "com": [0.25, 0, 0],
                                                        "inertia": [0.01, 0.02, 0.03, 0, 0, 0]}},
                   {"a": 0.4, "theta": "q", "inertia": {"mass": 1.5, "com": [0.2, 0, 0],
                                                        "inertia": [0.01, 0.01, 0.01, 0, 0, 0]}}],
        "base": {"xyz": [0.1, 0.2, 0.3], "rpy": [0, 0, "pi/2"]}, "tool": {"xyz": [0, 0, 0.1]}})
    q, qd, qdd = np.array([0.3, -0.7]), np.array([0.5, 1.0]), np.array([-0.2, 0.4])
    np.testing.assert_allclose(denavit.rnea(arm, q, qd, qdd), denavit.rnea(same, q, qd, qdd), atol=1e-12)
    np.testing.assert_allclose(denavit.forward_kinematics(arm, q), denavit.forward_kinematics(same, q), atol=1e-12)


@pytest.mark.parametrize("make, error, words", [
    (lambda: robot([revolute(a="L3")], parameters={"L1": 1.0}), ParseError, ["row 1", "'a'", "unknown symbol 'L3'"]),
    (lambda: robot([revolute(), revolute(d="__import__('os').system('x')")]), ParseError, ["row 2", "'d'"]),
    (lambda: robot([revolute(limits=(1.0, -1.0))]), ParseError, ["row 1", "limits", "above"]),
    (lambda: robot([revolute(a=float("nan"))]), ParseError, ["row 1", "'a'", "finite"]),
    (lambda: robot([revolute(a=[1, 2])]), ParseError, ["row 1", "'a'"]),
    (lambda: robot([revolute(offset="q")]), ParseError, ["row 1", "theta"]),
    (lambda: robot([revolute(inertia={"mass": -1})]), ParseError, ["row 1", "inertia", "mass"]),
    (lambda: robot([revolute()], convention="craig"), ParseError, ["standard or modified"]),
    (lambda: robot([revolute()], angle_unit="grad"), ParseError, ["angle_unit"]),
    (lambda: robot([fixed(a=1.0)]), ParseError, ["at least one joint"]),
    (lambda: robot([]), ParseError, ["non-empty"]),
    (lambda: robot([revolute()], parameters={"q": 1.0}), ParseError, ["'q'", "parameter name"]),
    (lambda: robot([revolute()], gravity=(0, 0)), ParseError, ["gravity", "3 values"]),
    (lambda: robot([1.5]), ModelError, ["row 1", "denavit.revolute"]),
    (lambda: robot(revolute()), ModelError, ["list of rows"]),
    (lambda: robot([revolute()], tool=revolute()), ModelError, ["tool", "joint variable"]),
    (lambda: robot([revolute()], tool=np.eye(3)), ModelError, ["tool", "4×4"]),
    (lambda: robot([revolute()], base=np.diag([1.0, 1.0, -1.0, 1.0])), ParseError, ["base", "rotation"]),
    (lambda: revolute(limits=3.0), ModelError, ["limits", "pair"]),
])
def test_bad_arguments_are_refused_with_a_clear_message(make, error, words):
    with pytest.raises(error) as info:
        make()
    message = str(info.value)
    assert "\n" not in message
    for w in words:
        assert w in message, (w, message)


def test_rows_are_keyword_only():
    with pytest.raises(TypeError):
        revolute(0.5)  # type: ignore[misc]
