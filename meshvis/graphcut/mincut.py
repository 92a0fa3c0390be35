"""s-t minimum cut of the visibility graph (appendix H §4, Eq. 10–11).

Source = OUTSIDE, sink = INSIDE; a node left on the source side is outside.  Three solvers
sit behind one function:

* ``"bk"`` (default): Boykov–Kolmogorov on float capacities, compiled here
  (:mod:`meshvis.graphcut.boykov_kolmogorov`);
* ``"pymaxflow"``: the same algorithm through PyMaxflow (the same labels; kept to check
  the kernel against);
* ``"scipy"``: ``scipy.sparse.csgraph.maximum_flow``, which needs integer capacities.
  Capacities are scaled so that the largest one maps to ``2**30`` and rounded to the
  nearest integer; capacities below ``0.5 / scale`` (relative 2**-31 of the largest)
  become 0.  The cut value then differs from the exact one by at most
  ``0.5 / scale`` per cut edge: :func:`rounding_bound` returns that bound.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from meshvis.errors import ParameterError
from meshvis.graphcut.boykov_kolmogorov import min_cut_bk
from meshvis.graphcut.solvers import DEFAULT_SOLVER, SOLVERS
from meshvis.graphcut.weights import Weights

#: largest integer capacity used by the scipy solver (int32 sums must not overflow: the
#: flow out of the source is bounded by the sum of its capacities, which we keep < 2**31)
INT_MAX_CAP = 2**30


@dataclass
class Cut:
    """Result of a min cut: ``outside[i]`` for every node, and the cut value (flow).

    ``settled`` counts the nodes the ``"bk"`` solver settled before its search.
    """

    outside: np.ndarray
    value: float
    solver: str
    scale: float = 1.0
    settled: int = 0


def min_cut(
    n: int,
    i: np.ndarray,
    j: np.ndarray,
    cap_ij: np.ndarray,
    cap_ji: np.ndarray,
    cap_source: np.ndarray,
    cap_sink: np.ndarray,
    solver: str = DEFAULT_SOLVER,
) -> Cut:
    """Minimum s-t cut of a graph with directed capacities.

    Parameters
    ----------
    n : int
        Number of nodes.
    i, j : (k,) int
        Edge ends.
    cap_ij, cap_ji : (k,) float
        Capacities i→j and j→i.
    cap_source, cap_sink : (n,) float
        Capacities source→node and node→sink.
    solver : {"bk", "pymaxflow", "scipy"}
        The max-flow solver.

    Returns
    -------
    Cut
        With ``outside[v]`` True where v stays connected to the source.
    """
    if solver == "bk":
        outside, value, settled = min_cut_bk(n, i, j, cap_ij, cap_ji, cap_source, cap_sink)
        return Cut(outside, value, "bk", settled=settled)
    if solver == "pymaxflow":
        return _cut_pymaxflow(n, i, j, cap_ij, cap_ji, cap_source, cap_sink)
    if solver == "scipy":
        return _cut_scipy(n, i, j, cap_ij, cap_ji, cap_source, cap_sink)
    raise ParameterError(f"unknown max-flow solver {solver!r}; choose one of {', '.join(SOLVERS)}")


def _cut_pymaxflow(n, i, j, cap_ij, cap_ji, cap_source, cap_sink) -> Cut:
    """Boykov–Kolmogorov through PyMaxflow, on the *reversed* graph.

    Nodes that are linked to neither terminal (a sealed cavity, an isolated sheet inside a
    solid) may sit on either side of a minimum cut.  The object-based definition wants
    them inside: outside means reachable from OUTSIDE.  PyMaxflow reports such free nodes
    as the source segment, so we swap the roles of the terminals and reverse every edge:
    the flow problem is the same, and free nodes land on the INSIDE side.
    """
    import maxflow

    if n == 0:  # every face degenerate: no nodes (PyMaxflow refuses empty arrays)
        return Cut(np.zeros(0, bool), 0.0, "pymaxflow")
    g = maxflow.Graph[float](n, len(i))
    ids = g.add_nodes(n)
    if len(i):
        g.add_edges(ids[i], ids[j], np.asarray(cap_ji, np.float64), np.asarray(cap_ij, np.float64))
    g.add_grid_tedges(ids, np.asarray(cap_sink, np.float64), np.asarray(cap_source, np.float64))
    value = g.maxflow()
    outside = np.asarray(g.get_grid_segments(ids), bool)  # sink segment of the reversed graph
    return Cut(outside, float(value), "pymaxflow")


def integer_scale(caps: list[np.ndarray]) -> float:
    """Scale that maps the largest capacity to :data:`INT_MAX_CAP` (1 if all are 0)."""
    top = max((float(c.max()) for c in caps if len(c)), default=0.0)
    return INT_MAX_CAP / top if top > 0 else 1.0


def rounding_bound(n_edges_cut: int, scale: float) -> float:
    """Largest difference between the scipy solver's cut value and the exact one."""
    return 0.5 * n_edges_cut / scale


