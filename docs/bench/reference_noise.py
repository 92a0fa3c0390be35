"""How much of an orientation error is the reference's own: errors judged by the reference and by its recount.

For every model given (a path), the script loads the reference of DESIGN.md §10 (cached as
``CACHE/<stem>.seed0.npz``, the cache of ``meshvis bench orientation``) and recounts its
decisive faces with :func:`meshvis.eval.reference.confirm` (2,048 rays per face, each from
its own point; cached as ``CACHE/<stem>.confirm2048.npz``).  It then prints, per input
(the file as it is, and with ``--soup`` the soup of ``meshvis bench orientation``):

* how many decisive faces the recount finds not decisive, or decisive the other way, and
  their share of the decisive area;
* ``orient`` with each seed asked for, MeshLab's re-orientation and, with ``--libigl``,
  libigl's ``reorient_facets_raycast``: the error by the reference (the number of
  ``meshvis bench orientation``) and the error on the faces the recount confirms, by the
  side it finds.

Run from the repository root::

    python docs/bench/reference_noise.py ../shared/models/real2/van_gogh_room.glb --seeds 0,1,2,3 --cache /tmp/mvcache
"""

from __future__ import annotations

import argparse
import os
import time
import warnings

import numpy as np

from meshvis.eval.baselines import BASELINES
from meshvis.eval.bench.orientation import soup_of
from meshvis.eval.reference import CONFIRM_RAYS, confirm, reference
from meshvis.geometry.adjacency import weld
from meshvis.geometry.duplicates import opposite_copies
from meshvis.io import load
from meshvis.repair.orient import orient


def _errors(flipped, turned, judged, side, confirmed, confirmed_side, area) -> str:
    """'by the reference / on confirmed faces', in percent of each one's judged area."""
    front = np.asarray(flipped, bool) ^ turned
    by_ref = area[judged & (front != side)].sum() / area[judged].sum()
    by_recount = area[confirmed & (front != confirmed_side)].sum() / area[confirmed].sum()
    return f"{100 * by_ref:.4f} % / {100 * by_recount:.4f} %"


def main() -> None:
    """Parse the command line and print the table."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("models", nargs="+", help="model files")
    ap.add_argument("--seeds", default="0", help="comma-separated seeds of orient")
    ap.add_argument("--cache", default="/tmp/meshvis-refcache", help="folder of the cached references")
    ap.add_argument("--soup", action="store_true", help="also the soup input (unwelded, 30 %% turned)")
    ap.add_argument("--libigl", action="store_true", help="also libigl (minutes on large models)")
    args = ap.parse_args()
    seeds = [int(s) for s in args.seeds.split(",")]
    warnings.simplefilter("ignore")
    for path in args.models:
        stem = os.path.splitext(os.path.basename(path))[0]
        soup = load(path)
        ref = reference(soup, seed=0, cache=os.path.join(args.cache, f"{stem}.seed0.npz"))
        t = time.perf_counter()
        rec = confirm(soup, ref, cache=os.path.join(args.cache, f"{stem}.confirm{CONFIRM_RAYS}.npz"))
        confirmed, confirmed_side = rec.judged(soup.n_faces)
        area = ref.area
        print(f"{stem}: {len(rec.faces)} decisive faces, recount {time.perf_counter() - t:.1f} s")
        kinds = ["as is", "soup"] if args.soup else ["as is"]
        for kind in kinds:
            s, turned = (soup, np.zeros(soup.n_faces, bool)) if kind == "as is" else soup_of(soup, 0)
            pairs = opposite_copies(weld(s.vertices, s.faces)[1])
            judged = ref.decisive.copy()
            judged[pairs.ravel()] = False  # as the benchmark: double-sided pairs are left out
            ok = confirmed & judged
            side = ref.outside_side.astype(bool)
            flipped_side = ok & (confirmed_side.astype(bool) != side)
            share = 100 / area[judged].sum()
            print(
                f"  {kind}: the recount finds {int((judged & ~confirmed).sum())} of {int(judged.sum())} judged"
                f" faces not decisive ({share * area[judged & ~confirmed].sum():.4f} % of the judged area)"
                f" and {int(flipped_side.sum())} decisive the other way ({share * area[flipped_side].sum():.4f} %)"
            )
            cs = confirmed_side.astype(bool)
            print("    error by the reference / on the faces the recount confirms:")
            for seed in seeds:
                r = orient(s, seed=seed)
                print(f"    meshvis seed {seed:<3} {_errors(r.flipped, turned, judged, side, ok, cs, area)}")
            methods = ["pymeshlab_reorient"] + (["libigl_reorient"] if args.libigl else [])
            for method in methods:
                b = BASELINES[method]
                res = b.run(s, **b.fixed)
                text = _errors(res.values, turned, judged, side, ok, cs, area) if res.ok else res.message
                print(f"    {method:16} {text}")


if __name__ == "__main__":
    main()
