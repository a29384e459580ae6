"""Running a costly function under a CPU-time bound, safely from a process with threads alive.

:func:`cpu_bounded` runs ``fn(*args)`` in a child process whose CPU time is limited (``RLIMIT_CPU``, so the
bound does not depend on the machine's load) and returns its value, or None when the CPU time runs out; an
exception raised by ``fn`` is raised again in the caller.

``fork()`` copies only the calling thread: a lock that another thread held at that moment (Jupyter, Dask workers,
a thread pool, numba's threading layer) stays held in the child forever, and a child that needs it waits without
using CPU, so its CPU limit never ends it.  A process that has imported numpy already has a second thread
(OpenBLAS's), so the caller is never forked.  Instead a small **worker** process, started once per process with
``sys.executable`` (a fresh interpreter, single-threaded: its BLAS and OpenMP pools are set to one thread, with the
modules named in ``warm`` imported once), forks one child per call.  The function and its arguments travel by
pickle (so ``fn`` must be a module-level function); the first call pays the worker's start (~0.6 s with sympy),
later calls a fork (~5 ms).  Calls from several threads take turns.  The worker ends when this process ends (its
requests pipe closes); a fork of this process starts its own (it neither waits for a turn held by one of the
parent's threads nor talks to the parent's worker); a caller interrupted while waiting ends the worker.

Where the OS has no ``fork`` or no ``RLIMIT_CPU`` (Windows), each call runs in a fresh interpreter
(multiprocessing's ``spawn``) and the bound is wall-clock time: :data:`WALL_SECONDS_WITHOUT_CPU_LIMIT` times
``seconds``, after the child's start, so it depends on the machine's load.  Elsewhere, a wall-clock safety net of
:data:`WALL_SAFETY_FACTOR` times ``seconds`` plus :data:`WALL_SAFETY_SECONDS` ends a child that waits without
using CPU.
"""

from __future__ import annotations

import atexit
import os
import pickle
import select
import signal
import struct
import subprocess
import sys
import threading
import time
from typing import Any, Callable

__all__ = ["cpu_bounded", "WALL_SAFETY_FACTOR", "WALL_SAFETY_SECONDS", "WALL_SECONDS_WITHOUT_CPU_LIMIT"]

#: The wall-clock safety net is this many times the CPU bound, plus WALL_SAFETY_SECONDS (a loaded machine gives a
#: child a fraction of a core; the CPU limit ends a busy child long before).
WALL_SAFETY_FACTOR = 40
WALL_SAFETY_SECONDS = 60
#: Without RLIMIT_CPU (Windows) the bound is wall-clock: this many times the CPU seconds asked for.
WALL_SECONDS_WITHOUT_CPU_LIMIT = 3

try:
    import resource
except ImportError:  # pragma: no cover - Windows
    resource = None  # type: ignore[assignment]

_CAN_FORK = hasattr(os, "fork") and resource is not None
#: Thread-pool sizes set to 1 in the worker, so that it really has one thread when it forks (numpy's BLAS would
#: otherwise start its own threads at import).
_THREAD_POOLS = ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS", "NUMEXPR_NUM_THREADS",
                 "VECLIB_MAXIMUM_THREADS", "NUMBA_NUM_THREADS")
_WORKER_START_SECONDS = 30  # the worker's own start (an interpreter, and the warm imports) on a loaded machine
_HEADER = struct.Struct("<Q")
_lock = threading.Lock()
_worker: subprocess.Popen | None = None


def cpu_bounded(fn: Callable, args: tuple, seconds: float, warm: tuple[str, ...] = ()) -> Any:
    """``fn(*args)`` in a child process limited to ``seconds`` of CPU time; None when it runs out.

    Parameters
    ----------
    fn : callable
        A module-level function (it is pickled by reference on the worker route).
    args : tuple
        Its arguments (picklable).
    seconds : float
        CPU seconds the child may use (rounded up to whole seconds, at least 1).
    warm : tuple of str
        Modules the worker imports once, before forking (``("denavit.symbolic",)``: sympy), so calls share them.

    Returns
    -------
    The value of ``fn(*args)``, or None when the CPU limit (or the wall-clock safety net) ended the child.

    Raises
    ------
    Exception
        The exception ``fn`` raised, raised again here.
    """
    if not _CAN_FORK:  # pragma: no cover - Windows
        status, value = _run_spawned(fn, args, seconds)
    else:
        with _lock:
            status, value = _run_in_worker(fn, args, seconds, warm)
    if status == "err":
        raise value
    return value if status == "ok" else None


