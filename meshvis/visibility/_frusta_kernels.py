"""Numba kernels of conservative from-point visibility (:mod:`.conservative`, FastV §3).

One call handles a batch of frusta from one viewpoint ``v``.  A frustum is a pyramid with
its apex at ``v``: its rays are ``axis + u * right + w * up`` for ``(u, w)`` in a
rectangle ``[u0, u1] x [w0, w1]`` of its root (a cube-map face or a camera's view).
Depth is measured along the root's ``axis``.  For each frustum the kernel

1. looks for *blockers* (FastV §3.2) from each seed triangle (the first hits of the
   frustum's centre and corner rays, traced by Embree): sets of triangles that every ray of
   the frustum provably hits (:func:`_walk`); the smallest deepest point of a blocker in
   the frustum is its far plane (FastV §3.3, "Far Plane Depth Update");
2. with a blocker, walks the bounding volume hierarchy of :mod:`meshvis.geometry.bvh` over
   the triangles meeting the frustum in front of the far plane and keeps each one unless
   it lies behind a blocker (:func:`_against`: behind the plane of every blocker triangle
   whose rays reach it) or a blocker is found for just the rays that reach it
   (:func:`_hidden_in_cut`);
3. without a blocker, asks for the frustum to be split in four (FastV §3.4), or at the
   subdivision limit tries *occluder fusion* (FastV keeps everything there): the union
   of the nearest triangles meeting the frustum covers it, and what lies behind its
   deepest point is hidden (:func:`_cover`); each triangle kept otherwise is kept unless
   the union of the triangles wholly before it covers the rays that may reach it, or a
   blocker is found for those rays.

Why a cut-out proves a cover.  In the frustum's coordinates ``(u, w)`` (rays ``axis + u
right + w up``) the rays that hit a triangle at a positive distance are exactly those on
the inner side of the three planes through ``v`` and its sides: three half-planes, the
signs of the ray's barycentric coordinates.  Each is moved inwards by the margin of the
side test (a ray that passes counts only when rounding cannot make it miss), except along
a side another face continues exactly (a welded neighbour, or a face whose side lies on
the same line, on the other side of the plane through ``v``): there the rays just past
the side hit that face.  A convex piece of the uncovered part minus such a triangle is at
most three convex pieces (outside side 0; inside 0 and outside 1; inside 0 and 1 and
outside 2), taken with a slack so that rounding keeps more; when no piece is left, every
ray of the frustum hits a triangle of the union no deeper than the union's deepest point.

Why a walk proves a blocker.  The walk starts at a seed triangle and, for every edge of a
triangle in the set that meets the frustum (segment against the frustum's planes), adds
a triangle across that edge which lies on the *other* side of the plane through ``v``
and the edge (an edge whose other triangles all lie on the same side is a silhouette or a
free edge: the walk fails, FastV §3.2 (b)).  Seen from ``v``, every edge point inside the
frustum then has the set's triangles on both sides, and every vertex inside it a full turn
of them, so the directions of the frustum whose rays hit the set are both open and closed
in the (connected) frustum: once one ray of the frustum is shown to hit the set (a probe
ray, checked strictly inside a triangle of the set), all do.  This needs no consistent
winding and no manifold model, only exactly shared (welded) vertices; a triangle whose
plane passes near ``v`` never joins a blocker.  Slivers whose corners lie on one line
(they join T-junctions) are looked through: the faces beyond them that together span the
edge cover it.  For the rays that reach one triangle ``t`` the frustum is the cone of the
planes through ``v`` and the edges of ``t``'s part in it; ``t``'s own edges lie on that
cone's boundary and are left out of the test.

Float safety.  Everything is float64, relative to ``v``.  Every test that *accepts* a
blocker (an edge's two triangles on opposite sides, a ray strictly inside a triangle, a
triangle behind a plane) must pass by a margin, and every test that *culls* (an edge, a
box or a triangle missing the frustum, a triangle behind the far plane) must fail by a
margin: ``delta`` (a length, in model units) against moved vertices and viewpoint,
``eta`` (an angle) against turned rays, and ``mu`` by which frusta and far depths are
widened.  All are far above the float32 rounding of the Embree scene that the sampled
reference traces, so the reference's rays see nothing that these tests hide.  In
particular a triangle touching its blocker (a side of a box behind the box's top, sharing
the top's edge) is kept: a ray through that edge meets both, and rounding decides which
one a tracer reports.
"""

from __future__ import annotations

import math

import numba
import numpy as np

#: status of a frustum after :func:`trace_frusta` (and the modes of :func:`_collect`; ANY is
#: the mode that only asks whether a triangle meets the frustum)
EMPTY, BLOCKED, SPLIT, OPEN, ANY = 0, 1, 2, 3, 4
#: status of a frustum at the limit without a blocker that the union of the triangles
#: meeting it covers (:func:`_fuse`)
FUSED = 5
#: nodes a traversal stack holds (the builder's trees are at most ~130 levels deep)
STACK = 512
#: vertices a clipped triangle can have (3 + one per clipping plane, 8 planes) and spare
POLY = 16
#: where in the frustum's unit square the rays that start a blocker's proof pass: the
#: centre, and two points off the diagonals and medians (a symmetric model's edges run
#: along those)
PROBES = np.array([[0.5, 0.5], [0.293, 0.618], [0.707, 0.382]])
#: planes of a frustum
FRUSTUM_PLANES = 4
#: where a triangle lies against a blocker (:func:`_against`)
BEHIND, IN_FRONT, ACROSS = 1, -1, 0
#: a probe ray must pass inside every plane of its cone by this fraction of its length
PROBE_SLACK = 1e-12
#: a triangle counts as only touching a frustum when its part in the frustum widened by
#: ``TOUCH_SLACK * mu`` (float64 rounding, not the float32 margin) is less than
#: ``TOUCH_WIDTH`` times that wide: the rays through that part are as good as none, and
#: those near the frustum's side are also the neighbouring frustum's (widened by ``mu``)
TOUCH_SLACK = 1e-6
TOUCH_WIDTH = 100.0
#: fillers looked through at one edge, and faces beyond them that may span it
MAX_FILLERS, MAX_SPAN = 32, 16
#: occluder fusion (:func:`_fuse`): the nearest triangles it tries, the convex pieces of
#: the part not yet covered, and the vertices of one piece; beyond any of them a frustum
#: keeps everything, as without fusion
FUSE_TRIANGLES, FUSE_PIECES, PIECE_VERTS = 64, 64, 24
#: slack of fusion's cuts in (u, w), so that rounding never drops a sliver the union
#: leaves uncovered: pieces overlap by it (float64 rounding of coordinates below 2)
FUSE_SLACK = 1e-13
#: a side of another face lies on a fusion candidate's side (a T-junction) when its ends
#: are within this fraction of ``delta`` (1e-12 of the scene's size by default) of its line
FUSE_COLLINEAR = 0.0
#: pieces thinner in (u, w) than this fraction of the angle margin ``eta`` (1e-11 by
#: default) are the rounding of cuts along a side two triangles share exactly, and are
#: dropped: a hole in the cover is at least about ``2 eta`` wide, the margins of its sides
FUSE_SLIVER = 1e-5


@numba.njit(cache=True, nogil=True, error_model="numpy")
def _cross(a0, a1, a2, b0, b1, b2):  # pragma: no cover - compiled
    return a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0


@numba.njit(cache=True, nogil=True, error_model="numpy")
def _frustum_rays(axis, right, up, u0, u1, w0, w1, rays, planes):  # pragma: no cover - compiled
    """Corner rays 0..3 (counter-clockwise in (u, w)) and the centre ray 4; unit inward side planes."""
    us = (u0, u1, u1, u0, 0.5 * (u0 + u1))
    ws = (w0, w0, w1, w1, 0.5 * (w0 + w1))
    for k in range(5):
        for c in range(3):
            rays[k, c] = axis[c] + us[k] * right[c] + ws[k] * up[c]
    for k in range(4):
        j = (k + 1) % 4
        n0, n1, n2 = _cross(rays[k, 0], rays[k, 1], rays[k, 2], rays[j, 0], rays[j, 1], rays[j, 2])
        norm = math.sqrt(n0 * n0 + n1 * n1 + n2 * n2)
        if n0 * rays[4, 0] + n1 * rays[4, 1] + n2 * rays[4, 2] < 0:
            norm = -norm
        planes[k, 0], planes[k, 1], planes[k, 2] = n0 / norm, n1 / norm, n2 / norm


