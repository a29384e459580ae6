"""Joint rates and accelerations from sampled joint positions: a zero-phase low-pass filter, then central
differences — the same filter applied to the torques and to every column of the regressor (Gautier 1997,
"parallel filtering").

q(t_i) sampled at a constant rate f_s is filtered forwards and backwards by a Butterworth low-pass of order
``order`` and cut-off ``cutoff`` (``scipy.signal.butter`` + ``sosfiltfilt``: no phase lag, the amplitude response
squared, so −6 dB at the cut-off); q̇ and q̈ are the central differences of the filtered q
(``numpy.gradient``: (q_{i+1} − q_{i−1}) / 2Δt, second-order one-sided at the ends), applied twice.  The torques
and the columns of Y(q, q̇, q̈) pass through the very same filter: since π is constant, filter(τ) = filter(Y) π
holds exactly, also for the Coulomb column sign(q̇) whose steps a filtered τ smooths (filtering τ alone would bias
the friction estimates).  The filtered samples are then decimated to every ⌊f_s / 2f_c⌋-th one (Gautier 1997):
filtered noise is correlated over about that many samples, and least squares that counted each as independent
would give σ too small by about the square root of that factor.  ``edge`` samples at each end (:data:`EDGE` periods of the cut-off) are dropped: there the forward-
backward filter and the one-sided differences are least accurate; the signals are extended by odd reflection
over :data:`PAD` such periods before filtering.
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
#: Samples dropped at each end, in periods of the cut-off (the end transient of q̈ is < 1 % of its amplitude there).
EDGE = 2
#: Samples of odd extension added at each end before filtering, in periods of the cut-off.
PAD = 5


def differentiate(t, q: np.ndarray, cutoff: float | None = None, order: int = FILTER_ORDER):
    """(q, q̇, q̈, smooth, kept, text): the filtered q with q̇, q̈ of the module's filter at every sample, the
    filter itself (``smooth(x)`` filters an array along its first axis: for τ and the regressor's columns), the
    samples to keep (a slice: the ends are dropped) and one line saying which filter was used.

    Parameters
    ----------
    t : array_like, shape (N,)
        Sample times [s], strictly increasing at a constant rate (within :data:`MAX_JITTER`).
    q : ndarray, shape (N, n)
        Joint positions at those times.
    cutoff : float, optional
        Cut-off frequency [Hz] (default min(:data:`DEFAULT_CUTOFF`, f_s / 5)); below the Nyquist frequency f_s / 2.
    """
    from scipy.signal import butter, sosfiltfilt

    N = q.shape[0]
    step = _step(t, N)
    fs = 1.0 / step
    fc = min(DEFAULT_CUTOFF, fs / 5) if cutoff is None else float(cutoff)
    if not (0 < fc < fs / 2):
        raise ValueError(f"filter cut-off {fc:g} Hz: must be > 0 and below the Nyquist frequency {fs / 2:g} Hz")
    edge = max(2, math.ceil(EDGE * fs / fc))
    if N <= 2 * edge + 3 * (2 * order + 1):
        raise ValueError(f"{N} samples are too few for the {fc:g} Hz filter at {fs:g} Hz ({2 * edge} are dropped at "
                         "the ends): record longer or give qd and qdd")
    sos = butter(order, fc / (fs / 2), output="sos")
    pad = min(N - 1, PAD * edge)  # odd extension at each end (scipy's default, 27 samples, leaves q̈ transients)

    def smooth(x: np.ndarray) -> np.ndarray:
        return sosfiltfilt(sos, x, axis=0, padlen=pad)

    qf = smooth(q)
    qd = np.gradient(qf, step, axis=0, edge_order=2)
    qdd = np.gradient(qd, step, axis=0, edge_order=2)
    every = max(1, int(fs / (2 * fc)))  # decimation to the filtered band's Nyquist rate: residuals ~ white again
    keep = slice(edge, N - edge, every)
    text = (f"q filtered by a zero-phase Butterworth low-pass (order {order}, forwards and backwards, cut-off "
            f"{fc:g} Hz, sampling {fs:g} Hz), qd and qdd by central differences, tau and the regressor filtered "
            f"alike; {edge} samples dropped at each end, then one in {every} kept (decimation)")
    return qf, qd, qdd, smooth, keep, text


def _step(t, N: int) -> float:
    """The sampling interval of ``t`` (N,), checked: finite, strictly increasing, uniform within MAX_JITTER."""
    t = np.asarray(t, dtype=float)
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
    return step
