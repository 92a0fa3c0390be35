"""Two checks behind docs/performance.md's account of the monastery's cut stage.

1. PyMaxflow holds the GIL: two max-flows of the final graph in two threads take about as
   long as the two one after another (on a 2-core machine; with the GIL released they
   would take about half).
2. Reordering the nodes (reverse Cuthill-McKee of the graph) gives the same labels and
   no faster cut.

Run from the repository root, on an otherwise idle machine::

    python docs/bench/maxflow_checks.py [MODEL]

MODEL defaults to ../shared/models/real/pybullet__samurai_monastry.obj.  The graph is the
one of the last max-flow of ``classify(model, seed=0)``.
"""

from __future__ import annotations

import os
import sys
import threading
import time

import numpy as np
import scipy.sparse as sp
from scipy.sparse.csgraph import reverse_cuthill_mckee

from meshvis.graphcut import mincut

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from settle_nodes import round_graphs  # noqa: E402 - the recording of the script beside this one

MODEL = "../shared/models/real/pybullet__samurai_monastry.obj"


def last_graph(path: str) -> tuple:
    """The arguments of the last max-flow that ``classify(path, seed=0)`` runs."""
    return round_graphs(path)[-1]


def seconds(f) -> float:
    """Wall seconds of one call of ``f()``."""
    t = time.perf_counter()
    f()
    return time.perf_counter() - t


def main(path: str) -> None:
    """Time PyMaxflow on the last graph of ``path``: two cuts serially and in threads, and in RCM order."""
    args = last_graph(path)
    n, i, j = args[0], args[1], args[2]
    print(f"{path}: last graph {n} nodes, {len(i)} edges")
    cut = mincut._cut_pymaxflow
    cut(*args)  # warm

    serial = seconds(lambda: (cut(*args), cut(*args)))
    pair = [threading.Thread(target=cut, args=args) for _ in range(2)]
    threaded = seconds(lambda: ([t.start() for t in pair], [t.join() for t in pair]))
    print(
        f"two cuts one after another {serial:.2f} s, in two threads {threaded:.2f} s (ratio {threaded / serial:.2f})"
    )

    adjacency = sp.coo_matrix((np.ones(len(i)), (i, j)), shape=(n, n)).tocsr()
    order = reverse_cuthill_mckee((adjacency + adjacency.T).tocsr(), symmetric_mode=True)
    rank = np.empty(n, np.int64)
    rank[order] = np.arange(n)
    moved = (n, rank[i], rank[j], args[3], args[4], args[5][order], args[6][order])
    base, reordered = cut(*args), cut(*moved)
    same = np.array_equal(base.outside, reordered.outside[rank])
    t_base = min(seconds(lambda: cut(*args)) for _ in range(3))
    t_moved = min(seconds(lambda: cut(*moved)) for _ in range(3))
    print(
        f"reverse Cuthill-McKee order: same labels {same}, cut {t_base:.2f} s -> {t_moved:.2f} s (best of 3)"
    )


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else MODEL)
