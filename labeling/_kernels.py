"""Compiled kernels (numba) of the labeling's 2D geometry.

:mod:`meshvis.labeling.geometry2d` answers its questions for whole arrays; its pairwise
matrices call :func:`meet_matrix` and :func:`hits_matrix` here, because the frames of a
live view test a few dozen leaders at a time, where numpy's per-call cost outweighs the
arithmetic.  The comparisons are those of the numpy predicates, so the answers are the
same.  :func:`scanline_mask` rasterises the internal area for
:func:`meshvis.labeling.internal_area.internal_area`.
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


@numba.njit(**_JIT)
def scanline_mask(left, right, xc):
    """Pixels between ``left[r]`` and ``right[r]`` on every row, and their summed-area table.

    ``xc`` (w,) are the pixel centres of a row; a NaN bound leaves its row empty.
    Returns mask (h, w) bool and integral (h + 1, w + 1) int32 (``integral[r, c]`` = pixels
    of the mask above row r and left of column c).
    """
    h, w = left.shape[0], xc.shape[0]
    mask = np.zeros((h, w), np.bool_)
    integral = np.zeros((h + 1, w + 1), np.int32)
    for r in range(h):
        run = 0
        for c in range(w):
            inside = xc[c] >= left[r] and xc[c] <= right[r]  # NaN compares False
            mask[r, c] = inside
            run += 1 if inside else 0
            integral[r + 1, c + 1] = integral[r, c + 1] + run
    return mask, integral


@numba.njit(**_JIT)
def lower_f4_near(px, py, d_a, w4, ax, ay, done, static, cell, f4, f4w, S, acc, grid, order, start):
    """Lower f4 (Eq. 4-5) of the candidates within ``d_a`` of the new anchor (px, py), in place.

    For :func:`meshvis.labeling.greedy.greedy_layout`: the candidates come from the bucket
    grid (``grid`` = (cell size, x0, y0, nx, ny); ``order``, ``start`` as in its
    ``_Buckets``) in the same order; the sums ``S`` (flat) of their (area, endpoint) cells
    take the change, summed per cell first (in ``acc``, zero on entry and on return) as
    ``np.bincount`` does.
    """
    size, x0, y0, nx, ny = grid[0], int(grid[1]), int(grid[2]), int(grid[3]), int(grid[4])
    i0 = max(int(math.floor((px - d_a) / size)) - x0, 0)
    i1 = min(int(math.floor((px + d_a) / size)) - x0, nx - 1)
    j0 = max(int(math.floor((py - d_a) / size)) - y0, 0)
    j1 = min(int(math.floor((py + d_a) / size)) - y0, ny - 1)
    if i0 > i1 or j0 > j1:
        return
    touched = []
    for j in range(j0, j1 + 1):
        for q in range(start[j * nx + i0], start[j * nx + i1 + 1]):
            c = order[q]
            if done[c]:
                continue
            new = min(math.hypot(ax[c] - px, ay[c] - py) / d_a, 1.0)
            new = min(f4[c], new)
            if not new < f4[c]:
                continue
            new_w = new**w4 if w4 != 1 else new
            if acc[cell[c]] == 0.0:
                touched.append(cell[c])
            acc[cell[c]] += static[c] * (new_w - f4w[c])
            f4[c] = new
            f4w[c] = new_w
    for t in touched:
        S[t] += acc[t]
        acc[t] = 0.0


@numba.njit(**_JIT)
def radial_image(mask, ri, ci, oy, ox, H, W):
    """Nearest-boundary candidates of the image's pixels (for :func:`meshvis.labeling.candidates.leader_candidates`).

    ``mask`` (hb, wb): a window of the grid of ``A_I`` whose pixel (r, c) is the image's
    pixel (r + oy, c + ox), centre (c + ox + 0.5, r + oy + 0.5); ``ri``, ``ci`` (hb, wb):
    the window row and column of each inside pixel's nearest outside pixel ``q`` (the
    EDT's feature transform).  The endpoint is ``q`` moved half a pixel back along the
    mean unit direction of all the inside pixels that share ``q`` (summed in row-major
    order, as ``np.bincount`` does); the leader runs from the pixel's centre to it.
    Returns, over the (H, W) image: endpoint x, y and leader length (NaN outside),
    endpoint id (-1 outside; the ids number the endpoints of the image's pixels in
    row-major order of ``q``), then the endpoints (n_e, 2) and the longest leader of the
    window (-inf when nothing is inside).
    """
    hb, wb = mask.shape
    sx, sy = np.zeros((hb, wb)), np.zeros((hb, wb))
    dense = np.full((hb, wb), -1, np.int64)
    for r in range(hb):
        for c in range(wb):
            if mask[r, c]:
                qr, qc = ri[r, c], ci[r, c]
                dx, dy = float(qc - c), float(qr - r)
                norm = max(math.hypot(dx, dy), 1e-12)
                sx[qr, qc] += dx / norm
                sy[qr, qc] += dy / norm
                if 0 <= r + oy < H and 0 <= c + ox < W:
                    dense[qr, qc] = 0
    # the endpoints of the image's pixels, numbered in row-major order of q
    n_e = 0
    for r in range(hb):
        for c in range(wb):
            if dense[r, c] == 0:
                dense[r, c] = n_e
                n_e += 1
    ex, ey = np.full((H, W), np.nan), np.full((H, W), np.nan)
    length = np.full((H, W), np.nan)
    eid = np.full((H, W), -1, np.int64)
    endpoints = np.empty((n_e, 2))
    d_max = -np.inf
    for r in range(hb):
        for c in range(wb):
            if not mask[r, c]:
                continue
            qr, qc = ri[r, c], ci[r, c]
            mx, my = sx[qr, qc], sy[qr, qc]
            mn = max(math.hypot(mx, my), 1e-12)
            x = (qc + ox + 0.5) - 0.5 * (mx / mn)
            y = (qr + oy + 0.5) - 0.5 * (my / mn)
            d = math.hypot(x - (c + ox + 0.5), y - (r + oy + 0.5))
            d_max = max(d_max, d)
            i, j = r + oy, c + ox
            if 0 <= i < H and 0 <= j < W:
                k = dense[qr, qc]
                ex[i, j], ey[i, j], length[i, j], eid[i, j] = x, y, d, k
                endpoints[k, 0], endpoints[k, 1] = x, y
    return ex, ey, length, eid, endpoints, d_max


@numba.njit(**_JIT)
def _on_silhouette(ids, r, c):
    """Pixel (r, c) lies on the border of ``ids`` or has a 4-neighbour with another id."""
    h, w = ids.shape
    if r == 0 or c == 0 or r == h - 1 or c == w - 1:
        return True
    v = ids[r, c]
    return v != ids[r - 1, c] or v != ids[r + 1, c] or v != ids[r, c - 1] or v != ids[r, c + 1]


@numba.njit(**_JIT)
def own_silhouette_distance(ids):
    """Distance of every pixel of ``ids`` (h, w) to the silhouette of its own area, plus 1.

    For :func:`meshvis.labeling.membership.silhouette_distance`: a silhouette pixel (one on
    the border, or with a 4-neighbour of another id) gets 1, every other pixel 1 + the
    Euclidean distance to the nearest silhouette pixel; background (id < 0) gets 0.  The
    exact squared distances are found in integers by the separable lower envelope of
    parabolas (Felzenszwalb and Huttenlocher), column pass then row pass, so the square
    roots are those of an exact EDT.
    """
    h, w = ids.shape
    g = np.empty((h, w), np.int64)  # vertical distance to the nearest silhouette pixel
    for c in range(w):
        last = -1
        for r in range(h):
            if _on_silhouette(ids, r, c):
                last = r
                g[r, c] = 0
            else:
                g[r, c] = r - last if last >= 0 else h + w
        last = -1
        for r in range(h - 1, -1, -1):
            if g[r, c] == 0:
                last = r
            elif last >= 0:
                g[r, c] = min(g[r, c], last - r)
    out = np.zeros((h, w))
    f = np.empty(w, np.int64)
    v = np.empty(w, np.int64)
    z = np.empty(w + 1)
    for r in range(h):
        for c in range(w):
            f[c] = g[r, c] * g[r, c]
        k = 0
        v[0] = 0
        z[0], z[1] = -np.inf, np.inf
        for q in range(1, w):
            fq = f[q] + q * q
            while True:
                p = v[k]
                s = (fq - (f[p] + p * p)) / (2.0 * (q - p))
                if s <= z[k]:
                    k -= 1
                else:
                    break
            k += 1
            v[k] = q
            z[k], z[k + 1] = s, np.inf
        k = 0
        for q in range(w):
            while z[k + 1] < q:
                k += 1
            if ids[r, q] >= 0:
                p = v[k]
                out[r, q] = math.sqrt(float((q - p) * (q - p) + f[p])) + 1.0
    return out
