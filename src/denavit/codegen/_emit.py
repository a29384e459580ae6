"""Source code from traced kernels: numba, numpy (vectorised), plain Python scalars, C99.

Only two kinds of text reach the generated source: identifiers made here (``q_0``, ``v12``) and constants
written by ``float.__repr__`` (digits, sign, point, exponent — checked finite).  Nothing a user typed, no
name from a robot file, is ever pasted into code.
"""

from __future__ import annotations

import math

from ._ik_lm import ik_lm_lines
from ._kernels import INTERNAL, KernelSpec
from ._llvm import LANES

__all__ = ["python_module", "c_sources", "group_batch", "vector_statements", "NUMBA", "NUMPY"]

NUMBA, NUMPY = "numba", "numpy"


def _const(v: float, lang: str) -> str:
    if not math.isfinite(v):
        raise ValueError(f"non-finite constant {v!r} in a kernel")  # the model refuses these: a bug if reached
    text = repr(float(v))
    return f"({text})" if text.startswith("-") else text


class _Names:
    def __init__(self, spec: KernelSpec, lang: str) -> None:
        self.spec, self.lang, self.tape = spec, lang, spec.tape

    def __call__(self, x) -> str:
        if isinstance(x, float):
            return _const(x, self.lang)
        op, a, b = self.tape.ops[x]
        if op == "input":
            return f"{a}_{b}"
        return f"v{x}"


_PY_FUNCS = {  # op → (scalar/numba form, vector form in namespace {ns}: numpy, torch or jax.numpy)
    "sin": ("math.sin({a})", "{ns}.sin({a})"),
    "cos": ("math.cos({a})", "{ns}.cos({a})"),
    "sign": ("_sign({a})", "{ns}.sign({a})"),
    "min": ("min({a}, {b})", "{ns}.minimum({a}, {b})"),
    "max": ("max({a}, {b})", "{ns}.maximum({a}, {b})"),
}
_C_FUNCS = {"sin": "sin({a})", "cos": "cos({a})", "sign": "(double)(({a} > 0.0) - ({a} < 0.0))",
            "min": "fmin({a}, {b})", "max": "fmax({a}, {b})"}
_INFIX = {"add": "+", "sub": "-", "mul": "*", "div": "/"}


def _expression(op: str, A: str, B: str | None, lang: str, vector: bool, ns: str = "np") -> str:
    """The right-hand side of one operation on the operands' texts, in C or Python (scalar, or vector in the array
    namespace ``ns``)."""
    if op in _INFIX:
        return f"{A} {_INFIX[op]} {B}"
    if op == "neg":
        return f"-{A}"
    if lang == "c":
        return _C_FUNCS[op].format(a=A, b=B)
    return _PY_FUNCS[op][1 if vector else 0].format(a=A, b=B, ns=ns)


def _statements(spec: KernelSpec, lang: str, vector: bool = False) -> list[str]:
    """One assignment per node of the kernel's program (inputs excluded)."""
    name = _Names(spec, lang)
    tape = spec.tape
    lines = []
    for i in tape.program(spec.outputs):
        op, a, b = tape.ops[i]
        if op == "input":
            continue
        expr = _expression(op, name(a), name(b) if b is not None else None, lang, vector)
        lines.append(f"double v{i} = {expr};" if lang == "c" else f"v{i} = {expr}")
    return lines


def _used_inputs(spec: KernelSpec) -> list[tuple[str, int]]:
    tape = spec.tape
    return [(tape.ops[i][1], tape.ops[i][2]) for i in tape.program(spec.outputs) if tape.ops[i][0] == "input"]


def _index(shape: tuple[int, ...], flat: int) -> tuple[int, ...]:
    idx = []
    for size in reversed(shape):
        idx.append(flat % size)
        flat //= size
    return tuple(reversed(idx))


