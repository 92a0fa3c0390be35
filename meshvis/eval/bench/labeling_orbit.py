"""Live labeling benchmark: coherence along 72-frame orbits, and layout time against the label count.

Two parts, measured in one process:

1. **orbits** — for every model and layout, 72 frames turning once around the model (5
   degrees a frame) at 512 x 512, laid out with the previous frame (coherent) and alone
   (free): :func:`meshvis.labeling.metrics.orbit_coherence` (label motion against the
   motion of the surface under the anchors, transitions with a jump over 50 px or a side
   change) and the overlaps and crossings summed over the frames;
2. **timing** — the layout time from a given ID buffer (everything after the buffer, the
   number a live frame costs the server) for 5 ... 30 labels in every layout, on the
   view of the engine assembly that shows the most parts: the labels beyond the first k
   parts get an empty text.  Median of ``repeat`` runs.

``meshvis bench labeling-orbit`` calls :func:`main`; Python code calls :func:`run`.
"""

from __future__ import annotations

import argparse
import os
import statistics
import time
from collections.abc import Callable, Sequence
from typing import Any

import numpy as np

from meshvis.labeling.candidates import LAYOUTS
from meshvis.labeling.frames import layout_frames, orbit
from meshvis.labeling.idbuffer import id_buffer
from meshvis.labeling.inputs import label_texts, load_models
from meshvis.labeling.metrics import orbit_coherence
from meshvis.labeling.pipeline import fit_camera, solve, warm_up
from meshvis.rays.camera import model_up
from meshvis.rays.caster import RayCaster

from .cases import machine, machine_lines
from .labeling import default_model, report

#: (name, file under the shared models folder, up axis) of the default orbit models
MODELS = (
    ("milk truck", "real/CesiumMilkTruck.glb", (0.0, 1.0, 0.0)),
    ("boolean", "real/boolean.glb", (0.0, 0.0, 1.0)),
    ("ferrari", "real2/ferrari348_lowpoly.glb", (0.0, 1.0, 0.0)),
    ("dutch ship", "real2/dutch_ship.glb", (0.0, 1.0, 0.0)),
)
#: the shared models folder, relative to the current folder (a checkout beside shared/)
DEFAULT_SHARED = os.path.join("..", "shared", "models")
#: label counts of the timing part
COUNTS = (5, 10, 20, 30)


def _orbit(soup: Any, up: Sequence[float], layout: str, frames: int, size: int, coherence: bool) -> dict:
    cams = orbit(soup, frames, up=up, size=(size, size))
    caster = RayCaster(soup)
    t = time.perf_counter()
    res = layout_frames(soup, cams, caster=caster, layout=layout, size=(size, size), coherence=coherence)
    out = orbit_coherence(res)
    out["seconds"] = time.perf_counter() - t
    out["labels_mean"] = float(np.mean([len(r.labels) for r in res]))
    out["overlaps"] = int(sum(r.metrics["overlaps"] for r in res))
    out["crossings"] = int(sum(r.metrics["crossings"] for r in res))
    out["left_out"] = int(sum(len(r.unplaced) for r in res))
    out["layout_ms_median"] = float(np.median([r.timings["layout_ms"] for r in res]))
    out["layout_ms_max"] = float(np.max([r.timings["layout_ms"] for r in res]))
    return out


def _busiest_view(soup: Any, size: int, up: Sequence[float]) -> tuple[Any, int]:
    """The ID buffer, among 24 azimuths at elevation 20, that shows the most parts."""
    caster = RayCaster(soup)
    best = None
    for az in range(0, 360, 15):
        ib = id_buffer(soup, fit_camera(soup, azimuth=az, elevation=20.0, up=up), (size, size), caster=caster)
        n = int((ib.areas >= 10).sum())
        if best is None or n > best[1]:
            best = (ib, n, az)
    assert best is not None
    return best[0], best[2]


