"""Scenes whose PVS is known by construction, shared as the ``levels`` fixture."""

from __future__ import annotations

import sys

import numpy as np
import pytest

from meshvis.soup import Soup


def quad(a, b, c, d) -> list:
    """Two triangles (a, b, c), (a, c, d)."""
    return [[a, b, c], [a, c, d]]


def box_quads(lo, hi) -> list:
    """The twelve triangles of an axis-aligned box."""
    (x0, y0, z0), (x1, y1, z1) = lo, hi
    return (
        quad((x0, y0, z0), (x0, y0, z1), (x0, y1, z1), (x0, y1, z0))
        + quad((x1, y0, z0), (x1, y1, z0), (x1, y1, z1), (x1, y0, z1))
        + quad((x0, y0, z0), (x1, y0, z0), (x1, y0, z1), (x0, y0, z1))
        + quad((x0, y1, z0), (x0, y1, z1), (x1, y1, z1), (x1, y1, z0))
        + quad((x0, y0, z0), (x0, y1, z0), (x1, y1, z0), (x1, y0, z0))
        + quad((x0, y0, z1), (x1, y0, z1), (x1, y1, z1), (x0, y1, z1))
    )


def wall_with_hole(x, y0, y1, z0, z1, hole) -> list:
    """The plane x = const over [y0, y1] x [z0, z1] with a rectangular hole (hy0, hy1, hz0, hz1)."""
    hy0, hy1, hz0, hz1 = hole
    out = []
    for ya, yb, za, zb in ((y0, hy0, z0, z1), (hy1, y1, z0, z1), (hy0, hy1, hz1, z1), (hy0, hy1, z0, hz0)):
        if ya < yb and za < zb:
            out += quad((x, ya, za), (x, yb, za), (x, yb, zb), (x, ya, zb))
    return out


def soup_of(groups: dict) -> tuple[Soup, dict]:
    """A soup of named groups of triangles (one part each) and the face indices of each group."""
    tris, part, index, start = [], [], {}, 0
    for k, (name, g) in enumerate(groups.items()):
        tris += g
        part += [k] * len(g)
        index[name] = np.arange(start, start + len(g))
        start += len(g)
    tri = np.asarray(tris, np.float64)
    soup = Soup(
        tri.reshape(-1, 3), np.arange(3 * len(tri)).reshape(-1, 3), part_id=part, part_names=list(groups)
    )
    return soup, index


def two_rooms():
    """Two rooms (x 0..2 and 2.4..4.4; y, z 0..2) joined by a door through a 0.4 thick wall.

    The door is a tunnel (y 0.8..1.2, z 0..1.5): from room A a line through it keeps
    |dy/dx| <= 1, so at x = 2.5 it is at y >= 0.7.  Room B holds a box in front of the door
    (seen from room A through it) and a box in the corner beside the door (y 0.05..0.25,
    x 2.5..2.7: seen from no point of room A); room A the mirror of both.  The cells are
    the two rooms (``CELLS``); the wall between them is no cell.
    """
    door = (0.8, 1.2, 0.0, 1.5)
    groups = {
        "shell": box_quads((0, 0, 0), (4.4, 2, 2)),
        "wall_a": wall_with_hole(2.0, 0, 2, 0, 2, door),
        "wall_b": wall_with_hole(2.4, 0, 2, 0, 2, door),
        "tunnel": (
            quad((2.0, 0.8, 0), (2.4, 0.8, 0), (2.4, 0.8, 1.5), (2.0, 0.8, 1.5))
            + quad((2.0, 1.2, 0), (2.4, 1.2, 0), (2.4, 1.2, 1.5), (2.0, 1.2, 1.5))
            + quad((2.0, 0.8, 1.5), (2.4, 0.8, 1.5), (2.4, 1.2, 1.5), (2.0, 1.2, 1.5))
        ),
        "seen_in_b": box_quads((3.7, 0.85, 0.1), (4.0, 1.15, 0.4)),
        "hidden_in_b": box_quads((2.5, 0.05, 0.05), (2.7, 0.25, 0.3)),
        "seen_in_a": box_quads((0.4, 0.85, 0.1), (0.7, 1.15, 0.4)),
        "hidden_in_a": box_quads((1.7, 0.05, 0.05), (1.9, 0.25, 0.3)),
    }
    return soup_of(groups)


#: the two rooms' cells, x0, y0, z0, x1, y1, z1
CELLS = [[0, 0, 0, 2, 2, 2], [2.4, 0, 0, 4.4, 2, 2]]
#: the view space of the two rooms (the model's box)
VIEW_SPACE = "box:0,0,0,4.4,2,2"


def split_space():
    """A sheet at x = 2 across the whole view space (0..4, 0..2, 0..2), a box on each side."""
    groups = {
        "sheet": quad((2, -0.1, -0.1), (2, 2.1, -0.1), (2, 2.1, 2.1), (2, -0.1, 2.1)),
        "left": box_quads((0.5, 0.5, 0.5), (1.0, 1.0, 1.0)),
        "right": box_quads((3.0, 0.5, 0.5), (3.5, 1.0, 1.0)),
    }
    return soup_of(groups)


@pytest.fixture(scope="session")
def levels():
    """This module: ``levels.two_rooms()``, ``levels.split_space()``, ..."""
    return sys.modules[__name__]
