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
chunk of up to a million rays, on slices in threads (:func:`meshvis._threads.in_threads`).

The summation orders of numpy's norm and einsum are the helpers of
:mod:`meshvis.rays._kernels`.
"""

from __future__ import annotations

import numba
import numpy as np

from meshvis._threads import in_threads
from meshvis.rays._kernels import einsum_dot3, norm3, query_buffers, segment_query


@numba.njit(cache=True, nogil=True, error_model="numpy")
def far_origins(targets, directions, center, margin):  # pragma: no cover - compiled
    """(n, 3) :meth:`Region.far_origins`; ``margin`` is ``(1 + FAR_MARGIN) * radius``."""
    out = np.empty_like(targets)
    for k in range(len(targets)):
        reach = (
            norm3(targets[k, 0] - center[0], targets[k, 1] - center[1], targets[k, 2] - center[2]) + margin
        )
        for c in range(3):
            out[k, c] = targets[k, c] - directions[k, c] * reach
    return out


@numba.njit(cache=True, nogil=True, error_model="numpy")
def framed_targets(directions, u, v, center, half):  # pragma: no cover - compiled
    """(n, 3) points of the box's orthographic frame across each direction (:meth:`Region.view_lines`).

    Each direction ``d`` gets two unit axes across it, ``a = d x e / |d x e|`` (``e`` the x
    axis, or the y axis where ``|d_x| >= 0.9``) and ``b = d x a``; the box of half sides
    ``half`` projects to ``|a|.half`` and ``|b|.half`` along them, and ``u``, ``v`` (uniform
    in [0, 1)) pick the point ``center + (2u - 1)|a|.half a + (2v - 1)|b|.half b``.
    """
    out = np.empty_like(directions)
    for k in range(len(directions)):
        d0, d1, d2 = directions[k, 0], directions[k, 1], directions[k, 2]
        if abs(d0) < 0.9:  # d x (1, 0, 0)
            a0, a1, a2 = 0.0, d2, -d1
        else:  # d x (0, 1, 0)
            a0, a1, a2 = -d2, 0.0, d0
        n = norm3(a0, a1, a2)
        a0, a1, a2 = a0 / n, a1 / n, a2 / n
        b0, b1, b2 = d1 * a2 - d2 * a1, d2 * a0 - d0 * a2, d0 * a1 - d1 * a0
        ru = (2.0 * u[k] - 1.0) * (abs(a0) * half[0] + abs(a1) * half[1] + abs(a2) * half[2])
        rv = (2.0 * v[k] - 1.0) * (abs(b0) * half[0] + abs(b1) * half[1] + abs(b2) * half[2])
        out[k, 0] = center[0] + ru * a0 + rv * b0
        out[k, 1] = center[1] + ru * a1 + rv * b1
        out[k, 2] = center[2] + ru * a2 + rv * b2
    return out


@numba.njit(cache=True, nogil=True, error_model="numpy")
def tilt_into_planes(directions, axis, tilt):  # pragma: no cover - compiled
    """Turn the first ``len(axis)`` directions into their coordinate plane ``axis``, tilted out by ``tilt`` (in place).

    The component along ``axis`` is dropped, the rest scaled to ``cos(tilt)`` and the
    component set to ``sin(tilt)`` (:func:`meshvis.visibility.regions.view_directions`).
    """
    for k in range(len(axis)):
        directions[k, axis[k]] = 0.0
        n = max(norm3(directions[k, 0], directions[k, 1], directions[k, 2]), 1e-300)
        c = np.cos(tilt[k])
        for j in range(3):
            directions[k, j] = directions[k, j] / n * c
        directions[k, axis[k]] = np.sin(tilt[k])


@numba.njit(cache=True, nogil=True, error_model="numpy")
def aimed_from(origins, targets):  # pragma: no cover - compiled
    """(n, 3) unit directions ``origins[k] -> targets[k]`` (``d / np.linalg.norm(d)``, no zero guard)."""
    out = np.empty_like(targets)
    for k in range(len(targets)):
        d0 = targets[k, 0] - origins[k, 0]
        d1 = targets[k, 1] - origins[k, 1]
        d2 = targets[k, 2] - origins[k, 2]
        n = norm3(d0, d1, d2)
        out[k, 0], out[k, 1], out[k, 2] = d0 / n, d1 / n, d2 / n
    return out


@numba.njit(cache=True, nogil=True, error_model="numpy")
def _facing_sides(directions, normals, face, out):  # pragma: no cover - compiled
    for k in range(len(face)):
        f = face[k]
        dot = einsum_dot3(
            directions[k, 0], directions[k, 1], directions[k, 2], normals[f, 0], normals[f, 1], normals[f, 2]
        )
        out[k] = 1 if dot >= 0 else 0


def facing_sides(directions: np.ndarray, normals: np.ndarray, face: np.ndarray) -> np.ndarray:
    """(n,) int8: ``einsum("ij,ij->i", directions, normals[face]) >= 0``."""
    out = np.empty(len(face), np.int8)
    in_threads(lambda a, b: _facing_sides(directions[a:b], normals, face[a:b], out[a:b]), len(face))
    return out


@numba.njit(cache=True, nogil=True, error_model="numpy")
def _seed_segments(
    points, normals, face, side, viewers, center, scale, offset, diagonal, o32, d32, dist, ok
):  # pragma: no cover - compiled
    pushed = np.empty(3)
    for k in range(len(points)):
        f = face[k]
        s = ((1.0 if side[k] == 0 else -1.0) * offset) * diagonal
        for c in range(3):
            pushed[c] = points[k, c] + normals[f, c] * s
        segment_query(k, pushed, viewers[k], center, scale, offset, o32, d32, dist, ok)


def seed_segments(
    points: np.ndarray,
    normals: np.ndarray,
    face: np.ndarray,
    side: np.ndarray,
    viewers: np.ndarray,
    center: np.ndarray,
    scale: float,
    offset: float,
    diagonal: float,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Embree inputs of ``RayCaster.occluded(RayCaster.push_off(points, face, side), viewers)``.

    ``center, scale, offset, diagonal`` are the caster's.  Returns ``(o32, d32, dist, ok)``
    as :func:`meshvis.rays._kernels.segment_queries`.
    """
    out = query_buffers(len(points))
    in_threads(
        lambda a, b: _seed_segments(
            points[a:b],
            normals,
            face[a:b],
            side[a:b],
            viewers[a:b],
            center,
            scale,
            offset,
            diagonal,
            *(x[a:b] for x in out),
        ),
        len(points),
    )
    return out


