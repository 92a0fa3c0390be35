"""Turned-over faces keep shading that matches their winding, in every edit-in-place writer.

Rule under test (every format): the shading normals of a turned face are negated unless
they already lie on its new front (mean dot product with its geometric normal > 0);
unturned faces keep theirs; a vertex shared by turned and unturned faces is copied.
Each test states the exact expected normal of every corner.
"""

import os

import numpy as np
import pytest
from helpers import real_model, validate_gltf, write_glb

import meshvis
from meshvis.io.gltf_edit import _EditState, read_container

HERE = os.path.dirname(__file__)


def _newell(p):
    """(k, 3) polygon normal by Newell's sum of a (k, c, 3) array of corner positions."""
    return np.cross(p, np.roll(p, -1, axis=1)).sum(axis=1)


# ---------------------------------------------------------------------------- OBJ
def _obj(path):
    """Positions, normals (as written) and the records as lists of (v, vn) 0-based."""
    v, vn, recs = [], [], []
    for line in open(path, encoding="latin-1"):
        t = line.partition("#")[0].split()
        if t and t[0] == "v":
            v.append([float(x) for x in t[1:4]])
        elif t and t[0] == "vn":
            vn.append([float(x) for x in t[1:4]])
        elif t and t[0] == "f":
            recs.append([(int(c.split("/")[0]) - 1, int(c.split("/")[2]) - 1) for c in t[1:]])
    return np.array(v), np.array(vn), recs


def _expected_obj_records(path, soup, flip):
    """The records the rule gives: (v, vn value) per corner, in output order."""
    v, vn, recs = _obj(path)
    out = []
    for r, rec in enumerate(recs):
        tris = np.flatnonzero(soup.source_face == r)
        turned = flip[tris]
        corners = np.array(rec)
        if turned.all() or not turned.any():  # a whole record
            order = [0, *range(len(rec) - 1, 0, -1)] if turned.all() else list(range(len(rec)))
            n_geo = _newell(v[corners[order, 0]][None])[0]
            out.append(_turn(v, vn, corners[order], n_geo, turned.all()))
        else:  # split into its triangles
            for t in tris:
                c = soup.source.data.corners[t]
                c = c[[0, 2, 1]] if flip[t] else c
                n_geo = _newell(v[corners[c, 0]][None])[0]
                out.append(_turn(v, vn, corners[c], n_geo, flip[t]))
    return out


def _turn(v, vn, corners, n_geo, turned):
    normals = vn[corners[:, 1]]
    if turned and float(np.mean(normals @ n_geo)) <= 0:
        normals = -normals
    return [(int(a), tuple(b)) for a, b in zip(corners[:, 0], normals)]


def test_obj_turned_faces_point_at_negated_normals(tmp_path):
    src = real_model("suzanne.obj")
    soup = meshvis.load(src)
    flip = np.arange(soup.n_faces) % 3 == 0  # splits many quads: vertices shared by both kinds
    out = str(tmp_path / "suzanne.obj")
    meshvis.save(soup.flipped(flip), out)
    v, vn, recs = _obj(out)
    got = [[(a, tuple(vn[b])) for a, b in rec] for rec in recs]
    assert got == _expected_obj_records(src, soup, flip)
    # the input's lines are all there in order; the copies follow the last vn line
    lines_in = open(src).read().splitlines()
    lines_out = open(out).read().splitlines()
    kept = [ln for ln in lines_out if not ln.startswith("f ")]
    last_vn = max(i for i, ln in enumerate(lines_in) if ln.startswith("vn "))
    n_new = len(vn) - 507
    assert 0 < n_new <= 507
    assert all(ln.startswith("vn ") for ln in kept[last_vn + 1 : last_vn + 1 + n_new])
    assert kept[: last_vn + 1] + kept[last_vn + 1 + n_new :] == [
        ln for ln in lines_in if not ln.startswith("f ")
    ]
    # untouched whole records are the input's lines, byte for byte
    f_in = [ln for ln in lines_in if ln.startswith("f ")]
    whole_kept = [r for r in range(len(f_in)) if not flip[soup.source_face == r].any()]
    f_out_text = {ln for ln in lines_out if ln.startswith("f ")}
    assert all(f_in[r] in f_out_text for r in whole_kept)


