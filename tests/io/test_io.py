"""Tests of meshvis.io: readers, writers, round trips, bad input, atomic writes."""

from __future__ import annotations

import os
import re
import tempfile
import warnings

import numpy as np
import pytest

import meshvis.io as mio
from meshvis.errors import ModelError, ModelFormatError, OutputError, ParameterError
from meshvis.io import as_soup
from meshvis.io.obj import MtlSource
from meshvis.io.ply import read_elements
from meshvis.io.triangulate import ear_clip, triangulate
from meshvis.soup import Material, Soup

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
REAL = os.path.normpath(os.path.join(ROOT, "..", "shared", "models", "real"))
README = os.path.normpath(os.path.join(ROOT, "..", "shared", "models", "README.md"))

needs_real = pytest.mark.skipif(not os.path.isdir(REAL), reason="shared real models not available")


def real(name: str) -> str:
    return os.path.join(REAL, name)


def _face_table() -> list[tuple[str, int]]:
    if not os.path.isfile(README):
        return []
    rows = re.findall(r"^\| `([^`]+)` \| ([\d,]+) \|", open(README).read(), re.M)
    return [(f, int(n.replace(",", ""))) for f, n in rows]


def _load_quiet(path, **kw) -> Soup:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return mio.load(path, **kw)


def _write(path, text: str | bytes) -> str:
    with open(path, "wb") as fh:
        fh.write(text.encode() if isinstance(text, str) else text)
    return str(path)


def _polygon_area(p: np.ndarray) -> float:
    """Area of a planar polygon from its Newell normal."""
    return float(np.linalg.norm(np.cross(p, np.roll(p, -1, axis=0)).sum(axis=0)) / 2)


# a concave 7-gon (an L with a notch) and a square, counter-clockwise seen from +z
SEVEN = np.array([[0, 0, 0], [4, 0, 0], [4, 1, 0], [1, 1, 0], [1, 3, 0], [0.5, 2, 0], [0, 3, 0]], float)
QUAD = np.array([[5, 0, 0], [7, 0, 0], [7, 2, 0], [5, 2, 0]], float)


def _colour_soup() -> Soup:
    """Two parts, two materials, per-corner UVs and colours, shared and unshared vertices."""
    rng = np.random.default_rng(7)
    v = rng.normal(size=(30, 3))
    f = np.array([rng.choice(30, 3, replace=False) for _ in range(40)])
    return Soup(
        v,
        f,
        part_id=np.repeat([0, 1], 20),
        part_names=["body", "lid"],
        material_id=np.tile([0, 0, 1, -1], 10),
        materials=[Material("red"), Material("blue")],
        uv=rng.random((40, 3, 2)),
        colors=rng.integers(0, 256, (40, 3, 4)).astype(np.uint8),
    )


# ---------------------------------------------------------------------------- real models
@pytest.mark.slow
@needs_real
@pytest.mark.parametrize("name,faces", _face_table() or [("missing", 0)])
def test_face_count_of_every_real_model(name, faces):
    soup = _load_quiet(real(name))
    assert soup.n_faces == faces
    assert soup.vertices.dtype == np.float64 and soup.faces.dtype == np.int64
    assert len(soup.part_id) == len(soup.material_id) == len(soup.source_face) == faces
    assert soup.part_id.max() < soup.n_parts


@needs_real
def test_real_table_lists_all_21_models():
    assert len(_face_table()) == 21


@pytest.mark.slow
@needs_real
def test_monastery_obj_keeps_file_order_and_materials():
    with pytest.warns(UserWarning, match="2 vertices"):
        soup = mio.load(real("pybullet__samurai_monastry.obj"))
    assert soup.n_faces == 124789
    assert len(soup.materials) == 81
    assert soup.uv is not None
    # the 201 two-vertex records (skipped) come last in the file
    assert np.array_equal(soup.source_face, np.arange(124789))
    # first face of the file: "f 78771/1 78772/2 78773/3"
    text = open(real("pybullet__samurai_monastry.obj")).read().splitlines()
    verts = [ln for ln in text if ln.startswith("v ")]
    expected = np.array([verts[i].split()[1:4] for i in (78770, 78771, 78772)], float)
    assert np.array_equal(soup.triangles[0], expected)


