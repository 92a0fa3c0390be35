"""``meshvis bench conservative`` end to end on a small generated scene."""

from __future__ import annotations

import json

import numpy as np
import pytest

import meshvis
from meshvis.cli.main import main
from meshvis.eval.bench import conservative as bench


def scene() -> meshvis.Soup:
    """A box with a smaller box inside it, and a slab beside them."""
    import trimesh

    parts = [
        trimesh.creation.box((2, 2, 2)),
        trimesh.creation.box((0.5, 0.5, 0.5)),
        trimesh.creation.box((0.2, 3, 1), transform=trimesh.transformations.translation_matrix((2, 0, 0))),
    ]
    return meshvis.as_soup(trimesh.util.concatenate(parts))


@pytest.mark.slow
def test_bench_conservative_reports_no_miss_and_caches_its_reference(tmp_path, capsys):
    soup = scene()
    path = tmp_path / "slot.ply"
    meshvis.save(soup, str(path))
    out = tmp_path / "r.json"
    argv = [
        "bench",
        "conservative",
        str(path),
        "--rays",
        "20000",
        "--max-level",
        "7",
        "--cache",
        str(tmp_path),
    ]
    assert main([*argv, "--json", str(out)]) == 0
    rows = json.loads(out.read_text())["rows"]
    assert [r["kind"] for r in rows] == ["inside"] * bench.INSIDE + ["outside"] * bench.OUTSIDE
    for r in rows:
        assert r["missed_faces"] == 0 and r["missed_sides"] == 0
        assert (
            r["conservative_faces"] >= r["seen_faces"] > 0 and r["area_ratio"] >= r["area_ratio_aimed"] >= 1
        )
    cached = sorted(tmp_path.glob("conservative-ref-*.npz"))
    assert len(cached) == len(rows)
    # a second run reads the references back: the same numbers
    assert main([*argv, "--json", str(out)]) == 0
    again = json.loads(out.read_text())["rows"]
    assert [r["seen_faces"] for r in again] == [r["seen_faces"] for r in rows]
    for r in again:
        assert 0 <= r["excess_at_limit"] <= 1 and 0 <= r["excess_several_parts"] <= 1 and r["cpu_seconds"] > 0
    # one row per viewpoint, then the scene's: mean ratios, summed frusta and times
    assert [line.split()[1] for line in capsys.readouterr().out.splitlines()[-2:]] == ["outside", "all"]


def test_the_viewpoints_are_inside_the_box_and_around_the_scene():
    from meshvis.rays.caster import RayCaster

    soup = scene()
    points = bench.viewpoints_of(soup, RayCaster(soup), seed=0)
    lo, hi = soup.bounds
    inside = np.array([p for k, p in points if k == "inside"])
    outside = np.array([p for k, p in points if k == "outside"])
    assert ((inside >= lo) & (inside <= hi)).all()
    radius = np.linalg.norm(outside - 0.5 * (lo + hi), axis=1)
    np.testing.assert_allclose(radius, bench.OUTSIDE_RADIUS * 0.5 * soup.diagonal)


def test_rays_are_not_aimed_at_faces_whose_corners_lie_on_one_line():
    from meshvis.geometry.adjacency import components, edges, face_adjacency
    from meshvis.visibility.conservative import FrustumScene

    soup = scene()
    flat = np.array([[0.0, 0.0, 5.0], [1.0, 0.0, 5.0], [2.0, 0.0, 5.0]])  # a line above the scene
    soup = meshvis.Soup(
        np.r_[soup.vertices, flat], np.r_[soup.faces, [[len(soup.vertices) + k for k in range(3)]]]
    )
    fs = FrustumScene.build(soup)
    part = components(soup.n_faces, face_adjacency(edges(fs.welded), manifold_only=False))[1]
    point = np.array([0.0, 0.0, 10.0])
    last = soup.n_faces - 1
    seen, parts = bench.aimed_seen(fs, point, np.array([0, last]), 16, np.random.default_rng(0), part)
    assert parts[1] == 0 and not seen[last].any()
    # the same rays twice: the same answer
    again = bench.aimed_seen(fs, point, np.array([0, last]), 16, np.random.default_rng(0), part)
    assert (again[0] == seen).all() and (again[1] == parts).all()
