"""Labeling benchmark: per-stage times and layout quality against the two baselines.

Three parts, all measured in one process on the same ID buffers:

1. **layouts** — for every layout at one image size (default 512 x 512): the time of
   every stage (median of ``repeat`` runs; ``layout_ms`` = everything after the ID
   buffer) and the quality metrics of the fuzzy-greedy method, the classic two-step
   method and adjustText fed the two-step anchors;
2. **sizes** — quality and time against the image size (256 ... 1024) for one layout:
   the labeling curve of the error-against-run-time report.  The error of a size is the
   mean distance of its anchors from the same method's anchors at the largest size
   (in image fractions, divided by ``d_S``);
3. **orbit** — frame-to-frame motion along an orbit: fuzzy with the coherence terms
   f6, f7, fuzzy without them, and the two-step method;
4. **views** — the quality of both methods over many views (azimuths evenly spaced at
   two elevations), per layout, so that one lucky or unlucky view does not decide a
   comparison.

``meshvis bench labeling`` calls :func:`main`; Python code calls :func:`run`.
"""

from __future__ import annotations

import argparse
import os
import statistics
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from meshvis._extras import import_extra
from meshvis.labeling.baselines import adjust_text
from meshvis.labeling.boxes import Spacing
from meshvis.labeling.candidates import LAYOUTS
from meshvis.labeling.frames import layout_frames, orbit
from meshvis.labeling.geometry2d import polyline_length
from meshvis.labeling.idbuffer import id_buffer
from meshvis.labeling.inputs import label_texts, load_models
from meshvis.labeling.metrics import is_clean, sequence_metrics
from meshvis.labeling.output import write_json
from meshvis.labeling.pipeline import LAYOUT_STAGES, fit_camera, solve
from meshvis.rays.caster import RayCaster

#: metrics shown in the tables
QUALITY = (
    "labels",
    "overlaps",
    "crossings",
    "leaders_through_labels",
    "label_over_model",
    "invalid_anchors",
    "salience_mean",
    "leader_mean_norm",
    "leader_max_norm",
    "shifted_labels",
    "labelling_rate",
)


#: the repository root of an editable install (meshvis/eval/bench/ is three folders down)
_SOURCE_ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))))


def default_model() -> tuple[Any, str]:
    """Find the project's engine-like assembly: ``models/assembly.obj``, else its generator.

    The file is looked for in the current folder (the repository root) and in the source
    tree; without it the model is made by :func:`meshvis.eval.generators.assembly`.

    Returns
    -------
    model : Soup
        The assembly.
    name : str
        The file's path, or ``"meshvis.eval.generators.assembly()"``.
    """
    for path in (
        os.path.join("models", "assembly.obj"),
        os.path.join(_SOURCE_ROOT, "models", "assembly.obj"),
    ):
        if os.path.exists(path):
            return load_models(path), path
    from meshvis.eval.generators import assembly

    return assembly().soup, "meshvis.eval.generators.assembly()"


def _pick(metrics: dict[str, Any]) -> dict[str, Any]:
    return {k: metrics[k] for k in QUALITY if k in metrics}


def _median_timings(runs: Sequence[dict[str, float]]) -> dict[str, float]:
    keys = [k for k in runs[0] if k != "metrics"]
    return {k: float(statistics.median(r.get(k, 0.0) for r in runs)) for k in keys}


def _load(model: Any) -> tuple[Any, str]:
    """Load the model to measure and name it (default: :func:`default_model`)."""
    if model is None:
        return default_model()
    soup = load_models(model)
    return soup, soup.path or str(model)


@dataclass(frozen=True)
class _Solver:
    """The settings every timed layout of one benchmark run shares."""

    texts: Sequence[str]
    d_e: float | None
    spacing: Spacing
    repeat: int

    def timed(self, ib: Any, layout: str, method: str) -> list:
        """One untimed warm-up layout (fonts, caches), then ``repeat`` timed ones."""
        solve(ib, self.texts, layout=layout, method=method, d_e=self.d_e, spacing=self.spacing)
        return [
            solve(ib, self.texts, layout=layout, method=method, d_e=self.d_e, spacing=self.spacing)
            for _ in range(max(1, self.repeat))
        ]


