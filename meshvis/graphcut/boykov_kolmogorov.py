"""Boykov–Kolmogorov maximum flow, compiled (the default solver of :mod:`~meshvis.graphcut.mincut`).

The algorithm of Boykov and Kolmogorov ("An experimental comparison of min-cut/max-flow
algorithms for energy minimization in vision", PAMI 2004), which PyMaxflow wraps in C++,
written here as numba kernels over flat arrays:

* a *search tree* grows from the source (OUTSIDE) and one from the sink (INSIDE) through
  arcs with residual capacity; where they touch, the path is *augmented* by its bottleneck;
* arcs saturated by the augmentation cut nodes off their tree (*orphans*); each orphan
  looks for a new parent in its own tree that still leads to the terminal, preferring the
  shortest such path (the distance and time-stamp marks of the paper), or becomes free;
* two shortcuts that do not change the result: a node that found a path grows on from
  the arc it stopped at (its neighbour freed by an adoption sends it back to its first
  arc), and an orphan stops looking at a root next to its terminal (none is closer);
* before the search, nodes whose terminal link outweighs all their edges are *settled*:
  such a node lies on its terminal's side of every minimum cut, so it is merged into that
  terminal and its edges become terminal links of its neighbours (two passes, which may
  settle those in turn); on the monastery's last graph this leaves 66 % of the nodes and
  41 % of the edges to the search (``meshvis bench classify`` prints the nodes settled);
* the loop ends when neither tree can grow.  The source tree is then exactly the set of
  nodes reachable from the source in the residual graph: a node in it is reached along its
  tree path, and a node outside it would have been adopted by the growth stage.

That set is the same for every maximum flow (the smallest source side among the minimum
cuts), so the labels do not depend on which maximum flow the search happens to find: this
kernel and PyMaxflow give the same labels (``tests/graphcut/test_boykov_kolmogorov.py``
checks it on random graphs with ties and on the graphs of bundled models, and
``meshvis bench stability`` on graphs whose weights span twelve orders of magnitude).  Where two minimum cuts have
exactly the same value, float rounding of the flow decides which one either returns.  A
node linked to
neither terminal and reachable from neither is free and counts as INSIDE, as the
object-based definition wants (DESIGN.md §4).

Why not PyMaxflow: its graph is built edge by edge through Python wrappers and kept as C++
structures; on the monastery's 1.4 M edges building it took a third of each cut, and the
kernel here is also faster on the search itself (``classify(..., solver="pymaxflow")`` gives
the same labels, to time against the default).

Arc layout: the arcs leaving node ``v`` are ``first[v] .. first[v + 1] - 1``; arc ``a``
goes to ``head[a]`` with residual capacity ``rcap[a]``, and ``sister[a]`` is its reverse.
``excess[v]`` is the residual terminal capacity: positive from the source, negative to the
sink (the two links of a node are netted first, as in the paper's code).
"""

from __future__ import annotations

import numba
import numpy as np

#: parent marks: a free node, a tree root linked to its terminal, a node cut off its tree
FREE, TERMINAL, ORPHAN = -1, -2, -3
#: distance of a node whose path to the terminal is broken
_NO_PATH = 1 << 62
#: relative margin by which a terminal link must outweigh a node's edges to settle it
SETTLE_MARGIN = 1e-9
#: settling passes before the max flow: on the monastery's graphs the first settles 23 %
#: of the nodes and the second 15 % of the rest; a third costs more than it saves
SETTLE_PASSES = 2


