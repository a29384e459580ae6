"""Source of an arm's kernels for a tensor framework (PyTorch or JAX): the tape's program on whole tensors.

One generator for both frameworks: the kernel bodies are the numpy backend's vector statements
(:func:`denavit.codegen._emit.vector_statements`) in the namespace ``xp`` — ``torch`` or ``jax.numpy``, whose
``sin``, ``cos``, ``sign``, ``minimum``, ``maximum`` are numpy's — and only a short prelude (how to split the last
axis, stack the outputs, broadcast the inputs and solve a linear system) differs between them.  Each operation of
the tape runs once on tensors of the batch shape (a sine or cosine of one angle is one node of the tape, computed
once); registers are rebound, never written in place, and the outputs are assembled with ``stack``, so autograd,
``torch.compile``, ``jax.jit``, ``jax.grad`` and ``vmap`` all follow the code.  Constants are Python floats, which
both frameworks treat as weakly typed: a float32 input stays float32.

One difference is there for speed: in JAX the sines and cosines of a kernel's joint angles come from one
``_sincos`` call on the input array (polynomials XLA vectorises, the numba backend's SIMD ones, inside a
``lax.cond`` whose branches XLA keeps whole, with ``jax.custom_jvp`` derivatives).  XLA's own sine and cosine are
one libm call per element on CPU (about 17 ns here, in float32 too), and XLA fuses each output entry into a loop
of its own that recomputes everything it depends on, the sines included: a 6-joint FK evaluated 111 sines and
cosines per configuration for the program's 12, and ran 25 to 100 times slower than the numba batch kernel.

As for the other backends, only identifiers made here and constants written by ``float.__repr__`` reach the source.
"""

from __future__ import annotations

import math
import re

from ._emit import vector_statements
from ._kernels import KernelSpec

__all__ = ["tensor_module", "FRAMEWORKS"]

FRAMEWORKS = ("torch", "jax")

_TORCH = '''import torch

xp = torch


def _split(x, k):
    """(..., k) -> k tensors of shape (...), each contiguous (one copy of x; autograd follows it)."""
    if x.ndim == 0 or x.shape[-1] != k:
        raise ValueError(f"expected shape (..., {k}), got {tuple(x.shape)}")
    return x.movedim(-1, 0).contiguous().unbind(0)


def _join(entries, shape):
    """Entries of shape (...) -> one tensor of shape (...) + shape (stacked: nothing written in place)."""
    return torch.stack(entries, -1).reshape(tuple(entries[0].shape) + shape)


def _broadcast(*xs):
    """The inputs with their batch axes (all but the last) broadcast together."""
    batch = torch.broadcast_shapes(*[x.shape[:-1] for x in xs])
    return [x.expand(tuple(batch) + (x.shape[-1],)) for x in xs]


def _solve(M, b):
    """x with M x = b, batched: M (..., n, n), b (..., n)."""
    return torch.linalg.solve(M, b.unsqueeze(-1)).squeeze(-1)
'''

