"""Numba kernels of the intersection tests of :mod:`meshvis.geometry.intersect`: broad and narrow phase.

One loop over the candidate pairs, with the arithmetic of the separating-axis and
shared-corner tests written out per pair: no (pairs, axes, corners) temporaries, and the
pairs never leave the cache.  The tests and their tolerances are those documented in
:mod:`meshvis.geometry.intersect`; the comparisons carry a relative slack of
:data:`SLACK` on the reporting side, so that a different order of the floating-point
operations can only add reports (the flags stay conservative).
"""

from __future__ import annotations

import math

import numba
import numpy as np

from meshvis._threads import in_threads
from meshvis.geometry._kernel_constants import (  # shared with the numpy formulations
    COPLANAR,
    INTERSECTS,
    NEAR_CELL_FLOOR,
    PROJ_SLACK,
    SLACK,
    TOO_CLOSE,
    WEDGE_SLACK,
)

# The kernels are serial and release the GIL; the large ones (the narrow phase, the face
# axes, the corner gather) run on slices in threads (meshvis._threads.in_threads), and
# their helpers are left to LLVM's inlining: numba's parallel loops and its own inlining
# (inline="always") cost them seconds of compilation on first use and gain no speed.


@numba.njit(cache=True, nogil=True, error_model="numpy")
def _proj_gap(ax, ay, az, T, lo, hi):
    """Gap between [lo, hi] and the projection of the 3 corners T (3, 3) on the axis."""
    p0 = ax * T[0, 0] + ay * T[0, 1] + az * T[0, 2]
    p1 = ax * T[1, 0] + ay * T[1, 1] + az * T[1, 2]
    p2 = ax * T[2, 0] + ay * T[2, 1] + az * T[2, 2]
    pmin = min(p0, min(p1, p2))
    pmax = max(p0, max(p1, p2))
    return max(pmin - hi, lo - pmax), p0, p1, p2


@numba.njit(cache=True, nogil=True, error_model="numpy")
def _unit_from(T, c, k):
    """Unit vector from corner c to corner k of T, as three scalars (no allocation)."""
    x = T[k, 0] - T[c, 0]
    y = T[k, 1] - T[c, 1]
    z = T[k, 2] - T[c, 2]
    n = math.sqrt(x * x + y * y + z * z)
    return x / n, y / n, z / n


@numba.njit(cache=True, nogil=True, error_model="numpy")
def _in_wedge(T, c, n, dx, dy, dz):
    """Direction d lies in the wedge of T at corner c (counter-clockwise about n)."""
    ax, ay, az = _unit_from(T, c, (c + 1) % 3)
    bx, by, bz = _unit_from(T, c, (c + 2) % 3)
    # (u1 x d) . n and (d x u2) . n
    a = (ay * dz - az * dy) * n[0] + (az * dx - ax * dz) * n[1] + (ax * dy - ay * dx) * n[2]
    b = (dy * bz - dz * by) * n[0] + (dz * bx - dx * bz) * n[1] + (dx * by - dy * bx) * n[2]
    s = -WEDGE_SLACK * (1 + SLACK)
    return a >= s and b >= s


@numba.njit(cache=True, nogil=True, error_model="numpy")
def _sides(T):
    """Side vectors ``T[s + 1] - T[s]`` (3, 3) and their lengths (3,) of one triangle."""
    E = np.empty((3, 3))
    L = np.empty(3)
    for s in range(3):
        t = (s + 1) % 3
        for d in range(3):
            E[s, d] = T[t, d] - T[s, d]
        L[s] = math.sqrt(E[s, 0] * E[s, 0] + E[s, 1] * E[s, 1] + E[s, 2] * E[s, 2])
    return E, L


@numba.njit(cache=True, nogil=True, error_model="numpy")
def _side(T, s):
    """Side ``T[s + 1] - T[s]`` of a triangle and its length, as four scalars."""
    t = (s + 1) % 3
    x = T[t, 0] - T[s, 0]
    y = T[t, 1] - T[s, 1]
    z = T[t, 2] - T[s, 2]
    return x, y, z, math.sqrt(x * x + y * y + z * z)


