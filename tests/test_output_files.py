"""``-o`` as users expect (issue 29): an output is replaced, atomically and only after the work succeeded; an input
is never overwritten; ``--no-clobber`` refuses an existing file; a write failure names the file.

The truth here is the file system itself: bytes and inodes read back after the run, never the code's own report.
"""

from __future__ import annotations

import errno
import os
import subprocess
import sys
from pathlib import Path

import pytest

from _hostile import assert_accepted_quietly, assert_refused, run_cli

TABLE = "| i | a | alpha | d | theta |\n|---|---|---|---|---|\n| 1 | 0.5 | 0 | 0 | \\theta_1 |\n"
ROBOT = "name: arm\nconvention: standard\njoints:\n  - {a: 1, alpha: 0, d: 0, theta: q}\n  - {a: 0.5, alpha: 0, d: 0, theta: q}\n"

# Each command that writes, with its input files, and the outputs it writes.
TWICE = {
    "plot": (["plot", "planar2r", "-q", "0.1,0.2", "-o", "arm.png"], {}, ["arm.png"]),
    "report": (["report", "planar2r", "--topics", "model,figures", "-o", "r.md"], {}, ["r.md", "r-planar2r-arm.png"]),
    "export": (["export", "planar2r", "--lang", "python", "-o", "gen"], {}, ["gen/planar2r.py"]),
    "import-table": (["import-table", "t.txt", "-o", "arm.yaml"], {"t.txt": TABLE}, ["arm.yaml"]),
    "convert": (["convert", "arm.yaml", "--to", "modified", "-o", "mdh.yaml"], {"arm.yaml": ROBOT}, ["mdh.yaml"]),
    "export-urdf": (["export-urdf", "planar2r", "-o", "arm.urdf"], {}, ["arm.urdf"]),
}


def _names(folder: Path) -> list[str]:
    return sorted(str(p.relative_to(folder)) for p in folder.rglob("*") if p.is_file())


@pytest.mark.parametrize("command", sorted(TWICE))
def test_the_same_command_twice_succeeds_both_times(tmp_path, command):
    argv, files, outputs = TWICE[command]
    first = run_cli(argv, tmp_path, files)
    assert_accepted_quietly(first)
    inodes = {name: (tmp_path / name).stat().st_ino for name in outputs}
    names = _names(tmp_path)
    again = run_cli(argv, tmp_path)
    assert_accepted_quietly(again)
    assert _names(tmp_path) == names  # the same files, no temporary file left behind
    for name in outputs:
        assert (tmp_path / name).stat().st_size > 0
        assert (tmp_path / name).stat().st_ino != inodes[name]  # a new file moved into place, not rewritten in place
    for name, text in files.items():  # inputs untouched
        assert (tmp_path / name).read_text() == text


@pytest.mark.parametrize("command", sorted(TWICE))
def test_no_clobber_refuses_an_existing_output(tmp_path, command):
    argv, files, outputs = TWICE[command]
    assert_accepted_quietly(run_cli(argv, tmp_path, files))
    (tmp_path / outputs[0]).write_bytes(b"mine")
    o = run_cli(argv + ["--no-clobber"], tmp_path)
    assert_refused(o, mentions=[Path(outputs[0]).name, "exists", "--no-clobber"])  # and no file changed


def test_report_no_clobber_refuses_before_the_work_when_only_the_picture_exists(tmp_path):
    o = run_cli(["report", "planar2r", "--topics", "model,figures", "-o", "r.md", "--no-clobber"], tmp_path,
                {"r-planar2r-arm.png": b"my picture"})
    assert_refused(o, mentions=["r-planar2r-arm.png", "--no-clobber"])
    assert "section" not in o.err  # no section was derived


def test_output_equal_to_the_input_is_refused(tmp_path):
    o = run_cli(["convert", "arm.yaml", "--to", "modified", "-o", "arm.yaml"], tmp_path, {"arm.yaml": ROBOT})
    assert_refused(o, mentions=["arm.yaml", "input"])


def test_output_reaching_the_input_through_a_symlink_or_a_hard_link_is_refused(tmp_path):
    (tmp_path / "arm.yaml").write_text(ROBOT)
    (tmp_path / "link.yaml").symlink_to("arm.yaml")
    os.link(tmp_path / "arm.yaml", tmp_path / "hard.yaml")
    sub = tmp_path / "sub"
    sub.mkdir()
    # the input read through a symlink, -o the real file; then -o a hard link of the input (same inode)
    assert_refused(run_cli(["convert", "link.yaml", "--to", "modified", "-o", "arm.yaml"], tmp_path),
                   mentions=["arm.yaml", "input"])
    assert_refused(run_cli(["convert", "arm.yaml", "--to", "modified", "-o", "hard.yaml"], tmp_path),
                   mentions=["hard.yaml", "input"])
    assert_refused(run_cli(["convert", "../arm.yaml", "--to", "modified", "-o", "../arm.yaml"], sub),
                   mentions=["arm.yaml", "input"])
    assert (tmp_path / "arm.yaml").read_text() == ROBOT


