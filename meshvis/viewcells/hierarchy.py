"""View cells by render cost: a kD-tree split where it most lowers Σ P(cell)·|PVS(cell)| (002 §3.3, §4.2).

A coarse pass of view space-direction samples gives *visibility segments* (002 §4.1): free
segments with the faces at their ends.  A node's PVS is estimated as the faces at the ends
of the segments that cross it, and its probability ``P`` as the share of the coarse
samples' starting points (uniform in the view space) that fall in it.  The render cost of a
cell is the number of faces in its PVS (002 §3.3's ``r(o)`` with one unit per triangle).

For a candidate plane ``x`` on axis ``a`` of a node, a face is in the PVS of the part below
``x`` when one of its segments reaches below ``x`` inside the node, i.e. when the least
coordinate of its segments there is below ``x``; likewise above.  With each face's least
and greatest coordinate sorted, every candidate's two PVS sizes are two binary searches,
so a node's candidates (positions of segment ends, at most :data:`CANDIDATES` per axis,
002 §4.2) cost one pass over its segments per axis.

Splitting is greedy over a priority queue of leaves (002 §4.2): the leaf whose best plane
lowers the cost most (plus :data:`ABSOLUTE_WEIGHT` of its own cost, so that a leaf whose
cost falls only after two splits is split at last) is split next, until the cell count, a
memory budget for the PVS or a minimal cost reduction (:data:`STALL` splits in a row
below it) is reached.  The bottom-up merging of 002 §4.3 is left out: 002 §6.3 measures
little gain from it over this subdivision.
"""

from __future__ import annotations

import heapq
from dataclasses import dataclass

import numpy as np

from meshvis.viewcells import _kernels
from meshvis.viewcells.cells import DEFAULT_AUTO_CELLS, MIN_VOLUME_SHARE, ViewCells
from meshvis.viewcells.viewspace import ViewSpace

#: view space-direction samples of the coarse pass (two rays each; 002 §6.2 finds a coarse
#: pass enough for a stable estimate of the cost)
COARSE_SAMPLES = 1 << 20
#: coarse samples' starting points that estimate the share of each node in the view space
VOLUME_POINTS = 1 << 18
#: candidate planes per axis and node (random segment ends inside the node, 002 §4.2)
CANDIDATES = 64
#: weight of a leaf's own cost in its priority (002 §4.2: 1 % suffices)
ABSOLUTE_WEIGHT = 0.01
#: a split below this share of the root's cost is small ...
MIN_REDUCTION = 1e-4
#: ... and this many small splits in a row end the subdivision
STALL = 10
#: no cell thinner than this share of the view space's side along the split axis
MIN_SIDE = 1e-3
#: bytes per PVS entry in the memory budget (a 32-bit face id)
ENTRY_BYTES = 4


@dataclass
class Segments:
    """Visibility segments: the faces at the two ends (-1: none) of free segments.

    Segment k is the line ``origin + t * direction`` for ``t0 <= t <= t1`` (clipped to the
    view space's box).
    """

    origin: np.ndarray
    direction: np.ndarray
    t0: np.ndarray
    t1: np.ndarray
    face_back: np.ndarray
    face_fwd: np.ndarray


@dataclass
class _Node:
    lo: np.ndarray
    hi: np.ndarray
    seg: np.ndarray  # indices of the segments crossing the node
    pts: np.ndarray  # indices of the coarse points in the node
    share: float  # P(node)
    pvs: int  # |PVS(node)|
    best: tuple = (0.0, -1, 0.0, 0.0, 0.0)  # (reduction, axis, position, cost below, cost above)