@numba.njit(cache=True, nogil=True, error_model="numpy")
def _edge_axis_gap(ei, ej, Ti, Tj, tau):
    """Gap between two triangles along the cross product of sides ``ei`` and ``ej`` (unit length).

    ``-inf`` when the sides are too close to parallel for a reliable axis (sine of their
    angle at most ``tau``): such an axis is skipped.
    """
    ex = ei[1] * ej[2] - ei[2] * ej[1]
    ey = ei[2] * ej[0] - ei[0] * ej[2]
    ez = ei[0] * ej[1] - ei[1] * ej[0]
    length = math.sqrt(ex * ex + ey * ey + ez * ez)
    if not length > tau * ei[3] * ej[3]:
        return -np.inf
    g, p0, p1, p2 = _proj_gap(ex, ey, ez, Ti, 0.0, 0.0)
    lo_i = min(p0, min(p1, p2))
    hi_i = max(p0, max(p1, p2))
    g, p0, p1, p2 = _proj_gap(ex, ey, ez, Tj, lo_i, hi_i)
    return g / length


@numba.njit(cache=True, nogil=True, error_model="numpy")
def pair_flags(i, j, order, tri, fw, axes, valid, has_normal, low, high, eps, near, tau, cos_angle, cos_fold):
    """(intersects, coplanar, too_close, folded) of the faces in rows ``i`` and ``j``.

    Faces are stored in the spatial order ``order`` (input id of each row); the pair is
    tested with the face of the smaller input id first, whatever its rows.
    """
    pad = max(eps, near)
    eps_r = eps * (1 + SLACK)
    near_r = near * (1 + SLACK)
    pad_r = pad * (1 + SLACK)
    inter = False
    close = False
    fold = False
    if order[i] > order[j]:  # as (smaller, larger) input id, the orientation of the tests
        i, j = j, i
    Ti = tri[i]
    Tj = tri[j]
    nshared = 0
    ci = -1
    cj = -1
    for a in range(3):
        for b in range(3):
            if fw[i, a] == fw[j, b]:
                nshared += 1
                ci = a
                cj = b
    # stage 1: the 4 axes of each face, the normals first
    max_gap = -np.inf
    in_plane = -np.inf
    mid_i = 0.5 * (low[i, 0] + high[i, 0])
    mid_j = 0.5 * (low[j, 0] + high[j, 0])
    g, p0, p1, p2 = _proj_gap(axes[i, 0, 0], axes[i, 0, 1], axes[i, 0, 2], Tj, low[i, 0], high[i, 0])
    dev_j = max(abs(p0 - mid_i), max(abs(p1 - mid_i), abs(p2 - mid_i)))  # j's corners from i's plane
    if valid[i, 0]:
        max_gap = g
    g, p0, p1, p2 = _proj_gap(axes[j, 0, 0], axes[j, 0, 1], axes[j, 0, 2], Ti, low[j, 0], high[j, 0])
    dev_i = max(abs(p0 - mid_j), max(abs(p1 - mid_j), abs(p2 - mid_j)))
    if valid[j, 0]:
        max_gap = max(max_gap, g)
    both = has_normal[i] and has_normal[j]
    cosn = axes[i, 0, 0] * axes[j, 0, 0] + axes[i, 0, 1] * axes[j, 0, 1] + axes[i, 0, 2] * axes[j, 0, 2]
    flat = both and abs(cosn) >= cos_angle * (1 - SLACK) and dev_j <= eps_r and dev_i <= eps_r
    # A gap along a normal above pad_r leaves a face's corners that far from the other's
    # plane: not flat, so nothing to report for a pair apart; and a pair sharing a corner
    # that is not flat needs no in-plane axis either (its tests below use the normals)
    if nshared == 0 and max_gap > pad_r:
        return False, False, False, False
    if nshared == 0 or flat:
        for k in range(1, 4):
            if valid[i, k]:
                g = _proj_gap(axes[i, k, 0], axes[i, k, 1], axes[i, k, 2], Tj, low[i, k], high[i, k])[0]
                max_gap = max(max_gap, g)
                in_plane = max(in_plane, g)
            if valid[j, k]:
                g = _proj_gap(axes[j, k, 0], axes[j, k, 1], axes[j, k, 2], Ti, low[j, k], high[j, k])[0]
                max_gap = max(max_gap, g)
                in_plane = max(in_plane, g)
            # apart along an in-plane axis: not intersecting nor too close, and not
            # overlapping in one plane either (in_plane is then above -eps)
            if nshared == 0 and max_gap > pad_r:
                return False, False, False, False
    copl = flat and in_plane < -eps * (1 - SLACK)
    if nshared == 0:
        # stage 2: edge x edge axes, until one shows the pair apart
        for a in range(3):
            ei = _side(Ti, a)
            for b in range(3):
                g = _edge_axis_gap(ei, _side(Tj, b), Ti, Tj, tau)
                max_gap = max(max_gap, g)
                if max_gap > pad_r:
                    return False, copl, False, False
        inter = (not flat) and max_gap <= eps_r
        close = max_gap <= near_r
    elif not flat:
        if nshared == 1 and both:
            ni = axes[i, 0]
            nj = axes[j, 0]
            lx = ni[1] * nj[2] - ni[2] * nj[1]
            ly = ni[2] * nj[0] - ni[0] * nj[2]
            lz = ni[0] * nj[1] - ni[1] * nj[0]
            length = math.sqrt(lx * lx + ly * ly + lz * lz)
            if length > tau:
                lx /= length
                ly /= length
                lz /= length
                meet = (_in_wedge(Ti, ci, ni, lx, ly, lz) and _in_wedge(Tj, cj, nj, lx, ly, lz)) or (
                    _in_wedge(Ti, ci, ni, -lx, -ly, -lz) and _in_wedge(Tj, cj, nj, -lx, -ly, -lz)
                )
            else:
                meet = True
            inter = meet
            close = meet
        elif nshared == 2 and both:
            fold = _folded(Ti, Tj, fw[i], fw[j], cos_fold)
    return inter, copl, close, fold


