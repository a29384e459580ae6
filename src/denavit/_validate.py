"""Input checks at the public boundary: the one home of shape and value validation."""

from __future__ import annotations

from typing import Any

import numpy as np

from .errors import ShapeError

__all__ = ["as_joint_array", "as_transform", "as_vector", "checked_out"]


def as_joint_array(q: Any, n: int, name: str = "q") -> np.ndarray:
    """``q`` as a float array of shape (..., n); raise ShapeError/ValueError with a clear message."""
    try:
        arr = np.asarray(q, dtype=float)
    except (TypeError, ValueError):
        raise ShapeError(f"{name} must be numbers, shape (..., {n}); got {q!r:.80}") from None
    if arr.ndim == 0 or arr.shape[-1] != n:
        raise ShapeError(f"{name}: expected shape (..., {n}) for a {n}-joint robot, got {arr.shape}")
    if not np.all(np.isfinite(arr)):
        raise ShapeError(f"{name} has non-finite values (NaN or inf)")
    return arr


def as_vector(v: Any, n: int, name: str) -> np.ndarray:
    """A float array of shape (..., n) (same rules as :func:`as_joint_array`)."""
    return as_joint_array(v, n, name)


def as_transform(T: Any, name: str = "T") -> np.ndarray:
    """A float array of shape (..., 4, 4) whose rotation part is orthonormal."""
    arr = np.asarray(T, dtype=float)
    if arr.ndim < 2 or arr.shape[-2:] != (4, 4):
        raise ShapeError(f"{name}: expected shape (..., 4, 4), got {arr.shape}")
    if not np.all(np.isfinite(arr)):
        raise ShapeError(f"{name} has non-finite values")
    R = arr[..., :3, :3]
    err = np.abs(np.swapaxes(R, -1, -2) @ R - np.eye(3)).max() if arr.size else 0.0
    if err > 1e-6:
        raise ShapeError(f"{name}: rotation part is not orthonormal (error {err:.2g})")
    return arr


def checked_out(out: Any, shape: tuple[int, ...], name: str = "out") -> np.ndarray:
    """``out`` when it can take a result of ``shape`` in place: a writeable, C-contiguous float64 ndarray of exactly
    that shape (no broadcasting, no casting); ShapeError naming what was expected and what was given otherwise."""
    if (isinstance(out, np.ndarray) and out.dtype == np.float64 and out.shape == shape and out.flags.c_contiguous
            and out.flags.writeable):
        return out
    if not isinstance(out, np.ndarray):
        got = type(out).__name__
    else:
        flaws = [w for w, bad in (("not C-contiguous", not out.flags.c_contiguous),
                                  ("read-only", not out.flags.writeable)) if bad]
        got = f"{out.dtype} array of shape {out.shape}" + "".join(f", {w}" for w in flaws)
    raise ShapeError(f"{name}: expected a writeable C-contiguous float64 array of shape {shape}, got {got}")
