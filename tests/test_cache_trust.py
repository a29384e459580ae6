"""The kernel cache as another user and a careless disk would leave it (issue 29, "Cache").

Files in the cache are imported as code, so the tests plant a module under the predictable name — a well-formed
one: the key and SHA-256 line and a checked-hash ``.pyc`` made here with ``py_compile``, so that only the trust
check stands between it and ``exec`` — whose only effect is to write a marker file.  The folder is made
someone else's (the owner check injected through ``current_uid``; a real ``chown`` when the tests run as root),
group- or world-writable, or inside a folder others can change; the planted code must never run.  Then every
kind of damage (truncated, empty, garbage, wrong-hash files, a folder or a symlink in a file's place, numba's
index and data files) must be deleted and rebuilt with one warning, the results right (checked against the
planar 2R formula), no temporary file left, and no file outside the cache touched.
"""

from __future__ import annotations

import hashlib
import json
import os
import py_compile
import stat
import tempfile
import time
import warnings
from pathlib import Path

import numpy as np
import pytest

import denavit
from denavit.cli import main
from denavit.codegen import _cache, _cache_folder, numba_available, robot_key
from denavit.errors import DenavitWarning

needs_numba = pytest.mark.skipif(not numba_available(), reason="numba (the 'fast' extra) is not installed")
Q = np.array([0.3, 0.4])
PLANT = "import pathlib\npathlib.Path({marker!r}).write_text('planted code ran')\n"


def planar_xy(q):
    """End point of the unit-length planar 2R arm (planar2r: a1 = a2 = 1), by elementary trigonometry."""
    return np.array([np.cos(q[0]) + np.cos(q[0] + q[1]), np.sin(q[0]) + np.sin(q[0] + q[1])])


@pytest.fixture
def env(tmp_path, monkeypatch):
    """A configured cache folder, a private temporary folder for the fallbacks, nothing loaded yet."""
    kernels, tmp = tmp_path / "kernels", tmp_path / "tmp"
    tmp.mkdir()
    monkeypatch.setenv("DENAVIT_CACHE_DIR", str(kernels))
    monkeypatch.setattr(tempfile, "tempdir", str(tmp))
    monkeypatch.setattr(_cache, "_LOADED", {})
    monkeypatch.setattr(_cache_folder, "_PRIVATE", [])
    return tmp_path


def compile_planar(backend="numpy"):
    """Kernels of planar2r (fk only: the smallest build), after forgetting what this process loaded."""
    _cache._LOADED.clear()
    fast = denavit.compile(denavit.load_robot("planar2r"), backend=backend, kernels=["fk"])
    np.testing.assert_allclose(fast.fk(Q)[:2, 3], planar_xy(Q), atol=1e-14)
    # a keyword call: numba's fk_1 (the first call went through fk's built-in, which hands this one back)
    np.testing.assert_allclose(fast.fk(Q, frames=False)[:2, 3], planar_xy(Q), atol=1e-14)
    return fast


def modname(backend="numpy"):
    return f"_denavit_kernels_{backend}_{robot_key(denavit.load_robot('planar2r'), backend, True, ('fk',))}"


def plant(folder: Path, marker: Path, backend="numpy") -> None:
    """A forged module under the predictable name: a valid key and hash line and a checked-hash pyc (made here,
    independently of denavit's writer), whose code writes ``marker``."""
    name = modname(backend)
    body = PLANT.format(marker=str(marker)).encode()
    key = name.rsplit("_", 1)[1]
    source = f"# denavit kernels {key} sha256 {hashlib.sha256(body).hexdigest()}\n".encode() + body
    folder.mkdir(parents=True, exist_ok=True)
    (folder / f"{name}.py").write_bytes(source)
    py_compile.compile(str(folder / f"{name}.py"), cfile=str(folder / f"{name}.pyc"), doraise=True,
                       invalidation_mode=py_compile.PycInvalidationMode.CHECKED_HASH)


def outside(root: Path, cache: Path) -> dict:
    """Every file under ``root`` but outside ``cache``: path → (content digest, mtime)."""
    seen = {}
    for p in sorted(root.rglob("*")):
        if cache in p.parents or p == cache or p.is_symlink() or not p.is_file():
            continue
        seen[str(p)] = (hashlib.sha256(p.read_bytes()).hexdigest(), p.stat().st_mtime_ns)
    return seen


def no_denavit_warning(fn):
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        result = fn()
    assert not [w for w in caught if issubclass(w.category, DenavitWarning)], [str(w.message) for w in caught]
    return result


