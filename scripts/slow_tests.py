"""Write tests/slow_tests.txt, the tests of the quick subset that took more than 2 s, from a pytest run's
``--durations=0`` report (issue 31: the quick subset, ``python -m pytest -m "not slow"``, stays small).

    python -m pytest -q -m "not slow" --durations=0 -p no:cacheprovider > durations.txt
    python scripts/slow_tests.py durations.txt            # adds the tests over 2 s to tests/slow_tests.txt

or, better on a busy machine, from CPU seconds (tests/conftest.py writes them when ``DENAVIT_CPU_TIMES`` is set):

    DENAVIT_CPU_TIMES=cpu.txt python -m pytest -q -m "not slow" -p no:cacheprovider
    python scripts/slow_tests.py --cpu cpu.txt
    python scripts/slow_tests.py --cpu cpu.txt --budget 45   # the costliest, until the rest take <= 45 CPU-s

``--budget`` bounds the sum of the tests' own CPU seconds.  The start-up comes on top: each pytest-xdist worker
imports every test module (about 16 CPU-s here), the controlling process handles every report (2-5 ms a test),
and workers and subprocesses start: 60-70 CPU-s in all on two workers.  Measured on 2026-12-04 on a quiet
2-core machine with warm numba caches: ``--budget 45`` gave a quick subset of 3,098 tests in 117 CPU-s (65 s
wall).  CPU seconds grow by a third or more at load 10, and by half on the first run after a kernel changed
(numba compiles it again), so measure on a quiet machine, on the second run.

tests/conftest.py gives every test listed there the ``slow`` mark.  A test's time is the sum of its setup, call
and teardown, in wall-clock seconds of the run the report comes from: on a busy machine that is more than its
CPU time, so the list errs towards the quick subset being smaller.  Entries already listed stay (a test that
was slow once is not timed in the quick subset again); remove a line by hand to bring a test back.
"""

from __future__ import annotations

import argparse
import re
import sys
from collections import defaultdict
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
LIST = ROOT / "tests" / "slow_tests.txt"
HEADER = ("# Tests given the `slow` mark by tests/conftest.py (written by scripts/slow_tests.py from a --durations\n"
          "# report of the quick subset: each took more than the threshold). One pytest node id a line.\n")
_LINE = re.compile(r"^([\d.]+)s (setup|call|teardown)\s+(\S.*?)\s*$")


def slow_ids(report: str, threshold: float) -> set[str]:
    total: dict[str, float] = defaultdict(float)
    for line in report.splitlines():
        m = _LINE.match(line)
        if m:
            total[m.group(3)] += float(m.group(1))
    return {node for node, seconds in total.items() if seconds > threshold}


def slow_ids_cpu(report: str, threshold: float) -> set[str]:
    """Node ids whose CPU seconds (lines ``seconds node-id``, as tests/conftest.py writes them) exceed threshold."""
    out = set()
    for line in report.splitlines():
        seconds, _, node = line.partition(" ")
        try:
            if node and float(seconds) > threshold:
                out.add(node.strip())
        except ValueError:
            continue
    return out


def within_budget(report: str, budget: float, listed: set[str]) -> set[str]:
    """The costliest tests of a CPU report (not already listed) until the others sum to at most ``budget``."""
    cost: dict[str, float] = {}
    for line in report.splitlines():
        seconds, _, node = line.partition(" ")
        try:
            if node.strip() and node.strip() not in listed:
                cost[node.strip()] = cost.get(node.strip(), 0.0) + float(seconds)
        except ValueError:
            continue
    total, out = sum(cost.values()), set()
    for node, seconds in sorted(cost.items(), key=lambda kv: -kv[1]):
        if total <= budget:
            break
        out.add(node)
        total -= seconds
    print(f"the quick subset's tests: {sum(cost.values()):.0f} -> {total:.0f} CPU-s ({len(out)} more listed)")
    return out


def read_list(path: Path = LIST) -> set[str]:
    if not path.exists():
        return set()
    return {line.strip() for line in path.read_text(encoding="utf-8").splitlines()
            if line.strip() and not line.startswith("#")}


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("report", type=Path, help="the output of pytest --durations=0 (or, with --cpu, of DENAVIT_CPU_TIMES)")
    ap.add_argument("--cpu", action="store_true", help="the report is CPU seconds per test (DENAVIT_CPU_TIMES)")
    ap.add_argument("--threshold", type=float, default=2.0, help="seconds (default 2)")
    ap.add_argument("--budget", type=float, default=None,
                    help="with --cpu: also list the costliest tests until the rest sum to at most this many CPU-s")
    args = ap.parse_args(argv)
    if args.budget is not None and not args.cpu:
        ap.error("--budget needs a CPU report (--cpu)")
    read = slow_ids_cpu if args.cpu else slow_ids
    text = args.report.read_text(encoding="utf-8", errors="replace")
    ids = read_list() | read(text, args.threshold)
    if args.budget is not None:
        ids |= within_budget(text, args.budget, ids)
    LIST.write_text(HEADER + "".join(f"{node}\n" for node in sorted(ids)), encoding="utf-8")
    print(f"{len(ids)} tests listed in {LIST.relative_to(ROOT)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
