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
    """A numba intrinsic ``f(in_0, …, in_{k-1}, out) -> None`` evaluating the program into ``out``."""
    from llvmlite import ir
    from numba.core import cgutils, types
    from numba.extending import intrinsic

    dbl = ir.DoubleType()
    i64 = ir.IntType(64)

    def codegen(context, builder, sig, args):
        arrays = [context.make_array(ty)(context, builder, val) for ty, val in zip(sig.args, args)]
        module = builder.module
        fns = {name: module.declare_intrinsic(f"llvm.{name}", [dbl]) for name in ("sin", "cos")}
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
                                               [ir.Constant(i64, ref[2])])
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
                v = builder.call(fns[op], [A])
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
        out_ty, out = sig.args[-1], arrays[-1]
        for index, ref in outputs:
            ptr = cgutils.get_item_pointer(context, builder, out_ty, out, [ir.Constant(i64, i) for i in index])
            builder.store(operand(ref), ptr)
        return context.get_dummy_value()

    def typer(typingctx, *args):
        return types.void(*args), codegen

    # numba's @intrinsic needs a fixed signature: inputs + out
    if n_inputs == 1:
        def kernel(typingctx, a0, a1):
            return typer(typingctx, a0, a1)
    elif n_inputs == 2:
        def kernel(typingctx, a0, a1, a2):
            return typer(typingctx, a0, a1, a2)
    elif n_inputs == 3:
        def kernel(typingctx, a0, a1, a2, a3):
            return typer(typingctx, a0, a1, a2, a3)
    else:  # pragma: no cover - kernels have one to three inputs
        raise ValueError(f"kernels take 1 to 3 inputs, not {n_inputs}")
    return intrinsic(kernel)
