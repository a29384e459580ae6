"""numba's compile of a generated kernel with LLVM's -O3 run once, not twice.

numba optimises the LLVM module of every function it compiles twice: each function alone by the -O3 function
pipeline (``CPUCodeLibrary._optimize_functions``: it shrinks ordinary numba code — reference counts, boxing,
bounds checks — before modules are linked and inlined), then the linked module by the full -O3 module pipeline,
which runs the same function simplification again.  A kernel is neither: its program is a straight line of
doubles written as IR by :mod:`denavit.codegen._llvm`, its common subexpressions already shared by the tracer.
The first pass buys it nothing and costs about a quarter of LLVM's optimisation time (InstCombine, dead-store
elimination and GVN over tens of thousands of instructions).  Measured on the Panda's base kernels: every fast-call
entry the same machine code, instruction for instruction, with and without it, the batch group 24,740 instructions
against 25,705.

So the kernels' compiles (and only theirs: the IK solvers in the same generated module are ordinary numba code and
keep numba's pipeline) run with that first pass reduced to what it does besides optimising (setting the module's
data layout), under numba's global compiler lock so that no other thread compiles meanwhile.  When numba's
internals are not those assumed here (the method is missing), the kernels compile as numba always does.
"""

from __future__ import annotations

import functools
from contextlib import contextmanager

__all__ = ["lean", "lean_kernels"]


def _layout_only(self, ll_module) -> None:
    """``CPUCodeLibrary._optimize_functions`` without the function passes (the data layout it sets is kept)."""
    ll_module.data_layout = self._codegen._data_layout


@contextmanager
def lean():
    """numba compiles made in this block skip the per-function -O3 pass (module docstring)."""
    from numba.core import codegen
    from numba.core.compiler_lock import global_compiler_lock

    library = getattr(codegen, "CPUCodeLibrary", None)
    original = library.__dict__.get("_optimize_functions") if library is not None else None
    if original is None:  # another numba: compile as it always does
        yield
        return
    with global_compiler_lock:  # re-entrant: nested blocks and numba's own locking inside are fine
        library._optimize_functions = _layout_only
        try:
            yield
        finally:
            library._optimize_functions = original


def lean_kernels(module) -> None:
    """Make every kernel dispatcher of a generated ``module`` (``<k>_1``, ``<k>_n`` for each kernel k with a
    program ``_<k>_steps``, and ``group_n``) compile in :func:`lean`; its other functions are left as they are."""
    names = ["group_n"]
    for attr in vars(module):
        if attr.startswith("_") and attr.endswith("_steps"):
            names += [f"{attr[1:-6]}_1", f"{attr[1:-6]}_n"]
    for name in names:
        dispatcher = getattr(module, name, None)
        compile_ = getattr(dispatcher, "compile", None)
        if compile_ is None or getattr(compile_, "_denavit_lean", False):
            continue

        @functools.wraps(compile_)
        def compile_lean(sig, _compile=compile_):
            with lean():
                return _compile(sig)

        compile_lean._denavit_lean = True
        dispatcher.compile = compile_lean
