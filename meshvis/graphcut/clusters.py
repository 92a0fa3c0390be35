"""Triangle clustering: which triangle sides can share one half-space node (appendix H §2).

Two triangles may be clustered across an edge when the edge is manifold (exactly two
faces use it, after welding) and neither triangle is flagged (intersecting, coplanar, or
too close to a non-adjacent triangle).  A cluster's triangles then have two consistent
sets of sides, one per half-space node (appendix H §3.1, "Triangle Clusters").

Input models are often wound inconsistently, so "side 0" of two clustered faces need not
be the same half-space.  We solve both problems at once on the *orientation double
cover*: one graph node per (face, side); a clusterable edge whose two faces traverse it
in opposite directions (consistent winding) joins (f,0)-(g,0) and (f,1)-(g,1), an
inconsistent one joins (f,0)-(g,1) and (f,1)-(g,0).  The connected components of this
graph are exactly the cluster half-space nodes.  A non-orientable cluster (a Möbius band)
would put both sides of a face in one component; its faces are split into single-face
clusters instead.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from meshvis.geometry._kernels import component_labels
from meshvis.geometry.adjacency import EdgeTable


@dataclass
class Clustering:
    """Result of :func:`cluster_sides`.

    Attributes
    ----------
    side_node : (m, 2) int64 array
        Half-space node of (face, side); -1 for faces not clustered (flagged faces, which get point
        nodes instead).
    n_nodes : int
        Number of cluster half-space nodes (ids 0 .. n_nodes-1).
    opposite : (n_nodes,) int64 array
        The node on the other side of the same cluster.
    cluster : (m,) int64 array
        Cluster id per face (-1 for faces not clustered).
    n_clusters : int
        Number of clusters.
    n_split_nonorientable : int
        Faces split out of non-orientable clusters.
    """

    side_node: np.ndarray
    n_nodes: int
    opposite: np.ndarray
    cluster: np.ndarray
    n_clusters: int
    n_split_nonorientable: int


def manifold_face_pairs(table: EdgeTable) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Pairs of faces sharing a manifold edge (used by exactly two faces).

    Parameters
    ----------
    table : EdgeTable
        Edges of the welded faces (:func:`meshvis.geometry.adjacency.edges`).

    Returns
    -------
    f : (k,) int64 array
        First face of each pair.
    g : (k,) int64 array
        Second face.
    consistent : (k,) bool array
        True when the two faces traverse the edge in opposite directions.
    """
    start = np.searchsorted(table.half_edge, np.flatnonzero(table.manifold))
    f, g = table.half_face[start], table.half_face[start + 1]
    consistent = table.half_forward[start] != table.half_forward[start + 1]
    keep = f != g  # a face using the same edge twice is degenerate
    return f[keep], g[keep], consistent[keep]


def cluster_sides(
    table: EdgeTable, clusterable: np.ndarray, joinable: np.ndarray | None = None
) -> Clustering:
    """Cluster the sides of the clusterable faces into half-space nodes.

    Parameters
    ----------
    table : EdgeTable
        Edges of the welded faces (adjacency only; the model is not changed).
    clusterable : (m,) bool array
        Faces that get cluster nodes (not flagged, not degenerate).
    joinable : (m,) bool array
        Faces that may be joined to others across an edge (default: all clusterable ones); a
        clusterable face that is not joinable is a single-face cluster.

    Returns
    -------
    Clustering
        The half-space nodes of the clusters.
    """
    m = len(clusterable)
    f, g, consistent = manifold_face_pairs(table)
    join = clusterable if joinable is None else clusterable & joinable
    ok = join[f] & join[g]
    f, g, consistent = f[ok], g[ok], consistent[ok]

    def components(f: np.ndarray, g: np.ndarray, consistent: np.ndarray) -> np.ndarray:
        # double cover: node 2*face + side
        cross = (~consistent).astype(np.int64)
        rows = np.concatenate([2 * f, 2 * f + 1])
        cols = np.concatenate([2 * g + cross, 2 * g + 1 - cross])
        return component_labels(2 * m, rows, cols)

    label = components(f, g, consistent)
    bad_face = label[0::2] == label[1::2]
    n_split = 0
    if bad_face.any():
        # non-orientable clusters: drop every edge touching them, their faces become singletons
        n_split = int(bad_face.sum())
        keep = ~(bad_face[f] | bad_face[g])
        label = components(f[keep], g[keep], consistent[keep])

    side_label = label.reshape(m, 2)
    used = side_label[clusterable]
    uniq, compact = np.unique(used.ravel(), return_inverse=True)
    side_node = np.full((m, 2), -1, np.int64)
    side_node[clusterable] = compact.reshape(-1, 2)
    n_nodes = len(uniq)
    opposite = np.empty(n_nodes, np.int64)
    opposite[side_node[clusterable, 0]] = side_node[clusterable, 1]
    opposite[side_node[clusterable, 1]] = side_node[clusterable, 0]
    # cluster id: the smaller of a face's two node ids, compacted
    cluster = np.full(m, -1, np.int64)
    if clusterable.any():
        pair_min = np.minimum(side_node[clusterable, 0], side_node[clusterable, 1])
        uniq_c, cl = np.unique(pair_min, return_inverse=True)
        cluster[clusterable] = cl
        n_clusters = len(uniq_c)
    else:
        n_clusters = 0
    return Clustering(side_node, n_nodes, opposite, cluster, n_clusters, n_split)
