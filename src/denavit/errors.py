"""Exception hierarchy of denavit.

Every error a user can cause derives from :class:`DenavitError`; the command line catches it at the
top and prints one line.  The ``ValueError`` subclasses keep ``except ValueError`` working.
"""

from __future__ import annotations

__all__ = [
    "DenavitError",
    "ModelError",
    "ShapeError",
    "ParseError",
    "UnsupportedRobotError",
    "MissingDependencyError",
    "DenavitWarning",
    "Terminated",
]


class DenavitError(Exception):
    """Base class of every denavit error."""


class ModelError(DenavitError, ValueError):
    """The robot model is invalid (bad DH table, limits, inertial data...)."""


class ShapeError(DenavitError, ValueError):
    """An array has the wrong shape; the message says what was expected and what was received."""


class ParseError(DenavitError, ValueError):
    """A robot file, expression, table or claim could not be read.

    The message names the place: file, row and field where known.
    """

    def __init__(self, message: str, *, where: str | None = None) -> None:
        self.where = where
        super().__init__(f"{where}: {message}" if where else message)


class UnsupportedRobotError(DenavitError):
    """The requested method does not apply to this robot (e.g. analytic IK of a non-Pieper arm)."""


class MissingDependencyError(DenavitError, ImportError):
    """An optional dependency is missing; the message names the extra to install."""


class Terminated(KeyboardInterrupt):
    """SIGTERM arrived while denavit ran a local Dask cluster: raised in the main thread so that every cleanup
    (the cluster's close first) runs as the stack unwinds, like Ctrl-C's KeyboardInterrupt.  The command line
    exits with status 128 + SIGTERM = 143 and prints nothing, as a process killed by SIGTERM would."""


class DenavitWarning(UserWarning):
    """Input that is accepted but probably not what was meant (e.g. ``alpha: 90`` in a radian file).

    The message says what to write instead; the command line prints it as one ``warning:`` line.
    """
