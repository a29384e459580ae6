"""Long work off the request path: one child process per job, with progress messages and cancel.

A job (:data:`denavit.web._work.KINDS`) runs in a process of a ``forkserver`` context whose server has imported
sympy and the report once, so a job starts in milliseconds and a symbolic derivation never holds the web
server's GIL: the slider answers stay quick while a 7-joint arm's dynamics is derived.  Cancel terminates the
process (SIGTERM); every job also has an OS CPU limit.  At most :data:`MAX_RUNNING` jobs run at once and
:data:`MAX_KEPT` finished ones are remembered (the oldest forgotten first).
"""

from __future__ import annotations

import multiprocessing
import secrets
import threading
import time
from collections import OrderedDict
from typing import Any

from ._handlers import RequestError, one_line

__all__ = ["JOB_CPU_SECONDS", "MAX_KEPT", "MAX_RUNNING", "Jobs"]

MAX_RUNNING = 4
MAX_KEPT = 16
#: CPU seconds a job may use (a 7-joint arm's full report takes minutes on a slow machine).
JOB_CPU_SECONDS = 900.0
#: Progress lines kept per job.
MAX_PROGRESS = 50


class _Job:
    def __init__(self, kind: str) -> None:
        self.id = secrets.token_hex(8)
        self.kind = kind
        self.state = "running"          # running | done | failed | cancelled
        self.progress: list[str] = []
        self.result: Any = None
        self.error = ""
        self.started = time.monotonic()
        self.finished: float | None = None
        self.process: Any = None
        self.cpu_seconds: float | None = None  # the job process's own CPU time, when it finished
        self.exitcode: int | None = None  # the process's exit code, read once by the job's reader thread
        self.slot: str | None = None  # a new job in the same slot supersedes this one (one page's one panel)

    def to_json(self, with_result: bool = True) -> dict[str, Any]:
        end = self.finished if self.finished is not None else time.monotonic()
        out = {"id": self.id, "kind": self.kind, "state": self.state, "progress": list(self.progress),
               "error": self.error, "seconds": round(end - self.started, 3), "cpu_seconds": self.cpu_seconds}
        if with_result and self.state == "done":
            out["result"] = self.result
        return out


class Jobs:
    """The jobs of one server.  Thread-safe; the page polls :meth:`status`."""

    def __init__(self, max_running: int = MAX_RUNNING, cpu_seconds: float = JOB_CPU_SECONDS) -> None:
        self.max_running = max_running
        self.cpu_seconds = cpu_seconds
        self._jobs: OrderedDict[str, _Job] = OrderedDict()
        self._lock = threading.Lock()
        self._ctx: Any = None

    def _context(self) -> Any:
        if self._ctx is None:
            methods = multiprocessing.get_all_start_methods()
            self._ctx = multiprocessing.get_context("forkserver" if "forkserver" in methods else "spawn")
            if "forkserver" in methods:
                self._ctx.set_forkserver_preload(["denavit.web._work", "denavit.report", "denavit.grade"])
        return self._ctx

    def warm_up(self) -> None:
        """Start the fork server (it imports sympy and the report once) before the first job needs it."""
        ctx = self._context()
        if ctx.get_start_method() == "forkserver":
            from multiprocessing import forkserver

            forkserver.ensure_running()

    def start(self, kind: str, payload: dict[str, Any], slot: str | None = None) -> dict[str, Any]:
        """Start a job; 429 when :attr:`max_running` already run.  A running job in the same ``slot`` (a page's
        panel: its formula, its report, ...) is cancelled first, in the same step: superseded work never counts
        against the limit, however slowly the page's own cancel arrives."""
        from ._work import KINDS, run

        if kind not in KINDS:
            raise RequestError(f"unknown job {one_line(kind, 40)!r}; jobs: {', '.join(KINDS)}", 404)
        with self._lock:
            if slot is not None:
                for old in self._jobs.values():
                    if old.slot == slot and old.state == "running":
                        self._terminate(old)
            running = sum(j.state == "running" for j in self._jobs.values())
            if running >= self.max_running:
                raise RequestError(f"{running} jobs are running (at most {self.max_running}): wait or cancel one", 429)
            job = _Job(kind)
            job.slot = slot
            ctx = self._context()
            parent, child = ctx.Pipe(duplex=False)
            job.process = ctx.Process(target=run, args=(kind, payload, child, self.cpu_seconds), daemon=True)
            job.process.start()
            child.close()
            self._jobs[job.id] = job
            self._forget_old()
        threading.Thread(target=self._follow, args=(job, parent), daemon=True).start()
        return job.to_json()

    def _follow(self, job: _Job, conn: Any) -> None:
        """Read the job's messages until it ends (the reader thread of one job)."""
        try:
            while True:
                try:
                    kind, data = conn.recv()
                except (EOFError, OSError):
                    break
                if kind == "progress":
                    job.progress = (job.progress + [data])[-MAX_PROGRESS:]
                elif kind == "cpu":
                    job.cpu_seconds = round(float(data), 3)
                elif kind == "done":
                    job.result, job.state = data, "done"
                elif kind == "error":
                    job.error, job.state = data, "failed"
        finally:
            conn.close()
            # Only this thread joins the process: a forkserver child's exit code is one message on its sentinel,
            # so a second reader would find it gone (and record 255).
            job.process.join(timeout=30)
            job.exitcode = code = job.process.exitcode
            if job.state == "running":
                job.state = "failed"
                job.error = (f"the job stopped: it used its {self.cpu_seconds:g} s of CPU" if code == -24  # SIGXCPU
                             else f"the job's process ended without an answer (exit code {code})")
            job.finished = time.monotonic()

    def _forget_old(self) -> None:
        done = [k for k, j in self._jobs.items() if j.state != "running"]
        for k in done[: max(0, len(self._jobs) - MAX_KEPT)]:
            del self._jobs[k]

    def _get(self, job_id: Any) -> _Job:
        job = self._jobs.get(job_id) if isinstance(job_id, str) else None
        if job is None:
            raise RequestError(f"no job {one_line(job_id, 40)!r} (finished jobs are forgotten after {MAX_KEPT} more)", 404)
        return job

    def status(self, job_id: Any) -> dict[str, Any]:
        return self._get(job_id).to_json()

    def cancel(self, job_id: Any) -> dict[str, Any]:
        """Terminate a running job (its state becomes ``cancelled``); a finished job is left as it is."""
        job = self._get(job_id)
        with self._lock:
            if job.state == "running":
                self._terminate(job)
        return job.to_json(with_result=False)

    @staticmethod
    def _terminate(job: _Job) -> None:
        job.state = "cancelled"
        job.error = "cancelled"
        job.process.terminate()

    def shutdown(self) -> None:
        """Terminate every running job (the server is stopping)."""
        for job in list(self._jobs.values()):
            if job.state == "running" and job.process is not None:
                job.state = "cancelled"
                job.process.terminate()
