"""The browser workbench (``denavit serve``): a local web page over the library, no logic of its own.

Needs the ``web`` extra (Starlette and uvicorn): ``pip install "denavit[web]"``.  :func:`create_app` builds the
application; the command line serves it on 127.0.0.1.  See ``docs/workbench.md``.
"""

from __future__ import annotations

from typing import Any

from ..errors import MissingDependencyError
from ._jobs import JOB_CPU_SECONDS, MAX_RUNNING, Jobs
from ._work import claim_lines

__all__ = ["JOB_CPU_SECONDS", "MAX_RUNNING", "Jobs", "claim_lines", "create_app", "require_web"]

WEB_EXTRA = 'the workbench needs Starlette and uvicorn, which are not installed: pip install "denavit[web]"'


def require_web() -> None:
    """Raise MissingDependencyError naming the ``web`` extra when Starlette or uvicorn is missing."""
    for name in ("starlette", "uvicorn"):
        try:
            __import__(name)
        except ImportError as exc:
            if exc.name not in (None, name) and not str(exc.name).startswith(name + "."):
                raise
            raise MissingDependencyError(WEB_EXTRA) from None


def create_app(robot: Any = None, **options: Any) -> Any:
    """The workbench's Starlette application (see :func:`denavit.web._app.create_app`)."""
    require_web()
    from ._app import create_app as build

    return build(robot, **options)
