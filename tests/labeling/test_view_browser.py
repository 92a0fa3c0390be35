"""``meshvis view`` in headless Chromium: labels drawn, never overlapping, updating as the model turns.

Run with ``pytest -m browser`` (the main suite leaves these out).  Chromium is the system's
(Debian's ``chromium`` package, ``/usr/bin/chromium``), driven by Playwright; WebGL runs on
SwiftShader, which renders the part-ID buffer into its render target like a GPU does.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import time

import numpy as np
import pytest

from meshvis.labeling.geometry2d import boxes_overlap

pytestmark = pytest.mark.browser

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
ASSEMBLY = os.path.join(ROOT, "models", "assembly.obj")
CHROMIUM = os.environ.get("MESHVIS_CHROMIUM", "/usr/bin/chromium")
#: launch flags: headless, no GPU (SwiftShader WebGL), nothing fetched, a fresh profile
FLAGS = [
    "--no-sandbox",
    "--disable-gpu",
    "--use-angle=swiftshader",
    "--enable-unsafe-swiftshader",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
    "--no-first-run",
]
VIEWPORT = {"width": 800, "height": 600}


@pytest.fixture(scope="module")
def page(tmp_path_factory):
    playwright = pytest.importorskip("playwright.sync_api")
    assert shutil.which(CHROMIUM) or os.path.exists(CHROMIUM), f"{CHROMIUM} not installed"
    proc = subprocess.Popen(
        [sys.executable, "-m", "meshvis", "view", ASSEMBLY, "--port", "0", "--no-browser"],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    try:
        line = proc.stdout.readline()
        assert line.startswith("meshvis view: http://127.0.0.1:"), (
            line,
            proc.stderr.read() if proc.poll() else "",
        )
        url = line.split()[2]
        with playwright.sync_playwright() as pw:
            profile = tmp_path_factory.mktemp("chromium-profile")
            # a persistent context is Playwright's way of giving Chromium a fresh --user-data-dir
            browser = pw.chromium.launch_persistent_context(
                str(profile), executable_path=CHROMIUM, headless=True, args=FLAGS, viewport=VIEWPORT
            )
            errors: list[str] = []
            pg = browser.new_page()
            pg.on("pageerror", lambda e: errors.append(str(e)))
            pg.goto(url)
            pg.wait_for_function("window.meshvisView && window.meshvisView.labels() > 0", timeout=120_000)
            yield pg, errors
            browser.close()
    finally:
        proc.terminate()
        proc.wait(timeout=30)


def _received(pg) -> list[dict]:
    return pg.evaluate("window.meshvisView.stats.received")


def test_the_page_draws_labels_on_the_model(page):
    pg, errors = page
    assert not errors
    texts = pg.eval_on_selector_all("#labels text", "ns => ns.map(n => n.textContent)")
    assert len(texts) >= 5 and all(texts)
    first = _received(pg)[0]
    # every anchor's 3D point was found by the server's ray through the page's pixel: the
    # GPU's ID buffer and the server's camera agree
    assert all(None not in lab["anchor3d"] for lab in first["labels"])


def test_turning_the_model_updates_the_labels_without_overlaps(page):
    pg, errors = page
    before = len(_received(pg))
    box = pg.locator("canvas").bounding_box()
    x, y = box["x"] + box["width"] / 2, box["y"] + box["height"] / 2
    pg.mouse.move(x, y)
    pg.mouse.down()
    start = time.perf_counter()
    for i in range(80):  # about 3 s of dragging: the model turns by a few degrees a step
        pg.mouse.move(x + 3 * i, y + (i % 7))
        pg.wait_for_timeout(30)
    pg.mouse.up()
    elapsed = time.perf_counter() - start
    pg.wait_for_function("window.meshvisView.idle()", timeout=60_000)
    frames = _received(pg)[before:]
    rate = len(frames) / elapsed
    print(f"\n{len(frames)} layouts in {elapsed:.2f} s while turning: {rate:.1f} per second")
    assert len(frames) >= 5
    assert not errors
    for f in frames:
        boxes = np.array([lab["box"] for lab in f["labels"]]).reshape(-1, 4)
        overlap = boxes_overlap(boxes, boxes)
        np.fill_diagonal(overlap, False)
        assert not overlap.any(), f["seq"]
    # the labels follow the model: the last layout differs from the first one of the turn
    first = {lab["part"]: lab["box"] for lab in frames[0]["labels"]}
    last = {lab["part"]: lab["box"] for lab in frames[-1]["labels"]}
    common = set(first) & set(last)
    assert common and any(not np.allclose(first[p], last[p]) for p in common)
    # and the drawn labels are those of the last layout
    drawn = pg.eval_on_selector_all("#labels text", "ns => ns.length")
    assert drawn == len(frames[-1]["labels"])
