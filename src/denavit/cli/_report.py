"""Subcommands on written work: report (a whole derivation), check (a person's claims), import-table."""

from __future__ import annotations

import argparse
import os
from pathlib import Path
from typing import Any

from ..errors import ParseError
from ._common import add_common, joint_values, load, nonneg_int, stage_printer
from ._output import add_no_clobber, check_output, output_file, output_files

#: Suffixes of a report file (the format follows the suffix).
REPORT_SUFFIXES = (".md", ".markdown", ".tex", ".html", ".htm", ".pdf")
#: Suffixes of a robot file written by import-table.
ROBOT_SUFFIXES = (".yaml", ".yml", ".json")
#: Largest table file import-table reads (bytes).
MAX_TABLE_FILE_BYTES = 1_000_000


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("report", help="the whole derivation as a document (.md, .tex, .html or .pdf)")
    add_common(p)
    p.add_argument("-q", "--q", dest="q", action="append", metavar="Q",
                   help='joint values of the numeric case, e.g. "0, pi/4, 90deg", or a named pose; repeat -q for '
                        "several cases (each numeric section then shows every case)")
    p.add_argument("--ignore-limits", action="store_true", help="compute even if q is outside the joint limits")
    p.add_argument("--qd", metavar="QD", action="append",
                   help="joint rates for the velocity section: once for every case, or once per -q in order")
    p.add_argument("--wrench", metavar="W", action="append",
                   help="end-effector wrench fx,fy,fz,nx,ny,nz (base axes) for statics: once, or once per -q")
    p.add_argument("-o", "--output", metavar="FILE", help="report file: .md, .tex, .html or .pdf (Markdown on stdout if absent)")
    p.add_argument("--topics", metavar="LIST", help="comma-separated sections to include (default: all)")
    p.add_argument("--simplify", choices=["none", "trig", "full"], default="trig", help="simplification policy")
    add_no_clobber(p)
    p.set_defaults(handler=cmd_report)

    p = sub.add_parser("check", help="grade a report as written (.md/.tex/.txt) or a claims file, result by result",
                       description="denavit check [ROBOT] REPORT.md grades a derivation as written (the arm from the "
                       "report's own DH table(s) unless ROBOT is given); denavit check ROBOT CLAIMS.yaml judges a "
                       "claims file. See docs/grading.md and docs/claims.md.")
    add_common(p, robot=False, angles=False)
    p.add_argument("robot", metavar="ROBOT", help="built-in name or robot file (optional for a report)")
    p.add_argument("claims", metavar="REPORT", nargs="?",
                   help="the report (.md, .markdown, .tex, .txt) or a YAML claims file (see docs/claims.md)")
    p.add_argument("--arm", action="append", default=[], metavar="SECTION=ROBOT",
                   help="the arm of one section of a report (SECTION: the heading's number, e.g. 3 for '3) …' or "
                        "'## 3. …'); repeatable")
    p.add_argument("-o", "--output", metavar="FILE", help="the report handed back annotated: .html (typeset, a mark "
                   "beside every judged equation) or .md (verdicts as quotes under each equation)")
    p.add_argument("--all", action="store_true", help="list the equations that state no result too")
    p.add_argument("--seed", type=nonneg_int, default=0, help="seed of the random test points (default 0)")
    add_no_clobber(p)
    p.set_defaults(handler=cmd_check)

    p = sub.add_parser("import-table", help="read a DH table pasted from a document and write a robot file")
    p.add_argument("file", metavar="FILE", help="text file holding the table (tab, Markdown or LaTeX cells)")
    p.add_argument("-o", "--output", metavar="ROBOT_FILE", help="robot file to write (.yaml or .json); stdout if absent")
    p.add_argument("--convention", choices=["standard", "modified"], help="override the convention read from the header")
    p.add_argument("--name", help="robot name (default: the file's stem)")
    add_no_clobber(p)
    p.add_argument("--json", action="store_true", help="machine-readable JSON on stdout")
    p.add_argument("--deg", action="store_true", help="the table's angles are in degrees")
    p.set_defaults(handler=cmd_import_table)


def _figure_names(args: argparse.Namespace, robot, fmt: str) -> list[str]:
    """The picture files a .md/.tex report writes beside itself (checked before any work)."""
    if fmt not in ("md", "tex") or not args.output:
        return []
    topics = [t.strip() for t in args.topics.split(",")] if args.topics else None
    if topics is not None and "figures" not in topics:
        return []
    from ..report import arm_picture_name

    return [f"{Path(args.output).stem}-{arm_picture_name(robot.name)}"]


