"""The workbench's long work, run in a child process (:mod:`denavit.web._jobs`): the symbolic T_0_n, the
derivation report, the checker, the singular conditions, the workspace picture and
the reachability map.

Each job is a function ``(payload, progress) -> dict`` of JSON data; the robot is re-read from its file mapping
here (``robot_from_dict``), so nothing but JSON crosses the process boundary.  The report is the library's
own: :func:`denavit.report.derive` rendered by :func:`~denavit.report.render_html` (and Markdown/LaTeX for the
downloads); the check is :func:`denavit.grade.grade_text` for a report and :func:`denavit.check.check_file`
for a claims file, as ``denavit check`` does.
"""

from __future__ import annotations

import contextlib
import re
import tempfile
from collections.abc import Callable
from pathlib import Path
from typing import Any

from .. import ParseError, robot_from_dict

__all__ = ["KINDS", "MAX_TEXT_CHARS", "claim_lines", "run"]

#: Longest report or claims text accepted for checking (characters).
MAX_TEXT_CHARS = 400_000
#: Report formats of an uploaded report, by the name the page sends.
_REPORT_FORMATS = ("md", "tex", "txt")


def _robot(payload: dict[str, Any]) -> Any:
    doc = payload.get("robot")
    if not isinstance(doc, dict):
        raise ParseError("'robot' must be the robot-file mapping")
    return robot_from_dict(doc, where="table")


def _values(raw: Any, what: str) -> list[Any] | None:
    """A report input: None or empty (not given), a list of numbers (the sliders), or a typed text such as
    ``"0, pi/4, -pi/3"`` split into its values, which the report reads exactly (cos(π/4) stays √2/2)."""
    from ..io import split_values

    if raw is None or raw == "" or raw == []:
        return None
    if isinstance(raw, str):
        return split_values(raw, what)
    if isinstance(raw, list) and all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in raw):
        return raw
    raise ParseError(f"'{what}' must be a list of numbers or a text like \"0, pi/4\"")


def formula(payload: dict[str, Any], progress: Callable[[str], None]) -> dict[str, Any]:
    """T_0_n and the end-effector position as LaTeX, from the report's forward-kinematics section."""
    from ..report import Equation, Text, derive, math_of

    progress("symbolic forward kinematics")
    section = derive(_robot(payload), topics=["fk"]).section("fk")
    steps = []
    for step in section.steps:
        if isinstance(step, Equation):
            steps.append({"math": math_of(step)})
        elif isinstance(step, Text):
            steps.append({"text": step.text})
    return {"steps": steps, "status": section.status, "reason": section.reason}


def report(payload: dict[str, Any], progress: Callable[[str], None]) -> dict[str, Any]:
    """The derivation report: its sections (title, status) and the HTML, Markdown and LaTeX renderings."""
    from ..report import TOPICS, derive, render_html, render_latex, render_markdown

    topics = payload.get("topics") or list(TOPICS)
    if not isinstance(topics, list) or not all(isinstance(t, str) for t in topics):
        raise ParseError(f"'topics' must be a list of names from {', '.join(TOPICS)}")
    given = {key: _values(payload.get(key), key) for key in ("q", "qd", "wrench")}
    d = derive(_robot(payload), topics=topics, progress=progress, **given)
    progress("rendering")
    md, md_files = render_markdown(d, "report-")
    tex, tex_files = render_latex(d, "report-")
    pdf, pdf_note = "", ""
    if payload.get("pdf") is True:
        from ..report import latex_engine, pdf_from_latex

        if latex_engine() is None:
            pdf_note = "no PDF: no LaTeX engine is installed (Debian: texlive-latex-extra)"
        else:
            progress("typesetting the PDF")
            import base64

            pdf = base64.b64encode(pdf_from_latex(tex, tex_files)).decode("ascii")
    return {"title": d.title, "pdf": pdf, "pdf_note": pdf_note,
            "sections": [{"key": s.key, "title": s.title, "status": s.status, "reason": s.reason} for s in d.sections],
            "html": render_html(d)[0], "md": md, "tex": tex,
            "note": (f"the Markdown and LaTeX downloads refer to {len(md_files)} picture file(s) that are only in the "
                     "HTML download") if md_files else ""}


