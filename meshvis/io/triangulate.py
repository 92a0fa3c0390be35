"""Triangulation of the polygons read from model files.

Readers hand over polygons as one flat array of corners plus a corner count per polygon.
:func:`triangulate` turns them into triangles that index that flat corner array (so that
every per-corner attribute -- vertex, UV, colour -- can be gathered with the same index)
and reports which polygon each triangle came from.

Strategy, vectorised per polygon size:

* triangles pass through unchanged;
* convex polygons are fanned from their first corner;
* quads with one reflex corner are fanned from that corner (always valid for a quad);
* every other polygon is ear-clipped in the plane of its Newell normal.

All triangles keep the winding of their polygon, so their normals agree with it.
"""

from __future__ import annotations

import numpy as np

from meshvis.errors import ModelFormatError


def triangulate(
    vertices: np.ndarray, counts: np.ndarray, corners: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Split polygons into triangles.

    Parameters
    ----------
    vertices : (n, 3) float
        Vertex positions.
    counts : (p,) int
        Number of corners of each polygon; every count must be at least 3.
    corners : (sum(counts),) int
        Vertex index of every corner, polygon after polygon.

    Raises
    ------
    ModelFormatError
        A polygon has more corners than the cap (:func:`check_corners`).

    Returns
    -------
    triangles : (t, 3) int64
        Positions in ``corners`` of the three corners of each triangle, with
        ``t = sum(counts - 2)``.
    source : (t,) int64
        Index of the polygon each triangle came from; non-decreasing.
    """
    counts = np.asarray(counts, np.int64)
    corners = np.asarray(corners, np.int64)
    check_corners(counts)
    start = np.zeros(len(counts), np.int64)
    np.cumsum(counts[:-1], out=start[1:])
    n_tri = counts - 2
    tri_start = np.zeros(len(counts), np.int64)
    np.cumsum(n_tri[:-1], out=tri_start[1:])
    total = int(n_tri.sum()) if len(counts) else 0
    triangles = np.empty((total, 3), np.int64)
    source = np.repeat(np.arange(len(counts), dtype=np.int64), n_tri)

    for k in np.unique(counts):
        k = int(k)
        polys = np.flatnonzero(counts == k)
        # (g, k) positions of the corners of every polygon with k corners
        pos = start[polys, None] + np.arange(k)
        rows = tri_start[polys, None] + np.arange(k - 2)
        if k == 3:
            triangles[rows[:, 0]] = pos
            continue
        pts = np.asarray(vertices, np.float64)[corners[pos]]
        reflex = _reflex_corners(pts)
        n_reflex = reflex.sum(axis=1)
        # fan start: corner 0 for convex polygons, the reflex corner for quads with one
        first = np.zeros(len(polys), np.int64)
        fan = n_reflex == 0
        if k == 4:
            one = n_reflex == 1
            first[one] = np.argmax(reflex[one], axis=1)
            fan |= one
        if fan.any():
            i = np.arange(1, k - 1)
            fan_pos = pos[fan]
            f0 = first[fan, None]
            a = np.take_along_axis(fan_pos, f0, 1)
            b = np.take_along_axis(fan_pos, (f0 + i) % k, 1)
            c = np.take_along_axis(fan_pos, (f0 + i + 1) % k, 1)
            triangles[rows[fan].ravel()] = np.stack([np.broadcast_to(a, b.shape), b, c], axis=-1).reshape(
                -1, 3
            )
        for g in np.flatnonzero(~fan):
            local = ear_clip(pts[g])
            triangles[rows[g]] = pos[g][local]
    return triangles, source


def check_corners(counts: np.ndarray) -> None:
    """Refuse polygons with more corners than :data:`meshvis.limits.MAX_POLYGON_CORNERS`.

    Raises
    ------
    ModelFormatError
        Without a file name; :func:`meshvis.io.load` adds it.
    """
    from meshvis import limits

    if len(counts) and int(counts.max()) > limits.MAX_POLYGON_CORNERS:
        i = int(np.argmax(counts))
        raise ModelFormatError(
            f"polygon {i} has {int(counts[i])} corners, more than the cap of {limits.MAX_POLYGON_CORNERS}"
        )


def _newell_normal(pts: np.ndarray) -> np.ndarray:
    """(g, 3) Newell normals of (g, k, 3) polygons (length = twice the projected area)."""
    nxt = np.roll(pts, -1, axis=1)
    return np.cross(pts, nxt).sum(axis=1)


def _reflex_corners(pts: np.ndarray) -> np.ndarray:
    """(g, k) bool: corners where the polygon turns against its Newell normal.

    A turn counts as reflex only when it is clearly negative relative to the polygon's
    size, so nearly straight corners of convex polygons are not flagged.
    """
    normal = _newell_normal(pts)
    prev = pts - np.roll(pts, 1, axis=1)
    nxt = np.roll(pts, -1, axis=1) - pts
    turn = np.einsum("gkc,gc->gk", np.cross(prev, nxt), normal)
    scale = np.einsum("gc,gc->g", normal, normal)  # |N|^2 ~ (polygon area)^2
    return turn < -1e-12 * scale[:, None]


def ear_clip(pts: np.ndarray) -> np.ndarray:
    """Triangulate one simple polygon by ear clipping.

    Parameters
    ----------
    pts : (k, 3) float
        Corner positions in order.

    Returns
    -------
    (k - 2, 3) int64
        Corner numbers (0..k-1) of the triangles, in the polygon's winding.

    Notes
    -----
    The polygon is projected onto the plane of its Newell normal, where its winding is
    counter-clockwise.  An ear is a convex corner whose triangle contains no reflex
    corner.  For degenerate or self-intersecting input where no ear exists, the most
    convex remaining corner is clipped, so exactly ``k - 2`` triangles always come out.
    """
    k = len(pts)
    normal = _newell_normal(pts[None])[0]
    length = np.linalg.norm(normal)
    if k == 3 or length == 0:
        fan = np.arange(1, k - 1)
        return np.stack([np.zeros(k - 2, np.int64), fan, fan + 1], axis=1)
    normal = normal / length
    # orthonormal basis (u, v) with u x v = normal: the projection is counter-clockwise
    helper = np.eye(3)[np.argmin(np.abs(normal))]
    u = np.cross(helper, normal)
    u /= np.linalg.norm(u)
    v = np.cross(normal, u)
    xy = np.stack([pts @ u, pts @ v], axis=1)
    xy -= xy.mean(axis=0)
    eps = 1e-12 * float(np.abs(xy).max() ** 2 + 1e-300)

    prev = np.roll(np.arange(k), 1)
    nxt = np.roll(np.arange(k), -1)
    alive = np.ones(k, bool)

    def turn(i: int) -> float:
        a, b, c = xy[prev[i]], xy[i], xy[nxt[i]]
        return float((b[0] - a[0]) * (c[1] - b[1]) - (b[1] - a[1]) * (c[0] - b[0]))

    turns = np.array([turn(j) for j in range(k)])
    out = np.empty((k - 2, 3), np.int64)
    n_out = 0
    remaining = k
    i: int = 0
    misses = 0
    while remaining > 3:
        if misses > remaining:
            # no ear found in a full pass: clip the most convex corner and go on
            live = np.flatnonzero(alive)
            i = int(live[np.argmax(turns[live])])
            is_ear = True
        else:
            is_ear = bool(turns[i] > eps) and _no_reflex_inside(xy, turns, alive, prev[i], i, nxt[i], eps)
        if is_ear:
            a, c = int(prev[i]), int(nxt[i])
            out[n_out] = (a, i, c)
            n_out += 1
            alive[i] = False
            nxt[a], prev[c] = c, a
            remaining -= 1
            turns[a], turns[c] = turn(a), turn(c)
            i = a
            misses = 0
        else:
            i = nxt[i]
            misses += 1
    out[n_out] = (prev[i], i, nxt[i])
    return out


def _no_reflex_inside(xy, turns, alive, a, b, c, eps) -> bool:
    """True when no live reflex corner other than a, b, c lies in triangle (a, b, c)."""
    cand = np.flatnonzero(alive & (turns <= eps))
    cand = cand[(cand != a) & (cand != b) & (cand != c)]
    if len(cand) == 0:
        return True
    p = xy[cand]
    A, B, C = xy[a], xy[b], xy[c]

    def side(P, Q):
        return (Q[0] - P[0]) * (p[:, 1] - P[1]) - (Q[1] - P[1]) * (p[:, 0] - P[0])

    inside = (side(A, B) >= -eps) & (side(B, C) >= -eps) & (side(C, A) >= -eps)
    return not inside.any()
