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
``pandora_lone.png``: the pandora level with a patch of one face counted as consistently
wound (left: such a face seen from both sides keeps its winding unless 4x evidence turns
it) and as ``orient`` returns it (right), at the largest decisive face that the left one
turns away.

    python docs/img/orientation/pictures.py        (writes docs/img/orientation/*.png)
    python docs/img/orientation/pictures.py lone   (only pandora_lone.png)
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
PANDORA = "real2/pandora_level.obj"


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
    lone_faces(root)


def _before_after(root, rel, name, value, labels):
    """The model, its reference, ``orient`` with ``O.<name>`` set to ``value`` and as it is.

    Prints the decisive area each of the two turns away, under ``labels`` (before, after).
    """
    soup = load(os.path.join(root, rel))
    stem = os.path.splitext(os.path.basename(rel))[0]
    ref = reference(soup, seed=0, cache=os.path.join(CACHE, f"{stem}.seed0.npz"))
    after = O.orient(soup, seed=0)
    rule = getattr(O, name)
    try:
        setattr(O, name, value)
        before = O.orient(soup, classification=after.classification)
    finally:
        setattr(O, name, rule)
    total = soup.areas[ref.decisive].sum()
    for label, r in zip(labels, (before, after)):
        wrong = ref.decisive & (r.flipped.astype(np.int8) != ref.outside_side)
        print(f"{stem}, {label}: {100 * soup.areas[wrong].sum() / total:.4f} % turned away")
    return soup, ref, before, after


def _wound_with_lone_faces(p):
    """``orient._consistently_wound`` as it was: a one-face patch counts as consistently wound."""
    patch, front = p.clustering.cluster, p.clustering.side_node[:, 0]
    ok = patch >= 0
    n = max(p.clustering.n_clusters, 1)
    lo, hi = np.full(n, np.iinfo(np.int64).max), np.full(n, -1)
    np.minimum.at(lo, patch[ok], front[ok])
    np.maximum.at(hi, patch[ok], front[ok])
    return ok & (lo[np.maximum(patch, 0)] == hi[np.maximum(patch, 0)])


def lone_faces(root=SHARED):
    """``pandora_lone.png``: one-face patches held to their winding (left) and not (right)."""
    labels = ("lone faces held", "lone faces free")
    soup, ref, before, after = _before_after(
        root, PANDORA, "_consistently_wound", _wound_with_lone_faces, labels
    )
    # the level from outside, faces the reference judges and the rule turns away from the
    # side that escapes in red, from the direction of the eight that shows most of them
    # held to their winding (a close view of one face looks at a wall in front of it)
    wrong = {
        label: ref.decisive & (r.flipped.astype(np.int8) != ref.outside_side)
        for label, r in (("held", before), ("free", after))
    }
    views = [(az, el) for az in (45.0, 135.0, 225.0, 315.0) for el in (30.0, -30.0)]
    red = []
    for az, el in views:
        face = render(before.soup, azimuth=az, elevation=el, size=(200, 150)).face
        red.append(int(wrong["held"][face[face >= 0]].sum()))
    az, el = views[int(np.argmax(red))]
    panels, counts = [], []
    for label, r in (("held", before), ("free", after)):
        view = render(r.soup, azimuth=az, elevation=el, size=(400, 300))
        image, hit = view.image.copy(), view.face >= 0
        mask = np.zeros(hit.shape, bool)
        mask[hit] = wrong[label][view.face[hit]]
        image[mask] = (215, 25, 40)
        panels.append(image)
        counts.append((int(mask.sum()), int((view.side == 1).sum())))
    gap = np.full((300, 8, 3), 255, np.uint8)
    save_png(np.concatenate([panels[0], gap, panels[1]], axis=1), os.path.join(HERE, "pandora_lone.png"))
    print(
        f"pandora lone faces, azimuth {az:g}, elevation {el:g}: (pixels of faces turned away, back-side pixels), held / free:",
        *counts,
    )


def crossing(root=SHARED):
    """``monastery_crossing.png``: the sign test on flagged faces off (left) and on."""
    labels = ("sign test off", "sign test on")
    soup, ref, before, after = _before_after(root, MODELS["monastery"], "CROSSING_LEVEL", 0.0, labels)
    wrong = np.flatnonzero(ref.decisive & (before.flipped.astype(np.int8) != ref.outside_side))
    f = wrong[np.argmax(soup.areas[wrong])]
    n = picture(
        before.soup, after.soup, close_view(soup, ref, f), os.path.join(HERE, "monastery_crossing.png")
    )
    print("monastery crossing: face", f, "escapes", ref.escaped[f], "back-side pixels, off / on:", *n)


if __name__ == "__main__":
    if sys.argv[1:2] == ["lone"]:
        lone_faces(*sys.argv[2:])
    else:
        main(*sys.argv[1:])
