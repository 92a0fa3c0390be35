"""Half-space nodes of the visibility graph (appendix H §3.1).

Node ids are laid out as:

* ``0 .. n_cluster-1`` — cluster nodes, one per consistent side of a triangle cluster;
* ``n_cluster + 2*p + s`` — point node of sample point ``p`` on side ``s`` of a flagged
  (intersecting / coplanar / too close) triangle.

A flagged face carries ``samples`` sample points, or, given a ``point_area``, points by its
size (:func:`sample_counts`): one per ``point_area`` times the model's mean face area, at
least one and at most ``samples``.  Most flagged faces of a large assembly are small (on a
city of real models four in five are below the mean face area), and their four points
would vote alike.

The two virtual terminals OUTSIDE and INSIDE are not stored here; the cut adds them.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from meshvis.graphcut import _kernels
from meshvis.graphcut.clusters import Clustering
from meshvis.rays.samples import (
    cosine_about_faces,
    pushed_points_in_faces,
    sample_scheme_barycentric,
    tangent_frames,
)


@dataclass
class NodeSet:
    """All half-space nodes of one model.

    Attributes
    ----------
    n : int
        Number of nodes.
    n_cluster : int
        Number of cluster nodes (they come first).
    area : (n,) float64 array
        A_i: sum of the node's triangle areas, or triangle area / samples.
    opposite : (n,) int64 array
        The node on the other side of the same geometry.
    n_faces : (n,) int64 array
        Triangles in a cluster node (1 for point nodes).
    side_node : (m, 2) int64 array
        Cluster node of each (face, side), -1 for flagged faces.
    entry_node : (e,) int64 array
        Node of each (node, face, side) entry of the cluster nodes, sorted by node.
    entry_face : (e,) int64 array
        Face of each entry.
    entry_side : (e,) int8 array
        Side of each entry.
    entry_cumarea : (e,) float64 array
        Cumulative area of the entries within their node, for area-weighted picking.
    node_start : (n_cluster + 1,) int64 array
        Offsets of each cluster node's entries.
    flagged : (k,) int64 array
        The flagged faces; sample points of flagged face q are ``point_start[q] ..
        point_start[q+1]-1``.
    samples : int
        The most sample points a flagged face carries.
    point_start : (k + 1,) int64 array
        Offsets of each flagged face's sample points.
    point_face : (P,) int64 array
        Face of each sample point.
    point_pos : (P, 3) float64 array
        Sample point on its face.
    point_origin : (P, 2, 3) float64 array
        Ray origin of each side, pushed off the surface.
    flagged_index : (m,) int64 array
        Position of a face in ``flagged`` or -1.
    sample_bary : (samples, samples, 3) float64 array
        Barycentric patterns of the sample points: row ``c - 1`` holds the ``c`` points of a
        face that carries ``c`` (the rest zero); every face of one count has the same.
    flagged_metric : (k, 3) float64 array
        Per flagged face ``(e1·e1, e1·e2, e2·e2)`` with ``e1 = b - a``, ``e2 = c - a``: the metric
        of its barycentric coordinates.
    tangents : tuple of two (m, 3) float64 arrays
        A tangent frame of every face normal (for ray directions).
    """

    n: int
    n_cluster: int
    area: np.ndarray
    opposite: np.ndarray
    n_faces: np.ndarray
    side_node: np.ndarray
    entry_node: np.ndarray
    entry_face: np.ndarray
    entry_side: np.ndarray
    entry_cumarea: np.ndarray
    node_start: np.ndarray
    flagged: np.ndarray
    samples: int
    point_start: np.ndarray
    point_face: np.ndarray
    point_pos: np.ndarray
    point_origin: np.ndarray
    flagged_index: np.ndarray
    sample_bary: np.ndarray
    flagged_metric: np.ndarray
    tangents: tuple[np.ndarray, np.ndarray]

    @property
    def n_points(self) -> int:
        """Number of sample points ``P``."""
        return len(self.point_face)

    @property
    def point_count(self) -> np.ndarray:
        """(k,) int64: sample points of each flagged face."""
        return np.diff(self.point_start)

    def points_of(self, q: np.ndarray) -> np.ndarray:
        """All sample points of the flagged faces ``q`` (positions in ``flagged``), face by face."""
        q = np.asarray(q, np.int64)
        count = self.point_start[q + 1] - self.point_start[q]
        first = np.repeat(self.point_start[q], count)
        # the rank of each point within its face: 0 .. count-1
        rank = np.arange(len(first)) - np.repeat(np.cumsum(count) - count, count)
        return first + rank

    @property
    def is_point(self) -> np.ndarray:
        """(n,) bool: the node is a sample-point node."""
        out = np.zeros(self.n, bool)
        out[self.n_cluster :] = True
        return out

    def point_node(self, p: np.ndarray, side: np.ndarray) -> np.ndarray:
        """Node id of side ``side`` of sample point ``p`` (both int arrays of one shape)."""
        return self.n_cluster + 2 * np.asarray(p, np.int64) + np.asarray(side, np.int64)


def side_normals(normals: np.ndarray, side: np.ndarray) -> np.ndarray:
    """Normal of the given side (side 0: the face normal, side 1: its negation)."""
    return normals * np.where(np.asarray(side) == 0, 1.0, -1.0)[:, None]


def build_nodes(
    triangles: np.ndarray,
    normals: np.ndarray,
    areas: np.ndarray,
    clustering: Clustering,
    flagged: np.ndarray,
    partner_pairs: np.ndarray,
    *,
    samples: int = 4,
    scheme: int = 2,
    offset: float,
    proximity: float,
    duplicate_first: np.ndarray | None = None,
    point_area: float | None = None,
) -> NodeSet:
    """Create the half-space nodes.

    Parameters
    ----------
    triangles : (m, 3, 3) float64 array
        Corner coordinates.
    normals : (m, 3) float64 array
        Unit normals of side 0.
    areas : (m,) float64 array
        Face areas.
    clustering : Clustering
        From :func:`meshvis.graphcut.clusters.cluster_sides`.
    flagged : (m,) bool array
        Faces that get sample-point nodes.
    partner_pairs : (k, 2) int64 array
        Pairs of faces flagged together (intersecting, coplanar, too close); used by the proximity
        adjustment of the sample points.
    samples : int
        The most sample points of a flagged face.
    scheme : {1, 2}
        Sample placement scheme (appendix H §3.1, see
        :func:`meshvis.rays.samples.sample_scheme_barycentric`).
    offset : float
        Push of ray origins off their surface (absolute, model units).
    proximity : float
        A sample point closer than this to a partner's plane, and inside it, is moved past
        that partner (appendix H Fig. 6).
    duplicate_first : (m,) int64 array, optional
        The first face of each face's group of copies
        (:func:`meshvis.geometry.adjacency.duplicate_faces`): the pairs of a group's first
        face stand for those of its copies, as :func:`meshvis.geometry.intersect.intersection_flags`
        gives them.  Default: no copies.
    point_area : float, optional
        Area of the surface one sample point stands for, relative to the mean face area
        (:func:`sample_counts`); None gives every flagged face ``samples`` points.

    Returns
    -------
    NodeSet
        Cluster nodes first, then two nodes per sample point.
    """
    side_node = clustering.side_node
    n_cluster = clustering.n_nodes
    e_node, e_face, e_side, node_start, c_area, c_faces = _cluster_entries(side_node, n_cluster, areas)
    count = sample_counts(areas, flagged, samples, point_area)
    pts = _point_nodes(
        triangles, normals, flagged, partner_pairs, count, samples, scheme, offset, proximity, duplicate_first
    )
    n_points = len(pts["point_face"])
    p_area = np.repeat(areas[pts["flagged"]] / count, count)
    return NodeSet(
        n=n_cluster + 2 * n_points,
        n_cluster=n_cluster,
        area=np.concatenate([c_area, np.repeat(p_area, 2)]),
        opposite=np.concatenate([clustering.opposite, n_cluster + (np.arange(2 * n_points) ^ 1)]),
        n_faces=np.concatenate([c_faces, np.ones(2 * n_points, np.int64)]),
        side_node=side_node,
        entry_node=e_node,
        entry_face=e_face,
        entry_side=e_side,
        entry_cumarea=np.cumsum(areas[e_face]),
        node_start=node_start,
        samples=samples,
        tangents=tangent_frames(normals),
        **pts,
    )


def _cluster_entries(side_node: np.ndarray, n_cluster: int, areas: np.ndarray):
    """Entries of the cluster nodes.

    Returns the (node, face, side) entries sorted by node, the start of each node's
    entries, and each node's area and face count.
    """
    faces_c = np.flatnonzero(side_node[:, 0] >= 0)
    e_node = np.concatenate([side_node[faces_c, 0], side_node[faces_c, 1]])
    e_face = np.concatenate([faces_c, faces_c])
    e_side = np.concatenate([np.zeros(len(faces_c), np.int8), np.ones(len(faces_c), np.int8)])
    order = np.lexsort((e_face, e_node))
    e_node, e_face, e_side = e_node[order], e_face[order], e_side[order]
    node_start = np.searchsorted(e_node, np.arange(n_cluster + 1))
    c_area = np.bincount(e_node, areas[e_face], minlength=n_cluster)
    c_faces = np.bincount(e_node, minlength=n_cluster)
    return e_node, e_face, e_side, node_start, c_area, c_faces


def sample_counts(
    areas: np.ndarray, flagged: np.ndarray, samples: int, point_area: float | None
) -> np.ndarray:
    """(k,) int64: sample points of each flagged face, by its size.

    A flagged face carries one point per ``point_area`` times the model's mean face area
    (over the faces with an area), rounded up, at least one and at most ``samples``: a
    small face is all on one side of what crosses it, or nearly so, and its one point (its
    centroid) says which.  The mean face area follows the model's tessellation, not its
    scale or extent, so a model and a city of its copies give their faces the same counts.

    Parameters
    ----------
    areas : (m,) float64 array
        Face areas.
    flagged : (m,) bool array
        Faces that get sample points.
    samples : int
        The most points of a face.
    point_area : float or None
        Area one point stands for, relative to the mean face area; None: ``samples`` for
        every flagged face.

    Returns
    -------
    (k,) int64 array
        Points of each flagged face, in face order.

    Examples
    --------
    >>> areas = np.array([1.0, 1.0, 0.1, 6.0])  # mean 2.025
    >>> sample_counts(areas, np.array([False, True, True, True]), 4, 1.0).tolist()
    [1, 1, 3]
    >>> sample_counts(areas, np.array([False, True, True, True]), 4, None).tolist()
    [4, 4, 4]
    """
    a = areas[np.asarray(flagged, bool)]
    if point_area is None or len(a) == 0:
        return np.full(len(a), samples, np.int64)
    with_area = areas[areas > 0]
    mean = with_area.mean() if len(with_area) else 1.0
    count = np.ceil(a / (point_area * mean))
    return np.clip(np.nan_to_num(count, nan=1.0), 1, samples).astype(np.int64)


def sample_patterns(samples: int, scheme: int) -> np.ndarray:
    """(samples, samples, 3) barycentric patterns: row ``c - 1`` holds the ``c`` points of a face that carries ``c``."""
    table = np.zeros((samples, samples, 3))
    for c in range(1, samples + 1):
        table[c - 1, :c] = sample_scheme_barycentric(c, scheme)
    return table


def _point_nodes(
    triangles, normals, flagged, partner_pairs, count, samples, scheme, offset, proximity, duplicate_first
) -> dict:
    """Sample points of the flagged faces with their pushed ray origins (NodeSet fields)."""
    m = len(triangles)
    flagged_faces = np.flatnonzero(flagged)
    flagged_index = np.full(m, -1, np.int64)
    flagged_index[flagged_faces] = np.arange(len(flagged_faces))
    table = sample_patterns(samples, scheme)
    point_start = np.concatenate([[0], np.cumsum(count)]).astype(np.int64)
    point_face = np.repeat(flagged_faces, count)
    rank = np.arange(len(point_face)) - np.repeat(point_start[:-1], count)
    bary = table[np.repeat(count, count) - 1, rank]
    tri = triangles[point_face]
    pos = bary[:, 0, None] * tri[:, 0] + bary[:, 1, None] * tri[:, 1] + bary[:, 2, None] * tri[:, 2]
    origin = np.empty((len(point_face), 2, 3))
    for s in (0, 1):
        origin[:, s] = _pushed_origins(
            pos,
            point_face,
            s,
            triangles,
            normals,
            flagged_index,
            partner_pairs,
            point_start,
            offset,
            proximity,
            duplicate_first,
        )
    tf = triangles[flagged_faces]
    e1, e2 = tf[:, 1] - tf[:, 0], tf[:, 2] - tf[:, 0]
    metric = np.stack(
        [np.einsum("ij,ij->i", e1, e1), np.einsum("ij,ij->i", e1, e2), np.einsum("ij,ij->i", e2, e2)], axis=1
    )
    return {
        "flagged": flagged_faces,
        "point_start": point_start,
        "point_face": point_face,
        "point_pos": pos,
        "point_origin": origin,
        "flagged_index": flagged_index,
        "sample_bary": table,
        "flagged_metric": metric,
    }


#: |cos| between a partner's normal and a side normal below which the two are taken as
#: perpendicular (about 0.06 degrees, like the parallel-plane tolerance of the flags)
PERPENDICULAR_COS = 1e-3


def _pushed_origins(
    pos,
    point_face,
    side,
    triangles,
    normals,
    flagged_index,
    pairs,
    point_start,
    offset,
    proximity,
    duplicate_first=None,
):
    """Ray origins of sample points on one side, pushed off the surface (appendix H Fig. 6).

    A point is first pushed by ``offset`` along its face's side normal.  If it also lies on a
    partner triangle (closer than ``proximity`` to its plane and inside it), it is moved
    along that partner's normal (oriented towards the same side) until it clears the
    partner by ``offset``; among several partners the one needing the furthest move wins.
    A partner at right angles (a face against a wall at a T-junction, a sliver along it,
    ``|cos| <`` :data:`PERPENDICULAR_COS`): the normals do not tell which side of the
    partner the origin belongs to, and picking one at random can push it through the
    partner (e.g. out of a room), so the point keeps the side of the partner it lies on,
    and does not move when it lies on the partner's plane itself.  One pass of
    :func:`meshvis.graphcut._kernels.pushed_origins` over the (point, partner) candidates;
    a copy of a face (``duplicate_first``) meets the partners of its group's first face,
    whose pairs stand for the whole group's (:func:`meshvis.geometry.intersect.intersection_flags`).
    """
    flagged = np.flatnonzero(flagged_index >= 0)
    point_start = np.asarray(point_start, np.int64)
    if point_start.shape != (len(flagged) + 1,) or point_start[-1] != len(pos):
        # the kernel indexes by these offsets: a wrong layout would read out of bounds
        raise ValueError("point_start must hold the offsets of every flagged face's points")
    # (face, partner) candidates: every pair both ways, grouped by face (stable: in that order)
    both = np.concatenate([pairs, pairs[:, ::-1]]) if len(pairs) else np.zeros((0, 2), np.int64)
    by_face = np.argsort(both[:, 0], kind="stable")
    start = np.searchsorted(both[by_face, 0], np.arange(len(triangles) + 1))
    first = np.arange(len(triangles)) if duplicate_first is None else duplicate_first
    return _kernels.pushed_origins(
        np.ascontiguousarray(pos, np.float64),
        np.ascontiguousarray(point_face, np.int64),
        int(side),
        np.ascontiguousarray(triangles, np.float64),
        np.ascontiguousarray(normals, np.float64),
        np.ascontiguousarray(flagged, np.int64),
        np.ascontiguousarray(start, np.int64),
        np.ascontiguousarray(both[by_face, 1], np.int64),
        np.ascontiguousarray(first, np.int64),
        np.ascontiguousarray(point_start, np.int64),
        float(offset),
        float(proximity),
        PERPENDICULAR_COS,
    )


def node_rays(
    nodes: NodeSet,
    normals: np.ndarray,
    triangles: np.ndarray,
    counts: np.ndarray,
    rng: np.random.Generator,
    offset: float,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Origins and cosine-distributed directions of ``counts[i]`` rays from every node i.

    Cluster nodes: pick a triangle of the node by area, a uniform point on it, push it off
    along the side normal (appendix H §3.2.2).  Point nodes: rays start at the (pushed)
    sample point.

    Parameters
    ----------
    nodes : NodeSet
        The nodes.
    normals : (m, 3) float64 array
        Unit normals of side 0.
    triangles : (m, 3, 3) float64 array
        Corner coordinates.
    counts : (nodes.n,) int array
        Rays to cast from each node.
    rng : numpy.random.Generator
        The random generator.
    offset : float
        Push of ray origins off their surface (absolute, model units).

    Returns
    -------
    source : (r,) int64 array
        Node id of each ray.
    origins : (r, 3) float64 array
        Ray origins.
    directions : (r, 3) float64 array
        Unit ray directions.
    """
    counts = np.asarray(counts, np.int64)
    n_c = int(counts[: nodes.n_cluster].sum())
    # one area draw per cluster ray, then the points on the chosen faces, then the directions
    draws = rng.random(n_c) if n_c else np.zeros(0)
    source, face, side, origins, rows_c = _kernels.ray_starts(
        counts,
        nodes.n_cluster,
        nodes.node_start,
        nodes.entry_cumarea,
        nodes.area,
        nodes.entry_face,
        nodes.entry_side,
        nodes.point_face,
        nodes.point_origin,
        draws,
    )
    if n_c:
        origins[rows_c] = pushed_points_in_faces(triangles, normals, face[rows_c], side[rows_c], offset, rng)
    # tangent frames depend on the face only (flipping the normal keeps them orthogonal)
    t1, t2 = nodes.tangents
    directions = cosine_about_faces(normals, (t1, t2), face, side, rng)
    return source, origins, directions
