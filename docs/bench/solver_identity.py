"""The compiled Boykov–Kolmogorov solver against PyMaxflow, model by model, in one process.

For every model (every file of the given folders, and with ``accuracy`` the soups of the
accuracy benchmark) it runs ``classify(model, seed=0)`` with ``solver="pymaxflow"`` and with
``solver="bk"``, and prints whether the labels and the rays cast are the same and the time
of the cut stage of each; ``--repairs`` also compares what ``orient`` turns and the layers
of ``layers`` (their extra cuts use the same solver).  Exits with status 1 when any
result differs.  Run from the repository root::

    python docs/bench/solver_identity.py ../shared/models/real ../shared/models/real2 accuracy --repairs

Every model is cut by both solvers alternately, so the times are a ratio measured side by
side (docs/performance.md, "Max-flow kernel").
"""

from __future__ import annotations

import sys
import time
import warnings

import numpy as np

from meshvis.eval.bench.scale_flags import load_spec, model_specs
from meshvis.graphcut.classify import classify
from meshvis.repair.layers import layers
from meshvis.repair.orient import orient


def _cut_seconds(c) -> float:
    return next(s.seconds for s in c.stages if s.name == "cut")


def _compare(name: str, soup, repairs: bool) -> bool:
    """Print one line for a model; True when both solvers give the same results."""
    runs = {solver: classify(soup, seed=0, solver=solver) for solver in ("pymaxflow", "bk")}
    old, new = runs["pymaxflow"], runs["bk"]
    same = np.array_equal(old.outside, new.outside) and old.n_rays == new.n_rays
    cells = [
        f"labels {'=' if np.array_equal(old.outside, new.outside) else 'DIFFER'}",
        f"rays {'=' if old.n_rays == new.n_rays else 'DIFFER'}",
        f"cut {_cut_seconds(old):.3f} s -> {_cut_seconds(new):.3f} s",
    ]
    if repairs:
        flips = [orient(soup, classification=c).flipped for c in (old, new)]
        peeled = [layers(soup, classification=c).layer for c in (old, new)]
        same_flips, same_layers = np.array_equal(*flips), np.array_equal(*peeled)
        same &= same_flips and same_layers
        cells += [f"orient {'=' if same_flips else 'DIFFER'}", f"layers {'=' if same_layers else 'DIFFER'}"]
    print(name, soup.n_faces, *cells, flush=True)
    return same


def main(argv: list[str]) -> int:
    """Compare the labels of the solvers on every model of the folders; 1 if any differ."""
    repairs = "--repairs" in argv
    folders = [a for a in argv if a != "--repairs"]
    if not folders:
        print(__doc__)
        return 2
    warnings.simplefilter("ignore")
    t = time.perf_counter()
    results = [_compare(name, load_spec(spec), repairs) for name, spec in model_specs(folders)]
    print(f"{sum(results)} of {len(results)} models the same ({time.perf_counter() - t:.0f} s)")
    return 0 if all(results) else 1


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
