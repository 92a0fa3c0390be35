"""Numba kernels of the graph cut's nodes and sampling.

* :func:`nearest_sample`, the hit snapping of :func:`meshvis.graphcut.sampling.snap_to_points`:
  the numpy version made one pass over all hits per sample point, with (hits,) temporaries
  for each term of the distance; this kernel keeps the running best per hit in registers.
* :func:`pushed_origins`, the ray origins of sample points that lie on a partner triangle
  (:func:`meshvis.graphcut.nodes.build_nodes`): the numpy version built (candidates, 3)
  arrays for every (sample point, partner) candidate and sorted them.

Both evaluate the same expressions in the same order as the numpy versions they replace,
with the same tie rules, so their output is bit for bit the same.
"""

from __future__ import annotations

import math

import numba
import numpy as np

from meshvis._threads import in_threads
from meshvis.rays._kernels import einsum_dot3


@numba.njit(cache=True, nogil=True, error_model="numpy")
def _nearest_sample(metric, u, v, count, sample_u, sample_v, best):  # pragma: no cover - compiled
    for k in range(len(u)):
        g0, g1, g2 = metric[k, 0], metric[k, 1], metric[k, 2]
        uk, vk = np.float64(u[k]), np.float64(v[k])
        row = count[k] - 1
        best_d2 = 0.0
        for s in range(count[k]):
            du, dv = uk - sample_u[row, s], vk - sample_v[row, s]
            d2 = g0 * du * du + 2 * g1 * du * dv + g2 * dv * dv
            if s == 0 or d2 < best_d2:
                best[k] = s
                best_d2 = d2


def nearest_sample(
    metric: np.ndarray,
    u: np.ndarray,
    v: np.ndarray,
    count: np.ndarray,
    sample_u: np.ndarray,
    sample_v: np.ndarray,
) -> np.ndarray:
    """(n,) index of the sample nearest to each hit under the face metric ``Δᵀ G Δ``.

    ``metric[k] = (e1·e1, e1·e2, e2·e2)`` of hit k's face; ``u, v`` the hits' barycentric
    coordinates; ``count[k]`` the samples of hit k's face; ``sample_u[c - 1], sample_v[c - 1]``
    the samples' of a face with ``c`` of them (the same pattern on every face of one count).
    Serial over slices of the hits, in threads (:func:`meshvis._threads.in_threads`).
    """
    best = np.zeros(len(u), np.int64)
    in_threads(
        lambda a, b: _nearest_sample(metric[a:b], u[a:b], v[a:b], count[a:b], sample_u, sample_v, best[a:b]),
        len(u),
    )
    return best


@numba.njit(cache=True, nogil=True, inline="always")
def _sign(x):  # pragma: no cover - compiled
    """``np.sign`` of one float (NaN stays NaN)."""
    if x > 0:
        return 1.0
    if x < 0:
        return -1.0
    return x  # 0.0, -0.0 or NaN, as np.sign gives them


@numba.njit(cache=True, nogil=True, inline="always")
def _max_nan(a, b):  # pragma: no cover - compiled
    """``np.maximum`` of two floats (a NaN wins)."""
    if a != a or b != b:
        return math.nan
    return a if a >= b else b


@numba.njit(cache=True, nogil=True, inline="always")
def _at_least(move, best):  # pragma: no cover - compiled
    """Whether ``move`` comes at or after ``best`` in numpy's sort order (NaN last)."""
    if move != move:
        return True
    if best != best:
        return False
    return move >= best


