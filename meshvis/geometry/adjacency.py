"""Connectivity of a triangle soup: welding, edges, face adjacency, degenerate and duplicate faces.

Everything here is a pure function over plain arrays ``(vertices, faces)`` so that the
diagnostics and the graph-cut preprocessing (appendix H §2: intersection and coplanarity
candidates, triangle clustering) can share it.

Welding is for *adjacency only*: it decides which faces touch, it never changes the model.
Tolerances are fractions of the bounding-box diagonal of the used vertices.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from meshvis.geometry._vectorised import kernels

#: default weld tolerance, as a fraction of the bounding-box diagonal
WELD_TOL = 1e-7


#: constants of the splitmix64 finaliser, the bit mixer of the coordinate hash in :func:`_exact_groups`
_MIX = (np.uint64(0xBF58476D1CE4E5B9), np.uint64(0x94D049BB133111EB), np.uint64(0x9E3779B97F4A7C15))


def _mix(z: np.ndarray) -> np.ndarray:
    """splitmix64 finaliser: every input bit changes about half of the output bits."""
    z = (z ^ (z >> np.uint64(30))) * _MIX[0]
    z = (z ^ (z >> np.uint64(27))) * _MIX[1]
    return z ^ (z >> np.uint64(31))


def used_vertices(faces: np.ndarray, n_vertices: int) -> np.ndarray:
    """(k,) int64: sorted ids of the vertices some face uses (a mask, O(n + m), no sort)."""
    mask = np.zeros(n_vertices, bool)
    mask[np.asarray(faces).ravel()] = True
    return np.flatnonzero(mask)


def _bounds(vertices: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """(2, 3) bounding box of the used vertices (one pass over the corners)."""
    return kernels(len(faces)).corner_bounds(np.asarray(vertices, np.float64), np.asarray(faces))


def _diagonal(vertices: np.ndarray, faces: np.ndarray) -> float:
    if len(faces) == 0:
        return 0.0
    lo, hi = _bounds(vertices, faces)
    return float(np.linalg.norm(hi - lo))


@dataclass(frozen=True)
class VertexGroups:
    """The used vertices of a soup grouped by bit-identical coordinates.

    Computed once per model (:func:`group_vertices`) and shared by the Embree scene, whose
    vertex buffer holds one vertex per group (every corner keeps its exact float32
    coordinates), and by :func:`weld`, which merges the groups further (``-0.0`` with
    ``0.0``, then within the weld tolerance).

    Attributes
    ----------
    used : (k,) int64 array
        Sorted ids of the vertices some face uses.
    group : (k,) int64 array
        Group of each used vertex, numbered by first occurrence.
    first : (g,) int64 array
        Vertex id of the first vertex of each group.
    """

    used: np.ndarray
    group: np.ndarray
    first: np.ndarray

    def corner_groups(self, faces: np.ndarray, n_vertices: int) -> np.ndarray:
        """(m, 3) int32 or int64: the group of every corner of ``faces``."""
        dtype = np.int32 if len(self.first) < 2**31 else np.int64
        of_vertex = np.zeros(n_vertices, dtype)
        of_vertex[self.used] = self.group
        return of_vertex[np.asarray(faces)]


def _hash_rows(bits: np.ndarray) -> np.ndarray:
    """(n,) uint64 hash of the (n, 3) uint64 rows (splitmix64 over the three words)."""
    return _mix(_mix(_mix(bits[:, 0] + _MIX[2]) ^ bits[:, 1]) ^ bits[:, 2])


def group_vertices(vertices: np.ndarray, faces: np.ndarray) -> VertexGroups:
    """Group the used vertices whose float64 coordinates are identical bit for bit.

    Equal rows are found through a hash table on a 64-bit hash of their bits (a numba
    kernel, rows compared in full, so a collision costs a probe, never a wrong group), or
    on a small model by sorting the rows (:mod:`meshvis.geometry._vectorised`).

    Parameters
    ----------
    vertices : (n, 3) float array
        Vertex coordinates.
    faces : (m, 3) int array
        Vertex indices of each triangle.

    Returns
    -------
    VertexGroups
        The groups; ``-0.0`` and ``0.0`` are different bits, so different groups.

    Examples
    --------
    >>> v = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 0, 0]], float)
    >>> g = group_vertices(v, np.array([[0, 1, 2], [3, 2, 1]]))
    >>> g.group.tolist(), g.first.tolist()
    ([0, 1, 2, 1], [0, 1, 2])
    """
    vertices = np.asarray(vertices, np.float64)
    used = used_vertices(faces, len(vertices))
    bits = np.ascontiguousarray(vertices[used]).view(np.uint64)
    group, first_row = kernels(len(faces)).exact_groups(bits, _hash_rows(bits))
    return VertexGroups(used, group, used[first_row])


def _lex_rank(pts: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Distinct rows ``pts`` in lexicographic order, and the rank of each input row."""
    lex = np.lexsort((pts[:, 2], pts[:, 1], pts[:, 0]))
    rank = np.empty(len(pts), np.int64)
    rank[lex] = np.arange(len(pts))
    return pts[lex], rank