def test_obj_orient_of_broken_windings_with_right_normals_gives_the_original(tmp_path):
    src = real_model("suzanne.obj")
    lines = open(src).read().splitlines()
    f_at = [i for i, ln in enumerate(lines) if ln.startswith("f ")]
    broken = list(lines)
    for i in f_at[::7]:  # windings reversed, normals left as they were (an exporter bug)
        c = broken[i].split()[1:]
        broken[i] = " ".join(["f", c[0], *c[:0:-1]])
    bad = str(tmp_path / "broken.obj")
    open(bad, "w").write("\n".join(broken) + "\n")
    soup = meshvis.load(bad)
    r = meshvis.orient(soup)
    expected = np.isin(soup.source_face, np.arange(len(f_at))[::7])
    assert np.array_equal(r.flipped, expected)
    os.mkdir(tmp_path / "out")
    out = str(tmp_path / "out" / "broken.obj")
    meshvis.save(r.soup, out)
    # the records whose normals agreed with their original winding come back as they were;
    # the others (normals that disagreed with the original winding) get negated copies
    v, vn, recs = _obj(src)
    agreed = [
        float(np.mean(vn[[b for _, b in rec]] @ _newell(v[[a for a, _ in rec]][None])[0])) > 0 for rec in recs
    ]
    got = open(out).read().splitlines()
    assert len(got) == len(lines) + len(_obj(out)[1]) - 507  # one line per record, plus the copies
    for r, i in enumerate(f_at):
        if r % 7 or agreed[r]:
            assert lines[i] in got
    assert sum(not agreed[r] for r in range(0, len(recs), 7)) == sum(
        lines[f_at[r]] not in got for r in range(len(recs))
    )


# ---------------------------------------------------------------------------- PLY
def _ply_with_normals(path, ascii):
    """pyvista's ant with float vertex normals and a colour, binary or ASCII."""
    import trimesh

    s = meshvis.load(real_model("pyvista__ant.ply"))
    n, m = len(s.vertices), len(s.faces)
    vn = trimesh.Trimesh(s.vertices, s.faces, process=False).vertex_normals.astype("<f4")
    red = (np.arange(n) % 256).astype("u1")
    fmt = "ascii" if ascii else "binary_little_endian"
    head = [
        "ply", f"format {fmt} 1.0", "comment normals test", f"element vertex {n}",
        "property float x", "property float y", "property float z",
        "property float nx", "property float ny", "property float nz", "property uchar red",
        f"element face {m}", "property list uchar int vertex_indices", "end_header",
    ]  # fmt: skip
    text = "\n".join(head) + "\n"
    if ascii:
        rows = [" ".join(map(str, [*p, *q, int(c)])) for p, q, c in zip(s.vertices.astype("f4"), vn, red)]
        rows += [f"3 {a} {b} {c}" for a, b, c in s.faces]
        open(path, "w").write(text + "\n".join(rows) + "\n")
        return
    vd = np.zeros(n, [("p", "<f4", 3), ("n", "<f4", 3), ("r", "u1")])
    vd["p"], vd["n"], vd["r"] = s.vertices, vn, red
    fd = np.zeros(m, [("k", "u1"), ("i", "<i4", 3)])
    fd["k"], fd["i"] = 3, s.faces
    open(path, "wb").write(text.encode() + vd.tobytes() + fd.tobytes())


def _ply_corners(path):
    from meshvis.io.ply import read_elements

    e, _ = read_elements(path, "x")
    v = e["vertex"]
    pos = np.column_stack([v[k] for k in "xyz"])
    nrm = np.column_stack([v[k] for k in ("nx", "ny", "nz")])
    return pos, nrm, e["face"]["vertex_indices"][1].reshape(-1, 3).astype(np.int64), v["red"]