def min_cut_bk(
    n: int,
    i: np.ndarray,
    j: np.ndarray,
    cap_ij: np.ndarray,
    cap_ji: np.ndarray,
    cap_source: np.ndarray,
    cap_sink: np.ndarray,
) -> tuple[np.ndarray, float, int]:
    """Minimum s-t cut by Boykov–Kolmogorov; source = OUTSIDE.

    Parameters
    ----------
    n : int
        Number of nodes.
    i, j : (k,) int arrays
        Edge ends (each unordered pair at most once).
    cap_ij, cap_ji : (k,) float64 arrays
        Capacities ``i → j`` and ``j → i`` (non-negative).
    cap_source, cap_sink : (n,) float64 arrays
        Capacities source → node and node → sink (non-negative).

    Returns
    -------
    outside : (n,) bool array
        Nodes reachable from the source in the residual graph of a maximum flow.
    value : float
        The maximum flow (= the minimum cut's capacity).
    settled : int
        Nodes settled before the search (module notes).

    Examples
    --------
    >>> import numpy as np
    >>> out, value, settled = min_cut_bk(2, np.array([0]), np.array([1]), np.array([1.0]),
    ...                         np.array([0.0]), np.array([5.0, 0.0]), np.array([0.0, 3.0]))
    >>> out.tolist(), value, settled
    ([True, False], 1.0, 2)
    """
    cap_source = np.asarray(cap_source, np.float64)
    cap_sink = np.asarray(cap_sink, np.float64)
    if n == 0:
        return np.zeros(0, bool), 0.0, 0
    excess = cap_source - cap_sink
    side, settled_flow, i, j, cap_ij, cap_ji = _settle_decided(
        np.asarray(i, np.int64),
        np.asarray(j, np.int64),
        np.asarray(cap_ij, np.float64),
        np.asarray(cap_ji, np.float64),
        excess,
    )
    outside, flow = side > 0, 0.0
    free = side == 0
    if free.any():  # the max flow of the free nodes and the edges between them, renumbered
        index = np.cumsum(free) - 1
        outside[free], flow = search(int(index[-1]) + 1, index[i], index[j], cap_ij, cap_ji, excess[free])
    # the netted part of each node's two terminal links flows straight through the node
    value = float(settled_flow + flow + np.minimum(cap_source, cap_sink).sum())
    return outside, value, int(n - free.sum())


def search(
    n: int, i: np.ndarray, j: np.ndarray, cap_ij: np.ndarray, cap_ji: np.ndarray, excess: np.ndarray
) -> tuple[np.ndarray, float]:
    """The Boykov–Kolmogorov search on a whole graph, without settling any node.

    ``excess`` (n,) is each node's netted terminal capacity (positive from the source); it
    is used up in place.  Returns the source tree's nodes and the flow through the edges
    (without the netted part of the terminal links).  :func:`min_cut_bk` runs it on the
    nodes its settling leaves.
    """
    first, head, sister, arc_ij, arc_ji = arcs_by_tail(n, np.asarray(i, np.int64), np.asarray(j, np.int64))
    rcap = np.empty(len(head), np.float64)
    rcap[arc_ij] = cap_ij
    rcap[arc_ji] = cap_ji
    return _max_flow(first, head, sister, rcap, excess)