@numba.njit(cache=True, nogil=True, error_model="numpy")
def pushed_origins(
    pos,
    point_face,
    side,
    triangles,
    normals,
    flagged,
    start,
    partner,
    duplicate_first,
    point_start,
    offset,
    proximity,
    square_cos,
):  # pragma: no cover - compiled
    """(P, 3) origins of :func:`meshvis.graphcut.nodes._pushed_origins` on one side.

    The sample points of flagged face ``flagged[q]`` are ``point_start[q] .. point_start[q + 1] - 1``.

    The partners of face ``f`` are ``partner[start[f] : start[f + 1]]``, in the numpy
    version's order (the pairs, then the pairs reversed); a copy of a face (``duplicate_first[f]
    != f``) also meets the partners of its group's first face (but itself).  Every sample
    point of a flagged face is tested against its partners; among those it lies on, the
    one with the furthest move wins, the last one on ties (the numpy version's stable sort).
    """
    n_points = len(pos)
    sgn = 1.0 if side == 0 else -1.0
    origin = np.empty((n_points, 3))
    ns = np.empty((n_points, 3))
    for k in range(n_points):
        for c in range(3):
            ns[k, c] = normals[point_face[k], c] * sgn
            origin[k, c] = pos[k, c] + offset * ns[k, c]
    best_move = np.zeros(n_points)
    best_orient = np.zeros(n_points)
    best_g = np.full(n_points, -1, np.int64)
    for q in range(len(flagged)):
        f = flagged[q]
        r = duplicate_first[f]
        for own in range(2):
            src = f if own == 0 else r
            if own == 1 and r == f:
                break
            for e in range(start[src], start[src + 1]):
                gg = partner[e]
                if own == 1 and gg == f:
                    continue
                _push_past(
                    gg,
                    point_start[q],
                    point_start[q + 1] - point_start[q],
                    pos,
                    ns,
                    triangles,
                    normals,
                    proximity,
                    offset,
                    square_cos,
                    best_move,
                    best_orient,
                    best_g,
                )
    for k in range(n_points):
        gg = best_g[k]
        if gg < 0:
            continue
        step = best_orient[k] * best_move[k]
        for c in range(3):
            origin[k, c] = (pos[k, c] + step * normals[gg, c]) + offset * ns[k, c]
    return origin


@numba.njit(cache=True, nogil=True, error_model="numpy")
def _push_past(
    gg,
    first,
    samples,
    pos,
    ns,
    triangles,
    normals,
    proximity,
    offset,
    square_cos,
    best_move,
    best_orient,
    best_g,
):  # pragma: no cover - compiled
    """Points ``first .. first + samples - 1`` lying on partner ``gg``: keep its move where it is the furthest."""
    n0, n1, n2 = normals[gg, 0], normals[gg, 1], normals[gg, 2]
    a0, a1, a2 = triangles[gg, 0, 0], triangles[gg, 0, 1], triangles[gg, 0, 2]
    v00, v01, v02 = triangles[gg, 1, 0] - a0, triangles[gg, 1, 1] - a1, triangles[gg, 1, 2] - a2
    v10, v11, v12 = triangles[gg, 2, 0] - a0, triangles[gg, 2, 1] - a1, triangles[gg, 2, 2] - a2
    d00 = einsum_dot3(v00, v01, v02, v00, v01, v02)
    d01 = einsum_dot3(v00, v01, v02, v10, v11, v12)
    d11 = einsum_dot3(v10, v11, v12, v10, v11, v12)
    den = d00 * d11 - d01 * d01
    ok = den > 0
    if not ok:
        den = 1.0
    scale = math.sqrt(_max_nan(d00, d11))
    t = proximity / (scale if scale > 0 else 1.0)
    for q in range(samples):
        pt = first + q
        p0, p1, p2 = pos[pt, 0], pos[pt, 1], pos[pt, 2]
        d = einsum_dot3(n0, n1, n2, p0 - a0, p1 - a1, p2 - a2)
        if not abs(d) < proximity:
            continue
        w0, w1, w2 = (p0 - d * n0) - a0, (p1 - d * n1) - a1, (p2 - d * n2) - a2
        d20 = einsum_dot3(w0, w1, w2, v00, v01, v02)
        d21 = einsum_dot3(w0, w1, w2, v10, v11, v12)
        v = (d11 * d20 - d01 * d21) / den
        w = (d00 * d21 - d01 * d20) / den
        u = 1 - v - w
        if not (ok and u >= -t and v >= -t and w >= -t):
            continue
        cos = einsum_dot3(n0, n1, n2, ns[pt, 0], ns[pt, 1], ns[pt, 2])
        orient = _sign(d) if abs(cos) < square_cos else _sign(cos)
        if orient == 0:
            continue
        move = offset - orient * d
        if best_g[pt] < 0 or _at_least(move, best_move[pt]):
            best_move[pt], best_orient[pt], best_g[pt] = move, orient, gg


