"""The README's "main job": orientation, inside removal and layers on a bundled model.

The bundled model is made by :func:`meshvis.eval.generators.overlapping_solids` (the same
generator that writes ``models/overlapping_solids.obj``): a box and a sphere that pass
through each other, turned into a triangle soup — vertices unwelded, faces shuffled, 30%
of them flipped.  The parts of each solid inside the other are hidden; intersecting
triangles need sample-point nodes.  Every result is checked against the generator's
ground truth.
"""

from __future__ import annotations

import contextlib
import os
import time
from collections.abc import Callable

import numpy as np

from meshvis import _validate
from meshvis.eval.generators import overlapping_solids, soupify
from meshvis.graphcut.classify import classify
from meshvis.io import save, staged_outputs
from meshvis.io.jsonfile import write_json
from meshvis.rays.camera import Camera
from meshvis.rays.render import render, render_layers, save_png
from meshvis.repair.layers import layers
from meshvis.repair.orient import orient
from meshvis.repair.remove import remove_interior

DEMO_FILES = (
    "input.obj",
    "input.png",
    "oriented.obj",
    "oriented.png",
    "exterior.obj",
    "interior.obj",
    "exterior.png",
    "layers.ply",
    "layers.png",
    "report.json",
)


def run_demo(
    folder: str,
    *,
    seed: int = 0,
    size: int = 512,
    say: Callable[[str], None] = print,
    detail: Callable[[str], None] | None = None,
) -> dict:
    """Run the three applications on the bundled soup and write everything to ``folder``.

    The soup is :func:`~meshvis.eval.generators.overlapping_solids` through
    :func:`~meshvis.eval.generators.soupify` (30 % of the faces flipped, shuffled,
    unwelded).  It is classified once; orientation, inside removal and layers reuse that
    classification, and each result is scored against the generator's truth (ambiguous
    faces left out).  The files are :data:`DEMO_FILES`: the input, the oriented model, the
    kept and removed faces, the layers (a per-face ``layer`` value in PLY), a preview of
    each and ``report.json``.

    Parameters
    ----------
    folder : str
        The output folder, created when missing; existing files of the same names are
        replaced.
    seed : int
        Seeds the soupification and the classification.
    size : int
        Width and height of the previews, in pixels.
    say : callable
        Receives one line of text per step (default :func:`print`).
    detail : callable, optional
        Receives the classification's summary (default: nowhere).

    Returns
    -------
    dict
        The summary also written to ``folder/report.json``: model, faces, seed, the share
        of the area oriented correctly, the share of faces whose removal agrees with the
        truth, the share of the area in the right layer, seconds and the classification
        report.

    Raises
    ------
    ParameterError
        ``seed`` is not an integer of at least 0, or ``size`` is not a picture size
        within ``MAX_PIXELS``; nothing is written.
    OSError
        ``folder`` cannot be created or written.

    Notes
    -----
    The files appear together when every step has succeeded; a failure (or Ctrl-C) leaves
    none of them, and no folder that the call created.
    """
    seed = _validate.seed(seed)
    _validate.image_size((size, size))
    made = not os.path.isdir(folder)
    os.makedirs(folder, exist_ok=True)
    try:
        with staged_outputs():
            return _run(folder, seed, size, say, detail)
    except BaseException:
        if made:
            with contextlib.suppress(OSError):
                os.rmdir(folder)  # only when empty
        raise


def _run(
    folder: str, seed: int, size: int, say: Callable[[str], None], detail: Callable[[str], None] | None
) -> dict:
    """:func:`run_demo` once its arguments are checked, inside one stage of outputs."""
    t0 = time.perf_counter()
    truth = soupify(overlapping_solids(), flip=0.3, seed=seed)
    soup = truth.soup
    soup.path = os.path.join(folder, "input.obj")
    save(soup, soup.path)
    say(
        f"bundled model: box and sphere passing through each other, as a soup of {soup.n_faces} faces, "
        f"30% flipped -> {soup.path}"
    )
    camera = Camera.fit(soup, azimuth=35, elevation=25, up=(0.0, 0.0, 1.0))
    shot = lambda s, name: save_png(render(s, camera, size=(size, size)).image, os.path.join(folder, name))  # noqa: E731
    shot(soup, "input.png")

    c = classify(soup, seed=seed)
    if detail is not None:
        detail(c.summary())
    ok = ~truth.ambiguous
    area = soup.areas

    o = orient(soup, classification=c)
    save(o.soup, os.path.join(folder, "oriented.obj"))
    shot(o.soup, "oriented.png")
    right = np.where(o.flipped, ~truth.outward, truth.outward) | truth.two_sided
    orient_acc = float((area * right * ok).sum() / (area * ok).sum())
    say(f"orient: flipped {int(o.flipped.sum())} faces; correct on {100 * orient_acc:.2f}% of the area")

    r = remove_interior(soup, classification=c, visibility="object")  # the cut, judged by its truth
    save(r.kept, os.path.join(folder, "exterior.obj"))
    save(r.removed, os.path.join(folder, "interior.obj"))
    shot(r.kept, "exterior.png")
    hidden = ~truth.outside.any(axis=1)
    removed_ok = float(((~r.keep) == hidden)[ok].mean())
    say(
        f"remove-interior: kept {int(r.keep.sum())}, removed {int((~r.keep).sum())}; "
        f"agrees with the truth on {100 * removed_ok:.2f}% of the faces"
    )

    lay = layers(soup, classification=c)
    save(soup, os.path.join(folder, "layers.ply"), face_values={"layer": lay.layer})
    save_png(render_layers(soup, lay.layer, camera, size=(size, size)), os.path.join(folder, "layers.png"))
    layer_acc = float((area * (lay.layer == truth.layer) * ok).sum() / (area * ok).sum())
    say(
        f"layers: {lay.n_layers} layers, faces per layer {lay.report(False)['faces_per_layer']}; "
        f"correct on {100 * layer_acc:.2f}% of the area"
    )

    summary = {
        "model": "overlapping box and sphere (meshvis.eval.generators.overlapping_solids, soupify flip=0.3)",
        "faces": soup.n_faces,
        "seed": seed,
        "orientation_correct_area": orient_acc,
        "removal_agreement_faces": removed_ok,
        "layer_correct_area": layer_acc,
        "seconds": time.perf_counter() - t0,
        "classification": c.report(per_face=False),
    }
    write_json(os.path.join(folder, "report.json"), summary)
    say(f"wrote {len(DEMO_FILES)} files to {folder}/ in {summary['seconds']:.1f} s")
    return summary
