"""The contract every bad input must meet, and a runner that checks it (issue 14).

A bad input — a robot file, a claims file, a pasted table, a command-line value, an output path — must end with

* exit code 2,
* exactly one line on stderr, naming what and where, with no traceback and no "internal error",
* nothing on stdout,
* nothing the user had written or overwritten (every file in the case's folder keeps its bytes; no new file
  appears unless the case says so),
* within a bound on its CPU time (a hang is reported as such) and, for the cases run in a child process, a
  memory bound.

Time bounds are on CPU seconds, not wall-clock seconds, so that a busy machine (other processes sharing the cores)
does not turn a correct run into a failure (issue 31): ``Outcome.seconds`` is the CPU time the run used
(``time.process_time`` in this process, ``resource.getrusage`` in the child), and the alarm that stops a runaway
case counts CPU time (``ITIMER_PROF`` in this process, ``RLIMIT_CPU`` in the child).  A case that waits without
using CPU is caught by a wall-clock backstop ``WALL_FACTOR`` times longer.

``run_cli`` runs ``denavit.cli.main`` in this process with stdout/stderr captured and a CPU-time alarm;
``run_cli_limited`` runs it in a child Python with an address-space limit, for the memory-bomb families.
``assert_refused`` checks the contract on an outcome.  Hostile test files build cases (hypothesis strategies
and specific triggers) and call these two.
"""

from __future__ import annotations

import contextlib
import hashlib
import io
import json
import math
import os
import resource
import signal
import subprocess
import sys
import time
import warnings
from dataclasses import dataclass, field
from pathlib import Path
from typing import Mapping, Sequence

def corpus(n: int) -> int:
    """How many generated cases a hostile corpus runs: all ``n``, or a fifth in the quick subset
    (``pytest -m "not slow"``, flagged by tests/conftest.py); what each case asserts is the same."""
    return max(5, n // 5) if os.environ.get("DENAVIT_QUICK_TESTS") == "1" else n


#: CPU-time bound (seconds) for one bad input.
TIME_LIMIT = 10.0
#: The wall-clock backstop (for a case that waits rather than computes) is this many times the CPU bound.
WALL_FACTOR = 10
#: Address-space bound for the child-process runner (bytes).
MEMORY_LIMIT = 3 * 1024**3


class Hang(BaseException):
    """Raised by the alarm: the case ran past its time bound (BaseException, so ``except Exception`` lets it by)."""


@dataclass
class Outcome:
    argv: list[str]
    code: int | None
    out: str
    err: str
    seconds: float  # CPU seconds of the run
    hung: bool = False
    before: dict[str, str] = field(default_factory=dict)   # file name -> sha256 before the run
    after: dict[str, str] = field(default_factory=dict)    # ... and after

    def describe(self) -> str:
        return (f"argv={self.argv!r} code={self.code} hung={self.hung} t={self.seconds:.2f}s\n"
                f"stderr={self.err[:600]!r}\nstdout={self.out[:300]!r}")


def _hashes(folder: Path) -> dict[str, str]:
    found = {}
    for p in sorted(folder.rglob("*")):
        if p.is_file() and not p.is_symlink():
            found[str(p.relative_to(folder))] = hashlib.sha256(p.read_bytes()).hexdigest()
        elif p.exists() and not p.is_dir():
            found[str(p.relative_to(folder))] = "special"
    return found


def write_files(folder: Path, files: Mapping[str, str | bytes] | None) -> None:
    for name, content in (files or {}).items():
        path = folder / name
        path.parent.mkdir(parents=True, exist_ok=True)
        if isinstance(content, bytes):
            path.write_bytes(content)
        else:
            path.write_text(content, encoding="utf-8", errors="surrogatepass")


def run_cli(argv: Sequence[str], folder: Path, files: Mapping[str, str | bytes] | None = None,
            time_limit: float = TIME_LIMIT) -> Outcome:
    """Run ``denavit`` with ``argv`` inside ``folder`` (files written there first); never raises."""
    from denavit.cli import main

    write_files(folder, files)
    before = _hashes(folder)
    out, err = io.StringIO(), io.StringIO()
    old_cwd = os.getcwd()
    hung = False
    code: int | None = None

    def alarm(signum, frame):  # noqa: ARG001
        raise Hang()

    previous = signal.signal(signal.SIGALRM, alarm), signal.signal(signal.SIGPROF, alarm)
    t0 = time.process_time()
    try:
        os.chdir(folder)
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err), warnings.catch_warnings():
            warnings.simplefilter("default")  # as a user's interpreter would: warnings shown, on stderr
            signal.setitimer(signal.ITIMER_PROF, time_limit)  # CPU time of this process
            signal.setitimer(signal.ITIMER_REAL, WALL_FACTOR * time_limit)  # the backstop for a wait
            try:
                code = main(list(argv))
            except Hang:
                hung = True
            except SystemExit as exc:  # main() should never let one escape; recorded as its code
                code = exc.code if isinstance(exc.code, int) else 1
            finally:
                signal.setitimer(signal.ITIMER_PROF, 0)
                signal.setitimer(signal.ITIMER_REAL, 0)
    finally:
        signal.signal(signal.SIGALRM, previous[0])
        signal.signal(signal.SIGPROF, previous[1])
        os.chdir(old_cwd)
    seconds = time.process_time() - t0
    return Outcome(list(argv), code, out.getvalue(), err.getvalue(), seconds, hung, before, _hashes(folder))


