"""denavit.notebook.teach: the slider panel, driven from code (no browser, no kernel)."""

from __future__ import annotations

import re
import subprocess
import sys

import numpy as np
import pytest

import denavit
from denavit import JointType, MissingDependencyError


def _readout_matrix(panel) -> np.ndarray:
    cells = re.findall(r"<td[^>]*>(-?[\d.]+)</td>", panel.readout.value)
    return np.array([float(c) for c in cells]).reshape(4, 4)


def test_import_without_ipywidgets_and_teach_names_the_extra():
    code = ("import sys; sys.modules['ipywidgets'] = None\n"
            "import denavit, denavit.notebook\n"
            "try:\n    denavit.notebook.teach(denavit.load_robot('planar2r'))\n"
            "except denavit.MissingDependencyError as e:\n    print('REFUSED', e)\n")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stderr
    assert out.stdout.startswith("REFUSED") and "denavit[notebook]" in out.stdout


def test_require_ipywidgets_raises_missing_dependency(monkeypatch):
    monkeypatch.setitem(sys.modules, "ipywidgets", None)
    from denavit.notebook import require_ipywidgets

    with pytest.raises(MissingDependencyError, match=r"denavit\[notebook\]"):
        require_ipywidgets()


@pytest.mark.parametrize("name", ["puma560", pytest.param("stanford", marks=pytest.mark.slow),
                                  pytest.param("panda", marks=pytest.mark.slow)])
def test_moving_sliders_updates_the_pose_readout(name):
    widgets = pytest.importorskip("ipywidgets")
    pytest.importorskip("matplotlib")
    from denavit.notebook import teach

    robot = denavit.load_robot(name)
    panel = teach(robot)
    assert isinstance(panel, widgets.Box)
    assert len(panel.sliders) == robot.dof
    rng = np.random.default_rng(11)
    lim = np.clip(robot.q_limits, -np.pi, np.pi)
    for _ in range(3):
        q = lim[:, 0] + rng.random(robot.dof) * (lim[:, 1] - lim[:, 0])
        for s, v, kind in zip(panel.sliders, q, robot.joint_types):
            s.value = float(np.degrees(v)) if kind is JointType.REVOLUTE else float(v)
        np.testing.assert_allclose(panel.q, q, atol=1e-12)
        T = denavit.forward_kinematics(robot, q)
        np.testing.assert_allclose(panel.T, T, atol=1e-12)
        np.testing.assert_allclose(_readout_matrix(panel), T, atol=1e-6)
        assert panel.picture.value[:8] == b"\x89PNG\r\n\x1a\n"


def test_sliders_follow_the_joint_limits_in_degrees_and_metres():
    pytest.importorskip("ipywidgets")
    from denavit.notebook import teach

    robot = denavit.load_robot("stanford")
    panel = teach(robot, picture=False)
    assert panel.picture is None
    for s, (lo, hi), kind in zip(panel.sliders, robot.q_limits, robot.joint_types):
        if kind is JointType.REVOLUTE:
            assert (s.min, s.max) == pytest.approx((np.degrees(lo), np.degrees(hi)))
        else:
            assert (s.min, s.max) == pytest.approx((lo, hi))
    s = panel.sliders[0]
    s.value = s.max + 50  # the slider clamps, the pose follows the clamped value
    assert panel.q[0] == pytest.approx(robot.q_limits[0, 1])
    np.testing.assert_allclose(_readout_matrix(panel), denavit.forward_kinematics(robot, panel.q), atol=1e-6)


def test_initial_q_and_its_shape():
    pytest.importorskip("ipywidgets")
    from denavit.notebook import teach

    robot = denavit.load_robot("planar2r")
    panel = teach(robot, q=[0.3, -0.4], picture=False)
    np.testing.assert_allclose(panel.q, [0.3, -0.4], atol=1e-12)
    np.testing.assert_allclose(_readout_matrix(panel), denavit.forward_kinematics(robot, [0.3, -0.4]), atol=1e-6)
    with pytest.raises(denavit.ShapeError, match="expected 2 joint values"):
        teach(robot, q=[0.1, 0.2, 0.3], picture=False)


def test_an_unlimited_revolute_joint_gets_a_full_turn_slider():
    pytest.importorskip("ipywidgets")
    from denavit.notebook import teach

    robot = denavit.robot([denavit.revolute(a=0.5), denavit.prismatic(limits=(0.0, 0.2))])
    panel = teach(robot, picture=False)
    assert (panel.sliders[0].min, panel.sliders[0].max) == pytest.approx((-180.0, 180.0))
    assert (panel.sliders[1].min, panel.sliders[1].max) == pytest.approx((0.0, 0.2))
    panel.sliders[1].value = 0.15
    np.testing.assert_allclose(_readout_matrix(panel), denavit.forward_kinematics(robot, [0.0, 0.15]), atol=1e-6)
