"""Page benchmark of ``meshvis view``: label updates per second in headless Chromium while the model turns.

Starts ``meshvis view MODEL --port 0`` in a child process, opens the page in the system's
Chromium (``/usr/bin/chromium``, driven by Playwright; WebGL on SwiftShader), lets it
settle, then turns the camera by ``step`` degrees every ``interval`` milliseconds for
``seconds`` seconds and reads what the page received: layouts per second, the server's
layout time, and the box overlaps of every received layout.  With ``--gif`` it also
records a full turn of the page afterwards (a screenshot after each step's answer) as an
animated GIF.

``meshvis bench labeling-page`` calls :func:`main`; Python code calls :func:`run`.
"""

from __future__ import annotations

import argparse
import io
import os
import subprocess
import sys
import time
from typing import Any

import numpy as np

from meshvis._extras import import_extra
from meshvis.labeling.candidates import LAYOUTS
from meshvis.labeling.geometry2d import boxes_overlap

from .cases import machine, machine_lines
from .labeling import report

CHROMIUM = "/usr/bin/chromium"
#: headless, WebGL on SwiftShader, nothing fetched from the network
FLAGS = (
    "--no-sandbox",
    "--disable-gpu",
    "--use-angle=swiftshader",
    "--enable-unsafe-swiftshader",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
    "--no-first-run",
)


def _overlaps(layout: dict) -> int:
    boxes = np.array([lab["box"] for lab in layout["labels"]], np.float64).reshape(-1, 4)
    hit = boxes_overlap(boxes, boxes)
    np.fill_diagonal(hit, False)
    return int(np.triu(hit, 1).sum())


def _cpu_seconds(pids: list[int]) -> float:
    """User + system CPU seconds used so far by the processes ``pids`` (those gone count 0)."""
    tick = os.sysconf("SC_CLK_TCK")
    total = 0
    for pid in pids:
        try:
            with open(f"/proc/{pid}/stat") as fh:
                fields = fh.read().rsplit(")", 1)[1].split()
        except OSError:
            continue
        total += int(fields[11]) + int(fields[12])  # utime, stime (fields 14, 15 of stat)
    return total / tick


def _browser_pids(profile: str) -> list[int]:
    """The processes of the browser started with the profile folder ``profile``."""
    pids = []
    for entry in os.listdir("/proc"):
        if not entry.isdigit():
            continue
        try:
            with open(f"/proc/{entry}/cmdline", "rb") as fh:
                cmdline = fh.read()
        except OSError:
            continue
        if profile.encode() in cmdline:
            pids.append(int(entry))
    return pids


