"""Wrong types and out-of-range values through the public API: each raises a specific
MeshvisError subclass with a message naming the argument, never a TypeError, IndexError,
AttributeError, ZeroDivisionError or MemoryError from inside, and never a silent result."""

from __future__ import annotations

import numpy as np
import pytest
import trimesh

import meshvis
from meshvis.errors import ModelError, ParameterError

BOX = trimesh.creation.box()
V, F = np.asarray(BOX.vertices), np.asarray(BOX.faces)
M = (V, F)


@pytest.fixture(scope="module")
def c():
    return meshvis.classify(M, seed=0, rays_per_node=8)


@pytest.fixture(scope="module")
def rc():
    return meshvis.RayCaster(M)


CASES = [
    # (call, error class, words of the message)
    (lambda c, rc, tmp: meshvis.load(None), ParameterError, "path must be a file path"),
    (lambda c, rc, tmp: meshvis.load(3), ParameterError, "path must be a file path"),
    (lambda c, rc, tmp: meshvis.save(M, None), ParameterError, "path must be a file path"),
    (lambda c, rc, tmp: meshvis.as_soup((V + 1j, F)), ModelError, "complex"),
    (lambda c, rc, tmp: meshvis.as_soup((V, F + 0.5)), ModelError, "not integers"),
    (lambda c, rc, tmp: meshvis.as_soup((V, F > 3)), ModelError, "dtype bool"),
    (lambda c, rc, tmp: meshvis.as_soup((V.astype(str), F)), ModelError, "must be numbers"),
    (lambda c, rc, tmp: meshvis.as_soup(([[0, 0], [1, 0, 0]], F)), ModelError, "numeric arrays"),
    (
        lambda c, rc, tmp: meshvis.classify(M, rays_per_node="32"),
        ParameterError,
        "rays_per_node must be an integer",
    ),
    (
        lambda c, rc, tmp: meshvis.classify(M, rays_per_node=1.5),
        ParameterError,
        "rays_per_node must be an integer",
    ),
    (
        lambda c, rc, tmp: meshvis.classify(M, rays_per_node=True),
        ParameterError,
        "rays_per_node must be an integer",
    ),
    (lambda c, rc, tmp: meshvis.classify(M, rays_per_node=10**9), ParameterError, "MAX_RAYS_PER_NODE"),
    (lambda c, rc, tmp: meshvis.classify(M, seed="x"), ParameterError, "seed must be an integer"),
    (lambda c, rc, tmp: meshvis.classify(M, seed=-1), ParameterError, "seed must be at least 0"),
    (lambda c, rc, tmp: meshvis.classify(M, seed=1.5), ParameterError, "seed must be an integer"),
    (lambda c, rc, tmp: meshvis.classify(M, samples_per_face="4"), ParameterError, "samples_per_face"),
    (lambda c, rc, tmp: meshvis.classify(M, samples_per_face=10**6), ParameterError, "MAX_SAMPLES_PER_FACE"),
    (lambda c, rc, tmp: meshvis.classify(M, sampling_scheme=3), ParameterError, "sampling_scheme"),
    (lambda c, rc, tmp: meshvis.classify(M, opening="x"), ParameterError, "opening must be a number"),
    (lambda c, rc, tmp: meshvis.classify(M, tolerance=None), ParameterError, "tolerance must be a number"),
    (lambda c, rc, tmp: meshvis.classify(M, offset=-1.0), ParameterError, "offset must be above 0"),
    (lambda c, rc, tmp: meshvis.classify(M, offset="x"), ParameterError, "offset must be a number"),
    (lambda c, rc, tmp: meshvis.classify(M, progress=3), ParameterError, "progress must be callable"),
    (lambda c, rc, tmp: meshvis.classify(M, caster="x"), ParameterError, "caster must be a RayCaster"),
    (
        lambda c, rc, tmp: meshvis.classify(M, hints={"inside_points": [[0, 0]]}),
        ParameterError,
        "shape (k, 3)",
    ),
    (
        lambda c, rc, tmp: meshvis.classify(M, hints={"inside_points": [[0, 0, 0, 0]]}),
        ParameterError,
        "shape (k, 3)",
    ),
    (lambda c, rc, tmp: meshvis.classify(M, hints={"inside_points": "a"}), ParameterError, "inside_points"),
    (
        lambda c, rc, tmp: meshvis.classify(M, hints={"inside": [[0, 0, 0]]}),
        ParameterError,
        "unknown argument 'inside'",
    ),
    (lambda c, rc, tmp: meshvis.Hints(rays="x"), ParameterError, "hint rays must be an integer"),
    (lambda c, rc, tmp: meshvis.Hints(strength="x"), ParameterError, "hint strength must be a number"),
    (
        lambda c, rc, tmp: meshvis.layers(M, classification=c, max_layers=0),
        ParameterError,
        "max_layers must be at least 1",
    ),
    (
        lambda c, rc, tmp: meshvis.layers(M, classification=c, max_layers="x"),
        ParameterError,
        "max_layers must be an integer",
    ),
    (
        lambda c, rc, tmp: meshvis.layers(M, classification=c, max_layers=1.5),
        ParameterError,
        "max_layers must be an integer",
    ),
    (
        lambda c, rc, tmp: meshvis.layers(M, classification="x"),
        ParameterError,
        "classification must be a Classification",
    ),
    (lambda c, rc, tmp: meshvis.layers(M, bogus=1), ParameterError, "unknown argument 'bogus' of classify()"),
    (
        lambda c, rc, tmp: meshvis.orient(M, classification="x"),
        ParameterError,
        "classification must be a Classification",
    ),
    (
        lambda c, rc, tmp: meshvis.remove_interior(M, classification="x"),
        ParameterError,
        "classification must be",
    ),
    (lambda c, rc, tmp: meshvis.render(M, size=(-5, 10)), ParameterError, "width must be at least 1"),
    (lambda c, rc, tmp: meshvis.render(M, size=(10, 0)), ParameterError, "height must be at least 1"),
    (lambda c, rc, tmp: meshvis.render(M, size=(10.5, 10)), ParameterError, "width must be an integer"),
    (lambda c, rc, tmp: meshvis.render(M, size="ab"), ParameterError, "size must be (width, height)"),
    (lambda c, rc, tmp: meshvis.render(M, size=5), ParameterError, "size must be (width, height)"),
    (
        lambda c, rc, tmp: meshvis.render(M, size=(8, 8), color_by="x"),
        ParameterError,
        "color_by must be one of",
    ),
    (
        lambda c, rc, tmp: meshvis.render(M, size=(8, 8), color_by="layer"),
        ParameterError,
        "needs face_values",
    ),
    (
        lambda c, rc, tmp: meshvis.render(M, size=(8, 8), color_by="layer", face_values=[1]),
        ParameterError,
        "one value per face",
    ),
    (lambda c, rc, tmp: meshvis.render(M, "x", size=(8, 8)), ParameterError, "camera must be a Camera"),
    (
        lambda c, rc, tmp: meshvis.render(M, size=(8, 8), azimuth="x"),
        ParameterError,
        "azimuth must be a number",
    ),
    (
        lambda c, rc, tmp: meshvis.render(M, size=(8, 8), caster="x"),
        ParameterError,
        "caster must be a RayCaster",
    ),
    (lambda c, rc, tmp: meshvis.RayCaster(M, offset="x"), ParameterError, "offset must be a number"),
    (lambda c, rc, tmp: meshvis.RayCaster(M, offset=-1), ParameterError, "offset must be at least 0"),
    (lambda c, rc, tmp: meshvis.RayCaster(M, threads="x"), ParameterError, "threads must be an integer"),
    (lambda c, rc, tmp: rc.intersect(np.zeros((3, 2)), np.ones((3, 2))), ParameterError, "shape (k, 3)"),
    (lambda c, rc, tmp: rc.intersect(np.zeros((3, 3)), np.ones((2, 3))), ParameterError, "differ in length"),
    (lambda c, rc, tmp: rc.intersect(np.zeros((1, 3)), np.zeros((1, 3))), ParameterError, "non-zero"),
    (lambda c, rc, tmp: rc.intersect(np.full((1, 3), np.nan), np.ones((1, 3))), ParameterError, "finite"),
    (lambda c, rc, tmp: rc.intersect("a", "b"), ParameterError, "origins must be numbers"),
    (
        lambda c, rc, tmp: rc.intersect(np.zeros((3, 3)), np.ones((3, 3)), max_distance=[1, 2]),
        ParameterError,
        "max_distance",
    ),
    (lambda c, rc, tmp: rc.occluded(np.zeros((3, 3)), np.ones((2, 3))), ParameterError, "differ in length"),
    (lambda c, rc, tmp: rc.occluded(np.zeros((3, 2)), np.ones((3, 2))), ParameterError, "shape (k, 3)"),
    (
        lambda c, rc, tmp: rc.push_off(np.zeros((3, 3)), np.array([100, 0, 0]), np.zeros(3)),
        ParameterError,
        "face must be in",
    ),
    (lambda c, rc, tmp: rc.part_of(np.array([100])), ParameterError, "face must be in"),
    (lambda c, rc, tmp: meshvis.Camera.fit(M, azimuth="x"), ParameterError, "azimuth must be a number"),
    (lambda c, rc, tmp: meshvis.Camera.fit(M).rays(-1, 5), ParameterError, "width must be at least 1"),
    (lambda c, rc, tmp: meshvis.save(M, tmp / "x.ply", face_groups="ab"), ParameterError, "face_groups"),
    (
        lambda c, rc, tmp: meshvis.save(M, tmp / "x.ply", face_groups=np.full(12, 0.5)),
        ParameterError,
        "face_groups must be integers",
    ),
    (
        lambda c, rc, tmp: meshvis.save(M, tmp / "x.obj", face_groups=np.zeros(12, int), group_names=3),
        ParameterError,
        "group_names",
    ),
    (
        lambda c, rc, tmp: meshvis.save(M, tmp / "x.ply", face_values={"a": np.zeros((12, 2))}),
        ParameterError,
        "one value per face",
    ),
    (
        lambda c, rc, tmp: meshvis.save(M, tmp / "x.ply", face_values={"a": np.array(["x"] * 12)}),
        ParameterError,
        "must be numbers",
    ),
    (
        lambda c, rc, tmp: meshvis.save(M, tmp / "x.ply", face_values=[1, 2]),
        ParameterError,
        "face_values must be a Mapping",
    ),
    # seeds of every seeded entry point (numpy's SeedSequence refused them with a ValueError)
    (lambda c, rc, tmp: meshvis.visible_from(M, seed=-5), ParameterError, "seed must be at least 0, got -5"),
    (lambda c, rc, tmp: meshvis.visible_from(M, seed=2**200), ParameterError, "seed must be at most"),
    (lambda c, rc, tmp: meshvis.visible_from(M, seed=1.5), ParameterError, "seed must be an integer"),
    (lambda c, rc, tmp: meshvis.orient_from(M, seed=-1), ParameterError, "seed must be at least 0"),
    (lambda c, rc, tmp: meshvis.orient(M, seed=-1), ParameterError, "seed must be at least 0"),
    (lambda c, rc, tmp: meshvis.layers(M, seed=-1), ParameterError, "seed must be at least 0"),
    (
        lambda c, rc, tmp: meshvis.remove_interior(M, visibility="view", seed=-1),
        ParameterError,
        "seed must be at least 0",
    ),
    (lambda c, rc, tmp: _demo(tmp, seed=-1), ParameterError, "seed must be at least 0"),
    (lambda c, rc, tmp: _demo(tmp, size=0), ParameterError, "width must be at least 1"),
    # values that used to pass silently
    (
        lambda c, rc, tmp: meshvis.visible_from(M, per_side="yes"),
        ParameterError,
        "per_side must be True or False",
    ),
    (lambda c, rc, tmp: meshvis.visible_from(M, budget=0), ParameterError, "budget must be at least 1"),
    (lambda c, rc, tmp: meshvis.visible_from(M, budget="100"), ParameterError, "budget must be an integer"),
    (lambda c, rc, tmp: meshvis.visible_from(M, min_new=-1), ParameterError, "min_new must be at least 0"),
    (
        lambda c, rc, tmp: meshvis.remove_interior(M, budget="100"),
        ParameterError,
        "budget must be an integer",
    ),
    (lambda c, rc, tmp: meshvis.remove_interior(M, budget=0), ParameterError, "budget must be at least 1"),
    (
        lambda c, rc, tmp: meshvis.remove_interior(M, keep_border="2"),
        ParameterError,
        "keep_border must be an integer",
    ),
    (
        lambda c, rc, tmp: meshvis.remove_interior(M, keep_border=-1),
        ParameterError,
        "keep_border must be at least 0",
    ),
    # raw Python / numpy errors from inside
    (
        lambda c, rc, tmp: meshvis.parse_region("upper-hemisphere", up="q"),
        ParameterError,
        "up must be auto, x, y, z",
    ),
    (
        lambda c, rc, tmp: meshvis.parse_region("upper-hemisphere", up=[1, 2]),
        ParameterError,
        "up must be auto, x, y, z or three numbers",
    ),
    (
        lambda c, rc, tmp: meshvis.parse_region("upper-hemisphere", up=[0, 0, 0]),
        ParameterError,
        "finite non-zero",
    ),
    (
        lambda c, rc, tmp: meshvis.Soup(V, F, part_id=[0, 1]),
        ModelError,
        "part_id must be numbers of shape (12,)",
    ),
    (lambda c, rc, tmp: meshvis.Soup(V, F, part_id=[5] * 12, part_names=["a"]), ModelError, "names no part"),
    (lambda c, rc, tmp: meshvis.Soup(V, F, part_id=[-1] * 12), ModelError, "part_id must be at least 0"),
    (
        lambda c, rc, tmp: meshvis.Soup(V, F, uv=np.zeros((5, 2))),
        ModelError,
        "uv must be numbers of shape (12, 3, 2)",
    ),
    (lambda c, rc, tmp: meshvis.Soup(V, F, colors=[1, 2]), ModelError, "colors must be numbers of shape"),
    (lambda c, rc, tmp: meshvis.Soup(V, F, source_face="x"), ModelError, "source_face must be numbers"),
    (lambda c, rc, tmp: meshvis.Camera.from_json([1, 2]), ParameterError, "a camera must be an object"),
    (lambda c, rc, tmp: meshvis.Camera.from_json({1: 2}), ParameterError, "unknown camera keys: 1"),
    (
        lambda c, rc, tmp: meshvis.Camera((0, 0, 5), (0, 0, 0), ortho_height=-1),
        ParameterError,
        "ortho_height",
    ),
    (lambda c, rc, tmp: meshvis.Camera.fit(M, distance=-1), ParameterError, "distance must be above 0"),
    (lambda c, rc, tmp: meshvis.Camera.fit(M, up="q"), ParameterError, "up must be auto, x, y, z"),
    (
        lambda c, rc, tmp: meshvis.classify(M, hints={"inside_points": [[10**400, 0, 0]]}),
        ParameterError,
        "finite",
    ),
]