def check(payload: dict[str, Any], progress: Callable[[str], None]) -> dict[str, Any]:
    """Grade a report (``kind`` md/tex/txt) or judge a claims file (``kind`` yaml) as ``denavit check`` does;
    ``kind`` auto reads the text as a claims file when it is one (a YAML mapping with a ``claims`` list, or a
    list of claims), else as a Markdown report."""
    text, kind = payload.get("text"), payload.get("kind")
    if not isinstance(text, str) or not text.strip():
        raise ParseError("'text' must be the report or claims file to check")
    if len(text) > MAX_TEXT_CHARS:
        raise ParseError(f"the text to check is too long ({len(text)} characters; at most {MAX_TEXT_CHARS})")
    if kind == "auto":
        kind = "yaml" if _is_claims_file(text) else "md"
    if kind in _REPORT_FORMATS:
        from ..grade import grade_text, graded_text, render_checked_html

        robot = _robot(payload) if payload.get("use_arm") else None
        progress("grading the report")
        graded = grade_text(text, kind, robot=robot, source=str(payload.get("name") or "report")[:80])
        return {"kind": "report", "summary": graded.summary(), "text": graded_text(graded),
                "html": render_checked_html(graded),
                "claims": [{"line": c.line, "verdict": c.verdict, "quantity": c.quantity} for c in graded.claims]}
    if kind == "yaml":
        return _check_claims_file(text, payload, progress)
    raise ParseError("'kind' must be md, tex or txt (a report), yaml (a claims file) or auto")


def _is_claims_file(text: str) -> bool:
    """Whether ``text`` is laid out as a claims file (docs/claims.md): a top-level ``claims:`` key, or a top-level
    list whose items start with ``quantity:`` or ``id:``.  A report has neither (the checker then reads it)."""
    return bool(_CLAIMS_LAYOUT.search(text))


_CLAIMS_LAYOUT = re.compile(r"^(claims\s*:|-\s+(quantity|id)\s*:)", re.MULTILINE)


def _check_claims_file(text: str, payload: dict[str, Any], progress: Callable[[str], None]) -> dict[str, Any]:
    """Judge a claims file with :func:`denavit.check.check_file` (the command line's judge) and give each
    verdict the lines of its claim in the file, so the page marks it in place."""
    from ..check import check_file, verdicts_text

    robot = _robot(payload)
    progress("judging the claims")
    with tempfile.TemporaryDirectory(prefix="denavit-web-") as tmp:  # check_file reads a file: ours, private
        path = Path(tmp) / "claims.yaml"
        path.write_text(text, encoding="utf-8")
        result = check_file(robot, path)
    data = result.to_json()
    lines = claim_lines(text)
    claims = []
    for k, c in enumerate(data["claims"]):
        first, last = lines[k] if k < len(lines) else (None, None)
        claims.append({"id": c["id"], "verdict": c["verdict"], "quantity": c["quantity"], "message": c["message"],
                       "hints": c["hints"], "line": first, "end_line": last})
    return {"kind": "claims", "summary": data["summary"], "notes": data["notes"], "source": text,
            "text": verdicts_text(result).replace(str(path), "claims"), "claims": claims}


