"""xacro documents expanded to URDF (by the optional xacrodoc; xacro evaluates Python: only for trusted files).

A xacro document is a program: a macro that calls itself twice, or an expression such as ``${10**(10**8)}``,
runs for hours or fills the memory.  The expansion therefore runs in a child process (a fresh interpreter,
``python -I``) under the same kind of bounds as every other hostile input: :data:`XACRO_CPU_SECONDS` of CPU
time (``RLIMIT_CPU``, independent of the machine's load), :data:`XACRO_MEMORY_BYTES` of address space
(``RLIMIT_AS``), an output of at most :data:`~denavit.interop._xml.MAX_XML_BYTES` (``RLIMIT_FSIZE`` on the file
it writes), and a wall-clock safety net of :data:`XACRO_WALL_SECONDS` for a child that waits without using CPU
(an include of a FIFO).  Where the OS has no ``resource`` module (Windows) only the wall-clock bound applies.
The child's own messages are kept off the terminal; what went wrong comes back as one line.
"""

from __future__ import annotations

import json
import signal
import subprocess
import sys
import tempfile

from ..errors import MissingDependencyError, ParseError
from ._xml import MAX_XML_BYTES

__all__ = ["expand_xacro", "XACRO_CPU_SECONDS", "XACRO_MEMORY_BYTES", "XACRO_WALL_SECONDS"]

#: CPU seconds the expansion may use (a real arm's xacro, a UR or a Panda, takes well under one second).
XACRO_CPU_SECONDS = 20
#: Address space of the expanding process [bytes] (the interpreter with xacrodoc takes about 25 MB).
XACRO_MEMORY_BYTES = 1 << 30
#: Wall-clock bound [s] on the child, for one that waits without using CPU.
XACRO_WALL_SECONDS = 120

# The child: limits first, then xacrodoc; it writes "ok\n" + the URDF, or "error\n" / "grew\n" + a message.
_CHILD = r"""
import json, sys
cfg = json.loads(sys.argv[1])
try:
    import resource
except ImportError:
    resource = None
for name, value, extra in (("RLIMIT_CPU", cfg["cpu"], 1), ("RLIMIT_AS", cfg["memory"], 0),
                           ("RLIMIT_FSIZE", cfg["fsize"], 0), ("RLIMIT_CORE", 0, 0)):
    if resource is not None and hasattr(resource, name):  # never above a limit the caller already has
        _, hard = resource.getrlimit(getattr(resource, name))
        top = value + extra if hard == resource.RLIM_INFINITY else min(hard, value + extra)
        resource.setrlimit(getattr(resource, name), (min(value, top), top))
sys.path[:] = cfg["path"]
import contextlib, io
out = sys.stdout.buffer
data = sys.stdin.buffer.read()
try:
    with contextlib.redirect_stderr(io.StringIO()), contextlib.redirect_stdout(io.StringIO()):
        from xacrodoc import XacroDoc
        doc = XacroDoc.from_string(data.decode("utf-8"), rootdir=cfg["rootdir"], resolve_packages=False)
        text = doc.to_urdf_string(use_protocols=True).encode("utf-8")
except (MemoryError, RecursionError):
    out.write(b"grew\n")
except Exception as exc:
    out.write(b"error\n" + (" ".join(str(exc).split())[:200] or type(exc).__name__).encode("utf-8", "replace"))
else:
    out.write(b"ok\n" + text if len(text) <= cfg["max_bytes"] else b"large\n")
out.flush()
"""


def expand_xacro(data: bytes, where: str, rootdir) -> bytes:
    """A xacro document expanded to URDF by xacrodoc (no ROS needed), in a bounded child process.

    Raises
    ------
    MissingDependencyError
        xacrodoc is not installed (the ``xacro`` extra).
    ParseError
        xacro's own error on the document, or a bound exceeded (CPU time, memory, output size, wall clock); one
        line naming ``where``.
    """
    import importlib.util

    if importlib.util.find_spec("xacrodoc") is None:
        raise MissingDependencyError("expanding xacro needs xacrodoc: pip install 'denavit[xacro]'")
    cfg = {"cpu": XACRO_CPU_SECONDS, "memory": XACRO_MEMORY_BYTES, "fsize": MAX_XML_BYTES + 65536,
           "max_bytes": MAX_XML_BYTES, "rootdir": rootdir, "path": [p for p in sys.path if isinstance(p, str)]}
    with tempfile.TemporaryFile() as out:
        try:
            done = subprocess.run([sys.executable, "-I", "-c", _CHILD, json.dumps(cfg)], input=data, stdout=out,
                                  stderr=subprocess.DEVNULL, timeout=XACRO_WALL_SECONDS, check=False)
        except subprocess.TimeoutExpired:
            raise ParseError(f"xacro: the expansion took longer than {XACRO_WALL_SECONDS} s (waiting on an "
                             "include?); stopped", where=where) from None
        out.seek(0)
        reply = out.read(MAX_XML_BYTES + 65536)
    status, _, body = reply.partition(b"\n")
    if status == b"ok" and done.returncode == 0:
        return body
    raise ParseError(_failure(status, body, done.returncode), where=where)


def _failure(status: bytes, body: bytes, returncode: int) -> str:
    """The one-line reason an expansion gave no URDF."""
    if status == b"error":
        return f"xacro: {body.decode('utf-8', 'replace')}"
    if status == b"large":
        return f"xacro: the expanded URDF is larger than {MAX_XML_BYTES} bytes"
    if status == b"grew" or returncode == -getattr(signal, "SIGSEGV", 11):
        return (f"xacro: the expansion grew beyond what can be held (limit {XACRO_MEMORY_BYTES >> 20} MB, or too "
                "deep a recursion)")
    if returncode in (-getattr(signal, "SIGXCPU", 24), -getattr(signal, "SIGKILL", 9)):
        return f"xacro: the expansion used more than {XACRO_CPU_SECONDS} s of CPU time (a runaway macro?); stopped"
    return (f"xacro: the expansion ended without a result (exit status {returncode}) within its bounds "
            f"({XACRO_CPU_SECONDS} s CPU, {XACRO_MEMORY_BYTES >> 20} MB)")
