"""Removal and layers by sight on scenes whose answer is known by construction: glass,
an inner shell joined to the outer one, a part seen through a gap, nested boxes with a
window; the self-check; see-through materials read from files."""

from __future__ import annotations

import json

import numpy as np
import pytest
import trimesh

from meshvis.cli.main import main
from meshvis.io import load, save
from meshvis.rays.caster import VISIBILITY_OFFSET, RayCaster
from meshvis.repair.layers import layers
from meshvis.repair.remove import remove_interior
from meshvis.soup import Material, Soup
from meshvis.visibility import parse_region, visible_from
from meshvis.visibility.check import self_check

from .conftest import box_faces, quad


def _soup(pieces: list[tuple[list, bool]]) -> tuple[Soup, np.ndarray]:
    """A soup of triangle lists, each of glass or not; and the piece index of every face."""
    tris = [t for tri, _ in pieces for t in tri]
    piece = np.concatenate([np.full(len(tri), i) for i, (tri, _) in enumerate(pieces)])
    glass = np.array([g for _, g in pieces])[piece]
    v = np.asarray(tris, np.float64).reshape(-1, 3)
    f = np.arange(len(v)).reshape(-1, 3)
    materials = [Material("wall"), Material("glass", see_through=True)]
    return Soup(v, f, material_id=glass.astype(np.int64), materials=materials, part_id=piece), piece


def _sides(lo, hi, skip=()) -> list:
    return [t for q in box_faces(lo, hi, skip).values() for t in q]


def glass_box():
    """A unit box whose +x wall is a glass pane, and a small box inside.

    Through the glass a viewer sees the inner box's +x, +-y and +-z sides; its -x side faces
    away from the pane and is hidden.  Returns the soup, the piece of every face (0 walls,
    1 pane, 2 inner box) and the truth of the default removal.
    """
    walls = _sides((0, 0, 0), (1, 1, 1), skip=("+x",))
    pane = box_faces((0, 0, 0), (1, 1, 1))["+x"]
    inner_sides = box_faces((0.4, 0.4, 0.4), (0.6, 0.6, 0.6))
    inner = [t for q in inner_sides.values() for t in q]
    soup, piece = _soup([(walls, False), (pane, True), (inner, False)])
    truth = np.ones(soup.n_faces, bool)
    hidden_side = 2 * list(inner_sides).index("-x")
    truth[len(walls) + len(pane) + hidden_side + np.arange(2)] = False
    return soup, piece, truth


def test_glass_lets_sight_through_and_opaque_makes_it_a_wall():
    soup, piece, truth = glass_box()
    assert soup.see_through.tolist() == (piece == 1).tolist()
    r = remove_interior(soup, seed=0)
    np.testing.assert_array_equal(r.keep, truth)
    assert r.see_through == 2 and r.report(per_face=False)["see_through_faces"] == 2
    wall = remove_interior(soup, seed=0, transparent="opaque")
    np.testing.assert_array_equal(wall.keep, piece != 2)  # the inner box is sealed in
    assert wall.see_through == 0
    # the search of visible_from and layers follow the same rule
    assert visible_from(soup, seed=1).seen[piece == 2].any()
    assert not visible_from(soup, seed=1, transparent="opaque").seen[piece == 2].any()
    lay = layers(soup, seed=0)
    np.testing.assert_array_equal(lay.layer == 1, truth)
    assert lay.see_through == 2


def test_see_through_materials_are_read_from_mtl_and_gltf(tmp_path):
    soup, piece, truth = glass_box()
    obj = tmp_path / "box.obj"
    save(soup, str(obj))
    mtl = next(tmp_path.glob("*.mtl"))
    text = mtl.read_text()
    assert "newmtl glass" in text
    mtl.write_text(text.replace("newmtl glass", "newmtl glass\nd 0.25"))
    back = load(obj)
    np.testing.assert_array_equal(back.see_through, piece == 1)
    # glTF: the OBJ's dissolve becomes alphaMode BLEND, read back as see-through
    glb = tmp_path / "box.gltf"
    save(back, str(glb))
    doc = json.loads(glb.read_text())
    assert [m.get("alphaMode") for m in doc["materials"]].count("BLEND") == 1
    np.testing.assert_array_equal(load(glb).see_through, piece == 1)
    for mode, extra in [
        ("MASK", {"pbrMetallicRoughness": {"baseColorFactor": [1, 1, 1, 0.1]}}),
        (None, {"extensions": {"KHR_materials_transmission": {"transmissionFactor": 0.9}}}),
    ]:
        for m in doc["materials"]:
            if m.get("alphaMode") == "BLEND":
                m.pop("alphaMode")
                m.update({"alphaMode": mode} if mode else {}, **extra)
        glb.write_text(json.dumps(doc))
        np.testing.assert_array_equal(load(glb).see_through, piece == 1)
        doc = json.loads(glb.read_text())


