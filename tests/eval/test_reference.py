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
