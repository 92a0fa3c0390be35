"""Compiled 2D predicates (numba), one pair of segments or segment and box at a time.

:mod:`meshvis.labeling.geometry2d` answers the same questions for whole arrays; its
pairwise matrices call :func:`meet_matrix` and :func:`hits_matrix` here, because the
frames of a live view test a few dozen leaders at a time, where numpy's per-call cost
outweighs the arithmetic.  The comparisons are those of the numpy predicates, so the
answers are the same.
"""

from __future__ import annotations

import math

import numba
import numpy as np

_JIT = dict(cache=True, nogil=True, error_model="numpy")


@numba.njit(**_JIT)
def hits_box(px, py, qx, qy, x0, y0, x1, y1):
    """Segment p-q passes through the interior of box (x0, y0, x1, y1) (``segment_hits_box``)."""
    if not (min(px, qx) < x1 and x0 < max(px, qx) and min(py, qy) < y1 and y0 < max(py, qy)):
        return False
    t_enter, t_exit = 0.0, 1.0
    for p, d, lo, hi in ((px, qx - px, x0, x1), (py, qy - py, y0, y1)):
        if d == 0.0:
            if not (p > lo and p < hi):
                return False
            continue
        t1, t2 = (lo - p) / d, (hi - p) / d
        if math.isnan(t1) or math.isnan(t2):
            return False
        t_enter = max(t_enter, min(t1, t2))
        t_exit = min(t_exit, max(t1, t2))
    return t_enter < t_exit


@numba.njit(**_JIT)
def _orient(ax, ay, bx, by, cx, cy):
    v = (bx - ax) * (cy - ay) - (by - ay) * (cx - ax)
    return 1.0 if v > 0 else (-1.0 if v < 0 else 0.0)


@numba.njit(**_JIT)
def _on_segment(ax, ay, bx, by, cx, cy):
    return min(ax, bx) <= cx <= max(ax, bx) and min(ay, by) <= cy <= max(ay, by)


@numba.njit(**_JIT)
def meet(ax, ay, bx, by, cx, cy, dx, dy):
    """Closed segments a-b and c-d meet, touching included (``segments_intersect``)."""
    if not (
        min(ax, bx) <= max(cx, dx)
        and min(cx, dx) <= max(ax, bx)
        and min(ay, by) <= max(cy, dy)
        and min(cy, dy) <= max(ay, by)
    ):
        return False
    o1, o2 = _orient(ax, ay, bx, by, cx, cy), _orient(ax, ay, bx, by, dx, dy)
    o3, o4 = _orient(cx, cy, dx, dy, ax, ay), _orient(cx, cy, dx, dy, bx, by)
    if o1 * o2 < 0 and o3 * o4 < 0:
        return True
    return (
        (o1 == 0 and _on_segment(ax, ay, bx, by, cx, cy))
        or (o2 == 0 and _on_segment(ax, ay, bx, by, dx, dy))
        or (o3 == 0 and _on_segment(cx, cy, dx, dy, ax, ay))
        or (o4 == 0 and _on_segment(cx, cy, dx, dy, bx, by))
    )


@numba.njit(**_JIT)
def meet_matrix(a, b):
    """(n, m) :func:`meet` of segments ``a`` (n, 2, 2) and ``b`` (m, 2, 2)."""
    out = np.zeros((a.shape[0], b.shape[0]), np.bool_)
    for i in range(a.shape[0]):
        for j in range(b.shape[0]):
            out[i, j] = meet(
                a[i, 0, 0], a[i, 0, 1], a[i, 1, 0], a[i, 1, 1], b[j, 0, 0], b[j, 0, 1], b[j, 1, 0], b[j, 1, 1]
            )
    return out


@numba.njit(**_JIT)
def hits_matrix(seg, boxes, shrink):
    """(n, m) :func:`hits_box` of segments ``seg`` (n, 2, 2) and ``boxes`` (m, 4) shrunk by ``shrink``."""
    out = np.zeros((seg.shape[0], boxes.shape[0]), np.bool_)
    for i in range(seg.shape[0]):
        px, py, qx, qy = seg[i, 0, 0], seg[i, 0, 1], seg[i, 1, 0], seg[i, 1, 1]
        for j in range(boxes.shape[0]):
            x0, y0 = boxes[j, 0] + shrink, boxes[j, 1] + shrink
            x1, y1 = boxes[j, 2] - shrink, boxes[j, 3] - shrink
            out[i, j] = hits_box(px, py, qx, qy, x0, y0, x1, y1)
    return out
