"""The one machine-code call behind ``CompiledRobot.analytic_ik`` for one pose: the target's check and the arm's
closed-form kernel (elbow, UR class or Stanford class: one entry each) in one compiled function, every output in
one float vector (one allocation and one call from Python; the check, the kernel call, two output arrays and the
result's views were half of a call's time).  Compiled once per machine (``cache=True``); imported only where numba is.

Layout of the output vector ``o`` (OUT_SIZE floats): ``o[:112]`` the (8, 14) block of the kernels (solutions,
residuals, solutions outside the limits), ``o[112:120]`` the label codes, ``o[120]`` kept, ``o[121]`` outside,
``o[122]`` status (0 answered, 1 for the plain solver, 2 a bad target), ``o[123:131]`` each kept solution's slot
in the plain solver's batched layout (its rank among the verified candidates), ``o[131]`` their number, ``o[132]``
the target's orthonormality error (inf for NaN or inf entries).  A batch runs the kernels over blocks of poses
(:mod:`._ik_nb_batch`).
"""

from __future__ import annotations

import math

from numba import njit

from ._ik_nb_elbow import ik_elbow_packed
from ._ik_nb_parallel import ik_parallel_packed
from ._ik_nb_stanford import ik_stanford_packed

__all__ = ["OUT_SIZE", "ENTRIES", "BAD_TARGET", "pose_error"]

OUT_SIZE = 133
#: a target whose rotation is this far from orthonormal (the largest |RᵀR − I| entry) is refused
BAD_TARGET = 1e-6


@njit(cache=True, nogil=True)
def pose_error(T):
    """The largest |RᵀR − I| entry of the 4×4 target T (the test of denavit's as_transform); inf if it holds a NaN
    or an infinity."""
    for i in range(4):
        for j in range(4):
            if not math.isfinite(T[i, j]):
                return math.inf
    worst = 0.0
    for i in range(3):
        for j in range(3):
            s = T[0, i] * T[0, j] + T[1, i] * T[1, j] + T[2, i] * T[2, j]
            worst = max(worst, abs(s - (1.0 if i == j else 0.0)))
    return worst


@njit(cache=True, nogil=True)
def _checked(T, o):
    """Record T's orthonormality error in o; False (status 2, nothing found) for a bad target."""
    err = pose_error(T)
    o[132] = err
    if err > BAD_TARGET:
        o[120], o[121], o[122] = 0.0, 0.0, 2.0
        return False
    return True


# one entry per kernel (each arm compiles only its own), for one pose (T (4, 4) C-contiguous, o (OUT_SIZE,))

@njit(cache=True, nogil=True)
def ik_one_elbow(T, K, o):
    """Every closed-form solution of the one pose T into o (layout in the module notes): the elbow kernel.  Returns
    the status o[122] (read from Python as a float, not as a numpy scalar)."""
    if _checked(T, o):
        ik_elbow_packed(T.reshape((1, 4, 4)), K, o[:112].reshape((1, 8, 14)), o[112:132].reshape((1, 20)))
    return o[122]


@njit(cache=True, nogil=True)
def ik_one_parallel(T, K, o):
    """:func:`ik_one_elbow` by the UR-class kernel."""
    if _checked(T, o):
        ik_parallel_packed(T.reshape((1, 4, 4)), K, o[:112].reshape((1, 8, 14)), o[112:132].reshape((1, 20)))
    return o[122]


@njit(cache=True, nogil=True)
def ik_one_stanford(T, K, o):
    """:func:`ik_one_elbow` by the Stanford-class kernel."""
    if _checked(T, o):
        ik_stanford_packed(T.reshape((1, 4, 4)), K, o[:112].reshape((1, 8, 14)), o[112:132].reshape((1, 20)))
    return o[122]


#: the one-pose entry of each closed form (the batch entries: :mod:`._ik_nb_batch`)
ENTRIES = {"elbow": ik_one_elbow, "parallel": ik_one_parallel, "stanford": ik_one_stanford}
