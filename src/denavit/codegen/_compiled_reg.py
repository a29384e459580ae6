"""The compiled object's regressor methods (a mixin of :class:`denavit.codegen.CompiledRobot`)."""

from __future__ import annotations

import numpy as np

__all__ = ["RegressorMethods"]


class RegressorMethods:
    """``regressor`` on the compiled arm: the kernel of :mod:`denavit.codegen._kernels_reg` (group
    ``"regressor"``, compiled or loaded from the disk cache on first use)."""

    def regressor(self, q, qd, qdd, *, threads=None) -> np.ndarray:
        """Y(q, q̇, q̈), shape (..., n, p): τ = Y π with π = ``denavit.inertial_parameters(robot,
        friction=self.friction)`` — the columns of :func:`denavit.regressor` with the compiled friction setting
        and motor inertia; batched over leading axes, ``threads=`` as the other batch calls."""
        return self._call("regressor", (q, qd, qdd), ("q", "qd", "qdd"), threads)