def _exact_groups(pts: np.ndarray, n_faces: int) -> tuple[np.ndarray, np.ndarray]:
    """Distinct rows of ``pts`` in lexicographic order, and the row of each input point.

    The same answer as ``np.unique(pts, axis=0, return_inverse=True)``, about 10x faster:
    equal points are grouped by the hash table of :func:`group_vertices`, and only the
    distinct points are sorted lexicographically.  The points must not hold ``-0.0`` (add
    ``0.0`` first) or NaN.  ``n_faces``, the model's faces, chooses the kernels.
    """
    bits = np.ascontiguousarray(pts, np.float64).view(np.uint64)
    group, first_row = kernels(n_faces).exact_groups(bits, _hash_rows(bits))
    uniq, rank = _lex_rank(pts[first_row])
    return uniq, rank[group]


def _distinct_points(
    vertices: np.ndarray, groups: VertexGroups, n_faces: int
) -> tuple[np.ndarray, np.ndarray]:
    """Distinct used points up to the sign of zero, lexicographic, and the one of each group."""
    # + 0.0 turns -0.0 into 0.0 so that both weld exactly
    firsts = vertices[groups.first]
    pts = firsts + 0.0
    if np.signbit(firsts[pts == 0]).any():
        return _exact_groups(pts, n_faces)  # some groups differ only in the sign of a zero: merge them
    return _lex_rank(pts)  # the groups are the distinct points already


