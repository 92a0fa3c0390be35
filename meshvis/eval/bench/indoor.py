"""Orientation of indoor scenes toward a region of viewers (``orient --from``), checked by sight.

For each scene a box of ``--box`` times the diagonal at the centre of its bounding box is
the region of viewers (pass ``--region`` to choose one).  :func:`meshvis.orient_from` turns
every face toward the side seen from it; then an independent :func:`meshvis.visible_from`
with another seed looks at the *output* from the same region: the share of the area seen
through exactly one side whose seen side is the front is the measure (1 = every face a
viewer in the box sees shows its front).
"""

from __future__ import annotations

import argparse
import os
import time

import numpy as np

from meshvis.eval.bench.real_models import add_models_argument, models_folder

#: scenes meant to be seen from inside, relative to the parent of ``--models``
SCENES = ("real2/van_gogh_room.glb", "real2/pandora_level.obj")
#: half the side of the default viewer box, as a fraction of the scene's diagonal
BOX = 0.01


def centre_box(soup, fraction: float = BOX) -> str:
    """A ``box:`` region of half-side ``fraction`` x diagonal at the centre of the bounding box."""
    lo, hi = soup.bounds
    c, h = 0.5 * (lo + hi), fraction * soup.diagonal
    return "box:" + ",".join(f"{x:.6g}" for x in np.concatenate([c - h, c + h]))


def run_scene(path: str, region: str | None = None, seed: int = 0) -> dict:
    """Orient one scene toward ``region`` (default :func:`centre_box`) and check the output."""
    from meshvis.io import load
    from meshvis.repair.orient import orient_from
    from meshvis.visibility import visible_from

    soup = load(path)
    region = region or centre_box(soup)
    t = time.perf_counter()
    result = orient_from(soup, region, seed=seed)
    seconds = time.perf_counter() - t
    check = visible_from(result.soup, region, seed=seed + 1, per_side=True)
    seen = np.asarray(check.seen_side)
    one = seen[:, 0] ^ seen[:, 1]
    area = result.soup.areas
    return {
        "model": os.path.basename(path),
        "faces": int(soup.n_faces),
        "region": region,
        "seconds": seconds,
        "flipped": int(result.flipped.sum()),
        "seen_area": float(area[seen.any(axis=1)].sum() / area.sum()),
        "both_sides_seen_area": float(area[seen.all(axis=1)].sum() / area.sum()),
        "facing_the_viewers": float(area[one & seen[:, 0]].sum() / max(area[one].sum(), 1e-300)),
    }


def add_arguments(p: argparse.ArgumentParser) -> None:
    """Add the options of ``meshvis bench indoor`` to ``p``.

    Parameters
    ----------
    p : argparse.ArgumentParser
        The benchmark's sub-parser.
    """
    p.add_argument("scenes", nargs="*", help=f"scene files (default: {', '.join(SCENES)})")
    p.add_argument("--region", help="the viewers' region for every scene (default: a box at the centre)")
    p.add_argument("--seed", type=int, default=0)
    add_models_argument(p)


def main(args: argparse.Namespace) -> int:
    """CLI entry of ``meshvis bench indoor``."""
    base = os.path.dirname(os.path.abspath(models_folder(args.models_dir)))
    paths = args.scenes or [os.path.join(base, s) for s in SCENES]
    print(
        f"{'scene':<22} {'faces':>7} {'time':>6} {'flipped':>8} {'seen':>6} {'both':>6} {'facing':>9}  region"
    )
    for path in paths:
        r = run_scene(path, args.region, args.seed)
        print(
            f"{r['model'][:22]:<22} {r['faces']:>7} {r['seconds']:>5.1f}s {r['flipped']:>8} "
            f"{r['seen_area']:>6.1%} {r['both_sides_seen_area']:>6.2%} {r['facing_the_viewers']:>9.4%}  {r['region']}"
        )
    return 0
