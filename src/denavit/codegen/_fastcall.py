"""The single call without Python in the way: a kernel as a CPython built-in function.

A method such as ``fast.fk(q)`` spends more time in Python than in its kernel: checking q, ``np.empty`` for the
result, and numba's entry point (which unboxes each array into a struct, with a memory-manager record per array).
Here the kernel's program is emitted a second time, into a C function with CPython's *fast-call* convention
(``PyObject *f(PyObject *self, PyObject *const *args, Py_ssize_t nargs, PyObject *kwnames)``, METH_FASTCALL |
METH_KEYWORDS), which

1. checks each argument in machine code: exactly ``numpy.ndarray`` (not a subclass), the float64 dtype object,
   one dimension of the kernel input's length (any stride: elements are read at ``data + k·stride``);
2. allocates the result with numpy's own ``PyArray_New`` (C API slot 93) and writes the program's outputs into it;
3. hands every other call — keywords, other types, other shapes, batches — unchanged to ``self``, the Python
   method, which does what it always did.

numba compiles that function as a ``cfunc`` (cached on disk like the kernels, behind the same guard); the addresses
it needs (the ndarray type, the float64 dtype, ``PyArray_New``, ``PyObject_Vectorcall``) are given to LLVM's linker
by name in each process.  The function object is made once with ``PyCFunction_NewEx`` (ctypes, at setup only) and
put on the instance in place of the method.  The ``PyArrayObject`` field offsets (numpy's public struct) and the
API slot are checked on a real array at setup; if anything differs, or anything fails, the method stays as it was.
"""

from __future__ import annotations

import ctypes
import sys

import numpy as np

__all__ = ["entry_intrinsic", "install", "ENTRY_SUFFIX"]

#: the generated module's fast-call function of kernel <name> is <name><ENTRY_SUFFIX>
ENTRY_SUFFIX = "_entry"
_NPY_DOUBLE = 12
_PYARRAY_NEW_SLOT = 93  # numpy/__multiarray_api.h: PyArray_New, stable since numpy 1.0
#: PyArrayObject_fields (numpy/ndarraytypes.h) after PyObject_HEAD: data, nd, dimensions, strides, base, descr
_OFF_TYPE, _OFF_DATA, _OFF_ND, _OFF_DIMS, _OFF_STRIDES, _OFF_DESCR = 8, 16, 24, 32, 40, 56
_SYMBOLS = ("denavit_ndarray_type", "denavit_float64_descr", "denavit_pyarray_new", "denavit_vectorcall")
_STATE: dict = {}
_CFUNCS: dict = {}  # (generated module's name, kernel) -> its compiled CFunc, for every object of that module


class _MethodDef(ctypes.Structure):
    _fields_ = [("ml_name", ctypes.c_char_p), ("ml_meth", ctypes.c_void_p), ("ml_flags", ctypes.c_int),
                ("ml_doc", ctypes.c_char_p)]


_METH_FASTCALL_KEYWORDS = 0x0080 | 0x0002


def _setup() -> bool:
    """Give LLVM the addresses by name, once per process; False when this interpreter or numpy is not the layout
    assumed here (then nothing is installed)."""
    if "ok" in _STATE:
        return _STATE["ok"]
    _STATE["ok"] = False
    try:
        from llvmlite import binding as ll

        api = ctypes.pythonapi
        get = api.PyCapsule_GetPointer
        get.restype, get.argtypes = ctypes.c_void_p, [ctypes.py_object, ctypes.c_char_p]
        try:
            from numpy._core import _multiarray_umath as mu  # numpy 2
        except ImportError:  # numpy 1
            from numpy.core import _multiarray_umath as mu

        table = ctypes.cast(get(mu._ARRAY_API, None), ctypes.POINTER(ctypes.c_void_p))
        new = ctypes.PYFUNCTYPE(ctypes.py_object, ctypes.c_void_p, ctypes.c_int, ctypes.POINTER(ctypes.c_ssize_t),
                               ctypes.c_int, ctypes.c_void_p, ctypes.c_void_p, ctypes.c_int, ctypes.c_int,
                               ctypes.c_void_p)(table[_PYARRAY_NEW_SLOT])
        dims = (ctypes.c_ssize_t * 2)(3, 5)
        a = new(id(np.ndarray), 2, dims, _NPY_DOUBLE, None, None, 0, 0, None)
        if not (type(a) is np.ndarray and a.shape == (3, 5) and a.dtype == np.float64 and a.flags.c_contiguous):
            return False
        word = lambda addr: ctypes.c_ssize_t.from_address(addr).value  # noqa: E731
        base = id(a)
        if (word(base + _OFF_TYPE) != id(np.ndarray) or word(base + _OFF_DATA) != a.ctypes.data
                or ctypes.c_int.from_address(base + _OFF_ND).value != 2
                or word(word(base + _OFF_DIMS) + 8) != 5 or word(word(base + _OFF_STRIDES)) != 40
                or word(base + _OFF_DESCR) != id(np.dtype(np.float64)) or id(a.dtype) != id(np.dtype(np.float64))):
            return False
        vectorcall = ctypes.cast(api.PyObject_Vectorcall, ctypes.c_void_p).value
        for name, addr in zip(_SYMBOLS, (id(np.ndarray), id(np.dtype(np.float64)), table[_PYARRAY_NEW_SLOT],
                                         vectorcall)):
            ll.add_symbol(name, addr)
        _STATE["ok"] = True
    except (AttributeError, ImportError, OSError, ValueError, TypeError):
        return False
    return True


