"""The Dask side of the schedulers: connecting to a given ``dask.distributed`` scheduler, and the private
LocalCluster that ``scheduler="dask"`` starts for a run.

Whoever can talk to a Dask scheduler runs code in its workers (tasks and results travel as pickles), so:

- the LocalCluster started here speaks TLS with credentials made for it alone (``Security.temporary()``: a
  self-signed CA and key held in memory and handed to the worker processes, never written to disk); a client
  without them is refused at the handshake.  No dashboard is served unless asked for (and then on 127.0.0.1);
- an address given by the user names a scheduler the user trusts: only ``tcp://`` and ``tls://`` are accepted;
- the worker processes die with the process that started them (see ``_guard``) and ignore Ctrl-C (the driver
  owns it: cancels, closes the cluster, one line); a SIGTERM of this process first closes the cluster, then
  exits with status 143.
"""

from __future__ import annotations

import contextlib
import os
import re
import signal
import threading
from typing import Iterator

from ..errors import DenavitError, MissingDependencyError, ParseError, Terminated

__all__ = ["CLOSE_TIMEOUT", "CONNECT_TIMEOUT", "GUARD", "LOCAL_CLUSTER_CONFIG", "SCHEMES", "check_address",
           "close_within", "cluster_failure", "connect", "local_cluster", "start_local_cluster"]

#: Dask settings of the LocalCluster that ``scheduler="dask"`` starts (single-threaded worker processes): the
#: workers' statistical profiler (a stack sample every 10 ms) and 0.1–0.5 s monitors cost an idle worker ~4 % of
#: a core; the C library's trim threshold is raised from the nanny's 64 kB for FK callables with large temporaries.
#: The scheduler's and workers' HTTP servers serve nothing (no dashboard, no JSON or Prometheus pages).
LOCAL_CLUSTER_CONFIG = {
    "distributed.worker.profile.enabled": False,
    "distributed.admin.system-monitor.interval": "2s",
    "distributed.worker.memory.monitor-interval": "1s",
    "distributed.nanny.pre-spawn-environ.MALLOC_TRIM_THRESHOLD_": 2**30,
    "distributed.scheduler.http.routes": [],
    "distributed.worker.http.routes": [],
}
#: Seconds to wait for a dask.distributed scheduler to answer.
CONNECT_TIMEOUT = 10.0
#: Seconds the Client's and the LocalCluster's close may take in all when a run ends.  It takes 1-5 s (up to load
#: 11 on 2 cores); once, in a full test run at load ~10, a close after Ctrl-C had not returned after 60 s, so the
#: wait is bounded: past it the run ends without it (the worker processes die with this process, see ``_guard``).
CLOSE_TIMEOUT = 20.0
#: Address schemes accepted for a scheduler of the user's (``inproc://`` and ``ucx://`` are refused).
SCHEMES = ("tcp", "tls")
#: The worker preload that ties each worker process to this one (module name, imported in the worker).
GUARD = "denavit.scale._guard"
#: Where the local cluster's HTTP server listens: loopback, a free port (never Dask's well-known 8787).
_HTTP_ADDRESS = "127.0.0.1:0"
#: HTTP routes of the scheduler when a dashboard is asked for (Dask's defaults but the proxy to other hosts).
_DASHBOARD_ROUTES = ["distributed.http.scheduler.prometheus", "distributed.http.scheduler.info",
                     "distributed.http.scheduler.json", "distributed.http.health", "distributed.http.statics"]
_ADDRESS = re.compile(r"^(tcp|tls)://([A-Za-z0-9_.\-]{1,253}|\[[0-9A-Fa-f:.]{2,45}\]):(\d{1,5})$")
_SCHEME = re.compile(r"^([A-Za-z][A-Za-z0-9+.\-]{0,30})://")
_QUIET = 50  # logging.CRITICAL: Dask's own log lines stay off stderr (a failure is one line from the caller)


