"""PLY and STL round trips: every element, property, type, comment and header byte kept."""

import numpy as np
import pytest
from helpers import real_model

import meshvis
from meshvis.io.ply import read_elements


def _equal_columns(a, b):
    assert a.keys() == b.keys()
    for prop, x in a.items():
        y = b[prop]
        if isinstance(x, tuple):
            assert np.array_equal(x[0], y[0]) and np.array_equal(x[1], y[1]) and x[1].dtype == y[1].dtype, (
                prop
            )
        else:
            assert np.array_equal(x, y) and x.dtype == y.dtype, prop


def _sorted_triangles(soup):
    t = np.round(soup.triangles, 5).reshape(len(soup.faces), 9)
    return t[np.lexsort(t.T[::-1])]


@pytest.mark.parametrize("name", ["pymeshlab_face000.ply", "pyvista__ant.ply"])
def test_unchanged_ply_is_the_same_file(name, tmp_path):
    src = real_model(name)
    out = str(tmp_path / name)
    meshvis.save(meshvis.load(src), out)
    with open(src, "rb") as fa, open(out, "rb") as fb:
        assert fa.read() == fb.read()


def test_ply_repair_changes_only_the_faces(tmp_path):
    src = real_model("pymeshlab_face000.ply")
    soup = meshvis.load(src)
    result = soup.flipped(np.arange(soup.n_faces) % 2 == 0).subset(np.arange(soup.n_faces) % 3 != 0)
    out = str(tmp_path / "o.ply")
    meshvis.save(result, out)
    a, comments_a = read_elements(src, "in")
    b, comments_b = read_elements(out, "out")
    assert comments_a == comments_b
    assert list(a) == list(b) == ["camera", "vertex", "face"]
    _equal_columns(a["camera"], b["camera"])
    _equal_columns(a["vertex"], b["vertex"])
    assert b["face"]["quality"].dtype == np.float32 and b["face"]["flags"].dtype == np.int32
    # the face rows are the kept input rows with their own flags and quality
    rows = result.source_face
    assert np.array_equal(np.sort(b["face"]["quality"]), np.sort(a["face"]["quality"][rows]))
    assert np.array_equal(_sorted_triangles(meshvis.load(out)), _sorted_triangles(result))


ASCII_QUADS = """ply
format ascii 1.0
comment made by hand
obj_info two quads
element vertex 6
property float x
property float y
property float z
property uchar red
element face 2
property list uchar int vertex_indices
property list uchar float texcoord
property short tag
end_header
0 0 0 10
1 0 0 20
1 1 0 30
0 1 0 40
2 0 0 50
2 1 0 60
4 0 1 2 3 8 0 0 0.5 0 0.5 0.5 0 0.5 7
4 1 4 5 2 8 0.5 0 1 0 1 0.5 0.5 0.5 -3
"""


@pytest.mark.parametrize("fmt", ["ascii", "binary_big_endian"])
def test_turned_polygon_stays_a_polygon_in_its_format(fmt, tmp_path):
    src = tmp_path / "q.ply"
    src.write_text(ASCII_QUADS)
    if fmt != "ascii":  # the same model as big-endian binary
        vert = np.zeros(6, [("x", ">f4"), ("y", ">f4"), ("z", ">f4"), ("red", "u1")])
        vert["x"], vert["y"], vert["red"] = [0, 1, 1, 0, 2, 2], [0, 0, 1, 1, 0, 1], [10, 20, 30, 40, 50, 60]
        face = np.zeros(2, [("n", "u1"), ("i", ">i4", 4), ("m", "u1"), ("t", ">f4", 8), ("tag", ">i2")])
        face["n"], face["m"], face["tag"] = 4, 8, [7, -3]
        face["i"] = [[0, 1, 2, 3], [1, 4, 5, 2]]
        face["t"] = [[0, 0, 0.5, 0, 0.5, 0.5, 0, 0.5], [0.5, 0, 1, 0, 1, 0.5, 0.5, 0.5]]
        header = ASCII_QUADS[: ASCII_QUADS.index("end_header") + 11].replace("ascii", "binary_big_endian")
        src.write_bytes(header.encode() + vert.tobytes() + face.tobytes())
    soup = meshvis.load(str(src))
    out = tmp_path / "o.ply"
    meshvis.save(soup.flipped(soup.source_face == 1), str(out))
    header = out.read_bytes().split(b"end_header")[0].decode()
    assert (
        f"format {fmt} 1.0" in header and "comment made by hand" in header and "obj_info two quads" in header
    )
    a, _ = read_elements(str(src), "in")
    b, _ = read_elements(str(out), "out")
    _equal_columns(a["vertex"], b["vertex"])
    assert b["face"]["vertex_indices"][1].tolist() == [0, 1, 2, 3, 1, 2, 5, 4]
    assert b["face"]["texcoord"][1].tolist() == [0, 0, 0.5, 0, 0.5, 0.5, 0, 0.5] + [
        0.5,
        0,
        0.5,
        0.5,
        1,
        0.5,
        1,
        0,
    ]
    assert b["face"]["tag"].tolist() == [7, -3]
    # one triangle of the first quad removed: its other triangle becomes a row of its own
    first = np.flatnonzero(soup.source_face == 0)[0]
    meshvis.save(soup.subset(np.arange(soup.n_faces) != first), str(out))
    b, _ = read_elements(str(out), "out")
    assert b["face"]["vertex_indices"][0].tolist() == [3, 4] and b["face"]["tag"].tolist() == [7, -3]


