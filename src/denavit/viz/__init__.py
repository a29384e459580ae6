"""Pictures of an arm: static plots, animations, a self-contained HTML viewer and workspace plots.

Importing this package is light: the geometry (:func:`arm_geometry`), the workspace sampling
(:func:`workspace`) and the HTML viewer (:func:`viewer_html`) need numpy only.  matplotlib, the
optional extra ``denavit[plot]``, is imported by the drawing functions when they are called, and
only through ``Figure`` objects with the Agg canvas: nothing here opens a window or touches
``pyplot`` state, so it works headless and inside other programs' figures.
"""

from __future__ import annotations

import importlib
from typing import Any

from ..errors import MissingDependencyError
from ._geometry import ArmGeometry, arm_geometry, default_configuration, robot_scale
from ._workspace import Workspace, plot_occupancy, plot_reachability, plot_workspace, sample_workspace, workspace
from ._html import slider_limits, viewer_html, write_viewer

__all__ = [
    "ArmGeometry",
    "arm_geometry",
    "default_configuration",
    "robot_scale",
    "Workspace",
    "sample_workspace",
    "workspace",
    "slider_limits",
    "viewer_html",
    "write_viewer",
    "plot_robot",
    "plot_workspace",
    "plot_occupancy",
    "plot_reachability",
    "save_figure",
    "animate_robot",
    "require_matplotlib",
    "MissingDependencyError",
]

_LAZY = {
    "plot_robot": "._plot",
    "save_figure": "._plot",
    "animate_robot": "._animate",
}


def require_matplotlib() -> Any:
    """Import and return matplotlib, or raise MissingDependencyError naming the ``plot`` extra."""
    try:
        import matplotlib
    except ImportError as exc:
        if exc.name not in (None, "matplotlib") and not str(exc.name).startswith("matplotlib"):
            raise
        raise MissingDependencyError(
            "pictures need matplotlib, which is not installed: pip install 'denavit[plot]'"
        ) from None
    return matplotlib


def __getattr__(name: str) -> Any:
    if name in _LAZY:
        module = importlib.import_module(_LAZY[name], __name__)
        return getattr(module, name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted(__all__)