@needs_real
def test_pins_instancing():
    soup = mio.load(real("pins.glb"))
    assert soup.n_parts == 7
    sizes = np.bincount(soup.part_id)
    assert sorted(sizes.tolist()) == [314] * 6 + [1524]
    dowels = [p for p in range(7) if sizes[p] == 314]
    centres = np.array([soup.triangles[soup.part_id == p].reshape(-1, 3).mean(axis=0) for p in dowels])
    # six instances of one mesh at six different places
    dist = np.linalg.norm(centres[:, None] - centres[None], axis=-1)
    assert dist[~np.eye(6, dtype=bool)].min() > 1.0
    assert len(soup.materials) == 2
    assert all(name.startswith(("sides", "dowel")) for name in soup.part_names)


@needs_real
def test_part_names_truck_and_boolean():
    truck = mio.load(real("CesiumMilkTruck.glb"))
    assert truck.part_names == ["Cesium_Milk_Truck", "Wheels", "Wheels.1"]
    assert [m.name for m in truck.materials] == ["truck", "glass", "window_trim", "wheels"]
    assert truck.uv is not None
    # the body node has three primitives with three materials, all in one part
    assert set(truck.material_id[truck.part_id == 0].tolist()) == {0, 1, 2}
    boolean = mio.load(real("boolean.glb"))
    assert boolean.n_parts == 28
    assert "base" in boolean.part_names and "cut_0" in boolean.part_names
    assert len(set(boolean.part_names)) == 28


@needs_real
def test_obj_parts_from_o_statements():
    chair = mio.load(real("chair_model.obj"))
    assert chair.part_names[0] == "mesh20_mesh20-geometry"
    assert chair.n_parts == 4  # 20 `o` lines, 4 of them with faces
    assert len(chair.materials) == 3


@needs_real
def test_obj_line_continuation_and_concave_polygons():
    soup = mio.load(real("wallhole.obj"))
    assert soup.n_faces == 66
    # ear clipping covers every polygon exactly: triangle areas add up per polygon
    text = open(real("wallhole.obj")).read().replace("\\\n", " ")
    verts = np.array([ln.split()[1:4] for ln in text.splitlines() if ln.startswith("v ")], float)
    polys = [
        [int(c.split("/")[0]) - 1 for c in ln.split()[1:]] for ln in text.splitlines() if ln.startswith("f ")
    ]
    for k, poly in enumerate(polys):
        assert soup.areas[soup.source_face == k].sum() == pytest.approx(_polygon_area(verts[poly]), rel=1e-9)


# ---------------------------------------------------------------------------- triangulation
def test_triangulate_quad_and_concave_heptagon():
    vertices = np.concatenate([SEVEN, QUAD])
    counts = np.array([7, 4, 3])
    corners = np.concatenate([np.arange(7), np.arange(7, 11), [0, 1, 2]])
    tri, src = triangulate(vertices, counts, corners)
    assert src.tolist() == [0] * 5 + [1] * 2 + [2]
    t = vertices[corners[tri]]
    cross = np.cross(t[:, 1] - t[:, 0], t[:, 2] - t[:, 0])
    assert (cross[:, 2] > 0).all()  # same winding as the polygon, nothing folded over
    assert (cross[:5, 2] / 2).sum() == pytest.approx(_polygon_area(SEVEN))
    assert (cross[5:7, 2] / 2).sum() == pytest.approx(4.0)


def test_ear_clip_many_vertices_star():
    n = 400
    ang = np.linspace(0, 2 * np.pi, n, endpoint=False)
    r = np.where(np.arange(n) % 2 == 0, 1.0, 0.4)
    pts = np.stack([r * np.cos(ang), r * np.sin(ang), np.zeros(n)], axis=1)
    tri = ear_clip(pts)
    assert tri.shape == (n - 2, 3)
    t = pts[tri]
    z = np.cross(t[:, 1] - t[:, 0], t[:, 2] - t[:, 0])[:, 2] / 2
    assert z.min() > -1e-12
    assert z.sum() == pytest.approx(_polygon_area(pts), rel=1e-9)