@pytest.mark.parametrize("ascii", [False, True])
def test_ply_turned_faces_get_negated_or_copied_normals(ascii, tmp_path):
    src = str(tmp_path / "n.ply")
    _ply_with_normals(src, ascii)
    soup = meshvis.load(src)
    flip = np.arange(soup.n_faces) % 3 == 0
    out = str(tmp_path / "o.ply")
    meshvis.save(soup.flipped(flip), out)
    pos0, n0, f0, red0 = _ply_corners(src)
    pos1, n1, f1, red1 = _ply_corners(out)
    nv = len(pos0)
    assert np.array_equal(f1[~flip], f0[~flip])  # untouched rows: the same indices
    assert np.array_equal(f1[flip], np.where(f1[flip] >= nv, f1[flip], f0[flip][:, [0, 2, 1]]))
    # every corner: the same position, the input's normal negated exactly when its face turned
    g0 = np.cross(pos0[f0[:, 1]] - pos0[f0[:, 0]], pos0[f0[:, 2]] - pos0[f0[:, 0]])
    agreed = np.einsum("tcj,tj->t", n0[f0], g0) > 0
    assert agreed.mean() > 0.9
    sign = np.where(flip & agreed, -1.0, 1.0)
    back = f1[:, [0, 2, 1]] * flip[:, None] + f1 * ~flip[:, None]  # corners in input order
    assert np.array_equal(pos1[back], pos0[f0])
    assert np.array_equal(n1[back], n0[f0] * sign[:, None, None])
    assert np.array_equal(red1[back], red0[f0])  # copies carry every property
    # the input vertices: negated in place only where no unturned face uses them
    used_kept = np.isin(np.arange(nv), f0[~flip | ~agreed])
    assert np.array_equal(n1[:nv][used_kept], n0[used_kept])
    assert len(pos1) - nv == int(np.isin(np.arange(nv), f0[flip & agreed]).sum() - (~used_kept).sum())


def test_ply_orient_of_broken_windings_with_right_normals_gives_the_original(tmp_path):
    src = str(tmp_path / "n.ply")
    _ply_with_normals(src, ascii=False)
    data = open(src, "rb").read()
    body = data.index(b"end_header\n") + len(b"end_header\n")
    n = meshvis.load(src).n_vertices
    faces = np.frombuffer(data[body + n * 25 :], [("k", "u1"), ("i", "<i4", 3)]).copy()
    broken = np.arange(len(faces)) % 7 == 0
    faces["i"][broken] = faces["i"][broken][:, [0, 2, 1]]
    bad = str(tmp_path / "broken.ply")
    open(bad, "wb").write(data[: body + n * 25] + faces.tobytes())
    r = meshvis.orient(meshvis.load(bad))
    assert np.array_equal(r.flipped, broken)
    out = str(tmp_path / "o.ply")
    meshvis.save(r.soup, out)
    assert open(out, "rb").read() == data


# ---------------------------------------------------------------------------- glTF
def _primitives(path):
    """Per (node, primitive): positions, normals, tangents (or None), (t, 3) indices."""
    doc, buffers, glb = read_container(path, "x")
    state = _EditState(doc, [bytearray(b) for b in buffers], glb, os.path.dirname(path))
    out = {}
    for i, node in enumerate(doc["nodes"]):
        if "mesh" not in node:
            continue
        for k, prim in enumerate(doc["meshes"][node["mesh"]]["primitives"]):
            a = prim["attributes"]
            tan = state.read_accessor(a["TANGENT"]) if "TANGENT" in a else None
            idx = state.read_accessor(prim["indices"]).reshape(-1, 3).astype(np.int64)
            out[i, k] = (state.read_accessor(a["POSITION"]), state.read_accessor(a["NORMAL"]), tan, idx)
    return doc, out


def _turned_per_primitive(soup, flip):
    """(node, primitive) -> which of its faces ``flip`` turns, from the reader's piece table."""
    pieces = soup.source.data.pieces
    ends = np.append(pieces[1:, 5], soup.n_faces)
    return {(int(p[0]), int(p[2])): flip[p[5] : e] for p, e in zip(pieces, ends)}


def _truck_with_tangents(path):
    """The milk truck with a TANGENT on every primitive: xyz perpendicular to the normal, w = 1."""
    doc, buffers, _ = read_container(real_model("CesiumMilkTruck.glb"), "truck")
    state = _EditState(doc, [bytearray(b) for b in buffers], 0)
    blob = bytearray(buffers[0])
    for mesh in doc["meshes"]:
        for prim in mesh["primitives"]:
            n = state.read_accessor(prim["attributes"]["NORMAL"]).astype(np.float64)
            t = np.cross(n, [0.0, 0.0, 1.0]) + np.cross(n, [0.0, 1.0, 0.0]) * 1e-3
            t /= np.linalg.norm(t, axis=1, keepdims=True)
            data = np.column_stack([t, np.ones(len(t))]).astype("<f4").tobytes()
            blob.extend(b"\x00" * ((-len(blob)) % 4))
            doc["bufferViews"].append({"buffer": 0, "byteOffset": len(blob), "byteLength": len(data)})
            blob.extend(data)
            doc["accessors"].append(
                {
                    "bufferView": len(doc["bufferViews"]) - 1,
                    "componentType": 5126,
                    "count": len(t),
                    "type": "VEC4",
                }
            )
            prim["attributes"]["TANGENT"] = len(doc["accessors"]) - 1
    doc["buffers"][0]["byteLength"] = len(blob)
    write_glb(doc, bytes(blob), path)


