"""Classification against the ground-truth generators and soupified real models
(issue: area-weighted correct classification >= 99.5% at default settings)."""

from pathlib import Path

import numpy as np
import pytest

from meshvis import classify, orient
from meshvis.eval import generators as G
from meshvis.graphcut.hints import Hints
from meshvis.io import load

REAL = Path(__file__).resolve().parents[3] / "shared" / "models" / "real"

CASES = {
    "nested_shells": lambda: G.nested_shells(),
    "house": lambda: G.house(),
    "cracked_box": lambda: G.cracked_box(),
    "box_with_opening": lambda: G.box_with_opening(),
    "cup": lambda: G.cup(),
    "terrain": lambda: G.terrain(),
    "overlapping_solids": lambda: G.overlapping_solids(),
    "sphere_pair": lambda: G.sphere_pair(),
    "house_soup": lambda: G.soupify(G.house(), flip=0.3, seed=2),
    "sphere_pair_soup": lambda: G.soupify(G.sphere_pair(), flip=0.5, seed=2, holes=0),
}


def side_accuracy(truth, c):
    """Area-weighted share of faces whose two side labels both match the truth."""
    ok = ~truth.ambiguous
    a = truth.soup.areas * ok
    right = (c.side_outside == truth.outside).all(axis=1)
    return float((a * right).sum() / a.sum())


@pytest.mark.slow
@pytest.mark.parametrize("name", sorted(CASES))
def test_generator_classified(name):
    truth = CASES[name]()
    hints = Hints(**truth.hints) if truth.hints else None
    c = classify(truth.soup, seed=0, hints=hints)
    assert side_accuracy(truth, c) >= 0.995
    # deterministic for a fixed seed
    again = classify(truth.soup, seed=0, hints=hints)
    assert np.array_equal(c.outside, again.outside) and again.counts.rays == c.counts.rays


def test_opening_none_reproduces_the_paper_prior():
    """With the paper's prior unchanged, a cup's inside is pulled inside: the reason for
    the ``opening`` threshold (meshvis.graphcut.weights.inside_prior)."""
    truth = G.cup()
    paper = classify(truth.soup, seed=0, opening=None)
    assert side_accuracy(truth, paper) < 0.9
    assert side_accuracy(truth, classify(truth.soup, seed=0)) >= 0.995


def oriented_fraction(truth, seed=0):
    r = orient(truth.soup, seed=seed)
    right = np.where(r.flipped, ~truth.outward, truth.outward) | truth.two_sided
    a = truth.soup.areas * ~truth.ambiguous
    return float((a * right).sum() / a.sum())


@pytest.mark.slow
@pytest.mark.parametrize("name", ["cow.obj", "stanford-bunny.obj", "dm_control__SKINbody.stl"])
def test_soupified_real_model_30_percent_flipped(name):
    path = REAL / name
    if not path.exists():
        pytest.skip("shared real models not present")
    soup = load(str(path))
    m = soup.n_faces
    # the truth is the original orientation (these models are consistently oriented outward;
    # the bunny is open at the bottom, so from_closed_mesh does not apply to it)
    truth = G.GroundTruth(soup, outside=np.c_[np.ones(m, bool), np.zeros(m, bool)], layer=1, outward=True)
    soupy = G.soupify(truth, flip=0.3, seed=0)
    assert soupy.flipped.mean() == pytest.approx(0.3, abs=0.02)
    assert oriented_fraction(soupy) >= 0.995
