"""Numba kernels of the from-region samplers (:mod:`.sampling`, :mod:`.regions`).

The numpy versions run each ray batch through a dozen passes over (n, 3) temporaries
(gathered corners and normals, norms, products) and, on small batches, pay numpy's call
overhead thousands of times per search.  These kernels do one pass per batch.  They take
the random numbers from the caller (drawn from the same generator, in the same order and
shapes as before) and evaluate the same floating-point expressions in the same order,
without fused multiply-adds, so their output is bit for bit that of the numpy code they
replace.

The kernels of the propagation loop (:func:`far_origins`, :func:`aimed_from`) run
thousands of times per search on batches of a few thousand rays, where starting the
thread pool costs more than the loop: they are serial.  The seed kernels run once per
chunk of up to a million rays and are parallel.

Summation orders replicated:

* ``np.linalg.norm(x, axis=1)`` sums the squares left to right: ``sqrt((x0*x0 + x1*x1) + x2*x2)``;
* ``np.einsum("ij,ij->i", a, b)`` over 3 columns adds the middle product last:
  ``(a0*b0 + a2*b2) + a1*b1`` (numpy's unrolled loop; checked on a million random rows).
"""

from __future__ import annotations

import math

import numba
import numpy as np

from meshvis.rays._kernels import query_buffers, segment_query


@numba.njit(cache=True, nogil=True, inline="always")
def _norm3(x0, x1, x2):  # pragma: no cover - compiled
    """``np.linalg.norm`` of one 3-vector."""
    return math.sqrt((x0 * x0 + x1 * x1) + x2 * x2)


@numba.njit(cache=True, nogil=True, parallel=True, error_model="numpy")
def points_in_faces(triangles, face, ru, rv):  # pragma: no cover - compiled
    """(n, 3) ``uniform_in_triangles(triangles[face], rng)`` from its two draws ``ru, rv``."""
    out = np.empty((len(face), 3))
    for k in numba.prange(len(face)):
        f = face[k]
        u = math.sqrt(ru[k])
        v = rv[k]
        wa, wb, wc = 1 - u, u * (1 - v), u * v
        for c in range(3):
            out[k, c] = (wa * triangles[f, 0, c] + wb * triangles[f, 1, c]) + wc * triangles[f, 2, c]
    return out


@numba.njit(cache=True, nogil=True, parallel=True, error_model="numpy")
def unit_rows(d):  # pragma: no cover - compiled
    """(n, 3) ``d / np.linalg.norm(d, axis=1, keepdims=True)``."""
    out = np.empty_like(d)
    for k in numba.prange(len(d)):
        n = _norm3(d[k, 0], d[k, 1], d[k, 2])
        for c in range(3):
            out[k, c] = d[k, c] / n
    return out


@numba.njit(cache=True, nogil=True, error_model="numpy")
def far_origins(targets, directions, center, margin):  # pragma: no cover - compiled
    """(n, 3) :meth:`Region.far_origins`; ``margin`` is ``(1 + FAR_MARGIN) * radius``."""
    out = np.empty_like(targets)
    for k in range(len(targets)):
        reach = (
            _norm3(targets[k, 0] - center[0], targets[k, 1] - center[1], targets[k, 2] - center[2]) + margin
        )
        for c in range(3):
            out[k, c] = targets[k, c] - directions[k, c] * reach
    return out


@numba.njit(cache=True, nogil=True, error_model="numpy")
def aimed_from(origins, targets):  # pragma: no cover - compiled
    """(n, 3) unit directions ``origins[k] -> targets[k]`` (``d / np.linalg.norm(d)``, no zero guard)."""
    out = np.empty_like(targets)
    for k in range(len(targets)):
        d0 = targets[k, 0] - origins[k, 0]
        d1 = targets[k, 1] - origins[k, 1]
        d2 = targets[k, 2] - origins[k, 2]
        n = _norm3(d0, d1, d2)
        out[k, 0], out[k, 1], out[k, 2] = d0 / n, d1 / n, d2 / n
    return out


@numba.njit(cache=True, nogil=True, parallel=True, error_model="numpy")
def facing_sides(directions, normals, face):  # pragma: no cover - compiled
    """(n,) int8: ``einsum("ij,ij->i", directions, normals[face]) >= 0``."""
    out = np.empty(len(face), np.int8)
    for k in numba.prange(len(face)):
        f = face[k]
        dot = (directions[k, 0] * normals[f, 0] + directions[k, 2] * normals[f, 2]) + directions[
            k, 1
        ] * normals[f, 1]
        out[k] = 1 if dot >= 0 else 0
    return out


@numba.njit(cache=True, nogil=True, parallel=True, error_model="numpy")
def seed_segments(points, normals, face, side, viewers, center, scale, offset, diagonal):  # pragma: no cover
    """Embree inputs of ``RayCaster.occluded(RayCaster.push_off(points, face, side), viewers)``.

    ``center, scale, offset, diagonal`` are the caster's.  Returns ``(o32, d32, dist, ok)``
    as :func:`meshvis.rays._kernels.segment_queries`.
    """
    o32, d32, dist, ok = query_buffers(len(points))
    pushed = np.empty_like(points)
    for k in numba.prange(len(points)):
        f = face[k]
        s = ((1.0 if side[k] == 0 else -1.0) * offset) * diagonal
        for c in range(3):
            pushed[k, c] = points[k, c] + normals[f, c] * s
        segment_query(k, pushed[k], viewers[k], center, scale, offset, o32, d32, dist, ok)
    return o32, d32, dist, ok
