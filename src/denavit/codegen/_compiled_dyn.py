"""The dynamics-derivative half of :class:`denavit.codegen.CompiledRobot`: rnea_derivatives,
forward_dynamics_derivatives and gravity_derivatives on the kernels of group ``dynamics_derivatives``
(traced by :mod:`denavit.codegen._kernels_dyn`, compiled or loaded from the disk cache on the first call)."""

from __future__ import annotations

import numpy as np

from ._kernels_dyn import GROUP

__all__ = ["DynDerivativeMethods", "GROUP"]

_ndarray, _F64, _empty, _STRIDE = np.ndarray, np.dtype(np.float64), np.empty, (8,)


class DynDerivativeMethods:
    """Mixed into CompiledRobot, whose ``_call`` (any call, loading the group first) and hot-path kernels
    ``_<name>_1`` (bound once the group is loaded) they use.  The hot path (three (n,) float64 contiguous arrays,
    kernel bound) is spelled out in each method: a helper call and a name built per call cost a microsecond."""

    def rnea_derivatives(self, q, qd, qdd, *, threads=None):
        """``(dtau_dq, dtau_dqd)``, each (..., n, n) [output, input] (as :func:`denavit.rnea_derivatives` with the
        robot's gravity and the object's friction)."""
        kernel = self.__dict__.get("_rnea_derivatives_1")
        if (kernel is not None and q.__class__ is _ndarray and qd.__class__ is _ndarray and qdd.__class__ is _ndarray
                and q.dtype is _F64 and qd.dtype is _F64 and qdd.dtype is _F64
                and q.shape == qd.shape == qdd.shape == self._vec and q.strides == qd.strides == qdd.strides == _STRIDE):
            out = _empty(self._shapes["rnea_derivatives"])
            kernel(q, qd, qdd, out)
            return out[0], out[1]
        out = self._call("rnea_derivatives", (q, qd, qdd), ("q", "qd", "qdd"), threads)
        return out[..., 0, :, :], out[..., 1, :, :]

    def forward_dynamics_derivatives(self, q, qd, tau, *, threads=None):
        """``(dqdd_dq, dqdd_dqd, dqdd_dtau)``, each (..., n, n); dqdd_dtau = M⁻¹ (as
        :func:`denavit.forward_dynamics_derivatives`); ModelError where M is singular."""
        n = self.dof
        kernel = self.__dict__.get("_forward_dynamics_derivatives_1")
        if (kernel is not None and q.__class__ is _ndarray and qd.__class__ is _ndarray and tau.__class__ is _ndarray
                and q.dtype is _F64 and qd.dtype is _F64 and tau.dtype is _F64
                and q.shape == qd.shape == tau.shape == self._vec and q.strides == qd.strides == tau.strides == _STRIDE):
            r = _empty(self._shapes["forward_dynamics_derivatives"])
            kernel(q, qd, tau, r)
        else:
            r = self._call("forward_dynamics_derivatives", (q, qd, tau), ("q", "qd", "tau"), threads)
        if r.ndim > 1:
            if not (r[..., -1] > 0.0).all():
                self._singular()
            D = r[..., :-1].reshape(r.shape[:-1] + (3, n, n))
            return D[..., 0, :, :], D[..., 1, :, :], D[..., 2, :, :]
        if not r[-1] > 0.0:
            self._singular()
        D = r[:-1].reshape(3, n, n)
        return D[0], D[1], D[2]

    def gravity_derivatives(self, q, *, threads=None, out=None):
        """∂g/∂q, (..., n, n) (as :func:`denavit.gravity_derivatives` with the robot's gravity); ``out=`` the
        caller's array to write and return (as the compiled object's other one-array calls)."""
        kernel = self.__dict__.get("_gravity_derivatives_1")
        if (out is None and kernel is not None and q.__class__ is _ndarray and q.dtype is _F64 and q.shape == self._vec
                and q.strides == _STRIDE):
            res = _empty(self._mshape)
            kernel(q, res)
            return res
        return self._call("gravity_derivatives", (q,), ("q",), threads, out)