@numba.njit(cache=True, nogil=True)
def _settle_decided(i, j, cap_ij, cap_ji, excess):  # pragma: no cover - compiled
    """Settle the nodes whose terminal link outweighs all their edges (module notes).

    A node whose excess from the source exceeds the capacity of every arc leaving it is on
    the source side of every minimum cut (moving it there lowers any cut); one whose excess
    to the sink exceeds every arc entering it is on the sink side of every minimum cut.
    Each pass settles such nodes and merges them into their terminal: an edge to an
    unsettled node becomes that node's terminal link, which may settle it in the next
    pass.  The max flow does the rest.

    ``excess`` (n,) is updated in place.  Returns ``side`` (n,) int8 (1 source, -1 sink,
    0 unsettled), the flow through the settled nodes, and the edges between unsettled
    nodes (new arrays: i, j, cap_ij, cap_ji).
    """
    n, k = len(excess), len(i)
    # the kept edges go to new arrays (the first pass writes them, later ones compact them)
    i_kept, j_kept = np.empty(k, np.int64), np.empty(k, np.int64)
    ij_kept, ji_kept = np.empty(k), np.empty(k)
    side = np.zeros(n, np.int8)
    out_sum = np.zeros(n)  # capacity of the arcs leaving / entering each node
    in_sum = np.zeros(n)
    to_source = np.empty(n)  # the terminal links that a pass's merges add
    to_sink = np.empty(n)
    flow = 0.0
    for e in range(k):
        out_sum[i[e]] += cap_ij[e]
        out_sum[j[e]] += cap_ji[e]
        in_sum[i[e]] += cap_ji[e]
        in_sum[j[e]] += cap_ij[e]
    for _ in range(SETTLE_PASSES):
        settled = 0
        for v in range(n):
            if side[v] != 0:
                continue
            # the sums are rounded: a node settles only by a clear margin
            if excess[v] > out_sum[v] * (1.0 + SETTLE_MARGIN):
                side[v] = 1
                settled += 1
            elif -excess[v] > in_sum[v] * (1.0 + SETTLE_MARGIN):
                side[v] = -1
                settled += 1
        if settled == 0:
            break
        to_source[:] = 0.0
        to_sink[:] = 0.0
        out_sum[:] = 0.0  # the sums of the next pass, over the edges kept
        in_sum[:] = 0.0
        kept = 0
        for e in range(k):
            a, b = i[e], j[e]
            if side[a] == 0 and side[b] == 0:
                i_kept[kept], j_kept[kept], ij_kept[kept], ji_kept[kept] = a, b, cap_ij[e], cap_ji[e]
                out_sum[a] += cap_ij[e]
                out_sum[b] += cap_ji[e]
                in_sum[a] += cap_ji[e]
                in_sum[b] += cap_ij[e]
                kept += 1
            elif side[b] == 0:  # a settled: a -> b becomes source -> b, or b -> a becomes b -> sink
                if side[a] > 0:
                    to_source[b] += cap_ij[e]
                else:
                    to_sink[b] += cap_ji[e]
            elif side[a] == 0:
                if side[b] > 0:
                    to_source[a] += cap_ji[e]
                else:
                    to_sink[a] += cap_ij[e]
            elif side[a] > side[b]:  # both settled, on opposite sides: the edge is cut
                flow += cap_ij[e]
            elif side[a] < side[b]:
                flow += cap_ji[e]
        k = kept
        i, j, cap_ij, cap_ji = i_kept, j_kept, ij_kept, ji_kept
        for v in range(n):
            if side[v] == 0 and (to_source[v] > 0.0 or to_sink[v] > 0.0):
                s = max(excess[v], 0.0) + to_source[v]
                t = max(-excess[v], 0.0) + to_sink[v]
                flow += min(s, t)  # netted: flows straight through v
                excess[v] = s - t
    return side, flow, i[:k], j[:k], cap_ij[:k], cap_ji[:k]


@numba.njit(cache=True, nogil=True)
def arcs_by_tail(n, i, j):  # pragma: no cover - compiled
    """Both arcs of every edge, grouped by tail node (a counting sort).

    Returns ``first`` (n + 1,), ``head`` and ``sister`` (2k,), and the positions of each
    edge's ``i → j`` and ``j → i`` arcs (k,).
    """
    k = len(i)
    first = np.zeros(n + 1, np.int64)
    for e in range(k):
        first[i[e] + 1] += 1
        first[j[e] + 1] += 1
    for v in range(n):
        first[v + 1] += first[v]
    fill = first[:-1].copy()
    head = np.empty(2 * k, np.int64)
    sister = np.empty(2 * k, np.int64)
    arc_ij = np.empty(k, np.int64)
    arc_ji = np.empty(k, np.int64)
    for e in range(k):
        a = fill[i[e]]
        fill[i[e]] += 1
        b = fill[j[e]]
        fill[j[e]] += 1
        head[a], head[b] = j[e], i[e]
        sister[a], sister[b] = b, a
        arc_ij[e], arc_ji[e] = a, b
    return first, head, sister, arc_ij, arc_ji


@numba.njit(cache=True, nogil=True, inline="always")
def _enqueue(queue, ends, v):  # pragma: no cover - compiled
    """Append ``v`` to a ring buffer whose ``ends`` are (first, one past last)."""
    queue[ends[1]] = v
    ends[1] = (ends[1] + 1) % len(queue)


@numba.njit(cache=True, nogil=True, inline="always")
def _push_front(queue, ends, v):  # pragma: no cover - compiled
    ends[0] = (ends[0] - 1) % len(queue)
    queue[ends[0]] = v