# --- another user's folder: planted code never runs ------------------------------------------------------------
def test_a_forged_module_runs_only_from_the_users_own_folder(env, monkeypatch):
    """The control first: in the user's own folder the forgery is indistinguishable from a real entry (only the
    user could have written it) and runs; the same folder seen as another user's is not used at all."""
    marker = env / "marker"
    plant(env / "kernels", marker)
    monkeypatch.setattr(_cache_folder, "current_uid", lambda: os.geteuid() + 4242)
    with pytest.warns(DenavitWarning, match="not used: owned by another user"):
        fast = compile_planar()
    assert not marker.exists()
    used = fast.path.parent
    assert env / "kernels" not in (used, *used.parents) and stat.S_IMODE(used.stat().st_mode) == 0o700
    monkeypatch.undo()
    monkeypatch.setenv("DENAVIT_CACHE_DIR", str(env / "kernels"))
    monkeypatch.setattr(_cache, "_LOADED", {})
    with pytest.raises(AttributeError):  # the planted module has no kernels (fk_1): the point is that it ran
        compile_planar()
    assert marker.read_text() == "planted code ran"


@pytest.mark.skipif(os.geteuid() != 0, reason="making a folder another user's needs root")
def test_a_folder_really_owned_by_another_user_is_not_used(env):
    marker = env / "marker"
    plant(env / "kernels", marker)
    for p in [env / "kernels", *(env / "kernels").iterdir()]:
        os.chown(p, 65534, 65534)
    with pytest.warns(DenavitWarning, match="uid 65534"):
        fast = compile_planar()
    assert not marker.exists() and fast.path.parent != env / "kernels"


@pytest.mark.parametrize("mode", [0o770, 0o707, 0o777])
def test_a_group_or_world_writable_folder_is_not_used(env, mode):
    marker = env / "marker"
    plant(env / "kernels", marker)
    (env / "kernels").chmod(mode)
    with pytest.warns(DenavitWarning, match=f"open to other users \\(mode {mode:o}\\)"):
        fast = compile_planar()
    assert not marker.exists() and fast.path.parent != env / "kernels"


def test_a_folder_inside_one_others_can_change_is_not_used_unless_sticky(env, monkeypatch):
    shared = env / "shared"
    shared.mkdir()
    shared.chmod(0o777)  # another user could move "kernels" away and put theirs in its place
    marker = env / "marker"
    plant(shared / "kernels", marker)
    (shared / "kernels").chmod(0o700)
    monkeypatch.setenv("DENAVIT_CACHE_DIR", str(shared / "kernels"))
    with pytest.warns(DenavitWarning, match="which other users can change"):
        assert compile_planar().path.parent != shared / "kernels"
    assert not marker.exists()
    shared.chmod(0o1777)  # sticky, as /tmp: only the owner may rename or delete what is in it
    (shared / "kernels" / f"{modname()}.py").unlink()  # (the forgery would run now: it is the user's own)
    assert no_denavit_warning(compile_planar).path.parent == shared / "kernels"


def test_a_configured_symlink_is_judged_by_the_folder_it_points_to(env, monkeypatch):
    theirs = env / "theirs"
    marker = env / "marker"
    plant(theirs, marker)
    theirs.chmod(0o777)
    (env / "link").symlink_to(theirs)
    monkeypatch.setenv("DENAVIT_CACHE_DIR", str(env / "link"))
    with pytest.warns(DenavitWarning, match="open to other users"):
        fast = compile_planar()
    assert not marker.exists() and theirs not in fast.path.parents


def test_new_folders_are_private_and_the_per_user_fallback_is_reused(env, monkeypatch):
    monkeypatch.setenv("DENAVIT_CACHE_DIR", str(env / "a" / "b" / "kernels"))
    fast = compile_planar()
    for p in (env / "a", env / "a" / "b", env / "a" / "b" / "kernels"):
        assert stat.S_IMODE(p.stat().st_mode) == 0o700, p
    assert fast.path.parent == env / "a" / "b" / "kernels"
    (env / "blocker").write_text("not a folder")
    monkeypatch.setenv("DENAVIT_CACHE_DIR", str(env / "blocker" / "kernels"))
    first, second = no_denavit_warning(compile_planar), no_denavit_warning(compile_planar)  # unwritable: no warning
    assert first.path.parent == second.path.parent == env / "tmp" / f"denavit-kernels-{os.geteuid()}"
    assert stat.S_IMODE(first.path.parent.stat().st_mode) == 0o700
    assert (env / "blocker").read_text() == "not a folder"