def _check_beside(args: argparse.Namespace, names: list[str]) -> list[str]:
    """The paths of files written beside -o; each refused like -o itself (not a regular file, an input, or
    existing with --no-clobber), before the work: they are replaced together with -o."""
    if not names:
        return []
    folder = os.path.dirname(args.output)
    paths = []
    for name in names:
        if os.path.basename(name) != name or name in (".", ".."):
            raise ParseError(f"-o {args.output!r}: cannot write a picture named {name!r} beside it")
        path = os.path.join(folder, name) if folder else name
        check_output(args, path, (), what="picture")
        paths.append(path)
    return paths


def cmd_report(args: argparse.Namespace):
    from ..report import derive, format_from_path, pdf_from_latex, render, render_latex, render_markdown

    robot = load(args)
    fmt = format_from_path(args.output) if args.output else "md"
    check_output(args, args.output, REPORT_SUFFIXES)
    _check_beside(args, _figure_names(args, robot, fmt))
    if fmt == "pdf":  # fail before the derivation, not after it: one error line, no wasted minutes
        from ..report import latex_engine

        if latex_engine() is None:
            pdf_from_latex("", {})  # raises MissingDependencyError naming the engines looked for
    cases = _cases(args, robot)
    topics = [t.strip() for t in args.topics.split(",") if t.strip()] if args.topics else None
    one = cases[0] if len(cases) == 1 else {"q": None, "qd": None, "wrench": None}
    d = derive(robot, one["q"], one["qd"], one["wrench"], cases=cases if len(cases) > 1 else None, topics=topics,
               simplify=args.simplify, deg=args.deg, progress=stage_printer(args, "report"))
    data = derivation_json(d)
    if args.output:
        prefix = Path(args.output).stem + "-"
        if fmt == "pdf":
            tex, files = render_latex(d, prefix)
            main_bytes, beside = pdf_from_latex(tex, files), {}
        else:
            text, beside = render(d, fmt, prefix)
            main_bytes = text.encode("utf-8")
        paths = _check_beside(args, list(beside))  # again, now that the names are known
        with output_files([args.output, *paths]) as tmps:  # the report and its pictures replaced together
            for tmp, blob in zip(tmps, [main_bytes, *beside.values()]):
                Path(tmp).write_bytes(blob)
        written = [Path(args.output)] + [Path(p) for p in paths]
        data["output"] = [str(p) for p in written]
        done = sum(s.status == "done" for s in d.sections)
        text = (f"wrote {written[0]} ({fmt}, {done} of {len(d.sections)} sections complete"
                + "".join(f"; {s.key}: {s.status} ({s.reason})" for s in d.sections if s.status != "done") + ")")
        if len(written) > 1:
            text += "\nand " + ", ".join(str(p) for p in written[1:])
        return data, text
    return data, render_markdown(d)[0]


def _cases(args: argparse.Namespace, robot) -> list[dict[str, Any]]:
    """The numeric cases of -q/--qd/--wrench (each validated: count, syntax, limits), as text values."""
    from ..io import parse_values, resolve_pose, split_values
    from ..report import MAX_CASES

    qs = args.q or [None]
    if len(qs) > MAX_CASES:
        raise ParseError(f"-q given {len(qs)} times; a report takes at most {MAX_CASES} numeric cases")
    for flag, given in (("--qd", args.qd), ("--wrench", args.wrench)):
        if given and len(given) not in (1, len(qs)):
            raise ParseError(f"{flag} given {len(given)} times for {len(qs)} case(s) (-q): give it once (used for "
                             "every case) or once per -q, in the same order")
    out = []
    for k, q_text in enumerate(qs):
        where = f"case {k + 1}: " if len(qs) > 1 else ""
        qd_text = args.qd[k if len(args.qd) > 1 else 0] if args.qd else None
        w_text = args.wrench[k if len(args.wrench) > 1 else 0] if args.wrench else None
        case: dict[str, Any] = {"q": None, "qd": None, "wrench": None}
        try:
            if q_text is not None:
                joint_values(args, robot, q_text)  # validates count, syntax and limits (or a named pose: qr, ...)
                pose = resolve_pose(robot, q_text) is not None
                case["q"] = q_text.strip() if pose else split_values(q_text, "q")
            if qd_text is not None:
                joint_values(args, robot, qd_text, what="qd", rates=True)
                case["qd"] = split_values(qd_text, "qd")
            if w_text is not None:
                parse_values(w_text, 6, what="wrench")
                case["wrench"] = split_values(w_text, "wrench")
        except ParseError as exc:
            raise ParseError(where + str(exc)) from None
        out.append(case)
    return out