def _cpu_limit(seconds: float) -> None:
    """Limit this process to ``seconds`` more CPU (soft: SIGXCPU, hard: one second later SIGKILL), no core file."""
    used = sum(resource.getrusage(resource.RUSAGE_SELF)[:2])
    limit = max(1, round(used + max(1.0, seconds)))  # the limit counts the CPU used since the fork
    _, hard = resource.getrlimit(resource.RLIMIT_CPU)
    hard = limit + 1 if hard == resource.RLIM_INFINITY else min(hard, limit + 1)
    resource.setrlimit(resource.RLIMIT_CPU, (min(limit, hard), hard))
    try:
        resource.setrlimit(resource.RLIMIT_CORE, (0, 0))  # SIGXCPU's default action dumps core
    except (ValueError, OSError):  # pragma: no cover
        pass


def _outcome(fn: Callable, args: tuple) -> bytes:
    """The pickled (status, value) of one call, made picklable whatever the function did."""
    try:
        result = ("ok", fn(*args))
    except Exception as exc:  # noqa: BLE001 - handed to the caller, which raises it
        result = ("err", exc)
    try:
        return pickle.dumps(result)
    except Exception as exc:  # noqa: BLE001 - an unpicklable value or exception
        return pickle.dumps(("err", RuntimeError(f"{type(result[1]).__name__}: {result[1]} ({exc})")))


def _fork_and_wait(run: Callable[[], bytes], wall: float) -> tuple[str, Any]:
    """Fork; the child writes ``run()`` to a pipe and exits; the parent reads it (None past ``wall`` seconds)."""
    r, w = os.pipe()
    pid = os.fork()
    if pid == 0:  # pragma: no cover - the child
        try:
            os.close(r)
            data = run()
            with os.fdopen(w, "wb") as f:
                f.write(data)
        finally:
            os._exit(0)
    os.close(w)
    chunks, deadline = [], time.monotonic() + wall
    try:
        while True:
            left = deadline - time.monotonic()
            if left <= 0 or not select.select([r], [], [], left)[0]:
                break
            chunk = os.read(r, 1 << 16)
            if not chunk:
                break
            chunks.append(chunk)
    finally:
        os.close(r)
        try:
            os.kill(pid, signal.SIGKILL)
        except ProcessLookupError:  # pragma: no cover
            pass
        os.waitpid(pid, 0)
    try:
        return pickle.loads(b"".join(chunks))
    except Exception:  # noqa: BLE001 - nothing, or a part: the child was ended by its limit
        return "limit", None


# --- the worker route ----------------------------------------------------------------------------------------


def _write(f, data: bytes) -> None:
    f.write(_HEADER.pack(len(data)) + data)
    f.flush()


def _read_exact(fd: int, n: int, deadline: float | None) -> bytes | None:
    buf = b""
    while len(buf) < n:
        if deadline is not None:
            left = deadline - time.monotonic()
            if left <= 0 or not select.select([fd], [], [], left)[0]:
                return None
        chunk = os.read(fd, min(n - len(buf), 1 << 20))
        if not chunk:
            return None
        buf += chunk
    return buf


def _read(fd: int, deadline: float | None) -> bytes | None:
    """One length-prefixed message from ``fd``; None on end of file or past the deadline."""
    header = _read_exact(fd, _HEADER.size, deadline)
    return None if header is None else _read_exact(fd, _HEADER.unpack(header)[0], deadline)


def _start_worker() -> subprocess.Popen:
    import json

    code = "import json, sys; sys.path[:] = json.loads(sys.argv[1]); from denavit.check._bounded import serve; serve()"
    env = dict(os.environ, **{name: "1" for name in _THREAD_POOLS})  # no BLAS threads: the worker forks
    return subprocess.Popen([sys.executable, "-c", code, json.dumps(sys.path)], stdin=subprocess.PIPE,
                            stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, start_new_session=True, close_fds=True,
                            env=env)


