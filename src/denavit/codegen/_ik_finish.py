"""What the compiled closed forms share and numba is not needed for: the folding edge and the packing of their
constants.  The step they end with (verification, folding, merging, sorting) is :mod:`._ik_nb_finish`.
"""

from __future__ import annotations

__all__ = ["DOUBLE_ROOT", "FOLD_EDGE", "pack_constants"]

#: Distance [rad, m] of a folded candidate from a decision of the folding — a joint limit, the limit ∓ 2π, or ±π where
#: angles wrap — under which the pose goes to the plain solver: a rounding difference there moves a solution by a
#: whole turn or across a limit (hypothesis found q3 = −1.3e-15 against the plain solver's +0 at a limit of −2π).
FOLD_EDGE = 1e-9
#: |ratio| of an arccos-type root (shoulder q1, elbow q3) within this of 1: next to a double root, the plain solver
#: polishes and looks for the lost partner; beyond it both roots are verified as they are (a root needing
#: polishing goes to the plain solver through ik_finish's residual test either way)
DOUBLE_ROOT = 1e-9


def pack_constants(values: dict, layout: tuple, what: str):
    """The constants of a closed-form kernel as one float64 vector, ``layout``'s (name, size) pairs in order (one
    argument to unbox per call instead of twenty); ValueError naming ``what`` if the sizes do not add up."""
    import numpy as np

    K = np.concatenate([np.asarray(values[name], dtype=np.float64).ravel() for name, _ in layout])
    expected = sum(size for _, size in layout)
    if K.size != expected:
        raise ValueError(f"{what} IK constants: {K.size} numbers for the layout's {expected}")
    return K
