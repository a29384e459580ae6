"""Source of an arm's kernels for a tensor framework (PyTorch or JAX): the tape's program on whole tensors.

One generator for both frameworks: the kernel bodies are the numpy backend's vector statements
(:func:`denavit.codegen._emit.vector_statements`) in the namespace ``xp`` — ``torch`` or ``jax.numpy``, whose
``sin``, ``cos``, ``sign``, ``minimum``, ``maximum`` are numpy's — and only a short prelude (how to split the last
axis, stack the outputs, broadcast the inputs and solve a linear system) differs between them.  Each operation of
the tape runs once on tensors of the batch shape (a sine or cosine of one angle is one node of the tape, computed
once); registers are rebound, never written in place, and the outputs are assembled with ``stack``, so autograd,
``torch.compile``, ``jax.jit``, ``jax.grad`` and ``vmap`` all follow the code.  Constants are Python floats, which
both frameworks treat as weakly typed: a float32 input stays float32.

As for the other backends, only identifiers made here and constants written by ``float.__repr__`` reach the source.
"""

from __future__ import annotations

import math

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

_JAX = '''import jax.numpy as xp


def _split(x, k):
    """(..., k) -> k arrays of shape (...)."""
    if x.ndim == 0 or x.shape[-1] != k:
        raise ValueError(f"expected shape (..., {k}), got {tuple(x.shape)}")
    return [x[..., i] for i in range(k)]


def _join(entries, shape):
    """Entries of shape (...) -> one array of shape (...) + shape (stacked: nothing written in place)."""
    return xp.stack(entries, -1).reshape(tuple(entries[0].shape) + shape)


def _broadcast(*xs):
    """The inputs with their batch axes (all but the last) broadcast together."""
    batch = xp.broadcast_shapes(*[x.shape[:-1] for x in xs])
    return [xp.broadcast_to(x, tuple(batch) + (x.shape[-1],)) for x in xs]


def _solve(M, b):
    """x with M x = b, batched: M (..., n, n), b (..., n)."""
    return xp.linalg.solve(M, b[..., None])[..., 0]
'''

_PRELUDES = {"torch": _TORCH, "jax": _JAX}

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


def _kernel(spec: KernelSpec) -> list[str]:
    """``def <name>(inputs...)``: the program on tensors of the batch shape, outputs stacked to (...) + shape."""
    args = ", ".join(a for a, _ in spec.inputs)
    L = [f"def {spec.name}({args}):",
         f'    """{spec.doc}: {", ".join(f"{a} (..., {k})" for a, k in spec.inputs)} -> (...) + {spec.shape!r}."""']
    if len(spec.inputs) > 1:
        L.append(f"    {args}, = _broadcast({args})")
    body, reg = vector_statements(spec, "xp")
    tape = spec.tape
    used = {f"{tape.ops[i][1]}_{tape.ops[i][2]}" for i in tape.program(spec.outputs) if tape.ops[i][0] == "input"}
    for a, k in spec.inputs:
        L.append(f"    _{a} = _split({a}, {k})")
        L += [f"    {a}_{i} = _{a}[{i}]" for i in range(k) if f"{a}_{i}" in used]
    L += ["    " + s for s in body]
    entries = [reg[o.i] if not isinstance(o, (int, float)) else "_z" if float(o) == 0.0 else f"(_z + {_constant(o)})"
               for o in spec.outputs]
    if any(isinstance(o, (int, float)) for o in spec.outputs):  # a constant entry: a tensor of the batch shape
        L.append(f"    _z = xp.zeros_like(_{spec.inputs[0][0]}[0])")
    L.append(f"    return _join([{', '.join(entries)}], {spec.shape!r})")
    return L + ["", ""]


def tensor_module(specs: dict[str, KernelSpec], framework: str, title: str) -> str:
    """A module needing only ``framework`` (``"torch"`` or ``"jax"``) with one function per kernel, named as the
    kernel (``fk(q)``, ``jacobian0(q)``, ``rnea(q, qd, qdd)``, …), on inputs (..., k) broadcast over their leading
    axes, and ``forward_dynamics(q, qd, tau)`` (by the framework's linear solve) when ``rnea`` and ``mass_matrix``
    are among them (a traced ``forward_dynamics`` kernel is left out).

    ``title`` opens the module's docstring (no user text: a ``\"\"\"`` or a backslash is refused).
    """
    if framework not in FRAMEWORKS:
        raise ValueError(f"framework must be one of {', '.join(FRAMEWORKS)}, got {framework!r}")
    if '"""' in title or "\\" in title:
        raise ValueError("a Python docstring cannot hold '\"\"\"' or a backslash here")
    head = [f'"""{title}', "", "Generated by denavit: straight-line code on tensors, do not edit.",
            f"Framework: {framework}.  Each kernel <name>(inputs...) takes inputs (..., k), broadcast over their",
            "leading axes, and returns (...) + its shape, on the inputs' device and dtype; differentiable and",
            'jit-compatible (no in-place writes)."""', "", _PRELUDES[framework], ""]
    body: list[str] = []
    for spec in specs.values():
        if spec.name != "forward_dynamics":  # the traced LDLᵀ solve gives way to the framework's (below)
            body += _kernel(spec)
    text = "\n".join(head + body).rstrip() + "\n"
    if "rnea" in specs and "mass_matrix" in specs:
        text += _FORWARD_DYNAMICS
    return text