@numba.njit(cache=True, nogil=True, error_model="numpy")
def narrow_phase(
    order,
    tri,
    fw,
    axes,
    valid,
    has_normal,
    low,
    high,
    pairs,
    eps,
    near,
    tau,
    cos_angle,
    cos_fold,
    inter,
    copl,
    close,
    fold,
):
    """Per-pair (intersects, coplanar, too_close, folded) flags; see ``classify_pairs``.

    The flags of :func:`pair_flags` of every pair are set in ``inter``, ``copl``, ``close``
    and ``fold`` (p,), which come in all False.
    """
    for q in range(pairs.shape[0]):
        inter[q], copl[q], close[q], fold[q] = pair_flags(
            pairs[q, 0],
            pairs[q, 1],
            order,
            tri,
            fw,
            axes,
            valid,
            has_normal,
            low,
            high,
            eps,
            near,
            tau,
            cos_angle,
            cos_fold,
        )


@numba.njit(cache=True, nogil=True, error_model="numpy")
def broad_narrow(
    first,
    starts,
    counts,
    ent,
    key,
    cell_rows,
    cell,
    lo,
    hi,
    bits,
    m,
    order,
    tri,
    fw,
    axes,
    valid,
    has_normal,
    low,
    high,
    eps,
    near,
    tau,
    cos_angle,
    cos_fold,
):
    """The pairs of :func:`broad_pairs` tested by :func:`pair_flags` as they are met.

    Only the pairs with a flag come out: (k,) int64 keys ``i * m + j`` (``i < j``, rows) and
    (k,) uint8 codes (:data:`INTERSECTS` | :data:`COPLANAR` | :data:`TOO_CLOSE`; a fold counts
    as coplanar), so that memory follows the flagged pairs, not the candidates.
    """
    cap = 64 + first.shape[0]
    out = np.empty(cap, np.int64)
    code = np.empty(cap, np.uint8)
    n = 0
    for q in range(first.shape[0]):
        a = first[q]
        for o in range(starts[q], starts[q] + counts[q]):
            b = ent[o]
            la = cell_rows[q] if cell_rows.shape[0] else cell[a]
            if not _meets_here(a, b, la, cell[b], key[q], lo, hi, bits):
                continue
            i = min(a, b)
            j = max(a, b)
            f_int, f_copl, f_close, f_fold = pair_flags(
                i, j, order, tri, fw, axes, valid, has_normal, low, high, eps, near, tau, cos_angle, cos_fold
            )
            c = (
                (INTERSECTS if f_int else 0)
                | (COPLANAR if (f_copl or f_fold) else 0)
                | (TOO_CLOSE if f_close else 0)
            )
            if c == 0:
                continue
            if n == cap:
                cap *= 2
                out = _grown(out, n, cap)
                code = _grown(code, n, cap)
            out[n] = i * m + j
            code[n] = c
            n += 1
    return out[:n].copy(), code[:n].copy()