@numba.njit(cache=True, nogil=True, inline="always")
def _guard(n):  # pragma: no cover - compiled
    """The divisor of ``_unit``: ``np.where(n > 0, n, 1.0)``."""
    return n if n > 0 else 1.0


@numba.njit(cache=True, nogil=True, error_model="numpy")
def reverse_jumps(
    band_face, parent_face, normals, triangles, origin, direction, point, threshold
):  # pragma: no cover
    """Band rays stopped more than ``threshold`` before the plane of their parent's face.

    Returns their indices (ascending) and the distance ``t_pred`` to that plane along each,
    as the numpy code of :func:`meshvis.visibility.sampling.reverse_sampling` computes them.
    """
    n = len(band_face)
    idx = np.empty(n, np.int64)
    t_out = np.empty(n)
    m = 0
    for i in range(n):
        f = parent_face[i]
        if band_face[i] == f:
            continue
        n0, n1, n2 = normals[f, 0], normals[f, 1], normals[f, 2]
        o0, o1, o2 = origin[i, 0], origin[i, 1], origin[i, 2]
        d0, d1, d2 = direction[i, 0], direction[i, 1], direction[i, 2]
        denom = einsum_dot3(d0, d1, d2, n0, n1, n2)
        t_pred = -np.inf
        if abs(denom) > 1e-6:
            w0, w1, w2 = triangles[f, 0, 0] - o0, triangles[f, 0, 1] - o1, triangles[f, 0, 2] - o2
            t_pred = einsum_dot3(w0, w1, w2, n0, n1, n2) / denom
        t_hit = einsum_dot3(point[i, 0] - o0, point[i, 1] - o1, point[i, 2] - o2, d0, d1, d2)
        if t_pred - t_hit > threshold:
            idx[m] = i
            t_out[m] = t_pred
            m += 1
    return idx[:m].copy(), t_out[:m].copy()