def test_binary_stl_keeps_its_header_and_attributes(tmp_path):
    src = real_model("dm_control__SKINbody.stl")
    with open(src, "rb") as fh:
        data = fh.read()
    soup = meshvis.load(src)
    out = str(tmp_path / "o.stl")
    meshvis.save(soup, out)
    with open(out, "rb") as fh:
        assert fh.read() == data
    keep = np.arange(soup.n_faces) % 4 != 0
    meshvis.save(soup.flipped(np.arange(soup.n_faces) % 2 == 0).subset(keep), out)
    with open(out, "rb") as fh:
        new = fh.read()
    assert new[:80] == data[:80]
    rec = np.dtype([("normal", "<f4", (3,)), ("corners", "<f4", (3, 3)), ("attr", "<u2")])
    a = np.frombuffer(data, rec, offset=84)
    b = np.frombuffer(new, rec, offset=84)
    assert np.array_equal(b["attr"], a["attr"][keep])
    same = np.flatnonzero(keep & (np.arange(soup.n_faces) % 2 == 1))
    assert np.array_equal(b["corners"][np.isin(np.flatnonzero(keep), same)], a["corners"][same])


def test_ascii_stl_stays_ascii(tmp_path):
    src = tmp_path / "a.stl"
    src.write_text(
        "solid thing\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\nendloop\n"
        "endfacet\nfacet normal 0 0 1\nouter loop\nvertex 1 0 0\nvertex 1 1 0\nvertex 0 1 0\nendloop\n"
        "endfacet\nendsolid thing\n"
    )
    soup = meshvis.load(str(src))
    out = tmp_path / "o.stl"
    meshvis.save(soup.flipped([True, False]), str(out))
    text = out.read_text()
    assert text.startswith("solid thing") and text.count("facet normal") == 2
    back = meshvis.load(str(out))
    assert np.allclose(back.normals, [[0, 0, -1], [0, 0, 1]])


def test_layers_add_face_properties_to_the_edited_ply(tmp_path):
    src = real_model("pymeshlab_face000.ply")
    soup = meshvis.load(src)
    layer = np.arange(soup.n_faces) % 3 + 1
    out = str(tmp_path / "l.ply")
    meshvis.save(soup, out, face_groups=layer - 1, group_names=["a", "b", "c"], face_values={"layer": layer})
    a, comments_a = read_elements(src, "in")
    b, comments_b = read_elements(out, "out")
    _equal_columns(a["camera"], b["camera"])
    _equal_columns(a["vertex"], b["vertex"])
    assert comments_b == comments_a + ["meshvis group 0 a", "meshvis group 1 b", "meshvis group 2 c"]
    assert np.array_equal(b["face"]["layer"], layer) and np.array_equal(b["face"]["group"], layer - 1)
    for prop in ("vertex_indices", "flags", "quality"):
        assert np.array_equal(b["face"][prop][1] if prop == "vertex_indices" else b["face"][prop],
                              a["face"][prop][1] if prop == "vertex_indices" else a["face"][prop])  # fmt: skip


def test_a_polygon_whose_triangles_differ_in_layer_is_split(tmp_path):
    src = tmp_path / "q.ply"
    src.write_text(ASCII_QUADS)
    soup = meshvis.load(str(src))
    layer = np.array([1, 2, 1, 1])  # the first quad's triangles in two layers
    out = tmp_path / "o.ply"
    meshvis.save(soup, str(out), face_values={"layer": layer})
    b, _ = read_elements(str(out), "out")
    assert b["face"]["vertex_indices"][0].tolist() == [3, 3, 4]
    assert b["face"]["layer"].tolist() == [1, 2, 1] and b["face"]["tag"].tolist() == [7, 7, -3]
