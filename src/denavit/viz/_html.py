"""A self-contained HTML viewer: one file, no network, forward kinematics computed in the page.

The page embeds the DH table as JSON and a small canvas renderer (``assets/viewer.js``, plain
JavaScript written for this package): one slider per joint within its limits, the live pose T of
the end effector and the joint values, the DH frames, the end-effector trace, and orbit/pan/zoom
with the mouse.
"""

from __future__ import annotations

import html
import json
import re
from importlib import resources
from pathlib import Path

import numpy as np

from ..errors import ParseError
from ..model import DHRobot, JointType
from ._geometry import arm_geometry, default_configuration, robot_scale

__all__ = ["viewer_html", "write_viewer", "slider_limits", "VIEW_SAMPLES"]

VIEW_SAMPLES = 256  # random configurations used to frame the camera
SLIDER_STEPS = 1000


def _asset(name: str) -> str:
    return resources.files("denavit.viz").joinpath("assets", name).read_text(encoding="utf-8")


def slider_limits(robot: DHRobot) -> np.ndarray:
    """Slider range per joint (n, 2): the joint limits; [−π, π] for unlimited revolute joints,
    ±(arm scale) for unlimited prismatic ones (:meth:`DHRobot.sampling_ranges`)."""
    return robot.sampling_ranges(robot_scale(robot))


def _view_box(robot: DHRobot, lim: np.ndarray) -> tuple[list[float], float]:
    """Centre and radius framing the arm over a fixed sample of configurations."""
    rng = np.random.default_rng(0)
    qs = lim[:, 0] + rng.random((VIEW_SAMPLES, robot.dof)) * (lim[:, 1] - lim[:, 0])
    pts = arm_geometry(robot, qs).skeleton.reshape(-1, 3)
    lo, hi = pts.min(axis=0), pts.max(axis=0)
    radius = max(float((hi - lo).max()) / 2, 1e-3)
    return ((lo + hi) / 2).tolist(), radius


def _sliders(robot: DHRobot, lim: np.ndarray, q0: np.ndarray) -> str:
    out = []
    for k, kind in enumerate(robot.joint_types):
        lo, hi = float(lim[k, 0]), float(lim[k, 1])
        step = (hi - lo) / SLIDER_STEPS if hi > lo else 1e-3
        m = round((float(q0[k]) - lo) / step)
        if m >= 1:  # put q0 on the slider's grid (the grid starts at min)
            step = (float(q0[k]) - lo) / m
        unit = "revolute" if kind is JointType.REVOLUTE else "prismatic"
        out.append(
            f'<div class="joint"><label for="q{k + 1}"><span>q{k + 1} ({unit})</span>'
            f'<span id="qv{k + 1}"></span></label>'
            f'<input type="range" id="q{k + 1}" min="{lo!r}" max="{hi!r}" step="{step!r}" value="{float(q0[k])!r}"></div>')
    return "\n  ".join(out)


def viewer_html(robot: DHRobot, q=None, title: str | None = None) -> str:
    """The viewer page for robot as one HTML string.

    Parameters
    ----------
    robot : DHRobot
    q : array_like, shape (n,), optional
        Initial slider positions (default :func:`default_configuration`); clipped to the sliders.
    title : str, optional
    """
    lim = slider_limits(robot)
    q0 = default_configuration(robot) if q is None else np.asarray(q, dtype=float)
    if q0.shape != (robot.dof,):
        raise ParseError(f"q: expected {robot.dof} values, got shape {q0.shape}")
    q0 = np.clip(q0, lim[:, 0], lim[:, 1])
    centre, radius = _view_box(robot, lim)
    data = {
        "name": robot.name,
        "convention": robot.convention.value,
        "rows": [{"a": link.a, "alpha": link.alpha, "d": link.d, "theta": link.theta, "joint": link.joint.value}
                 for link in robot.links],
        "joint_rows": list(robot.joint_rows),
        "joint_types": [t.value for t in robot.joint_types],
        "limits": lim.tolist(),
        "base": robot.base_matrix.tolist(),
        "tool": robot.tool_matrix.tolist(),
        "has_tool": not np.allclose(robot.tool_matrix, np.eye(4)),
        "q0": q0.tolist(),
        "scale": robot_scale(robot),
        "center": centre,
        "radius": radius,
    }
    # \u escapes keep any text of the robot file from closing the <script> block
    blob = json.dumps(data).replace("<", "\\u003c").replace(">", "\\u003e").replace("&", "\\u0026")
    name = html.escape(title or robot.name)
    subtitle = html.escape(f"{robot.convention.value} DH, {robot.dof} joints "
                           f"({''.join('R' if t is JointType.REVOLUTE else 'P' for t in robot.joint_types)})"
                           + (f" — {robot.description}" if robot.description else ""))
    fills = {"SLIDERS": _sliders(robot, lim, q0), "SUBTITLE": subtitle, "TITLE": name, "DATA": blob,
             "SCRIPT": _asset("viewer.js")}
    # one pass, so text inside a filled value is never substituted again
    return re.sub(r"\$(SLIDERS|SUBTITLE|TITLE|DATA|SCRIPT)\b", lambda m: fills[m.group(1)], _asset("viewer.html"))


def write_viewer(robot: DHRobot, path: str | Path, q=None, title: str | None = None) -> Path:
    """Write :func:`viewer_html` to path (``.html``)."""
    path = Path(path)
    if path.suffix.lower() not in (".html", ".htm"):
        raise ParseError(f"-o {path}: the viewer is an HTML file; use a name ending in .html")
    if not path.parent.is_dir():
        raise ParseError(f"-o {path}: directory {str(path.parent)!r} does not exist")
    path.write_text(viewer_html(robot, q, title), encoding="utf-8")
    return path