def _numba_kernel(spec: KernelSpec) -> list[str]:
    """The program as literals for :func:`denavit.codegen.kernel_intrinsic`, and two jitted wrappers."""
    tape = spec.tape
    arg_of = {name: k for k, (name, _) in enumerate(spec.inputs)}
    position: dict[int, str] = {}
    steps = []

    def ref(x) -> str:
        if isinstance(x, float):
            return f"('c', {_const(x, 'py')})"
        return position[x]

    for i in tape.program(spec.outputs):
        op, a, b = tape.ops[i]
        if op == "input":
            position[i] = f"('i', {arg_of[a]}, {b})"
            continue
        steps.append(f"    ({op!r}, {ref(a)}, {'None' if b is None else ref(b)}),")
        position[i] = f"('n', {len(steps) - 1})"
    outs = [f"    ({_index(spec.shape, f)!r}, {ref(_ref(o))})," for f, o in enumerate(spec.outputs)]
    args = ", ".join(name for name, _ in spec.inputs)
    first = spec.inputs[0][0]
    k = spec.name
    return ([f"_{k}_steps = ("] + steps + [")", f"_{k}_outputs = ("] + outs + [")",
            f"_{k}, _{k}_rows = kernel_intrinsic({len(spec.inputs)}, _{k}_steps, _{k}_outputs)", "", "",
            "@njit(cache=True, nogil=True, no_cfunc_wrapper=True)", f"def {k}_1({args}, out):",
            f'    """{spec.doc}: one configuration, out {spec.shape}."""', f"    _{k}({args}, out)", "", "",
            "@njit(cache=True, nogil=True, no_cfunc_wrapper=True)", f"def {k}_n({args}, out):",
            f'    """{spec.doc}: a batch, inputs (B, k), out (B,) + {spec.shape}."""',
            # LANES rows per call (the last call masks the lanes past the end)
            f"    for b in range(0, {first}.shape[0], {LANES}):", f"        _{k}_rows({args}, out, b)", "", "",
            # compiled as a cfunc on first use, with _{k}_entry made then (see denavit.codegen._fastcall)
            f"def {k}_entry(self, args, nargs, kwnames):",
            f'    """{spec.doc}: the CPython fast-call entry of one configuration."""',
            f"    return _{k}_entry(self, args, nargs, kwnames)", "", ""])


def _numba_group(specs: dict[str, KernelSpec]) -> list[str]:
    """``group_n(sel, a_0, …, a_{m-1}, out)``: the batch form of every kernel of the module in one compiled function
    (kernel ``GROUP[sel]``; inputs (B, k), fewer than m inputs: the first repeated; ``out`` (B, size)).  numba
    spends about 0.1 s of fixed cost on each function it compiles: one for all the batches of a group."""
    names = [k for k in specs if k not in INTERNAL]
    if not names:
        return []
    arity = max(len(specs[k].inputs) for k in names)
    programs = [f"    ({len(specs[k].inputs)}, _{k}_steps, _{k}_outputs, {specs[k].shape!r})," for k in names]
    args = ", ".join(f"a{i}" for i in range(arity))
    return ([f"GROUP = {tuple(names)!r}", f"GROUP_ARITY = {arity}", f"_group_1, _group_rows = group_intrinsic({arity}, ("] + programs + ["))", "", "",
             "@njit(cache=True, nogil=True, no_cfunc_wrapper=True)", f"def group_n(sel, {args}, out):",
             '    """Kernel GROUP[sel] on a batch: inputs (B, k), out (B, size)."""',
             f"    _group_rows(sel, {args}, out)", "", ""])


def group_batch(module, name: str):
    """Kernel ``name`` of a generated module's ``group_n`` as ``f(*inputs, out)``, the form of ``<name>_n``: inputs
    (B, k) (missing ones filled with the first), ``out`` (B,) + shape, C-contiguous (a fresh array or a checked
    ``out=``), seen as (B, size); None when the module has no group holding it (the numpy backend)."""
    group = getattr(module, "GROUP", ())
    if name not in group:
        return None
    kernel, sel, arity = module.group_n, group.index(name), module.GROUP_ARITY

    def many(*arrays):
        *inputs, out = arrays
        inputs = [x.view() for x in inputs]
        for x in inputs:  # read-only, as broadcast inputs are: one signature (numba types mutability) for all
            x.flags.writeable = False
        inputs += [inputs[0]] * (arity - len(inputs))
        flat = out.view()
        flat.shape = (out.shape[0], math.prod(out.shape[1:]))  # raises rather than copy: out is C-contiguous
        kernel(sel, *inputs, flat)

    return many


