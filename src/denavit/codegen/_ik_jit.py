"""The shared closed forms of :mod:`denavit.ik` (``denavit.ik.forms``) made callable from numba-compiled code.

Every function of ``forms.JITTABLE`` is registered with ``numba.extending.register_jitable`` (numba compiles the
very function the plain solver runs on numpy batches, inlined into each compiled caller by numba's IR), and
``forms.select`` gets its scalar meaning ``a if c else b`` (``np.where`` would make a 0-d array of each choice) as
LLVM's ``select`` instruction: the lambda ``a if c else b`` stayed a call in large loop bodies, and a call stops
LLVM's loop vectoriser ("call instruction cannot be vectorized"; with the instruction a loop over poses of all of
``wrist_rest`` vectorises).  Importing this module is what registers them: the compiled closed forms import their
names from here.

numba keys the cached machine code of a function by its own file's modification time and size only, while the
kernels of ``codegen/_ik_nb_*.py`` inline :mod:`denavit.ik.forms` and each other: :func:`fresh_cache` keeps a
digest of all those sources beside numba's cache and drops the kernels' cache entries when it changes, so a
changed formula never meets a stale kernel.
"""

from __future__ import annotations

import hashlib
from pathlib import Path

from numba.core import types
from numba.extending import intrinsic, overload, register_jitable

from ..ik import forms

__all__ = ["fresh_cache", "WRIST_TOL", "atan2", "select", "half_angle", "elbow_plane", "elbow_q2", "elbow_roots", "shoulder_roots", "wrist_qb",
           "wrist_rest", "stanford_q1", "stanford_q2", "stanford_q3", "trig_roots",
           "trig_pairs", "wrist_constants"]


@intrinsic
def _select_ir(typingctx, c, a, b):
    """LLVM's ``select`` of two scalars (no branch: a loop of them stays vectorisable)."""
    ty = typingctx.unify_types(a, b)
    if not isinstance(c, types.Boolean) or not isinstance(ty, types.Number):
        return None

    def codegen(context, builder, sig, args):
        x, y = (context.cast(builder, v, t, ty) for v, t in zip(args[1:], sig.args[1:]))
        return builder.select(args[0], x, y)
    return ty(c, a, b), codegen


@overload(forms.select, jit_options={"nogil": True}, inline="always")
def _select(c, a, b):
    if isinstance(c, types.Boolean) and isinstance(a, types.Number) and isinstance(b, types.Number):
        return lambda c, a, b: _select_ir(c, a, b)
    return lambda c, a, b: a if c else b


for _f in forms.JITTABLE:
    register_jitable(inline="always")(_f)  # into each caller (numba's IR): no call passing arrays in a loop

WRIST_TOL, half_angle, atan2, select = forms.WRIST_TOL, forms.half_angle, forms.atan2, forms.select
elbow_plane, elbow_q2, elbow_roots = forms.elbow_plane, forms.elbow_q2, forms.elbow_roots
shoulder_roots, wrist_qb, wrist_rest = forms.shoulder_roots, forms.wrist_qb, forms.wrist_rest
wrist_constants = forms.wrist_constants
stanford_q1, stanford_q2, stanford_q3 = forms.stanford_q1, forms.stanford_q2, forms.stanford_q3
trig_roots, trig_pairs = forms.trig_roots, forms.trig_pairs

#: The stamp file kept beside numba's cache of the kernels: the SHA-256 of the sources they are compiled from.
STAMP = "denavit_ik_kernels.sha256"
_CHECKED: list[bool] = []


def kernel_sources() -> list[Path]:
    """The files whose text the closed-form kernels are compiled from (their own, the shared forms, this one)."""
    here = Path(__file__).resolve().parent
    return sorted(here.glob("_ik_nb_*.py")) + [here / "_ik_jit.py", here / "_ik_finish.py",
                                                  here.parent / "ik" / "_forms.py"]


def fresh_cache(*dispatchers, force: bool = False) -> None:
    """Before the kernels' first call in this process: where numba caches ``dispatchers``, compare the digest of
    :func:`kernel_sources` with the one stamped there (:data:`STAMP`); when they differ, remove the kernels' index
    files (``_ik_nb_*.nbi``: numba compiles them afresh) and stamp the new digest.  An unwritable cache is left
    alone (numba does not write there either)."""
    if _CHECKED and not force:
        return
    _CHECKED.append(True)
    h = hashlib.sha256()
    for path in kernel_sources():
        h.update(path.name.encode() + b"\0" + path.read_bytes())
    digest = h.hexdigest()
    for folder in {getattr(getattr(d, "_cache", None), "_cache_path", None) for d in dispatchers} - {None}:
        stamp = Path(folder) / STAMP
        try:
            if stamp.is_file() and stamp.read_text() == digest:
                continue
            for index in Path(folder).glob("_ik_nb_*.nbi"):
                index.unlink(missing_ok=True)
            Path(folder).mkdir(parents=True, exist_ok=True)
            stamp.write_text(digest)
        except OSError:
            continue
