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
``pandora_rare.png``: the pandora level with its lone faces whose rays barely escaped
left to the capped round of 2,048 rays (largest first) that flagged and two-sided faces
share (left: the rule before, where lone one-sided faces got no more rays) and given the
doubling rounds of ``meshvis.repair.evidence.until_decisive`` (right).
``van_gogh_near_line.png``: the van Gogh room with faces near the 4x line decided on their
first rays (left: ``meshvis.repair.evidence.until_settled`` off) and settled (right), at
the largest face the rounds turn to the side the settled recount of
``meshvis.eval.reference.confirm`` finds; red = faces that recount finds turned away.
``van_gogh_soup_pooled.png``: the van Gogh room as a soup (seed 0) with only its
consistently wound patches given the side their faces' rays see, pooled (left: the rule
before) and every open patch of several faces (right), at the largest face that the
pooled side turns to the side the settled recount finds; red as above.
``van_gogh_split.png``: the van Gogh room as it is, oriented by meshvis (left) and by
MeshLab (right), seen along a free line of sight to the front of face 11036; red = faces
turned away from the side their consistently wound patch (in the file) shows, by area
(``docs/bench/orientation/split_patches.py``).

    python docs/img/orientation/pictures.py        (writes docs/img/orientation/*.png)
    python docs/img/orientation/pictures.py lone   (only pandora_lone.png)
    python docs/img/orientation/pictures.py rare   (only pandora_rare.png)
    python docs/img/orientation/pictures.py near   (only van_gogh_near_line.png)
    python docs/img/orientation/pictures.py pooled (only van_gogh_soup_pooled.png)
    python docs/img/orientation/pictures.py split  (only van_gogh_split.png)
"""

import os
import sys

import numpy as np

from meshvis.eval.reference import reference
from meshvis.io import load
from meshvis.rays.camera import Camera
from meshvis.rays.render import render, save_png
from meshvis.repair import evidence
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
VAN_GOGH = "real2/van_gogh_room.glb"


def two_steps(soup, c):
    """The faces that steps 1-2 of ``meshvis.repair.orient`` alone turn over."""
    status, outer = O._own_sides(c, "keep")
    O._hidden_sides(c, O.patches(c), status, outer, "layer")
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
    rare_faces(root)
    near_line(root)
    pooled(root)


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
    _level_from_outside(ref, before, after, ("held", "free"), "pandora_lone.png")


def rare_faces(root=SHARED):
    """``pandora_rare.png``: lone faces that barely escaped in the shared capped round (left) or in rounds."""
    labels = ("lone faces in the shared round", "lone faces in rounds")
    soup = load(os.path.join(root, PANDORA))
    ref = reference(soup, seed=0, cache=os.path.join(CACHE, "pandora_level.seed0.npz"))
    after = O.orient(soup, seed=0)
    # the code before: one round of LAST_RAYS for every such face, lone or not, under one
    # cap; the non-lone ones are cast with the lone ones, in the order of their positions
    more, until = evidence.more_rays, evidence.until_decisive
    held = []

    def non_lone_later(soup_, caster, faces, escaped, cast, which, rays, share, rng):
        if share == O.UNSEEN_SHARE and not held:
            held.append(np.asarray(which))
            return np.zeros(0, np.int64)  # reached none (the later rounds are left out below)
        return more(soup_, caster, faces, escaped, cast, which, rays, share, rng)

    def together(soup_, caster, faces, escaped, cast, which, shown, rng, share=None):
        if share is not None:
            return None  # the rounds for the faces the capped round misses came later
        # of the lone faces, only those that only their own rays decide joined the round
        which = np.asarray(which, np.int64)
        own = after.classification.flagged | np.isin(after.status, (O.TWO_SIDED, O.CONFLICT))
        joint = np.sort(np.concatenate([held.pop(), which[own[faces[which]]]]))
        more(soup_, caster, faces, escaped, cast, joint, evidence.LAST_RAYS, O.UNSEEN_SHARE, rng)

    try:
        evidence.more_rays, evidence.until_decisive = non_lone_later, together
        before = O.orient(soup, classification=after.classification)
    finally:
        evidence.more_rays, evidence.until_decisive = more, until
    total = soup.areas[ref.decisive].sum()
    for label, r in zip(labels, (before, after)):
        wrong = ref.decisive & (r.flipped.astype(np.int8) != ref.outside_side)
        print(f"pandora_level, {label}: {100 * soup.areas[wrong].sum() / total:.4f} % turned away")
    # the largest face the rounds turn to the side the reference sees, from outside along
    # a free line of sight to it
    fixed = ref.decisive & (before.flipped.astype(np.int8) != ref.outside_side)
    fixed &= after.flipped.astype(np.int8) == ref.outside_side
    f = int(np.flatnonzero(fixed)[np.argmax(soup.areas[fixed])])
    cam = _seen_view(soup, f, int(ref.outside_side[f]))
    away = [ref.decisive & (r.flipped.astype(np.int8) != ref.outside_side) for r in (before, after)]
    counts = _marked((before, after), away, "pandora_rare.png", cam)
    print(
        f"pandora_rare.png: face {f}, reference escapes {ref.escaped[f].tolist()}; (pixels of faces"
        " turned away, back-side pixels), shared round / rounds:",
        *counts,
    )


def near_line(root=SHARED):
    """``van_gogh_near_line.png``: faces near the 4x line decided on their first rays (left) or settled."""
    soup = load(os.path.join(root, VAN_GOGH))
    after = O.orient(soup, seed=0)
    settle = evidence.until_settled
    try:
        evidence.until_settled = lambda *args: None  # the rule before: no rounds
        before = O.orient(soup, classification=after.classification)
    finally:
        evidence.until_settled = settle
    _van_gogh_pair(
        soup, before, after, np.zeros(soup.n_faces, bool), ("first rays", "settled"), "van_gogh_near_line.png"
    )


def pooled(root=SHARED):
    """``van_gogh_soup_pooled.png``: only consistently wound patches pooled (left), or every patch of several faces."""
    from meshvis.eval.bench.orientation import soup_of

    soup = load(os.path.join(root, VAN_GOGH))
    s, turned = soup_of(soup, 0)
    after = O.orient(s, seed=0)
    pool = O._pooled_patches

    def wound_only(c, p, *args):
        # the rule before: a patch the input winds either way counts as faces of their own
        size = np.where(O._consistently_wound(p), p.size, 1)
        return pool(c, O.Patches(p.clustering, p.closed, size), *args)

    try:
        O._pooled_patches = wound_only
        before = O.orient(s, classification=after.classification)
    finally:
        O._pooled_patches = pool
    labels = ("wound patches pooled", "every patch pooled")
    _van_gogh_pair(soup, before, after, turned, labels, "van_gogh_soup_pooled.png")


def split(root=SHARED):
    """``van_gogh_split.png``: the faces meshvis (left) and MeshLab (right) turn away from their patch."""
    from types import SimpleNamespace

    from meshvis.eval.baselines import pymeshlab_reorient
    from meshvis.geometry.adjacency import weld

    sys.path.insert(0, os.path.join(HERE, "..", "..", "bench", "orientation"))
    import split_patches as sp  # the script of docs/benchmarks.md, "Which faces leave their patch"

    soup = load(os.path.join(root, VAN_GOGH))
    patch, _ = sp.wound_patches(weld(soup.vertices, soup.faces)[1])
    ours = O.orient(soup, seed=0)
    theirs = pymeshlab_reorient(soup).values.astype(bool)
    flipped = (np.asarray(ours.flipped, bool), theirs)
    results = (ours, SimpleNamespace(soup=soup.flipped(theirs)))  # _marked draws r.soup
    away = [sp.made_whole(f, patch, soup.areas)[1] for f in flipped]
    near = _seen_view(soup, 11036, 0)
    # twice as far and a wider angle than the close view: both 134-face patches in sight
    target = np.asarray(near.target, float)
    eye = target + 2.0 * (np.asarray(near.position, float) - target)
    camera = Camera(eye, target, up=(0.0, 0.0, 1.0), fov=30.0)
    counts = _marked(results, away, "van_gogh_split.png", camera)
    print(
        "van_gogh_split.png: faces turned away from their consistently wound patch,",
        "meshvis / MeshLab:",
        *(int(a.sum()) for a in away),
        "; (pixels of them, back-side pixels):",
        *counts,
    )


def _van_gogh_pair(soup, before, after, turned, labels, png):
    """Draw ``before`` and ``after`` of the van Gogh room judged by the settled recount, as ``png``.

    ``turned``: (m,) bool, the faces the input turned over relative to the file.  The view
    is along a free line of sight to the largest face ``after`` turns to the side the
    recount finds and ``before`` does not; prints both errors and the pixel counts.
    """
    from meshvis.eval.reference import confirm

    ref = reference(soup, seed=0, cache=os.path.join(CACHE, "van_gogh_room.seed0.npz"))
    recount = confirm(soup, ref, cache=os.path.join(CACHE, "van_gogh_room.confirm2048.npz"))
    decisive, side = recount.judged(soup.n_faces)
    away = [decisive & ((r.flipped ^ turned).astype(np.int8) != side) for r in (before, after)]
    total = soup.areas[decisive].sum()
    for label, wrong in zip(labels, away):
        print(f"van_gogh_room, {label}: {100 * soup.areas[wrong].sum() / total:.4f} % turned away (recount)")
    fixed = away[0] & ~away[1]
    f = int(np.flatnonzero(fixed)[np.argmax(soup.areas[fixed])])
    counts = _marked((before, after), away, png, _seen_view(soup, f, int(side[f])))
    print(
        f"{png}: face {f}; (pixels of faces turned away, back-side pixels),",
        " / ".join(labels) + ":",
        *counts,
    )


def _marked(results, away, png, camera=None, **view_kw):
    """Render each result (``camera``, or ``render``'s view keywords) with its faces in ``away`` red.

    Saves them side by side as ``png``; returns (red pixels, back-side pixels) per result.
    """
    panels, counts = [], []
    for r, wrong in zip(results, away):
        view = render(r.soup, camera, size=(400, 300), **view_kw)
        image, hit = view.image.copy(), view.face >= 0
        mask = np.zeros(hit.shape, bool)
        mask[hit] = wrong[view.face[hit]]
        image[mask] = (215, 25, 40)
        panels.append(image)
        counts.append((int(mask.sum()), int((view.side == 1).sum())))
    gap = np.full((300, 8, 3), 255, np.uint8)
    save_png(np.concatenate([panels[0], gap, panels[1]], axis=1), os.path.join(HERE, png))
    return counts


def _seen_view(soup, f, side):
    """A camera outside along the free line of sight to face ``f``'s ``side`` nearest its normal."""
    from meshvis.rays.caster import RayCaster
    from meshvis.rays.samples import uniform_sphere

    normal = soup.normals[f] * (1.0 if side == 0 else -1.0)
    d = uniform_sphere(1 << 14, np.random.default_rng(0))
    d = d[d @ normal > 0]
    centre = soup.triangles[f].mean(axis=0)
    origin = np.repeat(centre[None], len(d), axis=0)
    free = (
        RayCaster(soup).intersect_from_surface(origin, np.full(len(d), f), np.full(len(d), side), d).face < 0
    )
    best = d[free][np.argmax(d[free] @ normal)]
    return Camera(centre + best * 0.2 * soup.diagonal, centre, up=(0.0, 0.0, 1.0), fov=12.0)


def _level_from_outside(ref, before, after, names, png):
    """Save the level from outside, before (left) and after (right), as ``png``.

    Faces the reference judges and a result turns away from the side that escapes are
    red; the view is the one of eight directions that shows most of them before (a close
    view of one face looks at a wall in front of it).
    """
    wrong = {
        label: ref.decisive & (r.flipped.astype(np.int8) != ref.outside_side)
        for label, r in zip(names, (before, after))
    }
    views = [(az, el) for az in (45.0, 135.0, 225.0, 315.0) for el in (30.0, -30.0)]
    red = []
    for az, el in views:
        face = render(before.soup, azimuth=az, elevation=el, size=(200, 150)).face
        red.append(int(wrong[names[0]][face[face >= 0]].sum()))
    az, el = views[int(np.argmax(red))]
    counts = _marked((before, after), [wrong[n] for n in names], png, azimuth=az, elevation=el)
    print(
        f"{png}, azimuth {az:g}, elevation {el:g}: (pixels of faces turned away, back-side pixels),",
        " / ".join(names),
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
    elif sys.argv[1:2] == ["rare"]:
        rare_faces(*sys.argv[2:])
    elif sys.argv[1:2] == ["near"]:
        near_line(*sys.argv[2:])
    elif sys.argv[1:2] == ["pooled"]:
        pooled(*sys.argv[2:])
    elif sys.argv[1:2] == ["split"]:
        split(*sys.argv[2:])
    else:
        main(*sys.argv[1:])
