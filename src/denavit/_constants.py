"""Limits and names shared by the library and the command line, in a module that imports nothing.

The command line's parser shows these in its ``--help`` texts and uses them as defaults and bounds; kept here,
building the parser loads neither :mod:`denavit.scale` nor :mod:`denavit.numeric` (each re-exports its own).
"""

from __future__ import annotations

__all__ = ["TWIST_ROWS", "LOCAL_SCHEDULERS", "MAX_WORKERS", "MAX_SAMPLES", "DEFAULT_ORIENTATIONS", "MAX_ORIENTATIONS"]

#: Names of the rows of a twist / Jacobian, in order.
TWIST_ROWS = ("vx", "vy", "vz", "wx", "wy", "wz")

#: Schedulers that need no address: in this process, a thread or process pool, a LocalCluster started here.
LOCAL_SCHEDULERS = ("auto", "synchronous", "threads", "processes", "dask")
#: Most local workers.
MAX_WORKERS = 256
#: Most samples in one run (10¹⁰ ≈ 1 h here with the default FK; bounded time).
MAX_SAMPLES = 10**10
#: Orientations per voxel by default, and at most.
DEFAULT_ORIENTATIONS = 100
MAX_ORIENTATIONS = 10_000
