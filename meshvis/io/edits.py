"""How a soup differs from the file it was read from.

Which input faces it still has, in which order, and which of them are turned over.

A reader stores a :class:`~meshvis.soup.SourceRecord` on the soup; every face carries its
``origin`` (its index as read) through :meth:`Soup.subset` and :meth:`Soup.flipped`.  A
writer of the same format calls :func:`face_edits`: when the soup still uses the vertices
as read and every face is an input face, possibly turned over, the writer edits the input
file instead of rebuilding it (only face data changes).  Otherwise the answer is None and
the writer writes the soup from scratch.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from meshvis.soup import Soup, SourceRecord


@dataclass(eq=False)
class FaceEdits:
    """The faces of a soup in terms of its source file.

    Parameters
    ----------
    record : SourceRecord
        The source record of the soup.
    origin : (m,) int64
        Input face of every face of the soup, in the soup's order.
    flipped : (m,) bool
        Whether that face is turned over relative to the input.
    """

    record: SourceRecord
    origin: np.ndarray
    flipped: np.ndarray

    @property
    def unchanged(self) -> bool:
        """True when the soup has exactly the input faces, in input order, none turned over."""
        m0 = len(self.record.faces)
        return (
            len(self.origin) == m0
            and bool(np.array_equal(self.origin, np.arange(m0)))
            and not self.flipped.any()
        )

    def kept_count(self) -> np.ndarray:
        """(m0,) how many times each input face occurs in the soup."""
        return np.bincount(self.origin, minlength=len(self.record.faces))

    def polygons(self, polygon: np.ndarray, n_polygons: int) -> tuple[np.ndarray, np.ndarray]:
        """Which input polygons can be written back whole.

        Parameters
        ----------
        polygon : (m0,) int64
            Input polygon of every input triangle.
        n_polygons : int
            Number of input polygons (those without triangles included).

        Returns
        -------
        whole : (n_polygons,) bool
            Every triangle of the polygon occurs exactly once and all are turned over or
            none: the polygon is written as one polygon.  True for polygons without
            triangles (records the reader skipped), which are written as they were.
        turned : (n_polygons,) bool
            Whole and turned over: written with its corners in reverse order.
        """
        m0 = len(self.record.faces)
        n_tri = np.bincount(polygon, minlength=n_polygons)
        once = np.bincount(polygon, weights=self.kept_count() == 1, minlength=n_polygons) == n_tri
        flips = np.bincount(self.origin, weights=self.flipped, minlength=m0)
        n_flip = np.bincount(polygon, weights=flips, minlength=n_polygons)
        whole = once & ((n_flip == 0) | (n_flip == n_tri))
        return whole, whole & (n_flip > 0)


def face_edits(soup: Soup, formats: tuple[str, ...]) -> FaceEdits | None:
    """The soup as edits of its source file, or None when it cannot be written that way.

    Parameters
    ----------
    soup : Soup
    formats : tuple of str
        Source formats the calling writer can edit.

    Returns
    -------
    FaceEdits or None
        None when the soup has no source record of one of ``formats``, when its vertices
        are not the vertices as read, or when a face is not an input face (in any
        rotation, either winding).
    """
    rec = soup.source
    if rec is None or rec.format not in formats:
        return None
    if soup.vertices is not rec.vertices:
        if soup.vertices.shape != rec.vertices.shape or not np.array_equal(soup.vertices, rec.vertices):
            return None
    origin = soup.origin
    if len(origin) and (origin.min() < 0 or origin.max() >= len(rec.faces)):
        return None
    orig = rec.faces[origin]
    cur = soup.faces
    same = np.zeros(len(cur), bool)
    turned = np.zeros(len(cur), bool)
    for r in range(3):
        same |= (np.roll(orig, -r, axis=1) == cur).all(axis=1)
        turned |= (np.roll(orig[:, ::-1], -r, axis=1) == cur).all(axis=1)
    if not (same | turned).all():
        return None
    return FaceEdits(rec, origin, turned & ~same)


@dataclass(eq=False)
class VertexSplit:
    """How the vertices of turned faces get turned shading normals.

    A vertex used only by turned faces keeps its row and has its normal negated; a vertex
    used by turned and unturned faces is copied (appended after the input's rows) with the
    normal negated, and the turned faces' corners point at the copy.

    Parameters
    ----------
    rows : (n + s,) int64
        Input row of every output vertex: ``0 .. n-1``, then the ``s`` copied rows.
    negate : (n + s,) bool
        Output vertices whose normal is turned.
    indices : (k,) int64
        The corner indices with the turned corners moved to the copies.
    not_split : int
        Shared vertices left without a copy because ``limit`` did not allow it.
    """

    rows: np.ndarray
    negate: np.ndarray
    indices: np.ndarray
    not_split: int = 0


def split_turned_vertices(
    indices: np.ndarray,
    corner_turned: np.ndarray,
    n_vertices: int,
    *,
    valid: np.ndarray | None = None,
    limit: int | None = None,
) -> VertexSplit:
    """Plan the vertex copies and normal turns of a repair that turned faces over.

    Parameters
    ----------
    indices : (k,) int
        Vertex index of every face corner, as written.
    corner_turned : (k,) bool
        Whether the corner's face is turned over (and its normals are to be turned).
    n_vertices : int
        Number of input vertices.
    valid : (k,) bool, optional
        Corners whose index refers to a vertex (others are left as they are).
    limit : int, optional
        Largest vertex index the file can store: no copy is made when copies would pass it.

    Returns
    -------
    VertexSplit

    Examples
    --------
    >>> s = split_turned_vertices(np.array([0, 1, 2, 2, 1, 3]), np.repeat([False, True], 3), 4)
    >>> s.rows.tolist(), s.negate.tolist(), s.indices.tolist()
    ([0, 1, 2, 3, 1, 2], [False, False, False, True, True, True], [0, 1, 2, 5, 4, 3])
    """
    idx = np.asarray(indices, np.int64)
    ok = np.ones(len(idx), bool) if valid is None else np.asarray(valid, bool)
    safe = np.where(ok, idx, 0)
    turned_use = np.bincount(idx[ok & corner_turned], minlength=n_vertices)[:n_vertices] > 0
    kept_use = np.bincount(idx[ok & ~corner_turned], minlength=n_vertices)[:n_vertices] > 0
    split = np.flatnonzero(turned_use & kept_use)
    not_split = 0
    if limit is not None and len(split) and n_vertices + len(split) - 1 > limit:
        not_split, split = len(split), split[:0]
    copy_of = np.full(n_vertices, -1, np.int64)
    copy_of[split] = n_vertices + np.arange(len(split))
    move = ok & corner_turned & (copy_of[safe] >= 0)
    return VertexSplit(
        rows=np.concatenate([np.arange(n_vertices), split]),
        negate=np.concatenate([turned_use & ~kept_use, np.ones(len(split), bool)]),
        indices=np.where(move, copy_of[safe], idx),
        not_split=not_split,
    )


def negate_in_type(values: np.ndarray) -> np.ndarray:
    """``-values`` in their own type (integers clipped: -(-128) is 127 in a signed byte).

    Parameters
    ----------
    values : ndarray
        Normals or tangent signs, float or (normalised) integer.

    Returns
    -------
    ndarray
        The negated values, same dtype.
    """
    if values.dtype.kind == "f":
        return -values
    info = np.iinfo(values.dtype)
    return np.clip(-values.astype(np.int64), info.min, info.max).astype(values.dtype)