@pytest.mark.parametrize("hijack", ["symlink", "world-writable", "another user's"])
def test_a_hijacked_per_user_fallback_gives_a_fresh_private_folder(env, monkeypatch, hijack):
    (env / "blocker").write_text("")
    monkeypatch.setenv("DENAVIT_CACHE_DIR", str(env / "blocker" / "kernels"))
    predictable, theirs, marker = env / "tmp" / f"denavit-kernels-{os.geteuid()}", env / "theirs", env / "marker"
    plant(theirs, marker)
    if hijack == "symlink":
        predictable.symlink_to(theirs)
    else:
        theirs.rename(predictable)
        predictable.chmod(0o777 if hijack == "world-writable" else 0o700)
        if hijack == "another user's":
            uid = os.geteuid()  # the folder was made by the test's user: seen from another user's session
            monkeypatch.setattr(_cache_folder, "current_uid", lambda: uid + 4242)
            predictable.rename(env / "tmp" / f"denavit-kernels-{uid + 4242}")
    stale = env / "tmp" / f"denavit-kernels-{_cache_folder.current_uid()}-999999999-x"  # a dead process's
    stale.mkdir()
    fast = compile_planar()
    used = fast.path.parent
    assert not marker.exists() and used.name.startswith(f"denavit-kernels-{_cache_folder.current_uid()}-")
    assert stat.S_IMODE(used.stat().st_mode) == 0o700
    assert not stale.exists() or hijack == "another user's"  # (made by the test's user: not theirs to sweep)


def test_the_probe_and_a_symlinked_entry_never_write_through_a_link(env):
    """Planted links at the old probe's predictable names and at the module's names, pointing at a file the
    user can write: the target is untouched (mkstemp never follows a link; a link in a file's place is replaced)."""
    victim = env / "victim.txt"
    victim.write_text("precious")
    kernels = env / "kernels"
    kernels.mkdir(mode=0o700)
    for name in (f".probe-{os.getpid()}", f".probe-{os.getpid()}.tmp", f"{modname()}.py", f"{modname()}.pyc"):
        (kernels / name).symlink_to(victim)
    before = outside(env, kernels)
    with pytest.warns(DenavitWarning, match="damaged"):
        fast = compile_planar()
    assert victim.read_text() == "precious" and outside(env, kernels) == before
    assert not fast.path.is_symlink() and fast.path.read_bytes().startswith(b"# denavit kernels ")


# --- temporary files ---------------------------------------------------------------------------------------------
def test_a_failed_write_leaves_no_temporary_file_and_names_the_path(env, monkeypatch, capsys):
    real = os.replace

    def full_disk(src, dst):
        raise OSError(27, "File too large")

    monkeypatch.setattr(os, "replace", full_disk)
    with pytest.raises(OSError) as info:
        compile_planar()
    assert info.value.filename == str(env / "kernels" / f"{modname()}.py")
    code = main(["compile", "planar2r", "--backend", "numpy"])
    err = capsys.readouterr().err
    assert code == 2 and len(err.splitlines()) == 1 and "File too large" in err
    assert f"'{env / 'kernels' / '_denavit_kernels_numpy_'}" in err
    assert "internal error" not in err
    monkeypatch.setattr(os, "replace", real)
    assert not [p.name for p in (env / "kernels").iterdir() if p.suffix == ".tmp"]


def test_leftovers_of_killed_processes_are_removed_recent_ones_kept(env):
    kernels = env / "kernels"
    kernels.mkdir(mode=0o700)
    old = [kernels / "tmpabc123.tmp", kernels / ".probe-1.tmp"]
    for p in old:
        p.write_text("x")
        os.utime(p, (time.time() - 7200, time.time() - 7200))
    (kernels / "tmprecent.tmp").write_text("a write in progress")
    (kernels / "notes.txt").write_text("not ours")
    compile_planar()
    assert not any(p.exists() for p in old)
    assert (kernels / "tmprecent.tmp").exists() and (kernels / "notes.txt").read_text() == "not ours"


# --- damaged entries: deleted, rebuilt once, with one note ------------------------------------------------------------
def _garbage(n):
    return np.random.default_rng(n).integers(0, 256, max(n, 64), dtype=np.uint8).tobytes()


