"""The HTML viewer in a real headless browser (Chromium driven by Playwright).

Needs ``pip install playwright`` and Debian's ``chromium`` at /usr/bin/chromium (``playwright install``
is not used: it downloads a browser build).  Skips when either is missing, except under CI=true,
where a missing browser is a failure.
"""

from __future__ import annotations

import json
import os
import shutil
from pathlib import Path

import numpy as np
import pytest

import denavit
from denavit.viz import write_viewer

pytestmark = pytest.mark.browser

CHROMIUM = os.environ.get("DENAVIT_CHROMIUM", "/usr/bin/chromium")
LAUNCH_ARGS = ["--headless", "--no-sandbox", "--disable-gpu", "--disable-background-networking",
               "--disable-component-update", "--disable-sync", "--no-first-run"]
from conftest import CI as IN_CI
READOUT_ATOL = 6e-5  # the visible readout has 4 decimals
ROBOTS = ["puma560", "stanford", "report004-5-rpp-cylindrical", "panda"]  # standard/modified, prismatic


def _unavailable(reason: str):
    if IN_CI:
        pytest.fail(f"browser test cannot run under CI: {reason}")
    pytest.skip(reason)


@pytest.fixture(scope="module")
def browser():
    try:
        from playwright.sync_api import sync_playwright
    except ImportError:
        _unavailable("playwright is not installed (pip install playwright)")
    if not (Path(CHROMIUM).exists() or shutil.which(CHROMIUM)):
        _unavailable(f"no chromium at {CHROMIUM} (apt-get install chromium)")
    with sync_playwright() as pw:
        b = pw.chromium.launch(executable_path=CHROMIUM, args=LAUNCH_ARGS, headless=True)
        yield b
        b.close()


def _open(browser, path: Path):
    page = browser.new_page(viewport={"width": 1100, "height": 700})
    problems: list[str] = []
    requests: list[str] = []
    page.on("console", lambda m: problems.append(f"console {m.type}: {m.text}") if m.type in ("error", "warning")
            else None)
    page.on("pageerror", lambda e: problems.append(f"page error: {e}"))
    page.on("request", lambda r: requests.append(r.url))
    page.goto(path.as_uri())
    page.wait_for_function("document.getElementById('T-json').textContent.length > 0")
    return page, problems, requests


def _canvas_pixels(page) -> np.ndarray:
    from io import BytesIO

    from PIL import Image

    png = page.locator("#view").screenshot()
    return np.asarray(Image.open(BytesIO(png)).convert("RGB"), dtype=float)