def test_concave_quad_uses_reflex_corner():
    dart = np.array([[0, 0, 0], [2, 0.5, 0], [0, 1, 0], [0.5, 0.5, 0]], float)
    tri, _ = triangulate(dart, np.array([4]), np.arange(4))
    t = dart[tri]
    z = np.cross(t[:, 1] - t[:, 0], t[:, 2] - t[:, 0])[:, 2] / 2
    assert (z > 0).all() and z.sum() == pytest.approx(_polygon_area(dart))


def _polygon_obj_text() -> str:
    lines = [f"v {x} {y} {z}" for x, y, z in np.concatenate([SEVEN, QUAD])]
    lines += ["f 1 2 3 4 5 6 7", "f 8 9 10 11", "f 1 2 3"]
    return "\n".join(lines) + "\n"


def test_obj_polygons_source_face(tmp_path):
    soup = mio.load(_write(tmp_path / "poly.obj", _polygon_obj_text()))
    assert soup.n_faces == 5 + 2 + 1
    assert soup.source_face.tolist() == [0] * 5 + [1] * 2 + [2]
    assert (soup.normals[:, 2] > 0.99).all()
    assert soup.areas[soup.source_face == 0].sum() == pytest.approx(_polygon_area(SEVEN))
    assert soup.part_names == ["poly"]


@pytest.mark.slow
def test_obj_polygon_with_many_vertices(tmp_path):
    n = 3000
    ang = np.linspace(0, 2 * np.pi, n, endpoint=False)
    ring = np.stack([np.cos(ang), np.sin(ang), np.zeros(n)], axis=1)
    notch = ring.copy()
    notch[::2, :2] *= 0.5  # a concave star with as many corners
    lines = [f"v {x!r} {y!r} {z!r}" for x, y, z in np.concatenate([ring, notch]).tolist()]
    lines += [
        "f " + " ".join(str(i + 1) for i in range(n)),
        "f " + " ".join(str(n + i + 1) for i in range(n)),
    ]
    soup = mio.load(_write(tmp_path / "big.obj", "\n".join(lines) + "\n"))
    assert soup.n_faces == 2 * (n - 2)
    assert np.bincount(soup.source_face).tolist() == [n - 2, n - 2]
    assert (soup.normals[soup.areas > 0, 2] > 0.99).all()
    assert soup.areas[soup.source_face == 0].sum() == pytest.approx(_polygon_area(ring), rel=1e-9)
    assert soup.areas[soup.source_face == 1].sum() == pytest.approx(_polygon_area(notch), rel=1e-9)


def test_off_polygons_source_face(tmp_path):
    v = np.concatenate([SEVEN, QUAD])
    text = "OFF\n# a comment\n11 3 0\n" + "\n".join(" ".join(map(str, p)) for p in v)
    text += "\n7 0 1 2 3 4 5 6\n4 7 8 9 10\n3 0 1 2\n"
    soup = mio.load(_write(tmp_path / "poly.off", text))
    assert soup.source_face.tolist() == [0] * 5 + [1] * 2 + [2]
    assert (soup.normals[:, 2] > 0.99).all()
    assert soup.areas.sum() == pytest.approx(_polygon_area(SEVEN) + 4.0 + 2.0)


def test_ply_mixed_polygons_ascii_and_binary(tmp_path):
    v = np.concatenate([SEVEN, QUAD])
    head = (
        "ply\nformat {fmt} 1.0\nelement vertex 11\nproperty double x\nproperty double y\nproperty double z\n"
        "element face 3\nproperty list uchar int vertex_indices\nend_header\n"
    )
    faces = [list(range(7)), [7, 8, 9, 10], [0, 1, 2]]
    text = head.format(fmt="ascii") + "\n".join(" ".join(map(str, p)) for p in v) + "\n"
    text += "\n".join(f"{len(f)} " + " ".join(map(str, f)) for f in faces) + "\n"
    a = mio.load(_write(tmp_path / "poly_ascii.ply", text))
    body = v.astype("<f8").tobytes() + b"".join(
        np.uint8(len(f)).tobytes() + np.array(f, "<i4").tobytes() for f in faces
    )
    b = mio.load(_write(tmp_path / "poly_bin.ply", head.format(fmt="binary_little_endian").encode() + body))
    for s in (a, b):
        assert s.source_face.tolist() == [0] * 5 + [1] * 2 + [2]
        assert (s.normals[:, 2] > 0.99).all()
    assert np.array_equal(a.triangles, b.triangles)