def check_address(text: str) -> None:
    """Refuse a scheduler address other than ``tcp://HOST:PORT`` or ``tls://HOST:PORT`` (ParseError)."""
    shown = text if len(text) <= 60 else text[:57] + "..."
    m = _ADDRESS.match(text)
    if m and 0 < int(m.group(3)) < 65536:
        return
    scheme = _SCHEME.match(text)
    if scheme and scheme.group(1).lower() not in SCHEMES:
        raise ParseError(f"scheduler {shown!r}: only tcp:// and tls:// addresses are accepted, not "
                         f"{scheme.group(1)}://")
    if not scheme and _ADDRESS.match("tcp://" + text):
        raise ParseError(f"scheduler {shown!r}: name the protocol: tcp://{shown} or tls://{shown}")
    raise ParseError(f"scheduler {shown!r}: expected dask, threads, processes, synchronous, auto or a dask "
                     "scheduler address such as tcp://127.0.0.1:8786 or tls://HOST:8786")


def connect(address: str):
    """A Client of the dask.distributed scheduler at ``address`` (trusted: it receives pickles).

    ``tls://`` uses the client credentials of the Dask configuration (``distributed.comm.tls.*``).  Raises
    ParseError when no scheduler answers within CONNECT_TIMEOUT or the handshake fails."""
    check_address(address)
    try:
        from distributed import Client, Security
    except ImportError:
        raise MissingDependencyError("a cluster scheduler needs dask.distributed: pip install 'denavit[scale]'") \
            from None
    security = Security()
    if address.startswith("tls://") and security.get_connection_args("client").get("ssl_context") is None:
        raise ParseError(f"scheduler {address}: a tls:// address needs the client's credentials in the Dask "
                         "configuration (distributed.comm.tls.ca-file, .client.cert, .client.key)")
    try:
        return Client(address, timeout=CONNECT_TIMEOUT, set_as_default=False, security=security)
    except (OSError, TimeoutError) as exc:
        raise ParseError(f"scheduler {address}: no dask scheduler answered within {CONNECT_TIMEOUT:g} s "
                         f"({type(exc).__name__})") from None
    except Exception as exc:  # noqa: BLE001 - a TLS or protocol mismatch: one line naming the address
        raise ParseError(f"scheduler {address}: the connection failed ({type(exc).__name__}: "
                         f"{str(exc).splitlines()[0][:200] if str(exc) else ''})") from None


def start_local_cluster(workers: int, dashboard: bool = False):
    """A LocalCluster of ``workers`` single-threaded processes on TLS with temporary credentials, and its Client.

    Ctrl-C and SIGTERM are held (blocked in this thread) while the cluster starts, so the cluster's threads and
    worker processes inherit a blocked Ctrl-C; either signal, if it came, lands once the Client exists, and the
    cluster is closed before it propagates."""
    try:
        import dask
        from distributed import Client, LocalCluster, Security
    except ImportError:
        raise MissingDependencyError("scheduler 'dask' needs dask.distributed: pip install 'denavit[scale]'") \
            from None
    if dashboard:
        import importlib.util

        if importlib.util.find_spec("bokeh") is None:
            raise MissingDependencyError("the Dask dashboard needs bokeh: pip install 'bokeh>=3.1'")
    try:
        security = Security.temporary()
    except ImportError:
        raise MissingDependencyError("scheduler 'dask' needs cryptography for the cluster's TLS credentials: "
                                     "pip install 'denavit[scale]'") from None
    config = dict(LOCAL_CLUSTER_CONFIG)
    if dashboard:
        config["distributed.scheduler.http.routes"] = _DASHBOARD_ROUTES
    held = _hold_signals()
    cluster = client = None
    try:
        with dask.config.set(config):
            cluster = LocalCluster(n_workers=workers, threads_per_worker=1, processes=True, security=security,
                                   dashboard_address=_HTTP_ADDRESS if dashboard else None,
                                   scheduler_kwargs={"dashboard": dashboard, "dashboard_address": _HTTP_ADDRESS},
                                   silence_logs=_QUIET, preload=[GUARD])
        client = Client(cluster, set_as_default=False)
        _release_signals(held)  # a Ctrl-C or SIGTERM held during the start is raised here
    except BaseException:
        _release_signals(held)
        close_within(CLOSE_TIMEOUT, *(part for part in (client, cluster) if part is not None))
        raise
    return client, cluster


