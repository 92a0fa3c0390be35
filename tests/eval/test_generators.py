"""Tests of the ground-truth generators and the sample models folder.

Besides shapes and determinism, the truth is checked against an independent computation:
the generalised winding number of the model's closed parts at points pushed just off
each face, which says how many closed shells enclose each side.  A side is outside
exactly when no shell encloses it, and the layer is one more than the smaller count.
"""

from __future__ import annotations

import importlib.util
import re
from pathlib import Path

import igl
import numpy as np
import pytest

from meshvis.errors import ModelError, ParameterError
from meshvis.eval import generators as g
from meshvis.eval.generators import GroundTruth, closed
from meshvis.geometry.adjacency import weld
from meshvis.soup import Soup, validate

ROOT = Path(__file__).resolve().parents[2]
MODELS = ROOT / "models"

# small settings for the slow-ish generators; defaults are exercised by test_defaults
SMALL = {
    "nested_shells": dict(subdivisions=2),
    "house": dict(cell=1.0),
    "cracked_box": dict(cell=0.125),
    "box_with_opening": dict(cell=0.125),
    "cup": dict(sections=24),
    "terrain": dict(n=20),
    "overlapping_solids": dict(subdivisions=3, cell=0.2),
    "sphere_pair": dict(subdivisions=3),
    "assembly": dict(sections=12, cell=0.4),
}
SEEDED = ["nested_shells", "house", "cracked_box", "terrain", "overlapping_solids", "sphere_pair"]


@pytest.fixture(scope="module")
def small():
    return {name: g.GENERATORS[name](**kw) for name, kw in SMALL.items()}


def _winding_sides(closed: Soup, query: Soup, eps: float) -> tuple[np.ndarray, np.ndarray]:
    """Winding number of ``closed`` at the points ``eps`` in front of and behind every face
    of ``query`` (exact libigl evaluation)."""
    c = query.triangles.mean(axis=1)
    n = query.normals
    q = np.concatenate([c + eps * n, c - eps * n])
    w = igl.winding_number(closed.vertices, closed.faces, q)
    return w[: len(c)], w[len(c) :]


def _assert_truth_matches_winding(t: GroundTruth, closed_mask: np.ndarray | None = None, tol: float = 0.3):
    """outside <=> no enclosing shell; layer = 1 + min count; outward points to the smaller count."""
    closed_mask = np.ones(t.n_faces, bool) if closed_mask is None else closed_mask
    closed = t.soup.subset(closed_mask)
    check = closed_mask & ~t.ambiguous
    q = t.soup.subset(check)
    wf, wb = _winding_sides(closed, q, 1e-6 * t.soup.diagonal)
    # the winding numbers are near integers away from ambiguous faces
    assert np.all(np.abs(wf - np.rint(wf)) < tol) and np.all(np.abs(wb - np.rint(wb)) < tol)
    wf, wb = np.rint(wf), np.rint(wb)
    np.testing.assert_array_equal(t.outside[check, 0], wf == 0)
    np.testing.assert_array_equal(t.outside[check, 1], wb == 0)
    np.testing.assert_array_equal(t.layer[check], 1 + np.minimum(wf, wb))
    # orientation truth: the outward side is the less enclosed one (ties: a convention)
    out = t.outward[check]
    assert np.all(out[wf < wb]) and not np.any(out[wf > wb])
    return wf, wb


def _canonical(tri: np.ndarray) -> np.ndarray:
    """(m, 9) key of a triangle up to cyclic rotation (winding kept): smallest corner first."""
    m = len(tri)
    c = tri.reshape(-1, 3)
    order = np.lexsort((c[:, 2], c[:, 1], c[:, 0], np.repeat(np.arange(m), 3)))
    first = order[::3] % 3  # lexicographically smallest corner of every triangle
    idx = (first[:, None] + np.arange(3)[None]) % 3
    return tri[np.arange(m)[:, None], idx].reshape(m, 9)


