"""Standalone source of an arm's kernels: C99 (header + source, libm only), a numpy-only Python module, or a
module needing only PyTorch or JAX."""

from __future__ import annotations

import re

from ..model import DHRobot
from ._emit import NUMPY, c_sources, python_module
from ._kernels import INTERNAL, KERNEL_NAMES, registered_kernels, trace_kernels, trace_registered
from ._tensor_emit import FRAMEWORKS, tensor_module

__all__ = ["export_sources", "default_prefix", "PREFIX_PATTERN", "LANGUAGES"]

LANGUAGES = ("c", "python") + FRAMEWORKS
#: A prefix becomes C identifiers and file names: letters, digits, underscores, at most 40, not a digit first.
PREFIX_PATTERN = re.compile(r"[A-Za-z_][A-Za-z0-9_]{0,39}")

_PY_API = '''

# --- convenience: (n,) or (..., n) in, arrays out -------------------------------------------------------
N = {n}


def _call(one, many, shape, *xs, lengths=None):
    xs = [np.asarray(x, dtype=float) for x in xs]
    for x, k in zip(xs, lengths or [N] * len(xs)):
        if x.ndim == 0 or x.shape[-1] != k:
            raise ValueError(f"expected shape (..., {{k}}), got {{x.shape}}")
    if all(x.ndim == 1 for x in xs):
        out = np.empty(shape)
        one(*xs, out)
        return out
    batch = np.broadcast_shapes(*[x.shape[:-1] for x in xs])
    flat = [np.ascontiguousarray(np.broadcast_to(x, batch + x.shape[-1:]).reshape(-1, x.shape[-1])) for x in xs]
    out = np.empty((flat[0].shape[0],) + shape)
    if out.shape[0]:
        many(*flat, out)
    return out.reshape(batch + shape)
'''

_PY_WRAPPERS = {
    "fk": ("fk(q)", "T_w_e, shape (..., 4, 4)", "q"),
    "position": ("position(q)", "p_w_e, the end-effector origin, shape (..., 3)", "q"),
    "frames": ("frames(q)", "world poses of the DH frames {{0}} ... {{N}}, shape (..., {rows}, 4, 4)", "q"),
    "jacobian0": ("jacobian0(q)", "geometric Jacobian J0 (base frame), rows (v, w), shape (..., 6, n)", "q"),
    "jacobiane": ("jacobiane(q)", "geometric Jacobian Je (tool frame), rows (v, w), shape (..., 6, n)", "q"),
    "rnea": ("rnea(q, qd, qdd)", "inverse dynamics tau (gravity and friction of the model), shape (..., n)",
             "q, qd, qdd"),
    "mass_matrix": ("mass_matrix(q)", "M(q), shape (..., n, n)", "q"),
    "gravity": ("gravity(q)", "g(q), shape (..., n)", "q"),
    "coriolis": ("coriolis(q, qd)", "c(q, qd) = C(q, qd) qd, shape (..., n)", "q, qd"),
}


def default_prefix(robot: DHRobot) -> str:
    """A C identifier from the robot's name (non-identifier characters become ``_``)."""
    text = re.sub(r"[^A-Za-z0-9_]", "_", robot.name)[:40] or "robot"
    return text if PREFIX_PATTERN.fullmatch(text) else ("r" + text)[:40]


