"""The numba backend's code generator: a traced program written straight into LLVM IR.

numba's front end (bytecode analysis, type inference, lowering) costs about a millisecond per Python
statement, so a 1,000-statement RNEA written as Python source takes seconds to compile.  A kernel is already
a typed straight-line program of doubles, so it needs none of that: :func:`kernel_intrinsic` makes a numba
``@intrinsic`` that emits the program's instructions (``fadd``, ``fmul``, …) directly with
llvmlite's IR builder, and the generated module wraps it in two tiny ``@njit(cache=True)`` functions (one
configuration, a batch loop).  LLVM then optimises the block as usual, numba caches the machine code on disk
like any jitted function, and the Python-level cost is one builder call per instruction.

The batch forms of all the kernels of one generated module are one compiled function (:func:`group_intrinsic`:
a switch on the kernel's number around their programs): numba's fixed cost per compiled function — its
pipeline, the CPython wrapper, a module of its own through LLVM, about 0.1 s — is then paid once per group, not
once per kernel.

No fast-math flags are set: no reassociation and no fused multiply-adds, so the numbers are those of the
numpy backend, operation for operation.

The batch form is SIMD: the same program on ``<LANES x double>`` vectors, LANES rows at once (one
AVX2 register).  libm has no vector sine, so there sin and cos come from :func:`_poly_sincos` — Cody–Waite
reduction by π/2 in three parts (exact for |x| < 2**19·π/2) and Taylor polynomials on [−π/4, π/4] truncated
below 1e-19 — within an ulp or two of libm; lanes with |x| beyond the reduction's range (or ±inf) take libm's
``sincos``, one lane at a time.  The one-configuration forms use the same polynomials on doubles (an inline
polynomial overlaps with the rest of the program; a libm call does not).  At the end of a batch the lanes
past the last row are masked (they store nothing), so a batch kernel holds only the vector form.

Program format (what the generated module embeds as literals): ``steps`` is a tuple of ``(op, a, b)`` in
evaluation order, each operand either ``("n", j)`` (the value of step j), ``("c", x)`` (a double constant) or
``("i", arg, k)`` (element k of input argument ``arg``); ``outputs`` is a tuple of ``(index tuple, operand)``.
"""

from __future__ import annotations

import inspect
import math

__all__ = ["kernel_intrinsic", "group_intrinsic", "LANES"]

#: rows computed at once by a batch kernel's SIMD form (4 doubles: one AVX2 register).
LANES = 4
#: |x| up to which the vector sine's three-part reduction is exact (k·PIO2_1 exact for |k| < 2**20).
_REDUCTION_RANGE = 2.0 ** 19 * 1.5707963267948966
#: π/2 as three doubles: 33 + 33 + 53 bits (so k·PIO2_1 and k·PIO2_2 are exact), and 2/π.
_PIO2 = (float.fromhex("0x1.921fb54400000p+0"), float.fromhex("0x1.0b4611a600000p-34"),
         float.fromhex("0x1.3198a2e037073p-69"))
_TWO_OVER_PI = float.fromhex("0x1.45f306dc9c883p-1")
#: Taylor coefficients in r² of sin r = r + r³·S(r²) and cos r = 1 − r²/2 + r⁴·C(r²), |r| ≤ π/4: the first
#: omitted terms, r¹⁹/19! and r¹⁸/18!, are below 1e-19 and 3e-18 there.
_SIN = tuple((-1.0) ** (k + 1) / math.factorial(2 * k + 3) for k in range(8))
_COS = tuple((-1.0) ** k / math.factorial(2 * k + 4) for k in range(7))



def kernel_intrinsic(n_inputs: int, steps: tuple, outputs: tuple):
    """Two numba intrinsics evaluating the program into ``out`` (each -> None).

    ``f(in_0, …, in_{k-1}, out)``: the inputs are vectors and ``out`` has the kernel's shape.
    ``f_rows(in_0, …, out, b)``: the inputs are (B, k) arrays and ``out`` (B,) + shape; rows ``b … b + LANES − 1``
    are computed at once, in SIMD, with no array views per row (a batch loop does no reference counting);
    lanes past the last row (B mod LANES at the end of a batch) compute a copy of the last row and store
    nothing."""

    def codegen(context, builder, sig, args, lanes):
        k = n_inputs + 1
        _program(context, builder, sig.args[:k], args[:k], args[-1] if lanes else None, steps, outputs, lanes)
        return context.get_dummy_value()

    return _intrinsics(n_inputs + 1, codegen)