def run(
    model: str,
    *,
    layout: str = "left-right",
    up: str = "auto",
    seconds: float = 10.0,
    step: float = 1.0,
    interval: float = 33.0,
    viewport: tuple[int, int] = (800, 600),
    gif: str | None = None,
    gif_frames: int = 36,
    chromium: str = CHROMIUM,
    profile: str | None = None,
) -> dict[str, Any]:
    """Turn the model in the page and measure what the page receives (see the module docstring).

    Parameters
    ----------
    model : the model file
    layout : the label layout
    up : the model's up axis for ``meshvis view --up``
    seconds : how long to turn
    step : degrees per turn step; interval : milliseconds between steps
    viewport : (width, height) of the page
    gif : after the measurement, record a full turn in ``gif_frames`` steps there (None: no recording)
    chromium : the browser binary
    profile : a fresh Chromium profile folder (default: a temporary one)

    Returns
    -------
    dict
        ``layouts`` received while turning, ``seconds``, ``per_second``, ``overlaps`` summed
        and ``layouts_with_overlap``, ``labels_mean``, the server's ``layout_ms`` and
        ``server_ms`` (median, max), the page's ``answer_ms`` (median: post to answer) and
        ``ids_ms`` (median: GPU ID render and read-back), ``cpu_ms_per_layout`` (CPU
        milliseconds of the server's and of the browser's processes while turning, per
        layout received), ``machine``.
    """
    import tempfile

    pw = import_extra("playwright.sync_api", "the page benchmark")
    where = machine()  # the load before the run
    cmd = [sys.executable, "-m", "meshvis", "view", model, "--port", "0", "--no-browser", "--up", up]
    proc = subprocess.Popen(
        cmd + ["--layout", layout], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True
    )
    frames = []
    try:
        line = proc.stdout.readline() if proc.stdout else ""
        if not line.startswith("meshvis view: "):
            raise RuntimeError(
                f"meshvis view did not start: {line}{proc.stderr.read() if proc.stderr else ''}"
            )
        url = line.split()[2]
        with tempfile.TemporaryDirectory() as tmp, pw.sync_playwright() as p:
            browser = p.chromium.launch_persistent_context(
                profile or tmp,
                executable_path=chromium,
                headless=True,
                args=list(FLAGS),
                viewport={"width": viewport[0], "height": viewport[1]},
            )
            page = browser.new_page()
            page.goto(url)
            page.wait_for_function("window.meshvisView && window.meshvisView.labels() > 0", timeout=180_000)
            page.wait_for_function("window.meshvisView.idle()", timeout=60_000)
            before = page.evaluate("window.meshvisView.stats.received.length")
            browser_pids = _browser_pids(profile or tmp)
            cpu0 = (_cpu_seconds([proc.pid]), _cpu_seconds(browser_pids))
            start = time.perf_counter()
            n = 0
            while time.perf_counter() - start < seconds:
                page.evaluate(f"window.meshvisView.turn({float(step)})")
                page.wait_for_timeout(interval)
                n += 1
            elapsed = time.perf_counter() - start
            cpu1 = (_cpu_seconds([proc.pid]), _cpu_seconds(browser_pids))
            got = page.evaluate(f"window.meshvisView.stats.received.slice({before})")
            timing = page.evaluate("window.meshvisView.stats.timing")
            for _ in range(gif_frames if gif else 0):
                # the recording: a turn, the answer, the boxes' glide, a screenshot
                page.evaluate(f"window.meshvisView.turn({360.0 / gif_frames})")
                page.wait_for_function("window.meshvisView.idle()", timeout=60_000)
                page.wait_for_timeout(250)
                frames.append(page.screenshot())
            browser.close()
    finally:
        proc.terminate()
        proc.wait(timeout=30)
    if gif and frames:
        _write_gif(frames, gif)
    recent = timing[-len(got) :] if got else []
    return {
        "model": model,
        "layout": layout,
        "viewport": list(viewport),
        "steps": n,
        "degrees": n * step,
        "seconds": elapsed,
        "layouts": len(got),
        "per_second": len(got) / elapsed if elapsed > 0 else 0.0,
        "overlaps": int(sum(_overlaps(f) for f in got)),
        "layouts_with_overlap": int(sum(_overlaps(f) > 0 for f in got)),
        "labels_mean": float(np.mean([len(f["labels"]) for f in got])) if got else 0.0,
        "id_size": [got[0]["width"], got[0]["height"]] if got else [0, 0],
        "layout_ms": _stats([f["layoutMs"] for f in got]),
        "server_ms": _stats([t["server"] for t in recent]),
        "answer_ms": _stats([t["answer"] for t in recent]),
        "ids_ms": _stats([t["ids"] for t in recent]),
        # CPU spent while turning, per layout received: the server's and the browser's
        # processes (all of them: page, renderer, SwiftShader), a load-independent cost
        "cpu_ms_per_layout": [
            1000.0 * (cpu1[0] - cpu0[0]) / max(len(got), 1),
            1000.0 * (cpu1[1] - cpu0[1]) / max(len(got), 1),
        ],
        "machine": where,
        "load_after": [round(x, 2) for x in os.getloadavg()],
    }


def _stats(values: list) -> list[float]:
    """[median, max] (zeros when empty)."""
    return [float(np.median(values)), float(np.max(values))] if values else [0.0, 0.0]