@numba.njit(cache=True, nogil=True, error_model="numpy")
def merged_edge_weights(indptr, indices, data, counted, area, is_point):  # pragma: no cover - compiled
    """Eq. 5 of :func:`meshvis.graphcut.weights.edge_weights` from a canonical CSR ``n_ij``.

    Every off-diagonal entry gives ``T_ij = A_i n_ij / n_i`` (halved, or for a point node
    towards a cluster node dropped, as there); ``(i, j)`` and ``(j, i)`` are merged into
    one edge ``i < j`` by adding their two terms (one addition, so the order of the two
    does not matter), and the edges come out sorted by ``(i, j)``, those of weight 0 left
    out.  The lower entries are first moved to the rows of their columns (in increasing
    row order, so each row's list stays sorted), then each row's two sorted lists are merged.
    """
    n = len(indptr) - 1
    low_count = np.zeros(n + 1, np.int64)
    for r in range(n):
        for e in range(indptr[r], indptr[r + 1]):
            if indices[e] < r:
                low_count[indices[e] + 1] += 1
    low_start = np.cumsum(low_count)
    low_at = low_start[:-1].copy()
    low_col = np.empty(low_start[-1], np.int64)
    low_val = np.empty(low_start[-1])
    out_i = np.empty(len(indices), np.int64)
    out_j = np.empty(len(indices), np.int64)
    out_w = np.empty(len(indices))

    def term(r, c, n_rc):
        if counted[r] <= 0:
            return 0.0
        t = area[r] * n_rc / max(counted[r], 1)
        if is_point[r] != is_point[c]:
            return t * (0.0 if is_point[r] else 1.0)
        return t * 0.5

    for r in range(n):
        for e in range(indptr[r], indptr[r + 1]):
            c = indices[e]
            if c < r:
                low_col[low_at[c]] = r
                low_val[low_at[c]] = term(r, c, data[e])
                low_at[c] += 1
    k = 0
    for r in range(n):
        a, a_end = indptr[r], indptr[r + 1]
        while a < a_end and indices[a] <= r:  # skip the lower part and the self-link
            a += 1
        b, b_end = low_start[r], low_start[r + 1]
        while a < a_end or b < b_end:
            if b >= b_end or (a < a_end and indices[a] < low_col[b]):
                c, w = indices[a], term(r, indices[a], data[a])
                a += 1
            elif a >= a_end or low_col[b] < indices[a]:
                c, w = low_col[b], low_val[b]
                b += 1
            else:
                c, w = indices[a], term(r, indices[a], data[a]) + low_val[b]
                a += 1
                b += 1
            if w > 0:
                out_i[k], out_j[k], out_w[k] = r, c, w
                k += 1
    return out_i[:k], out_j[:k], out_w[:k]


@numba.njit(cache=True, nogil=True, error_model="numpy")
def edge_maxima(w_max, i, j, w):  # pragma: no cover - compiled
    """``np.maximum.at(w_max, i, w)`` then ``np.maximum.at(w_max, j, w)``, in place (NaN wins)."""
    for ends in (i, j):
        for e in range(len(w)):
            x = w[e]
            if x > w_max[ends[e]] or x != x:
                w_max[ends[e]] = x
    return w_max