def group_intrinsic(arity: int, programs: tuple):
    """Two numba intrinsics running program ``sel`` of ``programs`` — one compiled function for a whole group of
    kernels (numba's fixed cost, ~0.1 s per compiled function, paid once).

    ``programs``: ``(n_inputs, steps, outputs, shape)`` per kernel (``outputs`` indexed by ``shape``, as
    :func:`kernel_intrinsic`'s).  ``f(sel, in_0, …, in_{arity-1}, out)``: vectors, ``out`` flat; ``f_batch(sel,
    in_0, …, out)``: (B, k) inputs and a (B, m) ``out``, the whole batch LANES rows at a time as
    :func:`kernel_intrinsic`'s rows.  Each kernel has its own loop over the rows (the switch is outside the loops:
    one loop holding every kernel would keep every kernel's loop-invariant addresses live, and spill).  A kernel
    of fewer inputs ignores the last ones; an unknown ``sel`` does nothing."""
    from llvmlite import ir
    from numba.core import cgutils

    def flat(index, shape):
        f = 0
        for i, size in zip(index, shape):
            f = f * size + i
        return (f,)

    programs = tuple((k, steps, tuple((flat(index, shape), ref) for index, ref in outputs))
                     for k, steps, outputs, shape in programs)

    def codegen(context, builder, sig, args, lanes):
        sel, out_at = args[0], 1 + arity
        done = builder.append_basic_block("dv_done")
        switch = builder.switch(sel, done)
        for j, (k, steps, outputs) in enumerate(programs):
            block = builder.append_basic_block(f"dv_kernel{j}")
            switch.add_case(ir.Constant(sel.type, j), block)
            builder.position_at_end(block)
            tys, vals = sig.args[1:1 + k] + (sig.args[out_at],), args[1:1 + k] + (args[out_at],)
            if not lanes:
                _program(context, builder, tys, vals, None, steps, outputs, 0)
            else:
                n_rows = cgutils.unpack_tuple(builder, context.make_array(tys[0])(context, builder, vals[0]).shape)[0]
                i64 = ir.IntType(64)
                with cgutils.for_range_slice(builder, ir.Constant(i64, 0), n_rows, ir.Constant(i64, lanes)) as (row, _):
                    _program(context, builder, tys, vals, row, steps, outputs, lanes)
            builder.branch(done)
        builder.position_at_end(done)
        return context.get_dummy_value()

    return _intrinsics(arity + 2, codegen, rows=False)


def _intrinsics(n_args: int, codegen, rows: bool = True):
    """The pair of numba intrinsics (one configuration: ``n_args`` arguments; SIMD: one more, the row, if ``rows``)."""
    from numba.core import types
    from numba.extending import intrinsic

    def typer(lanes):
        def make(typingctx, *args):
            return types.void(*args), lambda context, builder, sig, a: codegen(context, builder, sig, a, lanes)
        return make

    # numba's @intrinsic needs a fixed signature (inputs + out (+ row)); *args alone is not lowered, so the
    # signature numba reads (inspect's __signature__) names each argument
    def arity(k, lanes):
        t = typer(lanes)

        def kernel(typingctx, *args):
            return t(typingctx, *args)

        P = inspect.Parameter
        kernel.__signature__ = inspect.Signature([P(a, P.POSITIONAL_OR_KEYWORD) for a in ("typingctx", *(f"a{i}" for i in range(k)))])
        return intrinsic(kernel)

    return arity(n_args, 0), arity(n_args + rows, LANES)