def _demo(tmp, **kw):
    from meshvis.eval.demo import run_demo

    return run_demo(str(tmp / "demo"), say=lambda text: None, **kw)


@pytest.mark.parametrize("call, kind, words", CASES, ids=[w for _, _, w in CASES])
def test_wrong_argument_is_a_meshvis_error(call, kind, words, c, rc, tmp_path):
    with pytest.raises(kind) as info:
        call(c, rc, tmp_path)
    assert words in str(info.value)
    assert "\n" not in str(info.value)
    assert list(tmp_path.iterdir()) == []  # nothing written


def test_right_arguments_still_work(c, rc, tmp_path):
    """The checks accept what the documentation allows: numpy integers, integral float faces,
    a single hint point, a scalar max_distance."""
    assert meshvis.as_soup((V, F.astype(float))).n_faces == 12
    r = meshvis.classify(M, seed=np.int64(2), rays_per_node=np.int32(8), hints={"inside_points": [0, 0, 0]})
    assert r.side_outside[:, 0].all()
    hits = rc.intersect(np.array([[0, 0, 5.0]]), np.array([[0, 0, -1.0]]), max_distance=10.0)
    assert hits.hit.all()
    assert meshvis.layers(M, classification=c, max_layers=np.int64(1)).n_layers == 1
    assert meshvis.render(M, size=(np.int64(8), 6)).image.shape == (6, 8, 3)
