"""Real repairs (``run_operation``, as the CLI and the batch run them) on real models, per format.

The output must be the input with only the repaired faces changed: removed faces gone,
turned faces turned, everything else (elements, properties, lines, nodes, accessors,
texture bytes, header) equal, and no note that the file was rebuilt.
"""

import os

import numpy as np
import pytest
from helpers import real_model

import meshvis
from meshvis.io.gltf_edit import read_container
from meshvis.io.ply import read_elements
from meshvis.repair.operation import run_operation


def _repair(op, name, tmp_path, ext=None, **options):
    src = real_model(name)
    soup = meshvis.load(src)
    out = str(tmp_path / ("out" + (ext or os.path.splitext(name)[1])))
    notes = []
    report = run_operation(op, soup, {"output": out, "seed": 0, **options}, say=notes.append)
    assert not [n for n in notes if "written anew" in n], notes
    if op == "remove-interior":
        keep = np.asarray(report["per_face"]["keep"], bool)
        assert 0 < (~keep).sum() < len(keep)
        return src, soup, out, soup.subset(keep)
    flip = np.asarray(report["per_face"]["flipped"], bool)
    assert flip.any() and not np.any(report["per_face"]["duplicated"])
    return src, soup, out, soup.flipped(flip)


def _sorted_triangles(soup):
    t = np.round(soup.triangles, 5).reshape(len(soup.faces), 9)
    return t[np.lexsort(t.T[::-1])]


def test_remove_interior_of_pins_glb_edits_only_index_data(tmp_path):
    src, _, out, expected = _repair("remove-interior", "pins.glb", tmp_path)
    a, abuf, _ = read_container(src, "in")
    b, bbuf, _ = read_container(out, "out")
    for key in (
        "asset",
        "scene",
        "scenes",
        "materials",
        "textures",
        "images",
        "samplers",
        "animations",
        "skins",
    ):
        assert a.get(key) == b.get(key), key
    assert [{k: v for k, v in n.items() if k != "mesh"} for n in a["nodes"]] == [
        {k: v for k, v in n.items() if k != "mesh"} for n in b["nodes"]
    ]
    index = {p["indices"] for m in a["meshes"] + b["meshes"] for p in m["primitives"]}
    for i, acc in enumerate(a["accessors"]):
        if i not in index:  # vertex data: the same accessor on the same bytes
            assert b["accessors"][i] == acc
            bv = a["bufferViews"][acc["bufferView"]]
            s, e = bv.get("byteOffset", 0), bv.get("byteOffset", 0) + bv["byteLength"]
            assert bytes(bbuf[bv["buffer"]][s:e]) == bytes(abuf[bv["buffer"]][s:e])
    assert np.array_equal(_sorted_triangles(meshvis.load(out)), _sorted_triangles(expected))


@pytest.mark.parametrize("name", ["teapot.obj", "cow.obj"])
def test_remove_interior_of_an_obj_edits_only_face_records(name, tmp_path):
    src, _, out, expected = _repair("remove-interior", name, tmp_path, visibility="object")

    def rest(path):
        return [ln for ln in open(path, encoding="latin-1").read().splitlines() if not ln.startswith("f ")]

    assert [ln for ln in rest(out) if ln != f"o {os.path.splitext(name)[0]}"] == rest(src)
    faces_in = [ln for ln in open(src).read().splitlines() if ln.startswith("f ")]
    faces_out = [ln for ln in open(out).read().splitlines() if ln.startswith("f ")]
    assert set(faces_out) <= set(faces_in)  # kept records as written (none of these are split)
    assert np.array_equal(_sorted_triangles(meshvis.load(out)), _sorted_triangles(expected))


def test_remove_interior_of_a_ply_keeps_every_other_element_and_row(tmp_path):
    src, soup, out, expected = _repair("remove-interior", "pyvista__ant.ply", tmp_path)
    a, ca = read_elements(src, "in")
    b, cb = read_elements(out, "out")
    assert ca == cb and list(a) == list(b)
    for k, col in a["vertex"].items():
        assert np.array_equal(b["vertex"][k], col) and b["vertex"][k].dtype == col.dtype
    rows = a["face"]["vertex_indices"][1].reshape(-1, 3)
    assert np.array_equal(b["face"]["vertex_indices"][1].reshape(-1, 3), rows[expected.source_face])
    with open(src, "rb") as fa, open(out, "rb") as fb:
        assert (
            fb.read()
            .split(b"end_header")[0]
            .replace(f"element face {expected.n_faces}".encode(), f"element face {soup.n_faces}".encode())
            == fa.read().split(b"end_header")[0]
        )


@pytest.mark.parametrize("op", ["orient", "remove-interior"])
def test_repairs_of_a_binary_stl_keep_its_header_and_records(op, tmp_path):
    src, soup, out, expected = _repair(op, "soup.stl", tmp_path, visibility="object")
    rec = np.dtype([("normal", "<f4", (3,)), ("corners", "<f4", (3, 3)), ("attr", "<u2")])
    data, new = open(src, "rb").read(), open(out, "rb").read()
    assert new[:80] == data[:80]
    a, b = np.frombuffer(data, rec, offset=84), np.frombuffer(new, rec, offset=84)
    origin = expected.origin
    turned = np.einsum("ij,ij->i", expected.normals, soup.normals[origin]) < 0
    assert np.array_equal(b["attr"], a["attr"][origin])
    assert np.array_equal(b["normal"], np.where(turned[:, None], -a["normal"][origin], a["normal"][origin]))
    assert np.array_equal(b["corners"][~turned], a["corners"][origin][~turned])
    assert np.array_equal(
        np.sort(b["corners"][turned], axis=1), np.sort(a["corners"][origin][turned], axis=1)
    )


def test_a_cross_format_output_says_what_it_lacks(tmp_path):
    soup = meshvis.load(real_model("suzanne.obj"))
    notes = []
    run_operation("orient", soup, {"output": str(tmp_path / "s.ply"), "seed": 0}, say=notes.append)
    [note] = [n for n in notes if "written anew" in n]
    assert "formats differ" in note and "vn normals" in note
