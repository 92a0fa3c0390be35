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
    """The monastery and the skin + rib cage, read from ``models_dir`` (checked to exist)."""
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
    """Classify each model once and return one result dict per model (default models from ``models_dir``)."""
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
    lines = []
    for r in results:
        lines.append(
            f"== {r['model']}: {r['faces']} faces, {r['seconds']:.2f} s total "
            f"(load average {r['load_average']:.2f})"
        )
        lines.append(r["summary"])
        lines.append(f"Embree share of the sampling stage: {100 * r['embree_share_of_sampling']:.0f}%")
    return "\n".join(lines)
