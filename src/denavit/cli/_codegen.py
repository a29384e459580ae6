"""``denavit compile`` (build and cache an arm's kernels), ``denavit cache`` (where, how big; ``--clear``) and
``denavit export`` (standalone C or Python)."""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

from ..errors import ParseError
from ._common import add_common, load, stage_printer
from ._output import add_no_clobber, check_output, output_files

__all__ = ["register"]


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("compile", help="generate and cache an arm's kernels (FK, Jacobians, dynamics); time them")
    add_common(p, angles=False)
    p.add_argument("--backend", choices=["numba", "numpy"], help="default: numba when installed (the 'fast' extra)")
    p.set_defaults(handler=cmd_compile)

    p = sub.add_parser("cache", help="the kernel cache: the folder in use and its size; --clear deletes the kernels")
    p.add_argument("--clear", action="store_true", help="delete every cached kernel (rebuilt when next needed)")
    p.add_argument("--json", action="store_true", help="machine-readable JSON on stdout")
    p.add_argument("--deg", action="store_true", help="accepted like every command's --deg (the cache has no angles)")
    p.set_defaults(handler=cmd_cache)

    p = sub.add_parser("export", help="write an arm's kernels as standalone C99, numpy, PyTorch or JAX source")
    add_common(p, angles=False)
    p.add_argument("--lang", required=True, choices=["c", "python", "torch", "jax"],
                   help="c: PREFIX.h + PREFIX.c; python: PREFIX.py (numpy); torch, jax: PREFIX.py (that framework only)")
    p.add_argument("-o", "--output", required=True, metavar="DIR", help="folder to write into (made if absent)")
    p.add_argument("--prefix", help="C function / module name prefix (default: from the robot's name)")
    p.add_argument("--kernels", metavar="NAMES", help="comma-separated kernel names, or 'all' (default: the built-in "
                   "ones; 'all' adds the registered ones: derivatives, regressors)")
    add_no_clobber(p)
    p.set_defaults(handler=cmd_export)


def cmd_compile(args: argparse.Namespace):
    from ..codegen import compile

    robot = load(args)
    # at a terminal only, so that a failure (no numba, an unwritable cache) stays one line on stderr
    show = (stage_printer(args, "compile") if sys.stderr.isatty() else None) or (lambda stage: None)
    t0 = time.perf_counter()
    show("generating the kernels (from the cache when this arm was compiled before)")
    fast = compile(robot, backend=args.backend)
    show(f"compiling and timing {len(fast.kernels)} kernels ({fast.backend})")
    timings = fast.warm()
    total = time.perf_counter() - t0
    folder = fast.path.parent  # the folder actually used (the configured one may have been unsafe or unwritable)
    lines = [f"{robot.name}: {robot.dof} joints, backend {fast.backend}, {len(fast.kernels)} kernels in "
             f"{total:.2f} s (cache: {folder})"]
    lines += [f"  {name:<17} {dt * 1e3:8.1f} ms" for name, dt in timings.items()]
    return {"robot": robot.name, "backend": fast.backend, "kernels": list(fast.kernels), "seconds": total,
            "kernel_seconds": timings, "cache": str(folder)}, "\n".join(lines)


def cmd_cache(args: argparse.Namespace):
    from ..codegen import cache_info, clear_cache

    info = clear_cache() if args.clear else cache_info()
    size = f"{info['files']} files, {info['bytes'] / 1e6:.1f} MB"
    text = (f"removed {size} from {info['folder']}" if args.clear else f"kernel cache: {info['folder']} ({size})")
    if info["reason"]:
        text += f"\n(configured {info['configured']}: not used, {info['reason']})"
    return {**info, "cleared": bool(args.clear)}, text


def cmd_export(args: argparse.Namespace):
    from ..codegen import export_sources

    if args.prefix is not None and not _valid_prefix(args.prefix):
        raise ParseError(f"--prefix {args.prefix!r}: expected a C identifier (letters, digits, _; "
                         "not a digit first; at most 40)")
    if not args.output.strip():
        raise ParseError(f"-o {args.output!r}: empty path; name the folder to write into (. for this one)")
    folder = Path(args.output)
    if folder.exists() and not folder.is_dir():
        raise ParseError(f"-o {args.output!r} is not a folder")
    if not folder.exists() and not folder.parent.is_dir():
        raise ParseError(f"-o {args.output!r}: its parent folder does not exist")
    kernels = _kernel_names(args.kernels)
    robot = load(args)
    files = export_sources(robot, args.lang, args.prefix, kernels)
    if folder.is_dir():  # each file replaced like -o FILE: a regular file, not an input, --no-clobber refuses
        for name in files:
            check_output(args, str(folder / name), ())
    try:
        folder.mkdir(exist_ok=True)
    except OSError as exc:
        raise ParseError(f"-o {args.output!r}: {exc.strerror}") from None
    with output_files([str(folder / name) for name in files]) as tmps:  # replaced together
        for tmp, text in zip(tmps, files.values()):
            Path(tmp).write_text(text, encoding="utf-8")
    written = [str(folder / name) for name in files]
    return {"robot": robot.name, "lang": args.lang, "files": written}, "wrote " + ", ".join(written)


def _kernel_names(text: str | None):
    """--kernels: None (the built-in ones), "all", or a tuple of known names (ParseError naming the choices)."""
    from ..codegen import KERNEL_NAMES, registered_kernels

    if text is None or text.strip() == "all":
        return None if text is None else "all"
    names = tuple(x.strip() for x in text.split(",") if x.strip())
    known = KERNEL_NAMES + tuple(registered_kernels())
    unknown = [x for x in names if x not in known]
    if unknown or not names:
        raise ParseError(f"--kernels {text!r}: unknown {', '.join(unknown) or '(none given)'}; choose from "
                         f"{', '.join(known)} or 'all'")
    return names


def _valid_prefix(text: str) -> bool:
    from ..codegen import PREFIX_PATTERN

    return PREFIX_PATTERN.fullmatch(text) is not None
