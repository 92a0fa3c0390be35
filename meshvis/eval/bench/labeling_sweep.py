"""Guarantee sweep of the label layout: many views, sizes and models, every layout, both methods.

The layout benchmark (:mod:`meshvis.eval.bench.labeling`) measures one model closely; this sweep checks
the promises everywhere it can reach in a minute or two: for every (model, view, image
size, layout, method) it lays the labels out once and records whether the layout is
clean (no box overlap, no leader crossing, no box over the model, no bad anchor, no
leader through a box), how many visible parts were left out, and the leader lengths.
Boxes may reach beyond the image here (``solve(..., inside=False)``): the sweep checks the
box stage's own promise that every visible part gets a place.  The summary is per (layout, method, size): clean layouts, labels placed and left out,
mean leader, the 90th percentile and the largest of each layout's longest leader (all
divided by ``d_S``), and the mean layout time.

``meshvis bench labeling-sweep`` calls :func:`main`; Python code calls :func:`run`.
"""

from __future__ import annotations

import argparse
import os
from collections.abc import Callable, Sequence
from typing import Any

import numpy as np

from meshvis.eval.bench.real_models import DEFAULT_MODELS, add_models_argument, models_folder
from meshvis.labeling.candidates import LAYOUTS
from meshvis.labeling.idbuffer import id_buffer
from meshvis.labeling.inputs import label_texts, load_models
from meshvis.labeling.metrics import is_clean
from meshvis.labeling.pipeline import METHODS, fit_camera, solve, warm_up
from meshvis.rays.caster import RayCaster

from .labeling import default_model, report

#: (name, files, up axis) of the real models the sweep uses when they are present
REAL = (
    ("truck", ("CesiumMilkTruck.glb",), (0.0, 1.0, 0.0)),
    ("boolean", ("boolean.glb",), (0.0, 0.0, 1.0)),
    (
        "dog",
        tuple(f"dm_control__{n}.stl" for n in ("SKINbody", "BONEMergedSkull", "BONERibcage")),
        (0.0, 0.0, 1.0),
    ),
)


def default_models(
    models_dir: str | os.PathLike = DEFAULT_MODELS,
) -> list[tuple[str, Any, tuple[float, float, float]]]:
    """List the sweep's models: the generated engine assembly and the real multi-part models present.

    The real models of :data:`REAL` are taken from ``models_dir`` when all their files
    are there.

    Parameters
    ----------
    models_dir : str or os.PathLike
        The folder of the real models.

    Returns
    -------
    list of (str, model, (3,) float)
        Name, model (a soup, a path or a list of paths) and up direction, per model.

    Raises
    ------
    ParameterError
        When ``models_dir`` is not a folder.
    """
    out: list[tuple[str, Any, tuple[float, float, float]]] = [
        ("assembly", default_model()[0], (0.0, 0.0, 1.0))
    ]
    folder = models_folder(models_dir)
    for name, files, up in REAL:
        paths = [os.path.join(folder, f) for f in files]
        if all(os.path.exists(p) for p in paths):
            out.append((name, paths if len(paths) > 1 else paths[0], up))
    return out


def run(
    models: Sequence[tuple[str, Any, Sequence[float]]] | None = None,
    *,
    azimuths: int = 8,
    elevations: Sequence[float] = (10.0, 45.0, 80.0),
    sizes: Sequence[int] = (192, 384, 512),
    layouts: Sequence[str] = tuple(LAYOUTS),
    methods: Sequence[str] = METHODS,
    progress: Callable[[str], None] | None = None,
    models_dir: str | os.PathLike = DEFAULT_MODELS,
) -> dict[str, Any]:
    """Lay out every case once and summarise.

    A case is a (model, view, image size, layout, method); the views are ``azimuths``
    evenly spaced azimuths at each elevation, the camera fitted to the model.

    Parameters
    ----------
    models : sequence of (str, model, (3,) float), optional
        (name, model, up) triples, the model as
        :func:`meshvis.labeling.inputs.load_models` takes it; default
        :func:`default_models` of ``models_dir``.
    azimuths : int
        Views per elevation, evenly spaced around the up axis.
    elevations : sequence of float
        Camera elevations (degrees).
    sizes : sequence of int
        Image widths = heights (pixels).
    layouts : sequence of str
        The layouts to run.
    methods : sequence of str
        The layout methods to run.
    progress : callable, optional
        Called with a line of text after each model.
    models_dir : str or os.PathLike
        Folder of the real models of the default ``models``.

    Returns
    -------
    dict
        ``cases`` (per case key ``model|azimuth|elevation|size|layout|method``: ``labels``,
        ``unplaced``, ``clean``, ``leader_mean``, ``leader_max``, ``leader_sum`` (/ ``d_S``),
        ``layout_ms``) and ``summary`` (see :func:`summarise`).

    Raises
    ------
    ParameterError
        Without ``models``, when ``models_dir`` is not a folder.
    ModelError
        A model cannot be read.
    """
    say = progress or (lambda s: None)
    warm_up()  # one-time imports are not a layout's time
    cases: dict[str, dict[str, Any]] = {}
    for name, model, up in models if models is not None else default_models(models_dir):
        soup = load_models(model)
        caster = RayCaster(soup)
        texts = label_texts(soup.part_names)
        for el in elevations:
            for az in np.arange(azimuths) * 360.0 / azimuths:
                cam = fit_camera(soup, azimuth=float(az), elevation=float(el), up=tuple(up))
                for n in sizes:
                    ib = id_buffer(soup, cam, (n, n), caster=caster)
                    for layout in layouts:
                        for method in methods:
                            r = solve(ib, texts, layout=layout, method=method, inside=False)
                            m = r.metrics
                            cases[f"{name}|{az:g}|{el:g}|{n}|{layout}|{method}"] = {
                                "labels": int(m["labels"]),
                                "unplaced": len(r.unplaced),
                                "clean": bool(is_clean(m) and m["leaders_through_labels"] == 0),
                                "leader_mean": float(m["leader_mean_norm"]),
                                "leader_max": float(m["leader_max_norm"]),
                                "leader_sum": float(m["leader_sum_norm"]),
                                "layout_ms": float(r.timings["layout_ms"]),
                            }
        say(f"{name}: {len(cases)} layouts so far")
    return {"cases": cases, "summary": summarise(cases)}