def claim_lines(text: str) -> list[tuple[int, int]]:
    """The first and last line (1-based) of each claim of a claims file, in order, from the YAML parser's marks
    (the claims list of the top mapping, or the top list).  Called on a text the checker has read already, so its
    nesting and size are within the claims file's bounds; trailing blank and comment lines are not the claim's."""
    import yaml

    root = yaml.compose(text, Loader=getattr(yaml, "CSafeLoader", yaml.SafeLoader))
    seq = root
    if isinstance(root, yaml.MappingNode):
        seq = next((v for k, v in root.value if isinstance(k, yaml.ScalarNode) and k.value == "claims"), None)
    if not isinstance(seq, yaml.SequenceNode):
        return []
    rows = text.split("\n")
    out = []
    for node in seq.value:
        first = node.start_mark.line + 1
        end = node.end_mark  # just after the claim: on its last line, or at the start of the next item's line
        ended_inside = end.line < len(rows) and rows[end.line][: end.column].strip() != ""
        last = max(first, end.line + 1 if ended_inside else end.line)
        while last > first and (not rows[last - 1].strip() or rows[last - 1].lstrip().startswith("#")):
            last -= 1
        out.append((first, last))
    return out


def singularities(payload: dict[str, Any], progress: Callable[[str], None]) -> dict[str, Any]:
    """The singular conditions of the arm's Jacobian (:func:`denavit.symbolic.singularity_analysis`, as
    ``denavit singularities``), each with the joint values that solve it, so the page can name the nearest one."""
    import sympy as sp

    from ..symbolic import singularity_analysis

    res = singularity_analysis(_robot(payload), "auto", "base", progress=progress)
    return {"measure": res.measure, "rows": list(res.rows), "everywhere": res.everywhere, "reason": res.reason,
            "determinant": sp.latex(res.determinant),
            "complete": not ("minors" in res.measure and not res.conditions and not res.everywhere),
            "conditions": [{"latex": sp.latex(c.factor) + " = 0", "kind": c.kind, "explanation": c.explanation,
                            "solutions": [{"variable": x.variable, "values": [float(v) for v in x.values]}
                                          for x in c.solutions]} for c in res.conditions]}


#: Most configurations sampled by one workspace job (10⁸ take about 30 s of CPU for a 6-joint arm with numba).
MAX_WORKSPACE_SAMPLES = 10**9


def workspace(payload: dict[str, Any], progress: Callable[[str], None]) -> dict[str, Any]:
    """The workspace by streamed sampling (:func:`denavit.scale.occupancy`, as ``denavit workspace``: reach, area or
    volume with its interval) and its picture (:func:`~denavit.viz.plot_occupancy`).  Threads, not processes: the
    job is a daemon process, which may not start others.  The library's progress line is the job's progress."""
    import base64
    import io

    from ..scale import occupancy
    from ..viz import plot_occupancy

    samples = payload.get("samples", 1_000_000)
    if not isinstance(samples, int) or isinstance(samples, bool) or not 1_000 <= samples <= MAX_WORKSPACE_SAMPLES:
        raise ParseError(f"'samples' must be a whole number from 1000 to {MAX_WORKSPACE_SAMPLES:.0e}")
    robot = _robot(payload)
    progress(f"sampling {samples} configurations")
    with _progress_lines(progress):
        ws = occupancy(robot, samples, seed=0, scheduler="threads", progress=True)
    progress("drawing")
    buf = io.BytesIO()
    plot_occupancy(ws, robot.name).savefig(buf, format="png")
    e = ws.estimate
    return {"png": base64.b64encode(buf.getvalue()).decode("ascii"), "samples": ws.samples, "reach": ws.reach,
            "volume": None if ws.planar else e.value, "area": e.value if ws.planar else None, "low": e.low,
            "high": e.high, "planar": ws.planar, "extent": ws.extent.tolist()}


@contextlib.contextmanager
def _progress_lines(progress: Callable[[str], None]):
    """The library's progress line (written to stderr) sent as the job's progress while the block runs."""
    import sys

    stderr, sys.stderr = sys.stderr, _ProgressLines(progress)
    try:
        yield
    finally:
        sys.stderr = stderr