@numba.njit(cache=True, nogil=True, error_model="numpy")
def reverse_rays(
    idx, t_pred, band_face, triangles, origin, direction, point, parent_point, at_infinity, pass_by
):  # pragma: no cover
    """The mutated rays of reverse sampling, in the order of the numpy code's ``[cross]`` masks.

    For each jump ``idx[j]``: the plane through the viewer ray and the parent's point cuts
    the occluder's edges where their ends' signed distances change sign; a point
    ``pass_by`` beyond each cut, away from the hit point, gets a unit direction towards the
    predicted point.  Returns ``(beside, direction, ok_dir)``: (c, 3), (c, 3), (c,) bool.
    """
    k = len(idx)
    beside = np.empty((3 * k, 3))
    out_dir = np.empty((3 * k, 3))
    ok_dir = np.empty(3 * k, np.bool_)
    s = np.empty(3)
    m = 0
    for j in range(k):
        i = idx[j]
        h0, h1, h2 = point[i, 0], point[i, 1], point[i, 2]
        o0, o1, o2 = origin[i, 0], origin[i, 1], origin[i, 2]
        d0, d1, d2 = direction[i, 0], direction[i, 1], direction[i, 2]
        t = t_pred[j]
        q0, q1, q2 = o0 + d0 * t, o1 + d1 * t, o2 + d2 * t  # the predicted point
        if at_infinity:
            a0, a1, a2 = d0, d1, d2
            b0, b1, b2 = parent_point[i, 0] - h0, parent_point[i, 1] - h1, parent_point[i, 2] - h2
        else:
            a0, a1, a2 = h0 - o0, h1 - o1, h2 - o2
            b0, b1, b2 = parent_point[i, 0] - o0, parent_point[i, 1] - o1, parent_point[i, 2] - o2
        # np.cross, then _unit
        p0, p1, p2 = a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0
        g = _guard(norm3(p0, p1, p2))
        p0, p1, p2 = p0 / g, p1 / g, p2 / g
        if not norm3(p0, p1, p2) > 0:
            continue
        f = band_face[i]
        for e in range(3):
            s[e] = einsum_dot3(
                triangles[f, e, 0] - h0, triangles[f, e, 1] - h1, triangles[f, e, 2] - h2, p0, p1, p2
            )
        for e in range(3):
            en = (e + 1) % 3
            if not s[e] * s[en] < 0:
                continue
            frac = s[e] / (s[e] - s[en])
            x0 = triangles[f, e, 0] + (triangles[f, en, 0] - triangles[f, e, 0]) * frac
            x1 = triangles[f, e, 1] + (triangles[f, en, 1] - triangles[f, e, 1]) * frac
            x2 = triangles[f, e, 2] + (triangles[f, en, 2] - triangles[f, e, 2]) * frac
            u0, u1, u2 = x0 - h0, x1 - h1, x2 - h2
            g = _guard(norm3(u0, u1, u2))
            y0, y1, y2 = x0 + u0 / g * pass_by, x1 + u1 / g * pass_by, x2 + u2 / g * pass_by
            beside[m, 0], beside[m, 1], beside[m, 2] = y0, y1, y2
            v0, v1, v2 = q0 - y0, q1 - y1, q2 - y2
            g = _guard(norm3(v0, v1, v2))
            v0, v1, v2 = v0 / g, v1 / g, v2 / g
            out_dir[m, 0], out_dir[m, 1], out_dir[m, 2] = v0, v1, v2
            ok_dir[m] = norm3(v0, v1, v2) > 0
            m += 1
    return beside[:m].copy(), out_dir[:m].copy(), ok_dir[:m].copy()


@numba.njit(cache=True, nogil=True, error_model="numpy")
def hit_rows(origin, direction, face, side, distance):  # pragma: no cover - compiled
    """The rows of the rays that hit (``face >= 0``): face, side, origin, direction, point.

    ``point = origin + direction * distance``, as :func:`meshvis.visibility.sampling.trace`
    computes it.
    """
    n = 0
    for i in range(len(face)):
        if face[i] >= 0:
            n += 1
    out_face = np.empty(n, np.int64)
    out_side = np.empty(n, np.int8)
    out_o = np.empty((n, 3))
    out_d = np.empty((n, 3))
    out_p = np.empty((n, 3))
    m = 0
    for i in range(len(face)):
        if face[i] < 0:
            continue
        out_face[m] = face[i]
        out_side[m] = side[i]
        t = distance[i]
        for c in range(3):
            out_o[m, c] = origin[i, c]
            out_d[m, c] = direction[i, c]
            out_p[m, c] = origin[i, c] + direction[i, c] * t
        m += 1
    return out_face, out_side, out_o, out_d, out_p


@numba.njit(cache=True, nogil=True, error_model="numpy")
def split_segments(owner, a_pt, b_pt, a_f, b_f, min_len):  # pragma: no cover - compiled
    """The band edges to halve and their midpoints (one step of border sampling).

    An edge is halved when its ends saw different faces and it is longer than ``min_len``
    (``np.linalg.norm``); returns the kept rows of ``owner, a_pt, b_pt, a_f, b_f`` and the
    midpoints ``0.5 * (a + b)``.
    """
    n = len(owner)
    keep = np.empty(n, np.bool_)
    m = 0
    for i in range(n):
        keep[i] = (a_f[i] != b_f[i]) and (
            norm3(b_pt[i, 0] - a_pt[i, 0], b_pt[i, 1] - a_pt[i, 1], b_pt[i, 2] - a_pt[i, 2]) > min_len
        )
        if keep[i]:
            m += 1
    o_owner = np.empty(m, owner.dtype)
    o_af = np.empty(m, a_f.dtype)
    o_bf = np.empty(m, b_f.dtype)
    o_a = np.empty((m, 3))
    o_b = np.empty((m, 3))
    mid = np.empty((m, 3))
    j = 0
    for i in range(n):
        if not keep[i]:
            continue
        o_owner[j], o_af[j], o_bf[j] = owner[i], a_f[i], b_f[i]
        for c in range(3):
            o_a[j, c] = a_pt[i, c]
            o_b[j, c] = b_pt[i, c]
            mid[j, c] = 0.5 * (a_pt[i, c] + b_pt[i, c])
        j += 1
    return o_owner, o_a, o_b, o_af, o_bf, mid
