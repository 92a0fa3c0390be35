"""Pictures of docs/benchmarks.md, "Orientation on real scenes".

Where the cut and layer votes alone (steps 1-2 of meshvis.repair.orient) turn visible faces away from the viewer,
and the same view after all four steps: a close view of the largest face the reference
(meshvis.eval.reference, cached in /tmp/meshvis-refcache) sees decisively from one side
and the two steps turn away from it.  Orange = a back side seen, i.e. a face turned
away from this viewer.  ``<name>_left.png``: the same for the largest decisive face that
all four steps still turn away from the side the reference sees (what is left).
``monastery_crossing.png``: the monastery with its flagged faces kept to their consistently
wound patch unless 4x evidence turns them (``CROSSING_LEVEL = 0``, left) and as ``orient``
returns it (right), at the largest decisive face that the left one turns away.

    python docs/img/orientation/pictures.py   (writes docs/img/orientation/*.png)
"""

import os
import sys

import numpy as np

from meshvis.eval.reference import reference
from meshvis.io import load
from meshvis.rays.camera import Camera
from meshvis.rays.render import render, save_png
from meshvis.repair import orient as O

CACHE = "/tmp/meshvis-refcache"
HERE = os.path.dirname(os.path.abspath(__file__))
SHARED = os.path.join(HERE, "..", "..", "..", "..", "shared", "models")
MODELS = {
    "monastery": "real/pybullet__samurai_monastry.obj",
    "mannequiny": "real2/mannequiny.glb",
    "ferrari": "real2/ferrari348_lowpoly.glb",
}


def two_steps(soup, c):
    """The faces that steps 1-2 of ``meshvis.repair.orient`` alone turn over."""
    status, outer = O._own_sides(c, "keep")
    O._hidden_sides(c, status, outer, "layer")
    flip = outer == 1
    flip[(status == O.TWO_SIDED) | (status == O.DEGENERATE)] = False
    return flip


def close_view(soup, ref, f):
    """A camera 0.12 diagonals off face ``f``, on the side that the reference sees escape."""
    centre = soup.triangles[f].mean(axis=0)
    normal = soup.normals[f] * (1.0 if ref.outside_side[f] == 0 else -1.0)
    return Camera(centre + normal * 0.12 * soup.diagonal, centre, up=(0.0, 1.0, 0.0), fov=50.0)


def picture(before, after, cam, path):
    """Both models from ``cam``, side by side; back-side pixels of each."""
    ra, rb = render(before, cam, size=(400, 300)), render(after, cam, size=(400, 300))
    gap = np.full((300, 8, 3), 255, np.uint8)
    save_png(np.concatenate([ra.image, gap, rb.image], axis=1), path)
    return int((ra.side == 1).sum()), int((rb.side == 1).sum())


def main(root=SHARED):
    """Write the pictures of every model in ``MODELS`` (read from ``root``)."""
    for name, rel in MODELS.items():
        soup = load(os.path.join(root, rel))
        r = O.orient(soup, seed=0)
        before = soup.flipped(two_steps(soup, r.classification))
        after = r.soup
        # the worst region: the largest visible face (decisive in the reference) that the two
        # steps leave facing away from its viewers, seen from the side that escapes
        stem = os.path.splitext(os.path.basename(rel))[0]
        ref = reference(soup, seed=0, cache=os.path.join(CACHE, f"{stem}.seed0.npz"))
        two = two_steps(soup, r.classification)
        wrong = np.flatnonzero(ref.decisive & (two.astype(np.int8) != ref.outside_side))
        f = wrong[np.argmax(soup.areas[wrong])]
        n = picture(before, after, close_view(soup, ref, f), os.path.join(HERE, f"{name}.png"))
        print(name, f"face {f}: back-side pixels, two steps / all four:", *n)
        left = np.flatnonzero(ref.decisive & (r.flipped.astype(np.int8) != ref.outside_side))
        if len(left):
            g = left[np.argmax(soup.areas[left])]
            n = picture(before, after, close_view(soup, ref, g), os.path.join(HERE, f"{name}_left.png"))
            share = soup.areas[g] / soup.areas[ref.decisive].sum()
            print(
                name,
                f"left: face {g} ({100 * share:.3f} % of the decisive area), escapes",
                ref.escaped[g],
                "back-side pixels:",
                *n,
            )
    crossing(root)


def crossing(root=SHARED):
    """``monastery_crossing.png``: the sign test on flagged faces off (left) and on."""
    rel = MODELS["monastery"]
    soup = load(os.path.join(root, rel))
    stem = os.path.splitext(os.path.basename(rel))[0]
    ref = reference(soup, seed=0, cache=os.path.join(CACHE, f"{stem}.seed0.npz"))
    after = O.orient(soup, seed=0)
    level = O.CROSSING_LEVEL
    try:
        O.CROSSING_LEVEL = 0.0
        before = O.orient(soup, classification=after.classification)
    finally:
        O.CROSSING_LEVEL = level
    total = soup.areas[ref.decisive].sum()
    for label, r in (("off", before), ("on", after)):
        wrong = ref.decisive & (r.flipped.astype(np.int8) != ref.outside_side)
        print(f"monastery, sign test {label}: {100 * soup.areas[wrong].sum() / total:.4f} % turned away")
    wrong = np.flatnonzero(ref.decisive & (before.flipped.astype(np.int8) != ref.outside_side))
    f = wrong[np.argmax(soup.areas[wrong])]
    n = picture(before.soup, after.soup, close_view(soup, ref, f), os.path.join(HERE, "monastery_crossing.png"))
    print("monastery crossing: face", f, "escapes", ref.escaped[f], "back-side pixels, off / on:", *n)


if __name__ == "__main__":
    main(*sys.argv[1:])