#: Voxel edges a page's reachability map may ask for [m] (the library refuses too many cells itself).
REACH_RESOLUTION = (0.01, 10.0)
#: Most orientations per voxel a page may ask for (each is one IK problem per voxel).
MAX_REACH_ORIENTATIONS = 1_000


def reachability(payload: dict[str, Any], progress: Callable[[str], None]) -> dict[str, Any]:
    """The reachability map (:func:`denavit.scale.reachability`, as ``denavit reachability``: per voxel the share of
    a fixed set of orientations the arm reaches, and the manipulability) and its picture
    (:func:`~denavit.viz.plot_reachability`).  The library's progress line (a screen of samples, then the voxels)
    is passed on as the job's progress."""
    import base64
    import io

    from ..scale import reachability as reach_map
    from ..viz import plot_reachability

    h, k = payload.get("resolution", 0.1), payload.get("orientations", 100)
    if not isinstance(h, (int, float)) or isinstance(h, bool) or not REACH_RESOLUTION[0] <= h <= REACH_RESOLUTION[1]:
        raise ParseError(f"'resolution' must be a voxel edge from {REACH_RESOLUTION[0]} to {REACH_RESOLUTION[1]} m")
    if not isinstance(k, int) or isinstance(k, bool) or not 1 <= k <= MAX_REACH_ORIENTATIONS:
        raise ParseError(f"'orientations' must be a whole number from 1 to {MAX_REACH_ORIENTATIONS}")
    robot = _robot(payload)
    progress(f"reachability of {robot.name}: {k} orientations per {h:g} m voxel")
    with _progress_lines(progress):
        rmap = reach_map(robot, float(h), k, progress=True)
    progress("drawing")
    buf = io.BytesIO()
    plot_reachability(rmap, robot.name).savefig(buf, format="png")
    return {"png": base64.b64encode(buf.getvalue()).decode("ascii"), **rmap.summary()}


class _ProgressLines:
    """A text stream standing in for stderr: each line the library's progress bar redraws (``\\r`` 12.5%  200/1,600
    voxels …) becomes one progress message."""

    def __init__(self, progress: Callable[[str], None]) -> None:
        self.progress = progress

    def write(self, text: str) -> int:
        line = text.replace("\n", "\r").split("\r")
        line = next((part.strip() for part in reversed(line) if part.strip()), "")
        if line:
            self.progress(line)
        return len(text)

    def flush(self) -> None:
        pass

    def isatty(self) -> bool:
        return False


#: The jobs a page may start, by name.
KINDS: dict[str, Callable[[dict[str, Any], Callable[[str], None]], dict[str, Any]]] = {
    "formula": formula, "report": report, "check": check, "workspace": workspace,
    "singularities": singularities, "reachability": reachability,
}


def run(kind: str, payload: dict[str, Any], conn: Any, cpu_seconds: float) -> None:
    """Child process entry: run the job, sending ``("progress", text)`` messages then ``("done", result)`` or
    ``("error", line)``.  The CPU limit ends a runaway job (SIGXCPU) as the OS enforces it."""
    import resource
    import warnings

    import numpy as np

    from ._handlers import one_line

    limit = int(cpu_seconds)
    resource.setrlimit(resource.RLIMIT_CPU, (limit, limit + 5))
    warnings.simplefilter("ignore")
    try:
        with np.errstate(all="ignore"):
            result = KINDS[kind](payload, lambda text: conn.send(("progress", one_line(text))))
        usage = resource.getrusage(resource.RUSAGE_SELF)
        conn.send(("cpu", usage.ru_utime + usage.ru_stime))
        conn.send(("done", result))
    except (ValueError, ArithmeticError, LookupError, TypeError, RecursionError, MemoryError) as exc:
        conn.send(("error", one_line(exc)))
    except Exception as exc:  # noqa: BLE001 — denavit errors and anything else: one line, never a traceback
        conn.send(("error", one_line(f"{type(exc).__name__}: {exc}")))
    finally:
        conn.close()
