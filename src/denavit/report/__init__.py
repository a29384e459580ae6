"""Written derivations: build a report as data (:func:`derive`), render it (:func:`render`, :func:`write_report`).

Importing this package imports sympy (the derivation is symbolic); ``import denavit`` does not.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from ._capabilities import arm_picture_name
from ._derivation import MAX_CASES, TOPICS, Derivation, Equation, Figure, Heading, Numbers, Section, Table, Text, derive
from ._pdf import latex_engine, pdf_from_latex
from ._render import (
    FORMATS,
    KATEX_TYPESET_SCRIPT,
    katex_bundle,
    math_of,
    number_text,
    render,
    render_html,
    render_latex,
    render_markdown,
)

__all__ = [
    "arm_picture_name",
    "TOPICS",
    "MAX_CASES",
    "Derivation",
    "Section",
    "Text",
    "Heading",
    "Equation",
    "Numbers",
    "Table",
    "Figure",
    "derive",
    "render",
    "render_markdown",
    "render_latex",
    "render_html",
    "math_of",
    "number_text",
    "FORMATS",
    "katex_bundle",
    "KATEX_TYPESET_SCRIPT",
    "latex_engine",
    "pdf_from_latex",
    "write_report",
    "format_from_path",
]

_SUFFIX = {".md": "md", ".markdown": "md", ".tex": "tex", ".html": "html", ".htm": "html", ".pdf": "pdf"}


def format_from_path(path: str | Path) -> str:
    """``md``, ``tex``, ``html`` or ``pdf`` from a file name (ParseError for anything else)."""
    from ..errors import ParseError

    fmt = _SUFFIX.get(Path(path).suffix.lower())
    if fmt is None:
        raise ParseError(f"-o {str(path)!r}: the report format comes from the suffix; use .md, .tex, .html or .pdf")
    return fmt


def write_report(derivation: Derivation, path: str | Path, fmt: str | None = None) -> list[Path]:
    """Render ``derivation`` and write it (and its pictures, beside it for md/tex); returns the files written."""
    path = Path(path)
    fmt = fmt or format_from_path(path)
    prefix = path.stem + "-"
    if fmt == "pdf":
        tex, files = render_latex(derivation, prefix)
        data: Any = pdf_from_latex(tex, files)
        path.write_bytes(data)
        return [path]
    text, files = render(derivation, fmt, prefix)
    path.write_text(text, encoding="utf-8")
    written = [path]
    for name, blob in files.items():
        target = path.with_name(name)
        target.write_bytes(blob)
        written.append(target)
    return written
