"""The numba backend's code generator: a traced program written straight into LLVM IR.

numba's front end (bytecode analysis, type inference, lowering) costs about a millisecond per Python
statement, so a 1,000-statement RNEA written as Python source takes seconds to compile.  A kernel is already
a typed straight-line program of doubles, so it needs none of that: :func:`kernel_intrinsic` makes a numba
``@intrinsic`` that emits the program's instructions (``fadd``, ``fmul``, ``llvm.sin`` …) directly with
llvmlite's IR builder, and the generated module wraps it in two tiny ``@njit(cache=True)`` functions (one
configuration, a batch loop).  LLVM then optimises the block as usual, numba caches the machine code on disk
like any jitted function, and the Python-level cost is one builder call per instruction.

No fast-math flags are set: no reassociation and no fused multiply-adds, so the numbers are those of the
numpy backend, operation for operation.

Program format (what the generated module embeds as literals): ``steps`` is a tuple of ``(op, a, b)`` in
evaluation order, each operand either ``("n", j)`` (the value of step j), ``("c", x)`` (a double constant) or
``("i", arg, k)`` (element k of input argument ``arg``); ``outputs`` is a tuple of ``(index tuple, operand)``.
"""

from __future__ import annotations

__all__ = ["kernel_intrinsic"]


def kernel_intrinsic(n_inputs: int, steps: tuple, outputs: tuple):
    """Two numba intrinsics, ``f(in_0, …, in_{k-1}, out)`` and ``f(in_0, …, in_{k-1}, out, b)`` (-> None), evaluating the program into ``out``.

    Without ``b`` the inputs are vectors and ``out`` has the kernel's shape; with an integer ``b`` the inputs are
    (B, k) arrays and ``out`` (B,) + shape, and row ``b`` is computed — no array views per row, so a batch loop
    does no reference counting.  sin and cos of one argument are one ``sincos`` call (glibc, libm)."""
    from llvmlite import ir
    from numba.core import cgutils, types
    from numba.extending import intrinsic

    dbl = ir.DoubleType()
    i64 = ir.IntType(64)

    def codegen(context, builder, sig, args):
        batched = isinstance(sig.args[-1], types.Integer)
        arrays = [context.make_array(ty)(context, builder, val)
                  for ty, val in zip(sig.args[:n_inputs + 1], args[:n_inputs + 1])]
        row = [args[-1]] if batched else []
        module = builder.module
        fns = {name: module.declare_intrinsic(f"llvm.{name}", [dbl]) for name in ("sin", "cos")}
        sincos = cgutils.get_or_insert_function(
            module, ir.FunctionType(ir.VoidType(), [dbl, dbl.as_pointer(), dbl.as_pointer()]), "sincos")
        both: dict = {}
        for name in ("minnum", "maxnum"):
            fns[name] = module.declare_intrinsic(f"llvm.{name}", [dbl], ir.FunctionType(dbl, [dbl, dbl]))
        inputs: dict = {}
        values: list = []

        def operand(ref):
            kind = ref[0]
            if kind == "n":
                return values[ref[1]]
            if kind == "c":
                return ir.Constant(dbl, ref[1])
            key = (ref[1], ref[2])
            v = inputs.get(key)
            if v is None:
                arg = ref[1]
                ptr = cgutils.get_item_pointer(context, builder, sig.args[arg], arrays[arg],
                                               row + [ir.Constant(i64, ref[2])])
                v = inputs[key] = builder.load(ptr)
            return v

        one, zero, minus = ir.Constant(dbl, 1.0), ir.Constant(dbl, 0.0), ir.Constant(dbl, -1.0)
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
                    s_ptr, c_ptr = cgutils.alloca_once(builder, dbl), cgutils.alloca_once(builder, dbl)
                    builder.call(sincos, [A, s_ptr, c_ptr])
                    pair = both[repr(a)] = (builder.load(s_ptr), builder.load(c_ptr))
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
        out_ty, out = sig.args[n_inputs], arrays[n_inputs]
        for index, ref in outputs:
            ptr = cgutils.get_item_pointer(context, builder, out_ty, out, row + [ir.Constant(i64, i) for i in index])
            builder.store(operand(ref), ptr)
        return context.get_dummy_value()

    def typer(typingctx, *args):
        return types.void(*args), codegen

    # numba's @intrinsic needs a fixed signature: inputs + out (+ row)
    def kernel2(typingctx, a0, a1):
        return typer(typingctx, a0, a1)

    def kernel3(typingctx, a0, a1, a2):
        return typer(typingctx, a0, a1, a2)

    def kernel4(typingctx, a0, a1, a2, a3):
        return typer(typingctx, a0, a1, a2, a3)

    def kernel5(typingctx, a0, a1, a2, a3, a4):
        return typer(typingctx, a0, a1, a2, a3, a4)

    single = {2: kernel2, 3: kernel3, 4: kernel4}[n_inputs + 1]
    batch = {3: kernel3, 4: kernel4, 5: kernel5}[n_inputs + 2]
    return intrinsic(single), intrinsic(batch)
