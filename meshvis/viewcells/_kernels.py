"""Numba kernels of the global sampler: locating points in the view cells and walking segments.

The view cells are the leaves of a kD-tree kept as flat arrays (:class:`.cells.ViewCells`):
per node the split axis (-1 for a leaf), the split position, the two children and the
leaf's cell (-1 for a leaf outside the view space).  A sample is a line
``origin + t * direction`` with ``-t_back <= t <= t_fwd``; :func:`walk` visits every leaf
the segment pierces (a stack-based kD-tree traversal, clipped to the root box) and adds the
faces hit at its two ends to each leaf's PVS, a bit set of (cells, words) uint64.

The walk writes the shared bit set, so it runs in one thread, in sample order: the same
samples give the same PVS and the same log, bit for bit.
"""

from __future__ import annotations

import numba
import numpy as np

#: deepest kD-tree the walk's stack holds
MAX_DEPTH = 64


@numba.njit(cache=True, nogil=True)
def locate(tree, points):  # pragma: no cover - compiled
    """(n,) int32: the cell of each point (-1 outside the root box or in a leaf without a cell).

    ``tree`` is ``(axis, split, left, right, cell, lo, hi)`` (:meth:`.cells.ViewCells.tree_arrays`).
    """
    axis, split, left, right, cell, lo, hi = tree
    n = len(points)
    out = np.full(n, -1, np.int32)
    for k in range(n):
        inside = True
        for c in range(3):
            if not (lo[c] <= points[k, c] <= hi[c]):
                inside = False
        if not inside:
            continue
        node = 0
        while axis[node] >= 0:
            a = axis[node]
            node = left[node] if points[k, a] <= split[node] else right[node]
        out[k] = cell[node]
    return out


@numba.njit(cache=True, nogil=True, inline="always")
def _clip(o, d, lo, hi, t0, t1):  # pragma: no cover - compiled
    """The part ``[t0, t1]`` of the line ``o + t d`` inside the box (empty when t0 > t1)."""
    for c in range(3):
        if d[c] != 0.0:
            ta = (lo[c] - o[c]) / d[c]
            tb = (hi[c] - o[c]) / d[c]
            if ta > tb:
                ta, tb = tb, ta
            if ta > t0:
                t0 = ta
            if tb < t1:
                t1 = tb
        elif o[c] < lo[c] or o[c] > hi[c]:
            return 1.0, 0.0
    return t0, t1


@numba.njit(cache=True, nogil=True, inline="always")
def _add(bits, c, f):  # pragma: no cover - compiled
    """Set bit (c, f); True when it was not set."""
    w = f >> 6
    mask = np.uint64(1) << np.uint64(f & 63)
    if bits[c, w] & mask:
        return False
    bits[c, w] |= mask
    return True