def _compare_layout(
    solver: _Solver, ib: Any, layout: str, adjusttext: bool, iterations: int, say: Callable[[str], None]
) -> dict[str, Any]:
    """Median stage times and the metrics of both methods (and adjustText) on one layout."""
    entry: dict[str, Any] = {}
    for method in ("fuzzy", "two-step"):
        runs = solver.timed(ib, layout, method)
        entry[method] = {
            "timings": _median_timings([r.timings for r in runs]),
            "metrics": _pick(runs[-1].metrics),
        }
        if method == "two-step" and adjusttext:
            at = adjust_text(runs[-1], iterations=iterations)
            entry["adjusttext"] = {
                "timings": {"boxes": at.timings["boxes"], "layout_ms": 1000.0 * at.timings["boxes"]},
                "metrics": _pick(at.metrics),
            }
    f = entry["fuzzy"]
    say(
        f"{layout:11s} fuzzy {f['timings']['layout_ms']:6.1f} ms, leader {f['metrics']['leader_mean_norm']:.3f}, "
        f"salience {f['metrics']['salience_mean']:.3f}"
    )
    return entry


def _anchor_error(anchors: dict[int, np.ndarray], ref: dict[int, np.ndarray], ref_ds: float) -> float:
    """Mean distance of the anchors from the reference anchors of the same parts, / ``d_S``."""
    common = sorted(set(anchors) & set(ref))
    if not common:
        return 0.0
    return float(np.mean([np.linalg.norm(anchors[p] - ref[p]) for p in common]) / ref_ds)


def _size_curve(
    solver: _Solver, idbuf_at: Callable, sizes: Sequence[int], layout: str, say: Callable[[str], None]
) -> dict[int, dict[str, Any]]:
    """Quality and time against the image size; the largest size is each method's reference."""
    ref_anchor: dict[str, dict[int, np.ndarray]] = {}
    ref_ds: dict[str, float] = {}
    per_size = {}
    for n in sorted(sizes, reverse=True):
        ibn, idn = idbuf_at(n)
        rec: dict[str, Any] = {"idbuffer_s": idn}
        for method in ("fuzzy", "two-step"):
            runs = solver.timed(ibn, layout, method)
            r = runs[-1]
            lay_ms = float(statistics.median(x.timings["layout_ms"] for x in runs))
            scale = 1.0 / n  # anchors in fractions of the image, comparable across sizes
            anchors = {lab.part: lab.anchor * scale for lab in r.labels}
            if method not in ref_anchor:
                ref_anchor[method] = dict(anchors)
                ref_ds[method] = r.sphere_diameter * scale
            rec[method] = {
                "layout_ms": lay_ms,
                "total_s": idn + lay_ms / 1000.0,
                "error": _anchor_error(anchors, ref_anchor[method], ref_ds[method]),
                "metrics": _pick(r.metrics),
            }
        per_size[int(n)] = rec
        say(
            f"size {n:5d}: id buffer {idn * 1000:7.1f} ms, fuzzy layout {rec['fuzzy']['layout_ms']:6.1f} ms, "
            f"error {rec['fuzzy']['error']:.4f}"
        )
    return {k: per_size[k] for k in sorted(per_size)}


#: the orbit's variants: fuzzy with and without the coherence terms f6, f7, and two-step
_ORBIT_VARIANTS = {
    "fuzzy": dict(method="fuzzy"),
    "fuzzy-no-coherence": dict(method="fuzzy", coherence=False),
    "two-step": dict(method="two-step", coherence=False),
}


def _orbit(
    soup: Any,
    cams: list,
    caster: RayCaster,
    layout: str,
    size: int,
    d_e: float | None,
    spacing: Spacing,
    say: Callable[[str], None],
) -> dict[str, dict[str, Any]]:
    """Frame-to-frame motion and quality along an orbit, per variant."""
    out = {}
    for key, kw in _ORBIT_VARIANTS.items():
        res = layout_frames(
            soup, cams, caster=caster, layout=layout, size=(size, size), d_e=d_e, spacing=spacing, **kw
        )
        seq = sequence_metrics(res)
        seq["clean_frames"] = int(
            sum(
                r.metrics["overlaps"] == 0
                and r.metrics["crossings"] == 0
                and r.metrics["label_over_model"] == 0
                for r in res
            )
        )
        seq["layout_ms_mean"] = float(np.mean([r.timings["layout_ms"] for r in res[1:]] or [0.0]))
        seq["leader_mean_norm"] = float(np.mean([r.metrics["leader_mean_norm"] for r in res]))
        seq["salience_mean"] = float(np.mean([r.metrics["salience_mean"] for r in res]))
        out[key] = seq
        say(
            f"orbit {key:18s} label motion {seq['label_motion_mean']:.2f} px/frame, anchor motion "
            f"{seq['anchor_motion_mean']:.2f}, flips {seq['side_flips']}, swaps {seq['order_swaps']}"
        )
    return out


