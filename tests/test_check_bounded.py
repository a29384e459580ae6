"""The checker's CPU-bounded symbolic analysis from a process with threads alive (Jupyter, Dask, thread pools).

A forked copy of a process keeps every lock that another thread held at the fork, so a child that needs one waits
forever without using CPU (its CPU limit never fires).  These tests hold such a lock in a thread, with a thread pool
busy too, and ask for the analysis: it must come back promptly with the main thread's answer.
"""

from __future__ import annotations

import os
import threading
import time
from concurrent.futures import ThreadPoolExecutor

import pytest

import denavit as dn
from denavit.check import _bounded, _singular, check_claims
from denavit.model import Frame

pytestmark = pytest.mark.skipif(not hasattr(os, "fork"), reason="the CPU-bounded route needs fork (POSIX)")

_HELD = threading.Lock()  # held by a thread of the test process while the analysis runs
_REAL_ANALYSE = _singular._analyse


def _analyse_needing_the_lock(*args):
    with _HELD:  # free in a fresh worker; held for ever in a fork of the test process
        return _REAL_ANALYSE(*args)


def _raise_value_error(text):
    return int(text)


@pytest.fixture
def threads_alive():
    """A thread holding _HELD and a thread pool with a running task, for the duration of the test."""
    release, started = threading.Event(), threading.Event()

    def hold():
        with _HELD:
            started.set()
            release.wait(120)

    holder = threading.Thread(target=hold, daemon=True)
    holder.start()
    assert started.wait(10)
    pool = ThreadPoolExecutor(2)
    busy = pool.submit(release.wait, 120)
    try:
        yield
    finally:
        release.set()
        holder.join(10)
        busy.result(10)
        pool.shutdown()


def test_a_fork_of_this_process_would_find_the_lock_held(threads_alive):
    """The hazard is real here: a forked child sees _HELD locked (and would wait on it without using CPU)."""
    pid = os.fork()
    if pid == 0:  # pragma: no cover - the child
        os._exit(0 if _HELD.locked() else 1)
    _, status = os.waitpid(pid, 0)
    assert os.waitstatus_to_exitcode(status) == 0


def test_the_bounded_analysis_with_threads_alive_gives_the_main_threads_answer(threads_alive, monkeypatch):
    from denavit import symbolic as S

    robot = dn.load_robot("scara")  # 4 joints: analysed in a CPU-bounded child
    assert threading.active_count() >= 3 and len(os.listdir("/proc/self/task")) >= 3
    expected = S.singularity_analysis(robot, rows="vx,vy", frame=Frame.BASE)  # in the main thread, unbounded
    monkeypatch.setattr(_singular, "_analyse", _analyse_needing_the_lock)
    monkeypatch.setattr(_bounded, "WALL_SAFETY_FACTOR", 1)  # a regression (a forked child stuck on _HELD) fails
    monkeypatch.setattr(_bounded, "WALL_SAFETY_SECONDS", 10)  # in ~50 s instead of ~8 minutes
    _singular._analysis.cache_clear()
    try:  # a stuck child shows as None (the safety net), so no clock is needed here
        got = _singular._analysis(robot, "vx,vy", Frame.BASE)
        v = check_claims(robot, [{"quantity": "singularities", "rows": "vx,vy", "value": r"\sin q_2 = 0"}]).verdicts[0]
    finally:
        _singular._analysis.cache_clear()
    assert got is not None, "the analysis was ended by the safety net: the child was stuck"
    assert got.conditions == expected.conditions and got.rows == expected.rows
    assert v.verdict == "correct", v.message


def test_cpu_bounded_from_several_threads_at_once(threads_alive):
    with ThreadPoolExecutor(4) as pool:
        futures = [pool.submit(_bounded.cpu_bounded, abs, (-k,), 5) for k in range(8)]
        assert [f.result(timeout=120) for f in futures] == list(range(8))
    if os.path.isdir("/proc/self/task"):  # the worker, which forks, has a single thread (no BLAS pool)
        assert len(os.listdir(f"/proc/{_bounded._worker.pid}/task")) == 1


def test_cpu_bounded_raises_the_functions_exception(threads_alive):
    """(None past the CPU limit: test_check_limits' spinning analysis.)"""
    with pytest.raises(ValueError, match="invalid literal"):
        _bounded.cpu_bounded(_raise_value_error, ("x",), 5)
    assert _bounded.cpu_bounded(abs, (-2.5,), 1) == 2.5


def test_a_fork_of_the_caller_gets_its_own_worker_even_while_a_thread_holds_the_callers_turn(threads_alive):
    """A process forked while another thread is inside cpu_bounded (holding its lock) must not wait for that
    lock, nor talk to the parent's worker."""
    assert _bounded.cpu_bounded(abs, (-1,), 1) == 1  # the parent's worker is running
    parent_worker = _bounded._worker
    inside, leave = threading.Event(), threading.Event()

    def hold_the_turn():
        with _bounded._lock:
            inside.set()
            leave.wait(60)

    t = threading.Thread(target=hold_the_turn, daemon=True)
    t.start()
    assert inside.wait(10)
    try:
        pid = os.fork()
        if pid == 0:  # pragma: no cover - the child
            ok = False
            try:
                ok = _bounded.cpu_bounded(abs, (-4,), 1) == 4 and _bounded._worker is not parent_worker
                _bounded._stop_worker()
            finally:
                os._exit(0 if ok else 1)
        deadline = time.monotonic() + 60
        while (done := os.waitpid(pid, os.WNOHANG))[0] == 0 and time.monotonic() < deadline:
            time.sleep(0.05)
        if done[0] == 0:
            os.kill(pid, 9)
            os.waitpid(pid, 0)
            pytest.fail("the forked child waited on the parent's lock")
        assert os.waitstatus_to_exitcode(done[1]) == 0
    finally:
        leave.set()
        t.join(10)
    assert _bounded._worker is parent_worker and _bounded.cpu_bounded(abs, (-2,), 1) == 2


def _sleep_then(value, seconds):
    time.sleep(seconds)
    return value


def test_an_interrupted_call_leaves_no_stale_reply_for_the_next(threads_alive):
    """An exception in the waiting caller (Ctrl-C in Jupyter, an alarm) ends the worker: the next call gets its own
    answer, not the interrupted call's."""
    import signal

    class Interrupted(BaseException):
        pass

    def interrupt(signum, frame):
        raise Interrupted

    old = signal.signal(signal.SIGALRM, interrupt)
    try:
        signal.setitimer(signal.ITIMER_REAL, 0.2)
        with pytest.raises(Interrupted):
            _bounded.cpu_bounded(_sleep_then, ("stale", 0.5), 5)
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, old)
    time.sleep(0.6)  # the interrupted call's reply would be waiting by now
    assert _bounded.cpu_bounded(_sleep_then, ("fresh", 0.0), 5) == "fresh"


def test_without_an_interpreter_to_start_the_call_counts_as_out_of_time(monkeypatch):
    """An embedded Python whose sys.executable cannot be started: None (a claim is then judged on its own
    conditions, never 'correct'), not a crash."""
    monkeypatch.setattr(_bounded, "_worker", None)
    monkeypatch.setattr(_bounded.sys, "executable", "/nonexistent/python")
    assert _bounded.cpu_bounded(abs, (-3,), 1) is None
