"""Error against time of ``orient`` over its classification budget, seed by seed, in one process.

For one model (a path), as it is and as the soup of ``meshvis bench orientation``, it runs
``orient`` with the default budget, with ``rays_per_node`` 16 and 8, and with a looser
``tolerance`` of the progressive rounds, each with seeds 0-3, and prints the wall time and
the error by the reference / on the faces its recount confirms (as
``docs/bench/reference_noise.py``, whose judging it uses; the references are read from
its cache).  Run from the repository root::

    python docs/bench/orient_budget.py ../shared/models/real2/van_gogh_room.glb --cache /tmp/mvcache

(docs/benchmarks.md, "What 5x libigl costs on the van Gogh room").
"""

from __future__ import annotations

import argparse
import os
import sys
import time
import warnings

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from reference_noise import (  # noqa: E402 - the judging of the script beside this one
    CONFIRM_RAYS,
    _errors,
    confirm,
    load,
    opposite_copies,
    orient,
    reference,
    soup_of,
    weld,
)

#: the budgets compared, as keywords of ``orient`` (the first is the default)
BUDGETS = ({}, {"rays_per_node": 16}, {"rays_per_node": 8}, {"tolerance": 0.003})


def main() -> None:
    """Print one line per input, budget and seed."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("model", help="model file")
    ap.add_argument("--cache", default="/tmp/meshvis-refcache", help="folder of the cached references")
    args = ap.parse_args()
    warnings.simplefilter("ignore")
    stem = os.path.splitext(os.path.basename(args.model))[0]
    soup = load(args.model)
    ref = reference(soup, seed=0, cache=os.path.join(args.cache, f"{stem}.seed0.npz"))
    rec = confirm(soup, ref, cache=os.path.join(args.cache, f"{stem}.confirm{CONFIRM_RAYS}.npz"))
    confirmed, confirmed_side = rec.judged(soup.n_faces)
    for kind in ("as is", "soup"):
        s, turned = (soup, np.zeros(soup.n_faces, bool)) if kind == "as is" else soup_of(soup, 0)
        judged = ref.decisive.copy()
        judged[opposite_copies(weld(s.vertices, s.faces)[1]).ravel()] = False
        side = ref.outside_side.astype(bool)
        orient(s, seed=0)  # compiled kernels and caches warm before the first timing
        for budget in BUDGETS:
            for seed in range(4):
                t = time.perf_counter()
                r = orient(s, seed=seed, **budget)
                seconds = time.perf_counter() - t
                errors = _errors(
                    r.flipped, turned, judged, side, confirmed & judged, confirmed_side.astype(bool), ref.area
                )
                print(
                    f"{kind:6} {str(budget or 'default'):24} seed {seed}  {seconds:.3f} s  {errors}",
                    flush=True,
                )


if __name__ == "__main__":
    main()