def _header(
    name: str, soup: Any, *, d_e: float | None, spacing: Spacing, size: int, repeat: int, setup_s: float
) -> dict[str, Any]:
    """Describe the run in the result, with empty sections to fill."""
    return {
        "model": name,
        "d_e": d_e,
        "rotate": spacing.rotate,
        "parts": soup.n_parts,
        "faces": soup.n_faces,
        "size": int(size),
        "repeat": int(repeat),
        "setup_s": setup_s,
        "layouts": {},
        "sizes": {},
        "orbit": {},
        "views": {},
    }


def _view_buffers(
    soup: Any, caster: RayCaster, views: int, elevations: Sequence[float], up: Sequence[float], size: int
) -> list:
    """ID buffers of ``views`` azimuths evenly spaced at each elevation."""
    cams = [
        fit_camera(soup, azimuth=az, elevation=el, up=up)
        for el in elevations
        for az in np.arange(views) * 360.0 / views
    ]
    return [id_buffer(soup, c, (size, size), caster=caster) for c in cams]


def _many_views(
    bufs: list, solver: _Solver, layouts: Sequence[str], say: Callable[[str], None]
) -> dict[str, dict[str, Any]]:
    """:func:`compare_views` of every layout over the ID buffers ``bufs``."""
    out = {}
    for layout in layouts:
        out[layout] = v = compare_views(bufs, solver.texts, layout, solver.d_e, solver.spacing)
        say(
            f"views {layout:11s} leader fuzzy {v['fuzzy']['leader_mean']:.3f} two-step "
            f"{v['two-step']['leader_mean']:.3f}, fuzzy shorter in {v['fuzzy_shorter']} of {v['views']}"
        )
    return out