def entry_intrinsic(lengths: tuple, shape: tuple, steps: tuple, outputs: tuple, flagged: bool = False):
    """A numba intrinsic ``f(self, args, nargs, kwnames) -> PyObject*`` (all pointer-sized): the checks, the program
    and the result (see the module's docstring).  ``flagged``: the kernel's last output is a flag that must be > 0
    (forward dynamics: M regular); the result is the outputs before it, and a call whose flag is not > 0 goes to
    the Python method (which raises the error)."""
    from llvmlite import ir
    from numba.core import cgutils, types
    from numba.extending import intrinsic

    from ._llvm import emit_steps

    i8, i32, i64, dbl = ir.IntType(8), ir.IntType(32), ir.IntType(64), ir.DoubleType()
    ptr = i8.as_pointer()
    size = 1
    for s in shape:
        size *= s

    def codegen(context, builder, sig, args):
        this, argv, nargs, kwnames = args
        module = builder.module

        def extern(name):
            g = module.globals.get(name) or ir.GlobalVariable(module, i8, name)
            return builder.bitcast(g, ptr)

        fn = builder.function
        fallback, done = fn.append_basic_block("dv_fallback"), fn.append_basic_block("dv_done")
        incoming = []

        def require(ok):
            nxt = fn.append_basic_block("dv_ok")
            builder.cbranch(ok, nxt, fallback)
            builder.position_at_end(nxt)

        def field(obj, offset, ty):
            return builder.load(builder.bitcast(builder.gep(obj, [ir.Constant(i64, offset)]), ty.as_pointer()))

        argv = builder.bitcast(argv, ptr.as_pointer())
        require(builder.and_(builder.icmp_unsigned("==", kwnames, ir.Constant(ptr, None)),
                             builder.icmp_signed("==", nargs, ir.Constant(i64, len(lengths)))))
        arrays = []
        for j, k in enumerate(lengths):
            obj = builder.load(builder.gep(argv, [ir.Constant(i64, j)]))
            require(builder.icmp_unsigned("==", field(obj, _OFF_TYPE, ptr), extern("denavit_ndarray_type")))
            require(builder.and_(  # an ndarray: its fields can be read
                builder.icmp_unsigned("==", field(obj, _OFF_DESCR, ptr), extern("denavit_float64_descr")),
                builder.icmp_signed("==", field(obj, _OFF_ND, i32), ir.Constant(i32, 1))))
            require(builder.icmp_signed("==", builder.load(field(obj, _OFF_DIMS, i64.as_pointer())), ir.Constant(i64, k)))
            arrays.append((field(obj, _OFF_DATA, ptr), builder.load(field(obj, _OFF_STRIDES, i64.as_pointer()))))
        def load(arg, k):
            data, stride = arrays[arg]
            return builder.load(builder.bitcast(builder.gep(data, [builder.mul(ir.Constant(i64, k), stride)]),
                                                dbl.as_pointer()))

        operand = emit_steps(builder, steps, 0, load)
        flat = {}
        for index, ref in outputs:
            f = 0
            for i, s in zip(index, (size + 1,) if flagged else shape):
                f = f * s + i
            flat[f] = ref
        if flagged:
            require(builder.fcmp_ordered(">", operand(flat.pop(size)), ir.Constant(dbl, 0.0)))
        new_ty = ir.FunctionType(ptr, [ptr, i32, i64.as_pointer(), i32, ptr, ptr, i32, i32, ptr])
        new = builder.bitcast(extern("denavit_pyarray_new"), new_ty.as_pointer())
        dims = cgutils.alloca_once(builder, i64, size=len(shape))
        for j, s in enumerate(shape):
            builder.store(ir.Constant(i64, s), builder.gep(dims, [ir.Constant(i32, j)]))
        null = ir.Constant(ptr, None)
        out = builder.call(new, [extern("denavit_ndarray_type"), ir.Constant(i32, len(shape)), dims,
                                 ir.Constant(i32, _NPY_DOUBLE), null, null, ir.Constant(i32, 0), ir.Constant(i32, 0),
                                 null])
        failed = builder.icmp_unsigned("==", out, null)
        compute = fn.append_basic_block("dv_compute")
        incoming.append((null, builder.block))
        builder.cbranch(failed, done, compute)
        builder.position_at_end(compute)
        data = builder.bitcast(field(out, _OFF_DATA, ptr), dbl.as_pointer())
        for f, ref in flat.items():
            builder.store(operand(ref), builder.gep(data, [ir.Constant(i64, f)]))
        incoming.append((out, builder.block))
        builder.branch(done)
        builder.position_at_end(fallback)
        call_ty = ir.FunctionType(ptr, [ptr, ptr.as_pointer(), i64, ptr])
        again = builder.call(builder.bitcast(extern("denavit_vectorcall"), call_ty.as_pointer()),
                             [this, argv, nargs, kwnames])
        incoming.append((again, builder.block))
        builder.branch(done)
        builder.position_at_end(done)
        result = builder.phi(ptr)
        for value, block in incoming:
            result.add_incoming(value, block)
        return result

    @intrinsic
    def entry(typingctx, this, argv, nargs, kwnames):
        return types.voidptr(this, argv, nargs, kwnames), codegen

    return entry


