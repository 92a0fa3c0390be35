"""The rescue pass: where it spends its rays, and how it passes a rare line of sight on."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from meshvis.errors import ParameterError
from meshvis.rays.caster import VISIBILITY_OFFSET, RayCaster
from meshvis.repair.layers import layers
from meshvis.visibility import parse_region, visible_from
from meshvis.visibility.check import (
    RESCUE_SHARE,
    RESCUE_STREAM,
    rescue_pass,
    self_check,
)

from .conftest import box_faces, quad, soup_of


def _outside(soup):
    return RayCaster(soup, offset=VISIBILITY_OFFSET), parse_region("outside").bind(soup)


def test_faces_deep_in_hidden_ones_get_the_first_rays_only():
    outer = [t for q in box_faces((0, 0, 0), (1, 1, 1)).values() for t in q]
    inner = [t for q in box_faces((0.4, 0.4, 0.4), (0.6, 0.6, 0.6)).values() for t in q]
    soup = soup_of(outer + inner)
    caster, region = _outside(soup)
    unseen = np.arange(soup.n_faces) >= 12  # the sealed inner box: no neighbour was seen
    r = rescue_pass(caster, region, unseen, ~unseen, rays=64, first=4, seed=0)
    assert r.faces == 12 and r.full_faces == 0 and r.rays == 12 * 4 and not r.seen.any()
    # call one inner face seen: the inner faces sharing a corner with it get every ray
    seen = ~unseen
    seen[12] = True
    r = rescue_pass(caster, region, unseen & ~seen, seen, rays=64, first=4, seed=0)
    assert 0 < r.full_faces < 11 and r.rays == 11 * 4 + r.full_faces * 60 and not r.seen.any()
    assert r.report()["faces_full_rays"] == r.full_faces and r.short_faces == 0
    # a budget lowers the count of those faces, and the pass says for how many
    capped = rescue_pass(caster, region, unseen & ~seen, seen, rays=64, first=4, seed=0, budget=11 * 4 + 30)
    assert capped.full_faces == 0 and capped.short_faces == r.full_faces
    assert 11 * 4 < capped.rays <= 11 * 4 + 30
    spent = rescue_pass(caster, region, unseen & ~seen, seen, rays=64, first=4, seed=0, budget=0)
    assert spent.rays == 11 * 4 and spent.short_faces == r.full_faces  # the first round is always cast
    # by default the budget is a share of the search's rays
    vis = visible_from(soup, seed=0, caster=caster)
    search = dataclasses.replace(vis, rays={**vis.rays, "total": round((11 * 4 + 30) / RESCUE_SHARE)})
    by_search = rescue_pass(caster, region, unseen & ~seen, seen, rays=64, first=4, seed=0, search=search)
    assert by_search.rays == capped.rays and by_search.short_faces == capped.short_faces
    # first >= rays: one round of rays from every face
    assert rescue_pass(caster, region, unseen, ~unseen, rays=4, first=32, seed=0).rays == 12 * 4


def _slit_box():
    """A unit box with a thin slit in its lid (x 0.49..0.51) and no +x wall below z 0.98 but
    a strip of 32 faces (z 0.98..1): lines through the slit reach the strip within a few
    degrees of one direction.  Returns the soup and the strip mask."""
    tris = [t for q in box_faces((0, 0, 0), (1, 1, 1), skip=("+z", "+x")).values() for t in q]
    tris += quad((1, 0, 0), (1, 1, 0), (1, 1, 0.98), (1, 0, 0.98))
    n = len(tris)
    for i in range(16):
        y0, y1 = i / 16, (i + 1) / 16
        tris += quad((1, y0, 0.98), (1, y1, 0.98), (1, y1, 1), (1, y0, 1))
    for (xa, ya), (xb, yb) in [
        ((0, 0), (0.49, 1)),
        ((0.51, 0), (1, 1)),
        ((0.49, 0), (0.51, 0.1)),
        ((0.49, 0.9), (0.51, 1)),
    ]:
        tris += quad((xa, ya, 1), (xb, ya, 1), (xb, yb, 1), (xa, yb, 1))
    soup = soup_of(tris)
    strip = np.zeros(soup.n_faces, bool)
    strip[n : n + 32] = True
    return soup, strip


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_a_rare_line_of_sight_is_passed_on_to_the_neighbours(seed):
    soup, strip = _slit_box()
    caster, region = _outside(soup)
    flat = self_check(caster, region, strip, rays=2, seed=seed, stream=RESCUE_STREAM)
    assert 0 < flat.seen.sum() < 32  # two random rays a face find some of the strip
    r = rescue_pass(caster, region, strip, ~strip, rays=2, first=2, seed=seed)
    assert r.seen[strip].all() and not r.seen[~strip].any() and r.rays > 64


def test_layers_by_sight_take_the_rescue_rays(scenes):
    soup, _, _ = scenes.slot_box()
    with pytest.raises(ParameterError, match="rescue_rays"):
        layers(soup, rescue_rays=-1)
    assert (layers(soup, seed=0, budget=200).layer == 1).all()  # the rescue sees what the short search missed
    short = layers(soup, seed=0, budget=200, rescue_rays=0, max_layers=1)
    assert (short.layer == 2).any()


def _slit_over_tiles():
    """A closed unit box with a slit 0.05 wide in its lid (x and y 0.475..0.525) over a floor
    (z 0.01, above the box's own) tiled with 0.01 squares in x 0.5..0.7, y 0.4..0.6: each
    tile is seen only through the slit, along lines within about 3 degrees of one direction.
    Returns the soup and the index of the first tile triangle."""
    h, cell, n = 0.01, 0.01, 20
    tris = [t for q in box_faces((0, 0, 0), (1, 1, 1), skip=("+z",)).values() for t in q]
    for (xa, ya), (xb, yb) in [
        ((0, 0), (0.5, 1)),
        ((0.7, 0), (1, 1)),
        ((0.5, 0), (0.7, 0.4)),
        ((0.5, 0.6), (0.7, 1)),
    ]:
        tris += quad((xa, ya, h), (xa, yb, h), (xb, yb, h), (xb, ya, h))
    first = len(tris)
    for i in range(n):
        for j in range(n):
            x, y = 0.5 + i * cell, 0.4 + j * cell
            tris += quad((x, y, h), (x, y + cell, h), (x + cell, y + cell, h), (x + cell, y, h))
    a, b = 0.475, 0.525
    for (xa, ya), (xb, yb) in [((0, 0), (a, 1)), ((b, 0), (1, 1)), ((a, 0), (b, a)), ((a, b), (b, 1))]:
        tris += quad((xa, ya, 1), (xb, ya, 1), (xb, yb, 1), (xa, yb, 1))
    return soup_of(tris), first


def test_a_face_seen_through_a_slit_is_aimed_at_along_its_seen_neighbours_sightings():
    soup, first = _slit_over_tiles()
    caster, region = _outside(soup)
    vis = visible_from(soup, seed=0, caster=caster)
    target = first + 2 * (10 * 20 + 10)  # the tile at x 0.6, y 0.5
    unseen = np.zeros(soup.n_faces, bool)
    unseen[target] = True
    seen = vis.seen & ~unseen  # the search missed the tile, not its neighbours
    corners = caster.vertex_groups.corner_groups(soup.faces, len(soup.vertices))
    neighbours = np.isin(corners, corners[target]).any(axis=1) & ~unseen
    assert seen[neighbours].all() and np.abs(vis.sighting[neighbours]).sum(axis=1).all()
    aimed = [rescue_pass(caster, region, unseen, seen, seed=s, search=vis) for s in range(8)]
    blind = [rescue_pass(caster, region, unseen, seen, seed=s) for s in range(8)]  # random rays only
    assert all(r.seen[target] for r in aimed)
    assert sum(r.seen[target] for r in blind) <= 2  # 256 random rays: found about one time in ten
    assert all(not r.seen[~unseen].any() for r in aimed + blind)
