"""Closed shells: nested spheres, overlapping solids, a cracked sphere around a hidden one."""

from __future__ import annotations

import numpy as np

from meshvis.errors import ParameterError

from ._shapes import _box, _compose, _icosphere, _Piece, _random_rotation
from .closed import _closed_pieces_truth
from .truth import GroundTruth


def nested_shells(
    n: int = 3, kind: str = "sphere", subdivisions: int = 3, cell: float = 0.1, seed: int = 0
) -> GroundTruth:
    """Build concentric closed shells that do not touch: the textbook layer test.

    Parameters
    ----------
    n : int
        Number of shells, at least 1; radii (or half sizes) shrink linearly from 1 to 0.35.
    kind : {"sphere", "box", "mixed"}
        Icospheres, axis-aligned boxes of half size ``r * (1, 0.8, 0.6)``, or alternating
        spheres and cubes, each inscribed in the previous one, sizes halving per shell.
    subdivisions : int
        Icosphere subdivision level (20 * 4**subdivisions faces per sphere).
    cell : float
        Box cell size relative to the shell's half size.
    seed : int
        Seeds the random rotation of every sphere (so tessellations do not line up).

    Returns
    -------
    GroundTruth
        Shell ``i`` (1 = outermost) is layer ``i``; only shell 1 has an outside side (its
        front); every face is built facing away from the common centre, so ``outward`` is
        all True (layer semantics; the "cavity" reading would turn shells 2.. inward).

    Raises
    ------
    ParameterError
        ``n`` below 1 or an unknown ``kind``.

    Examples
    --------
    >>> t = nested_shells(n=2, subdivisions=1)
    >>> t.n_faces, t.n_layers, int(t.visible.sum())
    (160, 2, 80)
    >>> t.soup.part_names
    ['shell_1', 'shell_2']
    """
    if n < 1:
        raise ParameterError(f"nested_shells needs n >= 1, got {n}")
    if kind not in ("sphere", "box", "mixed"):
        raise ParameterError(f"unknown shell kind {kind!r} (sphere, box, mixed)")
    rng = np.random.default_rng(seed)
    if kind == "mixed":
        # a cube inscribed (95 %) in a sphere, a sphere of half the radius inside the cube, ...
        scales = 0.5 ** np.arange(n)
        half = np.full(3, 0.95 / np.sqrt(3.0))
    else:
        scales = np.linspace(1.0, 0.35, n) if n > 1 else np.array([1.0])
        half = np.array([1.0, 0.8, 0.6])
    pieces = []
    for i, r in enumerate(scales):
        rot = _random_rotation(rng)
        use_box = kind == "box" or (kind == "mixed" and i % 2 == 1)
        if use_box:
            V, F = _box(-r * half, r * half, cell * r)
        else:
            V, F = _icosphere(subdivisions, r, rotation=rot)
        pieces.append(_Piece(V, F, f"shell_{i + 1}", outside=(i == 0, False), layer=i + 1))
    return _compose(
        pieces,
        "nested_shells",
        f"{n} concentric closed {kind} shells; layer i = shell i, all faces outward; "
        "tests layers and inside removal (everything but shell 1 is hidden)",
    )


def overlapping_solids(subdivisions: int = 4, cell: float = 0.1, seed: int = 0) -> GroundTruth:
    """Build two closed solids that interpenetrate: a sphere and a box pushed half into it.

    Parameters
    ----------
    subdivisions : int
        Icosphere level of the unit sphere.
    cell : float
        Box triangle size.
    seed : int
        Jitters the box position and rotates the sphere's tessellation.

    Returns
    -------
    GroundTruth
        Truth from the generalised winding number (libigl) of the *other* solid at points
        just off each face: faces inside the other solid are hidden (layer 2), the rest are
        one-sided with the front outside (layer 1).  Faces that straddle the intersection
        curve are ``ambiguous``.

    Examples
    --------
    >>> t = overlapping_solids(subdivisions=1, cell=0.5)
    >>> t.soup.part_names, t.n_layers, t.check()
    (['sphere', 'box'], 2, [])
    """
    rng = np.random.default_rng(seed)
    sV, sF = _icosphere(subdivisions, 1.0, rotation=_random_rotation(rng))
    shift = rng.uniform(-0.05, 0.05, 3)
    bV, bF = _box(np.array([0.25, -0.7, -0.6]) + shift, np.array([2.0, 0.7, 0.6]) + shift, cell)
    return _closed_pieces_truth(
        [(sV, sF), (bV, bF)],
        ["sphere", "box"],
        "overlapping_solids",
        "a sphere and a box that interpenetrate; faces inside the other solid (winding number 1) are hidden",
    )


def sphere_pair(
    subdivisions: int = 4, crack: int = 6, inner_radius: float = 0.5, seed: int = 0
) -> GroundTruth:
    """Build an outer sphere with a small hole of ``crack`` missing faces, and an inner sphere.

    The hole is the ``crack`` faces nearest to a random vertex (its one-ring for 6 on a
    regular vertex).

    Parameters
    ----------
    subdivisions : int
        Icosphere level of the outer sphere (radius 1); the inner sphere is one level
        coarser, at least level 1.
    crack : int
        Faces removed from the outer sphere.
    inner_radius : float
        Radius of the inner sphere.
    seed : int
        Chooses the vertex of the hole and rotates both tessellations.

    Returns
    -------
    GroundTruth
        The hole is a defect (DESIGN.md §4: small cracks must not let the outside in):
        outer sphere layer 1, front outside; inner sphere hidden, layer 2, outward.

    Examples
    --------
    >>> t = sphere_pair(subdivisions=2)
    >>> t.n_faces, int(t.hidden.sum())
    (394, 80)
    """
    rng = np.random.default_rng(seed)
    V, F = _icosphere(subdivisions, 1.0, rotation=_random_rotation(rng))
    v = V[rng.integers(len(V))]
    dist = np.linalg.norm(V[F].mean(axis=1) - v, axis=1)
    keep = np.ones(len(F), bool)
    keep[np.argsort(dist, kind="stable")[: int(crack)]] = False
    iV, iF = _icosphere(max(subdivisions - 1, 1), inner_radius, rotation=_random_rotation(rng))
    pieces = [
        _Piece(V, F[keep], "outer_sphere", outside=(True, False), layer=1),
        _Piece(iV, iF, "inner_sphere", outside=(False, False), layer=2),
    ]
    return _compose(
        pieces,
        "sphere_pair",
        f"outer sphere missing {int(crack)} faces around one vertex, inner sphere hidden; "
        "tests that a small hole does not let the outside in",
    )
