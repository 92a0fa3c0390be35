"""OBJ round trips on real models: a repair edits the face records, every other line stays."""

import os
from collections import Counter

import numpy as np
import pytest
from helpers import real_model

import meshvis

MODELS = ["spot.obj", "suzanne.obj", "bunny10k_textured.obj"]
#: statements a face edit never touches (mtllib is rewritten to the output's MTL file)
KEPT = ("v", "vt", "vn", "vp", "s", "o", "g", "usemtl", "#", "l")


def _lines(path):
    with open(path, encoding="latin-1") as fh:
        return fh.read().splitlines()


def _non_face_lines(path):
    """Every line that is not a face record or mtllib, in order (comments included)."""
    out = []
    for line in _lines(path):
        word = line.split(None, 1)[0] if line.split() else ""
        if word not in ("f", "mtllib"):
            out.append(line)
    return out


def _without_normal_copies(lines_out, lines_in):
    """``lines_out`` without the negated ``vn`` copies a turned face adds after the last ``vn`` line."""
    is_vn = [ln.startswith("vn ") for ln in lines_in]
    if not any(is_vn):
        return lines_out
    last = max(i for i, x in enumerate(is_vn) if x)
    n_new = sum(ln.startswith("vn ") for ln in lines_out) - sum(is_vn)
    return lines_out[: last + 1] + lines_out[last + 1 + n_new :]


def _keyword_counts(path):
    return Counter(line.split(None, 1)[0] if line.split() else "" for line in _lines(path))


def _sorted_triangles(soup):
    t = np.round(soup.triangles, 6).reshape(len(soup.faces), 9)
    return t[np.lexsort(t.T[::-1])]


@pytest.mark.parametrize("name", MODELS)
def test_unchanged_repair_writes_the_input_lines(name, tmp_path):
    src = real_model(name)
    out = str(tmp_path / name)  # same stem: no part name to keep
    meshvis.save(meshvis.load(src), out)
    a = [ln for ln in _lines(src) if not ln.startswith("mtllib")]
    b = [ln for ln in _lines(out) if not ln.startswith("mtllib")]
    assert a == b
    assert abs(os.path.getsize(out) - os.path.getsize(src)) <= 0.05 * os.path.getsize(src)


@pytest.mark.parametrize("name", MODELS)
def test_removal_and_flips_change_only_those_faces(name, tmp_path):
    src = real_model(name)
    soup = meshvis.load(src)
    flip = np.arange(soup.n_faces) % 2 == 0
    result = soup.flipped(flip).subset(np.arange(soup.n_faces) % 3 != 0)
    out = str(tmp_path / name)
    meshvis.save(result, out)
    assert _without_normal_copies(_non_face_lines(out), _non_face_lines(src)) == _non_face_lines(src)
    back = meshvis.load(out)
    assert np.array_equal(_sorted_triangles(back), _sorted_triangles(result))
    if back.uv is not None:
        assert np.array_equal(
            np.sort(back.uv.reshape(-1, 6), axis=0), np.sort(result.uv.reshape(-1, 6), axis=0)
        )


def test_suzanne_keeps_normals_comments_and_quads(tmp_path):
    src = real_model("suzanne.obj")
    soup = meshvis.load(src)
    out = str(tmp_path / "s.obj")
    r = meshvis.orient(soup)
    meshvis.save(r.soup, out)
    a, b = _keyword_counts(src), _keyword_counts(out)
    assert a["vn"] == b["vn"] == 507
    assert b["#"] == a["#"] > 0  # comments
    # a quad stays a quad unless orient turned only one of its triangles over
    n_tri = np.bincount(soup.source_face)
    n_flip = np.bincount(soup.source_face, weights=r.flipped)
    mixed = (n_flip > 0) & (n_flip < n_tri)
    assert b["f"] == a["f"] + int((n_tri[mixed] - 1).sum())
    assert mixed.sum() < 0.01 * len(n_tri)


def test_smoothing_groups_objects_and_materials_are_kept(tmp_path):
    src = real_model("chair_model.obj")
    soup = meshvis.load(src)
    out = str(tmp_path / "c.obj")
    meshvis.save(soup.subset(np.arange(soup.n_faces) % 2 == 0), out)
    a, b = _keyword_counts(src), _keyword_counts(out)
    assert a["s"] > 0 and all(a[k] == b[k] for k in KEPT)


def test_a_turned_over_polygon_stays_one_polygon(tmp_path):
    src = real_model("suzanne.obj")
    soup = meshvis.load(src)
    first_quad = soup.source_face == soup.source_face[np.argmax(np.bincount(soup.source_face) == 2)]
    out = str(tmp_path / "s.obj")
    meshvis.save(soup.flipped(first_quad), out)
    records_in = [ln for ln in _lines(src) if ln.startswith("f ")]
    records_out = [ln for ln in _lines(out) if ln.startswith("f ")]
    assert len(records_in) == len(records_out)
    changed = [(x, y) for x, y in zip(records_in, records_out) if x != y]
    assert len(changed) == 1
    x, y = changed[0][0].split()[1:], changed[0][1].split()[1:]
    assert len(x) == 4 and [c.split("/")[0] for c in y] == [c.split("/")[0] for c in [x[0], *x[:0:-1]]]
    # its normals: four negated copies appended after the input's 507 (tests/io/test_turned_normals.py)
    assert sorted(int(c.split("/")[2]) for c in y) == [508, 509, 510, 511]


def test_a_partly_kept_polygon_becomes_its_kept_triangles(tmp_path):
    src = real_model("suzanne.obj")
    soup = meshvis.load(src)
    quad = int(np.flatnonzero(np.bincount(soup.source_face) == 2)[0])
    drop = np.flatnonzero(soup.source_face == quad)[0]
    out = str(tmp_path / "s.obj")
    meshvis.save(soup.subset(np.arange(soup.n_faces) != drop), out)
    records = [ln for ln in _lines(out) if ln.startswith("f ")]
    assert len(records) == len([ln for ln in _lines(src) if ln.startswith("f ")])
    assert sum(len(r.split()) == 4 for r in records) == 1 + sum(
        len(r.split()) == 4 for r in _lines(src) if r.startswith("f ")
    )
