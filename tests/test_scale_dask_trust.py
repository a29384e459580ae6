"""The Dask cluster `--scheduler dask` starts is private and dies with its driver; addresses are checked.

Played as another local user would: connect to the cluster's address without its credentials (refused); as a
careless one: SIGTERM or SIGKILL the main process (no worker process survives it), Ctrl-C in a terminal (the
whole process group gets SIGINT: one line on stderr), an ``inproc://``/``ucx://`` address (one line, exit 2).
Waits are polled with generous caps (a busy machine); nothing asserts a tight wall-clock time.
"""

from __future__ import annotations

import os
import re
import signal
import subprocess
import sys
import threading
import time
import urllib.error
import urllib.request

import pytest

from _hostile import assert_refused, run_cli

#: Cap of every wait on a subprocess or a cluster [s].
CAP = 60.0
#: Cap of the wait for a Dask run to be under way (interpreter start, cluster start, first task) [s].
START_CAP = 180.0
_PROGRESS = re.compile(r"^\s*\d+(\.\d+)?%")


# ---- addresses ------------------------------------------------------------------------------------------------

@pytest.mark.parametrize("address, mention", [
    ("inproc://127.0.0.1/123/1", "inproc://"),
    ("ucx://127.0.0.1:8786", "ucx://"),
    ("ws://127.0.0.1:8786", "ws://"),
    ("127.0.0.1:8786", "tcp://127.0.0.1:8786"),
    ("tcp://127.0.0.1:0", "tcp://"),
])
def test_only_tcp_and_tls_addresses_are_accepted(tmp_path, address, mention):
    o = run_cli(["workspace", "planar2r", "--samples", "200", "--scheduler", address], tmp_path)
    assert_refused(o, mentions=["scheduler", mention])


def test_tls_address_without_credentials_is_one_line(tmp_path):
    pytest.importorskip("distributed")
    o = run_cli(["workspace", "planar2r", "--samples", "200", "--scheduler", "tls://127.0.0.1:8786"], tmp_path)
    assert_refused(o, mentions=["tls://127.0.0.1:8786", "credentials"])


def test_dashboard_only_with_a_local_cluster(tmp_path):
    o = run_cli(["workspace", "planar2r", "--samples", "200", "--scheduler", "threads", "--dashboard"], tmp_path)
    assert_refused(o, mentions=["--dashboard", "--scheduler dask"])


def test_dashboard_without_bokeh_is_one_line(tmp_path):
    pytest.importorskip("distributed")
    import importlib.util

    if importlib.util.find_spec("bokeh") is not None:
        pytest.skip("bokeh is installed: the dashboard would start")
    o = run_cli(["workspace", "planar2r", "--samples", "200", "--scheduler", "dask", "--dashboard"], tmp_path)
    assert o.code == 1 and o.out == "" and "Traceback" not in o.err, o.describe()
    assert len(o.err.strip().splitlines()) == 1 and "bokeh" in o.err, o.describe()


# ---- the private cluster --------------------------------------------------------------------------------------

_TRY_CLIENT = """
import os, sys
from distributed import Client, Security
security = Security.temporary() if sys.argv[2] == "other-ca" else None
try:
    Client(sys.argv[1], security=security, timeout=float(sys.argv[3]), set_as_default=False)
except Exception as exc:  # any refusal will do; its type is reported
    print("REFUSED", type(exc).__name__, flush=True)
    os._exit(0)  # no interpreter teardown: a half-made Client's __del__ can hang (distributed's LoopRunner)
print("CONNECTED", flush=True)
os._exit(0)
"""


def _refused(address: str, credentials: str) -> str:
    """The exception type name of a Client that tries ``address`` with no credentials (``"none"``) or with those
    of another temporary CA (``"other-ca"``), in a child process of its own (a refused Client left in this process
    once deadlocked the next one's construction); fails the test if it connects or takes longer than CAP."""
    res = subprocess.run([sys.executable, "-c", _TRY_CLIENT, address, credentials, str(CAP / 2)],
                         capture_output=True, text=True, timeout=3 * CAP)
    if "CONNECTED" in res.stdout:
        pytest.fail(f"a client without the cluster's credentials connected to {address}")
    assert res.stdout.startswith("REFUSED"), res.stdout + res.stderr[-2000:]
    return res.stdout.split()[1]


def _listening_ports(pid: int) -> set[int]:
    import psutil

    return {c.laddr.port for c in psutil.Process(pid).net_connections("inet") if c.status == psutil.CONN_LISTEN}