@numba.njit(cache=True, nogil=True, error_model="numpy")
def _clip(poly, n, out, p0, p1, p2, off):  # pragma: no cover - compiled
    """Keep the part of polygon ``poly[:n]`` where ``p . x + off >= 0``; returns its size in ``out``."""
    k = 0
    for i in range(n):
        j = (i + 1) % n
        fi = p0 * poly[i, 0] + p1 * poly[i, 1] + p2 * poly[i, 2] + off
        fj = p0 * poly[j, 0] + p1 * poly[j, 1] + p2 * poly[j, 2] + off
        if fi >= 0:
            out[k, 0], out[k, 1], out[k, 2] = poly[i, 0], poly[i, 1], poly[i, 2]
            k += 1
        if (fi >= 0) != (fj >= 0):
            t = fi / (fi - fj)
            for c in range(3):
                out[k, c] = poly[i, c] + t * (poly[j, c] - poly[i, c])
            k += 1
    return k


@numba.njit(cache=True, nogil=True, error_model="numpy")
def _constraint(k, planes, n_planes, axis, far, mu):  # pragma: no cover - compiled
    """The ``k``-th half-space ``p . x + off >= 0`` of a frustum widened by ``mu``.

    First its side planes (through ``v``) moved out by ``mu``; then the cap ``axis . x >=
    -mu``: without it, side planes moved out meet far behind ``v`` when the frustum is
    thin (``mu`` over the sine of its half angle), and the widened frustum would take in
    everything near ``v``; then, when ``far`` is finite, the far plane moved out.
    """
    if k < n_planes:
        return planes[k, 0], planes[k, 1], planes[k, 2], mu
    if k == n_planes:
        return axis[0], axis[1], axis[2], mu
    return -axis[0], -axis[1], -axis[2], far + mu


@numba.njit(cache=True, nogil=True, error_model="numpy")
def _clip_triangle(X, planes, n_planes, axis, far, mu, poly, tmp):  # pragma: no cover - compiled
    """The part of triangle ``X`` (relative to ``v``) inside the frustum widened by ``mu``.

    The frustum is ``n_planes`` unit inward planes through ``v`` around the unit ``axis``,
    cut at depth ``far`` (``inf``: not cut; see :func:`_constraint`).  The polygon is
    written to ``poly``; returns its vertex count (0: the triangle misses the frustum).
    """
    n_constraints = n_planes + (1 if far == np.inf else 2)
    all_in = True
    for k in range(n_constraints):
        p0, p1, p2, off = _constraint(k, planes, n_planes, axis, far, mu)
        f0 = p0 * X[0, 0] + p1 * X[0, 1] + p2 * X[0, 2] + off
        f1 = p0 * X[1, 0] + p1 * X[1, 1] + p2 * X[1, 2] + off
        f2 = p0 * X[2, 0] + p1 * X[2, 1] + p2 * X[2, 2] + off
        if f0 < 0 and f1 < 0 and f2 < 0:
            return 0
        if f0 < 0 or f1 < 0 or f2 < 0:
            all_in = False
    for i in range(3):
        for c in range(3):
            poly[i, c] = X[i, c]
    if all_in:
        return 3
    n = 3
    for k in range(n_constraints):
        p0, p1, p2, off = _constraint(k, planes, n_planes, axis, far, mu)
        n = _clip(poly, n, tmp, p0, p1, p2, off)
        if n == 0:
            return 0
        for i in range(n):
            for c in range(3):
                poly[i, c] = tmp[i, c]
    return n


@numba.njit(cache=True, nogil=True, error_model="numpy")
def _depth_range(poly, n, axis):  # pragma: no cover - compiled
    near, deep = np.inf, -np.inf
    for i in range(n):
        d = axis[0] * poly[i, 0] + axis[1] * poly[i, 1] + axis[2] * poly[i, 2]
        near = min(near, d)
        deep = max(deep, d)
    return near, deep


@numba.njit(cache=True, nogil=True, error_model="numpy")
def _segment_meets(P, Q, planes, n_planes, axis, mu):  # pragma: no cover - compiled
    """Whether segment ``P``-``Q`` (relative to ``v``) meets the frustum widened by ``mu``."""
    t0, t1 = 0.0, 1.0
    for k in range(n_planes + 1):
        p0, p1, p2, off = _constraint(k, planes, n_planes, axis, np.inf, mu)
        fp = p0 * P[0] + p1 * P[1] + p2 * P[2] + off
        fq = p0 * Q[0] + p1 * Q[1] + p2 * Q[2] + off
        if fp < 0 and fq < 0:
            return False
        if fp < 0:
            t0 = max(t0, fp / (fp - fq))
        elif fq < 0:
            t1 = min(t1, fp / (fp - fq))
    # a segment that only grazes the widened frustum counts: it is within ~mu of it
    return t0 <= t1 + 1e-9


@numba.njit(cache=True, nogil=True, error_model="numpy")
def _relative(tri, f, v, X):  # pragma: no cover - compiled
    for i in range(3):
        for c in range(3):
            X[i, c] = tri[f, i, c] - v[c]


@numba.njit(cache=True, nogil=True, error_model="numpy")
def _plane(X):  # pragma: no cover - compiled
    """Unit normal of triangle ``X`` and the signed distance of ``v`` (the origin) from its plane."""
    n0, n1, n2 = _cross(
        X[1, 0] - X[0, 0], X[1, 1] - X[0, 1], X[1, 2] - X[0, 2],
        X[2, 0] - X[0, 0], X[2, 1] - X[0, 1], X[2, 2] - X[0, 2],
    )  # fmt: skip
    norm = math.sqrt(n0 * n0 + n1 * n1 + n2 * n2)
    if not norm > 0:
        return 0.0, 0.0, 0.0, 0.0
    n0, n1, n2 = n0 / norm, n1 / norm, n2 / norm
    return n0, n1, n2, -(n0 * X[0, 0] + n1 * X[0, 1] + n2 * X[0, 2])


@numba.njit(cache=True, nogil=True, error_model="numpy")
def _sees_plane(X, delta):  # pragma: no cover - compiled
    """+1 / -1: the side of the triangle's plane ``v`` is on, by at least ``2 delta``; 0 if nearer or degenerate."""
    _, _, _, side = _plane(X)
    if not abs(side) > 2.0 * delta:
        return 0
    return 1 if side > 0 else -1


@numba.njit(cache=True, nogil=True, error_model="numpy")
def _edge_tolerance(P, Q, m0, m1, m2, Z, delta, eta, point):  # pragma: no cover - compiled
    """Margin of ``Z . m`` with ``m = P x Q``: the side of ``Z`` against the plane through ``v``
    and edge P-Q, for corners moved by ``delta`` and rays turned by ``eta``.

    To first order, moving ``P`` and ``Q`` by ``dP``, ``dQ`` changes ``Z . m`` by
    ``dP . (Q x Z) + dQ . (Z x P)``; moving ``Z`` itself (a ``point``, not a ray
    direction) adds ``|dZ| |m|``, turning it adds ``eta |Z| |m|``; moving ``v`` moves all
    three.  Twice that bound.
    """
    a0, a1, a2 = _cross(Q[0], Q[1], Q[2], Z[0], Z[1], Z[2])
    b0, b1, b2 = _cross(Z[0], Z[1], Z[2], P[0], P[1], P[2])
    lm = math.sqrt(m0 * m0 + m1 * m1 + m2 * m2)
    lz = math.sqrt(Z[0] * Z[0] + Z[1] * Z[1] + Z[2] * Z[2])
    tol = (
        delta * (math.sqrt(a0 * a0 + a1 * a1 + a2 * a2) + math.sqrt(b0 * b0 + b1 * b1 + b2 * b2))
        + eta * lz * lm
    )
    if point:
        tol += delta * lm
    return 2.0 * tol


@numba.njit(cache=True, nogil=True, error_model="numpy")
def _ray_inside(X, r, delta, eta):  # pragma: no cover - compiled
    """The ray from ``v`` along ``r`` passes strictly inside triangle ``X``, in front of ``v``.

    The Plücker side of the ray against each directed edge is ``r . (P x Q)`` for lines through
    ``v``; the ray passes inside when the three agree (by a margin), and hits the triangle in
    front of ``v`` when they agree with the side of the plane that ``v`` is on.
    """
    front = _sees_plane(X, delta)
    if front == 0:
        return False
    sign = 0
    for i in range(3):
        P = X[i]
        Q = X[(i + 1) % 3]
        m0, m1, m2 = _cross(P[0], P[1], P[2], Q[0], Q[1], Q[2])
        e = r[0] * m0 + r[1] * m1 + r[2] * m2
        if abs(e) <= _edge_tolerance(P, Q, m0, m1, m2, r, delta, eta, False):
            return False
        s = 1 if e > 0 else -1
        if sign == 0:
            sign = s
        elif s != sign:
            return False
    # n . r has the sign of the edge functions; the hit is in front when n . (a - v) agrees,
    # i.e. when v is on the side of the plane opposite to the rays' sign
    return sign == -front


