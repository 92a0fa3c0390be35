"""The geometry kernels of :mod:`meshvis.geometry._kernels` as numpy array code, for small models.

numba costs a command about a third of a second before its first compiled kernel runs
(importing it, setting up its compiler target, which imports scipy's linear algebra).  On
a model of a few thousand faces the work itself takes less than that, so the analysis of
``meshvis info`` and the classification's preprocessing run these numpy formulations
instead (:func:`compiled` decides), and a small model never imports numba on that path.

Each function gives the answer of its compiled namesake, bit for bit: the same arithmetic
in the same order of operations, the same pairs and the same numbering
(``tests/geometry/test_vectorised.py`` compares them).  Where the compiled kernel walks a
grid (the broad phase, the near-point pairs), the numpy version finds the same set of
pairs another way (a sweep along one axis, sorted cell keys); every result is ordered
afterwards, so the search order does not show.
"""

from __future__ import annotations

import sys
from types import ModuleType

import numpy as np

from meshvis.geometry._kernel_constants import (
    COPLANAR,
    INTERSECTS,
    NEAR_CELL_FLOOR,
    PROJ_SLACK,
    SLACK,
    TOO_CLOSE,
    WEDGE_SLACK,
)

#: models with at most this many faces are analysed by this module's numpy code.  On the
#: shared models of 100 to 6,320 faces ``meshvis info`` takes less CPU time this way than
#: with numba's set-up (docs/startup.md); the numpy code is several times slower than the
#: compiled kernels per face pair, so a command that loads numba for its rays anyway pays
#: a little more at this size (0.1 to 0.2 s), and above it the compiled kernels win
SMALL_MODEL_FACES = 4096
#: candidate pairs met at once by :func:`flagged_pairs` (bounds the temporaries)
PAIR_CHUNK = 1 << 16


def compiled(faces: int) -> bool:
    """Whether a model of ``faces`` faces is analysed by the compiled kernels (else by this module)."""
    return faces > SMALL_MODEL_FACES


def kernels(faces: int) -> ModuleType:
    """The kernels for a model of ``faces`` faces: :mod:`meshvis.geometry._kernels` or this module.

    Both modules offer the functions called through this one with the same arguments.
    """
    if compiled(faces):
        from meshvis.geometry import _kernels

        return _kernels
    return sys.modules[__name__]