@numba.njit(cache=True, nogil=True, inline="always")
def _dequeue(queue, ends):  # pragma: no cover - compiled
    v = queue[ends[0]]
    ends[0] = (ends[0] + 1) % len(queue)
    return v


@numba.njit(cache=True, nogil=True)
def _max_flow(first, head, sister, rcap, excess):  # pragma: no cover - compiled
    """Boykov–Kolmogorov on the arc layout (module notes); ``rcap`` and ``excess`` in place.

    Returns (source-tree membership, flow pushed through the edges).
    """
    n = len(excess)
    parent = np.full(n, FREE, np.int64)  # arc from the node to its parent, or a mark
    in_sink_tree = np.zeros(n, np.bool_)
    stamp = np.zeros(n, np.int64)  # when `dist` was last known to be right
    dist = np.zeros(n, np.int64)  # tree distance to the terminal
    active = np.empty(n + 1, np.int64)  # ring buffer; each node at most once
    active_ends = np.zeros(2, np.int64)
    queued = np.zeros(n, np.bool_)
    orphans = np.empty(n + 1, np.int64)  # ring buffer; a node is an orphan at most once
    orphan_ends = np.zeros(2, np.int64)
    scan_from = first[:-1].copy()  # where the growth of each node goes on
    arcs = (first, head, sister, rcap)
    tree = (parent, in_sink_tree, stamp, dist)
    queues = (active, active_ends, queued, scan_from, orphans, orphan_ends)
    for v in range(n):
        if excess[v] != 0:
            parent[v] = TERMINAL
            in_sink_tree[v] = excess[v] < 0
            dist[v] = 1
            queued[v] = True
            _enqueue(active, active_ends, v)
    time = 0
    flow = 0.0
    current = -1  # the node whose growth found a path keeps growing next
    while True:
        v = -1
        if current >= 0:
            queued[current] = False
            if parent[current] != FREE:
                v = current
            current = -1
        while v < 0 and active_ends[0] != active_ends[1]:
            u = _dequeue(active, active_ends)
            queued[u] = False
            if parent[u] != FREE:
                v = u
        if v < 0:
            break
        # growth: adopt free neighbours, stop at the first arc into the other tree.  A node
        # that found a path grows on from that arc: the arcs before it led into its own
        # tree, and one that could lead elsewhere again (a neighbour freed by the adoption)
        # sends the scan back to the start (`scan_from` reset in `_adopt`)
        bridge = -1  # arc from the source tree to the sink tree
        sink_side = in_sink_tree[v]
        for a in range(scan_from[v], first[v + 1]):
            if (rcap[sister[a]] if sink_side else rcap[a]) > 0:
                u = head[a]
                if parent[u] == FREE:
                    in_sink_tree[u] = sink_side
                    parent[u] = sister[a]
                    stamp[u] = stamp[v]
                    dist[u] = dist[v] + 1
                    scan_from[u] = first[u]
                    if not queued[u]:
                        queued[u] = True
                        _enqueue(active, active_ends, u)
                elif in_sink_tree[u] != sink_side:
                    bridge = sister[a] if sink_side else a
                    scan_from[v] = a
                    break
                elif stamp[u] <= stamp[v] and dist[u] > dist[v]:
                    # a shorter way to the terminal for u
                    parent[u] = sister[a]
                    stamp[u] = stamp[v]
                    dist[u] = dist[v] + 1
        time += 1
        if bridge < 0:
            scan_from[v] = first[v]
            continue
        current = v
        queued[v] = True
        flow += _augment(bridge, head, sister, rcap, excess, parent, orphans, orphan_ends)
        _adopt(time, arcs, tree, queues)
    outside = np.zeros(n, np.bool_)
    for v in range(n):
        outside[v] = parent[v] != FREE and not in_sink_tree[v]
    return outside, flow


