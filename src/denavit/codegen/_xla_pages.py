"""Output buffers for the JAX kernels' blocks: on Linux CPU uninitialised and advised huge pages, as numpy's are.

Why: XLA's CPU client allocates every result afresh with ``posix_memalign``; glibc maps each block above 32 MB
with a fresh ``mmap`` and frees it with ``munmap``, so a 10⁶-pose float64 FK result (128 MB) costs 31,251 page
faults of 4 KB on every call — 75-80 ms of CPU, more than the numba batch kernel's whole FK.  numpy, where numba's
output comes from, advises the kernel to back its large arrays with 2-MB pages (``madvise(MADV_HUGEPAGE)``, numpy
≥ 1.22): 64 faults for the same array.  :func:`output_buffer` gives XLA's buffer the same advice, from inside the
compiled program: an XLA FFI custom call (the typed FFI of ``xla/ffi/api/c_api.h``, written here with ctypes:
no compiler, no extension module) that receives the buffer XLA allocated for its result, advises its 2-MB-aligned
interior and writes nothing.  The kernels' blocks then write every row of it (``_blocked`` in the generated
module), so no value of the uninitialised buffer is ever read, and XLA's pass writing zeros into the whole output
goes too.  Nothing else of the process changes: no allocator setting, no environment variable; the advice lives
and dies with that buffer's mapping.

Elsewhere (not Linux, another platform than CPU at lowering, a jax without ``jax.ffi``, or a runtime refusing the
handler's registration) it is ``jnp.zeros``, as before.  A program holding the custom call cannot be serialised
by ``jax.export`` without ``DisabledSafetyCheck.custom_call(TARGET)``.
"""

from __future__ import annotations

import ctypes
import math
import sys
import threading

__all__ = ["output_buffer", "TARGET"]

TARGET = "denavit_output_buffer"  #: the FFI target's name in XLA's registry (CPU)
_MADV_HUGEPAGE = 14  # linux/mman.h
_HUGE = 1 << 21  # x86-64 and arm64 (4-KB base pages): a PMD, the size transparent huge pages come in
_ADVISE_FROM = 1 << 22  # numpy's threshold for its own advice (numpy/core/src/multiarray/alloc.c)
_ITEMSIZE = {10: 2, 11: 4, 12: 8, 16: 2}  # XLA_FFI_DataType F16, F32, F64, BF16
_API_VERSION = (0, 1)  # the oldest typed-FFI version whose structs (below) the runtime accepts (jaxlib 0.10: 0.1-0.3)

_size_t, _ptr, _i64, _int = ctypes.c_size_t, ctypes.c_void_p, ctypes.c_int64, ctypes.c_int


class _ExtensionBase(ctypes.Structure):  # XLA_FFI_Extension_Base
    _fields_ = [("struct_size", _size_t), ("type", _int), ("next", _ptr)]


class _ApiVersion(ctypes.Structure):  # XLA_FFI_Api_Version
    _fields_ = [("struct_size", _size_t), ("extension_start", _ptr), ("major", _int), ("minor", _int)]


class _Metadata(ctypes.Structure):  # XLA_FFI_Metadata (up to traits)
    _fields_ = [("struct_size", _size_t), ("api_version", _ApiVersion), ("traits", ctypes.c_uint32)]


_METADATA_SIZE = _Metadata.traits.offset + ctypes.sizeof(ctypes.c_uint32)  # XLA_FFI_Metadata_STRUCT_SIZE


class _MetadataExtension(ctypes.Structure):  # XLA_FFI_Metadata_Extension
    _fields_ = [("base", _ExtensionBase), ("metadata", ctypes.POINTER(_Metadata))]


class _Sequence(ctypes.Structure):  # XLA_FFI_Args and XLA_FFI_Rets share this layout
    _fields_ = [("struct_size", _size_t), ("extension_start", _ptr), ("size", _i64), ("types", _ptr),
                ("items", ctypes.POINTER(_ptr))]


class _CallFrame(ctypes.Structure):  # XLA_FFI_CallFrame, up to rets (attrs and future are not read)
    _fields_ = [("struct_size", _size_t), ("extension_start", ctypes.POINTER(_ExtensionBase)), ("api", _ptr),
                ("ctx", _ptr), ("stage", _int), ("args", _Sequence), ("rets", _Sequence)]


