"""Measure the figures README.md states and write them into its marked block (issue 31).

Every number in README.md about the project's cost (tests, seconds) comes from here, between the markers
``<!-- figures: begin ... -->`` and ``<!-- figures: end -->``; tests/test_docs.py fails on such a figure anywhere
else in the README, and on a block this script would not have written.  Run it from the repository's root:

    python scripts/readme_figures.py              # counts the tests and times the README's report command
    python scripts/readme_figures.py --suite      # also runs the quick subset and the whole suite (minutes)
    python scripts/readme_figures.py --print      # measure, print the block, leave README.md alone

Times are CPU seconds (user + system, of the measured process and every child it waited for:
``resource.getrusage(RUSAGE_CHILDREN)``), which a busy machine does not change; the wall-clock time depends on
the load and the number of cores, so it is given with the load average it was measured under.
"""

from __future__ import annotations

import argparse
import datetime
import os
import platform
import re
import resource
import shlex
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
README = ROOT / "README.md"
BEGIN = "<!-- figures: begin (written by scripts/readme_figures.py; do not edit by hand) -->"
END = "<!-- figures: end -->"


def _children_cpu() -> float:
    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime


def run_measured(argv: list[str], cwd: Path) -> tuple[subprocess.CompletedProcess, float, float]:
    """Run ``argv``; return the process, its CPU seconds (with its children) and its wall-clock seconds."""
    c0, t0 = _children_cpu(), time.perf_counter()
    proc = subprocess.run(argv, cwd=cwd, capture_output=True, text=True, env=dict(os.environ, MPLBACKEND="Agg"))
    return proc, _children_cpu() - c0, time.perf_counter() - t0


def report_command(readme: str) -> list[str]:
    """The README's first ``denavit report ...`` command (after ``&&``), as argv."""
    line = next(line for line in readme.splitlines() if "denavit report " in line)
    return shlex.split(line[line.index("denavit report "):])


def measure_report(readme: str, tmp: Path) -> float:
    argv = [sys.executable, "-m", "denavit"] + report_command(readme)[1:]
    proc, cpu, _ = run_measured(argv, tmp)
    if proc.returncode != 0:
        raise SystemExit(f"the README's report command failed: {proc.stderr.strip()[-500:]}")
    return cpu


def count_tests(marks: str | None) -> int:
    argv = [sys.executable, "-m", "pytest", "--collect-only", "-q", "-p", "no:cacheprovider", "-n", "0"]
    proc, _, _ = run_measured(argv + (["-m", marks] if marks else []), ROOT)
    m = re.search(r"(\d+)(?:/\d+)? tests? (?:collected|selected)", proc.stdout)
    if m is None:
        raise SystemExit(f"could not count the tests: {proc.stdout[-500:]}{proc.stderr[-500:]}")
    return int(m.group(1))


def time_suite(marks: str | None) -> tuple[float, float, bool]:
    argv = [sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider"] + (["-m", marks] if marks else [])
    proc, cpu, wall = run_measured(argv, ROOT)
    return cpu, wall, proc.returncode == 0


def _commit() -> str:
    proc = subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=ROOT, capture_output=True, text=True)
    return proc.stdout.strip() or "unknown"


def render(f: dict) -> str:
    """The block, from the measured figures ``f``."""
    lines = [BEGIN, "",
             f"Measured by `python scripts/readme_figures.py` on {f['date']} at commit {f['commit']} "
             f"({f['cores']} cores, load average {f['load']:.1f} at the start):", "",
             f"- `denavit report puma560 ...` (the first command above): {f['report_cpu']:.0f} s of CPU;",
             f"- the tests: {f['tests']:,} in all, {f['quick']:,} in the quick subset (`-m \"not slow\"`)"
             + (";" if "quick_cpu" in f else ".")]
    if "quick_cpu" in f:
        lines += [f"- the quick subset took {f['quick_cpu']:.0f} s of CPU ({f['quick_wall'] / 60:.1f} min on the "
                  f"clock), the whole suite {f['suite_cpu'] / 60:.1f} min of CPU ({f['suite_wall'] / 60:.1f} min "
                  "on the clock)."]
    return "\n".join(lines + ["", END])


_PARSE = re.compile(
    r"on (?P<date>\d{4}-\d\d-\d\d) at commit (?P<commit>\w+) \((?P<cores>\d+) cores, load average "
    r"(?P<load>[\d.]+) at the start\).*?: (?P<report_cpu>\d+) s of CPU;.*?tests: (?P<tests>[\d,]+) in all, "
    r"(?P<quick>[\d,]+) in the quick subset"
    r"(?:.*?took (?P<quick_cpu>\d+) s of CPU \((?P<quick_wall>[\d.]+) min on the clock\), the whole suite "
    r"(?P<suite_cpu>[\d.]+) min of CPU \((?P<suite_wall>[\d.]+) min on the clock\))?", re.S)


def parse(block: str) -> dict:
    """The figures of a block written by :func:`render` (so that ``render(parse(b)) == b`` checks ``b``)."""
    m = _PARSE.search(block)
    if m is None:
        raise ValueError("not a block written by scripts/readme_figures.py")
    g = {k: v for k, v in m.groupdict().items() if v is not None}
    f = {"date": g["date"], "commit": g["commit"], "cores": int(g["cores"]), "load": float(g["load"]),
         "report_cpu": float(g["report_cpu"]), "tests": int(g["tests"].replace(",", "")),
         "quick": int(g["quick"].replace(",", ""))}
    if "quick_cpu" in g:
        f.update(quick_cpu=float(g["quick_cpu"]), quick_wall=60 * float(g["quick_wall"]),
                 suite_cpu=60 * float(g["suite_cpu"]), suite_wall=60 * float(g["suite_wall"]))
    return f


def block_of(readme: str) -> str:
    """The marked block of the README's text (markers included)."""
    start, end = readme.find(BEGIN), readme.find(END)
    if start < 0 or end < start:
        raise ValueError(f"README.md has no block between {BEGIN!r} and {END!r}")
    return readme[start:end + len(END)]


def replace_block(readme: str, block: str) -> str:
    old = block_of(readme)
    return readme.replace(old, block, 1)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--suite", action="store_true", help="also time the quick subset and the whole suite")
    ap.add_argument("--print", action="store_true", help="print the block instead of writing README.md")
    args = ap.parse_args(argv)
    import tempfile

    readme = README.read_text(encoding="utf-8")
    f = {"date": datetime.date.today().isoformat(), "commit": _commit(), "cores": os.cpu_count(),
         "load": os.getloadavg()[0], "platform": platform.platform()}
    with tempfile.TemporaryDirectory() as tmp:
        f["report_cpu"] = measure_report(readme, Path(tmp))
    f["tests"], f["quick"] = count_tests(None), count_tests("not slow")
    if args.suite:
        f["quick_cpu"], f["quick_wall"], ok_quick = time_suite("not slow")
        f["suite_cpu"], f["suite_wall"], ok_suite = time_suite(None)
        if not (ok_quick and ok_suite):
            print("warning: the test run had failures; the times are still written", file=sys.stderr)
    block = render(f)
    if args.print:
        print(block)
    else:
        README.write_text(replace_block(readme, block), encoding="utf-8")
    return 0


if __name__ == "__main__":
    sys.exit(main())