@numba.njit(cache=True, nogil=True)
def walk(
    tree,
    origin,
    direction,
    t_back,
    t_fwd,
    face_back,
    face_fwd,
    origin_cell,
    bits,
    cell_segments,
    contribution,
    own,
    useful,
    clip,
    log_cell,
    log_face,
    n_log,
    start,
    new_sample,
    new_t0,
    new_t1,
    base,
):  # pragma: no cover - compiled
    """Add the faces at the ends of samples ``start..`` to the PVS of every cell they pierce.

    Per sample ``k`` it writes ``origin_cell[k]`` (the cell of the sample's point, -1 for
    none), ``contribution[k]`` (new PVS entries), ``own[k]`` (bit 0: the back face is new in
    the cell of the point, bit 1: the forward face is), ``useful[k]`` (bit
    0: the back face is new in some cell, bit 1: the forward face is) and ``clip[k]`` (the
    segment's parameters clipped to the root box); each new entry is appended to
    ``log_cell, log_face`` from ``n_log`` on, with the sample and the part ``[t0, t1]`` of
    its segment inside the cell in ``new_sample, new_t0, new_t1`` at ``n_log - base``.  It
    stops before a sample whose entries might not fit the log.

    Returns
    -------
    done : int
        The first sample not processed (``len(origin)`` when all were).
    n_log : int
        Entries in the log.
    """
    axis, split, left, right, cell, lo, hi = tree
    n = len(origin)
    cap = len(log_cell)
    n_cells_max = len(cell_segments)
    stack_node = np.empty(2 * MAX_DEPTH + 2, np.int64)
    stack_t0 = np.empty(2 * MAX_DEPTH + 2)
    stack_t1 = np.empty(2 * MAX_DEPTH + 2)
    for k in range(start, n):
        if n_log + 2 * n_cells_max > cap:
            return k, n_log
        o = origin[k]
        d = direction[k]
        t0, t1 = _clip(o, d, lo, hi, -t_back[k], t_fwd[k])
        clip[k, 0], clip[k, 1] = t0, t1
        fb, ff = face_back[k], face_fwd[k]
        origin_cell[k] = -1
        contribution[k] = 0
        own[k] = 0
        useful[k] = 0
        if t0 > t1:
            continue
        top = 0
        stack_node[0], stack_t0[0], stack_t1[0] = 0, t0, t1
        while top >= 0:
            node, a0, a1 = stack_node[top], stack_t0[top], stack_t1[top]
            top -= 1
            ax = axis[node]
            if ax < 0:
                c = cell[node]
                if c < 0:
                    continue
                cell_segments[c] += 1
                home = a0 <= 0.0 <= a1 and origin_cell[k] < 0
                if home:
                    origin_cell[k] = c
                if fb >= 0 and _add(bits, c, fb):
                    contribution[k] += 1
                    useful[k] |= 1
                    if home:
                        own[k] |= 1
                    log_cell[n_log], log_face[n_log] = c, fb
                    new_sample[n_log - base], new_t0[n_log - base], new_t1[n_log - base] = k, a0, a1
                    n_log += 1
                if ff >= 0 and ff != fb and _add(bits, c, ff):
                    contribution[k] += 1
                    useful[k] |= 2
                    if home:
                        own[k] |= 2
                    log_cell[n_log], log_face[n_log] = c, ff
                    new_sample[n_log - base], new_t0[n_log - base], new_t1[n_log - base] = k, a0, a1
                    n_log += 1
                continue
            s = split[node]
            p0 = o[ax] + a0 * d[ax]
            p1 = o[ax] + a1 * d[ax]
            if p0 <= s and p1 <= s:
                top += 1
                stack_node[top], stack_t0[top], stack_t1[top] = left[node], a0, a1
            elif p0 >= s and p1 >= s:
                top += 1
                stack_node[top], stack_t0[top], stack_t1[top] = right[node], a0, a1
            else:
                tm = (s - o[ax]) / d[ax]
                near, far = (left[node], right[node]) if d[ax] > 0 else (right[node], left[node])
                top += 1
                stack_node[top], stack_t0[top], stack_t1[top] = near, a0, tm
                top += 1
                stack_node[top], stack_t0[top], stack_t1[top] = far, tm, a1
    return n, n_log


@numba.njit(cache=True, nogil=True)
def unpack_rows(bits, n_faces):  # pragma: no cover - compiled
    """CSR of a bit set: ``(ptr, faces)``, the faces of row r in ``faces[ptr[r]:ptr[r + 1]]``, ascending."""
    rows = bits.shape[0]
    ptr = np.zeros(rows + 1, np.int64)
    total = 0
    for r in range(rows):
        for w in range(bits.shape[1]):
            x = bits[r, w]
            while x:
                x &= x - np.uint64(1)
                total += 1
        ptr[r + 1] = total
    faces = np.empty(total, np.int64)
    m = 0
    for r in range(rows):
        for w in range(bits.shape[1]):
            x = bits[r, w]
            b = 0
            while x:
                if x & np.uint64(1):
                    f = w * 64 + b
                    if f < n_faces:
                        faces[m] = f
                        m += 1
                x >>= np.uint64(1)
                b += 1
    return ptr, faces[:m].copy()


@numba.njit(cache=True, nogil=True)
def count_rows(bits):  # pragma: no cover - compiled
    """(rows,) int64: bits set per row."""
    out = np.zeros(bits.shape[0], np.int64)
    for r in range(bits.shape[0]):
        t = 0
        for w in range(bits.shape[1]):
            x = bits[r, w]
            while x:
                x &= x - np.uint64(1)
                t += 1
        out[r] = t
    return out