def _cut_scipy(n, i, j, cap_ij, cap_ji, cap_source, cap_sink) -> Cut:
    from scipy.sparse.csgraph import breadth_first_order, maximum_flow

    s, t = n, n + 1
    scale = integer_scale([cap_ij, cap_ji, cap_source, cap_sink])
    # The sum of source capacities bounds every flow; keep it within int32.
    total = float(np.sum(cap_source)) * scale
    if total >= 2**31 - 1:
        scale *= (2**31 - 2) / total / 1.0000001
    rows = np.concatenate([i, j, np.full(n, s), np.arange(n)])
    cols = np.concatenate([j, i, np.arange(n), np.full(n, t)])
    caps = np.concatenate([cap_ij, cap_ji, cap_source, cap_sink]) * scale
    caps = np.rint(caps).astype(np.int64)
    keep = caps > 0
    # parallel edges are summed by the conversion to CSR
    graph = sp.csr_matrix((caps[keep], (rows[keep], cols[keep])), shape=(n + 2, n + 2)).astype(np.int32)
    res = maximum_flow(graph, s, t)
    flow = res.flow.tocsr()
    residual = (graph - flow).tocsr()
    residual.data = np.maximum(residual.data, 0)
    # residual also has reverse capacity equal to the flow on each edge
    reverse = flow.T.tocsr()
    reverse.data = np.maximum(reverse.data, 0)
    res_graph = (residual + reverse).tocsr()
    res_graph.eliminate_zeros()
    reach = breadth_first_order(res_graph, s, directed=True, return_predecessors=False)
    outside = np.zeros(n + 2, bool)
    outside[reach] = True
    return Cut(outside[:n], res.flow_value / scale, "scipy", scale)


def cut_value(outside: np.ndarray, i, j, cap_ij, cap_ji, cap_source, cap_sink) -> float:
    """Capacity of the cut given by ``outside`` (source side), computed directly."""
    outside = np.asarray(outside, bool)
    v = float(np.sum(cap_sink[outside])) + float(np.sum(cap_source[~outside]))
    v += float(np.sum(cap_ij[outside[i] & ~outside[j]])) + float(np.sum(cap_ji[outside[j] & ~outside[i]]))
    return v


class VisibilityGraph:
    """The weighted visibility graph with its terminals; cut it, tie nodes, export it.

    Parameters
    ----------
    n : int
        Number of half-space nodes.
    weights : Weights
        The edge and terminal weights (:class:`~meshvis.graphcut.weights.Weights`).
    """

    def __init__(self, n: int, weights: Weights):
        self.n = n
        self.weights = weights

    @property
    def n_edges(self) -> int:
        """Number of node-node edges of the graph."""
        return len(self.weights.edges_i)

    def cut(self, solver: str = DEFAULT_SOLVER, tie_to_source: np.ndarray | None = None) -> Cut:
        """Min cut; nodes in ``tie_to_source`` (bool mask) are forced outside (layer peeling)."""
        w = self.weights
        cap_out = w.cap_out
        if tie_to_source is not None and np.any(tie_to_source):
            # "infinite" capacity: more than every other capacity together
            big = 1.0 + float(w.cap_ij.sum() + w.cap_ji.sum() + w.cap_out.sum() + w.cap_in.sum())
            cap_out = np.where(tie_to_source, big, cap_out)
        return min_cut(self.n, w.edges_i, w.edges_j, w.cap_ij, w.cap_ji, cap_out, w.cap_in, solver)

    def to_networkx(self, node_attributes: dict[str, np.ndarray] | None = None):
        """A ``networkx.DiGraph`` with nodes 0..n-1 plus "OUTSIDE" and "INSIDE".

        Edges carry ``weight`` (unfiltered w) and ``capacity`` (filtered, directed).
        """
        from meshvis._extras import import_extra

        nx = import_extra("networkx", "GraphML export (--graphml)")
        w = self.weights
        g = nx.DiGraph()
        attrs = node_attributes or {}
        for v in range(self.n):
            g.add_node(v, **{k: _py(a[v]) for k, a in attrs.items()})
        g.add_node("OUTSIDE")
        g.add_node("INSIDE")
        g.add_edges_from(
            (int(a), int(b), {"weight": float(x), "capacity": float(c)})
            for a, b, x, c in zip(w.edges_i, w.edges_j, w.w, w.cap_ij)
        )
        g.add_edges_from(
            (int(b), int(a), {"weight": float(x), "capacity": float(c)})
            for a, b, x, c in zip(w.edges_i, w.edges_j, w.w, w.cap_ji)
        )
        for u in np.flatnonzero(w.w_out > 0):
            g.add_edge("OUTSIDE", int(u), weight=float(w.w_out[u]), capacity=float(w.cap_out[u]))
        for u in np.flatnonzero(w.w_in > 0):
            g.add_edge(int(u), "INSIDE", weight=float(w.w_in[u]), capacity=float(w.cap_in[u]))
        return g


def _py(x):
    return x.item() if hasattr(x, "item") else x