_JAX = """import math

import jax
import jax.custom_batching
import jax.numpy as xp
from jax import lax


def _split(x, k):
    \"\"\"(..., k) -> k arrays of shape (...).\"\"\"
    if x.ndim == 0 or x.shape[-1] != k:
        raise ValueError(f"expected shape (..., {k}), got {tuple(x.shape)}")
    return [x[..., i] for i in range(k)]


def _join(entries, shape):
    \"\"\"Entries of shape (...) -> one array of shape (...) + shape, stacked row by row (nothing written in place).
    Rows of a few entries let XLA fuse the entries' loops into the output's; one stack of 16 entries or more it
    leaves as a copy of 16 separate results (a 4x4 pose: 1.3-1.5x the time at 1e4-1e6 configurations).\"\"\"
    if len(shape) == 1:
        return xp.stack(entries, -1)
    step = len(entries) // shape[0]
    return xp.stack([_join(entries[i * step:(i + 1) * step], shape[1:]) for i in range(shape[0])], -len(shape))


def _broadcast(*xs):
    \"\"\"The inputs with their batch axes (all but the last) broadcast together.\"\"\"
    batch = xp.broadcast_shapes(*[x.shape[:-1] for x in xs])
    return [xp.broadcast_to(x, tuple(batch) + (x.shape[-1],)) for x in xs]


def _solve(M, b):
    \"\"\"x with M x = b, batched: M (..., n, n), b (..., n).\"\"\"
    return xp.linalg.solve(M, b[..., None])[..., 0]


# Batches of _BLOCKED_FROM configurations or more run in blocks of _BLOCK rows (see _blocked): a block's inputs,
# sines, cosines and output stay in cache.
_BLOCK = BLOCK_ROWS
_BLOCKED_FROM = BLOCKED_FROM

OUTPUT_BUFFER


def _blocked(kernel, *xs):
    \"\"\"kernel(*xs) on inputs (..., k) whose batch axes are broadcast together; from _BLOCKED_FROM rows on, in
    blocks of _BLOCK rows inside one lax.fori_loop.  XLA otherwise allocates every intermediate array of the whole
    batch afresh on each call, tens of MB, and pays a page fault per 4 KB of it (at 10**6 rows most of the time).
    Each step computes its block inside a lax.cond whose two branches are the same kernel (the predicate, always
    true, does not matter): XLA keeps a branch whole, so the block goes into a buffer of its own by the kernel's
    vectorised loop and is then copied into the output (fused into the write at a dynamic offset, it compiled to
    scalar code; carried to the next step instead, it cost a copy more: 15-20% of a float64 call).  The last
    block ends at the last row, overlapping the one before (those rows are written twice with the same values):
    every row of the output is written, so its initial buffer (_output_buffer) needs no values.  jit, grad (a
    scan), jacfwd and vmap follow it.\"\"\"
    batch = xs[0].shape[:-1]
    rows = math.prod(batch)
    if rows < max(_BLOCKED_FROM, 2 * _BLOCK):
        return kernel(*xs)
    flat = [x.reshape((rows, x.shape[-1])) for x in xs]
    block = jax.eval_shape(kernel, *[jax.ShapeDtypeStruct((_BLOCK, x.shape[-1]), x.dtype) for x in flat])

    def step(i, out):
        start = xp.minimum(i * _BLOCK, rows - _BLOCK)
        part = [lax.dynamic_slice_in_dim(x, start, _BLOCK) for x in flat]
        return lax.dynamic_update_slice_in_dim(out, lax.cond(i >= 0, kernel, kernel, *part), start, 0)

    out = lax.fori_loop(0, -(-rows // _BLOCK), step, _output_buffer((rows,) + block.shape[1:], block.dtype))
    return out.reshape(batch + block.shape[1:])


# sin and cos by polynomials XLA vectorises (its own sine and cosine on CPU are one libm call per element, in
# float32 too): x = k*pi/2 + r by Cody-Waite reduction in three parts (k*P[0], k*P[1] exact for |x| <= RANGE),
# Taylor polynomials of sin r and cos r on [-pi/4, pi/4] truncated below 1e-19 (float32: below 2e-9), the quadrant
# k mod 4 choosing +-sin r / +-cos r: within an ulp or two of libm (the numba backend's SIMD kernels use the same).
_SC = {"float64": (TWO_OVER_PI_64, P_64, RANGE_64, SIN_TAYLOR, COS_TAYLOR),
       "float32": (TWO_OVER_PI_32, P_32, RANGE_32, SIN_TAYLOR_32, COS_TAYLOR_32)}


def _poly_sincos(x, in_range):
    \"\"\"(sin x, cos x) for |x| <= RANGE (NaN stays NaN).\"\"\"
    two_over_pi, parts, _, sin_taylor, cos_taylor = _SC[x.dtype.name]
    k = xp.round(x * two_over_pi)
    r = x
    for p in parts:
        r = r - k * p
    z = r * r
    n = xp.where(in_range, k, 0.0).astype(xp.int32)
    odd = (n & 1) != 0  # sin x is +-cos r, cos x is +-sin r
    cos_taylor = tuple(cos_taylor) + (0.0,) * (len(sin_taylor) - len(cos_taylor))  # acc = 0 * z + C[-1] first

    def one(use_cos):
        \"\"\"sin r or cos r, whichever use_cos picks: one polynomial per output element, its coefficients selected
        (XLA computes sin x and cos x in two loops: with both polynomials in each, 2-10% slower).\"\"\"
        acc = xp.where(use_cos, cos_taylor[-1], sin_taylor[-1])
        for cs, cc in zip(reversed(sin_taylor[:-1]), reversed(cos_taylor[:-1])):
            acc = acc * z + xp.where(use_cos, cc, cs)
        return xp.where(use_cos, 1.0 - z * 0.5, r) + xp.where(use_cos, z * z, z * r) * acc

    s, c = one(odd), one(~odd)
    return xp.where((n & 2) != 0, -s, s), xp.where(((n + 1) & 2) != 0, -c, c)


def _sincos_rows(x):
    \"\"\"(sin x, cos x), elementwise, each computed once: the branches of a lax.cond are kept whole, where XLA
    would otherwise recompute the polynomials inside every fused loop that uses them.  Angles beyond the
    reduction's range (or a dtype other than float32 and float64) take XLA's sin and cos.\"\"\"
    if x.dtype.name not in _SC:
        return xp.sin(x), xp.cos(x)
    limit = _SC[x.dtype.name][2]

    def polynomial(x):
        return _poly_sincos(x, xp.abs(x) <= limit)

    def with_libm(x):
        in_range = xp.abs(x) <= limit
        s, c = _poly_sincos(x, in_range)
        return xp.where(in_range, s, xp.sin(x)), xp.where(in_range, c, xp.cos(x))

    return lax.cond(xp.any(xp.abs(x) > limit), with_libm, polynomial, x)


def _sincos_batched(axis_size, in_batched, x):
    \"\"\"Under vmap: the whole batched array at once (elementwise), so that the range test stays one lax.cond
    rather than a select evaluating both branches.\"\"\"
    return _sincos_rows_vmap(x), (in_batched[0], in_batched[0])


_sincos_rows_vmap = jax.custom_batching.custom_vmap(_sincos_rows)
_sincos_rows_vmap.def_vmap(_sincos_batched)
_sincos_d = jax.custom_jvp(_sincos_rows_vmap)


@_sincos_d.defjvp
def _sincos_jvp(primals, tangents):
    (x,), (dx,) = primals, tangents
    s, c = _sincos_d(x)
    return (s, c), (c * dx, -s * dx)


@jax.jit
def _sincos(x):
    \"\"\"(sin x, cos x) of an array (one compiled call when run op by op; inlined under jax.jit).\"\"\"
    return _sincos_d(x)
"""

