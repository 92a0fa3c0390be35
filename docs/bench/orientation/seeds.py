"""meshvis `orient` with several seeds on one model, judged by the cached reference.

Usage (from the repository root; the reference from the cache of `meshvis bench orientation`):
    python docs/bench/orientation/seeds.py STEM SEED[,SEED...] ["as is"|soup]

Prints per seed the time, the evidence rays, the error (the decisive area whose front is
not the side that escapes, DESIGN.md §10) and the three faces that weigh most in it.
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
name, seeds = sys.argv[1], [int(s) for s in sys.argv[2].split(",")]
kind = sys.argv[3] if len(sys.argv) > 3 else "as is"
path = next(os.path.join(d, f) for d in R for f in os.listdir(d) if os.path.splitext(f)[0] == name)
model = load(path)
ref = reference(model, seed=0, cache=f"/tmp/meshvis-refcache/{name}.seed0.npz")
s, turned = (model, np.zeros(model.n_faces, bool)) if kind == "as is" else soup_of(model, 0)
judged = ref.decisive.copy()
judged[opposite_copies(weld(s.vertices, s.faces)[1]).ravel()] = False
total = ref.area[judged].sum()
for seed in seeds:
    t = time.perf_counter()
    r = orient(s, seed=seed)
    sec = time.perf_counter() - t
    wrong = judged & ((np.asarray(r.flipped, bool) ^ turned) != ref.outside_side.astype(bool))
    top = np.argsort(-ref.area * wrong, kind="stable")[:3]
    shares = ", ".join(f"{f} {100 * ref.area[f] / total:.3f} %" for f in top if wrong[f])
    print(
        f"{name} {kind} seed {seed}: {sec:.1f} s, {r.visibility['rays']} evidence rays, "
        f"error {100 * ref.area[wrong].sum() / total:.4f} % (largest: {shares})",
        flush=True,
    )