def test_export_to_an_empty_folder_name_is_refused(tmp_path):
    o = run_cli(["export", "planar2r", "--lang", "c", "-o", ""], tmp_path)
    assert_refused(o, mentions=["-o", "empty"])  # nothing written into the current folder


@pytest.mark.parametrize("argv", [["convert", "planar2r", "--to", "modified"], ["plot", "planar2r"],
                                  ["report", "planar2r", "--topics", "model"]])
def test_an_empty_output_path_is_refused(tmp_path, argv):
    assert_refused(run_cli(argv + ["-o", ""], tmp_path), mentions=["-o", "empty"])


def test_a_replaced_file_keeps_its_permissions(tmp_path):
    out = tmp_path / "arm.yaml"
    out.write_text("old")
    out.chmod(0o640)
    assert_accepted_quietly(run_cli(["convert", "planar2r", "--to", "modified", "-o", "arm.yaml"], tmp_path))
    assert out.stat().st_mode & 0o777 == 0o640 and "convention: modified" in out.read_text()


def test_a_write_failing_midway_leaves_the_existing_file_and_names_it(tmp_path, monkeypatch):
    """A full disk while the picture is saved: exit 2, one line naming arm.png, the old arm.png as it was."""
    import denavit.viz

    def full_disk(fig, path, **kwargs):
        Path(path).write_bytes(b"half a pic")
        raise OSError(errno.ENOSPC, "No space left on device")

    (tmp_path / "arm.png").write_bytes(b"my old picture")
    monkeypatch.setattr(denavit.viz, "save_figure", full_disk)
    o = run_cli(["plot", "planar2r", "-o", "arm.png"], tmp_path)
    assert_refused(o, mentions=["arm.png", "No space left on device"])  # no file changed, none appeared


def test_a_command_failing_after_writing_leaves_the_existing_file(tmp_path, monkeypatch):
    """Not only OS errors: any failure inside the write (here a bug of the writer) replaces nothing."""
    import denavit.viz

    def broken(fig, path, **kwargs):
        Path(path).write_bytes(b"half a pic")
        raise ValueError("a writer bug")

    (tmp_path / "arm.png").write_bytes(b"my old picture")
    monkeypatch.setattr(denavit.viz, "save_figure", broken)
    o = run_cli(["plot", "planar2r", "-o", "arm.png"], tmp_path)
    assert o.code == 1 and "internal error" in o.err
    assert o.after == o.before  # arm.png as it was, no temporary file left


def test_a_report_and_its_picture_are_replaced_together(tmp_path, monkeypatch):
    """The second of the report's two files fails to write: neither the old report nor the old picture changes."""
    argv = ["report", "planar2r", "--topics", "model,figures", "-o", "r.md", "--json"]  # --json: no progress lines
    assert_accepted_quietly(run_cli(argv, tmp_path))
    (tmp_path / "r.md").write_text("old report")
    (tmp_path / "r-planar2r-arm.png").write_bytes(b"old picture")
    calls = []
    real = Path.write_bytes

    def second_fails(self, data):
        calls.append(self.name)
        if len(calls) == 2:
            raise OSError(errno.EFBIG, "File too large")
        return real(self, data)

    monkeypatch.setattr(Path, "write_bytes", second_fails)
    o = run_cli(argv, tmp_path)
    assert_refused(o, mentions=["'r.md'", "'r-planar2r-arm.png'", "File too large", "nothing was replaced"])
    assert len(calls) == 2


@pytest.mark.skipif(not hasattr(os, "fork"), reason="RLIMIT_FSIZE is POSIX")
def test_compile_past_a_file_size_limit_names_the_cache_folder(tmp_path):
    """A file-size limit (as a full disk) while the kernel cache is written: the error line says where (the file in
    the cache folder), not only "File too large"."""
    code = ("import resource, sys; resource.setrlimit(resource.RLIMIT_FSIZE, (4096, 4096)); "
            "from denavit.cli import main; sys.exit(main(sys.argv[1:]))")
    env = {**os.environ, "DENAVIT_CACHE_DIR": str(tmp_path / "cache"), "PYTHONPATH": os.pathsep.join(sys.path)}
    done = subprocess.run([sys.executable, "-c", code, "compile", "planar2r", "--backend", "numpy"],
                          capture_output=True, text=True, env=env, timeout=600, check=False)
    lines = done.stderr.strip().splitlines()
    assert done.returncode == 2 and len(lines) == 1, done.stderr
    assert str(tmp_path / "cache") in lines[0] and "File too large" in lines[0]
