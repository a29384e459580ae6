"""The shared closed forms of :mod:`denavit.ik` (``denavit.ik.forms``) made callable from numba-compiled code.

Every function of ``forms.JITTABLE`` is registered with ``numba.extending.register_jitable`` (numba compiles the
very function the plain solver runs on numpy batches, inlined into each compiled caller), and ``forms.select``
gets its scalar meaning ``a if c else b`` (``np.where`` would make a 0-d array of each choice).  Importing this
module is what registers them: the compiled closed forms import their names from here.  The generated modules'
cache key covers the ik package's sources (:mod:`._cache`), so a changed formula never meets a stale kernel.
"""

from __future__ import annotations

from numba.extending import overload, register_jitable

from ..ik import forms

__all__ = ["WRIST_TOL", "half_angle", "elbow_plane", "elbow_q2", "elbow_roots", "shoulder_roots", "wrist_qb",
           "wrist_rest", "stanford_q1", "stanford_q2", "stanford_q3", "trig_roots"]


@overload(forms.select, jit_options={"nogil": True})
def _select(c, a, b):
    return lambda c, a, b: a if c else b


for _f in forms.JITTABLE:
    register_jitable(_f)

WRIST_TOL, half_angle = forms.WRIST_TOL, forms.half_angle
elbow_plane, elbow_q2, elbow_roots = forms.elbow_plane, forms.elbow_q2, forms.elbow_roots
shoulder_roots, wrist_qb, wrist_rest = forms.shoulder_roots, forms.wrist_qb, forms.wrist_rest
stanford_q1, stanford_q2, stanford_q3 = forms.stanford_q1, forms.stanford_q2, forms.stanford_q3
trig_roots = forms.trig_roots
