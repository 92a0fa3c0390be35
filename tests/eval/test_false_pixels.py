"""False pixels (GVS §4.2-4.3): what a viewer sees of a deletion."""

from __future__ import annotations

import numpy as np
import trimesh

from meshvis.eval.false_pixels import face_pixels, false_pixels, fibonacci_sphere, seen_faces


def _nested():
    a, b = trimesh.creation.box(), trimesh.creation.box(extents=(0.5, 0.5, 0.5))
    return np.vstack([a.vertices, b.vertices]), np.vstack([a.faces, b.faces + 8])


def test_fibonacci_sphere_is_even_and_unit():
    d = fibonacci_sphere(128)
    np.testing.assert_allclose(np.linalg.norm(d, axis=1), 1.0)
    assert abs(d.mean(axis=0)).max() < 0.02
    assert (d[:, 2] > 0).sum() == 64


def test_deleting_hidden_geometry_costs_no_pixels_and_visible_geometry_does():
    table = face_pixels(_nested(), size=64, views=32)
    removed = np.zeros(24, bool)
    removed[12:] = True  # the inner box
    assert false_pixels(table, removed)["mean"] == 0.0
    assert not seen_faces(table)[12:].any() and seen_faces(table)[:12].all()
    removed[0] = True
    fp = false_pixels(table, removed)
    # one outer triangle's pixels over all model pixels, per million, exactly
    mine = table.face == 0
    per_view = np.zeros(32)
    np.add.at(per_view, table.view[mine], table.pixels[mine])
    expected = per_view / table.model_pixels * 1e6
    assert np.isclose(fp["mean"], expected.mean()) and np.isclose(fp["worst"], expected.max())
    assert fp["worst"] >= fp["mean"] > 0


def test_upper_views_only_look_from_above():
    v, f = _nested()
    table = face_pixels((v, f), size=32, views=32)
    bottom = np.flatnonzero(trimesh.Trimesh(v[:8], f[:12], process=False).face_normals[:, 2] < -0.9)
    removed = np.zeros(24, bool)
    removed[bottom] = True
    assert false_pixels(table, removed)["mean"] > 0
    up = false_pixels(table, removed, up=(0, 0, 1))
    assert up["mean"] == 0.0 and up["views"] == 16


def test_the_pixel_table_is_cached(tmp_path):
    cache = tmp_path / "px.npz"
    a = face_pixels(_nested(), size=32, views=8, cache=cache)
    b = face_pixels(_nested(), size=32, views=8, cache=cache)
    assert cache.is_file()
    np.testing.assert_array_equal(a.pixels, b.pixels)
    np.testing.assert_array_equal(a.model_pixels, b.model_pixels)
