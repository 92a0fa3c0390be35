"""The visibility filter of AGVS §5: extend each PVS by faces near its faces, by the sampling density.

An aggressive PVS misses faces that the samples passed between; around a face in the PVS of
a cell, the gap between samples is about ``e(o) = k min(e_g(o), e_l(o))`` (the object
space filter):

* ``e_g(o) = 2 d(o) / sqrt(n_v)``: the ``n_v`` segments that crossed the cell, spread
  evenly over a sphere of radius ``d(o)`` (the face's distance from the cell), are about
  ``2 d / sqrt(n_v)`` apart;
* ``e_l(o) = r(o) / sqrt(n_v(o))``: the ``n_v(o)`` segment ends on the face, spread over a
  disk of its radius ``r(o)``.  The ends are counted over all cells (the sampler keeps no
  count per cell and face), so this is the smaller of the two in practice.

A face joins the PVS when its centroid lies within ``e(o)`` of a PVS face.  (§5 adds every
object whose bounding volume meets the grown bounding volume; the bounding spheres of a
mesh's triangles overlap their neighbours' and a large triangle's sphere holds whole pieces
of furniture, so at triangle level that would add everything near a face whatever the
sampling density.)  The filter only
adds faces: the PVS becomes an approximate set (some faces added are hidden), with fewer
wrong pixels.
"""

from __future__ import annotations

import numpy as np

#: the user's factor ``k`` of the extension
SCALE = 1.0


def visibility_filter(sampler, soup, scale: float = SCALE) -> dict:
    """Extend the PVS of every cell of ``sampler`` in place; what was added.

    Parameters
    ----------
    sampler : GlobalSampler
        The run's state (its bit sets grow).
    soup : Soup
        The model.
    scale : float
        The factor ``k`` of the extension.

    Returns
    -------
    dict
        ``added`` (PVS entries the filter added), ``mean_added`` (per cell), ``scale``.
    """
    from scipy.spatial import cKDTree

    from meshvis.viewcells import _kernels

    cells = sampler.cells
    tri = soup.triangles
    centre = tri.mean(axis=1)
    radius = sampler.face_radius
    tree = cKDTree(centre)
    local = radius / np.sqrt(np.maximum(sampler.face_hits, 1))
    ptr, faces = _kernels.unpack_rows(sampler.bits, soup.n_faces)
    added = 0
    for c in range(cells.n_cells):
        mine = faces[ptr[c] : ptr[c + 1]]
        if len(mine) == 0:
            continue
        lo, hi = cells.cell_lo[c], cells.cell_hi[c]
        gap = np.maximum(np.maximum(lo - centre[mine], centre[mine] - hi), 0.0)
        distance = np.linalg.norm(gap, axis=1)
        glob = 2 * distance / np.sqrt(max(int(sampler.cell_segments[c]), 1))
        e = scale * np.minimum(glob, local[mine])
        near = tree.query_ball_point(centre[mine], radius[mine] + e)
        cand = np.concatenate([np.asarray(n, np.int64) for n in near])
        owner = np.repeat(np.arange(len(mine)), [len(n) for n in near])
        close = _point_triangle_distance(centre[cand], tri[mine[owner]]) <= e[owner]
        hit = np.unique(cand[close])
        word = sampler.bits[c, hit >> 6]
        new = hit[((word >> (hit & 63).astype(np.uint64)) & np.uint64(1)) == 0]
        np.bitwise_or.at(sampler.bits[c], new >> 6, np.left_shift(np.uint64(1), (new & 63).astype(np.uint64)))
        added += len(new)
    return {"added": int(added), "mean_added": added / max(cells.n_cells, 1), "scale": float(scale)}


def _point_triangle_distance(p: np.ndarray, tri: np.ndarray) -> np.ndarray:
    """(n,) distance from each point to its triangle (the closest point by barycentric clamping)."""
    a, b, c = tri[:, 0], tri[:, 1], tri[:, 2]
    ab, ac, ap = b - a, c - a, p - a
    # the projection on the plane, then the nearest of it and the three edges when it falls outside
    n = np.cross(ab, ac)
    nn = np.einsum("ij,ij->i", n, n)
    safe = np.where(nn > 0, nn, 1.0)
    height = np.einsum("ij,ij->i", ap, n) / np.sqrt(safe)
    q = p - (np.einsum("ij,ij->i", ap, n) / safe)[:, None] * n
    inside = np.ones(len(p), bool)
    for u, v in ((a, b), (b, c), (c, a)):
        inside &= np.einsum("ij,ij->i", np.cross(v - u, q - u), n) >= 0
    best = np.where(inside & (nn > 0), np.abs(height), np.inf)
    for u, v in ((a, b), (b, c), (c, a)):
        e = v - u
        ee = np.einsum("ij,ij->i", e, e)
        t = np.clip(np.einsum("ij,ij->i", p - u, e) / np.where(ee > 0, ee, 1.0), 0.0, 1.0)
        best = np.minimum(best, np.linalg.norm(p - (u + t[:, None] * e), axis=1))
    return best