class _Addresses:
    """Element addresses of numba arrays: each array's data pointer (as bytes) and strides, read once at the start
    (before any conditional block); an element's address is data + Σ index·stride (numba's get_item_pointer would
    re-read them per element).  ``batched``: the first dimension is the batch row."""

    def __init__(self, builder, arrays, batched: bool) -> None:
        from llvmlite import ir
        from numba.core import cgutils

        self.b, self.batched, self.ir = builder, batched, ir
        self.i64, self.dptr = ir.IntType(64), ir.DoubleType().as_pointer()
        i8p = ir.IntType(8).as_pointer()
        self.layout = [(builder.bitcast(a.data, i8p), cgutils.unpack_tuple(builder, a.strides)) for a in arrays]
        self.bases: dict = {}  # (input, row) -> the row's address: inputs are read in the main flow only

    def inner(self, arg, index):
        """Σ index_k·stride_k over an element's own dimensions (not the batch row), or None for 0."""
        offset = None
        for i, stride in zip(index, self.layout[arg][1][1:] if self.batched else self.layout[arg][1]):
            if i:
                term = self.b.mul(self.ir.Constant(self.i64, i), stride)
                offset = term if offset is None else self.b.add(offset, term)
        return offset

    def base(self, arg, r):
        data, strides = self.layout[arg]
        return self.b.gep(data, [self.b.mul(r, strides[0])]) if self.batched else data

    def at(self, base_ptr, offset):
        return self.b.bitcast(base_ptr if offset is None else self.b.gep(base_ptr, [offset]), self.dptr)

    def item(self, arg, index, r):
        key = (arg, id(r))
        if key not in self.bases:
            self.bases[key] = self.base(arg, r)
        return self.at(self.bases[key], self.inner(arg, index))


def _program(context, builder, tys, vals, row, steps: tuple, outputs: tuple, lanes: int) -> None:
    """Emit one program at the builder: ``tys``/``vals`` the input arrays then ``out`` (numba types and values),
    ``row`` the first batch row (``lanes`` > 0: SIMD over LANES rows) or None (one configuration)."""
    from llvmlite import ir
    from numba.core import cgutils

    dbl, i64 = ir.DoubleType(), ir.IntType(64)
    n_inputs = len(vals) - 1
    arrays = [context.make_array(ty)(context, builder, val) for ty, val in zip(tys, vals)]
    rows = [None]
    if lanes:  # rows b … b + lanes − 1; past the batch's end a lane reads the last row and stores nothing
        n_rows = cgutils.unpack_tuple(builder, arrays[0].shape)[0]
        last = builder.sub(n_rows, ir.Constant(i64, 1))
        inside = [builder.icmp_signed("<", builder.add(row, ir.Constant(i64, j)), n_rows) for j in range(lanes)]
        rows = [builder.select(inside[j], builder.add(row, ir.Constant(i64, j)), last) for j in range(lanes)]
    A = _Addresses(builder, arrays, bool(lanes))

    def load(arg, k):
        if not lanes:
            return builder.load(A.item(arg, [k], rows[0]))
        v = ir.Constant(ir.VectorType(dbl, lanes), ir.Undefined)
        for j, r in enumerate(rows):
            v = builder.insert_element(v, builder.load(A.item(arg, [k], r)), ir.Constant(i64, j))
        return v

    operand = emit_steps(builder, steps, lanes, load)
    if not lanes:
        row_base = A.base(n_inputs, rows[0])
        for index, ref in outputs:
            builder.store(operand(ref), A.at(row_base, A.inner(n_inputs, index)))
        return
    results = [(A.inner(n_inputs, index), operand(ref)) for index, ref in outputs]
    for j, r in enumerate(rows):
        with cgutils.if_likely(builder, inside[j]):
            row_base = A.base(n_inputs, r)
            for offset, v in results:
                builder.store(builder.extract_element(v, ir.Constant(i64, j)), A.at(row_base, offset))