@numba.njit(cache=True, nogil=True, error_model="numpy")
def _folded(Ti, Tj, fi, fj, cos_fold):
    """Two faces on one edge whose other corners lie on the same side, at an angle below the fold.

    ``u`` and ``w`` are the unit vectors from the shared edge to each third corner,
    perpendicular to the edge; their angle is the angle between the two half-planes (0 when
    one face lies folded onto the other).
    """
    # shared edge: the corners of i found in j; k_i, k_j the third corners
    a = -1
    b = -1
    ki = 0
    for c in range(3):
        hit = fi[c] == fj[0] or fi[c] == fj[1] or fi[c] == fj[2]
        if hit:
            if a < 0:
                a = c
            else:
                b = c
        else:
            ki = c
    kj = 0
    for c in range(3):
        if fj[c] != fi[a] and fj[c] != fi[b]:
            kj = c
    ex, ey, ez = _unit_from(Ti, a, b)
    ux = Ti[ki, 0] - Ti[a, 0]
    uy = Ti[ki, 1] - Ti[a, 1]
    uz = Ti[ki, 2] - Ti[a, 2]
    wx = Tj[kj, 0] - Ti[a, 0]
    wy = Tj[kj, 1] - Ti[a, 1]
    wz = Tj[kj, 2] - Ti[a, 2]
    du = ux * ex + uy * ey + uz * ez
    dw = wx * ex + wy * ey + wz * ez
    ux, uy, uz = ux - du * ex, uy - du * ey, uz - du * ez
    wx, wy, wz = wx - dw * ex, wy - dw * ey, wz - dw * ez
    lu = math.sqrt(ux * ux + uy * uy + uz * uz)
    lw = math.sqrt(wx * wx + wy * wy + wz * wz)
    if lu == 0 or lw == 0:
        return False
    return (ux * wx + uy * wy + uz * wz) / (lu * lw) >= cos_fold


@numba.njit(cache=True, nogil=True, error_model="numpy")
def _low_cell(x, h, top):
    """Cell coordinate of ``x`` on a grid of size ``h``, clipped to ``[0, top]`` (as :func:`grid_cells`)."""
    return np.int64(min(max(math.floor(x / h), 0.0), top))


@numba.njit(cache=True, nogil=True, error_model="numpy")
def _meets_here(a, b, la, lb, key_q, lo, hi, bits):
    """Boxes ``a`` and ``b`` overlap, and the lower corner of their overlap lies in cell ``key_q``.

    ``la`` and ``lb`` are the boxes' lower cells on this grid, packed like the keys.  The
    lower cell of the overlap is their larger coordinates, so each overlapping pair is met
    in exactly one of the cells both cover.
    """
    mask = (np.int64(1) << bits) - 1
    cx = max(la >> (2 * bits), lb >> (2 * bits))
    cy = max((la >> bits) & mask, (lb >> bits) & mask)
    cz = max(la & mask, lb & mask)
    # one expression with & (no early exit): most candidates fail one of the seven tests
    # at random, and a branch per test mispredicts about half of them (twice the time)
    return (
        (((cx << (2 * bits)) | (cy << bits) | cz) == key_q)
        & (lo[a, 0] <= hi[b, 0])
        & (lo[b, 0] <= hi[a, 0])
        & (lo[a, 1] <= hi[b, 1])
        & (lo[b, 1] <= hi[a, 1])
        & (lo[a, 2] <= hi[b, 2])
        & (lo[b, 2] <= hi[a, 2])
    )


@numba.njit(cache=True, nogil=True, error_model="numpy")
def broad_pairs(first, starts, counts, ent, key, cell_rows, cell, lo, hi, bits, m):
    """Pairs met in their lowest common grid cell whose boxes overlap (broad phase step).

    Row ``q`` stands for box ``first[q]`` in the cell ``key[q]``; its candidates are the
    boxes ``ent[starts[q] : starts[q] + counts[q]]``.  ``cell`` (m,) holds the lower cell of
    every box on its own level, packed like the keys, ``cell_rows`` (empty, or one per row)
    that of the row's box on this grid when it lives on a finer level.  A pair is kept
    when the cell holding the lower corner of the two boxes' overlap is this cell -- so
    each pair is emitted once -- and the closed boxes overlap on every axis.  Returns (k,)
    int64 pair keys ``i * m + j`` with ``i < j``.
    """
    out = np.empty(counts.sum(), np.int64)
    n = 0
    for q in range(first.shape[0]):
        a = first[q]
        for o in range(starts[q], starts[q] + counts[q]):
            b = ent[o]
            la = cell_rows[q] if cell_rows.shape[0] else cell[a]
            if _meets_here(a, b, la, cell[b], key[q], lo, hi, bits):
                out[n] = min(a, b) * m + max(a, b)
                n += 1
    return out[:n]


