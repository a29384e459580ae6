"""Reachability and manipulability maps: per voxel, the share of a fixed orientation set the arm reaches.

For every cell of a cubic grid inside the reach ball (edge ``resolution``, centred on the base of joint 1)
and every rotation of a fixed, deterministic near-uniform set on SO(3) (super-Fibonacci spiral, Alexa 2022),
the pose (rotation, cell centre) is solved by batched closed-form IK (``denavit.analytic_ik``: all solutions,
within the joint limits) or, for arms without one, by ``denavit.solve_ik`` (numeric, restarts; a failure there
is not a proof of unreachability).  Zacharias, Borst & Hirzinger (IROS 2007) call the fraction the
reachability index.  The manipulability map is, per cell, the mean over reached orientations of the best
Yoshikawa manipulability √det(J Jᵀ) among that pose's solutions.

Cells far from every position sample are skipped: a position screen of SCREEN_SAMPLES configurations
(:func:`occupancy` at the map's resolution) marks the cells hit, grown by SCREEN_MARGIN cells; the rest of the
reach ball gets fraction 0 without IK (``screen=False`` tests the whole ball).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from .._constants import DEFAULT_ORIENTATIONS, MAX_ORIENTATIONS
from ..errors import ModelError, UnsupportedRobotError
from ..model import DHRobot
from ._sampler import MAX_CELLS, MIN_CELLS, Grid, reach_bound, sampling_limits
from ._schedule import Progress, run, session

__all__ = ["ReachabilityMap", "reachability", "orientation_set", "DEFAULT_ORIENTATIONS", "MAX_ORIENTATIONS",
           "MAX_POSES", "MAX_NUMERIC_POSES", "VOXELS_PER_TASK"]

#: Most (voxel, orientation) poses in one map with closed-form IK, and with numeric IK.
MAX_POSES = 5 * 10**7
MAX_NUMERIC_POSES = 20_000
#: Voxels per task.
VOXELS_PER_TASK = 200
#: Numeric IK: random restarts per pose.
NUMERIC_RESTARTS = 4
#: Samples of the position screen (cells no sample comes within SCREEN_MARGIN cells of are not tested).
SCREEN_SAMPLES = 2**21
SCREEN_MARGIN = 2


def orientation_set(k: int) -> np.ndarray:
    """k rotation matrices (k, 3, 3) spread near-uniformly over SO(3) (super-Fibonacci spiral, Alexa 2022)."""
    phi, psi = np.sqrt(2.0), 1.533751168755204288118041
    s = np.arange(k) + 0.5
    r, R = np.sqrt(s / k), np.sqrt(1.0 - s / k)
    a, b = 2 * np.pi * s / phi, 2 * np.pi * s / psi
    w, x, y, z = r * np.sin(a), r * np.cos(a), R * np.sin(b), R * np.cos(b)  # unit quaternions (k,)
    return np.stack([
        np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)], -1),
        np.stack([2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)], -1),
        np.stack([2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)], -1),
    ], -2)


@dataclass(frozen=True)
class ReachabilityMap:
    """Per-voxel reachability and manipulability (world frame, metres).

    Attributes
    ----------
    grid : Grid
        Cubic cells of edge ``grid.resolution`` along the world axes around ``grid.centre``.
    fraction : ndarray of float32, shape (side, side, side)
        Share of the orientations reached at the cell centre (0 outside the reach ball).
    manipulability : ndarray of float32, same shape
        Mean over reached orientations of the best √det(J Jᵀ) of the pose's solutions (0 where none).
    orientations : ndarray (k, 3, 3)
    method : str
        ``"analytic"`` or ``"numeric"``.
    voxels : int
        Cells tested (inside the reach ball).
    """

    grid: Grid
    fraction: np.ndarray
    manipulability: np.ndarray
    orientations: np.ndarray
    method: str
    voxels: int

    def summary(self) -> dict:
        f = self.fraction
        h = self.grid.resolution
        return {"resolution": h, "orientations": len(self.orientations), "method": self.method,
                "voxels_tested": self.voxels, "voxels_reached": int((f > 0).sum()),
                "reachable_volume": float((f > 0).sum() * h**3),
                "dexterous_volume": float((f >= 0.5).sum() * h**3), "mean_fraction": float(f[f > 0].mean())
                if (f > 0).any() else 0.0, "max_manipulability": float(self.manipulability.max())}

    def save(self, path) -> None:
        """Write the maps and grid to ``.npz`` (plain arrays)."""
        g = self.grid
        with open(path, "wb") as fh:  # a file object: numpy adds no '.npz' to the name
            np.savez_compressed(fh, fraction=self.fraction, manipulability=self.manipulability,
                            orientations=self.orientations, centre=g.centre, resolution=g.resolution,
                            side=g.side)


def _poses(grid: Grid, cells: np.ndarray, rot: np.ndarray) -> np.ndarray:
    p = grid.cell_centres(cells)  # (B, 3)
    T = np.zeros((len(p), len(rot), 4, 4))
    T[..., :3, :3] = rot
    T[..., :3, 3] = p[:, None, :]
    T[..., 3, 3] = 1.0
    return T  # (B, K, 4, 4)


def _analytic_task(robot, grid, cells, rot):
    from ..ik import analytic_ik
    from ..numeric import geometric_jacobian, manipulability

    res = analytic_ik(robot, _poses(grid, cells, rot))
    valid = np.asarray(res.valid)  # (B, K, S)
    w = np.zeros(valid.shape)
    if valid.any():
        w[valid] = manipulability(geometric_jacobian(robot, res.solutions[valid], threads=1))
    reached = valid.any(axis=-1)  # (B, K)
    best = w.max(axis=-1)  # (B, K)
    return cells, reached.mean(axis=-1), _mean_reached(best, reached)


def _numeric_task(robot, grid, cells, rot, seed):
    from ..ik import solve_ik
    from ..numeric import geometric_jacobian, manipulability

    T = _poses(grid, cells, rot)
    reached = np.zeros(T.shape[:2], dtype=bool)
    best = np.zeros(T.shape[:2])
    flat = np.ravel_multi_index(tuple(cells.T), grid.shape)
    for i in range(len(cells)):
        for k in range(len(rot)):
            rng = np.random.Generator(np.random.Philox(np.random.SeedSequence(seed, spawn_key=(int(flat[i]), k))))
            r = solve_ik(robot, T[i, k], restarts=NUMERIC_RESTARTS, rng=rng)
            if r.success:
                reached[i, k] = True
                best[i, k] = float(manipulability(geometric_jacobian(robot, r.q, threads=1)))
    return cells, reached.mean(axis=-1), _mean_reached(best, reached)


def _near_samples(robot, grid: Grid, seed: int, scheduler, workers, progress=False) -> np.ndarray:
    """Cells of ``grid`` within SCREEN_MARGIN cells of a position sample (boolean, grid.shape)."""
    from ._occupancy import occupancy
    from ._volume import interior

    everything = np.ones(grid.shape, dtype=bool)
    if grid.side <= MIN_CELLS:  # too coarse a grid to screen: test every cell
        return everything
    try:
        occ = occupancy(robot, SCREEN_SAMPLES, grid.resolution, seed, scheduler=scheduler, workers=workers,
                        progress=progress)
    except ModelError:  # a grid finer than occupancy's MAX_CELLS: test every cell
        return everything
    if occ.planar or occ.grid.side != grid.side or not np.allclose(occ.grid.centre, grid.centre):
        return everything
    near = occ.counts > 0
    for _ in range(SCREEN_MARGIN):  # dilation = complement of the erosion of the complement
        near = ~interior(~near)
    return near


def _mean_reached(best, reached):
    n = reached.sum(axis=-1)
    return np.where(n > 0, (best * reached).sum(axis=-1) / np.maximum(n, 1), 0.0)


def _method(robot: DHRobot, ik: str) -> str:
    from ..ik import analytic_ik
    from ..numeric import forward_kinematics

    if ik not in ("auto", "analytic", "numeric"):
        raise ModelError(f"ik must be auto, analytic or numeric, got {ik!r}")
    if robot.dof < 6:
        raise UnsupportedRobotError(f"{robot.name}: a reachability map needs an arm that sets the full pose "
                                    f"(6 or more joints); this one has {robot.dof}")
    if ik == "numeric":
        return "numeric"
    try:
        res = analytic_ik(robot, forward_kinematics(robot, np.zeros((1, robot.dof))))
        if res.controlled != "pose":
            raise UnsupportedRobotError(f"{robot.name} controls {res.controlled} only")
    except UnsupportedRobotError:
        if ik == "analytic":
            raise
        return "numeric"
    return "analytic"


def reachability(robot: DHRobot, resolution: float = 0.05, orientations: int = DEFAULT_ORIENTATIONS, *,
                 ik: str = "auto", scheduler: Any = "threads", workers: int | None = None, seed: int = 0,
                 screen: bool = True, progress: bool | None = False) -> ReachabilityMap:
    """Reachability (share of orientations reached) and manipulability per voxel of the reach ball.

    Parameters
    ----------
    robot : DHRobot
        An arm with 6 or more joints.
    resolution : float
        Voxel edge [m].
    orientations : int
        Size of the fixed orientation set (:func:`orientation_set`).
    ik : {"auto", "analytic", "numeric"}
        ``auto``: closed form when the arm has one, numeric otherwise.
    scheduler, workers, progress
        As for :func:`denavit.scale.occupancy`.
    seed : int
        Seed of the position screen and of the numeric solver's restarts (per voxel and orientation).
    screen : bool
        Skip cells more than SCREEN_MARGIN cells from every position sample (see the module notes).

    Returns
    -------
    ReachabilityMap
    """
    sampling_limits(robot)
    method = _method(robot, ik)
    k = int(orientations)
    if not 1 <= k <= MAX_ORIENTATIONS:
        raise ModelError(f"orientations must be from 1 to {MAX_ORIENTATIONS}, got {orientations}")
    h = float(resolution)
    if not (h > 0 and np.isfinite(h)):
        raise ModelError(f"resolution must be a positive length in metres, got {resolution}")
    centre, R = reach_bound(robot)
    cells_per_side = 2 * R / h
    cap = round(MAX_CELLS ** (1 / 3))
    if cells_per_side > cap:
        raise ModelError(f"resolution {h:g} m gives {cells_per_side:.3g} cells along the {2 * R:.4g} m reach box "
                         f"(at most {cap}): use a resolution of at least {2 * R / cap:.3g} m")
    side = max(1, int(np.ceil(cells_per_side)))
    grid = Grid(centre, np.eye(3), h, side, 1)
    ball = 4 / 3 * np.pi * (R + h) ** 3 / h**3  # cells to test, about
    limit = MAX_POSES if method == "analytic" else MAX_NUMERIC_POSES
    if ball * k > limit:
        raise ModelError(f"resolution {h:g} m and {k} orientations make about {ball * k:.3g} IK problems "
                         f"(at most {limit:.3g} with {method} IK): use a coarser resolution or fewer orientations")
    with session(scheduler, workers) as where:  # one cluster for the screen and the map
        near = _near_samples(robot, grid, seed, where, workers, progress) if screen else None
        cells, frac, manip, rot = _map(robot, grid, centre, R, near, k, method, seed, where, workers, progress)
    return ReachabilityMap(grid, frac, manip, rot, method, len(cells))


def _map(robot, grid: Grid, centre, R: float, near, k: int, method: str, seed: int, scheduler, workers, progress):
    """The tested cells (m, 3), the fraction and manipulability grids and the orientation set of a map."""
    h, side = grid.resolution, grid.side
    jk = np.indices((side, side), dtype=np.int32).reshape(2, -1).T  # (side², 2)
    parts = []
    for i in range(side):  # one x-slice at a time: memory ∝ side², not side³
        idx = np.column_stack([np.full(len(jk), i, dtype=np.int32), jk])  # (side², 3)
        inside = np.linalg.norm(grid.cell_centres(idx) - centre, axis=1) <= R + 0.5 * np.sqrt(3) * h
        if near is not None:
            inside &= near[i].reshape(-1)
        parts.append(idx[inside])
    cells = np.concatenate(parts)
    rot = orientation_set(k)
    if method == "analytic":
        tasks = ((robot, grid, cells[i:i + VOXELS_PER_TASK], rot) for i in range(0, len(cells), VOXELS_PER_TASK))
        fn = _analytic_task
    else:
        tasks = ((robot, grid, cells[i:i + 8], rot, int(seed)) for i in range(0, len(cells), 8))
        fn = _numeric_task
    frac = np.zeros(grid.shape, dtype=np.float32)
    manip = np.zeros(grid.shape, dtype=np.float32)
    bar = Progress(len(cells), "voxels", progress)
    try:
        for c, f, w in run(fn, tasks, scheduler, workers):
            frac[tuple(c.T)], manip[tuple(c.T)] = f, w
            bar.update(len(c))
    finally:
        bar.close()
    return cells, frac, manip, rot