def emit_steps(builder, steps: tuple, lanes: int, load):
    """Emit the program ``steps`` at the builder (on doubles, or ``<lanes x double>`` vectors); ``load(arg, k)`` gives
    element k of input ``arg`` (called once per element used, in the main flow).  Returns ``operand(ref)``: the value
    of a step, a constant or an input, for the outputs."""
    from llvmlite import ir
    from numba.core import cgutils

    dbl = ir.DoubleType()
    module = builder.module
    vty = ir.VectorType(dbl, lanes) if lanes else dbl
    sincos = cgutils.get_or_insert_function(
        module, ir.FunctionType(ir.VoidType(), [dbl, dbl.as_pointer(), dbl.as_pointer()]), "sincos")
    fns = {name: _intrinsic(module, name, vty, 2) for name in ("minnum", "maxnum")}
    both: dict = {}
    inputs: dict = {}
    values: list = []
    constants: dict = {}

    def const(x: float):
        key = (x, math.copysign(1.0, x))  # −0.0 == 0.0 as a key; its sign still matters
        c = constants.get(key)
        if c is None:
            c = constants[key] = ir.Constant(vty, [x] * lanes) if lanes else ir.Constant(dbl, x)
        return c

    def operand(ref):
        kind = ref[0]
        if kind == "n":
            return values[ref[1]]
        if kind == "c":
            return const(ref[1])
        key = (ref[1], ref[2])
        v = inputs.get(key)
        if v is None:
            v = inputs[key] = load(ref[1], ref[2])
        return v

    one, zero, minus = const(1.0), const(0.0), const(-1.0)
    for op, a, b in steps:
        A = operand(a)
        if op == "add":
            v = builder.fadd(A, operand(b))
        elif op == "sub":
            v = builder.fsub(A, operand(b))
        elif op == "mul":
            v = builder.fmul(A, operand(b))
        elif op == "div":
            v = builder.fdiv(A, operand(b))
        elif op == "neg":
            v = builder.fneg(A)
        elif op in ("sin", "cos"):
            pair = both.get(repr(a))
            if pair is None:
                pair = _poly_sincos(builder, A, lanes, sincos, const)
                both[repr(a)] = pair
            v = pair[0] if op == "sin" else pair[1]
        elif op == "sign":  # 1, −1 or 0 (NaN stays NaN through the multiplications it feeds)
            v = builder.select(builder.fcmp_ordered(">", A, zero), one,
                               builder.select(builder.fcmp_ordered("<", A, zero), minus, zero))
        elif op == "min":
            v = builder.call(fns["minnum"], [A, operand(b)])
        elif op == "max":
            v = builder.call(fns["maxnum"], [A, operand(b)])
        else:  # pragma: no cover - the tape has no other operations
            raise ValueError(f"unknown operation {op!r}")
        values.append(v)
    return operand


def _intrinsic(module, name: str, ty, n_args: int):
    """The LLVM intrinsic ``llvm.<name>`` on ``ty`` (double or a vector of doubles), declared once per module
    (llvmlite's ``declare_intrinsic`` cannot name vector overloads: ``llvm.rint.v4f64``)."""
    from llvmlite import ir
    from numba.core import cgutils

    suffix = f"v{ty.count}f64" if isinstance(ty, ir.VectorType) else "f64"
    return cgutils.get_or_insert_function(module, ir.FunctionType(ty, [ty] * n_args), f"llvm.{name}.{suffix}")


