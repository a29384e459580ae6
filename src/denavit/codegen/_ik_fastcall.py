"""``CompiledRobot.analytic_ik`` of one pose as a CPython built-in function: no Python between the call and the kernel.

The Python method spends about a microsecond around its kernel: checking T, ``np.empty`` for the output vector,
numba's entry point (which unboxes three arrays, one memory-manager record each) and the result object.  Here one
numba ``cfunc`` with CPython's fast-call signature (``PyObject *f(PyObject *self, PyObject *const *args,
Py_ssize_t nargs, PyObject *kwnames)``, made a built-in by :func:`denavit.codegen._fastcall.make_builtin`) does it
all in machine code, per call:

1. the call must be exactly ``f(T)``, T exactly a ``numpy.ndarray`` of the float64 dtype object and shape (4, 4),
   any strides: its 16 entries are copied to the stack (``data + i·stride₀ + j·stride₁``, unaligned loads);
2. the output vector (OUT_SIZE floats, :mod:`._ik_nb_entry`) is made by numpy's ``PyArray_New``;
3. the arm's one-pose entry (``ik_one_elbow``, ``ik_one_parallel`` or ``ik_one_stanford`` of :mod:`._ik_nb_entry`:
   the very machine code the method calls, its address given to LLVM by name, ``denavit_ik_one_<kind>``, once
   numba has compiled or loaded it) solves the pose into it, with the constants K of the arm, the GIL released
   meanwhile (as numba's entry of these ``nogil`` kernels does);
4. status 0 (answered): the result is ``PyType_GenericNew(result type)`` with the output vector,
   ``(labels, plan kind)`` and the solutions (a new (k, 6) array, the first k rows of the kernel's (8, 14) block,
   columns 0-5) stored in its three slots — the object the method builds, field for field;
5. anything else — another call, another argument, a pose the kernel hands over (status 1) or refuses (status 2),
   an exception in the kernel — releases what was made and calls the Python method with the same arguments, which
   does what it always did (the plain solver, the error; the kernel's second run there is nothing beside the
   plain solver's milliseconds).

The built-in's ``self`` is the tuple ``(method, K, (labels, kind), result type)``.  The byte offsets the code reads
— of a tuple's items and of the result's three slots — are found on real objects by :func:`install` and kept in a
process-wide table given to LLVM by name (``denavit_ik_layout``), so the machine code numba caches on disk holds
no address or offset of this process, nor the kernel (a kernel compiled afresh from changed sources is the one
called; this module's own code is all the cache holds, keyed by this file).  When anything is not as assumed, or
fails, no built-in is made and the method stays.  Imported only where numba is.
"""

from __future__ import annotations

import ctypes

import numpy as np
from llvmlite import ir
from numba import carray, njit, types
from numba.core import cgutils, sigutils
from numba.core.ccallback import CFunc
from numba.extending import intrinsic

from . import _fastcall
from ._fastcall import (
    OFF_DATA,
    OFF_DESCR,
    OFF_DIMS,
    OFF_ND,
    OFF_STRIDES,
    OFF_TYPE,
    call,
    extern,
    field,
)
from ._ik_nb_entry import OUT_SIZE, ik_one_elbow, ik_one_parallel, ik_one_stanford

__all__ = ["install"]

_P, _I32, _I64, _F64 = ir.IntType(8).as_pointer(), ir.IntType(32), ir.IntType(64), ir.DoubleType()
_NULL = ir.Constant(_P, None)
#: words of ``denavit_ik_layout``: offset of a tuple's first item, of the result's slots ``_o``, ``_m``, ``solutions``
_SLOTS = ("_o", "_m", "solutions")
_LAYOUT = (ctypes.c_int64 * (1 + len(_SLOTS)))()
_STATE: dict = {}
_MADE: dict = {}  # kind -> (its CFunc, the address of its code), once per process


def _k(n: int):
    return ir.Constant(_I64, n)


def _word(b, k: int):
    return b.load(b.gep(b.bitcast(extern(b, "denavit_ik_layout"), _I64.as_pointer()), [_k(k)]))


def _item(b, tup, k: int):
    """Item k of the tuple at ``tup`` (a borrowed reference)."""
    return b.load(b.bitcast(b.gep(tup, [b.add(_word(b, 0), _k(8 * k))]), _P.as_pointer()))


@intrinsic
def _stack_pose(typingctx):
    """16 doubles on the stack of the calling function."""
    return types.CPointer(types.float64)(), lambda context, b, sig, a: cgutils.alloca_once(b, _F64, size=16)