def install(module, name: str, lengths: tuple, shape: tuple, method, guard, flagged: bool = False):
    """``(function, keep)``: the built-in function of kernel ``name`` of the generated ``module``, calling ``method``
    (the Python method, bound) for everything it does not handle itself, and what must live as long as it; None
    when this process cannot have one.  ``shape``: the result's (``flagged``: see :func:`entry_intrinsic`).  ``guard(cfunc)``
    puts the disk cache's guard in front of numba's cache before anything is loaded."""
    py_func = getattr(module, f"{name}{ENTRY_SUFFIX}", None)
    if py_func is None or not _setup():
        return None
    from numba.core import sigutils, types
    from numba.core.ccallback import CFunc

    cf = _CFUNCS.get((module.__name__, name))  # one per generated module and kernel, whatever the objects
    if cf is None:
        setattr(module, f"_{name}{ENTRY_SUFFIX}", entry_intrinsic(tuple(lengths), tuple(shape),
                                                              getattr(module, f"_{name}_steps"),
                                                              getattr(module, f"_{name}_outputs"), flagged))
        sig = sigutils.normalize_signature(types.voidptr(types.voidptr, types.voidptr, types.intp, types.voidptr))
        cf = CFunc(py_func, sig, {}, {})  # what numba.cfunc(sig, cache=True) does, with the guard put in first
        cf.enable_caching()
        guard(cf)
        cf.compile()
        _CFUNCS[(module.__name__, name)] = cf
    doc = (method.__doc__ or "").encode("utf-8", "replace")
    definition = _MethodDef(name.encode(), cf.address, _METH_FASTCALL_KEYWORDS, doc)
    make = ctypes.pythonapi.PyCFunction_NewEx
    make.restype, make.argtypes = ctypes.py_object, [ctypes.POINTER(_MethodDef), ctypes.py_object, ctypes.py_object]
    builtin = make(ctypes.byref(definition), method, None)
    return builtin, (definition, doc, cf)  # the caller keeps these as long as the function (it holds the caller)


if sys.maxsize < 2**62:  # pragma: no cover - the offsets above are those of 64-bit builds
    _STATE["ok"] = False
