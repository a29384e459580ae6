"""The single call without Python in the way: a kernel as a CPython built-in function.

A method such as ``fast.fk(q)`` spends more time in Python than in its kernel: checking q, ``np.empty`` for the
result, and numba's entry point (which unboxes each array into a struct, with a memory-manager record per array).
Here the kernel's program is emitted a second time, into a C function with CPython's *fast-call* convention
(``PyObject *f(PyObject *self, PyObject *const *args, Py_ssize_t nargs, PyObject *kwnames)``, METH_FASTCALL |
METH_KEYWORDS), which

1. checks each argument in machine code: exactly ``numpy.ndarray`` (not a subclass), the float64 dtype object,
   one dimension of the kernel input's length (any stride: elements are read at ``data + k·stride``);
2. allocates the result with numpy's own ``PyArray_New`` (C API slot 93) and writes the program's outputs into it;
   a kernel with several results (``rnea_derivatives``: ∂τ/∂q and ∂τ/∂q̇) returns a tuple of fresh arrays, made by
   ``PyTuple_New`` and filled by ``PyTuple_SetItem`` (which steals each array's only reference), so the caller
   owns one tuple holding the only references to its arrays; if an allocation fails, the tuple is released
   (``Py_DecRef`` frees the arrays already in it) and NULL returned with numpy's MemoryError set;
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

from ._lean import lean

__all__ = ["entry_intrinsic", "install", "ENTRY_SUFFIX", "setup", "extern", "call", "field", "make_builtin",
           "NPY_DOUBLE", "OFF_TYPE", "OFF_DATA", "OFF_ND", "OFF_DIMS", "OFF_STRIDES", "OFF_DESCR"]

#: the generated module's fast-call function of kernel <name> is <name><ENTRY_SUFFIX>
ENTRY_SUFFIX = "_entry"
NPY_DOUBLE = 12
_PYARRAY_NEW_SLOT = 93  # numpy/__multiarray_api.h: PyArray_New, stable since numpy 1.0
#: PyArrayObject_fields (numpy/ndarraytypes.h) after PyObject_HEAD: data, nd, dimensions, strides, base, descr
OFF_TYPE, OFF_DATA, OFF_ND, OFF_DIMS, OFF_STRIDES, OFF_DESCR = 8, 16, 24, 32, 40, 56
_SYMBOLS = ("denavit_ndarray_type", "denavit_float64_descr", "denavit_pyarray_new", "denavit_vectorcall",
            "denavit_tuple_new", "denavit_tuple_setitem", "denavit_decref", "denavit_incref", "denavit_generic_new")
_STATE: dict = {}
_CFUNCS: dict = {}  # (generated module's name, kernel) -> (its CFunc, the entry's address), for every object


class _MethodDef(ctypes.Structure):
    _fields_ = [("ml_name", ctypes.c_char_p), ("ml_meth", ctypes.c_void_p), ("ml_flags", ctypes.c_int),
                ("ml_doc", ctypes.c_char_p)]


_METH_FASTCALL_KEYWORDS = 0x0080 | 0x0002


def setup() -> bool:
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
        a = new(id(np.ndarray), 2, dims, NPY_DOUBLE, None, None, 0, 0, None)
        if not (type(a) is np.ndarray and a.shape == (3, 5) and a.dtype == np.float64 and a.flags.c_contiguous):
            return False
        word = lambda addr: ctypes.c_ssize_t.from_address(addr).value  # noqa: E731
        base = id(a)
        if (word(base + OFF_TYPE) != id(np.ndarray) or word(base + OFF_DATA) != a.ctypes.data
                or ctypes.c_int.from_address(base + OFF_ND).value != 2
                or word(word(base + OFF_DIMS) + 8) != 5 or word(word(base + OFF_STRIDES)) != 40
                or word(base + OFF_DESCR) != id(np.dtype(np.float64)) or id(a.dtype) != id(np.dtype(np.float64))):
            return False
        functions = [ctypes.cast(getattr(api, f), ctypes.c_void_p).value
                     for f in ("PyObject_Vectorcall", "PyTuple_New", "PyTuple_SetItem", "Py_DecRef", "Py_IncRef",
                               "PyType_GenericNew")]
        for name, addr in zip(_SYMBOLS, [id(np.ndarray), id(np.dtype(np.float64)), table[_PYARRAY_NEW_SLOT]]
                              + functions):
            ll.add_symbol(name, addr)
        _STATE["ok"] = True
    except (AttributeError, ImportError, OSError, ValueError, TypeError):
        return False
    return True


def _flat_outputs(outputs: tuple, kernel_shape: tuple) -> dict:
    """The program's outputs by flat (C-order) index in the kernel's output shape: {index: operand}."""
    flat = {}
    for index, ref in outputs:
        f = 0
        for i, s in zip(index, kernel_shape):
            f = f * s + i
        flat[f] = ref
    return flat


def extern(builder, name: str):
    """The address (an ``i8*``) of the process-wide symbol ``name`` (given to LLVM by :func:`setup`)."""
    from llvmlite import ir

    module = builder.module
    g = module.globals.get(name) or ir.GlobalVariable(module, ir.IntType(8), name)
    return builder.bitcast(g, ir.IntType(8).as_pointer())


def call(builder, name: str, ret, args, types):
    """A call of the C function at symbol ``name`` (return type ``ret``, argument types ``types``)."""
    from llvmlite import ir

    return builder.call(builder.bitcast(extern(builder, name), ir.FunctionType(ret, types).as_pointer()), args)


def field(builder, obj, offset: int, ty):
    """The ``ty`` at byte ``offset`` of the object at ``obj`` (an ``i8*``)."""
    from llvmlite import ir

    return builder.load(builder.bitcast(builder.gep(obj, [ir.Constant(ir.IntType(64), offset)]), ty.as_pointer()))


class _Emitter:
    """The IR of one fast-call entry, in the function being lowered: its checks branch to ``fallback``, and every
    way out joins at ``done`` (a phi of the returned object)."""

    def __init__(self, builder):
        from llvmlite import ir

        self.ir, self.b = ir, builder
        self.i32, self.i64 = ir.IntType(32), ir.IntType(64)
        self.ptr = ir.IntType(8).as_pointer()
        self.null = ir.Constant(self.ptr, None)
        fn = builder.function
        self.fallback, self.done = fn.append_basic_block("dv_fallback"), fn.append_basic_block("dv_done")
        self.incoming: list = []

    def extern(self, name):
        return extern(self.b, name)

    def call(self, name, ret, args, types):
        return call(self.b, name, ret, args, types)

    def require(self, ok, otherwise=None):
        nxt = self.b.function.append_basic_block("dv_ok")
        self.b.cbranch(ok, nxt, otherwise or self.fallback)
        self.b.position_at_end(nxt)

    def field(self, obj, offset, ty):
        return field(self.b, obj, offset, ty)

    def new_array(self, shape):
        """``PyArray_New(&PyArray_Type, nd, dims, NPY_DOUBLE, NULL, NULL, 0, 0, NULL)``: a fresh C-contiguous
        float64 array (a new reference), or NULL with the error set."""
        from numba.core import cgutils

        ir, i32, i64, ptr, null = self.ir, self.i32, self.i64, self.ptr, self.null
        dims = cgutils.alloca_once(self.b, i64, size=len(shape))
        for j, s in enumerate(shape):
            self.b.store(ir.Constant(i64, s), self.b.gep(dims, [ir.Constant(i32, j)]))
        return self.call("denavit_pyarray_new", ptr, [
            self.extern("denavit_ndarray_type"), ir.Constant(i32, len(shape)), dims, ir.Constant(i32, NPY_DOUBLE),
            null, null, ir.Constant(i32, 0), ir.Constant(i32, 0), null],
            [ptr, i32, i64.as_pointer(), i32, ptr, ptr, i32, i32, ptr])

    def results(self, blocks):
        """(object returned, data pointer of each block): one array, or a tuple of ``len(blocks)`` arrays.  A
        failed allocation returns NULL (the tuple, when made, released with the arrays already in it)."""
        ir, b, ptr, i64 = self.ir, self.b, self.ptr, self.i64
        fail = b.function.append_basic_block("dv_nomemory")
        if len(blocks) == 1:
            out = self.new_array(blocks[0])
            self.require(b.icmp_unsigned("!=", out, self.null), fail)
            arrays, result = [out], out
        else:
            result = self.call("denavit_tuple_new", ptr, [ir.Constant(i64, len(blocks))], [i64])
            self.require(b.icmp_unsigned("!=", result, self.null), fail)
            release = b.function.append_basic_block("dv_release")
            arrays = []
            for j, shape in enumerate(blocks):
                out = self.new_array(shape)
                self.require(b.icmp_unsigned("!=", out, self.null), release)
                self.call("denavit_tuple_setitem", self.i32, [result, ir.Constant(i64, j), out], [ptr, i64, ptr])
                arrays.append(out)
            here = b.block
            b.position_at_end(release)  # Py_DecRef(tuple): frees it and the arrays it holds (NULL slots skipped)
            self.call("denavit_decref", ir.VoidType(), [result], [ptr])
            b.branch(fail)
            b.position_at_end(here)
        here = b.block
        b.position_at_end(fail)
        self.incoming.append((self.null, fail))
        b.branch(self.done)
        b.position_at_end(here)
        return result, [b.bitcast(self.field(a, OFF_DATA, ptr), ir.DoubleType().as_pointer()) for a in arrays]

    def finish(self, result, argv):
        """Return ``result`` from here; lower the fallback (the bound method, called with the same arguments)."""
        b, ptr = self.b, self.ptr
        self.incoming.append((result, b.block))
        b.branch(self.done)
        b.position_at_end(self.fallback)
        this, args, nargs, kwnames = argv
        again = self.call("denavit_vectorcall", ptr, [this, args, nargs, kwnames],
                          [ptr, ptr.as_pointer(), self.i64, ptr])
        self.incoming.append((again, b.block))
        b.branch(self.done)
        b.position_at_end(self.done)
        phi = b.phi(ptr)
        for value, block in self.incoming:
            phi.add_incoming(value, block)
        return phi


def _checked_arrays(e: _Emitter, argv, nargs, kwnames, lengths: tuple) -> list:
    """Branch to the fallback unless the call is exactly ``f(a_0, …, a_{k-1})`` with each a_j an ndarray (not a
    subclass) of the float64 dtype object, one dimension of length ``lengths[j]``; (data, stride) of each."""
    b, ir, i64, ptr = e.b, e.ir, e.i64, e.ptr
    e.require(b.and_(b.icmp_unsigned("==", kwnames, e.null),
                     b.icmp_signed("==", nargs, ir.Constant(i64, len(lengths)))))
    arrays = []
    for j, k in enumerate(lengths):
        obj = b.load(b.gep(argv, [ir.Constant(i64, j)]))
        e.require(b.icmp_unsigned("==", e.field(obj, OFF_TYPE, ptr), e.extern("denavit_ndarray_type")))
        e.require(b.and_(  # an ndarray: its fields can be read
            b.icmp_unsigned("==", e.field(obj, OFF_DESCR, ptr), e.extern("denavit_float64_descr")),
            b.icmp_signed("==", e.field(obj, OFF_ND, e.i32), ir.Constant(e.i32, 1))))
        e.require(b.icmp_signed("==", b.load(e.field(obj, OFF_DIMS, i64.as_pointer())), ir.Constant(i64, k)))
        arrays.append((e.field(obj, OFF_DATA, ptr), b.load(e.field(obj, OFF_STRIDES, i64.as_pointer()))))
    return arrays


def _emit_entry(builder, argv4, lengths: tuple, kernel_shape: tuple, blocks: tuple, steps: tuple, outputs: tuple,
                flagged: bool):
    """Lower one fast-call entry at ``builder`` (its arguments ``argv4`` = self, args, nargs, kwnames): the checks,
    the program, the result (module docstring); returns the object to return (a phi)."""
    from llvmlite import ir

    from ._llvm import emit_steps

    sizes = [int(np.prod(s, dtype=np.int64)) for s in blocks]
    flat = _flat_outputs(outputs, kernel_shape)
    e = _Emitter(builder)
    this, args, nargs, kwnames = argv4
    argv = builder.bitcast(args, e.ptr.as_pointer())
    arrays = _checked_arrays(e, argv, nargs, kwnames, lengths)

    def load(arg, k):
        data, stride = arrays[arg]
        return builder.load(builder.bitcast(builder.gep(data, [builder.mul(ir.Constant(e.i64, k), stride)]),
                                            ir.DoubleType().as_pointer()))

    # allocated first, so the program's values go to memory as they are made (not held across the calls)
    result, data = e.results(blocks)
    operand = emit_steps(builder, steps, 0, load)
    flag = flat.pop(sum(sizes)) if flagged else None
    start = 0
    for block, size in enumerate(sizes):
        for f in range(start, start + size):
            if f in flat:
                builder.store(operand(flat[f]), builder.gep(data[block], [ir.Constant(e.i64, f - start)]))
        start += size
    if flagged:  # not > 0: the result is released and the method raises the error
        discard = builder.function.append_basic_block("dv_discard")
        e.require(builder.fcmp_ordered(">", operand(flag), ir.Constant(ir.DoubleType(), 0.0)), discard)
        here = builder.block
        builder.position_at_end(discard)
        e.call("denavit_decref", ir.VoidType(), [result], [e.ptr])
        builder.branch(e.fallback)
        builder.position_at_end(here)
    return e.finish(result, (this, argv, nargs, kwnames))


def _sibling(module, symbol: str, program: tuple) -> None:
    """Another kernel's entry as a function ``symbol`` of the same LLVM module, with the C signature of the
    fast-call convention (``PyObject *f(PyObject *, PyObject *const *, Py_ssize_t, PyObject *)``)."""
    from llvmlite import ir

    ptr = ir.IntType(8).as_pointer()
    fn = ir.Function(module, ir.FunctionType(ptr, [ptr, ptr, ir.IntType(64), ptr]), name=symbol)
    builder = ir.IRBuilder(fn.append_basic_block("entry"))
    builder.ret(_emit_entry(builder, fn.args, *program))


def entry_intrinsic(lengths: tuple, kernel_shape: tuple, blocks: tuple, steps: tuple, outputs: tuple,
                    flagged: bool = False, siblings: tuple = ()):
    """A numba intrinsic ``f(self, args, nargs, kwnames) -> PyObject*`` (all pointer-sized): the checks, the program
    and the result (module docstring).  The kernel's outputs (``kernel_shape``, C order) fill the result ``blocks``
    in turn: one block is returned as an array, several as a tuple.  ``flagged``: the output after the blocks must
    be > 0 (forward dynamics: M regular), else the result is released and the Python method called (it raises).
    ``siblings``: ``(symbol, program)`` pairs, ``program`` the arguments above of another kernel: its entry is
    written into the same LLVM module as a function of that (process-wide) name, so that one numba compile —
    its fixed cost paid once — makes the built-ins of several kernels."""
    from numba.core import types
    from numba.extending import intrinsic

    program = (tuple(lengths), tuple(kernel_shape), tuple(map(tuple, blocks)), steps, outputs, flagged)

    def codegen(context, builder, sig, args):
        for symbol, other in siblings:
            if symbol not in builder.module.globals:
                _sibling(builder.module, symbol, other)
        return _emit_entry(builder, args, *program)

    @intrinsic
    def entry(typingctx, this, argv, nargs, kwnames):
        return types.voidptr(this, argv, nargs, kwnames), codegen

    return entry


def _symbol(module, name: str) -> str:
    """The process-wide name of kernel ``name``'s entry in the cfunc of ``module`` (a generated module's name is
    made of its cache key: unique per arm, backend and kernels)."""
    return f"denavit_entry_{''.join(c if c.isalnum() else '_' for c in module.__name__)}_{name}"


def _compiled_entries(module, specs: tuple, guard) -> dict:
    """Compile (or load from the disk cache) the built-ins of every kernel of ``specs`` — ``(name, lengths,
    kernel_shape, blocks, flagged)`` each — in one numba cfunc, made from the first one's ``<name>_entry``:
    {name: (the CFunc, the entry's address)}; a kernel whose address cannot be had is left out."""
    from numba.core import sigutils, types
    from numba.core.ccallback import CFunc

    def program(name, lengths, kernel_shape, blocks, flagged):
        return (tuple(lengths), tuple(kernel_shape), tuple(map(tuple, blocks)), getattr(module, f"_{name}_steps"),
                getattr(module, f"_{name}_outputs"), flagged)

    lead, *rest = specs
    siblings = tuple((_symbol(module, s[0]), program(*s)) for s in rest)
    setattr(module, f"_{lead[0]}{ENTRY_SUFFIX}", entry_intrinsic(*program(*lead), siblings=siblings))
    sig = sigutils.normalize_signature(types.voidptr(types.voidptr, types.voidptr, types.intp, types.voidptr))
    cf = CFunc(getattr(module, f"{lead[0]}{ENTRY_SUFFIX}"), sig, {}, {})  # numba.cfunc(sig, cache=True), guarded
    cf.enable_caching()
    guard(cf)
    with lean():  # LLVM's -O3 once, as for the kernels (see denavit.codegen._lean)
        cf.compile()
    entries = {lead[0]: (cf, cf.address)}
    for (name, *_), (symbol, _) in zip(rest, siblings):
        address = cf._library.get_pointer_to_function(symbol)
        if address:
            entries[name] = (cf, address)
    return entries


def install(module, name: str, lengths: tuple, kernel_shape: tuple, blocks: tuple, method, guard,
            flagged: bool = False, together: tuple = ()):
    """``(function, keep)``: the built-in function of kernel ``name`` of the generated ``module``, calling ``method``
    (the Python method, bound) for everything it does not handle itself, and what must live as long as it; None
    when this process cannot have one.  ``kernel_shape``: the kernel's output; ``blocks``: the result's arrays
    (``flagged``: see :func:`entry_intrinsic`).  ``together``: ``(name, lengths, kernel_shape, blocks, flagged)`` of
    every kernel of ``module`` with a built-in (``name`` among them, the same tuple whichever is asked for first):
    their built-ins are compiled at once, in one numba cfunc.  ``guard(cfunc)`` puts the disk cache's guard in front
    of numba's cache before anything is loaded."""
    if getattr(module, f"{name}{ENTRY_SUFFIX}", None) is None or not setup():
        return None
    made = _CFUNCS.get((module.__name__, name))  # one per generated module and kernel, whatever the objects
    if made is None:
        specs = tuple(together) if any(s[0] == name for s in together) else (
            (name, lengths, kernel_shape, blocks, flagged),)
        entries = _compiled_entries(module, specs, guard)
        for kernel in (s[0] for s in specs):
            _CFUNCS[(module.__name__, kernel)] = entries.get(kernel, (None, 0))
        made = _CFUNCS[(module.__name__, name)]
    cf, address = made
    if not address:
        return None
    builtin, keep = make_builtin(method, address, method)
    return builtin, (keep, cf)  # the caller keeps these as long as the function (it holds the caller)


def make_builtin(method, address: int, this):
    """``(function, keep)``: a built-in function named and documented as ``method``, its C code the fast-call
    function at ``address``, called with ``this`` as its first argument; ``keep`` must live as long as it."""
    doc = (method.__doc__ or "").encode("utf-8", "replace")
    definition = _MethodDef(method.__name__.encode(), address, _METH_FASTCALL_KEYWORDS, doc)
    make = ctypes.pythonapi.PyCFunction_NewEx
    make.restype, make.argtypes = ctypes.py_object, [ctypes.POINTER(_MethodDef), ctypes.py_object, ctypes.py_object]
    return make(ctypes.byref(definition), this, None), (definition, doc)


if sys.maxsize < 2**62:  # pragma: no cover - the offsets above are those of 64-bit builds
    _STATE["ok"] = False