def test_gltf_turned_faces_turn_normals_and_tangent_handedness(tmp_path):
    src = str(tmp_path / "truck.glb")
    _truck_with_tangents(src)
    soup = meshvis.load(src)
    flip = np.arange(soup.n_faces) % 5 == 0  # both wheel instances differ: the shared mesh splits
    out = str(tmp_path / "o.glb")
    meshvis.save(soup.flipped(flip), out)
    _, before = _primitives(src)
    doc, after = _primitives(out)
    turned_of = _turned_per_primitive(soup, flip)
    assert before.keys() == after.keys()
    n_split = 0
    for key, (p0, n0, t0, f0) in before.items():
        p1, n1, t1, f1 = after[key]
        turned = turned_of[key]
        assert np.array_equal(f1[~turned], f0[~turned])  # unturned faces: the same corners
        back = np.where(turned[:, None], f1[:, [0, 2, 1]], f1)  # corners in input order
        g0 = np.cross(p0[f0[:, 1]] - p0[f0[:, 0]], p0[f0[:, 2]] - p0[f0[:, 0]])
        agreed = np.einsum("tcj,tj->t", n0[f0].astype(np.float64), g0) > 0
        sign = np.where(turned & agreed, -1.0, 1.0)[:, None, None]
        assert np.array_equal(p1[back], p0[f0])
        assert np.array_equal(n1[back], n0[f0] * sign)
        assert np.array_equal(t1[back][..., :3], t0[f0][..., :3])
        assert np.array_equal(t1[back][..., 3:], t0[f0][..., 3:] * sign)
        n_split += len(p1) - len(p0)
    assert n_split > 0
    assert len(doc["meshes"]) == 3  # the wheels' instances needed different changes
    assert validate_gltf(out)["errors"] == 0


def test_gltf_orient_of_broken_windings_with_right_normals_restores_them(tmp_path):
    src = real_model("CesiumMilkTruck.glb")
    doc, buffers, _ = read_container(src, "truck")
    blob = bytearray(buffers[0])
    state = _EditState(doc, [blob], 0)
    for prim in [p for m in doc["meshes"] for p in m["primitives"]]:
        acc = doc["accessors"][prim["indices"]]
        idx = state.read_accessor(prim["indices"]).reshape(-1, 3)
        turned = np.arange(len(idx)) % 7 == 0
        idx[turned] = idx[turned][:, [0, 2, 1]]  # windings reversed, normals as they were
        at = doc["bufferViews"][acc["bufferView"]].get("byteOffset", 0) + acc.get("byteOffset", 0)
        blob[at : at + idx.nbytes] = idx.astype(idx.dtype.newbyteorder("<")).tobytes()
    bad = str(tmp_path / "broken.glb")
    write_glb(doc, bytes(blob), bad)
    soup = meshvis.load(bad)
    broken = np.zeros(soup.n_faces, bool)
    for p, e in zip(soup.source.data.pieces, np.append(soup.source.data.pieces[1:, 5], soup.n_faces)):
        broken[p[5] : e] = np.arange(e - p[5]) % 7 == 0
    r = meshvis.orient(soup)
    assert np.array_equal(r.flipped, broken)
    out = str(tmp_path / "o.glb")
    meshvis.save(r.soup, out)
    _, orig = _primitives(src)
    d1, fixed = _primitives(out)
    n_disagree = 0
    for key, (p0, n0, _, f0) in orig.items():
        p1, n1, _, f1 = fixed[key]
        g0 = np.cross(p0[f0[:, 1]] - p0[f0[:, 0]], p0[f0[:, 2]] - p0[f0[:, 0]])
        g1 = np.cross(p1[f1[:, 1]] - p1[f1[:, 0]], p1[f1[:, 2]] - p1[f1[:, 0]])
        assert np.array_equal(g1, g0)  # the original windings, on the same positions
        assert np.array_equal(p1[f1], p0[f0])
        # normals as in the original, except on broken faces whose normals disagreed with
        # the original winding: those lay on the broken front, so they turned with the face
        agreed = np.einsum("tcj,tj->t", n0[f0].astype(np.float64), g0) > 0
        turned = np.arange(len(f0)) % 7 == 0
        sign = np.where(turned & ~agreed, -1.0, 1.0)[:, None, None]
        assert np.array_equal(n1[f1], n0[f0] * sign)
        n_disagree += int((turned & ~agreed).sum())
    assert n_disagree < 0.01 * soup.n_faces
    assert validate_gltf(out)["errors"] == 0