def _lower_pose(b, args, nargs, kwnames, buf):
    """True, T copied to buf, when the call is exactly f(T) with T an ndarray, float64, shape (4, 4); else False."""
    fn = b.function
    no, join = fn.append_basic_block("pose_no"), fn.append_basic_block("pose_join")

    def need(ok):
        nxt = fn.append_basic_block("pose_ok")
        b.cbranch(ok, nxt, no)
        b.position_at_end(nxt)

    need(b.and_(b.icmp_unsigned("==", kwnames, _NULL), b.icmp_signed("==", nargs, _k(1))))
    obj = b.load(b.bitcast(args, _P.as_pointer()))
    need(b.icmp_unsigned("==", field(b, obj, OFF_TYPE, _P), extern(b, "denavit_ndarray_type")))
    need(b.and_(b.icmp_unsigned("==", field(b, obj, OFF_DESCR, _P), extern(b, "denavit_float64_descr")),  # ndarray
                b.icmp_signed("==", field(b, obj, OFF_ND, _I32), ir.Constant(_I32, 2))))
    dims = field(b, obj, OFF_DIMS, _I64.as_pointer())
    need(b.and_(b.icmp_signed("==", b.load(dims), _k(4)), b.icmp_signed("==", b.load(b.gep(dims, [_k(1)])), _k(4))))
    data, strides = field(b, obj, OFF_DATA, _P), field(b, obj, OFF_STRIDES, _I64.as_pointer())
    s0, s1 = b.load(strides), b.load(b.gep(strides, [_k(1)]))
    for i in range(4):
        row = b.gep(data, [b.mul(_k(i), s0)])
        for j in range(4):
            at = b.bitcast(b.gep(row, [b.mul(_k(j), s1)]), _F64.as_pointer())
            b.store(b.load(at, align=1), b.gep(buf, [_k(4 * i + j)]))
    yes = b.block
    b.branch(join)
    b.position_at_end(no)
    b.branch(join)
    b.position_at_end(join)
    ok = b.phi(ir.IntType(1))
    ok.add_incoming(ir.Constant(ir.IntType(1), 1), yes)
    ok.add_incoming(ir.Constant(ir.IntType(1), 0), no)
    return ok


@intrinsic
def _read_pose(typingctx, args, nargs, kwnames, buf):
    """See :func:`_lower_pose`."""
    return types.boolean(args, nargs, kwnames, buf), lambda context, b, sig, a: _lower_pose(b, *a)


def _lower_new(b, dims: list):
    """``PyArray_New(&PyArray_Type, len(dims), dims, NPY_DOUBLE, …)``: a new reference, or NULL (error set)."""
    at = cgutils.alloca_once(b, _I64, size=len(dims))
    for j, d in enumerate(dims):
        b.store(d, b.gep(at, [_k(j)]))
    return call(b, "denavit_pyarray_new", _P, [
        extern(b, "denavit_ndarray_type"), ir.Constant(_I32, len(dims)), at, ir.Constant(_I32, _fastcall.NPY_DOUBLE),
        _NULL, _NULL, ir.Constant(_I32, 0), ir.Constant(_I32, 0), _NULL],
        [_P, _I32, _I64.as_pointer(), _I32, _P, _P, _I32, _I32, _P])


@intrinsic
def _new_vector(typingctx):
    """A new float64 array (OUT_SIZE,): a new reference, or NULL (error set)."""
    return types.voidptr(), lambda context, b, sig, a: _lower_new(b, [_k(OUT_SIZE)])


@intrinsic
def _new_rows(typingctx, k):
    """A new float64 array (k, 6): a new reference, or NULL (error set)."""
    return types.voidptr(k), lambda context, b, sig, a: _lower_new(b, [a[0], _k(6)])


@intrinsic
def _is_null(typingctx, p):
    return types.boolean(p), lambda context, b, sig, a: b.icmp_unsigned("==", a[0], _NULL)


@intrinsic
def _data(typingctx, p):
    """The data pointer of the ndarray at p."""
    return (types.CPointer(types.float64)(p),
            lambda context, b, sig, a: b.bitcast(field(b, a[0], OFF_DATA, _P), _F64.as_pointer()))


@intrinsic
def _k_data(typingctx, this):
    """The data pointer of K (item 1 of ``this``)."""
    return (types.CPointer(types.float64)(this),
            lambda context, b, sig, a: b.bitcast(field(b, _item(b, a[0], 1), OFF_DATA, _P), _F64.as_pointer()))


@intrinsic
def _k_size(typingctx, this):
    """The length of K (item 1 of ``this``)."""
    return types.intp(this), lambda context, b, sig, a: b.load(field(b, _item(b, a[0], 1), OFF_DIMS,
                                                                      _I64.as_pointer()))