# ---------------------------------------------------------------------------- OBJ details
def test_obj_relative_indices(tmp_path):
    text = (
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nf -3 -2 -1\n"
        "v 5 0 0\nv 6 0 0\nv 5 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nf -3/-3 -2/-2 -1/-1\nf 1 -2 -1\n"
    )
    soup = mio.load(_write(tmp_path / "rel.obj", text))
    assert soup.faces.tolist() == [[0, 1, 2], [3, 4, 5], [0, 4, 5]]
    assert np.array_equal(soup.uv[1], [[0, 0], [1, 0], [0, 1]])


def test_two_vertex_records_are_skipped_with_a_warning(tmp_path):
    path = _write(tmp_path / "edge.obj", _TRI + "v 1 1 0\nf 1 2 3\nf 1 2\nf 2 4 3\n")
    with pytest.warns(UserWarning, match="edge.obj: skipped 1 face records with 2 vertices"):
        soup = mio.load(path)
    assert soup.faces.tolist() == [[0, 1, 2], [1, 3, 2]]
    assert soup.source_face.tolist() == [0, 2]  # index of the f record in the file


def test_obj_corner_layouts_colours_groups(tmp_path):
    text = (
        "\n".join(
            [
                "mtllib missing.mtl",
                "v 0 0 0 1 0 0",
                "v 1 0 0 0 1 0",
                "v 0 1 0 0 0 1",
                "v 1 1 0 1 1 1",
                "vt 0 0",
                "vt 1 0",
                "vt 0 1",
                "vn 0 0 1",
                "f 1 2 3",
                "o lid",
                "usemtl shiny",
                "f 1/1/1 2/2/1 3/3/1",
                "g hinge",
                "f 2//1 4//1 3//1  # trailing comment",
                "o body",
                "f 2/2 4/1 3/3",
                "o lid",
                "usemtl dull",
                "f 1/1 2/2 4/3",
            ]
        )
        + "\n"
    )
    soup = mio.load(_write(tmp_path / "layouts.obj", text))
    assert soup.n_faces == 5
    assert soup.part_names == ["layouts", "lid", "lid/hinge", "body"]
    assert soup.part_id.tolist() == [0, 1, 2, 3, 1]
    assert [m.name for m in soup.materials] == ["shiny", "dull"]
    assert soup.material_id.tolist() == [-1, 0, 0, 0, 1]
    assert soup.colors[0, 0].tolist() == [255, 0, 0, 255]
    assert soup.colors[4, 2].tolist() == [255, 255, 255, 255]
    assert np.array_equal(soup.uv[3], [[1, 0], [0, 0], [0, 1]])
    assert np.array_equal(soup.uv[2], np.zeros((3, 2)))  # v//vn has no UV


def test_obj_mixed_layout_rewrite_matches_the_two_regular_expression_passes():
    """The targeted rewrite of mixed corner layouts gives the text of the general one."""
    import random

    from meshvis.io import obj

    forms = {
        "v": lambda v, r: v,
        "vt": lambda v, r: f"{v}/{r.randint(1, 9)}",
        "vtn": lambda v, r: f"{v}/{r.randint(1, 9)}/{r.randint(1, 9)}",
        "vn": lambda v, r: f"{v}/0/{r.randint(1, 9)}",  # '//' is rewritten before
    }
    rng, mixed = random.Random(0), 0
    for _ in range(2000):
        records = []
        for _ in range(rng.randint(1, 8)):
            layout = rng.choice([*forms, "any"])
            corners = [
                forms[layout if layout != "any" else rng.choice(list(forms))](str(rng.randint(-9, 99)), rng)
                for _ in range(rng.randint(2, 5))
            ]
            sep = rng.choice([" ", "  ", "\t"])
            records.append("f" + sep + sep.join(corners) + rng.choice(["", " "]))
        body = "\n".join(records)
        n_corner, slashes = len(body.split()) - len(records), body.count("/")
        if slashes in (0, 2 * n_corner) or (slashes == n_corner and obj._TWO_SLASHES.search(body) is None):
            continue  # one layout: not rewritten
        mixed += 1
        expected = obj._BARE.sub(r"\1/0", obj._THIRD.sub(r"\1", body))
        assert obj._mixed_to_uv(body, n_corner, slashes) == expected, body
    assert mixed > 1000