def run(
    model: Any = None,
    *,
    size: int = 512,
    layouts: Sequence[str] = tuple(LAYOUTS),
    sizes: Sequence[int] = (256, 384, 512, 768, 1024),
    size_layout: str = "left-right",
    orbit_frames: int = 12,
    orbit_layout: str = "left-right",
    repeat: int = 5,
    adjusttext: bool = True,
    adjusttext_iterations: int = 200,
    up: Sequence[float] = (0.0, 0.0, 1.0),
    azimuth: float = 30.0,
    elevation: float = 20.0,
    views: int = 12,
    view_elevations: Sequence[float] = (20.0, 45.0),
    d_e: float | None = None,
    rotate: float | None = None,
    progress: Callable[[str], None] | None = None,
) -> dict[str, Any]:
    """Run the labeling benchmark (the four parts of the module docstring).

    Parameters
    ----------
    model : Soup, trimesh object, (V, F), path or a sequence of these, optional
        The model, as :func:`meshvis.labeling.inputs.load_models` takes it; default
        :func:`default_model`.
    size : int
        Image width and height of the layout comparison, in pixels.
    layouts : sequence of str
        The layouts to compare (keys of :data:`meshvis.labeling.candidates.LAYOUTS`).
    sizes : sequence of int
        Image sizes of the quality-against-size curve.
    size_layout : str
        Layout of the size curve.
    orbit_frames : int
        Frames of the orbit (0 or 1 skips the orbit).
    orbit_layout : str
        Layout of the orbit.
    repeat : int
        Runs per timing (the median is reported); a first, untimed run warms caches.
    adjusttext : bool
        Also run the adjustText baseline (slow: seconds per layout).
    adjusttext_iterations : int
        Its fixed iteration count.
    up : (3,) float
        The model's up direction, for the cameras.
    azimuth : float
        Azimuth of the benchmark view in degrees (the camera is fitted to the model).
    elevation : float
        Elevation of the benchmark view and of the orbit, in degrees.
    views : int
        Azimuths of the many-views comparison at each of ``view_elevations`` (0 skips it).
    view_elevations : sequence of float
        Elevations of the many-views comparison, in degrees.
    d_e : float, optional
        Endpoint distance threshold of the fuzzy method (fraction of ``d_S``; default the
        paper's, see :func:`meshvis.labeling.pipeline.solve`).
    rotate : float, optional
        ``Spacing.rotate`` of both methods (pixels; default the Spacing default).
    progress : callable, optional
        Called with a line of text after each step.

    Returns
    -------
    dict
        ``model``, ``parts``, ``size``, ``layouts`` (per layout: ``fuzzy``, ``two-step``,
        ``adjusttext`` each with ``timings`` (seconds, ``layout_ms`` in ms) and
        ``metrics``), ``sizes`` (per size: times and metrics of both methods, ``error``),
        ``orbit`` (sequence metrics of the three variants), ``views`` (per layout:
        :func:`compare_views`).

    Raises
    ------
    MissingExtraError
        ``adjusttext`` is True and adjustText is not installed.
    ModelError
        The model cannot be used.
    """
    say = progress or (lambda s: None)
    if adjusttext:  # fail before the first layout, not in the middle of the run
        import_extra("adjustText", "meshvis bench labeling without --no-adjusttext")
    spacing = Spacing() if rotate is None else Spacing(rotate=float(rotate))
    soup, name = _load(model)
    texts = label_texts(soup.part_names)
    t0 = time.perf_counter()
    caster = RayCaster(soup)
    setup_s = time.perf_counter() - t0
    cam = fit_camera(soup, azimuth=azimuth, elevation=elevation, up=up)
    out = _header(name, soup, d_e=d_e, spacing=spacing, size=size, repeat=repeat, setup_s=setup_s)
    out["view_elevations"] = [float(e) for e in view_elevations]  # the last key of the header

    def idbuf_at(n: int):  # the ID buffer of the benchmark view at n x n pixels, and its seconds
        t = time.perf_counter()
        return id_buffer(soup, cam, (n, n), caster=caster), time.perf_counter() - t

    ib, id_s = idbuf_at(size)
    out.update(visible_parts=int(len(ib.visible())), idbuffer_s=id_s)
    solver = _Solver(texts=texts, d_e=d_e, spacing=spacing, repeat=repeat)
    for layout in layouts:
        out["layouts"][layout] = _compare_layout(solver, ib, layout, adjusttext, adjusttext_iterations, say)
    out.update(sizes=_size_curve(solver, idbuf_at, sizes, size_layout, say), size_layout=size_layout)
    if orbit_frames and orbit_frames > 1:
        cams = orbit(soup, orbit_frames, elevation=elevation, start=azimuth, up=up)
        out["orbit"] = _orbit(soup, cams, caster, orbit_layout, size, d_e, spacing, say)
        out.update(orbit_layout=orbit_layout, orbit_frames=int(orbit_frames))
    if views:
        bufs = _view_buffers(soup, caster, views, view_elevations, up, size)
        out["views"] = _many_views(bufs, solver, layouts, say)
    return out


