"""The ray backend: hit side, distances, offsets, occlusion, and invariance under extreme
translations and scales (the scene is built on a centred unit-size float32 copy)."""

import numpy as np
import pytest
import trimesh

from meshvis.rays.caster import CHUNK, RayCaster
from meshvis.rays.samples import uniform_sphere
from meshvis.soup import Soup


def sphere_soup():
    m = trimesh.creation.icosphere(3)
    return Soup(m.vertices, m.faces)


def test_hit_side_front_from_outside_back_from_inside():
    rc = RayCaster(sphere_soup())
    d = uniform_sphere(2000, np.random.default_rng(0))
    outside = rc.intersect(-3 * d, d)
    inside = rc.intersect(np.zeros_like(d), d)
    assert (outside.side == 0).all() and (inside.side == 1).all()
    assert np.allclose(outside.distance, 2.0, atol=2e-2)  # the icosphere is inscribed in r=1
    assert np.allclose(inside.distance, 1.0, atol=2e-2)


def test_miss_and_max_distance():
    rc = RayCaster(trimesh.creation.box())
    h = rc.intersect(np.array([[0, 0, 5.0], [0, 0, 5.0]]), np.array([[0, 0, 1.0], [0, 0, -1.0]]))
    assert h.face[0] == -1 and h.side[0] == -1 and np.isinf(h.distance[0])
    assert h.face[1] >= 0 and h.side[1] == 0
    short = rc.intersect(np.array([[0, 0, 5.0]]), np.array([[0, 0, -1.0]]), max_distance=4.0)
    assert short.face[0] == -1


def test_exact_distance_is_float64_accurate():
    rc = RayCaster(trimesh.creation.box())
    h = rc.intersect(np.array([[0.1, 0.2, 7.0]]), np.array([[0, 0, -1.0]]), exact_distance=True)
    assert h.distance[0] == pytest.approx(6.5, abs=1e-12)


def test_barycentric_coordinates_reproduce_hit_point():
    s = sphere_soup()
    rc = RayCaster(s)
    d = uniform_sphere(500, np.random.default_rng(1))
    h = rc.intersect(np.zeros_like(d), d)
    t = s.triangles[h.face]
    u, v = h.bary[:, 0:1], h.bary[:, 1:2]
    p = (1 - u - v) * t[:, 0] + u * t[:, 1] + v * t[:, 2]
    assert np.allclose(p, h.points(np.zeros_like(d), d), atol=1e-5)


def test_origin_on_surface_needs_push_off():
    """An origin exactly on a face must not report its own face once pushed off."""
    s = sphere_soup()
    rc = RayCaster(s)
    rng = np.random.default_rng(2)
    face = rng.integers(0, s.n_faces, 5000)
    pts = s.triangles[face].mean(axis=1)
    outward = s.normals[face]
    h = rc.intersect_from_surface(pts, face, np.zeros(len(face), np.int8), outward)
    assert (h.face == -1).all()  # leaving a convex surface outward escapes
    inward = rc.intersect_from_surface(pts, face, np.ones(len(face), np.int8), -outward)
    assert (inward.face != face).all() and (inward.side == 1).all()


def test_occluded_segments():
    rc = RayCaster(trimesh.creation.box())
    a = np.array([[0, 0, 5.0], [0, 0, 5.0], [0, 0, 0.0]])
    b = np.array([[0, 0, -5.0], [0, 0, 0.6], [0, 0, 0.49]])
    assert rc.occluded(a, b).tolist() == [True, False, False]
    # a target lying exactly on the surface does not occlude itself
    assert not rc.occluded(np.array([[0, 0, 5.0]]), np.array([[0, 0, 0.5]]))[0]