def test_obj_mtl_and_texture_are_written_back(tmp_path):
    from PIL import Image

    src = tmp_path / "src"
    src.mkdir()
    Image.new("RGB", (4, 4), (200, 10, 10)).save(src / "skin.png")
    _write(src / "m.mtl", "newmtl skin\nKd 1 0.5 0.25\nmap_Kd skin.png\n\nnewmtl plain\nKd 0 1 0\n")
    obj = _write(
        src / "m.obj",
        "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\n"
        "usemtl skin\nf 1/1 2/2 3/3\nusemtl plain\nf 1/1 3/3 2/2\n",
    )
    soup = mio.load(obj)
    assert isinstance(soup.materials[0].source, MtlSource)
    assert soup.materials[0].source.textures() == [("map_Kd", "skin.png")]
    out = tmp_path / "out"
    out.mkdir()
    mio.save(soup, out / "copy.obj")
    assert (out / "copy.mtl").is_file() and (out / "skin.png").is_file()
    back = mio.load(out / "copy.obj")
    assert [m.name for m in back.materials] == ["skin", "plain"]
    assert "Kd 1 0.5 0.25" in back.materials[0].source.text
    assert back.material_id.tolist() == [0, 1]
    assert np.array_equal(back.uv, soup.uv)
    # glTF gets the texture embedded and the colour factor from Kd
    mio.save(soup, out / "copy.glb")
    glb = mio.load(out / "copy.glb")
    assert [m.name for m in glb.materials] == ["skin", "plain"]
    assert getattr(glb.materials[0].source, "baseColorTexture", None) is not None
    # and back from glTF materials to OBJ: a PNG is written next to the MTL
    mio.save(glb, out / "again.obj")
    assert "map_Kd" in open(out / "again.mtl").read()
    assert any(f.startswith("again_skin") for f in os.listdir(out))


# ---------------------------------------------------------------------------- round trips
@pytest.mark.slow
@needs_real
@pytest.mark.parametrize("name", ["bunny10k_textured.obj", "spot.obj"])
@pytest.mark.parametrize("ext", [".obj", ".ply", ".glb", ".gltf", ".off", ".stl"])
def test_round_trip_textured_models(tmp_path, name, ext):
    soup = mio.load(real(name))
    out = tmp_path / ("copy" + ext)
    mio.save(soup, out)
    back = mio.load(out)
    assert back.n_faces == soup.n_faces
    exact = ext in (".obj", ".ply", ".off")
    tol = 0 if exact else 1e-6 * soup.diagonal
    # same faces in the same order (all faces are one part and material here)
    assert np.abs(back.triangles - soup.triangles).max() <= tol
    if ext in (".obj", ".ply", ".glb", ".gltf"):
        assert back.part_names == soup.part_names
        assert np.abs(back.uv - soup.uv).max() <= (0 if exact else 1e-6)
        assert [m.name for m in back.materials] == [m.name for m in soup.materials]
        assert np.array_equal(back.material_id, soup.material_id)


@pytest.mark.parametrize("ext", [".obj", ".ply", ".glb", ".gltf", ".off", ".stl"])
def test_round_trip_generated_soup(tmp_path, ext):
    soup = _colour_soup()
    out = tmp_path / ("gen" + ext)
    mio.save(soup, out)
    back = mio.load(out)
    assert back.n_faces == soup.n_faces
    exact = ext in (".obj", ".ply", ".off")
    assert np.abs(back.triangles - soup.triangles).max() <= (0 if exact else 1e-6)
    if ext == ".stl":
        return
    rgb_only = ext == ".obj"
    k = 3 if rgb_only else 4
    assert np.array_equal(back.colors[..., :k], soup.colors[..., :k])
    if ext == ".off":
        return
    assert back.part_names == soup.part_names
    assert np.array_equal(back.part_id, soup.part_id)
    assert np.abs(back.uv - soup.uv).max() <= (0 if exact else 1e-6)
    names = [back.materials[i].name if i >= 0 else None for i in back.material_id]
    expected = [soup.materials[i].name if i >= 0 else None for i in soup.material_id]
    if ext == ".obj":  # OBJ cannot unset a material: faces after one get "none"
        expected = [e if e is not None else "none" for e in expected]
    assert names == expected