@numba.njit(cache=True, nogil=True, error_model="numpy")
def sweep_order(key, x, by_key):
    """Order of grid entries by cell ``key``, then by ``x``, then by position (a stable lexsort).

    ``by_key`` is the stable order of the keys alone (modified in place and returned).
    """
    order = by_key
    n = key.shape[0]
    s = 0
    while s < n:
        e = s + 1
        while e < n and key[order[e]] == key[order[s]]:
            e += 1
        if e - s > 1:
            run = order[s:e].copy()
            xs = np.empty(e - s)
            for k in range(e - s):
                xs[k] = x[run[k]]
            by_x = np.argsort(xs, kind="mergesort")
            for k in range(e - s):
                order[s + k] = run[by_x[k]]
        s = e
    return order


@numba.njit(cache=True, nogil=True, error_model="numpy")
def finer_rows(lo, hi, fine, h, top, bits, gkey, grank, sweep, xs, margin):
    """Rows of the pairs of finer boxes ``fine`` with the entries of a coarser grid.

    Every cell of size ``h`` a fine box covers is looked up among the grid's sorted cell
    keys ``gkey``; a cell found gives a row: the box, the first entry of the cell, the
    entries of the cell that start (in x) before the box ends (the sweep values of
    :class:`meshvis.geometry.intersect._Grid`), and the cell.  Rows without entries are
    left out.  Returns ``first``, ``starts``, ``counts``, ``key`` and ``low`` (r,) int64,
    ``low`` the box's lower cell on this grid, packed like the keys.
    """
    cap = 16 + fine.shape[0]
    low = np.empty(cap, np.int64)
    first = np.empty(cap, np.int64)
    starts = np.empty(cap, np.int64)
    counts = np.empty(cap, np.int64)
    key = np.empty(cap, np.int64)
    n = 0
    ng = gkey.shape[0]
    for t in range(fine.shape[0]):
        f = fine[t]
        a0 = _low_cell(lo[f, 0], h, top)
        a1 = _low_cell(lo[f, 1], h, top)
        a2 = _low_cell(lo[f, 2], h, top)
        b0 = _low_cell(hi[f, 0], h, top)
        b1 = _low_cell(hi[f, 1], h, top)
        b2 = _low_cell(hi[f, 2], h, top)
        packed = (a0 << (2 * bits)) | (a1 << bits) | a2
        for z in range(a2, b2 + 1):
            for y in range(a1, b1 + 1):
                for x in range(a0, b0 + 1):
                    k = (x << (2 * bits)) | (y << bits) | z
                    start = np.searchsorted(gkey, k)
                    if start >= ng or gkey[start] != k:
                        continue
                    end = np.searchsorted(sweep, grank[start] + hi[f, 0] * xs + margin, side="right")
                    if end <= start:
                        continue
                    if n == cap:
                        cap *= 2
                        first = _grown(first, n, cap)
                        starts = _grown(starts, n, cap)
                        counts = _grown(counts, n, cap)
                        key = _grown(key, n, cap)
                        low = _grown(low, n, cap)
                    first[n] = f
                    low[n] = packed
                    starts[n] = start
                    counts[n] = end - start
                    key[n] = k
                    n += 1
    return first[:n].copy(), starts[:n].copy(), counts[:n].copy(), key[:n].copy(), low[:n].copy()


@numba.njit(cache=True, nogil=True)
def _grown(a, n, cap):
    """A copy of ``a[:n]`` with room for ``cap`` entries."""
    out = np.empty(cap, a.dtype)
    out[:n] = a[:n]
    return out