@pytest.mark.parametrize(
    "scale,shift", [(1.0, 0.0), (1e-6, 0.0), (1e6, 0.0), (1.0, 1e6), (1e-6, 1e6), (1e6, 1e6)]
)
def test_same_results_under_translation_and_scale(scale, shift):
    """Translation by 1e6 x size and scales 1e-6 / 1e6 give the same faces, sides and
    relative distances as the untouched model."""
    s = sphere_soup()
    rng = np.random.default_rng(3)
    d = uniform_sphere(20000, rng)
    o = rng.uniform(-0.5, 0.5, (20000, 3))
    base = RayCaster(s).intersect(o, d)
    size = s.diagonal * scale  # translate by shift x the moved model's own size
    offset = np.array([shift * size, -shift * size, shift * size])
    moved = Soup(s.vertices * scale + offset, s.faces)
    h = RayCaster(moved).intersect(o * scale + offset, d)
    agree = (h.face == base.face).mean()
    assert agree >= 0.9995  # a few rays may graze an edge and pick the neighbour
    assert (h.side == base.side).mean() >= 0.9995
    both = (h.face >= 0) & (base.face >= 0)
    assert np.allclose(h.distance[both] / scale, base.distance[both], rtol=1e-4, atol=1e-5)


@pytest.mark.slow
def test_threads_give_identical_hits():
    s = sphere_soup()
    rng = np.random.default_rng(4)
    d = uniform_sphere(300_000, rng)
    o = rng.uniform(-0.5, 0.5, (300_000, 3))
    one, two = RayCaster(s, threads=1), RayCaster(s, threads=2)
    a, b = one.intersect(o, d), two.intersect(o, d)
    assert np.array_equal(a.face, b.face) and np.array_equal(a.side, b.side)
    assert np.array_equal(a.distance, b.distance) and np.array_equal(a.bary, b.bary)
    assert np.array_equal(one.occluded(o, o + d), two.occluded(o, o + d))
    # the smallest batch that is split: two chunks and a few rays more
    n = 2 * CHUNK + 7
    a, b = one.intersect(o[:n], d[:n]), two.intersect(o[:n], d[:n])
    assert np.array_equal(a.face, b.face) and np.array_equal(a.distance, b.distance)


def test_part_ids():
    a = trimesh.creation.box()
    b = trimesh.creation.box()
    b.apply_translation([5, 0, 0])
    s = Soup(
        np.vstack([a.vertices, b.vertices]),
        np.vstack([a.faces, b.faces + 8]),
        part_id=np.r_[np.zeros(12, int), np.ones(12, int)],
        part_names=["a", "b"],
    )
    rc = RayCaster(s)
    h = rc.intersect(np.array([[0, 0, 5.0], [5, 0, 5.0], [20, 0, 5.0]]), np.array([[0, 0, -1.0]] * 3))
    assert rc.part_of(h.face).tolist() == [0, 1, -1]


def test_scene_on_distinct_vertices_gives_the_hits_of_the_full_buffer():
    import embreex.mesh_construction as mc
    import embreex.rtcore_scene as rs

    m = trimesh.creation.icosphere(3)
    corners = m.vertices[m.faces].reshape(-1, 3)  # every face its own corners
    corners[np.isclose(corners, 0)] *= -1.0  # and some zeros negative
    v = np.vstack([corners, [[np.nan, 0, 0], [1e30, 1e30, 1e30]]])  # unused vertices
    s = Soup(v, np.arange(len(corners)).reshape(-1, 3))
    rc = RayCaster(s)
    # the scene of the whole vertex buffer, as float32 of the same normalised copy
    v32 = ((s.vertices - rc.center) * rc.scale).astype(np.float32)
    v32[~np.isfinite(v32).all(axis=1)] = 0
    full = rs.EmbreeScene()
    mc.TriangleMesh(full, v32, s.faces.astype(np.int32))
    rng = np.random.default_rng(5)
    d = uniform_sphere(20_000, rng).astype(np.float32)
    o = rng.uniform(-0.6, 0.6, (20_000, 3)).astype(np.float32)
    a, b = rc._scene.run(o, d, output=1), full.run(o, d, output=1)
    for key in ("primID", "tfar", "u", "v", "Ng"):
        assert np.array_equal(a[key], b[key])
    assert len(rc.vertex_groups.first) < len(corners)
