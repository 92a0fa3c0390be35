"""Numba kernel of the escape rays of :func:`meshvis.repair.evidence.escapes`.

Each ray's random numbers are a hash of the seed, its face and its index among that face's
rays (:func:`ray_uniform`), drawn inside the kernel: the k-th ray cast from a face is the
same whichever other faces were cast from before it, so that which faces get more rays
(chosen from counts that depend on the side each face shows) never changes another face's
rays.  The kernel writes the Embree inputs directly (no (faces, rays, 3) float64 arrays
for :meth:`RayCaster.occluded` to read again) and, like the kernels of
:mod:`meshvis.rays._kernels`, is serial and runs on slices of the faces in threads.
"""

from __future__ import annotations

import math

import numba
import numpy as np

from meshvis._threads import in_threads
from meshvis.rays._kernels import einsum_dot3, query_buffers, segment_query, warp_weights

#: the odd constant of splitmix64 (2^64 over the golden ratio): consecutive counters land far apart
GOLDEN = np.uint64(0x9E3779B97F4A7C15)
#: uniforms per ray: two for the direction, two for the point on the face
PER_RAY = 4


@numba.njit(cache=True, nogil=True, inline="always")
def mix64(z):  # pragma: no cover - compiled
    """The splitmix64 finaliser: a bijection of uint64 whose outputs look independent."""
    z = (z ^ (z >> np.uint64(30))) * np.uint64(0xBF58476D1CE4E5B9)
    z = (z ^ (z >> np.uint64(27))) * np.uint64(0x94D049BB133111EB)
    return z ^ (z >> np.uint64(31))


@numba.njit(cache=True, nogil=True, inline="always")
def face_key(seed_key, face):  # pragma: no cover - compiled
    """The key of one face's stream of uniforms."""
    return mix64(seed_key ^ (np.uint64(face) * GOLDEN))


@numba.njit(cache=True, nogil=True, inline="always")
def ray_uniform(key, n):  # pragma: no cover - compiled
    """The n-th uniform in [0, 1) of the stream ``key`` (53 bits)."""
    z = mix64(key + (np.uint64(n) + np.uint64(1)) * GOLDEN)
    return float(z >> np.uint64(11)) * (1.0 / 9007199254740992.0)


@numba.njit(cache=True, nogil=True, inline="always")
def draw_ray(key, first, a, b, c, n, through, o, d):  # pragma: no cover - compiled
    """One ray from uniforms ``first .. first + 3`` of stream ``key``: its point on the face
    (a, b, c) into ``o``, its direction into ``d``; returns whether it leaves through the back.

    The direction is uniform on the sphere (z uniform in [-1, 1], the azimuth uniform),
    mirrored to side ``through`` where that is 0 or 1; the point is uniform on the face
    (the square-root warp).
    """
    z = 1.0 - 2.0 * ray_uniform(key, first)
    phi = 2.0 * math.pi * ray_uniform(key, first + 1)
    s = math.sqrt(max(0.0, 1.0 - z * z))
    d[0], d[1], d[2] = s * math.cos(phi), s * math.sin(phi), z
    along = einsum_dot3(d[0], d[1], d[2], n[0], n[1], n[2])
    if through >= 0 and (along < 0) != (through == 1):
        for j in range(3):
            d[j] *= -1.0
        along *= -1.0
    wa, wb, wc = warp_weights(ray_uniform(key, first + 2), ray_uniform(key, first + 3))
    for j in range(3):
        o[j] = (wa * a[j] + wb * b[j]) + wc * c[j]
    return along < 0