@numba.njit(cache=True, nogil=True, error_model="numpy")
def _probe_ray(rays, s, t, out):  # pragma: no cover - compiled
    """The ray at ``(s, t)`` in the frustum's unit square (corner 0 at (0, 0), corner 2 at (1, 1))."""
    for c in range(3):
        bottom = rays[0, c] + s * (rays[1, c] - rays[0, c])
        top = rays[3, c] + s * (rays[2, c] - rays[3, c])
        out[c] = bottom + t * (top - bottom)


@numba.njit(cache=True, nogil=True, error_model="numpy")
def _off_cone(a, b, P, Q, t, T, wid, delta, eta):  # pragma: no cover - compiled
    """Whether edge ``P``-``Q`` (welded ends ``a``, ``b``) provably misses the open cone of
    rays through triangle ``t`` (``T``: its corners relative to ``v``).

    ``t``'s own edges lie on the cone's boundary.  An edge from a corner ``c`` of ``t``
    misses the open cone when its other end lies outside one of the two planes through
    ``v`` and ``t``'s edges at ``c`` (by a margin): the cone near ``c`` is the convex wedge
    of those planes, and the edge leaves ``c`` outside it.
    """
    if t < 0:
        return False
    ca, cb = -1, -1
    for i in range(3):
        if wid[t, i] == a:
            ca = i
        if wid[t, i] == b:
            cb = i
    if ca >= 0 and cb >= 0:
        return True
    if ca < 0 and cb < 0:
        return False
    c, other = (ca, Q) if ca >= 0 else (cb, P)
    C = T[c]
    for k in (1, 2):
        A = T[(c + k) % 3]  # the edge c-A of t, and t's third corner B inside its plane
        B = T[(c + 3 - k) % 3]
        m0, m1, m2 = _cross(C[0], C[1], C[2], A[0], A[1], A[2])
        side_b = m0 * B[0] + m1 * B[1] + m2 * B[2]
        side_o = m0 * other[0] + m1 * other[1] + m2 * other[2]
        if side_b * side_o < 0 and abs(side_o) > _edge_tolerance(C, A, m0, m1, m2, other, delta, eta, True):
            return True
    return False


@numba.njit(cache=True, nogil=True, error_model="numpy")
def _other_side(g, a, b, P, Q, m0, m1, m2, ez, v, tri, wid, delta, eta, Y):  # pragma: no cover - compiled
    """Whether face ``g``, across edge ``a``-``b`` (corners ``P``, ``Q``), lies on the other side of
    the plane through ``v`` and the edge than the corner ``ez`` was measured at, by a margin,
    and ``v`` sees its plane."""
    c = 0
    while c < 2 and (wid[g, c] == a or wid[g, c] == b):
        c += 1
    for d in range(3):
        Y[0, d] = tri[g, c, d] - v[d]
    ey = Y[0, 0] * m0 + Y[0, 1] * m1 + Y[0, 2] * m2
    if ez * ey >= 0 or abs(ey) <= _edge_tolerance(P, Q, m0, m1, m2, Y[0], delta, eta, True):
        return False
    _relative(tri, g, v, Y)
    return _sees_plane(Y, delta) != 0


@numba.njit(cache=True, nogil=True, error_model="numpy")
def _faces_across(
    e,
    f,
    a,
    b,
    P,
    Q,
    m0,
    m1,
    m2,
    ez,
    v,
    tri,
    wid,
    face_edge,
    edge_start,
    edge_face,
    filler,
    delta,
    eta,
    out,
    n,
    Y,
    found,
    fill,
    seg,
):  # pragma: no cover - compiled
    """The faces that cover the other side of edge ``e`` (welded ends ``a``, ``b``) of face ``f``.

    Writes them to ``found`` and returns their number; 0 when the edge is not covered.  A
    face across the edge whose far corner lies on the other side of the plane through
    ``v`` and the edge (by a margin) covers it; one already in ``out[:n]`` is preferred.
    ``filler`` faces (slivers whose corners lie on one line: they join T-junctions, often
    several in a row) are looked through: the faces beyond them, on the other side, whose
    edges on that line together span the edge, cover it.
    """
    best = -1
    n_fill = 0
    for h in range(edge_start[e], edge_start[e + 1]):
        g = edge_face[h]
        if g == f:
            continue
        if filler[g] >= 0:
            if n_fill < len(fill):
                fill[n_fill] = g
                n_fill += 1
            continue
        if _other_side(g, a, b, P, Q, m0, m1, m2, ez, v, tri, wid, delta, eta, Y):
            for j in range(n):
                if out[j] == g:
                    found[0] = g
                    return 1
            if best < 0:
                best = g
    if best >= 0:
        found[0] = best
        return 1
    if n_fill == 0:
        return 0
    # through the fillers: every face beyond them on the other side, with the stretch of the
    # edge's line (parameter 0 at P, 1 at Q) that its shared edge spans
    lx, ly, lz = Q[0] - P[0], Q[1] - P[1], Q[2] - P[2]
    ll = lx * lx + ly * ly + lz * lz
    n_seg = 0
    i = 0
    while i < n_fill:
        g = fill[i]
        i += 1
        for side in range(3):
            e2 = face_edge[g, side]
            if e2 < 0:
                continue
            a2, b2 = wid[g, side], wid[g, (side + 1) % 3]
            for h in range(edge_start[e2], edge_start[e2 + 1]):
                g2 = edge_face[h]
                if g2 in (g, f):
                    continue
                if filler[g2] >= 0:
                    seen = False
                    for j in range(n_fill):
                        if fill[j] == g2:
                            seen = True
                            break
                    if not seen:
                        if n_fill == len(fill):
                            return 0
                        fill[n_fill] = g2
                        n_fill += 1
                    continue
                if not _other_side(g2, a2, b2, P, Q, m0, m1, m2, ez, v, tri, wid, delta, eta, Y):
                    continue
                if n_seg == len(found):
                    return 0
                s0 = ((tri[g, side, 0] - v[0] - P[0]) * lx + (tri[g, side, 1] - v[1] - P[1]) * ly
                      + (tri[g, side, 2] - v[2] - P[2]) * lz) / ll  # fmt: skip
                k = (side + 1) % 3
                s1 = ((tri[g, k, 0] - v[0] - P[0]) * lx + (tri[g, k, 1] - v[1] - P[1]) * ly
                      + (tri[g, k, 2] - v[2] - P[2]) * lz) / ll  # fmt: skip
                found[n_seg] = g2
                seg[n_seg, 0], seg[n_seg, 1] = min(s0, s1), max(s0, s1)
                n_seg += 1
    # those stretches must span [0, 1]: sweep them from the left
    reach = 0.0
    progress = True
    while progress and reach < 1.0:
        progress = False
        for j in range(n_seg):
            if seg[j, 0] <= reach and seg[j, 1] > reach:
                reach = seg[j, 1]
                progress = True
    return n_seg if reach >= 1.0 else 0


@numba.njit(cache=True, nogil=True, error_model="numpy")
def _walk(
    seed, v, tri, wid, face_edge, edge_start, edge_face, filler, planes, n_planes, axis, t, T,
    probes, n_probes, delta, eta, mu, out, X, Y, found, fill, seg,
):  # fmt: skip  # pragma: no cover - compiled
    """Grow a blocker from ``seed`` (FastV §3.2) into ``out``; its size, 0 when none is proved.

    The frustum is ``planes[:n_planes]`` around ``axis``; with ``t >= 0`` it lies inside the
    cone of rays through triangle ``t`` (corners ``T``), and edges that miss that cone's
    interior are not tested (:func:`_off_cone`).  One of the rays ``probes[:n_probes]``
    (inside the frustum) must pass strictly inside a triangle of the set.
    """
    _relative(tri, seed, v, X)
    if _sees_plane(X, delta) == 0 or filler[seed] >= 0:
        return 0
    out[0] = seed
    n = 1
    i = 0
    while i < n:
        f = out[i]
        _relative(tri, f, v, X)
        for s in range(3):
            a, b = wid[f, s], wid[f, (s + 1) % 3]
            P, Q, Z = X[s], X[(s + 1) % 3], X[(s + 2) % 3]
            if not _segment_meets(P, Q, planes, n_planes, axis, mu) or _off_cone(
                a, b, P, Q, t, T, wid, delta, eta
            ):
                continue
            e = face_edge[f, s]
            if e < 0:
                return 0
            m0, m1, m2 = _cross(P[0], P[1], P[2], Q[0], Q[1], Q[2])
            ez = Z[0] * m0 + Z[1] * m1 + Z[2] * m2
            if abs(ez) <= _edge_tolerance(P, Q, m0, m1, m2, Z, delta, eta, True):
                return 0
            n_found = _faces_across(
                e, f, a, b, P, Q, m0, m1, m2, ez, v, tri, wid, face_edge, edge_start, edge_face, filler,
                delta, eta, out, n, Y, found, fill, seg,
            )  # fmt: skip
            if n_found == 0:
                return 0  # a free or silhouette edge meets the frustum
            for q in range(n_found):
                known = False
                for j in range(n):
                    if out[j] == found[q]:
                        known = True
                        break
                if not known:
                    if n == len(out):
                        return 0
                    out[n] = found[q]
                    n += 1
        i += 1
    for k in range(n_probes):
        for j in range(n):
            _relative(tri, out[j], v, X)
            if _ray_inside(X, probes[k], delta, eta):
                return n
    return 0