#: The JAX prelude's sine and cosine (the numba backend's SIMD polynomials, denavit.codegen._llvm): π/2 in three
#: parts whose first two times k are exact for |k| < 2**20 (float64: 33, 33, 53 bits; float32, Cephes' split: 8, 11,
#: 24 bits, exact for |k| < 2**13), the reduction's range (half that) and the Taylor coefficients in r² of
#: sin r = r + r³·S(r²), cos r = 1 − r²/2 + r⁴·C(r²) (first omitted terms below 1e-19 and 3e-18 on [−π/4, π/4];
#: float32 keeps the first 4 of each, omitted terms below 2e-9 and 2e-10: the same largest error against libm in
#: float64, 0.76 and 0.77 ulp of 1 in float32, on 3·10⁵ angles up to 6000, and half the polynomial's work).
_PIO2_64 = (float.fromhex("0x1.921fb54400000p+0"), float.fromhex("0x1.0b4611a600000p-34"),
            float.fromhex("0x1.3198a2e037073p-69"))
_PIO2_32 = (1.5703125, 4.837512969970703125e-4, 7.54978995489188216e-8)
_RANGE_64, _RANGE_32 = 2.0 ** 19 * (math.pi / 2), 2.0 ** 12 * (math.pi / 2)
_SIN_TAYLOR = tuple((-1.0) ** (k + 1) / math.factorial(2 * k + 3) for k in range(8))
_COS_TAYLOR = tuple((-1.0) ** k / math.factorial(2 * k + 4) for k in range(7))
_TAYLOR_TERMS_32 = 4
#: The JAX kernels' batches from BLOCKED_FROM configurations on run in blocks of BLOCK_ROWS (the prelude's
#: _blocked; FK, one core, time of one pass / time in blocks: Puma 560 float64 0.92 at 3·10⁴ rows, 0.97 at 7·10⁴,
#: 1.15 at 10⁵, 2 at 2·10⁵; Panda float32 0.89 at 10⁵, 1.1 at 2·10⁵; blocks of 1024-4096 rows within 7% at 10⁶).
BLOCK_ROWS = 2048
BLOCKED_FROM = 2 ** 17