def _sigint_disposition():
    return int(signal.getsignal(signal.SIGINT))


@pytest.mark.slow
def test_local_cluster_refuses_clients_without_its_credentials_and_serves_no_dashboard():
    distributed = pytest.importorskip("distributed")
    from denavit.scale import local_cluster

    with local_cluster(1) as client:
        cluster = client.cluster
        address = cluster.scheduler_address
        assert address.startswith("tls://127.0.0.1:"), address
        _refused(address.replace("tls://", "tcp://"), "none")  # plain TCP to the TLS port
        _refused(address, "none")  # TLS without a certificate
        _refused(address, "other-ca")  # a certificate of another (temporary) CA
        with distributed.Client(address, security=cluster.security, timeout=CAP, set_as_default=False) as own:
            assert len(own.scheduler_info()["workers"]) == 1  # the credentials are what the refusals lacked
        # no dashboard: nothing listens on Dask's 8787, and the scheduler's HTTP server serves no page
        port = cluster.scheduler.http_server.port
        assert port != 8787 and 8787 not in _listening_ports(os.getpid())
        for path in ("/status", "/json/identity.json", "/info/main/workers.html", "/health", "/metrics"):
            with pytest.raises(urllib.error.HTTPError) as info:
                urllib.request.urlopen(f"http://127.0.0.1:{port}{path}", timeout=CAP)
            assert info.value.code == 404, path
        # the workers leave Ctrl-C to the driver
        assert list(client.run(_sigint_disposition).values()) == [int(signal.SIG_IGN)]
    assert cluster.status.name == "closed"


class _Dies:
    """An FK callable that ends any process but the test's running it (a worker killed mid-task)."""

    def __init__(self):
        self.home = os.getpid()

    def __call__(self, q):
        if os.getpid() != self.home:
            os._exit(3)
        import denavit
        from denavit.scale import PositionFK

        return PositionFK(denavit.load_robot("planar2r"))(q)


@pytest.mark.slow
def test_a_dying_worker_is_one_error_and_no_log(capfd):
    pytest.importorskip("distributed")
    import dask

    import denavit
    from denavit.errors import DenavitError
    from denavit.scale import occupancy

    with dask.config.set({"distributed.scheduler.allowed-failures": 0}), \
            pytest.raises(DenavitError, match="worker process died") as info:
        occupancy(denavit.load_robot("planar2r"), 1000, seed=0, scheduler="dask", workers=1, fk=_Dies())
    assert "\n" not in str(info.value)
    assert capfd.readouterr().err == ""  # none of Dask's log lines


# ---- the CLI's cluster and signals ----------------------------------------------------------------------------

#: ``python -m denavit`` as a terminal's shell starts it: Ctrl-C at Python's default.  A child inherits ignored
#: signals, and pytest itself may run with SIGINT and SIGQUIT ignored: POSIX shells start an asynchronous command
#: (``python -m pytest ... &``) with both ignored when job control is off, as in scripts and CI runners (seen: /proc
#: SigIgn 0x...1001006 in pytest, its xdist workers and the CLI they launched; ``bash -c 'grep SigIgn
#: /proc/self/status & wait'`` shows 0x6).  A program started with SIGINT ignored rightly ignores Ctrl-C, so
#: without this line the test waited 60 s for an exit that could not come.
_AS_FROM_A_SHELL = ("import runpy, signal, sys; signal.signal(signal.SIGINT, signal.default_int_handler); "
                    "sys.argv[0] = 'denavit'; runpy.run_module('denavit', run_name='__main__', alter_sys=True)")


