"""The compiled object's kinematic-derivative methods (a mixin of :class:`denavit.codegen.CompiledRobot`)."""

from __future__ import annotations

import numpy as np

from ..model import Frame
from ._kernels_kin import GROUP

__all__ = ["KinDerivativeMethods"]

_ndarray, _F64, _empty, _STRIDE = np.ndarray, np.dtype(np.float64), np.empty, (8,)


def _suffix(frame) -> str:
    if frame == "base" or frame is Frame.BASE:
        return "0"
    if frame == "tool" or frame is Frame.TOOL:
        return "e"
    raise ValueError(f"frame {str(frame)[:40]!r}: choose base or tool")


class KinDerivativeMethods:
    """``jacobian_dot``, ``acceleration_bias`` and ``kinematic_hessian`` on the compiled arm: the kernels of
    :mod:`denavit.codegen._kernels_kin` (group ``"kinematic_derivatives"``, compiled or loaded from the disk cache
    on first use).  One configuration of float64 (n,) arrays goes straight to the kernel; anything else (lists,
    batches, other dtypes, wrong shapes) takes ``_call`` with its checks; ``out=`` (the caller's array, as the
    compiled object's other calls) too."""

    kin_group = GROUP

    def _kin2(self, name: str, q, qd, threads, out=None):
        """The single call's hot path when the kernel is loaded and q, q̇ are float64 (n,) arrays, else ``_call``."""
        if (out is None and q.__class__ is _ndarray and qd.__class__ is _ndarray and q.dtype is _F64 and qd.dtype is _F64
                and q.shape == self._vec and qd.shape == self._vec and q.strides == qd.strides == _STRIDE
                and (threads is None or threads.__class__ is int and threads > 0)):
            kernel = self.__dict__.get(f"_{name}_1")
            if kernel is not None:
                res = _empty(self._shapes[name])
                kernel(q, qd, res)
                return res
        return self._call(name, (q, qd), ("q", "qd"), threads, out)

    def jacobian_dot(self, q, qd, frame="base", *, threads=None, out=None) -> np.ndarray:
        """J̇, shape (..., 6, n): d/dt J0 (``base``) or d/dt Je (``tool``), as :func:`denavit.jacobian_dot`."""
        if (frame == "base" and q.__class__ is _ndarray and qd.__class__ is _ndarray and threads is None
                and out is None):
            kernel = self.__dict__.get("_jacobian_dot0_1")  # the hot path, spelled out: no name built per call
            if (kernel is not None and q.dtype is _F64 and qd.dtype is _F64 and q.shape == self._vec
                    and qd.shape == self._vec and q.strides == qd.strides == _STRIDE):
                out = _empty(self._jshape)
                kernel(q, qd, out)
                return out
        return self._kin2("jacobian_dot" + _suffix(frame), q, qd, threads, out)

    def acceleration_bias(self, q, qd, frame="base", *, threads=None, out=None) -> np.ndarray:
        """(p̈, ω̇) of the end-effector origin at q̈ = 0, shape (..., 6), base or tool axes, as
        :func:`denavit.acceleration_bias`."""
        return self._kin2("acceleration_bias" + _suffix(frame), q, qd, threads, out)

    def kinematic_hessian(self, q, frame="base", *, threads=None, out=None) -> np.ndarray:
        """∂J/∂q, shape (..., 6, n, n) with ∂J[:, j]/∂q_k at [..., :, j, k], as :func:`denavit.kinematic_hessian`."""
        name = "kinematic_hessian" + _suffix(frame)
        if (out is None and q.__class__ is _ndarray and q.dtype is _F64 and q.shape == self._vec
                and q.strides == _STRIDE and (threads is None or threads.__class__ is int and threads > 0)):
            kernel = self.__dict__.get(f"_{name}_1")
            if kernel is not None:
                res = _empty(self._shapes[name])
                kernel(q, res)
                return res
        return self._call(name, (q,), ("q",), threads, out)