def _jax_prelude() -> str:
    """The JAX prelude with its constants written in (``float.__repr__``: exact round trips)."""
    two_over_pi = repr(2.0 / math.pi)
    values = {"TWO_OVER_PI_64": two_over_pi, "TWO_OVER_PI_32": two_over_pi, "P_64": repr(_PIO2_64),
              "P_32": repr(_PIO2_32), "RANGE_64": repr(_RANGE_64), "RANGE_32": repr(_RANGE_32),
              "SIN_TAYLOR_32": repr(_SIN_TAYLOR[:_TAYLOR_TERMS_32]),
              "COS_TAYLOR_32": repr(_COS_TAYLOR[:_TAYLOR_TERMS_32]),
              "SIN_TAYLOR": repr(_SIN_TAYLOR), "COS_TAYLOR": repr(_COS_TAYLOR), "BLOCK_ROWS": repr(BLOCK_ROWS),
              "BLOCKED_FROM": repr(BLOCKED_FROM)}
    text = _JAX
    for name, value in values.items():  # the longer names first (SIN_TAYLOR_32 before SIN_TAYLOR)
        text = re.sub(rf"\b{name}\b", value, text)
    return text


#: How the JAX blocks' output buffer is made: in denavit's own (cached) modules by denavit's output_buffer, which on
#: Linux CPU leaves it uninitialised and advised huge pages (denavit.codegen._xla_pages: page faults were most of
#: a 10**6-pose call); in an exported module, needing only JAX, XLA's zeros.
_OUTPUT_BUFFER = {
    False: "from denavit.codegen._xla_pages import output_buffer as _output_buffer  # noqa: E402 (huge pages on CPU)",
    True: 'def _output_buffer(shape, dtype):\n    """The blocks\' output buffer (they write every row of it)."""\n'
           "    return xp.zeros(shape, dtype)"}
_PRELUDES = {"torch": _TORCH, "jax": _jax_prelude()}

_FORWARD_DYNAMICS = '''

def forward_dynamics(q, qd, tau):
    """qdd = M(q)^-1 (tau - c(q, qd) - g(q) - tau_f(qd)), shape (..., n): the bias by rnea with qdd = 0 and the
    framework's linear solve (no check of M's regularity: a singular M gives what the solve gives)."""
    q, qd, tau = _broadcast(q, qd, tau)
    return _solve(mass_matrix(q), tau - rnea(q, qd, xp.zeros_like(qd)))
'''


def _constant(v) -> str:
    """A finite constant as ``float.__repr__`` writes it (the model refuses non-finite numbers: a bug if reached)."""
    if not math.isfinite(v):
        raise ValueError(f"non-finite constant {v!r} in a kernel")
    return repr(float(v))


def _trig_of_inputs(spec: KernelSpec, body: list[str]) -> tuple[list[str], list[str]]:
    """For JAX: the sines and cosines of input columns read from one ``_sincos`` call per input (its polynomials
    computed once, see the prelude) instead of ``xp.sin`` / ``xp.cos`` per column, on the columns moved first
    ((..., k) -> (k, ...): the polynomials run on whole rows and each column is read contiguously, 15-20% of a
    block's time in float64, 25-30% in float32, against the (..., k) layout).  Returns the lines computing
    the table and the body with those statements rewritten; ``body`` holds one line per non-input node of the
    program, in its order (:func:`denavit.codegen._emit.vector_statements`)."""
    tape = spec.tape
    nodes = [i for i in tape.program(spec.outputs) if tape.ops[i][0] != "input"]
    trig = {}  # line number -> (op, input name, column)
    for n, i in enumerate(nodes):
        op, a, _ = tape.ops[i]
        if op in ("sin", "cos") and isinstance(a, int) and tape.ops[a][0] == "input":
            trig[n] = (op, tape.ops[a][1], tape.ops[a][2])
    columns = {name: sorted({k for _, a, k in trig.values() if a == name}) for _, name, _ in trig.values()}
    head, slot = [], {}
    for name, ks in columns.items():
        pick = f"{name}[..., {ks!r}]" if ks != list(range(dict(spec.inputs)[name])) else name
        head.append(f"    _s_{name}, _c_{name} = _sincos(xp.moveaxis({pick}, -1, 0))")
        slot.update({(name, k): j for j, k in enumerate(ks)})
    body = list(body)
    for n, (op, name, k) in trig.items():
        target = body[n].split(" = ", 1)[0]
        body[n] = f"{target} = _{op[0]}_{name}[{slot[name, k]}]"
    return head, body