@numba.njit(cache=True, nogil=True)
def pick_neighbours(face, cell, ptr, nbr, bits, draw):  # pragma: no cover - compiled
    """For each (face, cell): a neighbour of the face not yet in the cell's PVS, else -1.

    The neighbours of face f are ``nbr[ptr[f]:ptr[f + 1]]``; the search starts at a random
    one (``draw`` in [0, 1)) and goes round them.
    """
    n = len(face)
    out = np.full(n, -1, np.int64)
    for k in range(n):
        f = face[k]
        a, b = ptr[f], ptr[f + 1]
        m = b - a
        if m == 0:
            continue
        first = int(draw[k] * m)
        c = cell[k]
        for j in range(m):
            g = nbr[a + (first + j) % m]
            if not (bits[c, g >> 6] >> np.uint64(g & 63)) & np.uint64(1):
                out[k] = g
                break
    return out


@numba.njit(cache=True, nogil=True)
def vertex_neighbours(faces_welded, n_vertices, fan_cap):  # pragma: no cover - compiled
    """CSR ``(ptr, nbr)`` of the faces sharing a (welded) vertex with each face.

    Vertices shared by more than ``fan_cap`` faces (the hub of a fan) add no neighbours.
    """
    m = len(faces_welded)
    count = np.zeros(n_vertices + 1, np.int64)
    for f in range(m):
        for j in range(3):
            count[faces_welded[f, j] + 1] += 1
    vptr = np.cumsum(count)
    fill = vptr[:-1].copy()
    vfaces = np.empty(vptr[-1], np.int64)
    for f in range(m):
        for j in range(3):
            v = faces_welded[f, j]
            vfaces[fill[v]] = f
            fill[v] += 1
    ptr = np.zeros(m + 1, np.int64)
    out = np.empty(max(16, 12 * m), np.int64)
    n = 0
    tmp = np.empty(3 * fan_cap, np.int64)
    for f in range(m):
        t = 0
        for j in range(3):
            v = faces_welded[f, j]
            a, b = vptr[v], vptr[v + 1]
            if b - a > fan_cap:
                continue
            for i in range(a, b):
                if vfaces[i] != f:
                    tmp[t] = vfaces[i]
                    t += 1
        u = np.unique(tmp[:t])
        if n + len(u) > len(out):
            grown = np.empty(2 * len(out) + len(u), np.int64)
            grown[:n] = out[:n]
            out = grown
        out[n : n + len(u)] = u
        n += len(u)
        ptr[f + 1] = n
    return ptr, out[:n].copy()


@numba.njit(cache=True, nogil=True)
def clip_segments(origin, direction, t0, t1, idx, lo, hi):  # pragma: no cover - compiled
    """The part of segments ``idx`` inside the box ``[lo, hi]``: (k, 2) parameters (a > b: none)."""
    k = len(idx)
    out = np.empty((k, 2))
    for j in range(k):
        i = idx[j]
        a, b = _clip(origin[i], direction[i], lo, hi, t0[i], t1[i])
        out[j, 0], out[j, 1] = a, b
    return out


@numba.njit(cache=True, nogil=True)
def node_faces(origin, direction, ab, idx, face_back, face_fwd, scratch_lo, scratch_hi):  # pragma: no cover
    """Per distinct face at the ends of segments ``idx`` (clipped to ``ab``): per axis the least
    and the greatest coordinate of its segments' parts, ``(faces, lo (f, 3), hi (f, 3))``.

    ``scratch_lo`` / ``scratch_hi`` are (m, 3), all ``inf`` / ``-inf``, and are left so.
    """
    k = len(idx)
    seen = np.empty(2 * k, np.int64)
    m = 0
    for j in range(k):
        a, b = ab[j, 0], ab[j, 1]
        if a > b:
            continue
        i = idx[j]
        for end in range(2):
            f = face_back[i] if end == 0 else face_fwd[i]
            if f < 0:
                continue
            if scratch_lo[f, 0] == np.inf:
                seen[m] = f
                m += 1
            for c in range(3):
                pa = origin[i, c] + a * direction[i, c]
                pb = origin[i, c] + b * direction[i, c]
                low, high = (pa, pb) if pa <= pb else (pb, pa)
                if low < scratch_lo[f, c]:
                    scratch_lo[f, c] = low
                if high > scratch_hi[f, c]:
                    scratch_hi[f, c] = high
    out_lo = np.empty((m, 3))
    out_hi = np.empty((m, 3))
    for j in range(m):
        f = seen[j]
        for c in range(3):
            out_lo[j, c] = scratch_lo[f, c]
            out_hi[j, c] = scratch_hi[f, c]
            scratch_lo[f, c] = np.inf
            scratch_hi[f, c] = -np.inf
    return seen[:m].copy(), out_lo, out_hi
