"""``layers`` outputs keep the input: glTF gets child nodes, PLY a property, OBJ per-layer edits."""

import os

import numpy as np
import pytest
from helpers import real_model, validate_gltf

import meshvis
from meshvis.io.gltf_edit import read_container
from meshvis.io.ply import read_elements
from meshvis.repair.operation import layer_paths, run_operation


def _sorted_triangles(soup):
    t = np.round(soup.triangles, 5).reshape(len(soup.faces), 9)
    return t[np.lexsort(t.T[::-1])]


def _run(src, out):
    soup = meshvis.load(src)
    notes = []
    report = run_operation("layers", soup, {"output": out, "seed": 0}, say=notes.append)
    return soup, report, notes


def _layers(report):
    return np.asarray(report["per_face"]["layer"])


@pytest.mark.parametrize("name", ["CesiumMilkTruck.glb", "pins.glb"])
def test_gltf_layers_output_is_the_input_with_a_child_node_per_deeper_layer(name, tmp_path):
    src = real_model(name)
    out = str(tmp_path / name)
    soup, report, notes = _run(src, out)
    layer = _layers(report)
    assert layer.max() >= 2 and "layer_files" not in report
    assert not [n for n in notes if "written anew" in n]  # edited in place
    a, abuf, _ = read_container(src, "in")
    b, bbuf, _ = read_container(out, "out")
    for key in ("animations", "materials", "textures", "images", "samplers", "scenes", "skins", "asset"):
        assert b.get(key) == a.get(key), key
    n0 = len(a["nodes"])
    for na, nb in zip(a["nodes"], b["nodes"]):  # the input's nodes, in place, with new children
        assert {k: v for k, v in na.items() if k not in ("mesh", "children")} == {
            k: v for k, v in nb.items() if k not in ("mesh", "children")
        }
        assert nb.get("children", [])[: len(na.get("children", []))] == na.get("children", [])
        assert all(c >= n0 for c in nb.get("children", [])[len(na.get("children", [])) :])
    assert all(set(n) <= {"name", "mesh", "skin", "weights"} for n in b["nodes"][n0:])  # no own transform
    for im in a.get("images", []):  # texture bytes
        va = a["bufferViews"][im["bufferView"]]
        assert b["bufferViews"][im["bufferView"]] == va
        start, end = va.get("byteOffset", 0), va.get("byteOffset", 0) + va["byteLength"]
        assert bytes(bbuf[0][start:end]) == bytes(abuf[0][start:end])
    back = meshvis.load(out)
    part_layer = [int(p.rsplit(".layer", 1)[1]) if ".layer" in p else 1 for p in back.part_names]
    got = np.array(part_layer)[back.part_id]
    for k in range(1, int(layer.max()) + 1):
        assert np.array_equal(
            _sorted_triangles(back.subset(got == k)), _sorted_triangles(soup.subset(layer == k))
        )
    assert validate_gltf(out)["errors"] == 0


@pytest.mark.parametrize("name", ["suzanne.obj", "spot.obj"])
def test_obj_layer_files_keep_normals_uvs_and_groups(name, tmp_path):
    src = real_model(name)
    out = str(tmp_path / name)
    soup, report, _ = _run(src, out)
    layer = _layers(report)
    assert report["layer_files"] == layer_paths(out, int(layer.max()))

    def non_face(path):
        lines = open(path, encoding="latin-1").read().splitlines()
        return [ln for ln in lines if not ln.startswith(("f ", "mtllib"))]

    stem = os.path.splitext(name)[0]
    for k, path in enumerate(report["layer_files"], start=1):
        # v, vt, vn, s, g, usemtl, comments; the faces before any o/g keep the input's part name
        assert [ln for ln in non_face(path) if ln != f"o {stem}"] == non_face(src)
        back = meshvis.load(path)
        assert np.array_equal(_sorted_triangles(back), _sorted_triangles(soup.subset(layer == k)))
        if soup.uv is not None:
            uv = soup.subset(layer == k).uv.reshape(-1, 6)
            assert np.array_equal(np.sort(back.uv.reshape(-1, 6), axis=0), np.sort(uv, axis=0))


def test_ply_layers_output_is_the_input_with_a_layer_property(tmp_path):
    src = real_model("pyvista__ant.ply")
    out = str(tmp_path / "ant.ply")
    soup, report, notes = _run(src, out)
    assert "layer_files" not in report and not [n for n in notes if "written anew" in n]  # edited
    a, ca = read_elements(src, "in")
    b, cb = read_elements(out, "out")
    assert list(b) == list(a) and all(np.array_equal(a["vertex"][k], b["vertex"][k]) for k in a["vertex"])
    assert np.array_equal(a["face"]["vertex_indices"][1], b["face"]["vertex_indices"][1])
    assert np.array_equal(b["face"]["layer"][soup.source_face], _layers(report))