def derivation_json(d) -> dict[str, Any]:
    """The derivation as plain data: sections of steps with their LaTeX and values."""
    from ..report import Equation, Figure, Heading, Numbers, Table, Text, math_of

    sections = []
    for s in d.sections:
        steps: list[dict[str, Any]] = []
        for st in s.steps:
            if isinstance(st, Text):
                steps.append({"type": "text", "text": st.text})
            elif isinstance(st, Heading):
                steps.append({"type": "heading", "text": st.text})
            elif isinstance(st, Equation):
                steps.append({"type": "equation", "lhs": st.lhs, "latex": math_of(st), "note": st.note})
            elif isinstance(st, Numbers):
                steps.append({"type": "numbers", "lhs": st.lhs, "values": st.values, "note": st.note})
            elif isinstance(st, Table):
                steps.append({"type": "table", "header": list(st.header), "rows": [list(r) for r in st.rows]})
            elif isinstance(st, Figure):
                steps.append({"type": "figure", "caption": st.caption, "name": st.name})
        sections.append({"key": s.key, "title": s.title, "status": s.status, "reason": s.reason, "steps": steps})
    return {**d.inputs, "title": d.title, "sections": sections}


#: Files ``check -o`` writes: the annotated report.
CHECKED_SUFFIXES = (".html", ".htm", ".md", ".markdown")


def _arms(items: list[str]) -> dict[str, Any]:
    from ..io import load_robot

    arms: dict[str, Any] = {}
    for item in items:
        key, sep, name = item.partition("=")
        if not sep or not key.strip() or not name.strip():
            raise ParseError(f"--arm {item[:80]!r}: expected SECTION=ROBOT, e.g. --arm 3=articulated-rrr")
        if key.strip() in arms:
            raise ParseError(f"--arm: section {key.strip()[:40]!r} given twice")
        arms[key.strip()] = load_robot(name.strip())
    return arms


def cmd_check(args: argparse.Namespace):
    from ..grade import REPORT_SUFFIXES

    if args.claims is None:
        args.robot, args.claims = None, args.robot
    path = Path(args.claims)
    if path.suffix.lower() in REPORT_SUFFIXES:
        return _check_report(args, path)
    if args.robot is None:
        raise ParseError(f"{args.claims!r}: a claims file needs the arm: denavit check ROBOT {args.claims} (a report "
                         f"is {', '.join(REPORT_SUFFIXES)})")
    if args.output or args.arm:
        raise ParseError("-o and --arm are for reports (.md, .tex, .txt), not claims files")
    from ..check import check_file, verdicts_text

    robot = load(args)
    result = check_file(robot, path, seed=args.seed)
    return result.to_json(), verdicts_text(result)


def _check_report(args: argparse.Namespace, path: Path):
    from ..grade import grade_report, graded_text, render_checked_html, render_checked_markdown

    check_output(args, args.output, CHECKED_SUFFIXES)
    robot = load(args) if args.robot is not None else None
    report = grade_report(path, robot, _arms(args.arm), seed=args.seed)
    msg = graded_text(report, show_all=args.all)
    if args.output:
        render = render_checked_html if Path(args.output).suffix.lower() in (".html", ".htm") else \
            render_checked_markdown
        text = render(report)
        with output_file(args.output) as tmp:
            Path(tmp).write_text(text, encoding="utf-8")
        msg += f"\nwrote {args.output}"
    data = report.to_json()
    data.pop("text", None)
    return {**data, "output": args.output}, msg


def cmd_import_table(args: argparse.Namespace):
    from ..io import robot_to_dict
    from ..tables import import_table, table_file_text

    path = Path(args.file)
    check_output(args, args.output, ROBOT_SUFFIXES)
    if not path.is_file():  # /dev/zero, a folder, a FIFO: not read (a device never ends)
        raise ParseError(f"{'not a regular file' if path.exists() else 'no such file'}: {str(path)!r}")
    if path.stat().st_size > MAX_TABLE_FILE_BYTES:
        raise ParseError(f"{str(path)!r} is too large for a DH table (at most {MAX_TABLE_FILE_BYTES} bytes)")
    text = path.read_text(encoding="utf-8", errors="replace")
    result = import_table(text, name=args.name or path.stem, convention=args.convention,
                          degrees=True if args.deg else None, where=str(path))
    robot = result.robot
    out = Path(args.output) if args.output else None
    fmt = "json" if out is not None and out.suffix.lower() == ".json" else "yaml"
    file_text = table_file_text(result, fmt, source=path.name)
    if out is not None:
        with output_file(str(out)) as tmp:
            Path(tmp).write_text(file_text, encoding="utf-8")
        msg = (f"wrote {out} ({robot.convention.value} DH, {robot.n_rows} row{'s' * (robot.n_rows != 1)}, "
               f"{robot.dof} joint{'s' * (robot.dof != 1)})")
        msg += "".join(f"\nnote: {n}" for n in result.notes)
    else:
        msg = file_text
    return {"file": str(path), "output": args.output, "convention": robot.convention.value,
            "notes": list(result.notes), "robot_file": result.data, "robot": robot_to_dict(robot)}, msg
