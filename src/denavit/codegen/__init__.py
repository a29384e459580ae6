"""Generated kernels: each arm's FK, Jacobians and dynamics as straight-line code (numba or numpy), and
exported as standalone C99 or Python source.  DESIGN.md's one bridge between the engines.

>>> import denavit
>>> fast = denavit.compile(denavit.load_robot("planar2r"), backend="numpy")
>>> fast.fk([0.0, 0.0])[:3, 3].tolist()
[2.0, 0.0, 0.0]
"""

from ._bridge import numeric_function
from ._cache import active_cache_dir, cache_dir, cache_info, clear_cache, numba_available, robot_key
from ._compiled import CompiledRobot, compile
from ._ik_lm import numba_ik_lm
from ._export import LANGUAGES, PREFIX_PATTERN, default_prefix, export_sources
from ._kernels import KERNEL_NAMES, KernelSpec, register_kernel, registered_kernels, trace_kernels
from ._llvm import kernel_intrinsic
from ._tensor import TensorRobot
from ._trace import Sym, Tape

__all__ = ["compile", "CompiledRobot", "TensorRobot", "export_sources", "default_prefix", "LANGUAGES", "PREFIX_PATTERN", "cache_dir",
           "active_cache_dir", "cache_info", "clear_cache", "numba_available", "robot_key", "KERNEL_NAMES", "KernelSpec",
           "register_kernel", "registered_kernels", "trace_kernels", "Sym", "Tape", "kernel_intrinsic", "numeric_function",
           "numba_ik_lm"]
