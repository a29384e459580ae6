"""Redraw docs/images/grading-report004.png: the top of the checked page of student report 004 (docs/grading.md).

The report is not distributed with denavit; it is the project's seed report 004 (``shared/seeds/004_*.txt`` beside
the clone, as tests/conftest.py finds it), or give its path.  Runs the command docs/grading.md shows and photographs
the checked page in headless Chromium (``DENAVIT_CHROMIUM``, default /usr/bin/chromium; needs playwright), 1,100 px
wide and 1,500 px tall, so the counts in the picture are those of the code that drew it.  From the repository's
root:

    python scripts/grading_picture.py [REPORT]
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
PICTURE = ROOT / "docs" / "images" / "grading-report004.png"
ARMS = ("1=planar2r-mdh", "2=planar3r-mdh", "3=articulated-rrr", "4=spherical-rrp", "5=cylindrical-rpp",
        "6=spherical-wrist", "7=scara-rrrp", "8=lift-prrr")
CHROMIUM = os.environ.get("DENAVIT_CHROMIUM", "/usr/bin/chromium")


def _seed_report() -> Path:
    for shared in (ROOT.parent / "shared" / "seeds", ROOT.parents[1] / "shared" / "seeds"):
        found = sorted(shared.glob("004_*.txt")) if shared.is_dir() else []
        if found:
            return found[0]
    raise SystemExit("grading_picture: seed report 004 not found beside the clone; give its path")


def main(argv: list[str]) -> int:
    source = Path(argv[0]) if argv else _seed_report()
    from playwright.sync_api import sync_playwright

    with tempfile.TemporaryDirectory() as tmp:
        report, checked = Path(tmp) / "report004.md", Path(tmp) / "checked.html"
        shutil.copyfile(source, report)  # the command docs/grading.md shows, on a file of that name
        cmd = [sys.executable, "-m", "denavit", "check", str(report), *(a for arm in ARMS for a in ("--arm", arm)),
               "-o", str(checked)]
        env = {**os.environ, "PYTHONPATH": str(ROOT / "src")}
        summary = subprocess.run(cmd, check=True, capture_output=True, text=True, env=env).stdout.splitlines()[0]
        with sync_playwright() as pw:
            browser = pw.chromium.launch(executable_path=CHROMIUM, headless=True,
                                         args=["--headless", "--no-sandbox", "--disable-gpu", "--no-first-run"])
            page = browser.new_page(viewport={"width": 1100, "height": 1500})
            page.goto(checked.as_uri())
            page.wait_for_function("document.querySelectorAll('.katex').length > 0")
            page.screenshot(path=str(PICTURE))
            browser.close()
    print(f"wrote {PICTURE.relative_to(ROOT)} ({summary})")
    return 0


if __name__ == "__main__":
    raise SystemExit(main(sys.argv[1:]))
