"""The reachable workspace by vectorized sampling within the joint limits.

Joint values are drawn uniformly inside the limits (revolute joints without limits take
[−π, π]); the end-effector origins form a point cloud whose bounding box, reach and volume are
estimated.  The volume is the number of occupied cubic voxels of a stated edge length times the
voxel volume (an occupancy estimate: it grows with the sample count and shrinks with finer voxels,
so both are reported).  A planar arm's cloud has no thickness; its area is estimated the same way
with square pixels in its plane.

This module keeps every sample in memory (small runs, the point cloud itself); :mod:`denavit.scale` streams
any number of samples into voxel counts with a volume interval, and :func:`plot_occupancy` /
:func:`plot_reachability` draw its results.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import ModelError
from ..model import DHRobot
from ..numeric import forward_kinematics
from ..scale import sampling_limits

__all__ = ["Workspace", "sample_workspace", "workspace", "plot_workspace", "sampling_limits", "plot_occupancy",
           "plot_reachability"]

DEFAULT_SAMPLES = 100_000
DEFAULT_CELLS = 40  # voxels along the longest bounding-box side when no resolution is given
FLAT_TOLERANCE = 1e-9  # relative thickness below which the cloud counts as planar
BATCH = 50_000  # FK batch size (bounds memory)


@dataclass(frozen=True)
class Workspace:
    """A sampled workspace and its figures (world frame, metres).

    Attributes
    ----------
    points : ndarray, shape (m, 3)
        End-effector origins.
    samples : int
    resolution : float
        Voxel (or pixel, for a planar arm) edge length [m].
    bounds_min, bounds_max, extent : ndarray, shape (3,)
        Axis-aligned bounding box and its side lengths [m].
    reach : float
        Largest distance of a sample from the base origin {0} [m].
    voxels : int
        Occupied voxels (pixels when planar).
    volume : float
        voxels · resolution³ [m³]; 0 for a planar arm.
    planar : bool
        The cloud lies in one plane (thickness below FLAT_TOLERANCE·size).
    area : float
        For a planar arm, occupied pixels · resolution² [m²]; else 0.
    """

    points: np.ndarray
    samples: int
    resolution: float
    bounds_min: np.ndarray
    bounds_max: np.ndarray
    extent: np.ndarray
    reach: float
    voxels: int
    volume: float
    planar: bool
    area: float
    base_origin: np.ndarray

    def summary(self) -> dict:
        """The figures as plain data (for --json)."""
        return {"samples": self.samples, "resolution": self.resolution, "bounds_min": self.bounds_min.tolist(),
                "bounds_max": self.bounds_max.tolist(), "extent": self.extent.tolist(), "reach": self.reach,
                "voxels": self.voxels, "volume": self.volume, "planar": self.planar, "area": self.area}


def sample_workspace(robot: DHRobot, samples: int = DEFAULT_SAMPLES, rng: np.random.Generator | None = None
                     ) -> np.ndarray:
    """End-effector origins (samples, 3) at joint values uniform inside the limits."""
    if int(samples) < 1:
        raise ModelError(f"samples must be a positive integer, got {samples}")
    rng = np.random.default_rng() if rng is None else rng
    lim = sampling_limits(robot)
    out = np.empty((int(samples), 3))
    for start in range(0, int(samples), BATCH):
        m = min(BATCH, int(samples) - start)
        q = lim[:, 0] + rng.random((m, robot.dof)) * (lim[:, 1] - lim[:, 0])  # (m, n)
        out[start:start + m] = forward_kinematics(robot, q)[:, :3, 3]
    return out


def _occupied(points: np.ndarray, h: float) -> int:
    cells = np.floor((points - points.min(axis=0)) / h).astype(np.int64)
    return int(np.unique(cells, axis=0).shape[0])


def workspace(robot: DHRobot, samples: int = DEFAULT_SAMPLES, resolution: float | None = None,
              rng: np.random.Generator | None = None) -> Workspace:
    """Sample the reachable workspace and estimate its size.

    Parameters
    ----------
    robot : DHRobot
    samples : int
        Number of random configurations.
    resolution : float, optional
        Voxel edge [m]; default: the longest bounding-box side / 40.
    rng : numpy.random.Generator, optional

    Returns
    -------
    Workspace
    """
    pts = sample_workspace(robot, samples, rng)
    lo, hi = pts.min(axis=0), pts.max(axis=0)
    extent = hi - lo
    size = float(extent.max())
    if resolution is None:
        resolution = size / DEFAULT_CELLS if size > 0 else 1.0
    if not resolution > 0 or not np.isfinite(resolution):
        raise ModelError(f"resolution must be a positive length in metres, got {resolution}")
    centred = pts - pts.mean(axis=0)
    sv = np.linalg.svd(centred[:: max(1, len(pts) // 20000)], compute_uv=False, full_matrices=False)
    planar = bool(len(sv) == 3 and sv[2] <= FLAT_TOLERANCE * max(sv[0], 1e-300) * np.sqrt(len(pts)))
    if planar:
        _, _, Vt = np.linalg.svd(centred[:: max(1, len(pts) // 20000)], full_matrices=False)
        flat = centred @ Vt[:2].T  # (m, 2) coordinates in the plane
        voxels = _occupied(flat, resolution)
        volume, area = 0.0, voxels * resolution**2
    else:
        voxels = _occupied(pts, resolution)
        volume, area = voxels * resolution**3, 0.0
    o0 = robot.base_matrix[:3, 3]
    reach = float(np.linalg.norm(pts - o0, axis=-1).max())
    return Workspace(pts, int(samples), float(resolution), lo, hi, extent, reach, voxels, float(volume), planar,
                     float(area), o0)


def plot_workspace(ws: Workspace, title: str = "", max_points: int = 20_000, figsize=(13.5, 4.6), dpi: int = 100):
    """Three panels: the 3-D point cloud, the x–y projection and the x–z section through the base.

    The section keeps the points within ±resolution of the plane y = y_base.  Returns a Figure.
    """
    from ._plot import new_figure, set_equal_axes

    fig = new_figure(figsize, dpi)
    pts = ws.points[:: max(1, len(ws.points) // max_points)]
    ax3 = fig.add_subplot(1, 3, 1, projection="3d")
    cloud = ax3.scatter(*pts.T, s=0.6, c=pts[:, 2], cmap="viridis", alpha=0.5, depthshade=False, linewidths=0)
    fig.colorbar(cloud, ax=ax3, label="height z [m]", shrink=0.6, pad=0.12)
    set_equal_axes(ax3, np.vstack([ws.points.min(axis=0), ws.points.max(axis=0)]), margin=0.02)
    ax3.view_init(elev=22, azim=-58)
    ax3.set_box_aspect((1, 1, 1), zoom=0.82)  # room for the z label beside the next panel
    ax3.set_title("point cloud", fontsize=9)
    ax_xy = fig.add_subplot(1, 3, 2)
    ax_xy.scatter(pts[:, 0], pts[:, 1], s=0.6, color="#2b6cb0", alpha=0.4, linewidths=0)
    ax_xy.set_title("x–y projection (top view)", fontsize=9)
    ax_xy.set_xlabel("x [m]")
    ax_xy.set_ylabel("y [m]")
    ax_xz = fig.add_subplot(1, 3, 3)
    sect = ws.points[np.abs(ws.points[:, 1] - ws.base_origin[1]) <= ws.resolution]
    if len(sect) == 0 or ws.planar:
        sect = ws.points
        ax_xz.set_title("x–z projection", fontsize=9)
    else:
        ax_xz.set_title(f"x–z section, |y − y0| ≤ {ws.resolution:.3g} m", fontsize=9)
    sect = sect[:: max(1, len(sect) // max_points)]
    ax_xz.scatter(sect[:, 0], sect[:, 2], s=0.8, color="#c05621", alpha=0.5, linewidths=0)
    ax_xz.set_xlabel("x [m]")
    ax_xz.set_ylabel("z [m]")
    for ax in (ax_xy, ax_xz):
        ax.set_aspect("equal", adjustable="datalim")
        ax.grid(True, linewidth=0.3)
    size = (f"area ≈ {ws.area:.4g} m²" if ws.planar else f"volume ≈ {ws.volume:.4g} m³") + \
        f" ({ws.resolution:.3g} m cells, {ws.samples} samples)"
    fig.suptitle(f"{title} workspace — extent {ws.extent[0]:.3g} × {ws.extent[1]:.3g} × {ws.extent[2]:.3g} m, "
                 f"reach {ws.reach:.3g} m, {size}", fontsize=10)
    return fig


# ---- pictures of the streamed results (denavit.scale) ------------------------------------------------------

def _image(ax, img: np.ndarray, extent, label_x: str, label_y: str, cmap: str, title: str, vmax=None):
    im = ax.imshow(img.T, origin="lower", extent=extent, cmap=cmap, vmin=0, vmax=vmax, interpolation="nearest")
    ax.set_xlabel(label_x)
    ax.set_ylabel(label_y)
    ax.set_title(title, fontsize=9)
    return im


def _level_counts(occ) -> tuple[np.ndarray, float]:
    """The counts summed to the cell edge of the reported estimate."""
    from ..scale import coarsen

    c, h = occ.counts, occ.grid.resolution
    while h < occ.estimate.resolution * (1 - 1e-9):
        c, h = coarsen(c), 2 * h
    return c, h


def _crop(ax, lo, hi, pad: float, extent) -> None:
    """Limits around the occupied box ``lo``–``hi`` with a margin ``pad``, never past the image's ``extent``
    (x0, x1, y0, y1): beyond it the axes showed a white band (issue 31)."""
    ax.set_xlim(max(lo[0] - pad, extent[0]), min(hi[0] + pad, extent[1]))
    ax.set_ylim(max(lo[1] - pad, extent[2]), min(hi[1] + pad, extent[3]))


_DENSITY = "ln(1 + samples per cell): sampling density"


def plot_occupancy(occ, title: str = "", figsize=(13.5, 4.6), dpi: int = 100):
    """Pictures of a :class:`denavit.scale.Occupancy`: x–y projection, x–z and y–z sections through the base.

    Cells (at the edge of the reported estimate) are shaded by the log of their sample count: the sampling
    density, not a reachability measure.  A planar arm gets one picture of its plane.  Returns a Figure.
    """
    from ._plot import new_figure

    g, e = occ.grid, occ.estimate
    counts, h = _level_counts(occ)
    n = counts.shape[0]
    span = (g.lo, g.lo + n * h)
    dens = np.log1p(counts.astype(float))
    hit = np.argwhere(counts > 0)
    lo_u, hi_u = g.lo + hit.min(axis=0) * h, g.lo + (hit.max(axis=0) + 1) * h  # occupied box, grid coordinates
    fig = new_figure((min(figsize[0], 6.4), figsize[1] + 0.6) if occ.planar else figsize, dpi)
    if occ.planar:
        ax = fig.add_subplot(1, 1, 1)
        im = _image(ax, dens, (*span, *span), "u [m] (in the arm's plane)", "v [m]", "viridis",
                    "sampled cells (log count)")
        fig.colorbar(im, ax=ax, label=_DENSITY, shrink=0.8)
        ax.set_aspect("equal")
        _crop(ax, lo_u, hi_u, 2 * h, (*span, *span))
        size = f"area {e.value:.4g} m² ∈ [{e.low:.4g}, {e.high:.4g}]"
    else:
        i0 = n // 2  # the centre plane holds the base of joint 1
        panels = [(dens.max(axis=2), (0, 1), "x–y projection (top view)"),
                  (dens[:, i0, :], (0, 2), "x–z section through the base"),
                  (dens[i0, :, :], (1, 2), "y–z section through the base")]
        for k, (img, (a, b), name) in enumerate(panels):
            ax = fig.add_subplot(1, 3, k + 1)
            c = g.centre[[a, b]]
            ext = (c[0] + span[0], c[0] + span[1], c[1] + span[0], c[1] + span[1])
            im = _image(ax, img, ext, "xyz"[a] + " [m]", "xyz"[b] + " [m]", "viridis", name,
                        vmax=float(dens.max()) or 1.0)
            ax.set_aspect("equal")
            _crop(ax, c + lo_u[[a, b]], c + hi_u[[a, b]], 2 * h, ext)
        fig.colorbar(im, ax=fig.axes, label=_DENSITY, shrink=0.8)  # one scale (vmax) for the three panels
        size = f"volume {e.value:.4g} m³ ∈ [{e.low:.4g}, {e.high:.4g}]"
    fig.suptitle(f"{title} workspace — {size}{chr(10) if occ.planar else ' '}({e.resolution:.3g} m cells, "
                 f"{occ.samples:,} samples), reach {occ.reach:.3g} m", fontsize=10)  # two lines on the narrow figure
    return fig


def plot_reachability(rmap, title: str = "", slices: int = 4, figsize=(13.5, 7.0), dpi: int = 100):
    """Horizontal slices of a :class:`denavit.scale.ReachabilityMap`: reachability (top), manipulability (bottom).

    ``slices`` heights evenly spread over the reached cells.  Returns a Figure.
    """
    from ._plot import new_figure

    g = rmap.grid
    hit = np.argwhere(rmap.fraction > 0)
    ks = np.linspace(hit[:, 2].min(), hit[:, 2].max(), slices + 2)[1:-1].round().astype(int) if len(hit) else \
        np.full(slices, g.side // 2)
    lo = g.centre + g.lo
    ext = (lo[0], lo[0] + g.side * g.resolution, lo[1], lo[1] + g.side * g.resolution)
    wmax = float(rmap.manipulability.max()) or 1.0
    fig = new_figure(figsize, dpi)
    for j, k in enumerate(ks):
        z = lo[2] + (k + 0.5) * g.resolution
        ax = fig.add_subplot(2, slices, j + 1)
        im1 = _image(ax, rmap.fraction[:, :, k], ext, "x [m]", "y [m]", "magma", f"z = {z:.3g} m", vmax=1.0)
        ax.set_aspect("equal")
        ax = fig.add_subplot(2, slices, slices + j + 1)
        im2 = _image(ax, rmap.manipulability[:, :, k], ext, "x [m]", "y [m]", "viridis", f"z = {z:.3g} m",
                     vmax=wmax)
        ax.set_aspect("equal")
    fig.colorbar(im1, ax=fig.axes[0::2], label="share of orientations reached", shrink=0.8)
    fig.colorbar(im2, ax=fig.axes[1::2], label="manipulability √det(J J$^T$)", shrink=0.8)
    s = rmap.summary()
    fig.suptitle(f"{title} reachability — {s['orientations']} orientations per {g.resolution:.3g} m voxel "
                 f"({rmap.method} IK); reachable {s['reachable_volume']:.3g} m³, ≥ 50 % of orientations "
                 f"{s['dexterous_volume']:.3g} m³", fontsize=10)
    return fig