def test_face_groups_and_values(tmp_path):
    soup = _colour_soup()
    groups = np.arange(40) % 3
    values = {"layer": np.arange(40) * 0.5, "hidden": np.arange(40) % 2 == 0}
    mio.save(soup, tmp_path / "g.ply", face_groups=groups, group_names=["a", "b", "c"], face_values=values)
    elements, comments = read_elements(str(tmp_path / "g.ply"), "g.ply")
    assert np.array_equal(elements["face"]["group"], groups)
    assert np.array_equal(elements["face"]["layer"], values["layer"])
    assert np.array_equal(elements["face"]["hidden"], values["hidden"])
    assert "meshvis group 1 b" in comments
    mio.save(soup, tmp_path / "g.glb", face_groups=groups, group_names=["a", "b", "c"])
    glb = mio.load(tmp_path / "g.glb")
    assert glb.part_names == ["a", "b", "c"]
    assert np.bincount(glb.part_id).tolist() == np.bincount(groups).tolist()
    mio.save(soup, tmp_path / "g.obj", face_groups=groups, group_names=["a", "b", "c"])
    obj = mio.load(tmp_path / "g.obj")
    assert np.array_equal(obj.triangles, soup.triangles)
    names = np.array(obj.part_names)[obj.part_id]
    assert names[0] == "body/a" and names[25] == "lid/b"
    with pytest.raises(ParameterError):
        mio.save(soup, tmp_path / "bad.ply", face_groups=np.zeros(3, int))


def test_three_mf_and_scene(tmp_path):
    import trimesh

    scene = trimesh.Scene()
    scene.add_geometry(trimesh.creation.box(), node_name="box", geom_name="box")
    scene.add_geometry(
        trimesh.creation.icosphere(subdivisions=1),
        node_name="ball",
        geom_name="ball",
        transform=trimesh.transformations.translation_matrix([3, 0, 0]),
    )
    soup = as_soup(scene)
    assert sorted(soup.part_names) == ["ball", "box"]
    assert soup.n_faces == 12 + 80
    path = tmp_path / "scene.3mf"
    path.write_bytes(trimesh.exchange.threemf.export_3MF(scene))
    back = mio.load(path)
    assert back.n_faces == 92
    assert back.n_parts == 2
    assert back.bounds[1][0] == pytest.approx(soup.bounds[1][0])


def test_load_name_and_as_soup(tmp_path):
    path = _write(tmp_path / "t.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")
    assert mio.load(path, name="shown.obj").path == "shown.obj"
    assert as_soup(path).n_faces == 1


# ---------------------------------------------------------------------------- bad input
_TRI = "v 0 0 0\nv 1 0 0\nv 0 1 0\n"
_PLY_HEAD = (
    "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
    "element face 1\nproperty list uchar int vertex_indices\nend_header\n"
)

