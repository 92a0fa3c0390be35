"""A bounding volume hierarchy of axis-aligned boxes over a model's triangles, in float64.

Embree answers ray queries; a conservative visibility query needs another one: *every*
triangle that meets a volume (a thin pyramid from a viewpoint).  :func:`build_bvh` builds
a binary tree of boxes by the surface area heuristic (centroids sorted into
:data:`BINS` bins along the longest axis of their bounds, the split that minimises
area x count on both sides), with at most :data:`LEAF_SIZE` triangles per leaf.  The
boxes bound the float64 corners exactly (min and max are exact operations), so a test
that rejects a box rejects every triangle in it.

The tree is flat arrays, walked by compiled kernels with a stack
(:mod:`meshvis.visibility._frusta_kernels`): node ``k`` has the box ``lo[k], hi[k]``;
it is a leaf when ``count[k] > 0`` and holds the triangles ``order[first[k]:first[k] +
count[k]]``, otherwise its children are ``first[k]`` and ``first[k] + 1``.

>>> import numpy as np
>>> tri = np.array([[[0, 0, 0], [1, 0, 0], [0, 1, 0]], [[5, 5, 5], [6, 5, 5], [5, 6, 5]]], float)
>>> bvh = build_bvh(tri)
>>> bvh.lo[0].tolist(), bvh.hi[0].tolist(), sorted(bvh.order.tolist())
([0.0, 0.0, 0.0], [6.0, 6.0, 5.0], [0, 1])
"""

from __future__ import annotations

from dataclasses import dataclass

import numba
import numpy as np

#: most triangles in a leaf
LEAF_SIZE = 4
#: bins of the surface area heuristic along the split axis
BINS = 16
#: deepest tree the traversal stacks allow (a split always separates at least one triangle,
#: so this bounds the depth only for models of more than ~10^19 triangles, or for
#: degenerate splits, where the builder falls back to halving the range)
MAX_DEPTH = 64


@dataclass(frozen=True)
class Bvh:
    """A flat bounding volume hierarchy (see the module notes for the layout).

    Attributes
    ----------
    lo, hi : (k, 3) float64
        Box of each node.
    first, count : (k,) int64
        A leaf's range in ``order`` (``count > 0``), or an inner node's first child.
    order : (m,) int64
        Triangle indices in leaf order.
    """

    lo: np.ndarray
    hi: np.ndarray
    first: np.ndarray
    count: np.ndarray
    order: np.ndarray

    @property
    def n_nodes(self) -> int:
        """Number of nodes."""
        return len(self.first)


def build_bvh(triangles: np.ndarray) -> Bvh:
    """Build the hierarchy of a model's triangles.

    Parameters
    ----------
    triangles : (m, 3, 3) float array
        Corners of each triangle.  Triangles with a non-finite corner are left out.

    Returns
    -------
    Bvh

    Examples
    --------
    >>> tri = np.random.default_rng(0).random((1000, 3, 3))
    >>> bvh = build_bvh(tri)
    >>> int(bvh.count.max()) <= LEAF_SIZE, sorted(bvh.order.tolist()) == list(range(1000))
    (True, True)
    """
    tri = np.ascontiguousarray(triangles, np.float64).reshape(-1, 3, 3)
    ok = np.isfinite(tri).all(axis=(1, 2))
    keep = np.flatnonzero(ok).astype(np.int64)
    lo_t = tri[keep].min(axis=1)
    hi_t = tri[keep].max(axis=1)
    lo, hi, first, count, order = _build(lo_t, hi_t, LEAF_SIZE, BINS)
    return Bvh(lo, hi, first, count, keep[order])


@numba.njit(cache=True, nogil=True, error_model="numpy")
def _half_area(lo, hi):  # pragma: no cover - compiled
    dx, dy, dz = hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]
    return dx * dy + dy * dz + dz * dx


