"""glTF/GLB round trips on real models: a repair edits the input document, it does not rebuild it."""

import os

import numpy as np
import pytest
from helpers import real_model, validate_gltf, write_glb

import meshvis
from meshvis.io.gltf_edit import read_container

HERE = os.path.dirname(__file__)
MODELS = ["CesiumMilkTruck.glb", "pins.glb"]
#: top-level glTF properties a face edit never touches
KEPT = ("asset", "scene", "scenes", "materials", "textures", "images", "samplers", "animations", "skins",
        "cameras", "extensionsUsed", "extensionsRequired", "extensions", "extras")  # fmt: skip


def _index_accessors(doc):
    return {p["indices"] for m in doc.get("meshes", []) for p in m["primitives"] if "indices" in p}


def _view_bytes(doc, buffers, view):
    bv = doc["bufferViews"][view]
    start = bv.get("byteOffset", 0)
    return bytes(buffers[bv["buffer"]][start : start + bv["byteLength"]])


def _non_index_data(doc, buffers):
    """Every accessor that is not index data, with the bytes of its view; every image's bytes."""
    idx = _index_accessors(doc)
    accs = {
        i: (a, _view_bytes(doc, buffers, a["bufferView"]) if "bufferView" in a else None)
        for i, a in enumerate(doc.get("accessors", []))
        if i not in idx
    }
    images = [
        _view_bytes(doc, buffers, im["bufferView"]) if "bufferView" in im else im.get("uri")
        for im in doc.get("images", [])
    ]
    return accs, images


def _sorted_triangles(soup):
    t = np.round(soup.triangles, 4).reshape(len(soup.faces), 9)
    return t[np.lexsort(t.T[::-1])]


def _assert_only_faces_changed(src, out):
    a, abuf, _ = read_container(src, "in")
    b, bbuf, _ = read_container(out, "out")
    for key in KEPT:
        assert a.get(key) == b.get(key), key
    assert len(b["nodes"]) == len(a["nodes"])
    for na, nb in zip(a["nodes"], b["nodes"]):
        assert {k: v for k, v in na.items() if k != "mesh"} == {k: v for k, v in nb.items() if k != "mesh"}
    accs_a, img_a = _non_index_data(a, abuf)
    accs_b, img_b = _non_index_data(b, bbuf)
    assert img_a == img_b  # texture bytes untouched
    for i, value in accs_a.items():
        assert accs_b[i] == value, f"accessor {i}"


@pytest.mark.parametrize("name", MODELS)
def test_unchanged_repair_gives_the_same_document(name, tmp_path):
    src = real_model(name)
    out = str(tmp_path / name)
    meshvis.save(meshvis.load(src), out)
    a, abuf, _ = read_container(src, "in")
    b, bbuf, _ = read_container(out, "out")
    assert a == b
    assert [bytes(x) for x in abuf] == [bytes(x) for x in bbuf]
    assert abs(os.path.getsize(out) - os.path.getsize(src)) <= 0.05 * os.path.getsize(src)


def test_truck_keeps_normals_tree_animation_and_texture(tmp_path):
    src = real_model("CesiumMilkTruck.glb")
    soup = meshvis.load(src)
    out = str(tmp_path / "o.glb")
    meshvis.save(meshvis.orient(soup).soup, out)
    a, _, _ = read_container(src, "in")
    b, _, _ = read_container(out, "out")
    assert a["animations"] and b["animations"] == a["animations"]
    assert all("NORMAL" in p["attributes"] for m in b["meshes"] for p in m["primitives"])
    assert b["materials"] == a["materials"]
    assert [n.get("children") for n in b["nodes"]] == [n.get("children") for n in a["nodes"]]


@pytest.mark.parametrize("name", MODELS)
def test_removal_changes_only_the_removed_faces(name, tmp_path):
    src = real_model(name)
    soup = meshvis.load(src)
    keep = np.ones(soup.n_faces, bool)
    keep[::3] = False
    out = str(tmp_path / name)
    meshvis.save(soup.subset(keep), out)
    _assert_only_faces_changed(src, out)
    back = meshvis.load(out)
    assert np.array_equal(_sorted_triangles(back), _sorted_triangles(soup.subset(keep)))