@intrinsic
def _hand_back(typingctx, this, args, nargs, kwnames):
    """The method (item 0 of ``this``) called with the same arguments: ``PyObject_Vectorcall``."""

    def codegen(context, b, sig, a):
        this, args, nargs, kwnames = a
        return call(b, "denavit_vectorcall", _P, [_item(b, this, 0), b.bitcast(args, _P.as_pointer()), nargs,
                                                  kwnames], [_P, _P.as_pointer(), _I64, _P])

    return types.voidptr(this, args, nargs, kwnames), codegen


@intrinsic
def _release(typingctx, p):
    def codegen(context, b, sig, a):
        call(b, "denavit_decref", ir.VoidType(), [a[0]], [_P])
        return context.get_dummy_value()

    return types.none(p), codegen


@intrinsic
def _result(typingctx, this, out, rows):
    """``PyType_GenericNew(result type)`` (item 3 of ``this``) holding ``out`` and ``rows`` (the references are given
    to it) and ``(labels, kind)`` (item 2, a new reference) in its slots; NULL (error set, ``out`` and ``rows``
    released) if it fails."""

    def codegen(context, b, sig, a):
        this, out, rows = a
        res = call(b, "denavit_generic_new", _P, [_item(b, this, 3), _NULL, _NULL], [_P, _P, _P])
        with b.if_else(b.icmp_unsigned("==", res, _NULL), likely=False) as (failed, made):
            with failed:
                for p in (out, rows):
                    call(b, "denavit_decref", ir.VoidType(), [p], [_P])
            with made:
                m = _item(b, this, 2)
                call(b, "denavit_incref", ir.VoidType(), [m], [_P])
                for k, p in enumerate((out, m, rows)):
                    b.store(p, b.bitcast(b.gep(res, [_word(b, 1 + k)]), _P.as_pointer()))
        return res

    return types.voidptr(this, out, rows), codegen


@njit(inline="always")
def _constants(this):
    """K (item 1 of ``this``) as an array."""
    return carray(_k_data(this), (_k_size(this),))


@njit(inline="always")
def _answer(this, out):
    """The result of an answered pose (status 0) whose output vector is ``out``: its solutions copied into a new
    (k, 6) array, then the result object (:func:`_result`); NULL (error set) if an allocation fails."""
    o = carray(_data(out), (OUT_SIZE,))
    k = int(o[120])
    rows = _new_rows(k)
    if _is_null(rows):
        _release(out)
        return rows
    q = carray(_data(rows), (k, 6))
    for s in range(k):
        for j in range(6):
            q[s, j] = o[14 * s + j]
    return _result(this, out, rows)


def _kernel_call(kind: str):
    """An intrinsic ``f(T, K, o) -> float``: the compiled one-pose entry ``ik_one_<kind>`` called by numba's calling
    convention at the symbol ``denavit_ik_one_<kind>``, without the GIL (``PyEval_SaveThread`` … ``RestoreThread``,
    as numba's own entry of these ``nogil`` kernels does: other threads run meanwhile); 1.0 (hand over) if it
    raised."""

    @intrinsic
    def kernel(typingctx, T, K, o):
        def codegen(context, b, sig, args):
            fnty = context.call_conv.get_function_type(sig.return_type, sig.args)
            fn = cgutils.get_or_insert_function(b.module, fnty, f"denavit_ik_one_{kind}")
            thread = call(b, "denavit_save_thread", _P, [], [])
            status, value = context.call_conv.call_function(b, fn, sig.return_type, sig.args, args)
            call(b, "denavit_restore_thread", ir.VoidType(), [thread], [_P])
            return b.select(status.is_error, ir.Constant(_F64, 1.0), value)

        return types.float64(T, K, o), codegen

    return kernel


_one_elbow, _one_parallel, _one_stanford = (_kernel_call(k) for k in ("elbow", "parallel", "stanford"))


# the three built-ins' code (one each: numba caches a function by its name and line), the same but for the kernel

def _elbow(this, args, nargs, kwnames):
    """The built-in of an arm of the elbow class (module docstring)."""
    pose = _stack_pose()
    if _read_pose(args, nargs, kwnames, pose):
        out = _new_vector()
        if _is_null(out):
            return out
        if _one_elbow(carray(pose, (4, 4)), _constants(this), carray(_data(out), (OUT_SIZE,))) == 0.0:
            return _answer(this, out)
        _release(out)
    return _hand_back(this, args, nargs, kwnames)


def _parallel(this, args, nargs, kwnames):
    """The built-in of an arm of the UR class."""
    pose = _stack_pose()
    if _read_pose(args, nargs, kwnames, pose):
        out = _new_vector()
        if _is_null(out):
            return out
        if _one_parallel(carray(pose, (4, 4)), _constants(this), carray(_data(out), (OUT_SIZE,))) == 0.0:
            return _answer(this, out)
        _release(out)
    return _hand_back(this, args, nargs, kwnames)


