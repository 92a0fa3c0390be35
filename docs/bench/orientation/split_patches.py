"""How much of each method's error, judged by the reference, it saves by splitting patches.

Usage (from the repository root):
    python docs/bench/orientation/split_patches.py [STEM,...] [--seed 0] [--libigl]
        [--cache /tmp/meshvis-refcache]

For every real model as it is, runs meshvis ``orient`` and MeshLab's re-orientation (and
libigl's with ``--libigl``) and prints, per method:

* the error by the reference and on the faces the settled recount confirms, in % of the
  judged decisive area (as ``meshvis_only.py --confirm`` judges);
* the manifold edges whose faces disagree on the winding (after welding);
* ``split``: the faces of the input's consistently wound patches (edge-connected,
  orientable, several faces, every front on one side) that end up showing the side
  their patch shows less, by area, and their share of the judged decisive area;
* ``whole``: both errors once every such patch is made whole again, each showing the
  side most of its area shows;
* ``split faces``: of the split faces, how many the reference and the settled recount
  each find decisive on the side they were split to (``right``), decisive on the other
  side (``wrong``), or do not judge (``-``: not decisive, or a pair stored twice).

Item 3 of issue 14 lets a face leave such a patch only on decisive evidence of its own;
the ``whole`` column shows what a method's error is without the faces it turned away
from their patch.
"""

import argparse
import time

import numpy as np
from meshvis_only import errors, judged_faces, judges, model_files
from winding import inconsistent_edges

from meshvis.eval.baselines import libigl_reorient, pymeshlab_reorient
from meshvis.geometry.adjacency import edges, weld
from meshvis.graphcut.clusters import cluster_sides
from meshvis.io import load
from meshvis.repair.orient import orient

#: the inputs of ``meshvis bench orientation`` that some method splits patches of
DEFAULT_STEMS = (
    "pybullet__samurai_monastry",
    "pandora_level",
    "van_gogh_room",
    "dutch_ship",
    "zdm2_level",
    "mannequiny",
    "ferrari348_lowpoly",
)


def wound_patches(faces: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The input's consistently wound patches.

    Returns ``patch``, (m,) int64, the patch of each face (-1: none, or a patch of one face
    or wound either way), and ``front``, (m,) int64, the side node of each face's front.
    """
    table = edges(faces)
    cl = cluster_sides(table, np.ones(len(faces), bool))
    patch, front = cl.cluster.copy(), cl.side_node[:, 0]
    ok = patch >= 0
    n = max(cl.n_clusters, 1)
    lo = np.full(n, np.iinfo(np.int64).max)
    hi = np.full(n, -1)
    np.minimum.at(lo, patch[ok], front[ok])
    np.maximum.at(hi, patch[ok], front[ok])
    size = np.bincount(patch[ok], minlength=n)
    at = np.maximum(patch, 0)
    patch[~(ok & (lo[at] == hi[at]) & (size[at] > 1))] = -1
    return patch, front


def made_whole(turned: np.ndarray, patch: np.ndarray, area: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``turned`` with every wound patch turned as its area's majority; and the faces that moved.

    In a consistently wound patch every face shows the same side exactly when every face
    has the same ``turned``.
    """
    ok = patch >= 0
    n = int(patch.max()) + 1 if ok.any() else 1
    turned_area = np.bincount(patch[ok], area[ok] * turned[ok], n)
    total = np.bincount(patch[ok], area[ok], n)
    majority = turned_area > 0.5 * total
    whole = turned.copy()
    whole[ok] = majority[patch[ok]]
    return whole, whole != turned


def main() -> None:
    """Print one line per model and method."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("stems", nargs="?", default=",".join(DEFAULT_STEMS))
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--libigl", action="store_true", help="also run libigl's reorientation (slow)")
    ap.add_argument("--cache", default="/tmp/meshvis-refcache")
    args = ap.parse_args()
    files = model_files()
    methods = {
        "meshvis": lambda s: np.asarray(orient(s, seed=args.seed).flipped, bool),
        "MeshLab": lambda s: np.asarray(pymeshlab_reorient(s).values, bool),
    }
    if args.libigl:
        methods["libigl"] = lambda s: np.asarray(libigl_reorient(s).values, bool)
    print(
        f"{'model':28} {'method':8} {'ref %':>8} {'conf %':>8} {'edges':>6} "
        f"{'split':>6} {'split %':>8} {'whole ref %':>11} {'whole conf %':>12} {'s':>6}  "
        f"{'split by ref':>14} {'split by conf':>14}"
    )
    for stem in args.stems.split(","):
        soup = load(files[stem])
        ref, sides = judges(stem, soup, args.cache, recount=True)
        judged = judged_faces(soup)
        faces = weld(soup.vertices, soup.faces)[1]
        patch, _ = wound_patches(faces)
        decisive_area = ref.area[judged & ref.decisive].sum()
        print(
            f"{stem:28} {'input':8} "
            + " ".join(f"{e:8.4f}" for e in errors(np.zeros(soup.n_faces, bool), ref, sides, judged))
            + f" {inconsistent_edges(faces, np.zeros(soup.n_faces, bool)):6d}",
            flush=True,
        )
        for name, run in methods.items():
            t = time.perf_counter()
            turned = run(soup)
            seconds = time.perf_counter() - t
            whole, moved = made_whole(turned, patch, ref.area)
            split_area = 100 * ref.area[moved & judged & ref.decisive].sum() / max(decisive_area, 1e-300)
            e, w = errors(turned, ref, sides, judged), errors(whole, ref, sides, judged)
            verdicts = []
            for decisive, side in sides:
                d = moved & judged & decisive
                right, wrong = d & (turned == side.astype(bool)), d & (turned != side.astype(bool))
                verdicts.append(f"{int(right.sum())}/{int(wrong.sum())}/{int((moved & ~d).sum())}")
            print(
                f"{stem:28} {name:8} {e[0]:8.4f} {e[1]:8.4f} {inconsistent_edges(faces, turned):6d} "
                f"{int(moved.sum()):6d} {split_area:8.4f} {w[0]:11.4f} {w[1]:12.4f} {seconds:6.2f}  "
                f"{verdicts[0]:>14} {verdicts[1]:>14}",
                flush=True,
            )


if __name__ == "__main__":
    main()
