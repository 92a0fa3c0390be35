"""Open surfaces: a cup modelled as one sheet and a heightfield terrain."""

from __future__ import annotations

import numpy as np

from ._shapes import _compose, _grid_tris, _orient_from, _Piece, _revolve, _weld
from .truth import GroundTruth


def cup(
    radius: float = 1.0,
    height: float = 1.2,
    flare: float = 0.15,
    sections: int = 64,
    bottom_rings: int = 8,
    wall_rings: int = 16,
) -> GroundTruth:
    """Build a cup modelled as a single sheet (open top): every face is two-sided.

    A surface of revolution about z: a flat bottom disc of ``bottom_rings`` rings and a
    wall flaring from ``radius`` to ``radius * (1 + flare)`` over ``height``.

    Parameters
    ----------
    radius : float
        Radius of the bottom disc.
    height : float
        Height of the wall.
    flare : float
        How much wider the rim is than the bottom, as a fraction of ``radius``.
    sections : int
        Segments around the axis.
    bottom_rings : int
        Rings of the bottom disc.
    wall_rings : int
        Rings of the wall.

    Returns
    -------
    GroundTruth
        Both sides of every face are outside, layer 1, ``two_sided``; the front faces the
        larger open region (away from the axis and downward), so ``outward`` is True.

    Examples
    --------
    >>> t = cup(sections=8, bottom_rings=2, wall_rings=2)
    >>> t.n_faces, bool(t.two_sided.all()), bool(t.outside.all())
    (56, True, True)
    """
    r = np.concatenate(
        [
            np.linspace(0, radius, bottom_rings + 1),
            radius * (1 + flare * np.linspace(0, 1, wall_rings + 1)[1:]),
        ]
    )
    z = np.concatenate([np.zeros(bottom_rings + 1), height * np.linspace(0, 1, wall_rings + 1)[1:]])
    V, F = _weld(_revolve(r, z, sections))
    F = _orient_from(V, F, (0.0, 0.0, 0.5 * height))
    return _compose(
        [_Piece(V, F, "cup", outside=(True, True), layer=1, two_sided=True)],
        "cup",
        "single-sheet cup with an open top: both sides of every face are outside",
    )


def terrain(
    n: int = 64, size: float = 1.0, amplitude: float = 0.15, bumps: int = 12, seed: int = 0
) -> GroundTruth:
    """Build a heightfield sheet: open, with no inherent inside; the user names the sides.

    Heights are a sum of ``bumps`` random Gaussian hills and pits plus a gentle slope.

    Parameters
    ----------
    n : int
        Grid cells per side (``2 n**2`` faces).
    size : float
        Extent in x and y (the grid spans ``[0, size]``).
    amplitude : float
        Height scale: every bump's height is uniform in ``[-amplitude, amplitude]``.
    bumps : int
        Number of hills and pits.
    seed : int
        Positions, widths and heights of the bumps.

    Returns
    -------
    GroundTruth
        Hints: one inside point below the terrain's centre, one outside point above it.
        Given them, the top side (the front) is outside and the bottom inside; layer 1.

    Examples
    --------
    >>> t = terrain(n=4)
    >>> t.n_faces, sorted(t.hints), t.hints["outside_points"].shape
    (32, ['inside_points', 'outside_points'], (1, 3))
    """
    rng = np.random.default_rng(seed)
    x = np.linspace(0.0, size, n + 1)
    X, Y = np.meshgrid(x, x, indexing="ij")
    c = rng.uniform(0, size, (bumps, 2))
    s = rng.uniform(0.05, 0.25, bumps) * size
    a = rng.uniform(-1, 1, bumps) * amplitude
    d2 = (X[..., None] - c[:, 0]) ** 2 + (Y[..., None] - c[:, 1]) ** 2
    Z = (a * np.exp(-d2 / (2 * s**2))).sum(-1) + 0.2 * amplitude * (X + 0.5 * Y) / size
    P = np.stack([X, Y, Z], -1)
    V, F = _weld(_grid_tris(P))  # normal e_x x e_y = +z: front up
    mid = np.array([size / 2, size / 2])
    hints = {
        "inside_points": [[*mid, Z.min() - 0.25 * size]],
        "outside_points": [[*mid, Z.max() + 0.25 * size]],
    }
    return _compose(
        [_Piece(V, F, "terrain", outside=(True, False), layer=1)],
        "terrain",
        "open heightfield; with the hints the top side is outside, the bottom inside",
        hints,
    )
