"""Compiled kernel of the silhouette layout's candidate search (numba).

The search wants the cheapest candidate box that is valid (no model pixel, box, leader
under it; its leader crosses no box, leader or path) and blocks no later label's ray.
Testing every candidate with array operations costs as much for the first valid one as
for the last; walking them in order of cost and stopping at the first that passes costs
a few tests per label.  The predicates are those of :mod:`meshvis.labeling.geometry2d`,
written for one pair at a time (:mod:`meshvis.labeling._kernels`), with the same
comparisons (so the same answers).
"""

from __future__ import annotations

import math

import numba
import numpy as np

from .._kernels import hits_box as _hits_box
from .._kernels import meet as _meet

_JIT = dict(cache=True, nogil=True, error_model="numpy")


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


@numba.njit(**_JIT)
def _leaders_meet(anchors, ports, assign, i, j):
    a, b = anchors[i], ports[assign[i]]
    c, d = anchors[j], ports[assign[j]]
    return _meet(a[0], a[1], b[0], b[1], c[0], c[1], d[0], d[1])


@numba.njit(**_JIT)
def uncross_ports(anchors, ports, limit):
    """Swap the ports of crossing leaders ``anchor -> port`` (for :func:`.stacking.uncross`).

    The first crossing pair in row-major order is swapped, then only the two moved
    leaders are tested again.  Returns the port of each anchor and the number of swaps.
    """
    n = anchors.shape[0]
    assign = np.arange(n)
    x = np.zeros((n, n), np.bool_)
    for i in range(n):
        for j in range(i + 1, n):
            x[i, j] = x[j, i] = _leaders_meet(anchors, ports, assign, i, j)
    swaps = 0
    while swaps < limit:
        first_i, first_j = -1, -1
        for i in range(n):
            for j in range(i + 1, n):
                if x[i, j]:
                    first_i, first_j = i, j
                    break
            if first_i >= 0:
                break
        if first_i < 0:
            break
        assign[first_i], assign[first_j] = assign[first_j], assign[first_i]
        swaps += 1
        for k in (first_i, first_j):
            for m in range(n):
                if m != k:
                    x[k, m] = x[m, k] = _leaders_meet(anchors, ports, assign, k, m)
    return assign, swaps


@numba.njit(**_JIT)
def radial_candidates(E, N, own, anchor, w, h, tier_step, clearance, n_t, below, size, centre, attach, costs):
    """The candidate lists of :func:`.silhouette._radial_candidates` in one pass.

    ``E``, ``N`` (e, 2): endpoints and their push-out directions; ``own``: the label's own
    endpoint; ``size`` = (W, H); ``centre``: last frame's box centre (NaN: none);
    ``attach`` (A, 2): attach points in half sizes; ``costs`` = (behind-port cost,
    behind-port cosine, outside-image cost, coherence cost).  Candidates are walked in
    (endpoint, tier, attach) order, with the arithmetic of the array version in the same
    order.  Returns boxes (K, 4), leaders (L, 3, 2), the leader of each box, cost, tier
    and endpoint move.
    """
    behind_cost, behind_cos, outside_cost, coherence_cost = costs
    n_e, n_a = E.shape[0], attach.shape[0]
    cap = n_e * n_t * n_a
    boxes = np.empty((cap, 4))
    cost = np.empty(cap)
    tiers = np.empty(cap, np.int64)
    shifts = np.empty(cap)
    lid = np.empty(cap, np.int64)
    leaders = np.empty((n_e * n_t, 3, 2))
    hw, hh = w / 2, h / 2
    base = math.hypot(own[0] - anchor[0], own[1] - anchor[1])
    follow = not math.isnan(centre[0]) and not math.isinf(centre[0])
    k = 0
    n_l = 0
    for ie in range(n_e):
        moved = math.hypot(E[ie, 0] - own[0], E[ie, 1] - own[1])
        longer = math.hypot(E[ie, 0] - anchor[0], E[ie, 1] - anchor[1]) - base
        bend = (h + longer) if moved > 0 else 0.0
        for it in range(n_t):
            push = clearance + it * tier_step
            px, py = E[ie, 0] + push * N[ie, 0], E[ie, 1] + push * N[ie, 1]
            first = True
            for ia in range(n_a):
                ox, oy = attach[ia, 0] * hw, attach[ia, 1] * hh
                along = (N[ie, 0] * ox + N[ie, 1] * oy) / math.hypot(ox, oy)
                c = (
                    it * tier_step
                    + bend
                    + ((1.0 - along) * h + (behind_cost if along <= behind_cos else 0.0))
                )
                if not c < below:
                    continue
                cx, cy = px + ox, py + oy
                x0, y0, x1, y1 = cx - hw, cy - hh, cx + hw, cy + hh
                c = c + (outside_cost if (x0 < 0 or y0 < 0 or x1 > size[0] or y1 > size[1]) else 0.0)
                if follow:
                    c = c + coherence_cost * math.hypot(cx - centre[0], cy - centre[1])
                if not c < below:
                    continue
                if first:
                    leaders[n_l, 0, 0], leaders[n_l, 0, 1] = anchor[0], anchor[1]
                    leaders[n_l, 1, 0], leaders[n_l, 1, 1] = E[ie, 0], E[ie, 1]
                    leaders[n_l, 2, 0], leaders[n_l, 2, 1] = px, py
                    n_l += 1
                    first = False
                boxes[k, 0], boxes[k, 1], boxes[k, 2], boxes[k, 3] = x0, y0, x1, y1
                cost[k] = c
                tiers[k] = it
                shifts[k] = moved
                lid[k] = n_l - 1
                k += 1
    return boxes[:k], leaders[:n_l], lid[:k], cost[:k], tiers[:k], shifts[:k]
