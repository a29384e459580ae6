"""Static pictures of an arm with matplotlib, drawn on ``Figure`` objects (never pyplot).

Revolute joints are drawn as cylinders along their axis, prismatic joints as boxes along theirs,
links as the DH centre line (:attr:`ArmGeometry.skeleton`), and every frame as a labelled x/y/z
triad (red/green/blue).  Axis scaling is equal on x, y and z.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any, Sequence

import numpy as np

from ..errors import ParseError
from ..model import DHRobot, JointType
from . import require_matplotlib
from ._geometry import ArmGeometry, arm_geometry, default_configuration

__all__ = ["plot_robot", "save_figure", "new_figure", "draw_arm", "set_equal_axes", "FIGURE_FORMATS"]

FIGURE_FORMATS = ("png", "svg", "pdf")
LINK_COLOR = "#3b4a5a"
REVOLUTE_COLOR = "#e0902a"
PRISMATIC_COLOR = "#3a8fd0"
AXIS_COLORS = ("#d62728", "#2ca02c", "#1f77b4")  # x, y, z
PATH_COLOR = "#9c27b0"
TRIAD_FRACTION = 0.12  # triad length as a fraction of the arm's scale
GLYPH_FRACTION = 0.035  # joint glyph radius as a fraction of the arm's scale
BOX_ZOOM = 0.9  # the 3-D box drawn at 90 % of its axes, so the tick and axis labels (z [m]) stay inside the figure


def new_figure(figsize: tuple[float, float] = (6.4, 6.4), dpi: int = 100, ncols: int = 1):
    """A matplotlib Figure with an Agg canvas (no window, no pyplot state)."""
    require_matplotlib()
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=figsize, dpi=dpi, layout="constrained")
    FigureCanvasAgg(fig)
    return fig


def _cylinder(T: np.ndarray, radius: float, length: float, k: int = 16) -> tuple[np.ndarray, ...]:
    """Surface grid (X, Y, Z), each (2, k+1), of a cylinder along the z axis of pose T, centred on its origin."""
    u = np.linspace(0, 2 * np.pi, k + 1)
    local = np.stack(np.broadcast_arrays(radius * np.cos(u)[None], radius * np.sin(u)[None],
                                         np.array([[-length / 2], [length / 2]])), axis=-1)  # (2, k+1, 3)
    world = local @ T[:3, :3].T + T[:3, 3]
    return world[..., 0], world[..., 1], world[..., 2]


def _box_faces(T: np.ndarray, half: Sequence[float]) -> np.ndarray:
    """The six faces (6, 4, 3) of a box with half-sizes (hx, hy, hz) in the axes of pose T."""
    hx, hy, hz = half
    corners = np.array([[sx * hx, sy * hy, sz * hz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)])
    faces = [[0, 1, 3, 2], [4, 5, 7, 6], [0, 1, 5, 4], [2, 3, 7, 6], [0, 2, 6, 4], [1, 3, 7, 5]]
    world = corners @ T[:3, :3].T + T[:3, 3]  # (8, 3)
    return world[np.array(faces)]


def _draw_joints(ax, geom: ArmGeometry) -> None:
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection

    r = GLYPH_FRACTION * geom.scale
    for T, kind in zip(geom.joint_frames, geom.joint_types):
        if kind is JointType.REVOLUTE:
            X, Y, Z = _cylinder(T, r, 2.6 * r)
            ax.plot_surface(X, Y, Z, color=REVOLUTE_COLOR, shade=True, linewidth=0, alpha=0.95)
            cap = np.stack([X[1], Y[1], Z[1]], axis=-1)
            ax.add_collection3d(Poly3DCollection([cap], facecolor=REVOLUTE_COLOR, edgecolor="#8a5210",
                                                 linewidths=0.5))
        else:
            faces = _box_faces(T, (0.9 * r, 0.9 * r, 2.2 * r))
            ax.add_collection3d(Poly3DCollection(list(faces), facecolor=PRISMATIC_COLOR, edgecolor="#1d4f78",
                                                 linewidths=0.6, alpha=0.9))


def _draw_triads(ax, geom: ArmGeometry, labels: bool) -> None:
    length = TRIAD_FRACTION * geom.scale
    seen: dict[tuple, int] = {}
    for origin, axes, name in zip(geom.triad_origins, geom.triad_axes, geom.triad_labels):
        for axis, color, letter in zip(axes, AXIS_COLORS, "xyz"):
            tip = origin + length * axis
            ax.plot(*np.stack([origin, tip]).T, color=color, linewidth=1.4)
            if labels:
                ax.text(*(origin + 1.15 * length * axis), f"$x_{{{name}}}$".replace("x", letter, 1),
                        color=color, fontsize=7, ha="center", va="center")
        if labels:  # frames sharing an origin: stack their names instead of overprinting
            key = tuple(np.round(origin / max(length, 1e-12), 1))
            k = seen.get(key, 0)
            seen[key] = k + 1
            ax.text(*(origin - 0.35 * length * (axes[0] + axes[1]) - 0.25 * k * length * np.array([0, 0, 1])),
                    f"{{{name}}}", fontsize=7, color="#333333", ha="center", va="center")


def draw_arm(ax, geom: ArmGeometry, *, frames: bool = True, labels: bool = True,
             path: np.ndarray | None = None) -> None:
    """Draw one configuration (an unbatched ArmGeometry) into a 3-D Axes."""
    if geom.skeleton.ndim != 2:
        raise ValueError("draw_arm takes the geometry of one configuration (unbatched)")
    base = geom.frames[0]
    r = GLYPH_FRACTION * geom.scale
    pad = _box_faces(base, (1.6 * r, 1.6 * r, 0.3 * r))  # a plate under joint 1's glyph
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection

    ax.add_collection3d(Poly3DCollection(list(pad - 1.6 * r * base[:3, 2]),
                                         facecolor="#9e9e9e", edgecolor="#616161", linewidths=0.5))
    ax.plot(*geom.skeleton.T, color=LINK_COLOR, linewidth=3.2, solid_capstyle="round")
    _draw_joints(ax, geom)
    ee = geom.end_effector[:3, 3]
    ax.scatter(*ee, color="#111111", s=18, depthshade=False)
    if path is not None and len(path):
        ax.plot(*np.asarray(path).T, color=PATH_COLOR, linewidth=1.5, linestyle="-")
    if frames:
        _draw_triads(ax, geom, labels)


def set_equal_axes(ax, points: np.ndarray, margin: float = 0.08) -> None:
    """Equal scaling on x, y, z around the bounding box of points (m, 3)."""
    lo, hi = points.min(axis=0), points.max(axis=0)
    centre = (lo + hi) / 2
    half = max(float((hi - lo).max()) / 2, 1e-3) * (1 + margin)
    ax.set_xlim(centre[0] - half, centre[0] + half)
    ax.set_ylim(centre[1] - half, centre[1] + half)
    ax.set_zlim(centre[2] - half, centre[2] + half)
    ax.set_box_aspect((1, 1, 1), zoom=BOX_ZOOM)
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.set_zlabel("z [m]")


def drawn_points(geom: ArmGeometry, path: np.ndarray | None = None) -> np.ndarray:
    """Every point a picture must contain (m, 3): skeleton, triad tips and the path."""
    tips = geom.triad_origins[..., None, :] + TRIAD_FRACTION * geom.scale * geom.triad_axes
    parts = [geom.skeleton.reshape(-1, 3), tips.reshape(-1, 3), geom.triad_origins.reshape(-1, 3)]
    if path is not None and len(path):
        parts.append(np.asarray(path).reshape(-1, 3))
    return np.concatenate(parts)


def default_view(points: np.ndarray) -> tuple[float, float]:
    """(elev, azim) in degrees: oblique, steeper for a flat (planar) arm."""
    extent = points.max(axis=0) - points.min(axis=0)
    flat = extent[2] < 0.15 * max(extent[0], extent[1], 1e-9)
    return (55.0 if flat else 22.0), -58.0


def plot_robot(robot: DHRobot, q=None, ax: Any = None, *, frames: bool = True, labels: bool = True,
               path=None, title: str | None = None, elev: float | None = None, azim: float | None = None,
               figsize: tuple[float, float] = (6.4, 6.4), dpi: int = 100):
    """Draw the arm at configuration q; returns the matplotlib Figure.

    Parameters
    ----------
    robot : DHRobot
    q : array_like, shape (n,), optional
        Joint values [rad or m]; default: :func:`default_configuration`.
    ax : mpl_toolkits.mplot3d.Axes3D, optional
        Draw into this 3-D Axes (of any figure) instead of a new Figure.
    frames, labels : bool
        Draw every DH frame as an x/y/z triad; label the frames and axes.
    path : array_like, shape (k, n), optional
        A joint trajectory whose end-effector trace is drawn.
    title : str, optional
    elev, azim : float, optional
        View angles [deg]; default oblique (steeper for planar arms).
    figsize, dpi
        Size of a new Figure.

    Returns
    -------
    matplotlib.figure.Figure
        Not shown: save it with :func:`save_figure` or ``fig.savefig``.
    """
    q = default_configuration(robot) if q is None else q
    geom = arm_geometry(robot, q)
    trace = None
    if path is not None:
        trace = arm_geometry(robot, path).end_effector[..., :3, 3].reshape(-1, 3)
    if ax is None:
        fig = new_figure(figsize, dpi)
        ax = fig.add_subplot(projection="3d")
    else:
        fig = ax.figure
    draw_arm(ax, geom, frames=frames, labels=labels, path=trace)
    pts = drawn_points(geom, trace)
    set_equal_axes(ax, pts)
    e0, a0 = default_view(pts)
    ax.view_init(elev=e0 if elev is None else elev, azim=a0 if azim is None else azim)
    ax.set_title(title if title is not None else robot.name, fontsize=10)
    return fig


def figure_format(path: str | Path, allowed: Sequence[str] = FIGURE_FORMATS) -> str:
    """The file format from the extension of path, or ParseError listing the choices."""
    path = Path(path)
    ext = path.suffix.lower().lstrip(".")
    if ext not in allowed:
        raise ParseError(f"-o {path}: unsupported picture format {path.suffix or '(none)'!r}; "
                         f"use one of {', '.join('.' + a for a in allowed)}")
    if not path.parent.exists() or not path.parent.is_dir():
        raise ParseError(f"-o {path}: directory {str(path.parent)!r} does not exist")
    return ext


def save_figure(fig, path: str | Path, dpi: int | None = None) -> Path:
    """Write a Figure to .png, .svg or .pdf (format from the extension)."""
    fmt = figure_format(path)
    fig.savefig(path, format=fmt, dpi=dpi)
    return Path(path)