# ============================================================================ basic validity
@pytest.mark.slow
@pytest.mark.parametrize("name", list(SMALL))
def test_valid_soup_and_truth_shapes(small, name):
    t = small[name]
    s = t.soup
    m = s.n_faces
    validate(s.vertices, s.faces)
    assert s.vertices.dtype == np.float64 and np.isfinite(s.vertices).all()
    assert s.faces.min() >= 0 and s.faces.max() < s.n_vertices
    assert t.outside.shape == (m, 2) and t.outside.dtype == bool
    assert t.layer.shape == (m,) and t.outward.shape == (m,) and t.two_sided.shape == (m,)
    assert t.ambiguous.shape == (m,)
    assert np.all(s.areas > 0), "degenerate faces"
    assert t.check() == []
    assert t.name == name and t.notes
    # meaningful part names, one per part id in use
    assert len(s.part_names) == int(s.part_id.max()) + 1
    assert not any(re.fullmatch(r"part\d+", n) for n in s.part_names)
    assert set(np.unique(s.part_id)) == set(range(len(s.part_names)))
    assert t.visible.any()
    assert t.ambiguous.mean() < 0.3


@pytest.mark.parametrize(
    "name",
    [
        "nested_shells",
        "house",
        "cracked_box",
        "box_with_opening",
        "cup",
        "terrain",
        "overlapping_solids",
        "sphere_pair",
    ],
)
@pytest.mark.slow
def test_defaults_size(name):
    t = g.GENERATORS[name]()
    assert 1000 <= t.n_faces <= 20000
    assert t.check() == []


@pytest.mark.slow
def test_assembly_default_size_and_parts():
    t = g.assembly()
    s = t.soup
    assert 1000 <= t.n_faces <= 20000
    assert 25 <= s.n_parts <= 40
    assert g.is_closed(s)
    # sizes spread over more than an order of magnitude
    diag = np.array(
        [np.linalg.norm(np.ptp(s.triangles[s.part_id == p].reshape(-1, 3), axis=0)) for p in range(s.n_parts)]
    )
    assert diag.max() / diag.min() > 10
    names = s.part_names
    hidden_frac = np.array([t.hidden[s.part_id == p].mean() for p in range(s.n_parts)])
    assert all(hidden_frac[names.index(f"piston_{i}")] == 1 for i in range(1, 5))
    assert 0.2 < hidden_frac[names.index("bolt_1")] < 0.8  # half sunk into the valve cover
    assert hidden_frac[names.index("air_filter")] < 0.5


@pytest.mark.slow
@pytest.mark.parametrize("name", SEEDED)
def test_deterministic(name):
    kw = SMALL[name]
    a, b = g.GENERATORS[name](seed=3, **kw), g.GENERATORS[name](seed=3, **kw)
    c = g.GENERATORS[name](seed=4, **kw)
    for x in ("outside", "layer", "outward", "two_sided", "ambiguous"):
        np.testing.assert_array_equal(getattr(a, x), getattr(b, x))
    np.testing.assert_array_equal(a.soup.vertices, b.soup.vertices)
    np.testing.assert_array_equal(a.soup.faces, b.soup.faces)
    assert a.soup.part_names == b.soup.part_names
    assert c.soup.n_vertices != a.soup.n_vertices or not np.array_equal(c.soup.vertices, a.soup.vertices)


# ============================================================================ truth against winding numbers
@pytest.mark.slow
def test_nested_shells_truth(small):
    t = small["nested_shells"]
    assert g.is_closed(t.soup)
    wf, wb = _assert_truth_matches_winding(t)
    np.testing.assert_array_equal(t.layer, 1 + wf)
    assert t.outward.all() and np.all(wb == wf + 1)
    assert t.layer.max() == 3 and t.visible.sum() == np.sum(t.soup.part_id == 0)
    for kind in ("box", "mixed"):
        tb = g.nested_shells(n=4, kind=kind)
        assert g.is_closed(tb.soup) and tb.check() == []
        _assert_truth_matches_winding(tb)


def test_nested_shells_bad_arguments():
    with pytest.raises(ParameterError):
        g.nested_shells(n=0)
    with pytest.raises(ParameterError):
        g.nested_shells(kind="torus")