BAD_TEXT = {
    "nan.obj": ("v nan 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", ModelError, "NaN"),
    "inf.obj": ("v 0 inf 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", ModelError, "infinite"),
    "range.obj": (_TRI + "f 1 2 9\n", ModelFormatError, "out of range"),
    "negative.obj": (_TRI + "f -1 -2 -9\n", ModelFormatError, "before the first vertex"),
    "zero.obj": (_TRI + "f 0 1 2\n", ModelFormatError, "index 0"),
    "short.obj": (_TRI + "f 1 2 3\nf 1\n", ModelFormatError, "at least 3"),
    "edges.obj": (_TRI + "f 1 2\n", ModelError, "no faces"),
    "noface.obj": (_TRI, ModelError, "no faces"),
    "blank.obj": ("\n \n\n", ModelError, "no faces"),
    "empty.obj": ("", ModelError, "empty"),
    "badnumber.obj": ("v 0 0 0\nv 1 x 0\nv 0 1 0\nf 1 2 3\n", ModelFormatError, "line 2"),
    "badface.obj": (_TRI + "f 1 2 a\n", ModelFormatError, "line 4"),
    "nan.off": ("OFF\n3 1 0\n0 0 nan\n1 0 0\n0 1 0\n3 0 1 2\n", ModelError, "NaN"),
    "range.off": ("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 5\n", ModelError, "out of range"),
    "short.off": ("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n1 0\n", ModelFormatError, "at least 3"),
    "truncated.off": ("OFF\n3 2 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n", ModelFormatError, "truncated"),
    "range.ply": (_PLY_HEAD + "0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n", ModelError, "out of range"),
    "negative.ply": (_PLY_HEAD + "0 0 0\n1 0 0\n0 1 0\n3 0 -1 2\n", ModelError, "out of range"),
    "short.ply": (_PLY_HEAD + "0 0 0\n1 0 0\n0 1 0\n1 0\n", ModelFormatError, "at least 3"),
    "truncated.ply": (_PLY_HEAD + "0 0 0\n1 0 0\n", ModelFormatError, "truncated"),
    "nan.stl": (
        "solid s\nfacet normal 0 0 1\nouter loop\nvertex nan 0 0\nvertex 1 0 0\nvertex 0 1 0\n"
        "endloop\nendfacet\nendsolid s\n",
        ModelError,
        "NaN",
    ),
    "truncated_ascii.stl": (
        "solid s\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\n",
        ModelFormatError,
        "truncated",
    ),
    "unknown.xyz": (_TRI, ModelFormatError, "unknown file extension"),
    "obj_named.stl": (_TRI + "f 1 2 3\n", ModelFormatError, "looks like OBJ"),
    "obj_named.ply": (_TRI + "f 1 2 3\n", ModelFormatError, "looks like OBJ"),
    "obj_named.glb": (_TRI + "f 1 2 3\n", ModelFormatError, "looks like OBJ"),
    "off_named.obj": ("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n", ModelFormatError, "looks like OFF"),
    "bad.gltf": (
        '{"asset": {"version": "2.0"}, "meshes": [{"primitives": [{"attributes": {"POSITION": 5}}]}]}',
        ModelError,
        "",
    ),
}


def _check(path: str, cls, fragment: str) -> ModelError:
    with pytest.raises(cls) as info, warnings.catch_warnings():
        warnings.simplefilter("ignore")
        mio.load(path)
    msg = str(info.value)
    assert os.path.basename(path) in msg
    assert "\n" not in msg and "Traceback" not in msg
    assert fragment in msg
    return info.value


@pytest.mark.parametrize("name", sorted(BAD_TEXT))
def test_bad_text_files(tmp_path, name):
    text, cls, fragment = BAD_TEXT[name]
    _check(_write(tmp_path / name, text), cls, fragment)


def test_stl_named_obj_is_refused(tmp_path):
    soup = _colour_soup()
    mio.save(soup, tmp_path / "real.stl")
    os.replace(tmp_path / "real.stl", tmp_path / "stl_named.obj")
    _check(str(tmp_path / "stl_named.obj"), ModelFormatError, "looks like STL")


@pytest.mark.parametrize("ext", [".obj", ".ply", ".stl", ".off", ".glb", ".gltf", ".3mf"])
def test_random_bytes(tmp_path, ext):
    data = np.random.default_rng(3).integers(0, 256, 4000, dtype=np.uint8).tobytes()
    _check(_write(tmp_path / ("random" + ext), data), ModelError, "")


@pytest.mark.parametrize("ext", [".obj", ".ply", ".stl", ".off", ".glb", ".gltf", ".3mf"])
def test_empty_files(tmp_path, ext):
    _check(_write(tmp_path / ("empty" + ext), b""), ModelError, "empty")