def auto_cells(
    view_space: ViewSpace,
    segments: Segments,
    points: np.ndarray,
    n_cells: int = DEFAULT_AUTO_CELLS,
    *,
    n_faces: int,
    memory: int | None = None,
    min_reduction: float = MIN_REDUCTION,
    rng: np.random.Generator,
) -> tuple[ViewCells, dict]:
    """Build the view cells by render cost from a coarse pass.

    Parameters
    ----------
    view_space : ViewSpace
        The space the cells partition.
    segments : Segments
        The coarse pass's visibility segments, clipped to the view space's box.
    points : (p, 3) float
        Uniform points of the view space (the coarse samples' starts): P(node) is their share.
    n_cells : int
        Most cells.
    n_faces : int
        Faces of the model.
    memory : int, optional
        Budget in bytes for the estimated PVS of all cells (:data:`ENTRY_BYTES` per entry).
    min_reduction : float
        Minimal cost reduction, a share of the root's cost (:data:`STALL` in a row stop).
    rng : numpy.random.Generator
        Picks the candidate planes.

    Returns
    -------
    cells : ViewCells
    info : dict
        ``coarse_segments``, ``expected_cost`` (Σ P·|PVS| of the coarse PVS) of the root and
        of the cells, ``cost_by_cells`` (the cost after each split), ``stopped``.
    """
    scratch_lo = np.full((n_faces, 3), np.inf)
    scratch_hi = np.full((n_faces, 3), -np.inf)
    points = points[:VOLUME_POINTS]
    n_pts = max(len(points), 1)
    min_side = MIN_SIDE * (view_space.hi - view_space.lo)

    def make(lo, hi, seg, pts) -> _Node:
        ab = clipped(segments, seg, lo, hi)
        inside = ab[:, 0] <= ab[:, 1]
        node = _Node(lo, hi, seg[inside], pts, len(pts) / n_pts, 0)
        _evaluate(node, ab[inside], segments, points, n_pts, min_side, scratch_lo, scratch_hi, rng)
        return node

    root = make(
        view_space.lo.copy(), view_space.hi.copy(), np.arange(len(segments.origin)), np.arange(len(points))
    )
    axis, split, left, right = [-1], [0.0], [-1], [-1]
    nodes = {0: root}
    leaves = {0}
    root_cost = root.share * root.pvs
    cost = root_cost
    history = [float(cost)]
    heap = [(-_priority(root), 0)]
    stalled = 0
    stopped = "cell count"
    while heap:
        if _live(nodes, leaves, view_space) >= n_cells:
            break
        if memory is not None and ENTRY_BYTES * sum(nodes[i].pvs for i in leaves) >= memory:
            stopped = "memory budget"
            break
        _, i = heapq.heappop(heap)
        node = nodes[i]
        reduction, a, s, _, _ = node.best
        if a < 0:
            continue
        stalled = stalled + 1 if reduction < min_reduction * root_cost else 0
        if stalled >= STALL:
            stopped = "minimal cost reduction"
            break
        ids = []
        for below in (True, False):
            lo, hi = node.lo.copy(), node.hi.copy()
            (hi if below else lo)[a] = s
            seg = node.seg
            p = points[node.pts, a]
            pts = node.pts[p <= s] if below else node.pts[p > s]
            child = make(lo, hi, seg, pts)
            k = len(axis)
            axis.append(-1)
            split.append(0.0)
            left.append(-1)
            right.append(-1)
            nodes[k] = child
            ids.append(k)
        axis[i], split[i], left[i], right[i] = a, s, ids[0], ids[1]
        leaves.discard(i)
        leaves.update(ids)
        cost += nodes[ids[0]].share * nodes[ids[0]].pvs + nodes[ids[1]].share * nodes[ids[1]].pvs
        cost -= node.share * node.pvs
        history.append(float(cost))
        for k in ids:
            heapq.heappush(heap, (-_priority(nodes[k]), k))
        node.seg = node.pts = np.zeros(0, np.int64)  # an inner node keeps no segments
    else:
        stopped = "nothing left to split"
    cell = np.full(len(axis), -1, np.int32)
    alive = sorted(i for i in leaves if _volume(nodes[i], view_space) > MIN_VOLUME_SHARE)
    cell[alive] = np.arange(len(alive), dtype=np.int32)
    cells = ViewCells(
        view_space,
        np.array(axis),
        np.array(split),
        np.array(left),
        np.array(right),
        cell,
        kind=f"auto:{n_cells}",
    )
    info = {
        "coarse_segments": int(len(segments.origin)),
        "expected_cost_root": float(root_cost),
        "expected_cost": float(cost),
        "cost_by_cells": history,
        "stopped": stopped,
    }
    return cells, info


def _priority(node: _Node) -> float:
    return node.best[0] + ABSOLUTE_WEIGHT * node.share * node.pvs if node.best[1] >= 0 else -np.inf


def _volume(node: _Node, view_space: ViewSpace) -> float:
    return float(view_space.volume_share(node.lo[None], node.hi[None])[0])


def _live(nodes: dict, leaves: set, view_space: ViewSpace) -> int:
    """Leaves with some view space in them (the cells there would be now)."""
    return sum(1 for i in leaves if nodes[i].share > 0 or _volume(nodes[i], view_space) > MIN_VOLUME_SHARE)


def clipped(segments: Segments, idx: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """(k, 2): the parameters ``[a, b]`` of the part of segments ``idx`` inside the box (a > b: none)."""
    return _kernels.clip_segments(
        segments.origin,
        segments.direction,
        segments.t0,
        segments.t1,
        np.ascontiguousarray(idx, np.int64),
        lo,
        hi,
    )


def _evaluate(
    node: _Node, ab, segments: Segments, points, n_pts, min_side, scratch_lo, scratch_hi, rng
) -> None:
    """The node's PVS size and its best split (``node.best``); ``ab`` clips its segments to it."""
    _, f_lo3, f_hi3 = _kernels.node_faces(
        segments.origin,
        segments.direction,
        ab,
        np.ascontiguousarray(node.seg, np.int64),
        segments.face_back,
        segments.face_fwd,
        scratch_lo,
        scratch_hi,
    )
    node.pvs = len(f_lo3)
    best = (0.0, -1, 0.0, 0.0, 0.0)
    if node.pvs == 0 or node.share <= 0:
        node.best = best
        return
    for axis in range(3):
        f_lo, f_hi = np.sort(f_lo3[:, axis]), np.sort(f_hi3[:, axis])
        lo_edge, hi_edge = node.lo[axis] + min_side[axis], node.hi[axis] - min_side[axis]
        if lo_edge >= hi_edge:
            continue
        ends = np.concatenate([f_lo, f_hi])
        ends = ends[(ends > lo_edge) & (ends < hi_edge)]
        if len(ends) > CANDIDATES:
            ends = rng.choice(ends, CANDIDATES, replace=False)
        x = np.unique(ends)
        if len(x) == 0:
            continue
        below = np.searchsorted(f_lo, x, side="left")  # faces reaching below x
        above = len(f_hi) - np.searchsorted(f_hi, x, side="right")  # faces reaching above x
        p = np.sort(points[node.pts, axis])
        share_below = np.searchsorted(p, x, side="right") / n_pts
        share_above = node.share - share_below
        after = share_below * below + share_above * above
        reduction = node.share * node.pvs - after
        k = int(np.argmax(reduction))
        if reduction[k] > best[0]:
            best = (
                float(reduction[k]),
                axis,
                float(x[k]),
                float(share_below[k] * below[k]),
                float(share_above[k] * above[k]),
            )
    node.best = best