def test_the_command_keeps_what_shows_through_glass_unless_told_opaque(tmp_path, capsys):
    soup, piece, truth = glass_box()
    src = tmp_path / "box.glb"
    save(soup, str(src))
    assert load(src).see_through.sum() == 2
    out, rep = tmp_path / "kept.glb", tmp_path / "r.json"
    argv = ["remove-interior", str(src), "-o", str(out), "--report", str(rep), "--force"]
    assert main(argv) == 0
    printed = capsys.readouterr().out
    assert "2 faces of see-through materials let sight through" in printed
    assert "self-check: 64 fresh random rays from each of 2 removed faces saw 0 of them" in printed
    report = json.loads(rep.read_text())
    assert report["removed_faces"] == 2 and report["see_through_faces"] == 2
    assert report["self_check"]["faces_seen"] == 0
    assert main(argv + ["--transparent", "opaque", "-q"]) == 0
    report = json.loads(rep.read_text())
    assert report["removed_faces"] == int((piece == 2).sum()) and report["see_through_faces"] == 0


def joined_shells(subdivisions: int = 3, holes: int = 3):
    """An outer sphere joined to an inner one by tubes from small holes in the inner sphere.

    The inner sphere (radius 0.6) has ``holes`` small holes; each hole's rim is joined by a
    tube to the outer sphere (radius 1), whose edges above the rim it shares: one connected
    surface, of which only the outer sphere can be seen.  Returns the soup and the mask of
    the outer sphere's faces.
    """
    outer = trimesh.creation.icosphere(subdivisions)
    v = outer.vertices
    f = outer.faces
    # a hole: the faces around a vertex (its 1-ring); the ring's boundary edges become tubes
    rng = np.random.default_rng(0)
    centers = rng.choice(len(v), holes, replace=False)
    cut = np.isin(f, centers).any(axis=1)
    inner_faces = f[~cut]
    rim = []
    for tri in f[cut]:
        for a, b in ((tri[0], tri[1]), (tri[1], tri[2]), (tri[2], tri[0])):
            if a not in centers and b not in centers:
                rim.append((a, b))
    n = len(v)
    vertices = np.vstack([v, 0.6 * v])
    tubes = []
    for a, b in rim:  # inner edge (a, b) -> outer edge (a, b): the rim's quad, facing outward of the tube
        tubes += [[a + n, b + n, b], [a + n, b, a]]
    faces = np.vstack([f, inner_faces + n, np.array(tubes)])
    outer_mask = np.zeros(len(faces), bool)
    outer_mask[: len(f)] = True
    return Soup(vertices, faces), outer_mask


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_an_inner_shell_joined_through_small_holes_goes_and_the_outer_stays_whole(seed):
    soup, outer = joined_shells()
    from meshvis.geometry.adjacency import components, edges, face_adjacency, weld

    _, welded = weld(soup.vertices, soup.faces)
    assert components(soup.n_faces, face_adjacency(edges(welded), manifold_only=False))[0] == 1
    r = remove_interior(soup, seed=seed)
    np.testing.assert_array_equal(r.keep, outer)
    assert r.check.faces == int((~outer).sum()) and not r.check.seen.any()
    # the cut calls the inner shell outside wherever a path through the tubes reaches it
    lay = layers(soup, seed=seed)
    np.testing.assert_array_equal(lay.layer == 1, outer)


def gap_box():
    """A closed box with a slit in its +z lid; below the slit a part seen through it, beside
    it, under the lid and behind a baffle, a part no line through the slit reaches.

    Returns the soup, the piece of every face (0 box, 1 seen part, 2 hidden part, 3
    baffle) and the truth: the seen part's top, the box and the baffle's slit-side face.
    """
    box = _sides((0, 0, 0), (1, 1, 1), skip=("+z",))
    lid = []
    for (xa, ya), (xb, yb) in [
        ((0, 0), (0.48, 1)),
        ((0.52, 0), (1, 1)),
        ((0.48, 0), (0.52, 0.3)),
        ((0.48, 0.7), (0.52, 1)),
    ]:
        lid += quad((xa, ya, 1), (xb, ya, 1), (xb, yb, 1), (xa, yb, 1))
    seen = _sides((0.4, 0.4, 0.1), (0.6, 0.6, 0.3))
    hidden = _sides((0.85, 0.4, 0.85), (0.95, 0.6, 0.95))
    baffle = quad(
        (0.8, 0, 0.7), (0.8, 1, 0.7), (0.8, 1, 0.999), (0.8, 0, 0.999)
    )  # faces -x, towards the slit
    soup, piece = _soup([(box + lid, False), (seen, False), (hidden, False), (baffle, False)])
    return soup, piece


