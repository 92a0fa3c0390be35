"""Numba kernel of the escape rays of :func:`meshvis.repair.evidence.escapes`.

The numpy version built each batch's points, directions, pushed origins and segment ends
as (faces, rays, 3) float64 arrays, then :meth:`RayCaster.occluded` read them again: most
of the evidence stage was that memory traffic, not Embree.  This kernel takes the random
numbers from the caller (drawn in the same order as before) and writes the Embree inputs
directly, evaluating the same expressions in the same order, so that the counts are bit
for bit those of the numpy version (the summation orders are the helpers of
:mod:`meshvis.rays._kernels`).  Like those, the kernel is serial and runs on slices of
the faces in threads.
"""

from __future__ import annotations

import numba
import numpy as np

from meshvis._threads import in_threads
from meshvis.rays._kernels import einsum_dot3, norm3, query_buffers, segment_query, warp_weights


@numba.njit(cache=True, nogil=True, error_model="numpy")
def _escape_queries(
    triangles, normal, ru, rv, gauss, through, push, reach, center, scale, offset, o32, d32, dist, ok, back
):  # pragma: no cover - compiled
    k, rays = ru.shape
    o = np.empty(3)
    t = np.empty(3)
    d = np.empty(3)
    for f in range(k):
        a, b, c = triangles[f, 0], triangles[f, 1], triangles[f, 2]
        n = normal[f]
        for r in range(rays):
            row = f * rays + r
            g = gauss[row]
            length = norm3(g[0], g[1], g[2])
            for j in range(3):
                d[j] = g[j] / length
            along = einsum_dot3(d[0], d[1], d[2], n[0], n[1], n[2])  # np.einsum("krj,kj->kr")
            if through[f] >= 0 and (along < 0) != (through[f] == 1):
                for j in range(3):
                    d[j] *= -1.0
                along *= -1.0
            bk = along < 0
            back[row] = bk
            shift = -push if bk else push
            wa, wb, wc = warp_weights(ru[f, r], rv[f, r])
            for j in range(3):
                o[j] = (wa * a[j] + wb * b[j] + wc * c[j]) + n[j] * shift
                t[j] = o[j] + d[j] * reach
            segment_query(row, o, t, center, scale, offset, o32, d32, dist, ok)


def escape_queries(
    triangles: np.ndarray,
    normal: np.ndarray,
    ru: np.ndarray,
    rv: np.ndarray,
    gauss: np.ndarray,
    through: np.ndarray,
    push: float,
    reach: float,
    center: np.ndarray,
    scale: float,
    offset: float,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Segments of ``rays`` uniform random rays from uniform points of each of k faces.

    Parameters
    ----------
    triangles : (k, 3, 3) corners; normal : (k, 3) unit normals
    ru, rv : (k, rays) uniforms of the square-root warp of ``uniform_in_triangles``
    gauss : (k * rays, 3) standard normal draws (``uniform_sphere``'s directions)
    through : (k,) int, -1 for both sides, else the side every ray leaves through
        (a direction on the other side is mirrored)
    push : push of the origins off the face (model units); reach : segment length
    center, scale, offset : the scene transform and end push of :meth:`RayCaster.occluded`

    Returns
    -------
    o32, d32, dist, ok : as :func:`meshvis.rays._kernels.segment_queries`
    back : (k * rays,) bool
        The ray leaves through the back
    """
    k, rays = ru.shape
    out = (*query_buffers(k * rays), np.empty(k * rays, np.bool_))

    def work(a: int, b: int) -> None:
        rows = slice(a * rays, b * rays)
        _escape_queries(
            triangles[a:b],
            normal[a:b],
            ru[a:b],
            rv[a:b],
            gauss[rows],
            through[a:b],
            push,
            reach,
            center,
            scale,
            offset,
            *(x[rows] for x in out),
        )

    in_threads(work, k, rays)
    return out
