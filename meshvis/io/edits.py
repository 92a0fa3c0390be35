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