@numba.njit(cache=True, nogil=True)
def _augment(bridge, head, sister, rcap, excess, parent, orphans, orphan_ends):  # pragma: no cover - compiled
    """Push the bottleneck along source root → bridge → sink root; orphan saturated nodes."""
    # bottleneck: the bridge, the source-tree arcs (parent → child), the sink-tree arcs
    # (child → parent) and the two terminal links
    b = rcap[bridge]
    v = head[sister[bridge]]
    while parent[v] != TERMINAL:
        b = min(b, rcap[sister[parent[v]]])
        v = head[parent[v]]
    b = min(b, excess[v])
    v = head[bridge]
    while parent[v] != TERMINAL:
        b = min(b, rcap[parent[v]])
        v = head[parent[v]]
    b = min(b, -excess[v])
    # b equals one of the residuals exactly, so that one becomes exactly 0
    rcap[sister[bridge]] += b
    rcap[bridge] -= b
    v = head[sister[bridge]]
    while True:
        p = parent[v]
        if p == TERMINAL:
            excess[v] -= b
            if excess[v] == 0:
                parent[v] = ORPHAN
                _push_front(orphans, orphan_ends, v)
            break
        rcap[p] += b
        rcap[sister[p]] -= b
        if rcap[sister[p]] == 0:
            parent[v] = ORPHAN
            _push_front(orphans, orphan_ends, v)
        v = head[p]
    v = head[bridge]
    while True:
        p = parent[v]
        if p == TERMINAL:
            excess[v] += b
            if excess[v] == 0:
                parent[v] = ORPHAN
                _push_front(orphans, orphan_ends, v)
            break
        rcap[sister[p]] += b
        rcap[p] -= b
        if rcap[p] == 0:
            parent[v] = ORPHAN
            _push_front(orphans, orphan_ends, v)
        v = head[p]
    return b


@numba.njit(cache=True, nogil=True)
def _adopt(time, arcs, tree, queues):  # pragma: no cover - compiled
    """Give every orphan a parent of its own tree that still reaches the terminal, or free it."""
    first, head, sister, rcap = arcs
    parent, in_sink_tree, stamp, dist = tree
    active, active_ends, queued, scan_from, orphans, orphan_ends = queues
    while orphan_ends[0] != orphan_ends[1]:
        v = _dequeue(orphans, orphan_ends)
        sink_side = in_sink_tree[v]
        best, best_d = -1, _NO_PATH
        for a in range(first[v], first[v + 1]):
            # flow must be able to go parent → v in the source tree, v → parent in the sink tree
            if (rcap[a] if sink_side else rcap[sister[a]]) <= 0:
                continue
            u = head[a]
            if in_sink_tree[u] != sink_side or parent[u] == FREE:
                continue
            # walk up from u until a terminal, a node stamped this time, or an orphan
            d, w = 0, u
            while True:
                if stamp[w] == time:
                    d += dist[w]
                    break
                p = parent[w]
                d += 1
                if p == TERMINAL:
                    stamp[w], dist[w] = time, 1
                    break
                if p == ORPHAN:
                    d = _NO_PATH
                    break
                w = head[p]
            if d == _NO_PATH:
                continue
            if d < best_d:
                best, best_d = a, d
            # stamp the path so later walks stop early
            w = u
            while stamp[w] != time:
                stamp[w], dist[w] = time, d
                d -= 1
                w = head[parent[w]]
            if best_d == 1:  # a root next to the terminal: no parent is closer
                break
        if best >= 0:
            parent[v], stamp[v], dist[v] = best, time, best_d + 1
            continue
        parent[v] = FREE
        scan_from[v] = first[v]
        for a in range(first[v], first[v + 1]):
            u = head[a]
            p = parent[u]
            if in_sink_tree[u] != sink_side or p == FREE:
                continue
            # a neighbour that could feed v may adopt it again (from the start of its arcs,
            # also when it is the node growing now); v's children are orphans now
            if (rcap[a] if sink_side else rcap[sister[a]]) > 0:
                scan_from[u] = first[u]
                if not queued[u]:
                    queued[u] = True
                    _enqueue(active, active_ends, u)
            if p != TERMINAL and p != ORPHAN and head[p] == v:
                parent[u] = ORPHAN
                _enqueue(orphans, orphan_ends, u)
