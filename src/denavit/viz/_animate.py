"""Animations of a joint trajectory: GIF through matplotlib's PillowWriter, MP4 through ffmpeg.

Frames are drawn on a Figure with the Agg canvas and grabbed by the writer, so no window opens.
The axis box is fixed over the whole motion (equal scaling) and the end-effector trace grows.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..errors import MissingDependencyError, ParseError, ShapeError
from ..model import DHRobot
from ._geometry import arm_geometry
from ._plot import default_view, draw_arm, drawn_points, figure_format, new_figure, set_equal_axes

__all__ = ["animate_robot", "ANIMATION_FORMATS"]

ANIMATION_FORMATS = ("gif", "mp4")


def _writer(fmt: str, fps: float):
    from matplotlib import animation

    if fmt == "gif":
        return animation.PillowWriter(fps=fps)
    if not animation.writers.is_available("ffmpeg"):
        raise MissingDependencyError("writing .mp4 needs the ffmpeg program on PATH (e.g. apt-get install "
                                     "ffmpeg); write a .gif instead")
    return animation.FFMpegWriter(fps=fps)


def animate_robot(robot: DHRobot, q_path, output: str | Path, *, fps: float = 20.0, frames: bool = True,
                  labels: bool = False, trace: bool = True, title: str | None = None,
                  figsize: tuple[float, float] = (6.4, 6.4), dpi: int = 100) -> Path:
    """Write an animation of the arm following a joint trajectory.

    Parameters
    ----------
    robot : DHRobot
    q_path : array_like, shape (k, n)
        One configuration per frame.
    output : path
        ``.gif`` (Pillow, bundled with matplotlib) or ``.mp4`` (needs ffmpeg).
    fps : float
        Frames per second.
    frames, labels, trace : bool
        Draw the DH frame triads, their labels, and the end-effector trace so far.
    figsize, dpi
        Frame size in inches and dots per inch: 640 × 640 pixels by default.

    Returns
    -------
    pathlib.Path
        The file written.
    """
    fmt = figure_format(output, ANIMATION_FORMATS)
    q_path = np.asarray(q_path, dtype=float)
    if q_path.ndim != 2 or q_path.shape[1] != robot.dof or len(q_path) < 1:
        raise ShapeError(f"q_path: expected shape (k, {robot.dof}), got {q_path.shape}")
    if not fps > 0:
        raise ParseError(f"fps must be positive, got {fps}")
    writer = _writer(fmt, fps)
    geom = arm_geometry(robot, q_path)  # batched over the k frames
    ee = geom.end_effector[:, :3, 3]  # (k, 3)
    pts = np.concatenate([drawn_points(_frame(geom, i)) for i in range(len(q_path))] + [ee])
    elev, azim = default_view(pts)
    fig = new_figure(figsize, dpi)
    ax = fig.add_subplot(projection="3d")
    with writer.saving(fig, str(output), dpi):
        for i in range(len(q_path)):
            ax.clear()
            draw_arm(ax, _frame(geom, i), frames=frames, labels=labels, path=ee[: i + 1] if trace else None)
            set_equal_axes(ax, pts)
            ax.view_init(elev=elev, azim=azim)
            ax.set_title(title if title is not None else robot.name, fontsize=10)
            writer.grab_frame()
    return Path(output)


def _frame(geom, i: int):
    """The unbatched geometry of frame i of a batched ArmGeometry."""
    from dataclasses import fields, replace

    arrays = {f.name: getattr(geom, f.name)[i] for f in fields(geom)
              if isinstance(getattr(geom, f.name), np.ndarray)}
    return replace(geom, **arrays)
