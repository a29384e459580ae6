"""The finite Fourier series of the excitation trajectories, its limits as linear constraints, and the scaling
that makes the limits hold at every instant (the notes of :mod:`denavit.calibration._excite`).

x = [q_0, a_1 … a_H, b_1 … b_H] per joint: q = P x, q̇ = V x, q̈ = A x with P, V, A from :func:`fourier_basis`.
"""

from __future__ import annotations

import numpy as np

__all__ = ["feasible_start", "fourier_basis", "fourier_series", "limit_constraints", "within_limits"]

CHECK_PER_HARMONIC = 256  # instants per period and harmonic of the all-instants check


def fourier_series(q0, a, b, base_freq: float, t) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """q, q̇, q̈ of the finite Fourier series (module equation) at times ``t``.

    Parameters
    ----------
    q0 : array_like, shape (n,)
    a, b : array_like, shape (n, H)
    base_freq : float
        f [Hz].
    t : array_like, shape (k,)
        [s].

    Returns
    -------
    q, qd, qdd : ndarray, shape (k, n)
    """
    a, b = np.atleast_2d(np.asarray(a, dtype=float)), np.atleast_2d(np.asarray(b, dtype=float))
    X = np.concatenate([np.asarray(q0, dtype=float).reshape(-1, 1), a, b], axis=1)  # (n, 2H + 1)
    P, V, A = fourier_basis(np.asarray(t, dtype=float).reshape(-1), a.shape[1], 2 * np.pi * base_freq)
    return P @ X.T, V @ X.T, A @ X.T


def fourier_basis(t: np.ndarray, H: int, w: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """P, V, A of shape (k, 2H + 1) with q = P x, q̇ = V x, q̈ = A x, x = [q0, a_1..a_H, b_1..b_H]."""
    wl = w * np.arange(1, H + 1)  # (H,)
    s, c = np.sin(np.outer(t, wl)), np.cos(np.outer(t, wl))  # (k, H)
    one, zero = np.ones((t.size, 1)), np.zeros((t.size, 1))
    return (np.hstack([one, s / wl, -c / wl]), np.hstack([zero, c, s]), np.hstack([zero, -s * wl, c * wl]))


def limit_constraints(t: np.ndarray, H: int, w: float, window, qd_max, qdd_max) -> tuple[np.ndarray, np.ndarray]:
    """C, d with C x + d ≥ 0 ⇔ the limits hold at ``t``; rows scaled by their limit (width, q̇_max, q̈_max)."""
    P, V, A = fourier_basis(t, H, w)
    n, k = len(qd_max), P.shape[1]
    blocks, offsets = [], []
    for j in range(n):
        lo, hi = window[j]
        width = hi - lo
        rows = [-P / width, P / width, -V / qd_max[j], V / qd_max[j], -A / qdd_max[j], A / qdd_max[j]]
        consts = [hi / width, -lo / width, 1.0, 1.0, 1.0, 1.0]
        block = np.zeros((6 * t.size, n * k))
        block[:, j * k:(j + 1) * k] = np.vstack(rows)
        blocks.append(block)
        offsets.append(np.repeat(consts, t.size))
    return np.vstack(blocks), np.concatenate(offsets)


def feasible_start(rng: np.random.Generator, t, H: int, w: float, window, qd_max, qdd_max) -> np.ndarray:
    """A random feasible start: q0 mid-window, coefficients ~ U(−1, 1)/l scaled to 0.9 of what the limits allow."""
    n = len(qd_max)
    P, V, A = fourier_basis(t, H, w)
    decay = np.tile(1.0 / np.arange(1, H + 1), 2)
    X = np.zeros((n, 2 * H + 1))
    for j in range(n):
        X[j, 1:] = rng.uniform(-1.0, 1.0, 2 * H) * decay
        half = (window[j, 1] - window[j, 0]) / 2
        peak = [np.abs(M[:, 1:] @ X[j, 1:]).max() / lim for M, lim in ((P, half), (V, qd_max[j]), (A, qdd_max[j]))]
        X[j, 1:] *= 0.9 / max(max(peak), 1e-300)
        X[j, 0] = window[j].mean()
    return X.ravel()


def within_limits(x: np.ndarray, span: float, H: int, w: float, window, qd_max, qdd_max) -> np.ndarray:
    """x with each joint's oscillation scaled down (never up) so the limits hold at every t in [0, span].

    On a grid of spacing h, f ≤ c at the grid points and |f''| ≤ M give f ≤ c + M h²/8 in between (the maximum's
    nearest grid point is within h/2 of it, where f' = 0).  M is bounded by Σ_l (ω l)^k |c_l|, |c_l| = |(a_l, b_l)|,
    k = 1, 2, 3 for q, q̇, q̈.
    """
    n = len(qd_max)
    grid = np.linspace(0.0, span, int(np.ceil(CHECK_PER_HARMONIC * H * span * w / (2 * np.pi))) + 2)
    h = grid[1] - grid[0]
    P, V, A = fourier_basis(grid, H, w)
    X = x.reshape(n, 2 * H + 1).copy()
    wl = w * np.arange(1, H + 1)
    for j in range(n):
        X[j, 0] = np.clip(X[j, 0], *window[j])
        c = np.hypot(X[j, 1:H + 1], X[j, H + 1:])
        e_q, e_qd, e_qdd = (np.sum(wl**k * c) * h**2 / 8 for k in (1, 2, 3))
        f = P[:, 1:] @ X[j, 1:]  # q − q0
        room_up, room_down = max(window[j, 1] - X[j, 0], 1e-300), max(X[j, 0] - window[j, 0], 1e-300)
        need = [(f.max() + e_q) / room_up, (e_q - f.min()) / room_down,
                (np.abs(V @ X[j]).max() + e_qd) / qd_max[j], (np.abs(A @ X[j]).max() + e_qdd) / qdd_max[j]]
        worst = max(need)
        if worst > 1.0:
            X[j, 1:] /= worst
    return X.ravel()