def _stop_worker() -> None:
    global _worker
    proc, _worker = _worker, None
    if proc is None:
        return
    try:
        os.killpg(proc.pid, signal.SIGKILL)  # the worker and a child it is running
    except (ProcessLookupError, PermissionError, AttributeError):
        proc.kill()
    proc.wait()
    for f in (proc.stdin, proc.stdout):
        try:
            f.close()
        except OSError:  # pragma: no cover
            pass


def _forget_worker() -> None:
    """In a fork of this process: the parent's worker and lock are the parent's (the lock may be held)."""
    global _lock, _worker
    _lock, _worker = threading.Lock(), None


atexit.register(_stop_worker)
if hasattr(os, "register_at_fork"):  # POSIX
    os.register_at_fork(after_in_child=_forget_worker)


def _wall(seconds: float) -> float:
    return seconds * WALL_SAFETY_FACTOR + WALL_SAFETY_SECONDS


def _run_spawned(fn: Callable, args: tuple, seconds: float) -> tuple[str, Any]:
    """Without fork or RLIMIT_CPU: a fresh interpreter (multiprocessing's spawn) ended after a wall-clock time."""
    import multiprocessing as mp

    ctx = mp.get_context("spawn")
    recv, send = ctx.Pipe(duplex=False)
    child = ctx.Process(target=_spawned, args=(send, fn, args), daemon=True)
    child.start()
    send.close()
    try:
        if recv.poll(seconds * WALL_SECONDS_WITHOUT_CPU_LIMIT + _WORKER_START_SECONDS):
            return pickle.loads(recv.recv_bytes())
        return "limit", None
    except (EOFError, OSError):
        return "limit", None
    finally:
        if child.is_alive():
            child.kill()
        child.join()
        recv.close()


def _spawned(conn, fn: Callable, args: tuple) -> None:  # pragma: no cover - runs in the spawned child
    conn.send_bytes(_outcome(fn, args))
    conn.close()


def _run_in_worker(fn: Callable, args: tuple, seconds: float, warm: tuple[str, ...]) -> tuple[str, Any]:
    global _worker
    request = pickle.dumps((list(sys.path), tuple(warm), pickle.dumps((fn, args)), seconds))
    for _ in range(2):  # a worker that has ended (past its safety net, or killed by its user) is started again once
        if _worker is None or _worker.poll() is not None:
            _stop_worker()
            try:
                _worker = _start_worker()
            except OSError:  # no interpreter to start (an embedded Python): the bound cannot be kept
                return "limit", None
        try:
            _write(_worker.stdin, request)
        except OSError:
            _stop_worker()
            continue
        try:
            reply = _read(_worker.stdout.fileno(), time.monotonic() + _wall(seconds) + _WORKER_START_SECONDS)
        except BaseException:  # interrupted (KeyboardInterrupt, an alarm): its reply would answer the next request
            _stop_worker()
            raise
        if reply is None:  # past the safety net, or the worker died: it is ended, and started again next time
            _stop_worker()
            return "limit", None
        return pickle.loads(reply)
    return "limit", None


def serve() -> None:  # pragma: no cover - runs in the worker process
    """The worker's loop: one request in (stdin), one reply out (stdout), each length-prefixed; ends at EOF."""
    import importlib

    out = os.fdopen(os.dup(1), "wb")
    os.dup2(2, 1)  # what the functions print goes to stderr, not into the replies
    sys.stdout = sys.stderr
    inp = sys.stdin.buffer
    while True:
        message = _read(inp.fileno(), None)
        if message is None:
            return
        path, warm, payload, seconds = pickle.loads(message)
        sys.path[:] = path
        for name in warm:
            try:
                importlib.import_module(name)
            except Exception:  # noqa: BLE001 - the child meets the same error and reports it
                pass

        def run(payload=payload, seconds=seconds) -> bytes:
            try:
                fn, args = pickle.loads(payload)  # imports fn's module (before the limit: not counted)
            except Exception as exc:  # noqa: BLE001
                return pickle.dumps(("err", exc))
            _cpu_limit(seconds)
            return _outcome(fn, args)

        _write(out, pickle.dumps(_fork_and_wait(run, _wall(seconds))))
