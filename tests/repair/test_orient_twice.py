"""``orient`` twice is ``orient`` once: orienting its own output turns nothing.

A face's side comes from evidence that does not depend on how the face came in wound (the
cut and the rays run on the canonically wound model); the input's winding is kept only
where the evidence leaves the face open, and the output then keeps it again.  A few small
models run in the main suite; every shared model (``real/``, ``real2/``, ``ai/``) runs
under the ``shared_models`` marker, a step of its own in ``.ci/run``
(``pytest -m shared_models``).
"""

from __future__ import annotations

import numpy as np
import pytest
from helpers import REAL, real_model

from meshvis.cli.main import main
from meshvis.io import load
from meshvis.repair.orient import STATUS_NAMES, orient
from meshvis.soup import Soup

#: every shared model, by folder (real/, real2/, ai/)
SHARED = sorted(
    p for d in (REAL, REAL.parent / "real2", REAL.parent / "ai") if d.is_dir() for p in d.iterdir()
)
SHARED = [p for p in SHARED if p.suffix.lower() != ".md"]
#: the monastery: a scene standing on the ground, y up (OBJ)
MONASTERY = "pybullet__samurai_monastry.obj"


def _turned_again(soup: Soup, seed: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """The faces ``orient`` turns, and those a second ``orient`` of its output turns."""
    once = orient(soup, seed=seed)
    twice = orient(once.soup, seed=seed)
    assert twice.soup.n_faces == soup.n_faces
    return once.flipped, twice.flipped


def _check_twice(soup: Soup, seed: int = 0) -> None:
    once, again = _turned_again(soup, seed)
    assert not again.any(), f"the second run turned {int(again.sum())} faces (the first {int(once.sum())})"


@pytest.mark.slow
@pytest.mark.parametrize("name", ["soup.stl", "wallhole.obj", "pyvista__ant.ply", "ferrari348_lowpoly.glb"])
def test_orient_twice_turns_nothing_more_on_small_models(name):
    """The Ferrari turned 240 hidden faces more on the second run and back on a third: ray
    parity cast from each face's front only, and a sheet inside a closed body looks inward
    from either side.  soup.stl: 8 faces more (the cut's random rays and the evidence's
    followed the input's winding)."""
    _check_twice(load(real_model(name)))


@pytest.mark.slow
def test_orient_twice_turns_nothing_more_on_a_soup_turned_at_random():
    """The cow unwelded, 30 % of its faces turned over: ``orient`` gives it one winding,
    and the second run keeps it (whatever the first run's input winding was)."""
    cow = load(real_model("cow.obj"))
    m = cow.n_faces
    turned = np.random.default_rng(3).random(m) < 0.3
    soup = Soup(cow.vertices[cow.faces].reshape(-1, 3), np.arange(3 * m).reshape(m, 3)).flipped(turned)
    once, again = _turned_again(soup, seed=2)
    assert once.any() and not again.any()


def test_orient_decides_a_face_the_same_whichever_way_it_comes_in():
    """The box with every second face turned over, and the box as it is: the same output."""
    import trimesh

    box = trimesh.creation.box()
    faces = np.asarray(box.faces)
    turned = np.arange(len(faces)) % 2 == 1
    a = orient((box.vertices, faces), seed=1).soup
    b = orient((box.vertices, np.where(turned[:, None], faces[:, ::-1], faces)), seed=1).soup
    np.testing.assert_array_equal(a.normals, b.normals)


def test_orient_tests_the_same_faces_whether_two_copies_are_wound_alike_or_not():
    """A first run may turn one of two copies of a face wound alike (on trellis2_plant,
    eight pairs of hidden copies with their own rays); the second run then finds them
    stored with opposite winding, and writes them as they are.  That must change no other
    face's evidence: the rounds' ray budgets count the faces tested (the plant's second run
    turned one face when the copies were left out of the test)."""
    import trimesh

    box = trimesh.creation.box()
    v, f = np.asarray(box.vertices), np.asarray(box.faces)
    open_box = f[v[f].mean(axis=1)[:, 2] < 0.49]  # no lid: every face is tested
    alike = np.vstack([open_box, open_box[:1]])
    opposite = np.vstack([open_box, open_box[:1, ::-1]])
    a, b = orient((v, alike), seed=0), orient((v, opposite), seed=0)
    assert (a.double_sided, b.double_sided) == (0, 2)
    assert a.visibility == b.visibility
    np.testing.assert_array_equal(a.soup.normals[1:-1], b.soup.normals[1:-1])


@pytest.mark.slow
def test_orient_on_its_own_output_file_writes_the_same_file(tmp_path):
    """The command line: orient the file, then orient what it wrote; the faces are the same."""
    first, second = tmp_path / "once.stl", tmp_path / "twice.stl"
    assert main(["orient", real_model("soup.stl"), "-o", str(first), "--quiet"]) == 0
    assert main(["orient", str(first), "-o", str(second), "--quiet"]) == 0
    a, b = load(str(first)), load(str(second))
    np.testing.assert_array_equal(a.triangles, b.triangles)


@pytest.mark.slow
@pytest.mark.shared_models
@pytest.mark.parametrize("path", SHARED, ids=[p.name for p in SHARED])
def test_orient_twice_is_orient_once_on_every_shared_model(path):
    _check_twice(load(str(path)))


@pytest.fixture(scope="module")
def monastery():
    """The monastery and ``orient``'s outputs of it (seed 0): by default, and with its
    ground found (``ground=None``)."""
    soup = load(real_model(MONASTERY))
    return soup, {False: orient(soup, seed=0), None: orient(soup, seed=0, ground=None)}


def _back_facing(model, elevation: float) -> float:
    """Share of the model's pixels showing a back side, seen from ``elevation`` degrees (y up)."""
    from meshvis.rays.render import render

    image = render(model, size=(256, 256), elevation=elevation, up=(0, 1, 0))
    hit = image.face >= 0
    return float((image.side[hit] == 1).mean())


@pytest.mark.slow
@pytest.mark.shared_models
@pytest.mark.parametrize(
    "ground, elevation",
    [
        (False, 20.0),
        pytest.param(
            False,
            60.0,
            marks=pytest.mark.xfail(
                strict=True,
                reason="seen from every direction, courtyard floors seen more than 4x as often "
                "from the open space below the scene are turned down, most of their patch's "
                "area with them (0.0 % back-facing pixels before, 8.9 % after); the "
                "orientation benchmark, whose viewers are all around, counts them as right",
            ),
        ),
        (None, 20.0),
        (None, 60.0),
    ],
)
def test_orient_shows_the_monastery_no_more_backs_from_above(monastery, ground, elevation):
    """The monastery stands on the ground, y up.  Seen from above the horizon, ``orient``'s
    output shows no more back-facing pixels than the input, by default and with its ground
    found (``ground=None``: the scene is seen from above its ground only)."""
    soup, results = monastery
    r = results[ground]
    assert r.visibility["ground"] == (ground is None)  # found where asked for
    assert (r.status == STATUS_NAMES.index("two-sided")).sum() > 1000
    before, after = _back_facing(soup, elevation), _back_facing(r.soup, elevation)
    assert after <= before, f"from {elevation} degrees: {before:.2%} back-facing before, {after:.2%} after"