@pytest.mark.parametrize("seed", [0, 1, 2, 3, 4])
def test_a_part_seen_only_through_a_gap_is_kept_and_one_behind_a_baffle_goes(seed):
    soup, piece = gap_box()
    r = remove_interior(soup, seed=seed)
    top = np.flatnonzero(piece == 1)[2 * 5 : 2 * 6]  # the +z side of the part below the slit
    assert r.keep[top].all()
    assert not r.keep[piece == 2].any()
    assert r.keep[piece == 0].all() and r.keep[piece == 3].all()


def nested_boxes_with_a_window():
    """An outer box with a square window in its +x wall, a closed box in it, and a closed box in that.

    Truth of the layers by sight: layer 1 is the outer box and every side of the middle box
    but -x (seen through the window; -x faces away from it); once they are gone, the middle
    box's -x side and every side of the inner box are seen: layer 2.
    """
    wall = []
    for (ya, za), (yb, zb) in [((0, 0), (1, 3)), ((2, 0), (3, 3)), ((1, 0), (2, 1)), ((1, 2), (2, 3))]:
        wall += quad((3, ya, za), (3, yb, za), (3, yb, zb), (3, ya, zb))
    outer = _sides((0, 0, 0), (3, 3, 3), skip=("+x",)) + wall
    middle_sides = box_faces((1.2, 1.2, 1.2), (1.8, 1.8, 1.8))
    middle = [t for q in middle_sides.values() for t in q]
    inner = _sides((1.4, 1.4, 1.4), (1.6, 1.6, 1.6))
    soup, piece = _soup([(outer, False), (middle, False), (inner, False)])
    truth = np.where(piece == 2, 2, 1)
    minus_x = len(outer) + 2 * list(middle_sides).index("-x") + np.arange(2)
    truth[minus_x] = 2
    return soup, piece, truth


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_layers_by_sight_of_nested_boxes_with_a_window(seed):
    soup, piece, truth = nested_boxes_with_a_window()
    r = layers(soup, seed=seed)
    np.testing.assert_array_equal(r.layer, truth)
    assert r.n_layers == 2 and r.unreached == 0 and r.classification is None
    assert len(r.searches) == 2  # every face had a layer after the second
    np.testing.assert_array_equal(r.layer == 1, remove_interior(soup, seed=seed, check_rays=0).keep)
    assert layers(soup, seed=seed, max_layers=1).layer.tolist() == np.minimum(truth, 2).tolist()
    # the cut's layers (the paper's): the three boxes one after another
    cut = layers(soup, seed=seed, visibility="object")
    assert cut.classification is not None
    assert (cut.layer[piece == 0] == 1).all() and (cut.layer[piece == 2] > cut.layer[piece == 1].min()).all()


def test_the_layers_command_peels_by_sight_or_by_the_cut(tmp_path):
    soup, piece, truth = nested_boxes_with_a_window()
    src = tmp_path / "boxes.ply"
    save(soup, str(src))
    out, rep = tmp_path / "layers.ply", tmp_path / "r.json"
    argv = ["layers", str(src), "-o", str(out), "--report", str(rep), "-q", "--force"]
    assert main(argv) == 0
    report = json.loads(rep.read_text())
    assert report["visibility"] == "view" and report["faces_per_layer"] == [
        int((truth == 1).sum()),
        int((truth == 2).sum()),
        0,
    ]
    assert report["per_face"]["layer"] == truth.tolist() and "classification" not in report
    assert main(argv + ["--visibility", "object"]) == 0
    report = json.loads(rep.read_text())
    assert report["visibility"] == "object" and "classification" in report


