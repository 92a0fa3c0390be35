"""Visibility sampling: cast rays from every node and count where they land (appendix H §3.2.2).

The counts of one or more rounds are accumulated in a :class:`VisibilityCounts`:
``hits[i, j] = n_ij`` (sparse), ``cast[i] = n_i`` (rays that count: cast minus discarded),
``escaped[i]`` (misses, which link node *i* to the OUTSIDE terminal).
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from meshvis.graphcut import _kernels
from meshvis.graphcut.nodes import NodeSet, node_rays
from meshvis.rays.caster import RayCaster

#: rays traced per Embree batch (bounded memory: ~100 bytes per ray in flight)
BATCH = 1 << 20
#: hits held before they are added to the sparse counts: memory follows the nodes' links,
#: not the rays of a round
HITS_HELD = 1 << 23


@dataclass
class VisibilityCounts:
    """Accumulated ray statistics of all rounds so far."""

    n: int
    # filled by the first round
    hits: sp.csr_matrix = None
    cast: np.ndarray = None  # type: ignore[assignment]
    escaped: np.ndarray = None  # type: ignore[assignment]
    discarded: np.ndarray = None  # type: ignore[assignment]
    rays: int = 0
    reverse_rays: int = 0
    time_embree: float = 0.0
    time_total: float = 0.0

    def __post_init__(self) -> None:
        if self.hits is None:
            self.hits = sp.csr_matrix((self.n, self.n), dtype=np.float64)
            self.cast = np.zeros(self.n, np.int64)
            self.escaped = np.zeros(self.n, np.int64)
            self.discarded = np.zeros(self.n, np.int64)


def snap_to_points(nodes: NodeSet, face: np.ndarray, bary: np.ndarray) -> np.ndarray:
    """Index of the sample point of ``face`` (a flagged face) nearest to each hit.

    Hits are given by their barycentric coordinates ``(u, v)`` on the face.  Every flagged
    face with the same number of sample points carries the same barycentric pattern, so
    the squared 3D distance to sample *k* is the quadratic form ``Δᵀ G Δ`` of the
    barycentric difference Δ = (u-u_k, v-v_k) with the face's metric tensor ``G`` (dot
    products of its two edge vectors): no 3D coordinates need to be gathered.
    """
    q = nodes.flagged_index[face]
    first = nodes.point_start[q]
    bu, bv = nodes.sample_bary[:, :, 1], nodes.sample_bary[:, :, 2]
    best = _kernels.nearest_sample(
        nodes.flagged_metric[q],
        np.ascontiguousarray(bary[:, 0]),
        np.ascontiguousarray(bary[:, 1]),
        nodes.point_start[q + 1] - first,
        np.ascontiguousarray(bu),
        np.ascontiguousarray(bv),
    )
    return first + best


def sample_round(
    caster: RayCaster,
    nodes: NodeSet,
    rays_per_node: np.ndarray,
    rng: np.random.Generator,
    counts: VisibilityCounts,
    progress=None,
) -> VisibilityCounts:
    """Cast ``rays_per_node[i]`` rays from every node i and add the results to ``counts``.

    A hit on a clustered face links to that cluster's node of the side hit.  A hit on a
    flagged face is snapped to the nearest sample point on that face and kept only if a
    reverse ray from the sample point (pushed to the side hit) reaches the ray's origin;
    otherwise the ray is discarded (it counts neither as a hit nor as an escape).
    """
    t_start = time.perf_counter()
    soup = caster.soup
    normals, triangles = soup.normals, soup.triangles
    offset = caster.offset * caster.diagonal
    rays_per_node = np.asarray(rays_per_node, np.int64)
    # process nodes in slices whose ray count stays near BATCH
    cum = np.cumsum(rays_per_node)
    edges = np.searchsorted(cum, np.arange(BATCH, cum[-1] + BATCH, BATCH) if len(cum) and cum[-1] else [])
    bounds = np.unique(np.concatenate([[0], np.minimum(edges + 1, nodes.n), [nodes.n]]))
    rows, cols = [], []
    for a, b in zip(bounds[:-1], bounds[1:]):
        per = np.zeros(nodes.n, np.int64)
        per[a:b] = rays_per_node[a:b]
        if per.sum() == 0:
            continue
        src, origins, dirs = node_rays(nodes, normals, triangles, per, rng, offset)
        t0 = time.perf_counter()
        h = caster.intersect(origins, dirs)
        counts.time_embree += time.perf_counter() - t0
        counts.rays += len(src)
        f, s, sr, dst, flagged_at, ray_at = _kernels.split_hits(
            h.face, h.side, src, nodes.side_node, counts.escaped
        )
        p, blocked = np.zeros(0, np.int64), np.zeros(0, bool)
        if len(flagged_at):  # hits on flagged faces: snap to a sample point, check the way back
            assert h.bary is not None  # intersect always fills it
            # a face with no node (degenerate after welding, yet thick enough for Embree to
            # hit) tells nothing about either side: its hits are discarded as blocked ones
            real = nodes.flagged_index[f[flagged_at]] >= 0
            p, blocked = np.zeros(len(flagged_at), np.int64), np.ones(len(flagged_at), bool)
            p[real] = snap_to_points(nodes, f[flagged_at[real]], h.bary[ray_at[real]])
            t0 = time.perf_counter()
            blocked[real] = caster.occluded(
                nodes.point_origin[p[real], s[flagged_at[real]]], origins[ray_at[real]]
            )
            counts.time_embree += time.perf_counter() - t0
            counts.reverse_rays += int(real.sum())
        r, c = _kernels.kept_hits(sr, s, dst, flagged_at, p, blocked, nodes.n_cluster, counts.discarded)
        rows.append(r)
        cols.append(c)
        if sum(len(x) for x in rows) >= HITS_HELD:  # the round's hits so far into the matrix
            _add_hits(counts, rows, cols, nodes.n)
        if progress is not None:
            progress(len(src))
    counts.cast += rays_per_node
    _add_hits(counts, rows, cols, nodes.n)
    counts.time_total += time.perf_counter() - t_start
    return counts


def _add_hits(counts: VisibilityCounts, rows: list, cols: list, n: int) -> None:
    """Add the (row, column) hits held in ``rows`` and ``cols`` to ``counts.hits``; empty the lists."""
    if rows:
        r, c = np.concatenate(rows), np.concatenate(cols)
        add = sp.coo_matrix((np.ones(len(r)), (r, c)), shape=(n, n)).tocsr()
        counts.hits = (counts.hits + add).tocsr()
    rows.clear()
    cols.clear()