@pytest.mark.parametrize("name", MODELS)
def test_flips_change_only_the_flipped_faces(name, tmp_path):
    src = real_model(name)
    soup = meshvis.load(src)
    flip = np.zeros(soup.n_faces, bool)
    flip[:40] = True  # faces of the first piece only
    out = str(tmp_path / name)
    meshvis.save(soup.flipped(flip), out)
    _assert_only_faces_changed(src, out)
    back = meshvis.load(out)
    a, _, _ = read_container(src, "in")
    b, _, _ = read_container(out, "out")
    assert len(b["meshes"]) == len(a["meshes"])  # one instance's faces: no split
    dots = np.einsum("ij,ij->i", back.normals, soup.normals)
    big = soup.areas > 1e-6 * soup.areas.max()
    assert np.array_equal(dots[big] < 0, flip[big])


def test_shared_mesh_is_split_only_for_the_instance_that_differs(tmp_path):
    src = real_model("pins.glb")
    soup = meshvis.load(src)
    a, _, _ = read_container(src, "in")
    dowel = soup.part_id == 2  # one of the six instances of the shared dowel mesh
    out = str(tmp_path / "p.glb")
    meshvis.save(soup.flipped(dowel), out)
    b, _, _ = read_container(out, "out")
    assert len(a["meshes"]) == 2 and len(b["meshes"]) == 3
    users = [n.get("mesh") for n in b["nodes"]]
    assert users.count(1) == 5 and users.count(2) == 1
    back = meshvis.load(out)
    assert np.array_equal(back.normals[dowel].round(4), -soup.normals[dowel].round(4))


@pytest.mark.parametrize("name", MODELS)
@pytest.mark.parametrize("change", ["none", "remove", "flip"])
def test_outputs_pass_the_khronos_validator(name, change, tmp_path):
    soup = meshvis.load(real_model(name))
    if change == "remove":
        soup = soup.subset(np.arange(soup.n_faces) % 4 != 0)
    elif change == "flip":
        soup = soup.flipped(np.arange(soup.n_faces) % 5 == 0)
    out = str(tmp_path / name)
    meshvis.save(soup, out)
    report = validate_gltf(out)
    assert report["errors"] == 0, report["messages"]


@pytest.mark.parametrize(
    "name", ["ferrari348_lowpoly.glb", "van_gogh_room.glb", "zdm2_level.glb", "mannequiny.glb"]
)
def test_edits_of_larger_models_add_no_validator_error(name, tmp_path):
    src = real_model(name)
    soup = meshvis.load(src)
    out = str(tmp_path / name)
    meshvis.save(soup.flipped(np.arange(soup.n_faces) % 2 == 0).subset(np.arange(soup.n_faces) % 3 != 0), out)
    before, after = validate_gltf(src), validate_gltf(out)
    codes = {m.split()[0] for m in before["messages"]}
    assert after["errors"] <= before["errors"]
    assert {m.split()[0] for m in after["messages"]} <= codes, after["messages"]
    _assert_only_faces_changed(src, out)


def test_a_mirrored_instance_is_edited_in_the_file_winding(tmp_path):
    doc, buffers, _ = read_container(real_model("pins.glb"), "pins")
    m = doc["nodes"][3]["matrix"]
    doc["nodes"][3]["matrix"] = [-v for v in m[:4]] + m[4:]  # mirror the third node's x axis
    src = str(tmp_path / "mirror.glb")
    write_glb(doc, bytes(buffers[0]), src)
    soup = meshvis.load(src)
    mirrored = soup.part_id == soup.part_names.index(doc["nodes"][3]["name"])
    flip = mirrored | (soup.part_id == soup.part_names.index(doc["nodes"][2]["name"]))
    out = str(tmp_path / "o.glb")
    meshvis.save(soup.flipped(flip), out)
    back = meshvis.load(out)
    assert np.allclose(back.normals, soup.flipped(flip).normals, atol=1e-9)
    # the mirrored node and its unmirrored sibling both turned over: one shared copy, no more
    b, _, _ = read_container(out, "out")
    assert len(b["meshes"]) == 3 and b["nodes"][2]["mesh"] == b["nodes"][3]["mesh"] == 2
