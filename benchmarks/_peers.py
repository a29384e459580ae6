"""Shared pieces of the benchmarks: peer-library models (see denavit.peers) and a timer."""

import time

import numpy as np

from denavit.peers import expand_q, to_pinocchio
from denavit.peers import to_roboticstoolbox as to_rtb

__all__ = ["best_time", "expand_q", "to_pinocchio", "to_rtb"]


def best_times(fns, repeat: int, number: int) -> list[float]:
    """Best over `repeat` rounds of the mean time of `number` calls [s] for each of `fns`, the functions taking turns
    within each round, so a burst of load on the shared machine reaches all of them alike."""
    best = [np.inf] * len(fns)
    for _ in range(repeat):
        for i, fn in enumerate(fns):
            t0 = time.perf_counter()
            for _ in range(number):
                fn()
            best[i] = min(best[i], (time.perf_counter() - t0) / number)
    return best


def best_time(fn, repeat: int, number: int) -> float:
    """Best over `repeat` runs of the mean time of `number` calls [s]."""
    best = np.inf
    for _ in range(repeat):
        t0 = time.perf_counter()
        for _ in range(number):
            fn()
        best = min(best, (time.perf_counter() - t0) / number)
    return best