def _write_gif(frames: list[bytes], path: str) -> None:
    """The screenshots as an animated GIF, cropped to what is drawn (48 colours), written atomically."""
    from PIL import Image, ImageChops

    from meshvis.io import atomic_write

    images = [Image.open(io.BytesIO(png)).convert("RGB") for png in frames]
    white = Image.new("RGB", images[0].size, (255, 255, 255))
    boxes = [ImageChops.difference(im, white).getbbox() for im in images]
    boxes = [b for b in boxes if b]
    if boxes:  # the union of the drawn parts, plus a margin (the status line included)
        pad = 8
        x0, y0 = min(b[0] for b in boxes) - pad, min(b[1] for b in boxes) - pad
        x1, y1 = max(b[2] for b in boxes) + pad, max(b[3] for b in boxes) + pad
        images = [im.crop((max(x0, 0), max(y0, 0), min(x1, im.width), min(y1, im.height))) for im in images]
    pal = [im.convert("P", palette=Image.Palette.ADAPTIVE, colors=48) for im in images]
    with atomic_write(path, "wb") as fh:
        pal[0].save(
            fh, format="GIF", save_all=True, append_images=pal[1:], duration=150, loop=0, optimize=True
        )


def format(result: dict[str, Any]) -> str:  # noqa: A001 - the bench modules' common name
    """The summary of a :func:`run` result."""
    r = result
    return "\n".join(
        [
            f"page benchmark: {r['model']} ({r['layout']}), page {r['viewport'][0]} x {r['viewport'][1]}, "
            f"ID buffer {r['id_size'][0]} x {r['id_size'][1]}",
            *machine_lines(r["machine"])[:2],
            f"- load average (1, 5, 15 min) at the start: {', '.join(str(x) for x in r['machine']['load_average'])}; "
            f"at the end: {', '.join(str(x) for x in r['load_after'])}",
            "",
            f"turned {r['degrees']:.0f} degrees in {r['seconds']:.1f} s ({r['steps']} steps)",
            f"layouts received      {r['layouts']} ({r['per_second']:.1f} per second)",
            f"labels per layout     {r['labels_mean']:.1f}",
            f"box overlaps          {r['overlaps']} (in {r['layouts_with_overlap']} of {r['layouts']} layouts)",
            f"server layout ms      median {r['layout_ms'][0]:.1f}, max {r['layout_ms'][1]:.1f}",
            f"server frame ms       median {r['server_ms'][0]:.1f}, max {r['server_ms'][1]:.1f} (decode + layout + JSON)",
            f"page post->answer ms  median {r['answer_ms'][0]:.1f}, max {r['answer_ms'][1]:.1f}",
            f"page ID render+read   median {r['ids_ms'][0]:.1f} ms",
            f"CPU ms per layout     server {r['cpu_ms_per_layout'][0]:.1f}, browser {r['cpu_ms_per_layout'][1]:.1f}",
        ]
    )


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Add the options of ``meshvis bench labeling-page`` to its parser.

    Parameters
    ----------
    parser : argparse.ArgumentParser
        The parser of the benchmark.
    """
    parser.add_argument("model", nargs="?", default=os.path.join("models", "assembly.obj"))
    parser.add_argument("--layout", choices=tuple(LAYOUTS), default="left-right")
    parser.add_argument("--up", choices=("auto", "x", "y", "z"), default="auto")
    parser.add_argument("--seconds", type=float, default=10.0, help="how long to turn (default 10)")
    parser.add_argument("--step", type=float, default=1.0, help="degrees per step (default 1)")
    parser.add_argument("--gif", metavar="FILE", help="also record a full turn of the page")
    parser.add_argument("--gif-frames", type=int, default=36, help="steps of the recorded turn (default 36)")
    parser.add_argument("--chromium", default=CHROMIUM, help=f"the browser (default {CHROMIUM})")
    parser.add_argument("--json", metavar="FILE", help="also write the numbers as JSON")


def main(args: argparse.Namespace) -> int:
    """Run ``meshvis bench labeling-page``.

    Parameters
    ----------
    args : argparse.Namespace
        The options of :func:`add_arguments`.

    Returns
    -------
    int
        Exit status 0.
    """
    result = run(
        args.model,
        layout=args.layout,
        up=args.up,
        seconds=args.seconds,
        step=args.step,
        gif=args.gif,
        gif_frames=args.gif_frames,
        chromium=args.chromium,
    )
    return report(result, format(result), args.json)