def weld(
    vertices: np.ndarray,
    faces: np.ndarray,
    tol: float = WELD_TOL,
    vertex_groups: VertexGroups | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """Merge vertices that lie closer than ``tol`` times the bounding-box diagonal.

    Exact duplicates are merged first (the groups of :func:`group_vertices`); the remaining
    distinct points closer than the weld distance are paired on a grid and merged by
    connected components, so a chain of points each within ``tol`` of the next becomes one
    vertex (harmless at the tiny default tolerance).

    Parameters
    ----------
    vertices : (n, 3) float array
        Vertex coordinates.
    faces : (m, 3) int array
        Vertex indices of each triangle.
    tol : float
        Weld distance as a fraction of the diagonal of the used vertices' bounding box
        (default :data:`WELD_TOL` = 1e-7).  ``0`` merges exact duplicates only.
    vertex_groups : VertexGroups, optional
        :func:`group_vertices` of the same arrays, when the caller has them already.

    Returns
    -------
    index : (n,) int64
        Welded vertex id of every input vertex, numbered ``0 .. k-1`` in lexicographic order
        of the coordinates (a merged group takes the rank of its smallest point); ``-1``
        for vertices no face uses.
    faces_welded : (m, 3) int64
        ``index[faces]``.  A face whose corners merged has repeated ids.

    Examples
    --------
    >>> v = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [1e-12, 0, 0]], float)
    >>> weld(v, np.array([[0, 1, 2], [3, 2, 1]]))[1].tolist()
    [[0, 2, 1], [0, 1, 2]]
    """
    vertices = np.asarray(vertices, np.float64)
    faces = np.asarray(faces, np.int64).reshape(-1, 3)
    index = np.full(len(vertices), -1, np.int64)
    if len(faces) == 0:
        return index, faces.copy()
    groups = vertex_groups if vertex_groups is not None else group_vertices(vertices, faces)
    uniq, of_group = _distinct_points(vertices, groups, len(faces))
    label = np.arange(len(uniq))
    radius = tol * _diagonal(vertices, faces)
    if radius > 0 and len(uniq) > 1:
        label = kernels(len(faces)).near_labels(uniq, radius)
    index[groups.used] = label[of_group][groups.group]
    return index, index[faces]


def collapsed(faces_welded: np.ndarray) -> np.ndarray:
    """(m,) bool: faces with a repeated (welded) corner, i.e. collapsed to a segment or point."""
    f = np.asarray(faces_welded)
    return (f[:, 0] == f[:, 1]) | (f[:, 1] == f[:, 2]) | (f[:, 2] == f[:, 0])


@dataclass(frozen=True)
class EdgeTable:
    """Undirected edges of a welded soup with their face incidence.

    Side ``s`` of face ``f`` runs from corner ``s`` to corner ``(s + 1) % 3``.  Collapsed
    faces (repeated welded corner) contribute no edges: their sides would pair the face
    with itself.

    Attributes
    ----------
    vertices : (k, 2) int64 array
        Welded end points of each edge, smaller id first.
    count : (k,) int64 array
        Number of face sides on the edge (1 boundary, 2 manifold, >2 non-manifold).
    face_edge : (m, 3) int64 array
        Edge of each face side; -1 for collapsed faces.
    half_face : (h,) int64 array
        Face of each half-edge (face side), sorted by edge.
    half_edge : (h,) int64 array
        Edge of each half-edge, non-decreasing.
    half_forward : (h,) bool array
        The face traverses its edge from the smaller to the larger id.
    """

    vertices: np.ndarray
    count: np.ndarray
    face_edge: np.ndarray
    half_face: np.ndarray
    half_edge: np.ndarray
    half_forward: np.ndarray

    @property
    def boundary(self) -> np.ndarray:
        """(k,) bool: edges used by one face."""
        return self.count == 1

    @property
    def manifold(self) -> np.ndarray:
        """(k,) bool: edges used by exactly two faces."""
        return self.count == 2

    @property
    def nonmanifold(self) -> np.ndarray:
        """(k,) bool: edges used by more than two faces."""
        return self.count > 2

    @property
    def consistent(self) -> np.ndarray:
        """(k,) bool: manifold edges whose two faces traverse them in opposite directions.

        A manifold edge traversed twice in the same direction means one of its two faces is
        wound the other way (a flipped face).  Boundary and non-manifold edges are ``True``.
        """
        out = np.ones(len(self.count), bool)
        start = np.searchsorted(self.half_edge, np.flatnonzero(self.manifold))
        out[self.half_edge[start]] = self.half_forward[start] != self.half_forward[start + 1]
        return out


def stable_order(keys: np.ndarray, bound: int) -> np.ndarray:
    """``np.argsort(keys, kind="stable")`` for int64 keys in ``[0, bound)``.

    When ``bound * len(keys)`` fits in int64 the keys are made unique by their position
    (``key * len + position``) and sorted by value (a SIMD sort, about 5x faster than a
    stable argsort of 4 M keys); the positions are the stable order.
    """
    h = len(keys)
    if h == 0 or bound * h >= 2**63:
        return np.argsort(keys, kind="stable")
    composite = keys * np.int64(h)
    composite += np.arange(h, dtype=np.int64)
    composite.sort()
    composite %= h
    return composite


def edges(faces_welded: np.ndarray) -> EdgeTable:
    """Unique undirected edges of welded faces, their face counts and traversal directions.

    Edge keys are ``lo * n + hi`` in int64 (``n`` = number of welded vertices), sorted
    once; edges and counts come from the runs of equal keys in that order.

    Parameters
    ----------
    faces_welded : (m, 3) int array
        The ``faces_welded`` output of :func:`weld`.

    Returns
    -------
    EdgeTable
        The edges, the face side of every half-edge and their directions.
    """
    f = np.asarray(faces_welded, np.int64).reshape(-1, 3)
    m = len(f)
    n = int(f.max()) + 1 if m else 1
    ok = ~collapsed(f)
    a = f[ok]
    b = np.roll(a, -1, axis=1)
    forward = (a < b).ravel()
    keys = np.minimum(a, b).ravel() * np.int64(n)
    keys += np.maximum(a, b).ravel()
    del a, b  # the temporaries go as soon as they are used: this runs beside the broad phase
    order = stable_order(keys, n * n)
    sorted_keys = keys[order]
    del keys
    h = len(sorted_keys)
    new = np.ones(h, bool)
    new[1:] = sorted_keys[1:] != sorted_keys[:-1]
    starts = np.flatnonzero(new)
    ukeys = sorted_keys[starts]
    del sorted_keys
    edge_of = np.cumsum(new) - 1
    del new
    count = np.diff(np.append(starts, h))
    face_edge = np.full((m, 3), -1, np.int64)
    per_half = np.empty(h, np.int64)
    per_half[order] = edge_of
    face_edge[ok] = per_half.reshape(-1, 3)
    del per_half
    return EdgeTable(
        vertices=np.stack([ukeys // n, ukeys % n], axis=1),
        count=count.astype(np.int64),
        face_edge=face_edge,
        half_face=np.repeat(np.flatnonzero(ok), 3)[order],
        half_edge=edge_of,
        half_forward=forward[order],
    )


def face_adjacency(table: EdgeTable, manifold_only: bool = True) -> np.ndarray:
    """Pairs of faces that share an edge.

    Parameters
    ----------
    table : EdgeTable
        From :func:`edges`.
    manifold_only : bool
        ``True``: one pair per manifold edge.  ``False``: also link the faces around every
        non-manifold edge (as a chain, enough for connectivity).

    Returns
    -------
    (p, 2) int64 array
        Face pairs, the smaller index first.
    """
    he, hf = table.half_edge, table.half_face
    same = he[1:] == he[:-1]  # consecutive half-edges on one edge
    if manifold_only:
        same &= table.count[he[1:]] == 2
    i = np.flatnonzero(same)
    pairs = np.stack([hf[i], hf[i + 1]], axis=1)
    pairs = pairs[pairs[:, 0] != pairs[:, 1]]
    return np.sort(pairs, axis=1)


def components(n_faces: int, pairs: np.ndarray) -> tuple[int, np.ndarray]:
    """Connected components of faces linked by ``pairs``.

    Parameters
    ----------
    n_faces : int
        Number of faces.
    pairs : (p, 2) int array
        Linked faces, e.g. from :func:`face_adjacency`.

    Returns
    -------
    n_components : int
        Number of components.
    label : (n_faces,) int64 array
        Component of each face (numbered by smallest face index).
    """
    pairs = np.asarray(pairs, np.int64).reshape(-1, 2)
    label = kernels(n_faces).component_labels(
        n_faces, np.ascontiguousarray(pairs[:, 0]), np.ascontiguousarray(pairs[:, 1])
    )
    return int(label.max()) + 1 if n_faces else 0, label


def degenerate_faces(
    vertices: np.ndarray,
    faces: np.ndarray,
    tol: float = WELD_TOL,
    faces_welded: np.ndarray | None = None,
    zero_area: bool = False,
) -> np.ndarray:
    """(m,) bool: faces of (near-)zero area.

    A face is degenerate when its smallest altitude ``2 A / l_max`` (``A`` area, ``l_max``
    longest side) is at most ``tol`` times the bounding-box diagonal — the triangle is a
    segment or a point up to the weld tolerance — or when welding collapsed two corners.
    Using the altitude rather than the area keeps the test independent of the triangle's size
    and of the model's scale.

    Parameters
    ----------
    vertices : (n, 3) float array
        Vertex coordinates.
    faces : (m, 3) int array
        Vertex indices of each triangle.
    tol : float
        Fraction of the bounding-box diagonal (default :data:`WELD_TOL`).
    faces_welded : (m, 3) int array, optional
        The ``faces_welded`` output of :func:`weld`, to also flag collapsed faces.
    zero_area : bool
        Also flag the faces of zero area as :attr:`meshvis.soup.Soup.areas` computes it
        (the same arithmetic, without caching the soup's triangles).

    Returns
    -------
    (m,) bool array
        True for the degenerate faces.
    """
    v = np.asarray(vertices, np.float64)
    f = np.asarray(faces, np.int64).reshape(-1, 3)
    if len(f) == 0:
        return np.zeros(0, bool)
    lo, hi = _bounds(v, f)  # corners shifted by lo: small magnitudes before the cross product
    flat, zero = kernels(len(f)).flat_faces(v, f, lo, tol * float(np.linalg.norm(hi - lo)))
    out = flat | zero if zero_area else flat
    if faces_welded is not None:
        out |= collapsed(faces_welded)
    return out


def duplicate_faces(faces_welded: np.ndarray) -> np.ndarray:
    """Index of the first face with the same welded vertex set, whatever the winding.

    Parameters
    ----------
    faces_welded : (m, 3) int array
        The ``faces_welded`` output of :func:`weld`.

    Returns
    -------
    first : (m,) int64
        ``first[i] == i`` for a face seen for the first time; ``first[i] < i`` when face ``i``
        repeats face ``first[i]`` (same corners, either winding).  ``first != arange(m)``
        marks the redundant copies.
    """
    f = np.sort(np.asarray(faces_welded, np.int64).reshape(-1, 3), axis=1)
    m = len(f)
    n = int(f.max()) + 1 if m else 1
    if n**3 < 2**63:  # one int64 key per sorted corner triple: one stable sort, not a lexsort
        key = (f[:, 0] * np.int64(n) + f[:, 1]) * np.int64(n) + f[:, 2]
        order = stable_order(key, n**3)
    else:
        order = np.lexsort((np.arange(m), f[:, 2], f[:, 1], f[:, 0]))
    s = f[order]
    new = np.ones(m, bool)
    new[1:] = np.any(s[1:] != s[:-1], axis=1)
    group_first = order[np.flatnonzero(new)]
    first = np.empty(m, np.int64)
    first[order] = group_first[np.cumsum(new) - 1]
    return first
