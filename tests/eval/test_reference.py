"""The dense random reference (DESIGN.md §10) on models whose answer is known."""

from __future__ import annotations

import numpy as np
import pytest

from meshvis.eval import generators
from meshvis.eval.reference import Confirmation, confirm, reference


@pytest.mark.slow
def test_nested_shells_outer_seen_from_its_outside_inner_never():
    truth = generators.nested_shells(n=2, subdivisions=1)
    ref = reference(truth.soup, seed=1)
    outer = truth.layer == 1
    assert ref.seen[outer].all() and not ref.seen[~outer].any()
    # a closed outer shell escapes only through its outward side
    assert (ref.seen_side[outer] == truth.outside[outer]).all()
    assert ref.decisive[outer].all()
    assert ref.orientation_error(np.where(truth.outward, 0, 1)) == 0.0
    assert ref.orientation_error(np.where(truth.outward, 1, 0)) == 1.0


@pytest.mark.slow
def test_reference_is_deterministic_and_cached(tmp_path):
    soup = generators.nested_shells(n=2, subdivisions=1).soup
    cache = tmp_path / "ref.npz"
    first = reference(soup, seed=3, cache=cache)
    again = reference(soup, seed=3, cache=cache)  # read back from the cache
    fresh = reference(soup, seed=3)
    for name in ("escaped", "cast", "seen", "seen_side", "rays"):
        assert np.array_equal(getattr(first, name), getattr(again, name))
        assert np.array_equal(getattr(first, name), getattr(fresh, name))
    other = reference(soup, seed=4, cache=cache)  # another seed does not reuse the cache
    assert not np.array_equal(other.escaped, first.escaped)


@pytest.mark.slow
def test_confirm_recounts_the_decisive_faces_and_caches_them(tmp_path):
    truth = generators.nested_shells(n=2, subdivisions=1)
    ref = reference(truth.soup, seed=0)
    cache = tmp_path / "confirm.npz"
    first = confirm(truth.soup, ref, rays=256, cache=cache)
    assert np.array_equal(first.faces, np.flatnonzero(ref.decisive))
    assert (first.cast.sum(axis=1) == 256).all() and (first.escaped <= first.cast).all()
    # the closed outer shell escapes only outward, whatever the points: the same verdicts
    decisive, side = first.judged(truth.soup.n_faces)
    assert np.array_equal(decisive, ref.decisive)
    assert np.array_equal(side[decisive], ref.outside_side[decisive])
    again = confirm(truth.soup, ref, rays=256, cache=cache)  # read back
    assert np.array_equal(again.escaped, first.escaped)
    more = confirm(truth.soup, ref, rays=512, cache=cache)  # other parameters: recounted
    assert (more.cast.sum(axis=1) == 512).all()


def test_confirm_takes_the_side_by_escape_share():
    # 40 of 1000 rays escape through the front, 9 of 100 through the back: the back's share
    # is larger although fewer of its rays escape
    c = Confirmation(np.array([1]), np.array([[40, 9]]), np.array([[1000, 100]]))
    decisive, side = c.judged(3)
    assert decisive.tolist() == [False, False, False] and side.tolist() == [0, 0, 0]
    c = Confirmation(np.array([1]), np.array([[4, 90]]), np.array([[1000, 1000]]))
    decisive, side = c.judged(3)
    assert decisive.tolist() == [False, True, False] and side.tolist() == [0, 1, 0]


def test_judged_leaves_out_a_face_whose_counts_do_not_tell_its_side_of_the_line():
    # 90 : 20 escapes of 1000 rays each is 4.5x, but a face of exactly 4x escapes that way
    # often (the line's mean is 88 of 110): no verdict either way; 90 : 5 tells
    c = Confirmation(np.array([0, 1]), np.array([[20, 90], [5, 90]]), np.array([[1000, 1000]] * 2))
    decisive, side = c.judged(2)
    assert decisive.tolist() == [False, True] and side.tolist() == [0, 1]


@pytest.mark.slow
def test_confirm_settles_a_face_near_the_line_with_more_rays():
    """The triangle between two holes (its back sees 6.3x the solid angle its front sees):
    64 rays leave its side of the 4x line open, so the recount doubles them until the
    counts tell, and then calls it decisive, back out."""
    from helpers import two_holes

    from meshvis.repair.evidence import near_the_line

    soup = two_holes(0.4, 0.15)
    ref = reference(soup, seed=0)
    assert ref.decisive[0]
    short = Confirmation(*_first_rays(soup, ref, 64))
    assert near_the_line(short.escaped[:1], short.cast[:1])[0]  # 64 rays do not tell
    c = confirm(soup, ref, rays=64)
    assert c.faces[0] == 0 and c.cast[0].sum() > 64
    assert not near_the_line(c.escaped[:1], c.cast[:1])[0]
    decisive, side = c.judged(soup.n_faces)
    assert decisive[0] and side[0] == 1


def _first_rays(soup, ref, rays):
    """The recount's first round alone (the same generator as :func:`confirm`)."""
    from meshvis.eval.reference import _recount
    from meshvis.rays.caster import VISIBILITY_OFFSET, RayCaster

    faces = np.flatnonzero(ref.decisive)
    rng = np.random.default_rng([0, 0xC0F])
    return (faces, *_recount(soup, RayCaster(soup, offset=VISIBILITY_OFFSET), faces, rays, rng, None))