@numba.njit(cache=True, nogil=True, error_model="numpy")
def _build(lo_t, hi_t, leaf_size, bins):  # pragma: no cover - compiled
    """Top-down binned-SAH build over triangle boxes; see :func:`build_bvh`."""
    m = len(lo_t)
    cen = 0.5 * (lo_t + hi_t)
    order = np.arange(m)
    cap = max(2 * m - 1, 1)
    lo = np.empty((cap, 3))
    hi = np.empty((cap, 3))
    first = np.zeros(cap, np.int64)
    count = np.zeros(cap, np.int64)
    # the stack holds (node, start, end) of ranges still to split
    st_node = np.empty(MAX_DEPTH * 2 + 2, np.int64)
    st_a = np.empty(MAX_DEPTH * 2 + 2, np.int64)
    st_b = np.empty(MAX_DEPTH * 2 + 2, np.int64)
    n_nodes = 1
    top = 0
    st_node[0], st_a[0], st_b[0] = 0, 0, m
    bin_lo = np.empty((bins, 3))
    bin_hi = np.empty((bins, 3))
    bin_n = np.zeros(bins, np.int64)
    right_area = np.empty(bins)
    key = np.empty(m, np.int64)
    if m == 0:
        lo[0, :] = 0.0
        hi[0, :] = 0.0
        return lo[:1], hi[:1], first[:1], np.zeros(1, np.int64), order
    while top >= 0:
        node, a, b = st_node[top], st_a[top], st_b[top]
        top -= 1
        # the node's box and its centroids' box
        for c in range(3):
            lo[node, c] = np.inf
            hi[node, c] = -np.inf
        clo = np.full(3, np.inf)
        chi = np.full(3, -np.inf)
        for i in range(a, b):
            t = order[i]
            for c in range(3):
                lo[node, c] = min(lo[node, c], lo_t[t, c])
                hi[node, c] = max(hi[node, c], hi_t[t, c])
                clo[c] = min(clo[c], cen[t, c])
                chi[c] = max(chi[c], cen[t, c])
        n = b - a
        if n <= leaf_size or top + 3 >= len(st_node):
            first[node], count[node] = a, n
            continue
        axis = 0
        for c in range(1, 3):
            if chi[c] - clo[c] > chi[axis] - clo[axis]:
                axis = c
        extent = chi[axis] - clo[axis]
        mid = a + n // 2
        if extent > 0:
            # bin the centroids, then sweep for the split of least area x count
            bin_n[:] = 0
            for k in range(bins):
                for c in range(3):
                    bin_lo[k, c] = np.inf
                    bin_hi[k, c] = -np.inf
            scale = bins / extent
            for i in range(a, b):
                t = order[i]
                k = min(int((cen[t, axis] - clo[axis]) * scale), bins - 1)
                key[i] = k
                bin_n[k] += 1
                for c in range(3):
                    bin_lo[k, c] = min(bin_lo[k, c], lo_t[t, c])
                    bin_hi[k, c] = max(bin_hi[k, c], hi_t[t, c])
            acc_lo = np.full(3, np.inf)
            acc_hi = np.full(3, -np.inf)
            for k in range(bins - 1, 0, -1):
                for c in range(3):
                    acc_lo[c] = min(acc_lo[c], bin_lo[k, c])
                    acc_hi[c] = max(acc_hi[c], bin_hi[k, c])
                right_area[k] = _half_area(acc_lo, acc_hi) if acc_lo[0] <= acc_hi[0] else 0.0
            acc_lo[:] = np.inf
            acc_hi[:] = -np.inf
            best, best_cost, n_left, left_n = -1, np.inf, 0, 0
            for k in range(bins - 1):
                for c in range(3):
                    acc_lo[c] = min(acc_lo[c], bin_lo[k, c])
                    acc_hi[c] = max(acc_hi[c], bin_hi[k, c])
                left_n += bin_n[k]
                if left_n == 0 or left_n == n:
                    continue
                cost = _half_area(acc_lo, acc_hi) * left_n + right_area[k + 1] * (n - left_n)
                if cost < best_cost:
                    best, best_cost, n_left = k, cost, left_n
            if best >= 0:
                # partition order[a:b] by bin: bins 0..best to the left
                i, j = a, b - 1
                while i <= j:
                    if key[i] <= best:
                        i += 1
                    else:
                        order[i], order[j] = order[j], order[i]
                        key[i], key[j] = key[j], key[i]
                        j -= 1
                mid = a + n_left
        child = n_nodes
        n_nodes += 2
        first[node], count[node] = child, 0
        top += 1
        st_node[top], st_a[top], st_b[top] = child, a, mid
        top += 1
        st_node[top], st_a[top], st_b[top] = child + 1, mid, b
    return lo[:n_nodes], hi[:n_nodes], first[:n_nodes], count[:n_nodes], order