def test_obj_relative_normal_indices_resolve_and_stay_valid(tmp_path):
    # two triangles sharing an edge, normals given by relative (negative) indices
    src = tmp_path / "rel.obj"
    src.write_text(
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nvn 0 0 1\nvn 0 0 1\nvn 0 0 1\n"
        "f 1//-3 2//-2 3//-1\nvn 0 0 1\nf 2//-1 4//-1 3//-1\n"
    )
    soup = meshvis.load(str(src))
    os.mkdir(tmp_path / "out")
    out = str(tmp_path / "out" / "rel.obj")
    meshvis.save(soup.flipped(np.array([True, False])), out)
    lines = open(out).read().splitlines()
    # a later face counts back: the copies go to the end, so its -1 still means the 4th normal
    assert lines[:9] == src.read_text().splitlines()[:7] + ["f 1//5 3//6 2//7", "vn 0 0 1"]
    assert lines[9:] == ["f 2//-1 4//-1 3//-1", "vn -0 -0 -1", "vn -0 -0 -1", "vn -0 -0 -1"]


def test_ply_copies_that_would_overflow_the_index_type_are_not_made(tmp_path):
    g = np.stack(np.meshgrid(np.arange(16.0), np.arange(16.0)), -1).reshape(-1, 2)
    v = np.column_stack([g, np.zeros(256)]).astype("<f4")  # 256 vertices: uchar indices are full
    q = (np.arange(15)[:, None] * 16 + np.arange(15)).reshape(-1)
    f = np.concatenate([np.stack([q, q + 1, q + 17], 1), np.stack([q, q + 17, q + 16], 1)])
    head = (
        "ply\nformat binary_little_endian 1.0\nelement vertex 256\nproperty float x\nproperty float y\n"
        "property float z\nproperty float nx\nproperty float ny\nproperty float nz\n"
        f"element face {len(f)}\nproperty list uchar uchar vertex_indices\nend_header\n"
    )
    vd = np.zeros(256, [("p", "<f4", 3), ("n", "<f4", 3)])
    vd["p"], vd["n"] = v, [0, 0, 1]
    fd = np.zeros(len(f), [("k", "u1"), ("i", "u1", 3)])
    fd["k"], fd["i"] = 3, f
    src = tmp_path / "grid.ply"
    src.write_bytes(head.encode() + vd.tobytes() + fd.tobytes())
    soup = meshvis.load(str(src))
    flip = np.arange(soup.n_faces) < len(q)  # the first triangle of every quad
    out = str(tmp_path / "o.ply")
    with pytest.warns(UserWarning, match="keep their normals"):
        meshvis.save(soup.flipped(flip), out)
    pos, n, faces, _ = _ply_corners_no_red(out)
    assert len(pos) == 256 and faces.max() <= 255
    only_turned = ~np.isin(np.arange(256), f[~flip])
    assert 0 < only_turned.sum() < 256
    assert np.array_equal(n[only_turned, 2], -np.ones(only_turned.sum())) and (n[~only_turned, 2] == 1).all()


def _ply_corners_no_red(path):
    from meshvis.io.ply import read_elements

    e, _ = read_elements(path, "x")
    v = e["vertex"]
    pos = np.column_stack([v[k] for k in "xyz"])
    nrm = np.column_stack([v[k] for k in ("nx", "ny", "nz")])
    return pos, nrm, e["face"]["vertex_indices"][1].reshape(-1, 3).astype(np.int64), None
