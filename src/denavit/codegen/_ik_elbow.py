"""Analytic IK on the compiled kernels: the elbow + spherical-wrist closed form, its constants.

The same formulas as :class:`denavit.ik._closed.ElbowPosition` and ``wrist_angles`` — the very functions of
:mod:`denavit.ik.forms` (Craig 3rd ed. Sec. 4.7; Paden–Kahan subproblems 1 and 2; the digit-keeping half-angle
forms), compiled by numba in :mod:`._ik_nb_elbow` — for the eight candidates of one pose at a time, each verified by
the FK of the arm's chain, folded into the joint limits, merged when equal and labelled (shoulder, elbow, wrist: the
tests of docs/ik.md).

Every case the plain solver treats specially is handed back to it (``status`` 1): a joint left free by the
pose (wrist centre on axis 1 or 2, wrist axes aligned), a root next to a double root (|ratio| near 1), a
candidate that would need polishing, or two solutions closer than the merge radius.  The compiled path answers
only where its answer is the plain solver's.  This module holds what needs no numba: the layout of the constants.
"""

from __future__ import annotations

__all__ = ["ELBOW_LAYOUT"]

#: The constants of ``ik_elbow_packed``'s vector K, in order, with their sizes (303 numbers for a 6R arm; "chain":
#: the chain's constants C0 … C6, whose FK verifies the candidates; "trig": ``forms.wrist_constants`` of the wrist and
#: cos, sin of the elbow's base angle).  The 4×4 blocks come first and the 3-vectors and 3×3 blocks next, so that
#: the kernel views each group with one reshape (a reshape is a helper call; views of its rows are free).
ELBOW_LAYOUT = (("C0i", 16), ("consts", 64), ("chain", 112), ("R6", 9), ("R1", 9), ("R2", 9), ("R4", 9), ("R5", 9),
                ("X_e", 3), ("p1", 3), ("a", 3), ("p2", 3), ("P", 3), ("scalars", 9), ("trig", 10), ("lo", 6),
                ("hi", 6), ("revolute", 6), ("theta", 6), ("tols", 8))