def _kernel(spec: KernelSpec, framework: str) -> list[str]:
    """``def <name>(inputs...)``: the program on tensors of the batch shape, outputs stacked to (...) + shape."""
    args = ", ".join(a for a, _ in spec.inputs)
    L = [f"def {spec.name}({args}):",
         f'    """{spec.doc}: {", ".join(f"{a} (..., {k})" for a, k in spec.inputs)} -> (...) + {spec.shape!r}."""']
    if len(spec.inputs) > 1:
        L.append(f"    {args}, = _broadcast({args})")
    if framework == "jax":  # the batch in cache-sized blocks (the prelude's _blocked) of the rows' program below
        L += [f"    return _blocked(_{spec.name}_rows, {args})", "", "",
              f"def _{spec.name}_rows({args}):", f'    """{spec.name} on inputs whose batch axes match."""']
    body, reg = vector_statements(spec, "xp")
    head = []
    if framework == "jax":
        head, body = _trig_of_inputs(spec, body)
    entries = [reg[o.i] if not isinstance(o, (int, float)) else "_z" if float(o) == 0.0 else f"(_z + {_constant(o)})"
               for o in spec.outputs]
    used = set(re.findall(r"\b[A-Za-z]\w*_\d+\b", " ".join(body + entries)))  # columns still read as such
    for a, k in spec.inputs:
        L.append(f"    _{a} = _split({a}, {k})")
        L += [f"    {a}_{i} = _{a}[{i}]" for i in range(k) if f"{a}_{i}" in used]
    L += head
    L += ["    " + s for s in body]
    if any(isinstance(o, (int, float)) for o in spec.outputs):  # a constant entry: a tensor of the batch shape
        L.append(f"    _z = xp.zeros_like(_{spec.inputs[0][0]}[0])")
    L.append(f"    return _join([{', '.join(entries)}], {spec.shape!r})")
    return L + ["", ""]


def tensor_module(specs: dict[str, KernelSpec], framework: str, title: str, standalone: bool = True) -> str:
    """A module needing only ``framework`` (``"torch"`` or ``"jax"``) with one function per kernel, named as the
    kernel (``fk(q)``, ``jacobian0(q)``, ``rnea(q, qd, qdd)``, …), on inputs (..., k) broadcast over their leading
    axes, and ``forward_dynamics(q, qd, tau)`` (by the framework's linear solve) when ``rnea`` and ``mass_matrix``
    are among them (a traced ``forward_dynamics`` kernel is left out).

    ``title`` opens the module's docstring (no user text: a ``\"\"\"`` or a backslash is refused).  ``standalone``
    (an exported module): JAX's blocks start from XLA's zeros; otherwise (the kernel cache's module) from
    denavit's output buffer, advised huge pages on Linux CPU (:mod:`denavit.codegen._xla_pages`).
    """
    if framework not in FRAMEWORKS:
        raise ValueError(f"framework must be one of {', '.join(FRAMEWORKS)}, got {framework!r}")
    if '"""' in title or "\\" in title:
        raise ValueError("a Python docstring cannot hold '\"\"\"' or a backslash here")
    head = [f'"""{title}', "", "Generated by denavit: straight-line code on tensors, do not edit.",
            f"Framework: {framework}.  Each kernel <name>(inputs...) takes inputs (..., k), broadcast over their",
            "leading axes, and returns (...) + its shape, on the inputs' device and dtype; differentiable and",
            'jit-compatible (no in-place writes)."""', "",
            _PRELUDES[framework].replace("OUTPUT_BUFFER", _OUTPUT_BUFFER[standalone]), ""]
    body: list[str] = []
    for spec in specs.values():
        if spec.name != "forward_dynamics":  # the traced LDLᵀ solve gives way to the framework's (below)
            body += _kernel(spec, framework)
    text = "\n".join(head + body).rstrip() + "\n"
    if "rnea" in specs and "mass_matrix" in specs:
        text += _FORWARD_DYNAMICS
    return text
