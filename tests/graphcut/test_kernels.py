"""The compiled kernels of the graph cut give the bits of the numpy code they replace."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import scipy.sparse as sp

from meshvis.graphcut import _kernels
from meshvis.graphcut.nodes import PERPENDICULAR_COS, _pushed_origins, build_nodes, node_rays, side_normals
from meshvis.graphcut.preprocess import preprocess
from meshvis.graphcut.weights import edge_weights
from meshvis.io import load
from meshvis.rays.samples import cosine_about_faces, pushed_points_in_faces, sample_scheme_barycentric

MODELS = Path(__file__).resolve().parents[2] / "models"


def _numpy_pushed_origins(
    pos, point_face, side, triangles, normals, flagged_index, pairs, point_start, offset, proximity
):
    """The numpy expression that :func:`meshvis.graphcut._kernels.pushed_origins` replaced
    (with each flagged face's sample points at ``point_start[q] .. point_start[q + 1] - 1``)."""
    n_s = side_normals(normals[point_face], np.full(len(point_face), side))
    origin = pos + offset * n_s
    both = np.concatenate([pairs, pairs[:, ::-1]])
    both = both[flagged_index[both[:, 0]] >= 0]
    f, g = both[:, 0], both[:, 1]
    count = np.diff(point_start)[flagged_index[f]]
    first = np.repeat(point_start[flagged_index[f]], count)
    pt = first + np.arange(count.sum()) - np.repeat(np.cumsum(count) - count, count)
    g = np.repeat(g, count)
    p = pos[pt]
    ng = normals[g]
    d = np.einsum("ij,ij->i", ng, p - triangles[g, 0])
    near = np.abs(d) < proximity
    pt, g, p, ng, d = pt[near], g[near], p[near], ng[near], d[near]
    q, tri = p - d[:, None] * ng, triangles[g]
    a, b, c = tri[:, 0], tri[:, 1], tri[:, 2]
    v0, v1, v2 = b - a, c - a, q - a
    d00, d01 = np.einsum("ij,ij->i", v0, v0), np.einsum("ij,ij->i", v0, v1)
    d11, d20, d21 = (
        np.einsum("ij,ij->i", v1, v1),
        np.einsum("ij,ij->i", v2, v0),
        np.einsum("ij,ij->i", v2, v1),
    )
    den = d00 * d11 - d01 * d01
    ok = den > 0
    den = np.where(ok, den, 1.0)
    v = (d11 * d20 - d01 * d21) / den
    w = (d00 * d21 - d01 * d20) / den
    u = 1 - v - w
    scale = np.sqrt(np.maximum(d00, d11))
    t = proximity / np.where(scale > 0, scale, 1.0)
    inside = ok & (u >= -t) & (v >= -t) & (w >= -t)
    pt, ng, d = pt[inside], ng[inside], d[inside]
    cos = np.einsum("ij,ij->i", ng, n_s[pt])
    orient = np.sign(cos)
    square = np.abs(cos) < PERPENDICULAR_COS
    orient[square] = np.sign(d[square])
    moved = orient != 0
    pt, ng, d, orient = pt[moved], ng[moved], d[moved], orient[moved]
    move = offset - orient * d
    order = np.lexsort((move, pt))
    last = np.r_[pt[order][1:] != pt[order][:-1], True]
    sel = order[last]
    origin[pt[sel]] = pos[pt[sel]] + (orient[sel] * move[sel])[:, None] * ng[sel] + offset * n_s[pt[sel]]
    return origin


@pytest.fixture
def crossings():
    """Flagged faces, each with partners through, along and across its sample points."""
    rng = np.random.default_rng(3)
    m, samples, proximity, offset = 600, 4, 1e-3, 1e-4
    tri = rng.normal(size=(m, 3, 3)) * np.exp(rng.normal(size=(m, 1, 1)))
    bary = sample_scheme_barycentric(samples, 2)
    flagged = np.flatnonzero(rng.random(m) < 0.5)
    pairs = []
    for f in flagged[: len(flagged) // 2]:  # partners built on f's own sample points
        pts = bary @ tri[f]
        normal = np.cross(tri[f, 1] - tri[f, 0], tri[f, 2] - tri[f, 0])
        normal /= np.linalg.norm(normal)
        for kind in range(3):
            g = rng.integers(0, m)
            centre = pts[rng.integers(0, samples)]
            if kind == 0:  # nearly coplanar, just off the plane
                tri[g] = centre + (tri[f] - tri[f].mean(0)) * 2 + normal * rng.normal() * proximity * 0.5
            elif kind == 1:  # at right angles, through the point
                side = np.cross(normal, tri[f, 1] - tri[f, 0])
                tri[g] = centre + np.array([side, -side, normal]) * rng.random()
            pairs.append((f, g))
    pairs += [tuple(rng.integers(0, m, 2)) for _ in range(300)]
    pairs = np.array(pairs, np.int64)
    normals = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    normals /= np.linalg.norm(normals, axis=1, keepdims=True)
    flagged = np.union1d(flagged, np.unique(pairs))[::2]  # some partners are not flagged themselves
    flagged_index = np.full(m, -1, np.int64)
    flagged_index[flagged] = np.arange(len(flagged))
    # every face its own number of points (the first ``c`` of the pattern)
    count = rng.integers(1, samples + 1, len(flagged))
    point_start = np.concatenate([[0], np.cumsum(count)])
    pos = np.concatenate([bary[:c] @ tri[f] for f, c in zip(flagged, count)])
    point_face = np.repeat(flagged, count)
    return pos, point_face, tri, normals, flagged_index, pairs, point_start, offset, proximity


@pytest.mark.parametrize("side", [0, 1])
def test_pushed_origins_are_the_numpy_expression(crossings, side):
    pos, point_face, tri, normals, flagged_index, pairs, point_start, offset, proximity = crossings
    args = (pos, point_face, side, tri, normals, flagged_index, pairs, point_start, offset, proximity)
    expected = _numpy_pushed_origins(*args)
    got = _pushed_origins(*args)
    moved = np.any(
        expected != pos + offset * side_normals(normals[point_face], np.full(len(pos), side)), axis=1
    )
    assert moved.sum() > 50  # the fixture does exercise the partner moves
    assert got.dtype == expected.dtype and got.tobytes() == expected.tobytes()


def test_pushed_origins_without_partners(crossings):
    pos, point_face, tri, normals, flagged_index, _, point_start, offset, proximity = crossings
    none = np.zeros((0, 2), np.int64)
    got = _pushed_origins(
        pos, point_face, 1, tri, normals, flagged_index, none, point_start, offset, proximity
    )
    assert np.array_equal(got, pos - offset * normals[point_face])


def _numpy_edge_weights(hits, counted, area, is_point):
    """The numpy expression of Eq. 5 that :func:`meshvis.graphcut._kernels.merged_edge_weights` replaced."""
    h = sp.csr_matrix(hits)
    h.sum_duplicates()
    n = len(area)
    r = np.repeat(np.arange(n, dtype=np.int64), np.diff(h.indptr))
    c, n_ij = h.indices.astype(np.int64), h.data
    off = r != c
    r, c, n_ij = r[off], c[off], n_ij[off]
    t = area[r] * n_ij / np.maximum(counted[r], 1)
    t[counted[r] <= 0] = 0.0
    mixed = is_point[r] != is_point[c]
    t *= np.where(mixed, np.where(is_point[r], 0.0, 1.0), 0.5)
    key = np.minimum(r, c) * np.int64(n) + np.maximum(r, c)
    order = np.argsort(key, kind="stable")
    key, t = key[order], t[order]
    new = np.ones(len(key), bool)
    new[1:] = key[1:] != key[:-1]
    starts = np.flatnonzero(new)
    w = np.add.reduceat(t, starts) if len(t) else t
    key = key[starts]
    keep = w > 0
    return key[keep] // n, key[keep] % n, w[keep]


@pytest.mark.parametrize("n", [0, 1, 7, 3000])
def test_edge_weights_are_the_numpy_expression(n):
    rng = np.random.default_rng(n)
    k = 12 * n
    r, c = rng.integers(0, max(n, 1), k), rng.integers(0, max(n, 1), k)
    r, c = np.concatenate([r, c[: k // 2]]), np.concatenate([c, r[: k // 2]])  # many (j, i) twins
    hits = sp.coo_matrix((rng.integers(1, 9, len(r)).astype(float), (r, c)), shape=(n, n)).tocsr()
    counted = rng.integers(-1, 40, n)  # some nodes with no counted rays
    area = rng.random(n) * np.exp(rng.normal(size=n) * 4)
    is_point = rng.random(n) < 0.6
    expected = _numpy_edge_weights(hits, counted, area, is_point)
    got = edge_weights(hits, counted, area, is_point)
    if n > 100:
        assert len(expected[0]) > n and np.sum(expected[2] > 0) > n  # the case has merged edges
    for a, b in zip(got, expected):
        assert a.dtype == b.dtype and a.tobytes() == b.tobytes()


def test_edge_maxima_are_maximum_at():
    rng = np.random.default_rng(5)
    n, k = 500, 4000
    i, j, w = rng.integers(0, n, k), rng.integers(0, n, k), rng.random(k)
    w[::97] = np.nan
    start = rng.random(n) * 0.5
    expected = start.copy()
    with np.errstate(invalid="ignore"):
        np.maximum.at(expected, i, w)
        np.maximum.at(expected, j, w)
    got = _kernels.edge_maxima(start.copy(), i, j, w)
    assert got.tobytes() == expected.tobytes()


def _numpy_node_rays(nodes, normals, triangles, counts, rng, offset):
    """The numpy layout of :func:`meshvis.graphcut.nodes.node_rays` before :func:`_kernels.ray_starts`."""
    source = np.repeat(np.arange(nodes.n, dtype=np.int64), counts)
    origins = np.empty((len(source), 3))
    face = np.empty(len(source), np.int64)
    side = np.empty(len(source), np.int8)
    rows_c = np.flatnonzero(source < nodes.n_cluster)
    if len(rows_c):
        src_c = source[rows_c]
        start = nodes.node_start[src_c]
        base = np.where(start > 0, nodes.entry_cumarea[np.maximum(start - 1, 0)], 0.0)
        target = base + rng.random(len(src_c)) * nodes.area[src_c]
        idx = np.searchsorted(nodes.entry_cumarea, target, side="right")
        idx = np.clip(idx, start, nodes.node_start[src_c + 1] - 1)
        f, s = nodes.entry_face[idx], nodes.entry_side[idx]
        origins[rows_c] = pushed_points_in_faces(triangles, normals, f, s, offset, rng)
        face[rows_c], side[rows_c] = f, s
    pn = source >= nodes.n_cluster
    k = source[pn] - nodes.n_cluster
    origins[pn] = nodes.point_origin[k // 2, k % 2]
    face[pn], side[pn] = nodes.point_face[k // 2], k % 2
    t1, t2 = nodes.tangents
    return source, origins, cosine_about_faces(normals, (t1, t2), face, side, rng)


@pytest.mark.parametrize("model", ["overlapping_solids.obj", "assembly.obj"])
def test_node_rays_are_the_numpy_layout(model):
    soup = load(MODELS / model)
    pre = preprocess(soup)
    offset = 1e-4 * soup.diagonal
    nodes = build_nodes(
        soup.triangles, soup.normals, soup.areas, pre.clustering, pre.flagged, pre.partner_pairs,
        offset=offset, proximity=2 * offset,
    )  # fmt: skip
    assert nodes.n_points and nodes.n_cluster  # both kinds of node cast rays
    counts = np.random.default_rng(1).integers(0, 6, nodes.n)
    got = node_rays(nodes, soup.normals, soup.triangles, counts, np.random.default_rng(2), offset)
    expected = _numpy_node_rays(nodes, soup.normals, soup.triangles, counts, np.random.default_rng(2), offset)
    for a, b in zip(got, expected):
        assert a.dtype == b.dtype and a.tobytes() == b.tobytes()


def test_hit_split_and_keep_are_the_numpy_steps():
    rng = np.random.default_rng(9)
    n_faces, n_cluster, n, rays = 50, 30, 200, 5000
    side_node = rng.integers(0, n_cluster, (n_faces, 2))
    side_node[rng.random(n_faces) < 0.3] = -1  # flagged faces
    face = np.where(rng.random(rays) < 0.2, -1, rng.integers(0, n_faces, rays))
    side = np.where(face < 0, -1, rng.integers(0, 2, rays)).astype(np.int8)
    src = rng.integers(0, n, rays)
    escaped, discarded = np.zeros(n, np.int64), np.zeros(n, np.int64)
    f, s, sr, dst, flagged_at, ray_at = _kernels.split_hits(face, side, src, side_node, escaped)
    hit = face >= 0
    assert np.array_equal(escaped, np.bincount(src[~hit], minlength=n))
    assert np.array_equal(f, face[hit]) and np.array_equal(s, side[hit]) and np.array_equal(sr, src[hit])
    expected_dst = side_node[face[hit], side[hit]]
    idx = np.flatnonzero(expected_dst < 0)
    assert np.array_equal(dst, expected_dst) and np.array_equal(flagged_at, idx)
    assert np.array_equal(ray_at, np.flatnonzero(hit)[idx])
    point, blocked = rng.integers(0, 40, len(idx)), rng.random(len(idx)) < 0.4
    rows, cols = _kernels.kept_hits(sr, s, dst, flagged_at, point, blocked, n_cluster, discarded)
    expected_dst[idx] = n_cluster + 2 * point + s[idx]
    keep = np.ones(len(sr), bool)
    keep[idx[blocked]] = False
    assert np.array_equal(discarded, np.bincount(sr[~keep], minlength=n))
    assert np.array_equal(rows, sr[keep]) and np.array_equal(cols, expected_dst[keep])
