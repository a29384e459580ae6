"""The regressor half of :class:`denavit.codegen.CompiledRobot`: ``regressor`` on the kernel of group
``regressor`` (traced by :mod:`denavit.codegen._kernels_reg`, compiled or loaded from the disk cache on first use)."""

from __future__ import annotations

import numpy as np

from ._kernels_reg import GROUP

__all__ = ["RegressorMethods", "GROUP"]

_ndarray, _F64, _empty, _STRIDE = np.ndarray, np.dtype(np.float64), np.empty, (8,)


class RegressorMethods:
    """Mixed into CompiledRobot, whose ``_call`` (loading the group on first use) and hot-path kernel
    ``_regressor_1`` (bound once the group is loaded) it uses."""

    def regressor(self, q, qd, qdd, *, threads=None, out=None) -> np.ndarray:
        """Y(q, q̇, q̈), shape (..., n, 13 n): τ = Y π with π = ``denavit.inertial_parameters(robot)`` — the
        columns of :func:`denavit.regressor` (inertial, FV, FC, IA); batched over leading axes, ``threads=`` as
        the other batch calls; ``out=`` the caller's array to write and return (as the other calls)."""
        kernel = self.__dict__.get("_regressor_1")
        if (out is None and kernel is not None and q.__class__ is _ndarray and qd.__class__ is _ndarray
                and qdd.__class__ is _ndarray and q.dtype is _F64 and qd.dtype is _F64 and qdd.dtype is _F64
                and q.shape == qd.shape == qdd.shape == self._vec and q.strides == qd.strides == qdd.strides == _STRIDE):
            res = _empty(self._shapes["regressor"])
            kernel(q, qd, qdd, res)
            return res
        return self._call("regressor", (q, qd, qdd), ("q", "qd", "qdd"), threads, out)
