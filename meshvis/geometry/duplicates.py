"""Surfaces stored twice with opposite winding: double-sided by duplication.

Game and web assets often make a sheet visible from both sides by storing each of its
triangles twice, once per winding, so that back-face culling shows one copy from either
side.  Such a pair is one piece of geometry with both orientations present on purpose:
:func:`meshvis.orient` keeps both copies as they are, and
:func:`meshvis.remove_interior` keeps only the copy facing the viewer where one side of the
sheet is hidden.

>>> import numpy as np
>>> pairs = opposite_copies(np.array([[0, 1, 2], [0, 2, 1], [1, 2, 0], [2, 3, 1]]))
>>> pairs.tolist()
[[0, 1]]
"""

from __future__ import annotations

import numpy as np

from meshvis.geometry.adjacency import duplicate_faces


def winding_parity(faces_welded: np.ndarray) -> np.ndarray:
    """(m,) bool: the face lists its corners in the cyclic order of its sorted corners.

    Two faces with the same corners have opposite winding exactly when their parities
    differ.
    """
    f = np.asarray(faces_welded, np.int64).reshape(-1, 3)
    a, b, c = f[:, 0], f[:, 1], f[:, 2]
    # even permutations of (lo, mid, hi) are its cyclic rotations
    return ((a < b) & (b < c)) | ((b < c) & (c < a)) | ((c < a) & (a < b))


def opposite_copies(faces_welded: np.ndarray) -> np.ndarray:
    """Pairs of faces with the same welded corners and opposite winding.

    Within a group of coincident faces, faces of one winding are paired with faces of the
    other in index order; a face left over (more copies of one winding) is in no pair.

    Parameters
    ----------
    faces_welded : (m, 3) int64
        Welded faces (:func:`meshvis.geometry.adjacency.weld`)

    Returns
    -------
    (k, 2) int64
        Face pairs ``(i, j)``, ``i < j``, sorted by ``i``

    Examples
    --------
    >>> opposite_copies(np.array([[0, 1, 2], [2, 1, 0]])).tolist()
    [[0, 1]]
    """
    f = np.asarray(faces_welded, np.int64).reshape(-1, 3)
    m = len(f)
    if m == 0:
        return np.zeros((0, 2), np.int64)
    group = duplicate_faces(f)
    parity = winding_parity(f)
    repeated = np.bincount(group, minlength=m)[group] > 1
    idx = np.flatnonzero(repeated)
    pairs = []
    # rank of each face among the faces of its group with its winding: the r-th face of one
    # winding pairs with the r-th of the other
    for p in (True, False):
        sel = idx[parity[idx] == p]
        order = np.lexsort((sel, group[sel]))
        sel = sel[order]
        start = np.searchsorted(group[sel], group[sel], side="left")
        pairs.append((group[sel], np.arange(len(sel)) - start, sel))
    (g1, r1, f1), (g0, r0, f0) = pairs
    key1 = g1 * m + r1
    key0 = g0 * m + r0
    common, i1, i0 = np.intersect1d(key1, key0, return_indices=True)
    out = np.sort(np.stack([f1[i1], f0[i0]], axis=1), axis=1)
    return out[np.argsort(out[:, 0], kind="stable")]


def in_opposite_copy(faces_welded: np.ndarray) -> np.ndarray:
    """(m,) bool: the face is one copy of a double-sided pair (:func:`opposite_copies`)."""
    out = np.zeros(len(faces_welded), bool)
    out[opposite_copies(faces_welded).ravel()] = True
    return out


def hidden_copies(pairs: np.ndarray, outside: np.ndarray) -> np.ndarray:
    """Copies of double-sided pairs that face a hidden side while the other copy faces a seen one.

    Copy ``i`` of a pair ``(i, j)`` shows its front on the side where ``j`` shows its back.
    Where exactly one side of the pair's sheet is outside (by either copy's labels), the
    copy whose front faces the other, hidden side is returned; pairs seen from both sides
    or from none are left alone.

    Parameters
    ----------
    pairs : (k, 2) int64
        From :func:`opposite_copies`
    outside : (m, 2) float or bool
        Per face and side (0 front, 1 back): outside when > 0

    Returns
    -------
    (m,) bool
        The copies to drop

    Examples
    --------
    >>> hidden_copies(np.array([[0, 1]]), np.array([[1.0, 0.0], [0.0, 1.0]])).tolist()
    [False, True]
    """
    out = np.zeros(len(outside), bool)
    if len(pairs) == 0:
        return out
    i, j = pairs[:, 0], pairs[:, 1]
    seen = np.asarray(outside) > 0
    a = seen[i, 0] | seen[j, 1]  # the side i's front faces
    b = seen[i, 1] | seen[j, 0]  # the side j's front faces
    out[j[a & ~b]] = True
    out[i[b & ~a]] = True
    return out
