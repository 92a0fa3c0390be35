"""The max flow with and without settling the decided nodes first, on every cut of a classification.

For each model it records the graphs of every round of ``classify(model, seed=0)`` and
cuts each one twice, alternately, best of three: by ``min_cut_bk`` (which settles the
nodes whose terminal link outweighs their edges, then runs the search on the rest) and by
the same search on the whole graph.  It prints the nodes and edges the search is left
with, both times and whether the labels are the same, and exits with status 1 when any
labels differ.  Run from the repository root, on an otherwise idle machine::

    python docs/bench/settle_nodes.py ../shared/models/real/pybullet__samurai_monastry.obj

(docs/performance.md, "Settled nodes").
"""

from __future__ import annotations

import sys
import time
import warnings

import numpy as np

import meshvis
from meshvis.graphcut import boykov_kolmogorov as bk
from meshvis.graphcut import mincut


def round_graphs(path: str) -> list[tuple]:
    """The arguments of every max flow that ``classify(path, seed=0)`` runs."""
    calls = []
    solve = mincut.min_cut_bk

    def record(*args):
        calls.append(args)
        return solve(*args)

    mincut.min_cut_bk = record
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            meshvis.classify(meshvis.load(path), seed=0)
    finally:
        mincut.min_cut_bk = solve
    return calls


def whole_graph(n, i, j, cap_ij, cap_ji, cap_source, cap_sink):
    """``min_cut_bk`` without the settling passes: the search on every node and edge."""
    outside, flow = bk.search(n, i, j, cap_ij, cap_ji, cap_source - cap_sink)
    return outside, float(flow + np.minimum(cap_source, cap_sink).sum())


def _best(f, args, runs: dict, key: str):
    t = time.perf_counter()
    result = f(*args)
    runs[key] = min(runs.get(key, np.inf), time.perf_counter() - t)
    return result


def main(paths: list[str]) -> int:
    """Time every cut of each model whole and settled; 1 if any labels differ."""
    same_everywhere = True
    for path in paths:
        graphs = round_graphs(path)
        total = {"whole": 0.0, "settled": 0.0}
        print(f"{path}: {len(graphs)} cuts")
        for k, args in enumerate(graphs):
            n, i, j, cap_ij, cap_ji, cap_s, cap_t = args
            side, *_ = bk._settle_decided(
                np.asarray(i, np.int64), np.asarray(j, np.int64), cap_ij, cap_ji, cap_s - cap_t
            )
            free = side == 0
            edges_left = int((free[i] & free[j]).sum())
            runs: dict = {}
            for _ in range(3):
                whole = _best(whole_graph, args, runs, "whole")
                settled = _best(bk.min_cut_bk, args, runs, "settled")
            same = np.array_equal(whole[0], settled[0])
            same_everywhere &= same
            total["whole"] += runs["whole"]
            total["settled"] += runs["settled"]
            print(
                f"  cut {k + 1}: {n} nodes, {len(i)} edges; search on {free.sum()} nodes "
                f"({free.mean():.1%}) and {edges_left} edges ({edges_left / max(len(i), 1):.1%}); "
                f"{runs['whole']:.3f} s -> {runs['settled']:.3f} s; labels {'=' if same else 'DIFFER'}; "
                f"value {whole[1]:.12g} -> {settled[1]:.12g}"
            )
        print(
            f"  all cuts: {total['whole']:.3f} s -> {total['settled']:.3f} s "
            f"({total['settled'] / max(total['whole'], 1e-12):.2f})"
        )
    return 0 if same_everywhere else 1


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
