"""Vectorised 2D predicates on segments and axis-aligned boxes (screen pixels).

Used both to place label boxes and to measure layouts, so that the placement and the
metrics agree on what "overlap" and "crossing" mean.  Boxes are ``(x0, y0, x1, y1)`` with
``x0 <= x1``, ``y0 <= y1``; segments are ``(2, 2)`` arrays ``[[x0, y0], [x1, y1]]``.
"""

from __future__ import annotations

import numpy as np


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


def _orient(p: np.ndarray, q: np.ndarray, r: np.ndarray) -> np.ndarray:
    """Sign of the cross product (q - p) x (r - p)."""
    v = (q[..., 0] - p[..., 0]) * (r[..., 1] - p[..., 1]) - (q[..., 1] - p[..., 1]) * (r[..., 0] - p[..., 0])
    return np.sign(v)


def _on_segment(p: np.ndarray, q: np.ndarray, r: np.ndarray) -> np.ndarray:
    """For collinear p, q, r: True where r lies within the bounding box of segment pq."""
    return (
        (np.minimum(p[..., 0], q[..., 0]) <= r[..., 0])
        & (r[..., 0] <= np.maximum(p[..., 0], q[..., 0]))
        & (np.minimum(p[..., 1], q[..., 1]) <= r[..., 1])
        & (r[..., 1] <= np.maximum(p[..., 1], q[..., 1]))
    )


def _seg_bbox(seg: np.ndarray) -> np.ndarray:
    return np.concatenate([seg.min(axis=1), seg.max(axis=1)], axis=1)


def segments_intersect(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """(n, m) True where closed segment ``a[i]`` meets closed segment ``b[j]`` (touching counts).

    Pairs whose bounding boxes are apart are rejected first; the orientation tests run
    on the remaining pairs only.

    Parameters
    ----------
    a : (n, 2, 2) float
        Segments, each as its two end points.
    b : (m, 2, 2) float
        Segments, each as its two end points.
    """
    a = np.asarray(a, np.float64).reshape(-1, 2, 2)
    b = np.asarray(b, np.float64).reshape(-1, 2, 2)
    out = np.zeros((len(a), len(b)), bool)
    if len(a) == 0 or len(b) == 0:
        return out
    ba, bb = _seg_bbox(a), _seg_bbox(b)
    near = (
        (ba[:, None, 0] <= bb[None, :, 2])
        & (bb[None, :, 0] <= ba[:, None, 2])
        & (ba[:, None, 1] <= bb[None, :, 3])
        & (bb[None, :, 1] <= ba[:, None, 3])
    )
    i, j = np.nonzero(near)
    if len(i) == 0:
        return out
    p1, p2, q1, q2 = a[i, 0], a[i, 1], b[j, 0], b[j, 1]
    o1, o2 = _orient(p1, p2, q1), _orient(p1, p2, q2)
    o3, o4 = _orient(q1, q2, p1), _orient(q1, q2, p2)
    proper = (o1 * o2 < 0) & (o3 * o4 < 0)
    touch = (
        ((o1 == 0) & _on_segment(p1, p2, q1))
        | ((o2 == 0) & _on_segment(p1, p2, q2))
        | ((o3 == 0) & _on_segment(q1, q2, p1))
        | ((o4 == 0) & _on_segment(q1, q2, p2))
    )
    out[i, j] = proper | touch
    return out


def segment_hits_box(seg: np.ndarray, boxes: np.ndarray, shrink: float = 0.0) -> np.ndarray:
    """(n, m) True where segment ``seg[i]`` passes through the interior of box ``boxes[j]``.

    The box is shrunk by ``shrink`` on every side first, so a segment that ends on (or
    grazes) a box edge does not count.  Pairs whose bounding boxes do not overlap are
    rejected first; the slab test (Liang-Barsky) runs on the others.
    """
    seg = np.asarray(seg, np.float64).reshape(-1, 2, 2)
    boxes = np.asarray(boxes, np.float64).reshape(-1, 4)
    out = np.zeros((len(seg), len(boxes)), bool)
    if len(seg) == 0 or len(boxes) == 0:
        return out
    lo_all = boxes[:, :2] + shrink
    hi_all = boxes[:, 2:] - shrink
    sb = _seg_bbox(seg)
    near = (
        (sb[:, None, 0] < hi_all[None, :, 0])
        & (lo_all[None, :, 0] < sb[:, None, 2])
        & (sb[:, None, 1] < hi_all[None, :, 1])
        & (lo_all[None, :, 1] < sb[:, None, 3])
    )
    i, j = np.nonzero(near)
    if len(i) == 0:
        return out
    p = seg[i, 0]
    d = seg[i, 1] - p
    lo, hi = lo_all[j], hi_all[j]
    with np.errstate(divide="ignore", invalid="ignore"):
        t1 = (lo - p) / d
        t2 = (hi - p) / d
    tmin = np.minimum(t1, t2)
    tmax = np.maximum(t1, t2)
    # a zero direction component: inside the slab -> no constraint, outside -> never
    zero = d == 0
    inside_slab = (p > lo) & (p < hi)
    tmin = np.where(zero, np.where(inside_slab, -np.inf, np.inf), tmin)
    tmax = np.where(zero, np.where(inside_slab, np.inf, -np.inf), tmax)
    t_enter = np.maximum(np.maximum(tmin[:, 0], tmin[:, 1]), 0.0)
    t_exit = np.minimum(np.minimum(tmax[:, 0], tmax[:, 1]), 1.0)
    out[i, j] = t_enter < t_exit
    return out


def polyline_length(points: np.ndarray) -> float:
    """Length of a polyline ``(k, 2)``."""
    points = np.asarray(points, np.float64).reshape(-1, 2)
    return float(np.linalg.norm(np.diff(points, axis=0), axis=1).sum())
