"""meshvis alone on the inputs of `meshvis bench orientation`, judged the same way.

Usage (from the repository root; references from the cache of the benchmark):
    python docs/bench/orientation/meshvis_only.py STEM[,STEM...] ["as is"|soup[,...]]
"""

import os
import sys
import time

import numpy as np

from meshvis.eval.bench.orientation import soup_of
from meshvis.eval.reference import reference
from meshvis.geometry.adjacency import weld
from meshvis.geometry.duplicates import opposite_copies
from meshvis.io import load
from meshvis.repair.orient import orient

R = ["../shared/models/real", "../shared/models/real2"]
kinds = sys.argv[2].split(",") if len(sys.argv) > 2 else ["as is", "soup"]
for name in sys.argv[1].split(","):
    path = next(os.path.join(d, f) for d in R for f in os.listdir(d) if os.path.splitext(f)[0] == name)
    soup = load(path)
    ref = reference(soup, seed=0, cache=f"/tmp/meshvis-refcache/{name}.seed0.npz")
    for kind in kinds:
        s, turned = (soup, np.zeros(soup.n_faces, bool)) if kind == "as is" else soup_of(soup, 0)
        pairs = opposite_copies(weld(s.vertices, s.faces)[1])
        judged = ref.decisive.copy()
        judged[pairs.ravel()] = False
        t = time.perf_counter()
        r = orient(s, seed=0)
        sec = time.perf_counter() - t
        wrong = judged & ((np.asarray(r.flipped, bool) ^ turned) != ref.outside_side.astype(bool))
        print(
            f"{name:32} {kind:6} {sec:7.1f} s  error {100 * ref.area[wrong].sum() / ref.area[judged].sum():.4f} %",
            flush=True,
        )