@numba.njit(cache=True, nogil=True, error_model="numpy")
def _against(
    poly, n_poly, t, blocker, n_blocker, v, tri, delta, mu, X, q_a, q_b
):  # pragma: no cover - compiled
    """Where polygon ``poly`` (part of triangle ``t``) lies against a blocker's sheet:
    :data:`BEHIND`, :data:`IN_FRONT` or :data:`ACROSS` (also: not decided).

    A ray that meets blocker triangle ``b`` crosses ``b``'s plane there, once.  Where the
    part of ``poly`` inside the cone of rays through ``b`` (widened by ``mu``) lies on the
    far side of that plane (from ``v``) by ``2 delta``, every such ray meets ``b`` before
    ``t``; where it lies on ``v``'s side by ``2 delta``, ``t`` comes first.  ``poly`` is
    behind the blocker when it is behind each of its triangles whose cone it enters.
    """
    behind, front, met = True, True, False
    for j in range(n_blocker):
        b = blocker[j]
        if b == t:
            return ACROSS
        _relative(tri, b, v, X)
        n0, n1, n2, side = _plane(X)
        sign = -1.0 if side > 0 else 1.0  # distances measured away from v
        # only the part of poly inside the cone of rays through b matters
        for i in range(n_poly):
            for c in range(3):
                q_a[i, c] = poly[i, c]
        n = n_poly
        for k in range(3):
            P, Q, Z = X[k], X[(k + 1) % 3], X[(k + 2) % 3]
            m0, m1, m2 = _cross(P[0], P[1], P[2], Q[0], Q[1], Q[2])
            norm = math.sqrt(m0 * m0 + m1 * m1 + m2 * m2)
            if not norm > 0:
                return ACROSS
            if m0 * Z[0] + m1 * Z[1] + m2 * Z[2] < 0:
                norm = -norm
            n = _clip(q_a, n, q_b, m0 / norm, m1 / norm, m2 / norm, mu)
            for i in range(n):
                for c in range(3):
                    q_a[i, c] = q_b[i, c]
            if n == 0:
                break
        for i in range(n):
            met = True
            h = sign * (n0 * (q_a[i, 0] - X[0, 0]) + n1 * (q_a[i, 1] - X[0, 1]) + n2 * (q_a[i, 2] - X[0, 2]))
            behind = behind and h > 2.0 * delta
            front = front and h < -2.0 * delta
        if not (behind or front):
            return ACROSS
    if not met:
        return ACROSS
    return BEHIND if behind else IN_FRONT


@numba.njit(cache=True, nogil=True, error_model="numpy")
def _against_blockers(
    poly, n_poly, t, blocks, starts, n_blocks, v, tri, delta, mu, X, q_a, q_b
):  # pragma: no cover - compiled
    """:func:`_against` for the frustum's blockers: behind one of them, else in front of one, else across."""
    out = ACROSS
    for j in range(n_blocks):
        a, b = starts[j], starts[j + 1]
        c = _against(poly, n_poly, t, blocks[a:b], b - a, v, tri, delta, mu, X, q_a, q_b)
        if c == BEHIND:
            return BEHIND
        if c == IN_FRONT:
            out = IN_FRONT
    return out


@numba.njit(cache=True, nogil=True, error_model="numpy")
def _box_meets(lo, hi, k, v, planes, axis, far, mu):  # pragma: no cover - compiled
    """Whether node ``k``'s box may meet the frustum widened by ``mu`` and cut at ``far``."""
    for p in range(FRUSTUM_PLANES):
        best = 0.0
        for c in range(3):
            a = planes[p, c] * (lo[k, c] - v[c])
            b = planes[p, c] * (hi[k, c] - v[c])
            best += max(a, b)
        if best + mu < 0:
            return False
    deepest = 0.0
    for c in range(3):
        deepest += max(axis[c] * (lo[k, c] - v[c]), axis[c] * (hi[k, c] - v[c]))
    if deepest + mu < 0:
        return False  # behind v (see _constraint)
    if far != np.inf:
        near = 0.0
        for c in range(3):
            a = axis[c] * (lo[k, c] - v[c])
            b = axis[c] * (hi[k, c] - v[c])
            near += min(a, b)
        if near > far + mu:
            return False
    return True


@numba.njit(cache=True, nogil=True, error_model="numpy")
def _first_hit(v, d, t_max, skip, tri, lo, hi, first, count, order, stack):  # pragma: no cover - compiled
    """The triangle that the ray ``v + s d``, ``0 < s < t_max``, meets first (not ``skip``); -1 if none.

    A plain float64 ray cast through the hierarchy (slab test, then Möller-Trumbore): it
    only proposes seeds, whose blockers are proved by :func:`_walk`.
    """
    inv0 = 1.0 / d[0] if d[0] != 0 else np.inf
    inv1 = 1.0 / d[1] if d[1] != 0 else np.inf
    inv2 = 1.0 / d[2] if d[2] != 0 else np.inf
    best, best_t = -1, t_max
    top = 0
    stack[0] = 0
    while top >= 0:
        k = stack[top]
        top -= 1
        near, far = 0.0, best_t
        for c, inv in ((0, inv0), (1, inv1), (2, inv2)):
            if inv == np.inf:
                if v[c] < lo[k, c] or v[c] > hi[k, c]:
                    near, far = 1.0, 0.0
                continue
            ta = (lo[k, c] - v[c]) * inv
            tb = (hi[k, c] - v[c]) * inv
            near = max(near, min(ta, tb))
            far = min(far, max(ta, tb))
        if near > far:
            continue
        if count[k] == 0:
            top += 1
            stack[top] = first[k]
            top += 1
            stack[top] = first[k] + 1
            continue
        for i in range(first[k], first[k] + count[k]):
            f = order[i]
            if f == skip:
                continue
            e10, e11, e12 = (
                tri[f, 1, 0] - tri[f, 0, 0],
                tri[f, 1, 1] - tri[f, 0, 1],
                tri[f, 1, 2] - tri[f, 0, 2],
            )
            e20, e21, e22 = (
                tri[f, 2, 0] - tri[f, 0, 0],
                tri[f, 2, 1] - tri[f, 0, 1],
                tri[f, 2, 2] - tri[f, 0, 2],
            )
            p0, p1, p2 = _cross(d[0], d[1], d[2], e20, e21, e22)
            det = e10 * p0 + e11 * p1 + e12 * p2
            if det == 0:
                continue
            s0, s1, s2 = v[0] - tri[f, 0, 0], v[1] - tri[f, 0, 1], v[2] - tri[f, 0, 2]
            u = (s0 * p0 + s1 * p1 + s2 * p2) / det
            if u < 0 or u > 1:
                continue
            q0, q1, q2 = _cross(s0, s1, s2, e10, e11, e12)
            w = (d[0] * q0 + d[1] * q1 + d[2] * q2) / det
            if w < 0 or u + w > 1:
                continue
            h = (e20 * q0 + e21 * q1 + e22 * q2) / det
            if 0 < h < best_t:
                best, best_t = f, h
    return best