@numba.njit(cache=True, nogil=True, error_model="numpy")
def face_axes(tri, tau, axes, valid, has_normal, low, high):
    """Per-face separating axes of the narrow phase: unit normal and three in-plane edge normals.

    The arithmetic is that of the numpy formulation (``cross``, ``norm``, one division per
    component), written per face; the projection intervals are widened by
    :data:`PROJ_SLACK`.  Fills ``axes`` (m, 4, 3) (zero rows are unusable), ``valid``
    (m, 4), ``has_normal`` (m,), which come in all zero, and the projection interval
    ``low``, ``high`` (m, 4) of the face on each axis.
    """
    m = tri.shape[0]
    for f in range(m):
        edges, edge_len = _sides(tri[f])
        a = edges[0]
        b = edges[1]
        nx = a[1] * b[2] - a[2] * b[1]
        ny = a[2] * b[0] - a[0] * b[2]
        nz = a[0] * b[1] - a[1] * b[0]
        n_len = math.sqrt(nx * nx + ny * ny + nz * nz)
        # a normal is reliable when sin(angle between two sides) exceeds tau
        if n_len > tau * edge_len[0] * edge_len[1]:
            has_normal[f] = True
            valid[f, 0] = True
            axes[f, 0, 0] = nx / n_len
            axes[f, 0, 1] = ny / n_len
            axes[f, 0, 2] = nz / n_len
        ux = axes[f, 0, 0]
        uy = axes[f, 0, 1]
        uz = axes[f, 0, 2]
        for s in range(3):
            e = edges[s]
            wx = uy * e[2] - uz * e[1]
            wy = uz * e[0] - ux * e[2]
            wz = ux * e[1] - uy * e[0]
            w_len = math.sqrt(wx * wx + wy * wy + wz * wz)
            if w_len > 0:
                valid[f, s + 1] = True
                axes[f, s + 1, 0] = wx / w_len
                axes[f, s + 1, 1] = wy / w_len
                axes[f, s + 1, 2] = wz / w_len
        for k in range(4):
            lo = np.inf
            hi = -np.inf
            for c in range(3):
                p = axes[f, k, 0] * tri[f, c, 0] + axes[f, k, 1] * tri[f, c, 1] + axes[f, k, 2] * tri[f, c, 2]
                lo = min(lo, p)
                hi = max(hi, p)
            low[f, k] = lo - PROJ_SLACK
            high[f, k] = hi + PROJ_SLACK


@numba.njit(cache=True, nogil=True, error_model="numpy")
def grid_levels(lo, hi, h0, top, max_cells):
    """Finest level ``L < top`` whose cells of size ``h0 * 2**L`` a box covers at most ``max_cells`` of (else ``top``)."""
    m = lo.shape[0]
    level = np.full(m, top, np.int64)
    for f in range(m):
        h = h0
        for L in range(top):
            covered = 1.0
            for d in range(3):
                covered *= math.floor(hi[f, d] / h) - math.floor(lo[f, d] / h) + 1
            if covered <= max_cells:
                level[f] = L
                break
            h *= 2.0
    return level


@numba.njit(cache=True, nogil=True, error_model="numpy")
def exact_groups(bits, h):
    """Group equal rows of ``bits`` (n, 3) uint64 through an open-addressing table on the hashes ``h``.

    Returns ``group`` (n,) int64, numbered by first occurrence, and ``first`` (k,) int64, the
    first row of each group.  Rows are compared in full, so a hash collision costs a probe,
    never a wrong group.
    """
    n = bits.shape[0]
    size = 1
    while size < 2 * n:
        size *= 2
    mask = np.uint64(size - 1)
    table = np.full(size, -1, np.int64)
    group = np.empty(n, np.int64)
    first = np.empty(n, np.int64)
    k = 0
    for r in range(n):
        slot = h[r] & mask
        while True:
            g = table[slot]
            if g < 0:
                table[slot] = k
                first[k] = r
                group[r] = k
                k += 1
                break
            q = first[g]
            if bits[q, 0] == bits[r, 0] and bits[q, 1] == bits[r, 1] and bits[q, 2] == bits[r, 2]:
                group[r] = g
                break
            slot = (slot + np.uint64(1)) & mask
    return group, first[:k]


@numba.njit(cache=True, nogil=True, error_model="numpy")
def flat_faces(v, faces, lo, bound):
    """Per face: twice the area at most ``bound`` times the longest side, and zero area.

    The first test is that of :func:`meshvis.geometry.adjacency.degenerate_faces` (corners
    shifted by ``lo`` first), the second the ``areas <= 0`` of :class:`meshvis.soup.Soup`
    (``|(t1 - t0) x (t2 - t0)|`` of the unshifted corners); the arithmetic is that of the
    numpy formulations (norms summed x, y, z).  Returns two (m,) bool arrays.
    """
    m = faces.shape[0]
    flat = np.empty(m, np.bool_)
    zero = np.empty(m, np.bool_)
    t = np.empty((3, 3))
    e = np.empty((3, 3))
    for f in range(m):
        for c in range(3):
            for d in range(3):
                t[c, d] = v[faces[f, c], d] - lo[d]
        longest = 0.0
        for s in range(3):
            for d in range(3):
                e[s, d] = t[(s + 1) % 3, d] - t[s, d]
            longest = max(longest, math.sqrt(e[s, 0] * e[s, 0] + e[s, 1] * e[s, 1] + e[s, 2] * e[s, 2]))
        nx = e[0, 1] * e[1, 2] - e[0, 2] * e[1, 1]
        ny = e[0, 2] * e[1, 0] - e[0, 0] * e[1, 2]
        nz = e[0, 0] * e[1, 1] - e[0, 1] * e[1, 0]
        flat[f] = math.sqrt(nx * nx + ny * ny + nz * nz) <= bound * longest
        a0 = faces[f, 0]
        a1 = faces[f, 1]
        a2 = faces[f, 2]
        ux = v[a1, 0] - v[a0, 0]
        uy = v[a1, 1] - v[a0, 1]
        uz = v[a1, 2] - v[a0, 2]
        wx = v[a2, 0] - v[a0, 0]
        wy = v[a2, 1] - v[a0, 1]
        wz = v[a2, 2] - v[a0, 2]
        cx = uy * wz - uz * wy
        cy = uz * wx - ux * wz
        cz = ux * wy - uy * wx
        zero[f] = 0.5 * math.sqrt(cx * cx + cy * cy + cz * cz) <= 0
    return flat, zero


