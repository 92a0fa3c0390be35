"""Small scenes whose visibility is known by construction, shared as the ``scenes`` fixture."""

from __future__ import annotations

import sys

import numpy as np
import pytest

from meshvis.soup import Soup


def quad(a, b, c, d) -> list[list[float]]:
    """Two triangles (a, b, c), (a, c, d): counter-clockwise seen from the front."""
    return [[a, b, c], [a, c, d]]


def soup_of(triangles, part_id=None) -> Soup:
    tri = np.asarray(triangles, np.float64).reshape(-1, 3, 3)
    vertices = tri.reshape(-1, 3)
    faces = np.arange(len(vertices)).reshape(-1, 3)
    if part_id is None:
        return Soup(vertices, faces)
    return Soup(vertices, faces, part_id=np.asarray(part_id, np.int64))


def box_faces(lo, hi, skip=()) -> dict[str, list]:
    """The six sides of an axis-aligned box as quads, fronts facing out; ``skip`` names sides to leave out."""
    (x0, y0, z0), (x1, y1, z1) = lo, hi
    sides = {
        "-x": quad((x0, y0, z0), (x0, y0, z1), (x0, y1, z1), (x0, y1, z0)),
        "+x": quad((x1, y0, z0), (x1, y1, z0), (x1, y1, z1), (x1, y0, z1)),
        "-y": quad((x0, y0, z0), (x1, y0, z0), (x1, y0, z1), (x0, y0, z1)),
        "+y": quad((x0, y1, z0), (x0, y1, z1), (x1, y1, z1), (x1, y1, z0)),
        "-z": quad((x0, y0, z0), (x0, y1, z0), (x1, y1, z0), (x1, y0, z0)),
        "+z": quad((x0, y0, z1), (x1, y0, z1), (x1, y1, z1), (x0, y1, z1)),
    }
    return {k: v for k, v in sides.items() if k not in skip}


def slot_box():
    """A unit box whose top has a slot (x 0.45..0.55, y 0.1..0.9).

    Every inner side is seen through the slot except the top's underside; the top strip of
    the +x wall (z 0.95..1) is seen only along lines within ~6 degrees of the horizontal.
    Returns the soup, the index of the two strip faces, and the truth ``(m, 2)`` bool.
    """
    sides = box_faces((0, 0, 0), (1, 1, 1), skip=("+z", "+x"))
    tris = [t for q in sides.values() for t in q]
    wall = quad((1, 0, 0), (1, 1, 0), (1, 1, 0.95), (1, 0, 0.95))
    strip = quad((1, 0, 0.95), (1, 1, 0.95), (1, 1, 1), (1, 0, 1))
    top = []
    for (xa, ya), (xb, yb) in [
        ((0, 0), (0.45, 1)),
        ((0.55, 0), (1, 1)),
        ((0.45, 0), (0.55, 0.1)),
        ((0.45, 0.9), (0.55, 1)),
    ]:
        top += quad((xa, ya, 1), (xb, ya, 1), (xb, yb, 1), (xa, yb, 1))
    tris = tris + wall + strip + top
    soup = soup_of(tris)
    n_top = len(top)
    truth = np.ones((soup.n_faces, 2), bool)
    truth[-n_top:, 1] = False
    strip_faces = np.arange(soup.n_faces - n_top - 2, soup.n_faces - n_top)
    return soup, strip_faces, truth


def pierced_box():
    """A closed unit box and one large triangle mostly inside it, its tip sticking out at +x.

    Truth: the box's outer sides and both sides of the triangle are seen; the box's inner sides are not.
    """
    tris = [t for q in box_faces((0, 0, 0), (1, 1, 1)).values() for t in q]
    tris.append([(0.1, 0.1, 0.5), (1.3, 0.5, 0.5), (0.1, 0.9, 0.5)])
    soup = soup_of(tris, part_id=[0] * 12 + [1])
    truth = np.zeros((13, 2), bool)
    truth[:12, 0] = True
    truth[12] = True
    return soup, truth


def sealed_pocket():
    """An open cup (part 0, no top) sealed by a lid box (part 1) sitting on its rim.

    Truth: the cup's inner sides and both sides of the lid's bottom are never seen.
    Returns the soup, the lid-bottom face indices and the truth.
    """
    cup = [t for q in box_faces((0, 0, 0), (1, 1, 1), skip=("+z",)).values() for t in q]
    lid_sides = box_faces((0, 0, 1), (1, 1, 1.2))
    lid = [t for q in lid_sides.values() for t in q]
    soup = soup_of(cup + lid, part_id=[0] * len(cup) + [1] * len(lid))
    truth = np.zeros((soup.n_faces, 2), bool)
    truth[:, 0] = True
    bottom = len(cup) + 2 * list(lid_sides).index("-z") + np.arange(2)
    truth[bottom, 0] = False
    return soup, bottom, truth


def unit_cube():
    """A closed cube centred at 0 with side 1 (fronts out), and the names of its faces in order."""
    sides = box_faces((-0.5, -0.5, -0.5), (0.5, 0.5, 0.5))
    names = [k for k in sides for _ in range(2)]
    return soup_of([t for q in sides.values() for t in q]), np.array(names)


@pytest.fixture
def scenes():
    """This module: ``scenes.slot_box()``, ``scenes.pierced_box()``, ..."""
    return sys.modules[__name__]