def test_the_self_check_catches_a_planted_visible_face(scenes):
    cube, names = scenes.unit_cube()
    removed = np.zeros(12, bool)
    removed[3] = True  # plant: a removal that took away a face every viewer sees
    caster = RayCaster(cube, offset=VISIBILITY_OFFSET)
    check = self_check(caster, parse_region("outside").bind(cube), removed, seed=0)
    assert check.seen.tolist() == [i == 3 for i in range(12)]
    assert check.seen_area_fraction == 1.0 and check.rays == 64 and check.faces == 1
    assert "saw 1 of them (100 % of the removed area)" in check.summary()
    # an honest removal: the check sees none of the removed faces
    soup, bottom, truth = scenes.sealed_pocket()
    honest = remove_interior(soup, seed=0)
    assert honest.check.faces == 2 and not honest.check.seen.any()
    assert remove_interior(soup, seed=0, check_rays=0).check is None
    # the check draws its own random stream: the same seed gives the same check
    again = self_check(caster, parse_region("outside").bind(cube), removed, seed=0)
    np.testing.assert_array_equal(again.seen, check.seen)


def test_the_rescue_pass_keeps_what_the_search_missed(scenes):
    cube, names = scenes.unit_cube()
    vis = visible_from(cube, seed=0)
    assert vis.seen.all()
    vis.seen_side[3] = False  # plant: the search "missed" a face every viewer sees
    r = remove_interior(cube, view=vis, seed=0)
    assert r.keep.all() and r.rescue.seen.tolist() == [i == 3 for i in range(12)]
    assert r.reason[3] == "kept: a ray of the rescue pass saw it"
    assert r.check.faces == 0 and r.rescue.rays_per_face == 256
    assert any("found a view of 1 of them (kept)" in line for line in r.summary())
    assert r.report(per_face=False)["rescue"]["faces_seen"] == 1
    assert not remove_interior(cube, view=vis, seed=0, rescue_rays=0).keep[3]  # no rescue: removed
    # a search cut short by its budget misses faces in view; the rescue sees each of them
    soup, _, truth = scenes.slot_box()
    short = remove_interior(soup, seed=0, budget=200, rescue_rays=0)
    assert short.visibility.stopped == "budget" and short.keep.sum() < soup.n_faces
    r = remove_interior(soup, seed=0, budget=200)
    assert r.keep.all() and r.rescue.seen.sum() == soup.n_faces - short.keep.sum()
    assert not r.check.seen.any()
    # layers by sight end every layer with the same pass: layer 1 is the removal's kept faces
    assert (layers(soup, seed=0, budget=200).layer == 1).all()
    # "both": the cut proposes, the search and then the rescue may keep
    both = remove_interior(soup, visibility="both", seed=0, budget=200)
    assert both.keep.all() and both.rescue is not None
    assert remove_interior(soup, visibility="object", seed=0).rescue is None  # the cut alone: no rescue


def test_every_mode_runs_the_self_check(scenes):
    soup, bottom, truth = scenes.sealed_pocket()
    for mode in ("view", "object", "both"):
        r = remove_interior(soup, visibility=mode, seed=0)
        report = r.report(per_face=True)
        assert report["self_check"]["faces_checked"] == int((~r.keep).sum())
        assert len(report["per_face"]["seen_by_check"]) == soup.n_faces


def test_a_budget_that_ends_the_search_shows_in_the_summary(scenes):
    soup, _, _ = scenes.slot_box()
    r = remove_interior(soup, seed=0, budget=200)
    assert r.visibility.stopped == "budget"
    assert any("stopped at its ray budget" in line for line in r.summary())
    assert not any("budget" in line for line in remove_interior(soup, seed=0).summary())


@pytest.mark.parametrize("scale, shift", [(1e-6, 0.0), (1e6, 0.0), (1.0, 1e6), (1e-3, 1e5)])
def test_removal_and_layers_by_sight_hold_at_extreme_scales_and_far_from_the_origin(scale, shift):
    soup, piece, truth = glass_box()
    moved = Soup(
        soup.vertices * scale + shift, soup.faces, material_id=soup.material_id, materials=soup.materials
    )
    np.testing.assert_array_equal(remove_interior(moved, seed=0).keep, truth)
    boxes, _, layer_truth = nested_boxes_with_a_window()
    far = Soup(boxes.vertices * scale + shift, boxes.faces)
    np.testing.assert_array_equal(layers(far, seed=0).layer, layer_truth)


def test_removal_by_sight_of_one_triangle_and_of_nothing():
    one = Soup(np.eye(3), np.array([[0, 1, 2]]))
    r = remove_interior(one, seed=0)
    assert r.keep.tolist() == [True] and r.check.faces == 0
    flat = Soup(np.zeros((3, 3)), np.array([[0, 1, 2]]))  # zero area: nothing to see
    r = remove_interior(flat, seed=0)
    assert r.keep.tolist() == [False] and r.check.faces == 0 and r.check.seen_area_fraction == 0.0
