"""Numba kernels of the ray generators of :mod:`meshvis.rays.samples`: one pass per ray.

The numpy versions gather the normal and the two tangents of every ray's face into
(rays, 3) arrays, then build the direction in three more passes over such arrays; at a
few million rays per round that memory traffic is most of their time.  These kernels read
each face's data once per ray and write the result directly.  They take the random
numbers from the caller (drawn from the same generator, in the same order as before) and
evaluate the same expressions in the same order, without fused multiply-adds, so their
output is bit for bit that of the numpy expressions they replace.

Each kernel is serial over the rows it is given and writes into arrays its caller made;
the function of the same name without the underscore allocates them and runs the kernel
on slices in threads (:func:`meshvis._threads.in_threads`, ``MESHVIS_THREADS`` threads).
Numba's own ``parallel=True`` would compile each kernel about 0.2 s longer on first use
and would take numba's thread count, not meshvis'.

The inline helpers below are shared by every kernel module of the package (rays, repair,
visibility), so that each numpy summation order is written once:

* ``np.linalg.norm(x, axis=1)`` sums the squares left to right (:func:`norm3`);
* ``np.einsum("ij,ij->i", a, b)`` over 3 columns adds the middle product last,
  ``(a0*b0 + a2*b2) + a1*b1`` (:func:`einsum_dot3`; numpy's baseline loop, the same with
  AVX, AVX2 and AVX-512 switched off);
* the square-root warp of ``uniform_in_triangles`` (:func:`warp_weights`).
"""

from __future__ import annotations

import math

import numba
import numpy as np

from meshvis._threads import in_threads


@numba.njit(cache=True, nogil=True, inline="always")
def norm3(x0, x1, x2):  # pragma: no cover - compiled
    """``np.linalg.norm`` of one 3-vector."""
    return math.sqrt((x0 * x0 + x1 * x1) + x2 * x2)


@numba.njit(cache=True, nogil=True, inline="always")
def einsum_dot3(a0, a1, a2, b0, b1, b2):  # pragma: no cover - compiled
    """``np.einsum("ij,ij->i", a, b)`` of one row (numpy adds the middle product last)."""
    return (a0 * b0 + a2 * b2) + a1 * b1


@numba.njit(cache=True, nogil=True, inline="always")
def warp_weights(ru, rv):  # pragma: no cover - compiled
    """Corner weights ``(1-√u, √u (1-v), √u v)`` of the square-root warp from its two uniforms.

    A point is then ``wa * a + wb * b + wc * c`` (left to right, as numpy evaluates it).
    """
    u = math.sqrt(ru)
    return 1 - u, u * (1 - rv), u * rv


@numba.njit(cache=True, nogil=True, error_model="numpy")
def _unit_rows(d, out):  # pragma: no cover - compiled
    for k in range(len(d)):
        n = norm3(d[k, 0], d[k, 1], d[k, 2])
        for c in range(3):
            out[k, c] = d[k, c] / n


def unit_rows(d: np.ndarray) -> np.ndarray:
    """(n, 3) ``d / np.linalg.norm(d, axis=1, keepdims=True)``."""
    out = np.empty_like(d)
    in_threads(lambda a, b: _unit_rows(d[a:b], out[a:b]), len(d))
    return out


@numba.njit(cache=True, nogil=True, error_model="numpy")
def _points_in_faces(triangles, face, ru, rv, out):  # pragma: no cover - compiled
    for k in range(len(face)):
        f = face[k]
        wa, wb, wc = warp_weights(ru[k], rv[k])
        for c in range(3):
            out[k, c] = wa * triangles[f, 0, c] + wb * triangles[f, 1, c] + wc * triangles[f, 2, c]


def points_in_faces(triangles: np.ndarray, face: np.ndarray, ru: np.ndarray, rv: np.ndarray) -> np.ndarray:
    """(n, 3) ``uniform_in_triangles(triangles[face], rng)`` from its two draws ``ru, rv``."""
    out = np.empty((len(face), 3))
    in_threads(lambda a, b: _points_in_faces(triangles, face[a:b], ru[a:b], rv[a:b], out[a:b]), len(face))
    return out


