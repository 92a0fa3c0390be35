"""The dense random reference (DESIGN.md §10) on models whose answer is known."""

from __future__ import annotations

import numpy as np
import pytest

from meshvis.eval import generators
from meshvis.eval.reference import reference


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
