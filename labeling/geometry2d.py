"""Vectorised 2D predicates on segments and axis-aligned boxes (screen pixels).

Used both to place label boxes and to measure layouts, so that the placement and the
metrics agree on what "overlap" and "crossing" mean.  Boxes are ``(x0, y0, x1, y1)`` with
``x0 <= x1``, ``y0 <= y1``; segments are ``(2, 2)`` arrays ``[[x0, y0], [x1, y1]]``.
"""

from __future__ import annotations

import numpy as np

from ._kernels import hits_matrix, meet_matrix


def boxes_overlap(a: np.ndarray, b: np.ndarray, gap: float = 0.0) -> np.ndarray:
    """(n, m) True where box ``a[i]`` grown by ``gap`` and box ``b[j]`` share interior area."""
    a = np.asarray(a, np.float64).reshape(-1, 4)[:, None, :]
    b = np.asarray(b, np.float64).reshape(-1, 4)[None, :, :]
    return (
        (a[..., 0] - gap < b[..., 2])
        & (b[..., 0] < a[..., 2] + gap)
        & (a[..., 1] - gap < b[..., 3])
        & (b[..., 1] < a[..., 3] + gap)
    )


def overlap_area(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """(n, m) intersection area of boxes ``a[i]`` and ``b[j]``."""
    a = np.asarray(a, np.float64).reshape(-1, 4)[:, None, :]
    b = np.asarray(b, np.float64).reshape(-1, 4)[None, :, :]
    w = np.minimum(a[..., 2], b[..., 2]) - np.maximum(a[..., 0], b[..., 0])
    h = np.minimum(a[..., 3], b[..., 3]) - np.maximum(a[..., 1], b[..., 1])
    return np.clip(w, 0, None) * np.clip(h, 0, None)


def segments_intersect(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """(n, m) True where closed segment ``a[i]`` meets closed segment ``b[j]`` (touching counts).

    Pairs whose bounding boxes are apart are rejected first; the orientation tests (signs
    of cross products, then the collinear touching cases) run on the remaining pairs only.

    Parameters
    ----------
    a : (n, 2, 2) float
        Segments, each as its two end points.
    b : (m, 2, 2) float
        Segments, each as its two end points.

    Examples
    --------
    >>> a = np.array([[[0, 0], [2, 2]]]); b = np.array([[[0, 2], [2, 0]], [[3, 3], [4, 4]]])
    >>> segments_intersect(a, b).tolist()
    [[True, False]]
    """
    a = np.ascontiguousarray(a, np.float64).reshape(-1, 2, 2)
    b = np.ascontiguousarray(b, np.float64).reshape(-1, 2, 2)
    return meet_matrix(a, b)


def segment_hits_box(seg: np.ndarray, boxes: np.ndarray, shrink: float = 0.0) -> np.ndarray:
    """(n, m) True where segment ``seg[i]`` passes through the interior of box ``boxes[j]``.

    The box is shrunk by ``shrink`` on every side first, so a segment that ends on (or
    grazes) a box edge does not count.  Pairs whose bounding boxes do not overlap are
    rejected first; the slab test (Liang-Barsky) runs on the others.

    Parameters
    ----------
    seg : (n, 2, 2), boxes : (m, 4), shrink : float

    Examples
    --------
    >>> seg = np.array([[[0, 1], [4, 1]]]); boxes = np.array([[1, 0, 2, 2], [1, 1, 2, 2]])
    >>> segment_hits_box(seg, boxes).tolist()  # the second box's edge is only grazed
    [[True, False]]
    """
    seg = np.ascontiguousarray(seg, np.float64).reshape(-1, 2, 2)
    boxes = np.ascontiguousarray(boxes, np.float64).reshape(-1, 4)
    return hits_matrix(seg, boxes, float(shrink))


def polyline_length(points: np.ndarray) -> float:
    """Length of a polyline ``(k, 2)``."""
    points = np.asarray(points, np.float64).reshape(-1, 2)
    return float(np.linalg.norm(np.diff(points, axis=0), axis=1).sum())