@numba.njit(cache=True, nogil=True, error_model="numpy")
def grid_cells(lo, hi, h, top, bits):
    """Cells of size ``h`` covered by the boxes ``[lo, hi]`` (broad phase).

    Returns ``owner`` (e,) int64 (the box of each entry, boxes in order, cells in x, then
    y, then z order), ``key`` (e,) int64 (``x << 2 bits | y << bits | z``) and ``c0`` (m, 3)
    int64, the lower cell of each box (cell coordinates clipped to ``[0, top]``).
    """
    m = lo.shape[0]
    c0 = np.empty((m, 3), np.int64)
    span = np.empty((m, 3), np.int64)
    total = 0
    for f in range(m):
        n = 1
        for d in range(3):
            a = min(max(math.floor(lo[f, d] / h), 0.0), top)
            b = min(max(math.floor(hi[f, d] / h), 0.0), top)
            c0[f, d] = np.int64(a)
            span[f, d] = np.int64(b) - np.int64(a) + 1
            n *= span[f, d]
        total += n
    owner = np.empty(total, np.int64)
    key = np.empty(total, np.int64)
    e = 0
    for f in range(m):
        for z in range(span[f, 2]):
            for y in range(span[f, 1]):
                for x in range(span[f, 0]):
                    owner[e] = f
                    key[e] = ((c0[f, 0] + x) << (2 * bits)) | ((c0[f, 1] + y) << bits) | (c0[f, 2] + z)
                    e += 1
    return owner, key, c0


@numba.njit(cache=True, nogil=True, inline="always")
def _root(parent, x):
    while parent[x] != x:
        parent[x] = parent[parent[x]]  # path halving
        x = parent[x]
    return x


@numba.njit(cache=True, nogil=True)
def component_labels(n, a, b):
    """Connected components of ``n`` nodes linked by the edges ``(a[k], b[k])`` (union-find).

    Returns (n,) int64 labels numbered in the order of each component's smallest node, the
    numbering of ``scipy.sparse.csgraph.connected_components``.
    """
    parent = np.arange(n)
    for k in range(a.shape[0]):
        _join(parent, a[k], b[k])
    return _labels(parent)


@numba.njit(cache=True, nogil=True, inline="always")
def _join(parent, i, j):
    """Union of the sets of ``i`` and ``j``; the smaller root becomes the root."""
    x = _root(parent, i)
    y = _root(parent, j)
    if x < y:
        parent[y] = x
    elif y < x:
        parent[x] = y


@numba.njit(cache=True, nogil=True)
def _labels(parent):
    """(n,) int64 set labels numbered in the order of each set's smallest element."""
    n = parent.shape[0]
    label = np.empty(n, np.int64)
    count = 0
    for i in range(n):
        root = _root(parent, i)
        if root == i:
            label[i] = count
            count += 1
        else:
            label[i] = label[root]
    return label


#: constants of the cell hash of :func:`near_labels` (odd multipliers of the splitmix64 family)
_CELL_MIX = (np.uint64(0x9E3779B97F4A7C15), np.uint64(0xBF58476D1CE4E5B9), np.uint64(0x94D049BB133111EB))


@numba.njit(cache=True, nogil=True, inline="always")
def _cell_hash(x, y, z):
    a = np.uint64(x + 1) * _CELL_MIX[0]
    b = np.uint64(y + 1) * _CELL_MIX[1]
    c = np.uint64(z + 1) * _CELL_MIX[2]
    k = a ^ (b >> np.uint64(21)) ^ b ^ (c >> np.uint64(42)) ^ c
    return k ^ (k >> np.uint64(31))