@needs_real
@pytest.mark.parametrize(
    "name,keep",
    [
        ("pins.glb", 20000),
        ("CesiumMilkTruck.glb", 3000),
        ("pyvista__ant.ply", 9000),
        ("busted.STL", 50000),
        ("cycloidal.ply", 600000),
    ],
)
def test_truncated_real_files(tmp_path, name, keep):
    data = open(real(name), "rb").read()[:keep]
    _check(_write(tmp_path / name, data), ModelFormatError, "truncated")


def test_binary_ply_truncated_in_variable_lists(tmp_path):
    head = (
        "ply\nformat binary_little_endian 1.0\nelement vertex 4\nproperty float x\nproperty float y\n"
        "property float z\nelement face 2\nproperty list uchar int vertex_indices\nend_header\n"
    )
    body = np.eye(4, 3, dtype="<f4").tobytes() + bytes([3]) + np.arange(3, dtype="<i4").tobytes()
    body += bytes([4]) + np.arange(2, dtype="<i4").tobytes()  # second face cut short
    _check(_write(tmp_path / "cut.ply", head.encode() + body), ModelFormatError, "truncated")


def test_folder_missing_and_unreadable(tmp_path, monkeypatch):
    folder = tmp_path / "folder.obj"
    folder.mkdir()
    _check(str(folder), ModelError, "folder")
    _check(str(tmp_path / "missing.obj"), ModelError, "not found")
    path = _write(tmp_path / "locked.obj", _TRI + "f 1 2 3\n")
    if hasattr(os, "geteuid") and os.geteuid() != 0:
        os.chmod(path, 0)
    else:  # root reads everything: simulate the permission error

        def refuse(*args, **kwargs):
            raise PermissionError(13, "Permission denied")

        monkeypatch.setattr(mio.reading, "open", refuse, raising=False)
    err = _check(path, ModelError, "permission denied")
    assert type(err) is ModelError


# ---------------------------------------------------------------------------- writing
def test_atomic_write_keeps_old_file_on_error(tmp_path):
    path = tmp_path / "out.txt"
    path.write_text("old")
    with pytest.raises(RuntimeError), mio.atomic_write(path, "w") as fh:
        fh.write("partial")
        raise RuntimeError("boom")
    assert path.read_text() == "old"
    assert os.listdir(tmp_path) == ["out.txt"]
    with mio.atomic_write(path, "wb") as fh:
        fh.write(b"new")
    assert path.read_bytes() == b"new"
    assert os.listdir(tmp_path) == ["out.txt"]


def test_failed_save_leaves_existing_file(tmp_path, monkeypatch):
    import meshvis.io.obj as io_obj

    soup = _colour_soup()
    path = tmp_path / "keep.obj"
    path.write_text("original")

    def fail(*args, **kwargs):
        raise RuntimeError("disk on fire")

    monkeypatch.setattr(io_obj, "fmt_floats", fail)
    with pytest.raises(RuntimeError):
        mio.save(soup, path)
    assert path.read_text() == "original"
    assert sorted(os.listdir(tmp_path)) == ["keep.obj"]


def test_save_errors(tmp_path, monkeypatch):
    soup = _colour_soup()
    with pytest.raises(OutputError, match="folder does not exist"):
        mio.save(soup, tmp_path / "nope" / "x.obj")
    with pytest.raises(OutputError, match="cannot write"):
        mio.save(soup, tmp_path / "x.fbx")

    def refuse(*args, **kwargs):
        raise PermissionError(13, "Permission denied")

    monkeypatch.setattr(tempfile, "mkstemp", refuse)
    with pytest.raises(OutputError, match="not writable"):
        mio.save(soup, tmp_path / "x.ply")
    assert not (tmp_path / "x.ply").exists()


def test_sniff():
    assert mio.sniff(b"glTF\x02\x00\x00\x00", 100) == "glb"
    assert mio.sniff(b"ply\nformat ascii 1.0\n", 100) == "ply"
    assert mio.sniff(b"# comment\nv 1 2 3\n", 100) == "obj"
    assert mio.sniff(b"COFF\n3 1 0\n", 100) == "off"
    assert mio.sniff(b"solid x\n facet normal 0 0 1\n", 100) == "stl"
    assert mio.sniff(b"\x00" * 80 + np.uint32(2).tobytes(), 184) == "stl"
    assert mio.sniff(b"hello world\n", 12) is None