class _Run:
    """``denavit workspace`` on a LocalCluster of two workers, in its own session (as from a terminal)."""

    def __init__(self, folder):
        self.proc = subprocess.Popen(
            [sys.executable, "-c", _AS_FROM_A_SHELL, "workspace", "puma560", "--samples", "1e9", "--scheduler", "dask",
             "--workers", "2", "--progress", "--seed", "1"],
            cwd=folder, stdout=subprocess.PIPE, stderr=subprocess.PIPE, start_new_session=True)
        self.err = bytearray()
        self.reader = threading.Thread(target=self._read, daemon=True)
        self.reader.start()

    def _read(self):
        for chunk in iter(lambda: self.proc.stderr.read1(4096), b""):
            self.err += chunk

    def under_way(self):
        """Wait for the first progress line (a task is done: cluster up, run going); the worker processes."""
        import psutil

        deadline = time.monotonic() + START_CAP
        while b"%" not in self.err and self.proc.poll() is None and time.monotonic() < deadline:
            time.sleep(0.2)
        assert b"%" in self.err, f"no progress within {START_CAP} s: {bytes(self.err)[-800:]!r}"
        family = psutil.Process(self.proc.pid).children(recursive=True)
        workers = [p for p in family if "spawn_main" in " ".join(p.cmdline())]
        assert len(workers) == 2, [p.cmdline() for p in family]
        return family

    def finish(self):
        """Exit code and the stderr lines that are not progress redraws."""
        try:
            self.proc.wait(timeout=CAP)
        except subprocess.TimeoutExpired:
            os.killpg(self.proc.pid, signal.SIGKILL)
            pytest.fail(f"the main process did not exit within {CAP} s")
        self.reader.join(CAP)
        text = bytes(self.err).decode(errors="replace")
        lines = [s.strip() for s in re.split(r"[\r\n]", text)]
        return self.proc.returncode, [s for s in lines if s and not _PROGRESS.match(s)]


def _none_survive(family) -> list:
    """Poll (up to CAP) until none of ``family`` runs; returns the survivors (killed, for the next test)."""
    import psutil

    deadline = time.monotonic() + CAP
    while True:
        alive = [p for p in family if p.is_running() and p.status() != psutil.STATUS_ZOMBIE]
        if not alive or time.monotonic() > deadline:
            break
        time.sleep(0.5)
    for p in alive:
        p.kill()
    return [(p.pid, p.cmdline()) for p in alive]


@pytest.mark.slow
def test_sigterm_to_the_main_process_closes_the_cluster_and_leaves_no_worker(tmp_path):
    pytest.importorskip("distributed")
    run = _Run(tmp_path)
    family = run.under_way()
    run.proc.send_signal(signal.SIGTERM)  # the main process only, as `kill PID` does
    code, lines = run.finish()
    assert code == 128 + signal.SIGTERM and lines == [], (code, lines)
    assert _none_survive(family) == []


@pytest.mark.slow
def test_sigkill_to_the_main_process_leaves_no_worker(tmp_path):
    pytest.importorskip("distributed")
    run = _Run(tmp_path)
    family = run.under_way()
    run.proc.kill()
    run.finish()
    assert _none_survive(family) == []


def _process_state(pid: int) -> str:
    """The kernel's view of a process (Linux): signal masks, and each thread's name, state and wait channel."""
    proc = f"/proc/{pid}"
    try:
        status = dict(line.split(":", 1) for line in open(f"{proc}/status").read().splitlines() if ":" in line)
        parts = [f"{k}={status[k].strip()}" for k in ("State", "SigBlk", "SigIgn", "SigCgt") if k in status]
        for tid in sorted(os.listdir(f"{proc}/task")):
            name = open(f"{proc}/task/{tid}/comm").read().strip()
            wchan = open(f"{proc}/task/{tid}/wchan").read().strip()
            state = open(f"{proc}/task/{tid}/stat").read().rsplit(")", 1)[1].split()[0]
            parts.append(f"{name}:{state}:{wchan}")
        return " ".join(parts)
    except OSError as exc:
        return f"(no /proc view: {exc})"


@pytest.mark.slow
def test_ctrl_c_in_a_terminal_is_one_line(tmp_path):
    """A terminal's Ctrl-C sends SIGINT to the whole foreground process group, workers included.

    If the process does not exit, the failure carries its /proc view (signal masks: SigIgn with bit 2 set is an
    inherited ignored SIGINT; each thread's state and wait channel)."""
    pytest.importorskip("distributed")
    run = _Run(tmp_path)
    family = run.under_way()
    os.killpg(run.proc.pid, signal.SIGINT)
    try:
        run.proc.wait(timeout=CAP)
    except subprocess.TimeoutExpired:
        seen = _process_state(run.proc.pid)
        os.killpg(run.proc.pid, signal.SIGKILL)
        _none_survive(family)
        pytest.fail(f"the main process did not exit within {CAP} s after Ctrl-C; {seen}")
    code, lines = run.finish()
    assert code == 130 and lines == ["denavit: interrupted"], (code, lines)
    assert _none_survive(family) == []
    assert os.listdir(tmp_path) == []


