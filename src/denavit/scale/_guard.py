"""Worker preload of the LocalCluster ``scheduler="dask"`` starts: ties each worker process to the process
that started it, and leaves Ctrl-C to that process.

Dask's nanny starts each worker with a pipe whose end-of-file makes the worker exit, but that needs the worker's
Python to run (a task holding the GIL delays it).  So, in each worker process (``worker.nanny`` set):

- Linux: ``prctl(PR_SET_PDEATHSIG, SIGKILL)`` — the kernel kills the worker when its parent dies, SIGKILL of the
  parent included (prctl(2));
- everywhere: a daemon thread polls ``os.getppid()`` every POLL seconds and exits when it changes (the parent
  died and the worker was re-parented);
- SIGINT is ignored (a terminal's Ctrl-C reaches the whole process group; the driver cancels the tasks and
  closes the cluster) and SIGTERM unblocked (the driver starts the cluster with both blocked, see ``_cluster``).

Dask calls :func:`dask_setup` when the worker starts (the ``preload`` option of a Nanny or Worker).
"""

from __future__ import annotations

import ctypes
import multiprocessing
import os
import signal
import sys
import threading
import time

__all__ = ["POLL", "dask_setup"]

#: Seconds between two checks that the parent process is alive.
POLL = 1.0
#: prctl(2) option: the signal the kernel sends this process when its parent dies (linux/prctl.h).
_PR_SET_PDEATHSIG = 1


def dask_setup(worker) -> None:
    """Tie this worker process to its parent (a worker without a nanny runs in the driver: left alone)."""
    parent = multiprocessing.parent_process()
    if getattr(worker, "nanny", None) is None or parent is None:
        return
    if threading.current_thread() is threading.main_thread():
        signal.signal(signal.SIGINT, signal.SIG_IGN)
    if hasattr(signal, "pthread_sigmask"):
        signal.pthread_sigmask(signal.SIG_UNBLOCK, {signal.SIGTERM})
    die_with(parent.pid)


def die_with(ppid: int) -> None:
    """End this process when the process ``ppid`` (its parent) ends."""
    if sys.platform.startswith("linux"):
        try:
            libc = ctypes.CDLL(None, use_errno=True)
            libc.prctl(_PR_SET_PDEATHSIG, signal.SIGKILL, 0, 0, 0)
        except (OSError, AttributeError):  # no prctl: the polling thread alone
            pass
    if os.getppid() != ppid:  # the parent died before the kernel was told
        os._exit(1)
    threading.Thread(target=_watch, args=(ppid,), name="denavit parent watch", daemon=True).start()


def _watch(ppid: int) -> None:
    while os.getppid() == ppid:
        time.sleep(POLL)
    os._exit(1)