class _Buffer(ctypes.Structure):  # XLA_FFI_Buffer
    _fields_ = [("struct_size", _size_t), ("extension_start", _ptr), ("dtype", _int), ("data", _ptr),
                ("rank", _i64), ("dims", ctypes.POINTER(_i64))]


def _answer_metadata(frame: _CallFrame) -> None:
    """XLA asks each handler once, at registration, which FFI version it was written for (and its traits)."""
    ext = ctypes.cast(frame.extension_start, ctypes.POINTER(_MetadataExtension)).contents
    if ext.base.struct_size < ctypes.sizeof(_MetadataExtension) or not ext.metadata:
        return
    md = ext.metadata.contents
    if md.struct_size >= _METADATA_SIZE:
        md.api_version.major, md.api_version.minor = _API_VERSION
        md.traits = 0


def _advise(frame: _CallFrame, madvise) -> None:
    """madvise(MADV_HUGEPAGE) on the 2-MB pages lying wholly inside the result buffer (≥ 4 MB; nothing written)."""
    if (frame.struct_size < ctypes.sizeof(_CallFrame) or frame.stage != 3  # XLA_FFI_ExecutionStage_EXECUTE
            or frame.rets.struct_size < ctypes.sizeof(_Sequence) or frame.rets.size != 1):
        return
    buf = ctypes.cast(frame.rets.items[0], ctypes.POINTER(_Buffer)).contents
    if buf.struct_size < ctypes.sizeof(_Buffer) or buf.dtype not in _ITEMSIZE or not buf.data:
        return
    nbytes = _ITEMSIZE[buf.dtype] * math.prod(buf.dims[i] for i in range(buf.rank))
    start, end = -(-buf.data // _HUGE) * _HUGE, (buf.data + nbytes) // _HUGE * _HUGE
    if nbytes >= _ADVISE_FROM and end > start:
        madvise(start, end - start, _MADV_HUGEPAGE)  # a failure (THP off) leaves 4-KB pages: nothing to report


def _make_handler():
    """The C-callable handler ``XLA_FFI_Error* (XLA_FFI_CallFrame*)``; it returns NULL (success) whatever happens:
    its only effect is the advice, and without it the buffer is still a valid, wholly overwritten output."""
    libc = ctypes.CDLL(None, use_errno=True)
    madvise = libc.madvise
    madvise.argtypes, madvise.restype = (_ptr, _size_t, _int), _int

    @ctypes.CFUNCTYPE(_ptr, ctypes.POINTER(_CallFrame))
    def handler(frame_p):
        try:
            frame = frame_p.contents
            if frame.extension_start and frame.extension_start.contents.type == 1:  # XLA_FFI_Extension_Metadata
                _answer_metadata(frame)
            else:
                _advise(frame, madvise)
        except Exception:  # noqa: BLE001 - nothing may propagate into XLA's C++ (see the docstring)
            pass
        return None

    return handler


_LOCK = threading.Lock()
_STATE: list[bool] = []  # [registered]: decided once per process
_HANDLERS: list = []  # the handler, referenced for the process whatever happened (XLA may keep its address)


def _registered() -> bool:
    """Register the FFI target once per process (after the CPU backend is up, so that a refusal raises here
    rather than failing the backend's start); False when it cannot be."""
    with _LOCK:
        if not _STATE:
            ok = False
            if sys.platform.startswith("linux"):
                try:
                    import jax
                    import jax.ffi

                    jax.devices("cpu")
                    _HANDLERS.append(_make_handler())
                    jax.ffi.register_ffi_target(TARGET, jax.ffi.pycapsule(ctypes.cast(_HANDLERS[0], _ptr).value),
                                                platform="cpu")
                    ok = True
                except Exception:  # noqa: BLE001 - old jax (no jax.ffi), no CPU backend, a refused version
                    ok = False
            _STATE.append(ok)
        return _STATE[0]


def output_buffer(shape, dtype):
    """An array of ``shape`` and ``dtype`` for a result the caller overwrites entirely, inside a traced JAX
    function: on Linux CPU XLA's buffer left uninitialised and advised huge pages (see the module docstring),
    elsewhere zeros.  Its values must not be read before they are written."""
    import jax
    import jax.numpy as jnp

    def zeros():
        return jnp.zeros(shape, dtype)

    if not _registered():
        return zeros()

    def advised():
        return jax.ffi.ffi_call(TARGET, jax.ShapeDtypeStruct(shape, dtype))()

    return jax.lax.platform_dependent(cpu=advised, default=zeros)