def test_house_truth(small):
    t = small["house"]
    s = t.soup
    names = s.part_names
    partition = s.part_id == names.index("partition")
    # every room, piece of furniture, the cabinet, the safe and the roof is closed
    for p, name in enumerate(names):
        if name != "partition":
            assert g.is_closed(s.subset(s.part_id == p)), name
    wf, wb = _assert_truth_matches_winding(t, ~partition)
    check = ~partition & ~t.ambiguous
    # hidden room walls tie (a room on each side) and face into their room: outward False
    assert np.any(wf == wb) and not np.any(t.outward[check][wf == wb])
    rooms = np.array([names[p].startswith("room_") for p in s.part_id])
    assert np.any(rooms & t.hidden) and np.all(t.outward[rooms & t.visible])
    assert np.all(t.layer[s.part_id == names.index("safe")] == 3)
    assert np.all(t.two_sided[partition]) and np.all(t.hidden[partition]) and np.all(t.layer[partition] == 2)
    assert np.all(t.hidden[~rooms & (s.part_id != names.index("roof"))])
    # every hidden room face has a coplanar, oppositely facing duplicate in another part
    n = s.normals
    axis = np.argmax(np.abs(n), axis=1)
    value = s.triangles[np.arange(s.n_faces), 0, axis]
    sign = np.sign(n[np.arange(s.n_faces), axis]).astype(int)
    planes = {}
    for a, v, sg, p in zip(axis.tolist(), value.tolist(), sign.tolist(), s.part_id.tolist()):
        planes.setdefault((a, v, sg), set()).add(p)
    for f in np.flatnonzero(rooms & t.hidden):
        other = planes.get((int(axis[f]), float(value[f]), -int(sign[f])), set()) - {int(s.part_id[f])}
        assert other, f"hidden room face {f} has no coplanar duplicate"
    assert t.ambiguous.any()


def test_house_rejects_enclosed_rooms():
    with pytest.raises(ParameterError):
        g.house(rooms=(3, 3), floors=2)
    t = g.house(rooms=(3, 3), floors=1, cell=1.5, furniture=0, partition=False)
    assert t.check() == []


def test_overlapping_solids_truth(small):
    t = small["overlapping_solids"]
    s = t.soup
    assert g.is_closed(s)
    _assert_truth_matches_winding(t)
    sphere, box = s.part_id == 0, s.part_id == 1
    # winding number of the *other* solid at the centroids: ~1 for hidden, ~0 for visible
    c = s.triangles.mean(axis=1)
    w = np.empty(s.n_faces)
    w[sphere] = igl.winding_number(s.vertices, s.faces[box], c[sphere])
    w[box] = igl.winding_number(s.vertices, s.faces[sphere], c[box])
    ok = ~t.ambiguous
    assert np.all(np.abs(w[ok & t.hidden] - 1) < 0.05)
    assert np.all(np.abs(w[ok & t.visible]) < 0.05)
    # analytic: box faces well inside the unit sphere are hidden, well outside visible
    r = np.linalg.norm(c, axis=1)
    assert np.all(t.hidden[box & (r < 0.95)]) and np.all(t.visible[box & (r > 1.0)])
    assert 0.05 < t.hidden[sphere].mean() < 0.5 and 0.05 < t.hidden[box].mean() < 0.5


@pytest.mark.slow
def test_assembly_truth(small):
    t = small["assembly"]
    assert g.is_closed(t.soup)
    _assert_truth_matches_winding(t)


def test_sphere_pair_truth(small):
    t = small["sphere_pair"]
    s = t.soup
    outer, inner = s.part_id == 0, s.part_id == 1
    assert outer.sum() == 20 * 4**3 - 6
    assert not g.is_closed(s.subset(outer), oriented=False)
    assert g.is_closed(s.subset(inner))
    assert np.all(np.linalg.norm(s.vertices[s.faces[inner]], axis=-1) < 0.6)
    # the hole is small: winding numbers stay near integers, truth as for a closed pair
    _assert_truth_matches_winding(t, tol=0.3)
    assert np.all(t.layer[inner] == 2) and np.all(t.hidden[inner]) and np.all(t.visible[outer])


def test_cracked_box_truth(small):
    t = small["cracked_box"]
    s = t.soup
    box = s.part_id == 0
    sheet = s.subset(box)
    assert not g.is_closed(sheet, oriented=False)
    # the sheet is 6 sides + 3 extra cracks = 9 separate pieces with slits between them
    labels = closed._components(sheet)
    assert labels.max() + 1 == 9
    from scipy.spatial import cKDTree

    V = sheet.triangles.reshape(-1, 3)
    lab = np.repeat(labels, 3)
    gap = 1e-3 * np.linalg.norm([2.0, 1.5, 1.0])
    nearest = np.inf
    for k in range(labels.max() + 1):
        d, _ = cKDTree(V[lab != k]).query(V[lab == k])
        nearest = min(nearest, d.min())
    assert 0.999 * gap < nearest < 1.001 * gap
    _assert_truth_matches_winding(t, tol=0.3)
    assert np.all(t.hidden[~box]) and np.all(t.layer[~box] == 2)


