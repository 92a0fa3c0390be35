"""Numba kernel of the hit snapping of :func:`meshvis.graphcut.sampling.snap_to_points`.

The numpy version made one pass over all hits per sample point, with (hits,) temporaries
for each term of the distance; this kernel keeps the running best per hit in registers.
It evaluates the same quadratic form in the same order, with the same tie rule (the first
sample wins), so its choice is bit for bit that of the numpy version.
"""

from __future__ import annotations

import numba
import numpy as np


@numba.njit(cache=True, nogil=True, parallel=True, error_model="numpy")
def nearest_sample(metric, u, v, sample_u, sample_v):  # pragma: no cover - compiled
    """(n,) index of the sample nearest to each hit under the face metric ``Δᵀ G Δ``.

    ``metric[k] = (e1·e1, e1·e2, e2·e2)`` of hit k's face; ``u, v`` the hits' barycentric
    coordinates; ``sample_u, sample_v`` the samples' (the same pattern on every face).
    """
    n = len(u)
    best = np.zeros(n, np.int64)
    for k in numba.prange(n):
        g0, g1, g2 = metric[k, 0], metric[k, 1], metric[k, 2]
        uk, vk = np.float64(u[k]), np.float64(v[k])
        best_d2 = 0.0
        for s in range(len(sample_u)):
            du, dv = uk - sample_u[s], vk - sample_v[s]
            d2 = g0 * du * du + 2 * g1 * du * dv + g2 * dv * dv
            if s == 0 or d2 < best_d2:
                best[k] = s
                best_d2 = d2
    return best