@numba.njit(cache=True, nogil=True, error_model="numpy")
def _cone_of(poly, n_poly, cut, probes, margin):  # pragma: no cover - compiled
    """The cone of rays through convex polygon ``poly``: its planes, and probe rays inside it.

    Writes the unit inward normals of the planes through ``v`` and ``poly``'s edges to
    ``cut`` and rays strictly inside all of them (their points at least ``margin`` inside,
    towards the polygon's centre and the centres of its fan triangles) to ``probes``;
    returns both counts.  No probe: the polygon has no area seen from ``v``.
    """
    for c in range(3):
        probes[0, c] = 0.0
    for i in range(n_poly):
        for c in range(3):
            probes[0, c] += poly[i, c] / n_poly
    n_cut = 0
    for i in range(n_poly):
        P, Q = poly[i], poly[(i + 1) % n_poly]
        m0, m1, m2 = _cross(P[0], P[1], P[2], Q[0], Q[1], Q[2])
        norm = math.sqrt(m0 * m0 + m1 * m1 + m2 * m2)
        if not norm > 0:
            continue  # a repeated vertex bounds nothing
        if m0 * probes[0, 0] + m1 * probes[0, 1] + m2 * probes[0, 2] < 0:
            norm = -norm
        cut[n_cut, 0], cut[n_cut, 1], cut[n_cut, 2] = m0 / norm, m1 / norm, m2 / norm
        n_cut += 1
    for i in range(1, n_poly - 1):
        for c in range(3):
            probes[i, c] = (poly[0, c] + poly[i, c] + poly[i + 1, c]) / 3.0
    n_probes = 0
    for i in range(max(n_poly - 1, 1)):
        lp = math.sqrt(probes[i, 0] ** 2 + probes[i, 1] ** 2 + probes[i, 2] ** 2)
        inside = n_cut >= 3
        for k in range(n_cut):
            if (
                not cut[k, 0] * probes[i, 0] + cut[k, 1] * probes[i, 1] + cut[k, 2] * probes[i, 2]
                > margin + PROBE_SLACK * lp
            ):
                inside = False
                break
        if inside:
            for c in range(3):
                probes[n_probes, c] = probes[i, c]
            n_probes += 1
    return n_cut, n_probes


@numba.njit(cache=True, nogil=True, error_model="numpy")
def _hidden_in_cut(
    t, poly, n_poly, planes, axis, seeds, v, tri, wid, face_edge, edge_start, edge_face, filler, lo, hi, first,
    count, order, delta, eta, mu, cut, cap, T, probe, blocker, cand, X, Y, clip_a, clip_b, stack, found, fill, seg,
):  # fmt: skip  # pragma: no cover - compiled
    """Whether a blocker lies before triangle ``t`` for every ray that reaches ``poly``.

    ``poly`` is the part of ``t`` inside the (widened) frustum; the rays through it form the
    convex cone of the planes through ``v`` and ``poly``'s edges, inside the cone of rays
    through ``t``: edges that touch ``t`` from outside that cone are not tested
    (:func:`_off_cone`).
    """
    _relative(tri, t, v, T)
    if _sees_plane(T, delta) == 0:
        return False
    # t only touching the frustum (along a line or at a point) is seen through it by no
    # set of rays of positive measure; but a sliver as thin as that everywhere is seen by
    # some (a ray aimed at it hits it), and only a blocker proves it hidden
    n0 = _clip_triangle(T, planes, FRUSTUM_PLANES, axis, np.inf, TOUCH_SLACK * mu, clip_a, clip_b)
    if n0 == 0:
        return True
    touch = TOUCH_WIDTH * TOUCH_SLACK * mu
    if _cone_of(clip_a, n0, cut, probe, touch)[1] == 0 and _cone_of(T, 3, cut, probe, touch)[1] > 0:
        return True
    n_cut, n_probes = _cone_of(poly, n_poly, cut, probe, 0.0)
    if n_probes == 0:
        return False
    lp = math.sqrt(probe[0, 0] ** 2 + probe[0, 1] ** 2 + probe[0, 2] ** 2)
    for c in range(3):
        cap[c] = probe[0, c] / lp  # the cone's axis (see _constraint)
    # seeds: the first triangle before t along each probe ray (none: t is seen along it), then
    # the frustum's
    n_cand = 0
    for k in range(n_probes):
        f = _first_hit(v, probe[k], 1.0, t, tri, lo, hi, first, count, order, stack)
        if f < 0:
            return False
        cand[n_cand] = f
        n_cand += 1
    for q in range(len(seeds)):
        cand[n_cand] = seeds[q]
        n_cand += 1
    for q in range(n_cand):
        s = cand[q]
        if s < 0 or s == t:
            continue
        dup = False
        for r in range(q):
            if cand[r] == s:
                dup = True
                break
        if dup:
            continue
        n = _walk(
            s, v, tri, wid, face_edge, edge_start, edge_face, filler, cut, n_cut, cap, t, T, probe, n_probes,
            delta, eta, mu, blocker, X, Y, found, fill, seg,
        )  # fmt: skip
        if n == 0:
            continue
        # the blocker's triangles that meet the cut frustum must all lie before t
        k = 0
        for j in range(n):
            _relative(tri, blocker[j], v, X)
            if _clip_triangle(X, cut, n_cut, cap, np.inf, mu, clip_a, clip_b) > 0:
                blocker[k] = blocker[j]
                k += 1
        if _against(poly, n_poly, t, blocker, k, v, tri, delta, mu, X, clip_a, clip_b) == BEHIND:
            return True
    return False


@numba.njit(cache=True, nogil=True, error_model="numpy")
def _collect(
    mode, v, tri, wid, face_edge, edge_start, edge_face, filler, lo, hi, first, count, order,
    planes, axis, far, delta, eta, mu, keep, blocks, starts, n_blocks, seeds, sc, stack, fz, n_cand,
):  # fmt: skip  # pragma: no cover - compiled
    """Walk the hierarchy over the triangles meeting the frustum before ``far``.

    ``mode`` :data:`ANY`: return 1 at the first (marking nothing); :data:`BLOCKED`: mark
    the blockers' triangles, and the others unless they lie behind a blocker
    (:func:`_behind_a_blocker`) or one is found for the rays that reach them
    (:func:`_hidden_in_cut`); :data:`OPEN`: mark those for which none is found, and that
    the union of the first ``n_cand`` fusion candidates before them does not cover
    (:func:`_cover`, with the scratch ``fz``).  Triangles already marked are skipped.
    Returns the number marked.
    """
    X, Y, poly, tmp, cut, cap, T, probe, blocker, cand, clip_a, clip_b, ray_stack, found, fill, seg = sc
    top = 0
    stack[0] = 0
    marked = 0
    while top >= 0:
        k = stack[top]
        top -= 1
        if not _box_meets(lo, hi, k, v, planes, axis, far, mu):
            continue
        if count[k] == 0:
            top += 1
            stack[top] = first[k]
            top += 1
            stack[top] = first[k] + 1
            continue
        for i in range(first[k], first[k] + count[k]):
            t = order[i]
            if keep[t] and mode != ANY:
                continue
            _relative(tri, t, v, X)
            n_poly = _clip_triangle(X, planes, FRUSTUM_PLANES, axis, far, mu, poly, tmp)
            if n_poly == 0:
                continue
            if mode == ANY:
                return 1
            if mode == BLOCKED:
                # a blocker's own triangles too: another blocker may hide them
                c = _against_blockers(
                    poly, n_poly, t, blocks, starts, n_blocks, v, tri, delta, mu, Y, clip_a, clip_b
                )
                if c == BEHIND:
                    continue
                _relative(tri, t, v, T)
                if _hidden_in_cut(
                    t, poly, n_poly, planes, axis, seeds, v, tri, wid, face_edge, edge_start, edge_face, filler,
                    lo, hi, first, count, order, delta, eta, mu, cut, cap, T, probe, blocker, cand, X, Y,
                    clip_a, clip_b, ray_stack, found, fill, seg,
                ):  # fmt: skip
                    continue
            elif mode == OPEN:
                # hidden behind the union of the triangles before it, or behind a blocker
                if n_cand > 0 and _cover(
                    t, _depth_range(poly, n_poly, axis)[0], n_cand, v, axis, tri, wid, face_edge, edge_start,
                    edge_face, filler, delta, eta, mu, fz, Y, T,
                ) < np.inf:  # fmt: skip
                    continue
                if _hidden_in_cut(
                    t, poly, n_poly, planes, axis, seeds, v, tri, wid, face_edge, edge_start, edge_face, filler,
                    lo, hi, first, count, order, delta, eta, mu, cut, cap, T, probe, blocker, cand, X, Y,
                    clip_a, clip_b, ray_stack, found, fill, seg,
                ):  # fmt: skip
                    continue
            keep[t] = mode  # BLOCKED or OPEN: why the triangle is kept
            marked += 1
    return marked