def test_box_with_opening_truth(small):
    t = small["box_with_opening"]
    s = t.soup
    cave = s.part_id == 0
    assert np.all(t.outside[cave]) and np.all(t.two_sided[cave])
    assert np.all(t.visible) and np.all(t.layer == 1)
    # the only boundary of the sheet is the opening's rim, in the plane y = -0.75
    tri = s.subset(cave)
    k = weld(tri.vertices, tri.faces, 0.0)[1]
    e = np.sort(np.stack([k, k[:, [1, 2, 0]]], -1).reshape(-1, 2), axis=1)
    uniq, count = np.unique(e, axis=0, return_counts=True)
    border = uniq[count == 1]
    pos = tri.triangles.reshape(-1, 3)[np.unique(k.ravel(), return_index=True)[1]]
    assert len(border) and np.allclose(pos[border.ravel()][:, 1], -0.75)
    # missing area ~ opening**2 of the side
    missing = 2.0 * 1.0 - tri.areas[np.isclose(tri.triangles[:, :, 1], -0.75).all(1)].sum()
    assert abs(missing - 0.6**2 * 2.0) < 0.15 * 2.0
    with pytest.raises(ParameterError):
        g.box_with_opening(side="top")


def test_cup_and_terrain(small):
    c = small["cup"]
    s = c.soup
    assert np.all(c.two_sided) and np.all(c.outside)
    # front faces away from the axis / downward
    d = s.triangles.mean(axis=1) - [0, 0, 0.6]
    assert np.all(np.einsum("ij,ij->i", s.normals, d) > 0)
    assert np.all(s.normals[s.triangles[:, :, 2].max(1) == 0][:, 2] < -0.999)
    assert not g.is_closed(s, oriented=False)
    t = small["terrain"]
    assert np.all(t.soup.normals[:, 2] > 0)
    assert np.all(t.outside[:, 0]) and not t.outside[:, 1].any()
    z = t.soup.vertices[:, 2]
    assert t.hints["inside_points"].shape == (1, 3) and t.hints["inside_points"][0, 2] < z.min()
    assert t.hints["outside_points"][0, 2] > z.max()


# ============================================================================ soupify
@pytest.mark.parametrize("unweld,shuffle", [(True, True), (False, False)])
def test_soupify_bookkeeping(small, unweld, shuffle):
    t = small["overlapping_solids"]
    s = g.soupify(t, flip=0.3, unweld=unweld, shuffle=shuffle, duplicate=0.1, seed=5)
    m0, m = t.n_faces, s.n_faces
    assert m == m0 + round(0.1 * m0)
    assert s.check() == []
    assert s.flipped.sum() == round(0.3 * m)
    o, f = s.origin_face, s.flipped
    # every output face is its origin, turned over exactly where flipped, corners rotated
    orig = t.soup.triangles[o]
    orig = np.where(f[:, None, None], orig[:, [0, 2, 1]], orig)
    np.testing.assert_array_equal(_canonical(s.soup.triangles), _canonical(orig))
    np.testing.assert_allclose(s.soup.normals, np.where(f[:, None], -1, 1) * t.soup.normals[o], atol=1e-12)
    np.testing.assert_array_equal(s.outward, t.outward[o] ^ f)
    np.testing.assert_array_equal(s.outside, np.where(f[:, None], t.outside[o][:, ::-1], t.outside[o]))
    np.testing.assert_array_equal(s.layer, t.layer[o])
    np.testing.assert_array_equal(s.soup.part_id, t.soup.part_id[o])
    # multiset of triangles up to orientation: the input plus the duplicated faces
    assert np.all(np.bincount(o, minlength=m0) >= 1) and np.all(np.bincount(o, minlength=m0) <= 2)
    if unweld:
        assert s.soup.n_vertices == 3 * m
        np.testing.assert_array_equal(s.soup.faces.ravel(), np.arange(3 * m))
    if shuffle:
        assert not np.all(np.diff(o) >= 0)
    else:
        assert np.all(np.diff(o[:m0]) > 0)
    # the oriented soup is the original orientation again
    np.testing.assert_allclose(
        s.oriented().normals, np.where(t.outward[o], 1, -1)[:, None] * t.soup.normals[o], atol=1e-12
    )