def _stanford(this, args, nargs, kwnames):
    """The built-in of an arm of the Stanford class."""
    pose = _stack_pose()
    if _read_pose(args, nargs, kwnames, pose):
        out = _new_vector()
        if _is_null(out):
            return out
        if _one_stanford(carray(pose, (4, 4)), _constants(this), carray(_data(out), (OUT_SIZE,))) == 0.0:
            return _answer(this, out)
        _release(out)
    return _hand_back(this, args, nargs, kwnames)


#: the one-pose entry of each closed form -> (kind, the built-in's code)
_CODE = {ik_one_elbow: ("elbow", _elbow), ik_one_parallel: ("parallel", _parallel),
         ik_one_stanford: ("stanford", _stanford)}


def _words(obj, size: int) -> list[int]:
    return [ctypes.c_ssize_t.from_address(id(obj) + k).value for k in range(0, size, 8)]


def _layout(result_type) -> bool:
    """Fill ``denavit_ik_layout`` from real objects (once per process): a tuple's first item, and the slots ``_o``,
    ``_m`` of ``result_type``, each found at exactly one word; check that ``PyType_GenericNew`` makes one.  False
    when something is not so (or another result type asks for other offsets): no built-in then."""
    if result_type in _STATE:
        return _STATE[result_type]
    _STATE[result_type] = False
    if not _fastcall.setup():
        return False
    marks = [object() for _ in _SLOTS]
    pair = tuple(marks[:2])
    inst = object.__new__(result_type)
    for name, mark in zip(_SLOTS, marks):
        getattr(result_type, name).__set__(inst, mark)
    tw, sw = _words(pair, 48), _words(inst, result_type.__basicsize__)
    if (tw.count(id(pair[0])) != 1 or tw[tw.index(id(pair[0])) + 1] != id(pair[1])
            or any(sw.count(id(mark)) != 1 for mark in marks)):
        return False
    new = ctypes.pythonapi.PyType_GenericNew
    new.restype, new.argtypes = ctypes.py_object, [ctypes.py_object, ctypes.c_void_p, ctypes.c_void_p]
    if type(new(result_type, None, None)) is not result_type:
        return False
    words = (8 * tw.index(id(pair[0])), *(8 * sw.index(id(mark)) for mark in marks))
    if any(_LAYOUT) and tuple(_LAYOUT) != words:  # another result type laid out otherwise
        return False
    from llvmlite import binding as ll

    _LAYOUT[:] = words
    ll.add_symbol("denavit_ik_layout", ctypes.addressof(_LAYOUT))
    for symbol, name in (("denavit_save_thread", "PyEval_SaveThread"),
                         ("denavit_restore_thread", "PyEval_RestoreThread")):
        ll.add_symbol(symbol, ctypes.cast(getattr(ctypes.pythonapi, name), ctypes.c_void_p).value)
    _STATE[result_type] = True
    return True


def install(one, method, K, labels_kind, result_type, guard):
    """``(function, keep)``: the built-in answering ``method(T)`` (the bound ``analytic_ik`` of one arm) for arms whose
    one-pose entry is ``one`` (a dispatcher of :mod:`._ik_nb_entry`, compiled or loaded in this process), with
    constants K and ``labels_kind`` = (labels, plan kind) kept in each result of ``result_type``; ``keep`` must live
    as long as the function.  None when this process cannot have it.  ``guard(cfunc)``: the disk cache's guard."""
    kind, code = _CODE.get(one, (None, None))
    C1, C2 = types.Array(types.float64, 1, "C"), types.Array(types.float64, 2, "C")
    cres = one.overloads.get((C2, C1, C1)) if kind else None  # what the method calls: T, K, o C-contiguous
    if (cres is None or type(K) is not np.ndarray or K.dtype != np.float64 or K.ndim != 1
            or not K.flags.c_contiguous or not _layout(result_type)):
        return None
    made = _MADE.get(kind)
    if made is None:
        from llvmlite import binding as ll

        address = cres.library.get_pointer_to_function(cres.fndesc.llvm_func_name)
        if not address:
            return None
        ll.add_symbol(f"denavit_ik_one_{kind}", address)
        cf = CFunc(code, sigutils.normalize_signature(types.voidptr(types.voidptr, types.voidptr, types.intp,
                                                                    types.voidptr)), {}, {})
        cf.enable_caching()
        guard(cf)
        cf.compile()
        made = _MADE[kind] = (cf, cf.address)
    builtin, keep = _fastcall.make_builtin(method, made[1], (method, K, labels_kind, result_type))
    return builtin, (keep, made[0])