@numba.njit(cache=True, nogil=True, error_model="numpy")
def _clip2(pu, pw, n, a, b, c, ou, ow):  # pragma: no cover - compiled
    """Keep the part of the (u, w) polygon ``pu, pw [:n]`` where ``a + b u + c w >= 0``.

    Writes it to ``ou, ow`` and returns its size; -1 when it would exceed their length.
    """
    k = 0
    for i in range(n):
        j = (i + 1) % n
        fi = a + b * pu[i] + c * pw[i]
        fj = a + b * pu[j] + c * pw[j]
        if fi >= 0:
            if k == len(ou):
                return -1
            ou[k], ow[k] = pu[i], pw[i]
            k += 1
        if (fi >= 0) != (fj >= 0):
            if k == len(ou):
                return -1
            t = fi / (fi - fj)
            ou[k], ow[k] = pu[i] + t * (pu[j] - pu[i]), pw[i] + t * (pw[j] - pw[i])
            k += 1
    return k


@numba.njit(cache=True, nogil=True, error_model="numpy")
def _width2(pu, pw, n):  # pragma: no cover - compiled
    """Width of the convex (u, w) polygon ``pu, pw [:n]``: its least extent across one of its sides."""
    width = 0.0 if n < 3 else np.inf
    for i in range(n if n >= 3 else 0):
        j = (i + 1) % n
        eu, ew = pu[j] - pu[i], pw[j] - pw[i]
        length = math.sqrt(eu * eu + ew * ew)
        if not length > 0:
            continue
        reach = 0.0
        for k in range(n):
            reach = max(reach, abs(eu * (pw[k] - pw[i]) - ew * (pu[k] - pu[i])) / length)
        width = min(width, reach)
    return 0.0 if width == np.inf else width


@numba.njit(cache=True, nogil=True, error_model="numpy")
def _sealed(
    t, k, X, v, tri, wid, face_edge, edge_start, edge_face, filler, delta, eta, Y
):  # pragma: no cover - compiled
    """Whether side ``k`` of triangle ``t`` (corners ``X``) is shared, exactly, with a face on the
    other side of the plane through ``v`` and the side (by a margin): rays just past the side
    meet that face, so the side needs no margin where both are used."""
    e = face_edge[t, k]
    if e < 0:
        return False
    P, Q, Z = X[k], X[(k + 1) % 3], X[(k + 2) % 3]
    m0, m1, m2 = _cross(P[0], P[1], P[2], Q[0], Q[1], Q[2])
    ez = Z[0] * m0 + Z[1] * m1 + Z[2] * m2
    if abs(ez) <= _edge_tolerance(P, Q, m0, m1, m2, Z, delta, eta, True):
        return False
    a, b = wid[t, k], wid[t, (k + 1) % 3]
    for h in range(edge_start[e], edge_start[e + 1]):
        g = edge_face[h]
        if (
            g != t
            and filler[g] < 0
            and _other_side(g, a, b, P, Q, m0, m1, m2, ez, v, tri, wid, delta, eta, Y)
        ):
            return True
    return False


@numba.njit(cache=True, nogil=True, error_model="numpy")
def _fusion_candidates(
    v, planes, axis, tri, filler, lo, hi, first, count, order, delta, mu, cand, near, deep, X, poly, tmp, stack,
):  # fmt: skip  # pragma: no cover - compiled
    """The nearest triangles meeting the frustum that may cover part of it, nearest first.

    Writes at most ``len(cand)`` of them to ``cand`` with the nearest and deepest depth of
    their part in the frustum widened by ``mu`` (``near``, ``deep``); returns how many.
    Triangles whose plane passes near ``v`` and slivers whose corners lie on one line
    cover nothing.
    """
    n_cand = 0
    top = 0
    stack[0] = 0
    while top >= 0:
        k = stack[top]
        top -= 1
        if not _box_meets(lo, hi, k, v, planes, axis, np.inf, mu):
            continue
        if count[k] == 0:
            top += 1
            stack[top] = first[k]
            top += 1
            stack[top] = first[k] + 1
            continue
        for i in range(first[k], first[k] + count[k]):
            t = order[i]
            if filler[t] >= 0:
                continue
            _relative(tri, t, v, X)
            if _sees_plane(X, delta) == 0:
                continue
            n_poly = _clip_triangle(X, planes, FRUSTUM_PLANES, axis, np.inf, mu, poly, tmp)
            if n_poly == 0:
                continue
            a, b = _depth_range(poly, n_poly, axis)
            slot = n_cand
            if n_cand == len(cand):  # full: replace the farthest, if farther
                slot = 0
                for j in range(1, n_cand):
                    if near[j] > near[slot]:
                        slot = j
                if near[slot] <= a:
                    continue
            else:
                n_cand += 1
            cand[slot], near[slot], deep[slot] = t, a, b
    for i in range(1, n_cand):
        j = i
        while j > 0 and near[j - 1] > near[j]:
            cand[j - 1], cand[j] = cand[j], cand[j - 1]
            near[j - 1], near[j] = near[j], near[j - 1]
            deep[j - 1], deep[j] = deep[j], deep[j - 1]
            j -= 1
    return n_cand


@numba.njit(cache=True, nogil=True, error_model="numpy")
def _seal_candidates(
    n_cand, cand, planes, axis, v, tri, wid, face_edge, edge_start, edge_face, filler, delta, eta, mu, sealed,
    seg, X, Y,
):  # fmt: skip  # pragma: no cover - compiled
    """For each side of each fusion candidate: whether faces on its other side continue the cover.

    A side is sealed when :func:`_sealed` (a welded neighbour), or when the sides of other
    candidates that lie on its line (within :data:`FUSE_COLLINEAR` times ``delta``: a
    T-junction, a corner of one face on the side of another), with their faces on its
    other side, span the stretch of the side inside the frustum widened by ``mu``.
    """
    line = FUSE_COLLINEAR * delta
    for q in range(n_cand):
        s = cand[q]
        _relative(tri, s, v, X)
        for k in range(3):
            sealed[q, k] = _sealed(
                s, k, X, v, tri, wid, face_edge, edge_start, edge_face, filler, delta, eta, Y
            )
            if sealed[q, k]:
                continue
            P, Q, Z = X[k], X[(k + 1) % 3], X[(k + 2) % 3]
            # the stretch [t0, t1] of P-Q inside the widened frustum
            t0, t1 = 0.0, 1.0
            for c in range(FRUSTUM_PLANES + 1):
                p0, p1, p2, off = _constraint(c, planes, FRUSTUM_PLANES, axis, np.inf, mu)
                fp = p0 * P[0] + p1 * P[1] + p2 * P[2] + off
                fq = p0 * Q[0] + p1 * Q[1] + p2 * Q[2] + off
                if fp < 0 and fq < 0:
                    t0, t1 = 1.0, 0.0
                    break
                if fp < 0:
                    t0 = max(t0, fp / (fp - fq))
                elif fq < 0:
                    t1 = min(t1, fp / (fp - fq))
            if t0 > t1:
                sealed[q, k] = True  # the side misses the frustum: nothing to seal
                continue
            lx, ly, lz = Q[0] - P[0], Q[1] - P[1], Q[2] - P[2]
            ll = lx * lx + ly * ly + lz * lz
            if not ll > 0:
                continue
            m0, m1, m2 = _cross(P[0], P[1], P[2], Q[0], Q[1], Q[2])
            ez = Z[0] * m0 + Z[1] * m1 + Z[2] * m2
            if abs(ez) <= _edge_tolerance(P, Q, m0, m1, m2, Z, delta, eta, True):
                continue
            n_seg = 0
            for j in range(n_cand):
                g = cand[j]
                if g == s:
                    continue
                for e in range(3):
                    # side e of g on the line of P-Q: both ends within `line` of it
                    on = True
                    for end in (e, (e + 1) % 3):
                        rx = tri[g, end, 0] - v[0] - P[0]
                        ry = tri[g, end, 1] - v[1] - P[1]
                        rz = tri[g, end, 2] - v[2] - P[2]
                        c0, c1, c2 = _cross(rx, ry, rz, lx, ly, lz)
                        if not c0 * c0 + c1 * c1 + c2 * c2 <= line * line * ll:
                            on = False
                            break
                    if not on:
                        continue
                    # g's third corner on the other side of the plane through v and P-Q
                    for d in range(3):
                        Y[0, d] = tri[g, (e + 2) % 3, d] - v[d]
                    ey = Y[0, 0] * m0 + Y[0, 1] * m1 + Y[0, 2] * m2
                    if ez * ey >= 0 or abs(ey) <= _edge_tolerance(P, Q, m0, m1, m2, Y[0], delta, eta, True):
                        continue
                    if n_seg == len(seg):
                        break
                    a, b = 0.0, 0.0
                    for end in range(2):
                        r = (e + end) % 3
                        s0 = ((tri[g, r, 0] - v[0] - P[0]) * lx + (tri[g, r, 1] - v[1] - P[1]) * ly
                              + (tri[g, r, 2] - v[2] - P[2]) * lz) / ll  # fmt: skip
                        if end == 0:
                            a = s0
                        else:
                            b = s0
                    seg[n_seg, 0], seg[n_seg, 1] = min(a, b), max(a, b)
                    n_seg += 1
            # those stretches must span [t0, t1]: sweep them from t0
            reach = t0
            progress = True
            while progress and reach < t1:
                progress = False
                for j in range(n_seg):
                    if seg[j, 0] <= reach and seg[j, 1] > reach:
                        reach = seg[j, 1]
                        progress = True
            sealed[q, k] = reach >= t1


