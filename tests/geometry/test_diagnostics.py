"""Adjacency analysis (welding, edges, components, degenerate and duplicate faces),
``diagnose`` and ``meshvis info``."""

from __future__ import annotations

import json

import numpy as np
import pytest
import trimesh

from meshvis.errors import ModelError
from meshvis.geometry import adjacency
from meshvis.geometry.diagnostics import diagnose, format_report
from meshvis.soup import Soup


def cube_soup(offset=(0.0, 0.0, 0.0)) -> tuple[np.ndarray, np.ndarray]:
    """A closed, consistently wound unit cube as an unwelded soup (3 vertices per face)."""
    box = trimesh.creation.box()
    v = box.vertices[box.faces].reshape(-1, 3) + np.asarray(offset)
    return v, np.arange(len(v)).reshape(-1, 3)


# --------------------------------------------------------------------------- welding
def test_weld_merges_within_tolerance_only():
    v = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [1e-9, 0, 0], [1e-5, 0, 0], [-0.0, 1, 0], [9, 9, 9]])
    f = np.array([[0, 1, 2], [3, 1, 5], [4, 1, 2]])
    index, fw = adjacency.weld(v, f)  # tolerance 1e-7 * diag ~ 1.4e-7
    assert index[0] == index[3]  # 1e-9 apart
    assert index[0] != index[4]  # 1e-5 apart
    assert index[2] == index[5]  # -0.0 and 0.0
    assert index[6] == -1  # unused
    assert np.array_equal(fw, index[f])
    assert fw.max() + 1 == 4
    # exact duplicates only
    index0, _ = adjacency.weld(v, f, tol=0.0)
    assert index0[0] != index0[3] and index0[2] == index0[5]


def test_vertex_groups_are_bit_identical_rows():
    v = np.array([[0, 0, 0], [1, 0, 0], [-0.0, 0, 0], [1, 0, 0], [5, 5, 5], [0, 0, 0]])
    f = np.array([[0, 1, 2], [3, 5, 1]])
    g = adjacency.group_vertices(v, f)
    assert g.used.tolist() == [0, 1, 2, 3, 5]  # vertex 4 unused
    assert g.group.tolist() == [0, 1, 2, 1, 0]  # -0.0 is other bits than 0.0
    assert g.first.tolist() == [0, 1, 2]
    assert g.corner_groups(f, len(v)).tolist() == [[0, 1, 2], [1, 0, 1]]


def test_weld_on_given_groups_is_weld_of_unique_points():
    rng = np.random.default_rng(3)
    pool = rng.integers(-2, 3, (40, 3)).astype(float) * 0.5
    pool[rng.random(pool.shape) < 0.2] *= -1  # zeros of both signs
    v = pool[rng.integers(0, 40, 300)]
    f = rng.permutation(300)[:297].reshape(-1, 3)
    groups = adjacency.group_vertices(v, f)
    index, fw = adjacency.weld(v, f, tol=0.0, vertex_groups=groups)
    # the reference: np.unique of the used points with -0.0 made 0.0
    used = np.unique(f)
    _, inverse = np.unique(v[used] + 0.0, axis=0, return_inverse=True)
    assert np.array_equal(index[used], inverse.ravel())
    assert np.array_equal(adjacency.weld(v, f, tol=0.0)[1], fw)


def test_weld_is_scale_invariant():
    v, f = cube_soup()
    v = v + np.random.default_rng(0).normal(scale=1e-9, size=v.shape)  # float noise
    for scale in (1e-6, 1.0, 1e6):
        _, fw = adjacency.weld(v * scale, f)
        assert fw.max() + 1 == 8


# --------------------------------------------------------------------------- edges
def test_closed_cube_edges():
    v, f = cube_soup()
    _, fw = adjacency.weld(v, f)
    t = adjacency.edges(fw)
    assert len(t.count) == 18
    assert t.manifold.all()
    assert t.consistent.all()
    assert (t.face_edge >= 0).all()
    # every edge's end points match the face sides that use it
    ends = np.sort(np.stack([fw, np.roll(fw, -1, axis=1)], axis=2), axis=2)
    assert np.array_equal(t.vertices[t.face_edge], ends)