MODULE_DAMAGE = {
    "pyc truncated": lambda py, pyc, m: pyc.write_bytes(pyc.read_bytes()[: pyc.stat().st_size // 2]),
    "pyc empty": lambda py, pyc, m: pyc.write_bytes(b""),
    "pyc garbage": lambda py, pyc, m: pyc.write_bytes(_garbage(pyc.stat().st_size)),
    "pyc right header, garbage code": lambda py, pyc, m: pyc.write_bytes(pyc.read_bytes()[:16] + _garbage(200)),
    "py truncated": lambda py, pyc, m: py.write_bytes(py.read_bytes()[: py.stat().st_size // 2]),
    "py garbage": lambda py, pyc, m: py.write_bytes(_garbage(py.stat().st_size)),
    "py wrong hash": lambda py, pyc, m: py.write_bytes(py.read_bytes().partition(b"\n")[0] + b"\n"
                                                       + PLANT.format(marker=str(m)).encode()),
    "py a folder": lambda py, pyc, m: (py.unlink(), py.mkdir(), (py / "x").write_text("x")),
    "pyc a symlink": lambda py, pyc, m: (pyc.unlink(), pyc.symlink_to(m.parent / "victim.txt")),
}


@pytest.mark.parametrize("damage", list(MODULE_DAMAGE))
def test_a_damaged_module_is_rebuilt_once_with_a_note(env, damage):
    victim, marker = env / "victim.txt", env / "marker"
    victim.write_text("precious")
    fast = compile_planar()
    py = fast.path
    MODULE_DAMAGE[damage](py, py.with_suffix(".pyc"), marker)
    before = outside(env, env / "kernels")
    with pytest.warns(DenavitWarning, match="damaged") as notes:
        compile_planar()
    assert len([w for w in notes if issubclass(w.category, DenavitWarning)]) == 1
    assert not marker.exists() and victim.read_text() == "precious" and outside(env, env / "kernels") == before
    head, _, body = py.read_bytes().partition(b"\n")
    assert head.endswith(hashlib.sha256(body).hexdigest().encode())  # written afresh, whole
    assert not [p for p in py.parent.iterdir() if p.suffix == ".tmp"]
    no_denavit_warning(compile_planar)  # rebuilt for good


def test_the_cli_rebuilds_a_damaged_entry_and_says_so_in_one_line(env, capsys):
    assert main(["compile", "planar2r", "--backend", "numpy"]) == 0
    capsys.readouterr()
    (pyc,) = (env / "kernels").glob("*.pyc")
    pyc.write_bytes(pyc.read_bytes()[:40])  # what a full disk or Ctrl-C left: "marshal data too short"
    _cache._LOADED.clear()
    code = main(["compile", "planar2r", "--backend", "numpy"])
    out, err = capsys.readouterr()
    assert code == 0 and f"(cache: {env / 'kernels'})" in out
    assert len(err.splitlines()) == 1 and err.startswith("denavit compile: warning: kernel cache: ") and "damaged" in err


NUMBA_DAMAGE = {
    "nbi garbage": lambda files: files[".nbi"].write_bytes(_garbage(files[".nbi"].stat().st_size)),
    "nbi truncated": lambda files: files[".nbi"].write_bytes(files[".nbi"].read_bytes()[:30]),
    "nbc garbage": lambda files: files[".nbc"].write_bytes(_garbage(files[".nbc"].stat().st_size)),
    "nbc truncated": lambda files: files[".nbc"].write_bytes(files[".nbc"].read_bytes()[:100]),
    "nbi a folder": lambda files: (files[".nbi"].unlink(), files[".nbi"].mkdir()),
}


@needs_numba
@pytest.mark.slow  # numba's start-up and a first compile: ~4 s for the first case in a process, ~0.8 s after
@pytest.mark.parametrize("damage", [*NUMBA_DAMAGE, "__pycache__ a symlink"])
def test_damaged_numba_files_are_rebuilt_once_with_a_note(env, damage):
    fast = compile_planar("numba")
    pycache = fast.path.parent / "__pycache__"
    files = {p.suffix: p for p in pycache.glob(f"{modname('numba')}.fk_1-*")}
    assert set(files) == {".nbi", ".nbc"}
    elsewhere = env / "elsewhere"
    elsewhere.mkdir()
    if damage in NUMBA_DAMAGE:
        NUMBA_DAMAGE[damage](files)
    else:
        os.rename(pycache, elsewhere / "__pycache__")
        pycache.symlink_to(elsewhere / "__pycache__")
    before = outside(env, env / "kernels")
    with pytest.warns(DenavitWarning, match="could not be loaded|was not a folder"):
        again = compile_planar("numba")
    assert sum(again._m.fk_1.stats.cache_misses.values()) == 1
    assert outside(env, env / "kernels") == before and not pycache.is_symlink()
    third = no_denavit_warning(lambda: compile_planar("numba"))  # numba's files were saved afresh: a cache hit
    assert sum(third._m.fk_1.stats.cache_hits.values()) == 1 and not sum(third._m.fk_1.stats.cache_misses.values())


# --- denavit cache ---------------------------------------------------------------------------------------------------
def test_cache_command_reports_the_folder_and_size_and_clears_only_its_own_files(env, capsys):
    fast = compile_planar()
    kernels = fast.path.parent
    (kernels / "notes.txt").write_text("the user's own file")
    ours = [p for p in kernels.iterdir() if p.name.startswith("_denavit_kernels_")]
    assert main(["cache", "--json"]) == 0
    info = json.loads(capsys.readouterr().out)
    assert info["folder"] == str(kernels) and info["files"] == len(ours) == 2
    assert info["bytes"] == sum(p.stat().st_size for p in ours)
    assert main(["cache"]) == 0 and capsys.readouterr().out.startswith(f"kernel cache: {kernels} (2 files, ")
    assert main(["cache", "--clear"]) == 0 and capsys.readouterr().out.startswith("removed 2 files, ")
    assert sorted(p.name for p in kernels.iterdir()) == ["notes.txt"]
    assert main(["cache", "--json"]) == 0 and json.loads(capsys.readouterr().out)["files"] == 0
    compile_planar()  # and the next compile simply builds again


def test_cache_command_names_the_folder_used_when_the_configured_one_is_unsafe(env, capsys):
    (env / "kernels").mkdir(mode=0o777)
    (env / "kernels").chmod(0o777)
    code = main(["cache"])
    out, err = capsys.readouterr()
    assert code == 0 and out.startswith(f"kernel cache: {env / 'tmp' / f'denavit-kernels-{os.geteuid()}'} ")
    assert f"configured {env / 'kernels'}: not used, open to other users (mode 777)" in out
    code = main(["compile", "planar2r", "--backend", "numpy"])  # and compile names the folder it used
    out, err = capsys.readouterr()
    assert code == 0 and f"(cache: {env / 'tmp' / f'denavit-kernels-{os.geteuid()}'})" in out
    assert len(err.splitlines()) == 1 and "warning: kernel cache" in err and "not used" in err


@pytest.mark.slow  # a new Python process importing denavit: ~2 s
def test_a_fresh_private_folder_is_gone_when_the_process_ends(env):
    """The last fallback (the per-user folder is not safe) lives as long as the process: removed at exit."""
    import subprocess
    import sys

    (env / "blocker").write_text("")
    (env / "tmp" / f"denavit-kernels-{os.geteuid()}").mkdir(mode=0o777)
    (env / "tmp" / f"denavit-kernels-{os.geteuid()}").chmod(0o777)
    script = ("import denavit; f = denavit.compile(denavit.load_robot('planar2r'), backend='numpy', kernels=['fk']);"
              "print(f.path.parent)")
    run = subprocess.run([sys.executable, "-W", "ignore", "-c", script], capture_output=True, text=True, check=True,
                         env={**os.environ, "TMPDIR": str(env / "tmp"), "DENAVIT_CACHE_DIR": str(env / "blocker" / "k")})
    used = Path(run.stdout.strip())
    assert used.parent == env / "tmp" and used.name.startswith(f"denavit-kernels-{os.geteuid()}-")
    assert not used.exists() and sorted(p.name for p in (env / "tmp").iterdir()) == [f"denavit-kernels-{os.geteuid()}"]


def test_the_cache_key_covers_every_module_a_traced_kernel_runs():
    """The generator digest in every key reads every module of codegen/, chain/ and numeric/ — in particular those
    the kernel groups trace through (dual numbers, derivatives, regressor): an upgrade changing one of them must
    not load a module generated by the old code (a hand-kept list once left out numeric/_dual.py)."""
    import sys

    from denavit.codegen._cache import generator_sources

    sources = set(generator_sources())
    robot = denavit.load_robot("puma560")
    from denavit.codegen import trace_kernels

    trace_kernels(robot)
    for name in ("numeric/_dual.py", "numeric/_dyn_derivatives.py", "numeric/_kin_derivatives.py",
                 "numeric/_regressor.py", "numeric/_dynamics_fast.py", "chain/_walk.py", "codegen/_kernels_dyn.py",
                 "codegen/_trace.py", "codegen/_emit.py"):
        assert name in sources, name
    root = Path(denavit.__file__).resolve().parent
    for mod in list(sys.modules.values()):
        path = getattr(mod, "__file__", None) or ""
        rel = Path(path).resolve().relative_to(root).as_posix() if path.startswith(str(root)) else ""
        if rel.split("/")[0] in ("codegen", "chain", "numeric"):
            assert rel in sources, rel
