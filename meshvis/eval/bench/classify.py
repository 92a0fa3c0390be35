"""``meshvis bench classify``: per-stage times of the classification on large real models.

Defaults: the 124,789-face samurai monastery and the dog skin with its rib cage inside
(``meshvis.eval.generators.skin_and_ribcage``).  Reports rays, nodes, edges, the time of every
stage and the share of the sampling stage spent inside Embree.
"""

from __future__ import annotations

import os
import time
from typing import Any

from meshvis.eval.bench.real_models import DEFAULT_MODELS, models_folder
from meshvis.eval.generators import skin_and_ribcage
from meshvis.graphcut.classify import classify
from meshvis.io import load


def default_models(models_dir: str | os.PathLike = DEFAULT_MODELS) -> list[tuple[str, Any]]:
    """List the default models: the monastery and the skin + rib cage, read from ``models_dir``.

    Parameters
    ----------
    models_dir : str or os.PathLike
        The folder of the real models (checked to exist; the files are read when built).

    Returns
    -------
    list of (str, callable)
        Name and a function of no argument that reads the model, per model.

    Raises
    ------
    ParameterError
        ``models_dir`` is not a folder.
    """
    folder = models_folder(models_dir)
    return [
        (
            "pybullet__samurai_monastry.obj",
            lambda: load(os.path.join(folder, "pybullet__samurai_monastry.obj")),
        ),
        ("skin + ribcage", lambda: skin_and_ribcage(folder).soup),
    ]


def run(
    models: list[str] | None = None,
    rays_per_node: int = 32,
    seed: int = 0,
    models_dir: str | os.PathLike = DEFAULT_MODELS,
) -> list[dict]:
    """Classify each model once and collect the counts and per-stage times.

    Parameters
    ----------
    models : list of str, optional
        Model files; default :func:`default_models` of ``models_dir``.
    rays_per_node : int
        Ray budget per node of the classification.
    seed : int
        Seed of the classification.
    models_dir : str or os.PathLike
        The folder of the real models, for the default models.

    Returns
    -------
    list of dict
        Per model: name, faces, total seconds, seconds per stage (or "skipped"), rounds,
        rays, nodes, edges, flagged faces, Embree's share of the sampling, outside area
        fraction, load average and the classification's summary text.

    Raises
    ------
    ParameterError
        Without ``models``, when ``models_dir`` is not a folder.
    ModelError
        A model cannot be read.
    FileNotFoundError
        A file of the skin + rib cage is missing.
    """
    todo = default_models(models_dir) if not models else [(m, lambda m=m: load(m)) for m in models]
    out = []
    for name, make in todo:
        soup = make()
        t = time.perf_counter()
        c = classify(soup, rays_per_node=rays_per_node, seed=seed)
        total = time.perf_counter() - t
        r = c.report(per_face=False)
        out.append(
            {
                "model": name,
                "faces": soup.n_faces,
                "seconds": total,
                "stages": {s.name: (round(s.seconds, 3) if s.ran else "skipped") for s in c.stages},
                "rounds": len(c.rounds),
                "rays": r["rays"],
                "reverse_rays": r["reverse_rays"],
                "nodes": r["nodes"],
                "point_nodes": r["point_nodes"],
                "edges": r["edges"],
                "flagged_faces": r["flagged_faces"],
                "embree_share_of_sampling": r["embree_share_of_sampling"],
                "outside_area_fraction": r["outside_area_fraction"],
                "load_average": os.getloadavg()[0],
                "summary": c.summary(),
            }
        )
    return out


def format(results: list[dict]) -> str:
    """Format the results of :func:`run`: per model a title line, the summary and Embree's share.

    Parameters
    ----------
    results : list of dict
        A result of :func:`run`.

    Returns
    -------
    str
        The text to print.
    """
    lines = []
    for r in results:
        lines.append(
            f"== {r['model']}: {r['faces']} faces, {r['seconds']:.2f} s total "
            f"(load average {r['load_average']:.2f})"
        )
        lines.append(r["summary"])
        lines.append(f"Embree share of the sampling stage: {100 * r['embree_share_of_sampling']:.0f}%")
    return "\n".join(lines)