@numba.njit(cache=True, nogil=True, error_model="numpy")
def _escape_queries(
    triangles,
    normal,
    face,
    start,
    rays,
    seed_key,
    through,
    push,
    reach,
    center,
    scale,
    offset,
    o32,
    d32,
    dist,
    ok,
    back,
):  # pragma: no cover - compiled
    o = np.empty(3)
    t = np.empty(3)
    d = np.empty(3)
    for f in range(len(face)):
        a, b, c = triangles[f, 0], triangles[f, 1], triangles[f, 2]
        n = normal[f]
        key = face_key(seed_key, face[f])
        for r in range(rays):
            row = f * rays + r
            bk = draw_ray(key, (start[f] + r) * PER_RAY, a, b, c, n, through[f], o, d)
            back[row] = bk
            shift = -push if bk else push
            for j in range(3):
                o[j] += n[j] * shift
                t[j] = o[j] + d[j] * reach
            segment_query(row, o, t, center, scale, offset, o32, d32, dist, ok)


@numba.njit(cache=True, nogil=True, error_model="numpy")
def _sample_rays(
    triangles, normal, face, start, rays, seed_key, through, points, directions, back
):  # pragma: no cover - compiled
    for f in range(len(face)):
        key = face_key(seed_key, face[f])
        for r in range(rays):
            row = f * rays + r
            back[row] = draw_ray(
                key,
                (start[f] + r) * PER_RAY,
                triangles[f, 0],
                triangles[f, 1],
                triangles[f, 2],
                normal[f],
                through[f],
                points[row],
                directions[row],
            )


def sample_rays(
    triangles: np.ndarray,
    normal: np.ndarray,
    face: np.ndarray,
    start: np.ndarray,
    rays: int,
    seed_key: int,
    through: np.ndarray,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The rays of :func:`escape_queries` as points on their faces (not pushed) and directions.

    Parameters and the rays are those of :func:`escape_queries`.

    Returns
    -------
    points : (k * rays, 3) float64; directions : (k * rays, 3) float64, unit
    back : (k * rays,) bool, the ray leaves through the back
    """
    k = len(face)
    points, directions = np.empty((k * rays, 3)), np.empty((k * rays, 3))
    back = np.empty(k * rays, np.bool_)
    _sample_rays(
        np.ascontiguousarray(triangles, np.float64),
        np.ascontiguousarray(normal, np.float64),
        np.ascontiguousarray(face, np.int64),
        np.ascontiguousarray(start, np.int64),
        rays,
        np.uint64(seed_key),
        np.ascontiguousarray(through, np.int64),
        points,
        directions,
        back,
    )
    return points, directions, back


def escape_queries(
    triangles: np.ndarray,
    normal: np.ndarray,
    face: np.ndarray,
    start: np.ndarray,
    rays: int,
    seed_key: int,
    through: np.ndarray,
    push: float,
    reach: float,
    center: np.ndarray,
    scale: float,
    offset: float,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Segments of ``rays`` random rays from random points of each of k faces.

    Ray ``start[i] + r`` of face ``face[i]`` (r < ``rays``) leaves a uniformly random point
    of the face in a uniformly random direction, both drawn from the face's stream
    (:func:`ray_uniform`).

    Parameters
    ----------
    triangles : (k, 3, 3) corners; normal : (k, 3) unit normals
    face : (k,) int64, the faces' indices in their model (the keys of their streams)
    start : (k,) int64, the index of each face's first ray here among all its rays
    rays : int, rays per face
    seed_key : int, the seed's key (:func:`seed_key`)
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
    k = len(face)
    out = (*query_buffers(k * rays), np.empty(k * rays, np.bool_))
    face = np.ascontiguousarray(face, np.int64)
    start = np.ascontiguousarray(start, np.int64)
    key = np.uint64(seed_key)

    def work(a: int, b: int) -> None:
        rows = slice(a * rays, b * rays)
        _escape_queries(
            triangles[a:b],
            normal[a:b],
            face[a:b],
            start[a:b],
            rays,
            key,
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


def seed_key(seed: int) -> int:
    """The key of a seed's streams: a hash of it (any int, taken modulo 2^64).

    Examples
    --------
    >>> seed_key(0) != seed_key(1)
    True
    """
    return int(mix64(np.uint64(seed % (1 << 64)) + GOLDEN))