def test_soupify_holes_and_winding():
    t = g.nested_shells(subdivisions=3)  # holes of ~13 faces stay small against 1280 per shell
    s = g.soupify(t, flip=0.5, holes=3, seed=2)
    assert t.n_faces - 3 * 13 <= s.n_faces < t.n_faces - 3
    assert len(np.unique(s.origin_face)) == s.n_faces
    assert s.check() == []
    # the truth still agrees with winding numbers once faces are turned outward again
    fixed = s.flip_faces(~s.outward)
    assert fixed.outward.all()
    _assert_truth_matches_winding(fixed, tol=0.3)
    # same seed, same soup
    s2 = g.soupify(t, flip=0.5, holes=3, seed=2)
    np.testing.assert_array_equal(s.soup.vertices, s2.soup.vertices)
    np.testing.assert_array_equal(s.origin_face, s2.origin_face)
    with pytest.raises(ParameterError):
        g.soupify(t, flip=1.5)


def test_from_closed_mesh(small):
    t = small["nested_shells"]
    c = g.from_closed_mesh(t.soup)
    np.testing.assert_array_equal(c.layer, t.layer)
    np.testing.assert_array_equal(c.outside, t.outside)
    assert c.outward.all()
    # an inside-out copy is recognised as such
    inv = g.from_closed_mesh(t.soup.flipped(np.ones(t.n_faces, bool)))
    assert not inv.outward.any() and np.array_equal(inv.outside[:, 1], t.outside[:, 0])
    # open or inconsistently wound models have no truth
    with pytest.raises(ModelError):
        g.from_closed_mesh(small["terrain"].soup)
    with pytest.raises(ModelError):
        g.from_closed_mesh(g.soupify(t, flip=0.3, seed=0).soup)
    # an unwelded, shuffled copy is still closed once welded: same answer per face
    sh = g.soupify(t, flip=0.0, seed=3)
    c2 = g.from_closed_mesh(sh.soup)
    np.testing.assert_array_equal(c2.layer, sh.layer)
    np.testing.assert_array_equal(c2.outside, sh.outside)
    # and the soup of a closed model keeps consistent truth
    soup = g.soupify(c, flip=0.2, duplicate=0.05, seed=1)
    assert soup.check() == []


def _exact_sides_winding(V, F, faces, eps):
    """Exact winding number of (V, F) just in front of and behind the centroids of ``faces``."""
    import igl

    t = V[F[faces]]
    c = t.mean(axis=1)
    n = np.cross(t[:, 1] - t[:, 0], t[:, 2] - t[:, 0])
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    w = np.asarray(igl.winding_number(V, F, np.concatenate([c + eps * n, c - eps * n])))
    return w[: len(faces)], w[len(faces) :]


@pytest.mark.slow
def test_from_closed_real_model():
    path = ROOT.parent / "shared" / "models" / "real" / "cow.obj"
    if not path.exists():
        pytest.skip("real models not available")
    t = g.from_closed_mesh(path)
    s = t.soup
    assert t.outward.all() and t.check() == []
    # cow.obj crosses itself: crossing faces have no single answer
    from meshvis.geometry.intersect import intersection_flags

    crossing = intersection_flags(s.vertices, s.faces)["intersects"]
    assert crossing.sum() > 50 and np.all(t.ambiguous[crossing])
    # faces inside the cow's own fold are hidden: checked with the exact winding number
    fold = t.hidden & ~t.ambiguous
    assert 0 < fold.sum() < 20
    front, back = _exact_sides_winding(s.vertices, s.faces, np.flatnonzero(fold), 1e-4 * s.diagonal)
    assert np.all(front > 0.5) and np.all(back > 1.5)
    # every other face is the plain surface: layer 1, outside in front
    rest = ~t.ambiguous & ~fold
    assert np.all(t.layer[rest] == 1) and t.outside[rest, 0].all() and not t.outside[rest, 1].any()
    sample = np.flatnonzero(rest)[::50]
    front, back = _exact_sides_winding(s.vertices, s.faces, sample, 1e-4 * s.diagonal)
    assert np.all(np.abs(front) < 0.5) and np.all(np.abs(back - 1) < 0.5)