@numba.njit(cache=True, nogil=True, error_model="numpy")
def _half_planes(
    X, grow, sealed, rays, reach, axis, right, up, delta, eta, hp
):  # pragma: no cover - compiled
    """The rays of a triangle (corners ``X``) in the frustum's ``(u, w)``: three half-planes.

    Row ``k`` of ``hp`` is ``a, b, c, slack`` of ``a + b u + c w >= 0`` for side ``k``
    (``d . (P x Q)`` with the sign of the triangle's orientation, ``d = axis + u right +
    w up``), moved by the margin of :func:`_edge_tolerance` bounded over the frustum's
    rays (its ``delta`` terms are norms of linear functions of the ray, largest at a
    corner ray ``rays[:4]``; ``reach`` is the longest): out when ``grow`` (every ray that
    may reach the triangle), else in (rays that surely hit it), except across a side that
    is ``sealed`` (:func:`_seal_candidates`).
    ``slack`` is :data:`FUSE_SLACK` in the units of ``a + b u + c w``.
    """
    n0, n1, n2 = _cross(X[1, 0], X[1, 1], X[1, 2], X[2, 0], X[2, 1], X[2, 2])
    sign = 1.0 if X[0, 0] * n0 + X[0, 1] * n1 + X[0, 2] * n2 > 0 else -1.0
    for k in range(3):
        P, Q = X[k], X[(k + 1) % 3]
        m0, m1, m2 = _cross(P[0], P[1], P[2], Q[0], Q[1], Q[2])
        m0, m1, m2 = sign * m0, sign * m1, sign * m2
        hp[k, 0] = axis[0] * m0 + axis[1] * m1 + axis[2] * m2
        hp[k, 1] = right[0] * m0 + right[1] * m1 + right[2] * m2
        hp[k, 2] = up[0] * m0 + up[1] * m1 + up[2] * m2
        if grow or not sealed[k]:
            turn = 0.0  # the largest |Q x d| + |d x P| over the frustum's rays d
            for c in range(4):
                d = rays[c]
                a0, a1, a2 = _cross(Q[0], Q[1], Q[2], d[0], d[1], d[2])
                b0, b1, b2 = _cross(d[0], d[1], d[2], P[0], P[1], P[2])
                turn = max(
                    turn, math.sqrt(a0 * a0 + a1 * a1 + a2 * a2) + math.sqrt(b0 * b0 + b1 * b1 + b2 * b2)
                )
            lm = math.sqrt(m0 * m0 + m1 * m1 + m2 * m2)
            margin = 2.0 * (delta * turn + eta * reach * lm)
            hp[k, 0] += margin if grow else -margin
        hp[k, 3] = FUSE_SLACK * math.sqrt(hp[k, 1] ** 2 + hp[k, 2] ** 2)


@numba.njit(cache=True, nogil=True, error_model="numpy")
def _cover(
    t, near_t, n_cand, v, axis, tri, wid, face_edge, edge_start, edge_face, filler, delta, eta, mu, fz, X, Y
):  # pragma: no cover - compiled
    """Occluder fusion: whether the union of the nearest triangles covers the frustum's rays,
    all of them (``t < 0``) or those that may reach triangle ``t`` (from depth ``near_t``).

    The frustum's rays are ``axis + u right + w up`` over its box; each triangle's rays
    are three half-planes in ``(u, w)`` (:func:`_half_planes`; moved out for ``t``, in
    for the triangles that cover).  Starting from the box (cut to ``t``'s rays), the part
    not yet covered is kept as convex pieces, and each candidate (:func:`_fusion_candidates`),
    nearest first, is cut out of them: a piece it enters leaves at most three pieces
    outside it.  For ``t`` only candidates wholly before it count (deepest depth ``2 mu``
    before ``near_t``).  Pieces thinner than :data:`FUSE_SLIVER` times ``eta`` are the
    rounding of cuts along a shared side, and are dropped.

    Returns the deepest depth of the candidates that cut something, plus ``mu``, once
    nothing is left (``-inf`` when nothing was to cover); ``inf`` when a cap is hit or the
    cover has a hole.
    """
    cand, near, deep, sealed, pu, pw, pn, qu, qw, qn, hp, cu, cw, ru, rw, right, up, box, rays = fz
    sliver = FUSE_SLIVER * eta
    reach = 0.0  # longest corner ray: bounds the margins over the frustum
    for k in range(4):
        reach = max(reach, math.sqrt(rays[k, 0] ** 2 + rays[k, 1] ** 2 + rays[k, 2] ** 2))
    cu[0], cu[1], cu[2], cu[3] = box[0], box[1], box[1], box[0]
    cw[0], cw[1], cw[2], cw[3] = box[2], box[2], box[3], box[3]
    n = 4
    if t >= 0:
        _relative(tri, t, v, X)
        _half_planes(X, True, sealed[0], rays, reach, axis, right, up, delta, eta, hp)
        for k in range(3):
            n = _clip2(cu, cw, n, hp[k, 0] + hp[k, 3], hp[k, 1], hp[k, 2], ru, rw)
            if n < 0:
                return np.inf
            for i in range(n):
                cu[i], cw[i] = ru[i], rw[i]
    if _width2(cu, cw, n) <= sliver:
        return -np.inf
    pn[0] = n
    for i in range(n):
        pu[0, i], pw[0, i] = cu[i], cw[i]
    n_pieces = 1
    far = -np.inf
    for q in range(n_cand):
        s = cand[q]
        if t >= 0:
            if near[q] + 2.0 * mu >= near_t:
                break  # the rest start no nearer
            if s == t or deep[q] + 2.0 * mu >= near_t:
                continue
        _relative(tri, s, v, X)
        _half_planes(X, False, sealed[q], rays, reach, axis, right, up, delta, eta, hp)
        used = False
        n_next = 0
        for p in range(n_pieces):
            n = pn[p]
            # a piece outside one of the half-planes is left whole
            outside = False
            for k in range(3):
                most = -np.inf
                for i in range(n):
                    most = max(most, hp[k, 0] + hp[k, 1] * pu[p, i] + hp[k, 2] * pw[p, i])
                if most <= hp[k, 3]:
                    outside = True
                    break
            if outside:
                if n_next == len(qn):
                    return np.inf
                qn[n_next] = n
                for i in range(n):
                    qu[n_next, i], qw[n_next, i] = pu[p, i], pw[p, i]
                n_next += 1
                continue
            used = True
            # what is left: outside half-plane 0; inside 0, outside 1; inside 0 and 1, outside 2
            for i in range(n):
                cu[i], cw[i] = pu[p, i], pw[p, i]
            for k in range(3):
                if n_next == len(qn):
                    return np.inf
                m = _clip2(cu, cw, n, hp[k, 3] - hp[k, 0], -hp[k, 1], -hp[k, 2], qu[n_next], qw[n_next])
                if m < 0:
                    return np.inf
                if _width2(qu[n_next], qw[n_next], m) > sliver:
                    qn[n_next] = m
                    n_next += 1
                if k == 2:
                    break
                n = _clip2(cu, cw, n, hp[k, 0] + hp[k, 3], hp[k, 1], hp[k, 2], ru, rw)
                if n < 0:
                    return np.inf
                for i in range(n):
                    cu[i], cw[i] = ru[i], rw[i]
                if _width2(cu, cw, n) <= sliver:
                    break
        if used:
            far = max(far, deep[q])
        n_pieces = n_next
        for p in range(n_pieces):
            pn[p] = qn[p]
            for i in range(qn[p]):
                pu[p, i], pw[p, i] = qu[p, i], qw[p, i]
        if n_pieces == 0:
            return far + mu
    return np.inf


