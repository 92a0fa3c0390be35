"""A winding of every face that does not depend on the winding the face came in with.

A face's three corners can be listed in two cyclic orders, one per side that counts as its
front.  Work that draws random numbers per face side (rays from a side, sample points on
a triangle) gives a face turned over other numbers than the same face as it was, so its
result would depend on how the input happens to be wound.  Done on the *canonical*
winding instead (the corners sorted by position, :func:`canonical_faces`), the same
geometry gives the same numbers however it came in; the input's winding is then one bit
per face, :func:`turned_from_canonical`, kept for the rules that honour it.

>>> import numpy as np
>>> v = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0]])
>>> f = np.array([[0, 1, 2], [0, 2, 1], [2, 0, 1]])
>>> canonical_faces(v, f).tolist()  # by x, then y: (0, 0, 0), (0, 1, 0), (1, 0, 0)
[[0, 2, 1], [0, 2, 1], [0, 2, 1]]
>>> turned_from_canonical(v, f).tolist()
[True, False, True]
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from meshvis.soup import Soup

#: the three cyclic rotations of (0, 1, 2): the corner orders that keep a face's winding
_EVEN = np.array([[0, 1, 2], [1, 2, 0], [2, 0, 1]])


def _corner_order(vertices: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """(m, 3) positions in each face of its corners sorted by (x, y, z), then vertex index."""
    v = np.asarray(vertices, np.float64).reshape(-1, 3)
    f = np.asarray(faces, np.int64).reshape(-1, 3)
    rank = np.empty(len(v), np.int64)
    rank[np.lexsort((np.arange(len(v)), v[:, 2], v[:, 1], v[:, 0]))] = np.arange(len(v))
    return np.argsort(rank[f], axis=1, kind="stable")


def canonical_faces(vertices: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """Every face with its corners sorted by position: the same array whichever way it is wound.

    Corners are ordered by their coordinates (x first, then y, then z) and, where two
    corners share a position, by vertex index; so a face listed in any of its six corner
    orders comes out the same.

    Parameters
    ----------
    vertices : (n, 3) float
        Vertex positions.
    faces : (m, 3) int
        Corner indices per face.

    Returns
    -------
    (m, 3) int64
        The faces with their corners in canonical order.
    """
    f = np.asarray(faces, np.int64).reshape(-1, 3)
    return np.take_along_axis(f, _corner_order(vertices, f), axis=1)


def turned_from_canonical(vertices: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """(m,) bool: the face is wound the other way round than its :func:`canonical_faces`.

    Its front is then the canonical face's back.

    Parameters
    ----------
    vertices : (n, 3) float
        Vertex positions.
    faces : (m, 3) int
        Corner indices per face.

    Returns
    -------
    (m,) bool
        True where the corner order is an odd permutation of the canonical one.
    """
    order = _corner_order(vertices, faces)
    return ~(order[:, None, :] == _EVEN[None]).all(axis=2).any(axis=1)


def canonically_wound(soup: Soup) -> Soup:
    """``soup`` with every face's corners in canonical order (:func:`canonical_faces`).

    Per-corner UVs and colours follow their corners; everything else is kept.

    Parameters
    ----------
    soup : Soup
        The model.

    Returns
    -------
    Soup
        The same faces in the same order, each wound the canonical way.
    """
    order = _corner_order(soup.vertices, soup.faces)
    rows = np.arange(soup.n_faces)[:, None]
    return replace(
        soup,
        faces=soup.faces[rows, order],
        uv=None if soup.uv is None else soup.uv[rows, order],
        colors=None if soup.colors is None else soup.colors[rows, order],
    )
