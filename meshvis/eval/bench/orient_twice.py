"""Orient twice on the shared models, and the back-facing pixels of a scene seen from above.

``meshvis bench orient-twice [MODEL ...] [--models DIR] [--seed S] [--elevations 20,60]``
orients each model (default: every file of ``real/``, ``real2/`` and ``ai/`` beside
``--models``), then orients the output again, and prints per model the faces the first
run turns, the faces the second run turns (0: ``orient`` is idempotent) and the time of
each run.  For the models standing on the ground (:data:`GROUNDED`: the monastery, y up)
it also renders the input and the output from each elevation above the horizon and
prints the share of the model's pixels that show a back side (``meshvis render
--color-by side`` shows them orange).
"""

from __future__ import annotations

import argparse
import os
import time
from pathlib import Path

from meshvis.eval.bench.real_models import add_models_argument, models_folder

#: models that stand on the ground, with their up axis: seen from above, their input shows
#: (almost) no back sides
GROUNDED = {"pybullet__samurai_monastry.obj": (0.0, 1.0, 0.0)}
#: the shared model folders, beside the folder of ``--models``
FOLDERS = ("real", "real2", "ai")
#: picture size of the back-facing share
SIZE = (512, 512)


def back_facing(model, elevation: float, up) -> float:
    """Share of the model's pixels that show a back side, seen from ``elevation`` degrees.

    Parameters
    ----------
    model : Soup or anything :func:`meshvis.render` accepts
    elevation : float, degrees above the horizon (azimuth 30, the render default)
    up : (3,) float, the model's up axis

    Returns
    -------
    float, back-facing pixels over the model's pixels
    """
    from meshvis.rays.render import render

    r = render(model, size=SIZE, elevation=elevation, up=up)
    hit = r.face >= 0
    return float((r.side[hit] == 1).mean()) if hit.any() else 0.0


def run_model(path: str, seed: int = 0, elevations: tuple[float, ...] = (20.0, 60.0)) -> dict:
    """Orient one model twice; the back-facing shares where the model is grounded.

    Returns
    -------
    dict with ``model``, ``faces``, ``turned_once``, ``turned_twice``, ``seconds_once``,
    ``seconds_twice`` and, for a grounded model, ``back_facing``: elevation -> (input,
    output) shares
    """
    from meshvis.io import load
    from meshvis.repair.orient import orient

    soup = load(path)
    t = time.perf_counter()
    once = orient(soup, seed=seed)
    t_once = time.perf_counter() - t
    t = time.perf_counter()
    twice = orient(once.soup, seed=seed)
    t_twice = time.perf_counter() - t
    out = {
        "model": os.path.basename(path),
        "faces": soup.n_faces,
        "turned_once": int(once.flipped.sum()),
        "turned_twice": int(twice.flipped.sum()),
        "seconds_once": t_once,
        "seconds_twice": t_twice,
    }
    up = GROUNDED.get(os.path.basename(path))
    if up is not None:
        out["back_facing"] = {
            e: (back_facing(soup, e, up), back_facing(once.soup, e, up)) for e in elevations
        }
    return out


def add_arguments(p: argparse.ArgumentParser) -> None:
    """Add the options of ``meshvis bench orient-twice`` to ``p``.

    Parameters
    ----------
    p : argparse.ArgumentParser
        The benchmark's sub-parser.
    """
    p.add_argument(
        "model_files", nargs="*", metavar="MODEL", help="model files (default: every shared model)"
    )
    p.add_argument("--seed", type=int, default=0, help="seed of orient (default 0)")
    p.add_argument("--elevations", default="20,60", help="degrees above the horizon (default 20,60)")
    add_models_argument(p)


def main(args: argparse.Namespace) -> int:
    """CLI entry of ``meshvis bench orient-twice``: one line per model, then the grounded models' pixels."""
    paths = args.model_files
    if not paths:
        root = models_folder(args.models_dir).parent
        paths = sorted(
            os.fspath(f)
            for d in FOLDERS
            if (root / d).is_dir()
            for f in Path(root / d).iterdir()
            if f.suffix.lower() != ".md"
        )
    elevations = tuple(float(e) for e in args.elevations.split(","))
    print(f"load {os.getloadavg()[0]:.2f}")
    print(f"{'model':<34} {'faces':>8} {'turned':>7} {'again':>6} {'once':>7} {'twice':>7}")
    grounded, total = [], 0.0
    for path in paths:
        r = run_model(path, args.seed, elevations)
        total += r["seconds_once"] + r["seconds_twice"]
        print(
            f"{r['model'][:34]:<34} {r['faces']:>8} {r['turned_once']:>7} {r['turned_twice']:>6} "
            f"{r['seconds_once']:>6.2f}s {r['seconds_twice']:>6.2f}s",
            flush=True,
        )
        if "back_facing" in r:
            grounded.append(r)
    print(f"{len(paths)} models, orient twice in {total:.0f} s; load {os.getloadavg()[0]:.2f}")
    for r in grounded:
        for e, (before, after) in r["back_facing"].items():
            print(
                f"{r['model']}: from {e:g} degrees, back-facing pixels {before:.2%} before, {after:.2%} after"
            )
    return 0
