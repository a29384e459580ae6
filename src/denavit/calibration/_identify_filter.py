"""Joint rates and accelerations from sampled joint positions: a zero-phase low-pass filter, then central
differences — the same filter applied to the torques (Gautier 1997, "parallel filtering").

q(t_i) sampled at a constant rate f_s is filtered forwards and backwards by a Butterworth low-pass of order
``order`` and cut-off ``cutoff`` (``scipy.signal.butter`` + ``sosfiltfilt``: no phase lag, the amplitude response
squared, so −6 dB at the cut-off); q̇ and q̈ are the central differences of the filtered q
(``numpy.gradient``: (q_{i+1} − q_{i−1}) / 2Δt, second-order one-sided at the ends), applied twice.  The torques
pass through the very same filter, so that the filter's attenuation near the cut-off acts alike on both sides of
τ = Y(q, q̇, q̈) π.  ``edge`` samples at each end (one period of the cut-off) are dropped: there the forward-
backward filter and the one-sided differences are least accurate.
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["DEFAULT_CUTOFF", "FILTER_ORDER", "MAX_JITTER", "differentiate"]

#: Cut-off [Hz] when none is given: 10 Hz (robot excitation trajectories stay below ~2 Hz), at most f_s / 5.
DEFAULT_CUTOFF = 10.0
#: Order of the Butterworth low-pass (run forwards and backwards: an effective order of twice that).
FILTER_ORDER = 4
#: Largest accepted deviation of one sampling interval from the mean interval, relative (the filter and the
#: differences assume a constant rate).
MAX_JITTER = 0.01


def differentiate(t, q: np.ndarray, tau: np.ndarray, cutoff: float | None = None, order: int = FILTER_ORDER):
    """(q, q̇, q̈, τ, kept, text): the filtered q and τ with q̇, q̈ of the module's filter, on the samples ``kept``
    (a slice: the ends are dropped), and one line saying which filter was used.

    Parameters
    ----------
    t : array_like, shape (N,)
        Sample times [s], strictly increasing at a constant rate (within :data:`MAX_JITTER`).
    q, tau : ndarray, shape (N, n)
        Joint positions and torques at those times.
    cutoff : float, optional
        Cut-off frequency [Hz] (default min(:data:`DEFAULT_CUTOFF`, f_s / 5)); below the Nyquist frequency f_s / 2.
    """
    from scipy.signal import butter, sosfiltfilt

    t = np.asarray(t, dtype=float)
    N = q.shape[0]
    if t.ndim != 1 or t.shape[0] != N:
        raise ValueError(f"t: expected shape ({N},) (one time per sample), got {t.shape}")
    if not np.all(np.isfinite(t)):
        raise ValueError("t has non-finite values (NaN or inf)")
    dt = np.diff(t)
    if N < 3 or not np.all(dt > 0):
        k = int(np.argmax(dt <= 0)) + 1 if N >= 3 else 0
        raise ValueError("t must be strictly increasing with at least 3 samples"
                         + (f" (sample {k + 1}: t = {t[k]:.9g} after {t[k - 1]:.9g})" if N >= 3 else f", got {N}"))
    step = float(np.mean(dt))
    jitter = float(np.max(np.abs(dt - step)) / step)
    if jitter > MAX_JITTER:
        raise ValueError(f"t: the sampling interval varies by {100 * jitter:.3g} % (at most {100 * MAX_JITTER:g} % "
                         "is accepted: resample at a constant rate, or give qd and qdd)")
    fs = 1.0 / step
    fc = min(DEFAULT_CUTOFF, fs / 5) if cutoff is None else float(cutoff)
    if not (0 < fc < fs / 2):
        raise ValueError(f"filter cut-off {fc:g} Hz: must be > 0 and below the Nyquist frequency {fs / 2:g} Hz")
    edge = max(2, math.ceil(fs / fc))
    if N <= 2 * edge + 3 * (2 * order + 1):
        raise ValueError(f"{N} samples are too few for the {fc:g} Hz filter at {fs:g} Hz ({2 * edge} are dropped at "
                         "the ends): record longer or give qd and qdd")
    sos = butter(order, fc / (fs / 2), output="sos")
    qf = sosfiltfilt(sos, q, axis=0)
    tauf = sosfiltfilt(sos, tau, axis=0)
    qd = np.gradient(qf, step, axis=0, edge_order=2)
    qdd = np.gradient(qd, step, axis=0, edge_order=2)
    keep = slice(edge, N - edge)
    text = (f"q filtered by a zero-phase Butterworth low-pass (order {order}, forwards and backwards, cut-off "
            f"{fc:g} Hz, sampling {fs:g} Hz), qd and qdd by central differences, tau filtered alike; "
            f"{edge} samples dropped at each end")
    return qf[keep], qd[keep], qdd[keep], tauf[keep], keep, text
