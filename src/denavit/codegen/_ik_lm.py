"""Numeric IK in each generated numba module: the Levenberg–Marquardt of :mod:`denavit.ik.lm` (one implementation:
the plain ``solve_ik`` runs the same code) compiled with the module's own fused FK + Jacobian kernel.

A generated module holds only the binding (:func:`ik_lm_lines`): ``ik_lm(...)``, an ``njit(cache=True)`` function
of that module calling the ``solve`` that :func:`denavit.ik.lm.bind` makes for its ``fk_jacobian0_1``, so numba
specialises the LM for that arm's kernel and caches the machine code with the module (whose cache key holds the
digest of ``denavit/ik``: a changed LM never meets a stale one).
"""

from __future__ import annotations

__all__ = ["ik_lm_lines", "numba_ik_lm"]

_REGISTERED: list[bool] = []

_ARGS = "T, q0, lo, hi, slo, shi, revolute, w, L, tol, max_iterations, restarts, seed, first, out_q, out_info"


def numba_ik_lm(fkj, owner: str):
    """``(solve, check)`` for the generated numba module ``owner`` (its ``__name__``): the ``solve`` of
    :func:`denavit.ik.lm.bind` for the module's fused kernel ``fkj``, made callable from numba-compiled code with
    the functions it calls (``numba.extending.register_jitable``), and the targets' test ``ik_check(T, Q)`` (largest
    |RᵀR − I| entry; inf for a non-finite target, −1 for a non-finite seed).

    The two closures are named after ``owner``: numba names machine code by module, qualified name and a counter
    of its process, and every arm's closures share module and name; two arms compiled in two processes could get
    the same counter, and loaded from the cache into one process, one arm's ik_lm then ran the other's code (its
    kernel): the symbols must differ."""
    from numba.extending import register_jitable

    from ..ik import lm
    from ._ik_nb_finish import ik_check

    if not _REGISTERED:
        for f in lm.JITTABLE:
            register_jitable(f)
        _REGISTERED.append(True)
    attempt, solve = lm.bind(fkj)
    for f in (attempt, solve):
        f.__qualname__ = f"{owner}.{f.__name__}"
    register_jitable(attempt)
    register_jitable(solve)
    return solve, ik_check


def ik_lm_lines() -> list[str]:
    """The binding's text in a generated numba module (fixed: nothing of the robot or the user enters it)."""
    return ["from denavit.codegen import numba_ik_lm", "", "_lm_solve, ik_check = numba_ik_lm(fk_jacobian0_1, __name__)", "", "",
            "@njit(cache=True, nogil=True)", f"def ik_lm({_ARGS}):",
            '    """Levenberg-Marquardt of denavit.ik.lm (see there) on this arm\'s fused FK + J0 kernel."""',
            f"    _lm_solve({_ARGS})", ""]