def compare_views(
    buffers: Sequence[Any],
    texts: Sequence[str],
    layout: str,
    d_e: float | None = None,
    spacing: Spacing | None = None,
) -> dict[str, Any]:
    """Measure the quality of the fuzzy and the two-step method over many views of one model.

    Parameters
    ----------
    buffers : sequence of IdBuffer
        The ID buffers of the views (:func:`meshvis.labeling.idbuffer.id_buffer`).
    texts : sequence of str
        The label text of every part.
    layout : str
        The layout.
    d_e : float, optional
        As in :func:`meshvis.labeling.pipeline.solve`.
    spacing : Spacing, optional
        As in :func:`meshvis.labeling.pipeline.solve`.

    Returns
    -------
    dict
        Per method: ``labels`` and ``unplaced`` (summed), ``clean`` (views with no
        overlap, crossing, box over the model or bad anchor), ``leader_mean`` and
        ``salience_mean`` (means over the views of each view's mean), ``box_ms`` and
        ``layout_ms`` (medians over the views), ``layout_ms_max`` (the slowest view) and
        ``labels_max`` (the most labels in one view); and ``views``, ``fuzzy_shorter`` (views
        whose mean leader is shorter with fuzzy), ``common_leader`` (per method: summed
        leader length / d_S over the labels both methods place in a view, summed over the
        views) and ``common_first_segment`` (the same for the leaders' first segments:
        anchor to endpoint in the silhouette layout).
    """
    per: dict[str, list] = {"fuzzy": [], "two-step": []}
    common = {"fuzzy": 0.0, "two-step": 0.0}
    inside = {"fuzzy": 0.0, "two-step": 0.0}
    for ib in buffers:
        res = {m: solve(ib, texts, layout=layout, method=m, d_e=d_e, spacing=spacing) for m in per}
        both = set.intersection(*({lab.part for lab in r.labels} for r in res.values()))
        for m, r in res.items():
            per[m].append(r)
            mine = [lab for lab in r.labels if lab.part in both]
            common[m] += sum(polyline_length(lab.leader) for lab in mine) / r.sphere_diameter
            inside[m] += sum(polyline_length(lab.leader[:2]) for lab in mine) / r.sphere_diameter
    out: dict[str, Any] = {"views": len(buffers), "common_leader": common, "common_first_segment": inside}
    for m, rs in per.items():
        out[m] = {
            "labels": int(sum(r.metrics["labels"] for r in rs)),
            "unplaced": int(sum(len(r.unplaced) for r in rs)),
            "clean": int(sum(is_clean(r.metrics) for r in rs)),
            "leader_mean": float(np.mean([r.metrics["leader_mean_norm"] for r in rs])),
            "salience_mean": float(np.mean([r.metrics["salience_mean"] for r in rs])),
            "box_ms": float(np.median([1000.0 * r.timings["boxes"] for r in rs])),
            "layout_ms": float(np.median([r.timings["layout_ms"] for r in rs])),
            "layout_ms_max": float(max(r.timings["layout_ms"] for r in rs)),
            "labels_max": int(max(r.metrics["labels"] for r in rs)),
        }
    out["fuzzy_shorter"] = int(
        sum(
            a.metrics["leader_mean_norm"] < b.metrics["leader_mean_norm"]
            for a, b in zip(per["fuzzy"], per["two-step"])
        )
    )
    return out


def _format_times(result: dict[str, Any]) -> list[str]:
    """Per-stage time per frame of every layout and method."""
    stages = list(LAYOUT_STAGES)
    head = f"{'layout':11s} {'method':10s} " + " ".join(f"{s[:6]:>6s}" for s in stages) + f" {'layout':>7s}"
    lines = ["per-stage time per frame (ms)", head]
    for layout, entry in result["layouts"].items():
        for method in ("fuzzy", "two-step"):
            t = entry[method]["timings"]
            lines.append(
                f"{layout:11s} {method:10s} "
                + " ".join(f"{1000 * t.get(s, 0.0):6.1f}" for s in stages)
                + f" {t['layout_ms']:7.1f}"
            )
        if "adjusttext" in entry:
            lines.append(
                f"{layout:11s} {'adjusttext':10s} "
                + " ".join(f"{'':6s}" for _ in stages)
                + f" {entry['adjusttext']['timings']['layout_ms']:7.1f}"
            )
    return lines


def _format_quality(result: dict[str, Any]) -> list[str]:
    """Tabulate the quality metrics of every layout and method."""
    lines = [
        "",
        "quality",
        f"{'layout':11s} {'method':10s} {'labels':>6s} {'overlap':>7s} {'cross':>5s} "
        f"{'thru':>4s} {'over_px':>7s} {'bad_a':>5s} {'salience':>8s} {'leader':>7s} {'max':>6s} {'shifted':>7s}",
    ]
    for layout, entry in result["layouts"].items():
        for method in ("fuzzy", "two-step", "adjusttext"):
            if method not in entry:
                continue
            m = entry[method]["metrics"]
            lines.append(
                f"{layout:11s} {method:10s} {m['labels']:6d} {m['overlaps']:7d} {m['crossings']:5d} "
                f"{m['leaders_through_labels']:4d} {m['label_over_model']:7d} {m['invalid_anchors']:5d} "
                f"{m['salience_mean']:8.3f} {m['leader_mean_norm']:7.3f} {m['leader_max_norm']:6.3f} "
                f"{m.get('shifted_labels', 0):7d}"
            )
    return lines