@pytest.mark.parametrize("route", ["prctl", "poll"])
def test_guard_ends_a_process_whose_parent_is_killed(route):
    """The worker preload alone (without Dask's own pipe): a grandchild tied to its parent by ``die_with``
    outlives neither a SIGKILL of that parent (Linux: the kernel's parent-death signal) nor, with prctl
    unavailable, the polling thread's check."""
    import psutil

    if route == "prctl" and not sys.platform.startswith("linux"):
        pytest.skip("PR_SET_PDEATHSIG is Linux's")
    only = "sys.platform = 'other'" if route == "poll" else "guard.POLL = 1e6"  # one route at a time
    grandchild = ("import os, sys, time\n"
                  "import denavit.scale._guard as guard\n"
                  f"{only}\n"
                  "guard.die_with(os.getppid())\n"
                  "print('tied', flush=True)\n"
                  "time.sleep(600)\n")
    parent = ("import subprocess, sys, time\n"
              f"p = subprocess.Popen([sys.executable, '-c', {grandchild!r}], stdout=subprocess.PIPE)\n"
              "assert p.stdout.readline() == b'tied\\n'\n"
              "print(p.pid, flush=True)\n"
              "time.sleep(600)\n")
    proc = subprocess.Popen([sys.executable, "-c", parent], stdout=subprocess.PIPE, text=True)
    try:
        pid = int(proc.stdout.readline())
        child = psutil.Process(pid)
        assert child.is_running()
    finally:
        proc.kill()
        proc.wait(CAP)
    assert _none_survive([child]) == []


def test_sigterm_reaching_the_caller_outside_the_cluster_block_is_still_143_and_silent(monkeypatch, capsys):
    """SIGTERM can land while the main thread is in the caller's frame (occupancy merging a result) rather than in
    the generator holding the cluster: the Terminated then reaches the command line, which exits 143 and prints
    nothing (it printed 'denavit: interrupted' and exited 130, as for Ctrl-C, in about a third of the runs)."""
    import denavit.scale
    from denavit.cli import main
    from denavit.errors import Terminated

    def terminated(*args, **kwargs):
        raise Terminated

    monkeypatch.setattr(denavit.scale, "occupancy", terminated)
    assert main(["workspace", "planar2r", "--samples", "1000"]) == 128 + signal.SIGTERM
    out, err = capsys.readouterr()
    assert (out, err) == ("", "")


class _Part:
    """A stand-in for a Client or a cluster: ``close`` records its call, then blocks, fails or returns."""

    def __init__(self, log, name, behaviour="return"):
        self.log, self.name, self.behaviour = log, name, behaviour
        self.release = threading.Event()

    def close(self):
        self.log.append(self.name)
        if self.behaviour == "block":
            self.release.wait()
        elif self.behaviour == "fail":
            raise RuntimeError("close failed")


def test_closing_the_cluster_is_bounded_and_ordered():
    """close_within closes the Client, then the cluster; a close that fails does not stop the next one or
    replace the outcome; one that never returns is left behind after the bound (the run ends anyway)."""
    from denavit.scale._cluster import close_within

    log: list = []
    assert close_within(10.0, _Part(log, "client", "fail"), _Part(log, "cluster")) is True
    assert log == ["client", "cluster"]

    log.clear()
    stuck = _Part(log, "client", "block")
    start = time.process_time()
    assert close_within(0.2, stuck, _Part(log, "cluster")) is False
    assert log == ["client"]  # the cluster's close waits behind the stuck one, in the helper thread
    assert time.process_time() - start < 1.0  # a wait, not a spin
    stuck.release.set()


def test_local_cluster_ends_even_when_the_close_hangs(monkeypatch):
    """The run's own exception (here Ctrl-C) leaves local_cluster within CLOSE_TIMEOUT though the close hangs."""
    import denavit.scale._cluster as cluster_module

    log: list = []
    client, cluster = _Part(log, "client", "block"), _Part(log, "cluster")
    monkeypatch.setattr(cluster_module, "start_local_cluster", lambda workers, dashboard: (client, cluster))
    monkeypatch.setattr(cluster_module, "CLOSE_TIMEOUT", 0.2)
    outcome: list = []

    def run():
        try:
            with cluster_module.local_cluster(2):
                raise KeyboardInterrupt
        except KeyboardInterrupt as exc:
            outcome.append(exc)

    runner = threading.Thread(target=run, daemon=True)  # not the main thread: SIGTERM handling stays off
    runner.start()
    runner.join(30.0)  # 150x the bound: only a close that is not bounded gets here
    assert not runner.is_alive(), "local_cluster waited for a close that never returns"
    assert len(outcome) == 1 and log == ["client"]
    client.release.set()
