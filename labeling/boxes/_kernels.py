"""Compiled kernel of the silhouette layout's candidate search (numba).

The search wants the cheapest candidate box that is valid (no model pixel, box, leader
under it; its leader crosses no box, leader or path) and blocks no later label's ray.
Testing every candidate with array operations costs as much for the first valid one as
for the last; walking them in order of cost and stopping at the first that passes costs
a few tests per label.  The predicates are those of :mod:`meshvis.labeling.geometry2d`,
written for one pair at a time, with the same comparisons (so the same answers).
"""

from __future__ import annotations

import math

import numba
import numpy as np

_JIT = dict(cache=True, nogil=True, error_model="numpy")


@numba.njit(**_JIT)
def _hits_box(px, py, qx, qy, x0, y0, x1, y1):
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
def _meet(ax, ay, bx, by, cx, cy, dx, dy):
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
def _area_pixels(b, integral, pad):
    """Pixels of ``A_I`` under box b (``InternalArea.boxes_hit``)."""
    hp, wp = integral.shape[0] - 1, integral.shape[1] - 1
    c0 = int(min(max(math.ceil(b[0] - 0.5 + pad), 0), wp))
    c1 = int(min(max(math.floor(b[2] - 0.5 + pad) + 1, 0), wp))
    r0 = int(min(max(math.ceil(b[1] - 0.5 + pad), 0), hp))
    r1 = int(min(max(math.floor(b[3] - 0.5 + pad) + 1, 0), hp))
    c1, r1 = max(c1, c0), max(r1, r0)
    return integral[r1, c1] - integral[r0, c1] - integral[r1, c0] + integral[r0, c0]


@numba.njit(**_JIT)
def _box_free(b, integral, pad, pboxes, psegs, gap):
    if _area_pixels(b, integral, pad) != 0:
        return False
    for j in range(pboxes.shape[0]):
        q = pboxes[j]
        if b[0] - gap < q[2] and q[0] < b[2] + gap and b[1] - gap < q[3] and q[1] < b[3] + gap:
            return False
    for j in range(psegs.shape[0]):
        s = psegs[j]
        if _hits_box(s[0, 0], s[0, 1], s[1, 0], s[1, 1], b[0], b[1], b[2], b[3]):
            return False
    return True


@numba.njit(**_JIT)
def _leader_free(poly, pboxes, psegs, paths):
    for i in range(poly.shape[0] - 1):
        ax, ay, bx, by = poly[i, 0], poly[i, 1], poly[i + 1, 0], poly[i + 1, 1]
        for j in range(pboxes.shape[0]):
            q = pboxes[j]
            if _hits_box(ax, ay, bx, by, q[0], q[1], q[2], q[3]):
                return False
        for j in range(psegs.shape[0]):
            s = psegs[j]
            if _meet(ax, ay, bx, by, s[0, 0], s[0, 1], s[1, 0], s[1, 1]):
                return False
        for j in range(paths.shape[0]):
            s = paths[j]
            if _meet(ax, ay, bx, by, s[0, 0], s[0, 1], s[1, 0], s[1, 1]):
                return False
    return True


@numba.njit(**_JIT)
def first_free(
    order, boxes, leader_of, leaders, cost, integral, pad, pboxes, psegs, paths, rays, gap, blocked
):
    """Walk the candidates in ``order`` (cheapest first) for :func:`.silhouette._cheapest`.

    Returns (the first valid candidate that blocks no ray, -1) or, when every valid one
    blocks a ray, (-1, the valid one of least ``cost + blocked * rays blocked``; -1 if none
    is valid).
    """
    status = np.zeros(leaders.shape[0], np.int8)  # 0 untested, 1 free, 2 blocked
    fallback, best = -1, np.inf
    for i in order:
        b = boxes[i]
        if not _box_free(b, integral, pad, pboxes, psegs, gap):
            continue
        lid = leader_of[i]
        if status[lid] == 0:
            status[lid] = 1 if _leader_free(leaders[lid], pboxes, psegs, paths) else 2
        if status[lid] == 2:
            continue
        n = 0
        for j in range(rays.shape[0]):
            r = rays[j]
            if _hits_box(r[0, 0], r[0, 1], r[1, 0], r[1, 1], b[0], b[1], b[2], b[3]):
                n += 1
        if n == 0:
            return i, -1
        c = cost[i] + blocked * n
        if c < best:
            best, fallback = c, i
    return -1, fallback