def _format_sizes(result: dict[str, Any]) -> list[str]:
    """Quality and time against the image size."""
    lines = [
        "",
        f"quality against image size ({result['size_layout']}); error = mean anchor distance to the "
        f"same method's anchors at the largest size / d_S",
        f"{'size':>5s} {'id_ms':>7s} {'fz_ms':>7s} {'fz_err':>7s} {'fz_leader':>9s} {'fz_sal':>6s} "
        f"{'2s_ms':>7s} {'2s_err':>7s} {'2s_leader':>9s} {'2s_sal':>6s}",
    ]
    for n, rec in result["sizes"].items():
        f, t = rec["fuzzy"], rec["two-step"]
        lines.append(
            f"{int(n):5d} {rec['idbuffer_s'] * 1000:7.1f} {f['layout_ms']:7.1f} {f['error']:7.4f} "
            f"{f['metrics']['leader_mean_norm']:9.3f} {f['metrics']['salience_mean']:6.3f} "
            f"{t['layout_ms']:7.1f} {t['error']:7.4f} {t['metrics']['leader_mean_norm']:9.3f} "
            f"{t['metrics']['salience_mean']:6.3f}"
        )
    return lines


def _format_orbit(result: dict[str, Any]) -> list[str]:
    """Motion per frame along the orbit, per variant."""
    lines = [
        "",
        f"orbit of {result['orbit_frames']} frames ({result['orbit_layout']}), motion per frame (px)",
        f"{'variant':20s} {'label':>6s} {'anchor':>6s} {'flips':>5s} {'swaps':>5s} {'clean':>5s} "
        f"{'leader':>6s} {'salience':>8s} {'ms':>6s}",
    ]
    for key, s in result["orbit"].items():
        lines.append(
            f"{key:20s} {s['label_motion_mean']:6.2f} {s['anchor_motion_mean']:6.2f} {s['side_flips']:5d} "
            f"{s['order_swaps']:5d} {s['clean_frames']:5d} {s['leader_mean_norm']:6.3f} "
            f"{s['salience_mean']:8.3f} {s['layout_ms_mean']:6.1f}"
        )
    return lines


def _format_views(result: dict[str, Any]) -> list[str]:
    """Both methods over many views, per layout."""
    n = next(iter(result["views"].values()))["views"]
    lines = [
        "",
        f"{n} views (azimuths evenly spaced, elevations {result.get('view_elevations')}), "
        "per layout; leader = mean over the views of the mean leader / d_S; common = summed over "
        "the labels both methods place; box = median box-stage ms; fz_ms, fz_max = median and "
        "slowest layout ms of the fuzzy method; most = most labels in one view",
        f"{'layout':11s} {'fz_labels':>9s} {'2s_labels':>9s} {'fz_clean':>8s} {'2s_clean':>8s} "
        f"{'fz_leader':>9s} {'2s_leader':>9s} {'shorter':>7s} {'fz_common':>9s} {'2s_common':>9s} "
        f"{'fz_sal':>6s} {'fz_box':>6s} {'2s_box':>6s} {'fz_ms':>6s} {'fz_max':>6s} {'most':>4s}",
    ]
    for layout, v in result["views"].items():
        f, t = v["fuzzy"], v["two-step"]
        lines.append(
            f"{layout:11s} {f['labels']:9d} {t['labels']:9d} {f['clean']:8d} {t['clean']:8d} "
            f"{f['leader_mean']:9.3f} {t['leader_mean']:9.3f} {v['fuzzy_shorter']:7d} "
            f"{v['common_leader']['fuzzy']:9.2f} {v['common_leader']['two-step']:9.2f} "
            f"{f['salience_mean']:6.3f} {f['box_ms']:6.1f} {t['box_ms']:6.1f} "
            f"{f['layout_ms']:6.1f} {f['layout_ms_max']:6.1f} {f['labels_max']:4d}"
        )
    return lines