@pytest.mark.parametrize("case, boundary", [("one", 3), ("adjacent", 4), ("apart", 6)])
def test_boundary_edges_after_deleting_faces(case, boundary):
    box = trimesh.creation.box()
    sides = [set(map(frozenset, _sides(face))) for face in box.faces]
    adjacent = next(k for k in range(1, 12) if sides[0] & sides[k])
    apart = next(k for k in range(1, 12) if not sides[0] & sides[k])
    removed = {"one": [0], "adjacent": [0, adjacent], "apart": [0, apart]}[case]
    v, f = cube_soup()
    keep = np.setdiff1d(np.arange(12), removed)
    d = diagnose((v, f[keep]))
    assert d["boundary_edges"] == boundary
    assert d["closed"] is False
    assert d["nonmanifold_edges"] == 0
    assert d["winding_consistent"] is True


def _sides(face):
    return [(face[i], face[(i + 1) % 3]) for i in range(3)]


def test_nonmanifold_edge():
    v = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1]], float)
    f = np.array([[0, 1, 2], [1, 0, 3], [0, 1, 4]])  # three faces on edge 0-1
    t = adjacency.edges(adjacency.weld(v, f)[1])
    assert t.nonmanifold.sum() == 1
    assert t.boundary.sum() == 6
    d = diagnose((v, f))
    assert d["nonmanifold_edges"] == 1 and d["edge_manifold"] is False
    assert d["components"] == 1


def test_flipped_face_breaks_winding():
    v, f = cube_soup()
    f = f.copy()
    f[5] = f[5, [0, 2, 1]]
    d = diagnose((v, f))
    assert d["winding_consistent"] is False
    assert d["inconsistent_edges"] == 3  # the three sides of the flipped face
    assert d["closed"] is True
    t = adjacency.edges(adjacency.weld(v, f)[1])
    assert np.array_equal(np.flatnonzero(~t.consistent), np.sort(t.face_edge[5]))


def test_duplicates_either_winding():
    v, f = cube_soup()
    f = np.concatenate([f, f[[0]], f[[3]][:, [0, 2, 1]], f[[0]]])  # 3 redundant copies
    first = adjacency.duplicate_faces(adjacency.weld(v, f)[1])
    assert first[:12].tolist() == list(range(12))
    assert first[12:].tolist() == [0, 3, 0]
    d = diagnose((v, f))
    assert d["duplicate_faces"] == 3
    assert d["coplanar_faces"] == 5  # faces 0 and 3 and their three copies overlap
    assert d["intersecting_faces"] == 0


def test_degenerate_faces():
    v = np.array(
        [[0, 0, 0], [1, 0, 0], [0, 1, 0], [2, 0, 0], [0.5, 1e-10, 0], [0.5, 1e-3, 0], [3, 3, 3]], float
    )
    f = np.array(
        [
            [0, 1, 2],  # fine
            [0, 1, 3],  # collinear
            [0, 0, 2],  # repeated corner
            [0, 1, 4],  # needle: altitude 1e-10 << 1e-7 * diag
            [0, 1, 5],  # thin but real: altitude 1e-3
            [1, 2, 6],  # fixes the diagonal
        ]
    )
    deg = adjacency.degenerate_faces(v, f)
    assert deg.tolist() == [False, True, True, True, False, False]
    assert diagnose((v, f))["degenerate_faces"] == 3
    # scale invariant
    assert np.array_equal(adjacency.degenerate_faces(v * 1e-6 + 1e3 * 1e-6, f), deg)


def test_components_and_adjacency():
    a, fa = cube_soup()
    b, fb = cube_soup((3, 0, 0))
    tri = np.array([[10, 0, 0], [11, 0, 0], [10, 1, 0]], float)
    v = np.concatenate([a, b, tri])
    f = np.concatenate([fa, fb + len(a), [[len(a) + len(b), len(a) + len(b) + 1, len(a) + len(b) + 2]]])
    _, fw = adjacency.weld(v, f)
    t = adjacency.edges(fw)
    pairs = adjacency.face_adjacency(t)
    assert len(pairs) == 36  # 18 manifold edges per cube
    assert (pairs[:, 0] < pairs[:, 1]).all()
    n, label = adjacency.components(len(f), pairs)
    assert n == 3
    assert len(set(label[:12])) == 1 and len(set(label[12:24])) == 1 and label[0] != label[12]
    d = diagnose((v, f))
    assert d["components"] == 3 and d["faces"] == 25 and d["boundary_edges"] == 3


