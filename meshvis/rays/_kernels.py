"""Numba kernels of the ray generators of :mod:`meshvis.rays.samples`: one pass per ray.

The numpy versions gather the normal and the two tangents of every ray's face into
(rays, 3) arrays, then build the direction in three more passes over such arrays; at a
few million rays per round that memory traffic is most of their time.  These kernels read
each face's data once per ray and write the result directly.  They take the random
numbers from the caller (drawn from the same generator, in the same order as before) and
evaluate the same expressions in the same order, without fused multiply-adds, so their
output is bit for bit that of the numpy expressions they replace.
"""

from __future__ import annotations

import math

import numba
import numpy as np

#: 2π as the numpy expression ``2 * np.pi * xi`` evaluates it (the product first)
TWO_PI = 2 * math.pi


@numba.njit(cache=True, nogil=True, parallel=True, error_model="numpy")
def cosine_directions(normals, t1, t2, face, flip, xi1, xi2):  # pragma: no cover - compiled
    """(r, 3) cosine-distributed directions about the side normal of ``face[k]``.

    ``flip[k]`` selects side 1 (the negated normal); ``t1, t2`` are the faces' tangents.
    """
    r = len(face)
    out = np.empty((r, 3))
    for k in numba.prange(r):
        f = face[k]
        sgn = -1.0 if flip[k] else 1.0
        cos_t = math.sqrt(1.0 - xi1[k])
        sin_t = math.sqrt(xi1[k])
        phi = TWO_PI * xi2[k]
        a = sin_t * math.cos(phi)
        b = sin_t * math.sin(phi)
        for c in range(3):
            out[k, c] = a * t1[f, c] + b * t2[f, c] + cos_t * (normals[f, c] * sgn)
    return out


@numba.njit(cache=True, nogil=True, parallel=True, error_model="numpy")
def pushed_points(triangles, normals, face, flip, ru, rv, offset):  # pragma: no cover - compiled
    """(r, 3) uniform points on ``face[k]`` pushed by ``offset`` along its side normal.

    ``ru, rv`` are the two uniform numbers of the square-root warp of
    :func:`meshvis.rays.samples.uniform_in_triangles`.
    """
    out = np.empty((len(face), 3))
    for k in numba.prange(len(face)):
        f = face[k]
        sgn = -1.0 if flip[k] else 1.0
        u = math.sqrt(ru[k])
        v = rv[k]
        wa, wb, wc = 1 - u, u * (1 - v), u * v
        for c in range(3):
            p = wa * triangles[f, 0, c] + wb * triangles[f, 1, c] + wc * triangles[f, 2, c]
            out[k, c] = p + offset * (normals[f, c] * sgn)
    return out