def format(result: dict[str, Any]) -> str:  # noqa: A001 - the bench modules' common name
    """Format a :func:`run` result as plain-text tables.

    Parameters
    ----------
    result : dict
        A result of :func:`run`.

    Returns
    -------
    str
        The header, per-stage times, quality, and the size, orbit and views tables of the
        parts that ran.
    """
    lines = [
        f"labeling benchmark: {result['model']} ({result['parts']} parts, {result['visible_parts']} visible), "
        f"{result['size']} x {result['size']}, median of {result['repeat']} runs, d_e "
        f"{'paper default' if result.get('d_e') is None else result['d_e']}, rotate {result.get('rotate')} px",
        f"ray caster build {result['setup_s'] * 1000:.1f} ms, ID buffer {result['idbuffer_s'] * 1000:.1f} ms",
        "",
    ]
    lines += _format_times(result) + _format_quality(result)
    if result.get("sizes"):
        lines += _format_sizes(result)
    if result.get("orbit"):
        lines += _format_orbit(result)
    if result.get("views"):
        lines += _format_views(result)
    return "\n".join(lines)


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Add the options of ``meshvis bench labeling`` to its parser.

    Parameters
    ----------
    parser : argparse.ArgumentParser
        The parser of the benchmark.
    """
    parser.add_argument("model", nargs="*", help="model file(s) (default: models/assembly.obj)")
    parser.add_argument(
        "--size", type=int, default=512, help="image size of the layout comparison (default 512)"
    )
    parser.add_argument(
        "--sizes",
        type=int,
        nargs="+",
        default=[256, 384, 512, 768, 1024],
        help="image sizes of the quality-against-size curve",
    )
    parser.add_argument("--layouts", nargs="+", choices=tuple(LAYOUTS), default=list(LAYOUTS))
    parser.add_argument("--orbit", type=int, default=12, help="frames of the orbit (0: skip)")
    parser.add_argument(
        "--views",
        type=int,
        default=12,
        help="azimuths of the many-views comparison, at elevations 20 and 45 (0: skip; default 12)",
    )
    parser.add_argument("--repeat", type=int, default=5, help="runs per timing, median reported (default 5)")
    parser.add_argument("--no-adjusttext", action="store_true", help="skip the (slow) adjustText baseline")
    parser.add_argument("--up", choices=("x", "y", "z"), default="z", help="the model's up axis (default z)")
    parser.add_argument(
        "--d-e",
        type=float,
        default=None,
        help="d_e of the fuzzy method, fraction of d_S (default: the paper's, from the box size)",
    )
    parser.add_argument(
        "--rotate",
        type=float,
        default=None,
        help="largest endpoint move of a rotated leader, pixels (silhouette layout; 0: none)",
    )
    parser.add_argument("--json", metavar="FILE", help="also write the numbers as JSON")


def main(args: argparse.Namespace) -> int:
    """Run ``meshvis bench labeling``: print progress lines, then the tables.

    Parameters
    ----------
    args : argparse.Namespace
        The options of :func:`add_arguments`.

    Returns
    -------
    int
        Exit status 0.

    Raises
    ------
    MissingExtraError
        adjustText is not installed and ``--no-adjusttext`` is not given.
    ModelError
        A model cannot be read.
    """
    from meshvis.rays.camera import AXES

    model = None
    if args.model:
        model = args.model if len(args.model) > 1 else args.model[0]
    result = run(
        model,
        size=args.size,
        layouts=args.layouts,
        sizes=args.sizes,
        orbit_frames=args.orbit,
        repeat=args.repeat,
        adjusttext=not args.no_adjusttext,
        up=AXES[args.up],
        views=args.views,
        d_e=args.d_e,
        rotate=args.rotate,
        progress=lambda s: print(s, flush=True),
    )
    return report(result, format(result), args.json)


def report(result: dict[str, Any], text: str, json_path: str | None) -> int:
    """Print a benchmark's tables after its progress lines and write its JSON.

    Parameters
    ----------
    result : dict
        The numbers, written to ``json_path``.
    text : str
        The tables to print.
    json_path : str or None
        The JSON file; None writes none.

    Returns
    -------
    int
        Exit status 0.
    """
    print()
    print(text)
    if json_path:
        write_json(result, json_path)
    return 0