# --------------------------------------------------------------------------- vertices
def corner_bounds(v: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """(2, 3) min and max corner over the vertices the faces use."""
    corners = v[faces.ravel()]
    return np.stack([corners.min(axis=0), corners.max(axis=0)])


def gather_normalised(v: np.ndarray, faces: np.ndarray, centre: np.ndarray, scale: float) -> np.ndarray:
    """(m, 3, 3) corners ``(v[faces] - centre) * scale``, in that order of operations."""
    return (v[faces] - centre) * scale


def exact_groups(bits: np.ndarray, h: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Group the equal rows of ``bits`` (n, 3) uint64.

    Returns ``group`` (n,) int64, numbered by first occurrence, and ``first`` (k,) int64, the
    first row of each group.  ``h`` (the hashes the compiled kernel probes with) is not
    needed: the rows are sorted instead.
    """
    if len(bits) == 0:
        return np.zeros(0, np.int64), np.zeros(0, np.int64)
    _, first, inverse = np.unique(bits, axis=0, return_index=True, return_inverse=True)
    by_first = np.argsort(first)
    number = np.empty(len(first), np.int64)
    number[by_first] = np.arange(len(first))
    return number[inverse.ravel()], first[by_first].astype(np.int64)


def flat_faces(
    v: np.ndarray, faces: np.ndarray, lo: np.ndarray, bound: float
) -> tuple[np.ndarray, np.ndarray]:
    """Per face: twice the area at most ``bound`` times the longest side, and zero area (two (m,) bool)."""
    t = _corners(v[faces] - lo)  # (corner, coordinate, m)
    e = np.roll(t, -1, axis=0) - t  # side s: corner s -> s + 1
    longest = _max3(_norm(e.transpose(1, 0, 2)))
    flat = _norm(_cross(e[0], e[1])) <= bound * longest
    c = _corners(v[faces])
    zero = 0.5 * _norm(_cross(c[1] - c[0], c[2] - c[0])) <= 0
    return flat, zero


def _cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """(3, ...) cross products of vectors stored component first, ``a[1] b[2] - a[2] b[1]`` as the kernels write it."""
    return np.stack([a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]])


def _dot(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """(...,) dot products ``a[0] b[0] + a[1] b[1] + a[2] b[2]`` of vectors stored component first."""
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def _norm(a: np.ndarray) -> np.ndarray:
    """(...,) lengths ``sqrt(x*x + y*y + z*z)`` of vectors stored component first."""
    return np.sqrt(_dot(a, a))


def _min3(p: np.ndarray) -> np.ndarray:
    """Smallest of ``p[0], p[1], p[2]`` (numpy's reductions are slow over three values)."""
    return np.minimum(np.minimum(p[0], p[1]), p[2])


def _max3(p: np.ndarray) -> np.ndarray:
    """Largest of ``p[0], p[1], p[2]``."""
    return np.maximum(np.maximum(p[0], p[1]), p[2])


def _corners(tri: np.ndarray) -> np.ndarray:
    """(3 corners, 3 coordinates, m) copy of the triangles (m, 3, 3): each coordinate one row."""
    return np.ascontiguousarray(np.asarray(tri, np.float64).transpose(1, 2, 0))


# --------------------------------------------------------------------------- components
def component_labels(n: int, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Connected components of ``n`` nodes linked by the edges ``(a[k], b[k])``.

    Returns (n,) int64 labels numbered in the order of each component's smallest node.
    Every node points at a smaller or equal node of its component; each round hooks the
    larger root of every edge onto the smaller and then follows the pointers to the roots,
    until the two ends of every edge share a root, which is then the smallest node of the
    component (it can only point at itself).
    """
    parent = np.arange(n)
    a = np.asarray(a, np.int64)
    b = np.asarray(b, np.int64)
    while len(a):
        ra, rb = parent[a], parent[b]
        apart = ra != rb
        if not apart.any():
            break
        ra, rb = ra[apart], rb[apart]
        np.minimum.at(parent, np.maximum(ra, rb), np.minimum(ra, rb))
        _to_roots(parent)
    roots = np.unique(parent)
    return np.searchsorted(roots, parent).astype(np.int64)


def _to_roots(parent: np.ndarray) -> None:
    """Point every node at its root, in place (pointer jumping)."""
    while True:
        up = parent[parent]
        if np.array_equal(up, parent):
            return
        parent[:] = up


def near_labels(pts: np.ndarray, r: float) -> np.ndarray:
    """Components of the points ``pts`` (n, 3) linked when their distance is at most ``r``.

    The pairs with ``dx*dx + dy*dy + dz*dz <= r*r`` are found on the grid of the compiled
    kernel (cells at least ``3 r`` wide, each point looking into its cell and the neighbour
    on its nearer side along each axis), its cells matched through sorted keys.  Returns
    (n,) int64 labels numbered in the order of each component's smallest point.
    """
    n = len(pts)
    if n > 1 and not np.isfinite(r):
        return np.zeros(n, np.int64)
    if n < 2:
        return np.arange(n, dtype=np.int64)
    lo = pts.min(axis=0)
    span = float((pts.max(axis=0) - lo).max())
    h = max(3.0 * r, span * NEAR_CELL_FLOOR)
    t = (pts - lo) / h
    cell_f = np.floor(t)
    side = np.where(t - cell_f < 0.5, -1, 1)
    cell = cell_f.astype(np.int64)
    # each axis' cell coordinates by rank, so that three of them pack into one int64 key
    axes = [np.unique(cell[:, d]) for d in range(3)]
    bits = max(1, int(n).bit_length())
    key = _cell_key(cell, axes, bits)[0]
    order = np.argsort(key, kind="stable")
    sorted_key = key[order]
    firsts, seconds = [], []
    for step in np.ndindex(2, 2, 2):
        probe = cell + np.array(step) * side
        probe_key, found = _cell_key(probe, axes, bits)
        start = np.searchsorted(sorted_key, probe_key, side="left")
        count = np.where(found, np.searchsorted(sorted_key, probe_key, side="right") - start, 0)
        i, pos = _expand(start, count)
        j = order[pos]
        d = pts[i] - pts[j]
        near = (j > i) & (d[:, 0] * d[:, 0] + d[:, 1] * d[:, 1] + d[:, 2] * d[:, 2] <= r * r)
        firsts.append(i[near])
        seconds.append(j[near])
    return component_labels(n, np.concatenate(firsts), np.concatenate(seconds))


def _cell_key(cell: np.ndarray, axes: list[np.ndarray], bits: int) -> tuple[np.ndarray, np.ndarray]:
    """(n,) int64 keys of the cells ``cell`` (n, 3) by the rank of each coordinate, and whether every coordinate is known."""
    key = np.zeros(len(cell), np.int64)
    found = np.ones(len(cell), bool)
    for d in range(3):
        rank = np.searchsorted(axes[d], cell[:, d])
        found &= axes[d][np.minimum(rank, len(axes[d]) - 1)] == cell[:, d]
        key = (key << bits) | rank
    return key, found


def _expand(start: np.ndarray, count: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """For row ``q`` with ``count[q]`` entries from ``start[q]``: (row of each entry, its position)."""
    row = np.repeat(np.arange(len(count)), count)
    offset = np.arange(len(row)) - np.repeat(np.cumsum(count) - count, count)
    return row, np.repeat(start, count) + offset


# --------------------------------------------------------------------------- intersection tests
def face_axes(tri, tau, axes, valid, has_normal, low, high) -> None:
    """Per-face separating axes: unit normal and three in-plane edge normals (fills the arrays).

    ``tri`` (m, 3, 3) are the corners; ``axes`` (m, 4, 3), ``valid`` (m, 4), ``has_normal``
    (m,) come in all zero; ``low``, ``high`` (m, 4) receive the projection interval of the
    face on each axis, widened by :data:`PROJ_SLACK`.
    """
    T = _corners(tri)
    e = np.roll(T, -1, axis=0) - T  # (side, coordinate, m)
    length = _norm(e.transpose(1, 0, 2))
    n = _cross(e[0], e[1])
    n_len = _norm(n)
    has_normal[:] = n_len > tau * length[0] * length[1]
    valid[:, 0] = has_normal
    unit = np.zeros_like(n)
    with np.errstate(divide="ignore", invalid="ignore"):
        unit[:, has_normal] = n[:, has_normal] / n_len[has_normal]
        axes[:, 0] = unit.T
        for s in range(3):
            w = _cross(unit, e[s])
            w_len = _norm(w)
            ok = w_len > 0
            valid[:, s + 1] = ok
            axes[ok, s + 1] = (w[:, ok] / w_len[ok]).T
    for k in range(4):
        p = _project(axes[:, k].T, T)
        low[:, k] = _min3(p) - PROJ_SLACK
        high[:, k] = _max3(p) + PROJ_SLACK


def _project(axis: np.ndarray, T: np.ndarray) -> np.ndarray:
    """(3 corners, p) projections of the corners ``T`` (3, 3, p) on ``axis`` (3, p), as ``ax*x + ay*y + az*z``."""
    return axis[0] * T[:, 0] + axis[1] * T[:, 1] + axis[2] * T[:, 2]


def _gap(p: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """(p,) gap between ``[lo, hi]`` and the projections ``p`` (3, p)."""
    return np.maximum(_min3(p) - hi, lo - _max3(p))


def _corner(T: np.ndarray, c: np.ndarray) -> np.ndarray:
    """(3, p) corner ``c[q]`` of each triangle ``T[:, :, q]`` (3, 3, p)."""
    return T[c, :, np.arange(T.shape[2])].T


def _unit_from(T: np.ndarray, c: np.ndarray, k: np.ndarray) -> np.ndarray:
    """(3, p) unit vectors from corner ``c`` to corner ``k`` of each triangle of ``T`` (3, 3, p)."""
    d = _corner(T, k) - _corner(T, c)
    return d / _norm(d)


def _in_wedge(T: np.ndarray, c: np.ndarray, n: np.ndarray, d: np.ndarray) -> np.ndarray:
    """(p,) the direction ``d`` lies in the wedge of ``T`` at corner ``c`` (counter-clockwise about ``n``)."""
    a = _dot(_cross(_unit_from(T, c, (c + 1) % 3), d), n)
    b = _dot(_cross(d, _unit_from(T, c, (c + 2) % 3)), n)
    s = -WEDGE_SLACK * (1 + SLACK)
    return (a >= s) & (b >= s)


def _folded(Ti, Tj, fi, fj, cos_fold) -> np.ndarray:
    """(p,) two faces on one edge folded onto each other by less than the fold angle.

    ``fi``, ``fj`` (3, p) are the welded corners; the corners are chosen as the compiled
    kernel chooses them: ``a`` the first corner of i found in j, ``b`` the last later one
    (-1 if none), ``ki`` the last corner of i not found, ``kj`` the last corner of j that
    is neither ``a`` nor ``b``.
    """
    p = fi.shape[1]
    rows = np.arange(p)
    a, b, ki, kj = np.full(p, -1), np.full(p, -1), np.zeros(p, np.int64), np.zeros(p, np.int64)
    for c in range(3):
        hit = (fi[c] == fj[0]) | (fi[c] == fj[1]) | (fi[c] == fj[2])
        first = hit & (a < 0)
        b = np.where(hit & ~first, c, b)
        a = np.where(first, c, a)
        ki = np.where(hit, ki, c)
    fa, fb = fi[a, rows], fi[b, rows]
    for c in range(3):
        kj = np.where((fj[c] != fa) & (fj[c] != fb), c, kj)
    e = _unit_from(Ti, a, b % 3)
    base = _corner(Ti, a)
    u = _corner(Ti, ki) - base
    w = _corner(Tj, kj) - base
    u = u - _dot(u, e) * e
    w = w - _dot(w, e) * e
    lu, lw = _norm(u), _norm(w)
    return (lu != 0) & (lw != 0) & (_dot(u, w) / (lu * lw) >= cos_fold)


def pair_flags(i, j, order, tri, fw, axes, valid, has_normal, low, high, eps, near, tau, cos_angle, cos_fold):
    """(intersects, coplanar, too_close, folded) (p,) bool of the faces in rows ``i`` and ``j`` (p,).

    The tests of :func:`meshvis.geometry._kernels.pair_flags`, every pair at once: each
    branch of the kernel is a mask here, and a value the kernel would not compute for a
    pair is computed and then left out by its mask.  The arguments are those of the kernel.
    """
    faces = _PairFaces(order, tri, fw, axes, valid, has_normal, low, high)
    return faces.flags(i, j, eps, near, tau, cos_angle, cos_fold)


class _PairFaces:
    """The per-face arrays of :func:`pair_flags`, stored component first for the pair tests."""

    def __init__(self, order, tri, fw, axes, valid, has_normal, low, high):
        self.order, self.valid, self.has_normal, self.low, self.high = order, valid, has_normal, low, high
        self.T = _corners(tri)  # (corner, coordinate, m)
        self.fw = np.ascontiguousarray(np.asarray(fw).T)  # (corner, m)
        self.axes = np.ascontiguousarray(np.asarray(axes).transpose(1, 2, 0))  # (axis, coordinate, m)

    def flags(self, i, j, eps, near, tau, cos_angle, cos_fold):
        """(intersects, coplanar, too_close, folded) of the row pairs ``(i, j)``."""
        with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
            return self._flags(i, j, eps, near, tau, cos_angle, cos_fold)

    def _flags(self, i, j, eps, near, tau, cos_angle, cos_fold):
        valid, low, high, has_normal = self.valid, self.low, self.high, self.has_normal
        pad = max(eps, near)
        eps_r = eps * (1 + SLACK)
        near_r = near * (1 + SLACK)
        pad_r = pad * (1 + SLACK)
        swap = self.order[i] > self.order[j]  # as (smaller, larger) input id, the orientation of the tests
        i, j = np.where(swap, j, i), np.where(swap, i, j)
        Ti, Tj = self.T[:, :, i], self.T[:, :, j]
        fi, fj = self.fw[:, i], self.fw[:, j]
        # the shared corners; the kernel keeps the last match (a, b) in the order of its loops
        nshared = np.zeros(len(i), np.int64)
        ci, cj = np.full(len(i), -1), np.full(len(i), -1)
        for a in range(3):
            for b in range(3):
                same = fi[a] == fj[b]
                nshared += same
                ci = np.where(same, a, ci)
                cj = np.where(same, b, cj)
        # stage 1: the normals
        ni, nj = self.axes[0][:, i], self.axes[0][:, j]
        mid_i = 0.5 * (low[i, 0] + high[i, 0])
        mid_j = 0.5 * (low[j, 0] + high[j, 0])
        p = _project(ni, Tj)
        g = _gap(p, low[i, 0], high[i, 0])
        dev_j = _max3(np.abs(p - mid_i))  # j's corners from i's plane
        max_gap = np.where(valid[i, 0], g, -np.inf)
        p = _project(nj, Ti)
        g = _gap(p, low[j, 0], high[j, 0])
        dev_i = _max3(np.abs(p - mid_j))
        max_gap = np.where(valid[j, 0], np.maximum(max_gap, g), max_gap)
        both = has_normal[i] & has_normal[j]
        flat = both & (np.abs(_dot(ni, nj)) >= cos_angle * (1 - SLACK)) & (dev_j <= eps_r) & (dev_i <= eps_r)
        apart = (nshared == 0) & (max_gap > pad_r)  # the kernel returns all False for these
        # the in-plane axes; the kernel needs them only where nshared == 0 or flat, and
        # nothing else reads max_gap or in_plane
        in_plane = np.full(len(i), -np.inf)
        for k in range(1, 4):
            for a, T in ((i, Tj), (j, Ti)):
                g = _gap(_project(self.axes[k][:, a], T), low[a, k], high[a, k])
                g = np.where(valid[a, k], g, -np.inf)
                max_gap = np.maximum(max_gap, g)
                in_plane = np.maximum(in_plane, g)
        copl = flat & (in_plane < -eps * (1 - SLACK))
        # stage 2: the edge x edge axes of the pairs without a shared corner still within reach
        reach = (nshared == 0) & (max_gap <= pad_r)
        if reach.any():
            Ei = np.roll(Ti, -1, axis=0) - Ti
            Ej = np.roll(Tj, -1, axis=0) - Tj
            Li, Lj = _norm(Ei.transpose(1, 0, 2)), _norm(Ej.transpose(1, 0, 2))
            for a in range(3):
                for b in range(3):
                    ax = _cross(Ei[a], Ej[b])
                    length = _norm(ax)
                    use = reach & (length > tau * Li[a] * Lj[b])
                    p = _project(ax, Ti)
                    gap = _gap(_project(ax, Tj), _min3(p), _max3(p)) / length
                    max_gap = np.where(use, np.maximum(max_gap, gap), max_gap)
        alone = nshared == 0
        inter = alone & ~flat & (max_gap <= eps_r)
        close = alone & (max_gap <= near_r)
        # one shared corner: crossing beyond it (tangent wedges); two: folded over
        corner = (nshared == 1) & both & ~flat
        if corner.any():
            s = np.flatnonzero(corner)
            line = _cross(ni[:, s], nj[:, s])
            length = _norm(line)
            line = line / length
            T1, T2, c1, c2 = Ti[:, :, s], Tj[:, :, s], ci[s], cj[s]
            meet = (_in_wedge(T1, c1, ni[:, s], line) & _in_wedge(T2, c2, nj[:, s], line)) | (
                _in_wedge(T1, c1, ni[:, s], -line) & _in_wedge(T2, c2, nj[:, s], -line)
            )
            meet |= ~(length > tau)
            inter[s] |= meet
            close[s] |= meet
        edge = (nshared == 2) & both & ~flat
        fold = np.zeros(len(i), bool)
        if edge.any():
            s = np.flatnonzero(edge)
            fold[s] = _folded(Ti[:, :, s], Tj[:, :, s], fi[:, s], fj[:, s], cos_fold)
        keep = ~apart
        return inter & keep, copl & keep, close & keep, fold & keep


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
) -> None:
    """The flags of :func:`pair_flags` of the row pairs ``pairs`` (p, 2), set in ``inter``, ``copl``, ``close``, ``fold`` (p,)."""
    faces = _PairFaces(order, tri, fw, axes, valid, has_normal, low, high)
    for s in range(0, len(pairs), PAIR_CHUNK):
        sl = slice(s, s + PAIR_CHUNK)
        i, j = pairs[sl, 0].astype(np.int64), pairs[sl, 1].astype(np.int64)
        inter[sl], copl[sl], close[sl], fold[sl] = faces.flags(i, j, eps, near, tau, cos_angle, cos_fold)


def sweep(lo: np.ndarray, hi: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The boxes ``[lo, hi]`` (m, 3) sorted along one axis, and how many later boxes each meets there.

    After sorting by their lower end, each box meets the later boxes that start before it
    ends.  The axis is the one with the fewest such meetings (counted first, one binary
    search per box).  Returns the order (m,) and the count (m,) of each sorted box.
    """
    m = len(lo)
    best: tuple[np.ndarray, np.ndarray] | None = None
    for axis in range(3):
        order = np.argsort(lo[:, axis], kind="stable")
        count = np.searchsorted(lo[order, axis], hi[order, axis], side="right") - np.arange(1, m + 1)
        count = np.maximum(count, 0)
        if best is None or count.sum() < best[1].sum():
            best = (order, count)
    assert best is not None
    return best


def _overlapping(lo, hi, order, count, rows: slice) -> tuple[np.ndarray, np.ndarray]:
    """Pairs ``i < j`` of overlapping boxes met by the sorted boxes ``rows`` of :func:`sweep`."""
    start = np.arange(rows.start + 1, rows.stop + 1)
    row, pos = _expand(start, count[rows])
    a, b = order[rows.start + row], order[pos]
    meet = np.ones(len(a), bool)
    for d in range(3):
        meet &= (lo[a, d] <= hi[b, d]) & (lo[b, d] <= hi[a, d])
    a, b = a[meet], b[meet]
    return np.minimum(a, b), np.maximum(a, b)


def overlapping_boxes(lo: np.ndarray, hi: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Pairs ``i < j`` (two (p,) int64) of closed boxes ``[lo, hi]`` (m, 3) that overlap on every axis.

    Examples
    --------
    >>> lo = np.array([[0.0, 0, 0], [0.5, 0.5, 0.5], [3, 3, 3]])
    >>> [x.tolist() for x in overlapping_boxes(lo, lo + 1)]
    [[0], [1]]
    """
    order, count = sweep(lo, hi)
    return _overlapping(lo, hi, order, count, slice(0, len(lo)))


def _row_chunks(count: np.ndarray, budget: int):
    """Slices of rows whose counts add up to about ``budget`` (at least one row each)."""
    total = np.cumsum(count)
    begin = 0
    while begin < len(count):
        base = total[begin - 1] if begin else 0
        end = max(int(np.searchsorted(total, base + budget, side="right")), begin + 1)
        yield slice(begin, end)
        begin = end


def flagged_pairs(
    lo: np.ndarray, hi: np.ndarray, swept: tuple[np.ndarray, np.ndarray], faces: tuple, tolerances: tuple
) -> tuple[np.ndarray, np.ndarray]:
    """The pairs of overlapping boxes with a flag.

    ``lo``, ``hi`` (m, 3) are the boxes of the first ``m`` rows of ``faces``, the per-face
    arrays of :func:`pair_flags` (``_Narrow.faces`` of :mod:`meshvis.geometry.intersect`),
    ``swept`` their :func:`sweep` and ``tolerances`` the numbers of :func:`pair_flags`.
    Returns (k,) int64 keys ``i * m + j`` (``i < j``) and (k,) uint8 codes as
    :func:`meshvis.geometry._kernels.broad_narrow` gives them (a fold counts as coplanar).
    """
    m = len(lo)
    order, count = swept
    test = _PairFaces(*faces)
    keys, codes = [np.zeros(0, np.int64)], [np.zeros(0, np.uint8)]
    for rows in _row_chunks(count, PAIR_CHUNK):
        i, j = _overlapping(lo, hi, order, count, rows)
        inter, copl, close, fold = test.flags(i, j, *tolerances)
        code = (inter * INTERSECTS | (copl | fold) * COPLANAR | close * TOO_CLOSE).astype(np.uint8)
        hit = code > 0
        keys.append(i[hit] * m + j[hit])
        codes.append(code[hit])
    return np.concatenate(keys), np.concatenate(codes)