@pytest.mark.slow
def test_skin_and_ribcage():
    try:
        t = g.skin_and_ribcage(ROOT.parent / "shared" / "models" / "real")
    except FileNotFoundError:
        pytest.skip("real models not available")
    s = t.soup
    skin, ribs = s.part_id == 0, s.part_id == 1
    assert t.check() == [] and s.part_names == ["skin", "ribcage"]
    assert np.all(t.visible[skin]) and np.all(t.layer[skin] == 1)
    assert t.hidden[ribs].mean() > 0.99 and np.all(t.layer[ribs & t.hidden] >= 2)
    # bones sink into each other: a rib face is one layer deeper per bone around it
    deep = np.flatnonzero(ribs & ~t.ambiguous & (t.layer >= 3))
    shallow = np.flatnonzero(ribs & ~t.ambiguous & (t.layer == 2))[::200]
    assert len(deep) > 100
    rib_soup = s.subset(np.flatnonzero(ribs)).flipped(~t.outward[ribs])  # every bone outward
    first = np.flatnonzero(ribs)[0]
    for faces, depth in ((deep[::10], t.layer[deep[::10]] - 2), (shallow, 0)):
        front, _ = _exact_sides_winding(rib_soup.vertices, rib_soup.faces, faces - first, 1e-5 * s.diagonal)
        np.testing.assert_array_equal(np.rint(front), depth)


def test_skin_and_ribcage_missing(tmp_path):
    with pytest.raises(FileNotFoundError):
        g.skin_and_ribcage(tmp_path)


# ============================================================================ truth files and models/
def test_truth_arrays_round_trip(small, tmp_path):
    t = g.soupify(small["terrain"], flip=0.4, seed=0)
    p = tmp_path / "t.truth.npz"
    t.save_arrays(p)
    first = p.read_bytes()
    t.save_arrays(p)
    assert p.read_bytes() == first  # byte for byte
    back = GroundTruth.load_arrays(p, t.soup)
    for x in ("outside", "layer", "outward", "two_sided", "ambiguous", "origin_face", "flipped"):
        np.testing.assert_array_equal(getattr(back, x), getattr(t, x))
    np.testing.assert_array_equal(back.hints["inside_points"], t.hints["inside_points"])
    assert back.name == t.name and back.notes == t.notes
    with pytest.raises(ModelError):
        GroundTruth.load_arrays(p, small["cup"].soup)


def _make_models_module():
    spec = importlib.util.spec_from_file_location("make_models", MODELS / "make_models.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def test_models_folder_is_current_and_small(tmp_path):
    mm = _make_models_module()
    names = sorted(mm.MODELS)
    total = 0
    for name in names:
        stem = Path(name).stem
        for f in (MODELS / name, MODELS / f"{stem}.truth.npz"):
            assert f.exists(), f"{f} missing: run python models/make_models.py"
            total += f.stat().st_size
        assert f"`{name}`" in (MODELS / "README.md").read_text(), f"{name} not documented"
    assert total < 1_000_000
    # regenerating a few small ones gives the same bytes (deterministic, and up to date)
    some = ["nested_shells.obj", "cup.obj", "sphere_pair_soup.obj"]
    mm.build(tmp_path, some)
    for name in some:
        for f in (name, f"{Path(name).stem}.truth.npz"):
            assert (tmp_path / f).read_bytes() == (MODELS / f).read_bytes(), f


def test_models_load_with_truth():
    from meshvis.io import load

    soup = load(MODELS / "house.obj")
    t = GroundTruth.load_arrays(MODELS / "house.truth.npz", soup)
    assert t.check() == []
    assert soup.part_names == list(np.load(MODELS / "house.truth.npz")["part_names"])
    a = load(MODELS / "assembly.obj")
    assert a.n_parts >= 25 and "fan" in a.part_names


def test_folded_onto_neighbour_finds_a_surface_stored_twice():
    from meshvis.soup import Soup

    def quad(z):  # corner 2 lifted by z: a skew quad
        return np.array([[0, 0, 0], [1, 0, 0], [1, 1, z], [0, 1, 0.0]])

    both = np.array([[0, 1, 2], [0, 2, 3], [0, 1, 3], [1, 2, 3]])  # both diagonals
    one = np.array([[0, 1, 2], [0, 2, 3]])
    assert closed._folded_onto_neighbour(Soup(quad(0.0), both)).all()
    assert not closed._folded_onto_neighbour(Soup(quad(0.0), one)).any()
    # a slightly skew quad (planes about 1 degree apart) is still one surface stored twice
    assert closed._folded_onto_neighbour(Soup(quad(np.tan(np.radians(0.7))), both)).all()
    # a real fin, 10 degrees open, is not
    assert not closed._folded_onto_neighbour(Soup(quad(np.tan(np.radians(10))), both)).any()
