"""Single-sheet boxes with hairline cracks or with a real opening.

:func:`cracked_box` has slits that must not let the outside in; :func:`box_with_opening`
is a cave whose inside is reachable.
"""

from __future__ import annotations

import numpy as np

from meshvis.errors import ParameterError

from ._shapes import _axis_patch, _box, _compose, _counts, _Piece, _weld
from .truth import GroundTruth

_SIDES = ["-x", "+x", "-y", "+y", "-z", "+z"]


def _box_sheet(
    lo,
    hi,
    cell: float,
    gap: float = 0.0,
    splits: dict | None = None,
    opening: tuple[str, float] | None = None,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Build a single-sheet box surface facing outward, optionally cracked or opened.

    Parameters
    ----------
    gap : float
        Every side is shrunk in its plane so that the edges of neighbouring sides are
        ``gap`` apart, leaving slits along the 12 box edges.
    splits : dict side -> (direction 0|1, fraction)
        The side is cut in two across the given in-plane direction, the halves ``gap`` apart.
    opening : (side, fraction)
        Cells of that side within a centred rectangle of ``fraction`` of its size are removed.

    Returns
    -------
    V, F, side : welded geometry and the box side (0..5, see ``_SIDES``) of every face
    """
    lo, hi = np.asarray(lo, np.float64), np.asarray(hi, np.float64)
    splits = splits or {}
    n = _counts(lo, hi, cell)
    tris, side = [], []
    for a in range(3):
        b, c = (a + 1) % 3, (a + 2) % 3
        for s, value in ((0, lo[a]), (1, hi[a])):
            sid = 2 * a + s
            # in-plane ranges of the side's pieces, as (b-range, c-range) pairs
            # pulled back by gap / sqrt(2): the edges of two perpendicular sides are then
            # exactly ``gap`` apart
            d = gap / np.sqrt(2.0)
            rb = (lo[b] + d, hi[b] - d)
            rc = (lo[c] + d, hi[c] - d)
            parts = [(rb, rc)]
            if _SIDES[sid] in splits:
                d, frac = splits[_SIDES[sid]]
                r = rb if d == 0 else rc
                cut = r[0] + frac * (r[1] - r[0])
                halves = [(r[0], cut - gap / 2), (cut + gap / 2, r[1])]
                parts = [(h, rc) if d == 0 else (rb, h) for h in halves]
            for pb, pc in parts:
                if gap == 0 and len(parts) == 1:
                    ub, vc = np.linspace(lo[b], hi[b], n[b] + 1), np.linspace(lo[c], hi[c], n[c] + 1)
                else:
                    ub = np.linspace(pb[0], pb[1], max(1, int(round((pb[1] - pb[0]) / cell))) + 1)
                    vc = np.linspace(pc[0], pc[1], max(1, int(round((pc[1] - pc[0]) / cell))) + 1)
                keep = None
                if opening is not None and opening[0] == _SIDES[sid]:
                    f = opening[1]
                    mb, mc = 0.5 * (ub[:-1] + ub[1:]), 0.5 * (vc[:-1] + vc[1:])
                    cb, cc = 0.5 * (lo[b] + hi[b]), 0.5 * (lo[c] + hi[c])
                    in_b = np.abs(mb - cb) < 0.5 * f * (hi[b] - lo[b])
                    in_c = np.abs(mc - cc) < 0.5 * f * (hi[c] - lo[c])
                    keep = ~(in_b[:, None] & in_c[None, :])
                t = _axis_patch(a, value, 1 if s else -1, ub, vc, keep)
                tris.append(t)
                side.append(np.full(len(t), sid))
    V, F = _weld(np.concatenate(tris))
    return V, F, np.concatenate(side)


def cracked_box(
    size: tuple[float, float, float] = (2.0, 1.5, 1.0),
    cell: float = 0.05,
    crack_width: float = 1e-3,
    face_cracks: int = 3,
    inner: bool = True,
    seed: int = 0,
) -> GroundTruth:
    """Build a single-sheet closed box with hairline cracks, and a small box inside it.

    The six sides are separate sheets pulled back from the box edges, leaving slits of
    about ``crack_width`` along all 12 edges; ``face_cracks`` randomly chosen sides are
    also cut in two across a random line, the halves ``crack_width`` apart.  No edge of a
    side meets an edge of another.

    Parameters
    ----------
    size : (3,) float
        Box extents, centred on the origin.
    cell : float
        Triangle size.
    crack_width : float
        Width of the slits as a fraction of the box diagonal.
    face_cracks : int
        Sides with an extra crack across them (clipped to 0..6).
    inner : bool
        Put a closed box (30 % of the size) at the centre.
    seed : int
        Chooses the cracked sides, the direction of each cut and where it falls (30 % to
        70 % across the side).

    Returns
    -------
    GroundTruth
        Cracks are defects: the interior stays inside.  Box sheet: layer 1, front outside.
        Inner box: hidden, layer 2, outward.

    Examples
    --------
    >>> t = cracked_box(cell=0.25)
    >>> t.soup.part_names, t.n_faces, int(t.hidden.sum())
    (['box', 'inner_box'], 432, 32)
    """
    rng = np.random.default_rng(seed)
    half = 0.5 * np.asarray(size, np.float64)
    gap = float(crack_width) * float(np.linalg.norm(2 * half))
    chosen = rng.permutation(6)[: int(np.clip(face_cracks, 0, 6))]
    splits = {_SIDES[s]: (int(rng.integers(2)), float(rng.uniform(0.3, 0.7))) for s in chosen}
    V, F, _ = _box_sheet(-half, half, cell, gap=gap, splits=splits)
    pieces = [_Piece(V, F, "box", outside=(True, False), layer=1)]
    if inner:
        iV, iF = _box(-0.3 * half, 0.3 * half, cell)
        pieces.append(_Piece(iV, iF, "inner_box", outside=(False, False), layer=2))
    return _compose(
        pieces,
        "cracked_box",
        f"single-sheet box with slits of {crack_width:g} x diagonal along all edges and across "
        f"{len(chosen)} sides, a closed box inside; cracks must not let the outside in",
    )


def box_with_opening(
    size: tuple[float, float, float] = (2.0, 1.5, 1.0),
    cell: float = 0.05,
    opening: float = 0.6,
    side: str = "-y",
    crack_width: float = 0.0,
    inner: bool = True,
    seed: int = 0,
) -> GroundTruth:
    """Build a single-sheet box with a large opening in one side: a cave (appendix H, Fig. 7).

    Parameters
    ----------
    size : (3,) float
        Box extents, centred on the origin.
    cell : float
        Triangle size.
    opening : float
        The opening is a centred rectangle of ``opening`` times the side's width and height
        (cells whose centre lies in it are removed); in (0, 1).
    side : {"-x", "+x", "-y", "+y", "-z", "+z"}
        The side with the opening.
    crack_width : float
        Optional slits along the edges as well (fraction of the diagonal).
    inner : bool
        Put a closed box (30 % of the size) at the centre, seen through the opening.
    seed : int
        Unused (the model is fully determined); kept for a uniform signature.

    Returns
    -------
    GroundTruth
        Everything inside is reachable through the opening: both sides of every sheet face
        are outside (``two_sided``, layer 1, front facing away from the box centre), and
        the inner box is visible (layer 1, front outside).  For small openings the truth
        stays "reachable"; where a method puts the line between crack and opening is its
        own parameter.

    Raises
    ------
    ParameterError
        An unknown ``side``, or ``opening`` outside (0, 1).

    Examples
    --------
    >>> t = box_with_opening(cell=0.25)
    >>> t.n_faces, t.n_layers, int(t.two_sided.sum())
    (432, 1, 400)
    """
    if side not in _SIDES:
        raise ParameterError(f"side must be one of {_SIDES}, got {side!r}")
    if not 0 < opening < 1:
        raise ParameterError(f"opening must be in (0, 1), got {opening}")
    half = 0.5 * np.asarray(size, np.float64)
    gap = float(crack_width) * float(np.linalg.norm(2 * half))
    V, F, _ = _box_sheet(-half, half, cell, gap=gap, opening=(side, float(opening)))
    pieces = [_Piece(V, F, "cave", outside=(True, True), layer=1, two_sided=True)]
    if inner:
        iV, iF = _box(-0.3 * half, 0.3 * half, cell)
        pieces.append(_Piece(iV, iF, "inner_box", outside=(True, False), layer=1))
    return _compose(
        pieces,
        "box_with_opening",
        f"single-sheet box with a {opening:g} x {opening:g} opening in side {side}; the inside is "
        "reachable, so both sides of the walls and the inner box are outside",
    )