def export_sources(robot: DHRobot, lang: str, prefix: str | None = None, kernels=None) -> dict[str, str]:
    """The files of a standalone export, ``{file name: text}``.

    ``lang="c"``: ``<prefix>.h`` and ``<prefix>.c`` — functions ``void <prefix>_<kernel>(const double q[n],
    ..., double out[k])`` writing row-major results, C99, libm only, no allocation.  ``lang="python"``:
    ``<prefix>.py``, needing only numpy, with ``fk(q)``, ``jacobian0(q)``, … on ``(n,)`` or ``(..., n)``.
    ``lang="torch"`` / ``"jax"``: ``<prefix>.py`` needing only that framework, one function per kernel on the
    framework's tensors (``fk(q)``, ``jacobian0(q)``, ``rnea(q, qd, qdd)``, ``forward_dynamics(q, qd, tau)`` by
    its linear solve, …), differentiable and jit-compatible (:mod:`denavit.codegen._tensor_emit`).
    ``kernels``: the built-in names (default all of ``KERNEL_NAMES`` the arm supports) and registered ones
    (:func:`~denavit.codegen.register_kernel`; ``"all"`` for every built-in and registered kernel).
    """
    if lang not in LANGUAGES:
        raise ValueError(f"lang must be one of {', '.join(LANGUAGES)}, got {lang!r}")
    prefix = default_prefix(robot) if prefix is None else prefix
    if not PREFIX_PATTERN.fullmatch(prefix):
        raise ValueError(f"prefix {prefix!r}: expected a C identifier of at most 40 characters")
    reg = registered_kernels()
    kernels = KERNEL_NAMES if kernels is None else (KERNEL_NAMES + tuple(reg) if kernels == "all" else tuple(kernels))
    unknown = [k for k in kernels if k not in KERNEL_NAMES and k not in reg]
    if unknown:
        raise ValueError(f"unknown kernels {unknown}; choose from {', '.join(KERNEL_NAMES + tuple(reg))}")
    specs = trace_kernels(robot, [k for k in kernels if k in KERNEL_NAMES])
    specs.update(trace_registered(robot, [k for k in kernels if k in reg]))
    n = robot.dof
    title = f"Kernels of a {n}-joint arm ({robot.convention.value} DH), exported by denavit."
    if lang in FRAMEWORKS:
        return _tensor_export(robot, specs, lang, prefix, title)
    if lang == "c":
        usage = _c_usage(prefix, n, "rnea" in specs)
        header, source = c_sources(specs, prefix, title + usage)
        return {f"{prefix}.h": header, f"{prefix}.c": source}
    text = python_module(specs, NUMPY, title + _py_usage(prefix, n))
    text += _PY_API.format(n=n)
    rows = len(robot.links) + 1
    for name, (sig, doc, args) in _PY_WRAPPERS.items():
        if name in specs:
            text += (f"\n\ndef {sig}:\n    \"\"\"{doc.format(rows=rows)}.\"\"\"\n"
                     f"    return _call({name}_1, {name}_n, {specs[name].shape!r}, {args})\n")
    for name in (k for k in specs if k in reg):
        spec = specs[name]
        args = ", ".join(a for a, _ in spec.inputs)
        text += (f"\n\ndef {name}({args}):\n    \"\"\"{spec.doc}, shape (...,) + {spec.shape!r}.\"\"\"\n"
                 f"    return _call({name}_1, {name}_n, {spec.shape!r}, {args}, "
                 f"lengths={[k for _, k in spec.inputs]!r})\n")
    if "forward_dynamics" in specs:
        text += (f"\n\ndef forward_dynamics(q, qd, tau):\n"
                 f"    \"\"\"qdd = M^-1 (tau - c - g - tau_f), shape (..., n); ValueError where M is singular.\"\"\"\n"
                 f"    r = _call(forward_dynamics_1, forward_dynamics_n, {specs['forward_dynamics'].shape!r}, q, qd, tau)\n"
                 f"    if not (r[..., -1] > 0.0).all():\n"
                 f"        raise ValueError(\"the mass matrix is singular at this configuration\")\n"
                 f"    return r[..., :-1]\n")
    return {f"{prefix}.py": text}


def _c_usage(prefix: str, n: int, dynamics: bool) -> str:
    lines = ["", "", "Usage:", f'    #include "{prefix}.h"', f"    double q[{n}] = {{0}}, T[16], J[{6 * n}];",
             f"    {prefix}_fk(q, T);          (T[4*i + j] = T_w_e(i, j))",
             f"    {prefix}_jacobian0(q, J);   (J[{n}*r + k]: row r of (v, w), joint k)"]
    if dynamics:
        lines += [f"    double qd[{n}] = {{0}}, qdd[{n}] = {{0}}, tau[{n}], M[{n * n}], a[{n + 1}];",
                  f"    {prefix}_rnea(q, qd, qdd, tau);",
                  f"    {prefix}_mass_matrix(q, M);",
                  f"    {prefix}_forward_dynamics(q, qd, tau, a);  (qdd in a[0..{n - 1}]; a[{n}] > 0 iff M is regular)"]
    lines += [f"Build: cc -std=c99 -O2 -c {prefix}.c && link with -lm."]
    return "\n".join(lines)


def _tensor_export(robot: DHRobot, specs: dict, lang: str, prefix: str, title: str) -> dict[str, str]:
    """``{<prefix>.py: text}``: the kernels for torch or jax; forward dynamics by the framework's solve of M (rnea and
    mass_matrix traced for it), the IK solvers' internal kernel left out."""
    if "forward_dynamics" in specs:
        specs.update(trace_kernels(robot, [k for k in ("rnea", "mass_matrix") if k not in specs]))
    specs = {k: v for k, v in specs.items() if k not in INTERNAL and k != "forward_dynamics"}
    return {f"{prefix}.py": tensor_module(specs, lang, title + _tensor_usage(prefix, robot.dof, lang))}


def _tensor_usage(prefix: str, n: int, lang: str) -> str:
    make = "torch.rand(1000, {n}, dtype=torch.float64)" if lang == "torch" else "jax.numpy.ones((1000, {n}))"
    imports = "torch" if lang == "torch" else "jax"
    return "\n".join(["", "", "Usage:", f"    import {imports}, {prefix}", f"    q = {make.format(n=n)}",
                      f"    T = {prefix}.fk(q)          # (1000, 4, 4)", f"    J = {prefix}.jacobian0(q)   # (1000, 6, {n})"])


def _py_usage(prefix: str, n: int) -> str:
    return "\n".join(["", "", "Usage:", f"    import numpy as np, {prefix}", f"    T = {prefix}.fk(np.zeros({n}))",
                      f"    J = {prefix}.jacobian0(np.random.rand(1000, {n}))  # a batch: (1000, 6, {n})"])
