"""Error against time of `classify` over the ray budget, on one model.

Usage (from the repository root):
    python docs/bench/classify_budget.py [MODEL]   # default: the samurai monastery

Error: share of the area whose hidden/kept verdict differs from a run at
rays_per_node=128 (seed 0), which is itself not converged; seeds 1 and 2 at the default
budget show the seed-to-seed spread.  One process; the kernels are warmed first.
"""

import sys
import time
import warnings

from meshvis.graphcut.classify import classify
from meshvis.io import load

warnings.simplefilter("ignore")
path = sys.argv[1] if len(sys.argv) > 1 else "../shared/models/real/pybullet__samurai_monastry.obj"
model = load(path)
classify(model, seed=0, rays_per_node=4)
runs = {}
for rpn, seed in [(128, 0), (32, 1), (32, 2), (4, 0), (8, 0), (16, 0), (32, 0), (64, 0)]:
    t = time.perf_counter()
    r = classify(model, seed=seed, rays_per_node=rpn)
    runs[rpn, seed] = (r.hidden.copy(), time.perf_counter() - t, r.n_rays, len(r.rounds))
area, reference = model.areas, runs[128, 0][0]
print("| rays_per_node | seed | classify | rays | rounds | hidden-verdict area differing from 128 |")
print("|---:|---:|---:|---:|---:|---:|")
for (rpn, seed), (hidden, seconds, rays, rounds) in sorted(runs.items()):
    differs = 100 * area[hidden != reference].sum() / area.sum()
    print(f"| {rpn} | {seed} | {seconds:.2f} s | {rays / 1e6:.2f} M | {rounds} | {differs:.2f} % |")