#: 2π as the numpy expression ``2 * np.pi * xi`` evaluates it (the product first)
TWO_PI = 2 * math.pi


@numba.njit(cache=True, nogil=True, error_model="numpy")
def _cosine_directions(normals, t1, t2, face, flip, xi1, xi2, out):  # pragma: no cover - compiled
    for k in range(len(face)):
        f = face[k]
        sgn = -1.0 if flip[k] else 1.0
        cos_t = math.sqrt(1.0 - xi1[k])
        sin_t = math.sqrt(xi1[k])
        phi = TWO_PI * xi2[k]
        a = sin_t * math.cos(phi)
        b = sin_t * math.sin(phi)
        for c in range(3):
            out[k, c] = a * t1[f, c] + b * t2[f, c] + cos_t * (normals[f, c] * sgn)


def cosine_directions(
    normals: np.ndarray,
    t1: np.ndarray,
    t2: np.ndarray,
    face: np.ndarray,
    flip: np.ndarray,
    xi1: np.ndarray,
    xi2: np.ndarray,
) -> np.ndarray:
    """(r, 3) cosine-distributed directions about the side normal of ``face[k]``.

    ``flip[k]`` selects side 1 (the negated normal); ``t1, t2`` are the faces' tangents.
    """
    out = np.empty((len(face), 3))
    in_threads(
        lambda a, b: _cosine_directions(normals, t1, t2, face[a:b], flip[a:b], xi1[a:b], xi2[a:b], out[a:b]),
        len(face),
    )
    return out


@numba.njit(cache=True, nogil=True, error_model="numpy")
def _pushed_points(triangles, normals, face, flip, ru, rv, offset, out):  # pragma: no cover - compiled
    for k in range(len(face)):
        f = face[k]
        sgn = -1.0 if flip[k] else 1.0
        wa, wb, wc = warp_weights(ru[k], rv[k])
        for c in range(3):
            p = wa * triangles[f, 0, c] + wb * triangles[f, 1, c] + wc * triangles[f, 2, c]
            out[k, c] = p + offset * (normals[f, c] * sgn)


def pushed_points(
    triangles: np.ndarray,
    normals: np.ndarray,
    face: np.ndarray,
    flip: np.ndarray,
    ru: np.ndarray,
    rv: np.ndarray,
    offset: float,
) -> np.ndarray:
    """(r, 3) uniform points on ``face[k]`` pushed by ``offset`` along its side normal.

    ``ru, rv`` are the two uniform numbers of the square-root warp of
    :func:`meshvis.rays.samples.uniform_in_triangles`.
    """
    out = np.empty((len(face), 3))
    in_threads(
        lambda a, b: _pushed_points(
            triangles, normals, face[a:b], flip[a:b], ru[a:b], rv[a:b], offset, out[a:b]
        ),
        len(face),
    )
    return out


@numba.njit(cache=True, nogil=True, error_model="numpy", inline="always")
def segment_query(k, o, t, center, scale, offset, o32, d32, dist, ok):  # pragma: no cover - compiled
    """Row k of :func:`segment_queries` for the segment from point ``o`` to point ``t`` (3 scalars each)."""
    s0, s1, s2 = t[0] - o[0], t[1] - o[1], t[2] - o[2]
    length = norm3(s0, s1, s2)
    ok[k] = length > 0
    if length > 0:
        d32[k, 0], d32[k, 1], d32[k, 2] = s0 / length, s1 / length, s2 / length
    else:
        d32[k, 0], d32[k, 1], d32[k, 2] = 0.0, 0.0, 1.0
    dist[k] = max(length * scale - offset, 0.0)
    for c in range(3):
        o32[k, c] = (o[c] - center[c]) * scale