@numba.njit(cache=True, nogil=True, error_model="numpy")
def trace_frusta(
    v, roots, root, box, at_limit, seeds,
    tri, wid, face_edge, edge_start, edge_face, filler,
    lo, hi, first, count, order,
    delta, eta, mu, max_walk, fusion, keep, status, far_depth,
):  # fmt: skip  # pragma: no cover - compiled
    """Blockers, far planes and kept triangles of a batch of frusta from ``v``.

    Parameters
    ----------
    v : (3,) float64
        The viewpoint.
    roots : (r, 3, 3) float64
        ``axis``, ``right``, ``up`` of each root.
    root : (n,) int64
        Root of each frustum.
    box : (n, 4) float64
        ``u0, u1, w0, w1`` of each frustum.
    at_limit : (n,) bool
        The frustum may not be split.
    seeds : (n, s) int64
        Seed triangles of each frustum (-1: none).
    tri, wid : (m, 3, 3) float64, (m, 3) int64
        Corners of the triangles and their welded vertex ids.
    face_edge, edge_start, edge_face : int64 arrays
        Edge of each triangle side, and the triangles of each edge (edge ``e``'s are
        ``edge_face[edge_start[e]:edge_start[e + 1]]``).
    filler : (m,) int8
        For a face whose corners lie exactly on one line (it joins a T-junction), the side
        that is its long edge; -1 for other faces.
    lo, hi, first, count, order :
        The :class:`~meshvis.geometry.bvh.Bvh`.
    delta, eta, mu : float
        Length margin, angle margin, and the widening of the frustum and of its far depth.
    max_walk : int
        Most triangles in one blocker.
    fusion : bool
        At the limit, try the union of the triangles meeting a frustum without a blocker
        (:func:`_fuse`).
    keep : (m,) uint8, in/out
        Set for every triangle kept, to the status of the frustum that kept it first
        (:data:`BLOCKED`: in front of a blocker's far plane; :data:`OPEN`: at the limit).
    status : (n,) int8, out
        :data:`EMPTY`, :data:`BLOCKED`, :data:`SPLIT`, :data:`OPEN` or :data:`FUSED` per frustum.
    far_depth : (n,) float64, out
        Far depth of each frustum (``inf`` without a blocker or a covering union).
    """
    n_seeds = seeds.shape[1]
    rays = np.empty((5, 3))
    planes = np.empty((FRUSTUM_PLANES, 3))
    probes = np.empty((len(PROBES), 3))
    blocks = np.empty(n_seeds * max_walk, np.int64)
    starts = np.zeros(n_seeds + 1, np.int64)
    walk = np.empty(max_walk, np.int64)
    sc = (
        np.empty((3, 3)), np.empty((POLY, 3)), np.empty((POLY, 3)), np.empty((POLY, 3)),
        np.empty((POLY, 3)), np.empty(3), np.empty((3, 3)), np.empty((POLY, 3)),
        np.empty(max_walk, np.int64), np.empty(n_seeds + POLY, np.int64),
        np.empty((POLY, 3)), np.empty((POLY, 3)), np.empty(STACK, np.int64),
        np.empty(MAX_SPAN, np.int64), np.empty(MAX_FILLERS, np.int64), np.empty((MAX_SPAN, 2)),
    )  # fmt: skip
    found, fill, seg = sc[13], sc[14], sc[15]
    cand = np.empty(FUSE_TRIANGLES, np.int64)
    near, deep = np.empty(FUSE_TRIANGLES), np.empty(FUSE_TRIANGLES)
    sealed = np.zeros((FUSE_TRIANGLES, 3), np.bool_)
    pu, pw = np.empty((FUSE_PIECES, PIECE_VERTS)), np.empty((FUSE_PIECES, PIECE_VERTS))
    qu, qw = np.empty((FUSE_PIECES, PIECE_VERTS)), np.empty((FUSE_PIECES, PIECE_VERTS))
    pn, qn = np.empty(FUSE_PIECES, np.int64), np.empty(FUSE_PIECES, np.int64)
    hp = np.empty((3, 4))
    cu, cw = np.empty(PIECE_VERTS), np.empty(PIECE_VERTS)
    ru, rw = np.empty(PIECE_VERTS), np.empty(PIECE_VERTS)
    X, Y, poly, tmp = sc[0], sc[1], sc[2], sc[3]
    stack = np.empty(STACK, np.int64)
    for i in range(len(root)):
        r = root[i]
        axis = roots[r, 0]
        _frustum_rays(
            axis, roots[r, 1], roots[r, 2], box[i, 0], box[i, 1], box[i, 2], box[i, 3], rays, planes
        )
        for k in range(len(PROBES)):
            _probe_ray(rays, PROBES[k, 0], PROBES[k, 1], probes[k])
        fz = (
            cand, near, deep, sealed, pu, pw, pn, qu, qw, qn, hp, cu, cw, ru, rw, roots[r, 1], roots[r, 2], box[i], rays
        )  # fmt: skip
        far = np.inf
        hit_any = False
        n_blocks = 0
        for j in range(n_seeds):
            s = seeds[i, j]
            if s < 0:
                continue
            hit_any = True
            dup = False
            for q in range(j):
                if seeds[i, q] == s:
                    dup = True
            if dup:
                continue
            n = _walk(
                s, v, tri, wid, face_edge, edge_start, edge_face, filler, planes, FRUSTUM_PLANES, axis,
                -1, X, probes, len(PROBES), delta, eta, mu, walk, X, Y, found, fill, seg,
            )  # fmt: skip
            if n == 0:
                continue
            # keep the members that meet the frustum; the deepest of them is the far depth
            deepest = -np.inf
            a = starts[n_blocks]
            k = a
            for q in range(n):
                _relative(tri, walk[q], v, X)
                n_poly = _clip_triangle(X, planes, FRUSTUM_PLANES, axis, np.inf, mu, poly, tmp)
                if n_poly > 0:
                    deepest = max(deepest, _depth_range(poly, n_poly, axis)[1])
                    blocks[k] = walk[q]
                    k += 1
            n_blocks += 1
            starts[n_blocks] = k
            far = min(far, deepest + mu)
        far_depth[i] = far
        if far < np.inf:
            status[i] = BLOCKED
            _collect(
                BLOCKED, v, tri, wid, face_edge, edge_start, edge_face, filler, lo, hi, first, count, order,
                planes, axis, far, delta, eta, mu, keep, blocks, starts, n_blocks, seeds[i], sc, stack, fz, 0,
            )  # fmt: skip
            continue
        if not hit_any:
            n_any = _collect(
                ANY, v, tri, wid, face_edge, edge_start, edge_face, filler, lo, hi, first, count, order,
                planes, axis, far, delta, eta, mu, keep, blocks, starts, 0, seeds[i], sc, stack, fz, 0,
            )  # fmt: skip
            hit_any = n_any > 0
        if not hit_any:
            status[i] = EMPTY
        elif not at_limit[i]:
            status[i] = SPLIT
        else:
            status[i] = OPEN
            n_cand = 0
            if fusion:
                n_cand = _fusion_candidates(
                    v, planes, axis, tri, filler, lo, hi, first, count, order, delta, mu, cand, near, deep,
                    X, poly, tmp, stack,
                )  # fmt: skip
                _seal_candidates(
                    n_cand, cand, planes, axis, v, tri, wid, face_edge, edge_start, edge_face, filler, delta, eta,
                    mu, sealed, seg, X, Y,
                )  # fmt: skip
                cover = _cover(
                    -1, np.inf, n_cand, v, axis, tri, wid, face_edge, edge_start, edge_face, filler,
                    delta, eta, mu, fz, X, Y,
                )  # fmt: skip
                if cover < np.inf:
                    status[i] = FUSED
                    far = far_depth[i] = cover
            # what lies beyond a covering union's far depth is hidden; the rest is kept
            # unless the union before it covers its rays, or a blocker is found for them
            _collect(
                OPEN, v, tri, wid, face_edge, edge_start, edge_face, filler, lo, hi, first, count, order,
                planes, axis, far, delta, eta, mu, keep, blocks, starts, 0, seeds[i], sc, stack, fz, n_cand,
            )  # fmt: skip


@numba.njit(cache=True, nogil=True, error_model="numpy")
def first_hits(v, d, tri, lo, hi, first, count, order, out):  # pragma: no cover - compiled
    """The triangle each ray ``v + s d[i]`` (``s > 0``) meets first, traced in float64; -1 if none.

    Parameters
    ----------
    v : (3,) float64
        Where the rays start.
    d : (n, 3) float64
        Their directions.
    tri : (m, 3, 3) float64
        The triangles.
    lo, hi, first, count, order :
        The :class:`~meshvis.geometry.bvh.Bvh` of ``tri``.
    out : (n,) int64, out
        The first triangle of each ray.
    """
    stack = np.empty(STACK, np.int64)
    for i in range(len(d)):
        out[i] = _first_hit(v, d[i], np.inf, -1, tri, lo, hi, first, count, order, stack)