@numba.njit(cache=True, nogil=True, error_model="numpy")
def ray_starts(
    counts,
    n_cluster,
    node_start,
    entry_cumarea,
    area,
    entry_face,
    entry_side,
    point_face,
    point_origin,
    draws,
):  # pragma: no cover - compiled  # noqa: E501
    """Source node, face and side of every ray of :func:`meshvis.graphcut.nodes.node_rays`.

    Rays come node by node, ``counts[i]`` of them for node ``i``.  A cluster node's ray picks
    its entry by area: the first entry of the node whose cumulative area exceeds
    ``base + draw × area`` (``np.searchsorted(..., side="right")`` clipped to the node's
    entries, one draw per cluster ray in order).  A point node's ray starts at the stored
    pushed origin of its sample point (written into ``origins``; cluster rows are left for
    the caller, whose points need more draws).

    Returns
    -------
    source, face : (r,) int64 arrays; side : (r,) int8 array; origins : (r, 3) float64 array;
    cluster_rows : (c,) int64 array
        The rows of cluster rays
    """
    total = 0
    for i in range(len(counts)):
        total += counts[i]
    source = np.empty(total, np.int64)
    face = np.empty(total, np.int64)
    side = np.empty(total, np.int8)
    origins = np.empty((total, 3))
    n_c = 0
    for i in range(n_cluster):
        n_c += counts[i]
    cluster_rows = np.empty(n_c, np.int64)
    row = 0
    c = 0
    for i in range(len(counts)):
        if i < n_cluster:
            start, end = node_start[i], node_start[i + 1]
            base = entry_cumarea[start - 1] if start > 0 else 0.0
            for _ in range(counts[i]):
                target = base + draws[c] * area[i]
                lo, hi = start, end  # first index in [start, end) with cumarea > target
                while lo < hi:
                    mid = (lo + hi) // 2
                    if entry_cumarea[mid] <= target:
                        lo = mid + 1
                    else:
                        hi = mid
                k = min(lo, end - 1)
                source[row], face[row], side[row] = i, entry_face[k], entry_side[k]
                cluster_rows[c] = row
                c += 1
                row += 1
        else:
            p, s = (i - n_cluster) // 2, (i - n_cluster) % 2
            for _ in range(counts[i]):
                source[row], face[row], side[row] = i, point_face[p], s
                for d in range(3):
                    origins[row, d] = point_origin[p, s, d]
                row += 1
    return source, face, side, origins, cluster_rows


@numba.njit(cache=True, nogil=True, error_model="numpy")
def split_hits(face, side, source, side_node, escaped):  # pragma: no cover - compiled
    """First step of :func:`meshvis.graphcut.sampling.sample_round` on one batch of hits.

    Adds the misses to ``escaped`` (per source node, in place) and returns, for the rays
    that hit (in ray order): the face, side and source node, the node of the side hit
    (-1 on a flagged face, which has no cluster node), and the positions among the hits
    and among all rays of the hits on flagged faces.
    """
    n_hit = 0
    for k in range(len(face)):
        if face[k] >= 0:
            n_hit += 1
        else:
            escaped[source[k]] += 1
    f = np.empty(n_hit, np.int64)
    s = np.empty(n_hit, np.int64)
    sr = np.empty(n_hit, np.int64)
    dst = np.empty(n_hit, np.int64)
    flagged_at = np.empty(n_hit, np.int64)
    ray_at = np.empty(n_hit, np.int64)
    h = 0
    q = 0
    for k in range(len(face)):
        if face[k] < 0:
            continue
        f[h], s[h], sr[h] = face[k], side[k], source[k]
        dst[h] = side_node[face[k], side[k]]
        if dst[h] < 0:
            flagged_at[q], ray_at[q] = h, k
            q += 1
        h += 1
    return f, s, sr, dst, flagged_at[:q], ray_at[:q]


@numba.njit(cache=True, nogil=True, error_model="numpy")
def kept_hits(sr, s, dst, flagged_at, point, blocked, n_cluster, discarded):  # pragma: no cover - compiled
    """Last step of :func:`meshvis.graphcut.sampling.sample_round` on one batch of hits.

    A hit on a flagged face links to the point node of its sample ``point`` on the side hit
    (``n_cluster + 2 p + s``); one whose reverse ray was
    ``blocked`` is discarded (added to ``discarded`` per source node, in place).  Returns
    the (source, destination) node of every kept hit, in hit order.
    """
    keep = np.ones(len(sr), np.bool_)
    for q in range(len(flagged_at)):
        h = flagged_at[q]
        dst[h] = n_cluster + 2 * point[q] + s[h]
        if blocked[q]:
            keep[h] = False
            discarded[sr[h]] += 1
    n_keep = 0
    for h in range(len(sr)):
        if keep[h]:
            n_keep += 1
    rows = np.empty(n_keep, np.int64)
    cols = np.empty(n_keep, np.int64)
    k = 0
    for h in range(len(sr)):
        if keep[h]:
            rows[k], cols[k] = sr[h], dst[h]
            k += 1
    return rows, cols