def _python_kernel(spec: KernelSpec) -> list[str]:
    """``<name>_1(inputs..., out)`` (one configuration, inputs (k,)) and ``<name>_n(inputs..., out)`` (a batch, (B, k)
    inputs, (B,) + shape output)."""
    args = ", ".join(name for name, _ in spec.inputs)
    used = _used_inputs(spec)
    name = _Names(spec, NUMPY)
    shape = spec.shape
    L: list[str] = []
    # --- one configuration ---------------------------------------------------------------------------
    L += [f"def {spec.name}_1({args}, out):", f'    """{spec.doc}: one configuration, out {shape}."""']
    for a, size in spec.inputs:
        names = [f"{a}_{k}" if (a, k) in used else "_" for k in range(size)]
        if any(x != "_" for x in names):
            L.append(f"    {', '.join(names)}, = {a}.tolist()")
    L += ["    " + s for s in _statements(spec, NUMPY)]
    L += [f"    out[{', '.join(map(str, _index(shape, f)))}] = {name(_ref(o))}" for f, o in enumerate(spec.outputs)]
    L += ["", ""]
    # --- a batch: numpy on chunks of CHUNK configurations, values kept in as few arrays as live at once ----
    L += [f"def {spec.name}_n({args}, out):", f'    """{spec.doc}: a batch, inputs (B, k), out (B,) + {shape}."""',
          f"    for s in range(0, {spec.inputs[0][0]}.shape[0], CHUNK):", "        e = s + CHUNK"]
    pad = "        "
    for a, _ in spec.inputs:
        if any(x == a for x, _ in used):
            L.append(f"{pad}{a}T = np.ascontiguousarray({a}[s:e].T)")
    L += [f"{pad}{a}_{k} = {a}T[{k}]" for a, k in used]
    body, reg = vector_statements(spec)
    L += [pad + x for x in body]
    for f, o in enumerate(spec.outputs):
        value = name(o) if isinstance(o, (int, float)) else reg[o.i]
        L.append(f"{pad}out[s:e, {', '.join(map(str, _index(shape, f)))}] = {value}")
    L += ["", ""]
    return L


def vector_statements(spec: KernelSpec, ns: str = "np") -> tuple[list[str], dict[int, str]]:
    """The program on arrays, each result in a register ``r<k>`` reused once its value is dead (a linear
    scan over the straight-line code): a batch keeps tens of arrays alive, not one per operation.  ``ns``: the
    array namespace (``np``; ``xp`` for torch or jax.numpy, whose sin, cos, sign, minimum, maximum are numpy's);
    each register is rebound, never written in place, so autograd and tracing JITs follow it."""
    tape = spec.tape
    prog = tape.program(spec.outputs)
    last: dict[int, float] = {}
    for pos, i in enumerate(prog):
        op, a, b = tape.ops[i]
        if op != "input":
            for x in (a, b):
                if isinstance(x, int):
                    last[x] = pos
    for o in spec.outputs:
        if not isinstance(o, (int, float)):
            last[o.i] = float("inf")
    reg: dict[int, str] = {}
    free: list[str] = []
    count = 0
    lines = []
    for pos, i in enumerate(prog):
        op, a, b = tape.ops[i]
        if op == "input":
            reg[i] = f"{a}_{b}"
            continue

        def ref(x):
            return _const(x, "py") if isinstance(x, float) else reg[x]

        expr = _expression(op, ref(a), ref(b) if b is not None else None, "py", True, ns)
        for x in {a, b}:
            if isinstance(x, int) and last.get(x) == pos and tape.ops[x][0] != "input":
                free.append(reg[x])
        if free:
            target = free.pop()
        else:
            target = f"r{count}"
            count += 1
        reg[i] = target
        lines.append(f"{target} = {expr}")
    return lines, reg


