"""Sliders that move an arm inside a Jupyter notebook: :func:`teach`.

Needs the optional extra ``denavit[notebook]`` (ipywidgets) and, for the picture, ``denavit[plot]``
(matplotlib).  Importing this module needs neither; :func:`teach` raises
:class:`~denavit.errors.MissingDependencyError` naming the extra when ipywidgets is missing.

The panel is an ``ipywidgets.VBox``: one slider per joint (revolute joints in degrees, prismatic ones in
metres, within the joint limits), a picture of the arm redrawn by matplotlib when a slider moves, and the
live end-effector pose ``T_0_e = forward_kinematics(robot, q)``.  Everything is computed in Python, so the
panel works in JupyterLab, classic Notebook, VS Code and Colab alike.
"""

from __future__ import annotations

import html
import io
from functools import lru_cache
from typing import Any

import numpy as np

from .errors import MissingDependencyError, ShapeError
from .model import DHRobot, JointType

__all__ = ["teach", "require_ipywidgets", "SLIDER_STEPS", "PICTURE_SIZE", "FRAMING_SAMPLES"]

SLIDER_STEPS = 720  # steps over a slider's range
PICTURE_SIZE = 4.5  # picture size [inch] at 80 dpi
FRAMING_SAMPLES = 128  # random configurations that fix the picture's axes (so the view does not jump)
_READOUT_DIGITS = 6


def require_ipywidgets() -> Any:
    """Import and return ipywidgets, or raise MissingDependencyError naming the ``notebook`` extra."""
    try:
        import ipywidgets
    except ImportError as exc:
        if exc.name not in (None, "ipywidgets") and not str(exc.name).startswith("ipywidgets"):
            raise
        raise MissingDependencyError(
            "sliders in a notebook need ipywidgets, which is not installed: pip install 'denavit[notebook]'"
        ) from None
    return ipywidgets


def _readout_html(robot: DHRobot, q: np.ndarray, T: np.ndarray) -> str:
    parts = []
    for k, (v, kind) in enumerate(zip(q, robot.joint_types), start=1):
        parts.append(f"q{k} = {np.degrees(v):.2f}°" if kind is JointType.REVOLUTE else f"q{k} = {v:.4f} m")
    rows = "".join("<tr>" + "".join(f"<td style='text-align:right'>{round(x, _READOUT_DIGITS) + 0.0:.{_READOUT_DIGITS}f}</td>"
                            for x in r)
                   + "</tr>" for r in T)
    return (f"<div class='denavit-teach'><p>{html.escape(', '.join(parts))}</p>"
            f"<p>T_0_e =</p><table class='denavit-pose'>{rows}</table></div>")


class _Picture:
    """One matplotlib Figure redrawn at each q, with axes fixed over the sliders' range."""

    def __init__(self, robot: DHRobot, lim: np.ndarray) -> None:
        from .viz import arm_geometry, require_matplotlib

        require_matplotlib()
        import mpl_toolkits.mplot3d  # noqa: F401  (registers the 3-D projection)
        from matplotlib.figure import Figure

        rng = np.random.default_rng(0)
        qs = lim[:, 0] + rng.random((FRAMING_SAMPLES, robot.dof)) * (lim[:, 1] - lim[:, 0])
        pts = arm_geometry(robot, qs).skeleton.reshape(-1, 3)
        lo, hi = pts.min(axis=0), pts.max(axis=0)
        self.centre, self.radius = (lo + hi) / 2, max(float((hi - lo).max()) / 2, 1e-3)
        self.robot = robot
        self.fig = Figure(figsize=(PICTURE_SIZE, PICTURE_SIZE), dpi=80)
        self.ax = self.fig.add_subplot(projection="3d")
        self.view: tuple[float, float] | None = None

    def png(self, q: np.ndarray) -> bytes:
        from .viz import plot_robot

        self.ax.cla()
        elev, azim = self.view if self.view is not None else (None, None)
        plot_robot(self.robot, q, ax=self.ax, labels=False, elev=elev, azim=azim)
        self.view = (self.ax.elev, self.ax.azim)
        for k, set_lim in enumerate((self.ax.set_xlim, self.ax.set_ylim, self.ax.set_zlim)):
            set_lim(self.centre[k] - self.radius, self.centre[k] + self.radius)
        self.ax.locator_params(nbins=4)
        self.ax.tick_params(labelsize=7)
        buf = io.BytesIO()
        self.fig.savefig(buf, format="png")
        return buf.getvalue()