def _timing(soup: Any, ib: Any, layouts: Sequence[str], counts: Sequence[int], repeat: int) -> dict:
    texts = label_texts(soup.part_names)
    order = [int(p) for p in np.argsort(-ib.areas, kind="stable") if ib.areas[p] >= 10]
    out: dict[str, dict[str, Any]] = {}
    for layout in layouts:
        rows = {}
        for k in counts:
            keep = set(order[:k])
            sub = [t if p in keep else "" for p, t in enumerate(texts)]
            solve(ib, sub, layout=layout, compute_metrics=False)  # warm caches and the compiled kernels
            runs, cpu = [], []
            for _ in range(max(1, repeat)):
                c0 = time.process_time()
                runs.append(solve(ib, sub, layout=layout, compute_metrics=False))
                cpu.append(1000.0 * (time.process_time() - c0))
            rows[str(k)] = {
                "labels": len(runs[0].labels),
                "layout_ms": float(statistics.median(r.timings["layout_ms"] for r in runs)),
                # the process's CPU time of the whole solve: what the layout costs, whatever
                # else the machine runs
                "cpu_ms": float(statistics.median(cpu)),
                "stages_ms": {
                    s: 1000.0 * float(statistics.median(r.timings.get(s, 0.0) for r in runs))
                    for s in ("area", "candidates", "salience", "memberships", "greedy", "boxes")
                },
            }
        out[layout] = rows
    return out


def run(
    models: Sequence[tuple[str, Any, Sequence[float]]] | None = None,
    *,
    layouts: Sequence[str] = ("left-right", "silhouette"),
    frames: int = 72,
    size: int = 512,
    timing_layouts: Sequence[str] = tuple(LAYOUTS),
    counts: Sequence[int] = COUNTS,
    repeat: int = 5,
    shared: str = DEFAULT_SHARED,
    progress: Callable[[str], None] | None = None,
) -> dict[str, Any]:
    """Run both parts of the benchmark (see the module docstring).

    Parameters
    ----------
    models : list of (name, model, up), optional
        Default :data:`MODELS` under ``shared`` (those present).
    layouts : layouts of the orbits
    frames : frames per orbit (360 / frames degrees a frame)
    size : image width and height, pixels
    timing_layouts : layouts of the timing part (empty: skip it)
    counts : label counts of the timing part
    repeat : timed runs per count (median reported)
    shared : the shared models folder
    progress : called with a line per finished item

    Returns
    -------
    dict
        ``machine``, ``orbits`` {model: {layout: {"coherent": ..., "free": ...}}},
        ``timing`` {layout: {count: {labels, layout_ms, cpu_ms, stages_ms}}} (``cpu_ms``: the
        process's CPU time of one solve, median), ``timing_view``.
    """
    say = progress or (lambda s: None)
    warm_up()
    if models is None:
        models = [
            (name, os.path.join(shared, path), up)
            for name, path, up in MODELS
            if os.path.exists(os.path.join(shared, path))
        ]
    result: dict[str, Any] = {
        "machine": machine(),
        "frames": frames,
        "size": size,
        "orbits": {},
        "timing": {},
    }
    for name, model, up in models:
        soup = load_models(model)
        result["orbits"][name] = {}
        for layout in layouts:
            entry = {
                key: _orbit(soup, up, layout, frames, size, key == "coherent") for key in ("coherent", "free")
            }
            result["orbits"][name][layout] = entry
            c = entry["coherent"]
            say(
                f"{name:10s} {layout:11s} motion x{c['motion_ratio']:.2f} of the surface, jumpy "
                f"{c['jumpy_transitions']}/{c['transitions']}, overlaps {c['overlaps']}, crossings {c['crossings']}"
            )
    if timing_layouts:
        soup, path = default_model()
        ib, azimuth = _busiest_view(soup, size, model_up(soup))
        result["timing_view"] = {"model": path, "azimuth": azimuth, "elevation": 20.0}
        result["timing"] = _timing(soup, ib, timing_layouts, counts, repeat)
        say(f"timing done on {path} at azimuth {azimuth}")
    result["load_after"] = [round(x, 2) for x in os.getloadavg()]
    return result