# --------------------------------------------------------------------------- diagnose
def test_diagnose_clean_cube_report():
    v, f = cube_soup()
    d = diagnose(Soup(v, f, path="cube.obj"))
    assert d["faces"] == 12 and d["vertices"] == 36 and d["welded_vertices"] == 8
    assert d["closed"] and d["edge_manifold"] and d["winding_consistent"]
    for key in (
        "boundary_edges",
        "nonmanifold_edges",
        "degenerate_faces",
        "duplicate_faces",
        "intersecting_faces",
        "coplanar_faces",
        "too_close_faces",
        "inconsistent_edges",
    ):
        assert d[key] == 0, key
    assert np.allclose(d["bounds"], [[-0.5] * 3, [0.5] * 3])
    assert d["diagonal"] == pytest.approx(np.sqrt(3))
    assert d["area"] == pytest.approx(6.0)
    assert {"weld", "edges", "intersections"} <= set(d["seconds"])
    json.dumps(d)  # plain values only
    text = format_report(d)
    assert text.splitlines()[0] == "cube.obj"
    assert "boundary edges" in text and "yes" in text


def test_diagnose_intersecting_cubes():
    a, fa = cube_soup()
    b, fb = cube_soup((0.5, 0.5, 0.5))  # overlaps a: their surfaces cross
    d = diagnose((np.concatenate([a, b]), np.concatenate([fa, fb + len(a)])))
    assert d["components"] == 2 and d["closed"]
    assert d["intersecting_faces"] > 0
    skipped = diagnose((np.concatenate([a, b]), np.concatenate([fa, fb + len(a)])), intersections=False)
    assert skipped["intersecting_faces"] is None and "intersections" not in skipped["seconds"]
    assert "-" in format_report(skipped)


def test_diagnose_rejects_bad_input():
    v, f = cube_soup()
    v[0] = np.nan
    with pytest.raises(ModelError):
        diagnose((v, f))


# --------------------------------------------------------------------------- command line
def test_cli_info_json(tmp_path, capsys):
    from meshvis.cli.main import main

    path = tmp_path / "box.obj"
    box = trimesh.creation.box()
    box.export(path)
    assert main(["info", str(path), "--json"]) == 0
    d = json.loads(capsys.readouterr().out)
    assert d["faces"] == 12 and d["closed"] is True and d["components"] == 1
    assert d["intersecting_faces"] == 0 and d["path"].endswith("box.obj")

    assert main(["info", str(path)]) == 0
    assert "connected components" in capsys.readouterr().out


def test_cli_info_errors(tmp_path, capsys):
    from meshvis.cli.main import main

    assert main(["info", str(tmp_path / "missing.obj")]) == 2
    assert "missing.obj" in capsys.readouterr().err
    path = tmp_path / "box.obj"
    trimesh.creation.box().export(path)
    assert main(["info", str(path), "--eps", "0"]) == 2
    assert "--eps" in capsys.readouterr().err


def test_diagnose_advances_a_progress_bar_through_every_step():
    import trimesh

    from meshvis.geometry.diagnostics import diagnose

    seen = []
    diagnose(trimesh.creation.icosphere(3), progress=lambda stage, fraction: seen.append((stage, fraction)))
    fractions = [f for _, f in seen]
    assert fractions[0] == 0.0 and fractions[-1] == 1.0
    assert fractions == sorted(fractions)
    # weld, degenerate, duplicates, the intersection tests (the edges are built alongside)
    assert len(set(fractions)) >= 5


def test_diagnose_counts_the_same_on_one_thread_and_on_several(monkeypatch):
    import trimesh

    from meshvis.geometry.diagnostics import analyse, diagnose
    from meshvis.io import as_soup

    mesh = trimesh.util.concatenate(
        [trimesh.creation.icosphere(3), trimesh.creation.box(extents=(1.8, 1.8, 1.8))]
    )
    counts = []
    for threads in ("1", "2"):
        monkeypatch.setenv("MESHVIS_THREADS", threads)
        d = diagnose(mesh)
        a = analyse(as_soup(mesh))
        assert np.array_equal(a.table.face_edge, analyse(as_soup(mesh)).table.face_edge)
        counts.append(({k: v for k, v in d.items() if "seconds" not in k}, a.table.face_edge))
    assert counts[0][0] == counts[1][0] and counts[0][0]["intersecting_faces"] > 0
    assert np.array_equal(counts[0][1], counts[1][1])