_CHILD = r"""
import json, os, resource, sys, time, io, contextlib
limit, cpu = int(sys.argv[1]), int(sys.argv[3])
resource.setrlimit(resource.RLIMIT_AS, (limit, limit))
resource.setrlimit(resource.RLIMIT_CPU, (cpu, cpu + 5))  # SIGXCPU past the CPU bound: the child dies
argv = json.loads(sys.argv[2])
from denavit.cli import main
def cpu_now():
    r = resource.getrusage(resource.RUSAGE_SELF)
    return r.ru_utime + r.ru_stime
out, err = io.StringIO(), io.StringIO()
t0 = cpu_now()
try:
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        code = main(argv)
except MemoryError:
    code = "MemoryError"
print(json.dumps({"code": code, "out": out.getvalue(), "err": err.getvalue(), "t": cpu_now() - t0}))
"""


def _children_cpu() -> float:
    """CPU seconds used so far by this process's waited-for children."""
    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime


def run_cli_limited(argv: Sequence[str], folder: Path, files: Mapping[str, str | bytes] | None = None,
                    time_limit: float = 3 * TIME_LIMIT, memory_limit: int = MEMORY_LIMIT) -> Outcome:
    """Run ``denavit`` in a child Python with an address-space limit and a CPU-time limit (``time_limit`` CPU
    seconds, the child's start included); a MemoryError or a kill is a failure, a CPU-limit kill a hang."""
    write_files(folder, files)
    before = _hashes(folder)
    env = dict(os.environ, OPENBLAS_NUM_THREADS="1", OMP_NUM_THREADS="1")
    env.pop("DENAVIT_DEBUG", None)
    c0 = _children_cpu()
    try:
        proc = subprocess.run([sys.executable, "-c", _CHILD, str(memory_limit), json.dumps(list(argv)),
                               str(max(1, math.ceil(time_limit)))], cwd=folder, capture_output=True, text=True,
                              timeout=WALL_FACTOR * time_limit, env=env, stdin=subprocess.DEVNULL)
    except subprocess.TimeoutExpired:
        return Outcome(list(argv), None, "", "", time_limit, True, before, _hashes(folder))
    seconds = _children_cpu() - c0  # the whole child; its own figure (the run alone) replaces it below
    if proc.returncode == -signal.SIGXCPU:
        return Outcome(list(argv), None, "", proc.stderr[-800:], time_limit, True, before, _hashes(folder))
    try:
        got = json.loads(proc.stdout.strip().splitlines()[-1])
    except (ValueError, IndexError):
        return Outcome(list(argv), None, proc.stdout, f"child died (rc {proc.returncode}): {proc.stderr[-800:]}",
                       seconds, False, before, _hashes(folder))
    code = got["code"] if isinstance(got["code"], int) else None
    err = got["err"] if code is not None else f"MemoryError\n{got['err']}"
    return Outcome(list(argv), code, got["out"], err, got["t"], False, before, _hashes(folder))


def assert_refused(o: Outcome, *, mentions: Sequence[str] = (), new_files: Sequence[str] = ()) -> None:
    """The contract for a bad input (see the module docstring).

    ``mentions``: substrings the error line must contain (case-insensitive), e.g. the file name, the row, the
    field. ``new_files``: names that may appear (none by default).
    """
    assert not o.hung, f"hung past the time bound\n{o.describe()}"
    assert o.code == 2, f"expected exit code 2\n{o.describe()}"
    lines = o.err.strip().splitlines()
    assert len(lines) == 1, f"expected exactly one line on stderr\n{o.describe()}"
    line = lines[0]
    assert "Traceback" not in o.err and "internal error" not in line, o.describe()
    assert "error" in line.lower(), o.describe()
    assert o.out == "", f"nothing may be printed on stdout\n{o.describe()}"
    for text in mentions:
        assert text.lower() in line.lower(), f"error line should mention {text!r}\n{o.describe()}"
    changed = {k for k in o.before if o.after.get(k) != o.before[k]}
    assert not changed, f"files changed or removed: {sorted(changed)}\n{o.describe()}"
    appeared = set(o.after) - set(o.before) - set(new_files)
    assert not appeared, f"files appeared: {sorted(appeared)}\n{o.describe()}"


def assert_accepted_quietly(o: Outcome) -> None:
    """A good input (the control case of a hostile family): exit 0, no hang, no traceback."""
    assert not o.hung and o.code == 0, o.describe()
    assert "Traceback" not in o.err and "internal error" not in o.err, o.describe()
