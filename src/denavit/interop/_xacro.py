"""xacro documents expanded to URDF (by the optional xacrodoc; xacro evaluates Python: only for trusted files)."""

from __future__ import annotations

from ..errors import MissingDependencyError, ParseError
from ._xml import MAX_XML_BYTES

__all__ = ["expand_xacro"]


def expand_xacro(data: bytes, where: str, rootdir) -> bytes:
    """A xacro document expanded to URDF by xacrodoc (no ROS needed); its messages are kept off the terminal."""
    import contextlib
    import io

    try:
        from xacrodoc import XacroDoc
    except ImportError as exc:
        if exc.name and exc.name.split(".")[0] != "xacrodoc":
            raise
        raise MissingDependencyError("expanding xacro needs xacrodoc: pip install 'denavit[xacro]'") from None
    chatter = io.StringIO()
    try:
        with contextlib.redirect_stderr(chatter), contextlib.redirect_stdout(chatter):
            doc = XacroDoc.from_string(data.decode("utf-8"), rootdir=rootdir, resolve_packages=False)
            text = doc.to_urdf_string(use_protocols=True)
    except (MemoryError, RecursionError):
        raise ParseError("xacro: the expansion grew beyond what can be held", where=where) from None
    except Exception as exc:  # xacro's own errors on the user's document: one line
        raise ParseError(f"xacro: {' '.join(str(exc).split())[:200] or type(exc).__name__}", where=where) from None
    out = text.encode("utf-8")
    if len(out) > MAX_XML_BYTES:
        raise ParseError(f"xacro: the expanded URDF is larger than {MAX_XML_BYTES} bytes", where=where)
    return out