def _page_state(page) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(slider values, T from the full-precision output, T parsed from the visible readout)."""
    n = len(json.loads(page.locator("#q-json").text_content()))
    sliders = np.array([float(page.locator(f"#q{k + 1}").input_value()) for k in range(n)])
    T_json = np.array(json.loads(page.locator("#T-json").text_content()))
    T_text = np.array([[float(x) for x in row.split()] for row in page.locator("#readout-T").text_content().splitlines()])
    return sliders, T_json, T_text


@pytest.mark.parametrize("name", ROBOTS)
def test_viewer_loads_draws_and_follows_sliders(browser, tmp_path, name):
    robot = denavit.load_robot(name)
    path = write_viewer(robot, tmp_path / f"{name}.html")
    page, problems, requests = _open(browser, path)
    try:
        # offline: the page asks for nothing but its own file
        assert [u for u in requests if not u.startswith("file://")] == []
        before = _canvas_pixels(page)
        assert before.std() > 5.0, "canvas looks blank"
        assert (np.abs(before - 255).sum(axis=-1) > 30).mean() > 0.005, "almost nothing drawn on the canvas"

        q0, T0, T0_text = _page_state(page)
        np.testing.assert_allclose(T0, denavit.forward_kinematics(robot, q0), atol=1e-12)
        np.testing.assert_allclose(T0_text, denavit.forward_kinematics(robot, q0), atol=READOUT_ATOL)

        # move two sliders as a user does: keyboard on the focused range input
        for k in (1, robot.dof - 1):
            slider = page.locator(f"#q{k + 1}")
            slider.focus()
            key = "ArrowLeft" if float(slider.input_value()) > float(slider.get_attribute("min")) + 0.5 * (
                float(slider.get_attribute("max")) - float(slider.get_attribute("min"))) else "ArrowRight"
            for _ in range(150):
                page.keyboard.press(key)
        q1, T1, T1_text = _page_state(page)
        assert np.abs(q1 - q0).max() > 0.05, "the sliders did not move"
        T_fk = denavit.forward_kinematics(robot, q1)
        np.testing.assert_allclose(T1, T_fk, atol=1e-12)
        np.testing.assert_allclose(T1_text, T_fk, atol=READOUT_ATOL)
        shown = page.locator(f"#qv{robot.dof}").text_content()
        assert shown.strip(), "joint value readout is empty"

        after = _canvas_pixels(page)
        assert np.abs(after - before).sum(axis=-1).astype(bool).mean() > 0.002, "the arm did not move on screen"
        trace = page.evaluate("window.denavitViewer.state().trace")
        assert len(trace) > 10, "no end-effector trace recorded"
        np.testing.assert_allclose(trace[-1], T_fk[:3, 3], atol=1e-12)
        assert problems == []
    finally:
        page.close()


def test_viewer_mouse_orbit_and_zoom_change_the_picture(browser, tmp_path):
    robot = denavit.load_robot("ur5")
    page, problems, _ = _open(browser, write_viewer(robot, tmp_path / "ur5.html"))
    try:
        box = page.locator("#view").bounding_box()
        cx, cy = box["x"] + box["width"] / 2, box["y"] + box["height"] / 2
        start = _canvas_pixels(page)
        page.mouse.move(cx, cy)
        page.mouse.down()
        page.mouse.move(cx + 120, cy + 40, steps=6)
        page.mouse.up()
        orbited = _canvas_pixels(page)
        assert np.abs(orbited - start).sum(axis=-1).astype(bool).mean() > 0.002
        page.mouse.wheel(0, -400)
        zoomed = _canvas_pixels(page)
        assert np.abs(zoomed - orbited).sum(axis=-1).astype(bool).mean() > 0.002
        # the view changes the picture, never the kinematics
        q, T, _ = _page_state(page)
        np.testing.assert_allclose(T, denavit.forward_kinematics(robot, q), atol=1e-12)
        assert problems == []
    finally:
        page.close()


def _overlap(a, b) -> bool:
    return not (a[2] < b[0] or a[0] > b[2] or a[3] < b[1] or a[1] > b[3])


@pytest.mark.parametrize("name, pose", [("puma560", "qn"), ("puma560", "qr"), ("ur5", "qr"), ("stanford", None),
                                        ("panda", "qr")])
def test_viewer_frame_labels_do_not_overprint(browser, tmp_path, name, pose):
    """Frame labels are placed apart: frames sharing an axis get one merged label (z5,6), and no two placed
    label boxes overlap; every frame's axis letters are still named."""
    robot = denavit.load_robot(name)
    q = dict(robot.poses)[pose] if pose else None
    path = write_viewer(robot, tmp_path / f"{name}.html", q=q)
    page, problems, _ = _open(browser, path)
    try:
        labels = json.loads(page.locator("#view").get_attribute("data-labels"))
        boxes = [b for _, b, free in labels if free]
        assert len(boxes) >= 0.9 * len(labels), labels
        for i in range(len(boxes)):
            for j in range(i + 1, len(boxes)):
                assert not _overlap(boxes[i], boxes[j]), (labels[i], labels[j])
        named = {(text[0], k) for text, _, _ in labels for k in text[1:].split(",")}
        frames = robot.n_rows + 1 + (0 if np.allclose(robot.tool_matrix, np.eye(4)) else 1)
        assert len(named) == 3 * frames  # x, y, z of every frame, merged or not
        assert problems == []
    finally:
        page.close()


def test_report_html_fits_the_window(browser, tmp_path):
    """The report's widest pieces (the IK tables of a 6-joint arm) fit a 1,280 px window: no table is wider than
    its column, the page does not scroll sideways, and no IK residual wraps inside its cell."""
    from denavit.report import derive, write_report

    robot = denavit.load_robot("puma560")
    q = dict(robot.poses)["qn"]
    out = tmp_path / "r.html"
    write_report(derive(robot, q, topics=["ik"]), out)
    page = browser.new_page(viewport={"width": 1280, "height": 900})
    try:
        page.goto(out.as_uri())
        page.wait_for_function("document.querySelectorAll('.katex').length > 0")
        sizes = page.evaluate("""Array.from(document.querySelectorAll('table')).map(t => [t.scrollWidth,
            t.closest('section').clientWidth, Math.ceil(t.getBoundingClientRect().right)])""")
        assert len(sizes) >= 2
        for width, column, right in sizes:
            assert width <= column and right <= 1280, sizes
        assert page.evaluate("document.documentElement.scrollWidth") <= 1280
        heights = page.evaluate("""Array.from(document.querySelectorAll('td.num')).map(td => td.getClientRects()
            .length ? td.querySelector('*') === null && td.getBoundingClientRect().height : 0)""")
        line = page.evaluate("parseFloat(getComputedStyle(document.querySelector('td.num')).lineHeight)")
        assert heights and max(heights) < 2.5 * line  # one line of text plus padding: nothing wrapped
    finally:
        page.close()