def format(result: dict[str, Any]) -> str:  # noqa: A001 - the bench modules' common name
    """The tables of a :func:`run` result."""
    lines = [
        f"live labeling benchmark: {result['frames']}-frame orbits ({360 / result['frames']:g} degrees a frame), "
        f"{result['size']} x {result['size']}",
        *machine_lines(result["machine"])[:2],
        f"- load average (1, 5, 15 min) at the start: {', '.join(str(x) for x in result['machine']['load_average'])}; "
        f"at the end: {', '.join(str(x) for x in result['load_after'])} (the machine is shared with other jobs)",
        "",
        "orbits: motion = mean label motion / mean motion of the surface under the anchors; jumpy = "
        "transitions with a label moving > 50 px or changing side",
        f"{'model':11s} {'layout':11s} {'labels':>6s} {'motion':>7s} {'free':>6s} {'jumpy':>9s} {'free':>9s} "
        f"{'jumps':>5s} {'sides':>5s} {'overl':>5s} {'cross':>5s} {'out':>4s} {'ms med':>7s} {'ms max':>7s}",
    ]
    if not result["orbits"]:
        lines = lines[:-3]
    for name, per in result["orbits"].items():
        for layout, e in per.items():
            c, f = e["coherent"], e["free"]
            lines.append(
                f"{name:11s} {layout:11s} {c['labels_mean']:6.1f} {c['motion_ratio']:7.2f} {f['motion_ratio']:6.2f} "
                f"{c['jumpy_transitions']:3d}/{c['transitions']:<3d} {100 * c['jumpy_fraction']:3.0f}% "
                f"{f['jumpy_transitions']:3d}/{f['transitions']:<3d}  {c['jumps']:5d} {c['side_changes']:5d} "
                f"{c['overlaps']:5d} {c['crossings']:5d} {c['left_out']:4d} {c['layout_ms_median']:7.1f} "
                f"{c['layout_ms_max']:7.1f}"
            )
    if result["timing"]:
        v = result["timing_view"]
        counts = list(next(iter(result["timing"].values())))
        lines += [
            "",
            f"layout time (ms, median) from a given ID buffer against the label count: {v['model']}, azimuth "
            f"{v['azimuth']}, elevation {v['elevation']:g}",
            f"{'layout':11s} " + " ".join(f"{c + ' lab':>8s}" for c in counts) + "   ms/label 5->30"
            f"   CPU ms {counts[-1]} lab",
        ]
        for layout, rows in result["timing"].items():
            ms = [rows[c]["layout_ms"] for c in counts]
            labs = [rows[c]["labels"] for c in counts]
            slope = (ms[-1] - ms[0]) / max(labs[-1] - labs[0], 1)
            cpu = rows[counts[-1]].get("cpu_ms", float("nan"))
            lines.append(
                f"{layout:11s} " + " ".join(f"{m:8.1f}" for m in ms) + f"   {slope:8.2f}   {cpu:10.1f}"
            )
        lines.append("(labels placed per count: " + ", ".join(str(rows[c]["labels"]) for c in counts) + ")")
    return "\n".join(lines)


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Add the options of ``meshvis bench labeling-orbit`` to its parser.

    Parameters
    ----------
    parser : argparse.ArgumentParser
        The parser of the benchmark.
    """
    parser.add_argument("--layouts", nargs="+", choices=tuple(LAYOUTS), default=["left-right", "silhouette"])
    parser.add_argument("--frames", type=int, default=72, help="frames per orbit (default 72: 5 degrees)")
    parser.add_argument("--size", type=int, default=512, help="image size (default 512)")
    parser.add_argument(
        "--timing-layouts",
        nargs="*",
        choices=tuple(LAYOUTS),
        default=list(LAYOUTS),
        help="(none: skip timing)",
    )
    parser.add_argument("--repeat", type=int, default=5, help="timed runs per label count (default 5)")
    parser.add_argument(
        "--shared", default=DEFAULT_SHARED, help=f"the shared models folder (default {DEFAULT_SHARED})"
    )
    parser.add_argument("--no-orbits", action="store_true", help="only the timing part")
    parser.add_argument("--json", metavar="FILE", help="also write the numbers as JSON")


def main(args: argparse.Namespace) -> int:
    """Run ``meshvis bench labeling-orbit``: progress lines, then the tables.

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
        [] if args.no_orbits else None,
        layouts=args.layouts,
        frames=args.frames,
        size=args.size,
        timing_layouts=args.timing_layouts,
        repeat=args.repeat,
        shared=args.shared,
        progress=lambda s: print(s, flush=True),
    )
    return report(result, format(result), args.json)
