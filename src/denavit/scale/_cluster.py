"""The Dask side of the schedulers: connecting to a given ``dask.distributed`` scheduler, and the LocalCluster
that ``scheduler="dask"`` starts for a run."""

from __future__ import annotations

from ..errors import MissingDependencyError, ParseError

__all__ = ["LOCAL_CLUSTER_CONFIG", "CONNECT_TIMEOUT", "connect", "start_local_cluster"]

#: Dask settings of the LocalCluster that ``scheduler="dask"`` starts (single-threaded worker processes): the
#: workers' statistical profiler (a stack sample every 10 ms) and 0.1–0.5 s monitors cost an idle worker ~4 % of
#: a core; the C library's trim threshold is raised from the nanny's 64 kB for FK callables with large temporaries.
LOCAL_CLUSTER_CONFIG = {
    "distributed.worker.profile.enabled": False,
    "distributed.admin.system-monitor.interval": "2s",
    "distributed.worker.memory.monitor-interval": "1s",
    "distributed.nanny.pre-spawn-environ.MALLOC_TRIM_THRESHOLD_": 2**30,
}
#: Seconds to wait for a dask.distributed scheduler to answer.
CONNECT_TIMEOUT = 10.0


def connect(address: str):
    """A Client of the dask.distributed scheduler at ``address`` (ParseError when none answers in time)."""
    try:
        from distributed import Client
    except ImportError:
        raise MissingDependencyError("a cluster scheduler needs dask.distributed: pip install 'denavit[scale]'") \
            from None
    try:
        return Client(address, timeout=CONNECT_TIMEOUT, set_as_default=False)
    except (OSError, TimeoutError) as exc:
        raise ParseError(f"scheduler {address}: no dask scheduler answered within {CONNECT_TIMEOUT:g} s "
                         f"({type(exc).__name__})") from None


def start_local_cluster(workers: int):
    """A LocalCluster of ``workers`` single-threaded processes and its Client."""
    try:
        import dask
        from distributed import Client, LocalCluster
    except ImportError:
        raise MissingDependencyError("scheduler 'dask' needs dask.distributed: pip install 'denavit[scale]'") \
            from None
    with dask.config.set(LOCAL_CLUSTER_CONFIG):
        cluster = LocalCluster(n_workers=workers, threads_per_worker=1, processes=True, dashboard_address=None)
    try:
        client = Client(cluster, set_as_default=False)
    except BaseException:
        cluster.close()
        raise
    return client, cluster