def _poly_sincos(builder, x, lanes: int, sincos, const):
    """(sin x, cos x) of a double (``lanes`` 0) or a ``<lanes x double>`` vector: Cody–Waite reduction
    x = k·π/2 + r, the Taylor polynomials of sin r and cos r, and the quadrant k mod 4 choosing ±sin r / ±cos r.
    Values with |x| > _REDUCTION_RANGE (or ±inf) are recomputed by libm's scalar ``sincos``."""
    from llvmlite import ir
    from numba.core import cgutils

    dbl, i64 = ir.DoubleType(), ir.IntType(64)
    vty, ity = (ir.VectorType(dbl, lanes), ir.VectorType(i64, lanes)) if lanes else (dbl, i64)

    def iconst(m: int):
        return ir.Constant(ity, [m] * lanes) if lanes else ir.Constant(i64, m)

    module = builder.module
    rint, fabs = _intrinsic(module, "rint", vty, 1), _intrinsic(module, "fabs", vty, 1)
    k = builder.call(rint, [builder.fmul(x, const(_TWO_OVER_PI))])
    r = x
    for part in _PIO2:
        r = builder.fsub(r, builder.fmul(k, const(part)))
    z = builder.fmul(r, r)

    def horner(coefficients):
        acc = const(coefficients[-1])
        for c in reversed(coefficients[:-1]):
            acc = builder.fadd(builder.fmul(acc, z), const(c))
        return acc

    s = builder.fadd(r, builder.fmul(builder.fmul(z, r), horner(_SIN)))
    c = builder.fadd(builder.fsub(const(1.0), builder.fmul(z, const(0.5))),
                     builder.fmul(builder.fmul(z, z), horner(_COS)))
    in_range = builder.fcmp_ordered("<=", builder.call(fabs, [x]), const(_REDUCTION_RANGE))
    n = builder.fptosi(builder.select(in_range, k, const(0.0)), ity)  # the quadrant (0 where out of range or NaN)
    swap = builder.icmp_signed("!=", builder.and_(n, iconst(1)), iconst(0))
    sin_r, cos_r = builder.select(swap, c, s), builder.select(swap, s, c)
    sin_neg = builder.icmp_signed("!=", builder.and_(n, iconst(2)), iconst(0))
    sin_v = builder.select(sin_neg, builder.fneg(sin_r), sin_r)
    cos_neg = builder.icmp_signed("!=", builder.and_(builder.add(n, iconst(1)), iconst(2)), iconst(0))
    cos_v = builder.select(cos_neg, builder.fneg(cos_r), cos_r)
    # out of the reduction's range (±inf too): libm, one value at a time; NaN stays NaN on the polynomial path
    big = builder.and_(builder.not_(in_range), builder.fcmp_ordered("==", x, x))
    s_out, c_out = cgutils.alloca_once_value(builder, sin_v), cgutils.alloca_once_value(builder, cos_v)
    any_big = (builder.icmp_unsigned("!=", builder.bitcast(big, ir.IntType(lanes)), ir.Constant(ir.IntType(lanes), 0))
               if lanes else big)
    with cgutils.if_unlikely(builder, any_big):
        builder.call(_lanes_sincos(module, sincos, lanes) if lanes else sincos, [x, s_out, c_out])
    return builder.load(s_out), builder.load(c_out)


def _lanes_sincos(module, sincos, lanes: int):
    """``void f(<lanes x double> x, <lanes x double>* s, <lanes x double>* c)``: libm's sincos lane by lane, one
    internal function per module (called where an angle is out of the polynomial's range: written once, not at
    every sine of every batch program, which LLVM would optimise each time)."""
    from llvmlite import ir
    from numba.core import cgutils

    name = f"denavit_lanes_sincos_{lanes}"
    fn = module.globals.get(name)
    if fn is not None:
        return fn
    dbl, i64 = ir.DoubleType(), ir.IntType(64)
    vty = ir.VectorType(dbl, lanes)
    fn = ir.Function(module, ir.FunctionType(ir.VoidType(), [vty, vty.as_pointer(), vty.as_pointer()]), name=name)
    fn.linkage = "internal"
    fn.attributes.add("noinline")
    fn.attributes.add("cold")
    b = ir.IRBuilder(fn.append_basic_block("entry"))
    x, s_out, c_out = fn.args
    s_ptr, c_ptr = cgutils.alloca_once(b, dbl), cgutils.alloca_once(b, dbl)
    s_v, c_v = ir.Constant(vty, ir.Undefined), ir.Constant(vty, ir.Undefined)
    for j in range(lanes):
        lane = ir.Constant(i64, j)
        b.call(sincos, [b.extract_element(x, lane), s_ptr, c_ptr])
        s_v, c_v = b.insert_element(s_v, b.load(s_ptr), lane), b.insert_element(c_v, b.load(c_ptr), lane)
    b.store(s_v, s_out)
    b.store(c_v, c_out)
    b.ret_void()
    return fn
