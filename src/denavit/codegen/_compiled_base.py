"""The base half of :class:`denavit.codegen.CompiledRobot`: FK, position, the Jacobians, RNEA, M, g, c and forward
dynamics on the kernels of the base group (each method's hot path first, then ``CompiledRobot._call``)."""

from __future__ import annotations

import numpy as np

from ..errors import ModelError
from ..model import Frame

__all__ = ["BaseMethods"]

_ndarray, _F64, _empty, _SHAPE44, _SHAPE3, _STRIDE = np.ndarray, np.dtype(np.float64), np.empty, (4, 4), (3,), (8,)


class BaseMethods:
    """Mixed into CompiledRobot, whose ``_call``, hot-path kernels ``_<name>_1`` and shapes (``_vec``,
    ``_jshape``, ``_mshape``, ``_fshape``) it uses."""

    # --- kinematics ---------------------------------------------------------------------------------------
    # Each method first tries the hot path: float64 ndarrays of shape (n,) go straight to the kernel with a
    # fresh output; anything else (lists, other dtypes, batches, wrong shapes) takes :meth:`_call`.
    def fk(self, q, frames: bool = False, *, threads=None, out=None) -> np.ndarray:
        """End-effector pose T_w_e, shape (..., 4, 4) (as :func:`denavit.forward_kinematics`); with
        ``frames=True`` the world poses of the DH frames {0} … {N}, shape (..., N+1, 4, 4) (as
        :func:`denavit.link_transforms`, tool not applied)."""
        if (out is None and not frames and q.__class__ is _ndarray and q.dtype is _F64 and q.shape == self._vec
                and q.strides == _STRIDE):
            out = _empty(_SHAPE44)
            self._fk_1(q, out)
            return out
        return self._call("frames" if frames else "fk", (q,), ("q",), threads, out)

    def position(self, q, *, threads=None, out=None) -> np.ndarray:
        """End-effector origin p_w_e, shape (..., 3): ``fk(q)[..., :3, 3]`` from a kernel that computes only
        what the origin needs (for workspace sampling)."""
        if (out is None and q.__class__ is _ndarray and q.dtype is _F64 and q.shape == self._vec
                and q.strides == _STRIDE):
            out = _empty(_SHAPE3)
            self._position_1(q, out)
            return out
        return self._call("position", (q,), ("q",), threads, out)

    def jacobian(self, q, frame: Frame | str = "base", *, threads=None, out=None) -> np.ndarray:
        """Geometric Jacobian, shape (..., 6, n), rows (v, ω): ``base`` J0 or ``tool`` Je (as
        :func:`denavit.geometric_jacobian`)."""
        if frame == "base" or frame is Frame.BASE:
            if (out is None and q.__class__ is _ndarray and q.dtype is _F64 and q.shape == self._vec
                    and q.strides == _STRIDE):
                out = _empty(self._jshape)
                self._jacobian0_1(q, out)
                return out
            return self._call("jacobian0", (q,), ("q",), threads, out)
        if frame == "tool" or Frame(frame) is Frame.TOOL:
            if (out is None and q.__class__ is _ndarray and q.dtype is _F64 and q.shape == self._vec
                    and q.strides == _STRIDE):
                out = _empty(self._jshape)
                self._jacobiane_1(q, out)
                return out
            return self._call("jacobiane", (q,), ("q",), threads, out)
        raise ValueError(f"frame must be 'base' or 'tool', got {frame!r}")  # pragma: no cover (Frame raises)

    # --- dynamics -------------------------------------------------------------------------------------------
    def rnea(self, q, qd, qdd, *, threads=None, out=None) -> np.ndarray:
        """Inverse dynamics τ = M q̈ + C q̇ + g + τ_f, shape (..., n) (as :func:`denavit.rnea` with the robot's
        gravity and friction)."""
        if (out is None and q.__class__ is _ndarray and qd.__class__ is _ndarray and qdd.__class__ is _ndarray
                and q.dtype is _F64 and qd.dtype is _F64 and qdd.dtype is _F64
                and q.shape == self._vec and qd.shape == self._vec and qdd.shape == self._vec
                and q.strides == qd.strides == qdd.strides == _STRIDE):
            out = _empty(self._vec)
            self._rnea_1(q, qd, qdd, out)
            return out
        return self._call("rnea", (q, qd, qdd), ("q", "qd", "qdd"), threads, out)

    def mass_matrix(self, q, *, threads=None, out=None) -> np.ndarray:
        """M(q), shape (..., n, n) (as :func:`denavit.mass_matrix`)."""
        if (out is None and q.__class__ is _ndarray and q.dtype is _F64 and q.shape == self._vec
                and q.strides == _STRIDE):
            out = _empty(self._mshape)
            self._mass_matrix_1(q, out)
            return out
        return self._call("mass_matrix", (q,), ("q",), threads, out)

    def gravity(self, q, *, threads=None, out=None) -> np.ndarray:
        """g(q), shape (..., n) (as :func:`denavit.gravity_torques` with the robot's gravity)."""
        if (out is None and q.__class__ is _ndarray and q.dtype is _F64 and q.shape == self._vec
                and q.strides == _STRIDE):
            out = _empty(self._vec)
            self._gravity_1(q, out)
            return out
        return self._call("gravity", (q,), ("q",), threads, out)

    def coriolis(self, q, qd, *, threads=None, out=None) -> np.ndarray:
        """c(q, q̇) = C(q, q̇) q̇, shape (..., n) (as :func:`denavit.coriolis_vector`)."""
        return self._call("coriolis", (q, qd), ("q", "qd"), threads, out)

    def forward_dynamics(self, q, qd, tau, *, threads=None) -> np.ndarray:
        """q̈ = M⁻¹ (τ − c − g − τ_f), shape (..., n) (as :func:`denavit.forward_dynamics`); ModelError where
        M is singular."""
        if (q.__class__ is _ndarray and qd.__class__ is _ndarray and tau.__class__ is _ndarray
                and q.dtype is _F64 and qd.dtype is _F64 and tau.dtype is _F64
                and q.shape == self._vec and qd.shape == self._vec and tau.shape == self._vec
                and q.strides == qd.strides == tau.strides == _STRIDE):
            r = _empty(self._fshape)
            self._forward_dynamics_1(q, qd, tau, r)
        else:
            r = self._call("forward_dynamics", (q, qd, tau), ("q", "qd", "tau"), threads)
        if r.ndim == 1:
            if not r[-1] > 0.0:
                self._singular()
        elif not (r[..., -1] > 0.0).all():
            self._singular()
        return r[..., :-1]

    def _singular(self):
        raise ModelError(f"robot {self.robot.name!r}: the mass matrix is singular at this configuration "
                         "(a joint whose subtree has no inertia about its axis)")