@lru_cache(maxsize=1)
def _panel_class() -> type:
    widgets = require_ipywidgets()

    class TeachPanel(widgets.VBox):
        """Sliders, picture and pose readout of one arm (see :func:`teach`)."""

        def __init__(self, robot: DHRobot, q0: np.ndarray, lim: np.ndarray, picture: bool) -> None:
            self.robot = robot
            self.revolute = np.array([t is JointType.REVOLUTE for t in robot.joint_types])
            sliders = []
            for k, kind in enumerate(robot.joint_types):
                conv = np.degrees if kind is JointType.REVOLUTE else float
                lo, hi, v = (float(conv(x)) for x in (lim[k, 0], lim[k, 1], q0[k]))
                unit = "°" if kind is JointType.REVOLUTE else " m"
                sliders.append(widgets.FloatSlider(
                    value=v, min=lo, max=hi, step=(hi - lo) / SLIDER_STEPS if hi > lo else 1e-3,
                    description=f"q{k + 1}{unit}", continuous_update=False,
                    readout_format=".1f" if kind is JointType.REVOLUTE else ".3f"))
            self.sliders = tuple(sliders)
            self.readout = widgets.HTML()
            self._picture = _Picture(robot, lim) if picture else None
            self.picture = widgets.Image(format="png") if picture else None
            for s in self.sliders:
                s.observe(self._changed, names="value")
            right = [w for w in (self.picture, self.readout) if w is not None]
            super().__init__([widgets.HBox([widgets.VBox(list(self.sliders)), widgets.VBox(right)])])
            self._changed()

        @property
        def q(self) -> np.ndarray:
            """Joint values of the sliders [rad, m]."""
            v = np.array([s.value for s in self.sliders], dtype=float)
            return np.where(self.revolute, np.radians(v), v)

        @property
        def T(self) -> np.ndarray:
            """End-effector pose T_0_e at :attr:`q` (4×4)."""
            from .numeric import forward_kinematics

            return forward_kinematics(self.robot, self.q)

        def _changed(self, change: Any = None) -> None:
            q = self.q
            self.readout.value = _readout_html(self.robot, q, self.T)
            if self._picture is not None:
                self.picture.value = self._picture.png(q)

    return TeachPanel


def teach(robot: DHRobot, q=None, *, picture: bool = True) -> Any:
    """An interactive panel for a notebook: a slider per joint, a picture of the arm and the live pose.

    Parameters
    ----------
    robot : DHRobot
    q : array_like, shape (n,), optional
        Initial joint values [rad, m]; default the robot's ``qz`` pose if it names one, else zero moved
        into the limits.  Clipped to the sliders' range.
    picture : bool
        Draw the arm (needs matplotlib); ``False`` shows the sliders and the pose only.

    Returns
    -------
    ipywidgets.VBox
        Display it as the last expression of a cell.  Its ``sliders`` (one ``FloatSlider`` per joint:
        degrees for revolute joints, metres for prismatic ones; ``[-180°, 180°]`` when a revolute joint has
        no limits), ``q`` (radians/metres), ``T`` (``forward_kinematics(robot, q)``), ``readout`` (the pose
        shown) and ``picture`` (an ``Image`` widget) are attributes, so the panel can also be driven from code.

    Raises
    ------
    MissingDependencyError
        ipywidgets (``denavit[notebook]``) or, with ``picture=True``, matplotlib is not installed.
    """
    from .viz import default_configuration
    from .viz import slider_limits

    cls = _panel_class()
    lim = slider_limits(robot)
    if q is None:
        poses = dict(getattr(robot, "poses", None) or ())
        q0 = np.asarray(poses["qz"], dtype=float) if "qz" in poses else default_configuration(robot)
    else:
        q0 = np.asarray(q, dtype=float)
    if q0.shape != (robot.dof,):
        raise ShapeError(f"q: expected {robot.dof} joint values, got shape {q0.shape}")
    q0 = np.clip(q0, lim[:, 0], lim[:, 1])
    return cls(robot, q0, lim, picture)