def _ref(o):
    """An output entry as a node index (int) or a constant (float)."""
    return float(o) if isinstance(o, (int, float)) else o.i


def python_module(specs: dict[str, KernelSpec], backend: str, title: str) -> str:
    """A Python module with ``<name>_1`` / ``<name>_n`` for every kernel (numba-jitted or numpy).

    ``title`` opens the module's docstring: it holds no user text (the robot's name never enters code), and a
    ``\"\"\"`` or a backslash, which would end the docstring or start an escape, is refused.
    """
    if '"""' in title or "\\" in title:
        raise ValueError("a Python docstring cannot hold '\"\"\"' or a backslash here")
    head = [f'"""{title}', "", "Generated by denavit.compile: straight-line code, do not edit.",
            f"Backend: {backend}.  Each kernel has <name>_1(inputs..., out) for one configuration and <name>_n(inputs..., out) for",
            'batches (inputs shaped (B, k), out (B,) + shape)."""', "", "import math", "", "import numpy as np"]
    if backend == NUMBA:
        head += ["from numba import njit", "", "from denavit.codegen._llvm import group_intrinsic, kernel_intrinsic", "", ""]
    else:
        head += ["", "CHUNK = 8192  # configurations per pass: the live arrays stay in cache", "", "",
                 "def _sign(x):", "    return 1.0 if x > 0.0 else (-1.0 if x < 0.0 else 0.0)", "", ""]
    body: list[str] = []
    for spec in specs.values():
        body += _numba_kernel(spec) if backend == NUMBA else _python_kernel(spec)
    if backend == NUMBA:
        body += _numba_group(specs)
    if backend == NUMBA and "fk" in specs and "fk_jacobian0" in specs:
        body += ik_lm_lines()  # the LM of denavit.ik.lm with this module's FK + Jacobian kernel
    return "\n".join(head + body).rstrip() + "\n"


def c_sources(specs: dict[str, KernelSpec], prefix: str, title: str) -> tuple[str, str]:
    """(header, source) of C99 functions ``void <prefix>_<name>(const double *in..., double *out)``."""
    protos, bodies = [], []
    for spec in specs.values():
        args = ", ".join(f"const double {a}[{k}]" for a, k in spec.inputs)
        size = 1
        for s in spec.shape:
            size *= s
        proto = f"void {prefix}_{spec.name}({args}, double out[{size}])"
        shape = "x".join(map(str, spec.shape))
        protos.append(f"/* {spec.doc}; out: {shape}, row-major. */\n{proto};")
        name = _Names(spec, "c")
        lines = [f"{proto}", "{"]
        lines += [f"    (void){a};" for a, _ in spec.inputs if a not in {x for x, _ in _used_inputs(spec)}]
        lines += [f"    const double {a}_{k} = {a}[{k}];" for a, k in _used_inputs(spec)]
        lines += ["    " + s for s in _statements(spec, "c")]
        lines += [f"    out[{f}] = {name(_ref(o))};" for f, o in enumerate(spec.outputs)]
        lines += ["}", ""]
        bodies.append("\n".join(lines))
    if "*/" in title:
        raise ValueError("a C comment cannot hold '*/'")
    title = title.replace("\n", "\n * ")
    guard = f"{prefix.upper()}_H"
    header = "\n".join([f"/* {title}", " * Generated by denavit: C99, libm only, no allocation. */",
                        f"#ifndef {guard}", f"#define {guard}", "", "#ifdef __cplusplus", 'extern "C" {', "#endif",
                        "", "\n\n".join(protos), "", "#ifdef __cplusplus", "}", "#endif", "", f"#endif /* {guard} */", ""])
    source = "\n".join([f"/* {title}", " * Generated by denavit: C99, libm only, no allocation. */",
                        "#include <math.h>", f'#include "{prefix}.h"', "", *bodies])
    return header, source