@numba.njit(cache=True, nogil=True, error_model="numpy")
def near_labels(pts, r):
    """Components of the points ``pts`` (n, 3) linked when their distance is at most ``r``.

    The pairs ``i < j`` with ``dx*dx + dy*dy + dz*dz <= r*r`` (the test of a k-d tree's
    ``query_pairs``) are found on a grid of cells at least ``3 r`` wide: a point within
    ``r`` of another lies in its cell or in the neighbour on its nearer side along each
    axis, so each point looks into 8 cells, found through a hash table of the occupied
    cells.  Returns (n,) int64 labels numbered in the order of each component's smallest
    point, as :func:`component_labels`.
    """
    n = pts.shape[0]
    parent = np.arange(n)
    if n > 1 and not math.isfinite(r):  # every distance is at most an infinite radius
        parent[:] = 0
    elif n > 1:
        lo = np.empty(3)
        span = 0.0
        for d in range(3):
            a = np.inf
            b = -np.inf
            for i in range(n):
                a = min(a, pts[i, d])
                b = max(b, pts[i, d])
            lo[d] = a
            span = max(span, b - a)
        h = max(3.0 * r, span * NEAR_CELL_FLOOR)
        cell = np.empty((n, 3), np.int64)
        side = np.empty((n, 3), np.int64)  # -1 or +1: the nearer neighbour cell along each axis
        key = np.empty(n, np.uint64)
        for i in range(n):
            for d in range(3):
                t = (pts[i, d] - lo[d]) / h
                c = math.floor(t)
                cell[i, d] = c
                side[i, d] = -1 if t - c < 0.5 else 1
            key[i] = _cell_hash(cell[i, 0], cell[i, 1], cell[i, 2])
        order = np.argsort(key)
        sorted_key = key[order]
        size = 1
        while size < 2 * n:
            size *= 2
        mask = np.uint64(size - 1)
        table = np.full(size, -1, np.int64)  # slot -> first position of its hash in sorted_key
        for p in range(n):
            if p > 0 and sorted_key[p] == sorted_key[p - 1]:
                continue
            slot = sorted_key[p] & mask
            while table[slot] >= 0:
                slot = (slot + np.uint64(1)) & mask
            table[slot] = p
        r2 = r * r
        for i in range(n):
            for a in range(2):
                for b in range(2):
                    for c in range(2):
                        cx = cell[i, 0] + a * side[i, 0]
                        cy = cell[i, 1] + b * side[i, 1]
                        cz = cell[i, 2] + c * side[i, 2]
                        k = _cell_hash(cx, cy, cz)
                        slot = k & mask
                        p = -1
                        while table[slot] >= 0:
                            if sorted_key[table[slot]] == k:
                                p = table[slot]
                                break
                            slot = (slot + np.uint64(1)) & mask
                        while 0 <= p < n and sorted_key[p] == k:
                            j = order[p]
                            p += 1
                            if j <= i or cell[j, 0] != cx or cell[j, 1] != cy or cell[j, 2] != cz:
                                continue
                            dx = pts[i, 0] - pts[j, 0]
                            dy = pts[i, 1] - pts[j, 1]
                            dz = pts[i, 2] - pts[j, 2]
                            if dx * dx + dy * dy + dz * dz <= r2:
                                _join(parent, i, j)
    return _labels(parent)


@numba.njit(cache=True, nogil=True)
def corner_bounds(v, faces):
    """(2, 3) min and max corner over the vertices the faces use (no mask, no gather)."""
    out = np.empty((2, 3))
    for d in range(3):
        out[0, d] = np.inf
        out[1, d] = -np.inf
    for f in range(faces.shape[0]):
        for c in range(3):
            p = faces[f, c]
            for d in range(3):
                x = v[p, d]
                out[0, d] = min(out[0, d], x)
                out[1, d] = max(out[1, d], x)
    return out


@numba.njit(cache=True, nogil=True)
def _gather_normalised(v, faces, centre, scale, out):
    for f in range(faces.shape[0]):
        for c in range(3):
            p = faces[f, c]
            for d in range(3):
                out[f, c, d] = (v[p, d] - centre[d]) * scale


def gather_normalised(v: np.ndarray, faces: np.ndarray, centre: np.ndarray, scale: float) -> np.ndarray:
    """(m, 3, 3) corners ``(v[faces] - centre) * scale``, in that order of operations."""
    out = np.empty((faces.shape[0], 3, 3))
    in_threads(lambda a, b: _gather_normalised(v, faces[a:b], centre, scale, out[a:b]), faces.shape[0])
    return out