def query_buffers(n: int) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Empty outputs of :func:`segment_queries` for n segments: o32, d32, dist, ok."""
    return (
        np.empty((n, 3), np.float32),
        np.empty((n, 3), np.float32),
        np.empty(n, np.float32),
        np.empty(n, np.bool_),
    )


@numba.njit(cache=True, nogil=True, error_model="numpy")
def _segment_queries(
    origins, targets, center, scale, offset, o32, d32, dist, ok
):  # pragma: no cover - compiled
    for k in range(len(origins)):
        segment_query(k, origins[k], targets[k], center, scale, offset, o32, d32, dist, ok)


def segment_queries(
    origins: np.ndarray, targets: np.ndarray, center: np.ndarray, scale: float, offset: float
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Embree inputs of the segments ``origins[k] -> targets[k]`` (:meth:`RayCaster.occluded`).

    Returns the float32 origins in scene coordinates, the float32 unit directions, the
    float32 lengths in scene units shortened by ``offset`` (never below 0), and whether
    each segment has a length.  A zero-length segment gets the direction +z.
    """
    out = query_buffers(len(origins))
    in_threads(
        lambda a, b: _segment_queries(
            origins[a:b], targets[a:b], center, scale, offset, *(x[a:b] for x in out)
        ),
        len(origins),
    )
    return out


@numba.njit(cache=True, nogil=True, error_model="numpy")
def _ray_queries(origins, directions, center, scale, unit, o32, d32):  # pragma: no cover - compiled
    for k in range(len(origins)):
        d0, d1, d2 = directions[k, 0], directions[k, 1], directions[k, 2]
        length = math.sqrt(einsum_dot3(d0, d1, d2, d0, d1, d2))
        unit[k, 0], unit[k, 1], unit[k, 2] = d0 / length, d1 / length, d2 / length
        for c in range(3):
            d32[k, c] = unit[k, c]
            o32[k, c] = (origins[k, c] - center[c]) * scale


def ray_queries(
    origins: np.ndarray, directions: np.ndarray, center: np.ndarray, scale: float
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Embree inputs of the rays ``origins + t * directions`` (:meth:`RayCaster.intersect`).

    Returns the float64 unit directions ``d / sqrt(einsum("ij,ij->i", d, d))`` (numpy's
    einsum adds the middle square last; a zero direction gives NaN, which the caller
    refuses), their float32 copy and the float32 origins in scene coordinates.
    """
    n = len(origins)
    out = np.empty((n, 3)), np.empty((n, 3), np.float32), np.empty((n, 3), np.float32)
    unit, o32, d32 = out
    in_threads(
        lambda a, b: _ray_queries(
            origins[a:b], directions[a:b], center, scale, unit[a:b], o32[a:b], d32[a:b]
        ),
        n,
    )
    return out


@numba.njit(cache=True, nogil=True, error_model="numpy")
def _hit_results(prim, tfar, ng, unit, scale, face, distance, side):  # pragma: no cover - compiled
    for k in range(len(prim)):
        f = prim[k]
        face[k] = f
        if f >= 0:
            distance[k] = np.float64(tfar[k]) / scale
            g0, g1, g2 = np.float64(ng[k, 0]), np.float64(ng[k, 1]), np.float64(ng[k, 2])
            dot = einsum_dot3(unit[k, 0], unit[k, 1], unit[k, 2], g0, g1, g2)
            side[k] = 1 if dot >= 0 else 0
        else:
            distance[k] = np.inf
            side[k] = -1


def hit_results(
    prim: np.ndarray, tfar: np.ndarray, ng: np.ndarray, unit: np.ndarray, scale: float
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Face (int64, -1 for a miss), distance (input units, inf for a miss) and side of each hit.

    ``side`` is 0 where ``einsum("ij,ij->i", unit, Ng) < 0`` (the ray met the front), 1
    where it is not, -1 for a miss.
    """
    n = len(prim)
    face, distance, side = np.empty(n, np.int64), np.empty(n), np.empty(n, np.int8)
    in_threads(
        lambda a, b: _hit_results(
            prim[a:b], tfar[a:b], ng[a:b], unit[a:b], scale, face[a:b], distance[a:b], side[a:b]
        ),
        n,
    )
    return face, distance, side