@contextlib.contextmanager
def local_cluster(workers: int | None = None, *, dashboard: bool = False) -> Iterator:
    """The Client of a private LocalCluster (see :func:`start_local_cluster`), closed on leaving; a SIGTERM of
    this process meanwhile closes the cluster and then exits (``SystemExit(143)``).

    ``dashboard=True`` serves Dask's dashboard on 127.0.0.1 at a free port (``client.dashboard_link``): plain
    HTTP that any local user can read (not a way to run code)."""
    with _terminate_cleanly():
        client, cluster = start_local_cluster(workers or os.cpu_count() or 1, dashboard)
        try:
            yield client
        finally:
            close_within(CLOSE_TIMEOUT, client, cluster)


def close_within(seconds: float, *parts) -> bool:
    """Close each of ``parts`` (a Client, its cluster) in turn, in a helper thread, waiting at most ``seconds``
    in all; True when every close returned.  A close that does not return in time is left behind (daemon thread):
    the run ends anyway, and the worker processes die with this process (``_guard``).  An error while closing is
    not the run's result and is dropped."""

    def close_all():
        for part in parts:
            try:
                part.close()
            except Exception:  # noqa: BLE001 - a failing close must not replace the run's own outcome
                pass

    closer = threading.Thread(target=close_all, name="denavit-close-cluster", daemon=True)
    closer.start()
    closer.join(seconds)
    return not closer.is_alive()


def cluster_failure(exc: BaseException) -> DenavitError | None:
    """A one-line error for a failure of the cluster itself (a worker killed, the connection lost, a task
    cancelled by the scheduler), or None for any other exception (a task's own error, raised as it is)."""
    import asyncio
    import concurrent.futures as cf

    from distributed.comm.core import CommClosedError
    from distributed.scheduler import KilledWorker

    if isinstance(exc, KilledWorker):
        why = "a task's worker process died (out of memory, or killed) as many times as Dask allows"
    elif isinstance(exc, CommClosedError):
        why = "the connection to the scheduler was lost"
    elif isinstance(exc, (cf.CancelledError, asyncio.CancelledError)):
        why = "the scheduler cancelled a task (it lost its workers or was shut down)"
    else:
        return None
    return DenavitError(f"the Dask cluster failed: {why} ({type(exc).__name__})")


def _raise_terminated(signum, frame):
    raise Terminated


@contextlib.contextmanager
def _terminate_cleanly() -> Iterator[None]:
    """While inside: SIGTERM (when its disposition is the default) raises :class:`denavit.errors.Terminated` in the
    main thread; once the cleanups ran, the process exits with status 128 + SIGTERM = 143 (``SystemExit``, so the
    exit handlers run too: multiprocessing's release the cluster's semaphores, and its resource tracker stays
    silent).  The signal may land in a frame outside this block — the caller consuming a generator that holds
    the cluster, say — and then reaches the caller as ``Terminated``; the command line exits 143 for it too."""
    if threading.current_thread() is not threading.main_thread() or \
            signal.getsignal(signal.SIGTERM) is not signal.SIG_DFL:
        yield
        return
    signal.signal(signal.SIGTERM, _raise_terminated)
    try:
        yield
    except Terminated:
        signal.signal(signal.SIGTERM, signal.SIG_DFL)
        raise SystemExit(128 + signal.SIGTERM) from None
    finally:
        signal.signal(signal.SIGTERM, signal.SIG_DFL)


def _hold_signals():
    """Block SIGINT and SIGTERM in this (main) thread; returns what to pass to :func:`_release_signals`.

    multiprocessing's resource tracker is started first: starting it unblocks both signals in the starting
    thread (``resource_tracker.ensure_running``), which would undo the hold in the cluster's thread."""
    if not hasattr(signal, "pthread_sigmask") or threading.current_thread() is not threading.main_thread():
        return None
    from multiprocessing import resource_tracker

    resource_tracker.ensure_running()
    return signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT, signal.SIGTERM})


def _release_signals(held) -> None:
    if held is not None:
        signal.pthread_sigmask(signal.SIG_SETMASK, held)
