"""Workspace and reachability at scale: streamed sampling, voxel occupancy, volume with an interval (refined
at the workspace's boundary), reachability and manipulability maps.

The same task functions run in this process, in a thread or process pool, or on a ``dask.distributed``
cluster: a private one started for the run (TLS with temporary credentials) or one given by a ``tcp://`` or
``tls://`` address, which is trusted (it receives pickles) (the optional extra ``denavit[scale]``); results depend on the seed only, not on
the number of workers or the chunk size.  See ``docs/workspace.md``.

Importing this package needs numpy only; dask is imported when a cluster or a dask array is asked for.
"""

from ._sampler import (BLOCK, COMPILED_FROM, FINE_CELLS, MAX_CELLS, CompiledPositionFK, Grid, PositionFK, default_fk,
                       reach_bound, sampling_limits)
from ._cluster import CONNECT_TIMEOUT, LOCAL_CLUSTER_CONFIG, SCHEMES, local_cluster
from ._schedule import LOCAL_SCHEDULERS, MAX_WORKERS, check_scheduler
from ._volume import MIN_COVERAGE, VolumeEstimate, coarsen, estimate_volume
from ._refine import MAX_REFINE, PILOT_SHARE, REFINE_CELLS, REFINE_COVERAGE, Refinement
from ._reach import DEFAULT_ORIENTATIONS, MAX_ORIENTATIONS, ReachabilityMap, orientation_set, reachability
from ._occupancy import (CLUSTER_CHUNK, DEFAULT_CHUNK, MAX_CHUNK, MAX_SAMPLES, TAIL_SHARE, Occupancy,
                         load_occupancy, new_seed, occupancy, sample_positions)

__all__ = [
    "BLOCK",
    "CLUSTER_CHUNK",
    "COMPILED_FROM",
    "CompiledPositionFK",
    "DEFAULT_ORIENTATIONS",
    "CONNECT_TIMEOUT",
    "DEFAULT_CHUNK",
    "FINE_CELLS",
    "LOCAL_CLUSTER_CONFIG",
    "LOCAL_SCHEDULERS",
    "MAX_CELLS",
    "MAX_CHUNK",
    "MAX_ORIENTATIONS",
    "MAX_REFINE",
    "PILOT_SHARE",
    "REFINE_CELLS",
    "REFINE_COVERAGE",
    "SCHEMES",
    "TAIL_SHARE",
    "Refinement",
    "MAX_SAMPLES",
    "MAX_WORKERS",
    "MIN_COVERAGE",
    "Grid",
    "Occupancy",
    "PositionFK",
    "ReachabilityMap",
    "VolumeEstimate",
    "check_scheduler",
    "default_fk",
    "coarsen",
    "estimate_volume",
    "load_occupancy",
    "local_cluster",
    "new_seed",
    "occupancy",
    "orientation_set",
    "reachability",
    "reach_bound",
    "sample_positions",
    "sampling_limits",
]
