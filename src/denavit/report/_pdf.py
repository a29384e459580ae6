"""PDF through a LaTeX engine found on PATH (tectonic, latexmk, pdflatex, xelatex, lualatex)."""

from __future__ import annotations

import shutil
import subprocess
import tempfile
from pathlib import Path

from ..errors import DenavitError, MissingDependencyError

__all__ = ["latex_engine", "pdf_from_latex", "ENGINES"]

ENGINES = ("tectonic", "pdflatex", "xelatex", "lualatex")
TIMEOUT_S = 300


def latex_engine() -> str | None:
    """The first LaTeX engine on PATH, or None."""
    for name in ENGINES:
        if shutil.which(name):
            return name
    return None


def pdf_from_latex(tex: str, attachments: dict[str, bytes]) -> bytes:
    """Compile a LaTeX document (with its pictures) to PDF bytes.

    Raises
    ------
    MissingDependencyError
        No engine is installed (the message says which ones are looked for).
    DenavitError
        The engine ran but produced no PDF (the message quotes the first LaTeX error line).
    """
    engine = latex_engine()
    if engine is None:
        raise MissingDependencyError(
            f"PDF needs a LaTeX engine and none is installed (looked for {', '.join(ENGINES)}); "
            "write .tex or .html instead, or install one (e.g. apt-get install texlive-latex-extra)")
    with tempfile.TemporaryDirectory(prefix="denavit-report-") as tmp:
        work = Path(tmp)
        (work / "report.tex").write_text(tex, encoding="utf-8")
        for name, data in attachments.items():
            (work / name).write_bytes(data)
        cmd = [engine, "report.tex"] if engine == "tectonic" else [engine, "-interaction=nonstopmode", "-halt-on-error", "report.tex"]
        log = ""
        for _ in range(1 if engine == "tectonic" else 2):  # twice for references
            proc = subprocess.run(cmd, cwd=work, capture_output=True, text=True, timeout=TIMEOUT_S, check=False)
            log = proc.stdout + proc.stderr
            if proc.returncode != 0:
                break
        pdf = work / "report.pdf"
        if not pdf.exists():
            first = next((ln for ln in log.splitlines() if ln.startswith("!")), log.strip().splitlines()[-1:] or [""])
            raise DenavitError(f"{engine} did not produce a PDF: {first if isinstance(first, str) else first[0]}")
        return pdf.read_bytes()