def summarise(cases: dict[str, dict[str, Any]]) -> list[dict[str, Any]]:
    """Summarise the cases per (layout, method, size).

    Parameters
    ----------
    cases : dict
        The ``cases`` of a :func:`run` result.

    Returns
    -------
    list of dict
        One row per (layout, method, size), in layout order: ``layouts``, ``clean``,
        ``labels``, ``unplaced``, ``leader_mean`` (mean of the layouts' means),
        ``leader_max_p90`` and ``leader_max`` (90th percentile and largest of the layouts'
        longest leaders), ``layout_ms`` (mean).
    """
    groups: dict[tuple[str, str, int], list[dict[str, Any]]] = {}
    for key, c in cases.items():
        _, _, _, n, layout, method = key.split("|")
        groups.setdefault((layout, method, int(n)), []).append(c)
    order = {name: i for i, name in enumerate(LAYOUTS)}
    rows = []
    for (layout, method, n), cs in sorted(
        groups.items(), key=lambda kv: (order.get(kv[0][0], 99), kv[0][2], kv[0][1])
    ):
        worst = np.array([c["leader_max"] for c in cs])
        rows.append(
            {
                "layout": layout,
                "method": method,
                "size": n,
                "layouts": len(cs),
                "clean": int(sum(c["clean"] for c in cs)),
                "labels": int(sum(c["labels"] for c in cs)),
                "unplaced": int(sum(c["unplaced"] for c in cs)),
                "leader_mean": float(np.mean([c["leader_mean"] for c in cs])),
                "leader_max_p90": float(np.percentile(worst, 90)),
                "leader_max": float(worst.max()),
                "layout_ms": float(np.mean([c["layout_ms"] for c in cs])),
            }
        )
    return rows


def format(result: dict[str, Any]) -> str:  # noqa: A001 - the bench modules' common name
    """Format a :func:`run` result as a plain-text table, one row per summary row.

    Parameters
    ----------
    result : dict
        A result of :func:`run`.

    Returns
    -------
    str
        The table.
    """
    rows = result["summary"]
    lines = [
        f"labeling sweep: {len(result['cases'])} layouts; leader lengths / d_S; max = each layout's longest "
        "leader (90th percentile and largest over the layouts)",
        f"{'layout':11s} {'method':9s} {'size':>4s} {'layouts':>7s} {'clean':>5s} {'labels':>6s} "
        f"{'unplaced':>8s} {'mean':>6s} {'max_p90':>7s} {'max':>6s} {'ms':>6s}",
    ]
    for r in rows:
        lines.append(
            f"{r['layout']:11s} {r['method']:9s} {r['size']:4d} {r['layouts']:7d} {r['clean']:5d} "
            f"{r['labels']:6d} {r['unplaced']:8d} {r['leader_mean']:6.3f} {r['leader_max_p90']:7.2f} "
            f"{r['leader_max']:6.2f} {r['layout_ms']:6.1f}"
        )
    return "\n".join(lines)


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Add the options of ``meshvis bench labeling-sweep`` to its parser.

    Parameters
    ----------
    parser : argparse.ArgumentParser
        The parser of the benchmark.
    """
    parser.add_argument("--azimuths", type=int, default=8, help="views per elevation (default 8)")
    parser.add_argument(
        "--elevations",
        type=float,
        nargs="+",
        default=[10.0, 45.0, 80.0],
        help="camera elevations in degrees (default 10 45 80)",
    )
    parser.add_argument(
        "--sizes", type=int, nargs="+", default=[192, 384, 512], help="image sizes (default 192 384 512)"
    )
    parser.add_argument("--layouts", nargs="+", choices=tuple(LAYOUTS), default=list(LAYOUTS))
    parser.add_argument("--json", metavar="FILE", help="also write every case and the summary as JSON")
    add_models_argument(parser)


def main(args: argparse.Namespace) -> int:
    """Run ``meshvis bench labeling-sweep``: print progress lines, then the table.

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
    ParameterError
        ``--models`` is not a folder.
    """
    result = run(
        azimuths=args.azimuths,
        elevations=args.elevations,
        sizes=args.sizes,
        layouts=args.layouts,
        progress=lambda s: print(s, flush=True),
        models_dir=args.models_dir,
    )
    return report(result, format(result), args.json)
